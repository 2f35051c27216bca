//! The ledgers' checks of a run (`checks.txt`, "ledgers"), from the ledger columns of its
//! diagnostics table ([`crate::io::diagnostics`]) over the saves of the profiles: in a steady
//! state the walls' (and gravity's) power equals the contacts' dissipation rate; the energy
//! ledger's residual per save is within [`RESIDUAL_TOLERANCE`] of the energy that went through;
//! the momentum ledger closes to round-off ([`MOMENTUM_TOLERANCE`]).

use std::path::Path;

use super::stats::{block_standard_error, blocks_for, integrated_autocorrelation};
use super::{Limit, Verdict};
use crate::io::diagnostics::{read_ledgers, LedgerRecord};

/// Largest |residual| of the energy ledger over a save interval, relative to the energy that
/// went through the free particles (|W_walls| + |W_gravity| + D_n + D_t + D_slide).
///
/// Derivation: the residual is first order in dt (`tests/ledger.rs`). Its leading term is the
/// dashpot's: the law reports γn·vn²·dt at the half-step velocity the force is evaluated with,
/// while the force acts over the two half kicks around it; over a collision the difference sums
/// to γn·dt·(vn_in² − vn_out²)/4, which is γn·dt/(2·m_eff) of the energy the collision
/// dissipates (½·m_eff·(vn_in² − vn_out²)). For the benchmark (γn = 15, dt = 7.19e-5, a
/// free–free m_eff = m/2 = π/12) that is 2.1e-3 of the dissipation, about 1e-3 of the
/// throughput (1.2e-3 measured over 1000 steps from the steady state); the tangential dashpot
/// adds a term of the same kind. The tolerance is ten times that: a law that misreports its
/// dissipation by a few per cent, a work that is lost or counted twice, or a scheme out of its
/// stable range exceeds it (a 10 % misreport gives 4e-2: `tests/ledger.rs`), while dt up to
/// several times the benchmark's passes.
pub const RESIDUAL_TOLERANCE: f64 = 1e-2;

/// Largest |momentum residual| over a save interval, relative to the walls' impulse
/// (|F_bottom| + |F_top|)·Δt. The residual is round-off: each step adds each contact's force
/// to two particles in a different order, an error of about 2⁻⁵³ of the force per particle and
/// step, so over S steps of N particles at most N·2⁻⁵³ of the impulse when every error has the
/// same sign (4e-13 for the benchmark's 3480 particles); 1e-9 leaves room for the fixed-point
/// truncations and the momentum's own rounding, and is far below a missing half step at an end
/// of the interval (about 1/S: 2e-5 at a save every 50000 steps).
pub const MOMENTUM_TOLERANCE: f64 = 1e-9;

/// One interval of the ledgers: its row and its duration (time).
struct Interval<'a> {
    row: &'a crate::step::LedgerRow,
    duration: f64,
}

/// The intervals ending at the saves `saves` that have a ledger and whose previous save is in
/// the table (its duration is the difference of their times).
fn intervals<'a>(records: &'a [LedgerRecord], saves: &[u64]) -> Vec<Interval<'a>> {
    records
        .windows(2)
        .filter(|w| w[1].save == w[0].save + 1 && saves.contains(&w[1].save))
        .filter_map(|w| {
            let row = w[1].ledger.as_ref()?;
            let duration = w[1].time - w[0].time;
            (duration > 0.0).then_some(Interval { row, duration })
        })
        .collect()
}

/// The ledgers' verdicts over the intervals ending at `saves` (the profiles' saves) of the
/// diagnostics `records`.
pub fn checks(records: &[LedgerRecord], saves: &[u64]) -> Vec<Verdict> {
    let iv = intervals(records, saves);
    let mut out = Vec::new();
    if iv.is_empty() {
        return out;
    }
    let split = iv.iter().all(|i| i.row.dissipated.is_some());
    // 1. Steady state: wall (and gravity) power against the dissipation rate.
    if split {
        let power: Vec<f64> = iv
            .iter()
            .map(|i| (i.row.work_walls + i.row.work_gravity) / i.duration)
            .collect();
        let rate: Vec<f64> = iv
            .iter()
            .map(|i| i.row.dissipated.unwrap_or_default().iter().sum::<f64>() / i.duration)
            .collect();
        let gap: Vec<f64> = power.iter().zip(&rate).map(|(p, d)| p - d).collect();
        let (blocks, long) = blocks_for(gap.len(), integrated_autocorrelation(&gap));
        let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
        let (se_p, se_d, se_gap) = (
            block_standard_error(&power, blocks),
            block_standard_error(&rate, blocks),
            block_standard_error(&gap, blocks),
        );
        let tol = 3.0 * se_gap;
        let judged = blocks >= 2 && se_gap > 0.0;
        let caveat = match (judged, long) {
            (false, _) => "; not judged: too few saves for an error bar",
            (true, false) => "; blocks shorter than the correlation asks: the SE is low",
            (true, true) => "",
        };
        out.push(
            Verdict::judge(
                "",
                "ledgers: wall and gravity power = dissipation rate (steady state)",
                mean(&gap),
                Limit::Absolute {
                    expected: 0.0,
                    tolerance: tol,
                },
            )
            .judged_if(judged)
            .described(
                format!(
                    "{:.6e} ± {:.1e} vs {:.6e} ± {:.1e} energy/time (mean ± SE over {} \
                     intervals, {blocks} blocks)",
                    mean(&power),
                    se_p,
                    mean(&rate),
                    se_d,
                    iv.len()
                ),
                format!("difference < 3 SE of the difference ({tol:.2e}){caveat}"),
            ),
        );
    }
    // 2. The energy ledger's residual per save.
    if split {
        let worst = iv
            .iter()
            .map(|i| {
                let r = i.row;
                let d: f64 = r
                    .dissipated
                    .unwrap_or_default()
                    .iter()
                    .map(|x| x.abs())
                    .sum();
                let through = r.work_walls.abs() + r.work_gravity.abs() + d;
                r.residual.unwrap_or(f64::INFINITY).abs() / through
            })
            .fold(0.0, f64::max);
        out.push(
            Verdict::judge(
                "",
                "energy ledger: largest |residual| per save / energy throughput",
                worst,
                Limit::Below(RESIDUAL_TOLERANCE),
            )
            .described(
                format!("{worst:.3e} over {} intervals", iv.len()),
                format!(
                    "< {RESIDUAL_TOLERANCE:e}: ten times the first-order dashpot term \
                     γn·dt/(2 m_eff) of the benchmark (src/analysis/ledger.rs)"
                ),
            ),
        );
    } else {
        out.push(
            Verdict::reported("", "energy ledger: residual", f64::NAN, Limit::Below(0.0))
                .described(
                    "not measured".into(),
                    "a contact law that splits its dissipation (this one reports it as \
                     unsplit: the ledger cannot close)"
                        .into(),
                ),
        );
    }
    // 3. The momentum ledger's residual per save.
    let ratios: Vec<f64> = iv
        .iter()
        .filter_map(|i| {
            let [b, t] = i.row.mean_wall_force;
            let impulse = (b.norm() + t.norm()) * i.duration;
            (impulse > 0.0).then(|| i.row.momentum_residual.amax() / impulse)
        })
        .collect();
    let worst = ratios.iter().copied().fold(0.0, f64::max);
    out.push(
        Verdict::judge(
            "",
            "momentum ledger: largest |residual| per save / walls' impulse",
            worst,
            Limit::Below(MOMENTUM_TOLERANCE),
        )
        .judged_if(!ratios.is_empty())
        .described(
            format!("{worst:.3e} over {} intervals", ratios.len()),
            format!("< {MOMENTUM_TOLERANCE:e}: round-off (src/analysis/ledger.rs)"),
        ),
    );
    out
}

/// The ledger section of `checks.txt` for the run `dir/name` over the profiles' `saves`: a
/// heading line, then one line per verdict as the other checks print them; a note instead when
/// the run has no diagnostics table or a table without ledgers. Also returns the verdicts (none
/// with a note).
pub fn section(dir: &Path, name: &str, saves: &[u64]) -> anyhow::Result<(String, Vec<Verdict>)> {
    let path = dir.join(format!("{name}.diagnostics.csv"));
    let mut s = String::from("ledgers (every step, from the diagnostics' ledger columns):\n");
    if !path.exists() {
        s.push_str("info  no diagnostics table: no ledgers\n");
        return Ok((s, Vec::new()));
    }
    let Some(records) = read_ledgers(&path)? else {
        s.push_str("info  the diagnostics table has no ledger columns (an older run)\n");
        return Ok((s, Vec::new()));
    };
    let verdicts = checks(&records, saves);
    if verdicts.is_empty() {
        s.push_str("info  no ledger over these saves (a run's first save has none)\n");
    }
    for c in &verdicts {
        s.push_str(&crate::analysis::cg::checks::line(c));
    }
    Ok((s, verdicts))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::step::LedgerRow;
    use crate::Vec3;

    fn record(save: u64, residual: f64, momentum: f64) -> LedgerRecord {
        LedgerRecord {
            save,
            step: save * 10,
            time: save as f64,
            ledger: Some(LedgerRow {
                work_walls: 2.0,
                work_gravity: 0.0,
                dissipated: Some([1.0, 0.5, 0.5]),
                d_trans: 0.0,
                d_rot: 0.0,
                d_elastic: 0.0,
                residual: Some(residual),
                mean_wall_force: [Vec3::new(1.0, 0.0, 0.0), Vec3::new(-1.0, 0.0, 0.0)],
                momentum_residual: Vec3::new(momentum, 0.0, 0.0),
            }),
        }
    }

    #[test]
    fn a_residual_beyond_the_tolerance_fails_and_one_within_passes() {
        let verdicts = |residual: f64, momentum: f64| {
            let records: Vec<_> = (0..6).map(|k| record(k, residual, momentum)).collect();
            checks(&records, &[1, 2, 3, 4, 5])
        };
        let find = |v: &[Verdict], what: &str| {
            v.iter()
                .find(|c| c.quantity.starts_with(what))
                .unwrap()
                .pass()
        };
        let good = verdicts(1e-4, 1e-12);
        assert_eq!(find(&good, "energy ledger"), Some(true));
        assert_eq!(find(&good, "momentum ledger"), Some(true));
        // throughput 4: a residual of 0.1 is 2.5e-2 of it
        let bad = verdicts(0.1, 1e-6);
        assert_eq!(find(&bad, "energy ledger"), Some(false));
        assert_eq!(find(&bad, "momentum ledger"), Some(false));
    }
}
