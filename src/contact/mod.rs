//! Contact laws composed of small parts: a normal force model and a tangential model (spring,
//! dashpot and Coulomb cap). A variant is a new part, chosen once when the simulation is built,
//! never an `if` in the pair loop. The tangential conventions a case can name are listed,
//! with the properties they claim, in [`registry`]; the normal laws in [`normal_laws`].
//!
//! Conventions (MercuryDPM, `BaseInteraction` and `SlidingFrictionInteraction`; see
//! `docs/benchmark.md`, "How MercuryDPM computes it"): for a pair, P is the lower index and I
//! the higher; the unit normal `n` points from I to P; the overlap `δ = r_P + r_I − |x_P − x_I|`
//! is positive in contact; the contact point is `c = x_P − (r_P − δ/2) n`; forces are those on
//! P (I receives the opposite).

pub mod named;
pub mod normal;
pub mod normal_laws;
pub mod parameters;
pub mod plane;
pub mod registry;
pub mod tangential;

use crate::state::History;
pub use crate::state::PairForce;
use crate::Vec3;
pub use normal::{Damped, Damping, LinearSpringDashpot, NormalModel, Spring};
pub use normal_laws::{Normal, NormalVisitor};
pub use parameters::Parameters;
pub use registry::{Geometry, Properties, Tangential, TangentialVisitor};
pub use tangential::conventions::{
    Cundall1979, LammpsGranular, LammpsHookeHistory, Liggghts, MercurySlidingFriction, Objective,
    YadeApprox,
};
pub use tangential::{Arms, Frictionless, TangentialModel};

/// Kinematics of one pair in contact, evaluated at the contact point.
#[derive(Clone, Copy, Debug)]
pub struct PairKinematics {
    /// Unit normal from I to P.
    pub n: Vec3,
    /// Centre distance |x_P − x_I| (length).
    pub dist: f64,
    /// Overlap δ > 0 (length).
    pub delta: f64,
    /// Lever arm of P: c − x_P (length).
    pub arm_p: Vec3,
    /// Lever arm of I: c − x_I (length).
    pub arm_i: Vec3,
    /// Relative velocity of P's material point at c with respect to I's (length/time).
    pub v_rel: Vec3,
    /// Normal relative velocity v_rel·n (positive when separating).
    pub vn: f64,
    /// Tangential relative velocity v_rel − vn·n.
    pub vt: Vec3,
    /// Relative velocity of the centres v_P − v_I.
    pub v_centres: Vec3,
    /// Separation x_P − x_I (minimum image; length).
    pub r: Vec3,
    /// Radii of P and I (length).
    pub rad_p: f64,
    pub rad_i: f64,
    /// Inverse masses of P and I (1/mass; 0 for a fixed sphere or a wall).
    pub inv_mass_p: f64,
    pub inv_mass_i: f64,
    /// Angular velocities of P and I (1/time).
    pub w_p: Vec3,
    pub w_i: Vec3,
}

impl PairKinematics {
    /// Effective radius R* = r_P·r_I/(r_P + r_I) (length); r_P for a plane (r_I infinite).
    #[inline(always)]
    pub fn r_star(&self) -> f64 {
        if self.rad_i.is_infinite() {
            self.rad_p
        } else {
            self.rad_p * self.rad_i / (self.rad_p + self.rad_i)
        }
    }
    /// Effective mass m* = 1/(1/m_P + 1/m_I) (mass); m_P for a fixed partner (1/m_I = 0).
    #[inline(always)]
    pub fn m_star(&self) -> f64 {
        1.0 / (self.inv_mass_p + self.inv_mass_i)
    }
}

/// Everything known about the two spheres of a candidate pair.
#[derive(Clone, Copy, Debug)]
pub struct PairInput {
    /// Separation x_P − x_I (minimum image).
    pub r: Vec3,
    /// Radii of P and I.
    pub rad_p: f64,
    pub rad_i: f64,
    /// Inverse masses of P and I (1/mass; 0 for a fixed sphere or a wall).
    pub inv_mass_p: f64,
    pub inv_mass_i: f64,
    /// Velocities of P and I (the half-step velocities during a time step).
    pub v_p: Vec3,
    pub v_i: Vec3,
    /// Angular velocities of P and I.
    pub w_p: Vec3,
    pub w_i: Vec3,
}

impl PairInput {
    /// Two spheres of radii `rad_p` and `rad_i` (length) at separation `r` = x_P − x_I
    /// (minimum image), at rest, of no mass named (both inverse masses 0): what the saves' writers need to find a contact's normal,
    /// overlap and contact point exactly as the force pass computed them.
    pub fn at_rest(r: Vec3, rad_p: f64, rad_i: f64) -> PairInput {
        PairInput {
            r,
            rad_p,
            rad_i,
            inv_mass_p: 0.0,
            inv_mass_i: 0.0,
            v_p: Vec3::zeros(),
            v_i: Vec3::zeros(),
            w_p: Vec3::zeros(),
            w_i: Vec3::zeros(),
        }
    }

    /// Contact geometry and kinematics, or `None` when the spheres do not touch
    /// (contact iff |x_P − x_I| < r_P + r_I, strict, as in MercuryDPM).
    #[inline(always)]
    pub fn kinematics(&self) -> Option<PairKinematics> {
        let sum = self.rad_p + self.rad_i;
        let d2 = self.r.norm_squared();
        if d2 >= sum * sum {
            return None;
        }
        let dist = d2.sqrt();
        let n = self.r / dist;
        let delta = sum - dist;
        // Lever arms r − δ/2 (MercuryDPM: contact point in the middle of the overlap).
        let arm_p = -(self.rad_p - 0.5 * delta) * n;
        let arm_i = self.r + arm_p;
        // Velocity of each sphere's material point at c: v + ω × (c − x).
        let v_rel = (self.v_p + self.w_p.cross(&arm_p)) - (self.v_i + self.w_i.cross(&arm_i));
        let vn = v_rel.dot(&n);
        let vt = v_rel - vn * n;
        Some(PairKinematics {
            n,
            dist,
            delta,
            arm_p,
            arm_i,
            v_rel,
            vn,
            vt,
            v_centres: self.v_p - self.v_i,
            r: self.r,
            rad_p: self.rad_p,
            rad_i: self.rad_i,
            inv_mass_p: self.inv_mass_p,
            inv_mass_i: self.inv_mass_i,
            w_p: self.w_p,
            w_i: self.w_i,
        })
    }
}

/// The energy a contact's dissipative parts took from its particles over one step (energy
/// units, positive when taken), at the velocities the law saw: the energy ledger's dissipation,
/// split by the part that took it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dissipated {
    /// The normal dashpot: the part of the normal force that is not elastic, against the normal
    /// relative velocity.
    pub normal: f64,
    /// The tangential dashpot: the part of the tangential force the spring does not give,
    /// against the slip.
    pub tangential: f64,
    /// The Coulomb slider: the elastic energy the spring lost when the cap reset it.
    pub slide: f64,
}

/// A complete contact law: the force of one contact from its kinematics and its history.
pub trait ContactLaw: Send + Sync {
    /// False when the law can never produce a tangential force: the solver then skips torques
    /// and rotation entirely.
    const TANGENTIAL: bool;

    /// What the law carries per contact from one step to the next; the solver stores, saves,
    /// hashes and restores it without looking inside.
    type History: History;

    /// Force and torques of a contact, updating its `history` over one time step `dt` (time).
    fn evaluate(&self, k: &PairKinematics, history: &mut Self::History, dt: f64) -> PairForce;

    /// Elastic energy held by a contact of overlap `delta` (length, > 0), effective radius
    /// `r_star` (R* = r_P·r_I/(r_P + r_I), length; [`PairKinematics::r_star`]) and history
    /// `history` (energy units): what its springs can give back to the particles. The run
    /// guard's energy balance counts it, so that a packing releasing its springs is not taken
    /// for a gain.
    fn stored_energy(&self, delta: f64, r_star: f64, history: &Self::History) -> f64;

    /// The part of [`ContactLaw::stored_energy`] a function of the overlap `delta` (length)
    /// and the effective radius `r_star` (length) alone (energy units): what the normal spring
    /// holds and gives back exactly as the overlap closes. The run guard's contact accounts
    /// count it at every step. By default the energy held with a fresh history.
    fn normal_energy(&self, delta: f64, r_star: f64) -> f64 {
        self.stored_energy(delta, r_star, &Self::History::default())
    }

    /// Whether [`ContactLaw::evaluate_dissipating`] reports the dissipation split by part. False
    /// by default: the energy ledger then says the dissipation is not split and leaves its
    /// residual unmeasured, rather than take a zero for a closed balance.
    const SPLITS_DISSIPATION: bool = false;

    /// [`ContactLaw::evaluate`], and the energy the contact's dissipative parts took over the
    /// step ([`Dissipated`]; meaningful only with [`ContactLaw::SPLITS_DISSIPATION`]). The
    /// force must be bit for bit that of [`ContactLaw::evaluate`]. By default that force and
    /// nothing split.
    #[inline(always)]
    fn evaluate_dissipating(
        &self,
        k: &PairKinematics,
        history: &mut Self::History,
        dt: f64,
    ) -> (PairForce, Dissipated) {
        (self.evaluate(k, history, dt), Dissipated::default())
    }
}

/// A normal model and a tangential model composed into a contact law.
#[derive(Clone, Debug)]
pub struct Composed<N, T> {
    pub normal: N,
    pub tangential: T,
}

/// The solver stores one `Vec3` of history per contact: a law composes the tangential models
/// whose history it is.
impl<N: NormalModel, T: TangentialModel> ContactLaw for Composed<N, T> {
    const TANGENTIAL: bool = T::ACTIVE;
    /// The tangential model's history (the normal models keep none).
    type History = T::History;

    #[inline(always)]
    fn evaluate(&self, k: &PairKinematics, xi: &mut T::History, dt: f64) -> PairForce {
        self.evaluate_dissipating(k, xi, dt).0
    }

    fn stored_energy(&self, delta: f64, r_star: f64, xi: &T::History) -> f64 {
        self.normal.stored_energy(delta, r_star) + self.tangential.stored_energy(xi)
    }

    fn normal_energy(&self, delta: f64, r_star: f64) -> f64 {
        self.normal.stored_energy(delta, r_star)
    }

    const SPLITS_DISSIPATION: bool = N::SPLITS_DISSIPATION && T::SPLITS_DISSIPATION;

    #[inline(always)]
    fn evaluate_dissipating(
        &self,
        k: &PairKinematics,
        xi: &mut T::History,
        dt: f64,
    ) -> (PairForce, Dissipated) {
        let fn_signed = self.normal.force(k);
        let normal = self.normal.dissipated(k, fn_signed, dt);
        if T::ACTIVE {
            let (ft, [tangential, slide]) = self.tangential.force_dissipating(k, fn_signed, xi, dt);
            let f = fn_signed * k.n + ft;
            // Lever arms of the torques: to the contact point in the middle of the overlap
            // (MercuryDPM), or full radii along n where the convention's source does so.
            let (arm_p, arm_i) = if T::FULL_RADIUS_LEVER {
                (-k.rad_p * k.n, k.rad_i * k.n)
            } else {
                (k.arm_p, k.arm_i)
            };
            let force = PairForce {
                f,
                fn_signed,
                // Torque about each centre: (c − x) × F (MercuryDPM BaseInteraction).
                torque_p: arm_p.cross(&f),
                torque_i: arm_i.cross(&(-f)),
            };
            let lost = Dissipated {
                normal,
                tangential,
                slide,
            };
            (force, lost)
        } else {
            let force = PairForce {
                f: fn_signed * k.n,
                fn_signed,
                torque_p: Vec3::zeros(),
                torque_i: Vec3::zeros(),
            };
            let lost = Dissipated {
                normal,
                ..Dissipated::default()
            };
            (force, lost)
        }
    }
}

/// The benchmark's law: linear spring–dashpot normal force with absolute damping (not clipped)
/// and MercuryDPM's sliding friction (rate-form spring, Coulomb cap on spring + dashpot).
pub type MercuryLaw = Composed<LinearSpringDashpot, MercurySlidingFriction>;

/// The frictionless variant: the same normal force, no tangential force, no rotation.
pub type FrictionlessLaw = Composed<LinearSpringDashpot, Frictionless>;

#[cfg(test)]
mod tests {
    use super::*;

    fn input(r: Vec3) -> PairInput {
        PairInput::at_rest(r, 0.5, 0.5)
    }

    #[test]
    fn touching_exactly_is_not_a_contact() {
        assert!(input(Vec3::new(1.0, 0.0, 0.0)).kinematics().is_none());
        assert!(input(Vec3::new(0.999, 0.0, 0.0)).kinematics().is_some());
    }

    #[test]
    fn normal_points_from_i_to_p_and_overlap_is_positive() {
        let k = input(Vec3::new(0.0, 0.0, 0.9)).kinematics().unwrap();
        assert_eq!(k.n, Vec3::new(0.0, 0.0, 1.0));
        assert!((k.delta - 0.1).abs() < 1e-15);
        // contact point in the middle of the overlap: c = x_P − (r_P − δ/2) n
        assert!((k.arm_p.z + 0.45).abs() < 1e-15);
        assert!((k.arm_i.z - 0.45).abs() < 1e-15);
    }

    #[test]
    fn spin_enters_the_relative_velocity_with_lever_arm_r_minus_half_overlap() {
        let mut p = input(Vec3::new(0.0, 0.0, 0.9));
        p.w_p = Vec3::new(0.0, 1.0, 0.0);
        let k = p.kinematics().unwrap();
        // ω × (c − x_P) = (0,1,0) × (0,0,−0.45) = (−0.45, 0, 0)
        assert!((k.vt.x + 0.45).abs() < 1e-15);
    }
}
