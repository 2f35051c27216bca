//! Frame updates: how the stored spring ξ follows the turning contact plane over one step, in
//! the order the convention gives the increment by the slip and the update.

use super::previous_normal;
use crate::contact::PairKinematics;
use crate::Vec3;

/// How the stored spring advances over one step: the increment by the slip and the update
/// that makes it follow the contact plane, in the convention's order.
pub trait FrameUpdate: Send + Sync {
    /// Advances the spring ξ (length) over the step `dt` (time) with the tangential `slip`
    /// (length/time) of the contact `k`; `skip_below` is the out-of-plane length below which
    /// LAMMPS' `granular` skips its update (1e-10·mu|fn|/kt), ignored by the others.
    fn advance(xi: &mut Vec3, slip: Vec3, k: &PairKinematics, dt: f64, skip_below: f64);
}

/// MercuryDPM's rate form (`SlidingFrictionInteraction::integrate` for particle pairs):
/// dξ/dt = slip − (ξ·(v_P − v_I)/|r|) n, one explicit step. Its only frame update: no
/// projection onto the tangent plane, no rescaling, no twist about n.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RateForm;

impl FrameUpdate for RateForm {
    #[inline(always)]
    fn advance(xi: &mut Vec3, slip: Vec3, k: &PairKinematics, dt: f64, _: f64) {
        let rate = slip - k.n * xi.dot(&k.v_centres) / k.dist;
        *xi += rate * dt;
    }
}

/// No frame update at all: the spring keeps its lab-frame direction (Cundall & Strack 1979).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoFrameUpdate;

impl FrameUpdate for NoFrameUpdate {
    #[inline(always)]
    fn advance(xi: &mut Vec3, slip: Vec3, _: &PairKinematics, dt: f64, _: f64) {
        *xi += slip * dt;
    }
}

/// Increment, then project onto the new tangent plane, shortening the spring (LAMMPS
/// `pair_gran_hooke_history.cpp` "rotate shear displacements"; LIGGGHTS 3.8
/// `tangential_model_history.h`, same lines).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProjectAfter;

impl FrameUpdate for ProjectAfter {
    #[inline(always)]
    fn advance(xi: &mut Vec3, slip: Vec3, k: &PairKinematics, dt: f64, _: f64) {
        *xi += slip * dt;
        *xi -= xi.dot(&k.n) * k.n;
    }
}

/// Project onto the new tangent plane and rescale to the old length, then increment (LAMMPS
/// `pair_granular.cpp`, `tangential linear_history`: "rotate and update displacements", done
/// only when |ξ·n|·kt > 1e-10·Fscrit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProjectRescale;

impl FrameUpdate for ProjectRescale {
    #[inline(always)]
    fn advance(xi: &mut Vec3, slip: Vec3, k: &PairKinematics, dt: f64, skip_below: f64) {
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
        *xi += slip * dt;
    }
}

/// Yade's first-order rotation (`ScGeom::rotate`): ξ −= ξ × (n_old × n), then
/// ξ −= ξ × (½(ω_P + ω_I)·n_old·dt · n_old), then the increment.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstOrderRotation;

impl FrameUpdate for FirstOrderRotation {
    #[inline(always)]
    fn advance(xi: &mut Vec3, slip: Vec3, k: &PairKinematics, dt: f64, _: f64) {
        let n_old = previous_normal(k, dt);
        *xi -= xi.cross(&n_old.cross(&k.n));
        let twist = 0.5 * dt * (k.w_p + k.w_i).dot(&n_old);
        *xi -= xi.cross(&(twist * n_old));
        *xi += slip * dt;
    }
}

/// Exact rotation with the contact frame, then the increment: the tilt n_old → n (Rodrigues,
/// minimal rotation), then the twist about n by ½(ω_P + ω_I)·m·dt with m the step's midpoint
/// normal (the objective reference law; the symmetric m makes the split tilt + twist exact to
/// second order per step for any axis, where n_old or n would leave a first-order drift).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExactRotation;

impl FrameUpdate for ExactRotation {
    #[inline(always)]
    fn advance(xi: &mut Vec3, slip: Vec3, k: &PairKinematics, dt: f64, _: f64) {
        let n_old = previous_normal(k, dt);
        // Minimal rotation taking n_old to n, applied to ξ ⟂ n_old.
        *xi -= xi.dot(&k.n) / (1.0 + n_old.dot(&k.n)) * (n_old + k.n);
        let m = (n_old + k.n).normalize();
        let phi = 0.5 * dt * (k.w_p + k.w_i).dot(&m);
        *xi = *xi * phi.cos() + k.n.cross(xi) * phi.sin();
        *xi += slip * dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tangential::test_kinematics as kin;

    #[test]
    fn exact_rotation_keeps_length_and_plane_and_follows_the_tilt() {
        // P moved from (0,0,0.99) to r during dt with velocity v: n_old = z.
        let dt = 1e-2;
        let v = Vec3::new(3.0, 0.0, 0.0);
        let r = Vec3::new(0.0, 0.0, 0.99) + v * dt;
        let k = kin(r, v, Vec3::zeros(), Vec3::zeros());
        assert!((previous_normal(&k, dt) - Vec3::z()).norm() < 1e-15);
        let mut xi = Vec3::new(1e-3, 0.0, 0.0);
        ExactRotation::advance(&mut xi, Vec3::zeros(), &k, dt, 0.0);
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
        ExactRotation::advance(&mut xi, Vec3::zeros(), &k, dt, 0.0);
        assert!((xi - Vec3::new(0.0, 1e-3, 0.0)).norm() < 1e-18);
        let mut approx = Vec3::new(1e-3, 0.0, 0.0);
        FirstOrderRotation::advance(&mut approx, Vec3::zeros(), &k, dt, 0.0);
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
        ProjectAfter::advance(&mut a, Vec3::zeros(), &k, 0.0, 0.0);
        assert_eq!(a, Vec3::new(3e-4, 0.0, 0.0));
        ProjectRescale::advance(&mut b, Vec3::zeros(), &k, 0.0, 0.0);
        assert!((b - Vec3::new(5e-4, 0.0, 0.0)).norm() < 1e-18);
        let mut c = Vec3::new(3e-4, 0.0, 4e-4);
        ProjectRescale::advance(&mut c, Vec3::zeros(), &k, 0.0, 1e-3);
        assert_eq!(
            c,
            Vec3::new(3e-4, 0.0, 4e-4),
            "below LAMMPS' threshold: untouched"
        );
    }
}
