//! The statistics every report uses: medians and their distribution-free intervals (timings),
//! block standard errors, integrated autocorrelation times and χ² measures (profiles), and
//! least-squares lines (trends and convergence orders). Each function states what it assumes
//! of its values; none of them knows where the values come from.

/// The median of `values` (the mean of the two middle values for an even count). Panics on an
/// empty slice.
pub fn median(values: &[f64]) -> f64 {
    let mut r = values.to_vec();
    r.sort_by(f64::total_cmp);
    let n = r.len();
    if n % 2 == 1 {
        r[n / 2]
    } else {
        0.5 * (r[n / 2 - 1] + r[n / 2])
    }
}

/// Tukey's hinges of `values` (the medians of their lower and upper halves, each with the
/// middle value when the count is odd): the spread of the middle half of the values. Panics on
/// an empty slice.
pub fn hinges(values: &[f64]) -> (f64, f64) {
    let mut r = values.to_vec();
    r.sort_by(f64::total_cmp);
    let half = r.len().div_ceil(2);
    (median(&r[..half]), median(&r[r.len() - half..]))
}

/// A distribution-free interval for the median of the distribution `values` are drawn from,
/// taking them as independent: the k-th smallest and the k-th largest value, with the largest
/// k for which the interval covers the median with probability ≥ `confidence` (it misses only
/// when k or more values fall on one side of the median, each with probability ½: a binomial
/// tail; Conover, *Practical Nonparametric Statistics*, 3rd ed., §3.2). `None` when no such
/// interval reaches `confidence` (fewer than six values at 95 %).
pub fn median_interval(values: &[f64], confidence: f64) -> Option<(f64, f64)> {
    let mut r = values.to_vec();
    r.sort_by(f64::total_cmp);
    let n = r.len();
    // P(at most j of n values below the median) for j = 0, 1, …, summed in log space so that
    // 2⁻ⁿ does not underflow for long runs.
    let ln_half_n = -(n as f64) * std::f64::consts::LN_2;
    let mut ln_term = ln_half_n;
    let mut tail = 0.0;
    let mut k = 0;
    for j in 0..n.div_ceil(2) {
        if j > 0 {
            ln_term += ((n - j + 1) as f64 / j as f64).ln();
        }
        tail += ln_term.exp();
        if 2.0 * tail > 1.0 - confidence {
            break;
        }
        k = j + 1;
    }
    (k > 0).then(|| (r[k - 1], r[n - k]))
}

/// The value at quantile `q` ∈ [0, 1] of `values` by the nearest rank (the value at index
/// round((n − 1)·q) of the sorted values); 0 for no values.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// The `b`-th of `blocks` consecutive, nearly equal blocks of `n` items: items
/// b·n/blocks .. (b + 1)·n/blocks (integer division), so that the blocks cover all items.
pub fn block(b: usize, blocks: usize, n: usize) -> std::ops::Range<usize> {
    b * n / blocks..(b + 1) * n / blocks
}

/// Standard error of the mean of independent values: √(s²/n) with the unbiased variance s²
/// (0 for fewer than two values). Applied to block means, it is the block-averaging error of
/// a correlated series when the blocks are longer than its correlation time.
pub fn standard_error(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    if values.len() < 2 {
        return 0.0;
    }
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
}

/// Blocks are at least this many times 2τ − 1 values long, where τ is the series' integrated
/// autocorrelation time: 2τ − 1 = 2 Σ_(t≥1) ρ(t) is how many values each value is correlated
/// with beyond itself, and the variance of block means of length L is low by about
/// (2τ − 1)/L against its limit 2τσ²/L (Flyvbjerg & Petersen, J. Chem. Phys. 91:461, 1989;
/// an AR(1) series with ρ(1) = 0.8 is low by 11 %, its standard error by 6 %, at this factor).
pub const BLOCK_PER_CORRELATION: f64 = 5.0;

/// Fewest blocks a standard error is taken from: with fewer, the error of the error (a
/// χ² with blocks − 1 degrees of freedom) is over a third of it.
pub const MIN_BLOCKS: usize = 5;

/// The shortest block (values) for a series of integrated autocorrelation time `tau` (in units
/// of its spacing): [`BLOCK_PER_CORRELATION`]·(2τ − 1) rounded up, at least 1; infinite for a
/// NaN τ (too few values to measure it).
pub fn block_length_for(tau: f64) -> f64 {
    if tau.is_nan() {
        return f64::INFINITY;
    }
    (BLOCK_PER_CORRELATION * (2.0 * tau - 1.0)).ceil().max(1.0)
}

/// How many blocks `n` equally spaced values with integrated autocorrelation time `tau` are
/// cut into: blocks of at least [`block_length_for`] values. Returns the count and whether the
/// blocks are that long: when they would be fewer than [`MIN_BLOCKS`], [`MIN_BLOCKS`] shorter
/// blocks are taken (fewer when `n` is smaller) and the flag is false (the standard error is
/// then too small).
pub fn blocks_for(n: usize, tau: f64) -> (usize, bool) {
    let count = (n as f64 / block_length_for(tau)).floor() as usize;
    if count >= MIN_BLOCKS {
        (count, true)
    } else {
        (MIN_BLOCKS.min(n).max(1), false)
    }
}

/// Standard error of the mean of a correlated series `x` from `blocks` consecutive blocks
/// ([`block`]): the [`standard_error`] of the block means (0 for one block). With blocks of
/// [`block_length_for`] values or more it estimates √(2τσ²/n).
pub fn block_standard_error(x: &[f64], blocks: usize) -> f64 {
    let blocks = blocks.clamp(1, x.len().max(1));
    let means: Vec<f64> = (0..blocks)
        .map(|b| {
            let r = block(b, blocks, x.len());
            let len = r.len() as f64;
            x[r].iter().sum::<f64>() / len
        })
        .collect();
    standard_error(&means)
}

/// Standard error of the mean of `x`, an equally spaced series with integrated autocorrelation
/// time `tau` (in units of its spacing), from τ itself: √(2τσ²/n), with the series' variance σ²
/// estimated as c₀·n/(n − 2τ) from c₀ = Σ(x − x̄)²/n, which is low by the variance of the mean
/// itself, ≈ 2τσ²/n (Sokal, "Monte Carlo methods in statistical mechanics", 1997, §3). Unlike
/// blocks it needs no block as long as several τ, so it stays honest for a series of a few τ
/// when τ is known from elsewhere; its own relative scatter is about √(τ/n). 0 for fewer than
/// two values; with n ≤ 4τ the correction is capped at a factor 2 (n − 2τ taken as n/2).
pub fn tau_standard_error(x: &[f64], tau: f64) -> f64 {
    let n = x.len() as f64;
    if x.len() < 2 || tau.is_nan() {
        return 0.0;
    }
    let mean = x.iter().sum::<f64>() / n;
    let c0 = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    let tau = tau.max(0.5);
    (2.0 * tau * c0 / (n - 2.0 * tau).max(0.5 * n)).sqrt()
}

/// Integrated autocorrelation time τ = 1/2 + Σ ρ(t) of an equally spaced series, summed up to
/// the first window W ≥ 5τ (Sokal's automatic window), in units of the series' spacing; at
/// least 1/2 (uncorrelated values), exactly 1/2 for a constant series, NaN for fewer than four
/// values.
pub fn integrated_autocorrelation(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 4 {
        return f64::NAN;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let c0 = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
    if c0 == 0.0 {
        return 0.5;
    }
    let mut tau = 0.5;
    for t in 1..n / 2 {
        let c = (0..n - t)
            .map(|i| (x[i] - mean) * (x[i + t] - mean))
            .sum::<f64>()
            / n as f64;
        tau += c / c0;
        if t as f64 >= 5.0 * tau {
            break;
        }
    }
    tau.max(0.5)
}

/// The error-weighted mean of `values` (standard errors `errors`, weights 1/σ²) and the
/// reduced χ² of the values about it, Σ((x − mean)/σ)²/(n − 1) (divided by 1 for a single
/// value): ≈ 1 when the values are one constant plus independent Gaussian noise of those
/// errors. A zero error is taken as 1e-300.
pub fn weighted_mean_chi2(values: &[f64], errors: &[f64]) -> (f64, f64) {
    let w: Vec<f64> = errors.iter().map(|s| 1.0 / (s * s).max(1e-300)).collect();
    let mean = values.iter().zip(&w).map(|(x, w)| x * w).sum::<f64>() / w.iter().sum::<f64>();
    let chi2 = values
        .iter()
        .zip(errors)
        .map(|(x, s)| ((x - mean) / s.max(1e-300)).powi(2))
        .sum::<f64>();
    (mean, chi2 / (values.len() as f64 - 1.0).max(1.0))
}

/// The mean of d²/σ² over the (difference d, variance σ²) pairs with σ² > 0: ≈ 1 when the
/// differences are independent Gaussian noise of those variances (0 when no pair has a
/// variance).
pub fn mean_chi2(pairs: impl IntoIterator<Item = (f64, f64)>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (d, var) in pairs {
        if var > 0.0 {
            sum += d.powi(2) / var;
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// Least-squares slope of (x, y) points (NaN for fewer than two distinct x).
pub fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = (
        points.iter().map(|q| q.0).sum::<f64>() / n,
        points.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let sxy: f64 = points.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    let sxx: f64 = points.iter().map(|q| (q.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// Least-squares line through equally spaced values `y`: its change from the first to the last
/// point relative to the mean (0 for a zero mean), and its slope in units of the slope's
/// standard error (from the residuals, taken as independent; ±∞ for an exact line, 0 for fewer
/// than three points or constant values).
pub fn trend(y: &[f64]) -> (f64, f64) {
    let n = y.len() as f64;
    if y.len() < 3 {
        return (0.0, 0.0);
    }
    let x_mean = (n - 1.0) / 2.0;
    let y_mean = y.iter().sum::<f64>() / n;
    let sxx: f64 = (0..y.len()).map(|i| (i as f64 - x_mean).powi(2)).sum();
    let slope = y
        .iter()
        .enumerate()
        .map(|(i, v)| (i as f64 - x_mean) * (v - y_mean))
        .sum::<f64>()
        / sxx;
    let residual: f64 = y
        .iter()
        .enumerate()
        .map(|(i, v)| (v - y_mean - slope * (i as f64 - x_mean)).powi(2))
        .sum();
    let se = (residual / (n - 2.0) / sxx).sqrt();
    let change = if y_mean != 0.0 {
        slope * (n - 1.0) / y_mean
    } else {
        0.0
    };
    let t = if se > 0.0 {
        slope / se
    } else if slope == 0.0 {
        0.0
    } else {
        f64::INFINITY.copysign(slope)
    };
    (change, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_hinges_of_small_samples() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(hinges(&[5.0, 1.0, 3.0, 2.0, 4.0]), (2.0, 4.0));
        assert_eq!(hinges(&[4.0, 1.0, 3.0, 2.0]), (1.5, 3.5));
        assert_eq!(hinges(&[7.0]), (7.0, 7.0));
    }

    #[test]
    fn the_median_interval_is_the_widest_order_statistics_the_binomial_tail_allows() {
        let values = |n: usize| (1..=n).rev().map(|v| v as f64).collect::<Vec<f64>>();
        let at = |n| median_interval(&values(n), 0.95);
        assert_eq!(at(5), None);
        // n = 6: P(0 below) = 1/64 per side, 3.1 % in all; P(≤ 1 below) = 7/64 is too much
        assert_eq!(at(6), Some((1.0, 6.0)));
        // n = 10: P(≤ 1) = 11/1024 per side, 2.1 % in all; P(≤ 2) = 56/1024, 10.9 %
        assert_eq!(at(10), Some((2.0, 9.0)));
        // n = 20: P(≤ 5) = 21700/2²⁰ per side, 4.1 % in all; P(≤ 6) = 60460/2²⁰, 11.5 %
        assert_eq!(at(20), Some((6.0, 15.0)));
        // n = 30: P(≤ 9) = 2.1 % per side, 4.3 % in all; P(≤ 10) = 4.9 % per side is too much
        assert_eq!(at(30), Some((10.0, 21.0)));
        // n = 2000: 2⁻²⁰⁰⁰ underflows an f64; the normal approximation puts k near
        // 1000 − 1.96·√2000/2 ≈ 956
        let (lo, hi) = at(2000).unwrap();
        assert!((950.0..=960.0).contains(&lo), "{lo}");
        assert_eq!(hi, 2001.0 - lo);
        // at 80 %, n = 10 allows P(≤ 2) = 10.9 % in all but not P(≤ 3) = 34.4 %: k = 3
        assert_eq!(median_interval(&values(10), 0.8), Some((3.0, 8.0)));
    }

    #[test]
    fn quantiles_take_the_nearest_rank() {
        let v: Vec<f64> = (0..=100).rev().map(f64::from).collect();
        assert_eq!(quantile(&v, 0.5), 50.0);
        assert_eq!(quantile(&v, 0.99), 99.0);
        assert_eq!(quantile(&v, 1.0), 100.0);
        assert_eq!(quantile(&[2.0, 1.0], 0.5), 2.0, "index round(0.5) = 1");
        assert_eq!(quantile(&[], 0.5), 0.0);
    }

    #[test]
    fn blocks_cover_every_item_once() {
        let ranges: Vec<_> = (0..3).map(|b| block(b, 3, 10)).collect();
        assert_eq!(ranges, [0..3, 3..6, 6..10]);
    }

    #[test]
    fn the_standard_error_of_known_samples() {
        // 1, 2, 3, 4: variance 5/3, standard error √(5/12)
        let se = standard_error(&[1.0, 2.0, 3.0, 4.0]);
        assert!((se - (5.0f64 / 12.0).sqrt()).abs() < 1e-15, "{se}");
        assert_eq!(standard_error(&[7.0]), 0.0);
        assert_eq!(standard_error(&[2.0; 5]), 0.0);
    }

    #[test]
    fn the_autocorrelation_time_of_known_series() {
        assert!(integrated_autocorrelation(&[1.0, 2.0, 3.0]).is_nan());
        assert_eq!(integrated_autocorrelation(&[4.0; 10]), 0.5);
        // alternating signs: ρ(1) ≈ −1 pulls τ below ½, which is the floor
        let alternating: Vec<f64> = (0..100)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        assert_eq!(integrated_autocorrelation(&alternating), 0.5);
        // an AR(1) series x_(k+1) = a x_k + noise has τ = ½ (1 + a)/(1 − a): 4.5 at a = 0.8
        let (mut x, mut state) = (Vec::new(), 0.0f64);
        let mut seed = 12345u64;
        for _ in 0..200_000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let noise = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            state = 0.8 * state + noise;
            x.push(state);
        }
        let tau = integrated_autocorrelation(&x);
        assert!((tau - 4.5).abs() < 0.3, "{tau}");
    }

    /// An AR(1) series x_(k+1) = a x_k + u_k with u uniform on [−½, ½] (variance 1/12), from
    /// a seeded linear congruential generator, started in its stationary state's scale.
    fn ar1(a: f64, n: usize, seed: &mut u64) -> Vec<f64> {
        let mut uniform = || {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut state = uniform() / (1.0 - a * a).sqrt();
        (0..n)
            .map(|_| {
                state = a * state + uniform();
                state
            })
            .collect()
    }

    #[test]
    fn block_errors_of_an_ar1_series_give_its_known_standard_error() {
        // AR(1): variance σ²/(1 − a²), τ = ½ (1 + a)/(1 − a); the mean of n values has
        // SE = √(2τ·variance/n) (up to O(τ/n)).
        let (a, n) = (0.8, 400_000);
        let tau = 0.5 * (1.0 + a) / (1.0 - a);
        let var = (1.0 / 12.0) / (1.0 - a * a);
        let exact = (2.0 * tau * var / n as f64).sqrt();
        let x = ar1(a, n, &mut 2024);
        let measured_tau = integrated_autocorrelation(&x);
        let (blocks, long) = blocks_for(n, measured_tau);
        assert!(long && blocks >= 1000, "{blocks}");
        let se = block_standard_error(&x, blocks);
        // blocks of 5(2τ − 1) = 40: low by ~6 %; ~10000 blocks scatter by ~1/√(2·blocks) < 1 %
        assert!((se / exact - 1.0).abs() < 0.1, "{se} vs {exact}");
        // blocks of one value (the naive error) miss √(2τ) = 3
        let naive = block_standard_error(&x, n);
        assert!((exact / naive - (2.0 * tau).sqrt()).abs() < 0.3, "{naive}");
    }

    #[test]
    fn block_errors_cover_the_true_mean_of_independent_ar1_replicas() {
        // 400 replicas of 20000 values, each judged by its own τ and block error: about 95 %
        // of them hold the true mean 0 within ±2 SE (binomial spread ±1.1 %).
        let mut seed = 7;
        let replicas = 400;
        let covered = (0..replicas)
            .filter(|_| {
                let x = ar1(0.9, 20_000, &mut seed);
                let (blocks, long) = blocks_for(x.len(), integrated_autocorrelation(&x));
                assert!(long);
                let mean = x.iter().sum::<f64>() / x.len() as f64;
                mean.abs() < 2.0 * block_standard_error(&x, blocks)
            })
            .count();
        let fraction = covered as f64 / replicas as f64;
        assert!((0.91..=0.98).contains(&fraction), "{fraction}");
    }

    /// A series with a slow mode: the sum of a slow AR(1) series (a = 0.98, τ = 49.5) and a
    /// fast one (a = 0.5, τ = 1.5) of equal variance, so τ = (49.5 + 1.5)/2 = 25.5.
    fn slow_mode(n: usize, seed: &mut u64) -> Vec<f64> {
        let slow = ar1(0.98, n, seed);
        // equal variances: the fast series is scaled by √((1 − 0.5²)/(1 − 0.98²))
        let scale = ((1.0 - 0.25) / (1.0 - 0.98f64.powi(2))).sqrt();
        let fast = ar1(0.5, n, seed);
        slow.iter().zip(&fast).map(|(s, f)| s + scale * f).collect()
    }

    #[test]
    fn errors_from_a_known_tau_cover_a_slow_mode_that_ten_blocks_miss() {
        // 400 replicas of 500 values (about 20 τ): ten blocks of 50 ≈ 2τ values, or the series'
        // own τ measured on 500 values, miss much of the slow mode's variance; the error from
        // the true τ covers the true mean 0 as an error with n/τ − 1 degrees of freedom does.
        let (replicas, n, tau) = (400, 500, 25.5);
        let mut seed = 99;
        let (mut blocks10, mut own, mut known) = (0, 0, 0);
        for _ in 0..replicas {
            let x = slow_mode(n, &mut seed);
            let mean = x.iter().sum::<f64>() / n as f64;
            let inside = |se: f64| usize::from(mean.abs() <= 2.0 * se);
            blocks10 += inside(block_standard_error(&x, 10));
            own += inside(tau_standard_error(&x, integrated_autocorrelation(&x)));
            known += inside(tau_standard_error(&x, tau));
        }
        let frac = |k: usize| k as f64 / replicas as f64;
        // P(|t| ≤ 2) with n/τ − 1 = 18.6 degrees of freedom: 0.939 (t tables: t(0.97, 18) = 2.10)
        let expected = 0.939;
        let binomial = (expected * (1.0 - expected) / replicas as f64).sqrt();
        assert!(
            (frac(known) - expected).abs() < 3.5 * binomial,
            "known tau: {} vs {expected}",
            frac(known)
        );
        assert!(frac(blocks10) < 0.88, "ten blocks: {}", frac(blocks10));
        assert!(frac(own) < frac(known) - 0.03, "own tau: {}", frac(own));
    }

    #[test]
    fn the_error_from_tau_is_the_known_one_for_independent_and_correlated_values() {
        // independent values: τ = ½ gives the ordinary standard error
        let x = [1.0, 2.0, 3.0, 4.0];
        assert!((tau_standard_error(&x, 0.5) - standard_error(&x)).abs() < 1e-15);
        assert_eq!(tau_standard_error(&[5.0], 3.0), 0.0);
        // AR(1), a = 0.8 (τ = 4.5): √(2τ·variance/n) within 5 % over 400000 values
        let (a, n) = (0.8, 400_000);
        let x = ar1(a, n, &mut 2024);
        let exact = (2.0 * 4.5 * (1.0 / 12.0) / (1.0 - a * a) / n as f64).sqrt();
        let se = tau_standard_error(&x, 4.5);
        assert!((se / exact - 1.0).abs() < 0.05, "{se} vs {exact}");
        // n = 10τ: c₀ is low by 2τ/n = 20 % on average, which the error restores: over 2000
        // replicas the mean of se² is the exact 2τσ²/n within 5 %
        let (tau, n) = (4.5, 45);
        let mut seed = 5;
        let mean_var = (0..2000)
            .map(|_| tau_standard_error(&ar1(a, n, &mut seed), tau).powi(2))
            .sum::<f64>()
            / 2000.0;
        let exact = 2.0 * tau * (1.0 / 12.0) / (1.0 - a * a) / n as f64;
        assert!(
            (mean_var / exact - 1.0).abs() < 0.1,
            "{mean_var} vs {exact}"
        );
    }

    #[test]
    fn too_short_series_fall_back_to_the_fewest_blocks_and_say_so() {
        // independent values: blocks of one
        assert_eq!(blocks_for(100, 0.5), (100, true));
        // τ = 1: blocks of 5(2τ − 1) = 5
        assert_eq!(blocks_for(100, 1.0), (20, true));
        assert_eq!(blocks_for(20, 3.0), (5, false));
        assert_eq!(blocks_for(3, 0.5), (3, false));
        assert_eq!(blocks_for(3, f64::NAN), (3, false));
        assert_eq!(block_standard_error(&[1.0, 2.0, 3.0, 4.0], 2), 1.0);
    }

    #[test]
    fn chi2_of_values_about_their_weighted_mean() {
        // 1 ± 1 and 3 ± 1: mean 2, χ² = 1 + 1 over 1 degree of freedom
        assert_eq!(weighted_mean_chi2(&[1.0, 3.0], &[1.0, 1.0]), (2.0, 2.0));
        // a precise value pulls the mean: 0 ± 0.1 and 10 ± 1 weigh 100 : 1
        let (mean, _) = weighted_mean_chi2(&[0.0, 10.0], &[0.1, 1.0]);
        assert!((mean - 10.0 / 101.0).abs() < 1e-12, "{mean}");
        // differences of one standard deviation each give 1; pairs without variance are skipped
        assert_eq!(mean_chi2([(2.0, 4.0), (-3.0, 9.0), (5.0, 0.0)]), 1.0);
        assert_eq!(mean_chi2([(5.0, 0.0)]), 0.0);
    }

    #[test]
    fn slopes_and_trends_of_known_lines() {
        assert_eq!(slope(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]), 2.0);
        // y = x² at x = −1, 0, 1: symmetric, slope 0
        assert_eq!(slope(&[(-1.0, 1.0), (0.0, 0.0), (1.0, 1.0)]), 0.0);
        // exact line 10, 11, …, 14: a rise of 4 over a mean of 12, with no scatter
        let (change, t) = trend(&[10.0, 11.0, 12.0, 13.0, 14.0]);
        assert!((change - 4.0 / 12.0).abs() < 1e-12, "{change}");
        assert_eq!(t, f64::INFINITY, "an exact line is a trend");
        assert_eq!(trend(&[3.0; 5]), (0.0, 0.0));
        assert_eq!(trend(&[1.0, 2.0]), (0.0, 0.0));
        // alternating scatter of ±1 around a flat line: no trend
        let (change, t) = trend(&[1.0, -1.0, 1.0, -1.0, 1.0, -1.0].map(|v| 10.0 + v));
        assert!(change.abs() < 0.15 && t.abs() < 1.0, "{change} {t}");
        // a clear rise through scatter
        let y: Vec<f64> = (0..10)
            .map(|i| 10.0 + i as f64 + if i % 2 == 0 { 0.3 } else { -0.3 })
            .collect();
        let (_, t) = trend(&y);
        assert!(t > 10.0, "{t}");
    }
}
