//! `[run]`: time stepping, saves, threads, seed, initial file and gravity.

use serde::Deserialize;

use super::locate::Locator;
use super::{Case, CaseError};

/// `[run]`: time stepping and output.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Run {
    /// Number of time steps.
    pub steps: u64,
    /// A save (`.data`/`.fstat`) every this many steps, starting with step 0.
    pub save_every: u64,
    /// Time step (time units). Give exactly one of `dt` and `steps_per_collision`.
    pub dt: Option<f64>,
    /// dt = tc / steps_per_collision, tc the free–free collision time of the contact law.
    pub steps_per_collision: Option<f64>,
    /// Worker threads of the time step (default 2).
    #[serde(default = "default_threads")]
    pub threads: usize,
    /// Seed of the random initial configuration.
    #[serde(default)]
    pub seed: u64,
    /// Initial configuration file (official `GranularShearFlow.data` format or a MercuryCG
    /// `.data` save); relative to the case file. Without it the scene is generated.
    pub init: Option<String>,
    /// Gravity (acceleration); none when absent or zero.
    pub gravity: Option<[f64; 3]>,
}

fn default_threads() -> usize {
    2
}

impl Run {
    /// Saves and threads above zero, exactly one of `dt` and `steps_per_collision` (> 0), a
    /// finite gravity.
    pub(super) fn check(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        if self.save_every == 0 {
            return Err(at.error("run.save_every", "must be > 0, got 0".into()));
        }
        if self.threads == 0 {
            return Err(at.error("run.threads", "must be > 0, got 0".into()));
        }
        match (self.dt, self.steps_per_collision) {
            (Some(dt), None) => at.positive("run.dt", dt)?,
            (None, Some(s)) => at.positive("run.steps_per_collision", s)?,
            _ => {
                return Err(at.error(
                    "run.dt",
                    "give exactly one of dt and steps_per_collision".into(),
                ))
            }
        }
        if let Some(g) = self.gravity {
            if g.iter().any(|c| !c.is_finite()) {
                return Err(at.error("run.gravity", format!("must be finite, got {g:?}")));
            }
        }
        Ok(())
    }

    /// The field that sets the time step: `run.dt` or `run.steps_per_collision`.
    pub(super) fn dt_field(&self) -> &'static str {
        if self.dt.is_some() {
            "run.dt"
        } else {
            "run.steps_per_collision"
        }
    }
}

impl Case {
    /// Gravity, or `None` when absent or zero.
    pub fn gravity(&self) -> Option<[f64; 3]> {
        self.run.gravity.filter(|g| g.iter().any(|c| *c != 0.0))
    }
}
