//! Flat walls (infinite planes) and their contacts with the spheres, in canonical form.

use super::PairForce;
use crate::Vec3;

/// A flat wall: the plane through `point` with unit normal `normal` (pointing to the spheres'
/// side), moving rigidly with the constant `velocity` (length/time); `point` is advanced by
/// `velocity`·dt at every drift, as a prescribed sphere's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    pub point: Vec3,
    pub normal: Vec3,
    pub velocity: Vec3,
}

/// One contact of a sphere with a wall in a snapshot: the sphere's original index, the wall's
/// index (0-based, in the case's order), the law's history words, the spring it reports and
/// the force and torque of the last evaluation on the sphere (`force.torque_i` is zero: a wall
/// takes no torque).
#[derive(Clone, Debug, PartialEq)]
pub struct WallContact {
    pub particle: u32,
    pub wall: u32,
    pub history: Vec<f64>,
    pub spring: Vec3,
    pub force: PairForce,
}
