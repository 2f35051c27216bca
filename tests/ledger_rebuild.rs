//! A contact that a pair-list rebuild closes is booked in the energy ledger as the pair pass
//! books one that opens: what its tangential spring still held goes to the slider, in the step
//! it separated, whichever of the two closes it.

use verdem::case::Search;
use verdem::contact::{Composed, LinearSpringDashpot, MercuryLaw, MercurySlidingFriction};
use verdem::state::{Domain, Motion, Particles};
use verdem::step::neighbor::NeighborBuilder;
use verdem::step::{Core, Engine, LedgerRow, Simulation};
use verdem::Vec3;

const KT: f64 = 2000.0;
const DT: f64 = 1e-4;

/// Two free unit-mass spheres overlapping by 1e-4, spinning so that their surfaces slide (a
/// sticking contact: μ·fn far above the spring's force), with pair-list skin `skin`.
fn sliding_pair(skin: f64) -> Simulation<MercuryLaw> {
    let density = 6.0 / std::f64::consts::PI;
    let mut p = Particles::default();
    // equal spins about z: the contact points slide past each other at 4 along y
    let w = Vec3::new(0.0, 0.0, 4.0);
    p.push(Vec3::zeros(), Vec3::zeros(), w, 0.5, density, Motion::Free);
    let at = Vec3::new(1.0 - 1e-4, 0.0, 0.0);
    p.push(at, Vec3::zeros(), w, 0.5, density, Motion::Free);
    let domain = Domain::new(Vec3::repeat(-5.0), Vec3::repeat(5.0), [false; 3]);
    let builder = NeighborBuilder::new(skin, 0.0, 0.5, Search::AllPairs);
    let core = Core::new(domain, p, DT, None, builder, 1);
    let law = Composed {
        normal: LinearSpringDashpot {
            kn: 1e4,
            gamman: 0.0,
        },
        tangential: MercurySlidingFriction::new(KT, 0.0, 1e3),
    };
    Simulation::new(law, core)
}

/// Loads the pair's tangential spring over 50 steps, then pulls the spheres apart along x so
/// fast that they separate in the next drift, and runs that step. Returns the energy the spring
/// held before that step (½·kt·|ξ|², from its history words), the ledgers of the step and of
/// the loading before it (the pull itself is no work the ledgers see), and the rebuilds run in
/// the step.
fn pulled_apart(skin: f64) -> (f64, LedgerRow, LedgerRow, u64) {
    let mut e = sliding_pair(skin);
    e.advance(0).unwrap();
    let start = e.ledger();
    e.advance(50).unwrap();
    let snap = e.snapshot();
    assert_eq!(snap.contacts.len(), 1, "the pair is in contact");
    let xi = &snap.contacts[0].history;
    let held = 0.5 * KT * (xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
    let loading = e.ledger().since(&start);
    let mut pulled = snap.clone();
    pulled.particles.v[0].x -= 1.0;
    pulled.particles.v[1].x += 1.0;
    e.restore(&pulled);
    let before = e.ledger();
    let rebuilds = e.counters().rebuilds;
    e.advance(1).unwrap();
    assert!(e.snapshot().contacts.is_empty(), "the pair separated");
    let after = e.ledger();
    let rebuilt = e.counters().rebuilds - rebuilds;
    (held, after.since(&before), loading, rebuilt)
}

/// A skin below one step's motion rebuilds the list in the separating step, which closes the
/// contact; a wide one does not, and the pair pass closes it. Both book what the spring held as
/// the slider's, in that step: the ledgers agree bit for bit and close over the contact. Without
/// the rebuild's booking the held energy would vanish from the ledger: a residual of −held.
#[test]
fn a_contact_closed_by_a_rebuild_books_what_its_spring_held() {
    let (held, step, loading, rebuilt) = pulled_apart(1e-9);
    let (held_wide, step_wide, loading_wide, rebuilt_wide) = pulled_apart(0.5);
    assert!(rebuilt >= 1, "no rebuild in the separating step");
    assert_eq!(rebuilt_wide, 0, "the wide skin rebuilt");
    assert_eq!(held.to_bits(), held_wide.to_bits());
    assert!(held > 1e-2, "the spring held {held}");
    let slide = |r: &LedgerRow| r.dissipated.expect("the law splits its dissipation")[2];
    // the slider took exactly what the spring held (to the fixed point's resolution)
    assert!(
        (slide(&step) - held).abs() <= 1e-12 * held,
        "{step:?} held {held}"
    );
    assert_eq!(step, step_wide);
    assert_eq!(loading, loading_wide);
    // The ledger closes over the contact's life to the scheme's error, first order in dt: far
    // below the held energy a missing booking would leave as the residual.
    let residual = loading.residual.expect("split") + step.residual.expect("split");
    assert!(
        residual.abs() < 0.1 * held,
        "residual {residual}, held {held}"
    );
}
