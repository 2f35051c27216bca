//! The contact parameters of a case, from which the registries build a case's normal and
//! tangential models.

use crate::case;

/// The `[contact]` numbers a model can be built from; a model that needs another number adds a
/// field here and reads it from [`case::Contact`] in [`Parameters::of`].
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
}

impl Parameters {
    /// The parameters of the case's `[contact]` table `c`.
    pub fn of(c: &case::Contact) -> Parameters {
        Parameters {
            kn: c.kn,
            gamman: c.gamman,
            kt: c.kt,
            gammat: c.gammat,
            mu: c.mu,
            e_star: 0.0,
            g_star: 0.0,
        }
    }
}
