//! The engine: the law-independent face of a simulation ([`Engine`], what the run loop and the
//! tools drive) and how one is built from a case ([`build`]): the contact law is composed here,
//! once, from the parts the case switches on (normal law, clipped or not, friction or not,
//! tangential convention).

use super::guard::Failure;
use super::{energy, Core, Flows, Params, Reading, Simulation, StageTimes, State};
use crate::case::{self, Case, CaseError};
use crate::contact::normal::Clipped;
use crate::contact::{
    Composed, ContactLaw, Frictionless, Normal, NormalModel, NormalVisitor, Parameters, Tangential,
    TangentialModel, TangentialVisitor,
};
use crate::state::{Domain, History, Particles, SampledContact, Snapshot};
use crate::step::neighbor::NeighborBuilder;
use crate::Vec3;

/// The law-independent face of a simulation, for the run loop and the tools.
pub trait Engine: Send {
    /// The dynamic state (particles in memory order; see [`Engine::snapshot`]).
    fn state(&self) -> &State;
    /// The settings of the step.
    fn params(&self) -> &Params;
    /// The same, to change between calls of [`Engine::advance`].
    fn params_mut(&mut self) -> &mut Params;
    /// Time per stage and rebuilds since the counters were last reset.
    fn counters(&self) -> &StageTimes;
    /// The same, to reset.
    fn counters_mut(&mut self) -> &mut StageTimes;
    /// The state in canonical order (allocates; for saves, hashes and checkpoints).
    fn snapshot(&self) -> Snapshot;
    /// The active contacts, as [`Snapshot::contacts`] has them, with their particles' positions
    /// and radii: a sample of the contact stress without a snapshot of every particle.
    fn contact_sample(&self) -> Vec<SampledContact>;
    /// Takes [`Engine::contact_sample`] inside every later run at each step that is a multiple
    /// of `every` (0: never), once that step's forces are evaluated, without stopping the run.
    fn sample_contacts_every(&mut self, every: u64);
    /// The contact samples taken inside runs since the last call, by step, in step order.
    fn take_contact_samples(&mut self) -> Vec<(u64, Vec<SampledContact>)>;
    /// Overwrites the dynamic state from a canonical snapshot of the same scene whose contacts
    /// carry this law's history ([`Engine::history_words`] words each).
    fn restore(&mut self, snap: &Snapshot);
    /// Words of the canonical form of the contact law's history.
    fn history_words(&self) -> usize;
    /// Re-orders the particles and rebuilds the pair list, keeping every contact's history.
    fn rebuild(&mut self);
    /// Number of pairs in contact at the last force evaluation.
    fn contact_count(&self) -> usize;
    /// Number of candidate pairs at the last build.
    fn pair_count(&self) -> usize;
    /// Largest overlap of any contact in any step run so far, as a fraction of the pair's
    /// smaller radius (0 before the first step; the guard stops a run beyond `[guard] overlap`).
    fn deepest_overlap(&self) -> f64;
    /// Largest excess of a contact's energy account in any step run so far, as a fraction of
    /// the energy the contact took (0 when none gave out more than it took; the guard stops a
    /// run beyond `[guard] contact`).
    fn largest_excess(&self) -> f64;
    /// The ledgers read at the current step ([`Reading`]; the forces of the step evaluated):
    /// the energy and momentum flows accumulated over every step run so far, and the state's
    /// energies and free momentum. Two readings give the ledgers of the steps between them.
    fn ledger(&self) -> Reading;
    /// The ledgers' flows accumulated over every step run so far (those of [`Engine::ledger`]).
    fn flows(&self) -> Flows;
    /// Sets the accumulated flows: a run resumed from a checkpoint continues those of the run
    /// that wrote it.
    fn set_flows(&mut self, flows: Flows);
    /// Advances `steps` time steps (evaluating the initial forces first if needed). Stops early,
    /// with the reason, when the run guard finds a number that cannot be trusted; after that
    /// every call fails the same way.
    fn advance(&mut self, steps: u64) -> Result<(), Failure>;
}

impl<L: ContactLaw> Engine for Simulation<L> {
    fn state(&self) -> &State {
        &self.core.state
    }
    fn params(&self) -> &Params {
        &self.core.params
    }
    fn params_mut(&mut self) -> &mut Params {
        self.core.energy_at = None;
        &mut self.core.params
    }
    fn counters(&self) -> &StageTimes {
        &self.core.counters
    }
    fn counters_mut(&mut self) -> &mut StageTimes {
        &mut self.core.counters
    }
    fn snapshot(&self) -> Snapshot {
        self.core.snapshot()
    }
    fn contact_sample(&self) -> Vec<SampledContact> {
        self.core.contact_sample()
    }
    fn sample_contacts_every(&mut self, every: u64) {
        self.core.params.contact_every = every;
    }
    fn take_contact_samples(&mut self) -> Vec<(u64, Vec<SampledContact>)> {
        std::mem::take(&mut self.core.contact_samples)
    }
    fn restore(&mut self, snap: &Snapshot) {
        self.core.restore(snap)
    }
    fn history_words(&self) -> usize {
        <L::History as History>::WORDS
    }
    fn rebuild(&mut self) {
        self.rebuild_booked()
    }
    fn contact_count(&self) -> usize {
        self.core.contact_count()
    }
    fn pair_count(&self) -> usize {
        self.core.pair_count()
    }
    fn deepest_overlap(&self) -> f64 {
        self.core.deepest
    }
    fn largest_excess(&self) -> f64 {
        self.core.pumped
    }
    fn ledger(&self) -> Reading {
        let c = &self.core;
        let s = &c.state;
        energy::read(
            &self.law,
            &s.particles,
            &s.domain,
            c.params.gravity,
            &c.pairs,
            (s.step, c.params.dt, c.flows),
        )
    }
    fn flows(&self) -> Flows {
        self.core.flows
    }
    fn set_flows(&mut self, flows: Flows) {
        self.core.flows = flows;
    }
    fn advance(&mut self, steps: u64) -> Result<(), Failure> {
        self.advance_in_windows(steps)
    }
}

/// The initial state of a run, which [`build`] makes a simulation of ([`crate::scene::build`]
/// makes one from a case).
pub struct Scene {
    pub domain: Domain,
    pub particles: Particles,
    /// Start time (that of the `.data` file it was read from, else 0).
    pub time: f64,
    /// The flat walls (`[[wall]]`) at the start.
    pub walls: Vec<crate::state::Wall>,
}

/// Overrides of the case's numerical settings (command line).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub threads: Option<usize>,
    /// Bind the team's threads to CPUs (default: yes; see [`Core::bind`]).
    pub bind: Option<bool>,
    pub skin: Option<f64>,
    pub cell: Option<f64>,
}

/// Something done with the contact law of a case, whichever concrete type it composes to.
pub trait LawVisitor {
    type Output;
    /// Does the job with the composed law `law`.
    fn visit<L: ContactLaw + Clone + 'static>(self, law: L) -> Self::Output;
}

/// Composes the contact law of `case` and hands it to `v`: the normal law the registry builds
/// (clipped if the case asks), then the tangential convention; an error when the case names no
/// normal law or does not give the numbers it reads ([`Normal::checked`]), or names no
/// tangential convention ([`Tangential::of`]), with or without friction. Without friction the law has no tangential history, torque or spin
/// (model only what the case needs).
pub fn with_law<V: LawVisitor>(case: &Case, v: V) -> Result<V::Output, CaseError> {
    let normal = Normal::checked(case)?;
    let tangential = Tangential::of(case)?;
    let params = Parameters::of(case);
    let then = ClipThen {
        c: &case.contact,
        params,
        tangential,
        v,
    };
    Ok(normal.with_model(&params, then))
}

/// Clips the case's normal model if it asks to, then composes it with its tangential model.
struct ClipThen<'a, V> {
    c: &'a case::Contact,
    params: Parameters,
    tangential: Tangential,
    v: V,
}

impl<V: LawVisitor> NormalVisitor for ClipThen<'_, V> {
    type Output = V::Output;
    fn visit<N: NormalModel + Clone + 'static>(self, normal: N) -> V::Output {
        if self.c.clip_normal {
            with_tangential(&self.params, self.tangential, Clipped(normal), self.v)
        } else {
            with_tangential(&self.params, self.tangential, normal, self.v)
        }
    }
}

fn with_tangential<N, V>(p: &Parameters, tangential: Tangential, normal: N, v: V) -> V::Output
where
    N: NormalModel + Clone + 'static,
    V: LawVisitor,
{
    if p.mu <= 0.0 {
        return v.visit(Composed {
            normal,
            tangential: Frictionless,
        });
    }
    tangential.with_model(p, ComposeWith { normal, v })
}

/// Composes a normal model with the tangential model the registry builds, for a visitor.
struct ComposeWith<N, V> {
    normal: N,
    v: V,
}

impl<N, V> TangentialVisitor for ComposeWith<N, V>
where
    N: NormalModel + Clone + 'static,
    V: LawVisitor,
{
    type Output = V::Output;
    fn visit<T: TangentialModel + Clone + 'static>(self, tangential: T) -> V::Output {
        self.v.visit(Composed {
            normal: self.normal,
            tangential,
        })
    }
}

/// The parts of a simulation besides its law; the law decides the type of its contacts'
/// history, so the core is made once the law is known.
struct BuildSimulation {
    scene: Scene,
    dt: f64,
    gravity: Option<Vec3>,
    builder: NeighborBuilder,
    threads: usize,
    bind: bool,
    guard: case::Guard,
}

impl LawVisitor for BuildSimulation {
    type Output = Box<dyn Engine>;
    fn visit<L: ContactLaw + Clone + 'static>(self, law: L) -> Box<dyn Engine> {
        let mut core = Core::new(
            self.scene.domain,
            self.scene.particles,
            self.dt,
            self.gravity,
            self.builder,
            self.threads,
        );
        core.state.time = self.scene.time;
        core.set_walls(self.scene.walls);
        core.params.bind = self.bind;
        core.params.guard = self.guard;
        Box::new(Simulation::new(law, core))
    }
}

/// A ready-to-run simulation of `scene` under the case's contact law; an error when the case
/// names no tangential convention.
pub fn build(case: &Case, scene: Scene, o: &Overrides) -> Result<Box<dyn Engine>, CaseError> {
    let r_max = scene.particles.radius.iter().cloned().fold(0.0, f64::max);
    let builder = NeighborBuilder::new(
        o.skin.unwrap_or(case.neighbor.skin),
        o.cell.unwrap_or(case.neighbor.cell),
        r_max,
        case.neighbor.search,
    );
    let parts = BuildSimulation {
        scene,
        dt: case.dt(),
        gravity: case.gravity().map(Vec3::from),
        builder,
        threads: o.threads.unwrap_or(case.run.threads),
        bind: o.bind.unwrap_or(true),
        guard: case.guard,
    };
    with_law(case, parts)
}
