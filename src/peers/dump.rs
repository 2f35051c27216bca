//! Reader of the per-save dumps a cross-run asks the peers for (`dump custom … id type radius
//! x y z vx vy vz omegax omegay omegaz`, sorted by id, 17 significant digits).

use std::path::Path;

use super::DUMP_COLUMNS;
use crate::io::{parse_numbers, read_text, FormatError};
use crate::Vec3;

/// One save of a peer: atoms in id order (id 1 first).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub step: u64,
    pub radius: Vec<f64>,
    pub x: Vec<Vec3>,
    pub v: Vec<Vec3>,
    pub w: Vec<Vec3>,
}

fn err(file: &str, line: usize, msg: impl Into<String>) -> FormatError {
    FormatError {
        file: file.into(),
        line,
        msg: msg.into(),
    }
}

/// Reads a dump file; errors name the file and line (a missing `ITEM:` line, other columns,
/// ids not 1…N in order, a non-number).
pub fn read(path: &Path) -> Result<Frame, FormatError> {
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
    item(2, "ITEM: NUMBER OF ATOMS")?;
    let n = number(3)? as usize;
    item(4, "ITEM: BOX BOUNDS")?;
    let atoms = item(8, "ITEM: ATOMS")?;
    let cols: Vec<&str> = atoms.split_whitespace().skip(2).collect();
    if cols != DUMP_COLUMNS {
        return Err(err(
            &file,
            9,
            format!("columns must be `{}`", DUMP_COLUMNS.join(" ")),
        ));
    }
    let mut frame = Frame {
        step,
        radius: Vec::with_capacity(n),
        x: Vec::with_capacity(n),
        v: Vec::with_capacity(n),
        w: Vec::with_capacity(n),
    };
    let mut nums = Vec::new();
    for a in 0..n {
        let k = 9 + a;
        let line = lines
            .get(k)
            .ok_or_else(|| err(&file, k + 1, format!("{n} atoms announced, {a} found")))?;
        parse_numbers(&file, k + 1, line, &mut nums)?;
        if nums.len() != DUMP_COLUMNS.len() || nums[0] != (a + 1) as f64 {
            return Err(err(
                &file,
                k + 1,
                format!(
                    "expected atom {} with {} columns",
                    a + 1,
                    DUMP_COLUMNS.len()
                ),
            ));
        }
        frame.radius.push(nums[2]);
        frame.x.push(Vec3::new(nums[3], nums[4], nums[5]));
        frame.v.push(Vec3::new(nums[6], nums[7], nums[8]));
        frame.w.push(Vec3::new(nums[9], nums[10], nums[11]));
    }
    Ok(frame)
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
}
