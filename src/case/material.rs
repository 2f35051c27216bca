//! `[material]`: the one species of all spheres.

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
}

impl Material {
    /// Density and diameter > 0.
    pub(super) fn check(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        at.positive("material.density", self.density)?;
        at.positive("material.diameter", self.diameter)
    }
}
