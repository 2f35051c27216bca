//! LAMMPS `pair_style granular … tangential mindlin` (`src/GRANULAR/gran_sub_mod_tangential.cpp`,
//! `GranSubModTangentialMindlin::calculate_forces` with neither `mindlin_force` nor
//! `mindlin_rescale`): the history is a displacement, projected onto the new tangent plane and
//! rescaled to its old length (`rotate_rescale_vec`, skipped below 1e-10·Fscrit), then
//! incremented by vtr·dt with the full-radius slip; the force is −k·a·ξ with k = 8G*
//! (`k_scaled = k * contact_radius`), spring + dashpot capped at μ|fn| and the history reset to
//! the capped elastic part; torques with R − δ/2.

use super::{Displacement, NoSlip};
use crate::contact::tangential::cap::LammpsCap;
use crate::contact::tangential::frame::ProjectRescale;
use crate::contact::tangential::slip::FullRadiusSlip;

/// LAMMPS `tangential mindlin`.
pub type LammpsMindlin =
    NoSlip<FullRadiusSlip, ProjectRescale, LammpsCap, Displacement<false>, false>;
