//! Standard errors of profiles from blocks as long as each field's own correlation: every
//! column of [`super::COLUMNS`] gets its integrated autocorrelation time, measured on the series
//! it is averaged from (saves, or bins of in-run samples), and its error from blocks of at
//! least [`block_length_for`] units of that series. A column's core mean (the average over the
//! core slices) gets an error of its own, from the series of the core mean ([`core_mean`]).

use super::fields::{derive, Grid, Raw};
use super::{columns, core_range, COLUMNS};
use crate::analysis::stats::{
    block, block_length_for, blocks_for, integrated_autocorrelation, median, standard_error,
    tau_standard_error, MIN_BLOCKS,
};

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

/// How a column's standard error was taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// From blocks of at least [`block_length_for`] its τ, [`MIN_BLOCKS`] of them or more.
    Blocks,
    /// From its τ ([`tau_standard_error`]): the series is too short for such blocks, but τ is
    /// at least the reference's ([`REFERENCE_TAU`]) and the series is [`MIN_BLOCKS`] τ long or
    /// more (its error's degrees of freedom, [`degrees_of_freedom`], at least those of
    /// [`MIN_BLOCKS`] blocks).
    Tau,
    /// Too short: no reference τ and too few units for blocks (τ measured on a series shorter
    /// than its slow fluctuations comes out too small), or shorter than [`MIN_BLOCKS`] τ.
    /// The error is taken from τ all the same and is not to be trusted.
    TooShort,
    /// The in-run sampling is not one at which the column's reference τ was calibrated
    /// ([`Floor::inrun`]): taken as above, and not to be trusted.
    Uncalibrated,
}

/// Per column of [`COLUMNS`]: the integrated autocorrelation time (in units) of its series,
/// the blocks its standard error comes from and how the error was taken.
#[derive(Clone, Debug)]
pub struct FieldErrors {
    /// τ the error was taken with: the larger of `measured` and `floor`.
    pub tau: Vec<f64>,
    /// τ measured on this series ([`field_taus`]).
    pub measured: Vec<f64>,
    /// The reference τ in units (0 where there is none).
    pub floor: Vec<f64>,
    /// Blocks of [`block_length_for`] `tau` (or [`MIN_BLOCKS`] shorter ones when too few), as
    /// the checks' core means take them.
    pub blocks: Vec<usize>,
    pub method: Vec<Method>,
    /// Standard error of each column, per grid point.
    pub se: Vec<Vec<f64>>,
    /// The reference τ of each column's core mean in units (0 where there is none): what
    /// [`core_mean`] takes no τ below.
    pub core_floor: Vec<f64>,
    /// Whether the references hold for the series ([`Floor::calibrated`]).
    pub calibrated: Vec<bool>,
}

/// The reference τ (in units of a series) that errors take no τ below, per column of
/// [`COLUMNS`]: of one slice, and of the core mean (the average over the core slices).
#[derive(Clone, Debug, PartialEq)]
pub struct Floor {
    pub slice: Vec<f64>,
    pub core: Vec<f64>,
    /// Whether each column's references hold for the series; an error of a column whose do not
    /// is not to be trusted ([`Method::Uncalibrated`]).
    pub calibrated: Vec<bool>,
}

impl Floor {
    /// No reference: every τ is measured on the series itself.
    pub fn none() -> Floor {
        Floor {
            slice: vec![0.0; COLUMNS.len()],
            core: vec![0.0; COLUMNS.len()],
            calibrated: vec![true; COLUMNS.len()],
        }
    }

    /// The bumpy-shear benchmark's ([`REFERENCE_TAU`], [`CORE_REFERENCE_TAU`]) in units of
    /// `unit_time` (the time a unit of the series spans).
    pub fn reference(unit_time: f64) -> Floor {
        let of = |taus: &[f64]| taus.iter().map(|t| t / unit_time).collect();
        Floor {
            slice: of(&REFERENCE_TAU),
            core: of(&CORE_REFERENCE_TAU),
            calibrated: vec![true; COLUMNS.len()],
        }
    }

    /// The benchmark's references for in-run bins of `unit_time` with the contact stress
    /// sampled every `contact_every` and the particle fields every `particle_every` time units:
    /// those of [`Floor::reference`] at [`DEFAULT_SAMPLING`]; with the contact columns'
    /// references of [`DENSE_CONTACT_TAU`] at [`DENSE_SAMPLING`]; at any other sampling the
    /// contact columns' are not calibrated (how much of a bin's variance is the contacts' white
    /// noise, which sets the τ its error needs, depends on the sampling).
    pub fn inrun(unit_time: f64, contact_every: f64, particle_every: f64) -> Floor {
        let mut f = Floor::reference(unit_time);
        let at = |(k, kp): (u64, u64)| {
            let near = |steps: u64, t: f64| (steps as f64 * BENCHMARK_DT / t - 1.0).abs() < 1e-3;
            near(k, contact_every) && near(kp, particle_every)
        };
        if at(DEFAULT_SAMPLING) {
            return f;
        }
        let dense = at(DENSE_SAMPLING);
        for (k, c) in (FIRST_CONTACT_COLUMN..COLUMNS.len()).enumerate() {
            match DENSE_CONTACT_TAU[k].filter(|_| dense) {
                Some([slice, core]) => {
                    f.slice[c] = slice / unit_time;
                    f.core[c] = core / unit_time;
                }
                None => f.calibrated[c] = false,
            }
        }
        f
    }
}

/// The benchmark's time step (time units): tc/50 of a free–free contact
/// (`cases/shear_flow.toml`).
const BENCHMARK_DT: f64 = 7.192545031528827e-05;

/// The first contact-stress column of [`COLUMNS`] (`con_xx`); the pressure and the shear
/// stress follow the nine components.
const FIRST_CONTACT_COLUMN: usize = 15;

/// The in-run sampling the references were calibrated at, (contact interval, particle
/// interval) in steps of the benchmark's dt: the contact stress every 8 contact durations, the
/// particle fields (and a bin) every 24, `verdem run`'s default.
pub const DEFAULT_SAMPLING: (u64, u64) = (400, 1200);

/// A denser sampling, the contact stress every half a contact duration (`--inrun-every 25
/// --inrun-particle-every 1200`), at which the contact columns' references are
/// [`DENSE_CONTACT_TAU`].
pub const DENSE_SAMPLING: (u64, u64) = (25, 1200);

/// The reference τ (time units) of a slice and of the core mean of the contact columns
/// (con_xx … con_zz, pressure, shear stress) at [`DENSE_SAMPLING`]: the core's is the τ with
/// which the errors of 60 runs of 144 time units match the spread of their core means (two
/// chains of 30 from the full runs' final states, each run from the last save of the one
/// before), the slices' the default's but con_xy's (its slices' errors were 1.4 times too small
/// without one); validated on 20 more runs (docs/statistics.md, "Sampling the contact stress
/// every 25 steps"). Sampled this often, a bin's white noise is small and its slower part
/// rules, so the core's are longer than the default sampling's. `None`: not measured (con_yx,
/// con_yz, con_zx, con_zy).
pub const DENSE_CONTACT_TAU: [Option<[f64; 2]>; 11] = [
    Some([1.0, 0.52]),
    Some([1.0, 0.12]),
    Some([0.0, 0.31]),
    None,
    Some([1.0, 0.57]),
    None,
    None,
    None,
    Some([1.0, 0.49]),
    Some([1.0, 0.84]),
    Some([0.0, 0.33]),
];

/// Integrated autocorrelation time, in time units, of each column of [`COLUMNS`] at one slice of
/// the steady bumpy-shear benchmark, for in-run averaging at its default sampling: the τ with
/// which a run's error of each slice matches the spread of 20 independent runs of 144 time
/// units (`cases/shear_flow_quick.toml` from saves of the official full run 360 time units
/// apart, averaged in-run over their second half), median over the core slices
/// (docs/statistics.md, "Reference autocorrelation times"). vx's is that of the profile less
/// its uniform offset, the bed's drift ([`BED_DRIFT_SD`]). The contact stress decorrelates
/// within a contact's duration (0), except its normal components and the pressure, which
/// follow the bed's slower fluctuations (1 time unit: blocks long enough for them). Runs of
/// the benchmark's flow take no τ below these: one run of a few τ measures its own τ too small.
pub const REFERENCE_TAU: [f64; 26] = [
    6.0, 6.0, 5.2, 4.4, 1.8, 2.3, 2.35, 1.03, 0.92, 1.03, 2.61, 0.70, 0.92, 0.70, 1.31, 1.0, 0.0,
    0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0,
];

/// What no error of one run of the benchmark's flow (nor of an ensemble of perturbed copies of
/// one state) includes: the bed's mean x-velocity, a uniform offset of the vx profile, drifts
/// with an autocorrelation time of ~390 time units or more, so every run shorter than that and
/// every replica keeps its start's value (docs/statistics.md).
pub const SLOW_MODE_NOTE: &str = "  note: the bed's mean x-velocity drifts with a correlation \
     time of ~390 time units or more (standard deviation ~0.004); no error here includes that \
     drift (a common offset of vx), docs/statistics.md\n";

/// Standard deviation of the bed's drift: of the core mean of vx averaged over a window of 18 to
/// 1440 time units, 0.0041 to 0.0025 (the longest windows the least), measured over the second
/// half of the official full run (`golden/full_run_official/`, saves 2001–4000); a uniform
/// offset of the vx profile that errors from a run's own blocks leave out (velocity units).
pub const BED_DRIFT_SD: f64 = 0.0041;

/// Integrated autocorrelation time, in time units, of each column's core mean (the average over
/// the core slices) in the steady bumpy-shear benchmark, for in-run averaging at its default
/// sampling: the τ with which a run's error of its core mean ([`core_mean`]) matches the spread
/// of the core means of 58 independent runs of 144 time units (`cases/shear_flow_quick.toml`
/// from saves 2100, 2150, …, 4000 and 2125, 2225, …, 3925 of the official full run, averaged
/// in-run over their second half; docs/statistics.md, "The core mean's own τ"). The particle
/// fields' core means keep the bed's coherent fluctuations, which every slice shares, so their τ
/// is longer than a slice's; vx's and vy's follow the bed's drift (tens of time units and more:
/// no run shorter than five of them has a trusted error of them). A contact-stress core mean is
/// mostly the white noise of a few contacts a sample, with a slower part on top: a fraction of a
/// bin, at the default bins (1200 steps); con_zy needs none.
pub const CORE_REFERENCE_TAU: [f64; 26] = [
    9.7, 9.7, 54.0, 107.0, 11.8, 5.5, 3.6, 1.5, 2.1, 1.5, 4.7, 1.7, 2.1, 1.7, 2.8, 0.10, 0.057,
    0.074, 0.059, 0.10, 0.050, 0.082, 0.0, 0.10, 0.16, 0.080,
];

/// The integrated autocorrelation time of each column: the larger of that of its core mean
/// (the average over the core slices, [`core_range`], or over all slices when the box has no
/// core) and the median over those slices of each slice's own; NaN for fewer than four units.
pub fn field_taus(units: &[Unit], grid: &Grid) -> Vec<f64> {
    let per_unit: Vec<Vec<Vec<f64>>> = units
        .iter()
        .map(|u| derive(&u.mean()).iter().map(columns).collect())
        .collect();
    let core = core_or_all(grid);
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

/// The degrees of freedom of column `c`'s variance estimate in `errors` over `units` units:
/// blocks − 1 from blocks; from τ, n/τ − 1 (the sample variance of n values with an exponential
/// autocorrelation of integrated time τ scatters as that of n/τ independent ones; Priestley,
/// *Spectral Analysis and Time Series*, 1981, §5.3), at least 1.
pub fn degrees_of_freedom(errors: &FieldErrors, c: usize, units: usize) -> f64 {
    match errors.method[c] {
        Method::Blocks => errors.blocks[c] as f64 - 1.0,
        _ => (units as f64 / errors.tau[c] - 1.0).max(1.0),
    }
}

/// Standard errors of every column without a reference τ: [`field_errors_with_floor`] with
/// no floor.
pub fn field_errors(units: &[Unit], grid: &Grid) -> FieldErrors {
    field_errors_with_floor(units, grid, &Floor::none())
}

/// Standard errors of every column, per grid point, with τ the larger of its own
/// ([`field_taus`]) and `floor.slice` (units, per column): from blocks of at least
/// [`block_length_for`] τ when the units hold [`MIN_BLOCKS`] of them ([`Method::Blocks`]), else
/// from τ ([`tau_standard_error`], [`Method::Tau`] or [`Method::TooShort`]).
pub fn field_errors_with_floor(units: &[Unit], grid: &Grid, floors: &Floor) -> FieldErrors {
    let floor = &floors.slice;
    let measured = field_taus(units, grid);
    let n = units.len();
    let tau: Vec<f64> = measured
        .iter()
        .zip(floor)
        .map(|(&m, &f)| floored(m, f))
        .collect();
    let chosen: Vec<(usize, Method)> = (0..COLUMNS.len())
        .map(|c| match method(n, tau[c], floor[c]) {
            (b, _) if !floors.calibrated[c] => (b, Method::Uncalibrated),
            chosen => chosen,
        })
        .collect();
    let per_unit: Vec<Vec<Vec<f64>>> = units
        .iter()
        .map(|u| derive(&u.mean()).iter().map(columns).collect())
        .collect();
    let mut cache: Vec<(usize, Vec<Vec<Vec<f64>>>)> = Vec::new();
    let mut se = vec![vec![0.0; COLUMNS.len()]; grid.n];
    for (c, &(blocks, method)) in chosen.iter().enumerate() {
        if method != Method::Blocks {
            for (k, row) in se.iter_mut().enumerate() {
                let vals: Vec<f64> = per_unit.iter().map(|u| u[k][c]).collect();
                row[c] = tau_standard_error(&vals, tau[c]);
            }
            continue;
        }
        if !cache.iter().any(|(b, _)| *b == blocks) {
            cache.push((blocks, block_columns(units, blocks)));
        }
        let (_, cols) = cache.iter().find(|(b, _)| *b == blocks).expect("cached");
        for (k, row) in se.iter_mut().enumerate() {
            let vals: Vec<f64> = cols.iter().map(|b| b[k][c]).collect();
            row[c] = standard_error(&vals);
        }
    }
    FieldErrors {
        tau,
        measured,
        floor: floor.to_vec(),
        blocks: chosen.iter().map(|c| c.0).collect(),
        method: chosen.iter().map(|c| c.1).collect(),
        se,
        core_floor: floors.core.clone(),
        calibrated: floors.calibrated.clone(),
    }
}

/// A core mean with its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoreMean {
    pub mean: f64,
    pub se: f64,
    /// The degrees of freedom of `se`: blocks − 1, or n/τ − 1 when taken from τ
    /// ([`degrees_of_freedom`]).
    pub dof: f64,
    /// Whether `se` can be trusted: from blocks as long as the correlation asks, or from a τ at
    /// least the reference's over a series [`MIN_BLOCKS`] τ long ([`Method::TooShort`] is not).
    pub long_enough: bool,
}

/// The core mean of column `c` of [`COLUMNS`] over `units` (the mean over the core slices of the
/// merged profile; over all slices when the box has no core) and its standard error from the
/// series of the units' core means: from τ ([`tau_standard_error`]), the larger of the series'
/// own integrated autocorrelation time and the core's reference ([`FieldErrors::core_floor`]).
/// Trusted as a slice's error is ([`Method`]): when the series holds [`MIN_BLOCKS`] blocks of
/// at least [`block_length_for`] τ, or τ is the reference's or more and the series
/// [`MIN_BLOCKS`] τ long. The core mean keeps what moves every slice together, so its τ is not
/// a slice's: a slice's reference ([`REFERENCE_TAU`]) does not enter.
pub fn core_mean(units: &[Unit], grid: &Grid, errors: &FieldErrors, c: usize) -> CoreMean {
    let (all, series) = core_series(units, grid);
    core_mean_of(
        all[c],
        &series[c],
        errors.core_floor[c],
        errors.calibrated[c],
    )
}

/// Per column of [`COLUMNS`], its core mean over `units` with its error ([`core_mean`]).
pub fn core_means(units: &[Unit], grid: &Grid, errors: &FieldErrors) -> Vec<CoreMean> {
    let (all, series) = core_series(units, grid);
    (0..COLUMNS.len())
        .map(|c| {
            core_mean_of(
                all[c],
                &series[c],
                errors.core_floor[c],
                errors.calibrated[c],
            )
        })
        .collect()
}

/// Per column of [`COLUMNS`]: the core mean of the merged `units`, and the series of each
/// unit's core mean ([`core_or_all`]).
fn core_series(units: &[Unit], grid: &Grid) -> (Vec<f64>, Vec<Vec<f64>>) {
    let core = core_or_all(grid);
    let of = |u: &Unit| -> Vec<f64> {
        let d: Vec<Vec<f64>> = derive(&u.mean()).iter().map(columns).collect();
        (0..COLUMNS.len())
            .map(|c| core.clone().map(|k| d[k][c]).sum::<f64>() / core.len() as f64)
            .collect()
    };
    let per_unit: Vec<Vec<f64>> = units.iter().map(of).collect();
    let series = (0..COLUMNS.len())
        .map(|c| per_unit.iter().map(|u| u[c]).collect())
        .collect();
    (of(&merged(units)), series)
}

/// [`core_mean`] of one column: its merged core mean `mean`, the series of the units' core
/// means, the core's reference τ `floor` (units) and whether it holds for the series.
fn core_mean_of(mean: f64, series: &[f64], floor: f64, calibrated: bool) -> CoreMean {
    let n = series.len();
    let tau = floored(integrated_autocorrelation(series), floor);
    CoreMean {
        mean,
        se: tau_standard_error(series, tau),
        // n/τ − 1 as for a slice's error from τ ([`degrees_of_freedom`]); τ is at least ½
        dof: (n as f64 / tau.max(0.5) - 1.0).max(1.0),
        long_enough: calibrated && method(n, tau, floor).1 != Method::TooShort,
    }
}

/// The core slices of `grid` ([`core_range`]), or all of them when the box has no core.
fn core_or_all(grid: &Grid) -> std::ops::Range<usize> {
    match core_range(grid) {
        r if r.is_empty() => 0..grid.n,
        r => r,
    }
}

/// τ measured on a series, no smaller than the reference `floor` (0: none); the reference when
/// the series is too short to measure τ (NaN).
fn floored(measured: f64, floor: f64) -> f64 {
    if measured.is_nan() && floor > 0.0 {
        floor
    } else {
        measured.max(floor)
    }
}

/// How the error of a series of `n` units with τ `tau` is taken, with the reference `floor`
/// (0: none), and from how many blocks: see [`Method`].
fn method(n: usize, tau: f64, floor: f64) -> (usize, Method) {
    match blocks_for(n, tau) {
        (b, true) => (b, Method::Blocks),
        (b, false) if floor > 0.0 && n as f64 >= MIN_BLOCKS as f64 * tau => (b, Method::Tau),
        (b, false) => (b, Method::TooShort),
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

/// A line per column of [`COLUMNS`]: its τ in `unit`s (and the reference's, when it sets
/// τ), its blocks (of `units` in all) and the block length it needs, and how its error was
/// taken.
pub fn describe(errors: &FieldErrors, units: usize, unit: &str) -> String {
    let mut s = String::new();
    for (c, name) in COLUMNS.iter().enumerate() {
        let len = block_length_for(errors.tau[c]);
        let floored = errors.floor[c] > 0.0 && errors.tau[c] == errors.floor[c];
        let tau = if floored {
            format!(
                "{} {unit} (reference; measured {})",
                shown(errors.tau[c]),
                shown(errors.measured[c])
            )
        } else {
            format!("{} {unit}", shown(errors.tau[c]))
        };
        let how = match errors.method[c] {
            Method::Blocks => String::new(),
            Method::Tau => format!(
                ": error from tau ({:.1} degrees of freedom)",
                degrees_of_freedom(errors, c, units)
            ),
            Method::TooShort => ": TOO SHORT, error not to be trusted".into(),
            Method::Uncalibrated => {
                ": NOT CALIBRATED at this sampling, error not to be trusted".into()
            }
        };
        s.push_str(&format!(
            "  {name:9} tau {tau}, {} blocks of {:.1} (needs >= {}){how}\n",
            errors.blocks[c],
            units as f64 / errors.blocks[c] as f64,
            if len.is_finite() {
                format!("{len}")
            } else {
                "?".into()
            },
        ));
    }
    s
}

/// The per-column error table written beside in-run profiles (`NAME.profiles_inrun_errors.csv`):
/// per column of [`COLUMNS`], τ measured, the reference τ and the τ used (all in units of the
/// series), the blocks, the degrees of freedom of the error ([`degrees_of_freedom`]) and how it
/// was taken (`blocks`, `tau`, or `TOO SHORT`); then its core mean `core[c]` ([`core_mean`])
/// with its standard error, degrees of freedom and whether that error is trusted.
pub fn errors_csv(errors: &FieldErrors, units: usize, core: &[CoreMean]) -> String {
    let mut s = String::from(
        "column,tau_measured,tau_reference,tau_used,blocks,degrees_of_freedom,method,core_mean,\
         core_se,core_degrees_of_freedom,core_trusted\n",
    );
    let num = |x: f64| {
        if x.is_finite() {
            format!("{x:.4}")
        } else {
            String::new()
        }
    };
    let sci = |x: f64| {
        if x.is_finite() {
            format!("{x:.6e}")
        } else {
            String::new()
        }
    };
    for (c, name) in COLUMNS.iter().enumerate() {
        let m = &core[c];
        s.push_str(&format!(
            "{name},{},{},{},{},{},{},{},{},{},{}\n",
            num(errors.measured[c]),
            num(errors.floor[c]),
            num(errors.tau[c]),
            errors.blocks[c],
            num(degrees_of_freedom(errors, c, units)),
            match errors.method[c] {
                Method::Blocks => "blocks",
                Method::Tau => "tau",
                Method::TooShort => "TOO SHORT",
                Method::Uncalibrated => "NOT CALIBRATED",
            },
            sci(m.mean),
            sci(m.se),
            num(m.dof),
            m.long_enough,
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
    fn a_series_too_short_for_its_blocks_takes_the_reference_tau_or_says_too_short() {
        // 400 saves whose volume fraction follows a slow AR(1) series (a = 0.98, τ = 49.5):
        // blocks of 5(2τ − 1) = 490 saves are longer than the series, and τ measured on it is
        // too small
        let grid = Grid {
            z0: 0.0,
            z1: 10.0,
            n: 10,
        };
        let n = 400;
        let slow = ar1(0.98, n, 3);
        let units: Vec<Unit> = (0..n)
            .map(|t| {
                let mut raw = Raw::zeros(grid.n);
                for k in 0..grid.n {
                    raw.nu[k] = 0.5 + slow[t];
                    raw.rho[k] = 1.0;
                }
                Unit::of_save(raw)
            })
            .collect();
        let nu = 0;
        let own = field_errors(&units, &grid);
        assert_eq!(own.method[nu], Method::TooShort, "tau {}", own.tau[nu]);
        assert!(describe(&own, n, "saves")
            .lines()
            .next()
            .unwrap()
            .contains("TOO SHORT"));
        // with a reference τ of 49.5 saves (400 ≥ 5τ): every slice's error is the error from
        // that τ of its own series (stats::tau_standard_error, tested there)
        let mut floor = vec![0.0; COLUMNS.len()];
        floor[nu] = 49.5;
        let floors = Floor {
            slice: floor,
            ..Floor::none()
        };
        let e = field_errors_with_floor(&units, &grid, &floors);
        assert_eq!(e.method[nu], Method::Tau);
        assert_eq!(e.tau[nu], 49.5f64.max(own.tau[nu]));
        let series: Vec<f64> = slow.iter().map(|s| 0.5 + s).collect();
        let expected = tau_standard_error(&series, e.tau[nu]);
        for k in 0..grid.n {
            assert!(
                (e.se[k][nu] / expected - 1.0).abs() < 1e-9,
                "{}",
                e.se[k][nu]
            );
        }
        assert!((degrees_of_freedom(&e, nu, n) - (n as f64 / e.tau[nu] - 1.0)).abs() < 1e-12);
        let csv = errors_csv(&e, n, &core_means(&units, &grid, &e));
        let row = csv.lines().find(|l| l.starts_with("nu,")).unwrap();
        assert!(row.contains(",tau,") && row.contains(",49.5000,"), "{row}");
        // then the core mean, without a core reference: τ measured on the 400 values, which
        // do not hold 5 blocks of it: not trusted
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 11, "{row}");
        assert_eq!(cells[10], "false", "{row}");
        // a column without a reference τ keeps its own, and a constant one its blocks of one
        assert_eq!(e.method[COLUMNS.len() - 1], Method::Blocks);
    }

    /// The contact columns' references hold at the two calibrated in-run samplings only: the
    /// default's are the tables', the dense one's core references are its own, and at any other
    /// sampling (or at the dense one for a column it did not measure) the column's errors are
    /// marked not to be trusted, in the table and in its core mean, while the particle
    /// columns' stand.
    #[test]
    fn contact_references_hold_only_at_the_samplings_they_were_calibrated_at() {
        let bin = 1200.0 * BENCHMARK_DT;
        let at = |(k, kp): (u64, u64)| {
            Floor::inrun(bin, k as f64 * BENCHMARK_DT, kp as f64 * BENCHMARK_DT)
        };
        let col = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap();
        // the dense table's rows are the columns from con_xx to the end, in COLUMNS' order
        assert_eq!(FIRST_CONTACT_COLUMN, col("con_xx"));
        assert_eq!(
            COLUMNS.len() - FIRST_CONTACT_COLUMN,
            DENSE_CONTACT_TAU.len()
        );
        assert_eq!(COLUMNS[COLUMNS.len() - 1], "shear_xz");
        let (p, yx, nu) = (col("pressure"), col("con_yx"), col("nu"));
        assert_eq!(at(DEFAULT_SAMPLING), Floor::reference(bin));
        let dense = at(DENSE_SAMPLING);
        assert!(
            (dense.core[p] * bin - 0.84).abs() < 1e-12,
            "{}",
            dense.core[p]
        );
        let xy = col("con_xy");
        assert!(
            (dense.slice[xy] * bin - 1.0).abs() < 1e-12,
            "{}",
            dense.slice[xy]
        );
        assert_eq!(dense.slice[p], Floor::reference(bin).slice[p]);
        assert!(dense.calibrated[p] && !dense.calibrated[yx] && dense.calibrated[nu]);
        let other = at((25, 1000));
        assert!((FIRST_CONTACT_COLUMN..COLUMNS.len()).all(|c| !other.calibrated[c]));
        assert!((0..FIRST_CONTACT_COLUMN).all(|c| other.calibrated[c]));
        // 100 bins of white noise in 5 slices (core z in [3, 7] of [0, 10]): the contact
        // columns are marked, whatever their blocks
        let grid = Grid {
            z0: 0.0,
            z1: 10.0,
            n: 5,
        };
        let noise = ar1(0.0, 100, 7);
        let units: Vec<Unit> = noise
            .iter()
            .map(|x| {
                let mut raw = Raw::zeros(grid.n);
                for k in 0..grid.n {
                    raw.nu[k] = 0.5 + x;
                    raw.rho[k] = 1.0;
                    raw.contact[k][(0, 0)] = 1.0 + x;
                }
                Unit::of_save(raw)
            })
            .collect();
        let e = field_errors_with_floor(&units, &grid, &other);
        assert_eq!(e.method[p], Method::Uncalibrated);
        assert_ne!(e.method[nu], Method::Uncalibrated);
        let core = core_means(&units, &grid, &e);
        assert!(!core[p].long_enough);
        let csv = errors_csv(&e, units.len(), &core);
        let row = csv.lines().find(|l| l.starts_with("pressure,")).unwrap();
        assert!(
            row.contains(",NOT CALIBRATED,") && row.ends_with(",false"),
            "{row}"
        );
        let d = describe(&e, units.len(), "bins");
        assert_eq!(
            d.matches("NOT CALIBRATED").count(),
            COLUMNS.len() - FIRST_CONTACT_COLUMN
        );
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
            e.method[nu] == Method::Blocks && n / e.blocks[nu] >= 35,
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
