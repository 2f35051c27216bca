//! The reference partial-slip law: Mindlin & Deresiewicz (J. Appl. Mech. 20, 327, 1953) in the
//! incremental form of Thornton, Cummins & Cleary (Powder Technol. 233, 30, 2013, §2.3, after
//! Thornton & Yin 1991) at the current normal load N = |fn|: the tangential stiffness is
//! 8G*·a·θ with
//!
//! - θ³ = 1 − |T|/(μN) on a first (virgin) loading,
//! - θ³ = 1 − |T* − T|/(2μN) unloading from the turning point T*,
//! - θ³ = 1 − |T − T**|/(2μN) reloading from the turning point T**,
//!
//! T the elastic tangential force. An unloading branch that reaches −T* (|T − T*| = 2|T*|), or
//! a reloading branch that passes T*, rejoins the virgin curve (Masing's rule); a reversal on a
//! reloading branch starts a new unloading from there, forgetting the older loop (nested loops
//! are not stacked). When the contact radius shrinks, the force and the turning points are
//! scaled by a/a_prev (Walton's unloading rule, as Thornton et al. 2013 use it); Thornton's
//! ±μΔN(1 − θ) term for a changing normal load is not included, so with no tangential motion a
//! growing contact keeps its force and a shrinking one scales it by a/a_prev (and the cap μN
//! may cut it). Each step integrates
//! the stiffness at the step's midpoint force (second order in the increment). The stored force
//! and turning points follow the contact frame exactly ([`ExactRotation`]), with the objective
//! slip at the step's midpoint normal ([`MidpointObjectiveSlip`]): the objective reference
//! law's parts. The dashpot is added after the elastic force and the total capped at μN.

use super::contact_radius;
use crate::contact::tangential::frame::{ExactRotation, FrameUpdate};
use crate::contact::tangential::slip::{MidpointObjectiveSlip, Slip};
use crate::contact::tangential::{Arms, TangentialModel};
use crate::contact::PairKinematics;
use crate::state::History;
use crate::Vec3;

/// Which branch of the loop the contact is on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Branch {
    /// First loading from zero force (or after full sliding, or past a turning point).
    #[default]
    Virgin,
    /// Unloading from the turning point T* ([`Deresiewicz::turn`]).
    Unloading,
    /// Reloading from the turning point T** ([`Deresiewicz::back`]) towards T*.
    Reloading,
}

impl Branch {
    /// The branch's canonical word.
    fn word(self) -> f64 {
        match self {
            Branch::Virgin => 0.0,
            Branch::Unloading => 1.0,
            Branch::Reloading => 2.0,
        }
    }

    /// The branch of canonical word `w` (as [`Branch::word`] wrote it).
    fn of_word(w: f64) -> Branch {
        if w == 1.0 {
            Branch::Unloading
        } else if w == 2.0 {
            Branch::Reloading
        } else {
            Branch::Virgin
        }
    }
}

/// The history of a Mindlin–Deresiewicz contact: the elastic force T on P (force units), the
/// turning points T* and T** (force units), the branch and the last step's stiffness 8G*a
/// (force/length); canonical words Tx, Ty, Tz, T*x, T*y, T*z, T**x, T**y, T**z, branch, k.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Deresiewicz {
    pub force: Vec3,
    pub turn: Vec3,
    pub back: Vec3,
    pub branch: Branch,
    pub k: f64,
}

impl History for Deresiewicz {
    const WORDS: usize = 11;

    fn put_words(&self, out: &mut Vec<f64>) {
        for v in [self.force, self.turn, self.back] {
            out.extend_from_slice(&[v.x, v.y, v.z]);
        }
        out.extend_from_slice(&[self.branch.word(), self.k]);
    }

    fn from_words(w: &[f64]) -> Self {
        let v = |i: usize| Vec3::new(w[i], w[i + 1], w[i + 2]);
        Deresiewicz {
            force: v(0),
            turn: v(3),
            back: v(6),
            branch: Branch::of_word(w[9]),
            k: w[10],
        }
    }

    /// The displacement that gives the stored force at the no-slip stiffness, −T/(8G*a).
    fn spring(&self) -> Vec3 {
        if self.k > 0.0 {
            -self.force / self.k
        } else {
            Vec3::zeros()
        }
    }
}

/// Mindlin–Deresiewicz partial slip with shear modulus `g_star` (G*, force/length²), absolute
/// dashpot `gammat` (mass/time) and Coulomb coefficient `mu`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MindlinDeresiewicz {
    pub g_star: f64,
    pub gammat: f64,
    pub mu: f64,
}

impl MindlinDeresiewicz {
    /// The law of effective shear modulus `g_star` (force/length²), dashpot `gammat`
    /// (mass/time, absolute) and Coulomb coefficient `mu`.
    pub const fn new(g_star: f64, gammat: f64, mu: f64) -> Self {
        MindlinDeresiewicz { g_star, gammat, mu }
    }
}

/// θ of the branch `branch` at the force `t` with turning points `turn`, `back`, for the
/// Coulomb limit `limit` = μN (force): Thornton et al. 2013's θ at constant N.
#[inline(always)]
fn theta(branch: Branch, t: Vec3, turn: Vec3, back: Vec3, limit: f64) -> f64 {
    let used = match branch {
        Branch::Virgin => t.norm() / limit,
        Branch::Unloading => (turn - t).norm() / (2.0 * limit),
        Branch::Reloading => (t - back).norm() / (2.0 * limit),
    };
    (1.0 - used).max(0.0).cbrt()
}

impl TangentialModel for MindlinDeresiewicz {
    type History = Deresiewicz;
    const ACTIVE: bool = true;
    const SLIP_ARMS: Arms = <MidpointObjectiveSlip as Slip>::ARMS;
    const SLIP_SCALES_CENTRES: bool = <MidpointObjectiveSlip as Slip>::SCALES_CENTRES;

    fn force(&self, k: &PairKinematics, fn_signed: f64, h: &mut Deresiewicz, dt: f64) -> Vec3 {
        let k0 = 8.0 * self.g_star * contact_radius(k);
        let limit = self.mu * fn_signed.abs();
        let slip = MidpointObjectiveSlip::slip(k, dt);
        for v in [&mut h.force, &mut h.turn, &mut h.back] {
            ExactRotation::advance(v, Vec3::zeros(), k, dt, 0.0);
        }
        // an unloading contact scales its force and turning points by a/a_prev (Walton, as in
        // Thornton et al. 2013): a shrinking contact carries less, so no cycle creates energy
        if k0 < h.k {
            let shrink = k0 / h.k;
            h.force *= shrink;
            h.turn *= shrink;
            h.back *= shrink;
        }
        h.k = k0;
        if limit <= 0.0 {
            *h = Deresiewicz {
                k: k0,
                ..Deresiewicz::default()
            };
            return Vec3::zeros();
        }
        let du = slip * dt;
        // the force moves along −du: a reversal is a move back towards the branch's origin
        let origin = match h.branch {
            Branch::Virgin => Vec3::zeros(),
            Branch::Unloading => h.turn,
            Branch::Reloading => h.back,
        };
        if (h.force - origin).dot(&du) > 0.0 {
            match h.branch {
                Branch::Virgin | Branch::Reloading => {
                    h.turn = h.force;
                    h.branch = Branch::Unloading;
                }
                Branch::Unloading => {
                    h.back = h.force;
                    h.branch = Branch::Reloading;
                }
            }
        }
        let th = theta(h.branch, h.force, h.turn, h.back, limit);
        let half = h.force - 0.5 * k0 * th * du;
        let th = theta(h.branch, half, h.turn, h.back, limit);
        let t = h.force - k0 * th * du;
        // Masing: past −T* on unloading, past T* on reloading, the virgin curve again
        let rejoins = match h.branch {
            Branch::Virgin => false,
            Branch::Unloading => (t - h.turn).norm() >= 2.0 * h.turn.norm(),
            Branch::Reloading => (t - h.back).norm() >= (h.turn - h.back).norm(),
        };
        if rejoins {
            h.branch = Branch::Virgin;
        }
        h.force = t;
        let magnitude = t.norm();
        if magnitude > limit {
            h.force = t * (limit / magnitude);
            h.branch = Branch::Virgin;
        }
        let total = h.force - self.gammat * slip;
        let magnitude = total.norm();
        if magnitude > limit {
            total * (limit / magnitude)
        } else {
            total
        }
    }

    /// The no-slip spring's energy at the last step's stiffness, ½|T|²/(8G*a): the energy the
    /// force would give back unloading elastically; the partial-slip law gives back less.
    fn stored_energy(&self, h: &Deresiewicz) -> f64 {
        if h.k > 0.0 {
            0.5 * h.force.norm_squared() / h.k
        } else {
            0.0
        }
    }
}
