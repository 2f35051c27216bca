//! Standard errors of profiles from blocks as long as each field's own correlation: every
//! column of [`super::COLUMNS`] gets its integrated autocorrelation time, measured on the series
//! it is averaged from (saves, or bins of in-run samples), and its error from blocks of at
//! least [`block_length_for`] units of that series.

use super::fields::{derive, Grid, Raw};
use super::{columns, core_range, COLUMNS};
use crate::analysis::stats::{block, block_length_for, integrated_autocorrelation, median};

/// One unit of the series a profile is averaged from: a save, or a bin of in-run samples. It
/// holds the sums of its samples' raw fields and how many samples of the particles (volume
/// fraction, density, momentum, flux) and of the contacts (contact stress) it holds.
#[derive(Clone, Debug)]
pub struct Unit {
    pub sum: Raw,
    pub particle_samples: u64,
    pub contact_samples: u64,
}

impl Unit {
    /// No samples on `n` grid points.
    pub fn empty(n: usize) -> Unit {
        Unit {
            sum: Raw::zeros(n),
            particle_samples: 0,
            contact_samples: 0,
        }
    }

    /// The unit of one save: one sample of everything.
    pub fn of_save(raw: Raw) -> Unit {
        Unit {
            sum: raw,
            particle_samples: 1,
            contact_samples: 1,
        }
    }

    /// Adds the samples of `other`.
    pub fn merge(&mut self, other: &Unit) {
        self.sum.add_scaled(&other.sum, 1.0);
        self.particle_samples += other.particle_samples;
        self.contact_samples += other.contact_samples;
    }

    /// The mean raw fields of its samples: particle fields over the particle samples, contact
    /// stress over the contact samples (zero where there are none).
    pub fn mean(&self) -> Raw {
        let per = |n: u64| if n > 0 { 1.0 / n as f64 } else { 0.0 };
        let (p, c) = (per(self.particle_samples), per(self.contact_samples));
        let s = &self.sum;
        Raw {
            nu: s.nu.iter().map(|v| v * p).collect(),
            rho: s.rho.iter().map(|v| v * p).collect(),
            momentum: s.momentum.iter().map(|v| v * p).collect(),
            flux: s.flux.iter().map(|v| v * p).collect(),
            contact: s.contact.iter().map(|v| v * c).collect(),
        }
    }
}

/// All samples of `units` merged.
pub fn merged(units: &[Unit]) -> Unit {
    let mut all = Unit::empty(units.first().map_or(0, |u| u.sum.nu.len()));
    for u in units {
        all.merge(u);
    }
    all
}

/// The columns of [`COLUMNS`] derived from the mean of each of `blocks` consecutive blocks of
/// `units`, per block, per grid point.
pub fn block_columns(units: &[Unit], blocks: usize) -> Vec<Vec<Vec<f64>>> {
    (0..blocks)
        .map(|b| {
            derive(&merged(&units[block(b, blocks, units.len())]).mean())
                .iter()
                .map(columns)
                .collect()
        })
        .collect()
}

/// Per column of [`COLUMNS`]: the integrated autocorrelation time (in units) of its series,
/// the blocks its standard error comes from and whether they are [`block_length_for`] long.
#[derive(Clone, Debug)]
pub struct FieldErrors {
    pub tau: Vec<f64>,
    pub blocks: Vec<usize>,
    pub long_enough: Vec<bool>,
    /// Standard error of each column, per grid point.
    pub se: Vec<Vec<f64>>,
}

/// The integrated autocorrelation time of each column: the larger of that of its core mean
/// (the average over the core slices, [`core_range`], or over all slices when the box has no
/// core) and the median over those slices of each slice's own; NaN for fewer than four units.
pub fn field_taus(units: &[Unit], grid: &Grid) -> Vec<f64> {
    let per_unit: Vec<Vec<Vec<f64>>> = units
        .iter()
        .map(|u| derive(&u.mean()).iter().map(columns).collect())
        .collect();
    let core = match core_range(grid) {
        r if r.is_empty() => 0..grid.n,
        r => r,
    };
    (0..COLUMNS.len())
        .map(|c| {
            let core_mean: Vec<f64> = per_unit
                .iter()
                .map(|u| core.clone().map(|k| u[k][c]).sum::<f64>() / core.len() as f64)
                .collect();
            let slices: Vec<f64> = core
                .clone()
                .map(|k| {
                    let s: Vec<f64> = per_unit.iter().map(|u| u[k][c]).collect();
                    integrated_autocorrelation(&s)
                })
                .collect();
            let tau = integrated_autocorrelation(&core_mean);
            if tau.is_nan() {
                tau
            } else {
                tau.max(median(&slices))
            }
        })
        .collect()
}

/// Standard errors of every column from blocks of at least [`block_length_for`] its own τ
/// ([`field_taus`]); where the units are too few for [`crate::analysis::stats::MIN_BLOCKS`]
/// such blocks, from that many shorter ones, flagged.
pub fn field_errors(units: &[Unit], grid: &Grid) -> FieldErrors {
    let tau = field_taus(units, grid);
    let chosen: Vec<(usize, bool)> = tau
        .iter()
        .map(|&t| crate::analysis::stats::blocks_for(units.len(), t))
        .collect();
    let mut cache: Vec<(usize, Vec<Vec<Vec<f64>>>)> = Vec::new();
    let mut se = vec![vec![0.0; COLUMNS.len()]; grid.n];
    for (c, &(blocks, _)) in chosen.iter().enumerate() {
        if !cache.iter().any(|(b, _)| *b == blocks) {
            cache.push((blocks, block_columns(units, blocks)));
        }
        let (_, cols) = cache.iter().find(|(b, _)| *b == blocks).expect("cached");
        for (k, row) in se.iter_mut().enumerate() {
            let vals: Vec<f64> = cols.iter().map(|b| b[k][c]).collect();
            row[c] = crate::analysis::stats::standard_error(&vals);
        }
    }
    FieldErrors {
        tau,
        blocks: chosen.iter().map(|c| c.0).collect(),
        long_enough: chosen.iter().map(|c| c.1).collect(),
        se,
    }
}

/// The blocks' length needed by the slowest column, as a block count of `units`: the fewest
/// blocks of [`FieldErrors::blocks`] (used for the checks' core means and steadiness trend).
pub fn common_blocks(errors: &FieldErrors) -> usize {
    errors.blocks.iter().copied().min().unwrap_or(1)
}

/// `x` with two decimals, or "undefined" when it is not finite (no NaN in a report).
pub fn shown(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        "undefined".into()
    }
}

/// A line per column of [`COLUMNS`]: its τ in `unit`s, its blocks (of `units` in all) and the
/// block length it needs.
pub fn describe(errors: &FieldErrors, units: usize, unit: &str) -> String {
    let mut s = String::new();
    for (c, name) in COLUMNS.iter().enumerate() {
        let len = block_length_for(errors.tau[c]);
        s.push_str(&format!(
            "  {name:9} tau {:>8} {unit}, {:>5} blocks of {:>7.1} (needs >= {}){}\n",
            shown(errors.tau[c]),
            errors.blocks[c],
            units as f64 / errors.blocks[c] as f64,
            if len.is_finite() {
                format!("{len}")
            } else {
                "?".into()
            },
            if errors.long_enough[c] {
                ""
            } else {
                ": TOO SHORT, error too small"
            }
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` values of an AR(1) series x_(k+1) = a x_k + u_k, u uniform on [−½, ½], from a seeded
    /// linear congruential generator.
    fn ar1(a: f64, n: usize, seed: u64) -> Vec<f64> {
        let (mut seed, mut x) = (seed, 0.0);
        (0..n)
            .map(|_| {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                x = a * x + ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
                x
            })
            .collect()
    }

    #[test]
    fn each_column_gets_its_own_autocorrelation_time_and_blocks() {
        // 20000 saves of a box [0, 10] in 10 slices (core: z in [3, 7]): the volume fraction
        // follows a slow AR(1) series (a = 0.8, τ = 4.5), the x momentum a fast one (a = 0,
        // τ = ½), the same in every slice; density 1, no contacts.
        let grid = Grid {
            z0: 0.0,
            z1: 10.0,
            n: 10,
        };
        let n = 20_000;
        let (slow, fast) = (ar1(0.8, n, 1), ar1(0.0, n, 2));
        let units: Vec<Unit> = (0..n)
            .map(|t| {
                let mut raw = Raw::zeros(grid.n);
                for k in 0..grid.n {
                    raw.nu[k] = 0.5 + slow[t];
                    raw.rho[k] = 1.0;
                    raw.momentum[k].x = fast[t];
                }
                Unit::of_save(raw)
            })
            .collect();
        let e = field_errors(&units, &grid);
        let col = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap();
        let (nu, vx, con) = (col("nu"), col("vx"), col("con_xz"));
        assert!((e.tau[nu] - 4.5).abs() < 0.5, "{}", e.tau[nu]);
        assert!((e.tau[vx] - 0.5).abs() < 0.1, "{}", e.tau[vx]);
        assert_eq!(e.tau[con], 0.5, "a constant column");
        // blocks of at least 5(2τ − 1) ≈ 40 saves for ν, of one save for vx
        assert!(
            e.long_enough[nu] && n / e.blocks[nu] >= 35,
            "{}",
            e.blocks[nu]
        );
        assert_eq!(e.blocks[vx], n);
        // the errors are the known √(2τ·variance/n) of each series (within 10 %)
        let exact = |tau: f64, a: f64| (2.0 * tau * (1.0 / 12.0) / (1.0 - a * a) / n as f64).sqrt();
        assert!(
            (e.se[5][nu] / exact(4.5, 0.8) - 1.0).abs() < 0.1,
            "{}",
            e.se[5][nu]
        );
        assert!(
            (e.se[5][vx] / exact(0.5, 0.0) - 1.0).abs() < 0.1,
            "{}",
            e.se[5][vx]
        );
    }
}
