//! verdem: a deterministic discrete-element solver for spheres, built as a verification harness
//! and a reproducible benchmark suite for the ON-DEM "granular shear flow between bumpy walls" case.
//!
//! Data flow of a run: [`case`] (TOML, validated) → [`scene`] (walls and free spheres, generated or
//! read) into a [`state`] → [`step`] (the time step, top to bottom, under a [`contact`] law) →
//! [`io`] (MercuryCG `.data`/`.fstat` saves, checkpoints, hash, diagnostics).

pub mod analysis;
pub mod bench;
pub mod case;
pub mod child;
pub mod contact;
pub mod ensemble;
pub mod file_name;
pub mod io;
pub mod peers;
pub mod python;
pub mod run;
pub mod scene;
pub mod stability;
pub mod state;
pub mod step;
pub mod tradeoff;
pub mod verify;

/// Three-component vector of `f64` used for positions, velocities, forces and torques.
pub type Vec3 = nalgebra::Vector3<f64>;
