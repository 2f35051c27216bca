//! The time step, top to bottom, and the state it advances.
//!
//! One step n → n+1 (MercuryDPM's order, `benchmark.md` "How MercuryDPM computes it"):
//! 1. kick–drift of every free particle: v += (F/m + g)·dt/2, x += v·dt, ω += T/I·dt/2;
//!    prescribed (wall) particles: x += v·dt; positions wrap along periodic axes;
//! 2. the pair list is rebuilt when the displacement bound Σ max|v|·dt since the last build
//!    exceeds half the skin (no pair can then have come closer than r_P + r_I unlisted);
//! 3. pair forces at the new positions with the half-step velocities, each pair into its own
//!    slot (its tangential history updated in place);
//! 4. gather: each particle sums its slots in the order of its partners' ids; kick:
//!    v += (F/m + g)·dt/2, ω += T/I·dt/2; t += dt (a running sum).
//!
//! Steps 4 of one step and 1 of the next touch only one particle each, so they run fused in one
//! pass. With T threads every thread runs this loop on its own particles and pairs, and the
//! threads meet at a barrier after the per-particle pass and after the pair pass: two barriers
//! per step. No float is ever summed in an order that depends on the thread count, so results
//! are bitwise identical for any number of threads, any skin and any cell size.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use crate::contact::{ContactLaw, PairForce, PairInput, PairKinematics};
use crate::domain::Domain;
use crate::neighbor::{carry_history, NeighborBuilder, PairList};
use crate::state::{Motion, Particles};
use crate::team::{balanced_ranges, Shared, SpinBarrier};
use crate::Vec3;

/// Wall-clock time spent in each stage, in nanoseconds, measured on thread 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageTimes {
    /// Pair-list rebuilds.
    pub neighbor: u64,
    /// Pair forces.
    pub forces: u64,
    /// Gather of pair forces, kicks and drifts (per-particle pass).
    pub integrate: u64,
    /// Waiting for the other threads at barriers.
    pub wait: u64,
    /// Number of pair-list rebuilds.
    pub rebuilds: u64,
}

/// Everything a step advances, independent of the contact law.
pub struct Core {
    pub domain: Domain,
    pub particles: Particles,
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
    /// Upper bound of any particle's displacement since the last pair-list build (length).
    pub moved_bound: f64,
    /// Worker threads of the step.
    pub threads: usize,
    pub times: StageTimes,
    builder: NeighborBuilder,
    scratch: Scratch,
}

#[derive(Default)]
struct Scratch {
    old_p: Vec<u32>,
    old_i: Vec<u32>,
    old_xi: Vec<Vec3>,
    old_active: Vec<bool>,
    particle_ranges: Vec<(usize, usize)>,
    pair_ranges: Vec<(usize, usize)>,
}

impl Core {
    /// A state at step 0, time 0, with no forces evaluated yet.
    pub fn new(
        domain: Domain,
        particles: Particles,
        dt: f64,
        gravity: Option<Vec3>,
        builder: NeighborBuilder,
        threads: usize,
    ) -> Self {
        Core {
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
            moved_bound: 0.0,
            threads: threads.max(1),
            times: StageTimes::default(),
            builder,
            scratch: Scratch::default(),
        }
    }

    /// Skin of the pair list (length).
    pub fn skin(&self) -> f64 {
        self.builder.skin
    }

    /// Rebuilds the pair list at the current positions, keeping every pair's history.
    pub fn rebuild(&mut self) {
        if self.scratch.particle_ranges.is_empty() {
            self.scratch.particle_ranges = vec![(0, 0); self.threads];
        }
        let mut l = ListState {
            pairs: &mut self.pairs,
            xi: &mut self.xi,
            active: &mut self.active,
            out: &mut self.out,
            builder: &mut self.builder,
            scratch: &mut self.scratch,
            times: &mut self.times,
            motion: &self.particles.motion,
        };
        l.rebuild(
            &self.domain,
            &self.particles.x,
            &self.particles.radius,
            &self.particles.inv_mass,
        );
    }

    /// Rebuilds the pair list and sets the listed contacts (canonical order) as active with
    /// their history and force; used when resuming from a checkpoint.
    pub fn restore_contacts(&mut self, p: &[u32], i: &[u32], contacts: &[(Vec3, PairForce)]) {
        self.xi.clear();
        self.active.clear();
        self.pairs = PairList::default();
        self.rebuild();
        let saved: Vec<Option<(Vec3, PairForce)>> = contacts.iter().copied().map(Some).collect();
        let mut slots = Vec::new();
        carry_history(p, i, &saved, &self.pairs, &mut slots);
        for (k, slot) in slots.into_iter().enumerate() {
            if let Some((xi, out)) = slot {
                self.xi[k] = xi;
                self.out[k] = out;
                self.active[k] = true;
            }
        }
        self.forces_ready = true;
    }

    /// The contact geometry of pair `k` at the current positions (velocities not included), or
    /// `None` when it is not touching. Used for output; recomputes exactly what the force pass
    /// computed for n, δ and the contact point.
    pub fn pair_geometry(&self, k: usize) -> Option<PairKinematics> {
        let (p, i) = (self.pairs.p[k] as usize, self.pairs.i[k] as usize);
        let x = &self.particles.x;
        PairInput {
            r: self.domain.min_image(x[p] - x[i]),
            rad_p: self.particles.radius[p],
            rad_i: self.particles.radius[i],
            v_p: Vec3::zeros(),
            v_i: Vec3::zeros(),
            w_p: Vec3::zeros(),
            w_i: Vec3::zeros(),
        }
        .kinematics()
    }

    /// Number of pairs in contact at the last force evaluation.
    pub fn contact_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }
}

/// A simulation: the state and the contact law that advances it.
pub struct Simulation<L: ContactLaw> {
    pub law: L,
    pub core: Core,
}

/// The law-independent face of a simulation, for the run loop and the tools.
pub trait Engine: Send {
    fn core(&self) -> &Core;
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

/// Shared views of the arrays a step touches, handed to every thread.
struct StepView<'a, L> {
    law: &'a L,
    domain: &'a Domain,
    dt: f64,
    gravity: Vec3,
    x: Shared<&'a mut [Vec3]>,
    v: Shared<&'a mut [Vec3]>,
    w: Shared<&'a mut [Vec3]>,
    f: Shared<&'a mut [Vec3]>,
    t: Shared<&'a mut [Vec3]>,
    radius: &'a [f64],
    inv_mass: &'a [f64],
    inv_inertia: &'a [f64],
}

impl<L: ContactLaw> Simulation<L> {
    pub fn new(law: L, core: Core) -> Self {
        Simulation { law, core }
    }

    /// MercuryDPM evaluates the forces once before the first step, at x_0 with v_0.
    fn initial_forces(&mut self) {
        self.core.rebuild();
        let c = &mut self.core;
        let n = c.pairs.p.len();
        for k in 0..n {
            pair_force(
                &self.law,
                &c.domain,
                c.dt,
                k,
                &c.pairs,
                &c.particles.x,
                &c.particles.v,
                &c.particles.w,
                &c.particles.radius,
                &mut c.xi[k],
                &mut c.active[k],
                &mut c.out[k],
            );
        }
        for a in 0..c.particles.len() {
            let (f, t) = gather(a, &c.pairs, &c.active, &c.out);
            c.particles.f[a] = f;
            c.particles.t[a] = t;
        }
        c.forces_ready = true;
    }

    fn run<const ROT: bool, const GRAV: bool>(&mut self, steps: u64) {
        if steps == 0 {
            return;
        }
        let threads = self.core.threads;
        let barrier = SpinBarrier::new(threads);
        let vmax2: Vec<AtomicU64> = (0..threads).map(|_| AtomicU64::new(0)).collect();
        let core = &mut self.core;
        let gravity = core.gravity.unwrap_or_else(Vec3::zeros);
        let skin = core.skin();
        let bound0 = core.moved_bound;
        // The pair list and the partitions change at a rebuild (done by thread 0 alone while
        // the others wait at a barrier); the particle arrays are shared by index ranges.
        let Core {
            domain,
            particles,
            dt,
            pairs,
            xi,
            active,
            out,
            times,
            builder,
            scratch,
            threads: _,
            ..
        } = core;
        let view = StepView {
            law: &self.law,
            domain,
            dt: *dt,
            gravity,

            x: Shared::new(&mut particles.x[..]),
            v: Shared::new(&mut particles.v[..]),
            w: Shared::new(&mut particles.w[..]),
            f: Shared::new(&mut particles.f[..]),
            t: Shared::new(&mut particles.t[..]),
            radius: &particles.radius,
            inv_mass: &particles.inv_mass,
            inv_inertia: &particles.inv_inertia,
        };
        let list = Shared::new(ListState {
            pairs,
            xi,
            active,
            out,
            builder,
            scratch,
            times,
            motion: &particles.motion,
        });
        let work = |tid: usize| {
            let mut local = StageTimes::default();
            let mut clock = Instant::now();
            let mut lap = |slot: &mut u64| {
                if tid == 0 {
                    let now = Instant::now();
                    *slot += (now - clock).as_nanos() as u64;
                    clock = now;
                }
            };
            let mut bound = bound0;
            for s in 0..steps {
                // SAFETY (all blocks below): phases are separated by barriers; in each phase a
                // thread writes only its own particle range or pair range.
                let v2 = unsafe {
                    let l = list.get();
                    let (a, b) = l.scratch.particle_ranges[tid];
                    particle_pass::<L, ROT, GRAV>(&view, l, a, b, s > 0, true)
                };
                vmax2[tid].store(v2.to_bits(), Ordering::Relaxed);
                lap(&mut local.integrate);
                barrier.wait();
                lap(&mut local.wait);
                // Every thread derives the same bound from the same numbers.
                let m = vmax2
                    .iter()
                    .map(|a| f64::from_bits(a.load(Ordering::Relaxed)))
                    .fold(0.0, f64::max);
                bound += m.sqrt() * view.dt;
                if bound > 0.5 * skin {
                    bound = 0.0;
                    if tid == 0 {
                        unsafe {
                            list.get().rebuild(
                                view.domain,
                                view.x.get(),
                                view.radius,
                                view.inv_mass,
                            )
                        };
                    }
                    barrier.wait();
                    lap(&mut local.neighbor);
                }
                unsafe {
                    let l = list.get();
                    let (a, b) = l.scratch.pair_ranges[tid];
                    pair_pass(&view, l, a, b);
                }
                lap(&mut local.forces);
                barrier.wait();
                lap(&mut local.wait);
            }
            unsafe {
                let l = list.get();
                let (a, b) = l.scratch.particle_ranges[tid];
                particle_pass::<L, ROT, GRAV>(&view, l, a, b, true, false);
            }
            lap(&mut local.integrate);
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
        drop(view);
        let l = list.into_inner();
        l.times.forces += local.forces;
        l.times.integrate += local.integrate;
        l.times.wait += local.wait;
        core.moved_bound = bound;
        for _ in 0..steps {
            core.time += core.dt;
        }
        core.step += steps;
    }
}

/// The pair list and everything that changes with it.
struct ListState<'a> {
    pairs: &'a mut PairList,
    xi: &'a mut Vec<Vec3>,
    active: &'a mut Vec<bool>,
    out: &'a mut Vec<PairForce>,
    builder: &'a mut NeighborBuilder,
    scratch: &'a mut Scratch,
    times: &'a mut StageTimes,
    motion: &'a [crate::state::Motion],
}

impl ListState<'_> {
    /// Rebuilds the pair list at positions `x`, carries every pair's history over, and
    /// re-balances the particle and pair ranges of the threads.
    fn rebuild(&mut self, domain: &Domain, x: &[Vec3], radius: &[f64], inv_mass: &[f64]) {
        let t0 = Instant::now();
        let s = &mut *self.scratch;
        std::mem::swap(&mut s.old_p, &mut self.pairs.p);
        std::mem::swap(&mut s.old_i, &mut self.pairs.i);
        std::mem::swap(&mut s.old_xi, self.xi);
        std::mem::swap(&mut s.old_active, self.active);
        let motion = self.motion;
        // Wall–wall pairs never interact (neighbouring wall spheres overlap by round-off).
        self.builder.build(self.pairs, domain, x, radius, |a, b| {
            motion[a] == Motion::Free || motion[b] == Motion::Free
        });
        carry_history(&s.old_p, &s.old_i, &s.old_xi, self.pairs, self.xi);
        carry_history(&s.old_p, &s.old_i, &s.old_active, self.pairs, self.active);
        self.out.resize(self.pairs.p.len(), PairForce::default());
        let threads = s.particle_ranges.len();
        let adj = &self.pairs.adj_start;
        balanced_ranges(
            inv_mass.len(),
            threads,
            |a| {
                if inv_mass[a] > 0.0 {
                    8 + (adj[a + 1] - adj[a]) as u64
                } else {
                    2
                }
            },
            &mut s.particle_ranges,
        );
        balanced_ranges(self.pairs.p.len(), threads, |_| 1, &mut s.pair_ranges);
        self.times.neighbor += t0.elapsed().as_nanos() as u64;
        self.times.rebuilds += 1;
    }
}

/// Per-particle pass over `a..b`: with `kick_end`, gather the forces of the step that just
/// ended and apply the closing half kick; with `drift`, apply the opening half kick and the drift
/// of the next step. Returns the largest squared speed after the drift.
///
/// # Safety
/// Writes particles `a..b` only; reads pair outputs, which no one writes in this phase.
#[inline(never)]
unsafe fn particle_pass<L, const ROT: bool, const GRAV: bool>(
    view: &StepView<'_, L>,
    l: &ListState<'_>,
    a: usize,
    b: usize,
    kick_end: bool,
    drift: bool,
) -> f64 {
    let (x, v, w, f, t) = (view.x.get(), view.v.get(), view.w.get(), view.f.get(), view.t.get());
    let dt = view.dt;
    let mut vmax2: f64 = 0.0;
    // Each particle's values are loaded once into locals and stored once: a store followed by
    // an overlapping wider load of the same vector stalls store forwarding.
    for p in a..b {
        let im = view.inv_mass[p];
        if im > 0.0 {
            let (fp, tp) = if kick_end {
                let g = gather(p, l.pairs, l.active, l.out);
                f[p] = g.0;
                t[p] = g.1;
                g
            } else {
                (f[p], t[p])
            };
            // Half kick v += (F/m + g)·dt/2, ω += T/I·dt/2, in MercuryDPM's order of operations
            // (BaseParticle::integrateBeforeForceComputation); the closing kick of one step and
            // the opening kick of the next add the same increment twice.
            let acc = if GRAV { fp * im + view.gravity } else { fp * im };
            let dv = acc * 0.5 * dt;
            let mut vp = v[p];
            if kick_end {
                vp += dv;
            }
            if drift {
                vp += dv;
                let mut xp = x[p] + vp * dt;
                view.domain.wrap(&mut xp);
                x[p] = xp;
                vmax2 = vmax2.max(vp.norm_squared());
            }
            v[p] = vp;
            if ROT {
                let dw = tp * view.inv_inertia[p] * 0.5 * dt;
                let mut wp = w[p];
                if kick_end {
                    wp += dw;
                }
                if drift {
                    wp += dw;
                }
                w[p] = wp;
            }
        } else if drift {
            let vp = v[p];
            let mut xp = x[p] + vp * dt;
            view.domain.wrap(&mut xp);
            x[p] = xp;
            vmax2 = vmax2.max(vp.norm_squared());
        }
    }
    vmax2
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

/// Pair pass over pairs `a..b`.
///
/// # Safety
/// Writes the slots of pairs `a..b` only; reads particles, which no one writes in this phase.
#[inline(never)]
unsafe fn pair_pass<L: ContactLaw>(view: &StepView<'_, L>, l: &mut ListState<'_>, a: usize, b: usize) {
    let (x, v, w) = (view.x.get(), view.v.get(), view.w.get());
    for k in a..b {
        pair_force(
            view.law,
            view.domain,
            view.dt,
            k,
            l.pairs,
            x,
            v,
            w,
            view.radius,
            &mut l.xi[k],
            &mut l.active[k],
            &mut l.out[k],
        );
    }
}

/// Force of pair `k` into its slot; a pair that is not touching forgets its history.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_force<L: ContactLaw>(
    law: &L,
    domain: &Domain,
    dt: f64,
    k: usize,
    pairs: &PairList,
    x: &[Vec3],
    v: &[Vec3],
    w: &[Vec3],
    radius: &[f64],
    xi: &mut Vec3,
    active: &mut bool,
    out: &mut PairForce,
) {
    let (p, i) = (pairs.p[k] as usize, pairs.i[k] as usize);
    let r = domain.min_image(x[p] - x[i]);
    let sum = radius[p] + radius[i];
    if r.norm_squared() >= sum * sum {
        if *active {
            *active = false;
            *xi = Vec3::zeros();
        }
        return;
    }
    let input = PairInput {
        r,
        rad_p: radius[p],
        rad_i: radius[i],
        v_p: v[p],
        v_i: v[i],
        w_p: w[p],
        w_i: w[i],
    };
    if let Some(kin) = input.kinematics() {
        *out = law.evaluate(&kin, xi, dt);
        *active = true;
    }
}
