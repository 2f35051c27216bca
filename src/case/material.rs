//! `[material]`: the one species of all spheres, and the rules that mix two materials' elastic
//! constants into a pair's.

use serde::Deserialize;

use super::locate::Locator;
use super::CaseError;

/// `[material]`: one species for all spheres.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Particle density (mass/length³).
    pub density: f64,
    /// Particle diameter (length).
    pub diameter: f64,
    /// Young's modulus E (force/length²), for a law built from elastic constants (Hertz's).
    #[serde(default)]
    pub youngs: Option<f64>,
    /// Poisson's ratio ν (dimensionless, in (−1, 0.5]), given with `youngs`.
    #[serde(default)]
    pub poisson: Option<f64>,
}

impl Material {
    /// Density and diameter > 0; Young's modulus > 0 and Poisson's ratio in (−1, 0.5], both
    /// or neither.
    pub(super) fn check(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        at.positive("material.density", self.density)?;
        at.positive("material.diameter", self.diameter)?;
        match (self.youngs, self.poisson) {
            (Some(e), Some(nu)) => {
                at.positive("material.youngs", e)?;
                if !(nu > -1.0 && nu <= 0.5) {
                    return Err(at.error(
                        "material.poisson",
                        format!("a Poisson's ratio in (-1, 0.5] expected, got {nu}"),
                    ));
                }
                Ok(())
            }
            (None, None) => Ok(()),
            (Some(_), None) => Err(at.error(
                "material.youngs",
                "given without material.poisson: an elastic law needs both".into(),
            )),
            (None, Some(_)) => Err(at.error(
                "material.poisson",
                "given without material.youngs: an elastic law needs both".into(),
            )),
        }
    }

    /// Young's modulus and Poisson's ratio (E, ν), if the material gives them.
    pub fn elastic(&self) -> Option<(f64, f64)> {
        self.youngs.zip(self.poisson)
    }

    /// E* (force/length²) of two spheres of this material, E/(2(1−ν²))
    /// ([`effective_youngs`]); `None` without elastic constants.
    pub fn e_star(&self) -> Option<f64> {
        self.elastic().map(|m| effective_youngs([m, m]))
    }

    /// G* (force/length²) of two spheres of this material, G/(2(2−ν)) ([`effective_shear`]);
    /// `None` without elastic constants.
    pub fn g_star(&self) -> Option<f64> {
        self.elastic().map(|m| effective_shear([m, m]))
    }
}

/// E* (force/length²) of two materials of Young's moduli E and Poisson's ratios ν (each
/// `(E, ν)`), 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂ (Johnson, Contact Mechanics, 1985, §4.2).
pub fn effective_youngs([(e1, nu1), (e2, nu2)]: [(f64, f64); 2]) -> f64 {
    1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)
}

/// G* (force/length²) of two materials (each `(E, ν)`), 1/G* = (2−ν₁)/G₁ + (2−ν₂)/G₂ with
/// G = E/(2(1+ν)) (Mindlin 1949; LIGGGHTS `normal_model_hertz.h`'s Geff).
pub fn effective_shear([(e1, nu1), (e2, nu2)]: [(f64, f64); 2]) -> f64 {
    let g = |e: f64, nu: f64| e / (2.0 * (1.0 + nu));
    1.0 / ((2.0 - nu1) / g(e1, nu1) + (2.0 - nu2) / g(e2, nu2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Glass on limestone (Chung & Ooi 2011, test 1): E* and G* by hand; like materials give
    /// E/(2(1−ν²)).
    #[test]
    fn unlike_materials_mix_by_compliance() {
        let (glass, lime) = ((48e9, 0.20), (20e9, 0.25));
        let e = effective_youngs([glass, lime]);
        let by_hand = 1.0 / (0.96 / 48e9 + 0.9375 / 20e9);
        assert!((e / by_hand - 1.0).abs() < 1e-15);
        let g = effective_shear([glass, lime]);
        let by_hand = 1.0 / (1.8 / (48e9 / 2.4) + 1.75 / (20e9 / 2.5));
        assert!((g / by_hand - 1.0).abs() < 1e-15);
        let same = effective_youngs([glass, glass]);
        assert!((same / (48e9 / (2.0 * 0.96)) - 1.0).abs() < 1e-15);
    }
}
