//! Binary normal collisions against the closed forms of the linear spring–dashpot.

mod common;

use verdem::case::Tangential;

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
    assert_eq!(oblique, Tangential::ALL.len() * (5 + 3 * 2 + 2));
}

#[test]
fn only_the_objective_laws_are_objective_and_the_peers_show_their_known_defects() {
    let rows = verdem::verify::objectivity::rows(&load("objectivity.toml")).unwrap();
    let of = |conv: Tangential| {
        rows.iter()
            .filter(move |r| r.case.split_whitespace().nth(1) == Some(conv.name()))
    };
    for conv in Tangential::ALL {
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
    use verdem::kinematics::{drive, forces_csv, law_of, motion_csv, Increment};
    let case = load("objectivity.toml");
    let (x, radius) = verdem::kinematics::pair_of(&case).unwrap();
    let mut rows = vec![verdem::kinematics::MotionRow {
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
    let read = verdem::kinematics::parse_motion("m", &motion_csv(&rows)).unwrap();
    let expected = forces_csv(&drive(
        law_of(&case).as_ref(),
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
    assert_eq!(rows.len(), 4 + Tangential::ALL.len());
}
