//! LIGGGHTS 3.8 `model hertz tangential history` (`src/normal_model_hertz.h` sets
//! kt = 8·G*·√(R*δ); `src/tangential_model_history.h` integrates the shear displacement): the
//! history is a displacement with the force −kt(a)·ξ at the current stiffness, incremented then
//! projected onto the new plane without restoring its length, the spring alone capped at μ|fn|
//! and the dashpot dropped while sliding; slip and torques with R − δ/2 (`sidata.cri`).

use super::{Displacement, NoSlip};
use crate::contact::tangential::cap::LiggghtsCap;
use crate::contact::tangential::frame::ProjectAfter;
use crate::contact::tangential::slip::HalfOverlapSlip;

/// LIGGGHTS `tangential history` with the Hertz normal model.
pub type LiggghtsMindlin =
    NoSlip<HalfOverlapSlip, ProjectAfter, LiggghtsCap, Displacement<false>, false>;
