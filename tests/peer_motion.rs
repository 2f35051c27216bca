//! The real LAMMPS and LIGGGHTS libraries (Debian `liblammps0`, `libliggghts3`, installed with
//! the `lammps` and `liggghts` packages by ci/test.sh) driven through the prescribed motions
//! of the objectivity and ratcheting cases, beside verdem's re-implementations of their
//! conventions.

mod common;

use nalgebra::{Rotation3, Unit, UnitQuaternion};
use verdem::case::Case;
use verdem::kinematics::{self, ForceRow, Increment, MotionRow};
use verdem::peers::motion::{self, MotionPeer};
use verdem::verify::objectivity::{rigid_rotation, spin_sphere_2, tangent_axis, tangential_force};
use verdem::Vec3;

/// The objectivity case (the two spheres and the benchmark's law) in `peer`'s convention.
fn case_of(peer: MotionPeer) -> Case {
    let mut case = Case::load(&common::root().join("cases/verify/objectivity.toml")).unwrap();
    case.contact.tangential = peer.convention();
    case
}

/// Whether `peer`'s library loads; if not, prints why the test is skipped.
fn loaded(peer: MotionPeer) -> bool {
    match peer.load() {
        Ok(()) => true,
        Err(e) => {
            eprintln!("SKIPPED: {}: {e:#}", peer.name());
            false
        }
    }
}

/// verdem's re-implementation of the case's convention through `rows`.
fn verdem(case: &Case, rows: &[MotionRow]) -> Vec<ForceRow> {
    let (_, radius) = kinematics::pair_of(case).unwrap();
    let law = kinematics::law_of(case);
    kinematics::drive(law.as_ref(), radius, rows, Increment::Positions)
}

/// The largest difference of any force or torque component between `a` and `b`, over the
/// largest force or torque component of `b`.
fn difference(a: &[ForceRow], b: &[ForceRow]) -> f64 {
    assert_eq!(a.len(), b.len());
    let comps = |r: &ForceRow| -> Vec<f64> {
        r.f.iter()
            .chain(&r.torque)
            .flat_map(|v| v.iter().copied())
            .collect()
    };
    let (mut diff, mut scale) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        for (p, q) in comps(x).into_iter().zip(comps(y)) {
            diff = diff.max((p - q).abs());
            scale = scale.max(q.abs());
        }
    }
    diff / scale
}

/// The objectivity motion of `src/verify/objectivity.rs` (`drifts`): sphere 2 spun to load
/// the spring, held, then the pair rotated rigidly by 1 rad about `axis`; with the row of the
/// loaded state.
fn objectivity_motion(case: &Case, axis: Vec3) -> (Vec<MotionRow>, usize) {
    let (x, radius) = kinematics::pair_of(case).unwrap();
    let dt = case.dt();
    let n0 = (x[1] - x[0]).normalize();
    let fn0 = case.contact.kn * (radius[0] + radius[1] - (x[1] - x[0]).norm());
    let load = 0.2 * case.contact.mu * fn0 / case.contact.kt / radius[1];
    let mut rows = vec![MotionRow {
        t: 0.0,
        x,
        q: [UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    }];
    spin_sphere_2(&mut rows, tangent_axis(n0), load, 100, 10, dt);
    let loaded = rows.len() - 1;
    rigid_rotation(&mut rows, axis, 1.0, 100_000, dt);
    (rows, loaded)
}

/// Drifts per radian (Fn, |Ft|, direction of Ft) of forces `f` of the objectivity motion about
/// `axis`, as `objectivity::drifts` measures them.
fn drifts(case: &Case, f: &[ForceRow], loaded: usize, axis: Vec3) -> [f64; 3] {
    let (x, _) = kinematics::pair_of(case).unwrap();
    let n0 = (x[1] - x[0]).normalize();
    let rot = Rotation3::from_axis_angle(&Unit::new_normalize(axis), 1.0);
    let end = f.len() - 1;
    let (ft0, ft1) = (
        tangential_force(&f[loaded], n0),
        tangential_force(&f[end], rot * n0),
    );
    [
        (f[end].fn_signed - f[loaded].fn_signed) / f[loaded].fn_signed,
        (ft1.norm() - ft0.norm()) / ft0.norm(),
        ft1.angle(&(rot * ft0)),
    ]
}

fn axes(case: &Case) -> [(&'static str, Vec3); 3] {
    let (x, _) = kinematics::pair_of(case).unwrap();
    let n0 = (x[1] - x[0]).normalize();
    let t = tangent_axis(n0);
    [
        ("tangent axis", t),
        ("normal axis", n0),
        ("oblique axis", (t + n0 + t.cross(&n0)).normalize()),
    ]
}

fn objectivity(peer: MotionPeer) {
    if !loaded(peer) {
        return;
    }
    let case = case_of(peer);
    for (label, axis) in axes(&case) {
        let (rows, loaded) = objectivity_motion(&case, axis);
        let real = motion::drive(peer, &case, &rows, Increment::Positions).unwrap();
        let ours = verdem(&case, &rows);
        let d = difference(&real, &ours);
        let dr = drifts(&case, &real, loaded, axis);
        let dv = verdem::verify::objectivity::drifts(&case, axis).unwrap();
        eprintln!(
            "{} {label}: difference {d:.3e}; drifts real {dr:?} verdem {dv:?}",
            peer.name()
        );
    }
}

#[test]
fn lammps_objectivity() {
    objectivity(MotionPeer::Lammps);
}

#[test]
fn liggghts_objectivity() {
    objectivity(MotionPeer::Liggghts);
}
