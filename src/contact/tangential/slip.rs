//! Slips: how the relative tangential velocity at the contact is formed. The slip is the
//! velocity of P's material point at the contact relative to I's, tangential part.

use super::{previous_normal, Arms};
use crate::contact::PairKinematics;
use crate::Vec3;

/// How the relative tangential velocity at the contact is formed (over the step `dt` that
/// ends at the current positions).
pub trait Slip: Send + Sync {
    /// The lever arms along which the spins enter the slip.
    const ARMS: Arms;
    /// Whether the centres' relative velocity enters scaled by α = (R_P + R_I)/|r| (the
    /// objective slip), so that a rigid rotation of the pair leaves no slip.
    const SCALES_CENTRES: bool;
    /// The tangential relative velocity of P with respect to I at the contact (length/time),
    /// perpendicular to the normal (unit, from I to P); `dt` is the time step (time).
    fn slip(k: &PairKinematics, dt: f64) -> Vec3;
}

/// Lever arms to the contact point in the middle of the overlap, R − δ/2 (MercuryDPM; LIGGGHTS
/// 3.8 `tangential_model_history.h` via `sidata.cri = radi − 0.5·deltan`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HalfOverlapSlip;

impl Slip for HalfOverlapSlip {
    const ARMS: Arms = Arms::HalfOverlap;
    const SCALES_CENTRES: bool = false;
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
    const ARMS: Arms = Arms::FullRadius;
    const SCALES_CENTRES: bool = false;
    #[inline(always)]
    fn slip(k: &PairKinematics, _: f64) -> Vec3 {
        let v = k.v_centres - (k.rad_p * k.w_p + k.spin_arm_i()).cross(&k.n);
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
    const ARMS: Arms = Arms::FullRadius;
    const SCALES_CENTRES: bool = true;
    #[inline(always)]
    fn slip(k: &PairKinematics, _: f64) -> Vec3 {
        objective_slip(k, k.n)
    }
}

/// The objective slip with the lever arms along `m`, tangential part with respect to `m`.
#[inline(always)]
fn objective_slip(k: &PairKinematics, m: Vec3) -> Vec3 {
    let v = k.alpha() * k.v_centres - (k.rad_p * k.w_p + k.spin_arm_i()).cross(&m);
    v - v.dot(&m) * m
}

/// Objective slip at the step's midpoint normal m = (n_old + n)/|…|, then projected onto the
/// new tangent plane. Over a step the centres' chord (v_P − v_I)·dt of a rigid rotation is
/// exactly tangent at m (Cayley: (R − I) r = 2 tan(φ/2) ê × (R + I) r/2), so the spin term
/// cancels it to third order in the turn for any rotation axis (the objective reference law).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MidpointObjectiveSlip;

impl Slip for MidpointObjectiveSlip {
    const ARMS: Arms = Arms::FullRadius;
    const SCALES_CENTRES: bool = true;
    #[inline(always)]
    fn slip(k: &PairKinematics, dt: f64) -> Vec3 {
        let m = (previous_normal(k, dt) + k.n).normalize();
        let v = objective_slip(k, m);
        v - v.dot(&k.n) * k.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tangential::test_kinematics as kin;

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
}
