//! Profiles of an ensemble of independent replicas of one run: the ensemble mean of every
//! column and its standard error from the replicas' spread, and the coverage test of the
//! replicas' own (block) error bars against that mean.

use anyhow::ensure;

use super::cg::table::Table;
use super::cg::{core_window, COLUMNS, FIELDS};
use super::stats::standard_error;

/// The ensemble's profiles: per grid point and column of [`COLUMNS`], the mean of the replicas'
/// values and its standard error, the unbiased standard deviation over the replicas divided by
/// √R (the replicas are independent, so this error needs no assumption about correlation times).
/// The tables must share one grid; at least two are needed for an error.
pub fn merge(replicas: &[Table]) -> anyhow::Result<Table> {
    ensure!(
        replicas.len() >= 2,
        "an ensemble needs two replicas or more for its error bars, it has {}",
        replicas.len()
    );
    let first = &replicas[0];
    for (r, t) in replicas.iter().enumerate() {
        ensure!(
            t.z.len() == first.z.len()
                && t.z.iter().zip(&first.z).all(|(a, b)| (a - b).abs() < 1e-9),
            "replica {r}'s profiles are on another grid ({} points) than replica 0's ({} points)",
            t.z.len(),
            first.z.len()
        );
    }
    let n = first.z.len();
    let mut mean = vec![vec![0.0; COLUMNS.len()]; n];
    let mut se = vec![vec![0.0; COLUMNS.len()]; n];
    for k in 0..n {
        for c in 0..COLUMNS.len() {
            let values: Vec<f64> = replicas.iter().map(|t| t.mean[k][c]).collect();
            mean[k][c] = values.iter().sum::<f64>() / values.len() as f64;
            se[k][c] = standard_error(&values);
        }
    }
    let merged = Table {
        z: first.z.clone(),
        mean,
        se,
    };
    merged.ensure_finite(
        &format!("the merge of {} replicas", replicas.len()),
        "the replicas' values are too large for their mean and spread",
    )?;
    Ok(merged)
}

/// The coverage test of one benchmark profile over the core slices.
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    /// The profile's label in [`FIELDS`].
    pub field: &'static str,
    /// Of all (replica, core slice) pairs, how many have the replica's value within ±2 of its
    /// own block standard error of the ensemble mean, and how many there are.
    pub inside: usize,
    pub pairs: usize,
    /// The fraction of each replica's core slices that are inside.
    pub per_replica: Vec<f64>,
    /// The fraction expected when the block errors are honest: [`expected_coverage`].
    pub expected: f64,
    /// √(mean over core slices of the replicas' variance) / √(mean of the replicas' own block
    /// variances): ≈ 1 when the block errors are honest, > 1 when they are too small.
    pub spread_ratio: f64,
    /// The ensemble's core mean (the replicas' core means averaged) and its standard error from
    /// the spread of the replicas' core means.
    pub core_mean: f64,
    pub core_se: f64,
}

impl Coverage {
    /// The fraction of the (replica, core slice) pairs inside.
    pub fn fraction(&self) -> f64 {
        self.inside as f64 / self.pairs.max(1) as f64
    }
}

/// The coverage test of each benchmark profile ([`FIELDS`]): how often a replica's value at a
/// core slice lies within ±2 of its own block standard error of the ensemble mean `ensemble`
/// ([`merge`] of `replicas`). `blocks` is the number of blocks the replicas' errors come from.
pub fn coverage(
    replicas: &[Table],
    ensemble: &Table,
    blocks: usize,
) -> anyhow::Result<Vec<Coverage>> {
    let (lo, hi) = core_window(&ensemble.grid()?);
    let core: Vec<usize> = (0..ensemble.z.len())
        .filter(|&k| (lo..=hi).contains(&ensemble.z[k]))
        .collect();
    ensure!(
        !core.is_empty(),
        "the profiles have no slice in the core [{lo}, {hi}]"
    );
    let r = replicas.len();
    Ok(FIELDS
        .iter()
        .map(|&(field, col)| {
            let mut inside = 0;
            let mut per_replica = Vec::with_capacity(r);
            let (mut own_var, mut spread_var) = (0.0, 0.0);
            for t in replicas {
                let here = core
                    .iter()
                    .filter(|&&k| {
                        (t.mean[k][col] - ensemble.mean[k][col]).abs() <= 2.0 * t.se[k][col]
                    })
                    .count();
                inside += here;
                per_replica.push(here as f64 / core.len() as f64);
                own_var += core.iter().map(|&k| t.se[k][col].powi(2)).sum::<f64>();
            }
            for &k in &core {
                // the ensemble error is sd/√R: the replicas' variance is R·se²
                spread_var += r as f64 * ensemble.se[k][col].powi(2);
            }
            own_var /= (r * core.len()) as f64;
            spread_var /= core.len() as f64;
            let core_means: Vec<f64> = replicas
                .iter()
                .map(|t| core.iter().map(|&k| t.mean[k][col]).sum::<f64>() / core.len() as f64)
                .collect();
            Coverage {
                field,
                inside,
                pairs: r * core.len(),
                per_replica,
                expected: expected_coverage(r, blocks),
                spread_ratio: if own_var > 0.0 {
                    (spread_var / own_var).sqrt()
                } else {
                    f64::INFINITY
                },
                core_mean: core_means.iter().sum::<f64>() / r as f64,
                core_se: standard_error(&core_means),
            }
        })
        .collect())
}

/// The replicas' own errors of one profile's core mean against the replicas' spread.
#[derive(Clone, Debug, PartialEq)]
pub struct CoreCoverage {
    /// The profile's label in [`FIELDS`].
    pub field: &'static str,
    /// How many replicas have their core mean within ±2 of its own standard error of the
    /// replicas' mean, of how many.
    pub inside: usize,
    pub replicas: usize,
    /// The replicas' standard deviation of their core means over the root mean square of their
    /// own errors: ≈ 1 when those errors are honest.
    pub spread_ratio: f64,
}

/// The coverage of one profile's core means, each replica's `(core mean, its own standard
/// error)` in `means` (at least two replicas).
pub fn core_coverage(field: &'static str, means: &[(f64, f64)]) -> CoreCoverage {
    let r = means.len();
    let mean = means.iter().map(|m| m.0).sum::<f64>() / r as f64;
    let spread = means.iter().map(|m| (m.0 - mean).powi(2)).sum::<f64>() / (r as f64 - 1.0);
    let own = means.iter().map(|m| m.1 * m.1).sum::<f64>() / r as f64;
    CoreCoverage {
        field,
        inside: means
            .iter()
            .filter(|m| (m.0 - mean).abs() <= 2.0 * m.1)
            .count(),
        replicas: r,
        spread_ratio: if own > 0.0 {
            (spread / own).sqrt()
        } else {
            f64::INFINITY
        },
    }
}

/// The fraction of replicas within ±2 of their own block error of the ensemble mean when
/// those errors are honest (the values Gaussian, the blocks independent): a replica's deviation
/// from a mean that includes it has variance σ²(1 − 1/R), and its block error estimates σ from
/// `blocks` − 1 degrees of freedom, so the ratio is √(1 − 1/R) times Student's t with
/// `blocks` − 1 degrees of freedom, and the fraction is P(|t| ≤ 2/√(1 − 1/R)). Below 95 % for
/// few blocks (92.3 % for 10 blocks and many replicas), above for few replicas.
pub fn expected_coverage(replicas: usize, blocks: usize) -> f64 {
    expected_coverage_dof(replicas, blocks.max(2) as f64 - 1.0)
}

/// [`expected_coverage`] for errors whose variance is estimated with `dof` degrees of freedom
/// (at least 1).
pub fn expected_coverage_dof(replicas: usize, dof: f64) -> f64 {
    let r = replicas.max(2) as f64;
    student_t_within(2.0 / (1.0 - 1.0 / r).sqrt(), dof.max(1.0))
}

/// The 95 % Wilson score interval of a binomial fraction `inside`/`trials` (Wilson, J. Am.
/// Stat. Assoc. 22:209, 1927): the fractions p whose |p̂ − p| ≤ 1.96 √(p(1 − p)/n). Taken over
/// (replica, slice) pairs it is too narrow when neighbouring slices of one replica deviate
/// together.
pub fn wilson_interval(inside: usize, trials: usize) -> (f64, f64) {
    if trials == 0 {
        return (0.0, 1.0);
    }
    let (n, z) = (trials as f64, 1.959964);
    let p = inside as f64 / n;
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// P(|T| ≤ x) for Student's t with `dof` degrees of freedom: twice the integral from 0 to x of
/// its density Γ((ν+1)/2) / (√(νπ) Γ(ν/2)) · (1 + t²/ν)^(−(ν+1)/2) (Student 1908), by Simpson's
/// rule on 2000 intervals (error below 1e-9 for x ≤ 10).
pub fn student_t_within(x: f64, dof: f64) -> f64 {
    let norm = (libm::lgamma((dof + 1.0) / 2.0) - libm::lgamma(dof / 2.0)).exp()
        / (dof * std::f64::consts::PI).sqrt();
    let density = |t: f64| norm * (1.0 + t * t / dof).powf(-(dof + 1.0) / 2.0);
    let n = 2000;
    let h = x / n as f64;
    let sum: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * density(i as f64 * h)
        })
        .sum();
    2.0 * sum * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn core_coverage_counts_replicas_within_their_own_two_errors_and_the_spread_over_them() {
        // core means 0, 0, 3 → mean 1; deviations −1, −1, +2; own errors 0.6, 0.4, 0.9: the
        // first inside (1 ≤ 1.2), the second not (1 > 0.8), the third not (2 > 1.8)
        let c = core_coverage("nu", &[(0.0, 0.6), (0.0, 0.4), (3.0, 0.9)]);
        assert_eq!((c.inside, c.replicas), (1, 3));
        // spread: variance (1 + 1 + 4)/2 = 3; own: (0.36 + 0.16 + 0.81)/3
        let expected = (3.0f64 / ((0.36 + 0.16 + 0.81) / 3.0)).sqrt();
        assert!(
            (c.spread_ratio - expected).abs() < 1e-12,
            "{}",
            c.spread_ratio
        );
    }

    /// A table on the benchmark's grid (100 slices of [0, 22]) whose every column is `value`
    /// at every point, with error `se`.
    fn flat(value: f64, se: f64) -> Table {
        let z: Vec<f64> = (0..100).map(|k| 0.11 + 0.22 * k as f64).collect();
        Table {
            mean: z.iter().map(|_| vec![value; COLUMNS.len()]).collect(),
            se: z.iter().map(|_| vec![se; COLUMNS.len()]).collect(),
            z,
        }
    }

    #[test]
    fn the_merge_is_the_mean_and_the_spread_over_root_r() {
        // values 1, 2, 6: mean 3, sample variance ((−2)² + 1 + 3²)/2 = 7, se = √(7/3)
        let t = [flat(1.0, 0.1), flat(2.0, 0.1), flat(6.0, 0.1)];
        let m = merge(&t).unwrap();
        assert_eq!(m.z, t[0].z);
        for k in [0, 50, 99] {
            assert!((m.mean[k][3] - 3.0).abs() < 1e-15);
            assert!((m.se[k][3] - (7.0f64 / 3.0).sqrt()).abs() < 1e-15);
        }
        assert!(merge(&t[..1])
            .unwrap_err()
            .to_string()
            .contains("two replicas"));
        let mut other = flat(1.0, 0.1);
        other.z.pop();
        assert!(merge(&[t[0].clone(), other]).is_err());
    }

    #[test]
    fn student_t_matches_its_tables() {
        // two-sided 95 % points: t(9) = 2.262157, t(2) = 4.302653, normal 1.959964
        assert!((student_t_within(2.262157, 9.0) - 0.95).abs() < 1e-6);
        assert!((student_t_within(4.302653, 2.0) - 0.95).abs() < 1e-6);
        assert!((student_t_within(1.959964, 1e7) - 0.95).abs() < 1e-6);
        // many replicas, ten blocks: P(|t(9)| ≤ 2) in closed form for odd ν (Abramowitz and
        // Stegun 26.7.3): 2/π (θ + sin θ (cos θ + 2/3 cos³θ + 8/15 cos⁵θ + 48/105 cos⁷θ)),
        // θ = atan(2/3)
        let th = (2.0f64 / 3.0).atan();
        let c = th.cos();
        let closed = 2.0 / std::f64::consts::PI
            * (th
                + th.sin()
                    * (c + 2.0 / 3.0 * c.powi(3)
                        + 8.0 / 15.0 * c.powi(5)
                        + 48.0 / 105.0 * c.powi(7)));
        assert!((expected_coverage(1_000_000_000, 10) - closed).abs() < 1e-8);
    }

    #[test]
    fn the_wilson_interval_matches_its_tables() {
        // 50 of 100: 0.4038–0.5962; 0 of 10: 0–0.2775 (the rule of three's Wilson form)
        let (lo, hi) = wilson_interval(50, 100);
        assert!(
            (lo - 0.4038).abs() < 1e-4 && (hi - 0.5962).abs() < 1e-4,
            "{lo} {hi}"
        );
        let (lo, hi) = wilson_interval(0, 10);
        assert!(lo == 0.0 && (hi - 0.2775).abs() < 1e-4, "{hi}");
        assert_eq!(wilson_interval(0, 0), (0.0, 1.0));
    }

    #[test]
    fn coverage_counts_replicas_inside_their_own_error() {
        // core means 0, 0, 3 → ensemble 1; deviations −1, −1, +2; errors 0.6, 0.4, 0.9:
        // inside ±2 se for the first (1 ≤ 1.2), outside for the second (1 > 0.8) and third (2 > 1.8)
        let t = [flat(0.0, 0.6), flat(0.0, 0.4), flat(3.0, 0.9)];
        let m = merge(&t).unwrap();
        let c = coverage(&t, &m, 10).unwrap();
        assert_eq!(c.len(), FIELDS.len());
        for f in &c {
            assert_eq!(f.per_replica, vec![1.0, 0.0, 0.0]);
            assert_eq!(f.pairs % 3, 0);
            assert_eq!(f.inside * 3, f.pairs);
            assert!((f.core_mean - 1.0).abs() < 1e-12);
            assert!((f.core_se - m.se[50][0]).abs() < 1e-12);
            // replica variance 3 (sample), own variance (0.36 + 0.16 + 0.81)/3
            let ratio = (3.0f64 / ((0.36 + 0.16 + 0.81) / 3.0)).sqrt();
            assert!((f.spread_ratio - ratio).abs() < 1e-12, "{}", f.spread_ratio);
        }
    }

    #[test]
    fn honest_gaussian_errors_cover_as_expected_and_small_ones_do_not() {
        use rand::{Rng, SeedableRng};
        // replicas whose values are Gaussian with σ = 1 and whose error is the block error of
        // 10 Gaussian blocks: the coverage must come out at expected_coverage, within the
        // binomial noise of the many (replica, slice) pairs; errors a third of that must not
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut gauss = || {
            // Box–Muller
            let (u, v): (f64, f64) = (rng.gen_range(1e-12..1.0), rng.gen());
            (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
        };
        let r = 40;
        let mut tables: Vec<Table> = Vec::new();
        for _ in 0..r {
            let mut t = flat(0.0, 0.0);
            for k in 0..t.z.len() {
                for c in 0..COLUMNS.len() {
                    let blocks: Vec<f64> = (0..10).map(|_| gauss() * 10f64.sqrt()).collect();
                    t.mean[k][c] = blocks.iter().sum::<f64>() / 10.0;
                    t.se[k][c] = standard_error(&blocks);
                }
            }
            tables.push(t);
        }
        let m = merge(&tables).unwrap();
        for c in coverage(&tables, &m, 10).unwrap() {
            let sigma = (c.expected * (1.0 - c.expected) / c.pairs as f64).sqrt();
            assert!(
                (c.fraction() - c.expected).abs() < 4.0 * sigma,
                "{}: {} vs {}",
                c.field,
                c.fraction(),
                c.expected
            );
            assert!((c.spread_ratio - 1.0).abs() < 0.1, "{}", c.spread_ratio);
        }
        for t in tables.iter_mut() {
            t.se.iter_mut().flatten().for_each(|s| *s /= 3.0);
        }
        for c in coverage(&tables, &m, 10).unwrap() {
            assert!(c.fraction() < 0.6, "{}: {}", c.field, c.fraction());
            assert!(c.spread_ratio > 2.5, "{}", c.spread_ratio);
        }
    }
}
