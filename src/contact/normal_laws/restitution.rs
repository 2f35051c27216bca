//! The coefficient-of-restitution damping: γn from a restitution coefficient e and the
//! contact's stiffness and effective mass.

use crate::contact::normal::{Damping, Spring};
use crate::contact::PairKinematics;

/// γn = −2·c·β·√(S·m*), β = ln e/√(ln² e + π²), S the spring's tangent stiffness and c its
/// [`Spring::RESTITUTION_FACTOR`] (LIGGGHTS `normal_model_hertz.h` and `normal_model_hooke.h`;
/// LAMMPS `gran_sub_mod_damping.cpp`, `GranSubModDampingCoeffRestitution`, and
/// `doc/src/pair_granular.rst`). Exact for the linear spring (c = 1: e = exp(−γ/(2m*)·tc)); for
/// Hertz's an approximation whose error `verdem verify` measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Restitution {
    /// −2β (dimensionless, ≥ 0).
    pub minus_two_beta: f64,
}

impl Restitution {
    /// The damping that aims at the restitution `e` (in (0, 1]).
    pub fn new(e: f64) -> Restitution {
        let ln_e = e.ln();
        // β = ln e / √(ln² e + π²) (LIGGGHTS normal_model_hertz.h)
        let beta = ln_e / (ln_e * ln_e + std::f64::consts::PI * std::f64::consts::PI).sqrt();
        Restitution {
            minus_two_beta: -2.0 * beta,
        }
    }
}

impl Damping for Restitution {
    #[inline(always)]
    fn gamma<S: Spring>(&self, spring: &S, _: f64, k: &PairKinematics) -> f64 {
        let s = spring.stiffness(k.delta, k.r_star());
        self.minus_two_beta * S::RESTITUTION_FACTOR * (s * k.m_star()).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::normal::{head_on, Linear};

    /// With the linear spring, γn = √(4 m* kn/(1 + (π/ln e)²)), the closed form of the
    /// restitution e (LIGGGHTS `normal_model_hooke.h`), and e = 1 gives no damping.
    #[test]
    fn with_a_linear_spring_gamma_is_the_exact_one() {
        let (kn, e) = (2e5, 0.7f64);
        let k = head_on(1e-4, -1.0, [0.5, 0.5], [1.0 / 3.0, 1.0 / 5.0]);
        let m = 1.0 / (1.0 / 3.0 + 1.0 / 5.0);
        let exact = (4.0 * m * kn / (1.0 + (std::f64::consts::PI / e.ln()).powi(2))).sqrt();
        let g = Restitution::new(e).gamma(&Linear { kn }, kn * 1e-4, &k);
        assert!((g / exact - 1.0).abs() < 1e-14, "{g} {exact}");
        assert_eq!(Restitution::new(1.0).gamma(&Linear { kn }, 0.0, &k), 0.0);
    }
}
