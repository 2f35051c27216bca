//! A diagnosis, not only a FAIL: every prescribed-motion row declares, where it is defined,
//! the property of a contact law it tests ([`Property`], attached with [`Tests::tests`]), and
//! the table's summary maps the failed rows to those properties, each with the defect that
//! typically fails it and a pointer to its section of `docs/code-interface.md`.
//!
//! Some properties are measured through others: a spring that does not turn with the contact
//! frame does not twist either, a closed cycle leaves a spring behind when the spring does not
//! follow the frame, and the way back from the Coulomb limit is measured in units of kt. A
//! property whose failure may follow from another failed one says so ([`Finding::after`]), so
//! that the properties with no such excuse are the diagnosis.

use super::{is_error, Row};
use crate::analysis::report;

/// A property of a contact law that a prescribed-motion row tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Property {
    /// The stored spring turns with the contact frame when the normal tilts.
    Objectivity,
    /// The stored spring turns with the pair's twist about the normal.
    SpringTwist,
    /// The spring force for a given slip: kt times the slip arm's travel.
    Stiffness,
    /// The tangential force is capped at μ|Fn| and the spring is reset to the cap while
    /// sliding.
    CoulombCap,
    /// No force apart, and an unstretched spring when the contact closes again.
    ResetAtLoss,
    /// The normal force kn·δ − γn·vn.
    NormalForce,
    /// Each torque opposes the tangential force about its sphere's centre, with the arm to the
    /// contact point.
    Torques,
    /// The torques and the force conserve the pair's angular momentum.
    AngularMomentum,
    /// The forces file's columns agree with its force vectors and the motion's positions.
    ForcesFile,
    /// A closed cycle without sliding leaves no spring and does no net work.
    ClosedCycleEnergy,
    /// The dashpots: −γn·vn along n and −γt times the slip rate in the tangent plane, at the
    /// velocities of the motion, beside the springs.
    Dashpots,
}

impl Property {
    /// Every property, in the order of the summary: each after those it is measured through.
    pub const ALL: [Property; 11] = [
        Property::Objectivity,
        Property::SpringTwist,
        Property::Stiffness,
        Property::CoulombCap,
        Property::ResetAtLoss,
        Property::NormalForce,
        Property::Torques,
        Property::AngularMomentum,
        Property::ForcesFile,
        Property::ClosedCycleEnergy,
        Property::Dashpots,
    ];

    /// Its key: the reports' word for it and the anchor of its section in
    /// `docs/code-interface.md`.
    pub const fn key(self) -> &'static str {
        match self {
            Property::Objectivity => "objectivity",
            Property::SpringTwist => "spring-twist",
            Property::Stiffness => "tangential-stiffness",
            Property::CoulombCap => "coulomb-cap",
            Property::ResetAtLoss => "reset-at-contact-loss",
            Property::ClosedCycleEnergy => "energy-over-a-closed-cycle",
            Property::NormalForce => "normal-force",
            Property::Torques => "torques",
            Property::AngularMomentum => "angular-momentum",
            Property::ForcesFile => "forces-file",
            Property::Dashpots => "dashpots",
        }
    }

    /// Its name in the summary.
    pub const fn title(self) -> &'static str {
        match self {
            Property::Objectivity => "objectivity (the spring turns with the contact frame)",
            Property::SpringTwist => "twist of the spring about the normal",
            Property::Stiffness => "tangential stiffness",
            Property::CoulombCap => "Coulomb cap",
            Property::ResetAtLoss => "reset at contact loss",
            Property::ClosedCycleEnergy => "energy over a closed cycle",
            Property::NormalForce => "normal force",
            Property::Torques => "torques",
            Property::AngularMomentum => "angular momentum",
            Property::ForcesFile => "the forces file's columns",
            Property::Dashpots => "the dashpots",
        }
    }

    /// What a law that fails it typically does wrong, in one line.
    pub const fn defect(self) -> &'static str {
        match self {
            Property::Objectivity => {
                "the stored spring is not rotated with the contact frame (kept in the lab \
                 frame, or projected onto the new tangent plane without keeping its length)"
            }
            Property::SpringTwist => {
                "the spring is not turned with the pair's twist about the normal"
            }
            Property::Stiffness => {
                "the spring's stiffness is not the case's kt, or its slip arm is not between \
                 R - delta/2 and R"
            }
            Property::CoulombCap => {
                "the spring is not capped at mu|Fn|, or not reset to the cap while sliding, \
                 or the dashpot is stored in the spring"
            }
            Property::ResetAtLoss => {
                "the spring is not reset when the contact is lost, or a force acts while the \
                 spheres are apart"
            }
            Property::ClosedCycleEnergy => {
                "the law creates energy over a closed cycle: a rigid rotation or a change of \
                 overlap feeds its slip (arms that depend on the overlap, centres' velocity \
                 not scaled), or its spring does not return"
            }
            Property::NormalForce => {
                "the normal force is not kn*delta - gamman*vn, with delta = R1 + R2 - |x2 - x1|"
            }
            Property::Torques => {
                "a torque does not oppose the tangential force about its sphere's centre with \
                 the arm to the contact point (a wrong sign, or an arm outside R - delta .. R)"
            }
            Property::AngularMomentum => {
                "the torques are not taken about one contact point (full radii as torque arms), \
                 so T1 + T2 + r x F2 is not 0"
            }
            Property::ForcesFile => {
                "the columns delta, fn, ft or F1 = -F2 do not agree with the force vectors and \
                 the positions"
            }
            Property::Dashpots => {
                "a dashpot is not gamman*vn along n or gammat times the slip rate at the \
                 contact point (missing, scaled by a mass, or stored in the spring)"
            }
        }
    }

    /// The properties whose failure can make a row of this one fail too: a spring that does
    /// not turn with the frame does not twist; a closed cycle leaves a spring or work behind
    /// when the spring does not follow the frame, its stiffness or its torques are wrong; the
    /// way back from the Coulomb limit is measured in units of kt; the angular momentum holds
    /// only with the right torques.
    pub const fn measured_through(self) -> &'static [Property] {
        match self {
            Property::SpringTwist => &[Property::Objectivity],
            Property::ClosedCycleEnergy => &[
                Property::Objectivity,
                Property::SpringTwist,
                Property::Stiffness,
                Property::Torques,
            ],
            Property::CoulombCap => &[Property::Stiffness],
            Property::AngularMomentum => &[Property::Torques],
            _ => &[],
        }
    }

    /// Whether a row of it failed at the motion's step is judged again by refinement: not for
    /// the properties a law has no time discretisation to choose for (no force apart and a
    /// fresh spring after, the normal force at rest, the forces file's columns), whose rows
    /// a finer motion would only change (a refined jump apart grazes the contact, where the
    /// cap wipes a spring kept by mistake).
    pub const fn refines(self) -> bool {
        !matches!(
            self,
            Property::ResetAtLoss | Property::NormalForce | Property::ForcesFile
        )
    }

    /// The property keyed `key` ([`Property::key`]).
    pub fn of_key(key: &str) -> Option<Property> {
        Property::ALL.into_iter().find(|p| p.key() == key)
    }

    /// The pointer to its section: `docs/code-interface.md#KEY`.
    pub fn docs(self) -> String {
        format!("docs/code-interface.md#{}", self.key())
    }
}

/// A row declaring the property it tests.
pub trait Tests {
    /// The same row, testing `property`.
    fn tests(self, property: Property) -> Row;
}

impl Tests for Row {
    fn tests(self, property: Property) -> Row {
        self.testing(property.key())
    }
}

/// The property `row` tests, where it declares one.
pub fn property(row: &Row) -> Option<Property> {
    row.property.and_then(Property::of_key)
}

/// A property with failed rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    pub property: Property,
    /// Its gating rows that failed.
    pub failed: usize,
    /// The other failed properties it is measured through ([`Property::measured_through`]):
    /// its failure may follow from theirs. Empty: it failed on its own.
    pub after: Vec<Property>,
}

/// The failed rows of a table by the property they test.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Diagnosis {
    /// One per property with a failed row, in the order of [`Property::ALL`].
    pub findings: Vec<Finding>,
    /// Failed rows that declare no property (outside the prescribed-motion cases);
    /// [`is_error`] rows, which say their own cause, are not counted.
    pub undeclared: usize,
}

/// The gating, failed rows of `rows` by the property they test.
pub fn diagnose(rows: &[Row]) -> Diagnosis {
    let failed: Vec<&Row> = rows
        .iter()
        .filter(|r| r.gate && r.failed() && !is_error(r))
        .collect();
    let count = |p: Property| failed.iter().filter(|r| property(r) == Some(p)).count();
    let failing: Vec<Property> = Property::ALL
        .into_iter()
        .filter(|&p| count(p) > 0)
        .collect();
    let findings = failing
        .iter()
        .map(|&p| Finding {
            property: p,
            failed: count(p),
            after: p
                .measured_through()
                .iter()
                .copied()
                .filter(|q| failing.contains(q))
                .collect(),
        })
        .collect();
    Diagnosis {
        findings,
        undeclared: failed.iter().filter(|r| property(r).is_none()).count(),
    }
}

impl Diagnosis {
    /// The properties that failed on their own (no other failed property excuses them).
    pub fn causes(&self) -> Vec<Property> {
        self.findings
            .iter()
            .filter(|f| f.after.is_empty())
            .map(|f| f.property)
            .collect()
    }

    /// The summary printed after the table: a heading, then one line per property with failed
    /// rows (its name, how many, what it may follow from, the typical defect, the pointer to
    /// its section) and one for the failed rows of no property. Empty when nothing failed.
    pub fn summary(&self) -> String {
        if self.findings.is_empty() && self.undeclared == 0 {
            return String::new();
        }
        let mut s = String::from(
            "diagnosis, the failed rows by the property they test (docs/code-interface.md):\n",
        );
        for f in &self.findings {
            let after = if f.after.is_empty() {
                String::new()
            } else {
                let names: Vec<&str> = f.after.iter().map(|p| p.title()).collect();
                format!(", perhaps only through {}", names.join(" and "))
            };
            s.push_str(&format!(
                "  {}, {}{after}: {}; {}\n",
                f.property.title(),
                rows_word(f.failed),
                f.property.defect(),
                f.property.docs()
            ));
        }
        if self.undeclared > 0 {
            s.push_str(&format!(
                "  rows that declare no property, {}: their cases in docs/verification.md\n",
                rows_word(self.undeclared)
            ));
        }
        s
    }

    /// The findings as the JSON report's `diagnosis`.
    pub fn report(&self) -> Vec<report::Diagnosis> {
        self.findings
            .iter()
            .map(|f| report::Diagnosis {
                property: f.property.key().into(),
                title: f.property.title().into(),
                failed: f.failed,
                after: f.after.iter().map(|p| p.key().into()).collect(),
                defect: f.property.defect().into(),
                docs: f.property.docs(),
            })
            .collect()
    }
}

/// `1 row failed`, `N rows failed`.
fn rows_word(n: usize) -> String {
    format!("{n} row{} failed", if n == 1 { "" } else { "s" })
}

#[cfg(test)]
mod tests {
    use super::super::{error_row, row_abs};
    use super::*;

    fn failing(p: Property) -> Row {
        row_abs("c", "q", 0.0, 1.0, 1e-6).tests(p)
    }

    #[test]
    fn keys_name_their_property_once() {
        for p in Property::ALL {
            assert_eq!(Property::of_key(p.key()), Some(p));
            assert!(p.docs().ends_with(p.key()));
            // a property is measured through earlier ones only: no cycle
            assert!(p.measured_through().iter().all(|&q| q < p), "{p:?}");
        }
        assert_eq!(Property::of_key("nothing"), None);
    }

    #[test]
    fn a_property_measured_through_a_failed_one_is_not_a_cause() {
        let rows = [
            failing(Property::Stiffness),
            failing(Property::CoulombCap),
            failing(Property::CoulombCap),
            row_abs("c", "q", 0.0, 0.0, 1e-6).tests(Property::ResetAtLoss),
            failing(Property::ResetAtLoss).documenting(),
            error_row("c", &anyhow::anyhow!("broken")),
            row_abs("c", "q", 0.0, 1.0, 1e-6),
        ];
        let d = diagnose(&rows);
        assert_eq!(d.causes(), [Property::Stiffness]);
        assert_eq!(
            d.findings[1],
            Finding {
                property: Property::CoulombCap,
                failed: 2,
                after: vec![Property::Stiffness]
            }
        );
        assert_eq!(d.findings.len(), 2);
        assert_eq!(d.undeclared, 1);
        let s = d.summary();
        assert_eq!(s.lines().count(), 4, "{s}");
        assert!(s.contains("  Coulomb cap, 2 rows failed, perhaps only through tangential stiffness: the spring is not capped at mu|Fn|"), "{s}");
        assert!(s.contains("docs/code-interface.md#coulomb-cap\n"), "{s}");
        // the cap alone is a cause
        let alone = diagnose(&rows[1..3]);
        assert_eq!(alone.causes(), [Property::CoulombCap]);
        assert_eq!(alone.report()[0].after, Vec::<String>::new());
    }

    #[test]
    fn nothing_failed_says_nothing() {
        let rows = [row_abs("c", "q", 0.0, 0.0, 1e-6).tests(Property::Objectivity)];
        assert_eq!(diagnose(&rows), Diagnosis::default());
        assert_eq!(diagnose(&rows).summary(), "");
    }
}
