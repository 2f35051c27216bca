//! In-run averaging of the real LAMMPS-family peers (`verdem cross … --inrun`; Debian packages
//! `lammps` and `liggghts`, installed by ci/test.sh): their in-run profiles, read from the
//! dumps every K steps (contact forces, positions of the spheres in contact) and every KP steps
//! (all particles), are the coarse-graining of their own saves when the samples fall on the
//! saves' steps; a contact whose sphere the position dump lacks is refused.

mod common;

use verdem::analysis::cg::{self, CgOptions, Series};
use verdem::analysis::inrun::Inrun;
use verdem::case::Case;
use verdem::peers::{self, cross::cross_inrun, Run, Save};

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
        // the wall forces of each bin (one interval of 50 steps) are the line of walls.txt at
        // its last step, not those of the saves' contacts at that step
        let peer_dir = out.join(peer.binary());
        let means = wall_lines(&peer_dir.join("walls.txt"));
        assert_eq!(
            means.iter().map(|m| m.0).collect::<Vec<_>>(),
            (50..=10_000).step_by(50).collect::<Vec<_>>(),
            "{name}: the steps of walls.txt"
        );
        let walls = &inrun.peer.profiles.wall_force;
        assert!(inrun.peer.profiles.wall_force_every_step, "{name}");
        assert_eq!(walls.len(), means.len());
        assert_eq!(saves.wall_force.len(), walls.len());
        for ((_, m), w) in means.iter().zip(walls) {
            for g in 0..2 {
                assert!(
                    (m[g] - w[g]).norm() <= 1e-12 * m[g].norm(),
                    "{name}: walls.txt {m:?}, in-run {w:?}"
                );
            }
        }
        for g in 0..2 {
            assert!(
                walls.iter().any(|w| w[g].x != 0.0),
                "{name}: no force on wall {g}"
            );
            let apart = saves
                .wall_force
                .iter()
                .zip(walls)
                .filter(|(s, w)| (s[g] - w[g]).norm() > 1e-3 * w[g].norm())
                .count();
            assert!(
                apart > 0,
                "{name}: wall {g}'s every-step means are the sampled forces"
            );
        }
        // verdem in the peer's convention follows the peer's trajectory over the first 2000
        // steps (later chaos amplifies their round-off); its wall forces are its engine's
        // impulse per step, so the two codes' every-step means agree there (LAMMPS writes them
        // with 17 digits, LIGGGHTS with its default 6)
        let digits = if name == "lammps" { 1e-9 } else { 1e-5 };
        let own = &inrun.verdem_as_peer.profiles.wall_force;
        assert!(walls[..40].iter().any(|w| w[0].x != 0.0), "{name}");
        for (w, v) in walls[..40].iter().zip(own) {
            for g in 0..2 {
                assert!(
                    (w[g] - v[g]).norm() <= digits * v[g].norm() + 1e-12,
                    "{name}: wall {g}: peer {w:?}, verdem as the peer {v:?}"
                );
            }
        }
        // a walls.txt that lacks the last interval, or has a value that is not a number, is
        // refused, naming the file, the line and the field
        let sampling = peers::inrun::sampling(10_000, 50, 50);
        let template = snapshot(&case, &state);
        let walls_txt = peer_dir.join("walls.txt");
        let text = std::fs::read_to_string(&walls_txt).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let n = lines.len();
        std::fs::write(&walls_txt, lines[..n - 1].join("\n") + "\n").unwrap();
        let profiles = |o: &CgOptions| {
            let run = Run {
                dir: &peer_dir,
                np: 1,
            };
            peers::inrun::peer_profiles(peer, &run, o, &template, sampling, case.dt())
                .map(|_| ())
                .unwrap_err()
                .to_string()
        };
        let e = profiles(&o);
        assert!(
            e.contains("walls.txt")
                && e.contains(&format!(
                    "line {}: column 1 (step): the last step 9950",
                    n - 1
                ))
                && e.contains("needs 200"),
            "{name}: {e}"
        );
        let mut broken = lines.clone();
        let line = broken[5].replacen(' ', " 1.5.7 ", 1);
        broken[5] = &line;
        std::fs::write(&walls_txt, broken.join("\n") + "\n").unwrap();
        let e = profiles(&o);
        assert!(
            e.contains("walls.txt:6: column 2 (bottom fx): not a number"),
            "{name}: {e}"
        );
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
        let run_dir = out.join(peer.binary());
        let run = Run {
            dir: &run_dir,
            np: 1,
        };
        let e = peer
            .read_sample(&run, Save::every(50, 8), &snapshot(&case, &state), false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("positions.400.txt") && e.contains("missing"),
            "{name}: {e}"
        );
    }
}

/// Contacts sampled every step (K = 1) over 300 steps, in which the bottom wall is hit from step
/// ~270: `fix ave/time 1 1 1` also writes the set-up forces at step 0, which lie outside the
/// window and are not booked; every step's force on the walls equals that of verdem in the
/// peer's convention (its engine's impulse per step, same trajectory), and differs from the
/// sampled one, which the peer's contact dump re-evaluates at the end of the step with
/// full-step velocities in the dashpots (the step itself used half-step velocities).
#[test]
fn a_peers_wall_forces_are_every_steps_mean_also_when_every_step_is_sampled() {
    let (case, state) = steady();
    let dir = tempfile::tempdir().unwrap();
    for name in ["lammps", "liggghts"] {
        let peer = peers::by_name(name).unwrap();
        let out = dir.path().join(peer.binary());
        let r = cross_inrun(
            peer,
            &case,
            peer.convention(),
            &state,
            300,
            150,
            1,
            &out,
            Some((1, 150)),
        )
        .unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let inrun = r.inrun.expect("in-run profiles");
        let steps: Vec<u64> = wall_lines(&out.join(peer.binary()).join("walls.txt"))
            .iter()
            .map(|m| m.0)
            .collect();
        assert_eq!(steps, (0..=300).collect::<Vec<_>>(), "{name}");
        let (walls, own) = (
            &inrun.peer.profiles.wall_force,
            &inrun.verdem_as_peer.profiles.wall_force,
        );
        assert_eq!((walls.len(), own.len()), (2, 2), "{name}");
        assert!(walls[1][0].x != 0.0, "{name}: the bottom wall was not hit");
        let digits = if name == "lammps" { 1e-9 } else { 1e-5 };
        for (w, v) in walls.iter().zip(own) {
            for g in 0..2 {
                assert!(
                    (w[g] - v[g]).norm() <= digits * v[g].norm() + 1e-12,
                    "{name}: wall {g}: peer {w:?}, verdem as the peer {v:?}"
                );
            }
        }
        // the same run's forces at the samples (every step), from its contact dumps (the
        // particle dumps are removed once read: the particle fields here are the template's,
        // only the walls are compared)
        let template = snapshot(&case, &state);
        let o = CgOptions::for_case(&case);
        let sampling = peers::inrun::sampling(300, 1, 150);
        let mut sampled = Inrun::new(&o, &template.domain, sampling).unwrap();
        for step in 1..=300 {
            let run_dir = out.join(peer.binary());
            let run = Run {
                dir: &run_dir,
                np: 1,
            };
            let s = peer
                .read_sample(&run, Save::every(1, step), &template, false)
                .unwrap_or_else(|e| panic!("{name}: step {step}: {e:#}"));
            sampled.sample(&s, step % 150 == 0);
        }
        let sampled = sampled.result().unwrap();
        assert!(!sampled.profiles.wall_force_every_step);
        let (a, b) = (sampled.profiles.wall_force[1][0], walls[1][0]);
        assert!(
            (a - b).norm() > 1e-6 * b.norm() && (a - b).norm() < 0.1 * b.norm(),
            "{name}: bottom wall, sampled {a:?}, every step {b:?}"
        );
    }
}

/// The lines of a peer's `walls.txt`, read here on their own: the step and the two walls'
/// forces of each line after the `#` comments.
fn wall_lines(path: &std::path::Path) -> Vec<(u64, [verdem::Vec3; 2])> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            assert_eq!(v.len(), 7, "{}: {l}", path.display());
            let f = |k: usize| verdem::Vec3::new(v[k], v[k + 1], v[k + 2]);
            (v[0] as u64, [f(1), f(4)])
        })
        .collect()
}

/// verdem's state of `case` from `state`, its forces evaluated.
fn snapshot(case: &Case, state: &std::path::Path) -> verdem::state::Snapshot {
    let mut e = common::engine(
        case,
        Some(state),
        verdem::step::engine::Overrides::default(),
    );
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
            verdem::contact::Tangential::of(&case).unwrap(),
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
