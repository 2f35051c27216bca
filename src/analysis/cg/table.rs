//! Profiles as a table of numbers: written as CSV, read back (golden peer profiles are stored
//! this way), and compared slice by slice against their combined standard errors.

use crate::analysis::stats::{mean_chi2, weighted_mean_chi2};
use crate::io::{csv_table, read_text, FormatError};

use super::{columns, Grid, Profiles, COLUMNS};

/// Profiles at grid points `z`: for each point, every column of [`COLUMNS`] and its standard
/// error.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub z: Vec<f64>,
    pub mean: Vec<Vec<f64>>,
    pub se: Vec<Vec<f64>>,
}

impl Table {
    /// The table of coarse-grained profiles.
    pub fn of(p: &Profiles) -> Table {
        Table {
            z: (0..p.grid.n).map(|k| p.grid.z(k)).collect(),
            mean: p.mean.iter().map(columns).collect(),
            se: p.se.clone(),
        }
    }

    /// The grid of the table's points: uniform slices with the points at their centres, as
    /// [`Table::of`] writes them (at least two points).
    pub fn grid(&self) -> anyhow::Result<Grid> {
        let n = self.z.len();
        anyhow::ensure!(n >= 2, "a profiles table needs two grid points, it has {n}");
        let h = (self.z[n - 1] - self.z[0]) / (n - 1) as f64;
        Ok(Grid {
            z0: self.z[0] - h / 2.0,
            z1: self.z[n - 1] + h / 2.0,
            n,
        })
    }

    /// The first number of the table that is NaN or infinite, as (its row from 0, the name of
    /// its field as in the CSV's header, the number); `None` when all are finite.
    pub fn first_non_finite(&self) -> Option<(usize, String, f64)> {
        (0..self.z.len()).find_map(|k| {
            let pairs = self.mean[k].iter().zip(&self.se[k]);
            std::iter::once(self.z[k])
                .chain(pairs.flat_map(|(v, e)| [*v, *e]))
                .enumerate()
                .find(|(_, v)| !v.is_finite())
                .map(|(col, v)| (k, field_name(col), v))
        })
    }

    /// An error when a number of the table is NaN or infinite, naming `what` the table is, the
    /// field, its z and the number; `why` says what made it so.
    pub fn ensure_finite(&self, what: &str, why: &str) -> anyhow::Result<()> {
        match self.first_non_finite() {
            None => Ok(()),
            Some((k, field, v)) => anyhow::bail!(
                "{what}: {field} at z = {} is {v}, not a finite number ({why}); nothing written",
                self.z[k]
            ),
        }
    }

    /// The CSV text: z, then every column of [`COLUMNS`] followed by its standard error.
    pub fn csv(&self) -> String {
        csv_table::write(
            header(),
            (0..self.z.len()).map(|k| {
                let pairs = self.mean[k].iter().zip(&self.se[k]);
                std::iter::once(self.z[k]).chain(pairs.flat_map(|(v, e)| [*v, *e]))
            }),
        )
    }

    /// Reads a table written by [`Table::csv`]; a wrong header or a bad number is reported
    /// with the file, line and column.
    pub fn read(path: &std::path::Path) -> Result<Table, FormatError> {
        let (file, text) = read_text(path)?;
        let fail = |line: usize, msg: String| FormatError {
            file: file.clone(),
            line,
            msg,
        };
        let mut records = csv_table::records(&file, &text, false);
        match records.next().transpose()? {
            Some((1, names)) if names.iter().eq(header()) => {}
            _ => return Err(fail(1, "not a profiles table (unexpected header)".into())),
        }
        let mut table = Table {
            z: Vec::new(),
            mean: Vec::new(),
            se: Vec::new(),
        };
        for record in records {
            let (line_no, record) = record?;
            let row: Vec<f64> = record.deserialize(None).map_err(|e| {
                let col = match e.kind() {
                    csv::ErrorKind::Deserialize { err, .. } => err.field().unwrap_or(0) as usize,
                    _ => 0,
                };
                let tok = record.get(col).unwrap_or_default();
                fail(
                    line_no,
                    format!("field {}: not a number: {tok:?}", field_name(col)),
                )
            })?;
            if let Some(col) = row.iter().position(|v| !v.is_finite()) {
                return Err(fail(
                    line_no,
                    format!("field {}: not finite: {:?}", field_name(col), &record[col]),
                ));
            }
            if row.len() != 1 + 2 * COLUMNS.len() {
                return Err(fail(
                    line_no,
                    format!("{} fields, expected {}", row.len(), 1 + 2 * COLUMNS.len()),
                ));
            }
            table.z.push(row[0]);
            table
                .mean
                .push(row[1..].iter().step_by(2).copied().collect());
            table.se.push(row[2..].iter().step_by(2).copied().collect());
        }
        if table.z.is_empty() {
            return Err(fail(2, "no rows".into()));
        }
        Ok(table)
    }
}

/// The names of the CSV's fields: z, then each column of [`COLUMNS`] and its standard error.
fn header() -> Vec<String> {
    (0..1 + 2 * COLUMNS.len()).map(field_name).collect()
}

/// The name of field `col` (from 0) of a profiles table; fields past the last are named as the
/// last.
fn field_name(col: usize) -> String {
    if col == 0 {
        return "z".into();
    }
    let c = COLUMNS[(col - 1).min(COLUMNS.len() * 2 - 1) / 2];
    if col % 2 == 1 {
        c.to_string()
    } else {
        format!("{c}_se")
    }
}

/// χ²/dof of column `col` of `a` against `b` over the grid points with z in `window`: the mean
/// of (a − b)²/(se_a² + se_b²), ≈ 1 when they differ by noise only. Both tables must have the
/// same grid.
pub fn chi2(a: &Table, b: &Table, col: usize, window: (f64, f64)) -> anyhow::Result<f64> {
    Ok(mean_chi2(differences(a, b, col, window)?))
}

/// How two profiles differ apart from a uniform shift ([`shape`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    /// χ²/dof of the difference less `offset` (one degree of freedom fewer than the points).
    pub chi2: f64,
    /// The common offset a − b: the mean difference weighted by 1/(se_a² + se_b²).
    pub offset: f64,
    /// Its standard error from the points' errors, (Σ 1/(se_a² + se_b²))^(−1/2), which takes
    /// the points as independent (neighbouring slices are not: it is a lower bound).
    pub offset_se: f64,
}

/// [`chi2`] after removing the common offset of the two profiles, and that offset: the shape
/// test for a profile whose level drifts as a whole, as vx does with the bed's slow drift
/// (docs/statistics.md). NaN χ² for fewer than two points with an error, NaN offset for none.
pub fn shape(a: &Table, b: &Table, col: usize, window: (f64, f64)) -> anyhow::Result<Shape> {
    let (d, se): (Vec<f64>, Vec<f64>) = differences(a, b, col, window)?
        .filter(|&(_, var)| var > 0.0)
        .map(|(d, var)| (d, var.sqrt()))
        .unzip();
    let (offset, chi2) = weighted_mean_chi2(&d, &se);
    Ok(Shape {
        chi2: if d.len() < 2 { f64::NAN } else { chi2 },
        offset,
        offset_se: se.iter().map(|s| s.powi(-2)).sum::<f64>().sqrt().recip(),
    })
}

/// (a − b, se_a² + se_b²) of column `col` at the grid points with z in `window`; an error when
/// the tables' grids differ.
fn differences<'t>(
    a: &'t Table,
    b: &'t Table,
    col: usize,
    window: (f64, f64),
) -> anyhow::Result<impl Iterator<Item = (f64, f64)> + 't> {
    anyhow::ensure!(
        a.z.len() == b.z.len() && a.z.iter().zip(&b.z).all(|(x, y)| (x - y).abs() < 1e-9),
        "the profiles are on different grids ({} and {} points)",
        a.z.len(),
        b.z.len()
    );
    Ok((0..a.z.len())
        .filter(move |&k| !(a.z[k] < window.0 || a.z[k] > window.1))
        .map(move |k| {
            (
                a.mean[k][col] - b.mean[k][col],
                a.se[k][col].powi(2) + b.se[k][col].powi(2),
            )
        }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(shift: f64) -> Table {
        let z: Vec<f64> = (0..10).map(|k| k as f64 + 0.5).collect();
        Table {
            mean: z
                .iter()
                .map(|z| (0..COLUMNS.len()).map(|c| z * c as f64 + shift).collect())
                .collect(),
            se: z.iter().map(|_| vec![0.5; COLUMNS.len()]).collect(),
            z,
        }
    }

    #[test]
    fn tables_round_trip_and_chi2_sees_a_shift() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.csv");
        std::fs::write(&path, table(0.0).csv()).unwrap();
        let back = Table::read(&path).unwrap();
        assert_eq!(back, table(0.0));
        assert_eq!(chi2(&back, &table(0.0), 3, (0.0, 10.0)).unwrap(), 0.0);
        // a shift of one combined standard error (√0.5) gives χ²/dof = 1 on every point
        let one = chi2(&back, &table(0.5f64.sqrt()), 3, (2.0, 8.0)).unwrap();
        assert!((one - 1.0).abs() < 1e-12, "{one}");
    }

    #[test]
    fn the_shape_test_removes_a_uniform_shift_but_not_a_tilt() {
        // a uniform shift of 3 combined errors: χ² 9 per point, none left in the shape
        let shifted = table(3.0 * 0.5f64.sqrt());
        let s = shape(&shifted, &table(0.0), 3, (0.0, 10.0)).unwrap();
        assert!(s.chi2.abs() < 1e-20, "{s:?}");
        assert!((s.offset - 3.0 * 0.5f64.sqrt()).abs() < 1e-12, "{s:?}");
        // ten points of variance 0.5: the offset's error is √(0.5/10)
        assert!((s.offset_se - 0.05f64.sqrt()).abs() < 1e-12, "{s:?}");
        // a tilt of ±1 combined error about the middle stays in the shape: χ² over 9 dof
        let mut tilted = table(0.0);
        for (k, row) in tilted.mean.iter_mut().enumerate() {
            row[3] += if k < 5 { -1.0 } else { 1.0 } * 0.5f64.sqrt();
        }
        let s = shape(&tilted, &table(0.0), 3, (0.0, 10.0)).unwrap();
        assert!((s.chi2 - 10.0 / 9.0).abs() < 1e-12, "{s:?}");
        assert!(s.offset.abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn a_bad_field_is_named_with_its_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.csv");
        let text = table(0.0).csv().replacen(",0.5,", ",zero,", 1);
        std::fs::write(&path, text).unwrap();
        let e = Table::read(&path).unwrap_err().to_string();
        assert!(e.contains("p.csv:2: field ") && e.contains("zero"), "{e}");
        std::fs::write(&path, "z,vx\n1,2\n").unwrap();
        let e = Table::read(&path).unwrap_err().to_string();
        assert!(e.contains("p.csv:1: not a profiles table"), "{e}");
    }
}
