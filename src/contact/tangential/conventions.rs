//! The named tangential conventions: MercuryDPM's sliding friction, the conventions of peer
//! codes and the objective reference law.

use super::cap::{LammpsCap, LiggghtsCap, MercuryCap, SpringThenTotal};
use super::frame::{
    ExactRotation, FirstOrderRotation, NoFrameUpdate, ProjectAfter, ProjectRescale, RateForm,
};
use super::slip::{FullRadiusSlip, HalfOverlapSlip, MidpointObjectiveSlip, ObjectiveSlip};
use super::Convention;

/// MercuryDPM's sliding friction (`SlidingFrictionInteraction`), the benchmark's default:
/// spring kt and dashpot γt in parallel, in series with a Coulomb slider; slip with R − δ/2,
/// the spring integrated in rate form (its only frame update), spring + dashpot capped at
/// mu|fn| (compared as squares) and the spring reset to match the cap while sliding.
pub type MercurySlidingFriction = Convention<HalfOverlapSlip, RateForm, MercuryCap, false>;
/// LAMMPS `pair_style gran/hooke/history` (with absolute damping): full-radius slip, increment
/// then project, cap on spring + dashpot, torques with full radii (`torque[i] -= radi*tor`).
pub type LammpsHookeHistory = Convention<FullRadiusSlip, ProjectAfter, LammpsCap, true>;
/// LAMMPS `pair_style granular … tangential linear_history`: full-radius slip, project and
/// rescale then increment, cap on spring + dashpot, torques with R − δ/2 (`dist_to_contact`).
pub type LammpsGranular = Convention<FullRadiusSlip, ProjectRescale, LammpsCap, false>;
/// LIGGGHTS 3.8 `tangential history`: slip with R − δ/2, increment then project, cap on the
/// spring only, dashpot dropped while sliding.
pub type Liggghts = Convention<HalfOverlapSlip, ProjectAfter, LiggghtsCap, false>;
/// Yade's `ScGeom` with `avoidGranularRatcheting` (its default): objective slip, first-order
/// rotation of the spring, torques with R − δ/2; verdem adds the dashpot and cap of the
/// reference law (Yade's `FrictPhys` has no tangential dashpot).
pub type YadeApprox = Convention<ObjectiveSlip, FirstOrderRotation, SpringThenTotal, false>;
/// Yade's `Law2_ScGeom_ViscElPhys_Basic` (`pkg/dem/ViscoelasticPM.cpp`): slip of the material
/// points at the contact point in the middle of the overlap (R − δ/2), the stored elastic force
/// turned by `ScGeom::rotate` (first-order rotation) and then incremented, the elastic part alone
/// capped at mu|fn| and the dashpot added only while it sticks, torques with R − δ/2. Its normal
/// force is clipped at zero (`clip_normal`).
pub type YadeViscEl = Convention<HalfOverlapSlip, FirstOrderRotation, LiggghtsCap, false>;
/// Cundall & Strack (Géotechnique 29, 47, 1979): full-radius slip, no frame update at all,
/// torques with full radii.
pub type Cundall1979 = Convention<FullRadiusSlip, NoFrameUpdate, SpringThenTotal, true>;
/// The objective reference law: objective slip (at the step's midpoint normal), exact rotation
/// with the contact frame, elastic part capped and stored, dashpot added and the total capped,
/// torques with R − δ/2.
pub type Objective = Convention<MidpointObjectiveSlip, ExactRotation, SpringThenTotal, false>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tangential::TangentialModel;
    use crate::contact::{PairInput, PairKinematics};
    use crate::Vec3;

    fn sliding_pair(vt: f64) -> PairKinematics {
        PairInput {
            r: Vec3::new(0.0, 0.0, 0.999),
            rad_p: 0.5,
            rad_i: 0.5,
            inv_mass_p: 0.0,
            inv_mass_i: 0.0,
            v_p: Vec3::new(vt, 0.0, 0.0),
            v_i: Vec3::zeros(),
            w_p: Vec3::zeros(),
            w_i: Vec3::zeros(),
        }
        .kinematics()
        .unwrap()
    }

    const LAW: MercurySlidingFriction =
        MercurySlidingFriction::new(2e5 * 2.0 / 7.0, 15.0 * 2.0 / 7.0, 0.3);

    #[test]
    fn sticking_contact_builds_spring_against_the_motion() {
        let k = sliding_pair(1e-3);
        let mut xi = Vec3::zeros();
        let f = LAW.force(&k, 200.0, &mut xi, 1e-4);
        assert!((xi.x - 1e-7).abs() < 1e-20);
        let expected = -(LAW.kt * 1e-7 + LAW.gammat * 1e-3);
        assert!((f.x - expected).abs() < 1e-12);
    }

    #[test]
    fn sliding_contact_is_capped_at_mu_fn_and_spring_matches_the_cap() {
        let k = sliding_pair(10.0);
        let mut xi = Vec3::new(-1.0, 0.0, 0.0);
        let f = LAW.force(&k, 200.0, &mut xi, 1e-4);
        assert!((f.norm() - 60.0).abs() < 1e-12);
        let back = -(LAW.kt * xi + LAW.gammat * k.vt);
        assert!((back - f).norm() < 1e-9);
    }

    #[test]
    fn cap_uses_the_absolute_normal_force_in_the_attractive_tail() {
        let k = sliding_pair(10.0);
        let mut xi = Vec3::zeros();
        let f = LAW.force(&k, -1.0, &mut xi, 1e-4);
        assert!((f.norm() - 0.3).abs() < 1e-12);
        assert!(f.x < 0.0);
    }
}
