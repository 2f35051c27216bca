//! `[contact]`: the contact law's parameters, and the names of its normal law and tangential
//! convention.

use serde::Deserialize;

use super::locate::Locator;
use super::CaseError;

/// `[contact]`: the contact law.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// Normal spring stiffness (force/length) of a linear spring; not given for a law built
    /// from elastic constants (read as 0; [`Contact::given`] says whether it was).
    #[serde(default)]
    pub kn: f64,
    /// Absolute normal damping (mass/time); read as 0 when not given, which the laws that read
    /// it refuse ([`Contact::given`]).
    #[serde(default)]
    pub gamman: f64,
    /// Tangential spring stiffness (force/length).
    #[serde(default)]
    pub kt: f64,
    /// Absolute tangential damping (mass/time).
    #[serde(default)]
    pub gammat: f64,
    /// Coulomb friction coefficient; 0 switches friction (and rotation) off.
    #[serde(default)]
    pub mu: f64,
    /// Tangential convention (default `mercury`), as named; the contact layer resolves it
    /// (`contact::named`).
    #[serde(default = "default_tangential")]
    pub tangential: Convention,
    /// Normal law (default `linear`: the spring–dashpot with absolute damping), as named; the
    /// contact layer resolves it (`contact::named`).
    #[serde(default = "default_normal")]
    pub normal: Convention,
    /// Clip the attractive tail of the normal force, fn = max(fn, 0) (default false).
    #[serde(default)]
    pub clip_normal: bool,
    /// Normal restitution coefficient (in (0, 1]) of the dampings set from one.
    #[serde(default)]
    pub restitution: Option<f64>,
    /// Brilliantov et al.'s dissipative constant A (time, >= 0) of the viscoelastic damping.
    #[serde(default)]
    pub dissipative_constant: Option<f64>,
    /// The keys the case's `[contact]` table sets, as read.
    #[serde(skip)]
    pub given: Given,
}

/// The keys a table of the case sets, as read, and where the table begins (file, 1-based line
/// of its header; 0 unknown), for the checks of which numbers a law reads; not part of the
/// case's value: two cases are equal whichever keys spell them.
#[derive(Clone, Debug, Default)]
pub struct Given {
    pub keys: Vec<String>,
    pub file: String,
    pub line: usize,
}

impl Given {
    /// Whether the key `key` is set.
    pub fn has(&self, key: &str) -> bool {
        self.keys.iter().any(|k| k == key)
    }
}

impl PartialEq for Given {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

fn default_tangential() -> Convention {
    Convention {
        name: "mercury".into(),
        file: String::new(),
        line: 0,
    }
}

fn default_normal() -> Convention {
    Convention {
        name: "linear".into(),
        file: String::new(),
        line: 0,
    }
}

/// The name of a registry entry (a tangential convention, a normal law) as a case gives it,
/// with where it was read (the file and the 1-based line of its key, 0 when not read from a
/// file), so that the contact layer, which knows the registries, can refuse an unknown name at
/// its line. Two are equal when they name the same entry.
#[derive(Clone, Debug, Eq)]
pub struct Convention {
    /// The name (`mercury`, `objective`, …), not checked against the registry here.
    pub name: String,
    /// The file the name was read from, as errors name it.
    pub file: String,
    /// Its line (1-based; 0 unknown).
    pub line: usize,
}

impl Convention {
    /// The name as written in the case.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl PartialEq for Convention {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

/// Read as an enum's unit variant, as the registry's enum was: the parser's own messages for
/// a value that is not a name (`wanted string or table`) stay the same; whether the name is a
/// convention is the contact layer's check.
impl<'de> Deserialize<'de> for Convention {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Name;
        impl<'de> serde::de::Visitor<'de> for Name {
            type Value = String;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the name of a registry entry")
            }
            fn visit_enum<A: serde::de::EnumAccess<'de>>(self, a: A) -> Result<String, A::Error> {
                use serde::de::VariantAccess;
                let (name, variant) = a.variant::<String>()?;
                variant.unit_variant()?;
                Ok(name)
            }
        }
        let name = d.deserialize_enum("Tangential", &[], Name)?;
        Ok(Convention {
            name,
            file: String::new(),
            line: 0,
        })
    }
}

impl Contact {
    /// kn > 0 when given; gamman, kt, gammat, mu >= 0; restitution in
    /// (0, 1] and dissipative_constant >= 0 when given.
    pub(super) fn check(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        if self.given.has("kn") {
            at.positive("contact.kn", self.kn)?;
        }
        if let Some(e) = self.restitution {
            if !(e > 0.0 && e <= 1.0) {
                return Err(at.error(
                    "contact.restitution",
                    format!("a restitution coefficient in (0, 1] expected, got {e}"),
                ));
            }
        }
        if let Some(a) = self.dissipative_constant {
            at.non_negative("contact.dissipative_constant", a)?;
        }
        at.non_negative("contact.gamman", self.gamman)?;
        at.non_negative("contact.kt", self.kt)?;
        at.non_negative("contact.gammat", self.gammat)?;
        // kt > 0 with friction for the conventions whose spring is kt: contact::named
        at.non_negative("contact.mu", self.mu)?;
        Ok(())
    }
}
