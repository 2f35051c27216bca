//! In-run averaging (`verdem run`'s NAME.profiles_inrun.csv): the same fields as the saves'
//! coarse-graining when it samples the saves' steps, agreement within errors when it samples
//! more often, the analytical stress of a static compressed lattice, and the files a run writes.

mod common;

use verdem::analysis::cg::{self, CgOptions, Series, COLUMNS};
use verdem::analysis::inrun::{Inrun, Sampling};
use verdem::analysis::stats::standard_error;
use verdem::analysis::verdict::Outcome;
use verdem::case::Case;
use verdem::run::{self, RunOptions};
use verdem::step::engine::Overrides;
use verdem::step::Engine;

fn col(name: &str) -> usize {
    COLUMNS.iter().position(|c| *c == name).unwrap()
}

fn options(dir: &std::path::Path, end_step: u64, save_every: u64, saves: bool) -> RunOptions {
    RunOptions {
        write_saves: saves,
        ..common::run_options(dir, "s", end_step, save_every)
    }
}

/// The steady case from the full run's final state, on one thread.
fn steady() -> (Case, Box<dyn Engine>) {
    let case = Case::load(&common::root().join("cases/shear_flow_steady.toml")).unwrap();
    let init = common::root().join("golden/full_run/shear_flow.final.data");
    let e = common::engine(
        &case,
        Some(&init),
        Overrides {
            threads: Some(1),
            ..Overrides::default()
        },
    );
    (case, e)
}

/// Runs the steady case for `steps` steps with a save every `save_every` and an in-run
/// accumulator sampling `every` / `particle_every` over the steps of saves `first..`; returns
/// the saves' profiles (from save `first` on) and the in-run result.
fn steady_run(
    steps: u64,
    save_every: u64,
    first: u64,
    every: u64,
    particle_every: u64,
) -> (cg::Profiles, verdem::analysis::inrun::InrunResult) {
    let (case, mut e) = steady();
    let dir = tempfile::tempdir().unwrap();
    let o = CgOptions {
        from: Some(first),
        ..CgOptions::for_case(&case)
    };
    let mut inrun = Inrun::new(
        &o,
        &e.state().domain,
        Sampling {
            every,
            particle_every,
            // samples at the steps of saves first, first + 1, …
            from: first * save_every - every,
            to: steps,
        },
    )
    .unwrap();
    let opts = options(dir.path(), steps, save_every, true);
    run::run_observed(e.as_mut(), &opts, false, Some(&mut inrun)).unwrap();
    // Both take the walls' every-step mean forces: cg from the diagnostics' ledgers over each
    // save's interval, the accumulator from the engine's impulse over each bin.
    let saves = cg::coarse_grain(&Series::find(&dir.path().join("s")).unwrap(), &o).unwrap();
    let inrun = inrun.result().unwrap();
    assert!(saves.wall_force_every_step && inrun.profiles.wall_force_every_step);
    (saves, inrun)
}

#[test]
fn sampling_the_saves_steps_gives_the_saves_profiles() {
    // Samples at exactly the saves' steps see the states the saves hold: every column equals
    // the saves' coarse-graining up to the rounding of the .fstat forces' components.
    let (saves, inrun) = steady_run(20_000, 1000, 10, 1000, 1000);
    assert_eq!(inrun.contact_samples, 11);
    assert_eq!(inrun.particle_samples, 11);
    common::assert_columns_agree(&saves.mean, &inrun.profiles.mean, 1e-9, ("saves", "in-run"));
    // and the walls' mean force over each bin (the steps of a save's interval) equals the
    // diagnostics' mean over that save's interval: the same impulse, read twice
    assert_eq!(saves.wall_force.len(), inrun.profiles.wall_force.len());
    for (s, w) in saves.wall_force.iter().zip(&inrun.profiles.wall_force) {
        for g in 0..2 {
            assert!(
                (s[g] - w[g]).norm() <= 1e-9 * s[g].norm().max(1.0),
                "{s:?} {w:?}"
            );
        }
    }
}

#[test]
fn sampling_every_half_contact_agrees_with_the_saves_within_errors_and_is_more_precise() {
    // 20000 steps, saves 10..20 (11 saves) against contact samples every 25 steps over the same
    // steps (particle samples at the saves' steps, so that the kinetic parts are the same).
    let (saves, inrun) = steady_run(20_000, 1000, 10, 25, 1000);
    let p = &inrun.profiles;
    let core = cg::core_range(&saves.grid);
    // Core means (per slice, 11 saves leave most slices with a contact in only a few saves,
    // and their block errors say little).
    let core_mean = |q: &cg::Profiles, c: usize| -> (f64, f64) {
        let n = core.len() as f64;
        let mean = core
            .clone()
            .map(|k| cg::columns(&q.mean[k])[c])
            .sum::<f64>()
            / n;
        let vals: Vec<f64> = q
            .block_columns
            .iter()
            .map(|b| core.clone().map(|k| b[k][c]).sum::<f64>() / n)
            .collect();
        (mean, standard_error(&vals))
    };
    for name in ["con_xz", "con_zz", "pressure", "shear_xz"] {
        let ((a, sa), (b, sb)) = (core_mean(&saves, col(name)), core_mean(p, col(name)));
        let z = (a - b) / (sa * sa + sb * sb).sqrt();
        assert!(
            z.abs() < 3.0,
            "{name}: saves {a} +- {sa}, in-run {b} +- {sb}"
        );
    }
    // Standard errors of the core mean of σxz: 11 saves against ~11000 steps / 2τ ≈ 280
    // independent samples (τ ≈ 20 steps, docs/statistics.md): √(280/11) ≈ 5 times smaller.
    let core_se = |q: &cg::Profiles| core_mean(q, col("con_xz")).1;
    let ratio = core_se(&saves) / core_se(p);
    assert!(ratio > 2.5, "SE ratio saves / in-run {ratio:.2}");
}

#[test]
fn a_static_compressed_lattice_has_the_analytical_contact_stress() {
    // A simple cubic lattice of 4×4×4 spheres of diameter 1 at spacing a = 0.99 in a periodic
    // box, at rest: each sphere has six neighbours at overlap δ = 1 − a pressing equally from
    // opposite sides, so nothing moves, and each contact carries f = kn·δ (no relative velocity,
    // no damping force). The contact stress Σ f⊗l / V has one contact per sphere and direction:
    // σ_xx = σ_yy = σ_zz = kn·δ·a / a³ = kn·δ/a², no shear; σ_zz is the same in every slice
    // (the vertical branches tile each column), σ_xx and σ_yy hold only on average over the
    // height (the horizontal branches lie in the layers' slices).
    let (a, n, kn) = (0.99, 4usize, 2e5);
    let l = a * n as f64;
    let mut text = format!(
        "name = \"lattice\"\n[run]\nsteps = 100\nsave_every = 100\nsteps_per_collision = 50.0\n\
         threads = 1\n[domain]\nlo = [0.0, 0.0, 0.0]\nhi = [{l}, {l}, {l}]\n\
         periodic = [true, true, true]\n[material]\ndensity = 1.0\ndiameter = 1.0\n\
         [contact]\nkn = {kn}\ngamman = 15.0\nkt = 0.0\ngammat = 0.0\nmu = 0.0\n\
         [scene]\nkind = \"spheres\"\n"
    );
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let at = |q: usize| (q as f64 + 0.5) * a;
                text.push_str(&format!(
                    "[[scene.sphere]]\nx = [{}, {}, {}]\nv = [0.0, 0.0, 0.0]\n",
                    at(i),
                    at(j),
                    at(k)
                ));
            }
        }
    }
    let case = Case::parse(&text, "lattice.toml").unwrap();
    let mut e = common::engine(&case, None, Overrides::default());
    let slices = 36; // h = 0.11: the layers' centres fall inside slices
    let o = CgOptions {
        slices,
        walls: 0,
        periodic: [true; 3],
        ..CgOptions::default()
    };
    let mut inrun = Inrun::new(
        &o,
        &e.state().domain,
        Sampling {
            every: 5,
            particle_every: 10,
            from: 0,
            to: 100,
        },
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    run::run_observed(
        e.as_mut(),
        &options(dir.path(), 100, 100, false),
        false,
        Some(&mut inrun),
    )
    .unwrap();
    let r = inrun.result().unwrap();
    assert_eq!(r.contact_samples, 20);
    let expected = kn * (1.0 - a) / (a * a);
    let p = &r.profiles;
    let height_mean = |name: &str| {
        let c = col(name);
        p.mean.iter().map(|d| cg::columns(d)[c]).sum::<f64>() / slices as f64
    };
    for name in ["con_xx", "con_yy"] {
        let m = height_mean(name);
        assert!(
            (m / expected - 1.0).abs() < 1e-9,
            "{name}: {m} vs {expected}"
        );
    }
    for name in ["con_xy", "con_xz", "con_yz", "shear_xz", "kin_zz"] {
        let m = height_mean(name);
        assert!(m.abs() < 1e-9 * expected, "{name}: {m}");
    }
    // z is bounded in the coarse-graining (walls in the benchmark): the branches that cross
    // the periodic z boundary are spread inside the box only, so σzz is checked between the
    // lowest and the highest layer's centres, which every column's branches tile.
    let h = l / slices as f64;
    let inside = (0..slices).filter(|&k| {
        let z = p.grid.z(k);
        z - h / 2.0 >= 0.5 * a && z + h / 2.0 <= (n as f64 - 0.5) * a
    });
    assert_eq!(inside.clone().count(), 26);
    for k in inside {
        let zz = cg::columns(&p.mean[k])[col("con_zz")];
        assert!(
            (zz / expected - 1.0).abs() < 1e-9,
            "con_zz at slice {k}: {zz}"
        );
    }
}

#[test]
fn a_run_writes_its_in_run_profiles_and_judges_them_beside_the_saves() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("q");
    common::verdem_ok([
        "run",
        "cases/shear_flow_quick.toml",
        "--steps",
        "4000",
        "--save-every",
        "1000",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let name = "shear_flow_quick";
    let table = cg::table::Table::read(&out.join(format!("{name}.profiles_inrun.csv"))).unwrap();
    let saves = cg::table::Table::read(&out.join(format!("{name}.profiles.csv"))).unwrap();
    assert_eq!(table.z, saves.z);
    let checks = std::fs::read_to_string(out.join(format!("{name}.checks.txt"))).unwrap();
    assert!(
        checks.contains("in-run averaging: steps 3001..4000"),
        "{checks}"
    );
    assert!(checks.contains("every 400 steps (3 samples)"), "{checks}");
    assert!(
        checks.contains("checks of the in-run profiles:"),
        "{checks}"
    );
    assert!(checks.contains("SE ratio"), "{checks}");
    // 3 contact samples in one bin: no autocorrelation time, and no NaN written for it
    assert!(
        checks.contains("samples: undefined samples (pressure)"),
        "{checks}"
    );
    let mut words = checks.split(|c: char| !c.is_alphanumeric());
    assert!(!words.any(|w| w == "NaN" || w == "inf"), "{checks}");
}

/// The contact samples the engine takes inside its runs (`Engine::sample_contacts_every`) are,
/// bit for bit, what a stop at each sampled step reads (`Engine::contact_sample`), on one thread
/// and on two, across rebuilds and across the calls that split the steps.
#[test]
fn contact_samples_taken_inside_a_run_are_those_of_a_stop() {
    const K: u64 = 25;
    const STEPS: u64 = 3000;
    let case = Case::load(&common::root().join("cases/shear_flow_steady.toml")).unwrap();
    let init = common::root().join("golden/full_run/shear_flow.final.data");
    let engine = |threads| {
        let o = Overrides {
            threads: Some(threads),
            ..Overrides::default()
        };
        common::engine(&case, Some(&init), o)
    };
    let mut stopped = engine(1);
    let mut expected = Vec::new();
    for _ in 0..STEPS / K {
        stopped.advance(K).unwrap();
        expected.push((stopped.state().step, stopped.contact_sample()));
    }
    let contacts: usize = expected.iter().map(|(_, c)| c.len()).sum();
    assert!(contacts > 100, "only {contacts} contacts sampled");
    assert!(
        stopped.counters().rebuilds >= 3,
        "no rebuild among the samples"
    );
    for threads in [1, 2] {
        let mut e = engine(threads);
        e.sample_contacts_every(K);
        e.advance(1010).unwrap();
        e.advance(STEPS - 1010).unwrap();
        assert_eq!(e.take_contact_samples(), expected, "{threads} threads");
        assert!(e.take_contact_samples().is_empty());
        e.sample_contacts_every(0);
        e.advance(K).unwrap();
        assert!(
            e.take_contact_samples().is_empty(),
            "sampled after it was turned off"
        );
    }
}

/// `verdem cross`'s loop (`peers::inrun::advance_observed`) feeds an in-run accumulator exactly
/// as `verdem run`'s does: the same profiles and errors, bit for bit, the contact samples taken
/// inside the steps included.
#[test]
fn the_cross_loop_averages_in_run_as_the_run_loop_does() {
    let (case, _) = steady();
    let sampling = Sampling {
        every: 25,
        particle_every: 1200,
        from: 2400,
        to: 9600,
    };
    let outputs = |via_run: bool| {
        let (_, mut e) = steady();
        let mut acc = Inrun::new(&CgOptions::for_case(&case), &e.state().domain, sampling)
            .unwrap()
            .with_reference_tau(case.dt());
        if via_run {
            let dir = tempfile::tempdir().unwrap();
            let opts = options(dir.path(), sampling.to, 4800, false);
            run::run_observed(e.as_mut(), &opts, false, Some(&mut acc)).unwrap();
        } else {
            e.advance(0).unwrap();
            verdem::peers::inrun::advance_observed(e.as_mut(), sampling.to, &mut acc).unwrap();
        }
        let r = acc.result().expect("samples");
        assert_eq!(
            r.contact_samples,
            (sampling.to - sampling.from) / sampling.every
        );
        [
            verdem::analysis::inrun::csv(&r),
            verdem::analysis::inrun::errors_csv(&r),
        ]
    };
    assert_eq!(outputs(true), outputs(false));
}

/// The checks that judge by the contact stress's per-slice errors judge them at a calibrated
/// sampling and only report them at another (the particle fields' checks stand at both).
#[test]
fn checks_by_errors_not_calibrated_at_the_sampling_are_reported_only() {
    let (case, _) = steady();
    let verdicts = |particle_every: u64| {
        let (_, mut e) = steady();
        let s = Sampling {
            every: 25,
            particle_every,
            from: 6000,
            to: 30000,
        };
        let mut acc = Inrun::new(&CgOptions::for_case(&case), &e.state().domain, s)
            .unwrap()
            .with_reference_tau(case.dt());
        let dir = tempfile::tempdir().unwrap();
        let opts = options(dir.path(), s.to, 6000, false);
        run::run_observed(e.as_mut(), &opts, false, Some(&mut acc)).unwrap();
        let r = acc.result().expect("samples");
        cg::checks::run(&r.profiles, r.density)
    };
    let find = |v: &[cg::checks::Check], q: &str| {
        v.iter()
            .find(|c| c.quantity.starts_with(q))
            .unwrap_or_else(|| panic!("no check {q}"))
            .clone()
    };
    let (calibrated, other) = (verdicts(1200), verdicts(1000));
    for q in [
        "shear stress uniform",
        "sigma_zz uniform",
        "symmetric pressure",
    ] {
        let (a, b) = (find(&calibrated, q), find(&other, q));
        assert_ne!(
            a.outcome,
            Outcome::Reported,
            "{q} at the calibrated sampling"
        );
        assert_eq!(b.outcome, Outcome::Reported, "{q} at another sampling");
        assert!(
            b.expected_text.contains("not calibrated"),
            "{}",
            b.expected_text
        );
    }
    let nu = find(&other, "symmetric nu");
    assert_ne!(nu.outcome, Outcome::Reported);
}

/// The run's profiles picture overlays its in-run profiles on the saves' (drawn again from the
/// two tables it wrote, to the byte), and `compare --plot --inrun` overlays each table's in-run
/// table beside it; a table without one is named.
#[test]
fn the_run_s_picture_and_compare_s_overlay_show_the_in_run_profiles() {
    use verdem::analysis::cg::{plot, table::Table};
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a");
    common::verdem_ok([
        "run",
        "cases/shear_flow_steady.toml",
        "--steps",
        "40000",
        "--save-every",
        "4000",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let base = |ext: &str| out.join(format!("shear_flow_steady.{ext}"));
    let saves = Table::read(&base("profiles.csv")).unwrap();
    let inrun = Table::read(&base("profiles_inrun.csv")).unwrap();
    let redrawn = dir.path().join("redrawn.png");
    plot::run_png(&saves, &inrun, &redrawn).unwrap();
    let shown = std::fs::read(base("profiles.png")).unwrap();
    assert!(
        shown == std::fs::read(&redrawn).unwrap(),
        "the run drew other profiles"
    );
    let alone = dir.path().join("alone.png");
    plot::overlay_png(&[(plot::SAVES_LABEL, &saves)], &alone).unwrap();
    assert!(
        shown != std::fs::read(&alone).unwrap(),
        "no in-run profiles in the picture"
    );

    let overlay = dir.path().join("overlay.png");
    let profiles = base("profiles.csv");
    let p = profiles.to_str().unwrap();
    let args = ["compare", p, p, "--labels", "x,y", "--inrun", "--plot"];
    common::verdem_ok(args.iter().copied().chain([overlay.to_str().unwrap()]));
    let want = dir.path().join("want.png");
    let runs = [
        ("x", &saves),
        ("y", &saves),
        ("x (in-run)", &inrun),
        ("y (in-run)", &inrun),
    ];
    plot::overlay_png(&runs, &want).unwrap();
    assert!(std::fs::read(&overlay).unwrap() == std::fs::read(&want).unwrap());

    let lone = dir.path().join("lone.profiles.csv");
    std::fs::copy(&profiles, &lone).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .args(["compare", p, lone.to_str().unwrap(), "--inrun", "--plot"])
        .arg(&overlay)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "--inrun: {} has no in-run table beside it ({} is missing)",
            lone.display(),
            dir.path().join("lone.profiles_inrun.csv").display()
        )),
        "{err}"
    );
}
