//! Tsuji's damping: γn = α(e)·√(m*·F/δ), growing as δ^{1/4} with a Hertz spring.

use crate::contact::normal::{Damping, Spring};
use crate::contact::PairKinematics;

/// γn = α·√(m*·F_el/δ) (Tsuji, Tanaka & Ishida, Powder Technol. 71, 239, 1992: η = α√(m k)
/// δ^{1/4} for F_el = k δ^{3/2}), α(e) = √2·(1.2728 − 4.2783e + 11.087e² − 22.348e³ +
/// 27.467e⁴ − 18.022e⁵ + 4.8218e⁶), the fit of Marshall (J. Comput. Phys. 228, 1541, 2009,
/// eq. 53) to Tsuji's curve, with LAMMPS' √2 for the effective-mass convention
/// (`gran_sub_mod_damping.cpp`, `GranSubModDampingTsuji`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tsuji {
    /// α (dimensionless).
    pub alpha: f64,
}

impl Tsuji {
    /// The damping Tsuji's fit gives for the restitution `e` (in (0, 1]).
    pub fn new(e: f64) -> Tsuji {
        // Marshall 2009, eq. 53, times √2 (LAMMPS gran_sub_mod_damping.cpp)
        let fit = [1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218];
        let alpha = fit.iter().rev().fold(0.0, |acc, c| acc * e + c);
        Tsuji {
            alpha: std::f64::consts::SQRT_2 * alpha,
        }
    }
}

impl Damping for Tsuji {
    #[inline(always)]
    fn gamma<S: Spring>(&self, _: &S, elastic: f64, k: &PairKinematics) -> f64 {
        self.alpha * (k.m_star() * elastic / k.delta).max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fit at e = 1 is √2 times the sum of its coefficients (about 0: no damping) and
    /// grows as e falls.
    #[test]
    fn the_fit_is_about_zero_at_one_and_grows_as_e_falls() {
        let sum: f64 = 1.2728 - 4.2783 + 11.087 - 22.348 + 27.467 - 18.022 + 4.8218;
        assert!((Tsuji::new(1.0).alpha - std::f64::consts::SQRT_2 * sum).abs() < 1e-12);
        assert!(Tsuji::new(1.0).alpha.abs() < 0.01);
        assert!(Tsuji::new(0.5).alpha > Tsuji::new(0.9).alpha);
    }
}
