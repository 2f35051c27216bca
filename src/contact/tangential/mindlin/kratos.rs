//! Kratos DEM `DEM_D_Hertz_viscous_Coulomb`
//! (`applications/DEMApplication/custom_constitutive/DEM_D_Hertz_viscous_Coulomb_CL.cpp`):
//! kt = 4G*·kn/E* with kn = 2E*√(R*δ), i.e. 8G*a (`InitializeContact`); the elastic force is
//! incremental, F = F_old − kt·Δu, and when the overlap decreased the old force is first scaled
//! by √(δ/δ_prev) = a/a_prev (`minoring_factor`, `CalculateTangentialForceWithNeighbour`).
//! Kratos carries the old force in its local contact frame; verdem composes this storage with
//! the slip to the contact point in the middle of the overlap, the projection after the
//! increment and the cap of the elastic part then the total, which are verdem's choices for
//! the parts Kratos handles in its own frame and were not checked against it line by line.

use super::{Force, NoSlip};
use crate::contact::tangential::cap::SpringThenTotal;
use crate::contact::tangential::frame::ProjectAfter;
use crate::contact::tangential::slip::HalfOverlapSlip;

/// Kratos DEM `DEM_D_Hertz_viscous_Coulomb`'s tangential part.
pub type KratosHertzMindlin =
    NoSlip<HalfOverlapSlip, ProjectAfter, SpringThenTotal, Force<true>, false>;
