//! Coulomb caps: the tangential force from the spring and the dashpot, limited to mu·|fn|
//! with the signed normal force fn of the same contact, and the spring reset while sliding.

use std::cmp::Ordering;

use crate::Vec3;

/// The Coulomb cap: the tangential force on P from the spring ξ and the slip, with ξ reset
/// when sliding.
pub trait Cap: Send + Sync {
    /// The tangential force on P (force units) from the spring ξ (length) and the dashpot on
    /// `slip` (length/time), limited to the critical force `fcrit` = μ|fn| in the way the
    /// convention states, resetting ξ when the contact slides. `kt` in force/length, `gammat`
    /// in mass/time.
    fn cap(xi: &mut Vec3, slip: Vec3, fcrit: f64, kt: f64, gammat: f64) -> Vec3;
}

/// Cap spring + dashpot together at mu|fn| and reset the spring to match the capped total.
/// The sources differ in two details, the parameters: `COMPARE_SQUARES`, the contact slides
/// when |f|² > (mu fn)² (MercuryDPM) rather than when |f| > mu|fn| (LAMMPS; the two tests
/// differ in the last bit near the cap); `NO_FORCE_WITHOUT_SPRING`, a sliding contact with no
/// stretched spring (ξ = 0) gets no tangential force (LAMMPS) rather than the capped dashpot.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TotalCap<const COMPARE_SQUARES: bool, const NO_FORCE_WITHOUT_SPRING: bool>;

impl<const COMPARE_SQUARES: bool, const NO_FORCE_WITHOUT_SPRING: bool> Cap
    for TotalCap<COMPARE_SQUARES, NO_FORCE_WITHOUT_SPRING>
{
    #[inline(always)]
    fn cap(xi: &mut Vec3, slip: Vec3, fcrit: f64, kt: f64, gammat: f64) -> Vec3 {
        let f = -(kt * *xi + gammat * slip);
        let f2 = f.norm_squared();
        let sticks = if COMPARE_SQUARES {
            f2.partial_cmp(&(fcrit * fcrit)) != Some(Ordering::Greater)
        } else {
            f2.sqrt() <= fcrit
        };
        if sticks {
            return f;
        }
        if NO_FORCE_WITHOUT_SPRING && *xi == Vec3::zeros() {
            return Vec3::zeros();
        }
        let capped = f * (fcrit / f2.sqrt());
        *xi = -(capped + gammat * slip) / kt;
        capped
    }
}

/// MercuryDPM's cap (`SlidingFrictionInteraction::computeFrictionForce`): spring + dashpot
/// against mu|fn|, compared as squares, no guard.
pub type MercuryCap = TotalCap<true, false>;

/// LAMMPS' cap (`pair_gran_hooke_history` and `pair_granular`, "rescale frictional
/// displacements and forces if needed"): spring + dashpot against mu|fn|, compared as
/// magnitudes; no force while sliding with an unstretched spring.
pub type LammpsCap = TotalCap<false, true>;

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

#[cfg(test)]
mod tests {
    use super::*;

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
