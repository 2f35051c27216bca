//! Binary normal collisions against the closed forms of the linear spring–dashpot.

mod common;

#[test]
fn binary_collisions_match_the_closed_forms_at_the_benchmark_time_step() {
    let case = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let rows = verdem::verify::binary_collisions(&case).unwrap();
    let at_dt: Vec<_> = rows
        .iter()
        .filter(|r| r.case.contains("dt=tc/50"))
        .collect();
    assert_eq!(at_dt.len(), 24, "2 partners x 4 speeds x 3 quantities");
    for r in at_dt {
        assert!(r.pass, "{r:?}");
    }
    // the restitution error converges at first order in dt (dashpot on half-step velocities)
    let orders: Vec<_> = rows
        .iter()
        .filter(|r| r.quantity.starts_with("order"))
        .collect();
    assert_eq!(orders.len(), 2);
    for r in orders {
        assert!(r.pass, "{r:?}");
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
