//! The run guard: checks a step makes at almost no cost, which stop a run whose numbers can no
//! longer be trusted, naming the step, the particles, the quantity, its value and the limit.
//!
//! - every contact's force and torques are finite, so that no velocity can become otherwise
//!   (checked in the pair pass for the pairs in contact only), and every position, velocity
//!   and angular velocity is finite at the start of each run;
//! - no overlap exceeds a fraction of the smaller radius (checked in the pair pass for the
//!   pairs in contact only, and before the first step);
//! - no contact gives its particles more energy than it took from them and than its springs
//!   held, beyond a fraction of what it took (every contact keeps an energy account,
//!   [`crate::state::Tally`], booked in the pair pass);
//! - no free particle is outside the box along a walled axis or has a non-finite position
//!   (checked at every pair-list rebuild, which visits every particle anyway: a particle moves
//!   less than a skin between two rebuilds).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// What went wrong, in memory indices (translated to ids when reported).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Breach {
    /// A velocity (`angular` false) or angular velocity that is not finite.
    NotFinite { particle: usize, angular: bool },
    /// A contact force or torque between particles `p` and `i` that is not finite.
    Force { p: usize, i: usize },
    /// An overlap `delta` (length) beyond the limit between particles `p` and `i`.
    Overlap {
        p: usize,
        i: usize,
        delta: f64,
        limit: f64,
    },
    /// A contact between particles `p` and `i` whose energy account shows an `excess` (energy
    /// units) beyond `limit`, having taken `taken` from them.
    Pumped {
        p: usize,
        i: usize,
        excess: f64,
        taken: f64,
        limit: f64,
    },
    /// A force or torque of the contact of particle `particle` with flat wall `wall` (0-based)
    /// that is not finite.
    WallForce { particle: usize, wall: usize },
    /// An overlap `delta` (length) of particle `particle` with flat wall `wall` beyond `limit`.
    WallOverlap {
        particle: usize,
        wall: usize,
        delta: f64,
        limit: f64,
    },
    /// A position outside the box along walled axis `axis` (0, 1, 2), or not finite.
    Outside {
        particle: usize,
        axis: usize,
        x: f64,
    },
    /// The free particles' mechanical energy grew over the last `steps` steps by more than the
    /// walls and gravity supplied; `particle` is the one of largest kinetic energy, `kinetic`
    /// and `stored` the kinetic energy of all and the energy their contacts' springs hold.
    Energy {
        particle: Option<usize>,
        steps: u64,
        balance: super::energy::Balance,
        kinetic: f64,
        stored: f64,
    },
}

/// The first breach any thread saw in a run; the threads stop at their next meeting.
#[derive(Default)]
pub(super) struct Alarm {
    raised: AtomicBool,
    first: Mutex<Option<(u64, Breach)>>,
}

impl Alarm {
    /// Records `breach`, seen at run-local step `s`, unless one was recorded before.
    #[cold]
    pub fn raise(&self, s: u64, breach: Breach) {
        let mut first = self.first.lock().unwrap_or_else(|e| e.into_inner());
        first.get_or_insert((s, breach));
        self.raised.store(true, Ordering::Relaxed);
    }

    /// Whether a breach was recorded (read after a barrier, every thread sees the same).
    pub fn raised(&self) -> bool {
        self.raised.load(Ordering::Relaxed)
    }

    /// The first breach and the run-local step it was seen at.
    pub fn take(self) -> Option<(u64, Breach)> {
        self.first.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

/// A run stopped by the guard: the step and time of the stop and what was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The step being computed when the breach was found.
    pub step: u64,
    /// Its time (time units).
    pub time: f64,
    /// Ids (1-based, as in the input files) of the particles involved.
    pub ids: Vec<u32>,
    /// The quantity, its value and the limit, in words.
    pub what: String,
    /// The likely cause and what to do about it.
    pub remedy: &'static str,
    /// What the run had written that stays on disk, when a run loop reports it.
    pub kept: Option<String>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ids: Vec<String> = self.ids.iter().map(u32::to_string).collect();
        let who = match ids.len() {
            0 => String::new(),
            _ => format!("particle {}: ", ids.join(" and ")),
        };
        write!(
            f,
            "the run guard stopped the run at step {} (t = {}): {who}{}; {}",
            self.step, self.time, self.what, self.remedy
        )?;
        if let Some(kept) = &self.kept {
            write!(f, "; {kept}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Failure {}

const UNSTABLE: &str = "the explicit scheme is likely unstable: a smaller time step \
    (run.steps_per_collision), a softer contact or less damping";

impl Breach {
    /// The failure report of this breach at `step` and `time`, with `id` the original index of
    /// each memory index.
    pub fn report(self, step: u64, time: f64, id: &[u32]) -> Failure {
        let (particles, what, remedy) = match self {
            Breach::NotFinite { particle, angular } => (
                vec![particle],
                format!(
                    "{} is not finite",
                    if angular {
                        "angular velocity (or its kinetic energy 1/2 I w^2)"
                    } else {
                        "velocity (or its kinetic energy 1/2 m v^2)"
                    }
                ),
                "the state the run was given holds it (the step itself checks the forces that \
                 could make one): check the initial file, or what set the velocities",
            ),
            Breach::Force { p, i } => (
                vec![p, i],
                "the contact force or torque is not finite".to_string(),
                "coincident spheres, or an unstable step: check the state for overlapping \
                 spheres, or use a smaller time step",
            ),
            Breach::Overlap { p, i, delta, limit } => (
                vec![p, i],
                format!(
                    "overlap {delta:e} exceeds the limit {limit:e} (guard.overlap times the \
                     smaller radius)"
                ),
                UNSTABLE,
            ),
            Breach::WallForce { particle, wall } => (
                vec![particle],
                format!("the force or torque of its contact with wall[{wall}] is not finite"),
                "an unstable step: use a smaller time step",
            ),
            Breach::WallOverlap {
                particle,
                wall,
                delta,
                limit,
            } => (
                vec![particle],
                format!(
                    "overlap {delta:e} with wall[{wall}] exceeds the limit {limit:e} \
                     (guard.overlap times its radius): it is going through the wall"
                ),
                UNSTABLE,
            ),
            Breach::Pumped {
                p,
                i,
                excess,
                taken,
                limit,
            } => (
                vec![p, i],
                format!(
                    "the contact gave its particles {excess:e} more energy than it took from them \
                     ({taken:e}) and its springs held, beyond the limit {limit:e} (guard.contact \
                     times the energy it took)"
                ),
                "a contact law that is not dissipative, or an explicit scheme near its limit: \
                 check the law's parameters (a negative damping, a tangential convention that \
                 pumps energy), or use a smaller time step (run.steps_per_collision)",
            ),
            Breach::Outside { particle, axis, x } => (
                vec![particle],
                format!(
                    "position {} = {x} is outside the box or not finite",
                    ["x", "y", "z"][axis]
                ),
                "it passed through a wall or left an open side of the box: the explicit scheme \
                 is likely unstable (a smaller time step, run.steps_per_collision, a softer \
                 contact or less damping), or nothing holds it in (walls, or a larger box)",
            ),
            Breach::Energy {
                particle,
                steps,
                balance: b,
                kinetic,
                stored,
            } => (
                particle.into_iter().collect(),
                format!(
                    "the energy of the free particles went from {:e} to {:e} over the last \
                     {steps} steps (kinetic {kinetic:e}, held by contact springs {stored:e}) \
                     while the walls and gravity supplied {:e}: a gain of {:e} beyond the limit \
                     {:e} (guard.energy times the energy at play); the particle named has the \
                     largest kinetic energy",
                    b.before, b.after, b.supplied, b.gained, b.limit
                ),
                "a contact gave back more energy than it received: the explicit scheme is \
                 likely unstable (a smaller time step, run.steps_per_collision, a softer contact \
                 or less damping), or the contact law is not dissipative",
            ),
        };
        Failure {
            step,
            time,
            ids: particles.iter().map(|&m| id[m] + 1).collect(),
            what,
            remedy,
            kept: None,
        }
    }
}

/// The first free particle (memory order) with a position that is not finite, or outside the
/// box along a walled axis.
pub(super) fn outside(
    pt: &crate::state::Particles,
    domain: &crate::state::Domain,
) -> Option<Breach> {
    (0..pt.len())
        .filter(|&a| pt.inv_mass[a] > 0.0)
        .find_map(|a| {
            (0..3).find_map(|k| {
                let x = pt.x[a][k];
                let inside = if domain.periodic[k] {
                    x.is_finite()
                } else {
                    x >= domain.lo[k] && x <= domain.hi[k]
                };
                (!inside).then_some(Breach::Outside {
                    particle: a,
                    axis: k,
                    x,
                })
            })
        })
}

/// The first free particle (memory order) whose velocity or angular velocity is not finite,
/// or so large that its kinetic energy (½ m v², ½ I ω²) is not: every energy the diagnostics
/// table reports must be a number.
pub(super) fn not_finite(pt: &crate::state::Particles) -> Option<Breach> {
    let finite = |v: &crate::Vec3, inv: f64| (0.5 * v.norm_squared() / inv).is_finite();
    (0..pt.len())
        .filter(|&a| pt.inv_mass[a] > 0.0)
        .find_map(|a| {
            match (
                finite(&pt.v[a], pt.inv_mass[a]),
                finite(&pt.w[a], pt.inv_inertia[a]),
            ) {
                (true, true) => None,
                (v, _) => Some(Breach::NotFinite {
                    particle: a,
                    angular: v,
                }),
            }
        })
}
