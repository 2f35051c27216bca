//! Reader of the per-save dumps of the LAMMPS family: particles (`dump custom … id type radius
//! x y z vx vy vz omegax omegay omegaz`, sorted by id, 17 significant digits) and contacts
//! (`dump local`).

use std::path::Path;

use super::DUMP_COLUMNS;
use crate::io::{parse_numbers, read_text, FormatError};
use crate::peers::Frame;
use crate::Vec3;

fn err(file: &str, line: usize, msg: impl Into<String>) -> FormatError {
    FormatError {
        file: file.into(),
        line,
        msg: msg.into(),
    }
}

/// A dump's header and its table: the step, the `ITEM:` line that names the columns, and the
/// `count_item` rows of `columns` numbers each that follow it (line 10 on).
struct Table {
    step: u64,
    names: String,
    rows: Vec<Vec<f64>>,
}

/// Reads the header (`ITEM: TIMESTEP`, `count_item`, the box, `rows_item`) and the rows of a
/// LAMMPS-style dump, naming the file and line of anything out of place.
fn read_table(
    path: &Path,
    count_item: &str,
    rows_item: &str,
    columns: usize,
) -> Result<(String, Table), FormatError> {
    let (file, text) = read_text(path)?;
    let lines: Vec<&str> = text.lines().collect();
    let item = |k: usize, name: &str| -> Result<&str, FormatError> {
        match lines.get(k) {
            Some(l) if l.starts_with(name) => Ok(*l),
            _ => Err(err(&file, k + 1, format!("expected `{name}`"))),
        }
    };
    let number = |k: usize| -> Result<u64, FormatError> {
        lines
            .get(k)
            .and_then(|l| l.trim().parse().ok())
            .ok_or_else(|| err(&file, k + 1, "expected a whole number"))
    };
    item(0, "ITEM: TIMESTEP")?;
    let step = number(1)?;
    item(2, count_item)?;
    let n = number(3)? as usize;
    item(4, "ITEM: BOX BOUNDS")?;
    let names = item(8, rows_item)?.to_string();
    let mut rows = Vec::with_capacity(n);
    let mut nums = Vec::new();
    for e in 0..n {
        let k = 9 + e;
        let line = lines
            .get(k)
            .ok_or_else(|| err(&file, k + 1, format!("{n} rows announced, {e} found")))?;
        parse_numbers(&file, k + 1, line, &mut nums)?;
        if nums.len() != columns {
            return Err(err(
                &file,
                k + 1,
                format!("expected {columns} columns, got {}", nums.len()),
            ));
        }
        rows.push(nums.clone());
    }
    Ok((file, Table { step, names, rows }))
}

/// Reads a dump file; errors name the file and line (a missing `ITEM:` line, other columns,
/// ids not 1…N in order, a non-number).
pub fn read(path: &Path) -> Result<Frame, FormatError> {
    let (file, t) = read_table(
        path,
        "ITEM: NUMBER OF ATOMS",
        "ITEM: ATOMS",
        DUMP_COLUMNS.len(),
    )?;
    let cols: Vec<&str> = t.names.split_whitespace().skip(2).collect();
    if cols != DUMP_COLUMNS {
        return Err(err(
            &file,
            9,
            format!("columns must be `{}`", DUMP_COLUMNS.join(" ")),
        ));
    }
    let n = t.rows.len();
    let mut frame = Frame {
        step: t.step,
        radius: Vec::with_capacity(n),
        x: Vec::with_capacity(n),
        v: Vec::with_capacity(n),
        w: Vec::with_capacity(n),
    };
    for (a, r) in t.rows.iter().enumerate() {
        if r[0] != (a + 1) as f64 {
            return Err(err(
                &file,
                10 + a,
                format!(
                    "expected atom {} with {} columns",
                    a + 1,
                    DUMP_COLUMNS.len()
                ),
            ));
        }
        frame.radius.push(r[2]);
        frame.x.push(Vec3::new(r[3], r[4], r[5]));
        frame.v.push(Vec3::new(r[6], r[7], r[8]));
        frame.w.push(Vec3::new(r[9], r[10], r[11]));
    }
    Ok(frame)
}

/// Reads a `dump local` file of `columns` numbers per entry (the contact forces of a save).
pub fn read_entries(path: &Path, columns: usize) -> Result<Vec<Vec<f64>>, FormatError> {
    let (_, t) = read_table(path, "ITEM: NUMBER OF ENTRIES", "ITEM: ENTRIES", columns)?;
    Ok(t.rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DUMP: &str = "ITEM: TIMESTEP\n500\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n\
0 20\n0 10.392304845413264\n0 22\nITEM: ATOMS id type radius x y z vx vy vz omegax omegay omegaz\n\
1 1 0.5 1 2 3 0.1 0.2 0.30000000000000004 0 0 1\n2 2 0.5 4 5 6 -1 0 0 0 0 0\n";

    #[test]
    fn reads_a_dump_and_names_file_and_line_on_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("dump.500.txt");
        std::fs::write(&p, DUMP).unwrap();
        let f = read(&p).unwrap();
        assert_eq!(f.step, 500);
        assert_eq!(f.v[0].z, 0.30000000000000004);
        assert_eq!(f.x[1], Vec3::new(4.0, 5.0, 6.0));

        std::fs::write(&p, DUMP.replace("\n2 2 0.5", "\n3 2 0.5")).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.ends_with("dump.500.txt:11: expected atom 2 with 12 columns"),
            "{e}"
        );

        std::fs::write(&p, DUMP.replace("omegaz", "fx")).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("dump.500.txt:9: columns must be"), "{e}");
    }

    #[test]
    fn reads_local_entries_and_checks_their_columns() {
        let text = "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ENTRIES\n2\nITEM: BOX BOUNDS pp pp ff\n\
0 20\n0 10\n0 22\nITEM: ENTRIES c_a[1] c_a[2] c_b[1]\n1 2 0.5\n3 4 -1e-3\n";
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("contacts.100.txt");
        std::fs::write(&p, text).unwrap();
        let rows = read_entries(&p, 3).unwrap();
        assert_eq!(rows, vec![vec![1.0, 2.0, 0.5], vec![3.0, 4.0, -1e-3]]);
        let e = read_entries(&p, 4).unwrap_err().to_string();
        assert!(
            e.ends_with("contacts.100.txt:10: expected 4 columns, got 3"),
            "{e}"
        );
    }
}
