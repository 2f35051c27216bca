//! Two in-run results compared by their core means: each mean with its standard error from
//! the series of its core mean ([`CoreMean`]), and the difference A − B with its 95 % interval
//! (Student's t, Welch's degrees of freedom; [`Difference`]). Used by the cross-code comparison
//! (`verdem cross … --inrun`) and the speed/accuracy trade (`verdem tradeoff`).

use crate::analysis::cg::{self, COLUMNS, FIELDS};
use crate::analysis::ensemble::student_t_within;
use crate::analysis::inrun::InrunResult;
use crate::analysis::stats::{block_standard_error, blocks_for, integrated_autocorrelation};

pub use crate::analysis::cg::blocking::CoreMean;

impl CoreMean {
    /// Of column `name` of [`COLUMNS`] in `r`: the mean over the core slices and its standard
    /// error from the series of the core mean ([`cg::blocking::core_mean`]).
    pub fn of(r: &InrunResult, name: &str) -> CoreMean {
        let c = COLUMNS.iter().position(|x| *x == name).expect("column");
        cg::blocking::core_mean(&r.units, &r.profiles.grid, &r.errors, c)
    }
}

/// The mean x-force per wall area (force / (Lx·Ly)) the bottom (`g` = 0) or top (1) wall
/// receives over the bins of `r`, with its standard error from blocks as long as the series'
/// own correlation asks ([`blocks_for`]).
pub fn wall_shear(r: &InrunResult, g: usize) -> CoreMean {
    let l = r.profiles.domain.lengths();
    let x: Vec<f64> = r
        .profiles
        .wall_force
        .iter()
        .map(|w| w[g].x / (l.x * l.y))
        .collect();
    let (blocks, long_enough) = blocks_for(x.len(), integrated_autocorrelation(&x));
    CoreMean {
        mean: x.iter().sum::<f64>() / x.len().max(1) as f64,
        se: block_standard_error(&x, blocks),
        dof: blocks as f64 - 1.0,
        long_enough,
    }
}

/// One profile of two codes A and B: their core means, the χ²/dof of their profiles over the
/// core slices, and the difference A − B with its 95 % interval.
#[derive(Clone, Debug, PartialEq)]
pub struct Difference {
    /// The profile's name in [`FIELDS`].
    pub field: &'static str,
    pub a: CoreMean,
    pub b: CoreMean,
    pub chi2: f64,
}

impl Difference {
    /// A − B.
    pub fn delta(&self) -> f64 {
        self.a.mean - self.b.mean
    }

    /// The standard error of A − B, the two runs independent: √(se_A² + se_B²).
    pub fn se(&self) -> f64 {
        self.a.se.hypot(self.b.se)
    }

    /// The degrees of freedom of [`Difference::se`] (Welch 1947, Satterthwaite 1946):
    /// (s_A² + s_B²)² / (s_A⁴/ν_A + s_B⁴/ν_B), ν the degrees of freedom of each error (at
    /// least 1).
    pub fn dof(&self) -> f64 {
        let (va, vb) = (self.a.se.powi(2), self.b.se.powi(2));
        let (na, nb) = (self.a.dof.max(1.0), self.b.dof.max(1.0));
        let den = va * va / na + vb * vb / nb;
        if den > 0.0 {
            (va + vb).powi(2) / den
        } else {
            f64::INFINITY
        }
    }

    /// Half the width of the 95 % interval of A − B: Student's t quantile of
    /// [`Difference::dof`] degrees of freedom times [`Difference::se`].
    pub fn half_width(&self) -> f64 {
        t975(self.dof()) * self.se()
    }

    /// Whether the difference is real: its 95 % interval excludes 0.
    pub fn real(&self) -> bool {
        self.delta().abs() > self.half_width()
    }

    /// Whether both errors can be trusted ([`CoreMean::long_enough`]).
    pub fn errors_trusted(&self) -> bool {
        self.a.long_enough && self.b.long_enough
    }
}

/// The 0.975 quantile of Student's t with `dof` degrees of freedom (bisection of
/// [`student_t_within`]; the normal quantile 1.959964 beyond 1e6 degrees of freedom).
pub fn t975(dof: f64) -> f64 {
    if dof.is_nan() || dof >= 1e6 {
        return 1.959_964;
    }
    let (mut lo, mut hi) = (1.9, 20.0);
    if student_t_within(hi, dof.max(1.0)) < 0.95 {
        return f64::INFINITY;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if student_t_within(mid, dof.max(1.0)) < 0.95 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The differences of `a` from `b` in each profile of [`FIELDS`] (vx, ν, T, pressure, shear
/// stress), then in the x-force per area on the bottom and top walls ([`wall_shear`], no χ²:
/// NaN); the two must share the grid.
pub fn differences(a: &InrunResult, b: &InrunResult) -> Vec<Difference> {
    let core = |r: &InrunResult| cg::blocking::core_means(&r.units, &r.profiles.grid, &r.errors);
    let (core_a, core_b) = (core(a), core(b));
    let profiles = FIELDS.iter().map(|&(field, col)| Difference {
        field,
        a: core_a[col],
        b: core_b[col],
        chi2: cg::chi2(&a.profiles, &b.profiles, col),
    });
    let walls = [(0, "bottom wall Fx/A"), (1, "top wall Fx/A")].map(|(g, field)| Difference {
        field,
        a: wall_shear(a, g),
        b: wall_shear(b, g),
        chi2: f64::NAN,
    });
    profiles.chain(walls).collect()
}

#[cfg(test)]
impl Difference {
    /// The difference of two core means of the pressure, each `(mean, se, blocks)` from
    /// blocks as long as its correlation asks (χ²/dof 1): for the tests of what reads it.
    pub(crate) fn of_pressure_means(a: (f64, f64, usize), b: (f64, f64, usize)) -> Difference {
        let m = |(mean, se, blocks): (f64, f64, usize)| CoreMean {
            mean,
            se,
            dof: blocks as f64 - 1.0,
            long_enough: true,
        };
        Difference {
            field: "pressure",
            a: m(a),
            b: m(b),
            chi2: 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_are_those_of_the_tables() {
        // Student's t, two-sided 95 %: 12.706 (1), 2.776 (4), 2.262 (9), 1.960 (∞)
        for (dof, t) in [(1.0, 12.706), (4.0, 2.776), (9.0, 2.262), (1e9, 1.960)] {
            assert!((t975(dof) - t).abs() < 1e-3, "dof {dof}: {}", t975(dof));
        }
    }

    #[test]
    fn the_interval_combines_both_errors_with_welchs_degrees_of_freedom() {
        // errors 0.03 and 0.04 from 10 blocks each: combined 0.05 with Welch's
        // 0.05⁴ / ((0.03⁴ + 0.04⁴) / 9) = 16.7 degrees of freedom, t = 2.113 (tables: 2.120 for
        // 16, 2.110 for 17): half-width 0.1057
        let d = Difference::of_pressure_means((1.0, 0.03, 10), (0.88, 0.04, 10));
        assert!((d.delta() - 0.12).abs() < 1e-12);
        assert!((d.se() - 0.05).abs() < 1e-15);
        let dof = 0.05f64.powi(4) / ((0.03f64.powi(4) + 0.04f64.powi(4)) / 9.0);
        assert!(
            (d.dof() - dof).abs() < 1e-9 && (dof - 16.69).abs() < 0.01,
            "{dof}"
        );
        assert!((d.half_width() - 0.1057).abs() < 5e-4, "{}", d.half_width());
        assert!(d.real());
        // a difference of 0.1 lies within it: not real
        let d = Difference::of_pressure_means((1.0, 0.03, 10), (0.9, 0.04, 10));
        assert!(!d.real(), "0.1 against {}", d.half_width());
    }
}
