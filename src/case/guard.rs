//! `[guard]`: the limits of the run guard.

use serde::Deserialize;

use super::locate::Locator;
use super::CaseError;

/// `[guard]`: limits of the run guard, which stops a run whose numbers can no longer be
/// trusted (non-finite velocities and positions are always refused). The step runs with it as
/// it is (`step::Params::guard`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Guard {
    /// Largest overlap allowed, as a fraction of the smaller radius of the pair (0 < overlap
    /// ≤ 1; default [`DEFAULT_GUARD_OVERLAP`]).
    #[serde(default = "default_guard_overlap")]
    pub overlap: f64,
    /// Largest gain of the free particles' mechanical energy over a window of steps beyond what
    /// the walls and gravity supplied, as a fraction of the energy at play (> 0; default
    /// [`DEFAULT_GUARD_ENERGY`]).
    #[serde(default = "default_guard_energy")]
    pub energy: f64,
    /// Largest energy a contact may give its particles beyond what it took from them and what
    /// its springs held, as a fraction of what it took (> 0; default [`DEFAULT_GUARD_CONTACT`]).
    #[serde(default = "default_guard_contact")]
    pub contact: f64,
}

/// Default of `[guard] overlap`. The benchmark's largest overlaps are about 1 % of the radius
/// (δ ≈ v·√(m_eff/kn) with relative speeds of a few wall speeds: 2·√(0.26/2e5) ≈ 2.3e-3 against
/// r = 0.5); a linear spring whose overlap reaches a tenth of the radius is far outside the
/// regime the law describes, and usually a sign of a time step too large for the stiffness.
pub const DEFAULT_GUARD_OVERLAP: f64 = 0.1;

fn default_guard_overlap() -> f64 {
    DEFAULT_GUARD_OVERLAP
}

/// Default of `[guard] energy`. Within a contact the explicit scheme's energy departs from the
/// true one by about (ω·dt)²/4 of the contact's energy (0.1 % at tc/50, 2.5 % at tc/10, 20 %
/// at tc/3.5), and a window may end inside contacts; an instability or a law that gives back
/// more than it took grows without bound. `docs/verification.md` lists the gains measured.
pub const DEFAULT_GUARD_ENERGY: f64 = 0.05;

fn default_guard_energy() -> f64 {
    DEFAULT_GUARD_ENERGY
}

/// Default of `[guard] contact`.
pub const DEFAULT_GUARD_CONTACT: f64 = 0.01;

fn default_guard_contact() -> f64 {
    DEFAULT_GUARD_CONTACT
}

impl Default for Guard {
    fn default() -> Self {
        Guard {
            overlap: DEFAULT_GUARD_OVERLAP,
            energy: DEFAULT_GUARD_ENERGY,
            contact: DEFAULT_GUARD_CONTACT,
        }
    }
}

impl Guard {
    /// Every limit > 0, the overlap a fraction at most 1.
    pub(super) fn check(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        at.positive("guard.overlap", self.overlap)?;
        at.positive("guard.energy", self.energy)?;
        at.positive("guard.contact", self.contact)?;
        if self.overlap > 1.0 {
            return Err(at.error(
                "guard.overlap",
                format!(
                    "a fraction of the smaller radius at most 1, got {}",
                    self.overlap
                ),
            ));
        }
        Ok(())
    }
}
