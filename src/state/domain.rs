//! The simulation box: bounds and periodicity, minimum-image distances and position wrapping.

use crate::Vec3;

/// An axis-aligned box `[lo, hi]`, periodic along the axes flagged in `periodic`.
#[derive(Clone, Debug, PartialEq)]
pub struct Domain {
    /// Lower corner (length units).
    pub lo: Vec3,
    /// Upper corner (length units).
    pub hi: Vec3,
    /// Periodicity of x, y, z.
    pub periodic: [bool; 3],
    /// Period along each axis: the edge length on periodic axes, 0 elsewhere.
    period: Vec3,
}

impl Domain {
    /// A box `[lo, hi]` with the given periodicity.
    pub fn new(lo: Vec3, hi: Vec3, periodic: [bool; 3]) -> Self {
        let l = hi - lo;
        let period = Vec3::new(
            if periodic[0] { l.x } else { 0.0 },
            if periodic[1] { l.y } else { 0.0 },
            if periodic[2] { l.z } else { 0.0 },
        );
        Domain {
            lo,
            hi,
            periodic,
            period,
        }
    }

    /// Period along each axis (length): the edge length on periodic axes, 0 elsewhere.
    pub fn period(&self) -> Vec3 {
        self.period
    }

    /// Edge lengths `hi - lo`.
    pub fn lengths(&self) -> Vec3 {
        self.hi - self.lo
    }

    /// Minimum-image version of a separation vector `d = a - b`: along each periodic axis the
    /// image closest to zero is chosen (valid while |d| < 1.5 L, which always holds for wrapped
    /// positions).
    #[inline(always)]
    pub fn min_image(&self, d: Vec3) -> Vec3 {
        // Branch-free: d − L·([d > L/2] − [d < −L/2]); on a non-periodic axis L = 0 and d is
        // returned unchanged (d − 0 = d bit for bit, also for −0).
        let mut out = d;
        for k in 0..3 {
            let l = self.period[k];
            let shift = (d[k] > 0.5 * l) as i32 as f64 - (d[k] < -0.5 * l) as i32 as f64;
            out[k] = d[k] - l * shift;
        }
        out
    }

    /// Wraps a position back into `[lo, hi)` along periodic axes, as MercuryDPM's periodic
    /// boundaries do after each drift (one shift by the period, no modulo).
    #[inline(always)]
    pub fn wrap(&self, x: &mut Vec3) {
        // x − (up − down) with up, down ∈ {0, L} chosen without branches; x − 0 = x bit for bit.
        for k in 0..3 {
            if self.periodic[k] {
                let up = if x[k] >= self.hi[k] {
                    self.period[k]
                } else {
                    0.0
                };
                let down = if x[k] < self.lo[k] {
                    self.period[k]
                } else {
                    0.0
                };
                x[k] -= up - down;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shear_box() -> Domain {
        Domain::new(
            Vec3::zeros(),
            Vec3::new(20.0, 10.0, 22.0),
            [true, true, false],
        )
    }

    #[test]
    fn min_image_picks_the_nearest_periodic_copy_only_on_periodic_axes() {
        let d = shear_box();
        let m = d.min_image(Vec3::new(19.5, -9.0, 21.0));
        assert_eq!(m, Vec3::new(-0.5, 1.0, 21.0));
    }

    #[test]
    fn wrap_brings_positions_back_into_the_box() {
        let d = shear_box();
        let mut x = Vec3::new(20.25, -0.5, 30.0);
        d.wrap(&mut x);
        assert_eq!(x, Vec3::new(0.25, 9.5, 30.0));
    }
}
