//! Profiles of several codes or runs against a reference, over the core: per benchmark profile,
//! the χ²/dof of the difference in units of the combined standard error (≈ 1: noise; ≫ 1:
//! bias, or errors that miss slow fluctuations) and the difference of the core means relative
//! to the reference's mean magnitude (how large a systematic difference is; the slices' noise
//! averages down in it). For vx also the χ²/dof with the common offset removed and that offset:
//! the bed's slow drift shifts the velocity profile as a whole (docs/statistics.md).

use std::fmt::Write;

use super::checks::Shown;
use super::table::{chi2, shape, Shape, Table};
use super::{core_window, FIELDS};

/// One table against the reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub name: String,
    /// χ²/dof of each profile of [`FIELDS`] against the reference, core slices only; NaN
    /// (undefined) when neither table has an error bar on that profile there.
    pub chi2: [f64; 5],
    /// Σ(a − ref) / Σ|ref| of each profile over the core slices (dimensionless, signed).
    pub rel_mean: [f64; 5],
    /// vx against the reference less their common offset ([`shape`]).
    pub vx_shape: Shape,
}

/// Σ(a − b) / Σ|b| of column `col` over the grid points with z in `window`: the difference of
/// the core means relative to `b`'s mean magnitude; the tables must share the grid (checked by
/// [`chi2`]).
fn relative_mean_difference(a: &Table, b: &Table, col: usize, window: (f64, f64)) -> f64 {
    let (mut diff, mut norm) = (0.0, 0.0);
    for k in 0..a.z.len() {
        if (window.0..=window.1).contains(&a.z[k]) {
            diff += a.mean[k][col] - b.mean[k][col];
            norm += b.mean[k][col].abs();
        }
    }
    if norm > 0.0 {
        diff / norm
    } else {
        0.0
    }
}

/// Whether `a` or `b` has an error bar in column `col` at a grid point with z in `window`: a
/// combined variance se_a² + se_b² above 0 (what [`chi2`] divides by).
fn has_error_bars(a: &Table, b: &Table, col: usize, window: (f64, f64)) -> bool {
    (0..a.z.len()).any(|k| {
        (window.0..=window.1).contains(&a.z[k]) && a.se[k][col].powi(2) + b.se[k][col].powi(2) > 0.0
    })
}

/// Compares each of `others` with `reference` over the core of the reference's grid. A χ² is
/// undefined (NaN) where neither table has error bars; an error names the table and the
/// profile when a result that should be a number is not a finite one (values too large to
/// square or add).
pub fn compare(reference: &Table, others: &[(String, Table)]) -> anyhow::Result<Vec<Comparison>> {
    let window = core_window(&reference.grid()?);
    others
        .iter()
        .map(|(name, t)| {
            let mut c = Comparison {
                name: name.clone(),
                chi2: [f64::NAN; 5],
                rel_mean: [0.0; 5],
                vx_shape: shape(t, reference, FIELDS[0].1, window)?,
            };
            let too_large = |field: &str, what: &str, v: f64| {
                anyhow::anyhow!(
                    "{name}: the {what} of {field} against the reference is {v}, not a finite \
                     number: the tables' values are too large to compare"
                )
            };
            for (f, &(field, col)) in FIELDS.iter().enumerate() {
                if has_error_bars(t, reference, col, window) {
                    c.chi2[f] = chi2(t, reference, col, window)?;
                    if !c.chi2[f].is_finite() {
                        return Err(too_large(field, "χ²", c.chi2[f]));
                    }
                }
                c.rel_mean[f] = relative_mean_difference(t, reference, col, window);
                if !c.rel_mean[f].is_finite() {
                    return Err(too_large(
                        field,
                        "difference of the core means",
                        c.rel_mean[f],
                    ));
                }
            }
            for (what, v) in [
                ("χ² less the offset", c.vx_shape.chi2),
                ("common offset", c.vx_shape.offset),
            ] {
                if v.is_infinite() {
                    return Err(too_large("vx", what, v));
                }
            }
            Ok(c)
        })
        .collect()
}

/// The comparisons as a markdown table, one row per table.
pub fn markdown(reference: &str, rows: &[Comparison]) -> String {
    let names: Vec<&str> = FIELDS.iter().map(|(n, _)| *n).collect();
    let mut s = format!(
        "Against `{reference}`, core slices: χ²/dof (1 = noise) | difference of the core means \
         relative to the reference's | vx less the common offset of the two profiles: χ²/dof, and \
         that offset\n\n\
         | profiles | {} | {} | χ² vx less offset | vx offset |\n|---|{}\n",
        names
            .iter()
            .map(|n| format!("χ² {n}"))
            .collect::<Vec<_>>()
            .join(" | "),
        names
            .iter()
            .map(|n| format!("Δ {n}"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(2 * names.len() + 2)
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {:+.2e} |",
            r.name,
            r.chi2
                .iter()
                .map(|c| format!("{:.2}", Shown(*c)))
                .collect::<Vec<_>>()
                .join(" | "),
            r.rel_mean
                .iter()
                .map(|c| format!("{:+.2} %", 100.0 * c))
                .collect::<Vec<_>>()
                .join(" | "),
            Shown(r.vx_shape.chi2),
            Shown(r.vx_shape.offset)
        );
    }
    for r in rows {
        let undefined: Vec<&str> = FIELDS
            .iter()
            .zip(&r.chi2)
            .filter(|(_, c)| c.is_nan())
            .map(|((n, _), _)| *n)
            .collect();
        if undefined.is_empty() {
            continue;
        }
        let (f, largest) = r
            .rel_mean
            .iter()
            .enumerate()
            .filter(|(f, _)| undefined.contains(&FIELDS[*f].0))
            // the first of equal differences
            .rev()
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .expect("an undefined χ²");
        let which = if undefined.len() == FIELDS.len() {
            "χ² undefined".to_string()
        } else {
            format!("χ² of {} undefined", undefined.join(", "))
        };
        let _ = write!(
            s,
            "\n`{}`: {which}: no error bars in either table. Without them no difference can be \
             told from noise: no pass. What can be said: the largest difference of the core \
             means there is {:+.2} % ({}).\n",
            r.name,
            100.0 * largest,
            FIELDS[f].0
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::cg::COLUMNS;

    /// A 100-slice table over [0, 22] whose every column is `value` with standard error `se`.
    fn flat(value: f64, se: f64) -> Table {
        let z: Vec<f64> = (0..100).map(|k| (k as f64 + 0.5) * 0.22).collect();
        Table {
            mean: z.iter().map(|_| vec![value; COLUMNS.len()]).collect(),
            se: z.iter().map(|_| vec![se; COLUMNS.len()]).collect(),
            z,
        }
    }

    #[test]
    fn a_shift_of_one_combined_error_gives_chi2_one_and_its_relative_size() {
        let reference = flat(2.0, 0.03);
        let shifted = flat(2.0 + 0.03 * 2f64.sqrt(), 0.03);
        let rows = compare(&reference, &[("shifted".into(), shifted)]).unwrap();
        for f in 0..5 {
            assert!((rows[0].chi2[f] - 1.0).abs() < 1e-9, "{:?}", rows[0]);
            assert!((rows[0].rel_mean[f] - 0.03 * 2f64.sqrt() / 2.0).abs() < 1e-12);
        }
        // the shift is the common offset: nothing is left in vx's shape
        assert!(rows[0].vx_shape.chi2.abs() < 1e-12, "{:?}", rows[0]);
        assert!((rows[0].vx_shape.offset - 0.03 * 2f64.sqrt()).abs() < 1e-12);
        let md = markdown("ref", &rows);
        assert!(md.contains("| shifted | 1.00 |"), "{md}");
        assert!(md.contains("| 0.00 | +4.24e-2 |"), "{md}");
    }

    #[test]
    fn only_the_core_counts() {
        let reference = flat(1.0, 0.1);
        let mut near_walls = flat(1.0, 0.1);
        for k in (0..13).chain(87..100) {
            near_walls.mean[k] = vec![5.0; COLUMNS.len()];
        }
        let rows = compare(&reference, &[("walls".into(), near_walls)]).unwrap();
        assert_eq!(rows[0].chi2, [0.0; 5]);
        assert_eq!(rows[0].rel_mean, [0.0; 5]);
    }

    #[test]
    fn profiles_without_errors_give_no_chi2_no_offset_and_no_nan() {
        let rows = compare(&flat(1.0, 0.0), &[("exact".into(), flat(1.5, 0.0))]).unwrap();
        assert!(rows[0].vx_shape.offset.is_nan(), "{:?}", rows[0]);
        assert!(rows[0].chi2.iter().all(|c| c.is_nan()), "{:?}", rows[0]);
        let md = markdown("ref", &rows);
        assert!(md.contains("| exact | undefined | undefined |"), "{md}");
        assert!(md.contains("| undefined | undefined |"), "{md}");
        assert!(
            md.contains("`exact`: χ² undefined: no error bars in either table."),
            "{md}"
        );
        assert!(md.contains("+50.00 % (vx)"), "{md}");
        assert!(!md.contains("NaN") && !md.contains("0.00 |"), "{md}");
    }

    #[test]
    fn values_too_large_to_square_are_refused() {
        let e = compare(&flat(1.0, 1e-100), &[("huge".into(), flat(1e200, 1e-100))])
            .unwrap_err()
            .to_string();
        assert!(e.contains("huge: the χ² of vx") && e.contains("inf"), "{e}");
    }
}
