//! The coverage test of the profiles' own errors on synthetic replicas with a slow mode, through
//! the code the in-run profiles and the ensembles use (`cg::blocking`, `analysis::ensemble`):
//! every slice's volume fraction is the sum of a slow and a fast AR(1) series, its integrated
//! autocorrelation time τ known, each replica only ~17 τ long (too short for blocks of several
//! τ). With the known τ as the reference floor, (replica, core slice) pairs cover the ensemble
//! mean as honest errors with n/τ − 1 degrees of freedom do; with τ measured on the short series
//! alone they do not: that τ comes out too small in most replicas (blocks of it can look long
//! enough), which is why the benchmark's runs take a reference τ.
//!
//! The benchmark's own figure comes from `verdem ensemble` (docs/ensembles.md, "Coverage of
//! the in-run errors"); it takes ~25 minutes of one core, too long for this file.

use rand::{Rng, SeedableRng};
use verdem::analysis::cg::blocking::{self, Method, Unit};
use verdem::analysis::cg::fields::{Grid, Raw};
use verdem::analysis::cg::table::Table;
use verdem::analysis::cg::{columns, COLUMNS, FIELDS};
use verdem::analysis::ensemble;

/// AR(1) coefficients of the slow and the fast part and the slow part's integrated
/// autocorrelation time ½(1 + a)/(1 − a); with equal variances the sum's τ is their mean.
const SLOW: f64 = 0.97;
const FAST: f64 = 0.5;
const REPLICAS: usize = 40;
const UNITS: usize = 300;

fn tau_of(a: f64) -> f64 {
    0.5 * (1.0 + a) / (1.0 - a)
}

/// `n` stationary values of AR(1) x_(k+1) = a x_k + u_k, u uniform on [−½, ½] scaled to give
/// the stationary variance `var`.
fn ar1(a: f64, n: usize, var: f64, rng: &mut rand_pcg::Pcg64) -> Vec<f64> {
    // u uniform on [−½, ½] has variance 1/12; x then has (1/12)/(1 − a²)
    let scale = (var * 12.0 * (1.0 - a * a)).sqrt();
    let mut x = scale * (rng.gen::<f64>() - 0.5) / (1.0 - a * a).sqrt();
    (0..n)
        .map(|_| {
            x = a * x + scale * (rng.gen::<f64>() - 0.5);
            x
        })
        .collect()
}

/// One replica's units on the benchmark's grid: every slice's volume fraction is 0.4 plus its
/// own slow and fast series (variance 1e-4 each), density 1, nothing else.
fn replica(grid: &Grid, rng: &mut rand_pcg::Pcg64) -> Vec<Unit> {
    let series: Vec<Vec<f64>> = (0..grid.n)
        .map(|_| {
            let slow = ar1(SLOW, UNITS, 1e-4, rng);
            let fast = ar1(FAST, UNITS, 1e-4, rng);
            slow.iter().zip(&fast).map(|(s, f)| 0.4 + s + f).collect()
        })
        .collect();
    (0..UNITS)
        .map(|t| {
            let mut raw = Raw::zeros(grid.n);
            for k in 0..grid.n {
                raw.nu[k] = series[k][t];
                raw.rho[k] = 1.0;
            }
            Unit::of_save(raw)
        })
        .collect()
}

/// The replica's profiles with the errors `errors` took.
fn table(units: &[Unit], grid: &Grid, errors: &blocking::FieldErrors) -> Table {
    let mean = verdem::analysis::cg::fields::derive(&blocking::merged(units).mean());
    Table {
        z: (0..grid.n).map(|k| grid.z(k)).collect(),
        mean: mean.iter().map(columns).collect(),
        se: errors.se.clone(),
    }
}

/// The benchmark's z-grid: 100 slices between the walls' planes 0 and 22 (core: z in [3, 19]).
fn benchmark_grid() -> Grid {
    Grid {
        z0: 0.0,
        z1: 22.0,
        n: 100,
    }
}

#[test]
fn errors_with_the_reference_tau_cover_a_slow_mode_and_with_their_own_tau_do_not() {
    let grid = benchmark_grid();
    let nu = COLUMNS.iter().position(|c| *c == "nu").unwrap();
    let field = FIELDS.iter().position(|f| f.0 == "nu").unwrap();
    let tau = 0.5 * (tau_of(SLOW) + tau_of(FAST));
    let mut floor = blocking::Floor::none();
    floor.slice[nu] = tau;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(24);
    let (mut with, mut without) = (Vec::new(), Vec::new());
    let mut dof = f64::INFINITY;
    for _ in 0..REPLICAS {
        let units = replica(&grid, &mut rng);
        let e = blocking::field_errors_with_floor(&units, &grid, &floor);
        assert_eq!(e.method[nu], Method::Tau, "tau {}", e.tau[nu]);
        dof = dof.min(blocking::degrees_of_freedom(&e, nu, UNITS));
        with.push(table(&units, &grid, &e));
        let own = blocking::field_errors(&units, &grid);
        assert_ne!(
            own.method[nu],
            Method::Tau,
            "no reference, no error from tau"
        );
        without.push(table(&units, &grid, &own));
    }
    let cover = |tables: &[Table]| {
        let m = ensemble::merge(tables).unwrap();
        ensemble::coverage(tables, &m, 2).unwrap()[field].clone()
    };
    let c = cover(&with);
    // Honest errors with the fewest degrees of freedom over the replicas cover at least
    // `low`; errors known exactly (infinite degrees of freedom) cover `high`. τ is the larger of
    // the reference and the replica's own, so the errors lean to the conservative side:
    // the coverage lies between the two, within four binomial standard deviations of 2880
    // independent (replica, core slice) pairs (0.45 %) and 1 % for the n/τ approximation.
    let low = ensemble::expected_coverage_dof(REPLICAS, dof);
    let high = ensemble::expected_coverage_dof(REPLICAS, 1e9);
    let margin = 4.0 * (low * (1.0 - low) / c.pairs as f64).sqrt() + 0.01;
    assert!(
        (low - margin..=high + margin).contains(&c.fraction()),
        "coverage {} against {low}..{high} ({} pairs, spread/SE {})",
        c.fraction(),
        c.pairs,
        c.spread_ratio
    );
    assert!((c.spread_ratio - 1.0).abs() < 0.1, "{}", c.spread_ratio);
    // τ measured on 300 values alone misses part of the slow mode: the errors are too small
    let own = cover(&without);
    assert!(
        own.fraction() < c.fraction() - 0.03 && own.spread_ratio > 1.05,
        "own tau: coverage {}, spread/SE {}",
        own.fraction(),
        own.spread_ratio
    );
}

/// One replica's units in which every slice's volume fraction is 0.4 plus a slow series common
/// to all slices (variance 1e-4) and a fast one of its own (variance 1e-3): each slice's τ is
/// mostly the fast one's, its core mean's the slow one's.
fn coherent_replica(grid: &Grid, rng: &mut rand_pcg::Pcg64) -> Vec<Unit> {
    let slow = ar1(SLOW, UNITS, 1e-4, rng);
    let fast: Vec<Vec<f64>> = (0..grid.n).map(|_| ar1(FAST, UNITS, 1e-3, rng)).collect();
    (0..UNITS)
        .map(|t| {
            let mut raw = Raw::zeros(grid.n);
            for k in 0..grid.n {
                raw.nu[k] = 0.4 + slow[t] + fast[k][t];
                raw.rho[k] = 1.0;
            }
            Unit::of_save(raw)
        })
        .collect()
}

/// Replicas of the core-mean test.
const CORE_REPLICAS: usize = 120;

#[test]
fn a_core_mean_takes_the_cores_reference_tau_and_its_errors_then_cover_a_coherent_mode() {
    let grid = benchmark_grid();
    let nu = COLUMNS.iter().position(|c| *c == "nu").unwrap();
    // the slices' τ, variance-weighted: (1e-4·τ_slow + 1e-3·τ_fast) / 1.1e-3 ≈ 4.4; the core
    // mean's: the fast parts average out over ~73 slices, (1e-4·τ_slow + 1.4e-5·τ_fast) /
    // 1.14e-4 ≈ 29 (300 units: ~10 τ, an error from τ with ~9 degrees of freedom)
    let slice_tau = (1e-4 * tau_of(SLOW) + 1e-3 * tau_of(FAST)) / 1.1e-3;
    let core_tau = (1e-4 * tau_of(SLOW) + 1e-3 / 73.0 * tau_of(FAST)) / (1e-4 + 1e-3 / 73.0);
    let slice_only = {
        let mut f = blocking::Floor::none();
        f.slice[nu] = slice_tau;
        f.core[nu] = slice_tau;
        f
    };
    let with_core = {
        let mut f = slice_only.clone();
        f.core[nu] = core_tau;
        f
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(27);
    // per floor: the mean over the replicas of t², t = (core mean − 0.4) / its error
    let (mut honest, mut short) = (0.0, 0.0);
    let mut dof = f64::INFINITY;
    for _ in 0..CORE_REPLICAS {
        let units = coherent_replica(&grid, &mut rng);
        for (floor, sum) in [(&with_core, &mut honest), (&slice_only, &mut short)] {
            let e = blocking::field_errors_with_floor(&units, &grid, floor);
            let c = blocking::core_mean(&units, &grid, &e, nu);
            *sum += ((c.mean - 0.4) / c.se).powi(2) / CORE_REPLICAS as f64;
            if std::ptr::eq(floor, &with_core) {
                assert!(
                    c.long_enough,
                    "an error from the core's τ over ≥ 5 τ is trusted"
                );
                dof = dof.min(c.dof);
            }
        }
    }
    // Student's t with ν degrees of freedom has E[t²] = ν/(ν − 2), and the mean of 120 values
    // scatters by √(Var t² / 120) (≈ 0.2 at ν = 9); with the core's τ the mean lies within
    // three of those of its expectation (of the replicas' fewest degrees of freedom, and of
    // infinitely many); with the slices' τ the errors are ~2.6 times too small and t² is
    // several times larger
    let mean_t2 = |v: f64| v / (v - 2.0);
    let sd = |v: f64| {
        let m4 = 3.0 * v * v / ((v - 2.0) * (v - 4.0));
        ((m4 - mean_t2(v).powi(2)) / CORE_REPLICAS as f64).sqrt()
    };
    assert!(dof > 5.0, "{dof}");
    assert!(
        (1.0 - 3.0 * sd(dof)..=mean_t2(dof) + 3.0 * sd(dof)).contains(&honest),
        "with the core's τ: mean t² {honest} ({dof} degrees of freedom)"
    );
    assert!(
        short > 2.0 * honest && short > mean_t2(dof) + 3.0 * sd(dof),
        "with the slices' τ: mean t² {short} against {honest}"
    );
}
