//! The registry of tangential conventions: one entry per convention a case can name, giving
//! the name used in case files and on the command line, how its tangential model is built from
//! the case's contact [`Parameters`], the properties it claims and a one-line description. The
//! case parser, the law composition, the verification gates and the command line's help all
//! read this table: adding a convention is one entry here, plus a file of parts under
//! [`super::tangential`] if it needs new ones.
//!
//! Only the properties an entry lists are claimed; what follows from its model's lever arms
//! ([`Geometry`]: whether its torques conserve angular momentum, what the verification's
//! theory predicts for it) is read from the model's parts.

use super::tangential::conventions::{
    Cundall1979, LammpsGranular, LammpsHookeHistory, Liggghts, MercurySlidingFriction, Objective,
    YadeApprox, YadeViscEl,
};
use super::tangential::mindlin::deresiewicz::MindlinDeresiewicz;
use super::tangential::mindlin::force::LammpsMindlinForce;
use super::tangential::mindlin::kratos::KratosHertzMindlin;
use super::tangential::mindlin::lammps::LammpsMindlin;
use super::tangential::mindlin::liggghts::LiggghtsMindlin;
use super::tangential::mindlin::mercury::MercuryMindlin;
use super::tangential::mindlin::rescale::LammpsMindlinRescale;
use super::tangential::mindlin::yade::YadeMindlin;
use super::tangential::Arms;
use super::{Parameters, TangentialModel};

/// What a convention claims about its physics: the verification gates hold each convention to
/// the rows its properties promise and show the others as documentation of its defects.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Properties {
    /// Objective to second order per step: a rigid rotation of a loaded contact keeps |Fn| and
    /// |Ft| and turns Ft with the pair, and a closed cycle of relative motion below the sliding
    /// limit returns to zero force with zero net work (McNamara et al. 2008).
    pub objective: bool,
    /// The stored spring twists with the pair about the contact normal (by the mean spin
    /// about n); a spring that does not is left turned by a rotation about n.
    pub twists_spring: bool,
    /// While sliding the force is the capped spring alone, without the dashpot; the contact
    /// then slides at the end of an impact even below Walton's sticking limit ψ = 7mu/2.
    pub drops_dashpot_while_sliding: bool,
    /// The torques' lever arms reach the contact point where the force acts (R − δ/2), so a
    /// contact conserves angular momentum; full radii leave δ n × Ft per contact.
    pub conserves_angular_momentum: bool,
    /// The stiffness source: the spring is Mindlin's, kt = c·8G*·a from the material's elastic
    /// constants and the contact radius a = √(R*δ), not the case's constant kt. Rows that
    /// assume a constant kt run only the conventions without it ([`Tangential::constant_kt`]);
    /// a case naming it needs the material's youngs and poisson (`contact::named`).
    pub mindlin_stiffness: bool,
    /// Mindlin–Deresiewicz partial slip: the stiffness falls with the mobilised friction and
    /// a cycle at constant normal load follows the closed-form hysteresis loop (the Mindlin
    /// rows judge the loop for it and report it for the no-slip laws).
    pub partial_slip: bool,
}

impl Properties {
    /// No property at all.
    pub const NONE: Properties = Properties {
        objective: false,
        twists_spring: false,
        drops_dashpot_while_sliding: false,
        conserves_angular_momentum: false,
        mindlin_stiffness: false,
        partial_slip: false,
    };
}

/// The lever arms of a convention's slip and torques, read from its model's parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Geometry {
    /// The arms along which the spins enter the slip ([`TangentialModel::SLIP_ARMS`]).
    pub slip: Arms,
    /// Whether the slip scales the centres' relative velocity by α = (R_P + R_I)/|r|
    /// ([`TangentialModel::SLIP_SCALES_CENTRES`]).
    pub slip_scales_centres: bool,
    /// The arms of the torques ([`TangentialModel::FULL_RADIUS_LEVER`]).
    pub torque: Arms,
}

impl Geometry {
    /// The geometry of the model that `build` makes (never called: only its type is read).
    fn of<T: TangentialModel>(_build: impl Fn(&Parameters) -> T) -> Geometry {
        Geometry {
            slip: T::SLIP_ARMS,
            slip_scales_centres: T::SLIP_SCALES_CENTRES,
            torque: if T::FULL_RADIUS_LEVER {
                Arms::FullRadius
            } else {
                Arms::HalfOverlap
            },
        }
    }
}

/// Something done with a tangential model, whichever concrete type the convention names (its
/// history the `Vec3` the solver stores).
pub trait TangentialVisitor {
    type Output;
    /// Does the job with the tangential model `model`.
    fn visit<T: TangentialModel + Clone + 'static>(self, model: T) -> Self::Output;
}

/// Generates [`Tangential`] and its table from the entries
/// `Variant = "name", |p| model, [properties], "description";`, where `model` builds the
/// convention's tangential model from `p: &Parameters`.
macro_rules! conventions {
    ($(
        $variant:ident = $name:literal, |$p:ident| $build:expr, [$($property:ident),*],
            $description:literal;
    )*) => {
        /// A tangential contact convention, named in a case's `[contact] tangential`.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Tangential {
            $(
                #[doc = $description]
                $variant,
            )*
        }

        impl Tangential {
            /// Every convention, in the registry's order (that of the verification table).
            pub const ALL: [Tangential; [$($name),*].len()] = [$(Tangential::$variant),*];

            /// The name used in case files and on the command line.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Tangential::$variant => $name,)*
                }
            }

            /// The convention named `name` in case files, if any.
            pub fn named(name: &str) -> Option<Tangential> {
                Tangential::ALL.into_iter().find(|t| t.name() == name)
            }

            /// One line saying what the convention does and whose it is.
            pub const fn description(self) -> &'static str {
                match self {
                    $(Tangential::$variant => $description,)*
                }
            }

            /// The lever arms of the convention's slip and torques (see [`Geometry`]).
            pub fn geometry(self) -> Geometry {
                match self {
                    $(Tangential::$variant => Geometry::of(|$p: &Parameters| $build),)*
                }
            }

            /// Whether the convention's spring is the case's constant kt (it declares no
            /// [`Properties::mindlin_stiffness`]): the rows that assume one run it.
            pub fn constant_kt(self) -> bool {
                !self.properties().mindlin_stiffness
            }

            /// The conventions with the case's constant kt, in the registry's order.
            pub fn with_constant_kt() -> impl Iterator<Item = Tangential> {
                Tangential::ALL.into_iter().filter(|t| t.constant_kt())
            }

            /// The conventions with Mindlin's stiffness 8G*a, in the registry's order.
            pub fn with_mindlin_stiffness() -> impl Iterator<Item = Tangential> {
                Tangential::ALL.into_iter().filter(|t| !t.constant_kt())
            }

            /// What the convention claims (see [`Properties`]), and whether its torques conserve
            /// angular momentum (their arms reach the contact point).
            pub fn properties(self) -> Properties {
                let mut p = match self {
                    $(Tangential::$variant => Properties {
                        $($property: true,)*
                        ..Properties::NONE
                    },)*
                };
                p.conserves_angular_momentum = self.geometry().torque == Arms::HalfOverlap;
                p
            }

            /// Builds the convention's tangential model from the contact parameters `params`
            /// (its spring kt in force/length, dashpot γt in mass/time, absolute, and Coulomb
            /// coefficient μ, as the entry reads them) and hands it to `v`.
            pub fn with_model<V: TangentialVisitor>(self, params: &Parameters, v: V) -> V::Output {
                match self {
                    $(Tangential::$variant => {
                        let $p = params;
                        v.visit($build)
                    })*
                }
            }
        }
    };
}

conventions! {
    Mercury = "mercury", |p| MercurySlidingFriction::new(p.kt, p.gammat, p.mu), [],
        "MercuryDPM's sliding friction (the benchmark default): rate-form spring, cap on spring + dashpot";
    LammpsHookeHistory = "lammps-hooke-history", |p| LammpsHookeHistory::new(p.kt, p.gammat, p.mu), [],
        "LAMMPS `gran/hooke/history`: increment then project, full-radius lever arms";
    LammpsGranular = "lammps-granular", |p| LammpsGranular::new(p.kt, p.gammat, p.mu), [],
        "LAMMPS `granular … tangential linear_history`: project and rescale, then increment";
    Liggghts = "liggghts", |p| Liggghts::new(p.kt, p.gammat, p.mu), [drops_dashpot_while_sliding],
        "LIGGGHTS 3.8 `tangential history`: project; cap on the spring only, no dashpot while sliding";
    Yade = "yade", |p| YadeApprox::new(p.kt, p.gammat, p.mu), [twists_spring],
        "Yade's first-order rotation of the spring with the objective slip";
    YadeViscEl = "yade-viscel", |p| YadeViscEl::new(p.kt, p.gammat, p.mu), [twists_spring, drops_dashpot_while_sliding],
        "Yade `Law2_ScGeom_ViscElPhys_Basic`: first-order rotation, cap on the spring only, no dashpot while sliding";
    Cundall = "cundall", |p| Cundall1979::new(p.kt, p.gammat, p.mu), [],
        "Cundall & Strack 1979: no frame update at all";
    Objective = "objective", |p| Objective::new(p.kt, p.gammat, p.mu), [objective, twists_spring],
        "The objective reference law: exact rotation with the contact frame, objective slip";
    MindlinLammps = "mindlin-lammps", |p| LammpsMindlin::new(8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness],
        "LAMMPS `tangential mindlin`: displacement at the current stiffness 8G*a, project and rescale";
    MindlinRescale = "mindlin-rescale", |p| LammpsMindlinRescale::new(8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness],
        "LAMMPS `tangential mindlin_rescale`: displacement scaled by a/a_prev on unloading";
    MindlinForce = "mindlin-force", |p| LammpsMindlinForce::new(8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness],
        "LAMMPS `tangential mindlin/force`: incremental force, dF = -8G*a vt dt";
    MindlinLiggghts = "mindlin-liggghts", |p| LiggghtsMindlin::new(8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness, drops_dashpot_while_sliding],
        "LIGGGHTS `model hertz tangential history`: displacement at 8G*a, projected; cap on the spring only";
    MindlinKratos = "mindlin-kratos", |p| KratosHertzMindlin::new(8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness],
        "Kratos `DEM_D_Hertz_viscous_Coulomb`: incremental force, scaled by sqrt(delta/delta_prev) on unloading";
    MindlinYade = "mindlin-yade", |p| YadeMindlin::new(8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness, twists_spring],
        "Yade `MindlinPhys`: incremental force, first-order rotation, objective slip";
    MindlinMercury = "mindlin-mercury", |p| MercuryMindlin::new(2.0 / 3.0 * 8.0 * p.g_star, p.gammat, p.mu), [mindlin_stiffness, drops_dashpot_while_sliding],
        "MercuryDPM `MindlinInteraction`: rate-form displacement, Di Renzo & Di Maio's 2/3 of 8G*a";
    MindlinDeresiewicz = "mindlin-deresiewicz", |p| MindlinDeresiewicz::new(p.g_star, p.gammat, p.mu), [mindlin_stiffness, partial_slip, twists_spring],
        "The reference Mindlin-Deresiewicz partial slip with turning points, objective frame update";
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tangential::test_kinematics;
    use crate::Vec3;

    /// The work a contact's tangential force takes from a steady slip over `steps` steps, less
    /// what its spring holds at the end and what its dashpot and slider report, relative to the
    /// work.
    struct Unaccounted {
        steps: usize,
    }

    impl TangentialVisitor for Unaccounted {
        type Output = f64;
        fn visit<T: TangentialModel + Clone + 'static>(self, model: T) -> f64 {
            // P slides along x over I at rest, the normal along z fixed: no frame turns.
            let k = test_kinematics(
                Vec3::new(0.0, 0.0, 0.9999),
                Vec3::new(0.5, 0.0, 0.0),
                Vec3::zeros(),
                Vec3::zeros(),
            );
            let (dt, fn_signed) = (1e-4, 10.0);
            let mut history = T::History::default();
            let (mut taken, mut reported) = (0.0, 0.0);
            for _ in 0..self.steps {
                let (f, [dashpot, slide]) =
                    model.force_dissipating(&k, fn_signed, &mut history, dt);
                taken -= f.dot(&k.vt) * dt;
                reported += dashpot + slide;
            }
            (taken - model.stored_energy(&history) - reported) / taken
        }
    }

    /// Every convention with a constant kt splits its dissipation so that, over a contact that sticks and then
    /// slides, the work its force takes is what its spring holds plus what its dashpot and slider
    /// report, to a step's share of the work (the springs' work and energy telescope up to the
    /// two ends). Counting the spring energy the cap's reset releases as the slider's would
    /// leave ½·kt·|slip·dt|² a sliding step unaccounted: 0.7 % of the work here. (The Mindlin
    /// laws do not split theirs: the energy ledger says so.)
    #[test]
    fn every_convention_accounts_for_the_work_its_tangential_force_takes() {
        for t in Tangential::with_constant_kt() {
            let params = Parameters {
                kn: 1e4,
                gamman: 1.0,
                kt: 1000.0,
                gammat: 5.0,
                mu: 0.3,
                e_star: 0.0,
                g_star: 0.0,
                restitution: 1.0,
                dissipative_constant: 0.0,
            };
            let missing = t.with_model(&params, Unaccounted { steps: 500 });
            assert!(
                missing.abs() < 2e-3,
                "{}: {missing:e} of the work",
                t.name()
            );
        }
    }

    #[test]
    fn names_are_unique_and_the_full_radius_conventions_do_not_conserve_angular_momentum() {
        let names: std::collections::BTreeSet<_> = Tangential::ALL.map(Tangential::name).into();
        assert_eq!(names.len(), Tangential::ALL.len());
        for t in [Tangential::LammpsHookeHistory, Tangential::Cundall] {
            assert!(!t.properties().conserves_angular_momentum, "{}", t.name());
        }
        for t in [
            Tangential::Mercury,
            Tangential::LammpsGranular,
            Tangential::Objective,
        ] {
            assert!(t.properties().conserves_angular_momentum, "{}", t.name());
        }
        assert!(Tangential::Objective.properties().objective);
        assert!(!Tangential::Mercury.properties().objective);
    }
}
