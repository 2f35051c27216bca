//! The energy and momentum ledgers (`Engine::ledger`, the ledger columns of
//! `NAME.diagnostics.csv`): thread-count independent, the momentum ledger closed to round-off,
//! the energy ledger's residual converging with dt at the order derived below, and a law that
//! misreports its dissipation caught.

mod common;

use common::*;
use verdem::case::Case;
use verdem::contact::{
    ContactLaw, Dissipated, LinearSpringDashpot, MercuryLaw, MercurySlidingFriction, PairKinematics,
};
use verdem::state::PairForce;
use verdem::step::engine::Overrides;
use verdem::step::neighbor::NeighborBuilder;
use verdem::step::{Core, Engine, LedgerRow, Simulation};
use verdem::Vec3;

fn steady_case() -> Case {
    Case::load(&root().join("cases/shear_flow_steady.toml")).expect("case loads")
}

fn steady_init() -> std::path::PathBuf {
    root().join("golden/full_run/shear_flow.final.data")
}

/// A simulation of the steady case's scene under `law`, on one thread, with time step `dt`.
fn simulation<L: ContactLaw>(case: &Case, law: L, dt: f64) -> Simulation<L> {
    let scene = verdem::scene::build(case, Some(&steady_init())).expect("scene builds");
    let r_max = scene.particles.radius.iter().cloned().fold(0.0, f64::max);
    let n = &case.neighbor;
    let builder = NeighborBuilder::new(n.skin, n.cell, r_max, n.search);
    let gravity = case.gravity().map(Vec3::from);
    let mut core = Core::new(scene.domain, scene.particles, dt, gravity, builder, 1);
    core.state.time = scene.time;
    Simulation::new(law, core)
}

/// The benchmark's law with the case's parameters.
fn mercury_law(case: &Case) -> MercuryLaw {
    let c = &case.contact;
    verdem::contact::Composed {
        normal: LinearSpringDashpot {
            kn: c.kn,
            gamman: c.gamman,
        },
        tangential: MercurySlidingFriction::new(c.kt, c.gammat, c.mu),
    }
}

/// The ledgers of `steps` steps of `e` from its current state (forces evaluated first).
fn ledger_over(e: &mut dyn Engine, steps: u64) -> LedgerRow {
    e.advance(0).unwrap();
    let before = e.ledger();
    e.advance(steps).unwrap();
    e.ledger().since(&before)
}

/// The energy that passed through the free particles over an interval: what the walls and
/// gravity put in and the contacts took, the scale of the residual.
fn throughput(r: &LedgerRow) -> f64 {
    let d: f64 = r.dissipated.expect("split").iter().map(|d| d.abs()).sum();
    r.work_walls.abs() + r.work_gravity.abs() + d
}

#[test]
fn the_ledgers_are_bit_identical_on_one_and_two_threads() {
    let case = steady_case();
    let reading = |threads| {
        let o = Overrides {
            threads: Some(threads),
            bind: Some(false),
            ..Overrides::default()
        };
        let mut e = engine(&case, Some(&steady_init()), o);
        e.advance(1500).unwrap();
        e.ledger()
    };
    let (one, two) = (reading(1), reading(2));
    assert!(one.flows.dissipated.iter().all(|&d| d > 0), "{one:?}");
    assert!(
        one.flows.impulse.iter().flatten().any(|&j| j != 0),
        "{one:?}"
    );
    assert_eq!(one, two);
}

/// Δ(Σ m v) of the free particles equals the walls' impulse (F·dt every step, half a step at
/// each end) plus gravity's, to round-off: Newton's third law in the scheme. Without the half
/// steps at the ends the residual would be about F·dt, some 1e-4 of the throughput here.
#[test]
fn the_free_momentum_balances_the_walls_impulse_to_round_off() {
    let case = steady_case();
    let mut e = engine(&case, Some(&steady_init()), Overrides::default());
    e.advance(500).unwrap();
    let r = ledger_over(e.as_mut(), 3000);
    let duration = 3000.0 * case.dt();
    let impulse = (r.mean_wall_force[0].norm() + r.mean_wall_force[1].norm()) * duration;
    assert!(impulse > 0.0);
    let worst = r.momentum_residual.amax();
    assert!(
        worst <= 1e-10 * impulse,
        "momentum residual {:?} against the walls' impulse {impulse:e}",
        r.momentum_residual
    );
}

/// The energy ledger's residual over the same physical time (`span` steps of the benchmark's dt,
/// `dt`/2^k for k = 0, 1, 2) from the steady state, relative to the throughput.
fn relative_residuals<L: ContactLaw + Clone>(case: &Case, law: &L, span: u64) -> [f64; 3] {
    std::array::from_fn(|k| {
        let dt = case.dt() / (1u64 << k) as f64;
        let mut sim = simulation(case, law.clone(), dt);
        let r = ledger_over(&mut sim, span << k);
        r.residual.expect("split").abs() / throughput(&r)
    })
}

/// The residual converges at first order in dt (band 0.7–1.5 for the two halvings). Derivation:
/// the scheme's quantities are exact sums over its steps — the springs' work telescopes to the
/// change of their energy, the slider's share included (`Convention::force_dissipating`) —
/// except the dissipation, which the law reports at the velocities it sees, v(n−½), while the
/// force of step n acts over the two half kicks around t(n). The dashpot's discrete work
/// −γ·vn(n−½)·(vn(n−½) + vn(n+½))/2·dt differs from the reported γ·vn(n−½)²·dt by γ·vn·Δvn·dt/2
/// a step, which sums over a collision to γ·dt·(vn_in² − vn_out²)/4 ≠ 0: first order, as the
/// dashpot force evaluated with the half-step velocity is itself.
#[test]
fn the_energy_residual_converges_at_first_order_in_dt() {
    let case = steady_case();
    let law = mercury_law(&case);
    let res = relative_residuals(&case, &law, 1000);
    let orders = [(res[0] / res[1]).log2(), (res[1] / res[2]).log2()];
    eprintln!("benchmark law: relative residuals {res:?}, orders {orders:?}");
    for p in orders {
        assert!((0.7..=1.5).contains(&p), "order {p}: {res:?}");
    }
}

/// A law that reports `factor` times the dissipation of the benchmark's law.
#[derive(Clone)]
struct Misreporting {
    law: MercuryLaw,
    factor: f64,
}

impl ContactLaw for Misreporting {
    const TANGENTIAL: bool = true;
    type History = Vec3;
    fn evaluate(&self, k: &PairKinematics, h: &mut Vec3, dt: f64) -> PairForce {
        self.law.evaluate(k, h, dt)
    }
    fn stored_energy(&self, delta: f64, r_star: f64, h: &Vec3) -> f64 {
        self.law.stored_energy(delta, r_star, h)
    }
    const SPLITS_DISSIPATION: bool = true;
    fn evaluate_dissipating(
        &self,
        k: &PairKinematics,
        h: &mut Vec3,
        dt: f64,
    ) -> (PairForce, Dissipated) {
        let (f, d) = self.law.evaluate_dissipating(k, h, dt);
        let scaled = Dissipated {
            normal: d.normal * self.factor,
            tangential: d.tangential * self.factor,
            slide: d.slide * self.factor,
        };
        (f, scaled)
    }
}

/// A law that does not split its dissipation (the trait's default).
#[derive(Clone)]
struct Unsplit(MercuryLaw);

impl ContactLaw for Unsplit {
    const TANGENTIAL: bool = true;
    type History = Vec3;
    fn evaluate(&self, k: &PairKinematics, h: &mut Vec3, dt: f64) -> PairForce {
        self.0.evaluate(k, h, dt)
    }
    fn stored_energy(&self, delta: f64, r_star: f64, h: &Vec3) -> f64 {
        self.0.stored_energy(delta, r_star, h)
    }
}

/// The same steps under the true law and under one that reports 10 % too little dissipation:
/// the true law's residual is within the ledger's tolerance, the misreporting law's is not; a law
/// that does not split its dissipation gets no residual at all rather than a closed balance.
#[test]
fn a_law_that_misreports_its_dissipation_fails_the_ledger() {
    let case = steady_case();
    let law = mercury_law(&case);
    let relative = |r: &LedgerRow| r.residual.unwrap().abs() / throughput(r);
    let honest = ledger_over(&mut simulation(&case, law.clone(), case.dt()), 2000);
    let wrong = Misreporting {
        law: law.clone(),
        factor: 0.9,
    };
    let lying = ledger_over(&mut simulation(&case, wrong, case.dt()), 2000);
    let tolerance = verdem::analysis::ledger::RESIDUAL_TOLERANCE;
    eprintln!(
        "relative residuals: honest {} misreporting {}",
        relative(&honest),
        relative(&lying)
    );
    assert!(relative(&honest) < tolerance, "{honest:?}");
    assert!(relative(&lying) > tolerance, "{lying:?}");
    let mut unsplit = simulation(&case, Unsplit(law), case.dt());
    let r = ledger_over(&mut unsplit, 200);
    assert_eq!((r.dissipated, r.residual), (None, None));
    assert!(
        r.d_trans != 0.0
            && r.mean_wall_force
                .iter()
                .all(|f| f.iter().all(|x| x.is_finite()))
    );
}
