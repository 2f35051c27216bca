//! One verdict: a measured quantity, what it was judged against, the outcome, and whether a
//! failure fails the command that judged it. The verification table (`verdem verify`), the
//! profile checks (`verdem cg`), the timing goals (`verdem bench`) and the cross-runs'
//! profile comparison all report through it; each report keeps its own wording.

/// How a verdict came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The measurement meets its limit.
    Pass,
    /// The measurement misses its limit.
    Fail,
    /// The measurement's uncertainty covers the limit (or is not known yet): neither.
    Undecided,
    /// Shown for information, not judged.
    Reported,
}

/// What a measured value is judged against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Limit {
    /// |value − expected| / |expected| ≤ tolerance.
    Relative { expected: f64, tolerance: f64 },
    /// |value − expected| ≤ tolerance.
    Absolute { expected: f64, tolerance: f64 },
    /// value < the limit.
    Below(f64),
    /// value ≥ the limit.
    AtLeast(f64),
    /// Nothing: the value is reported only.
    None,
}

impl Limit {
    /// Whether `value` meets the limit (false for [`Limit::None`] and for NaN).
    pub fn admits(&self, value: f64) -> bool {
        match *self {
            Limit::Relative {
                expected,
                tolerance,
            } => ((value - expected) / expected).abs() <= tolerance,
            Limit::Absolute {
                expected,
                tolerance,
            } => (value - expected).abs() <= tolerance,
            Limit::Below(limit) => value < limit,
            Limit::AtLeast(limit) => value >= limit,
            Limit::None => false,
        }
    }

    /// The expected value of a [`Limit::Relative`] or [`Limit::Absolute`] limit, the bound of
    /// the others (NaN for [`Limit::None`]).
    pub fn expected(&self) -> f64 {
        match *self {
            Limit::Relative { expected, .. } | Limit::Absolute { expected, .. } => expected,
            Limit::Below(limit) | Limit::AtLeast(limit) => limit,
            Limit::None => f64::NAN,
        }
    }
}

/// One judged (or reported) quantity.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// What was run or examined (a verification case); empty when the quantity says it all.
    pub case: String,
    /// What was measured.
    pub quantity: String,
    /// The measured value, in the quantity's units.
    pub measured: f64,
    /// What `measured` is judged against.
    pub limit: Limit,
    pub outcome: Outcome,
    /// Whether a failure fails the command. A verdict that documents a peer convention's known
    /// defect (e.g. no twist of the spring) is shown but does not gate.
    pub gate: bool,
    /// The measurement and the expectation in words, for reports that print more than the
    /// number (e.g. "chi2/dof = 1.20 (mean 0.00310)" and "< 3"); empty when the numbers say it.
    pub measured_text: String,
    pub expected_text: String,
    /// The property of the judged subject the verdict tests, by its key (a contact law's
    /// `coulomb-cap`: `verify::diagnosis` names and explains it, the reports carry it); none
    /// where no property is declared.
    pub property: Option<&'static str>,
}

impl Verdict {
    /// `measured` judged against `limit`: [`Outcome::Pass`] or [`Outcome::Fail`], gating.
    pub fn judge(case: &str, quantity: &str, measured: f64, limit: Limit) -> Verdict {
        Verdict {
            case: case.into(),
            quantity: quantity.into(),
            measured,
            limit,
            outcome: if limit.admits(measured) {
                Outcome::Pass
            } else {
                Outcome::Fail
            },
            gate: true,
            measured_text: String::new(),
            expected_text: String::new(),
            property: None,
        }
    }

    /// `measured` shown beside `limit` but not judged ([`Outcome::Reported`], not gating).
    pub fn reported(case: &str, quantity: &str, measured: f64, limit: Limit) -> Verdict {
        Verdict {
            outcome: Outcome::Reported,
            gate: false,
            ..Verdict::judge(case, quantity, measured, limit)
        }
    }

    /// The same verdict, judged only when `judged`, else reported.
    pub fn judged_if(self, judged: bool) -> Verdict {
        if judged {
            self
        } else {
            Verdict {
                outcome: Outcome::Reported,
                gate: false,
                ..self
            }
        }
    }

    /// The same verdict, shown as evidence about a peer convention rather than gating.
    pub fn documenting(mut self) -> Verdict {
        self.gate = false;
        self
    }

    /// The same verdict, gating only when `gate` (a verdem claim), else documenting.
    pub fn gating_if(self, gate: bool) -> Verdict {
        if gate {
            self
        } else {
            self.documenting()
        }
    }

    /// The same verdict with the measurement and the expectation in words.
    pub fn described(mut self, measured: String, expected: String) -> Verdict {
        self.measured_text = measured;
        self.expected_text = expected;
        self
    }

    /// The same verdict, testing the property keyed `key`.
    pub fn testing(mut self, key: &'static str) -> Verdict {
        self.property = Some(key);
        self
    }

    /// Whether it passed.
    pub fn passed(&self) -> bool {
        self.outcome == Outcome::Pass
    }

    /// Whether it failed (gating or not).
    pub fn failed(&self) -> bool {
        self.outcome == Outcome::Fail
    }

    /// `Some(passed)` when it was judged, `None` when undecided or reported.
    pub fn pass(&self) -> Option<bool> {
        match self.outcome {
            Outcome::Pass => Some(true),
            Outcome::Fail => Some(false),
            Outcome::Undecided | Outcome::Reported => None,
        }
    }
}

/// The verdicts that gate and failed.
pub fn failures(verdicts: &[Verdict]) -> usize {
    verdicts.iter().filter(|v| v.gate && v.failed()).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_admit_what_they_say() {
        let rel = Limit::Relative {
            expected: -2.0,
            tolerance: 0.25,
        };
        assert!(rel.admits(-2.5) && rel.admits(-1.5) && !rel.admits(-2.51));
        let abs = Limit::Absolute {
            expected: 0.0,
            tolerance: 3.0,
        };
        assert!(abs.admits(-3.0) && abs.admits(3.0) && !abs.admits(3.01));
        assert!(Limit::Below(3.0).admits(2.99) && !Limit::Below(3.0).admits(3.0));
        assert!(Limit::AtLeast(1.7).admits(1.7) && !Limit::AtLeast(1.7).admits(1.69));
        for limit in [
            rel,
            abs,
            Limit::Below(3.0),
            Limit::AtLeast(1.7),
            Limit::None,
        ] {
            assert!(!limit.admits(f64::NAN), "{limit:?}");
        }
        assert!(!Limit::None.admits(0.0));
    }

    #[test]
    fn only_gating_failures_count() {
        let fail = Verdict::judge("c", "q", 5.0, Limit::Below(3.0));
        let pass = Verdict::judge("c", "q", 1.0, Limit::Below(3.0));
        assert_eq!(fail.pass(), Some(false));
        assert_eq!(pass.pass(), Some(true));
        let unjudged = fail.clone().judged_if(false);
        assert_eq!((unjudged.pass(), unjudged.gate), (None, false));
        let shown = Verdict::reported("c", "q", 5.0, Limit::Below(3.0));
        assert_eq!(shown.outcome, Outcome::Reported);
        assert_eq!(
            failures(&[
                fail.clone(),
                pass,
                unjudged,
                shown,
                fail.clone().documenting(),
                fail.clone().gating_if(true)
            ]),
            2
        );
    }
}
