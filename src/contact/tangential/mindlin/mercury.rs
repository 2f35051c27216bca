//! MercuryDPM `MindlinInteraction::computeFrictionForce`
//! (`Kernel/Interactions/FrictionForceInteractions/MindlinInteraction.cc`): the sliding spring
//! is a displacement integrated in rate form (dξ/dt = vt − (ξ·(v_P − v_I)/|r|) n for particle
//! pairs), K_t0 = 8G√(Rδ) (`updateTangentialStiffnessZero`) and the force
//! −(2/3)·K_t0·ξ (Di Renzo & Di Maio, Chem. Eng. Sci. 60, 1303, 2005, eq. 37); the spring alone
//! is capped at μ|fn|, the dashpot added only while it sticks, the spring reset to the cap. So
//! its registry entry builds it with k0 = (2/3)·8G*. MercuryDPM's K_t0 takes the species'
//! `getShearModulus()` and `getEffectiveRadius()` as they are: it is 8G*a when the species holds
//! the pair's effective G* (the file's own comment says dissimilar particles are not handled);
//! verdem takes the case's G*. MercuryDPM compares `<` where verdem's cap
//! compares `<=` (they differ only at the cap exactly). The turning-point path of the same file
//! (`updateK_t`) is not called by `computeFrictionForce` and is not composed here.

use super::{Displacement, NoSlip};
use crate::contact::tangential::cap::LiggghtsCap;
use crate::contact::tangential::frame::RateForm;
use crate::contact::tangential::slip::HalfOverlapSlip;

/// MercuryDPM's `MindlinInteraction`, built with k0 = (2/3)·8G*.
pub type MercuryMindlin =
    NoSlip<HalfOverlapSlip, RateForm, LiggghtsCap, Displacement<false>, false>;
