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
