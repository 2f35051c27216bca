//! Hertz's elastic spring between spheres of effective modulus E* and effective radius R*.

use crate::contact::normal::Spring;

/// Hertz's spring F = (4/3)·E*·√R*·δ^{3/2} (Johnson, Contact Mechanics, 1985, eq. 4.23), with
/// E* (force/length²) the pair's effective Young's modulus; R* is the contact's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hertz {
    pub e_star: f64,
}

impl Spring for Hertz {
    /// √(5/6): the factor LIGGGHTS (`normal_model_hertz.h`) and LAMMPS
    /// (`gran_sub_mod_damping.cpp`, `coeff_restitution`) put on the restitution damping of a
    /// Hertz spring.
    const RESTITUTION_FACTOR: f64 = 0.912_870_929_175_276_9;

    #[inline(always)]
    fn force(&self, delta: f64, r_star: f64) -> f64 {
        // (4/3) E* √(R* δ) δ (Johnson 1985, eq. 4.23)
        4.0 / 3.0 * self.e_star * (r_star * delta).sqrt() * delta
    }

    /// Sn = 2·E*·√(R*·δ) = 2·E*·a, a the contact radius (Johnson 1985, §4.2).
    #[inline(always)]
    fn stiffness(&self, delta: f64, r_star: f64) -> f64 {
        2.0 * self.e_star * (r_star * delta).sqrt()
    }

    /// (8/15)·E*·√R*·δ^{5/2}, the integral of the force.
    fn energy(&self, delta: f64, r_star: f64) -> f64 {
        8.0 / 15.0 * self.e_star * (r_star * delta).sqrt() * delta * delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stiffness is the force's derivative and the energy its integral (central
    /// differences and a midpoint sum), at an overlap and radius of Chung & Ooi's test 1.
    #[test]
    fn stiffness_and_energy_are_the_force_s_derivative_and_integral() {
        let h = Hertz { e_star: 1.4e10 };
        let (delta, r) = (2e-5, 5e-3);
        let d = 1e-9;
        let slope = (h.force(delta + d, r) - h.force(delta - d, r)) / (2.0 * d);
        assert!((slope / h.stiffness(delta, r) - 1.0).abs() < 1e-6);
        let n = 20_000;
        let step = delta / n as f64;
        let sum: f64 = (0..n)
            .map(|j| h.force((j as f64 + 0.5) * step, r) * step)
            .sum();
        assert!((sum / h.energy(delta, r) - 1.0).abs() < 1e-6, "{sum}");
        assert!((Hertz::RESTITUTION_FACTOR - (5.0f64 / 6.0).sqrt()).abs() < 1e-16);
    }
}
