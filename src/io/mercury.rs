//! MercuryCG-compatible `.data` and `.fstat` files (formats and conventions in
//! `benchmark.md`, "Output format"; MercuryDPM `BaseInteraction::writeToFStat`).
//!
//! `.data.NNNN`: `N time xmin ymin zmin xmax ymax zmax`, then per particle in id order
//! `rx ry rz vx vy vz radius alpha beta gamma omegax omegay omegaz info`. verdem does not track
//! orientation (it never enters the physics of spheres) and writes 0 for the three angles.
//!
//! `.fstat.NNNN`: three `#` lines (`# time 1`, `# xmin ymin zmin xmax ymax zmax`,
//! `# rmin rmax 0 0 0 0`), then per contact `time i j cx cy cz delta deltat fn ft nx ny nz tx ty tz`
//! with 0-based indices; n points from j towards i; fn = F·n signed; ft = |Ft|; t the direction
//! of the tangential force on i; deltat = −|ξ|; contact point from the lower index. A free–free
//! contact is written twice (i j, then j i with n and t negated), a free–wall contact once, free
//! particle first.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use super::{fmt_f64, parse_fields, parse_numbers, FormatError, Lines};

/// The columns of a `.data` header line.
const DATA_HEADER: [&str; 8] = ["N", "time", "xmin", "ymin", "zmin", "xmax", "ymax", "zmax"];
/// The columns of a `.data` particle line.
const DATA_COLUMNS: [&str; 14] = [
    "rx", "ry", "rz", "vx", "vy", "vz", "radius", "alpha", "beta", "gamma", "omegax", "omegay",
    "omegaz", "info",
];
/// The columns of an `.fstat` contact line.
const FSTAT_COLUMNS: [&str; 16] = [
    "time", "i", "j", "cx", "cy", "cz", "delta", "deltat", "fn", "ft", "nx", "ny", "nz", "tx",
    "ty", "tz",
];
use crate::contact::PairInput;
use crate::state::Domain;
use crate::state::Motion;
use crate::state::Snapshot;
use crate::Vec3;

/// Path of save `k` of kind `ext` (`data` or `fstat`) of the series `dir/name`:
/// `dir/name.ext.NNNN`, `k` zero-padded to four digits (MercuryCG's numbering).
pub fn save_path(dir: &Path, name: &str, ext: &str, k: u64) -> PathBuf {
    dir.join(format!("{name}.{ext}.{k:04}"))
}

fn push_vec(s: &mut String, v: &Vec3) {
    for k in 0..3 {
        s.push(' ');
        fmt_f64(s, v[k]);
    }
}

/// Text of the `.data` save of a state.
pub fn data_text(core: &Snapshot) -> String {
    let p = &core.particles;
    let mut s = String::with_capacity(200 * p.len() + 100);
    s.push_str(&p.len().to_string());
    s.push(' ');
    fmt_f64(&mut s, core.time);
    push_vec(&mut s, &core.domain.lo);
    push_vec(&mut s, &core.domain.hi);
    s.push('\n');
    for a in 0..p.len() {
        fmt_f64(&mut s, p.x[a].x);
        s.push(' ');
        fmt_f64(&mut s, p.x[a].y);
        s.push(' ');
        fmt_f64(&mut s, p.x[a].z);
        push_vec(&mut s, &p.v[a]);
        s.push(' ');
        fmt_f64(&mut s, p.radius[a]);
        s.push_str(" 0 0 0");
        push_vec(&mut s, &p.w[a]);
        s.push_str(" 0\n");
    }
    s
}

/// One contact as seen from particle `i` (the first index of an `.fstat` line).
struct Side {
    i: usize,
    j: usize,
    n: Vec3,
    t: Vec3,
}

/// Text of the `.fstat` save of a state (the contacts of the last force evaluation, which
/// belong to its positions).
pub fn fstat_text(core: &Snapshot) -> String {
    let p = &core.particles;
    let rmin = p.radius.iter().cloned().fold(f64::INFINITY, f64::min);
    let rmax = p.radius.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let mut s = String::new();
    s.push_str("# ");
    fmt_f64(&mut s, core.time);
    s.push_str(" 1\n#");
    push_vec(&mut s, &core.domain.lo);
    push_vec(&mut s, &core.domain.hi);
    s.push_str("\n# ");
    fmt_f64(&mut s, rmin);
    s.push(' ');
    fmt_f64(&mut s, rmax);
    s.push_str(" 0 0 0 0\n");
    for contact in &core.contacts {
        let (pp, ii) = (contact.p as usize, contact.i as usize);
        // n, δ and the contact point exactly as the force pass computed them.
        let Some(g) = (PairInput::at_rest(
            core.domain.min_image(p.x[pp] - p.x[ii]),
            p.radius[pp],
            p.radius[ii],
        ))
        .kinematics() else {
            continue;
        };
        let out = &contact.force;
        let ft_vec = out.f - out.fn_signed * g.n;
        let ft = ft_vec.norm();
        let t = if ft > 0.0 { ft_vec / ft } else { Vec3::zeros() };
        let c = p.x[pp] + g.arm_p;
        let forward = Side {
            i: pp,
            j: ii,
            n: g.n,
            t,
        };
        let backward = Side {
            i: ii,
            j: pp,
            n: -g.n,
            t: -t,
        };
        let sides: &[Side] = match (p.motion[pp], p.motion[ii]) {
            (Motion::Free, Motion::Free) => &[forward, backward],
            (Motion::Free, _) => &[forward],
            _ => &[backward],
        };
        for side in sides {
            fmt_f64(&mut s, core.time);
            s.push_str(&format!(" {} {}", side.i, side.j));
            push_vec(&mut s, &c);
            for v in [g.delta, -contact.spring.norm(), out.fn_signed, ft] {
                s.push(' ');
                fmt_f64(&mut s, v);
            }
            push_vec(&mut s, &side.n);
            push_vec(&mut s, &side.t);
            s.push('\n');
        }
    }
    s
}

/// One particle line of a `.data` file.
#[derive(Clone, Debug, PartialEq)]
pub struct DataRow {
    pub x: Vec3,
    pub v: Vec3,
    pub radius: f64,
    pub w: Vec3,
    /// Its line in the file (from 1), for messages.
    pub line: usize,
}

/// A parsed `.data` file.
#[derive(Clone, Debug, PartialEq)]
pub struct DataFile {
    pub time: f64,
    pub domain_lo: Vec3,
    pub domain_hi: Vec3,
    pub rows: Vec<DataRow>,
}

/// Reads a MercuryCG `.data` file line by line; any precision is accepted. See [`parse_data`].
pub fn read_data(path: &Path) -> Result<DataFile, FormatError> {
    parse_data(&mut super::open(path)?)
}

/// Parses a MercuryCG `.data` file. Errors name the file, the line and the field: a header that
/// is not `N time xmin ymin zmin xmax ymax zmax` with a whole N and a box of positive lengths, a
/// particle line without 14 numbers (13 are accepted: MercuryDPM omits `info` in some
/// versions), a non-number, NaN or an infinity, a radius that is not positive, more or fewer
/// particle lines than N, bytes that are not UTF-8.
pub fn parse_data<R: BufRead>(lines: &mut Lines<R>) -> Result<DataFile, FormatError> {
    let file = lines.file().to_string();
    let mut nums = Vec::new();
    let Some((head_line, head)) = lines.next_nonblank()? else {
        return Err(lines.error(
            1,
            "empty file: expected the header `N time xmin ymin zmin xmax ymax zmax`",
        ));
    };
    parse_fields(&file, head_line, head, &DATA_HEADER, &mut nums)?;
    if nums.len() != 8 {
        return Err(lines.error(
            head_line,
            format!(
                "header must be `N time xmin ymin zmin xmax ymax zmax` (8 numbers), got {} values",
                nums.len()
            ),
        ));
    }
    let n = super::count(&file, head_line, "N (particles)", nums[0])?;
    let lo = Vec3::new(nums[2], nums[3], nums[4]);
    let hi = Vec3::new(nums[5], nums[6], nums[7]);
    check_box_lengths(&file, head_line, &lo, &hi)?;
    let mut out = DataFile {
        time: nums[1],
        domain_lo: lo,
        domain_hi: hi,
        rows: Vec::with_capacity(super::reserve(n)),
    };
    while let Some((line_no, line)) = lines.next_nonblank()? {
        parse_fields(&file, line_no, line, &DATA_COLUMNS, &mut nums)?;
        if nums.len() != 14 && nums.len() != 13 {
            return Err(lines.error(
                line_no,
                format!(
                    "expected 14 columns (rx ry rz vx vy vz radius alpha beta gamma omegax omegay omegaz info), got {}",
                    nums.len()
                ),
            ));
        }
        if out.rows.len() == n {
            return Err(lines.error(
                line_no,
                format!(
                    "more particle lines than the {n} announced in the header (line {head_line})"
                ),
            ));
        }
        if nums[6] <= 0.0 {
            return Err(lines.error(
                line_no,
                format!("column 7 (radius): must be > 0, got {}", nums[6]),
            ));
        }
        out.rows.push(DataRow {
            x: Vec3::new(nums[0], nums[1], nums[2]),
            v: Vec3::new(nums[3], nums[4], nums[5]),
            radius: nums[6],
            w: Vec3::new(nums[10], nums[11], nums[12]),
            line: line_no,
        });
    }
    if out.rows.len() != n {
        return Err(lines.error(
            lines.line().max(1),
            format!(
                "header announces {n} particles but the file has {} (truncated?)",
                out.rows.len()
            ),
        ));
    }
    Ok(out)
}

/// Refuses a box with a length that is not positive.
fn check_box_lengths(file: &str, line: usize, lo: &Vec3, hi: &Vec3) -> Result<(), FormatError> {
    match (0..3).find(|&k| hi[k] <= lo[k]) {
        Some(k) => Err(FormatError {
            file: file.into(),
            line,
            msg: format!(
                "box: {} max {} is not above {} min {}",
                ["x", "y", "z"][k],
                hi[k],
                ["x", "y", "z"][k],
                lo[k]
            ),
        }),
        None => Ok(()),
    }
}

/// One contact line of an `.fstat` file.
#[derive(Clone, Debug, PartialEq)]
pub struct FstatRow {
    pub i: usize,
    pub j: usize,
    pub c: Vec3,
    pub delta: f64,
    pub deltat: f64,
    pub fn_signed: f64,
    pub ft: f64,
    pub n: Vec3,
    pub t: Vec3,
}

/// A parsed `.fstat` file.
#[derive(Clone, Debug, PartialEq)]
pub struct FstatFile {
    pub time: f64,
    pub rows: Vec<FstatRow>,
}

/// Reads an `.fstat` file line by line. See [`parse_fstat`].
pub fn read_fstat(path: &Path) -> Result<FstatFile, FormatError> {
    parse_fstat(&mut super::open(path)?, None)
}

/// Reads the `.data` and `.fstat` files of one save, and checks that every contact's indices
/// are particles of the `.data` file.
pub fn read_save(data: &Path, fstat: &Path) -> Result<(DataFile, FstatFile), FormatError> {
    let d = read_data(data)?;
    let f = parse_fstat(&mut super::open(fstat)?, Some(d.rows.len()))?;
    Ok((d, f))
}

/// Parses an `.fstat` file: three `#` header lines (`# time …`, the box, the radii), then 16
/// numbers per contact line, `time i j …`. Errors name the file, the line and the field: a
/// missing header, a line with other columns, a non-number, NaN or an infinity, indices that
/// are not whole numbers or are equal, a time other than the header's, a second header after
/// contact lines (one save per file), and with `particles` an index beyond the particles.
pub fn parse_fstat<R: BufRead>(
    lines: &mut Lines<R>,
    particles: Option<usize>,
) -> Result<FstatFile, FormatError> {
    let file = lines.file().to_string();
    let mut nums = Vec::new();
    let mut out = FstatFile {
        time: 0.0,
        rows: Vec::new(),
    };
    let headers = [
        ("`# time ...`", 1),
        ("`# xmin ymin zmin xmax ymax zmax`", 6),
        ("`# rmin rmax ...`", 2),
    ];
    for (k, (what, least)) in headers.into_iter().enumerate() {
        let line = match lines.next_line()? {
            Some((_, l)) => l.strip_prefix('#'),
            None => None,
        };
        let line_no = k + 1;
        let Some(rest) = line else {
            return Err(lines.error(line_no, format!("header line {line_no} must be {what}")));
        };
        parse_numbers(&file, line_no, rest, &mut nums)?;
        if nums.len() < least {
            return Err(lines.error(
                line_no,
                format!(
                    "header line {line_no} must be {what} (at least {least} numbers), got {}",
                    nums.len()
                ),
            ));
        }
        if k == 0 {
            out.time = nums[0];
        }
    }
    while let Some((line_no, line)) = lines.next_nonblank()? {
        if line.starts_with('#') {
            return Err(lines.error(
                line_no,
                "a second header after contact lines: one save per file expected",
            ));
        }
        parse_fields(&file, line_no, line, &FSTAT_COLUMNS, &mut nums)?;
        if nums.len() != 16 {
            return Err(lines.error(
                line_no,
                format!(
                    "expected 16 columns (time i j cx cy cz delta deltat fn ft nx ny nz tx ty tz), got {}",
                    nums.len()
                ),
            ));
        }
        if (nums[0] - out.time).abs() > 1e-9 * out.time.abs().max(1.0) {
            return Err(lines.error(
                line_no,
                format!(
                    "column 1 (time): {} differs from the header's {} (a contact of another save?)",
                    nums[0], out.time
                ),
            ));
        }
        let i = super::count(&file, line_no, "column 2 (i)", nums[1])?;
        let j = super::count(&file, line_no, "column 3 (j)", nums[2])?;
        if i == j {
            return Err(lines.error(
                line_no,
                format!("columns 2, 3 (i, j): a contact of particle {i} with itself"),
            ));
        }
        if let Some(n) = particles {
            if let Some((col, k)) = [(2, i), (3, j)].into_iter().find(|&(_, k)| k >= n) {
                return Err(lines.error(
                    line_no,
                    format!("column {col}: particle index {k} is not among the save's {n} particles (0..{})", n.saturating_sub(1)),
                ));
            }
        }
        out.rows.push(FstatRow {
            i,
            j,
            c: Vec3::new(nums[3], nums[4], nums[5]),
            delta: nums[6],
            deltat: nums[7],
            fn_signed: nums[8],
            ft: nums[9],
            n: Vec3::new(nums[10], nums[11], nums[12]),
            t: Vec3::new(nums[13], nums[14], nums[15]),
        });
    }
    Ok(out)
}

/// Checks that a file's box matches the case's within `tol` (files may round it to 10 digits).
pub fn check_box(
    file: &str,
    lo: &Vec3,
    hi: &Vec3,
    domain: &Domain,
    tol: f64,
) -> Result<(), FormatError> {
    if (lo - domain.lo).amax() > tol || (hi - domain.hi).amax() > tol {
        return Err(FormatError {
            file: file.into(),
            line: 1,
            msg: format!(
                "box {:?}..{:?} differs from the case's {:?}..{:?}",
                lo.as_slice(),
                hi.as_slice(),
                domain.lo.as_slice(),
                domain.hi.as_slice()
            ),
        });
    }
    Ok(())
}
