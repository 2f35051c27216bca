//! Built-in physics checks of steady-state profiles: momentum balance, wall consistency, mass,
//! symmetry, steadiness across the blocks of saves, and a kinetic-theory sanity check
//! (reported, never failed).

use super::blocking::BED_DRIFT_SD;
use super::{columns, core_range, Profiles, COLUMNS};
use crate::analysis::stats::{block, standard_error, trend, weighted_mean_chi2};
use crate::analysis::{Limit, Verdict};

/// A number in a report: as formatted when finite, else "undefined" (one block gives no error
/// bar, an empty core no mean): no NaN or infinity is written.
pub(super) struct Shown(pub(super) f64);

impl std::fmt::Display for Shown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_finite() {
            std::fmt::Display::fmt(&self.0, f)
        } else {
            f.write_str("undefined")
        }
    }
}

impl std::fmt::LowerExp for Shown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_finite() {
            std::fmt::LowerExp::fmt(&self.0, f)
        } else {
            f.write_str("undefined")
        }
    }
}

/// One check: its name is the verdict's quantity; the report prints the measurement and the
/// expectation in words.
pub type Check = Verdict;

/// How the name of the steadiness check starts.
const STEADY: &str = "steady:";

/// What a failed steadiness check means for the other verdicts, or `None` when it passed or was
/// not judged.
fn unsteady_note(checks: &[Check]) -> Option<&'static str> {
    checks
        .iter()
        .any(|c| c.quantity.starts_with(STEADY) && c.failed())
        .then_some(
            "note: the flow is not steady over these saves, and the uniformity, wall and \
             symmetry checks judge a steady flow. From rest the shear flow is still developing \
             at t = 144 (the quick case); coarse-grain later saves (--from) or run from a steady \
             state (cases/shear_flow_steady.toml starts from verdem's full run).",
        )
}

fn col(name: &str) -> usize {
    COLUMNS
        .iter()
        .position(|c| *c == name)
        .expect("known column")
}

/// A profile against its mirror image about the mid-plane ([`mirror`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Mirror {
    /// χ²/dof over the judged pairs (less `offset` when it was removed).
    chi2: f64,
    /// Pairs left out: a slice of the pair has no measured error.
    left_out: usize,
    /// Half the weighted mean of a_k − sign·a_(n−1−k): the uniform offset of the profile that
    /// breaks its symmetry (0 when not removed).
    offset: f64,
}

/// A profile against its mirror image about the mid-plane (`sign` −1 for an antisymmetric one)
/// over the pairs of slices k and n − 1 − k, with the pairs left out; with `less_offset`, the
/// uniform offset of the profile is fitted (weighted by the pairs' errors) and removed first,
/// one degree of freedom fewer (pairs without an error, such as two empty slices, keep their
/// difference as it is). A slice whose error is not zero but below round-off of its value
/// (blocks that differ only in their last bits: a slice the particles barely reach) has no
/// measured error; its pair is left out and counted rather than divided by a round-off error.
/// An error of exactly zero (identical blocks) keeps its meaning: any difference from the
/// mirror is then real.
fn mirror(values: &[f64], errors: &[f64], sign: f64, less_offset: bool) -> Mirror {
    let n = values.len();
    let unmeasured = |k: usize| errors[k] > 0.0 && errors[k] <= 1e-9 * values[k].abs();
    let (kept, left): (Vec<usize>, Vec<usize>) =
        (0..n / 2).partition(|&k| !(unmeasured(k) || unmeasured(n - 1 - k)));
    let pairs: Vec<(f64, f64)> = kept
        .iter()
        .map(|&k| {
            let d = values[k] - sign * values[n - 1 - k];
            (d, errors[k].powi(2) + errors[n - 1 - k].powi(2))
        })
        .collect();
    let (d, se): (Vec<f64>, Vec<f64>) = pairs
        .iter()
        .filter(|p| p.1 > 0.0)
        .map(|&(d, var)| (d, var.sqrt()))
        .unzip();
    let shift = if less_offset && !d.is_empty() {
        weighted_mean_chi2(&d, &se).0
    } else {
        0.0
    };
    let sum: f64 = pairs
        .iter()
        .map(|&(d, var)| {
            if var > 0.0 {
                (d - shift).powi(2) / var
            } else if d == 0.0 {
                0.0
            } else {
                f64::INFINITY
            }
        })
        .sum();
    let dof = pairs.len() as f64 - if less_offset { 1.0 } else { 0.0 };
    Mirror {
        chi2: sum / dof,
        left_out: left.len(),
        offset: shift / 2.0,
    }
}

/// Runs every check. `density` is the particle density (for the kinetic-theory check).
pub fn run(p: &Profiles, density: f64) -> Vec<Check> {
    let core = core_range(&p.grid);
    let cols: Vec<Vec<f64>> = p.mean.iter().map(columns).collect();
    let get = |name: &str| -> (Vec<f64>, Vec<f64>) {
        let c = col(name);
        (
            core.clone().map(|k| cols[k][c]).collect(),
            core.clone().map(|k| p.se[k][c]).collect(),
        )
    };
    let mut out = Vec::new();
    let (z0, z1) = (p.grid.z(core.start), p.grid.z(core.end - 1));
    let limit = 3.0;
    // One block gives no standard error: the checks against error bars are then reported only.
    let judged = p.blocks >= 2;
    let unjudged = if judged {
        ""
    } else {
        "; not judged: 1 block gives no error bar"
    };
    // A check by the errors of columns not calibrated at the in-run sampling is reported only.
    let by_errors_of = |names: &[&str]| -> (bool, &str) {
        if judged && !names.iter().all(|n| p.trusted[col(n)]) {
            (
                false,
                "; not judged: errors not calibrated at this sampling",
            )
        } else {
            (judged, unjudged)
        }
    };
    // 1. Momentum balance: shear stress and σzz uniform across the core.
    let (tau_mean, tau_chi) = {
        let (v, se) = get("shear_xz");
        weighted_mean_chi2(&v, &se)
    };
    let (judged_by, why) = by_errors_of(&["shear_xz"]);
    out.push(
        Verdict::judge(
            "",
            &format!("shear stress uniform for z in [{z0:.2}, {z1:.2}]"),
            tau_chi,
            Limit::Below(limit),
        )
        .judged_if(judged_by)
        .described(
            format!(
                "chi2/dof = {:.2} (mean {:.5})",
                Shown(tau_chi),
                Shown(tau_mean)
            ),
            format!("< {limit}{why}"),
        ),
    );
    let zz: Vec<f64> = core
        .clone()
        .map(|k| cols[k][col("kin_zz")] + cols[k][col("con_zz")])
        .collect();
    let zz_se: Vec<f64> = core
        .clone()
        .map(|k| (p.se[k][col("kin_zz")].powi(2) + p.se[k][col("con_zz")].powi(2)).sqrt())
        .collect();
    let (zz_mean, zz_chi) = weighted_mean_chi2(&zz, &zz_se);
    let (judged_by, why) = by_errors_of(&["kin_zz", "con_zz"]);
    out.push(
        Verdict::judge(
            "",
            &format!("sigma_zz uniform for z in [{z0:.2}, {z1:.2}]"),
            zz_chi,
            Limit::Below(limit),
        )
        .judged_if(judged_by)
        .described(
            format!(
                "chi2/dof = {:.2} (mean {:.5})",
                Shown(zz_chi),
                Shown(zz_mean)
            ),
            format!("< {limit}{why}"),
        ),
    );
    // 2. Wall consistency: σ·n at each wall equals the wall force per area. Top wall (normal
    // +z): σxz = F_top,x/A, σzz = F_top,z/A; bottom wall: σxz = −F_bot,x/A, σzz = −F_bot,z/A.
    // The wall forces are every step's when the run's diagnostics have the ledgers.
    let area = p.domain.lengths().x * p.domain.lengths().y;
    let blocks = p.blocks;
    let per_block = |f: &dyn Fn(usize) -> f64| -> (f64, f64) {
        let n = p.wall_force.len();
        let vals: Vec<f64> = (0..blocks)
            .map(|b| {
                let saves = block(b, blocks, n);
                let len = saves.len();
                saves.map(f).sum::<f64>() / len as f64
            })
            .collect();
        (
            vals.iter().sum::<f64>() / vals.len() as f64,
            standard_error(&vals),
        )
    };
    // The plain core means and their standard errors, from the same blocks of saves as the
    // profiles. Not the weighted means of the uniformity checks: a slice where few contacts
    // were caught has a small stress and a small error, so weights 1/SE² pull a weighted mean
    // of the snapshots' contact stress towards zero (a steady run's 20 saves gave a weighted
    // core σzz of 0.00108 against a plain 0.0073 and the walls' 0.0068).
    let plain_core = |f: &dyn Fn(&[f64]) -> f64| {
        core.clone().map(|k| f(&cols[k])).sum::<f64>() / core.len() as f64
    };
    let block_core = |f: &dyn Fn(&[f64]) -> f64| -> f64 {
        let vals: Vec<f64> = p
            .block_columns
            .iter()
            .map(|b| core.clone().map(|k| f(&b[k])).sum::<f64>() / core.len() as f64)
            .collect();
        standard_error(&vals)
    };
    let shear = |c: &[f64]| c[col("shear_xz")];
    let normal = |c: &[f64]| c[col("kin_zz")] + c[col("con_zz")];
    let (tau_core, tau_se) = (plain_core(&shear), block_core(&shear));
    let source = if p.wall_force_every_step {
        "wall forces: every step's mean over the saves' intervals"
    } else {
        "wall forces: at the saves"
    };
    let (zz_core, zz_core_se) = (plain_core(&normal), block_core(&normal));
    for (label, g, sign) in [("top", 1usize, 1.0), ("bottom", 0usize, -1.0)] {
        let (fx, fx_se) = per_block(&|s| sign * p.wall_force[s][g].x / area);
        let (fz, fz_se) = per_block(&|s| sign * p.wall_force[s][g].z / area);
        for (what, gap, wall, se_gap, se_wall) in [
            ("xz", tau_core, fx, tau_se, fx_se),
            ("zz", zz_core, fz, zz_core_se, fz_se),
        ] {
            let tol = 3.0 * (se_gap * se_gap + se_wall * se_wall).sqrt();
            out.push(
                Verdict::judge(
                    "",
                    &format!("sigma_{what} in the core = {label} wall force per area"),
                    gap - wall,
                    Limit::Absolute {
                        expected: 0.0,
                        tolerance: tol,
                    },
                )
                .judged_if(judged)
                .described(
                    format!("{:.5} vs {:.5} ({source})", Shown(gap), Shown(wall)),
                    format!("difference < 3 combined SE ({:.2e}){unjudged}", Shown(tol)),
                ),
            );
        }
    }
    // The shear stress the two walls transmit together, (F_top,x − F_bottom,x)/(2A): in a
    // steady state the x-momentum the top wall puts in leaves through the bottom one.
    let (fx, fx_se) = per_block(&|s| 0.5 * (p.wall_force[s][1].x - p.wall_force[s][0].x) / area);
    let tol = 3.0 * (tau_se * tau_se + fx_se * fx_se).sqrt();
    out.push(
        Verdict::judge(
            "",
            "sigma_xz in the core = (F_top,x - F_bottom,x)/2 per area",
            tau_core - fx,
            Limit::Absolute {
                expected: 0.0,
                tolerance: tol,
            },
        )
        .judged_if(judged)
        .described(
            format!("{:.5} vs {:.5} ({source})", Shown(tau_core), Shown(fx)),
            format!("difference < 3 combined SE ({:.2e}){unjudged}", Shown(tol)),
        ),
    );
    // 3. Mass: ∫ ν dz · Lx·Ly = Σ V_i, per save.
    let h = p.grid.h();
    let worst = p
        .per_save
        .iter()
        .map(|r| (r.nu.iter().sum::<f64>() * h * area - p.free_volume).abs() / p.free_volume)
        .fold(0.0, f64::max);
    let exact = matches!(p.kernel, super::kernel::Kernel::Heaviside { .. });
    let tol = if exact { 1e-12 } else { 1e-3 };
    out.push(
        Verdict::judge(
            "",
            &format!(
                "mass: integral of nu dz * Lx * Ly = {} free spheres' volume",
                p.free
            ),
            worst,
            Limit::Below(tol),
        )
        .described(
            format!(
                "max relative error {:.2e} over {} saves",
                Shown(worst),
                p.per_save.len()
            ),
            format!("< {tol:e}"),
        ),
    );
    // 4. Symmetry about the mid-plane. vx's is judged less its uniform offset, the bed's slow
    //    drift that no run's errors include, and the offset against that drift's measured size.
    for (name, sign) in [("nu", 1.0), ("T", 1.0), ("pressure", 1.0), ("vx", -1.0)] {
        let c = col(name);
        let values: Vec<f64> = cols.iter().map(|row| row[c]).collect();
        let errors: Vec<f64> = p.se.iter().map(|row| row[c]).collect();
        let drifts = sign < 0.0;
        let m = mirror(&values, &errors, sign, drifts);
        let unmeasured_note = if m.left_out > 0 {
            format!(
                ", {} pair(s) of slices without a measured error left out",
                m.left_out
            )
        } else {
            String::new()
        };
        let quantity = if drifts {
            format!("antisymmetric {name} about the mid-plane, less a uniform offset")
        } else {
            format!("symmetric {name} about the mid-plane")
        };
        let (judged_by, why) = by_errors_of(&[name]);
        out.push(
            Verdict::judge("", &quantity, m.chi2, Limit::Below(limit))
                .judged_if(judged_by)
                .described(
                    format!("chi2/dof = {:.2}{unmeasured_note}", Shown(m.chi2)),
                    format!("< {limit}{why}"),
                ),
        );
        if drifts {
            let tol = limit * BED_DRIFT_SD;
            out.push(
                Verdict::judge(
                    "",
                    &format!("{name}'s uniform offset within the bed's drift"),
                    m.offset.abs(),
                    Limit::Below(tol),
                )
                .judged_if(judged)
                .described(
                    format!(
                        "offset {:+.2e} (the bed's drift: standard deviation {BED_DRIFT_SD:.1e}, \
                         docs/statistics.md)",
                        Shown(m.offset)
                    ),
                    format!("|offset| < {tol:.2e}{unjudged}"),
                ),
            );
        }
    }
    // 5. Steadiness: no trend of the core's fluctuation energy ½ tr σ_kin across the blocks
    //    (its name starts with STEADY, which `unsteady_note` looks for).
    let energy: Vec<f64> = p
        .block_columns
        .iter()
        .map(|b| {
            core.clone()
                .map(|k| 0.5 * (b[k][col("kin_xx")] + b[k][col("kin_yy")] + b[k][col("kin_zz")]))
                .sum::<f64>()
                / core.len() as f64
        })
        .collect();
    let (change, t) = trend(&energy);
    out.push(
        Verdict::judge(
            "",
            &format!(
                "{STEADY} core fluctuation energy density has no trend across the {} blocks",
                energy.len()
            ),
            t.abs(),
            Limit::Below(3.0),
        )
        .judged_if(energy.len() >= 4)
        .described(
            format!(
                "linear change {:+.2} % over the saves, {:+.2} standard errors",
                Shown(100.0 * change),
                Shown(t)
            ),
            "|trend| < 3 standard errors (reported only with fewer than 4 blocks)".into(),
        ),
    );
    // 6. Kinetic theory: p/(ρp ν T) against 1 + 2(1+e) ν g0(ν), Carnahan–Starling g0 (reported).
    let e = 0.902;
    let ratios: Vec<f64> = core
        .clone()
        .filter(|&k| p.mean[k].temperature > 0.0 && p.mean[k].nu > 0.0)
        .map(|k| {
            let d = &p.mean[k];
            let g0 = (2.0 - d.nu) / (2.0 * (1.0 - d.nu).powi(3));
            let theory = 1.0 + 2.0 * (1.0 + e) * d.nu * g0;
            d.pressure / (density * d.nu * d.temperature) / theory
        })
        .collect();
    let mean_ratio = ratios.iter().sum::<f64>() / ratios.len().max(1) as f64;
    out.push(
        Verdict::reported(
            "",
            "kinetic theory p/(rho_p nu T) / (1 + 2(1+e) nu g0), core mean",
            mean_ratio,
            Limit::Relative {
                expected: 1.0,
                tolerance: 0.2,
            },
        )
        .described(
            format!("{:.3}", Shown(mean_ratio)),
            "about 1 (within ~20%; reported only)".into(),
        ),
    );
    out
}

/// One line of a checks report: PASS, FAIL or info, what was judged, the measurement and
/// what was expected.
pub fn line(c: &Check) -> String {
    format!(
        "{:4}  {}: {} (expected {})\n",
        result(c),
        c.quantity,
        c.measured_text,
        c.expected_text
    )
}

/// The report's word for `c`: `PASS`, `FAIL` or `info` (undecided or not judged).
pub fn result(c: &Check) -> &'static str {
    match c.pass() {
        Some(true) => "PASS",
        Some(false) => "FAIL",
        None => "info",
    }
}

/// A plain-text table of the checks, with the averaging facts a reviewer needs.
pub fn report(p: &Profiles, checks: &[Check]) -> String {
    let block_len = p.saves.len() as f64 / p.blocks as f64;
    let tau = p.tau_shear.max(p.tau_energy);
    let independence = if tau.is_nan() {
        "integrated autocorrelation time not estimated (fewer than 4 saves)".to_string()
    } else {
        let independent = block_len >= 2.0 * tau;
        format!(
            "integrated autocorrelation time {:.2} saves (shear), {:.2} (kinetic energy): blocks {} independent (block length {} 2 tau)",
            Shown(p.tau_shear),
            Shown(p.tau_energy),
            if independent { "are" } else { "are NOT" },
            if independent { ">=" } else { "<" },
        )
    };
    let mut s = format!(
        "saves {}..{} ({}), kernel {:?}, {} slices, {} blocks of {:.1} saves; {independence}\n",
        p.saves.first().unwrap_or(&0),
        p.saves.last().unwrap_or(&0),
        p.saves.len(),
        p.kernel,
        p.grid.n,
        p.blocks,
        block_len,
    );
    for c in checks {
        s.push_str(&line(c));
    }
    if let Some(note) = unsteady_note(checks) {
        s.push_str(note);
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::{mirror, unsteady_note, Limit, Shown, Verdict, STEADY};

    #[test]
    fn a_number_that_is_not_finite_is_written_as_a_word() {
        assert_eq!(format!("{:.2}", Shown(1.234)), "1.23");
        assert_eq!(format!("{:.2e}", Shown(1234.0)), "1.23e3");
        for x in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            assert_eq!(
                format!("{:.2} {:.2e}", Shown(x), Shown(x)),
                "undefined undefined"
            );
        }
    }

    #[test]
    fn only_a_failed_steadiness_check_adds_the_note() {
        let check = |name: &str, pass: Option<bool>| {
            let measured = if pass == Some(false) { 5.0 } else { 1.0 };
            Verdict::judge("", name, measured, Limit::Below(3.0)).judged_if(pass.is_some())
        };
        let steady = |pass| check(&format!("{STEADY} trend"), pass);
        let uniform = check("sigma_zz uniform", Some(false));
        assert!(unsteady_note(&[uniform, steady(Some(false))]).is_some());
        for pass in [Some(true), None] {
            assert_eq!(unsteady_note(&[steady(pass)]), None);
        }
        assert_eq!(
            unsteady_note(&[check("sigma_zz uniform", Some(false))]),
            None
        );
    }

    #[test]
    fn a_slice_without_a_measured_error_is_left_out_of_the_mirror_check() {
        // six slices; slice 0 is barely reached: a value with an error of round-off
        let values = [0.0107, 1.0, 2.0, 2.1, 1.1, 0.001];
        let errors = [3e-19, 0.1, 0.1, 0.1, 0.1, 2e-4];
        let m = mirror(&values, &errors, 1.0, false);
        assert_eq!(m.left_out, 1);
        assert!((m.chi2 - 0.5).abs() < 1e-9, "{m:?}");
        // with a measured error the same slice is judged, and fails
        let measured = [1e-4, 0.1, 0.1, 0.1, 0.1, 2e-4];
        let m = mirror(&values, &measured, 1.0, false);
        assert_eq!(m.left_out, 0);
        assert!(m.chi2 > 100.0, "{m:?}");
        // an error of exactly zero is identical blocks: the asymmetry is real
        let exact = [0.0, 0.1, 0.1, 0.1, 0.1, 0.0];
        let m = mirror(&values, &exact, 1.0, false);
        assert_eq!(m.left_out, 0);
        assert!(m.chi2.is_infinite(), "{m:?}");
        // antisymmetric: -v mirrors v
        let m = mirror(&[-1.0, 0.5, -0.5, 1.0], &[0.1; 4], -1.0, false);
        assert!(m.chi2 < 1e-12, "{m:?}");
    }

    #[test]
    fn a_uniform_offset_breaks_antisymmetry_and_is_measured_apart() {
        // an antisymmetric profile shifted by 0.03, errors 0.01: far from its mirror image
        let values: Vec<f64> = [-1.0, -0.5, -0.1, 0.1, 0.5, 1.0]
            .iter()
            .map(|v| v + 0.03)
            .collect();
        let errors = [0.01; 6];
        assert!(mirror(&values, &errors, -1.0, false).chi2 > 10.0);
        // less the offset it is antisymmetric, and the offset is the shift
        let m = mirror(&values, &errors, -1.0, true);
        assert!(m.chi2 < 1e-20, "{m:?}");
        assert!((m.offset - 0.03).abs() < 1e-12, "{m:?}");
        // empty slices at both ends (value and error 0) take no offset
        let mut padded = vec![0.0];
        padded.extend(&values);
        padded.push(0.0);
        let mut padded_errors = vec![0.0];
        padded_errors.extend(errors);
        padded_errors.push(0.0);
        let m = mirror(&padded, &padded_errors, -1.0, true);
        assert!(m.chi2 < 1e-20, "{m:?}");
        // an asymmetry that is not uniform stays in the shape and fails the check (< 3)
        let mut tilted = values.clone();
        tilted[0] += 0.05;
        let m = mirror(&tilted, &errors, -1.0, true);
        assert!(m.chi2 > 3.0, "{m:?}");
    }
}
