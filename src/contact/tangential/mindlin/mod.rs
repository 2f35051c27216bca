//! Mindlin tangential laws: a spring whose stiffness follows the contact radius,
//! kt = c·8G*·a with a = √(R*·δ) (Mindlin 1949; Johnson, Contact Mechanics, 1985, eq. 7.38),
//! not the case's constant kt.
//!
//! The no-slip laws ([`NoSlip`]) differ in what they store and how the store follows a change
//! of the contact radius: a displacement ξ with the force −kt(a)·ξ at the current stiffness
//! ([`Displacement`]; LAMMPS `mindlin`, LIGGGHTS `history`, MercuryDPM), or the force itself,
//! incremented by −kt(a)·slip·dt ([`Force`]; LAMMPS `mindlin/force`, Kratos, Yade), either of
//! them scaled by a/a_prev when the contact unloads (`RESCALE`; LAMMPS `mindlin_rescale`,
//! Kratos' √(δ/δ_prev) = a/a_prev). Each is composed with a slip, a frame update and a cap of
//! [`super`], as the linear conventions are; each peer's composition is one file here. The
//! reference law, Mindlin–Deresiewicz partial slip with its turning points, is
//! [`deresiewicz`].
//!
//! Conventions as in [`super`]: n from I to P, the slip of P's contact point relative to I's,
//! the force on P; the stiffness in force/length, c·8G* in force/length².

pub mod deresiewicz;
pub mod force;
pub mod kratos;
pub mod lammps;
pub mod liggghts;
pub mod mercury;
pub mod rescale;
pub mod yade;

use std::marker::PhantomData;

use super::cap::Cap;
use super::frame::FrameUpdate;
use super::slip::Slip;
use super::{Arms, TangentialModel};
use crate::contact::PairKinematics;
use crate::state::History;
use crate::Vec3;

/// The contact radius a = √(R*·δ) (length) of the contact `k` (Hertz; Johnson 1985, eq. 4.23).
#[inline(always)]
pub fn contact_radius(k: &PairKinematics) -> f64 {
    (k.r_star() * k.delta).sqrt()
}

/// LAMMPS' threshold below which its frame update is skipped: an out-of-plane force below
/// 1e-10·μ|fn| (`gran_sub_mod_tangential.cpp`, `EPSILON`).
const SKIP: f64 = 1e-10;

/// The history of a Mindlin spring stored as a displacement: ξ (length) and the contact radius
/// a (length) at the last step; canonical words ξx, ξy, ξz, a.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DisplacementHistory {
    pub xi: Vec3,
    pub a: f64,
}

impl History for DisplacementHistory {
    const WORDS: usize = 4;

    fn put_words(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[self.xi.x, self.xi.y, self.xi.z, self.a]);
    }

    fn from_words(words: &[f64]) -> Self {
        DisplacementHistory {
            xi: Vec3::new(words[0], words[1], words[2]),
            a: words[3],
        }
    }

    fn spring(&self) -> Vec3 {
        self.xi
    }
}

/// The history of a Mindlin spring stored as a force: the elastic force F on P (force units),
/// the contact radius a (length) and the stiffness kt (force/length) at the last step;
/// canonical words Fx, Fy, Fz, a, kt.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceHistory {
    pub force: Vec3,
    pub a: f64,
    pub kt: f64,
}

impl History for ForceHistory {
    const WORDS: usize = 5;

    fn put_words(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[self.force.x, self.force.y, self.force.z, self.a, self.kt]);
    }

    fn from_words(words: &[f64]) -> Self {
        ForceHistory {
            force: Vec3::new(words[0], words[1], words[2]),
            a: words[3],
            kt: words[4],
        }
    }

    /// The displacement that gives the stored force at the last stiffness, −F/kt.
    fn spring(&self) -> Vec3 {
        if self.kt > 0.0 {
            -self.force / self.kt
        } else {
            Vec3::zeros()
        }
    }
}

/// What a no-slip Mindlin law stores and how the store follows the contact radius.
pub trait Storage: Send + Sync {
    type History: History;
    /// Advances the store over the step `dt` (time) with the `slip` (length/time) of the contact
    /// `k` through the frame update `U`; `stiffness` is (a, kt, fcrit): the contact radius
    /// (length), the stiffness kt there (force/length) and μ|fn| (force), from which the frame
    /// update's skip threshold is computed.
    fn advance<U: FrameUpdate>(
        h: &mut Self::History,
        slip: Vec3,
        k: &PairKinematics,
        dt: f64,
        stiffness: (f64, f64, f64),
    );
    /// The displacement (length) whose force at `kt` is the stored elastic force.
    fn displacement(h: &Self::History, kt: f64) -> Vec3;
    /// Stores the displacement `xi` (length) the cap left, at the stiffness `kt`.
    fn store(h: &mut Self::History, xi: Vec3, kt: f64);
    /// The elastic energy (energy units) of the store for the law of stiffness per contact
    /// radius `k0` (force/length²): ½·kt·|ξ|² = ½·|F|²/kt at the last step's kt = k0·a.
    fn energy(h: &Self::History, k0: f64) -> f64;
}

/// The factor a/a_prev by which an unloading contact scales its store when `RESCALE` (LAMMPS
/// `mindlin_rescale`: `if (contact_radius < history[3])`), 1 otherwise.
#[inline(always)]
fn unloading<const RESCALE: bool>(a: f64, a_prev: f64) -> f64 {
    if RESCALE && a < a_prev {
        a / a_prev
    } else {
        1.0
    }
}

/// The store is a displacement ξ, the force −kt(a)·ξ at the current stiffness: a change of a
/// with no tangential motion changes the force (LAMMPS `tangential mindlin`; LAMMPS PR #2196).
/// With `RESCALE`, ξ is scaled by a/a_prev when the contact unloads (`mindlin_rescale`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Displacement<const RESCALE: bool>;

impl<const RESCALE: bool> Storage for Displacement<RESCALE> {
    type History = DisplacementHistory;

    #[inline(always)]
    fn advance<U: FrameUpdate>(
        h: &mut DisplacementHistory,
        slip: Vec3,
        k: &PairKinematics,
        dt: f64,
        (a, kt, fcrit): (f64, f64, f64),
    ) {
        h.xi *= unloading::<RESCALE>(a, h.a);
        U::advance(&mut h.xi, slip, k, dt, SKIP * fcrit / kt);
        h.a = a;
    }

    #[inline(always)]
    fn displacement(h: &DisplacementHistory, _: f64) -> Vec3 {
        h.xi
    }

    #[inline(always)]
    fn store(h: &mut DisplacementHistory, xi: Vec3, _: f64) {
        h.xi = xi;
    }

    fn energy(h: &DisplacementHistory, k0: f64) -> f64 {
        0.5 * k0 * h.a * h.xi.norm_squared()
    }
}

/// The store is the elastic force, incremented by −kt(a)·slip·dt: a change of a with no
/// tangential motion leaves the force (LAMMPS `mindlin/force`, eq. 18 of Thornton et al.,
/// Powder Technol. 233, 30, 2013). With `RESCALE`, the force is scaled by a/a_prev when the
/// contact unloads (`mindlin_rescale/force`; Kratos' √(δ/δ_prev)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Force<const RESCALE: bool>;

impl<const RESCALE: bool> Storage for Force<RESCALE> {
    type History = ForceHistory;

    #[inline(always)]
    fn advance<U: FrameUpdate>(
        h: &mut ForceHistory,
        slip: Vec3,
        k: &PairKinematics,
        dt: f64,
        (a, kt, fcrit): (f64, f64, f64),
    ) {
        h.force *= unloading::<RESCALE>(a, h.a);
        // the frame updates are linear in the store and the rate: the force's rate is −kt·slip
        U::advance(&mut h.force, -kt * slip, k, dt, SKIP * fcrit);
        h.a = a;
        h.kt = kt;
    }

    #[inline(always)]
    fn displacement(h: &ForceHistory, kt: f64) -> Vec3 {
        -h.force / kt
    }

    #[inline(always)]
    fn store(h: &mut ForceHistory, xi: Vec3, kt: f64) {
        h.force = -kt * xi;
    }

    fn energy(h: &ForceHistory, _: f64) -> f64 {
        if h.kt > 0.0 {
            0.5 * h.force.norm_squared() / h.kt
        } else {
            0.0
        }
    }
}

/// A no-slip Mindlin spring kt = k0·a (k0 = c·8G*, force/length²; a the contact radius), an
/// absolute dashpot γt (mass/time) and a Coulomb slider μ, made of a slip `S`, a frame update
/// `U`, a cap `C` and a storage `K`; torques with full radii when `FULL_LEVER`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoSlip<S, U, C, K, const FULL_LEVER: bool> {
    pub k0: f64,
    pub gammat: f64,
    pub mu: f64,
    parts: Parts<S, U, C, K>,
}

/// The parts of a [`NoSlip`] law, held by type only (no data, `Send + Sync` whatever they are).
type Parts<S, U, C, K> = PhantomData<fn() -> (S, U, C, K)>;

impl<S, U, C, K, const FULL_LEVER: bool> NoSlip<S, U, C, K, FULL_LEVER> {
    /// A Mindlin law of stiffness per contact radius `k0` (force/length²: 8G* for Mindlin's
    /// spring), absolute dashpot `gammat` (mass/time) and Coulomb coefficient `mu`.
    pub const fn new(k0: f64, gammat: f64, mu: f64) -> Self {
        NoSlip {
            k0,
            gammat,
            mu,
            parts: PhantomData,
        }
    }
}

impl<S: Slip, U: FrameUpdate, C: Cap, K: Storage, const FULL_LEVER: bool> TangentialModel
    for NoSlip<S, U, C, K, FULL_LEVER>
{
    type History = K::History;
    const ACTIVE: bool = true;
    const FULL_RADIUS_LEVER: bool = FULL_LEVER;
    const SLIP_ARMS: Arms = S::ARMS;
    const SLIP_SCALES_CENTRES: bool = S::SCALES_CENTRES;

    #[inline(always)]
    fn force(&self, k: &PairKinematics, fn_signed: f64, h: &mut K::History, dt: f64) -> Vec3 {
        let a = contact_radius(k);
        let kt = self.k0 * a;
        let slip = S::slip(k, dt);
        let fcrit = self.mu * fn_signed.abs();
        K::advance::<U>(h, slip, k, dt, (a, kt, fcrit));
        let mut xi = K::displacement(h, kt);
        let f = C::cap(&mut xi, slip, fcrit, kt, self.gammat);
        K::store(h, xi, kt);
        f
    }

    /// The no-slip spring's energy at the last step's stiffness ([`Storage::energy`]).
    fn stored_energy(&self, h: &K::History) -> f64 {
        K::energy(h, self.k0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tangential::test_kinematics;

    /// A contact of spheres of radius 0.5 at overlap `delta`, P sliding along x at `vt`.
    fn pair(delta: f64, vt: f64) -> PairKinematics {
        test_kinematics(
            Vec3::new(0.0, 0.0, 1.0 - delta),
            Vec3::new(vt, 0.0, 0.0),
            Vec3::zeros(),
            Vec3::zeros(),
        )
    }

    /// The stiffness is 8G*·a: a small slip from rest gives −8G*·√(R*δ)·slip·dt, whether the
    /// law stores a displacement or a force, and the histories round-trip through their words.
    #[test]
    fn a_first_increment_has_mindlin_s_stiffness_and_the_histories_round_trip() {
        let (g, delta, v, dt) = (1e7, 1e-3, 1e-3, 1e-4);
        let k = pair(delta, v);
        let kt = 8.0 * g * (0.25 * delta).sqrt();
        let expected = -kt * v * dt;
        let mut d = DisplacementHistory::default();
        let f = lammps::LammpsMindlin::new(8.0 * g, 0.0, 0.3).force(&k, 1e3, &mut d, dt);
        assert!((f.x / expected - 1.0).abs() < 1e-12, "{f:?}");
        let mut h = ForceHistory::default();
        let f = force::LammpsMindlinForce::new(8.0 * g, 0.0, 0.3).force(&k, 1e3, &mut h, dt);
        assert!((f.x / expected - 1.0).abs() < 1e-12, "{f:?}");
        let mut words = Vec::new();
        d.put_words(&mut words);
        h.put_words(&mut words);
        assert_eq!(words.len(), 9);
        assert_eq!(DisplacementHistory::from_words(&words[..4]), d);
        assert_eq!(ForceHistory::from_words(&words[4..]), h);
        assert!((h.spring() - d.spring()).norm() < 1e-12 * d.xi.norm());
    }

    /// With no tangential motion, a smaller overlap changes the force of a stored displacement
    /// by a/a_prev, leaves a stored force, and the rescaled laws scale either by a/a_prev.
    #[test]
    fn an_unloading_contact_changes_ft_as_its_store_says() {
        let (g, dt) = (1e7, 1e-4);
        let load = pair(1e-3, 1e-2);
        let held = pair(0.5e-3, 0.0);
        let ratio = 0.5f64.sqrt();
        let ft = |f: Vec3| f.x;
        macro_rules! after {
            ($law:ty) => {{
                let law = <$law>::new(8.0 * g, 0.0, 0.3);
                let mut h = Default::default();
                let before = ft(law.force(&load, 1e3, &mut h, dt));
                ft(law.force(&held, 1e3, &mut h, dt)) / before
            }};
        }
        assert!((after!(lammps::LammpsMindlin) - ratio).abs() < 1e-12);
        assert!((after!(force::LammpsMindlinForce) - 1.0).abs() < 1e-12);
        assert!((after!(rescale::LammpsMindlinRescale) - ratio * ratio).abs() < 1e-12);
        assert!((after!(kratos::KratosHertzMindlin) - ratio).abs() < 1e-12);
    }
}
