//! `[neighbor]`: the Verlet pair list.

use serde::Deserialize;

use super::locate::Locator;
use super::CaseError;

/// `[neighbor]`: the Verlet pair list.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Neighbor {
    /// Skin added to the contact distance (length); the list is rebuilt when a particle has
    /// moved more than skin/2.
    #[serde(default = "default_skin")]
    pub skin: f64,
    /// Cell edge (length); raised to 2 r_max + skin when smaller (0 = automatic).
    #[serde(default)]
    pub cell: f64,
    /// `cells` (default) or `all-pairs`.
    #[serde(default = "default_search")]
    pub search: Search,
}

/// How candidate pairs are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Search {
    /// Cell grid of edge ≥ 2 r_max + skin (the default).
    Cells,
    /// Every pair is tested (O(N²); a reference for tests).
    AllPairs,
}

fn default_skin() -> f64 {
    0.1
}
fn default_search() -> Search {
    Search::Cells
}

impl Default for Neighbor {
    fn default() -> Self {
        Neighbor {
            skin: default_skin(),
            cell: 0.0,
            search: default_search(),
        }
    }
}

impl Neighbor {
    /// The skin > 0.
    pub(super) fn check_skin(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        at.positive("neighbor.skin", self.skin)
    }

    /// The cell edge >= 0.
    pub(super) fn check_cell(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        at.non_negative("neighbor.cell", self.cell)
    }
}
