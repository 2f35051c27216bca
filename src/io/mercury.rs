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

use std::path::{Path, PathBuf};

use super::{fmt_f64, parse_numbers, FormatError};
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
        let Some(g) = (PairInput {
            r: core.domain.min_image(p.x[pp] - p.x[ii]),
            rad_p: p.radius[pp],
            rad_i: p.radius[ii],
            v_p: Vec3::zeros(),
            v_i: Vec3::zeros(),
            w_p: Vec3::zeros(),
            w_i: Vec3::zeros(),
        })
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
}

/// A parsed `.data` file.
#[derive(Clone, Debug, PartialEq)]
pub struct DataFile {
    pub time: f64,
    pub domain_lo: Vec3,
    pub domain_hi: Vec3,
    pub rows: Vec<DataRow>,
}

/// Reads a MercuryCG `.data` file; any precision is accepted. Errors name the file and line:
/// wrong column count, a header count that does not match the lines, a non-number, NaN.
pub fn read_data(path: &Path) -> Result<DataFile, FormatError> {
    let (file, text) = super::read_text(path)?;
    let mut lines = text.lines().enumerate();
    let mut nums = Vec::new();
    let (_, head) = lines.next().ok_or_else(|| FormatError {
        file: file.clone(),
        line: 1,
        msg: "empty file".into(),
    })?;
    parse_numbers(&file, 1, head, &mut nums)?;
    if nums.len() != 8 || nums[0] < 0.0 || nums[0].fract() != 0.0 {
        return Err(FormatError {
            file,
            line: 1,
            msg: format!(
                "header must be `N time xmin ymin zmin xmax ymax zmax` (8 numbers), got {} values",
                nums.len()
            ),
        });
    }
    let n = nums[0] as usize;
    let mut out = DataFile {
        time: nums[1],
        domain_lo: Vec3::new(nums[2], nums[3], nums[4]),
        domain_hi: Vec3::new(nums[5], nums[6], nums[7]),
        rows: Vec::with_capacity(n),
    };
    for (idx, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let line_no = idx + 1;
        parse_numbers(&file, line_no, line, &mut nums)?;
        if nums.len() != 14 && nums.len() != 13 {
            return Err(FormatError {
                file,
                line: line_no,
                msg: format!(
                    "expected 14 columns (rx ry rz vx vy vz radius alpha beta gamma omegax omegay omegaz info), got {}",
                    nums.len()
                ),
            });
        }
        if out.rows.len() == n {
            return Err(FormatError {
                file,
                line: line_no,
                msg: format!("more particle lines than the {n} announced in the header"),
            });
        }
        out.rows.push(DataRow {
            x: Vec3::new(nums[0], nums[1], nums[2]),
            v: Vec3::new(nums[3], nums[4], nums[5]),
            radius: nums[6],
            w: Vec3::new(nums[10], nums[11], nums[12]),
        });
    }
    if out.rows.len() != n {
        return Err(FormatError {
            file,
            line: text.lines().count(),
            msg: format!(
                "header announces {n} particles but the file has {} (truncated?)",
                out.rows.len()
            ),
        });
    }
    Ok(out)
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

/// Reads an `.fstat` file (three `#` lines, then 16 columns per contact line).
pub fn read_fstat(path: &Path) -> Result<FstatFile, FormatError> {
    let (file, text) = super::read_text(path)?;
    let mut out = FstatFile {
        time: f64::NAN,
        rows: Vec::new(),
    };
    let mut nums = Vec::new();
    for (idx, line) in text.lines().enumerate() {
        let line_no = idx + 1;
        if let Some(rest) = line.strip_prefix('#') {
            if idx == 0 {
                parse_numbers(&file, line_no, rest, &mut nums)?;
                out.time = *nums.first().ok_or_else(|| FormatError {
                    file: file.clone(),
                    line: 1,
                    msg: "first line must be `# time ...`".into(),
                })?;
            }
            continue;
        }
        if line.trim().is_empty() {
            continue;
        }
        parse_numbers(&file, line_no, line, &mut nums)?;
        if nums.len() != 16 {
            return Err(FormatError {
                file,
                line: line_no,
                msg: format!(
                    "expected 16 columns (time i j cx cy cz delta deltat fn ft nx ny nz tx ty tz), got {}",
                    nums.len()
                ),
            });
        }
        out.rows.push(FstatRow {
            i: nums[1] as usize,
            j: nums[2] as usize,
            c: Vec3::new(nums[3], nums[4], nums[5]),
            delta: nums[6],
            deltat: nums[7],
            fn_signed: nums[8],
            ft: nums[9],
            n: Vec3::new(nums[10], nums[11], nums[12]),
            t: Vec3::new(nums[13], nums[14], nums[15]),
        });
    }
    if out.time.is_nan() {
        return Err(FormatError {
            file,
            line: 1,
            msg: "missing `# time` header line".into(),
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
