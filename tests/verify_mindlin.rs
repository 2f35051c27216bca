//! The Mindlin rows: the reference law follows the Mindlin–Deresiewicz loop to second order in
//! the increment, the rows tell the no-slip treatments apart as their sources say, and they fail
//! a law that departs.

use verdem::contact::Tangential;
use verdem::verify::mindlin::Pair;
use verdem::verify::{mindlin_histories, mindlin_loop};

/// The reference law's branch errors fall as the square of the increment, and at the rows'
/// increments they are inside the rows' tolerances.
#[test]
fn the_reference_law_follows_the_loop_to_second_order() {
    let pair = Pair::aluminium(0.01);
    let coarse = mindlin_loop::measure(Tangential::MindlinDeresiewicz, &pair, 250);
    let fine = mindlin_loop::measure(Tangential::MindlinDeresiewicz, &pair, 500);
    for (c, f) in coarse.branches.iter().zip(fine.branches) {
        assert!(c / f > 3.5 && c / f < 4.5, "{coarse:?} {fine:?}");
    }
    for (c, f) in coarse.cycles.iter().zip(fine.cycles) {
        assert!(
            (c - 1.0).abs() / (f - 1.0).abs() > 3.5,
            "{coarse:?} {fine:?}"
        );
    }
    let rows = mindlin_loop::convention_rows(Tangential::MindlinDeresiewicz);
    assert_eq!(rows.len(), 15);
    assert!(rows.iter().all(|r| r.gate && r.passed()), "{rows:#?}");
}

/// A no-slip spring is not the partial-slip loop: its rows are reported, and their numbers
/// are beyond the tolerances the reference law meets (the rows can tell them apart).
#[test]
fn the_no_slip_variants_are_shown_departing_from_the_loop() {
    for conv in Tangential::with_mindlin_stiffness().filter(|c| !c.properties().partial_slip) {
        let rows = mindlin_loop::convention_rows(conv);
        assert!(
            rows.iter().all(|r| !r.gate && r.pass().is_none()),
            "{rows:#?}"
        );
        let m = mindlin_loop::measure(conv, &Pair::aluminium(0.01), mindlin_loop::STEPS);
        assert!(m.branches[0] > 1e-3, "{}: {m:?}", conv.name());
        assert!((m.cycles[0] - 1.0).abs() > 0.5, "{}: {m:?}", conv.name());
    }
}

/// With the tangential displacement held, a doubled overlap multiplies a stored
/// displacement's force by √2 and leaves a stored force; coming back (the second number is
/// the force over a/a_prev times the force at the doubled overlap), a stored displacement's
/// force follows a, a stored force stays, a rescaled force follows a/a_prev and a rescaled
/// displacement (a/a_prev)².
#[test]
fn the_held_history_tells_the_stores_apart() {
    let ratio = |conv: Tangential| {
        let rows = mindlin_histories::history_rows(conv, "held");
        (rows[0].measured, rows[1].measured)
    };
    let root2 = 2f64.sqrt();
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    let (up, down) = ratio(Tangential::MindlinLammps);
    assert!(close(up, root2) && close(down, 1.0), "{up} {down}");
    let (up, down) = ratio(Tangential::MindlinForce);
    assert!(close(up, 1.0) && close(down, root2), "{up} {down}");
    let (up, down) = ratio(Tangential::MindlinRescale);
    assert!(close(up, root2) && close(down, 1.0 / root2), "{up} {down}");
    let (up, down) = ratio(Tangential::MindlinKratos);
    assert!(close(up, 1.0) && close(down, 1.0), "{up} {down}");
    let (up, down) = ratio(Tangential::MindlinDeresiewicz);
    assert!(close(up, 1.0) && close(down, 1.0), "{up} {down}");
}

/// Over closed cycles of normal and tangential load the reference law never gives out more
/// work than it took; a stored displacement creates energy when the overlap grows while it is
/// held, an unscaled stored force when the overlap shrinks (LAMMPS PR #2196's defect), and the
/// rows say so (FAIL*) without gating.
#[test]
fn no_cycle_creates_energy_in_the_reference_law_and_the_rows_catch_those_that_do() {
    let work = |conv: Tangential| {
        let rows = mindlin_histories::history_rows(conv, "work");
        (rows[0].clone(), rows[2].clone())
    };
    let (up, down) = work(Tangential::MindlinDeresiewicz);
    assert!(
        up.gate && up.passed() && down.gate && down.passed(),
        "{up:?} {down:?}"
    );
    let (up, down) = work(Tangential::MindlinLammps);
    assert!(up.measured < -0.1 && !up.passed() && !up.gate, "{up:?}");
    assert!(down.passed(), "{down:?}");
    let (up, down) = work(Tangential::MindlinForce);
    assert!(up.passed(), "{up:?}");
    assert!(
        down.measured < -0.1 && !down.passed() && !down.gate,
        "{down:?}"
    );
    let (up, down) = work(Tangential::MindlinKratos);
    assert!(up.passed() && down.passed(), "{up:?} {down:?}");
}

/// A loaded contact turned rigidly keeps its force and turns it with the pair in the reference
/// law, on every axis; a full-radius slip (LAMMPS) is left off by δ·Ω relative to the pair.
#[test]
fn the_reference_law_is_objective_under_rigid_rotations() {
    let rows = mindlin_histories::history_rows(Tangential::MindlinDeresiewicz, "rotation");
    assert_eq!(rows.len(), 6);
    assert!(rows.iter().all(|r| r.gate && r.passed()), "{rows:#?}");
    let lammps = mindlin_histories::history_rows(Tangential::MindlinLammps, "rotation");
    assert!(lammps.iter().any(|r| !r.passed()), "{lammps:#?}");
}

/// Two spheres of radius 0.5 meeting obliquely in a closed box, with the law `law`.
fn oblique_pair<L: verdem::contact::ContactLaw>(law: L) -> verdem::step::Simulation<L> {
    use verdem::state::{Domain, Motion, Particles};
    use verdem::Vec3;
    let domain = Domain::new(
        Vec3::new(-5.0, -5.0, -5.0),
        Vec3::new(5.0, 5.0, 5.0),
        [false; 3],
    );
    let mut p = Particles::default();
    for (z, v) in [(-0.52, 0.5), (0.52, -0.5)] {
        let (x, v) = (Vec3::new(0.0, 0.0, z), Vec3::new(0.4 * v, 0.0, v));
        p.push(x, v, Vec3::zeros(), 0.5, 1.0, Motion::Free);
    }
    let builder =
        verdem::step::neighbor::NeighborBuilder::new(0.1, 0.0, 0.5, verdem::case::Search::AllPairs);
    let core = verdem::step::Core::new(domain, p, 1e-3, None, builder, 1);
    verdem::step::Simulation::new(law, core)
}

/// A run of `law` in contact: its history's words are in the snapshot (all `words` of them,
/// a tangential force loaded), in the hash, and a checkpoint resumes it bit for bit.
fn resumes_bit_for_bit<L: verdem::contact::ContactLaw + Clone>(law: L, words: usize) {
    use verdem::step::Engine;
    let mut sim = oblique_pair(law.clone());
    sim.advance(60).unwrap();
    let snap = sim.snapshot();
    assert_eq!(snap.contacts.len(), 1, "the spheres touch after 60 steps");
    let history = snap.contacts[0].history.clone();
    assert_eq!(history.len(), words);
    assert!(history[..3].iter().any(|w| *w != 0.0), "{history:?}");
    let mut other = snap.clone();
    other.contacts[0].history[words - 1] *= 1.0 + 1e-15;
    assert_ne!(
        verdem::io::hash::state_hash(&snap),
        verdem::io::hash::state_hash(&other)
    );
    let dir = tempfile::tempdir().unwrap();
    let ck = dir.path().join("mindlin.checkpoint");
    verdem::io::checkpoint::write(&ck, &snap, 1e-3, "mindlin:1").unwrap();
    let mut resumed = oblique_pair(law);
    resumed.advance(0).unwrap();
    verdem::io::checkpoint::read(&ck, &mut resumed, "mindlin:1").unwrap();
    assert_eq!(resumed.snapshot().contacts[0].history, history);
    sim.advance(5).unwrap();
    resumed.advance(5).unwrap();
    assert_eq!(
        verdem::io::hash::state_hash(&sim.snapshot()),
        verdem::io::hash::state_hash(&resumed.snapshot())
    );
}

/// The Mindlin histories (a force and the contact radius and stiffness, five words; the
/// Mindlin–Deresiewicz force, turning points, branch and stiffness, eleven) run through the
/// solver, the hash and a checkpoint resume with no change to any of them.
#[test]
fn mindlin_histories_resume_bit_for_bit_from_a_checkpoint() {
    use verdem::contact::tangential::mindlin::deresiewicz::MindlinDeresiewicz;
    use verdem::contact::tangential::mindlin::kratos::KratosHertzMindlin;
    use verdem::contact::{Composed, LinearSpringDashpot};
    let normal = LinearSpringDashpot {
        kn: 1e3,
        gamman: 0.0,
    };
    let g_star = 800.0;
    resumes_bit_for_bit(
        Composed {
            normal,
            tangential: MindlinDeresiewicz::new(g_star, 0.0, 0.3),
        },
        11,
    );
    resumes_bit_for_bit(
        Composed {
            normal,
            tangential: KratosHertzMindlin::new(8.0 * g_star, 0.0, 0.3),
        },
        5,
    );
}
