//! LAMMPS `tangential mindlin_rescale` (`src/GRANULAR/gran_sub_mod_tangential.cpp`,
//! `GranSubModTangentialMindlin::calculate_forces` with `mindlin_rescale`): as `mindlin`
//! ([`super::lammps`]), and before the frame update the displacement is scaled by a/a_prev when
//! the contact radius shrank (`if (contact_radius < history[3])`, the fourth history word
//! holding the last step's a; Walton's unloading rule as in Thornton et al., Powder Technol.
//! 233, 30, 2013). Since the force is −8G*·a·ξ, an unloading contact's force goes as
//! (a/a_prev)² with no tangential motion.

use super::{Displacement, NoSlip};
use crate::contact::tangential::cap::LammpsCap;
use crate::contact::tangential::frame::ProjectRescale;
use crate::contact::tangential::slip::FullRadiusSlip;

/// LAMMPS `tangential mindlin_rescale`.
pub type LammpsMindlinRescale =
    NoSlip<FullRadiusSlip, ProjectRescale, LammpsCap, Displacement<true>, false>;
