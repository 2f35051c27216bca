//! The prescribed-kinematics driver: one contact between two spheres driven through a given
//! motion, with the forces and torques of the case's contact law at every row. Any external
//! interaction-test suite can run verdem's law this way (`verdem kinematics`).
//!
//! Conventions: sphere 1 is i, sphere 2 is j; n points from 1 to 2 (verdem's pair with P = 2,
//! I = 1); forces and torques are those acting on each sphere about its own centre. Row k of
//! the forces is computed from row k of the motion (no lag); the increment over
//! [t_(k−1), t_k] uses the step-average velocities: by default from the positions and
//! quaternions, (x_k − x_(k−1))/Δt and the rotation vector of q_k q_(k−1)⁻¹ over Δt (exactly
//! what verdem's leapfrog feeds its law), or with `Increment::Trapezoid` the mean of the two
//! rows' velocities. Row 0 has no increment and uses its own velocities.

use nalgebra::{Quaternion, UnitQuaternion};

use crate::case::{Case, Scene, COARSE_STEPS_PER_COLLISION};
use crate::contact::{ContactLaw, PairForce, PairInput, PairKinematics};
use crate::io::FormatError;
use crate::step::engine::{self, LawVisitor};
use crate::Vec3;

/// The columns of a motion file, in order.
pub const MOTION_COLUMNS: [&str; 27] = [
    "t", "x1", "y1", "z1", "qw1", "qx1", "qy1", "qz1", "vx1", "vy1", "vz1", "wx1", "wy1", "wz1",
    "x2", "y2", "z2", "qw2", "qx2", "qy2", "qz2", "vx2", "vy2", "vz2", "wx2", "wy2", "wz2",
];

/// The columns of a forces file, in order.
pub const FORCE_COLUMNS: [&str; 16] = [
    "t", "fx1", "fy1", "fz1", "tx1", "ty1", "tz1", "fx2", "fy2", "fz2", "tx2", "ty2", "tz2",
    "delta", "fn", "ft",
];

/// The prescribed state of both spheres at one time (lab frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionRow {
    pub t: f64,
    pub x: [Vec3; 2],
    pub q: [UnitQuaternion<f64>; 2],
    pub v: [Vec3; 2],
    pub w: [Vec3; 2],
}

/// Forces and torques on each sphere at one time; `delta` is the overlap (negative apart),
/// `fn_signed` the signed normal force (positive repulsive), `ft` the tangential magnitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceRow {
    pub t: f64,
    pub f: [Vec3; 2],
    pub torque: [Vec3; 2],
    pub delta: f64,
    pub fn_signed: f64,
    pub ft: f64,
}

/// Which velocities drive the increment of a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Increment {
    /// From positions and quaternions (the step-average velocities).
    Positions,
    /// The mean of the two rows' velocities.
    Trapezoid,
}

impl Increment {
    /// Every choice.
    pub const ALL: [Increment; 2] = [Increment::Positions, Increment::Trapezoid];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Increment::Positions => "positions",
            Increment::Trapezoid => "trapezoid",
        }
    }

    /// One line saying which velocities it takes (for help texts).
    pub fn description(self) -> &'static str {
        match self {
            Increment::Positions => "From positions and quaternions (the step-average velocities)",
            Increment::Trapezoid => "The mean of the two rows' velocities",
        }
    }
}

/// A contact law behind a pointer (the driver needs no static dispatch).
pub trait DynLaw {
    /// A new contact of this law, with no history yet.
    fn new_contact(&self) -> Box<dyn DynContact + '_>;
}

/// One contact of a law, carrying the law's history from one evaluation to the next.
pub trait DynContact {
    /// As [`ContactLaw::evaluate`], over the step `dt` (time), advancing the contact's history.
    fn evaluate(&mut self, k: &PairKinematics, dt: f64) -> PairForce;
    /// Forgets the history (the spheres are apart).
    fn forget(&mut self);
}

/// A law and the history of one of its contacts.
struct LawContact<'a, L: ContactLaw> {
    law: &'a L,
    history: L::History,
}

impl<L: ContactLaw> DynContact for LawContact<'_, L> {
    fn evaluate(&mut self, k: &PairKinematics, dt: f64) -> PairForce {
        self.law.evaluate(k, &mut self.history, dt)
    }
    fn forget(&mut self) {
        self.history = L::History::default();
    }
}

impl<L: ContactLaw> DynLaw for L {
    fn new_contact(&self) -> Box<dyn DynContact + '_> {
        Box::new(LawContact {
            law: self,
            history: L::History::default(),
        })
    }
}

struct Boxed;

impl LawVisitor for Boxed {
    type Output = Box<dyn DynLaw>;
    fn visit<L: ContactLaw + Clone + 'static>(self, law: L) -> Box<dyn DynLaw> {
        Box::new(law)
    }
}

/// The contact law of `case`; an error when the case names no tangential convention.
pub fn law_of(case: &Case) -> Result<Box<dyn DynLaw>, crate::case::CaseError> {
    engine::with_law(case, Boxed)
}

/// The two spheres' starting positions and radii, from the case's `spheres` scene (an error
/// naming the file for any other scene).
pub fn pair_of(case: &Case) -> anyhow::Result<([Vec3; 2], [f64; 2])> {
    let sphere = match &case.scene {
        Scene::Spheres { sphere } if sphere.len() == 2 => sphere,
        _ => anyhow::bail!(
            "{}: scene: a contact of two spheres needs `kind = \"spheres\"` with exactly two \
             [[scene.sphere]]",
            case.path.display()
        ),
    };
    let r = |k: usize| sphere[k].radius.unwrap_or(0.5 * case.material.diameter);
    Ok((
        [Vec3::from(sphere[0].x), Vec3::from(sphere[1].x)],
        [r(0), r(1)],
    ))
}

/// The collision time (time) of the contact of the case's scene under its law,
/// [`Case::collision_time`] at the effective mass of the first of [`Case::pairs`] (the two
/// spheres of a `spheres` scene of two free spheres); `None` when the scene has no contact or
/// the law over-damps it. The time scale on which a prescribed motion has to resolve the law.
pub fn collision_time(case: &Case) -> Option<f64> {
    let (_, meff) = *case.pairs().first()?;
    case.collision_time(meff)
}

/// The widest step [t_(k−1), t_k] of `rows` at whose end the spheres of radii `radius` touch
/// (the steps whose increments the law takes, [`drive`]): its row k >= 1 and t_k − t_(k−1)
/// (time), the earliest of equal ones; `None` when they touch at no row after the first.
pub fn widest_contact_step(radius: [f64; 2], rows: &[MotionRow]) -> Option<(usize, f64)> {
    // as PairInput::kinematics tells a contact
    let sum = radius[0] + radius[1];
    let touching = |row: &MotionRow| (row.x[1] - row.x[0]).norm_squared() < sum * sum;
    (1..rows.len())
        .filter(|&k| touching(&rows[k]))
        .map(|k| (k, rows[k].t - rows[k - 1].t))
        .fold(None, |widest, (k, dt)| match widest {
            Some((_, w)) if w >= dt => widest,
            _ => Some((k, dt)),
        })
}

/// Whether steps `dt` (time) are coarse for a law of collision time `tc` (time): fewer than
/// [`COARSE_STEPS_PER_COLLISION`] per collision, where a run of verdem's scheme is warned
/// about. Its forces are still the law's at each row; what a coarse motion misses is the
/// collision's course between them.
pub fn coarse(dt: f64, tc: f64) -> bool {
    tc / dt < COARSE_STEPS_PER_COLLISION * (1.0 - 1e-12)
}

/// Drives one contact of spheres with radii `radius` (sphere 1, sphere 2) through `rows`.
pub fn drive(
    law: &dyn DynLaw,
    radius: [f64; 2],
    rows: &[MotionRow],
    increment: Increment,
) -> Vec<ForceRow> {
    let mut contact = law.new_contact();
    let mut out = Vec::with_capacity(rows.len());
    for (k, row) in rows.iter().enumerate() {
        let (v, w, dt) = match (k, increment) {
            (0, _) => (row.v, row.w, 0.0),
            (_, Increment::Positions) => {
                let prev = &rows[k - 1];
                let dt = row.t - prev.t;
                let spin = |s: usize| (row.q[s] * prev.q[s].inverse()).scaled_axis() / dt;
                (
                    [(row.x[0] - prev.x[0]) / dt, (row.x[1] - prev.x[1]) / dt],
                    [spin(0), spin(1)],
                    dt,
                )
            }
            (_, Increment::Trapezoid) => {
                let prev = &rows[k - 1];
                let mean = |a: [Vec3; 2], b: [Vec3; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
                (mean(prev.v, row.v), mean(prev.w, row.w), row.t - prev.t)
            }
        };
        // verdem's pair: P = sphere 2, I = sphere 1, n from 1 to 2.
        let input = PairInput {
            r: row.x[1] - row.x[0],
            rad_p: radius[1],
            rad_i: radius[0],
            inv_mass_p: 0.0,
            inv_mass_i: 0.0,
            v_p: v[1],
            v_i: v[0],
            w_p: w[1],
            w_i: w[0],
        };
        out.push(match input.kinematics() {
            Some(kin) => {
                let p = contact.evaluate(&kin, dt);
                ForceRow {
                    t: row.t,
                    f: [-p.f, p.f],
                    torque: [p.torque_i, p.torque_p],
                    delta: kin.delta,
                    fn_signed: p.fn_signed,
                    ft: (p.f - p.fn_signed * kin.n).norm(),
                }
            }
            None => {
                // apart: the history is forgotten, as in the solver
                contact.forget();
                ForceRow {
                    t: row.t,
                    f: [Vec3::zeros(); 2],
                    torque: [Vec3::zeros(); 2],
                    delta: radius[0] + radius[1] - input.r.norm(),
                    fn_signed: 0.0,
                    ft: 0.0,
                }
            }
        });
    }
    out
}

fn err(file: &str, line: usize, msg: String) -> FormatError {
    FormatError {
        file: file.into(),
        line,
        msg,
    }
}

/// Whether a record is a line of spaces or a comment after spaces (the reader skips empty
/// lines and lines starting with `#`).
fn blank_or_comment(record: &csv::StringRecord) -> bool {
    record.iter().eq([""]) || record[0].starts_with('#')
}

/// A record that is not a row of finite numbers: the message names the column.
fn bad_row(columns: &[&str], record: &csv::StringRecord, e: csv::Error) -> String {
    let field = match e.kind() {
        csv::ErrorKind::Deserialize { err, .. } => err.field(),
        _ => None,
    };
    match field.map(|c| c as usize) {
        Some(c) if c < columns.len() => format!(
            "{}: not a finite number: {:?}",
            columns[c],
            record.get(c).unwrap_or_default()
        ),
        _ => e.to_string(),
    }
}

/// The rows of a CSV table of finite numbers with the header `columns` (`#` comments and
/// blank lines skipped), each with its line; missing or extra columns, non-numbers and
/// non-finite numbers are errors naming the file, line and column.
fn numeric_rows<const N: usize>(
    file: &str,
    text: &str,
    columns: &[&str; N],
) -> Result<Vec<(usize, [f64; N])>, FormatError> {
    let mut records = crate::io::csv_table::records(file, text, true);
    let (hline, header) = records
        .find(|r| r.as_ref().map_or(true, |(_, h)| !blank_or_comment(h)))
        .transpose()?
        .ok_or_else(|| err(file, 1, "empty: expected a header line".into()))?;
    if header.iter().ne(columns.iter().copied()) {
        return Err(err(
            file,
            hline,
            format!(
                "header must be `{}`, got `{}`",
                columns.join(","),
                text.lines()
                    .nth(hline.saturating_sub(1))
                    .unwrap_or_default()
                    .trim()
            ),
        ));
    }
    let mut rows = Vec::new();
    for record in records {
        let (line, record) = record?;
        if blank_or_comment(&record) {
            continue;
        }
        if record.len() != N {
            return Err(err(
                file,
                line,
                format!("expected {N} columns, got {}", record.len()),
            ));
        }
        let v: Vec<f64> = record
            .deserialize(None)
            .map_err(|e| err(file, line, bad_row(columns, &record, e)))?;
        let v: [f64; N] = v
            .try_into()
            .map_err(|_| err(file, line, format!("expected {N} numbers")))?;
        if let Some(c) = v.iter().position(|x| !x.is_finite()) {
            return Err(err(
                file,
                line,
                format!("{}: not a finite number: {:?}", columns[c], &record[c]),
            ));
        }
        rows.push((line, v));
    }
    Ok(rows)
}

/// Parses a motion CSV (header line with [`MOTION_COLUMNS`], `#` comments allowed). Rejects
/// missing or extra columns, non-numbers, times that do not increase and quaternions whose
/// norm is not 1 within 1e-6, naming the file, line and column.
pub fn parse_motion(file: &str, text: &str) -> Result<Vec<MotionRow>, FormatError> {
    Ok(parse_motion_lines(file, text)?
        .into_iter()
        .map(|(_, row)| row)
        .collect())
}

/// As [`parse_motion`], with the line of each row.
pub fn parse_motion_lines(file: &str, text: &str) -> Result<Vec<(usize, MotionRow)>, FormatError> {
    let mut rows: Vec<(usize, MotionRow)> = Vec::new();
    for (line, v) in numeric_rows(file, text, &MOTION_COLUMNS)? {
        let sphere = |o: usize| -> Result<(Vec3, UnitQuaternion<f64>, Vec3, Vec3), FormatError> {
            let q = Quaternion::new(v[o + 3], v[o + 4], v[o + 5], v[o + 6]);
            if (q.norm() - 1.0).abs() > 1e-6 {
                return Err(err(
                    file,
                    line,
                    format!(
                        "{}..{}: quaternion norm {} is not 1",
                        MOTION_COLUMNS[o + 3],
                        MOTION_COLUMNS[o + 6],
                        q.norm()
                    ),
                ));
            }
            Ok((
                Vec3::new(v[o], v[o + 1], v[o + 2]),
                UnitQuaternion::new_normalize(q),
                Vec3::new(v[o + 7], v[o + 8], v[o + 9]),
                Vec3::new(v[o + 10], v[o + 11], v[o + 12]),
            ))
        };
        let (x1, q1, v1, w1) = sphere(1)?;
        let (x2, q2, v2, w2) = sphere(14)?;
        if let Some((_, prev)) = rows.last() {
            if v[0] <= prev.t {
                return Err(err(
                    file,
                    line,
                    format!("t: {} does not increase (previous {})", v[0], prev.t),
                ));
            }
        }
        rows.push((
            line,
            MotionRow {
                t: v[0],
                x: [x1, x2],
                q: [q1, q2],
                v: [v1, v2],
                w: [w1, w2],
            },
        ));
    }
    Ok(rows)
}

/// Parses a forces CSV (header line with [`FORCE_COLUMNS`], `#` comments allowed), each row
/// with its line. Rejects missing or extra columns, non-numbers and non-finite numbers,
/// naming the file, line and column.
pub fn parse_forces_lines(file: &str, text: &str) -> Result<Vec<(usize, ForceRow)>, FormatError> {
    Ok(numeric_rows(file, text, &FORCE_COLUMNS)?
        .into_iter()
        .map(|(line, v)| {
            let vec = |o: usize| Vec3::new(v[o], v[o + 1], v[o + 2]);
            let row = ForceRow {
                t: v[0],
                f: [vec(1), vec(7)],
                torque: [vec(4), vec(10)],
                delta: v[13],
                fn_signed: v[14],
                ft: v[15],
            };
            (line, row)
        })
        .collect())
}

/// The same motion as `rows` with `fine` rows per row (time step Δt/`fine`): row k of `rows`
/// is row k·`fine` of the result, unchanged. Row k's velocities are those of the step
/// [t_(k−1), t_k] (as every prescribed motion of the verification writes them), and between
/// two rows each sphere moves as that step's rigid motion: its orientation turns at the
/// constant rate of q_k q_(k−1)⁻¹ (a slerp), its centre along the circular arc from x_(k−1) to
/// x_k that ends with the velocity v_k (a straight line where v_k is along the chord or zero),
/// at constant speed; the rows in between carry the spin w_k and the velocity of the arc. A
/// rigid rotation, a spin in place, an orbit and a straight press are thus refined exactly.
pub fn refine(rows: &[MotionRow], fine: usize) -> Vec<MotionRow> {
    let Some(first) = rows.first() else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity((rows.len() - 1) * fine + 1);
    out.push(*first);
    for pair in rows.windows(2) {
        let (from, to) = (&pair[0], &pair[1]);
        for j in 1..fine {
            let s = j as f64 / fine as f64;
            let mut row = *to;
            row.t = from.t + s * (to.t - from.t);
            for k in 0..2 {
                let turn = (to.q[k] * from.q[k].inverse()).scaled_axis();
                row.q[k] = UnitQuaternion::from_scaled_axis(s * turn) * from.q[k];
                (row.x[k], row.v[k]) = along_arc(from.x[k], to.x[k], to.v[k], s);
            }
            out.push(row);
        }
        out.push(*to);
    }
    out
}

/// The point at the fraction `s` of the circular arc from `a` to `b` that ends with the
/// velocity `v` (constant speed), and its velocity there; a straight line when `v` is zero or
/// along the chord. A chord b − a of an arc turning by θ about the unit axis e makes the angle
/// θ/2 with the tangent at either end, and the chord to the fraction s has the length
/// |b − a|·sin(sθ/2)/sin(θ/2) (circle geometry).
fn along_arc(a: Vec3, b: Vec3, v: Vec3, s: f64) -> (Vec3, Vec3) {
    let chord = b - a;
    let axis = chord.cross(&v);
    let theta = 2.0 * axis.norm().atan2(chord.dot(&v));
    match nalgebra::Unit::try_new(axis, 1e-300) {
        Some(e) if theta.abs() > 1e-12 && chord.dot(&v) > 0.0 => {
            let turn = |angle: f64| UnitQuaternion::from_axis_angle(&e, angle);
            let x = a + turn(0.5 * (s - 1.0) * theta)
                * chord
                * ((0.5 * s * theta).sin() / (0.5 * theta).sin());
            (x, turn((s - 1.0) * theta) * v)
        }
        _ => (a + s * chord, v),
    }
}

/// A motion CSV of `rows` (round-trips bit for bit through [`parse_motion`]).
pub fn motion_csv(rows: &[MotionRow]) -> String {
    crate::io::csv_table::write(
        MOTION_COLUMNS,
        rows.iter().map(|r| {
            let mut v = vec![r.t];
            for k in 0..2 {
                let q = r.q[k].quaternion();
                v.extend(r.x[k].iter());
                v.extend([q.w, q.i, q.j, q.k]);
                v.extend(r.v[k].iter());
                v.extend(r.w[k].iter());
            }
            v
        }),
    )
}

/// A forces CSV of `rows`.
pub fn forces_csv(rows: &[ForceRow]) -> String {
    crate::io::csv_table::write(
        FORCE_COLUMNS,
        rows.iter().map(|r| {
            let mut v = vec![r.t];
            for k in 0..2 {
                v.extend(r.f[k].iter());
                v.extend(r.torque[k].iter());
            }
            v.extend([r.delta, r.fn_signed, r.ft]);
            v
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(t: f64, gap: f64) -> MotionRow {
        MotionRow {
            t,
            x: [Vec3::zeros(), Vec3::new(0.0, 0.0, 1.0 - gap)],
            q: [UnitQuaternion::identity(); 2],
            v: [Vec3::zeros(); 2],
            w: [Vec3::zeros(); 2],
        }
    }

    #[test]
    fn motion_csv_round_trips_and_errors_name_line_and_column() {
        let rows = vec![still(0.0, 1e-3), still(1e-4, 2e-3)];
        let text = motion_csv(&rows);
        assert_eq!(parse_motion("m.csv", &text).unwrap(), rows);

        let bad = text.replacen("0.999,", "0.999x,", 1);
        let e = parse_motion("m.csv", &bad).unwrap_err().to_string();
        assert!(e.starts_with("m.csv:2: z2: not a finite number"), "{e}");

        let mut lines: Vec<&str> = text.lines().collect();
        lines.swap(1, 2);
        let e = parse_motion("m.csv", &lines.join("\n"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.csv:3: t: 0 does not increase"), "{e}");

        let e = parse_motion("m.csv", "t,x1\n").unwrap_err().to_string();
        assert!(e.starts_with("m.csv:1: header must be"), "{e}");
        assert!(e.ends_with("got `t,x1`"), "{e}");

        // comments and blank lines count in the line numbers
        let commented = format!(
            "# a motion\n\n   \n{}",
            bad.replacen('\n', "\n  # row 1\n", 1)
        );
        let e = parse_motion("m.csv", &commented).unwrap_err().to_string();
        assert!(e.starts_with("m.csv:6: z2: not a finite number"), "{e}");
        let e = parse_motion("m.csv", "# nothing\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.csv:1: empty"), "{e}");
        let short = text.replacen(",0,0,0,0,", ",", 1);
        let e = parse_motion("m.csv", &short).unwrap_err().to_string();
        assert!(e.starts_with("m.csv:2: expected 27 columns, got 23"), "{e}");
        let nan = text.replacen("0.999,", "NaN,", 1);
        let e = parse_motion("m.csv", &nan).unwrap_err().to_string();
        assert_eq!(e, "m.csv:2: z2: not a finite number: \"NaN\"");

        let unnormalised = text.replacen(",1,0,0,0,", ",2,0,0,0,", 1);
        let e = parse_motion("m.csv", &unnormalised)
            .unwrap_err()
            .to_string();
        assert!(e.contains("quaternion norm 2 is not 1"), "{e}");
    }

    #[test]
    fn forces_csv_round_trips_and_errors_name_line_and_column() {
        let case = Case::parse(
            include_str!("../../cases/verify/objectivity.toml"),
            "o.toml",
        )
        .unwrap();
        let mut rows = vec![still(0.0, 1e-3)];
        rows.push(MotionRow {
            t: 1e-4,
            w: [Vec3::zeros(), Vec3::new(0.0, 0.3, 0.0)],
            ..still(1e-4, 1e-3)
        });
        let f = drive(
            law_of(&case).unwrap().as_ref(),
            [0.5, 0.5],
            &rows,
            Increment::Trapezoid,
        );
        let text = forces_csv(&f);
        let read: Vec<ForceRow> = parse_forces_lines("f.csv", &text)
            .unwrap()
            .into_iter()
            .map(|(_, r)| r)
            .collect();
        assert_eq!(read, f);
        assert!(f[1].ft > 0.0 && f[1].torque[1] != Vec3::zeros());

        let e = parse_forces_lines("f.csv", &text.replacen(",fn,", ",f_n,", 1))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("f.csv:1: header must be `t,fx1"), "{e}");
        let with_field = |k: usize, value: &str| {
            let mut lines: Vec<String> = text.lines().map(String::from).collect();
            let mut fields: Vec<&str> = lines[2].split(',').collect();
            fields[k] = value;
            lines[2] = fields.join(",");
            lines.join("\n")
        };
        let e = parse_forces_lines("f.csv", &with_field(1, "inf"))
            .unwrap_err()
            .to_string();
        assert_eq!(e, "f.csv:3: fx1: not a finite number: \"inf\"");
        let e = parse_forces_lines("f.csv", &with_field(15, "1,2"))
            .unwrap_err()
            .to_string();
        assert_eq!(e, "f.csv:3: expected 16 columns, got 17");
    }

    #[test]
    fn the_widest_contact_step_counts_the_steps_that_end_in_contact() {
        // apart (gap −1e-3) at t = 1 and 4: the steps ending there are not the law's
        let rows = [
            still(0.0, 1e-3),
            still(1.0, -1e-3),
            still(1.5, 1e-3),
            still(2.0, 1e-3),
            still(4.0, -1e-3),
            still(4.5, 1e-3),
        ];
        assert_eq!(widest_contact_step([0.5, 0.5], &rows), Some((2, 0.5)));
        assert_eq!(widest_contact_step([0.5, 0.5], &rows[..2]), None);
        assert!(coarse(0.5, 4.99) && !coarse(0.5, 5.0));
    }

    #[test]
    fn static_overlap_gives_kn_delta_on_sphere_2_along_n_and_nothing_apart() {
        let case = Case::parse(
            include_str!("../../cases/verify/binary_collision.toml"),
            "b.toml",
        )
        .unwrap();
        let law = law_of(&case).unwrap();
        let rows = [still(0.0, 1e-3), still(1e-4, 1e-3), still(2e-4, -1e-3)];
        let f = drive(law.as_ref(), [0.5, 0.5], &rows, Increment::Positions);
        // n from 1 to 2 is +z: sphere 2 is pushed along +z, sphere 1 along −z
        assert!((f[1].f[1].z - 2e5 * 1e-3).abs() < 1e-9);
        assert_eq!(f[1].f[0], -f[1].f[1]);
        assert!((f[1].delta - 1e-3).abs() < 1e-15 && f[1].ft == 0.0);
        assert_eq!(f[2].f, [Vec3::zeros(); 2]);
        assert!(f[2].delta < 0.0);
    }
}
