//! Reader of the benchmark's official initial configuration (`GranularShearFlow.data`):
//! `xMin 0.0 xMax 20.0 yMin … zMax 22.0`, `Particles N`, a column-title line, then N lines
//! `id x y z radius` with ids 1..N in order.

use std::io::BufRead;
use std::path::Path;

use super::{parse_fields, FormatError, Lines};
use crate::Vec3;

/// Positions and radii from an official initial file, plus its box.
#[derive(Clone, Debug, PartialEq)]
pub struct OfficialFile {
    pub lo: Vec3,
    pub hi: Vec3,
    pub x: Vec<Vec3>,
    pub radius: Vec<f64>,
    /// The line (from 1) of each particle, for messages.
    pub line: Vec<usize>,
}

/// True when a file starts like an official initial file (first token `xMin`).
pub fn looks_official(start: &[u8]) -> bool {
    start.trim_ascii_start().starts_with(b"xMin")
}

/// Reads an official initial file line by line. See [`parse`].
pub fn read(path: &Path) -> Result<OfficialFile, FormatError> {
    parse(&mut super::open(path)?)
}

/// Parses an official initial file. Errors name the file, the line and the field: a box line
/// that is not `xMin a xMax b yMin c yMax d zMin e zMax f` with finite numbers and positive
/// lengths, a count line that is not `Particles N`, a particle line without 5 numbers, a
/// non-number, NaN or an infinity, an id out of order or repeated, a radius that is not
/// positive, more or fewer particle lines than N, bytes that are not UTF-8.
pub fn parse<R: BufRead>(lines: &mut Lines<R>) -> Result<OfficialFile, FormatError> {
    let file = lines.file().to_string();
    let names = ["xMin", "xMax", "yMin", "yMax", "zMin", "zMax"];
    let head: Vec<String> = match lines.next_line()? {
        Some((_, l)) => l.split_whitespace().map(str::to_string).collect(),
        None => Vec::new(),
    };
    if head.len() != 12 || head.iter().step_by(2).zip(names).any(|(a, b)| *a != b) {
        return Err(lines.error(1, "expected `xMin a xMax b yMin c yMax d zMin e zMax f`"));
    }
    let mut bound = [0.0; 6];
    for (k, name) in names.iter().enumerate() {
        let tok = &head[2 * k + 1];
        bound[k] = match tok.parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            _ => return Err(lines.error(1, format!("{name}: not a finite number: {tok:?}"))),
        };
    }
    for k in 0..3 {
        if bound[2 * k + 1] <= bound[2 * k] {
            return Err(lines.error(
                1,
                format!(
                    "{}: {} is not above {} {}",
                    names[2 * k + 1],
                    bound[2 * k + 1],
                    names[2 * k],
                    bound[2 * k]
                ),
            ));
        }
    }
    let lo = Vec3::new(bound[0], bound[2], bound[4]);
    let hi = Vec3::new(bound[1], bound[3], bound[5]);
    let count_line: Vec<String> = match lines.next_line()? {
        Some((_, l)) => l.split_whitespace().map(str::to_string).collect(),
        None => Vec::new(),
    };
    let n: usize = match count_line.as_slice() {
        [word, n] if word == "Particles" => match n.parse::<f64>() {
            Ok(v) => super::count(&file, 2, "Particles", v)?,
            Err(_) => return Err(lines.error(2, format!("Particles: not a count: {n:?}"))),
        },
        _ => return Err(lines.error(2, "expected `Particles N`")),
    };
    if lines.next_line()?.is_none() {
        return Err(lines.error(
            3,
            format!("truncated: expected the column titles and {n} particle lines"),
        ));
    }
    let mut out = OfficialFile {
        lo,
        hi,
        x: Vec::with_capacity(super::reserve(n)),
        radius: Vec::with_capacity(super::reserve(n)),
        line: Vec::with_capacity(super::reserve(n)),
    };
    let mut nums = Vec::new();
    while let Some((line_no, line)) = lines.next_nonblank()? {
        parse_fields(
            &file,
            line_no,
            line,
            &["id", "x", "y", "z", "radius"],
            &mut nums,
        )?;
        if nums.len() != 5 {
            return Err(lines.error(
                line_no,
                format!("expected 5 columns (id x y z radius), got {}", nums.len()),
            ));
        }
        let id = out.x.len() + 1;
        if nums[0] != id as f64 {
            let seen = (nums[0] >= 1.0 && nums[0] < id as f64 && nums[0].fract() == 0.0)
                .then(|| out.line[nums[0] as usize - 1]);
            return Err(lines.error(
                line_no,
                match seen {
                    Some(first) => format!(
                        "id: {} repeats the id of line {first}; expected {id} (ids 1..N in order)",
                        nums[0]
                    ),
                    None => format!("id: expected {id} (ids 1..N in order), got {}", nums[0]),
                },
            ));
        }
        if id > n {
            return Err(lines.error(
                line_no,
                format!("more particle lines than the {n} announced on line 2"),
            ));
        }
        if nums[4] <= 0.0 {
            return Err(lines.error(line_no, format!("radius: must be > 0, got {}", nums[4])));
        }
        out.x.push(Vec3::new(nums[1], nums[2], nums[3]));
        out.radius.push(nums[4]);
        out.line.push(line_no);
    }
    if out.x.len() != n {
        return Err(lines.error(
            lines.line(),
            format!(
                "header announces {n} particles but the file has {} (truncated?)",
                out.x.len()
            ),
        ));
    }
    Ok(out)
}
