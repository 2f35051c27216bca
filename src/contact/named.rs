//! The tangential convention and the normal law a case names, resolved against their
//! registries: the case file holds names ([`case::Convention`]), the contact layer knows which
//! names are entries.

use std::path::Path;
use std::sync::LazyLock;

use serde::de::Error as _;

use super::normal_laws::Reads;
use super::{Normal, Parameters, Tangential};
use crate::case::{self, Case, CaseError};

/// The registries' names, in their order, as serde's messages list a field's choices.
static NAMES: LazyLock<Vec<&'static str>> =
    LazyLock::new(|| Tangential::ALL.iter().map(|t| t.name()).collect());
static NORMAL_NAMES: LazyLock<Vec<&'static str>> =
    LazyLock::new(|| Normal::ALL.iter().map(|n| n.name()).collect());

/// The error `file:line: field: unknown variant …` for a name no entry of `names` bears.
fn unknown(named: &case::Convention, field: &str, names: &'static [&'static str]) -> CaseError {
    CaseError {
        file: named.file.clone(),
        line: named.line,
        field: field.into(),
        msg: serde::de::value::Error::unknown_variant(named.name(), names).to_string(),
    }
}

impl Tangential {
    /// The convention `contact.tangential` names, or the error `file:line:
    /// contact.tangential: unknown variant …` at the line that names it; for a convention with
    /// Mindlin's stiffness ([`crate::contact::Properties::mindlin_stiffness`]) in a case that
    /// gives no elastic constants (G* = 0), the error `… needs the material's youngs and
    /// poisson` at the same line; for a convention with the case's constant kt, friction
    /// (mu > 0) with kt = 0 is the error `… contact.kt: must be > 0 with friction …`.
    pub fn of(case: &Case) -> Result<Tangential, CaseError> {
        let named = &case.contact.tangential;
        let t = Tangential::named(named.name())
            .ok_or_else(|| unknown(named, "contact.tangential", &NAMES))?;
        if t.properties().mindlin_stiffness && Parameters::of(case).g_star <= 0.0 {
            return Err(CaseError {
                file: named.file.clone(),
                line: named.line,
                field: "contact.tangential".into(),
                msg: format!(
                    "`{}` has Mindlin's stiffness 8G*a: it needs the material's youngs and \
                     poisson (the case gives no elastic constants, so G* = 0)",
                    t.name()
                ),
            });
        }
        let c = &case.contact;
        if !t.properties().mindlin_stiffness && c.mu > 0.0 && c.kt <= 0.0 {
            return Err(CaseError {
                file: case.path.display().to_string(),
                line: named.line,
                field: "contact.kt".into(),
                msg: format!(
                    "must be > 0 with friction (mu = {}): `{}` has the case's constant kt",
                    c.mu,
                    t.name()
                ),
            });
        }
        Ok(t)
    }
}

impl Normal {
    /// The normal law `contact.normal` names, or the error `file:line: contact.normal: unknown
    /// variant …` at the line that names it.
    pub fn of(contact: &case::Contact) -> Result<Normal, CaseError> {
        let named = &contact.normal;
        Normal::named(named.name()).ok_or_else(|| unknown(named, "contact.normal", &NORMAL_NAMES))
    }
}

impl Normal {
    /// The normal law `case` names, refusing a case that does not give the numbers the law
    /// reads ([`Normal::reads`]), or gives numbers of a normal law that it leaves unread: the
    /// error at the `contact.normal` line (the `[contact]` header's for a missing key).
    pub fn checked(case: &Case) -> Result<Normal, CaseError> {
        let normal = Normal::of(&case.contact)?;
        let c = &case.contact;
        let named = &c.normal;
        let (file, line) = if named.line > 0 {
            (named.file.clone(), named.line)
        } else {
            (c.given.file.clone(), c.given.line)
        };
        let refuse = |msg: String| CaseError {
            file: file.clone(),
            line,
            field: "contact.normal".into(),
            msg: format!("the normal law `{}` {msg}", normal.name()),
        };
        let missing = |key: &str, what: &str| CaseError {
            file: c.given.file.clone(),
            line: c.given.line,
            field: format!("contact.{key}"),
            msg: format!(
                "missing field `{key}` ({what}, which the normal law `{}` reads)",
                normal.name()
            ),
        };
        let reads = normal.reads();
        let elastic = case.material.elastic().is_some();
        if reads.contains(&Reads::Elastic) {
            if !elastic {
                return Err(refuse(
                    "builds its spring from the materials' elastic constants: material.youngs \
                     and material.poisson expected"
                        .into(),
                ));
            }
            if c.given.has("kn") {
                return Err(refuse(
                    "builds its spring from material.youngs and material.poisson and does not \
                     read contact.kn: remove it"
                        .into(),
                ));
            }
        }
        if reads.contains(&Reads::Kn) && !c.given.has("kn") {
            return Err(missing("kn", "a linear spring's stiffness"));
        }
        let optional = [
            (
                Reads::Gamman,
                "gamman",
                c.given.has("gamman"),
                "its absolute dashpot, 0 for none",
            ),
            (
                Reads::Restitution,
                "restitution",
                c.restitution.is_some(),
                "the restitution coefficient its damping aims at",
            ),
            (
                Reads::DissipativeConstant,
                "dissipative_constant",
                c.dissipative_constant.is_some(),
                "its dissipative constant A",
            ),
        ];
        for (read, key, given, what) in optional {
            match (reads.contains(&read), given) {
                (true, false) => return Err(missing(key, what)),
                (false, true) => {
                    return Err(refuse(format!("does not read contact.{key}: remove it")))
                }
                _ => {}
            }
        }
        Ok(normal)
    }
}

/// Refuses a case whose normal law or tangential convention no registry holds, or that does not
/// give the numbers its normal law reads ([`Normal::checked`]).
fn resolves(case: Case) -> Result<Case, CaseError> {
    Normal::checked(&case)?;
    Tangential::of(&case)?;
    Ok(case)
}

/// Reads a case file ([`Case::load`]) and refuses a normal law or tangential convention the
/// registries do not know, as for a command that uses the case before (or without) building
/// its law.
pub fn load(path: &Path) -> Result<Case, CaseError> {
    resolves(Case::load(path)?)
}

/// [`Case::load_for_prescribed_motion`], refusing an unknown name as [`load`].
pub fn load_for_prescribed_motion(path: &Path) -> Result<Case, CaseError> {
    resolves(Case::load_for_prescribed_motion(path)?)
}

/// The name of `t`, for a case whose convention is set in code (read from no file).
impl From<Tangential> for case::Convention {
    fn from(t: Tangential) -> case::Convention {
        case::Convention {
            name: t.name().into(),
            file: String::new(),
            line: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every registered name resolves to its convention, through a case as through code; an
    /// unknown one is the error at the line that names it, listing the names.
    #[test]
    fn a_case_names_a_convention_or_gets_the_list() {
        let text = include_str!("../../cases/shear_flow_quick.toml");
        for t in Tangential::with_constant_kt() {
            let named = text.replace(
                "tangential = \"mercury\"",
                &format!("tangential = \"{}\"", t.name()),
            );
            let case = case::Case::parse(&named, "q.toml").unwrap();
            assert_eq!(Tangential::of(&case).unwrap(), t);
            let mut set = case.clone();
            set.contact.tangential = t.into();
            assert_eq!(Tangential::of(&set).unwrap(), t);
        }
        let bad = text.replace("tangential = \"mercury\"", "tangential = \"nope\"");
        let case = case::Case::parse(&bad, "q.toml").unwrap();
        let line = bad
            .lines()
            .position(|l| l.starts_with("tangential"))
            .unwrap()
            + 1;
        let e = Tangential::of(&case).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!(
                "q.toml:{line}: contact.tangential: unknown variant `nope`, expected one of \
                 `mercury`, `lammps-hooke-history`,"
            )),
            "{e}"
        );
        assert!(e.ends_with("`mindlin-deresiewicz`"), "{e}");
    }

    /// A Mindlin convention in a case without elastic constants is refused at the line that
    /// names it, saying what it needs.
    #[test]
    fn a_mindlin_convention_needs_the_material_s_elastic_constants() {
        let text = include_str!("../../cases/shear_flow_quick.toml");
        let line = text
            .lines()
            .position(|l| l.starts_with("tangential"))
            .unwrap()
            + 1;
        for t in Tangential::with_mindlin_stiffness() {
            let named = text.replace(
                "tangential = \"mercury\"",
                &format!("tangential = \"{}\"", t.name()),
            );
            let case = case::Case::parse(&named, "q.toml").unwrap();
            let e = Tangential::of(&case).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!(
                    "q.toml:{line}: contact.tangential: `{}`",
                    t.name()
                )) && e.contains("needs the material's youngs and poisson"),
                "{e}"
            );
        }
        assert!(Tangential::with_mindlin_stiffness().count() >= 8);
    }
}
