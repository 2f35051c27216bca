//! `[output]`: files a run writes beside its MercuryCG saves.

use serde::Deserialize;

/// `[output]`: files a run writes beside its MercuryCG saves.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Also write each save as a ParaView file (`NAME.NNNN.vtu`, listed in `NAME.pvd`).
    #[serde(default)]
    pub vtk: bool,
}
