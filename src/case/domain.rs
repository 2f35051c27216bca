//! `[domain]`: the box.

use serde::Deserialize;

use super::locate::Locator;
use super::CaseError;

/// `[domain]`: the box.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub periodic: [bool; 3],
}

impl DomainSpec {
    /// `hi` above `lo` on every axis (the box against the spheres is the scene's check).
    pub(super) fn check(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        for k in 0..3 {
            if self.hi[k] <= self.lo[k] || self.hi[k].is_nan() {
                return Err(at.error(
                    "domain.hi",
                    format!(
                        "must exceed lo on every axis, got lo {:?} hi {:?}",
                        self.lo, self.hi
                    ),
                ));
            }
        }
        Ok(())
    }
}
