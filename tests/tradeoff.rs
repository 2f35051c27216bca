//! The speed/accuracy trade: what each variant changes, on a short run from MercuryDPM's state.

mod common;

#[test]
fn variants_change_what_they_should_and_nothing_else() {
    let case = common::quick_case();
    let pair = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = verdem::analysis::tradeoff::run(
        &case,
        &pair,
        &common::data("states/mercury_t143.85.data"),
        0.2,
        4,
        dir.path(),
    )
    .unwrap();
    let by = |name: &str| out.iter().find(|o| o.name == name).unwrap();
    let reference = by("reference");
    // skin and thread count change no bit (deterministic mode)
    for name in ["skin=0.05", "skin=0.2", "1 thread"] {
        assert_eq!(by(name).hash, reference.hash, "{name}");
        assert_eq!(by(name).chi2, [0.0; 5], "{name}");
    }
    // a finer dt changes the trajectory and shrinks the restitution error
    let errors: Vec<f64> = ["dt=tc/25", "reference", "dt=tc/100", "dt=tc/200"]
        .iter()
        .map(|n| by(n).restitution_error.abs())
        .collect();
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
    assert_ne!(by("dt=tc/100").hash, reference.hash);
    // softer contacts keep e and tc/dt: the same restitution error, fewer steps per time unit
    for name in ["kn/10", "kn/100"] {
        let o = by(name);
        assert!(
            (o.restitution_error - reference.restitution_error).abs() < 1e-9,
            "{name}: {} vs {}",
            o.restitution_error,
            reference.restitution_error
        );
        assert!(o.steps < reference.steps, "{name}");
    }
    // the replica repeats the reference's physics over the next stretch: same law and cost,
    // other bits, and a χ² that measures the noise floor
    let replica = by(verdem::analysis::tradeoff::REPLICA);
    assert_eq!(replica.steps, reference.steps);
    assert_eq!(replica.restitution_error, reference.restitution_error);
    assert_ne!(replica.hash, reference.hash);
    assert!(replica.chi2.iter().all(|&c| c > 0.0), "{:?}", replica.chi2);
    let table = verdem::analysis::tradeoff::markdown(&out);
    assert_eq!(table.lines().count(), 2 + 10);
}

/// The recorded trade over 300 time units (golden/tradeoff, see its provenance.toml): its
/// compare.md is what `verdem compare` gives on the stored profiles, and what docs/performance.md says of
/// it holds. The floor is the largest χ² of the same-physics runs (the replica and the finer
/// time steps) in each profile.
#[test]
fn the_recorded_trade_over_300_time_units_says_what_the_readme_says() {
    use verdem::analysis::cg::table::Table;
    let dir = common::root().join("golden/tradeoff");
    let names = [
        "reference",
        "replica",
        "dt_tc_25",
        "dt_tc_100",
        "dt_tc_200",
        "kn_10",
        "kn_100",
    ];
    let tables: Vec<(String, Table)> = names
        .iter()
        .map(|n| {
            let t = Table::read(&dir.join(format!("{n}.profiles.csv"))).unwrap();
            (n.to_string(), t)
        })
        .collect();
    let rows = verdem::analysis::cg::compare::compare(&tables[0].1, &tables[1..]).unwrap();
    assert_eq!(
        verdem::analysis::cg::compare::markdown("reference", &rows),
        std::fs::read_to_string(dir.join("compare.md")).unwrap()
    );
    let chi2 = |name: &str| rows.iter().find(|r| r.name == name).unwrap().chi2;
    let floor: Vec<f64> = (0..5)
        .map(|f| {
            ["replica", "dt_tc_100", "dt_tc_200"]
                .iter()
                .map(|n| chi2(n)[f])
                .fold(0.0, f64::max)
        })
        .collect();
    let [vx, nu, t, p, tau] = [0, 1, 2, 3, 4];
    let above = |name: &str, f: usize| chi2(name)[f] > floor[f];
    // dt = tc/25: within the floor in vx, T, p and τ, just above it in ν
    assert!(
        [vx, t, p, tau].iter().all(|&f| !above("dt_tc_25", f)),
        "{floor:?}"
    );
    // kn/10: within it in vx and τ, at it in p (within 10 %), above it in ν and T
    assert!(!above("kn_10", vx) && !above("kn_10", tau) && chi2("kn_10")[p] < 1.1 * floor[p]);
    assert!(above("kn_10", t));
    // kn/100: within it in vx, T and p, above it in ν and τ
    assert!([vx, t, p].iter().all(|&f| !above("kn_100", f)));
    assert!(above("kn_100", tau));
    // the ν profile's χ² is above the floor for every variant that changes the contact
    // dynamics, rising as they change more
    let nu_chi2: Vec<f64> = ["dt_tc_25", "kn_10", "kn_100"]
        .iter()
        .map(|n| chi2(n)[nu])
        .collect();
    assert!(
        nu_chi2[0] > floor[nu] && nu_chi2.windows(2).all(|w| w[0] < w[1]),
        "{nu_chi2:?}"
    );
}
