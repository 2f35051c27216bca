//! Yade `Ip2_FrictMat_FrictMat_MindlinPhys` with `Law2_ScGeom_MindlinPhys_Mindlin`
//! (`pkg/dem/HertzMindlin.cpp`): ks = kso·√δ with kso = 8G*√R* (`phys->ks = phys->kso *
//! std::pow(uN, 0.5)`); the elastic shear force is incremental, rotated with the contact
//! (`scg->rotate`: first-order rotation) then decremented by ks·vs·dt with the objective slip
//! (`getIncidentVel` with `preventGranularRatcheting`); Mohr–Coulomb caps the elastic part at
//! μ|fn| and the viscous part is added after; torques with R − δ/2. verdem caps the total again
//! after the dashpot (its reference cap). Which mixing of G and ν the shear modulus uses is the
//! case's G* (`Parameters::g_star`); the yade-mpi fork's `Ip2_FrictMat_FrictMat_MindlinPhys`
//! averages G and ν of the two materials instead.

use super::{Force, NoSlip};
use crate::contact::tangential::cap::SpringThenTotal;
use crate::contact::tangential::frame::FirstOrderRotation;
use crate::contact::tangential::slip::ObjectiveSlip;

/// Yade's `MindlinPhys` law.
pub type YadeMindlin =
    NoSlip<ObjectiveSlip, FirstOrderRotation, SpringThenTotal, Force<false>, false>;
