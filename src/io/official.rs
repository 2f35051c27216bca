//! Reader of the benchmark's official initial configuration (`GranularShearFlow.data`):
//! `xMin 0.0 xMax 20.0 yMin … zMax 22.0`, `Particles N`, a column-title line, then N lines
//! `id x y z radius` with ids 1..N in order.

use std::path::Path;

use super::{parse_numbers, FormatError};
use crate::Vec3;

/// Positions and radii from an official initial file, plus its box.
#[derive(Clone, Debug, PartialEq)]
pub struct OfficialFile {
    pub lo: Vec3,
    pub hi: Vec3,
    pub x: Vec<Vec3>,
    pub radius: Vec<f64>,
}

/// True when the text starts like an official initial file (first token `xMin`).
pub fn looks_official(text: &str) -> bool {
    text.split_whitespace().next() == Some("xMin")
}

/// Parses an official initial file.
pub fn read(path: &Path, text: &str) -> Result<OfficialFile, FormatError> {
    let file = path.display().to_string();
    let err = |line: usize, msg: String| FormatError {
        file: file.clone(),
        line,
        msg,
    };
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    let names = ["xMin", "xMax", "yMin", "yMax", "zMin", "zMax"];
    if head.len() != 12 || head.iter().step_by(2).zip(names).any(|(a, b)| *a != b) {
        return Err(err(
            1,
            "expected `xMin a xMax b yMin c yMax d zMin e zMax f`".into(),
        ));
    }
    let val = |k: usize| -> Result<f64, FormatError> {
        head[2 * k + 1].parse().map_err(|_| {
            err(
                1,
                format!("{}: not a number: {:?}", names[k], head[2 * k + 1]),
            )
        })
    };
    let lo = Vec3::new(val(0)?, val(2)?, val(4)?);
    let hi = Vec3::new(val(1)?, val(3)?, val(5)?);
    let count_line: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    let n: usize = match count_line.as_slice() {
        ["Particles", n] => n
            .parse()
            .map_err(|_| err(2, format!("Particles: not a count: {n:?}")))?,
        _ => return Err(err(2, "expected `Particles N`".into())),
    };
    lines.next();
    let mut out = OfficialFile {
        lo,
        hi,
        x: Vec::with_capacity(n),
        radius: Vec::with_capacity(n),
    };
    let mut nums = Vec::new();
    for (k, line) in lines.enumerate() {
        let line_no = k + 4;
        if line.trim().is_empty() {
            continue;
        }
        parse_numbers(&file, line_no, line, &mut nums)?;
        if nums.len() != 5 {
            return Err(err(
                line_no,
                format!("expected 5 columns (id x y z radius), got {}", nums.len()),
            ));
        }
        let id = out.x.len() + 1;
        if nums[0] != id as f64 {
            return Err(err(line_no, format!("id: expected {id}, got {}", nums[0])));
        }
        if nums[4] <= 0.0 {
            return Err(err(
                line_no,
                format!("radius: must be > 0, got {}", nums[4]),
            ));
        }
        out.x.push(Vec3::new(nums[1], nums[2], nums[3]));
        out.radius.push(nums[4]);
    }
    if out.x.len() != n {
        return Err(err(
            text.lines().count(),
            format!(
                "header announces {n} particles but the file has {}",
                out.x.len()
            ),
        ));
    }
    Ok(out)
}
