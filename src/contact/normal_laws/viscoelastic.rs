//! The viscoelastic damping of Brilliantov et al.: the spring's stiffness times a dissipative
//! constant A.

use crate::contact::{Damping, PairKinematics, Spring};

/// γn = A·dF/dδ, A (time) the dissipative constant: for Hertz's spring the dissipative force
/// (3/2)·A·ρ·√δ·δ̇ of F = ρ(δ^{3/2} + (3/2)A√δ·δ̇), ρ = (4/3)E*√R* (Brilliantov, Spahn,
/// Hertzsch & Pöschel, Phys. Rev. E 53, 5382, 1996, eq. 16).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viscoelastic {
    /// A (time, >= 0).
    pub a: f64,
}

impl Damping for Viscoelastic {
    #[inline(always)]
    fn gamma<S: Spring>(&self, spring: &S, _: f64, k: &PairKinematics) -> f64 {
        // (3/2) A ρ √δ = A dF_el/dδ (Brilliantov et al. 1996, eq. 16)
        self.a * spring.stiffness(k.delta, k.r_star())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::normal::{head_on, Damped, NormalModel};
    use crate::contact::normal_laws::hertz::Hertz;

    /// With Hertz's spring, γn = 2·A·E*·√(R*δ): the force is ρ(δ^{3/2} + (3/2)A√δ·δ̇) with
    /// δ̇ = −vn (Brilliantov et al. 1996), and A = 0 is elastic.
    #[test]
    fn with_hertz_the_dashpot_is_brilliantov_s() {
        let (e_star, a) = (2.5e10, 1e-6);
        let k = head_on(1e-4, -2.0, [0.01, 0.01], [100.0, 100.0]);
        let (delta, r) = (k.delta, k.r_star());
        let law = Damped {
            spring: Hertz { e_star },
            damping: Viscoelastic { a },
        };
        let rho = 4.0 / 3.0 * e_star * r.sqrt();
        let brilliantov = rho * (delta.powf(1.5) + 1.5 * a * delta.sqrt() * -k.vn);
        assert!((law.force(&k) / brilliantov - 1.0).abs() < 1e-12);
        let elastic = Damped {
            spring: Hertz { e_star },
            damping: Viscoelastic { a: 0.0 },
        };
        assert!((elastic.force(&k) / (rho * delta.powf(1.5)) - 1.0).abs() < 1e-12);
    }
}
