//! In-run averaging of the real LAMMPS-family peers (`verdem cross … --inrun`; Debian packages
//! `lammps` and `liggghts`, installed by ci/test.sh): their in-run profiles, read from the
//! dumps every K steps (contact forces, positions of the spheres in contact) and every KP steps
//! (all particles), are the coarse-graining of their own saves when the samples fall on the
//! saves' steps; a contact whose sphere the position dump lacks is refused.

mod common;

use verdem::analysis::cg::{self, CgOptions, Series};
use verdem::case::Case;
use verdem::peers::{self, cross::cross_inrun};

/// The benchmark's case, from the full run's final state.
fn steady() -> (Case, std::path::PathBuf) {
    let case = Case::load(&common::root().join("cases/shear_flow.toml")).unwrap();
    (
        case,
        common::root().join("golden/full_run/shear_flow.final.data"),
    )
}

#[test]
fn a_peers_inrun_profiles_are_the_coarse_graining_of_its_saves_at_the_same_steps() {
    let (case, state) = steady();
    let dir = tempfile::tempdir().unwrap();
    for name in ["lammps", "liggghts"] {
        let peer = peers::by_name(name).unwrap();
        let out = dir.path().join(peer.binary());
        // a save, a contact sample and a particle sample every 50 steps: in-run samples at
        // steps 50..=10000 are the saves 1..=200 (a wall has a contact in ~1 sample of 23, each
        // lasting about one interval: ~9 contacts expected on each wall)
        let r = cross_inrun(
            peer,
            &case,
            peer.convention(),
            &state,
            10_000,
            50,
            1,
            &out,
            Some((50, 50)),
        )
        .unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let inrun = r.inrun.expect("in-run profiles");
        assert_eq!(inrun.peer.contact_samples, 200);
        assert_eq!(inrun.peer.particle_samples, 200);
        let o = CgOptions {
            from: Some(1),
            ..CgOptions::for_case(&case)
        };
        let series = Series::find(&out.join(peer.binary()).join(&case.name)).unwrap();
        let saves = cg::coarse_grain(&series, &o).unwrap();
        let contacts = common::assert_columns_agree(
            &saves.mean,
            &inrun.peer.profiles.mean,
            1e-9,
            (&format!("{name} saves"), "in-run"),
        );
        // the peer's contacts were there to be compared
        assert!(contacts > 0.0, "{name}: no contact stress");
        // the wall forces of each sample are those of the saves' contacts
        assert_eq!(saves.wall_force.len(), inrun.peer.profiles.wall_force.len());
        for (s, w) in saves.wall_force.iter().zip(&inrun.peer.profiles.wall_force) {
            for g in 0..2 {
                assert!(
                    (s[g] - w[g]).norm() <= 1e-9 * s[g].norm().max(1.0),
                    "{name}: saves {s:?}, in-run {w:?}"
                );
            }
        }
        for g in 0..2 {
            assert!(
                inrun.peer.profiles.wall_force.iter().any(|w| w[g].x != 0.0),
                "{name}: no force on wall {g}"
            );
        }
        // the particle dumps are removed once read, the files of the table are written
        assert!(!out.join(peer.binary()).join("particles.50.txt").exists());
        for csv in [peer.binary(), "verdem", "verdem_own"] {
            assert!(out.join(format!("{csv}.profiles_inrun.csv")).exists());
        }
        // a contact whose sphere is missing from the position dump is refused, by file
        let positions = out.join(peer.binary()).join("positions.400.txt");
        let text = std::fs::read_to_string(&positions).unwrap();
        let mut lines: Vec<&str> = text.lines().collect();
        let n: usize = lines[3].trim().parse().unwrap();
        assert!(n > 0, "{name}: no sphere in contact at step 400");
        lines.remove(9);
        let count = (n - 1).to_string();
        lines[3] = &count;
        std::fs::write(&positions, lines.join("\n") + "\n").unwrap();
        let e = peer
            .read_sample(
                &out.join(peer.binary()),
                400,
                &snapshot(&case, &state),
                false,
            )
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("positions.400.txt") && e.contains("missing"),
            "{name}: {e}"
        );
    }
}

/// verdem's state of `case` from `state`, its forces evaluated.
fn snapshot(case: &Case, state: &std::path::Path) -> verdem::state::Snapshot {
    let mut e = common::engine(case, Some(state), verdem::engine::Overrides::default());
    e.advance(0).unwrap();
    e.snapshot()
}

#[test]
fn a_peer_without_inrun_dumps_and_intervals_that_do_not_divide_are_refused() {
    let (case, state) = steady();
    let dir = tempfile::tempdir().unwrap();
    let run = |peer: &str, inrun| {
        cross_inrun(
            peers::by_name(peer).unwrap(),
            &case,
            case.contact.tangential,
            &state,
            2000,
            200,
            1,
            &dir.path().join(peer),
            Some(inrun),
        )
        .unwrap_err()
        .to_string()
    };
    let e = run("kratos", (200, 200));
    assert!(e.contains("kratos has no in-run dumps"), "{e}");
    let e = run("lammps", (300, 600));
    assert!(e.contains("must be at least 1 and divide"), "{e}");
}
