//! The registry of normal laws: one entry per normal force model (spring and damping) a case
//! can name in `[contact] normal`, giving the name used in case files, how its model is built
//! from the case's contact [`Parameters`] and a one-line description. The case parser and the
//! law composition read this table: adding a normal law is one file in `normal_laws/` holding
//! its [`NormalModel`] and one entry here naming that file after `mod`.
//!
//! Whether a law splits its dissipation for the energy ledger follows from its model
//! ([`NormalModel::SPLITS_DISSIPATION`]); `[contact] clip_normal` clips any of them
//! ([`super::normal::Clipped`]).

use super::{LinearSpringDashpot, NormalModel, Parameters};

/// Something done with a normal model, whichever concrete type the case's law names.
pub trait NormalVisitor {
    type Output;
    /// Does the job with the normal model `model`.
    fn visit<N: NormalModel + Clone + 'static>(self, model: N) -> Self::Output;
}

/// Generates [`Normal`] and its table from the entries
/// `Variant = "name", mod file, |p| model, "description";`, where `model` builds the law's
/// normal model from `p: &Parameters` and the optional `mod file,` declares the module
/// `normal_laws/file.rs` that defines it.
macro_rules! normal_laws {
    ($(
        $variant:ident = $name:literal, $(mod $file:ident,)? |$p:ident| $build:expr,
            $description:literal;
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

            /// Builds the law's normal model from the contact parameters `params` (its
            /// stiffness kn in force/length and damping γn in mass/time, absolute, as the entry
            /// reads them) and hands it to `v`.
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
    Linear = "linear", |p| LinearSpringDashpot { kn: p.kn, gamman: p.gamman },
        "Linear spring with an absolute dashpot, fn = kn delta - gamman vn (the default; MercuryDPM `LinearViscoelasticNormalSpecies`)";
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
            model.force(self.delta, self.vn)
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
        };
        let f = Normal::Linear.with_model(
            &params,
            ForceAt {
                delta: 1e-3,
                vn: -1.0,
            },
        );
        assert_eq!(f, 200.0 + 15.0);
    }

    #[test]
    fn a_case_names_its_normal_law_linear_by_default_and_an_unknown_one_is_an_error_at_its_line() {
        use crate::case::Case;
        let text = include_str!("../../cases/verify/binary_collision.toml");
        let case = Case::parse(text, "pair.toml").unwrap();
        assert_eq!(Normal::of(&case.contact).unwrap(), Normal::Linear);
        let named = text.replace("[contact]\n", "[contact]\nnormal = \"linear\"\n");
        assert_eq!(Case::parse(&named, "pair.toml").unwrap(), case);
        let unknown = text.replace("[contact]\n", "[contact]\nnormal = \"hertz\"\n");
        let line = 1 + unknown
            .lines()
            .position(|l| l.starts_with("normal ="))
            .unwrap();
        let parsed = Case::parse(&unknown, "pair.toml").unwrap();
        let e = Normal::of(&parsed.contact).unwrap_err().to_string();
        let at = format!("pair.toml:{line}: contact.normal: unknown variant `hertz`");
        assert!(e.contains(&at) && e.contains("`linear`"), "{e}");
    }
}
