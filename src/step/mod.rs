//! The time step, top to bottom, and the state it advances; what it runs on: the pair list
//! ([`neighbor`]) and the thread team ([`team`]).
//!
//! One step n → n+1 (MercuryDPM's order, `docs/benchmark.md` "How MercuryDPM computes it"):
//! 1. kick–drift of every free particle: v += (F/m + g)·dt/2, x += v·dt, ω += T/I·dt/2;
//!    prescribed (wall) particles: x += v·dt; positions wrap along periodic axes;
//! 2. the pair list is rebuilt when two particles may have closed a gap of a skin since the last
//!    build (displacement bounds Σ max|v|·dt, one per speed class of the build), so that no pair
//!    can have come closer than r_P + r_I unlisted;
//! 3. pair forces at the new positions with the half-step velocities, each pair into its own
//!    slot (its tangential history updated in place);
//! 4. wall contacts: every free sphere against every flat wall, each contact into its own slot
//!    ([`walls`]; nothing when the case has none);
//! 5. gather: each particle sums its slots in the order of its partners' ids, then its wall
//!    slots in the walls' order; kick:
//!    v += (F/m + g)·dt/2, ω += T/I·dt/2; t += dt (a running sum).
//!
//! On a step the run samples ([`Params::contact_every`]), thread 0 reads the active contacts
//! between 4 and 5 while the other threads wait; nothing is written.
//!
//! Steps 5 of one step and 1 of the next touch only one particle each, so they run fused in one
//! pass ([`integrate`]). With T threads every thread runs [`Worker::run`], the stages above by
//! name; each pass is cut into chunks (contiguous particles, contiguous pairs) that the threads
//! take from a [`WorkQueue`], their own share first and then what is left of the others'. The
//! threads meet once a step, after the particle pass (every thread needs every particle's new
//! position and the largest speeds, which decide a rebuild). After the pair pass ([`forces`])
//! they do not: each particle chunk waits only for the pair chunks that hold its particles'
//! pairs, marked done chunk by chunk ([`Marks`]). Which thread may touch which array between
//! two meetings is stated in [`arrays`]. No float is ever summed in an order that depends on the
//! thread count, the chunk a thread takes, the memory order of the particles, the skin or the
//! cell size, so results are bitwise identical for all.

mod arrays;
pub mod core;
pub mod counters;
mod energy;
pub mod engine;
mod forces;
pub mod guard;
mod integrate;
pub mod neighbor;
pub mod team;
pub mod walls;

use std::sync::atomic::{AtomicU64, Ordering};

use self::arrays::Arrays;
pub use self::core::{Core, MeetHook, Params, State};
pub use self::counters::StageTimes;
pub use self::energy::{Flows, LedgerRow, Reading};
pub use self::engine::Engine;
use self::forces::{book_dropped, contact_breach, pair_chunk, pair_force, PairView};
use self::guard::{Alarm, Failure};
use self::integrate::{gather, particle_pass, Kick};
use self::walls::{wall_chunk, WallViews};
use crate::contact::ContactLaw;
use crate::state::{Domain, SampledContact, Wall};
use crate::step::neighbor::rebuild::{self, gap_closed, ListState, CLASSES};
use crate::step::team::{Bound, Crew, Marks, Shared, SpinBarrier, WorkQueue};
use crate::Vec3;
use counters::Laps;

/// A simulation: the state and the contact law that advances it.
pub struct Simulation<L: ContactLaw> {
    pub law: L,
    /// Changed only through [`Engine`]'s methods: a change of velocities or forces must go
    /// through a rebuild ([`Engine::restore`]), which the run guard's carried energy and the
    /// particles' quiet flags rely on.
    pub(crate) core: Core<L::History>,
}

/// Steps of a window of the run guard's energy balance: short enough that a slow instability is
/// stopped long before a save of the benchmark (every 50000 steps), long enough that measuring
/// the energy (a pass over the particles and the pairs) and starting the team of threads again
/// cost nothing against the steps; `verdem run` advances in blocks of this length anyway.
pub const ENERGY_WINDOW: u64 = 2000;

impl<L: ContactLaw> Simulation<L> {
    /// [`Engine::advance`]: the initial forces if needed, then `steps` steps in windows of
    /// [`ENERGY_WINDOW`], each closed by the run guard's energy balance.
    fn advance_in_windows(&mut self, steps: u64) -> Result<(), Failure> {
        if self.core.failure.is_none() && !self.core.state.forces_ready {
            // The state given is checked before its forces are evaluated and saved, so that no
            // save or diagnostics row is made of velocities the guard would refuse.
            match guard::not_finite(&self.core.state.particles) {
                Some(b) => {
                    let state = &self.core.state;
                    self.core.failure = Some(b.report(state.step, state.time, &state.id));
                }
                None => self.initial_forces(),
            }
        }
        if steps == 0 || self.core.failure.is_some() {
            return self.core.failure.clone().map_or(Ok(()), Err);
        }
        // The steps run in windows, each closed by the run guard's energy balance; the first
        // starts from the last call's closing energy when nothing changed the state since.
        let mut left = steps;
        let mut before = match self.core.energy_at.take() {
            Some((step, e)) if step == self.core.state.step => e,
            _ => self.energy(),
        };
        while left > 0 && self.core.failure.is_none() {
            let window = left.min(ENERGY_WINDOW);
            let supplied = match (L::TANGENTIAL, self.core.params.gravity.is_some()) {
                (true, false) => self.run::<true, false>(window),
                (true, true) => self.run::<true, true>(window),
                (false, false) => self.run::<false, false>(window),
                (false, true) => self.run::<false, true>(window),
            };
            if self.core.failure.is_none() {
                let after = self.energy();
                self.check_balance(window, &before, &after, supplied);
                before = after;
            }
            left -= window;
        }
        if self.core.failure.is_none() {
            self.core.energy_at = Some((self.core.state.step, before));
        }
        self.core.failure.clone().map_or(Ok(()), Err)
    }

    /// The mechanical energy of the current state ([`energy::measure`]).
    fn energy(&self) -> energy::Energy {
        let c = &self.core;
        let s = &c.state;
        let mut e = energy::measure(
            &self.law,
            &s.particles,
            &s.domain,
            c.params.gravity,
            &c.pairs,
        );
        if !c.walls.walls.is_empty() {
            let pt = &s.particles;
            let held = c.walls.stored(&self.law, &pt.x, &pt.radius, &s.id);
            e.stored += energy::float(held);
        }
        e
    }

    /// The run guard's energy balance of the `steps` steps just run, from `before` to `after`
    /// with the work `supplied` (fixed point) of the walls and of gravity along periodic axes.
    fn check_balance(
        &mut self,
        steps: u64,
        before: &energy::Energy,
        after: &energy::Energy,
        supplied: i128,
    ) {
        let tolerance = self.core.params.guard.energy;
        let b = energy::Balance::of(before, after, energy::float(supplied), tolerance);
        if b.breached() {
            let state = &mut self.core.state;
            let breach = guard::Breach::Energy {
                particle: after.liveliest,
                steps,
                balance: b,
                kinetic: after.kinetic,
                stored: after.stored,
            };
            self.core.failure = Some(breach.report(state.step, state.time, &state.id));
            state.forces_ready = false;
        }
    }

    /// Rebuilds the pair list on this thread ([`Core::rebuild`]) and books the contacts it
    /// closed as the pair pass would have ([`forces::book_dropped`]).
    fn rebuild_booked(&mut self) {
        self.core.rebuild();
        book_dropped(&self.law, &self.core.pairs, &mut self.core.flows);
    }

    /// A simulation of `core` under the contact law `law`.
    pub fn new(law: L, core: Core<L::History>) -> Self {
        Simulation { law, core }
    }

    /// MercuryDPM evaluates the forces once before the first step, at x_0 with v_0. The run
    /// guard checks the positions first.
    fn initial_forces(&mut self) {
        self.rebuild_booked();
        let state = &self.core.state;
        if let Some(b) = guard::outside(&state.particles, &state.domain) {
            self.core.failure = Some(b.report(state.step, state.time, &state.id));
            return;
        }
        let params = &self.core.params;
        let dt = if params.setup_advances_history {
            params.dt
        } else {
            0.0
        };
        let domain = self.core.state.domain.clone();
        let arr = Arrays::of(&mut self.core.list_state());
        let n = arr.x.len();
        // SAFETY: one thread; the views were just taken and nothing else touches the arrays.
        unsafe {
            let view = PairView {
                law: &self.law,
                domain: &domain,
                dt,
                x: arr.x,
                v: arr.v,
                w: arr.w,
                radius: arr.radius.slice(0..n),
                inv_mass: arr.inv_mass.slice(0..n),
                motion: arr.motion.slice(0..n),
                overlap: self.core.params.guard.overlap,
                excess: self.core.params.guard.contact,
            };
            for k in 0..arr.p.len() {
                let (p, i) = (arr.p.get(k) as usize, arr.i.get(k) as usize);
                let slot = (
                    arr.history.at_mut(k),
                    arr.active.at_mut(k),
                    arr.out.at_mut(k),
                );
                pair_force::<L, true>(&view, p, i, slot);
            }
            if arr.active.slice(0..arr.active.len()).contains(&true) {
                if let Some(b) = contact_breach(&view, &arr, 0..arr.p.len()) {
                    let state = &self.core.state;
                    self.core.failure = Some(b.report(state.step, state.time, &state.id));
                }
            }
            let views = WallViews::of(&mut self.core.walls);
            let walls = self.core.walls.walls.clone();
            if !walls.is_empty() {
                let overlap = self.core.params.guard.overlap;
                let watch = wall_chunk(&self.law, &walls, &views, &arr, (0, n), dt, overlap);
                if let (Some(b), None) = (watch.breach, &self.core.failure) {
                    let state = &self.core.state;
                    self.core.failure = Some(b.report(state.step, state.time, &state.id));
                }
            }
            for a in 0..n {
                let (mut f, mut t) = gather(a, &arr);
                if views.count > 0 {
                    views.add_to(arr.id.get(a), &mut f, &mut t);
                }
                *arr.f.at_mut(a) = f;
                *arr.t.at_mut(a) = t;
            }
        }
        self.core.state.forces_ready = true;
    }

    /// Advances `steps` steps on the team: every thread runs [`Worker::run`]. Returns the work
    /// the walls and gravity along periodic axes did on the free particles, in fixed point.
    fn run<const ROT: bool, const GRAV: bool>(&mut self, steps: u64) -> i128 {
        if steps == 0 {
            return 0;
        }
        // The run guard: velocities set since the last run are checked once here; within the
        // run only contact forces can make them otherwise, and those are checked.
        if let Some(b) = guard::not_finite(&self.core.state.particles) {
            let state = &self.core.state;
            self.core.failure = Some(b.report(state.step, state.time, &state.id));
            return 0;
        }
        let bound = self.core.work.moved_bound;
        let domain = self.core.state.domain.clone();
        let team = Team::new(&mut self.core, &self.law, &domain);
        let done =
            team.on_every_thread(|tid| Worker::new(&team, tid, bound).run::<ROT, GRAV>(steps));
        let breach = team.alarm.take();
        self.close_run(done, breach)
    }

    /// Books what the threads of a run left (`done`, merged) into the core: counters, bounds,
    /// the steps and time reached, the ledgers' flows, and the run guard's first breach as the
    /// simulation's failure. Returns the work supplied, as [`Simulation::run`] does.
    fn close_run(&mut self, done: Done, breach: Option<(u64, guard::Breach)>) -> i128 {
        let core = &mut self.core;
        let dt = core.params.dt;
        core.counters.add_times(&done.times);
        core.counters.rebuilds += done.times.rebuilds;
        core.work.moved_bound = done.bound;
        core.deepest = core.deepest.max(done.deepest);
        core.pumped = core.pumped.max(done.pumped);
        core.contact_samples.extend(done.samples);
        core.walls.walls = done.walls;
        for _ in 0..done.steps {
            core.state.time += dt;
        }
        core.state.step += done.steps;
        let supplied = done.supplied;
        let mut flows = done.flows;
        // what the walls did not supply, gravity along periodic axes did
        flows.gravity_work = supplied - flows.wall_work;
        core.flows.add(&flows);
        if let Some((_, b)) = breach {
            let state = &mut core.state;
            core.failure = Some(b.report(state.step, state.time, &state.id));
            state.forces_ready = false;
        }
        supplied
    }
}

/// What a thread's run leaves: its counters, the displacement bounds at the end, the steps
/// completed (fewer than asked when the run guard stops the run: every thread stops at the same
/// meeting), the work supplied in its passes (fixed point), the ledgers' flows of its passes
/// (all but the work of gravity, which is in `supplied`), the largest overlap and the largest
/// excess of a contact's energy account it saw, and the contact samples it took.
struct Done {
    times: StageTimes,
    bound: [f64; 2],
    steps: u64,
    supplied: i128,
    flows: Flows,
    deepest: f64,
    pumped: f64,
    samples: Vec<(u64, Vec<SampledContact>)>,
    /// The flat walls where this thread's drifts left them (every thread's are the same).
    walls: Vec<Wall>,
}

impl Done {
    /// Adds what another thread of the same run left.
    fn merge(&mut self, theirs: Done) {
        // an integer sum: the same in any order of the threads
        self.supplied += theirs.supplied;
        self.flows.add(&theirs.flows);
        self.deepest = self.deepest.max(theirs.deepest);
        self.pumped = self.pumped.max(theirs.pumped);
        self.samples.extend(theirs.samples);
    }
}

/// What the threads of a run share.
struct Team<'a, L: ContactLaw> {
    threads: usize,
    bind: bool,
    barrier: SpinBarrier,
    /// Each thread's largest squared speeds by kind (f64 bits), for even and odd steps: a thread
    /// may write the next step's while another still reads this one's.
    speeds: Vec<[[AtomicU64; 2]; 2]>,
    particle_queue: WorkQueue,
    pair_queue: WorkQueue,
    /// Each pair chunk's last step done, for the gathers that wait for it.
    pairs_done: Marks,
    /// The wall stage's particle chunks, and each one's last step done.
    wall_queue: WorkQueue,
    walls_done: Marks,
    /// The flat walls at the run's start and the views of their contact slots.
    walls: Vec<Wall>,
    wall_views: WallViews<L::History>,
    rebuild_queue: WorkQueue,
    list: Shared<ListState<'a, L::History>>,
    arrays: Shared<Arrays<L::History>>,
    meet: Option<MeetHook>,
    law: &'a L,
    /// Limits of the run guard.
    guard: crate::case::Guard,
    /// The first breach of the run guard's limits.
    alarm: Alarm,
    kick: Kick<'a>,
    skin: f64,
    /// A contact sample at every step that is a multiple of it (0: none).
    contact_every: u64,
    /// The step the run starts from.
    first_step: u64,
}

impl<'a, L: ContactLaw> Team<'a, L> {
    /// The team of a run of `core` under `law` in the box `domain` (the state's, borrowed for
    /// the run): `core.params.threads` threads, work queues of the chunks of the current plan
    /// (their live ends reset), the shared views of the arrays, and the step's parameters.
    fn new(core: &'a mut Core<L::History>, law: &'a L, domain: &'a Domain) -> Self {
        let threads = core.params.threads;
        let chunks = core.work.plan.chunks(core.state.particles.len());
        let skin = core.work.builder.skin;
        core.work.plan.reset_live();
        let params = &core.params;
        let (dt, meet, bind) = (params.dt, params.meet.clone(), params.bind);
        let (contact_every, first_step) = (params.contact_every, core.state.step);
        let guard = params.guard;
        let gravity = params.gravity.unwrap_or_else(Vec3::zeros);
        let periodic_gravity = params
            .gravity
            .map(|g| energy::periodic_part(g, domain))
            .filter(|g| *g != Vec3::zeros());
        let walls = core.walls.walls.clone();
        let wall_views = WallViews::of(&mut core.walls);
        let mut list = core.list_state();
        let arrays = Shared::new(Arrays::of(&mut list));
        Team {
            threads,
            bind: bind && threads > 1,
            barrier: SpinBarrier::new(threads),
            speeds: (0..threads)
                .map(|_| std::array::from_fn(|_| [AtomicU64::new(0), AtomicU64::new(0)]))
                .collect(),
            particle_queue: WorkQueue::new(threads, chunks),
            pair_queue: WorkQueue::new(threads, chunks),
            pairs_done: Marks::new(chunks),
            wall_queue: WorkQueue::new(threads, chunks),
            walls_done: Marks::new(chunks),
            walls,
            wall_views,
            rebuild_queue: WorkQueue::new(threads, chunks),
            list: Shared::new(list),
            arrays,
            meet,
            law,
            guard,
            alarm: Alarm::default(),
            kick: Kick {
                domain,
                dt,
                gravity,
                periodic_gravity,
            },
            skin,
            contact_every,
            first_step,
        }
    }

    /// Runs `work_of(tid)` on every thread of the team, thread 0 on this one and the others
    /// spawned for the run, and merges what they leave in thread order ([`Done::merge`]). A
    /// thread's panic is resumed here.
    fn on_every_thread(&self, work_of: impl Fn(usize) -> Done + Sync) -> Done {
        if self.threads == 1 {
            return work_of(0);
        }
        std::thread::scope(|s| {
            let handles: Vec<_> = (1..self.threads)
                .map(|tid| {
                    let work_of = &work_of;
                    s.spawn(move || work_of(tid))
                })
                .collect();
            let mut mine = work_of(0);
            for h in handles {
                mine.merge(h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
            }
            mine
        })
    }
}

/// One thread of a run: its share of every stage, and its own counters.
struct Worker<'t, 'a, L: ContactLaw> {
    team: &'t Team<'a, L>,
    tid: usize,
    /// Views of the shared arrays, refreshed after every rebuild.
    arr: Arrays<L::History>,
    /// Displacement bounds since the last build of a slow [0] and a fast [1] particle (length).
    bound: [f64; 2],
    times: StageTimes,
    laps: Laps,
    /// Work of the walls and of gravity along periodic axes on the free particles in this
    /// thread's passes, in fixed point (the run guard's energy balance).
    supplied: i128,
    /// The ledgers' flows in this thread's pair passes (the walls' work among them).
    flows: Flows,
    /// Largest overlap of its pair passes, as a fraction of the smaller radius.
    deepest: f64,
    /// Largest excess of a contact's energy account in its pair passes, as a fraction of what
    /// the contact took.
    pumped: f64,
    /// The contact samples it took (thread 0 only).
    samples: Vec<(u64, Vec<SampledContact>)>,
    /// The flat walls where they are at this step: every thread moves its own copy at its
    /// drifts, by the same arithmetic.
    walls: Vec<Wall>,
}

impl<'t, 'a, L: ContactLaw> Worker<'t, 'a, L> {
    fn new(team: &'t Team<'a, L>, tid: usize, bound: [f64; 2]) -> Self {
        Worker {
            team,
            tid,
            // SAFETY: the views are only read until thread 0 retakes them after a rebuild.
            arr: unsafe { *team.arrays.read() },
            bound,
            times: StageTimes::default(),
            laps: Laps::new(tid == 0),
            supplied: 0,
            flows: Flows::default(),
            deepest: 0.0,
            pumped: 0.0,
            samples: Vec::new(),
            walls: team.walls.clone(),
        }
    }

    /// The step loop of this thread, as named stages.
    fn run<const ROT: bool, const GRAV: bool>(mut self, steps: u64) -> Done {
        let _bound = if self.team.bind {
            Bound::to_nth_cpu(self.tid, self.team.threads)
        } else {
            None
        };
        for s in 0..steps {
            let speeds = self.kick_and_drift::<ROT, GRAV>((s > 0).then_some(s), true);
            self.publish_speeds(s, speeds);
            self.meet();
            if self.team.alarm.raised() {
                return self.done(s);
            }
            self.refill_queues(s);
            if self.skin_used_up(s) {
                self.rebuild(s);
            }
            self.pair_forces(s);
            self.wall_contacts(s);
            self.sample_contacts(s);
        }
        self.kick_and_drift::<ROT, GRAV>(Some(steps), false);
        self.done(steps)
    }

    /// What this thread leaves after `steps` steps.
    fn done(&mut self, steps: u64) -> Done {
        Done {
            times: self.times,
            bound: self.bound,
            steps,
            supplied: self.supplied,
            flows: self.flows,
            deepest: self.deepest,
            pumped: self.pumped,
            samples: std::mem::take(&mut self.samples),
            walls: self.walls.clone(),
        }
    }

    /// Particle pass over the chunks this thread takes: the closing kick of step `gather` (none
    /// on the first step of a run), once every pair chunk with a pair of the chunk's particles is
    /// done, then, with `drift`, the opening kick and drift of the next. Returns the largest
    /// squared speeds of slow [0] and fast [1] particles.
    fn kick_and_drift<const ROT: bool, const GRAV: bool>(
        &mut self,
        gather: Option<u64>,
        drift: bool,
    ) -> [f64; 2] {
        let team = self.team;
        let mut v2 = [0.0f64; 2];
        let mut waited = 0;
        while let Some(c) = team.particle_queue.next(self.tid) {
            // SAFETY: a chunk is taken by one thread; its pairs' chunks are done (the wait below)
            // before it gathers; the views are current (see `Worker::rebuild`).
            let seen = unsafe {
                let (a, b) = self.arr.particle_chunks.get(c);
                if let (Some(round), true) = (gather, team.threads > 1) {
                    let (first, end) = self.arr.needs.get(c);
                    let w = team.pairs_done.wait(first as usize..end as usize, round);
                    waited += w.as_nanos() as u64;
                    if team.wall_views.count > 0 {
                        waited += team.walls_done.wait(c..c + 1, round).as_nanos() as u64;
                    }
                }
                particle_pass::<L::History, ROT, GRAV>(
                    &team.kick,
                    (&self.arr, &team.wall_views),
                    a,
                    b,
                    gather.is_some(),
                    drift,
                    &mut self.supplied,
                )
            };
            for (m, x) in v2.iter_mut().zip(seen) {
                *m = m.max(x);
            }
        }
        if drift {
            // a wall moves rigidly, x += v·dt, as a prescribed sphere does
            for w in &mut self.walls {
                w.point += w.velocity * team.kick.dt;
            }
        }
        self.laps.lap(&mut self.times.integrate);
        self.times.count_wait_in_integrate(waited);
        v2
    }

    /// Publishes this thread's largest squared speeds of step `s` for the others.
    fn publish_speeds(&self, s: u64, v2: [f64; 2]) {
        let slots = &self.team.speeds[self.tid][(s % 2) as usize];
        for (slot, v) in slots.iter().zip(v2) {
            slot.store(v.to_bits(), Ordering::Relaxed);
        }
    }

    /// The threads meet: every particle has drifted and every speed is published.
    fn meet(&mut self) {
        self.team.barrier.wait();
        if let (0, Some(hook)) = (self.tid, &self.team.meet) {
            hook();
        }
        self.laps.lap(&mut self.times.wait);
    }

    /// A queue's chunks are handed out again only once its last pass is over (no thread takes
    /// from an emptied home); the pair queue starts full for the first step.
    fn refill_queues(&self, s: u64) {
        self.team.particle_queue.refill(self.tid);
        if s > 0 {
            self.team.pair_queue.refill(self.tid);
            if self.team.wall_views.count > 0 {
                self.team.wall_queue.refill(self.tid);
            }
        }
    }

    /// Grows the displacement bounds by the fastest speeds of step `s` times dt; true when two
    /// particles may have closed a gap of a skin since the last build. Every thread derives the
    /// same bounds from the same numbers.
    fn skin_used_up(&mut self, s: u64) -> bool {
        let parity = (s % 2) as usize;
        for (kind, b) in self.bound.iter_mut().enumerate() {
            let m = self
                .team
                .speeds
                .iter()
                .map(|a| f64::from_bits(a[parity][kind].load(Ordering::Relaxed)))
                .fold(0.0, f64::max);
            *b += m.sqrt() * self.team.kick.dt;
        }
        gap_closed(self.bound).into_iter().fold(0.0, f64::max) > self.team.skin
    }

    /// The team rebuilds the pair list between two barriers; thread 0 then books the contacts
    /// the rebuild closed (as this step's pair pass would have: [`forces::book_dropped`]),
    /// retakes the views and checks every position (the run guard; a breach stops the run at
    /// the next meeting).
    fn rebuild(&mut self, s: u64) {
        let team = self.team;
        self.bound = [0.0; 2];
        team.barrier.wait();
        let crew = Crew::Member {
            tid: self.tid,
            barrier: &team.barrier,
            queue: &team.rebuild_queue,
        };
        // SAFETY: every thread calls it and holds no reference into the list across it.
        unsafe { rebuild::rebuild(crew, &team.list, team.kick.domain) };
        if self.tid == 0 {
            // SAFETY: the other threads wait at the barrier below and read the views after it.
            let l = unsafe { team.list.exclusive() };
            if let Some(b) = guard::outside(l.particles, team.kick.domain) {
                team.alarm.raise(s, b);
            }
            book_dropped(team.law, l.pairs, &mut self.flows);
            // SAFETY: as above.
            unsafe { *team.arrays.exclusive() = Arrays::of(l) };
            self.times.rebuilds += 1;
        }
        team.barrier.wait();
        // SAFETY: thread 0 wrote the views before the barrier; nobody writes them until the next
        // rebuild.
        self.arr = unsafe { *team.arrays.read() };
        self.laps.lap(&mut self.times.neighbor);
    }

    /// Wall stage of step `s` over the particle chunks this thread takes, each marked done for
    /// its gather: every free sphere against every flat wall ([`walls::wall_chunk`]). Nothing
    /// when the case has no walls.
    fn wall_contacts(&mut self, s: u64) {
        let team = self.team;
        if team.wall_views.count == 0 {
            return;
        }
        let (dt, overlap) = (team.kick.dt, team.guard.overlap);
        while let Some(c) = team.wall_queue.next(self.tid) {
            // SAFETY: a chunk is taken by one thread; its particles are written by the particle
            // pass only after this chunk is marked done; their wall slots are theirs alone.
            let watch = unsafe {
                let chunk = self.arr.particle_chunks.get(c);
                let (law, views) = (team.law, &team.wall_views);
                wall_chunk(law, &self.walls, views, &self.arr, chunk, dt, overlap)
            };
            self.supplied += watch.wall_work;
            self.flows.add(&watch.flows);
            self.flows.wall_work += watch.wall_work;
            if let Some(b) = watch.breach {
                team.alarm.raise(s, b);
            }
            team.walls_done.set(c, s + 1);
        }
        self.laps.lap(&mut self.times.forces);
    }

    /// Thread 0 takes a contact sample of the step that the pair pass of step `s` has just
    /// evaluated when the run samples it ([`Params::contact_every`]); the team's other threads
    /// wait meanwhile, so that no position moves under it.
    fn sample_contacts(&mut self, s: u64) {
        let team = self.team;
        let step = team.first_step + s + 1;
        if team.contact_every == 0 || !step.is_multiple_of(team.contact_every) {
            return;
        }
        if team.threads > 1 {
            team.barrier.wait();
        }
        if self.tid == 0 {
            let (arr, n, pairs) = (&self.arr, self.arr.x.len(), self.arr.p.len());
            // SAFETY: every pair chunk of the step is done (each thread finished its pair pass
            // before the barrier above) and the other threads wait at the barrier below, so
            // nothing writes these arrays while they are read; the ids change only in a rebuild.
            let contacts = unsafe {
                core::contacts_of(
                    (
                        arr.x.slice(0..n),
                        arr.radius.slice(0..n),
                        team.list.read().id,
                    ),
                    (arr.p.slice(0..pairs), arr.i.slice(0..pairs)),
                    (arr.active.slice(0..pairs), arr.out.slice(0..pairs)),
                )
            };
            self.samples.push((step, contacts));
        }
        if team.threads > 1 {
            team.barrier.wait();
        }
        self.laps.lap(&mut self.times.wait);
    }

    /// Pair pass of step `s` over the chunks this thread takes, each marked done for the
    /// gathers. After a rebuild nothing has moved since the build: the pass visits only the pairs
    /// already touching, and the live ends grow from there.
    fn pair_forces(&mut self, s: u64) {
        let team = self.team;
        let closed = gap_closed(self.bound);
        let arr = &self.arr;
        let n = arr.x.len();
        // SAFETY: radii and masses are written only by a rebuild; every chunk is taken by one
        // thread; the particle pass writes a particle only after the chunks of its pairs are done.
        unsafe {
            let view = PairView {
                law: team.law,
                domain: team.kick.domain,
                dt: team.kick.dt,
                x: arr.x,
                v: arr.v,
                w: arr.w,
                radius: arr.radius.slice(0..n),
                inv_mass: arr.inv_mass.slice(0..n),
                motion: arr.motion.slice(0..n),
                overlap: team.guard.overlap,
                excess: team.guard.contact,
            };
            let touched = arr.touched.slice(0..n);
            while let Some(c) = team.pair_queue.next(self.tid) {
                let watch = pair_chunk(&view, arr, touched, c, closed);
                self.supplied += watch.wall_work;
                self.flows.add(&watch.flows);
                self.flows.wall_work += watch.wall_work;
                self.deepest = self.deepest.max(watch.worst);
                self.pumped = self.pumped.max(watch.pumped);
                if watch.worst > team.guard.overlap || watch.pumped > team.guard.contact {
                    let (seg, ends) = (arr.pair_ranges.get(c), arr.live.get(c));
                    let live = (0..CLASSES).flat_map(|class| seg[class]..ends[class]);
                    if let Some(b) = contact_breach(&view, arr, live) {
                        team.alarm.raise(s, b);
                    }
                }
                team.pairs_done.set(c, s + 1);
            }
        }
        self.laps.lap(&mut self.times.forces);
    }
}

#[cfg(test)]
mod tests {
    use super::{Core, Simulation};
    use crate::case::Case;
    use crate::contact::ContactLaw;
    use crate::step::engine::Scene;
    use crate::step::engine::{self, LawVisitor};
    use crate::step::neighbor::NeighborBuilder;
    use std::path::Path;

    /// Runs `steps` steps of the scene on one thread under the case's law, then checks the
    /// live prefixes of the pair chunks.
    struct RunAndCheck {
        scene: Scene,
        dt: f64,
        skin: f64,
        search: crate::case::Search,
        steps: u64,
    }

    impl LawVisitor for RunAndCheck {
        type Output = ();
        fn visit<L: ContactLaw + Clone + 'static>(self, law: L) {
            let builder = NeighborBuilder::new(self.skin, 0.0, 0.5, self.search);
            let core = Core::new(
                self.scene.domain,
                self.scene.particles,
                self.dt,
                None,
                builder,
                1,
            );
            let mut sim = Simulation::new(law, core);
            super::Engine::advance(&mut sim, self.steps).unwrap();
            let (c, steps) = (&sim.core, self.steps);
            assert!(c.counters.rebuilds >= 2, "no rebuild inside the run");
            let closed = super::gap_closed(c.work.moved_bound);
            let width = c.skin() / 16.0;
            let plan = &c.work.plan;
            for (seg, live) in plan.pair_ranges.iter().zip(&plan.live) {
                for (class, &end) in live.iter().enumerate() {
                    let widest = plan.gap[seg[class]..end]
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

    /// The live prefix of every class of every pair chunk holds only pairs whose build gap the
    /// particles can have closed since the build (to within a gap bin), also after a rebuild
    /// inside a run. Runs of several lengths from MercuryDPM's developed state end at different
    /// distances from their last rebuild, so some end soon after one.
    #[test]
    fn after_a_rebuild_the_pair_pass_visits_only_pairs_within_reach() {
        let case = Case::load(Path::new("cases/shear_flow_quick.toml")).unwrap();
        let state = Path::new("data/states/mercury_t143.85.data");
        for steps in [800, 1000, 1200, 1400] {
            let run = RunAndCheck {
                scene: crate::scene::build(&case, Some(state)).unwrap(),
                dt: case.dt(),
                skin: case.neighbor.skin,
                search: case.neighbor.search,
                steps,
            };
            engine::with_law(&case, run).unwrap();
        }
    }
}
