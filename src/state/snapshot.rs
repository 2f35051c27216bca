//! The state in canonical order: what saves, hashes and checkpoints are made of.

use super::{Domain, Particles};
use crate::Vec3;

/// Force and torques produced by one contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairForce {
    /// Total force on P (I receives −f).
    pub f: Vec3,
    /// Signed normal force f·n (negative in the attractive tail when not clipped).
    pub fn_signed: f64,
    /// Torque on P about its centre.
    pub torque_p: Vec3,
    /// Torque on I about its centre.
    pub torque_i: Vec3,
}

/// One contact of a [`Snapshot`], by original particle indices `p < i`.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    pub p: u32,
    pub i: u32,
    /// The contact law's history in its canonical words ([`crate::state::History`]); empty when
    /// unknown (a peer's contact).
    pub history: Vec<f64>,
    /// The elastic tangential displacement (length) of that history, for the `.fstat` output.
    pub spring: Vec3,
    /// Force and torques of the last evaluation (force on P).
    pub force: PairForce,
}

/// The state in canonical order: particles by id, contacts sorted by `(p, i)`.
#[derive(Clone, Debug)]
pub struct Snapshot {
    pub step: u64,
    pub time: f64,
    pub domain: Domain,
    pub particles: Particles,
    pub contacts: Vec<Contact>,
    /// The flat walls where they are at this step (none for most scenes).
    pub walls: Vec<super::Wall>,
    /// The spheres' contacts with them, sorted by (sphere, wall).
    pub wall_contacts: Vec<super::WallContact>,
}

/// A contact as a sample of the contact stress needs it: the original indices `p < i`, the
/// force of its last evaluation (on P), and the positions (length) and radii of P and I.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledContact {
    pub p: u32,
    pub i: u32,
    pub force: PairForce,
    pub x: [Vec3; 2],
    pub radius: [f64; 2],
}

impl Snapshot {
    /// The contacts of the snapshot as samples, in its order.
    pub fn sampled_contacts(&self) -> Vec<SampledContact> {
        let p = &self.particles;
        self.contacts
            .iter()
            .map(|c| {
                let (a, o) = (c.p as usize, c.i as usize);
                SampledContact {
                    p: c.p,
                    i: c.i,
                    force: c.force,
                    x: [p.x[a], p.x[o]],
                    radius: [p.radius[a], p.radius[o]],
                }
            })
            .collect()
    }
}
