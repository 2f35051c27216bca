//! Particle arrays (structure of arrays) for free and wall spheres.

pub mod domain;
pub mod history;
pub mod memory;
pub mod snapshot;
pub mod tally;
pub mod walls;

pub use domain::Domain;
pub use history::History;
pub use snapshot::{Contact, PairForce, SampledContact, Snapshot};
pub use tally::Tally;
pub use walls::{Wall, WallContact};

use crate::Vec3;

/// How a particle moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Integrated from the forces acting on it.
    Free,
    /// Moved rigidly with its constant prescribed velocity; never integrated, infinite mass.
    /// The number is the wall group (0 = bottom, 1 = top in the shear case).
    Prescribed(u8),
}

/// All particles of a scene, in id order (index = id − 1 of the input files).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    /// Centre positions (length), wrapped into the box along periodic axes.
    pub x: Vec<Vec3>,
    /// Translational velocities (length/time).
    pub v: Vec<Vec3>,
    /// Angular velocities (rad/time).
    pub w: Vec<Vec3>,
    /// Radii (length).
    pub radius: Vec<f64>,
    /// Inverse mass (1/mass); 0 for prescribed particles.
    pub inv_mass: Vec<f64>,
    /// Inverse moment of inertia of a solid sphere, 1/(0.4 m r²); 0 for prescribed particles.
    pub inv_inertia: Vec<f64>,
    /// Free or prescribed motion.
    pub motion: Vec<Motion>,
    /// Total contact force on each particle at the current step (force units).
    pub f: Vec<Vec3>,
    /// Total contact torque on each particle about its centre at the current step.
    pub t: Vec<Vec3>,
}

impl Particles {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Appends a particle of the given radius and density at rest (zero force and torque).
    /// Mass m = 4/3 π r³ ρ and inertia 0.4 m r², as MercuryDPM computes them for a sphere.
    pub fn push(&mut self, x: Vec3, v: Vec3, w: Vec3, radius: f64, density: f64, motion: Motion) {
        let mass = 4.0 / 3.0 * std::f64::consts::PI * radius * radius * radius * density;
        let free = motion == Motion::Free;
        self.x.push(x);
        self.v.push(v);
        self.w.push(w);
        self.radius.push(radius);
        self.inv_mass.push(if free { 1.0 / mass } else { 0.0 });
        self.inv_inertia.push(if free {
            1.0 / (0.4 * mass * radius * radius)
        } else {
            0.0
        });
        self.motion.push(motion);
        self.f.push(Vec3::zeros());
        self.t.push(Vec3::zeros());
    }

    /// True when particle `i` is integrated (not a wall sphere).
    #[inline(always)]
    pub fn is_free(&self, i: usize) -> bool {
        self.motion[i] == Motion::Free
    }

    /// Number of free particles.
    pub fn free_count(&self) -> usize {
        self.motion.iter().filter(|m| **m == Motion::Free).count()
    }
}
