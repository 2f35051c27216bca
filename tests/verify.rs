//! Binary normal collisions against the closed forms of the linear spring–dashpot.

mod common;

use verdem::contact::Tangential;

#[test]
fn binary_collisions_match_the_closed_forms_at_the_benchmark_time_step() {
    let case = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let rows = verdem::verify::binary_collisions(&case).unwrap();
    let at_dt: Vec<_> = rows
        .iter()
        .filter(|r| r.case.contains("dt=tc/50"))
        .collect();
    assert_eq!(
        at_dt.len(),
        32,
        "2 partners x 4 speeds x 4 quantities (one clipped)"
    );
    for r in at_dt {
        assert!(r.passed(), "{r:?}");
    }
    // the restitution error converges at first order in dt (dashpot on half-step velocities)
    let orders: Vec<_> = rows
        .iter()
        .filter(|r| r.quantity.starts_with("order"))
        .collect();
    assert_eq!(orders.len(), 2);
    for r in orders {
        assert!(r.passed(), "{r:?}");
    }
}

/// A wrong effective mass (the classic LAMMPS pitfall: damping scaled by m_eff) would move e
/// far outside the tolerance: the check can fail.
#[test]
fn a_wrong_damping_is_detected() {
    let mut case =
        verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
            .unwrap();
    let reference = verdem::verify::closed_form(&case, 0.5 * case.particle_mass()).e;
    case.contact.gamman *= 0.5 * case.particle_mass();
    let got = verdem::verify::collide(&case, 1.0, false, 50.0).unwrap();
    assert!(
        ((got.e - reference) / reference).abs() > 2e-3,
        "e = {} vs {reference}",
        got.e
    );
}

/// The convention a verification row is about: the word of its case that names one.
fn convention_of(r: &verdem::verify::Row) -> Tangential {
    r.case
        .split_whitespace()
        .find_map(Tangential::named)
        .unwrap_or_else(|| panic!("no convention named in {r:?}"))
}

fn load(name: &str) -> verdem::case::Case {
    verdem::case::Case::load(&common::root().join("cases/verify").join(name)).unwrap()
}

#[test]
fn every_gating_row_of_the_verification_table_passes() {
    let rows = verdem::verify::all(&common::root().join("cases/verify")).unwrap();
    let failed: Vec<_> = rows.iter().filter(|r| r.gate && !r.passed()).collect();
    assert!(failed.is_empty(), "{failed:#?}");
    // oblique impacts: 7 conventions, all sticking and sliding answers present
    let oblique = rows
        .iter()
        .filter(|r| r.case.starts_with("oblique"))
        .count();
    assert_eq!(
        oblique,
        Tangential::with_constant_kt().count() * (5 + 3 * 2 + 2)
    );
}

#[test]
fn only_the_objective_laws_are_objective_and_the_peers_show_their_known_defects() {
    let rows = verdem::verify::objectivity::rows(&load("objectivity.toml")).unwrap();
    let of = |conv: Tangential| {
        rows.iter()
            .filter(move |r| r.case.split_whitespace().nth(1) == Some(conv.name()))
    };
    for conv in Tangential::with_constant_kt() {
        if conv.properties().objective {
            assert!(of(conv).all(|r| r.passed() && r.gate), "{}", conv.name());
        } else {
            assert!(
                of(conv).any(|r| !r.passed()),
                "{} passed everything",
                conv.name()
            );
        }
    }
    // MercuryDPM's rate form has no twist: about the normal its force stays put in the lab
    // while the pair turns, a direction error of exactly the angle turned.
    let mercury_twist = of(Tangential::Mercury)
        .find(|r| r.case.ends_with("normal axis") && r.quantity.starts_with("Ft direction"))
        .unwrap();
    assert!(
        (mercury_twist.measured - 1.0).abs() < 1e-6,
        "{mercury_twist:?}"
    );
    // Yade's first-order rotation drifts by about half the step's turn per radian (1e-5/2).
    let yade = of(Tangential::Yade)
        .find(|r| r.case.ends_with("normal axis") && r.quantity.starts_with("|Ft|"))
        .unwrap();
    assert!((yade.measured - 5e-6).abs() < 1e-7, "{yade:?}");
}

#[test]
fn a_closed_cycle_returns_the_objective_laws_to_zero_force_and_ratchets_the_others() {
    let rows = verdem::verify::ratchet::rows(&load("objectivity.toml")).unwrap();
    for r in &rows {
        let properties = convention_of(r).properties();
        assert!(!properties.objective || r.passed(), "{r:?}");
        if r.quantity.starts_with("residual") && r.case.contains("about n") {
            // a spring that twists with the pair keeps the residual at round-off or at the
            // first-order error of Yade's update; the others are left turned by ~ a
            let twists = properties.twists_spring;
            assert_eq!(twists, r.measured < 1e-5, "{r:?}");
            assert_eq!(!twists, r.measured > 1e-2, "{r:?}");
        }
    }
}

#[test]
fn the_kinematics_command_writes_the_forces_of_the_driver() {
    use verdem::verify::kinematics::{drive, forces_csv, law_of, motion_csv, Increment};
    let case = load("objectivity.toml");
    let (x, radius) = verdem::verify::kinematics::pair_of(&case).unwrap();
    let mut rows = vec![verdem::verify::kinematics::MotionRow {
        t: 0.0,
        x,
        q: [nalgebra::UnitQuaternion::identity(); 2],
        v: [verdem::Vec3::zeros(); 2],
        w: [verdem::Vec3::zeros(); 2],
    }];
    verdem::verify::objectivity::spin_sphere_2(
        &mut rows,
        verdem::Vec3::y(),
        1e-3,
        50,
        5,
        case.dt(),
    );
    let dir = tempfile::tempdir().unwrap();
    let (motion, forces) = (dir.path().join("MOTION.csv"), dir.path().join("FORCES.csv"));
    std::fs::write(&motion, motion_csv(&rows)).unwrap();
    common::verdem_ok([
        "kinematics".as_ref(),
        common::root()
            .join("cases/verify/objectivity.toml")
            .as_os_str(),
        motion.as_os_str(),
        "--out".as_ref(),
        forces.as_os_str(),
    ]);
    // the command reads the motion back (quaternions normalised) and drives the same law
    let read = verdem::verify::kinematics::parse_motion("m", &motion_csv(&rows)).unwrap();
    let expected = forces_csv(&drive(
        law_of(&case).unwrap().as_ref(),
        radius,
        &read,
        Increment::Positions,
    ));
    assert_eq!(std::fs::read_to_string(&forces).unwrap(), expected);
    // the spun sphere carries a tangential force opposing its contact point's slip
    let last = expected.lines().last().unwrap();
    let ft: f64 = last.rsplit(',').next().unwrap().parse().unwrap();
    assert!(ft > 0.0);

    // a shear case is not a two-sphere contact: a clear error, no panic
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("kinematics")
        .arg(common::root().join("cases/shear_flow_quick.toml"))
        .arg(&motion)
        .arg("--out")
        .arg(&forces)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("shear_flow_quick.toml: scene"),
        "{err}"
    );
}

/// `verdem kinematics CASE MOTION --out FORCES`: its exit success, stdout and stderr.
fn kinematics_cmd(
    case: &std::path::Path,
    motion: &std::path::Path,
    forces: &std::path::Path,
) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("kinematics")
        .arg(case)
        .arg(motion)
        .arg("--out")
        .arg(forces)
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), text(&out.stdout), text(&out.stderr))
}

/// A prescribed motion integrates nothing: `kinematics` refuses a law that is not physical, as
/// `run` does, but not a time step beyond the scheme's stability limit, and warns about rows
/// coarse for the law's collision time while the spheres touch, writing the forces still.
#[test]
fn the_kinematics_command_checks_the_law_not_the_time_step_and_warns_about_coarse_rows() {
    use verdem::verify::kinematics::{
        drive, forces_csv, law_of, motion_csv, parse_motion, Increment,
    };
    let dir = tempfile::tempdir().unwrap();
    let template =
        std::fs::read_to_string(common::root().join("cases/verify/objectivity.toml")).unwrap();
    let kt_line = template
        .lines()
        .position(|l| l.starts_with("kt = "))
        .unwrap()
        + 1;
    let case_with_kt = |kt: &str| {
        let path = dir.path().join("c.toml");
        let text: Vec<String> = template
            .lines()
            .map(|l| {
                if l.starts_with("kt = ") {
                    format!("kt = {kt}")
                } else {
                    l.to_string()
                }
            })
            .collect();
        std::fs::write(&path, text.join("\n")).unwrap();
        path
    };
    // kt = 1000 kn: the tangential spring at tc/50 is beyond the scheme's limit
    let stiff = case_with_kt("2e8");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("run")
        .arg(&stiff)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && err.contains(
                "c.toml:11: run.steps_per_collision: at most the stability limit of the \
                 free–free tangential contact"
            ),
        "{err}"
    );

    let case = verdem::case::Case::load_for_prescribed_motion(&stiff).unwrap();
    let tc = verdem::verify::kinematics::collision_time(&case).unwrap();
    let (x, radius) = verdem::verify::kinematics::pair_of(&case).unwrap();
    let start = verdem::verify::kinematics::MotionRow {
        t: 0.0,
        x,
        q: [nalgebra::UnitQuaternion::identity(); 2],
        v: [verdem::Vec3::zeros(); 2],
        w: [verdem::Vec3::zeros(); 2],
    };
    let spin = verdem::verify::objectivity::spin_sphere_2;
    let (motion, forces) = (dir.path().join("m.csv"), dir.path().join("f.csv"));
    let expected = |rows: &[verdem::verify::kinematics::MotionRow]| {
        let read = parse_motion("m", &motion_csv(rows)).unwrap();
        forces_csv(&drive(
            law_of(&case).unwrap().as_ref(),
            radius,
            &read,
            Increment::Positions,
        ))
    };

    // fine rows while the spheres touch, then rows a collision time apart once they have parted:
    // no warning
    let mut rows = vec![start];
    spin(&mut rows, verdem::Vec3::y(), 1e-3, 50, 5, case.dt());
    for _ in 0..2 {
        let mut apart = *rows.last().unwrap();
        apart.t += tc;
        apart.x[1].z += 1.0;
        rows.push(apart);
    }
    std::fs::write(&motion, motion_csv(&rows)).unwrap();
    let (ok, stdout, stderr) = kinematics_cmd(&stiff, &motion, &forces);
    assert!(ok && stderr.is_empty(), "{stderr}");
    assert!(stdout.starts_with(&format!("{} rows of objectivity", rows.len())));
    assert_eq!(std::fs::read_to_string(&forces).unwrap(), expected(&rows));

    // rows 2^-11 apart in contact (about tc/7, every time and step exact): a warning naming the
    // first such row's line, and the forces
    let coarse = 2f64.powi(-11);
    let mut rows = vec![start];
    spin(&mut rows, verdem::Vec3::y(), 1e-3, 8, 2, coarse);
    std::fs::write(&motion, motion_csv(&rows)).unwrap();
    std::fs::remove_file(&forces).unwrap();
    let (ok, _, stderr) = kinematics_cmd(&stiff, &motion, &forces);
    assert!(ok, "{stderr}");
    let warning = format!(
        "warning: {}:3: rows up to Δt = {coarse:.4e} apart while the spheres touch, coarse for \
         the collision time of the law of {}, tc = {tc:.4e} (tc/Δt = {:.3}, below 10): the \
         forces are the law's at these rows, not an integration's",
        motion.display(),
        stiff.display(),
        tc / coarse
    );
    assert!(tc / coarse < 10.0);
    assert!(stderr.starts_with(&warning), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert_eq!(std::fs::read_to_string(&forces).unwrap(), expected(&rows));

    // a law that is not physical is refused, naming file, line and field; no forces written
    for (kt, msg) in [
        ("-5.0", "contact.kt: must be >= 0, got -5"),
        ("nan", "contact.kt: a finite number expected, got NaN"),
    ] {
        let bad = case_with_kt(kt);
        let _ = std::fs::remove_file(&forces);
        let (ok, _, stderr) = kinematics_cmd(&bad, &motion, &forces);
        let at = format!("{}:{kt_line}: {msg}", bad.display());
        assert!(!ok && stderr.contains(&at), "{kt}: {stderr}");
        assert!(!forces.exists());
    }
}

#[test]
fn the_gas_conserves_momentum_and_the_cluster_angular_momentum_unless_levers_are_full_radii() {
    let rows = verdem::verify::conservation::rows(&load("conservation.toml"), 100_000).unwrap();
    for r in &rows {
        if r.case.contains("cluster") {
            let full_radius = !convention_of(r).properties().conserves_angular_momentum;
            // full-radius lever arms leave δ n × Ft per contact: far above round-off
            assert_eq!(full_radius, r.measured > 1e-8, "{r:?}");
        }
        assert!(r.passed() || !r.gate, "{r:?}");
    }
    assert_eq!(rows.len(), 4 + Tangential::with_constant_kt().count());
}

/// A motion refined by the driver (`kinematics::refine`) is the motion the verification would
/// have written at the finer step: a rigid rotation of the pair, a spin in place and a straight
/// move, at 4 rows per row, match the same legs built with 4 times the steps at dt/4.
#[test]
fn a_refined_motion_is_the_same_motion_at_a_finer_step() {
    use verdem::verify::kinematics::{refine, MotionRow};
    use verdem::verify::objectivity::{rigid_rotation, spin_sphere_2};
    use verdem::Vec3;
    let start = MotionRow {
        t: 0.0,
        x: [Vec3::new(0.1, -0.2, 0.0), Vec3::new(0.1, -0.2, 0.999)],
        q: [nalgebra::UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    };
    let legs = |fine: usize| {
        let dt = 1e-3 / fine as f64;
        let mut rows = vec![start];
        spin_sphere_2(&mut rows, Vec3::x(), 0.01, 10 * fine, 2 * fine, dt);
        rigid_rotation(&mut rows, Vec3::new(1.0, 1.0, 1.0), 0.5, 20 * fine, dt);
        rigid_rotation(&mut rows, Vec3::z(), -0.3, 10 * fine, dt);
        rows
    };
    let (coarse, fine) = (legs(1), legs(4));
    let refined = refine(&coarse, 4);
    assert_eq!(refined.len(), fine.len());
    for (k, (r, f)) in refined.iter().zip(&fine).enumerate() {
        assert!((r.t - f.t).abs() < 1e-15, "row {k}: {r:?} {f:?}");
        for s in 0..2 {
            assert!((r.x[s] - f.x[s]).norm() < 1e-14, "row {k}: {r:?} {f:?}");
            assert!(r.q[s].angle_to(&f.q[s]) < 1e-14, "row {k}: {r:?} {f:?}");
            assert!((r.v[s] - f.v[s]).norm() < 1e-11, "row {k}: {r:?} {f:?}");
            assert!((r.w[s] - f.w[s]).norm() < 1e-11, "row {k}: {r:?} {f:?}");
        }
    }
    // the motion's own rows are kept bit for bit
    for (k, c) in coarse.iter().enumerate() {
        assert_eq!(refined[4 * k], *c);
    }
}
