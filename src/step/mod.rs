//! The time step, top to bottom, and the state it advances.
//!
//! One step n → n+1 (MercuryDPM's order, `benchmark.md` "How MercuryDPM computes it"):
//! 1. kick–drift of every free particle: v += (F/m + g)·dt/2, x += v·dt, ω += T/I·dt/2;
//!    prescribed (wall) particles: x += v·dt; positions wrap along periodic axes;
//! 2. the pair list is rebuilt when two particles may have closed a gap of a skin since the last
//!    build (displacement bounds Σ max|v|·dt, one per speed class of the build), so that no pair
//!    can have come closer than r_P + r_I unlisted;
//! 3. pair forces at the new positions with the half-step velocities, each pair into its own
//!    slot (its tangential history updated in place);
//! 4. gather: each particle sums its slots in the order of its partners' ids; kick:
//!    v += (F/m + g)·dt/2, ω += T/I·dt/2; t += dt (a running sum).
//!
//! Steps 4 of one step and 1 of the next touch only one particle each, so they run fused in one
//! pass. With T threads every thread runs this loop; each pass is cut into chunks (contiguous
//! particles, contiguous pairs) that the threads take from a [`WorkQueue`], their own share
//! first and then what is left of the others'. The threads meet at one barrier per step, after
//! the per-particle pass (every thread needs every particle's new position and the largest
//! speeds, which decide a rebuild). After the pair pass there is none: a thread done with the
//! pair chunks goes on to the particle chunks, and each particle chunk waits only for the pair
//! chunks that hold its particles' pairs, marked done chunk by chunk ([`Marks`]), so the
//! threads' ends of the pair pass overlap their partner's work instead of waiting for it. No
//! float is ever summed in an order that depends on the thread count, the chunk a thread takes,
//! the memory order of the particles, the skin or the cell size, so results are bitwise
//! identical for all.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

use crate::contact::{ContactLaw, PairForce, PairInput};
use crate::neighbor::{NeighborBuilder, PairList};
use crate::state::Domain;
use crate::state::{Contact, Motion, Particles, Snapshot};
use crate::team::{balanced_ranges, Bound, Marks, Shared, SpinBarrier, WorkQueue};
use crate::Vec3;

/// Wall-clock time spent in each stage, in nanoseconds, measured on thread 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageTimes {
    /// Pair-list rebuilds (including the re-ordering of particles in memory).
    pub neighbor: u64,
    /// Pair forces.
    pub forces: u64,
    /// Gather of pair forces, kicks and drifts (per-particle pass).
    pub integrate: u64,
    /// Waiting for the other threads: at barriers, and for the pair chunks a gather needs.
    pub wait: u64,
    /// Number of pair-list rebuilds.
    pub rebuilds: u64,
}

impl StageTimes {
    /// Moves `waited` ns, spent inside the particle pass waiting for pair chunks, from
    /// `integrate` to `wait`.
    fn count_wait_in_integrate(&mut self, waited: u64) {
        let waited = waited.min(self.integrate);
        self.integrate -= waited;
        self.wait += waited;
    }
}

/// Everything a step advances, independent of the contact law. Particle arrays are in memory
/// order (re-ordered by cell at every pair-list build); use [`Core::snapshot`] for id order.
pub struct Core {
    pub domain: Domain,
    pub particles: Particles,
    /// Original index (0-based id) of each particle in memory order.
    pub id: Vec<u32>,
    /// Time step (time units).
    pub dt: f64,
    /// Gravity (acceleration), `None` when the case has none: no gravity pass at all.
    pub gravity: Option<Vec3>,
    /// Index of the current step: the state is x_n, v_n, ω_n with the forces of step n.
    pub step: u64,
    /// Simulated time, accumulated as a running sum of dt (as MercuryDPM does).
    pub time: f64,
    /// Candidate pairs (within r_P + r_I + skin).
    pub pairs: PairList,
    /// Elastic tangential displacement of each pair (length); zero when not in contact.
    pub xi: Vec<Vec3>,
    /// Whether each pair was in contact at the last force evaluation.
    pub active: Vec<bool>,
    /// Force and torques of each active pair at the last force evaluation.
    pub out: Vec<PairForce>,
    /// Whether `particles.f`/`t` hold the forces of the current state.
    pub forces_ready: bool,
    /// Upper bounds of the displacement since the last pair-list build of any slow [0] and of
    /// any fast [1] particle, by their speed class at that build (length).
    pub moved_bound: [f64; 2],
    /// Worker threads of the step.
    pub threads: usize,
    /// Whether a team of more than one thread binds thread t to the t-th CPU the process may
    /// run on, while it runs (when the team fits on distinct CPUs); the default.
    pub bind: bool,
    /// Whether the force evaluation before the first step advances the tangential springs by
    /// one step, as MercuryDPM's does (true, the default); LAMMPS and LIGGGHTS skip the
    /// history update during their setup (`update->setupflag`), which cross-runs mirror.
    pub setup_advances_history: bool,
    /// A barrier shared with other runs, on which thread 0 waits once a step, after the particle
    /// pass (where a team's threads meet); `None` for a normal run. `verdem bench` couples
    /// independent 1-thread runs by it to measure what this machine gives jobs that share no
    /// data but wait for each other once a step, as a team does.
    pub lockstep: Option<Arc<SpinBarrier>>,
    pub times: StageTimes,
    /// Set by the pair pass for both particles of every contact, read and cleared by the next
    /// particle pass: a particle without contacts skips the gather (its sum is exactly zero).
    /// In the developed shear state ~12 contacts join 3480 spheres at a time; scanning every free
    /// particle's pair slots instead took one thread 673 k instructions a step against 384 k
    /// (valgrind's callgrind, steps 2000 to 4000 from `mercury_t143.85`, 2026-11-23).
    touched: Vec<AtomicBool>,
    /// Whether each particle (memory order) was within a skin of a periodic face at the last
    /// build; the others cannot cross one before the next build and skip the wrap.
    near_face: Vec<bool>,
    /// Whether each particle (memory order) is quiet: its force and torque slots hold zero and
    /// its velocities have absorbed a +0 kick (no −0 component), so that a free flight changes
    /// neither and only drifts it. Cleared at every build and at the start of every run.
    quiet: Vec<bool>,
    /// Speed class of each particle (memory order) at the last build: 1 for the fast ones
    /// (faster than [`SLOW_FRACTION`] of the fastest free particle, and all prescribed ones),
    /// 0 for the others.
    kind: Vec<u8>,
    builder: NeighborBuilder,
    scratch: Scratch,
}

#[derive(Default)]
struct Scratch {
    order: Vec<u32>,
    /// The particles and ids in the new memory order, filled by the team and then swapped in.
    next: Particles,
    next_id: Vec<u32>,
    /// The pairs each chunk of a build's search found, concatenated into the pair list.
    found: Vec<(Vec<u32>, Vec<u32>)>,
    /// P and I of the pairs in their final order, filled by the team and then swapped in.
    next_p: Vec<u32>,
    next_i: Vec<u32>,
    old_keys: Vec<(u64, u32)>,
    old_xi: Vec<Vec3>,
    fill: Vec<u32>,
    /// Class and gap bin of each pair, `class · GAP_BINS + bin`, in build order.
    bin: Vec<u8>,
    /// Build-order index of each pair, in the order of the chunks' bins.
    sorted: Vec<u32>,
    /// Threads of the step.
    threads: usize,
    /// The particle pass's chunks: ranges of particles of equal cost.
    particle_chunks: Vec<(usize, usize)>,
    /// The pair pass's chunks: ranges of pairs of equal count, in build order.
    pair_chunks: Vec<(usize, usize)>,
    /// Bounds of each pair chunk's classes after sorting: class `c` is `ranges[c]..ranges[c +
    /// 1]`, each sorted by gap bin (see [`CLASSES`]).
    pair_ranges: Vec<[usize; CLASSES + 1]>,
    /// End of the live prefix of each pair chunk's classes (see `run`); reset at every build.
    live: Vec<[usize; CLASSES]>,
    /// Gap |r| − (r_P + r_I) of each pair at the build, rounded down to a sixteenth of the skin
    /// (length).
    gap: Vec<f64>,
    /// Lowest and one past the highest memory index of a particle of each pair chunk's pairs.
    pair_hull: Vec<(u32, u32)>,
    /// The pair chunks a particle chunk's gather waits for: every chunk with a pair of its
    /// particles is in this range of chunk indices (which may hold others).
    needs: Vec<(u32, u32)>,
}

impl Scratch {
    /// Chunks of each pass: one for a team of one.
    fn chunks(&self) -> usize {
        if self.threads == 1 {
            1
        } else {
            self.threads * CHUNKS_PER_THREAD
        }
    }

    /// Starts every pair chunk's live prefixes empty.
    fn reset_live(&mut self) {
        for (live, ranges) in self.live.iter_mut().zip(&self.pair_ranges) {
            live.copy_from_slice(&ranges[..CLASSES]);
        }
    }
}

/// Gap bins of the pair list: one of overlapping pairs, then sixteen of a sixteenth of the skin
/// each, and one more for the round-off at the cut.
const GAP_BINS: usize = 18;

/// Classes of pairs, each visited up to its own live end: `3·across + kind_P + kind_I`, where
/// `across` marks a pair that may need a periodic image before the next build and the kinds are
/// the particles' speed classes: a pair's gap closes at most by the sum of its particles' class
/// displacement bounds, so pairs of slow particles are visited later.
const CLASSES: usize = 6;

/// Chunks of each pass per thread when the team has more than one: enough that a thread done
/// early takes over a small piece of its partner's work (the wait at a pass's end is at most
/// about one chunk), few enough that starting chunks stays cheap. A chunk start costs about
/// 70 ns (an atomic operation and a fresh loop over each of the chunk's arrays): 16 chunks on
/// 1 thread ran 2.7 % and 4.9 % slower than one chunk (40 paired rounds each). On the 2-vCPU CI
/// machine 8 per thread ran 4.1–5.9 % faster than 16 (three readings of 40–60 paired rounds,
/// faster in 24–40 of them); 6 and 12 were within noise of 8. Without the barrier after the
/// pair pass, 4, 5 and 6 per thread were within 2.2 % of 8 either way and 12 was 5.4 % slower
/// (40 paired rounds each).
const CHUNKS_PER_THREAD: usize = 8;

/// A free particle is fast, at a build, when its speed exceeds this fraction of the fastest
/// free particle's.
const SLOW_FRACTION: f64 = 0.1;

/// How far a slow–slow [0], slow–fast [1] and fast–fast [2] pair can have closed its gap since
/// the last build, from the displacement bounds of a slow [0] and a fast [1] particle (length).
fn gap_closed(bound: [f64; 2]) -> [f64; 3] {
    [2.0 * bound[0], bound[0] + bound[1], 2.0 * bound[1]]
}

fn key(p: u32, i: u32) -> u64 {
    ((p as u64) << 32) | i as u64
}

impl Core {
    /// A state at step 0, time 0, with no forces evaluated yet; particles in id order.
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
            id: (0..particles.len() as u32).collect(),
            domain,
            particles,
            dt,
            gravity,
            step: 0,
            time: 0.0,
            pairs: PairList::default(),
            xi: Vec::new(),
            active: Vec::new(),
            out: Vec::new(),
            forces_ready: false,
            moved_bound: [0.0; 2],
            threads,
            bind: true,
            setup_advances_history: true,
            lockstep: None,
            times: StageTimes::default(),
            touched: Vec::new(),
            near_face: Vec::new(),
            quiet: Vec::new(),
            kind: Vec::new(),
            builder,
            scratch: Scratch {
                threads,
                ..Scratch::default()
            },
        }
    }

    /// Skin of the pair list (length).
    pub fn skin(&self) -> f64 {
        self.builder.skin
    }

    fn list_state(&mut self) -> ListState<'_> {
        ListState {
            particles: &mut self.particles,
            id: &mut self.id,
            pairs: &mut self.pairs,
            xi: &mut self.xi,
            active: &mut self.active,
            out: &mut self.out,
            builder: &mut self.builder,
            scratch: &mut self.scratch,
            times: &mut self.times,
            touched: &mut self.touched,
            near_face: &mut self.near_face,
            quiet: &mut self.quiet,
            kind: &mut self.kind,
        }
    }

    /// Re-orders the particles and rebuilds the pair list, keeping every contact's history.
    pub fn rebuild(&mut self) {
        let domain = self.domain.clone();
        self.list_state().rebuild(Crew::Solo, &domain);
        self.moved_bound = [0.0; 2];
    }

    /// Rebuilds the pair list and sets the given contacts (by original ids) as active with
    /// their history and force; used when resuming from a checkpoint.
    pub fn restore_contacts(&mut self, contacts: &[Contact]) {
        for k in 0..self.active.len() {
            self.active[k] = false;
            self.xi[k] = Vec3::zeros();
        }
        self.rebuild();
        let mut slot = std::collections::HashMap::new();
        for k in 0..self.pairs.p.len() {
            let (p, i) = (
                self.id[self.pairs.p[k] as usize],
                self.id[self.pairs.i[k] as usize],
            );
            slot.insert(key(p, i), k);
        }
        for c in contacts {
            if let Some(&k) = slot.get(&key(c.p, c.i)) {
                self.xi[k] = c.xi;
                self.out[k] = c.force;
                self.active[k] = true;
            }
        }
        self.forces_ready = true;
    }

    /// Number of pairs in contact at the last force evaluation.
    pub fn contact_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }

    /// The state in canonical order (allocates; for saves, hashes and checkpoints).
    pub fn snapshot(&self) -> Snapshot {
        let n = self.particles.len();
        let mut pos = vec![0usize; n];
        for (a, &id) in self.id.iter().enumerate() {
            pos[id as usize] = a;
        }
        let src = &self.particles;
        let mut particles = Particles::default();
        for &a in &pos {
            particles.x.push(src.x[a]);
            particles.v.push(src.v[a]);
            particles.w.push(src.w[a]);
            particles.radius.push(src.radius[a]);
            particles.inv_mass.push(src.inv_mass[a]);
            particles.inv_inertia.push(src.inv_inertia[a]);
            particles.motion.push(src.motion[a]);
            particles.f.push(src.f[a]);
            particles.t.push(src.t[a]);
        }
        let mut contacts: Vec<Contact> = (0..self.pairs.p.len())
            .filter(|&k| self.active[k])
            .map(|k| Contact {
                p: self.id[self.pairs.p[k] as usize],
                i: self.id[self.pairs.i[k] as usize],
                xi: self.xi[k],
                force: self.out[k],
            })
            .collect();
        contacts.sort_unstable_by_key(|c| key(c.p, c.i));
        Snapshot {
            step: self.step,
            time: self.time,
            domain: self.domain.clone(),
            particles,
            contacts,
        }
    }

    /// Overwrites the dynamic state from a canonical snapshot of the same scene.
    pub fn restore(&mut self, s: &Snapshot) {
        let n = self.particles.len();
        assert_eq!(n, s.particles.len(), "snapshot of another scene");
        self.id = (0..n as u32).collect();
        self.particles = s.particles.clone();
        self.step = s.step;
        self.time = s.time;
        self.restore_contacts(&s.contacts);
    }
}

/// A simulation: the state and the contact law that advances it.
pub struct Simulation<L: ContactLaw> {
    pub law: L,
    pub core: Core,
}

/// The law-independent face of a simulation, for the run loop and the tools.
pub trait Engine: Send {
    /// The state and settings the law does not own.
    fn core(&self) -> &Core;
    /// The same, to change between calls of [`Engine::advance`].
    fn core_mut(&mut self) -> &mut Core;
    /// Advances `steps` time steps (evaluating the initial forces first if needed).
    fn advance(&mut self, steps: u64);
}

impl<L: ContactLaw> Engine for Simulation<L> {
    fn core(&self) -> &Core {
        &self.core
    }
    fn core_mut(&mut self) -> &mut Core {
        &mut self.core
    }
    fn advance(&mut self, steps: u64) {
        if !self.core.forces_ready {
            self.initial_forces();
        }
        match (L::TANGENTIAL, self.core.gravity.is_some()) {
            (true, false) => self.run::<true, false>(steps),
            (true, true) => self.run::<true, true>(steps),
            (false, false) => self.run::<false, false>(steps),
            (false, true) => self.run::<false, true>(steps),
        }
    }
}

/// What every thread of a step reads: the law, the box and the shared particle arrays.
struct StepView<'a, L> {
    law: &'a L,
    domain: &'a Domain,
    dt: f64,
    gravity: Vec3,
    particles: Shared<&'a mut Particles>,
}

impl<L: ContactLaw> Simulation<L> {
    /// A simulation of `core` under the contact law `law`.
    pub fn new(law: L, core: Core) -> Self {
        Simulation { law, core }
    }

    /// MercuryDPM evaluates the forces once before the first step, at x_0 with v_0.
    fn initial_forces(&mut self) {
        self.core.rebuild();
        let c = &mut self.core;
        let parts = ParticleSlices::of(&c.particles);
        let dt = if c.setup_advances_history { c.dt } else { 0.0 };
        for k in 0..c.pairs.p.len() {
            let (p, i) = (c.pairs.p[k] as usize, c.pairs.i[k] as usize);
            pair_force::<L, true>(
                &self.law,
                &c.domain,
                dt,
                p,
                i,
                &parts,
                &mut c.xi[k],
                &mut c.active[k],
                &mut c.out[k],
            );
        }
        let pt = &mut c.particles;
        for a in 0..pt.len() {
            let (f, t) = gather(a, &c.pairs, &c.active, &c.out);
            pt.f[a] = f;
            pt.t[a] = t;
        }
        c.forces_ready = true;
    }

    fn run<const ROT: bool, const GRAV: bool>(&mut self, steps: u64) {
        if steps == 0 {
            return;
        }
        let core = &mut self.core;
        let threads = core.threads;
        let barrier = SpinBarrier::new(threads);
        // Each thread's largest squared speeds by kind, for even and odd steps: a thread may
        // write the next step's while another still reads this one's.
        let vmax2: Vec<[[AtomicU64; 2]; 2]> = (0..threads)
            .map(|_| std::array::from_fn(|_| [AtomicU64::new(0), AtomicU64::new(0)]))
            .collect();
        let chunks = core.scratch.chunks();
        let particle_queue = WorkQueue::new(threads, chunks);
        let pair_queue = WorkQueue::new(threads, chunks);
        let pairs_done = Marks::new(chunks);
        let rebuild_queue = WorkQueue::new(threads, chunks);
        let bind = core.bind && threads > 1;
        let skin = core.skin();
        let bound0 = core.moved_bound;
        // Velocities or forces may have been set since the last run.
        core.quiet.fill(false);
        core.scratch.reset_live();
        let domain = core.domain.clone();
        let lockstep = core.lockstep.clone();
        let view = StepView {
            law: &self.law,
            domain: &domain,
            dt: core.dt,
            gravity: core.gravity.unwrap_or_else(Vec3::zeros),
            particles: Shared::new(unsafe { &mut *(&mut core.particles as *mut Particles) }),
        };
        // The list state also reaches the particles (a rebuild re-orders them); thread 0 uses it
        // for that alone, while the other threads wait at a barrier.
        let list = Shared::new(core.list_state());
        let work = |tid: usize| {
            let _bound = if bind {
                Bound::to_nth_cpu(tid, threads)
            } else {
                None
            };
            let mut local = StageTimes::default();
            let mut clock = Instant::now();
            let mut lap = |slot: &mut u64| {
                if tid == 0 {
                    let now = Instant::now();
                    *slot += (now - clock).as_nanos() as u64;
                    clock = now;
                }
            };
            // The particle pass over the chunks this thread takes, gathering the forces of step
            // `gather` (none on the first step of a run) once every pair chunk with a pair of
            // the chunk's particles is done; the largest squared speeds.
            let particles = |gather: Option<u64>, drift: bool| {
                let mut v2 = [0.0f64; 2];
                let mut waited = 0;
                while let Some(c) = particle_queue.next(tid) {
                    // SAFETY: a chunk is run by one thread, and its pairs' outputs are final
                    // (their chunks are marked done); see the loop below.
                    let seen = unsafe {
                        let l = list.get();
                        let (a, b) = l.scratch.particle_chunks[c];
                        if let (Some(round), true) = (gather, threads > 1) {
                            let (first, end) = l.scratch.needs[c];
                            let w = pairs_done.wait(first as usize..end as usize, round);
                            waited += w.as_nanos() as u64;
                        }
                        particle_pass::<L, ROT, GRAV>(&view, l, a, b, gather.is_some(), drift)
                    };
                    for (m, s) in v2.iter_mut().zip(seen) {
                        *m = m.max(s);
                    }
                }
                (v2, waited)
            };
            let mut bound = bound0;
            for s in 0..steps {
                // SAFETY (all blocks below): the particle pass and the rebuild are separated from
                // everything else by barriers; the pair pass of a step and the particle pass
                // that gathers its forces are separated, chunk by chunk, by the pair chunks'
                // marks; in each phase a thread writes only the particles or pairs of the chunks
                // it takes, and a rebuild's serial phases run on thread 0 alone between two
                // barriers.
                let (v2, waited) = particles((s > 0).then_some(s), true);
                let parity = (s % 2) as usize;
                for (slot, v) in vmax2[tid][parity].iter().zip(v2) {
                    slot.store(v.to_bits(), Ordering::Relaxed);
                }
                lap(&mut local.integrate);
                local.count_wait_in_integrate(waited);
                barrier.wait();
                if let (0, Some(other_runs)) = (tid, &lockstep) {
                    other_runs.wait();
                }
                lap(&mut local.wait);
                // A home is refilled only once its last pass is over (no thread takes from an
                // emptied home); the pair queue starts full for the first step.
                particle_queue.refill(tid);
                if s > 0 {
                    pair_queue.refill(tid);
                }
                // Every thread derives the same bounds from the same numbers.
                for (kind, b) in bound.iter_mut().enumerate() {
                    let m = vmax2
                        .iter()
                        .map(|a| f64::from_bits(a[parity][kind].load(Ordering::Relaxed)))
                        .fold(0.0, f64::max);
                    *b += m.sqrt() * view.dt;
                }
                if gap_closed(bound).into_iter().fold(0.0, f64::max) > skin {
                    bound = [0.0; 2];
                    barrier.wait();
                    let crew = Crew::Member {
                        tid,
                        barrier: &barrier,
                        queue: &rebuild_queue,
                    };
                    unsafe { list.get().rebuild(crew, view.domain) };
                    barrier.wait();
                    lap(&mut local.neighbor);
                }
                // After a rebuild nothing has moved since the new build: its pair pass visits
                // only the pairs already touching, and the live ends grow from there.
                let closed = gap_closed(bound);
                while let Some(c) = pair_queue.next(tid) {
                    unsafe {
                        let l = list.get();
                        let seg = l.scratch.pair_ranges[c];
                        let ends = &mut l.scratch.live[c];
                        // A pair whose gap at the build exceeds what its particles can have
                        // closed cannot touch yet; its slot stays inactive, exactly as a full
                        // pass would leave it.
                        let gap = &l.scratch.gap;
                        for (class, end) in ends.iter_mut().enumerate() {
                            let reach = closed[class % 3] + 1e-9;
                            while *end < seg[class + 1] && gap[*end] <= reach {
                                *end += 1;
                            }
                        }
                        let ends = *ends;
                        pair_chunk(&view, l, &seg, &ends);
                    }
                    pairs_done.set(c, s + 1);
                }
                lap(&mut local.forces);
            }
            let (_, waited) = particles(Some(steps), false);
            lap(&mut local.integrate);
            local.count_wait_in_integrate(waited);
            (local, bound)
        };
        let (local, bound) = if threads == 1 {
            work(0)
        } else {
            std::thread::scope(|s| {
                for tid in 1..threads {
                    let work = &work;
                    s.spawn(move || work(tid));
                }
                work(0)
            })
        };
        let core = &mut self.core;
        core.times.forces += local.forces;
        core.times.integrate += local.integrate;
        core.times.wait += local.wait;
        core.moved_bound = bound;
        for _ in 0..steps {
            core.time += core.dt;
        }
        core.step += steps;
    }
}

/// The pair list, the particles it indexes, and everything that changes with them.
struct ListState<'a> {
    particles: &'a mut Particles,
    id: &'a mut Vec<u32>,
    pairs: &'a mut PairList,
    xi: &'a mut Vec<Vec3>,
    active: &'a mut Vec<bool>,
    out: &'a mut Vec<PairForce>,
    builder: &'a mut NeighborBuilder,
    scratch: &'a mut Scratch,
    times: &'a mut StageTimes,
    touched: &'a mut Vec<AtomicBool>,
    near_face: &'a mut Vec<bool>,
    quiet: &'a mut Vec<bool>,
    kind: &'a mut Vec<u8>,
}

/// Who runs a rebuild: the team, each thread between the same barriers, or one thread alone
/// (outside a run), which then does every chunk of each parallel phase itself.
#[derive(Clone, Copy)]
enum Crew<'b> {
    Solo,
    Member {
        tid: usize,
        barrier: &'b SpinBarrier,
        /// The chunks of the parallel phases, as many as the passes have.
        queue: &'b WorkQueue,
    },
}

impl Crew<'_> {
    /// Whether this thread does the serial phases.
    fn leads(self) -> bool {
        matches!(self, Crew::Solo | Crew::Member { tid: 0, .. })
    }

    /// Waits for the whole crew.
    fn sync(self) {
        if let Crew::Member { barrier, .. } = self {
            barrier.wait();
        }
    }

    /// A parallel phase: runs `job` on each of the `chunks` chunks this thread takes (all of
    /// them, alone), then waits for the whole crew.
    fn share(self, chunks: usize, mut job: impl FnMut(usize)) {
        match self {
            Crew::Solo => (0..chunks).for_each(job),
            Crew::Member {
                tid,
                barrier,
                queue,
            } => {
                while let Some(c) = queue.next(tid) {
                    job(c);
                }
                barrier.wait();
                // The next parallel phase starts after a serial one and its barrier.
                queue.refill(tid);
            }
        }
    }
}

/// Part `part` of `0..n` split into `parts` nearly equal contiguous ranges.
fn chunk(n: usize, parts: usize, part: usize) -> std::ops::Range<usize> {
    n * part / parts..n * (part + 1) / parts
}

/// `to[k] = from[order[k]]` for `k` in `range`.
fn permute_range<T: Copy>(from: &[T], to: &mut [T], order: &[u32], range: std::ops::Range<usize>) {
    for (t, &o) in to[range.clone()].iter_mut().zip(&order[range]) {
        *t = from[o as usize];
    }
}

impl ListState<'_> {
    /// Re-orders the particles by cell, rebuilds the pair list, carries every contact's history
    /// over (matched by original ids), and splits both passes into chunks. The serial phases
    /// run on the lead thread, the others (permutation, search, sorting of the pair chunks,
    /// history) in chunks that the crew shares out; the results do not depend on the crew.
    ///
    /// # Safety (team)
    /// Every thread of the crew calls this with the same arguments; in a parallel phase each
    /// writes only the ranges of the chunks it takes, and no vector is resized outside the
    /// lead's phases.
    fn rebuild(&mut self, crew: Crew<'_>, domain: &Domain) {
        let t0 = Instant::now();
        let s = &mut *self.scratch;
        let pt = &mut *self.particles;
        let n = pt.len();
        let chunks = s.chunks();
        if crew.leads() {
            // History of the contacts, by original ids.
            s.old_keys.clear();
            for k in 0..self.pairs.p.len() {
                if self.active[k] {
                    let (p, i) = (
                        self.id[self.pairs.p[k] as usize],
                        self.id[self.pairs.i[k] as usize],
                    );
                    s.old_keys.push((key(p, i), k as u32));
                }
            }
            s.old_keys.sort_unstable();
            std::mem::swap(&mut s.old_xi, self.xi);
            // Memory order by cell; the builder is then ready to search the re-ordered
            // particles.
            self.builder.order(domain, &pt.x, self.id, &mut s.order);
            if s.next.len() != n {
                // room only: every element is written below
                s.next = pt.clone();
            }
            s.next_id.resize(n, 0);
            s.found.resize_with(chunks, Default::default);
        }
        crew.sync();
        crew.share(chunks, |part| {
            let r = chunk(n, chunks, part);
            let (from, to, o) = (&*pt, &mut s.next, &s.order);
            permute_range(&from.x, &mut to.x, o, r.clone());
            permute_range(&from.v, &mut to.v, o, r.clone());
            permute_range(&from.w, &mut to.w, o, r.clone());
            permute_range(&from.f, &mut to.f, o, r.clone());
            permute_range(&from.t, &mut to.t, o, r.clone());
            permute_range(&from.radius, &mut to.radius, o, r.clone());
            permute_range(&from.inv_mass, &mut to.inv_mass, o, r.clone());
            permute_range(&from.inv_inertia, &mut to.inv_inertia, o, r.clone());
            permute_range(&from.motion, &mut to.motion, o, r.clone());
            permute_range(self.id, &mut s.next_id, o, r);
        });
        if crew.leads() {
            std::mem::swap(pt, &mut s.next);
            std::mem::swap(self.id, &mut s.next_id);
        }
        crew.sync();
        crew.share(chunks, |part| {
            let motion = &pt.motion;
            let (found_p, found_i) = &mut s.found[part];
            found_p.clear();
            found_i.clear();
            // Wall–wall pairs never interact (neighbouring wall spheres overlap by round-off).
            self.builder.search(
                domain,
                &pt.x,
                &pt.radius,
                self.id,
                chunk(n, chunks, part),
                |a, b| motion[a] == Motion::Free || motion[b] == Motion::Free,
                (found_p, found_i),
            );
        });
        if crew.leads() {
            self.pairs.p.clear();
            self.pairs.i.clear();
            for (found_p, found_i) in &s.found {
                self.pairs.p.extend_from_slice(found_p);
                self.pairs.i.extend_from_slice(found_i);
            }
            self.plan_chunks(domain);
        }
        crew.sync();
        crew.share(chunks, |part| self.sort_chunk(domain, part));
        if crew.leads() {
            let s = &mut *self.scratch;
            std::mem::swap(&mut self.pairs.p, &mut s.next_p);
            std::mem::swap(&mut self.pairs.i, &mut s.next_i);
            for (needs, &(a, b)) in s.needs.iter_mut().zip(&s.particle_chunks) {
                let hull = &s.pair_hull;
                let touches = |j: &usize| (hull[*j].0 as usize) < b && (hull[*j].1 as usize) > a;
                let first = (0..chunks).find(touches).unwrap_or(0);
                let end = (0..chunks).rev().find(touches).map_or(first, |j| j + 1);
                *needs = (first as u32, end as u32);
            }
            self.pairs.index(n, self.id, &mut s.fill);
            s.reset_live();
            self.times.neighbor += t0.elapsed().as_nanos() as u64;
            self.times.rebuilds += 1;
        }
    }

    /// Lead phase of a rebuild, once the pairs are found: the particles' flags and speed
    /// classes, the chunks of both passes, and room for the pairs' new order and history.
    fn plan_chunks(&mut self, domain: &Domain) {
        let s = &mut *self.scratch;
        let pt = &*self.particles;
        let n_pairs = self.pairs.p.len();
        // All clear between a particle pass and a pair pass; only the length can change.
        self.touched
            .resize_with(pt.len(), || AtomicBool::new(false));
        self.quiet.clear();
        self.quiet.resize(pt.len(), false);
        let fastest = (0..pt.len())
            .filter(|&a| pt.inv_mass[a] > 0.0)
            .map(|a| pt.v[a].norm())
            .fold(0.0, f64::max);
        let slow = SLOW_FRACTION * fastest;
        self.kind.clear();
        self.kind.extend(
            (0..pt.len()).map(|a| u8::from(pt.inv_mass[a] == 0.0 || pt.v[a].norm() > slow)),
        );
        // Chunks: contiguous particles (a slab of space) of equal cost, and contiguous pairs of
        // equal count; the pair list is in owner (memory, so space) order, so a chunk's pairs
        // lie mostly among one particle chunk and its neighbours.
        let inv_mass = &pt.inv_mass;
        let chunks = s.chunks();
        let weight = |a: usize| if inv_mass[a] > 0.0 { 8 } else { 2 };
        balanced_ranges(pt.len(), chunks, weight, &mut s.particle_chunks);
        balanced_ranges(n_pairs, chunks, |_| 1, &mut s.pair_chunks);
        let skin = self.builder.skin;
        let interior = |a: usize| {
            (0..3).all(|k| {
                !domain.periodic[k]
                    || (pt.x[a][k] >= domain.lo[k] + skin && pt.x[a][k] < domain.hi[k] - skin)
            })
        };
        self.near_face.clear();
        self.near_face.extend((0..pt.len()).map(|a| !interior(a)));
        s.bin.resize(n_pairs, 0);
        s.sorted.resize(n_pairs, 0);
        s.gap.resize(n_pairs, 0.0);
        s.next_p.resize(n_pairs, 0);
        s.next_i.resize(n_pairs, 0);
        s.pair_ranges.resize(chunks, [0; CLASSES + 1]);
        s.pair_hull.resize(chunks, (0, 0));
        s.needs.resize(chunks, (0, 0));
        s.live.resize(chunks, [0; CLASSES]);
        // Room only: each chunk clears its pairs' history in `sort_chunk`.
        self.xi.resize(n_pairs, Vec3::zeros());
        self.active.resize(n_pairs, false);
        self.out.resize(n_pairs, PairForce::default());
    }

    /// Parallel phase of a rebuild: chunk `part` of the pairs in its final order and with its
    /// history. Within a chunk, interior pairs (no periodic image needed until the next build)
    /// come first, then the others; each part in bins of gap (GAP_BINS − 1 bins of a sixteenth
    /// of the skin, after one of all overlapping pairs), each bin in build (owner memory) order.
    /// A step visits only the prefix of bins whose gap the particles can have closed (see
    /// `live`), in near-memory order.
    fn sort_chunk(&mut self, domain: &Domain, part: usize) {
        let s = &mut *self.scratch;
        let pt = &*self.particles;
        let (pa, pb) = s.pair_chunks[part];
        let skin = self.builder.skin;
        let bin_width = skin / 16.0;
        for k in pa..pb {
            let (p, i) = (self.pairs.p[k] as usize, self.pairs.i[k] as usize);
            let direct = pt.x[p] - pt.x[i];
            let r = domain.min_image(direct);
            let cut = pt.radius[p] + pt.radius[i] + skin;
            let plain = !self.near_face[p]
                && !self.near_face[i]
                && r == direct
                && (0..3).all(|k| !domain.periodic[k] || cut + skin < 0.5 * domain.lengths()[k]);
            let gap = r.norm() - (pt.radius[p] + pt.radius[i]);
            // floor(gap / width) + 1, clamped to the bins; the cast floors a non-negative
            // quotient without a call to libm's floor.
            let q = gap / bin_width;
            let bin = if skin > 0.0 && q >= 0.0 {
                (q as usize).min(GAP_BINS - 2) + 1
            } else {
                0
            };
            let class =
                3 * usize::from(!plain) + usize::from(self.kind[p]) + usize::from(self.kind[i]);
            s.bin[k] = (class * GAP_BINS + bin) as u8;
        }
        // A stable counting sort of the chunk by (class, bin).
        let mut next = [0usize; CLASSES * GAP_BINS];
        for &b in &s.bin[pa..pb] {
            next[b as usize] += 1;
        }
        let mut at = pa;
        for (b, n) in next.iter_mut().enumerate() {
            let count = *n;
            *n = at;
            // Lower edge of the bin; overlapping pairs (bin 0) are always visited.
            s.gap[at..at + count].fill((b % GAP_BINS) as f64 * bin_width - bin_width);
            at += count;
        }
        let mut ranges = [pb; CLASSES + 1];
        for (c, r) in ranges.iter_mut().take(CLASSES).enumerate() {
            *r = next[c * GAP_BINS];
        }
        s.pair_ranges[part] = ranges;
        for k in pa..pb {
            let slot = &mut next[s.bin[k] as usize];
            s.sorted[*slot] = k as u32;
            *slot += 1;
        }
        let mut hull = (u32::MAX, 0);
        for k in pa..pb {
            let from = s.sorted[k] as usize;
            let (p, i) = (self.pairs.p[from], self.pairs.i[from]);
            s.next_p[k] = p;
            s.next_i[k] = i;
            hull = (hull.0.min(p).min(i), hull.1.max(p + 1).max(i + 1));
        }
        s.pair_hull[part] = hull;
        self.xi[pa..pb].fill(Vec3::zeros());
        self.active[pa..pb].fill(false);
        if s.old_keys.is_empty() {
            return;
        }
        for k in pa..pb {
            let (pm, im) = (s.next_p[k] as usize, s.next_i[k] as usize);
            // A contact the particles have just left would be closed by the coming force
            // pass; close it here, since that pass may skip pairs with a positive gap.
            let sum = pt.radius[pm] + pt.radius[im];
            let touching = domain.min_image(pt.x[pm] - pt.x[im]).norm_squared() < sum * sum;
            if !touching {
                continue;
            }
            let (p, i) = (self.id[pm], self.id[im]);
            if let Ok(o) = s.old_keys.binary_search_by_key(&key(p, i), |e| e.0) {
                self.xi[k] = s.old_xi[s.old_keys[o].1 as usize];
                self.active[k] = true;
            }
        }
    }
}

/// Per-particle pass over `a..b`: with `kick_end`, gather the forces of the step that just
/// ended and apply the closing half kick; with `drift`, apply the opening half kick and the drift
/// of the next step. Returns the largest squared speed after the drift of a slow [0] and of a
/// fast [1] particle (speed classes of the last build).
///
/// # Safety
/// Writes particles `a..b` only; with `kick_end`, call it only once every pair chunk holding a
/// pair of these particles is done: it reads those pairs' outputs, and the pair chunks read the
/// particles it writes.
#[inline(never)]
unsafe fn particle_pass<L, const ROT: bool, const GRAV: bool>(
    view: &StepView<'_, L>,
    l: &mut ListState<'_>,
    a: usize,
    b: usize,
    kick_end: bool,
    drift: bool,
) -> [f64; 2] {
    let pt = view.particles.get();
    let dt = view.dt;
    // Four running maxima of each kind, one per lane j mod 4: a single one would chain every
    // particle's comparison to the previous one's.
    let mut vmax2 = [[0.0f64; 4]; 2];
    let mut see = |class: usize, j: usize, vp: Vec3| {
        let s2 = vp.norm_squared();
        let lane = &mut vmax2[class][j & 3];
        if s2 > *lane {
            *lane = s2;
        }
    };
    // Plain slices of this thread's range: bounds and base pointers stay in registers.
    let x = &mut pt.x[a..b];
    let v = &mut pt.v[a..b];
    let w = &mut pt.w[a..b];
    let f = &mut pt.f[a..b];
    let t = &mut pt.t[a..b];
    let inv_mass = &pt.inv_mass[a..b];
    let inv_inertia = &pt.inv_inertia[a..b];
    let touched = &l.touched[a..b];
    let near_face = &l.near_face[a..b];
    let kind = &l.kind[a..b];
    let quiet = &mut l.quiet[a..b];
    // Each particle's values are loaded once into locals and stored once: a store followed by
    // an overlapping wider load of the same vector stalls store forwarding.
    for j in 0..x.len() {
        let im = inv_mass[j];
        let drift_to = |vp: Vec3, xj: Vec3| {
            let mut xp = xj + vp * dt;
            if near_face[j] {
                view.domain.wrap(&mut xp);
            }
            xp
        };
        if im > 0.0 {
            // load, then store only if set: a swap would be a locked instruction
            let contact = kick_end && touched[j].load(Ordering::Relaxed);
            if !GRAV && kick_end && !contact {
                // Free flight: F = T = 0 exactly, so both half kicks add +0; (v + 0) + 0 = v + 0
                // bit for bit, which is v itself once v has absorbed one +0 (quiet).
                if !quiet[j] {
                    f[j] = Vec3::zeros();
                    t[j] = Vec3::zeros();
                    v[j] += Vec3::zeros();
                    if ROT {
                        w[j] += Vec3::zeros();
                    }
                    quiet[j] = true;
                }
                if drift {
                    let vp = v[j];
                    x[j] = drift_to(vp, x[j]);
                    see(kind[j] as usize, j, vp);
                }
                continue;
            }
            quiet[j] = false;
            let (fp, tp) = if kick_end {
                let g = if contact {
                    touched[j].store(false, Ordering::Relaxed);
                    gather(a + j, l.pairs, l.active, l.out)
                } else {
                    (Vec3::zeros(), Vec3::zeros())
                };
                f[j] = g.0;
                t[j] = g.1;
                g
            } else {
                (f[j], t[j])
            };
            // Half kick v += (F/m + g)·dt/2, ω += T/I·dt/2, in MercuryDPM's order of operations
            // (BaseParticle::integrateBeforeForceComputation); the closing kick of one step and
            // the opening kick of the next add the same increment twice.
            let acc = if GRAV {
                fp * im + view.gravity
            } else {
                fp * im
            };
            let dv = acc * 0.5 * dt;
            let mut vp = v[j];
            if kick_end {
                vp += dv;
            }
            if drift {
                vp += dv;
                x[j] = drift_to(vp, x[j]);
                see(kind[j] as usize, j, vp);
            }
            v[j] = vp;
            if ROT {
                let dw = tp * inv_inertia[j] * 0.5 * dt;
                let mut wp = w[j];
                if kick_end {
                    wp += dw;
                }
                if drift {
                    wp += dw;
                }
                w[j] = wp;
            }
        } else if drift {
            let vp = v[j];
            x[j] = drift_to(vp, x[j]);
            see(kind[j] as usize, j, vp);
        }
    }
    vmax2.map(|lanes| lanes.into_iter().fold(0.0, f64::max))
}

/// Sum of the forces and torques of particle `a`'s active pairs, in the order of partner ids.
#[inline(always)]
fn gather(a: usize, pairs: &PairList, active: &[bool], out: &[PairForce]) -> (Vec3, Vec3) {
    let mut f = Vec3::zeros();
    let mut t = Vec3::zeros();
    let (s, e) = (pairs.adj_start[a] as usize, pairs.adj_start[a + 1] as usize);
    for &entry in &pairs.adj[s..e] {
        let k = (entry >> 1) as usize;
        if active[k] {
            let o = &out[k];
            if entry & 1 == 0 {
                f += o.f;
                t += o.torque_p;
            } else {
                f -= o.f;
                t += o.torque_i;
            }
        }
    }
    (f, t)
}

/// Pair pass over one chunk: the live prefix `seg[c]..ends[c]` of each class `c`. The first
/// `CLASSES / 2` classes hold interior pairs, whose direct separation is their minimum image.
/// One call per chunk rather than per class: with 16 chunks on 1 thread, 464.5 k instructions
/// a step against 466.2 k (valgrind's callgrind, steps 2000 to 4000 from `mercury_t143.85`).
///
/// # Safety
/// Writes the slots of these pairs and the `touched` flags of their particles only; reads
/// particles, which no one writes before the chunk is marked done.
#[inline(never)]
unsafe fn pair_chunk<L: ContactLaw>(
    view: &StepView<'_, L>,
    l: &mut ListState<'_>,
    seg: &[usize; CLASSES + 1],
    ends: &[usize; CLASSES],
) {
    // Plain slices: their bounds live in registers for the whole loop.
    let parts = ParticleSlices::of(view.particles.get());
    let touched = &l.touched[..];
    let (p, i) = (&l.pairs.p[..], &l.pairs.i[..]);
    let (xi, active, out) = (&mut l.xi[..], &mut l.active[..], &mut l.out[..]);
    for class in 0..CLASSES {
        let (a, b) = (seg[class], ends[class]);
        if a == b {
            continue;
        }
        let slots = PairSlots {
            p: &p[a..b],
            i: &i[a..b],
            xi: &mut xi[a..b],
            active: &mut active[a..b],
            out: &mut out[a..b],
        };
        if class < CLASSES / 2 {
            pair_range::<L, false>(view, &parts, touched, slots);
        } else {
            pair_range::<L, true>(view, &parts, touched, slots);
        }
    }
}

/// A range of pairs and their slots.
struct PairSlots<'a> {
    p: &'a [u32],
    i: &'a [u32],
    xi: &'a mut [Vec3],
    active: &'a mut [bool],
    out: &'a mut [PairForce],
}

/// Forces of a range of pairs into their slots; sets the `touched` flag of the free particles
/// of every contact. `PERIODIC` false for interior pairs.
#[inline(always)]
fn pair_range<L: ContactLaw, const PERIODIC: bool>(
    view: &StepView<'_, L>,
    parts: &ParticleSlices<'_>,
    touched: &[AtomicBool],
    s: PairSlots<'_>,
) {
    for k in 0..s.p.len() {
        let (p, i) = (s.p[k] as usize, s.i[k] as usize);
        pair_force::<L, PERIODIC>(
            view.law,
            view.domain,
            view.dt,
            p,
            i,
            parts,
            &mut s.xi[k],
            &mut s.active[k],
            &mut s.out[k],
        );
        if s.active[k] {
            // only free particles gather (and clear their flag)
            for q in [p, i] {
                if parts.inv_mass[q] > 0.0 {
                    touched[q].store(true, Ordering::Relaxed);
                }
            }
        }
    }
}

/// The particle arrays a pair force reads.
struct ParticleSlices<'a> {
    x: &'a [Vec3],
    v: &'a [Vec3],
    w: &'a [Vec3],
    radius: &'a [f64],
    inv_mass: &'a [f64],
}

impl<'a> ParticleSlices<'a> {
    fn of(pt: &'a Particles) -> Self {
        ParticleSlices {
            x: &pt.x,
            v: &pt.v,
            w: &pt.w,
            radius: &pt.radius,
            inv_mass: &pt.inv_mass,
        }
    }
}

/// Force of pair (p, i) into its slot; a pair that is not touching forgets its history.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_force<L: ContactLaw, const PERIODIC: bool>(
    law: &L,
    domain: &Domain,
    dt: f64,
    p: usize,
    i: usize,
    pt: &ParticleSlices<'_>,
    xi: &mut Vec3,
    active: &mut bool,
    out: &mut PairForce,
) {
    let direct = pt.x[p] - pt.x[i];
    let r = if PERIODIC {
        domain.min_image(direct)
    } else {
        direct
    };
    let sum = pt.radius[p] + pt.radius[i];
    if r.norm_squared() >= sum * sum {
        if *active {
            *active = false;
            *xi = Vec3::zeros();
        }
        return;
    }
    let input = PairInput {
        r,
        rad_p: pt.radius[p],
        rad_i: pt.radius[i],
        v_p: pt.v[p],
        v_i: pt.v[i],
        w_p: pt.w[p],
        w_i: pt.w[i],
    };
    if let Some(kin) = input.kinematics() {
        *out = law.evaluate(&kin, xi, dt);
        *active = true;
    }
}

#[cfg(test)]
mod tests {
    use crate::case::Case;
    use crate::engine::{self, Overrides};
    use std::path::Path;

    /// The live prefix of every class of every pair chunk holds only pairs whose build gap the
    /// particles can have closed since the build (to within a gap bin), also after a rebuild
    /// inside a run. Runs of several lengths from MercuryDPM's developed state end at different
    /// distances from their last rebuild, so some end soon after one.
    #[test]
    fn after_a_rebuild_the_pair_pass_visits_only_pairs_within_reach() {
        let case = Case::load(Path::new("cases/shear_flow_quick.toml")).unwrap();
        let state = Path::new("data/states/mercury_t143.85.data");
        for steps in [800, 1000, 1200, 1400] {
            let scene = crate::scene::build(&case, Some(state)).unwrap();
            let o = Overrides {
                threads: Some(1),
                ..Overrides::default()
            };
            let mut e = engine::build(&case, scene, &o);
            e.advance(steps);
            let c = e.core();
            assert!(c.times.rebuilds >= 2, "no rebuild inside the run");
            let closed = super::gap_closed(c.moved_bound);
            let width = c.skin() / 16.0;
            let s = &c.scratch;
            for (seg, live) in s.pair_ranges.iter().zip(&s.live) {
                for (class, &end) in live.iter().enumerate() {
                    let widest = s.gap[seg[class]..end]
                        .iter()
                        .fold(f64::MIN, |m, &g| m.max(g));
                    assert!(
                        widest <= closed[class % 3] + width,
                        "{steps} steps: class {class} visits a gap of {widest} with {} closed",
                        closed[class % 3]
                    );
                }
            }
        }
    }
}
