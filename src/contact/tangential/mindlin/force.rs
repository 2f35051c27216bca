//! LAMMPS `tangential mindlin/force` (`src/GRANULAR/gran_sub_mod_tangential.cpp`,
//! `GranSubModTangentialMindlin::calculate_forces` with `mindlin_force`): the history is the
//! elastic force, projected and rescaled onto the new tangent plane (skipped below
//! 1e-10·Fscrit), then incremented by −8G*·a·vtr·dt (eq. 18 of Thornton et al., Powder Technol.
//! 233, 30, 2013); spring + dashpot capped at μ|fn|, the history reset to the capped elastic
//! part; full-radius slip, torques with R − δ/2. A change of a with no tangential motion leaves
//! the force.

use super::{Force, NoSlip};
use crate::contact::tangential::cap::LammpsCap;
use crate::contact::tangential::frame::ProjectRescale;
use crate::contact::tangential::slip::FullRadiusSlip;

/// LAMMPS `tangential mindlin/force`.
pub type LammpsMindlinForce =
    NoSlip<FullRadiusSlip, ProjectRescale, LammpsCap, Force<false>, false>;
