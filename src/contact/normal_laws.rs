//! The registry of normal laws: one entry per normal force model (spring and damping) a case
//! can name in `[contact] normal`, giving the name used in case files, how its model is built
//! from the case's contact [`Parameters`] and a one-line description. The case parser and the
//! law composition read this table: adding a normal law is one file in `normal_laws/` holding
//! its [`NormalModel`] and one entry here naming that file after `mod`.
//!
//! Each entry also says which numbers of the case it reads (`reads [..]`, [`Reads`]): the case
//! must give them, and may not give a number of its normal law that the law leaves unread.
//! Whether a law splits its dissipation for the energy ledger follows from its model
//! ([`NormalModel::SPLITS_DISSIPATION`]); `[contact] clip_normal` clips any of them
//! ([`super::normal::Clipped`]).

use super::normal::{Absolute, Damped, Linear};
use super::{LinearSpringDashpot, NormalModel, Parameters};

/// A number of the case a normal law reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reads {
    /// `[contact] kn`: a linear spring's stiffness.
    Kn,
    /// `[material] youngs` and `poisson`: Hertz's spring, from E*.
    Elastic,
    /// `[contact] gamman`: the absolute dashpot.
    Gamman,
    /// `[contact] restitution`: a damping set from a restitution coefficient.
    Restitution,
    /// `[contact] dissipative_constant`: Brilliantov's viscoelastic damping.
    DissipativeConstant,
}

/// Something done with a normal model, whichever concrete type the case's law names.
pub trait NormalVisitor {
    type Output;
    /// Does the job with the normal model `model`.
    fn visit<N: NormalModel + Clone + 'static>(self, model: N) -> Self::Output;
}

/// Generates [`Normal`] and its table from the entries
/// `Variant = "name", mod file, reads [Kn, Gamman], |p| model, "description";`, where `model`
/// builds the law's normal model from `p: &Parameters`, `reads` lists the case's numbers it
/// reads ([`Reads`]) and the optional `mod file,` declares the module `normal_laws/file.rs` that
/// defines a part of it.
macro_rules! normal_laws {
    ($(
        $variant:ident = $name:literal, $(mod $file:ident,)? reads [$($reads:ident),*],
            |$p:ident| $build:expr, $description:literal;
    )*) => {
        $($(pub mod $file;)?)*

        /// A normal law (spring and damping), named in a case's `[contact] normal`.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Normal {
            $(
                #[doc = $description]
                $variant,
            )*
        }

        impl Normal {
            /// Every normal law, in the registry's order.
            pub const ALL: [Normal; [$($name),*].len()] = [$(Normal::$variant),*];

            /// The name used in case files.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Normal::$variant => $name,)*
                }
            }

            /// The normal law named `name` in case files, if any.
            pub fn named(name: &str) -> Option<Normal> {
                Normal::ALL.into_iter().find(|n| n.name() == name)
            }

            /// One line saying what the law does and whose it is.
            pub const fn description(self) -> &'static str {
                match self {
                    $(Normal::$variant => $description,)*
                }
            }

            /// The numbers of the case the law reads.
            pub const fn reads(self) -> &'static [Reads] {
                match self {
                    $(Normal::$variant => &[$(Reads::$reads),*],)*
                }
            }

            /// Builds the law's normal model from the contact parameters `params` (as the
            /// entry reads them) and hands it to `v`.
            pub fn with_model<V: NormalVisitor>(self, params: &Parameters, v: V) -> V::Output {
                match self {
                    $(Normal::$variant => {
                        let $p = params;
                        v.visit($build)
                    })*
                }
            }
        }
    };
}

normal_laws! {
    Linear = "linear", reads [Kn, Gamman], |p| LinearSpringDashpot { kn: p.kn, gamman: p.gamman },
        "Linear spring with an absolute dashpot, fn = kn delta - gamman vn (the default; MercuryDPM `LinearViscoelasticNormalSpecies`)";
    LinearRestitution = "linear-restitution", mod restitution, reads [Kn, Restitution],
        |p| Damped { spring: Linear { kn: p.kn }, damping: restitution::Restitution::new(p.restitution) },
        "Linear spring, dashpot gamman = -2 beta sqrt(kn m*) from contact.restitution (exact e; LIGGGHTS `model hooke`, LAMMPS `hooke` with `damping coeff_restitution`)";
    Hertz = "hertz", mod hertz, reads [Elastic, Gamman],
        |p| Damped { spring: hertz::Hertz { e_star: p.e_star }, damping: Absolute { gamman: p.gamman } },
        "Hertz spring fn = 4/3 E* sqrt(R*) delta^3/2 (Johnson 1985) with an absolute dashpot gamman (0: elastic)";
    HertzRestitution = "hertz-restitution", reads [Elastic, Restitution],
        |p| Damped { spring: hertz::Hertz { e_star: p.e_star }, damping: restitution::Restitution::new(p.restitution) },
        "Hertz spring, dashpot -2 sqrt(5/6) beta sqrt(Sn m*), Sn = 2 E* sqrt(R* delta), from contact.restitution (LIGGGHTS `model hertz`, LAMMPS `hertz/material` with `damping coeff_restitution`)";
    HertzTsuji = "hertz-tsuji", mod tsuji, reads [Elastic, Restitution],
        |p| Damped { spring: hertz::Hertz { e_star: p.e_star }, damping: tsuji::Tsuji::new(p.restitution) },
        "Hertz spring, Tsuji's dashpot alpha(e) sqrt(m* fn/delta) from contact.restitution (Tsuji et al. 1992; LAMMPS `damping tsuji`)";
    HertzViscoelastic = "hertz-viscoelastic", mod viscoelastic, reads [Elastic, DissipativeConstant], |p| Damped { spring: hertz::Hertz { e_star: p.e_star }, damping: viscoelastic::Viscoelastic { a: p.dissipative_constant } }, "Hertz spring, Brilliantov et al.'s viscoelastic dashpot A dF/ddelta = 2 A E* sqrt(R* delta), A from contact.dissipative_constant (Brilliantov et al. 1996)";
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The force of a law at an overlap and normal velocity.
    struct ForceAt {
        delta: f64,
        vn: f64,
    }

    impl NormalVisitor for ForceAt {
        type Output = f64;
        fn visit<N: NormalModel + Clone + 'static>(self, model: N) -> f64 {
            let k = crate::contact::normal::head_on(self.delta, self.vn, [0.5, 0.5], [1.0, 1.0]);
            model.force(&k)
        }
    }

    #[test]
    fn names_are_unique_and_the_linear_law_reads_kn_and_gamman() {
        let names: std::collections::BTreeSet<_> = Normal::ALL.map(Normal::name).into();
        assert_eq!(names.len(), Normal::ALL.len());
        assert_eq!(Normal::named("linear"), Some(Normal::Linear));
        let params = Parameters {
            kn: 2e5,
            gamman: 15.0,
            kt: 0.0,
            gammat: 0.0,
            mu: 0.0,
            e_star: 0.0,
            g_star: 0.0,
            restitution: 1.0,
            dissipative_constant: 0.0,
        };
        let f = Normal::Linear.with_model(
            &params,
            ForceAt {
                delta: 1e-3,
                vn: -1.0,
            },
        );
        assert!((f - (200.0 + 15.0)).abs() < 1e-9, "{f}");
    }

    #[test]
    fn a_case_names_its_normal_law_linear_by_default_and_an_unknown_one_is_an_error_at_its_line() {
        use crate::case::Case;
        let text = include_str!("../../cases/verify/binary_collision.toml");
        let case = Case::parse(text, "pair.toml").unwrap();
        assert_eq!(Normal::of(&case.contact).unwrap(), Normal::Linear);
        let named = text.replace("[contact]\n", "[contact]\nnormal = \"linear\"\n");
        assert_eq!(Case::parse(&named, "pair.toml").unwrap(), case);
        let unknown = text.replace("[contact]\n", "[contact]\nnormal = \"herz\"\n");
        let line = 1 + unknown
            .lines()
            .position(|l| l.starts_with("normal ="))
            .unwrap();
        let parsed = Case::parse(&unknown, "pair.toml").unwrap();
        let e = Normal::of(&parsed.contact).unwrap_err().to_string();
        let at = format!("pair.toml:{line}: contact.normal: unknown variant `herz`");
        assert!(e.contains(&at) && e.contains("`linear`"), "{e}");
    }

    /// A Hertz case: its law is built from E* and the scene's speeds; the numbers a law reads
    /// are required and the numbers it does not read refused, each at its line.
    #[test]
    fn a_hertz_case_gives_what_its_law_reads_and_nothing_else() {
        use crate::case::{Case, Stiffness};
        let text = include_str!("../../cases/verify/hertz_impact.toml");
        let case = Case::parse(text, "h.toml").unwrap();
        assert_eq!(Normal::checked(&case).unwrap(), Normal::Hertz);
        let e_star = 48e9 / (2.0 * (1.0 - 0.04));
        assert_eq!(case.stiffness(), Stiffness::Hertz { e_star });
        // dt from Hertz's free–free tc at the largest relative speed, 10 + 10 m/s
        let m = case.particle_mass();
        let tc = Case::hertz_collision_time(0.5 * m, 0.005, e_star, 20.0);
        assert!((case.dt() / (tc / 50.0) - 1.0).abs() < 1e-15);
        let line_of =
            |text: &str, start: &str| 1 + text.lines().position(|l| l.starts_with(start)).unwrap();
        let normal_line = line_of(text, "normal =");
        let contact_line = line_of(text, "[contact]");
        // a linear spring's kn with Hertz's law
        let with_kn = text.replace("gamman = 0.0", "gamman = 0.0\nkn = 1e5");
        let e = Normal::checked(&Case::parse(&with_kn, "h.toml").unwrap()).unwrap_err();
        assert_eq!(
            (e.line, e.field.as_str()),
            (normal_line, "contact.normal"),
            "{e}"
        );
        assert!(e.msg.contains("does not read contact.kn"), "{e}");
        // neither kn nor elastic constants: refused by the case itself at [contact]
        let bare = text.replace("youngs = 48e9\npoisson = 0.20\n", "");
        let e = Case::parse(&bare, "h.toml").unwrap_err();
        assert_eq!(
            (e.line, e.field.as_str()),
            (line_of(&bare, "[contact]"), "contact.kn"),
            "{e}"
        );
        assert!(e.msg.starts_with("missing field `kn`"), "{e}");
        // a linear spring's case naming Hertz's law
        let linear = bare.replace("gamman = 0.0", "gamman = 0.0\nkn = 1e5");
        let e = Normal::checked(&Case::parse(&linear, "h.toml").unwrap()).unwrap_err();
        assert!(
            e.msg
                .contains("material.youngs and material.poisson expected"),
            "{e}"
        );
        // a restitution damping without its e, with a gamman it does not read, with e out of range
        let named = text.replace("normal = \"hertz\"", "normal = \"hertz-restitution\"");
        let e = Normal::checked(&Case::parse(&named, "h.toml").unwrap()).unwrap_err();
        assert!(e.msg.contains("does not read contact.gamman"), "{e}");
        let no_e = named.replace("gamman = 0.0\n", "");
        let e = Normal::checked(&Case::parse(&no_e, "h.toml").unwrap()).unwrap_err();
        assert_eq!(
            (e.line, e.field.as_str()),
            (contact_line, "contact.restitution"),
            "{e}"
        );
        let good = no_e.replace("[contact]\n", "[contact]\nrestitution = 0.5\n");
        let parsed = Case::parse(&good, "h.toml").unwrap();
        assert_eq!(Normal::checked(&parsed).unwrap(), Normal::HertzRestitution);
        let bad = good.replace("restitution = 0.5", "restitution = 1.5");
        let e = Case::parse(&bad, "h.toml").unwrap_err();
        assert_eq!(e.field, "contact.restitution", "{e}");
        // a Poisson's ratio beyond 0.5
        let e = Case::parse(&text.replace("poisson = 0.20", "poisson = 0.7"), "h.toml");
        assert_eq!(e.unwrap_err().field, "material.poisson");
        // at rest: no impact speed to take Hertz's collision time at
        let still = text
            .replace("v = [10.0, 0.0, 0.0]", "")
            .replace("v = [-10.0, 0.0, 0.0]", "");
        assert_eq!(
            Case::parse(&still, "h.toml").unwrap_err().field,
            "scene.sphere"
        );
        // the stiffest contact at 20 m/s: tc/dt at its limit is 2.0; 5 steps are coarse
        let steps = |n: &str| text.replace("steps_per_collision = 50.0", n);
        let coarse = Case::parse(&steps("steps_per_collision = 5.0"), "h.toml").unwrap();
        assert_eq!(coarse.warnings().len(), 1, "{:?}", coarse.warnings());
        let limit = coarse.stability_limit().unwrap();
        assert!((tc / limit.dt - 2.0).abs() < 0.05, "{}", tc / limit.dt);
        let e = Case::parse(&steps("steps_per_collision = 1.5"), "h.toml").unwrap_err();
        assert_eq!(e.field, "run.steps_per_collision", "{e}");
    }
}
