//! Ratcheting: closed cycles of relative motion below the sliding limit (McNamara, García-Rojo &
//! Herrmann, PRE 77, 031304, 2008), per tangential convention (or for an external program),
//! through a [`MotionDriver`].
//!
//! At constant overlap (constant normal load), with the dashpots switched off: (A) sphere 2
//! translates around sphere 1 by an arc dx (an orbit at constant distance, loading the spring
//! to about half of mu·fn), (B) the pair rotates rigidly by a, (C) sphere 2 translates back by
//! −dx, (D) the pair rotates back by −a. The spheres end exactly where they started, so an
//! elastic contact must return to its initial (zero) force with zero net work. A slip that is
//! not objective deposits a spurious displacement −δ·Ω×n·dt during the rigid rotations (δ the
//! overlap, i.e. fn/kn), which the two rotations cancel only to O(δ·a·dx). A spring that does
//! not twist with the contact (a convention without the `twists_spring` property) is left
//! turned by the rotation's twist: a residual ≈ kt·dx·a whatever the load, which dominates the
//! δ-part here. The rotation is a = 0.1 rad, so that no convention reaches the sliding limit
//! (a full-radius slip adds −δ·a to the spring while the pair turns).

use nalgebra::{Unit, UnitQuaternion};

use super::diagnosis::{Property, Tests};
use super::driver::MotionDriver;
use super::objectivity::{rigid_rotation, tangent_axis};
use super::{row_abs, Row, Subject};
use crate::case::Case;
use crate::contact::Tangential;
use crate::verify::kinematics::{pair_of, ForceRow, MotionRow};
use crate::Vec3;

/// Appends `steps` rows translating sphere 2 around sphere 1's centre about `axis` by `angle`,
/// starting from the last row; sphere 1 and both spins are still.
fn orbit(rows: &mut Vec<MotionRow>, axis: Vec3, angle: f64, steps: usize, dt: f64) {
    let from = *rows.last().expect("a starting row");
    let axis = Unit::new_normalize(axis);
    let omega = axis.into_inner() * (angle / (steps as f64 * dt));
    for k in 1..=steps {
        let q = UnitQuaternion::from_axis_angle(&axis, angle * k as f64 / steps as f64);
        let mut row = from;
        row.t = from.t + k as f64 * dt;
        row.x[1] = from.x[0] + q * (from.x[1] - from.x[0]);
        row.v = [Vec3::zeros(), omega.cross(&(row.x[1] - from.x[0]))];
        row.w = [Vec3::zeros(); 2];
        rows.push(row);
    }
}

/// Net work done on the contact over the rows (trapezoidal in the forces, exact displacements
/// and rotation vectors), in units of force·length.
pub fn net_work(rows: &[MotionRow], f: &[ForceRow]) -> f64 {
    let mut w = 0.0;
    for k in 1..rows.len() {
        for s in 0..2 {
            let dx = rows[k].x[s] - rows[k - 1].x[s];
            let dphi = (rows[k].q[s] * rows[k - 1].q[s].inverse()).scaled_axis();
            w += 0.5 * (f[k].f[s] + f[k - 1].f[s]).dot(&dx);
            w += 0.5 * (f[k].torque[s] + f[k - 1].torque[s]).dot(&dphi);
        }
    }
    w
}

/// What one cycle left behind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    /// Tangential force at the end (force units).
    pub residual: f64,
    /// Largest tangential force during the cycle.
    pub peak: f64,
    /// Net work done on the contact (force·length).
    pub work: f64,
}

/// The motion of one cycle of `case`'s pair: at the case's positions scaled to the overlap
/// `overlap`, sphere 2 orbits sphere 1 by the arc `dx`, the pair rotates by 0.1 rad about
/// `axis`, sphere 2 orbits back, the pair rotates back.
pub fn motion(case: &Case, axis: Vec3, overlap: f64, dx: f64) -> anyhow::Result<Vec<MotionRow>> {
    let (mut x, radius) = pair_of(case)?;
    let dt = case.dt();
    let n0 = (x[1] - x[0]).normalize();
    x[1] = x[0] + n0 * (radius[0] + radius[1] - overlap);
    let orbit_axis = tangent_axis(n0);
    let theta = dx / (radius[0] + radius[1]);
    let a = 0.1;
    let mut rows = vec![MotionRow {
        t: 0.0,
        x,
        q: [UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    }];
    orbit(&mut rows, orbit_axis, theta, 2000, dt);
    rigid_rotation(&mut rows, axis, a, 10_000, dt);
    let turned = UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), a) * orbit_axis;
    orbit(&mut rows, turned, -theta, 2000, dt);
    rigid_rotation(&mut rows, axis, -a, 10_000, dt);
    Ok(rows)
}

/// One cycle of `case`'s contact ([`motion`]), driven by `driver`.
pub fn cycle(
    case: &Case,
    axis: Vec3,
    overlap: f64,
    dx: f64,
    driver: &dyn MotionDriver,
) -> anyhow::Result<Cycle> {
    let rows = motion(case, axis, overlap, dx)?;
    let f = driver.drive(case, &rows)?;
    Ok(Cycle {
        residual: f.last().map_or(0.0, |r| r.ft),
        peak: f.iter().map(|r| r.ft).fold(0.0, f64::max),
        work: net_work(&rows, &f),
    })
}

/// The rotations of the cycle, by their names in the table.
pub const ROTATIONS: [&str; 2] = ["rotation about n", "rotation about t"];

/// The name of the cycle of `subject`'s contact with the rotation named `label`.
pub fn case_name(subject: &str, label: &str) -> String {
    format!("ratchet {subject} {label}")
}

/// The ratcheting rows of `subject` with the rotation named `label` (one of [`ROTATIONS`]):
/// at the case's overlap and at twice it, dashpots off.
pub fn rotation_rows(base: &Case, subject: &Subject, label: &str) -> anyhow::Result<Vec<Row>> {
    let (x, radius) = pair_of(base)?;
    let n0 = (x[1] - x[0]).normalize();
    let axis = match label {
        "rotation about n" => n0,
        _ => tangent_axis(n0).cross(&n0),
    };
    let overlap = radius[0] + radius[1] - (x[1] - x[0]).norm();
    // loads the spring to half the sliding limit at the case's overlap
    let dx = 0.5 * base.contact.mu * base.contact.kn * overlap / base.contact.kt;
    let mut case = subject.case(base);
    case.contact.gamman = 0.0;
    case.contact.gammat = 0.0;
    let c = cycle(&case, axis, overlap, dx, subject.driver)?;
    let energy = c.peak * c.peak / (2.0 * case.contact.kt);
    let name = case_name(&subject.label, label);
    let gate = |r: Row| {
        r.gating_if(subject.properties.objective)
            .tests(Property::ClosedCycleEnergy)
    };
    let (res, work) = (c.residual / c.peak, c.work / energy);
    let mut rows = vec![
        gate(row_abs(&name, "residual |Ft| / peak |Ft|", 0.0, res, 1e-6)),
        gate(row_abs(
            &name,
            "net work / peak elastic energy",
            0.0,
            work,
            1e-6,
        )),
    ];
    // A spring that does not twist with the pair is left turned by the rotation's twist,
    // ≈ a·cos θ, wherever the translations put it: a residual ≈ kt·dx·a, independent of the
    // load.
    if !subject.properties.twists_spring && label == "rotation about n" {
        let twice = cycle(&case, axis, 2.0 * overlap, dx, subject.driver)?;
        rows.push(
            row_abs(
                &name,
                "load exponent of the residual (fn x2)",
                0.0,
                (twice.residual / c.residual).log2(),
                0.05,
            )
            .tests(Property::SpringTwist),
        );
    }
    Ok(rows)
}

/// The ratcheting rows of every tangential convention.
pub fn rows(base: &Case) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for conv in Tangential::with_constant_kt() {
        for label in ROTATIONS {
            rows.extend(rotation_rows(base, &Subject::own(conv), label)?);
        }
    }
    Ok(rows)
}
