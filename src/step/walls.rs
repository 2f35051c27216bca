//! The wall contacts: every free sphere against every flat wall, each (sphere, wall) contact
//! with its own history slot, created at first touch and reset when the contact opens, as a
//! pair's. The contact is the case's law evaluated on the sphere–plane kinematics
//! ([`crate::contact::plane`]): the sphere is P, the wall is I.
//!
//! The slots are indexed by the sphere's original id, `id · walls + wall`, so a pair-list
//! rebuild, which re-orders the particles in memory, leaves them where they are. The stage
//! runs over the particle chunks after the pair pass; a chunk's closing kick adds its spheres'
//! wall forces after their pair forces, in the walls' order, so the sums do not depend on the
//! thread count.

use std::sync::atomic::Ordering;

use super::arrays::Arrays;
use super::energy::{fixed, Flows};
use super::guard::Breach;
use crate::contact::plane::PlaneInput;
use crate::contact::ContactLaw;
use crate::state::{History, PairForce, Wall, WallContact};
use crate::step::team::SharedSlice;
use crate::Vec3;

/// The flat walls and their contact slots, `id · walls.len() + wall` for the sphere of
/// original id `id`.
pub struct WallSlots<H> {
    pub walls: Vec<Wall>,
    pub history: Vec<H>,
    pub active: Vec<bool>,
    pub out: Vec<PairForce>,
}

impl<H: History> WallSlots<H> {
    /// The walls `walls` for `particles` spheres, no contact yet.
    pub fn new(walls: Vec<Wall>, particles: usize) -> Self {
        let slots = walls.len() * particles;
        WallSlots {
            walls,
            history: vec![H::default(); slots],
            active: vec![false; slots],
            out: vec![PairForce::default(); slots],
        }
    }

    /// The active contacts, sorted by (sphere id, wall).
    pub fn contacts(&self) -> Vec<WallContact> {
        let count = self.walls.len().max(1);
        (0..self.active.len())
            .filter(|&s| self.active[s])
            .map(|s| {
                let h = &self.history[s];
                let mut history = Vec::with_capacity(H::WORDS);
                h.put_words(&mut history);
                WallContact {
                    particle: (s / count) as u32,
                    wall: (s % count) as u32,
                    history,
                    spring: h.spring(),
                    force: self.out[s],
                }
            })
            .collect()
    }

    /// Sets the walls and contacts of a snapshot of the same scene (`walls` as many as these).
    pub fn restore(&mut self, walls: &[Wall], contacts: &[WallContact]) {
        self.walls.copy_from_slice(walls);
        self.active.fill(false);
        self.history.fill(H::default());
        self.out.fill(PairForce::default());
        let count = self.walls.len();
        for c in contacts {
            let s = c.particle as usize * count + c.wall as usize;
            self.history[s] = H::from_words(&c.history);
            self.out[s] = c.force;
            self.active[s] = true;
        }
    }

    /// The elastic energy (energy units, fixed point) the springs of the active contacts hold,
    /// with the particles' positions `x` and radii `radius` in memory order and `id` their
    /// original indices.
    pub fn stored<L: ContactLaw<History = H>>(
        &self,
        law: &L,
        x: &[Vec3],
        radius: &[f64],
        id: &[u32],
    ) -> i128 {
        let count = self.walls.len();
        let mut sum = 0;
        for a in 0..x.len() {
            for (w, wall) in self.walls.iter().enumerate() {
                let s = id[a] as usize * count + w;
                let delta = radius[a] - (x[a] - wall.point).dot(&wall.normal);
                if self.active[s] && delta > 0.0 {
                    // a plane's R* is the sphere's radius
                    sum += fixed(law.stored_energy(delta, radius[a], &self.history[s]));
                }
            }
        }
        sum
    }
}

/// Views of the slots the team's threads share during a run: a chunk's slots are written by
/// the thread that takes the chunk in the wall stage and read by the one that takes it in the
/// particle pass, after the chunk is marked done.
pub(super) struct WallViews<H> {
    pub count: usize,
    pub history: SharedSlice<H>,
    pub active: SharedSlice<bool>,
    pub out: SharedSlice<PairForce>,
}

impl<H> WallViews<H> {
    pub fn of(slots: &mut WallSlots<H>) -> Self {
        WallViews {
            count: slots.walls.len(),
            history: SharedSlice::of(&mut slots.history),
            active: SharedSlice::of(&mut slots.active),
            out: SharedSlice::of(&mut slots.out),
        }
    }

    /// Adds the wall forces and torques of the sphere of original id `id` to `f` and `t`, in
    /// the walls' order.
    ///
    /// # Safety
    /// No thread writes the sphere's slots during the call.
    #[inline(always)]
    pub unsafe fn add_to(&self, id: u32, f: &mut Vec3, t: &mut Vec3) {
        let first = id as usize * self.count;
        for s in first..first + self.count {
            if self.active.get(s) {
                let o = self.out.get(s);
                *f += o.f;
                *t += o.torque_p;
            }
        }
    }
}

/// What the wall stage of a chunk leaves: the run guard's first breach, the walls' work on the
/// spheres (F·U·dt, fixed point) and the contacts' dissipation.
#[derive(Default)]
pub(super) struct WallWatch {
    pub breach: Option<Breach>,
    pub wall_work: i128,
    pub flows: Flows,
}

/// The wall contacts of the spheres `a..b` (memory order) against `walls` (where they are at
/// this step), at the positions and half-step velocities of `arr`, over a step `dt` (time):
/// each contact's force into its slot and its sphere's `touched` flag set; a contact that
/// opened forgets its history. `overlap` is the run guard's limit (a fraction of the radius).
///
/// # Safety
/// `arr` and `views` are valid; no other thread touches the particles `a..b` or their wall
/// slots during the call.
pub(super) unsafe fn wall_chunk<L: ContactLaw>(
    law: &L,
    walls: &[Wall],
    views: &WallViews<L::History>,
    arr: &Arrays<L::History>,
    (a, b): (usize, usize),
    dt: f64,
    overlap: f64,
) -> WallWatch {
    let mut watch = WallWatch::default();
    for j in a..b {
        let inv_mass = arr.inv_mass.get(j);
        if inv_mass <= 0.0 {
            // a prescribed sphere moves with its wall group and meets no flat wall
            continue;
        }
        let first = arr.id.get(j) as usize * views.count;
        for (w, wall) in walls.iter().enumerate() {
            let s = first + w;
            let input = PlaneInput {
                offset: arr.x.get(j) - wall.point,
                normal: wall.normal,
                rad_p: arr.radius.get(j),
                inv_mass_p: inv_mass,
                v_p: arr.v.get(j),
                w_p: arr.w.get(j),
                v_wall: wall.velocity,
            };
            let (history, active) = (views.history.at_mut(s), views.active.at_mut(s));
            let Some(kin) = input.kinematics() else {
                if *active {
                    if L::SPLITS_DISSIPATION {
                        let rad = arr.radius.get(j);
                        let held =
                            law.stored_energy(0.0, rad, history) - law.normal_energy(0.0, rad);
                        watch.flows.dissipated[2] += fixed(held);
                    }
                    *active = false;
                    *history = L::History::default();
                }
                continue;
            };
            let (mut force, lost) = law.evaluate_dissipating(&kin, history, dt);
            // a wall takes no torque (and a full-radius arm of a plane is infinite)
            force.torque_i = Vec3::zeros();
            *views.out.at_mut(s) = force;
            *active = true;
            arr.touched.slice(j..j + 1)[0].store(true, Ordering::Relaxed);
            let sum = |v: Vec3| v.x + v.y + v.z;
            if watch.breach.is_none() {
                let limit = overlap * input.rad_p;
                if !(sum(force.f) + sum(force.torque_p)).is_finite() {
                    watch.breach = Some(Breach::WallForce {
                        particle: j,
                        wall: w,
                    });
                } else if kin.delta > limit {
                    watch.breach = Some(Breach::WallOverlap {
                        particle: j,
                        wall: w,
                        delta: kin.delta,
                        limit,
                    });
                }
            }
            if L::SPLITS_DISSIPATION {
                let d = &mut watch.flows.dissipated;
                d[0] += fixed(lost.normal);
                d[1] += fixed(lost.tangential);
                d[2] += fixed(lost.slide);
            }
            // The wall's work on the sphere over the step, F·U·dt.
            watch.wall_work += fixed(force.f.dot(&wall.velocity) * dt);
        }
    }
    watch
}
