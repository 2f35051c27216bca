//! Coarse-graining against synthetic series with known answers, and the reader's errors.

mod common;

use std::path::Path;

use sha2::Digest;
use verdem::analysis::cg::{self, CgOptions, KernelChoice, COLUMNS};
use verdem::io::mercury;

const AREA: f64 = 4.0 * 5.0;

fn options(walls: usize, kernel: KernelChoice) -> CgOptions {
    CgOptions {
        from: Some(0),
        to: None,
        slices: 10,
        kernel,
        width: Some(0.7),
        walls,
        density: 1.0,
        periodic: [true, true, false],
        blocks: 2,
    }
}

/// Writes save `k` of series `name` in `dir`: particles `(x, v)` of radius 0.5, and fstat rows.
fn save(dir: &Path, k: u64, particles: &[([f64; 3], [f64; 3])], rows: &[String]) {
    let mut d = format!("{} 0 0 0 0 4 5 10\n", particles.len());
    for (x, v) in particles {
        d.push_str(&format!(
            "{} {} {} {} {} {} 0.5 0 0 0 0 0 0 0\n",
            x[0], x[1], x[2], v[0], v[1], v[2]
        ));
    }
    std::fs::write(dir.join(format!("s.data.{k:04}")), d).unwrap();
    let mut f = String::from("# 0 1\n# 0 0 0 4 5 10\n# 0.5 0.5 0 0 0 0\n");
    for r in rows {
        f.push_str(r);
        f.push('\n');
    }
    std::fs::write(dir.join(format!("s.fstat.{k:04}")), f).unwrap();
}

fn profiles(dir: &Path, o: &CgOptions) -> cg::Profiles {
    cg::coarse_grain(&cg::Series::find(&dir.join("s")).unwrap(), o).unwrap()
}

#[test]
fn uniform_velocity_lattice_has_exact_velocity_and_zero_temperature() {
    let dir = tempfile::tempdir().unwrap();
    let lattice: Vec<_> = (0..40)
        .map(|a| {
            (
                [
                    (a % 4) as f64 + 0.5,
                    (a / 4 % 5) as f64 + 0.5,
                    1.0 + (a / 20) as f64 * 5.0,
                ],
                [0.3, -0.1, 0.0],
            )
        })
        .collect();
    for k in 0..4 {
        save(dir.path(), k, &lattice, &[]);
    }
    let p = profiles(dir.path(), &options(0, KernelChoice::Heaviside));
    let mut seen = 0;
    for d in &p.mean {
        if d.rho > 0.0 {
            seen += 1;
            assert!((d.velocity.x - 0.3).abs() < 1e-15 && (d.velocity.y + 0.1).abs() < 1e-15);
            assert!(d.temperature.abs() < 1e-15, "T = {}", d.temperature);
        }
    }
    assert_eq!(seen, 2);
}

#[test]
fn prescribed_random_velocities_give_the_exact_temperature() {
    let dir = tempfile::tempdir().unwrap();
    // 12 particles in one slice (z in [5, 6)); velocities spread about their mean
    let parts: Vec<_> = (0..12)
        .map(|a| {
            let s = a as f64;
            (
                [s % 4.0, (s * 0.37) % 5.0, 5.5],
                [
                    0.2 + 0.1 * (s * 1.3).sin(),
                    0.05 * (s * 2.1).cos(),
                    -0.07 * (s * 0.7).sin(),
                ],
            )
        })
        .collect();
    save(dir.path(), 0, &parts, &[]);
    save(dir.path(), 1, &parts, &[]);
    let p = profiles(dir.path(), &options(0, KernelChoice::Heaviside));
    let n = parts.len() as f64;
    let mean: [f64; 3] = [0, 1, 2].map(|c| parts.iter().map(|(_, v)| v[c]).sum::<f64>() / n);
    let t = parts
        .iter()
        .map(|(_, v)| (0..3).map(|c| (v[c] - mean[c]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / (3.0 * n);
    let slice = &p.mean[5];
    assert!(
        (slice.temperature - t).abs() < 1e-14 * t.max(1.0),
        "{} vs {t}",
        slice.temperature
    );
    let m = std::f64::consts::PI / 6.0;
    assert!((slice.nu - n * m / (AREA * 1.0)).abs() < 1e-15);
}

/// One static contact whose branch crosses three slices: the contact stress is split between
/// them by the length of branch in each, and its integral over z times the area is f⊗l.
#[test]
fn contact_straddling_slices_integrates_to_f_outer_l() {
    for kernel in [
        KernelChoice::Heaviside,
        KernelChoice::Gauss,
        KernelChoice::Lucy,
    ] {
        let dir = tempfile::tempdir().unwrap();
        // i at z = 6.3 (above), j at z = 4.4: n from j to i
        let (zi, zj) = (6.3, 4.4);
        let l = [0.6, 0.0, zi - zj];
        let len: f64 = l[0] * l[0] + l[2] * l[2];
        let n = [l[0] / len.sqrt(), 0.0, l[2] / len.sqrt()];
        let (fnn, ft) = (2.0, 0.5);
        let t = [n[2], 0.0, -n[0]];
        let row = |a: usize, b: usize, s: f64| {
            format!(
                "0 {a} {b} 2 2 5 0.01 0 {fnn} {ft} {} {} {} {} {} {}",
                s * n[0],
                0.0,
                s * n[2],
                s * t[0],
                0.0,
                s * t[2]
            )
        };
        let parts = [([2.6, 2.0, zi], [0.0; 3]), ([2.0, 2.0, zj], [0.0; 3])];
        save(dir.path(), 0, &parts, &[row(0, 1, 1.0), row(1, 0, -1.0)]);
        let mut o = options(0, kernel);
        // smooth kernels are sampled finely enough for the sum over grid points to integrate
        o.slices = if kernel == KernelChoice::Heaviside {
            10
        } else {
            200
        };
        let p = profiles(dir.path(), &o);
        let h = p.grid.h();
        let f = [fnn * n[0] + ft * t[0], 0.0, fnn * n[2] + ft * t[2]];
        for (r, c) in [(0, 0), (0, 2), (2, 0), (2, 2)] {
            let integral: f64 = p.mean.iter().map(|d| d.contact[(r, c)]).sum::<f64>() * h * AREA;
            let expected = f[r] * l[c];
            let tol = if kernel == KernelChoice::Heaviside {
                1e-12
            } else {
                2e-2
            };
            assert!(
                (integral - expected).abs() < tol * expected.abs().max(1e-3),
                "{kernel:?} ({r},{c}): {integral} vs {expected}"
            );
        }
        if kernel == KernelChoice::Heaviside {
            // slice 4 = [4, 5): branch from 4.4 to 5.0 is 0.6 of 1.9; slice 5 = 1.0/1.9; slice 6 = 0.3/1.9
            let zz = |k: usize| p.mean[k].contact[(2, 2)] * h * AREA / (f[2] * l[2]);
            for (k, frac) in [(4, 0.6 / 1.9), (5, 1.0 / 1.9), (6, 0.3 / 1.9)] {
                assert!(
                    (zz(k) - frac).abs() < 1e-12,
                    "slice {k}: {} vs {frac}",
                    zz(k)
                );
            }
        }
    }
}

/// A free–wall contact: the branch runs from the contact point to the free sphere's centre only,
/// and the wall sphere carries no mass.
#[test]
fn contact_with_a_wall_sphere_uses_the_branch_from_the_contact_point() {
    let dir = tempfile::tempdir().unwrap();
    // particle 0 is a wall sphere at z = 0.5; free particle 1 above at z = 1.45
    let parts = [
        ([2.0, 2.0, 0.5], [-1.0, 0.0, 0.0]),
        ([2.0, 2.0, 1.45], [0.0; 3]),
    ];
    let row = "0 1 0 2 2 0.975 0.05 0 10 0 0 0 1 0 0 0".to_string();
    save(dir.path(), 0, &parts, &[row]);
    let p = profiles(dir.path(), &options(1, KernelChoice::Heaviside));
    let h = p.grid.h();
    let integral: f64 = p.mean.iter().map(|d| d.contact[(2, 2)]).sum::<f64>() * h * AREA;
    assert!(
        (integral - 10.0 * (1.45 - 0.975)).abs() < 1e-12,
        "{integral}"
    );
    let mass: f64 = p.mean.iter().map(|d| d.rho).sum::<f64>() * h * AREA;
    assert!(
        (mass - std::f64::consts::PI / 6.0).abs() < 1e-14,
        "wall sphere counted: {mass}"
    );
    // the free sphere pushes the wall down: force on wall group 0 is −10 z
    assert_eq!(p.wall_force[0][0].z, -10.0);
}

/// verdem's own output reads back: the mass check is exact and the files pass the checks' mass
/// line.
#[test]
fn coarse_grains_a_series_verdem_wrote() {
    let case = common::quick_case();
    let dir = tempfile::tempdir().unwrap();
    let mut e = common::engine(
        &case,
        Some(&common::data("states/mercury_t143.85.data")),
        Default::default(),
    );
    common::run_with_saves(e.as_mut(), dir.path(), "s", 2000, 500);
    let mut o = options(480, KernelChoice::Heaviside);
    o.slices = 100;
    let (p, _, report) = cg::write_all(&dir.path().join("s"), &o).unwrap();
    assert!(report.contains("PASS  mass"), "{report}");
    assert!(dir.path().join("s.profiles.png").exists());
    let csv = std::fs::read_to_string(dir.path().join("s.profiles.csv")).unwrap();
    assert_eq!(csv.lines().count(), 101);
    assert_eq!(
        csv.lines().next().unwrap().split(',').count(),
        1 + 2 * COLUMNS.len()
    );
    assert!(p.mean.iter().map(|d| d.nu).sum::<f64>() > 0.0);
}

#[test]
fn malformed_files_are_rejected_with_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let ok_line = "1 2 3 0 0 0 0.5 0 0 0 0 0 0 0";
    let e = mercury::read_data(&bad(
        "a.data",
        &format!("2 0 0 0 0 4 5 10\n{ok_line}\n1 2 3\n"),
    ))
    .unwrap_err();
    assert!(
        e.to_string().contains("a.data:3:") && e.to_string().contains("expected 14 columns"),
        "{e}"
    );
    let e = mercury::read_data(&bad(
        "b.data",
        &format!("3 0 0 0 0 4 5 10\n{ok_line}\n{ok_line}\n"),
    ))
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("header announces 3 particles but the file has 2"),
        "{e}"
    );
    let e = mercury::read_data(&bad(
        "c.data",
        &format!(
            "1 0 0 0 0 4 5 10\n{}\n",
            ok_line.replace("1 2 3", "1 NaN 3")
        ),
    ))
    .unwrap_err();
    assert!(
        e.to_string().contains("c.data:2:") && e.to_string().contains("not finite"),
        "{e}"
    );
    let e = mercury::read_fstat(&bad(
        "d.fstat",
        "# 0 1\n# 0 0 0 4 5 10\n# 0.5 0.5 0 0 0 0\n0 1 2 3\n",
    ))
    .unwrap_err();
    assert!(
        e.to_string().contains("d.fstat:4:") && e.to_string().contains("expected 16 columns"),
        "{e}"
    );
}

/// A check against error bars is judged only when there are two blocks or more: one save gives
/// no standard error, and its χ² would be infinite.
#[test]
fn checks_against_error_bars_need_two_blocks() {
    let dir = tempfile::tempdir().unwrap();
    // a layer of spheres near the bottom only: far from symmetric about the mid-plane
    let layer = |vx: f64| -> Vec<([f64; 3], [f64; 3])> {
        (0..20)
            .map(|a| {
                let x = [(a % 4) as f64 + 0.5, (a / 4) as f64 + 0.5, 1.0];
                (x, [vx + 0.01 * a as f64, 0.0, 0.0])
            })
            .collect()
    };
    let judge = |saves: u64| {
        for k in 0..saves {
            save(dir.path(), k, &layer(0.1 * (k + 1) as f64), &[]);
        }
        let p = profiles(dir.path(), &options(0, KernelChoice::Heaviside));
        let checks = cg::checks::run(&p, 1.0);
        (p.blocks, cg::checks::report(&p, &checks), checks)
    };
    let (blocks, report, checks) = judge(1);
    assert_eq!(blocks, 1, "{report}");
    let symmetric = |c: &[cg::checks::Check]| {
        c.iter()
            .find(|c| c.quantity == "symmetric nu about the mid-plane")
            .unwrap()
            .pass()
    };
    assert_eq!(symmetric(&checks), None, "{report}");
    assert!(!report.contains("FAIL"), "{report}");
    assert!(
        report.contains("not judged: 1 block gives no error bar"),
        "{report}"
    );
    let (blocks, report, checks) = judge(2);
    assert_eq!(blocks, 2, "{report}");
    assert_eq!(symmetric(&checks), Some(false), "{report}");
    assert!(!report.contains("not judged"), "{report}");
}

/// Every profiles table kept in golden/ reads back and is written again byte for byte.
#[test]
fn golden_profiles_tables_round_trip_byte_for_byte() {
    let mut tables = vec![common::root().join("golden/full_run/shear_flow.profiles.csv")];
    for dir in ["golden/peers", "golden/tradeoff"] {
        for entry in std::fs::read_dir(common::root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            let name = path.to_string_lossy().into_owned();
            if name.ends_with(".profiles.csv")
                || (dir == "golden/tradeoff" && name.ends_with(".profiles_inrun.csv"))
            {
                tables.push(path);
            }
        }
    }
    assert!(tables.len() >= 13, "{tables:?}");
    for path in tables {
        let text = std::fs::read_to_string(&path).unwrap();
        let table = verdem::analysis::cg::table::Table::read(&path).unwrap();
        assert!(table.csv() == text, "{}", path.display());
    }
}

/// Runs `verdem cg` on the series `dir/s` as the conservation case sees its saves (no wall
/// spheres, density 1), 10 slices, 2 blocks, every save, with `more` arguments; fails the test
/// when it has not finished within a minute (it used to spin forever on a non-finite range).
fn cg_command(dir: &Path, more: &[&str]) -> std::process::Output {
    let case = common::root().join("cases/verify/conservation.toml");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("cg")
        .arg(dir.join("s"))
        .arg("--case")
        .arg(case)
        .args(["--slices", "10", "--blocks", "2", "--from", "0"])
        .args(more)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("verdem cg did not finish within a minute");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// 40 spheres in two layers at rest but for a drift vx = 0.3, as `(x, v)`.
fn lattice() -> Vec<([f64; 3], [f64; 3])> {
    (0..40)
        .map(|a| {
            (
                [
                    (a % 4) as f64 + 0.5,
                    (a / 4 % 5) as f64 + 0.5,
                    1.0 + (a / 20) as f64 * 5.0,
                ],
                [0.3, 0.0, 0.0],
            )
        })
        .collect()
}

/// Every file `verdem cg` writes beside the series, that exists, holds no NaN or infinity
/// (no word that reads as one as a number).
fn assert_nothing_non_finite_written(dir: &Path) {
    for ext in ["profiles.csv", "checks.txt"] {
        if let Ok(text) = std::fs::read_to_string(dir.join(format!("s.{ext}"))) {
            let bad = text
                .split(|c: char| c.is_whitespace() || ",()[]:;=".contains(c))
                .find(|w| w.parse::<f64>().is_ok_and(|v| !v.is_finite()));
            assert_eq!(bad, None, "{ext}: {text}");
        }
    }
}

/// The check itself: it sees a NaN and an infinity, and not the word "info".
#[test]
fn the_check_for_non_finite_numbers_sees_them() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.checks.txt"),
        "info  x: 1.5 (expected 0)\n",
    )
    .unwrap();
    assert_nothing_non_finite_written(dir.path());
    for bad in ["1,NaN,2\n", "chi2/dof = inf\n"] {
        std::fs::write(dir.path().join("s.profiles.csv"), bad).unwrap();
        let caught = std::panic::catch_unwind(|| assert_nothing_non_finite_written(dir.path()));
        assert!(caught.is_err(), "{bad}");
    }
}

/// A series whose profiles are exact (a uniform drift, no contacts, no spread over the saves):
/// `verdem cg` writes its files, and none holds a NaN or an infinity (an exact trend's
/// infinitely many standard errors read "undefined").
#[test]
fn an_exact_series_is_written_without_a_non_finite_number() {
    let dir = tempfile::tempdir().unwrap();
    for k in 0..8 {
        save(dir.path(), k, &lattice(), &[]);
    }
    let out = cg_command(dir.path(), &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("s.profiles.csv").exists());
    assert!(dir.path().join("s.profiles.png").exists());
    assert_nothing_non_finite_written(dir.path());
}

#[test]
fn a_velocity_too_large_to_square_is_refused_naming_the_file_line_and_value() {
    let dir = tempfile::tempdir().unwrap();
    for k in 0..4 {
        let mut parts = lattice();
        if k == 2 {
            parts[7].1[0] = 1e200;
        }
        save(dir.path(), k, &parts, &[]);
    }
    let out = cg_command(dir.path(), &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    // particle 7 is on line 9 of its save, vx its fourth column
    assert!(
        err.contains("s.data.0002:9: particle 7: column 4 (vx): 1e200 is too large"),
        "{err}"
    );
    assert!(!dir.path().join("s.profiles.csv").exists(), "{err}");
    assert!(!dir.path().join("s.profiles.png").exists(), "{err}");
    assert_nothing_non_finite_written(dir.path());
}

#[test]
fn a_nan_in_a_save_is_refused_naming_the_file_line_and_value() {
    let dir = tempfile::tempdir().unwrap();
    for k in 0..4 {
        save(dir.path(), k, &lattice(), &[]);
    }
    let path = dir.path().join("s.data.0001");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[5] = lines[5].replacen(" 0.3 ", " NaN ", 1);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    let out = cg_command(dir.path(), &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("s.data.0001:6: column 4 (vx): not finite: \"NaN\""),
        "{err}"
    );
    assert!(!dir.path().join("s.profiles.csv").exists(), "{err}");
    assert_nothing_non_finite_written(dir.path());
}

/// Velocities whose squares are finite but whose spread over the blocks is not: the profiles'
/// standard errors would be infinite, and the coarse-graining says so instead.
#[test]
fn profiles_whose_errors_overflow_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for k in 0..4 {
        let mut parts = lattice();
        for p in &mut parts {
            p.1[0] = 1e150 * (k + 1) as f64;
        }
        save(dir.path(), k, &parts, &[]);
    }
    let series = cg::Series::find(&dir.path().join("s")).unwrap();
    let e = cg::coarse_grain(&series, &options(0, KernelChoice::Heaviside))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the profiles of saves 0 to 3") && e.contains("not a finite number"),
        "{e}"
    );
    let out = cg_command(dir.path(), &[]);
    assert!(!out.status.success());
    assert!(!dir.path().join("s.profiles.csv").exists());
    assert_nothing_non_finite_written(dir.path());
}

/// The axis of a plot is total: NaN, infinities and widths beyond the largest number are
/// refused, zero and huge widths give a usable range, drawing such profiles finishes, and the
/// benchmark plot's log axes and the particles' picture refuse ranges they cannot draw.
#[test]
fn plot_axes_are_total_and_prompt() {
    use verdem::analysis::cg::plot::{axis_range, panels_png, Curve};
    let (tx, rx) = std::sync::mpsc::channel();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("p.png");
    let png_in_thread = png.clone();
    std::thread::spawn(move || {
        let mut refused = Vec::new();
        for (lo, hi) in [
            (f64::NAN, 1.0),
            (0.0, f64::INFINITY),
            (f64::NEG_INFINITY, f64::INFINITY),
            (-1e308, 1e308),
            (-f64::MAX, f64::MAX),
        ] {
            refused.push(axis_range(lo, hi).is_err());
        }
        let mut ranges = Vec::new();
        for (lo, hi) in [
            (0.0, 0.0),
            (5.0, 5.0),
            (1e308, 1e308),
            (f64::MAX, f64::MAX),
            (0.0, 1e308),
            (1e20, 1e20 + 1e5),
            (1.0, 1.0 + f64::EPSILON),
            (-3.0, 2.0),
        ] {
            ranges.push(((lo, hi), axis_range(lo, hi).ok()));
        }
        let draw = |value: f64| {
            let curve = Curve {
                label: "",
                z: vec![1.0, 2.0, 3.0],
                value: vec![value; 3],
                se: vec![0.0; 3],
            };
            panels_png(&[("flat".to_string(), vec![curve])], &png_in_thread)
        };
        let mut drawn = vec![draw(1e308).is_ok(), draw(0.0).is_ok()];
        let inf = draw(f64::INFINITY).map_err(|e| format!("{e:#}"));
        // the benchmark's log axes: an end beyond the largest number or below the smallest
        // normal one is refused
        let cost = |points: Vec<(f64, f64)>| {
            verdem::bench::draw_cost(&[("code".to_string(), points)], &png_in_thread).is_err()
        };
        refused.push(cost(vec![(1.0, 1.5e308), (2.0, 1.0)]));
        refused.push(cost(vec![(1.0, 5e-324), (2.0, 1.0)]));
        // the particles' picture: a box too wide for its axes is refused
        let sphere = verdem::io::vtk::Particle {
            x: verdem::Vec3::zeros(),
            v: verdem::Vec3::new(1e308, 0.0, 0.0),
            w: verdem::Vec3::zeros(),
            radius: 0.5,
            wall: false,
        };
        let picture = |lo: f64, hi: f64| {
            verdem::analysis::particles::particles_png(
                std::slice::from_ref(&sphere),
                &verdem::Vec3::from_element(lo),
                &verdem::Vec3::from_element(hi),
                "t",
                &png_in_thread,
            )
        };
        refused.push(picture(-1e308, 1e308).is_err());
        drawn.push(picture(-1.0, 1.0).is_ok());
        tx.send((refused, ranges, drawn, inf)).unwrap();
    });
    let (refused, ranges, drawn, inf) = rx
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("the axes and plots finish within a minute");
    assert_eq!(refused, vec![true; 8]);
    for ((lo, hi), r) in ranges {
        let r = r.unwrap_or_else(|| panic!("{lo}..{hi} refused"));
        assert!(
            r.start.is_finite() && r.end.is_finite() && (r.end - r.start).is_finite(),
            "{lo}..{hi}: {r:?}"
        );
        assert!(
            r.start <= lo && r.end >= hi && r.start < r.end,
            "{lo}..{hi}: {r:?}"
        );
    }
    assert_eq!(drawn, [true; 3]);
    let e = inf.unwrap_err();
    assert!(e.contains("p.png: cannot draw") && e.contains("inf"), "{e}");
}

/// Two tables without error bars whose means differ by 155 %: `verdem compare` says the χ² is
/// undefined and gives the difference, never a χ² of 0 that reads as agreement.
#[test]
fn compare_without_error_bars_says_chi2_is_undefined() {
    use verdem::analysis::cg::table::Table;
    let dir = tempfile::tempdir().unwrap();
    let flat = |value: f64| {
        let z: Vec<f64> = (0..100).map(|k| (k as f64 + 0.5) * 0.22).collect();
        Table {
            mean: z.iter().map(|_| vec![value; COLUMNS.len()]).collect(),
            se: z.iter().map(|_| vec![0.0; COLUMNS.len()]).collect(),
            z,
        }
    };
    let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    std::fs::write(&a, flat(1.0).csv()).unwrap();
    std::fs::write(&b, flat(2.55).csv()).unwrap();
    let out = common::verdem_ok([
        "compare".as_ref(),
        a.as_os_str(),
        b.as_os_str(),
        "--labels".as_ref(),
        "ref,other".as_ref(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("`other`: χ² undefined: no error bars in either table."),
        "{text}"
    );
    assert!(text.contains("+155.00 %"), "{text}");
    assert!(
        text.contains("| other | undefined | undefined | undefined |"),
        "{text}"
    );
    assert!(
        !text.contains("| 0.00 |") && !text.contains("NaN"),
        "{text}"
    );
}

/// A series with one `.fstat` or one `.data` missing: `verdem cg` names the missing file and
/// writes nothing; with `--skip-incomplete` it warns, naming it, and coarse-grains the others.
#[test]
fn an_incomplete_save_is_said_or_skipped_with_a_warning() {
    for missing in ["fstat", "data"] {
        let dir = tempfile::tempdir().unwrap();
        for k in 0..4 {
            save(dir.path(), k, &lattice(), &[]);
        }
        std::fs::remove_file(dir.path().join(format!("s.{missing}.0002"))).unwrap();
        let out = cg_command(dir.path(), &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{err}");
        assert!(
            err.contains(&format!("s.{missing}.0002: missing (save 2 has "))
                && err.contains("--skip-incomplete"),
            "{err}"
        );
        assert!(!dir.path().join("s.profiles.csv").exists());
        let out = cg_command(dir.path(), &["--skip-incomplete"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        assert!(
            err.contains("warning: save 2 skipped: ")
                && err.contains(&format!("s.{missing}.0002: missing")),
            "{err}"
        );
        assert!(dir.path().join("s.profiles.csv").exists());
        let (series, incomplete) = cg::Series::scan(&dir.path().join("s")).unwrap();
        assert_eq!(series.saves, [0, 1, 3]);
        assert_eq!(incomplete.len(), 1);
    }
}

/// MercuryCG's `.stat` rows (`data/mercurycg/`, provenance in `data/README.md`): per row its
/// z and the raw fields verdem computes, in verdem's order: ν, ρ, momentum (3), momentum flux
/// (xx xy xz yy yz zz), contact stress (xx xy xz yx yy yz zx zy zz).
fn mercurycg_rows(name: &str) -> Vec<(f64, Vec<f64>)> {
    let text = std::fs::read_to_string(common::data(&format!("mercurycg/{name}"))).unwrap();
    text.lines()
        .skip(2)
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (v[1], v[2..22].to_vec())
        })
        .collect()
}

/// The same raw fields of verdem's profiles at grid point k, averaged over the saves as
/// MercuryCG's `-timeaverage`.
fn verdem_row(p: &cg::Profiles, k: usize) -> Vec<f64> {
    let n = p.per_save.len() as f64;
    let mean = |f: &dyn Fn(&cg::fields::Raw) -> f64| p.per_save.iter().map(f).sum::<f64>() / n;
    let mut row = vec![mean(&|r| r.nu[k]), mean(&|r| r.rho[k])];
    row.extend((0..3).map(|a| mean(&|r| r.momentum[k][a])));
    for (a, b) in [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)] {
        row.push(mean(&|r| r.flux[k][(a, b)]));
    }
    for a in 0..3 {
        row.extend((0..3).map(|b| mean(&|r| r.contact[k][(a, b)])));
    }
    row
}

/// `--kernel heaviside` and `--kernel mercury-gauss` against MercuryCG's own output on three
/// saves 100 steps apart of the steady case (data/README.md: the MercuryDPM commit and the exact
/// commands): every raw field of every core slice (z in [3, 19], where the wall spheres, which
/// MercuryCG weighs as particles, do not reach) agrees to MercuryCG's six printed digits.
/// `--kernel gauss` differs from it in the contact stress: the convention `mercury-gauss` is for.
#[test]
fn heaviside_and_mercury_gauss_agree_with_mercurycg_to_its_printed_digits() {
    let case = verdem::case::Case::load(&common::root().join("cases/shear_flow_steady.toml"))
        .expect("case loads");
    let init = common::root().join("golden/full_run/shear_flow.final.data");
    let dir = tempfile::tempdir().unwrap();
    let mut e = common::engine(&case, Some(&init), Default::default());
    common::run_with_saves(e.as_mut(), dir.path(), "s", 200, 100);
    // MercuryCG's input: the three saves' contacts with j >= i, the rows its reader keeps (it
    // skips the others' remainders with ignore(256), shorter than verdem's rows).
    let mut fstat = String::new();
    for k in 0..3 {
        let text = std::fs::read_to_string(dir.path().join(format!("s.fstat.{k:04}"))).unwrap();
        for l in text.lines() {
            let c: Vec<&str> = l.split_whitespace().collect();
            if l.starts_with('#') || c[2].parse::<usize>().unwrap() >= c[1].parse().unwrap() {
                fstat.push_str(l);
                fstat.push('\n');
            }
        }
    }
    let mut data = Vec::new();
    for k in 0..3 {
        data.extend(std::fs::read(dir.path().join(format!("s.data.{k:04}"))).unwrap());
    }
    // SHA-256 of MercuryCG's input `ref.data` (data/README.md, "MercuryCG reference profiles")
    assert_eq!(
        format!("{:x}", sha2::Sha256::digest(&data)),
        "f569e92d1cc3aede84e138883f73a4857addcdaf27bd818a431c25c99e6b0b38",
        "the steady case's first 200 steps no longer give the saves MercuryCG coarse-grained"
    );
    let reference = std::fs::read_to_string(common::data("mercurycg/steady_200.fstat")).unwrap();
    assert!(
        fstat == reference,
        "the steady case's first 200 steps no longer give data/mercurycg/steady_200.fstat: the \
         MercuryCG reference was made from other saves"
    );
    for (kernel, file) in [
        (KernelChoice::Heaviside, "steady_200.heaviside.stat"),
        (KernelChoice::MercuryGauss, "steady_200.gauss.stat"),
        (KernelChoice::Gauss, "steady_200.gauss.stat"),
    ] {
        let o = CgOptions {
            from: Some(0),
            slices: 100,
            kernel,
            width: Some(0.22),
            blocks: 1,
            ..CgOptions::for_case(&case)
        };
        let p = profiles_of(&dir.path().join("s"), &o);
        let rows = mercurycg_rows(file);
        assert_eq!(rows.len(), 72, "{file}");
        let mut worst_contact: f64 = 0.0;
        for (z, theirs) in &rows {
            let k = ((z - p.grid.z0) / p.grid.h()).floor() as usize;
            assert!((p.grid.z(k) - z).abs() < 1e-4, "{file}: z = {z}");
            let ours = verdem_row(&p, k);
            for (c, (a, b)) in ours.iter().zip(theirs).enumerate() {
                // six significant digits: half a unit of the sixth (and round-off), zero exact
                let unit = if *b == 0.0 {
                    0.0
                } else {
                    10f64.powf(b.abs().log10().floor() - 5.0)
                };
                let tol = 0.5 * unit * (1.0 + 1e-9);
                if kernel == KernelChoice::Gauss && c >= 11 {
                    worst_contact = worst_contact.max((a - b).abs() / b.abs().max(1e-300));
                } else {
                    assert!(
                        (a - b).abs() <= tol,
                        "{kernel:?} at z = {z}, column {c}: verdem {a} vs MercuryCG {b}"
                    );
                }
            }
        }
        if kernel == KernelChoice::Gauss {
            assert!(
                worst_contact > 1e-4,
                "gauss matches MercuryCG: {worst_contact}"
            );
        }
    }
}

fn profiles_of(base: &Path, o: &CgOptions) -> cg::Profiles {
    cg::coarse_grain(&cg::Series::find(base).unwrap(), o).unwrap()
}

/// `verdem cg --kernel mercury-gauss` is offered, described and applied: on a contact whose
/// branch reaches beyond 3 widths of some slices its profiles differ from `--kernel gauss`'s in
/// the contact stress, pressure and shear stress only.
#[test]
fn the_command_line_offers_mercury_gauss() {
    let help = common::verdem_ok(["cg", "--help"]).stdout;
    let help = String::from_utf8_lossy(&help);
    assert!(
        help.contains("mercury-gauss") && help.contains("uncut Gaussian"),
        "{help}"
    );
    let dir = tempfile::tempdir().unwrap();
    let parts = [([2.6, 2.0, 6.3], [0.0; 3]), ([2.0, 2.0, 4.4], [0.0; 3])];
    let (nx, nz) = (0.6 / 1.9924, 1.9 / 1.9924);
    let row = |a: usize, b: usize, s: f64| {
        format!("0 {a} {b} 2 2 5 0.01 0 2 0 {} 0 {} 0 0 0", s * nx, s * nz)
    };
    for k in 0..2 {
        save(dir.path(), k, &parts, &[row(0, 1, 1.0), row(1, 0, -1.0)]);
    }
    let base = dir.path().join("s");
    let csv = |kernel: &str| -> Vec<Vec<f64>> {
        common::verdem_ok([
            "cg",
            base.to_str().unwrap(),
            "--kernel",
            kernel,
            "--width",
            "0.3",
            "--slices",
            "40",
            "--from",
            "0",
            "--blocks",
            "1",
            "--case",
            "cases/verify/binary_collision.toml",
        ]);
        let text = std::fs::read_to_string(dir.path().join("s.profiles.csv")).unwrap();
        text.lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let (gauss, mercury) = (csv("gauss"), csv("mercury-gauss"));
    let header = std::fs::read_to_string(dir.path().join("s.profiles.csv")).unwrap();
    let names: Vec<&str> = header.lines().next().unwrap().split(',').collect();
    let mut differing = std::collections::BTreeSet::new();
    for (g, m) in gauss.iter().zip(&mercury) {
        for (c, (a, b)) in g.iter().zip(m).enumerate() {
            if a != b {
                differing.insert(names[c].trim());
            }
        }
    }
    assert!(
        !differing.is_empty()
            && differing.iter().all(|n| ["con_", "pressure", "shear_xz"]
                .iter()
                .any(|c| n.starts_with(c))),
        "{differing:?}"
    );
}
