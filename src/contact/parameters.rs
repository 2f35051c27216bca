//! The contact parameters of a case, from which the registries build a case's normal and
//! tangential models.

use crate::case::{self, Case};

/// The numbers of a case a model can be built from; a model that needs another number adds a
/// field here and reads it from the [`Case`] in [`Parameters::of`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameters {
    /// Normal spring stiffness (force/length).
    pub kn: f64,
    /// Absolute normal damping (mass/time).
    pub gamman: f64,
    /// Tangential spring stiffness (force/length).
    pub kt: f64,
    /// Absolute tangential damping (mass/time).
    pub gammat: f64,
    /// Coulomb friction coefficient (dimensionless).
    pub mu: f64,
    /// Effective Young's modulus of the pair, E* (force/length²): 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂
    /// (Johnson, Contact Mechanics, 1985, §4.2); 0 when the case gives no elastic constants.
    pub e_star: f64,
    /// Effective shear modulus of the pair, G* (force/length²): 1/G* = (2−ν₁)/G₁ + (2−ν₂)/G₂,
    /// G = E/(2(1+ν)) (Mindlin 1949); 0 when the case gives no elastic constants.
    pub g_star: f64,
    /// Normal restitution coefficient a damping aims at (dimensionless, in (0, 1]); 1 when the
    /// case gives none.
    pub restitution: f64,
    /// Brilliantov et al.'s dissipative constant A (time); 0 when the case gives none.
    pub dissipative_constant: f64,
}

impl Parameters {
    /// The parameters of the case `case`: its `[contact]` numbers, and E*, G* of a pair of its
    /// `[material]` (both spheres of the one material: [`case::Material::e_star`],
    /// [`case::Material::g_star`]).
    pub fn of(case: &Case) -> Parameters {
        let c: &case::Contact = &case.contact;
        Parameters {
            kn: c.kn,
            gamman: c.gamman,
            kt: c.kt,
            gammat: c.gammat,
            mu: c.mu,
            e_star: case.material.e_star().unwrap_or(0.0),
            g_star: case.material.g_star().unwrap_or(0.0),
            restitution: c.restitution.unwrap_or(1.0),
            dissipative_constant: c.dissipative_constant.unwrap_or(0.0),
        }
    }
}
