//! Reader of the per-save dumps of the LAMMPS family: particles (`dump custom … id type radius
//! x y z vx vy vz omegax omegay omegaz`, sorted by id, 17 significant digits) and contacts
//! (`dump local`).

use std::io::BufRead;
use std::path::Path;

use super::DUMP_COLUMNS;
use crate::io::{parse_fields, parse_numbers, FormatError, Lines};
use crate::peers::Frame;
use crate::Vec3;

fn err(file: &str, line: usize, msg: String) -> FormatError {
    FormatError {
        file: file.into(),
        line,
        msg,
    }
}

/// A dump's header and its table: the step, the `ITEM:` line that names the columns, and the
/// `count_item` rows of `columns` numbers each that follow it (line 10 on).
struct Table {
    file: String,
    step: u64,
    names: String,
    rows: Vec<Vec<f64>>,
    /// The line of each row.
    line: Vec<usize>,
}

/// Reads the header (`ITEM: TIMESTEP`, `count_item`, the box, `rows_item`) and the rows of a
/// LAMMPS-style dump line by line, naming the file, the line and the item of anything out of
/// place: a missing `ITEM:` line, a step or count that is not a whole number, a box line
/// without two finite bounds, a row without `columns` numbers, NaN or an infinity, fewer rows
/// than announced, anything but blank lines after them, bytes that are not UTF-8.
fn read_table<R: BufRead>(
    lines: &mut Lines<R>,
    count_item: &str,
    rows_item: &str,
    columns: usize,
) -> Result<Table, FormatError> {
    let file = lines.file().to_string();
    let item = |lines: &mut Lines<R>, name: &str| -> Result<String, FormatError> {
        match lines.next_line()? {
            Some((_, l)) if l.starts_with(name) => Ok(l.to_string()),
            Some((k, l)) => Err(err(
                &file,
                k,
                format!("expected `{name}`, got `{}`", l.trim()),
            )),
            None => Err(lines.error(
                lines.line() + 1,
                format!("expected `{name}` (truncated file?)"),
            )),
        }
    };
    let number = |lines: &mut Lines<R>, what: &str| -> Result<u64, FormatError> {
        match lines.next_line()? {
            Some((k, l)) => l.trim().parse().map_err(|_| {
                err(
                    &file,
                    k,
                    format!("{what}: expected a whole number, got `{}`", l.trim()),
                )
            }),
            None => Err(lines.error(
                lines.line() + 1,
                format!("{what}: expected a whole number (truncated file?)"),
            )),
        }
    };
    item(lines, "ITEM: TIMESTEP")?;
    let step = number(lines, "ITEM: TIMESTEP")?;
    item(lines, count_item)?;
    let n = number(lines, count_item)?;
    let n =
        usize::try_from(n).map_err(|_| lines.error(4, format!("{count_item}: {n} is too many")))?;
    item(lines, "ITEM: BOX BOUNDS")?;
    let mut nums = Vec::new();
    for axis in ["x", "y", "z"] {
        match lines.next_line()? {
            Some((k, l)) => {
                parse_numbers(&file, k, l, &mut nums)?;
                if nums.len() < 2 || nums[1] < nums[0] {
                    return Err(lines.error(
                        k,
                        format!("ITEM: BOX BOUNDS: expected `{axis}lo {axis}hi` with {axis}lo <= {axis}hi"),
                    ));
                }
            }
            None => {
                return Err(lines.error(
                    lines.line() + 1,
                    format!("ITEM: BOX BOUNDS: expected `{axis}lo {axis}hi` (truncated file?)"),
                ))
            }
        }
    }
    let names = item(lines, rows_item)?;
    let column_names: Vec<&str> = names.split_whitespace().skip(2).collect();
    let mut rows = Vec::with_capacity(crate::io::reserve(n));
    let mut line = Vec::with_capacity(crate::io::reserve(n));
    for e in 0..n {
        let Some((k, l)) = lines.next_line()? else {
            return Err(lines.error(
                lines.line() + 1,
                format!("{n} rows announced ({count_item}), {e} found (truncated file?)"),
            ));
        };
        parse_fields(&file, k, l, &column_names, &mut nums)?;
        if nums.len() != columns {
            return Err(lines.error(k, format!("expected {columns} columns, got {}", nums.len())));
        }
        rows.push(nums.clone());
        line.push(k);
    }
    if let Some((k, _)) = lines.next_nonblank()? {
        return Err(lines.error(
            k,
            format!("more lines than the {n} rows announced ({count_item}): one frame per file expected"),
        ));
    }
    Ok(Table {
        file,
        step,
        names,
        rows,
        line,
    })
}

/// Reads a dump file line by line. See [`parse`].
pub fn read(path: &Path) -> Result<Frame, FormatError> {
    parse(&mut crate::io::open(path)?)
}

/// One particle of a dump: its id (from 1) and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Atom {
    pub id: usize,
    pub radius: f64,
    pub x: Vec3,
    pub v: Vec3,
    pub w: Vec3,
}

/// The step and the particles of a dump of [`DUMP_COLUMNS`], with the line of each; errors
/// name the file and line (those of `read_table`, other columns, an id that is not a whole
/// number from 1, a radius that is not positive).
fn atoms<R: BufRead>(lines: &mut Lines<R>) -> Result<(u64, Vec<Atom>, Vec<usize>), FormatError> {
    let t = read_table(
        lines,
        "ITEM: NUMBER OF ATOMS",
        "ITEM: ATOMS",
        DUMP_COLUMNS.len(),
    )?;
    let err = |line: usize, msg: String| FormatError {
        file: t.file.clone(),
        line,
        msg,
    };
    let cols: Vec<&str> = t.names.split_whitespace().skip(2).collect();
    if cols != DUMP_COLUMNS {
        return Err(err(
            9,
            format!("columns must be `{}`", DUMP_COLUMNS.join(" ")),
        ));
    }
    let mut atoms = Vec::with_capacity(t.rows.len());
    for (r, &line) in t.rows.iter().zip(&t.line) {
        if !(r[0] >= 1.0 && r[0].fract() == 0.0) {
            return Err(err(
                line,
                format!("id: expected a whole number >= 1, got {}", r[0]),
            ));
        }
        if r[2] <= 0.0 {
            return Err(err(line, format!("radius: must be > 0, got {}", r[2])));
        }
        atoms.push(Atom {
            id: r[0] as usize,
            radius: r[2],
            x: Vec3::new(r[3], r[4], r[5]),
            v: Vec3::new(r[6], r[7], r[8]),
            w: Vec3::new(r[9], r[10], r[11]),
        });
    }
    Ok((t.step, atoms, t.line))
}

/// Parses a dump of one frame; errors name the file and line (those of [`atoms`], ids not
/// 1…N in order).
pub fn parse<R: BufRead>(lines: &mut Lines<R>) -> Result<Frame, FormatError> {
    let file = lines.file().to_string();
    let (step, atoms, line) = atoms(lines)?;
    let n = atoms.len();
    let mut frame = Frame {
        step,
        radius: Vec::with_capacity(n),
        x: Vec::with_capacity(n),
        v: Vec::with_capacity(n),
        w: Vec::with_capacity(n),
    };
    for (a, atom) in atoms.into_iter().enumerate() {
        if atom.id != a + 1 {
            return Err(err(
                &file,
                line[a],
                format!("id: expected {} (sorted ids 1..N), got {}", a + 1, atom.id),
            ));
        }
        frame.radius.push(atom.radius);
        frame.x.push(atom.x);
        frame.v.push(atom.v);
        frame.w.push(atom.w);
    }
    Ok(frame)
}

/// Reads a dump of some of the particles (any ids, as `dump_modify thresh` leaves them): its
/// step and particles. Errors as [`parse`]'s, without the order of ids.
pub fn read_atoms(path: &Path) -> Result<(u64, Vec<Atom>), FormatError> {
    let (step, atoms, _) = atoms(&mut crate::io::open(path)?)?;
    Ok((step, atoms))
}

/// Reads a `dump local` file of `columns` numbers per entry (the contact forces of a save).
pub fn read_entries(path: &Path, columns: usize) -> Result<Vec<Vec<f64>>, FormatError> {
    parse_entries(&mut crate::io::open(path)?, columns)
}

/// Parses a `dump local` file of `columns` numbers per entry.
pub fn parse_entries<R: BufRead>(
    lines: &mut Lines<R>,
    columns: usize,
) -> Result<Vec<Vec<f64>>, FormatError> {
    let t = read_table(lines, "ITEM: NUMBER OF ENTRIES", "ITEM: ENTRIES", columns)?;
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
            e.ends_with("dump.500.txt:11: id: expected 2 (sorted ids 1..N), got 3"),
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
