//! Verdicts by convergence: a prescribed-motion row that misses its tolerance at the motion's
//! step is run again at a half and a quarter of it (the same motion with finer rows,
//! [`super::driver::Refined`]), and passes when its error falls towards zero at an observed
//! order of at least one with an error extrapolated to dt → 0 within the tolerance: a
//! consistent discretisation of a correct law (spins from the rows, trapezoidal increments)
//! converges to the expected value, a defect (a missing twist, a wrong stiffness) keeps its
//! error however fine the step.

use super::Row;
use crate::analysis::verdict::Outcome;
use crate::analysis::Limit;

/// Rows per row of the motion at which a row is judged: dt, dt/2, dt/4.
pub const FINE: [usize; 3] = [1, 2, 4];

/// The least observed order that counts as convergence: first order, less the 0.1 by which
/// three step sizes can misjudge it when the error has a second-order part.
pub const MIN_ORDER: f64 = 0.9;

/// The signed error of a judged row and its tolerance: (measured − expected)/|expected| for a
/// relative limit, measured − expected for an absolute one; none for other limits.
fn error(r: &Row) -> Option<(f64, f64)> {
    match r.limit {
        Limit::Relative {
            expected,
            tolerance,
        } => Some(((r.measured - expected) / expected.abs(), tolerance)),
        Limit::Absolute {
            expected,
            tolerance,
        } => Some((r.measured - expected, tolerance)),
        _ => None,
    }
}

/// What refinement found for one row: its errors at dt, dt/2 and dt/4, the observed order
/// log₂((e₁ − e₂)/(e₂ − e₄)) (none when the differences change sign), the error extrapolated to
/// dt → 0 (Richardson: e₄ − (e₂ − e₄)/(2^p − 1)), where it converges, and how uncertain that
/// extrapolation is.
///
/// A consistent scheme's leading error has an integer order; an observed order that is not one
/// says that higher-order terms still weigh at these steps, and three step sizes cannot take
/// them out: an error a·h + b·h² extrapolates with its observed order to about b·h²/4, not 0.
/// The extrapolation's uncertainty is taken as the difference between the extrapolations with
/// the observed order and with the nearest integer order (at least 1): zero for an error that
/// is exactly a power of the step plus a constant (a defect's bias stays measured), of the size
/// of the higher-order terms otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    pub errors: [f64; 3],
    pub order: Option<f64>,
    pub extrapolated: Option<f64>,
    /// The extrapolation's uncertainty (the error's units), where it extrapolates.
    pub uncertainty: Option<f64>,
}

impl Convergence {
    /// The convergence of the errors `e` at dt, dt/2, dt/4: an order only when |e| falls at
    /// every refinement, an extrapolation only when that order is at least [`MIN_ORDER`].
    pub fn of(e: [f64; 3]) -> Convergence {
        let falls = e[2].abs() < e[1].abs() && e[1].abs() < e[0].abs();
        let ratio = (e[0] - e[1]) / (e[1] - e[2]);
        let order = (falls && ratio > 1.0 && ratio.is_finite()).then(|| ratio.log2());
        let richardson = |p: f64| e[2] - (e[1] - e[2]) / (p.exp2() - 1.0);
        let converging = order.filter(|&p| p >= MIN_ORDER);
        let extrapolated = converging.map(richardson);
        let uncertainty =
            converging.map(|p| (richardson(p) - richardson(p.round().max(1.0))).abs());
        Convergence {
            errors: e,
            order,
            extrapolated,
            uncertainty,
        }
    }

    /// Whether the error vanishes under refinement to within `tolerance`, the extrapolation's
    /// uncertainty added to it.
    pub fn vanishes(&self, tolerance: f64) -> bool {
        match (self.extrapolated, self.uncertainty) {
            (Some(e), Some(u)) => e.abs() <= tolerance + u,
            _ => false,
        }
    }
}

/// The row `at` (judged at the motion's step, failed) judged again by its refinements `half`
/// (dt/2) and `quarter` (dt/4), the same rows of the same case: it passes when its error
/// [`Convergence::vanishes`] within its tolerance. Its measured value stays the one at dt;
/// its words give the three measurements, the observed order and the extrapolated error.
pub fn judged_by_refinement(at: Row, half: &Row, quarter: &Row) -> Row {
    let (Some((e1, tolerance)), Some((e2, _)), Some((e4, _))) =
        (error(&at), error(half), error(quarter))
    else {
        return at;
    };
    let c = Convergence::of([e1, e2, e4]);
    let order = c.order.map_or(
        "none (the error does not fall at each refinement)".into(),
        |p| format!("{p:.2}"),
    );
    let u = c.uncertainty.unwrap_or(0.0);
    let (outcome, verdict) = match (c.order, c.extrapolated) {
        (_, Some(e)) if c.vanishes(tolerance) => (
            Outcome::Pass,
            format!(
                "error extrapolated to dt -> 0: {e:.1e} +- {u:.1e}, within the tolerance: \
                 converges"
            ),
        ),
        (_, Some(e)) => (
            Outcome::Fail,
            format!(
                "error extrapolated to dt -> 0: {e:.1e} +- {u:.1e}, beyond the tolerance: \
                 converges to a wrong value"
            ),
        ),
        (Some(_), None) => (
            Outcome::Fail,
            format!("below {MIN_ORDER}: the error does not vanish at first order"),
        ),
        (None, None) => (
            Outcome::Fail,
            "the error does not vanish under refinement".into(),
        ),
    };
    let text = format!(
        "{:.6e} at dt; {:.6e} at dt/2; {:.6e} at dt/4; observed order {order}; {verdict}",
        at.measured, half.measured, quarter.measured
    );
    Row {
        outcome,
        ..at.described(text, String::new())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_first_order_error_converges_and_a_constant_one_does_not() {
        let first = Convergence::of([4e-6, 2e-6, 1e-6]);
        assert!((first.order.unwrap() - 1.0).abs() < 1e-12);
        assert!(first.extrapolated.unwrap().abs() < 1e-18);
        assert!(first.vanishes(1e-12));
        // a defect of 1e-4 under a first-order part: the order is seen, the limit is not 0
        let biased = Convergence::of([1e-4 + 4e-6, 1e-4 + 2e-6, 1e-4 + 1e-6]);
        assert!((biased.extrapolated.unwrap() - 1e-4).abs() < 1e-12);
        assert!(!biased.vanishes(1e-6));
        // a constant error has no order
        let constant = Convergence::of([1e-4, 1e-4, 1e-4]);
        assert_eq!(constant.order, None);
        assert!(!constant.vanishes(1.0));
        // half order: seen, but too slow to count
        let slow = Convergence::of([1.0, 0.5f64.sqrt(), 0.5]);
        assert!((slow.order.unwrap() - 0.5).abs() < 1e-9);
        assert!(!slow.vanishes(1.0));
    }

    /// A correct law whose first-order error has a second-order part (e = a·h + b·h², as the
    /// step's velocities from positions with the slip at the row's normal give: 8e-3 per
    /// radian at the motion's step) extrapolates with its observed order to about b·h²/4,
    /// beyond a 1e-6 tolerance; the uncertainty of that extrapolation covers it. A defect's
    /// bias of 1e-4 under the same errors still fails.
    #[test]
    fn a_second_order_part_is_within_the_extrapolations_uncertainty_and_a_bias_is_not() {
        let e = |h: f64, bias: f64| bias + 8e-3 * h + 3e-5 * h * h;
        let correct = Convergence::of([e(1.0, 0.0), e(0.5, 0.0), e(0.25, 0.0)]);
        let x = correct.extrapolated.unwrap();
        assert!(x.abs() > 1e-6, "{correct:?}");
        assert!(correct.vanishes(1e-6), "{correct:?}");
        let biased = Convergence::of([e(1.0, 1e-4), e(0.5, 1e-4), e(0.25, 1e-4)]);
        assert!(!biased.vanishes(1e-6), "{biased:?}");
        let pure = Convergence::of([4e-6, 2e-6, 1e-6]);
        assert!(pure.uncertainty.unwrap() < 1e-18, "{pure:?}");
    }

    #[test]
    fn a_row_converging_at_first_order_passes_with_its_order_in_words() {
        let row = |m: f64| super::super::row_abs("c", "q", 0.0, m, 1e-6);
        let r = judged_by_refinement(row(4e-6), &row(2e-6), &row(1e-6));
        assert!(r.passed(), "{r:?}");
        assert_eq!(r.measured, 4e-6);
        assert!(r.measured_text.contains("observed order 1.00"), "{r:?}");
        let r = judged_by_refinement(row(4e-6), &row(4e-6), &row(4e-6));
        assert!(r.failed(), "{r:?}");
    }
}
