//! The real peers (Debian packages `lammps` and `liggghts`, installed by ci/test.sh) run the
//! inputs verdem generates from the quick case and MercuryDPM's developed state.

mod common;

use verdem::engine::Overrides;
use verdem::peers::{self, Peer};

#[test]
fn lammps_and_liggghts_run_the_generated_inputs() {
    let case = common::quick_case();
    let e = common::engine(
        &case,
        Some(&common::shared("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("state.lmp");
    std::fs::write(&data, peers::data_file(&e.core().snapshot(), 1.0)).unwrap();
    for peer in [Peer::Lammps, Peer::Liggghts] {
        let script = peers::input_script(peer, &case, &data.display().to_string(), 200).unwrap();
        for np in [1, 2] {
            let seconds = peers::run(peer, np, dir.path(), &script)
                .unwrap_or_else(|e| panic!("{peer:?} on {np} rank(s): {e:#}"));
            assert!(
                seconds > 0.0 && seconds.is_finite(),
                "{peer:?}: loop time {seconds}"
            );
        }
    }
}

#[test]
fn data_file_carries_every_particle_with_its_type_and_velocity() {
    let case = common::quick_case();
    let e = common::engine(
        &case,
        Some(&common::shared("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    let snap = e.core().snapshot();
    let text = peers::data_file(&snap, 1.0);
    let atoms: Vec<&str> = text
        .split("Atoms # sphere\n\n")
        .nth(1)
        .unwrap()
        .split("\n\nVelocities")
        .next()
        .unwrap()
        .lines()
        .collect();
    assert_eq!(atoms.len(), 3480);
    let types: Vec<&str> = atoms
        .iter()
        .map(|l| l.split_whitespace().nth(1).unwrap())
        .collect();
    assert!(types[..240].iter().all(|t| *t == "2") && types[240..480].iter().all(|t| *t == "3"));
    assert!(types[480..].iter().all(|t| *t == "1"));
    let x: f64 = atoms[2000]
        .split_whitespace()
        .nth(4)
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(x, snap.particles.x[2000].x);
}
