//! The tangential conventions of peer codes and an objective reference law, each composed of
//! three parts chosen once at build time: the slip (how the relative tangential velocity at the
//! contact is formed), the frame update (how the stored spring follows the turning contact
//! plane) and the Coulomb cap. MercuryDPM's rate form, the benchmark default, is
//! [`super::MercurySlidingFriction`].
//!
//! Conventions as in the rest of [`super`]: n points from I to P; the slip is the velocity of
//! P's material point at the contact relative to I's, tangential part; the spring ξ (length) is
//! stored so that its elastic force on P is −kt ξ; the cap is mu·|fn| with the signed normal
//! force fn of the same contact.
//!
//! The frame updates that rotate the spring need the previous normal. verdem does not store it:
//! its drift moved both centres by exactly v·dt with the half-step velocities the law sees, so
//! the previous separation is r − (v_P − v_I)·dt, to rounding ([`previous_normal`]).

use std::marker::PhantomData;

use super::{PairKinematics, TangentialModel};
use crate::Vec3;

/// How the relative tangential velocity at the contact is formed (over the step `dt` that
/// ends at the current positions).
pub trait Slip: Send + Sync {
    /// The tangential relative velocity of P with respect to I at the contact (length/time),
    /// perpendicular to the normal (unit, from I to P); `dt` is the time step (time).
    fn slip(k: &PairKinematics, dt: f64) -> Vec3;
}

/// Lever arms to the contact point in the middle of the overlap, R − δ/2 (MercuryDPM; LIGGGHTS
/// 3.8 `tangential_model_history.h` via `sidata.cri = radi − 0.5·deltan`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HalfOverlapSlip;

impl Slip for HalfOverlapSlip {
    #[inline(always)]
    fn slip(k: &PairKinematics, _: f64) -> Vec3 {
        k.vt
    }
}

/// Full radii as lever arms: v_P − v_I − (R_P ω_P + R_I ω_I) × n, tangential part (LAMMPS
/// `pair_gran_hooke_history.cpp` and `pair_granular.cpp`: wr = radi·ω_i + radj·ω_j,
/// vtr = vt − del × wr / r).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FullRadiusSlip;

impl Slip for FullRadiusSlip {
    #[inline(always)]
    fn slip(k: &PairKinematics, _: f64) -> Vec3 {
        let v = k.v_centres - (k.rad_p * k.w_p + k.rad_i * k.w_i).cross(&k.n);
        v - v.dot(&k.n) * k.n
    }
}

/// Objective slip at the current normal: α(v_P − v_I) − (R_P ω_P + R_I ω_I) × n with
/// α = (R_P + R_I)/|r|, tangential part (McNamara, García-Rojo & Herrmann, PRE 77, 031304,
/// 2008; Yade `ScGeom::getIncidentVel` with `avoidGranularRatcheting`, which uses the new
/// normal). Zero for a rigid motion in the continuum limit; over a finite step it leaves an
/// error of first order in the turn when the rotation mixes tilt and twist.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ObjectiveSlip;

impl Slip for ObjectiveSlip {
    #[inline(always)]
    fn slip(k: &PairKinematics, _: f64) -> Vec3 {
        objective_slip(k, k.n)
    }
}

/// The objective slip with the lever arms along `m`, tangential part with respect to `m`.
#[inline(always)]
fn objective_slip(k: &PairKinematics, m: Vec3) -> Vec3 {
    let alpha = (k.rad_p + k.rad_i) / k.dist;
    let v = alpha * k.v_centres - (k.rad_p * k.w_p + k.rad_i * k.w_i).cross(&m);
    v - v.dot(&m) * m
}

/// Objective slip at the step's midpoint normal m = (n_old + n)/|…|, then projected onto the
/// new tangent plane. Over a step the centres' chord (v_P − v_I)·dt of a rigid rotation is
/// exactly tangent at m (Cayley: (R − I) r = 2 tan(φ/2) ê × (R + I) r/2), so the spin term
/// cancels it to third order in the turn for any rotation axis (the objective reference law).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MidpointObjectiveSlip;

impl Slip for MidpointObjectiveSlip {
    #[inline(always)]
    fn slip(k: &PairKinematics, dt: f64) -> Vec3 {
        let m = (previous_normal(k, dt) + k.n).normalize();
        let v = objective_slip(k, m);
        v - v.dot(&k.n) * k.n
    }
}

/// The normal of the previous step, n_old = (r − (v_P − v_I)·dt)/|…| (unit, from I to P).
#[inline(always)]
pub fn previous_normal(k: &PairKinematics, dt: f64) -> Vec3 {
    (k.r - k.v_centres * dt).normalize()
}

/// How the stored spring follows the contact plane over one step.
pub trait FrameUpdate: Send + Sync {
    /// True when the update follows the increment ξ += slip·dt, false when it precedes it.
    const AFTER_INCREMENT: bool;
    /// Updates ξ; `skip_below` is the out-of-plane length below which LAMMPS' `granular`
    /// skips its update (1e-10·mu|fn|/kt), ignored by the others.
    fn update(xi: &mut Vec3, k: &PairKinematics, dt: f64, skip_below: f64);
}

/// No frame update at all: the spring keeps its lab-frame direction (Cundall & Strack 1979).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoFrameUpdate;

impl FrameUpdate for NoFrameUpdate {
    const AFTER_INCREMENT: bool = true;
    #[inline(always)]
    fn update(_: &mut Vec3, _: &PairKinematics, _: f64, _: f64) {}
}

/// Increment, then project onto the new tangent plane, shortening the spring (LAMMPS
/// `pair_gran_hooke_history.cpp` "rotate shear displacements"; LIGGGHTS 3.8
/// `tangential_model_history.h`, same lines).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProjectAfter;

impl FrameUpdate for ProjectAfter {
    const AFTER_INCREMENT: bool = true;
    #[inline(always)]
    fn update(xi: &mut Vec3, k: &PairKinematics, _: f64, _: f64) {
        *xi -= xi.dot(&k.n) * k.n;
    }
}

/// Project onto the new tangent plane and rescale to the old length, then increment (LAMMPS
/// `pair_granular.cpp`, `tangential linear_history`: "rotate and update displacements", done
/// only when |ξ·n|·kt > 1e-10·Fscrit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProjectRescale;

impl FrameUpdate for ProjectRescale {
    const AFTER_INCREMENT: bool = false;
    #[inline(always)]
    fn update(xi: &mut Vec3, k: &PairKinematics, _: f64, skip_below: f64) {
        let out_of_plane = xi.dot(&k.n);
        if out_of_plane.abs() > skip_below {
            let length = xi.norm();
            *xi -= out_of_plane * k.n;
            let projected = xi.norm();
            *xi *= if projected > 0.0 {
                length / projected
            } else {
                0.0
            };
        }
    }
}

/// Yade's first-order rotation (`ScGeom::rotate`): ξ −= ξ × (n_old × n), then
/// ξ −= ξ × (½(ω_P + ω_I)·n_old·dt · n_old).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstOrderRotation;

impl FrameUpdate for FirstOrderRotation {
    const AFTER_INCREMENT: bool = false;
    #[inline(always)]
    fn update(xi: &mut Vec3, k: &PairKinematics, dt: f64, _: f64) {
        let n_old = previous_normal(k, dt);
        *xi -= xi.cross(&n_old.cross(&k.n));
        let twist = 0.5 * dt * (k.w_p + k.w_i).dot(&n_old);
        *xi -= xi.cross(&(twist * n_old));
    }
}

/// Exact rotation with the contact frame: the tilt n_old → n (Rodrigues, minimal rotation),
/// then the twist about n by ½(ω_P + ω_I)·m·dt with m the step's midpoint normal (the
/// objective reference law; the symmetric m makes the split tilt + twist exact to second
/// order per step for any axis, where n_old or n would leave a first-order drift).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExactRotation;

impl FrameUpdate for ExactRotation {
    const AFTER_INCREMENT: bool = false;
    #[inline(always)]
    fn update(xi: &mut Vec3, k: &PairKinematics, dt: f64, _: f64) {
        let n_old = previous_normal(k, dt);
        // Minimal rotation taking n_old to n, applied to ξ ⟂ n_old.
        *xi -= xi.dot(&k.n) / (1.0 + n_old.dot(&k.n)) * (n_old + k.n);
        let m = (n_old + k.n).normalize();
        let phi = 0.5 * dt * (k.w_p + k.w_i).dot(&m);
        *xi = *xi * phi.cos() + k.n.cross(xi) * phi.sin();
    }
}

/// The Coulomb cap: the tangential force on P from the spring ξ and the slip, with ξ reset
/// when sliding.
pub trait Cap: Send + Sync {
    /// The tangential force on P (force units) from the spring ξ (length) and the dashpot on
    /// `slip` (length/time), limited to the critical force `fcrit` = μ|fn| in the way the
    /// convention states, resetting ξ when the contact slides. `kt` in force/length, `gammat`
    /// in mass/time.
    fn cap(xi: &mut Vec3, slip: Vec3, fcrit: f64, kt: f64, gammat: f64) -> Vec3;
}

/// Cap spring + dashpot together and reset the spring to match the capped total; a sliding
/// contact with no stretched spring gets no tangential force (LAMMPS `pair_gran_hooke_history`
/// and `pair_granular`, "rescale frictional displacements and forces if needed").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LammpsCap;

impl Cap for LammpsCap {
    #[inline(always)]
    fn cap(xi: &mut Vec3, slip: Vec3, fcrit: f64, kt: f64, gammat: f64) -> Vec3 {
        let f = -(kt * *xi + gammat * slip);
        let magnitude = f.norm();
        if magnitude <= fcrit {
            return f;
        }
        if *xi == Vec3::zeros() {
            return Vec3::zeros();
        }
        let capped = f * (fcrit / magnitude);
        *xi = -(capped + gammat * slip) / kt;
        capped
    }
}

/// Cap the spring alone at mu|fn| and drop the dashpot while sliding; the dashpot is added only
/// while the contact sticks (LIGGGHTS 3.8 `tangential_model_history.h`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LiggghtsCap;

impl Cap for LiggghtsCap {
    #[inline(always)]
    fn cap(xi: &mut Vec3, slip: Vec3, fcrit: f64, kt: f64, gammat: f64) -> Vec3 {
        let spring = -kt * *xi;
        let magnitude = spring.norm();
        if magnitude <= fcrit {
            return spring - gammat * slip;
        }
        let capped = spring * (fcrit / magnitude);
        *xi = -capped / kt;
        capped
    }
}

/// Cap the elastic part at mu|fn| and store it; then add the dashpot and cap the total again
/// (the dashpot never enters the stored spring; the objective reference law).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpringThenTotal;

impl Cap for SpringThenTotal {
    #[inline(always)]
    fn cap(xi: &mut Vec3, slip: Vec3, fcrit: f64, kt: f64, gammat: f64) -> Vec3 {
        let mut spring = -kt * *xi;
        let magnitude = spring.norm();
        if magnitude > fcrit {
            spring *= fcrit / magnitude;
            *xi = -spring / kt;
        }
        let total = spring - gammat * slip;
        let magnitude = total.norm();
        if magnitude > fcrit {
            total * (fcrit / magnitude)
        } else {
            total
        }
    }
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
    pub fn new(kt: f64, gammat: f64, mu: f64) -> Self {
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
    const ACTIVE: bool = true;
    const FULL_RADIUS_LEVER: bool = FULL_LEVER;

    #[inline(always)]
    fn force(&self, k: &PairKinematics, fn_signed: f64, xi: &mut Vec3, dt: f64) -> Vec3 {
        let slip = S::slip(k, dt);
        let fcrit = self.mu * fn_signed.abs();
        let skip_below = 1e-10 * fcrit / self.kt;
        if !U::AFTER_INCREMENT {
            U::update(xi, k, dt, skip_below);
        }
        *xi += slip * dt;
        if U::AFTER_INCREMENT {
            U::update(xi, k, dt, skip_below);
        }
        C::cap(xi, slip, fcrit, self.kt, self.gammat)
    }
}

/// LAMMPS `pair_style gran/hooke/history` (with absolute damping): full-radius slip, increment
/// then project, cap on spring + dashpot, torques with full radii (`torque[i] -= radi*tor`).
pub type LammpsHookeHistory = Convention<FullRadiusSlip, ProjectAfter, LammpsCap, true>;
/// LAMMPS `pair_style granular … tangential linear_history`: full-radius slip, project and
/// rescale then increment, cap on spring + dashpot, torques with R − δ/2 (`dist_to_contact`).
pub type LammpsGranular = Convention<FullRadiusSlip, ProjectRescale, LammpsCap, false>;
/// LIGGGHTS 3.8 `tangential history`: slip with R − δ/2, increment then project, cap on the
/// spring only, dashpot dropped while sliding.
pub type Liggghts = Convention<HalfOverlapSlip, ProjectAfter, LiggghtsCap, false>;
/// Yade's `ScGeom` with `avoidGranularRatcheting` (its default): objective slip, first-order
/// rotation of the spring, torques with R − δ/2; verdem adds the dashpot and cap of the
/// reference law (Yade's `FrictPhys` has no tangential dashpot).
pub type YadeApprox = Convention<ObjectiveSlip, FirstOrderRotation, SpringThenTotal, false>;
/// Cundall & Strack (Géotechnique 29, 47, 1979): full-radius slip, no frame update at all,
/// torques with full radii.
pub type Cundall1979 = Convention<FullRadiusSlip, NoFrameUpdate, SpringThenTotal, true>;
/// The objective reference law: objective slip (at the step's midpoint normal), exact rotation
/// with the contact frame, elastic part capped and stored, dashpot added and the total capped,
/// torques with R − δ/2.
pub type Objective = Convention<MidpointObjectiveSlip, ExactRotation, SpringThenTotal, false>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::PairInput;

    fn kin(r: Vec3, v_p: Vec3, w_p: Vec3, w_i: Vec3) -> PairKinematics {
        PairInput {
            r,
            rad_p: 0.5,
            rad_i: 0.5,
            v_p,
            v_i: Vec3::zeros(),
            w_p,
            w_i,
        }
        .kinematics()
        .unwrap()
    }

    #[test]
    fn objective_slip_vanishes_for_a_rigid_rotation_and_full_radius_slip_does_not() {
        // Both spheres spin with Ω about y; P's centre moves with Ω × r.
        let r = Vec3::new(0.0, 0.0, 0.99);
        let w = Vec3::new(0.0, 2.0, 0.0);
        let k = kin(r, w.cross(&r), w, w);
        assert!(ObjectiveSlip::slip(&k, 0.0).norm() < 1e-15);
        assert!(MidpointObjectiveSlip::slip(&k, 0.0).norm() < 1e-15);
        assert!(HalfOverlapSlip::slip(&k, 0.0).norm() < 1e-15);
        // full radii: (|r| − R_P − R_I) Ω × n = −δ Ω × n
        let spurious = FullRadiusSlip::slip(&k, 0.0);
        assert!((spurious.norm() - 0.01 * 2.0).abs() < 1e-12);
    }

    #[test]
    fn exact_rotation_keeps_length_and_plane_and_follows_the_tilt() {
        // P moved from (0,0,0.99) to r during dt with velocity v: n_old = z.
        let dt = 1e-2;
        let v = Vec3::new(3.0, 0.0, 0.0);
        let r = Vec3::new(0.0, 0.0, 0.99) + v * dt;
        let k = kin(r, v, Vec3::zeros(), Vec3::zeros());
        assert!((previous_normal(&k, dt) - Vec3::z()).norm() < 1e-15);
        let mut xi = Vec3::new(1e-3, 0.0, 0.0);
        ExactRotation::update(&mut xi, &k, dt, 0.0);
        assert!(xi.dot(&k.n).abs() < 1e-18);
        assert!((xi.norm() - 1e-3).abs() < 1e-18);
        // the tilt turns x towards −z as z turns towards +x
        assert!(xi.z < 0.0);
    }

    #[test]
    fn exact_twist_turns_the_spring_about_n_by_half_the_summed_spin() {
        let r = Vec3::new(0.0, 0.0, 0.99);
        let w = Vec3::new(0.0, 0.0, 100.0);
        let k = kin(r, Vec3::zeros(), w, w);
        let mut xi = Vec3::new(1e-3, 0.0, 0.0);
        let dt = std::f64::consts::FRAC_PI_2 / 100.0;
        ExactRotation::update(&mut xi, &k, dt, 0.0);
        assert!((xi - Vec3::new(0.0, 1e-3, 0.0)).norm() < 1e-18);
        let mut approx = Vec3::new(1e-3, 0.0, 0.0);
        FirstOrderRotation::update(&mut approx, &k, dt, 0.0);
        // first order: ξ + φ n × ξ, longer than ξ
        assert!((approx - Vec3::new(1e-3, 1e-3 * dt * 100.0, 0.0)).norm() < 1e-18);
    }

    #[test]
    fn projection_shortens_and_rescaled_projection_keeps_length() {
        let k = kin(
            Vec3::new(0.0, 0.0, 0.99),
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
        );
        let mut a = Vec3::new(3e-4, 0.0, 4e-4);
        let mut b = a;
        ProjectAfter::update(&mut a, &k, 0.0, 0.0);
        assert_eq!(a, Vec3::new(3e-4, 0.0, 0.0));
        ProjectRescale::update(&mut b, &k, 0.0, 0.0);
        assert!((b - Vec3::new(5e-4, 0.0, 0.0)).norm() < 1e-18);
        let mut c = Vec3::new(3e-4, 0.0, 4e-4);
        ProjectRescale::update(&mut c, &k, 0.0, 1e-3);
        assert_eq!(
            c,
            Vec3::new(3e-4, 0.0, 4e-4),
            "below LAMMPS' threshold: untouched"
        );
    }

    #[test]
    fn caps_differ_in_what_they_limit_and_store() {
        let (kt, gammat, fcrit) = (1000.0, 10.0, 1.0);
        let slip = Vec3::new(0.05, 0.0, 0.0);
        // spring force −2 (over the cap), dashpot −0.5
        let start = Vec3::new(2e-3, 0.0, 0.0);

        let mut xi = start;
        let f = LammpsCap::cap(&mut xi, slip, fcrit, kt, gammat);
        assert!((f.x + 1.0).abs() < 1e-12);
        assert!((-(kt * xi + gammat * slip) - f).norm() < 1e-12);

        let mut xi = start;
        let f = LiggghtsCap::cap(&mut xi, slip, fcrit, kt, gammat);
        assert!((f.x + 1.0).abs() < 1e-12 && (xi.x - 1e-3).abs() < 1e-15);

        let mut xi = start;
        let f = SpringThenTotal::cap(&mut xi, slip, fcrit, kt, gammat);
        assert!((f.x + 1.0).abs() < 1e-12 && (xi.x - 1e-3).abs() < 1e-15);

        // sticking: LIGGGHTS adds the dashpot like the others
        let small = Vec3::new(1e-4, 0.0, 0.0);
        let (mut a, mut b) = (small, small);
        assert_eq!(
            LiggghtsCap::cap(&mut a, slip, fcrit, kt, gammat),
            LammpsCap::cap(&mut b, slip, fcrit, kt, gammat)
        );

        // LAMMPS: sliding with no stretched spring gives no force at all
        let mut zero = Vec3::zeros();
        let f = LammpsCap::cap(&mut zero, Vec3::new(1.0, 0.0, 0.0), fcrit, kt, gammat);
        assert_eq!(f, Vec3::zeros());
    }
}
