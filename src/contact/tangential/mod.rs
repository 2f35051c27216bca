//! Tangential models: elastic spring ξ stored per contact, dashpot and Coulomb cap. The
//! returned vector is the tangential force on P.
//!
//! The tangential conventions of peer codes and an objective reference law are each composed
//! of three parts chosen once at build time: the slip ([`slip`]: how the relative tangential
//! velocity at the contact is formed), the frame update ([`frame`]: how the stored spring
//! follows the turning contact plane) and the Coulomb cap ([`cap`]). The compositions are named
//! in [`conventions`].
//!
//! Conventions as in the rest of [`super`]: n points from I to P; the slip is the velocity of
//! P's material point at the contact relative to I's, tangential part; the spring ξ (length) is
//! stored so that its elastic force on P is −kt ξ; the cap is mu·|fn| with the signed normal
//! force fn of the same contact.
//!
//! The frame updates that rotate the spring need the previous normal. verdem does not store it:
//! its drift moved both centres by exactly v·dt with the half-step velocities the law sees, so
//! the previous separation is r − (v_P − v_I)·dt, to rounding ([`previous_normal`]).

pub mod cap;
pub mod conventions;
pub mod frame;
pub mod slip;

use std::marker::PhantomData;

use super::PairKinematics;
use crate::Vec3;
use cap::Cap;
use frame::FrameUpdate;
use slip::Slip;

/// The lever arms from a sphere's centre to its contact along which a slip takes the spins or a
/// torque takes the force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arms {
    /// To the contact point in the middle of the overlap, R − δ/2: they change with the overlap.
    HalfOverlap,
    /// The full radii along the normal, −R_P n and R_I n: constant.
    FullRadius,
}

/// A tangential model. `fn_signed` is the signed normal force of the same contact; `xi` is the
/// contact's history, updated in place over the step `dt`.
pub trait TangentialModel: Send + Sync {
    /// What a contact carries from step to step: the elastic tangential displacement ξ
    /// (length) for every model so far.
    type History: crate::state::History;
    /// False for models that never produce a tangential force.
    const ACTIVE: bool;
    /// True when the torques use the full radii as lever arms (−R_P n, R_I n) instead of the
    /// arms to the contact point in the middle of the overlap.
    const FULL_RADIUS_LEVER: bool = false;
    /// The lever arms along which the spins enter the model's slip.
    const SLIP_ARMS: Arms;
    /// Whether the slip scales the centres' relative velocity by α = (R_P + R_I)/|r| (the
    /// objective slip).
    const SLIP_SCALES_CENTRES: bool;
    /// The tangential force on P (force units) for a contact with kinematics `k`, signed normal
    /// force `fn_signed` (positive repulsive), history `xi` (updated in place) and time step
    /// `dt` (time).
    fn force(&self, k: &PairKinematics, fn_signed: f64, xi: &mut Self::History, dt: f64) -> Vec3;

    /// Elastic energy held by the tangential spring of history `xi` (energy units).
    fn stored_energy(&self, xi: &Self::History) -> f64;

    /// Whether [`TangentialModel::force_dissipating`] is implemented (false by default: the
    /// law's dissipation is then not split).
    const SPLITS_DISSIPATION: bool = false;

    /// [`TangentialModel::force`] (bit for bit), and the energy (energy units) its dashpot and
    /// its Coulomb slider took over the step, `[dashpot, slider]` (see
    /// [`crate::contact::Dissipated`]). Zeros by default (not split).
    #[inline(always)]
    fn force_dissipating(
        &self,
        k: &PairKinematics,
        fn_signed: f64,
        xi: &mut Self::History,
        dt: f64,
    ) -> (Vec3, [f64; 2]) {
        (self.force(k, fn_signed, xi, dt), [0.0; 2])
    }
}

/// No tangential force at all (mu = 0 or no friction requested).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frictionless;

impl TangentialModel for Frictionless {
    type History = Vec3;
    const ACTIVE: bool = false;
    /// No slip is formed; the contact point's arms, as for the torques it does not make.
    const SLIP_ARMS: Arms = Arms::HalfOverlap;
    const SLIP_SCALES_CENTRES: bool = false;
    #[inline(always)]
    fn force(&self, _: &PairKinematics, _: f64, _: &mut Vec3, _: f64) -> Vec3 {
        Vec3::zeros()
    }

    fn stored_energy(&self, _: &Vec3) -> f64 {
        0.0
    }

    /// No tangential force takes any energy.
    const SPLITS_DISSIPATION: bool = true;
}

/// The normal of the previous step, n_old = (r − (v_P − v_I)·dt)/|…| (unit, from I to P).
#[inline(always)]
pub fn previous_normal(k: &PairKinematics, dt: f64) -> Vec3 {
    (k.r - k.v_centres * dt).normalize()
}

/// A tangential spring kt (force/length), dashpot γt (mass/time) and Coulomb slider mu, made of
/// a slip `S`, a frame update `U` and a cap `C`; torques use full radii when `FULL_LEVER`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convention<S, U, C, const FULL_LEVER: bool> {
    pub kt: f64,
    pub gammat: f64,
    pub mu: f64,
    parts: Parts<S, U, C>,
}

/// The parts of a [`Convention`], held by type only (no data, `Send + Sync` whatever they are).
type Parts<S, U, C> = PhantomData<fn() -> (S, U, C)>;

impl<S, U, C, const FULL_LEVER: bool> Convention<S, U, C, FULL_LEVER> {
    /// A tangential law with spring `kt` (force/length), dashpot `gammat` (mass/time, absolute)
    /// and Coulomb coefficient `mu`.
    pub const fn new(kt: f64, gammat: f64, mu: f64) -> Self {
        Convention {
            kt,
            gammat,
            mu,
            parts: PhantomData,
        }
    }
}

impl<S: Slip, U: FrameUpdate, C: Cap, const FULL_LEVER: bool> TangentialModel
    for Convention<S, U, C, FULL_LEVER>
{
    type History = Vec3;
    const ACTIVE: bool = true;
    const FULL_RADIUS_LEVER: bool = FULL_LEVER;
    const SLIP_ARMS: Arms = S::ARMS;
    const SLIP_SCALES_CENTRES: bool = S::SCALES_CENTRES;

    #[inline(always)]
    fn force(&self, k: &PairKinematics, fn_signed: f64, xi: &mut Vec3, dt: f64) -> Vec3 {
        self.force_dissipating(k, fn_signed, xi, dt).0
    }

    /// ½·kt·|ξ|²: the spring's elastic force on P is −kt·ξ.
    fn stored_energy(&self, xi: &Vec3) -> f64 {
        0.5 * self.kt * xi.norm_squared()
    }

    const SPLITS_DISSIPATION: bool = true;

    /// The dashpot takes −(Ft + kt·ξ)·slip·dt, the part of the force Ft the spring ξ (after the
    /// cap) does not give, against the slip. The slider takes what the cap's reset released
    /// from the spring, ½·kt·(|ξ₁|² − |ξ₂|²) (ξ₁ the spring before the cap, ξ₂ after it), less
    /// ½·kt·(ξ₁ − ξ₂)·(ξ₁ − ξ₀) (ξ₀ the spring at the start of the step): the part of the release
    /// the spring's force never did as work over this step's increment ξ₁ − ξ₀. With it the
    /// spring's work over the steps, its energy and the slider's share telescope exactly: a
    /// contact sliding steadily gives kt·ξ₂·slip·dt, an abrupt reset with no increment the whole
    /// release.
    #[inline(always)]
    fn force_dissipating(
        &self,
        k: &PairKinematics,
        fn_signed: f64,
        xi: &mut Vec3,
        dt: f64,
    ) -> (Vec3, [f64; 2]) {
        let slip = S::slip(k, dt);
        let fcrit = self.mu * fn_signed.abs();
        let skip_below = 1e-10 * fcrit / self.kt;
        let start = *xi;
        U::advance(xi, slip, k, dt, skip_below);
        let stretched = *xi;
        let f = C::cap(xi, slip, fcrit, self.kt, self.gammat);
        let dashpot = -(f + self.kt * *xi).dot(&slip) * dt;
        let reset = stretched - *xi;
        let released = stretched.norm_squared() - xi.norm_squared();
        let slide = 0.5 * self.kt * (released - reset.dot(&(stretched - start)));
        (f, [dashpot, slide])
    }
}

/// The kinematics of a pair of spheres of radius 0.5 at separation `r` (I at rest at the
/// origin), for the parts' tests.
#[cfg(test)]
pub(crate) fn test_kinematics(r: Vec3, v_p: Vec3, w_p: Vec3, w_i: Vec3) -> PairKinematics {
    crate::contact::PairInput {
        r,
        rad_p: 0.5,
        rad_i: 0.5,
        inv_mass_p: 0.0,
        inv_mass_i: 0.0,
        v_p,
        v_i: Vec3::zeros(),
        w_p,
        w_i,
    }
    .kinematics()
    .unwrap()
}
