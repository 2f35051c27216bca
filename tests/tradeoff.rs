//! The speed/accuracy trade: what each variant changes, on a short run from MercuryDPM's state.

mod common;

#[test]
fn variants_change_what_they_should_and_nothing_else() {
    let case = common::quick_case();
    let pair = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = verdem::tradeoff::run(
        &case,
        &pair,
        &common::shared("states/mercury_t143.85.data"),
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
    let replica = by(verdem::tradeoff::REPLICA);
    assert_eq!(replica.steps, reference.steps);
    assert_eq!(replica.restitution_error, reference.restitution_error);
    assert_ne!(replica.hash, reference.hash);
    assert!(replica.chi2.iter().all(|&c| c > 0.0), "{:?}", replica.chi2);
    let table = verdem::tradeoff::markdown(&out);
    assert_eq!(table.lines().count(), 2 + 10);
}
