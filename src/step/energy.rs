//! The run guard's energy balance: over a window of steps, the mechanical energy of the free
//! particles (kinetic, rotational, gravitational along walled axes, and what the contacts' springs
//! hold) may grow by no more than the walls and gravity along periodic axes supplied.
//!
//! Every contact law verdem runs is passive: its springs give back at most what they took and its
//! dashpots and sliders only take. So over any window E₁ − E₀ − W ≤ 0 in the continuous system,
//! where W is the work of the prescribed (wall) particles on the free ones plus that of gravity
//! along periodic axes (along walled axes gravity is in E as a potential). The explicit scheme
//! adds a bounded error of relative size about (ω·dt)²/4 within a contact (the modified energy of
//! Störmer–Verlet for a harmonic oscillator: Hairer, Lubich & Wanner, Geometric Numerical
//! Integration, 2006, §I.5), and first order at contact onset; an unstable scheme, or a law that
//! returns more energy than it received, makes the balance grow without bound.
//!
//! Sums are taken in fixed point ([`fixed`]): integer addition does not depend on the order of
//! the terms, so the balance, and whether the guard stops a run, are the same for any thread
//! count and any memory order of the particles.

use crate::contact::ContactLaw;
use crate::state::{Domain, Particles};
use crate::Vec3;

/// Scale of the fixed-point sums: 2⁶⁴ units per energy unit (resolution 5.4e-20, range ±9.2e18
/// energy units; a term beyond the range saturates, which the guard then reports as a gain).
const SCALE: f64 = 18446744073709551616.0;

/// `x` (energy units, or any unit of the same range: momentum, impulse) in fixed point. Terms below 0.5 energy units take the hardware's 64-bit
/// conversion, the others the 128-bit one (a call); both truncate towards zero.
#[inline]
pub(super) fn fixed(x: f64) -> i128 {
    let y = x * SCALE;
    if y.abs() < 9.2e18 {
        y as i64 as i128
    } else {
        y as i128
    }
}

/// A fixed-point sum back in its units.
pub(super) fn float(x: i128) -> f64 {
    x as f64 / SCALE
}

/// Gravity's components along periodic axes (acceleration): its work there is accumulated step
/// by step; along walled axes it is a potential.
pub(super) fn periodic_part(gravity: Vec3, domain: &Domain) -> Vec3 {
    Vec3::from_fn(|k, _| if domain.periodic[k] { gravity[k] } else { 0.0 })
}

/// The mechanical energy of the free particles and their contacts at one moment (energy
/// units): kinetic (with rotation), held by the contacts' springs, and gravitational along
/// walled axes (zero at the origin); and the free particle of largest kinetic energy (memory
/// index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Energy {
    pub kinetic: f64,
    pub stored: f64,
    pub potential: f64,
    pub liveliest: Option<usize>,
}

/// The energy of the state: ½mv² + ½Iω² of every free particle, −m·g·x along walled axes, and
/// the elastic energy the law's springs hold in every active contact.
pub(super) fn measure<L: ContactLaw>(
    law: &L,
    pt: &Particles,
    domain: &Domain,
    gravity: Option<Vec3>,
    pairs: &crate::step::neighbor::rebuild::Pairs<L::History>,
) -> Energy {
    let walled_g = gravity.map(|g| g - periodic_part(g, domain));
    let (mut kinetic, mut potential, mut stored) = (0i128, 0i128, 0i128);
    let mut liveliest = None;
    let mut most = -1.0;
    for a in (0..pt.len()).filter(|&a| pt.inv_mass[a] > 0.0) {
        let m = 1.0 / pt.inv_mass[a];
        // ½mv² + ½Iω², with I = 1/inv_inertia (0.4·m·r² for a solid sphere).
        let spin = if pt.inv_inertia[a] > 0.0 {
            0.5 * pt.w[a].norm_squared() / pt.inv_inertia[a]
        } else {
            0.0
        };
        let e = 0.5 * m * pt.v[a].norm_squared() + spin;
        if e > most {
            (most, liveliest) = (e, Some(a));
        }
        kinetic += fixed(e);
        if let Some(g) = walled_g {
            potential += fixed(-m * g.dot(&pt.x[a]));
        }
    }
    for k in (0..pairs.active.len()).filter(|&k| pairs.active[k]) {
        let (p, i) = (pairs.list.p[k] as usize, pairs.list.i[k] as usize);
        let r = domain.min_image(pt.x[p] - pt.x[i]);
        let delta = pt.radius[p] + pt.radius[i] - r.norm();
        if delta > 0.0 {
            let (rp, ri) = (pt.radius[p], pt.radius[i]);
            stored += fixed(law.stored_energy(delta, rp * ri / (rp + ri), &pairs.history[k]));
        }
    }
    Energy {
        kinetic: float(kinetic),
        stored: float(stored),
        potential: float(potential),
        liveliest,
    }
}

/// The balance of a window: `gained` = E₁ − E₀ − W (energy units) against its limit,
/// `tolerance` times the energy at play: the mean kinetic and spring energy of the two ends plus
/// |W| and the change of potential energy (whose zero is arbitrary). The limit is the round-off
/// and truncation the scheme is allowed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Balance {
    pub before: f64,
    pub after: f64,
    pub supplied: f64,
    pub gained: f64,
    pub limit: f64,
}

impl Balance {
    /// The balance from `e0` to `e1` with work `supplied` (energy units) put in.
    pub fn of(e0: &Energy, e1: &Energy, supplied: f64, tolerance: f64) -> Balance {
        let (before, after) = (
            e0.kinetic + e0.stored + e0.potential,
            e1.kinetic + e1.stored + e1.potential,
        );
        let at_play = 0.5 * (e0.kinetic + e0.stored + e1.kinetic + e1.stored)
            + supplied.abs()
            + (e1.potential - e0.potential).abs();
        Balance {
            before,
            after,
            supplied,
            gained: after - before - supplied,
            limit: tolerance * at_play,
        }
    }

    /// Whether the free particles gained more than was supplied, beyond the limit (a balance
    /// that is not finite counts as beyond it).
    pub fn breached(&self) -> bool {
        !self.gained.is_finite() || !self.limit.is_finite() || self.gained > self.limit
    }
}

/// What flowed into and out of the free particles, accumulated step by step in fixed point
/// ([`fixed`]), so that it is the same for any thread count and any order of the pairs: the
/// energy ledger's work and dissipation and the momentum ledger's wall impulses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Flows {
    /// Work of the prescribed (wall) particles on the free ones, F·U·dt per contact and step
    /// with F the force on the free particle and U the wall's velocity (energy units).
    pub wall_work: i128,
    /// Work of gravity along periodic axes, m·g·Δx per drift (energy units).
    pub gravity_work: i128,
    /// Energy the contacts' normal dashpots, tangential dashpots and Coulomb sliders took
    /// ([`crate::contact::Dissipated`]; energy units).
    pub dissipated: [i128; 3],
    /// Impulse the free particles gave wall group 0 and group 1 (and higher), F·dt per contact
    /// and step (momentum units).
    pub impulse: [[i128; 3]; 2],
}

impl Flows {
    /// The impulse the free particles gave wall group 0 and 1 (momentum units; [`Flows::impulse`]).
    pub fn wall_impulse(&self) -> [Vec3; 2] {
        std::array::from_fn(|g| Vec3::from_fn(|k, _| float(self.impulse[g][k])))
    }

    /// Adds `other`'s flows (integer sums: the same in any order).
    pub fn add(&mut self, other: &Flows) {
        self.wall_work += other.wall_work;
        self.gravity_work += other.gravity_work;
        for (a, b) in self.dissipated.iter_mut().zip(other.dissipated) {
            *a += b;
        }
        for (a, b) in self.impulse.iter_mut().zip(other.impulse) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
    }
}

/// The ledgers read at one step: the flows accumulated since the simulation was built, and the
/// state's energies and free momentum, in fixed point ([`fixed`]). Two readings give the
/// ledgers of the steps between them ([`Reading::since`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    pub step: u64,
    /// Time step (time).
    pub dt: f64,
    /// Whether the contact law splits its dissipation ([`ContactLaw::SPLITS_DISSIPATION`]).
    pub splits: bool,
    pub flows: Flows,
    /// Σ ½mv² and Σ ½Iω² of the free particles (energy units).
    pub trans: i128,
    pub rot: i128,
    /// Elastic energy the springs of the contacts with a free particle hold (energy units).
    pub elastic: i128,
    /// −Σ m·g·x of the free particles along walled axes (energy units; zero at the origin).
    pub potential: i128,
    /// Σ m·v of the free particles (momentum units).
    pub momentum: [i128; 3],
    /// Force the free particles exert on wall group 0 and 1 with this step's forces (force
    /// units).
    pub wall_force: [[i128; 3]; 2],
    /// Σ m·g of the free particles (force units; zero without gravity).
    pub weight: Vec3,
}

/// The ledgers of the steps between two readings (energy units, momentum units, force units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LedgerRow {
    /// Work of the walls on the free particles.
    pub work_walls: f64,
    /// Work of gravity on the free particles (along walled axes the fall of the potential).
    pub work_gravity: f64,
    /// Energy taken by the normal dashpots, tangential dashpots and Coulomb sliders; `None`
    /// when the contact law does not split its dissipation.
    pub dissipated: Option<[f64; 3]>,
    /// Change of Σ ½mv², Σ ½Iω² and of the springs' elastic energy.
    pub d_trans: f64,
    pub d_rot: f64,
    pub d_elastic: f64,
    /// ΔE_trans + ΔE_rot + ΔE_elastic − W_walls − W_gravity + D_n + D_t + D_slide; `None`
    /// when the law does not split its dissipation.
    pub residual: Option<f64>,
    /// Mean force the free particles exerted on wall group 0 and 1: impulse over the
    /// interval's duration.
    pub mean_wall_force: [Vec3; 2],
    /// Δ(Σ m v) of the free particles minus the impulse the walls and gravity gave them; the
    /// walls' impulse is F·dt per step with half a step's weight at each end (the closing and
    /// opening half kicks of the end steps): Newton's third law makes it vanish to round-off.
    pub momentum_residual: Vec3,
}

impl Reading {
    /// The ledgers from `before` to this reading (of the same simulation, later).
    pub fn since(&self, before: &Reading) -> LedgerRow {
        let (a, b) = (before, self);
        let (fa, fb) = (&a.flows, &b.flows);
        let steps = b.step - a.step;
        let duration = steps as f64 * b.dt;
        let d_pot = b.potential - a.potential;
        let (wall, grav) = (
            fb.wall_work - fa.wall_work,
            fb.gravity_work - fa.gravity_work - d_pot,
        );
        let dis: [i128; 3] = std::array::from_fn(|k| fb.dissipated[k] - fa.dissipated[k]);
        let (d_trans, d_rot, d_el) = (b.trans - a.trans, b.rot - a.rot, b.elastic - a.elastic);
        let residual = d_trans + d_rot + d_el - wall - grav + dis.iter().sum::<i128>();
        let impulse =
            |g: usize| -> Vec3 { Vec3::from_fn(|k, _| float(fb.impulse[g][k] - fa.impulse[g][k])) };
        let force = |r: &Reading| -> Vec3 {
            Vec3::from_fn(|k, _| float(r.wall_force[0][k] + r.wall_force[1][k]))
        };
        let dp = Vec3::from_fn(|k, _| float(b.momentum[k] - a.momentum[k]));
        // The walls' impulse on the free particles: −(impulse they received), plus half a step
        // of the force of the first step (its opening half kick) minus half a step of the last
        // (its closing kick is the next interval's opening one).
        let from_walls = -(impulse(0) + impulse(1)) + (force(b) - force(a)) * (0.5 * b.dt);
        let momentum_residual = dp - from_walls - b.weight * duration;
        let mean = |g: usize| {
            if duration > 0.0 {
                impulse(g) / duration
            } else {
                Vec3::zeros()
            }
        };
        LedgerRow {
            work_walls: float(wall),
            work_gravity: float(grav),
            dissipated: b.splits.then(|| dis.map(float)),
            d_trans: float(d_trans),
            d_rot: float(d_rot),
            d_elastic: float(d_el),
            residual: b.splits.then(|| float(residual)),
            mean_wall_force: [mean(0), mean(1)],
            momentum_residual,
        }
    }
}

/// The ledgers' reading of the state: the energies and free momentum of `pt` and the forces on
/// the walls of the contacts of `pairs` (forces of the current step), with the flows `flows`
/// accumulated so far.
pub(super) fn read<L: ContactLaw>(
    law: &L,
    pt: &Particles,
    domain: &Domain,
    gravity: Option<Vec3>,
    pairs: &crate::step::neighbor::rebuild::Pairs<L::History>,
    (step, dt, flows): (u64, f64, Flows),
) -> Reading {
    let walled_g = gravity.map(|g| g - periodic_part(g, domain));
    let mut r = Reading {
        step,
        dt,
        splits: L::SPLITS_DISSIPATION,
        flows,
        trans: 0,
        rot: 0,
        elastic: 0,
        potential: 0,
        momentum: [0; 3],
        wall_force: [[0; 3]; 2],
        weight: Vec3::zeros(),
    };
    let mut mass = 0i128;
    for a in (0..pt.len()).filter(|&a| pt.inv_mass[a] > 0.0) {
        let m = 1.0 / pt.inv_mass[a];
        mass += fixed(m);
        r.trans += fixed(0.5 * m * pt.v[a].norm_squared());
        if pt.inv_inertia[a] > 0.0 {
            // ½Iω², with I = 1/inv_inertia (0.4·m·r² for a solid sphere).
            r.rot += fixed(0.5 * pt.w[a].norm_squared() / pt.inv_inertia[a]);
        }
        for k in 0..3 {
            r.momentum[k] += fixed(m * pt.v[a][k]);
        }
        if let Some(g) = walled_g {
            r.potential += fixed(-m * g.dot(&pt.x[a]));
        }
    }
    r.weight = gravity.map_or(Vec3::zeros(), |g| g * float(mass));
    for k in (0..pairs.active.len()).filter(|&k| pairs.active[k]) {
        let (p, i) = (pairs.list.p[k] as usize, pairs.list.i[k] as usize);
        let (free_p, free_i) = (pt.inv_mass[p] > 0.0, pt.inv_mass[i] > 0.0);
        if !free_p && !free_i {
            continue;
        }
        let r_pi = domain.min_image(pt.x[p] - pt.x[i]);
        let delta = pt.radius[p] + pt.radius[i] - r_pi.norm();
        if delta > 0.0 {
            let (rp, ri) = (pt.radius[p], pt.radius[i]);
            r.elastic += fixed(law.stored_energy(delta, rp * ri / (rp + ri), &pairs.history[k]));
        }
        // out.f is the force on P; I receives −out.f.
        let f = pairs.out[k].f;
        for (q, sign) in [(p, 1.0), (i, -1.0)] {
            if let crate::state::Motion::Prescribed(g) = pt.motion[q] {
                for c in 0..3 {
                    r.wall_force[usize::from(g.min(1))][c] += fixed(sign * f[c]);
                }
            }
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_sums_do_not_depend_on_the_order_of_their_terms() {
        let terms = [0.1, 1e-12, 3.7e5, -2.5e-7, 0.3, 1e-19];
        let forward: i128 = terms.iter().map(|&x| fixed(x)).sum();
        let backward: i128 = terms.iter().rev().map(|&x| fixed(x)).sum();
        assert_eq!(forward, backward);
        let floats_fwd: f64 = terms.iter().sum();
        assert!((float(forward) - floats_fwd).abs() <= 1e-10 * floats_fwd);
    }

    fn kinetic(k: f64) -> Energy {
        Energy {
            kinetic: k,
            stored: 0.0,
            potential: 0.0,
            liveliest: None,
        }
    }

    #[test]
    fn a_gain_beyond_the_supply_breaches_and_a_loss_does_not() {
        let b = |k0, k1, w| Balance::of(&kinetic(k0), &kinetic(k1), w, 1e-2).breached();
        assert!(!b(10.0, 9.0, 0.5));
        assert!(!b(10.0, 10.5, 0.5));
        assert!(b(10.0, 11.0, 0.5));
        assert!(b(10.0, f64::NAN, 0.5));
        assert!(b(10.0, f64::INFINITY, 0.5));
    }

    #[test]
    fn the_zero_of_the_potential_energy_does_not_widen_the_limit() {
        let at = |k: f64, z: f64| Energy {
            potential: -z,
            ..kinetic(k)
        };
        // A fall of 1 turned into 1 of kinetic energy, with a gain of 0.1 beyond it, at any
        // height: the limit is 1 % of about 2, whatever the potential's zero.
        for z0 in [0.0, 1e6] {
            let b = Balance::of(&at(0.0, z0), &at(1.1, z0 - 1.0), 0.0, 1e-2);
            assert!(b.breached(), "{b:?}");
        }
    }
}
