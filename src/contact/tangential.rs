//! Tangential models: elastic spring ξ stored per contact, dashpot and Coulomb cap.
//! The returned vector is the tangential force on P.

use super::PairKinematics;
use crate::Vec3;

/// A tangential model. `fn_signed` is the signed normal force of the same contact; `xi` is the
/// contact's elastic tangential displacement (length), updated in place over the step `dt`.
pub trait TangentialModel: Send + Sync {
    /// False for models that never produce a tangential force.
    const ACTIVE: bool;
    /// True when the torques use the full radii as lever arms (−R_P n, R_I n) instead of the
    /// arms to the contact point in the middle of the overlap.
    const FULL_RADIUS_LEVER: bool = false;
    /// The tangential force on P (force units) for a contact with kinematics `k`, signed normal
    /// force `fn_signed` (positive repulsive), elastic tangential displacement `xi` (length,
    /// updated in place) and time step `dt` (time).
    fn force(&self, k: &PairKinematics, fn_signed: f64, xi: &mut Vec3, dt: f64) -> Vec3;
}

/// No tangential force at all (mu = 0 or no friction requested).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frictionless;

impl TangentialModel for Frictionless {
    const ACTIVE: bool = false;
    #[inline(always)]
    fn force(&self, _: &PairKinematics, _: f64, _: &mut Vec3, _: f64) -> Vec3 {
        Vec3::zeros()
    }
}

/// MercuryDPM's sliding friction (`SlidingFrictionInteraction::computeFrictionForce`): spring kt
/// and dashpot γt in parallel, in series with a Coulomb slider that caps the total
/// |kt ξ + γt vt| ≤ mu |fn|.
///
/// The spring is integrated in rate form, dξ/dt = vt − (ξ·(v_P − v_I)/|r|) n (its only frame
/// update: no projection onto the tangent plane, no rescaling, no spin about n). When sliding,
/// ξ is reset so that spring plus dashpot equal the cap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MercurySlidingFriction {
    pub kt: f64,
    pub gammat: f64,
    pub mu: f64,
}

impl TangentialModel for MercurySlidingFriction {
    const ACTIVE: bool = true;

    #[inline(always)]
    fn force(&self, k: &PairKinematics, fn_signed: f64, xi: &mut Vec3, dt: f64) -> Vec3 {
        // Rate form of the spring for particle pairs (MercuryDPM SlidingFrictionInteraction).
        let rate = k.vt - k.n * xi.dot(&k.v_centres) / k.dist;
        *xi += rate * dt;
        let ft = -(self.kt * *xi + self.gammat * k.vt);
        let ft2 = ft.norm_squared();
        let cap = self.mu * fn_signed;
        if ft2 > cap * cap {
            // Coulomb: scale the total to mu|fn| and reset the spring to match it.
            let scaled = ft * (self.mu * fn_signed.abs() / ft2.sqrt());
            *xi = -(scaled + self.gammat * k.vt) / self.kt;
            scaled
        } else {
            ft
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::PairInput;

    fn sliding_pair(vt: f64) -> PairKinematics {
        PairInput {
            r: Vec3::new(0.0, 0.0, 0.999),
            rad_p: 0.5,
            rad_i: 0.5,
            v_p: Vec3::new(vt, 0.0, 0.0),
            v_i: Vec3::zeros(),
            w_p: Vec3::zeros(),
            w_i: Vec3::zeros(),
        }
        .kinematics()
        .unwrap()
    }

    const LAW: MercurySlidingFriction = MercurySlidingFriction {
        kt: 2e5 * 2.0 / 7.0,
        gammat: 15.0 * 2.0 / 7.0,
        mu: 0.3,
    };

    #[test]
    fn sticking_contact_builds_spring_against_the_motion() {
        let k = sliding_pair(1e-3);
        let mut xi = Vec3::zeros();
        let f = LAW.force(&k, 200.0, &mut xi, 1e-4);
        assert!((xi.x - 1e-7).abs() < 1e-20);
        let expected = -(LAW.kt * 1e-7 + LAW.gammat * 1e-3);
        assert!((f.x - expected).abs() < 1e-12);
    }

    #[test]
    fn sliding_contact_is_capped_at_mu_fn_and_spring_matches_the_cap() {
        let k = sliding_pair(10.0);
        let mut xi = Vec3::new(-1.0, 0.0, 0.0);
        let f = LAW.force(&k, 200.0, &mut xi, 1e-4);
        assert!((f.norm() - 60.0).abs() < 1e-12);
        let back = -(LAW.kt * xi + LAW.gammat * k.vt);
        assert!((back - f).norm() < 1e-9);
    }

    #[test]
    fn cap_uses_the_absolute_normal_force_in_the_attractive_tail() {
        let k = sliding_pair(10.0);
        let mut xi = Vec3::zeros();
        let f = LAW.force(&k, -1.0, &mut xi, 1e-4);
        assert!((f.norm() - 0.3).abs() < 1e-12);
        assert!(f.x < 0.0);
    }
}
