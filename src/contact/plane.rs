//! The sphere–plane contact: a sphere P against a flat wall I (an infinite plane), as
//! MercuryDPM's `InfiniteWall::getDistanceAndNormal` and `BaseWall::getInteractionWith` compute
//! it. The plane is I with an infinite radius (`rad_i = ∞`, so R* = R_P) and no inverse mass
//! (m* = m_P); it moves rigidly and does not spin.
//!
//! Conventions beside the pair's (module [`crate::contact`]): `n` is the wall's unit normal,
//! pointing to the side the sphere is on (from I to P); `dist` is infinite, so that a frame
//! update following the turning normal at the rate ξ·(v_P − v_I)/|r| sees a plane that does not
//! turn; `r` is x_P minus its foot on the plane, (R − δ)·n; the lever arm of I is the contact
//! point relative to the wall's reference point.

use super::PairKinematics;
use crate::Vec3;

/// A sphere and a plane, everything the contact needs.
#[derive(Clone, Copy, Debug)]
pub struct PlaneInput {
    /// The sphere's centre relative to a point of the plane, x_P − p (length).
    pub offset: Vec3,
    /// The plane's unit normal, towards the sphere's side.
    pub normal: Vec3,
    /// The sphere's radius (length) and inverse mass (1/mass).
    pub rad_p: f64,
    pub inv_mass_p: f64,
    /// The sphere's velocity (length/time) and angular velocity (1/time).
    pub v_p: Vec3,
    pub w_p: Vec3,
    /// The plane's velocity (length/time; it moves rigidly, without spin).
    pub v_wall: Vec3,
}

impl PlaneInput {
    /// The overlap δ = R − (x − p)·n̂ (length; positive in contact), MercuryDPM's
    /// `BaseWall::getDistanceNormalOverlap` with `InfiniteWall::getDistance`.
    #[inline(always)]
    pub fn overlap(&self) -> f64 {
        self.rad_p - self.offset.dot(&self.normal)
    }

    /// Contact geometry and kinematics, or `None` when the sphere does not touch the plane
    /// (contact iff the centre's distance is below the radius, strict, as MercuryDPM's
    /// `InfiniteWall::getDistanceAndNormal`).
    #[inline(always)]
    pub fn kinematics(&self) -> Option<PairKinematics> {
        let n = self.normal;
        let height = self.offset.dot(&n);
        if height >= self.rad_p {
            return None;
        }
        let delta = self.rad_p - height;
        // Contact point c = x_P − (r_P − δ/2) n (MercuryDPM BaseWall::getInteractionWith).
        let arm_p = -(self.rad_p - 0.5 * delta) * n;
        let arm_i = self.offset + arm_p;
        // Velocity of the sphere's material point at c, v + ω × (c − x), against the wall's.
        let v_rel = (self.v_p + self.w_p.cross(&arm_p)) - self.v_wall;
        let vn = v_rel.dot(&n);
        let vt = v_rel - vn * n;
        Some(PairKinematics {
            n,
            dist: f64::INFINITY,
            delta,
            arm_p,
            arm_i,
            v_rel,
            vn,
            vt,
            v_centres: self.v_p - self.v_wall,
            r: height * n,
            rad_p: self.rad_p,
            rad_i: f64::INFINITY,
            inv_mass_p: self.inv_mass_p,
            inv_mass_i: 0.0,
            w_p: self.w_p,
            w_i: Vec3::zeros(),
        })
    }
}

impl PairKinematics {
    /// R_I·ω_I, I's spin on its full-radius lever arm (length/time); zero for a plane, which
    /// does not spin (and whose infinite radius would make it NaN).
    #[inline(always)]
    pub fn spin_arm_i(&self) -> Vec3 {
        if self.rad_i.is_infinite() {
            Vec3::zeros()
        } else {
            self.rad_i * self.w_i
        }
    }

    /// α = (R_P + R_I)/|r|, the objective slips' scale of the centres' velocity; 1 for a plane,
    /// its limit as R_I → ∞ (McNamara, García-Rojo & Herrmann, PRE 77, 031304, 2008).
    #[inline(always)]
    pub fn alpha(&self) -> f64 {
        if self.dist.is_infinite() {
            1.0
        } else {
            (self.rad_p + self.rad_i) / self.dist
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn floor(z: f64, w_p: Vec3, v_wall: Vec3) -> PlaneInput {
        PlaneInput {
            offset: Vec3::new(0.3, -0.2, z),
            normal: Vec3::new(0.0, 0.0, 1.0),
            rad_p: 0.5,
            inv_mass_p: 2.0,
            v_p: Vec3::new(1.0, 0.0, -0.1),
            w_p,
            v_wall,
        }
    }

    /// Overlap, contact point and effective radius and mass of a sphere on a floor; no contact
    /// at exactly touching height.
    #[test]
    fn a_sphere_on_a_floor_has_the_plane_limit_of_a_pair() {
        assert!(floor(0.5, Vec3::zeros(), Vec3::zeros())
            .kinematics()
            .is_none());
        let k = floor(0.4, Vec3::zeros(), Vec3::zeros())
            .kinematics()
            .unwrap();
        assert!((k.delta - 0.1).abs() < 1e-15);
        assert!((k.arm_p.z + 0.45).abs() < 1e-15);
        assert_eq!(k.r_star(), 0.5);
        assert_eq!(k.m_star(), 0.5);
        assert_eq!(k.vn, -0.1);
    }

    /// A sphere rolling without slip on a moving floor: v − U = ω × (R − δ/2) n, so the slip
    /// at the contact point is zero (the sign of ω × arm at a wall: Lethe #889).
    #[test]
    fn rolling_on_a_moving_floor_does_not_slip() {
        let u = Vec3::new(-0.7, 0.2, 0.0);
        let mut input = floor(0.4, Vec3::zeros(), u);
        input.v_p = Vec3::new(0.9, -0.4, 0.0);
        let arm = 0.45;
        // (v − U) = ω × (arm n) with ω ⊥ n: ω = n × (v − U)/arm
        input.w_p = Vec3::new(0.0, 0.0, 1.0).cross(&(input.v_p - u)) / arm;
        let k = input.kinematics().unwrap();
        assert!(k.vt.norm() < 1e-15, "slip {}", k.vt);
        let mut skid = input;
        skid.w_p = -input.w_p;
        assert!(skid.kinematics().unwrap().vt.norm() > 1.0);
    }
}
