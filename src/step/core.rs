//! What a time step advances and the settings it runs with, split by who owns them: the state
//! (saved, hashed, checkpointed), the parameters (set once per run), the counters, and the
//! workspace the step keeps between steps.

use std::collections::HashMap;
use std::sync::Arc;

use super::counters::StageTimes;
use super::guard::Failure;
use crate::case::Guard;
use crate::state::{
    Contact, Domain, History, PairForce, Particles, SampledContact, Snapshot, Wall,
};
use crate::step::neighbor::rebuild::{self, key, Flags, ListState, Pairs, Plan};
use crate::step::neighbor::NeighborBuilder;
use crate::step::team::{Crew, Shared};
use crate::step::walls::WallSlots;
use crate::Vec3;

/// The dynamic state. Particle arrays are in memory order (re-ordered by cell at every pair-list
/// build); [`Core::snapshot`] gives the canonical (id) order.
pub struct State {
    pub domain: Domain,
    pub particles: Particles,
    /// Original index (0-based id) of each particle in memory order.
    pub id: Vec<u32>,
    /// Index of the current step: the state is x_n, v_n, ω_n with the forces of step n.
    pub step: u64,
    /// Simulated time, accumulated as a running sum of dt (as MercuryDPM does).
    pub time: f64,
    /// Whether `particles.f`/`t` hold the forces of the current state.
    pub forces_ready: bool,
}

/// Called by thread 0 once a step, right after the team's threads meet; `verdem bench` uses it
/// to couple independent runs.
pub type MeetHook = Arc<dyn Fn() + Send + Sync>;

/// Settings of the step.
pub struct Params {
    /// Time step (time units).
    pub dt: f64,
    /// Gravity (acceleration), `None` when the case has none: no gravity pass at all.
    pub gravity: Option<Vec3>,
    /// Worker threads of the step.
    pub threads: usize,
    /// Whether a team of more than one thread binds thread t to the t-th CPU the process may
    /// run on, while it runs (when the team fits on distinct CPUs); the default.
    pub bind: bool,
    /// Whether the force evaluation before the first step advances the tangential springs by
    /// one step, as MercuryDPM's does (true, the default); LAMMPS and LIGGGHTS skip the
    /// history update during their setup (`update->setupflag`), which cross-runs mirror.
    pub setup_advances_history: bool,
    /// Called once a step after the meeting, on thread 0; `None` for a normal run.
    pub meet: Option<MeetHook>,
    /// Inside a run, a contact sample ([`Core::contact_sample`]) at every step that is a
    /// multiple of it, taken once the step's forces are evaluated and kept for
    /// [`super::Engine::take_contact_samples`]; 0 (the default): none.
    pub contact_every: u64,
    /// Limits of the run guard.
    pub guard: Guard,
}

/// What the step keeps between steps besides the state: the pair list's builder and plan, the
/// particles' flags, and how far particles may have moved since the last build.
pub(super) struct Workspace {
    /// Upper bounds of the displacement since the last pair-list build of any slow [0] and of
    /// any fast [1] particle, by their speed class at that build (length).
    pub moved_bound: [f64; 2],
    pub builder: NeighborBuilder,
    pub plan: Plan,
    pub flags: Flags,
}

/// Everything a step advances and runs with, for a contact law of history `H`.
pub struct Core<H> {
    pub state: State,
    /// Candidate pairs with their contact history and last forces.
    pub pairs: Pairs<H>,
    /// The flat walls and their contacts with the spheres.
    pub walls: WallSlots<H>,
    pub params: Params,
    pub counters: StageTimes,
    /// Why the run guard stopped the last run, if it did; the state is then not to be trusted
    /// and no further step is taken.
    pub failure: Option<Failure>,
    /// Largest overlap of any contact in the pair passes so far, as a fraction of the smaller
    /// radius of the pair.
    pub deepest: f64,
    /// Largest excess of a contact's energy account in the pair passes so far, as a fraction of
    /// what the contact took.
    pub pumped: f64,
    /// The ledgers' flows over every step run so far ([`super::Engine::ledger`]).
    pub(super) flows: super::Flows,
    pub(super) work: Workspace,
    /// The run guard's energy of the state at the end of the last [`super::Engine::advance`]
    /// and its step: the next call starts its balance from it. Forgotten by a rebuild from
    /// outside a run (which every restore and first force evaluation makes) and by a change of
    /// the parameters.
    pub(super) energy_at: Option<(u64, super::energy::Energy)>,
    /// The contact samples taken inside runs ([`Params::contact_every`]) since they were last
    /// taken out, by step.
    pub(super) contact_samples: Vec<(u64, Vec<SampledContact>)>,
}

impl<H: History> Core<H> {
    /// The pair list and everything that moves with it.
    pub(super) fn list_state(&mut self) -> ListState<'_, H> {
        let (state, work) = (&mut self.state, &mut self.work);
        ListState::new(
            &mut state.particles,
            &mut state.id,
            &mut self.pairs,
            &mut work.builder,
            &mut work.plan,
            &mut work.flags,
        )
    }

    /// A state at step 0, time 0 (time units), with no forces evaluated yet; particles in id
    /// order; `dt` in time units, `gravity` an acceleration.
    pub fn new(
        domain: Domain,
        particles: Particles,
        dt: f64,
        gravity: Option<Vec3>,
        builder: NeighborBuilder,
        threads: usize,
    ) -> Self {
        let threads = threads.max(1);
        Core {
            state: State {
                id: (0..particles.len() as u32).collect(),
                domain,
                particles,
                step: 0,
                time: 0.0,
                forces_ready: false,
            },
            pairs: Pairs::default(),
            walls: WallSlots::new(Vec::new(), 0),
            params: Params {
                dt,
                gravity,
                threads,
                bind: true,
                setup_advances_history: true,
                meet: None,
                contact_every: 0,
                guard: Guard::default(),
            },
            counters: StageTimes::default(),
            failure: None,
            deepest: 0.0,
            pumped: 0.0,
            flows: super::Flows::default(),
            work: Workspace {
                moved_bound: [0.0; 2],
                builder,
                plan: Plan::new(threads),
                flags: Flags::default(),
            },
            energy_at: None,
            contact_samples: Vec::new(),
        }
    }

    /// Sets the flat walls of the scene (where they are now), with no contact yet.
    pub fn set_walls(&mut self, walls: Vec<Wall>) {
        self.walls = WallSlots::new(walls, self.state.particles.len());
        self.state.forces_ready = false;
        self.energy_at = None;
    }

    /// Skin of the pair list (length).
    pub fn skin(&self) -> f64 {
        self.work.builder.skin
    }

    /// Number of candidate pairs at the last build.
    pub fn pair_count(&self) -> usize {
        self.pairs.list.p.len()
    }

    /// Re-orders the particles and rebuilds the pair list on this thread, keeping the history of
    /// every contact whose particles still touch; the others are closed and listed in
    /// [`Pairs::dropped`], for the caller that knows the law to book what they held
    /// (`Simulation` does).
    pub fn rebuild(&mut self) {
        self.energy_at = None;
        let domain = self.state.domain.clone();
        let start = std::time::Instant::now();
        let list = Shared::new(self.list_state());
        // SAFETY: a crew of one: every phase runs on this thread.
        unsafe { rebuild::rebuild(Crew::Solo, &list, &domain) };
        self.counters.neighbor += start.elapsed().as_nanos() as u64;
        self.counters.rebuilds += 1;
        self.work.moved_bound = [0.0; 2];
    }

    /// Rebuilds the pair list and sets the given contacts (by original ids) as active with
    /// their history and force; used when resuming from a checkpoint.
    pub fn restore_contacts(&mut self, contacts: &[Contact]) {
        let pairs = &mut self.pairs;
        pairs.active.fill(false);
        pairs.history.fill(H::default());
        self.rebuild();
        let (pairs, id) = (&mut self.pairs, &self.state.id);
        let slot: HashMap<u64, usize> = (0..pairs.list.p.len())
            .map(|k| {
                let (p, i) = (pairs.list.p[k] as usize, pairs.list.i[k] as usize);
                (key(id[p], id[i]), k)
            })
            .collect();
        for c in contacts {
            if let Some(&k) = slot.get(&key(c.p, c.i)) {
                pairs.history[k] = H::from_words(&c.history);
                pairs.out[k] = c.force;
                pairs.active[k] = true;
            }
        }
        self.state.forces_ready = true;
    }

    /// Number of pairs in contact at the last force evaluation.
    pub fn contact_count(&self) -> usize {
        self.pairs.active.iter().filter(|a| **a).count()
    }

    /// The active contacts as samples ([`SampledContact`]), sorted by `(p, i)` as a
    /// snapshot's: a pass over the pair list, without copying every particle.
    pub fn contact_sample(&self) -> Vec<SampledContact> {
        let (s, pairs) = (&self.state, &self.pairs);
        let pt = &s.particles;
        let list = (&pairs.list.p[..], &pairs.list.i[..]);
        contacts_of(
            (&pt.x, &pt.radius, &s.id),
            list,
            (&pairs.active, &pairs.out),
        )
    }

    /// The state in canonical order (allocates; for saves, hashes and checkpoints).
    pub fn snapshot(&self) -> Snapshot {
        let s = &self.state;
        let n = s.particles.len();
        let mut pos = vec![0usize; n];
        for (a, &id) in s.id.iter().enumerate() {
            pos[id as usize] = a;
        }
        let src = &s.particles;
        let by_id = |v: &[Vec3]| -> Vec<Vec3> { pos.iter().map(|&a| v[a]).collect() };
        let scalar_by_id = |v: &[f64]| -> Vec<f64> { pos.iter().map(|&a| v[a]).collect() };
        let particles = Particles {
            x: by_id(&src.x),
            v: by_id(&src.v),
            w: by_id(&src.w),
            radius: scalar_by_id(&src.radius),
            inv_mass: scalar_by_id(&src.inv_mass),
            inv_inertia: scalar_by_id(&src.inv_inertia),
            motion: pos.iter().map(|&a| src.motion[a]).collect(),
            f: by_id(&src.f),
            t: by_id(&src.t),
        };
        let pairs = &self.pairs;
        let mut contacts: Vec<Contact> = (0..pairs.list.p.len())
            .filter(|&k| pairs.active[k])
            .map(|k| {
                let h = &pairs.history[k];
                let mut history = Vec::with_capacity(H::WORDS);
                h.put_words(&mut history);
                Contact {
                    p: s.id[pairs.list.p[k] as usize],
                    i: s.id[pairs.list.i[k] as usize],
                    history,
                    spring: h.spring(),
                    force: pairs.out[k],
                }
            })
            .collect();
        contacts.sort_unstable_by_key(|c| key(c.p, c.i));
        Snapshot {
            step: s.step,
            time: s.time,
            domain: s.domain.clone(),
            particles,
            contacts,
            walls: self.walls.walls.clone(),
            wall_contacts: self.walls.contacts(),
        }
    }

    /// Overwrites the dynamic state from a canonical snapshot of the same scene.
    pub fn restore(&mut self, snap: &Snapshot) {
        let n = self.state.particles.len();
        assert_eq!(n, snap.particles.len(), "snapshot of another scene");
        self.state.id = (0..n as u32).collect();
        self.state.particles = snap.particles.clone();
        self.state.step = snap.step;
        self.state.time = snap.time;
        assert_eq!(
            self.walls.walls.len(),
            snap.walls.len(),
            "snapshot of another scene's walls"
        );
        self.walls.restore(&snap.walls, &snap.wall_contacts);
        self.restore_contacts(&snap.contacts);
    }
}

/// The active pairs among `pairs` (`p`, `i`: memory indices) of `particles` (positions, radii,
/// ids in memory order) as samples ([`SampledContact`], by original id), with the `slots`
/// (whether in contact, last force) of the pairs, sorted by `(p, i)` as a snapshot's contacts.
pub(super) fn contacts_of(
    particles: (&[Vec3], &[f64], &[u32]),
    pairs: (&[u32], &[u32]),
    slots: (&[bool], &[PairForce]),
) -> Vec<SampledContact> {
    let (x, radius, id) = particles;
    let (active, out) = slots;
    // Blocks of flags OR-ed without an early exit, which compiles to a few vector loads a
    // block: in the benchmark's flow one pair in a thousand is in contact.
    const BLOCK: usize = 64;
    let live = active
        .chunks(BLOCK)
        .enumerate()
        .filter(|(_, block)| block.iter().fold(false, |any, &a| any | a));
    let mut contacts: Vec<SampledContact> = live
        .flat_map(|(b, block)| {
            let first = b * BLOCK;
            block
                .iter()
                .enumerate()
                .filter(|(_, &a)| a)
                .map(move |(j, _)| first + j)
        })
        .map(|k| {
            let (a, o) = (pairs.0[k] as usize, pairs.1[k] as usize);
            SampledContact {
                p: id[a],
                i: id[o],
                force: out[k],
                x: [x[a], x[o]],
                radius: [radius[a], radius[o]],
            }
        })
        .collect();
    contacts.sort_unstable_by_key(|c| key(c.p, c.i));
    contacts
}
