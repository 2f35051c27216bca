//! Case files: the TOML schema, its validation, and derived quantities (collision time,
//! restitution, time step). Every error names the file, the line and the field.
//!
//! One file per section of the case file, each section's struct beside the checks of its
//! fields (`run`, `neighbor`, `guard`, `output`, `domain`, `material`, `contact`, `scene`,
//! `walls` for the `[[wall]]` tables);
//! reading and the order of the checks in `load`, where errors point in `locate`, the
//! quantities derived from the parameters in `derived`, and the time step against the scheme's
//! stability limit in `time_step`.

use std::path::{Path, PathBuf};

use serde::Deserialize;

mod contact;
mod derived;
mod domain;
mod guard;
mod load;
mod locate;
mod material;
mod neighbor;
mod output;
mod run;
mod scene;
mod time_step;
mod walls;

pub use contact::{Contact, Convention, Given};
pub use derived::{Stiffness, HERTZ_TC_PER_DELTA};
pub use domain::DomainSpec;
pub use guard::{Guard, DEFAULT_GUARD_CONTACT, DEFAULT_GUARD_ENERGY, DEFAULT_GUARD_OVERLAP};
pub use load::MAX_CASE_BYTES;
pub use material::{effective_shear, effective_youngs, Material};
pub use neighbor::{Neighbor, Search};
pub use output::Output;
pub use run::Run;
pub use scene::{Scene, SphereSpec};
pub use time_step::COARSE_STEPS_PER_COLLISION;
pub use walls::WallSpec;

/// An error in a case file: `file:line: field: message`.
#[derive(Debug, thiserror::Error)]
#[error("{file}:{line}: {field}: {msg}")]
pub struct CaseError {
    pub file: String,
    pub line: usize,
    pub field: String,
    pub msg: String,
}

/// A whole case file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Base name of the output files (`NAME.data.NNNN`).
    pub name: String,
    pub run: Run,
    #[serde(default)]
    pub neighbor: Neighbor,
    pub domain: DomainSpec,
    pub material: Material,
    pub contact: Contact,
    pub scene: Scene,
    #[serde(default)]
    pub guard: Guard,
    #[serde(default)]
    pub output: Output,
    /// Flat walls (`[[wall]]`), none by default.
    #[serde(default)]
    pub wall: Vec<WallSpec>,
    /// Directory the case was read from (relative paths in the case resolve against it).
    #[serde(skip)]
    pub dir: PathBuf,
    /// Path the case was read from.
    #[serde(skip)]
    pub path: PathBuf,
    /// What validation found acceptable but worth saying, as read (see [`Case::warnings`]).
    #[serde(skip)]
    warnings: Vec<String>,
}

impl Case {
    /// What validation accepted with a warning (`file:line: field: message`), for the case as
    /// read: a coarse time step and the restitution error it is expected to cost.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Resolves a path given in the case (relative to the case file).
    pub fn resolve(&self, p: &str) -> PathBuf {
        let path = Path::new(p);
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.dir.join(path)
        }
    }
}

#[cfg(test)]
mod tests;
