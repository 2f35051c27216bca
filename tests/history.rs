//! A contact law whose history is more than a tangential spring runs through the solver,
//! snapshots, the state hash and checkpoints without any change to them: here a frictionless
//! spring-dashpot that also counts its contact's age in steps (history: ξ and the age).

use verdem::contact::{ContactLaw, PairKinematics};
use verdem::state::{Domain, History, Motion, PairForce, Particles};
use verdem::step::neighbor::NeighborBuilder;
use verdem::step::{Core, Engine, Simulation};
use verdem::Vec3;

/// ξ (never loaded here) and the number of steps the contact has lasted.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Aged {
    xi: Vec3,
    age: f64,
}

impl History for Aged {
    const WORDS: usize = 4;
    fn put_words(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[self.xi.x, self.xi.y, self.xi.z, self.age]);
    }
    fn from_words(w: &[f64]) -> Self {
        Aged {
            xi: Vec3::new(w[0], w[1], w[2]),
            age: w[3],
        }
    }
    fn spring(&self) -> Vec3 {
        self.xi
    }
}

/// fn = kn·δ − γn·vn along n, and the age grows by one each evaluation.
#[derive(Clone)]
struct AgingLaw {
    kn: f64,
    gamman: f64,
}

impl ContactLaw for AgingLaw {
    const TANGENTIAL: bool = false;
    type History = Aged;
    fn evaluate(&self, k: &PairKinematics, h: &mut Aged, _dt: f64) -> PairForce {
        h.age += 1.0;
        let fn_signed = self.kn * k.delta - self.gamman * k.vn;
        PairForce {
            f: fn_signed * k.n,
            fn_signed,
            ..PairForce::default()
        }
    }
    fn stored_energy(&self, delta: f64, _r_star: f64, _: &Aged) -> f64 {
        0.5 * self.kn * delta * delta
    }
}

/// Two unit spheres approaching head-on along z in a closed box.
fn two_spheres() -> Simulation<AgingLaw> {
    let domain = Domain::new(
        Vec3::new(-5.0, -5.0, -5.0),
        Vec3::new(5.0, 5.0, 5.0),
        [false; 3],
    );
    let mut p = Particles::default();
    for (z, v) in [(-0.52, 0.5), (0.52, -0.5)] {
        let (x, v) = (Vec3::new(0.0, 0.0, z), Vec3::new(0.0, 0.0, v));
        p.push(x, v, Vec3::zeros(), 0.5, 1.0, Motion::Free);
    }
    let builder = NeighborBuilder::new(0.1, 0.0, 0.5, verdem::case::Search::AllPairs);
    let core = Core::new(domain, p, 1e-3, None, builder, 1);
    Simulation::new(
        AgingLaw {
            kn: 1e3,
            gamman: 0.0,
        },
        core,
    )
}

#[test]
fn a_four_word_history_is_snapshotted_hashed_and_checkpointed() {
    let mut sim = two_spheres();
    sim.advance(60).unwrap();
    let snap = sim.snapshot();
    assert_eq!(snap.contacts.len(), 1, "the spheres touch after 60 steps");
    let words = &snap.contacts[0].history;
    assert_eq!(words.len(), 4);
    let age = words[3];
    assert!(age > 1.0, "the contact has aged: {age}");

    // The age is part of the state: the hash sees one step of it.
    let mut older = snap.clone();
    older.contacts[0].history[3] += 1.0;
    assert_ne!(
        verdem::io::hash::state_hash(&snap),
        verdem::io::hash::state_hash(&older)
    );

    // A checkpoint carries all four words; the resumed run continues the same contact.
    let dir = tempfile::tempdir().unwrap();
    let ck = dir.path().join("aging.checkpoint");
    verdem::io::checkpoint::write(&ck, &snap, 1e-3, "aging:2").unwrap();
    let mut resumed = two_spheres();
    resumed.advance(0).unwrap();
    verdem::io::checkpoint::read(&ck, &mut resumed, "aging:2").unwrap();
    assert_eq!(resumed.snapshot().contacts[0].history, *words);
    sim.advance(5).unwrap();
    resumed.advance(5).unwrap();
    assert_eq!(
        verdem::io::hash::state_hash(&sim.snapshot()),
        verdem::io::hash::state_hash(&resumed.snapshot())
    );
    assert_eq!(resumed.snapshot().contacts[0].history[3], age + 5.0);
}
