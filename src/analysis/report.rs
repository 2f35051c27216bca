//! Verdicts as reports a CI system reads: JUnit XML ([`Report::junit`]) and a JSON table
//! ([`Report::json`]), one test case (one JSON row) per verdict.
//!
//! A verdict maps to a test case's status so that a JUnit reader fails the build exactly when
//! the command exits with its checks failed: a passed verdict passes, a gating failure (an ERROR
//! row included) fails, and everything that does not gate is skipped with the reason — a FAIL*
//! row (a peer convention's known defect), an undecided verdict, a value reported only. Where a
//! command's judgements are a report only (`cg`, `run`, `compare`, `cross`, `bench`'s goals),
//! its exit status stays 0 while a case that misses its limit is a failure in the report.
//!
//! Numbers are finite only: a non-finite value is `null` in the JSON and the word `undefined`
//! in the messages, so that neither file holds the token NaN or inf (which
//! [`crate::io::atomic::write`] refuses).

use std::path::Path;

use serde::Serialize;

use crate::analysis::verdict::{Limit, Outcome, Verdict};
use crate::io::{fmt_f64, xml_escaped};

/// A test case's status.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    Passed,
    Failed,
    Skipped,
}

/// One test case: a verdict in the words of the report that judged it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Case {
    /// The group it belongs to (JUnit's `classname`): the verdict's case, or the suite's name
    /// when the verdict has none.
    pub group: String,
    /// The test case's name: the quantity measured.
    pub name: String,
    pub status: Status,
    /// The word the command's text table prints for it (`PASS`, `FAIL`, `FAIL*`, `ERROR`, …).
    pub result: String,
    /// The expected value or bound; `None` when there is none or it is not finite.
    pub expected: Option<f64>,
    /// The measured value; `None` when it is not finite (the message says why).
    pub measured: Option<f64>,
    /// The tolerance of a relative or absolute limit; `None` for the others.
    pub tolerance: Option<f64>,
    /// How `measured` is judged: `relative`, `absolute`, `below`, `at least` or `none`.
    pub limit: &'static str,
    /// Expected, measured and tolerance in words, and for a skipped case why it is skipped.
    pub message: String,
    /// Why `measured` is `None`, where the report says (the field is absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub undefined: Option<String>,
    /// The row's other numbers (a comparison's difference of the core means, a save's spreads,
    /// …), in the order its text table gives them; the field is absent when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub details: Vec<Detail>,
    /// The key of the property the verdict tests, where it declares one (the field is absent
    /// otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub property: Option<String>,
}

/// One more number of a row: its name, its value (`None` when it is not a finite number) and,
/// for `None`, why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Detail {
    pub name: String,
    pub value: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub undefined: Option<String>,
}

impl Detail {
    /// `value` named `name`; when it is not finite, `None` and the reason `undefined`.
    pub fn new(name: &str, value: f64, undefined: &str) -> Detail {
        Detail {
            name: name.into(),
            value: finite(value),
            undefined: (!value.is_finite()).then(|| undefined.into()),
        }
    }
}

/// One property with failed cases: what a failure of it typically means.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Its key, as the cases' `property`.
    pub property: String,
    /// Its name in words.
    pub title: String,
    /// How many of its cases failed.
    pub failed: usize,
    /// The keys of other failed properties its failure may follow from (empty: on its own).
    pub after: Vec<String>,
    /// What a subject that fails it typically does wrong.
    pub defect: String,
    /// Where it is defined.
    pub docs: String,
}

/// A suite of test cases: one command's verdicts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The suite's name (`verdem verify`, …).
    pub suite: String,
    /// How many cases there are, passed, failed and skipped.
    pub tests: usize,
    pub passed: usize,
    pub failures: usize,
    pub skipped: usize,
    pub cases: Vec<Case>,
    /// The failed cases by the property they test (the field is absent when there are none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub diagnosis: Vec<Diagnosis>,
}

/// `v` in words: shortest round-trip decimal, `undefined` when not finite.
fn number(v: f64) -> String {
    if v.is_finite() {
        let mut s = String::new();
        fmt_f64(&mut s, v);
        s
    } else {
        "undefined".into()
    }
}

/// `text` escaped for an XML attribute: [`xml_escaped`], with line ends and tabs as character
/// references (a reader would otherwise turn them into spaces) and the other control
/// characters, which XML 1.0 forbids, as U+FFFD.
fn attribute(text: &str) -> String {
    xml_escaped(text)
        .chars()
        .map(|c| match c {
            '\n' => "&#10;".to_string(),
            '\r' => "&#13;".to_string(),
            '\t' => "&#9;".to_string(),
            c if c.is_control() => '\u{FFFD}'.to_string(),
            c => c.to_string(),
        })
        .collect()
}

/// `Some(v)` when finite.
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

impl Case {
    /// The test case of `v`, whose text table reads `result` for it; `suite` names the group
    /// when `v` has no case. Its message: `expected E, measured M, tolerance T (relative)` (the
    /// verdict's words instead of the numbers where it has them), then, when skipped, the
    /// reason.
    pub fn of(suite: &str, v: &Verdict, result: &str) -> Case {
        Case::skipped_because(suite, v, result, None)
    }

    /// As [`Case::of`], but a case that is skipped says `reason` for it (when given) instead of
    /// the reason its outcome gives.
    pub fn skipped_because(suite: &str, v: &Verdict, result: &str, reason: Option<&str>) -> Case {
        let (limit, tolerance) = match v.limit {
            Limit::Relative { tolerance, .. } => ("relative", Some(tolerance)),
            Limit::Absolute { tolerance, .. } => ("absolute", Some(tolerance)),
            Limit::Below(_) => ("below", None),
            Limit::AtLeast(_) => ("at least", None),
            Limit::None => ("none", None),
        };
        let expected = match v.limit {
            Limit::None => None,
            l => finite(l.expected()),
        };
        let words = |text: &str, value: Option<f64>| match (text.is_empty(), value) {
            (false, _) => text.to_string(),
            (true, Some(x)) => number(x),
            (true, None) => "undefined".into(),
        };
        let measured = words(&v.measured_text, finite(v.measured));
        let mut message = match v.limit {
            Limit::None if v.failed() => format!("could not be measured: {measured}"),
            Limit::None => format!("measured {measured}"),
            Limit::Relative { .. } | Limit::Absolute { .. } => format!(
                "expected {}, measured {measured}, tolerance {} ({limit})",
                words(&v.expected_text, expected),
                number(tolerance.unwrap_or(f64::NAN)),
            ),
            Limit::Below(_) | Limit::AtLeast(_) => format!(
                "expected {limit} {}, measured {measured}",
                words(&v.expected_text, expected)
            ),
        };
        if !v.measured.is_finite() && v.limit != Limit::None {
            message.push_str(" (the measured value is not a finite number)");
        }
        let (status, why) = match (v.outcome, v.gate) {
            (Outcome::Pass, _) => (Status::Passed, ""),
            (Outcome::Fail, true) => (Status::Failed, ""),
            (Outcome::Fail, false) => (
                Status::Skipped,
                "a known defect of a peer convention, shown but not gating",
            ),
            (Outcome::Undecided, _) => (
                Status::Skipped,
                "undecided, the uncertainty covers the limit",
            ),
            (Outcome::Reported, _) => (Status::Skipped, "reported for information, not judged"),
        };
        if status == Status::Skipped {
            message.push_str(&format!("; skipped: {}", reason.unwrap_or(why)));
        }
        Case {
            group: if v.case.is_empty() {
                suite.into()
            } else {
                v.case.clone()
            },
            name: v.quantity.clone(),
            status,
            result: result.into(),
            expected,
            measured: finite(v.measured),
            tolerance,
            limit,
            message,
            undefined: None,
            details: Vec::new(),
            property: v.property.map(String::from),
        }
    }

    /// The same case, saying why its measured value is undefined when it is.
    pub fn undefined_because(mut self, reason: &str) -> Case {
        if self.measured.is_none() {
            self.undefined = Some(reason.into());
        }
        self
    }

    /// The same case with the row's other numbers `details`.
    pub fn with_details(mut self, details: Vec<Detail>) -> Case {
        self.details = details;
        self
    }
}

impl Report {
    /// The suite `suite` of `verdicts`, each with the word `result` gives it in the command's
    /// text table, in their order.
    pub fn new(suite: &str, verdicts: &[Verdict], result: impl Fn(&Verdict) -> String) -> Report {
        let cases = verdicts
            .iter()
            .map(|v| Case::of(suite, v, &result(v)))
            .collect();
        Report::of_cases(suite, cases)
    }

    /// The suite `suite` of `cases`, in their order.
    pub fn of_cases(suite: &str, cases: Vec<Case>) -> Report {
        let count = |s| cases.iter().filter(|c| c.status == s).count();
        Report {
            suite: suite.into(),
            tests: cases.len(),
            passed: count(Status::Passed),
            failures: count(Status::Failed),
            skipped: count(Status::Skipped),
            cases,
            diagnosis: Vec::new(),
        }
    }

    /// The same report with the diagnosis of its failed cases.
    pub fn diagnosed(mut self, diagnosis: Vec<Diagnosis>) -> Report {
        self.diagnosis = diagnosis;
        self
    }

    /// JUnit XML: `<testsuites>` holding one `<testsuite>` with its counts, one `<testcase
    /// classname=GROUP name=NAME time="0">` per case, holding `<failure message=…>` or
    /// `<skipped message=…/>` when it did not pass (a failure's message also its text); every
    /// text escaped, line ends kept.
    pub fn junit(&self) -> String {
        let e = attribute;
        let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        s.push_str(&format!(
            "<testsuites name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\">\n",
            e(&self.suite),
            self.tests,
            self.failures,
            self.skipped
        ));
        s.push_str(&format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\" \
             time=\"0\">\n",
            e(&self.suite),
            self.tests,
            self.failures,
            self.skipped
        ));
        for c in &self.cases {
            let open = format!(
                "    <testcase classname=\"{}\" name=\"{}\" time=\"0\"",
                e(&c.group),
                e(&c.name)
            );
            match c.status {
                Status::Passed => s.push_str(&format!("{open}/>\n")),
                Status::Failed => s.push_str(&format!(
                    "{open}>\n      <failure message=\"{m}\" type=\"{}\">{m}</failure>\n    \
                     </testcase>\n",
                    e(&c.result),
                    m = e(&c.message)
                )),
                Status::Skipped => s.push_str(&format!(
                    "{open}>\n      <skipped message=\"{}\"/>\n    </testcase>\n",
                    e(&c.message)
                )),
            }
        }
        s.push_str("  </testsuite>\n</testsuites>\n");
        s
    }

    /// The report as a JSON object: `suite`, the counts `tests`, `passed`, `failures`,
    /// `skipped`, `cases`, an array of objects with the fields of [`Case`] (numbers that are
    /// not finite are `null`; `undefined`, `details` and `property` only where a report gives
    /// them), and `diagnosis`, the fields of [`Diagnosis`], where cases of a property failed.
    pub fn json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("a report serialises");
        s.push('\n');
        s
    }

    /// Writes [`Report::junit`] to `junit` and [`Report::json`] to `json`, those given,
    /// atomically.
    pub fn write(&self, junit: Option<&Path>, json: Option<&Path>) -> std::io::Result<()> {
        if let Some(path) = junit {
            crate::io::atomic::write(path, self.junit().as_bytes())?;
        }
        if let Some(path) = json {
            crate::io::atomic::write(path, self.json().as_bytes())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report() -> Report {
        let verdicts = [
            Verdict::judge(
                "a<b",
                "q&\"1\"",
                1.0,
                Limit::Relative {
                    expected: 1.0,
                    tolerance: 0.1,
                },
            ),
            Verdict::judge("c", "q2", 5.0, Limit::Below(3.0)),
            Verdict::judge("c", "q3", f64::NAN, Limit::AtLeast(1.0)).documenting(),
            Verdict::reported("", "q4", f64::INFINITY, Limit::None),
        ];
        Report::new("suite", &verdicts, |v| format!("{:?}", v.outcome))
    }

    #[test]
    fn statuses_follow_outcome_and_gate() {
        let r = report();
        let statuses: Vec<_> = r.cases.iter().map(|c| c.status).collect();
        assert_eq!(
            statuses,
            [
                Status::Passed,
                Status::Failed,
                Status::Skipped,
                Status::Skipped
            ]
        );
        assert_eq!((r.tests, r.passed, r.failures, r.skipped), (4, 1, 1, 2));
        assert_eq!(r.cases[1].message, "expected below 3, measured 5");
        assert_eq!(r.cases[3].group, "suite");
        assert!(r.cases[2].message.contains("not a finite number"));
        assert!(r.cases[2].message.contains("known defect"));
    }

    #[test]
    fn files_hold_no_non_finite_token_and_escape_their_text() {
        let r = report();
        for text in [r.junit(), r.json()] {
            assert_eq!(
                crate::io::atomic::non_finite(text.as_bytes()),
                None,
                "{text}"
            );
        }
        let xml = r.junit();
        assert!(
            xml.contains("classname=\"a&lt;b\" name=\"q&amp;&quot;1&quot;\""),
            "{xml}"
        );
        assert_eq!(attribute("a\nb\u{1}"), "a&#10;b\u{FFFD}");
        let json: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
        assert!(json["cases"][3]["measured"].is_null());
        assert_eq!(json["cases"][0]["tolerance"], 0.1);
    }
}
