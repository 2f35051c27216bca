//! Objectivity of the tangential force under a rigid rotation of a loaded contact, per
//! tangential convention (or for an external program), through a [`MotionDriver`].
//!
//! Sphere 2 is spun about an axis of the tangent plane until the tangential spring carries
//! about a fifth of mu·fn, held still, then the pair is rotated rigidly by 1 rad (positions,
//! orientations and spins consistent with the rigid motion) about an axis in the tangent plane
//! about the contact normal, or about an axis mixing both, in 10⁵ steps. An objective law
//! keeps Fn and |Ft| constant and turns Ft with the pair: every drift below is expected to
//! vanish (per radian). Only the conventions that claim to be objective (the reference law)
//! are held to it; the peers' rows document their conventions (a first-order frame update
//! drifts by about half the step's turn per radian, 5e-6 here).

use nalgebra::{Rotation3, Unit, UnitQuaternion};

use super::diagnosis::{Property, Tests};
use super::driver::MotionDriver;
use super::{row_abs, Row, Subject};
use crate::case::Case;
use crate::contact::Tangential;
use crate::verify::kinematics::{pair_of, ForceRow, MotionRow};
use crate::Vec3;

/// Steps of the rigid rotation per radian.
const STEPS_PER_RADIAN: usize = 100_000;

/// Appends `steps` rows rotating the whole pair rigidly about `axis` through the origin by
/// `angle`, starting from the last row.
pub fn rigid_rotation(rows: &mut Vec<MotionRow>, axis: Vec3, angle: f64, steps: usize, dt: f64) {
    let from = *rows.last().expect("a starting row");
    let axis = Unit::new_normalize(axis);
    let omega = axis.into_inner() * (angle / (steps as f64 * dt));
    for k in 1..=steps {
        let q = UnitQuaternion::from_axis_angle(&axis, angle * k as f64 / steps as f64);
        let x = [q * from.x[0], q * from.x[1]];
        rows.push(MotionRow {
            t: from.t + k as f64 * dt,
            x,
            q: [q * from.q[0], q * from.q[1]],
            v: [omega.cross(&x[0]), omega.cross(&x[1])],
            w: [omega, omega],
        });
    }
}

/// Appends `steps` rows spinning sphere 2 about `axis` by `angle` in place, then `hold` still
/// rows, starting from the last row; both centres and sphere 1 are still (their velocities
/// are zero, whatever the last row's).
pub fn spin_sphere_2(
    rows: &mut Vec<MotionRow>,
    axis: Vec3,
    angle: f64,
    steps: usize,
    hold: usize,
    dt: f64,
) {
    let from = *rows.last().expect("a starting row");
    let axis = Unit::new_normalize(axis);
    let omega = axis.into_inner() * (angle / (steps as f64 * dt));
    for k in 1..=steps + hold {
        let turned = angle * k.min(steps) as f64 / steps as f64;
        let mut row = from;
        row.t = from.t + k as f64 * dt;
        row.q[1] = UnitQuaternion::from_axis_angle(&axis, turned) * from.q[1];
        row.v = [Vec3::zeros(); 2];
        row.w = [
            Vec3::zeros(),
            if k <= steps { omega } else { Vec3::zeros() },
        ];
        rows.push(row);
    }
}

/// A unit axis in the tangent plane of the unit normal `n`: n × x, or y where n ∥ x.
pub fn tangent_axis(n: Vec3) -> Vec3 {
    n.cross(&Vec3::x()).try_normalize(1e-9).unwrap_or(Vec3::y())
}

/// Tangential part of the force on sphere 2.
pub fn tangential_force(f: &ForceRow, n: Vec3) -> Vec3 {
    f.f[1] - f.f[1].dot(&n) * n
}

/// Drifts per radian (Fn, |Ft|, direction of Ft) of `case`'s contact, driven by `driver`,
/// rotated about `axis`.
pub fn drifts(case: &Case, axis: Vec3, driver: &dyn MotionDriver) -> anyhow::Result<[f64; 3]> {
    let (x, radius) = pair_of(case)?;
    let dt = case.dt();
    let start = MotionRow {
        t: 0.0,
        x,
        q: [UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    };
    let n0 = (x[1] - x[0]).normalize();
    let fn0 = case.contact.kn * (radius[0] + radius[1] - (x[1] - x[0]).norm());
    // spin about a tangent axis until the spring carries ~ mu fn / 5
    let tangent = tangent_axis(n0);
    let load = 0.2 * case.contact.mu * fn0 / case.contact.kt / radius[1];
    let mut rows = vec![start];
    spin_sphere_2(&mut rows, tangent, load, 100, 10, dt);
    let loaded = rows.len() - 1;
    rigid_rotation(&mut rows, axis, 1.0, STEPS_PER_RADIAN, dt);
    let f = driver.drive(case, &rows)?;
    let end = rows.len() - 1;
    let rot = Rotation3::from_axis_angle(&Unit::new_normalize(axis), 1.0);
    let n1 = rot * n0;
    let (ft0, ft1) = (
        tangential_force(&f[loaded], n0),
        tangential_force(&f[end], n1),
    );
    let turned = rot * ft0;
    Ok([
        (f[end].fn_signed - f[loaded].fn_signed) / f[loaded].fn_signed,
        (ft1.norm() - ft0.norm()) / ft0.norm(),
        ft1.angle(&turned),
    ])
}

/// The rotation axes, by their names in the table.
pub const AXES: [&str; 3] = ["tangent axis", "normal axis", "oblique axis"];

/// The rotation axis named `label` (one of [`AXES`]) for the unit normal `n0`.
fn axis(n0: Vec3, label: &str) -> Vec3 {
    let in_plane = tangent_axis(n0);
    match label {
        "tangent axis" => in_plane,
        "normal axis" => n0,
        _ => (in_plane + n0 + in_plane.cross(&n0)).normalize(),
    }
}

/// The name of the case rotating `subject`'s contact about the axis named `label`.
pub fn case_name(subject: &str, label: &str) -> String {
    format!("objectivity {subject} {label}")
}

/// The objectivity rows of `subject` rotated about the axis named `label` (one of [`AXES`]).
pub fn axis_rows(base: &Case, subject: &Subject, label: &str) -> anyhow::Result<Vec<Row>> {
    let (x, _) = pair_of(base)?;
    let n0 = (x[1] - x[0]).normalize();
    let case = subject.case(base);
    let [dfn, dft, dir] = drifts(&case, axis(n0, label), subject.driver)?;
    let name = case_name(&subject.label, label);
    // about a tangent axis the normal tilts only; the other axes twist the pair about it
    let property = match label {
        "tangent axis" => Property::Objectivity,
        _ => Property::SpringTwist,
    };
    let gate = |r: Row| r.gating_if(subject.properties.objective).tests(property);
    Ok(vec![
        gate(row_abs(&name, "Fn drift per rad", 0.0, dfn, 1e-6)),
        gate(row_abs(&name, "|Ft| drift per rad", 0.0, dft, 1e-6)),
        gate(row_abs(&name, "Ft direction error per rad", 0.0, dir, 1e-6)),
    ])
}

/// The objectivity rows of every tangential convention.
pub fn rows(base: &Case) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for conv in Tangential::with_constant_kt() {
        for label in AXES {
            rows.extend(axis_rows(base, &Subject::own(conv), label)?);
        }
    }
    Ok(rows)
}
