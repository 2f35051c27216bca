//! The real LAMMPS and LIGGGHTS libraries (Debian `liblammps0`, `libliggghts3`, installed by
//! ci/test.sh) driven through the prescribed motions of the objectivity and ratcheting cases,
//! beside verdem's re-implementations of their conventions (`lammps-granular`, `liggghts`).
//!
//! Agreement bound: both sides integrate the same spring with one rounding per step in a
//! different order, so their forces may differ by at most about N·ε relative to the largest
//! force, N the number of rows (the rounding errors adding up in the worst case; a random walk
//! gives √N·ε). A law that differed by even a second-order term per step, (ω dt)² ≈ 1e-10 here,
//! would exceed it.

mod common;

use nalgebra::{Rotation3, Unit, UnitQuaternion};
use verdem::case::Case;
use verdem::peers::motion::{self, MotionPeer};
use verdem::verify::kinematics::{self, ForceRow, Increment, MotionRow};
use verdem::verify::objectivity::{rigid_rotation, spin_sphere_2, tangent_axis, tangential_force};
use verdem::verify::{self, ratchet, row_abs, Row};
use verdem::Vec3;

/// The tolerance of the verification table's objectivity and ratchet rows.
const ROW_TOLERANCE: f64 = 1e-6;

/// The bound on the binary's and the re-implementation's difference over `n` rows, relative
/// to the largest force or torque (module doc).
fn bound(n: usize) -> f64 {
    n as f64 * f64::EPSILON
}

/// Asserts that a measure of the binary agrees with the re-implementation's to `tol`.
fn assert_agree(what: &str, real: f64, ours: f64, tol: f64) {
    assert!(
        (real - ours).abs() <= tol,
        "{what}: binary {real:e}, re-implementation {ours:e} (tolerance {tol:e})"
    );
}

/// Prints the rows measured on the binary as the verification table prints them, and asserts
/// that each has the verdict of the same row measured on the re-implementation, `ours`, and
/// that some fail: the peer's convention does not promise them (they are FAIL* rows of
/// `verdem verify`), and the binary has the defect.
fn assert_defects(peer: MotionPeer, rows: &[Row], ours: &[Row]) {
    assert!(!peer.convention().properties().objective);
    eprintln!(
        "{} (the real library):\n{}",
        peer.name(),
        verify::table(rows)
    );
    for (r, o) in rows.iter().zip(ours) {
        assert_eq!(r.pass(), o.pass(), "{}: {}", r.case, r.quantity);
    }
    assert!(rows.iter().any(|r| r.pass() == Some(false)));
}

/// The objectivity case (the two spheres and the benchmark's law) in `peer`'s convention.
fn case_of(peer: MotionPeer) -> Case {
    let mut case = Case::load(&common::root().join("cases/verify/objectivity.toml")).unwrap();
    case.contact.tangential = peer.convention().into();
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
    let law = kinematics::law_of(case).unwrap();
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

/// Residual |Ft| over the peak |Ft|, and net work over the peak elastic energy, of a cycle.
fn ratchet_measures(case: &Case, rows: &[MotionRow], f: &[ForceRow]) -> [f64; 2] {
    let peak = f.iter().map(|r| r.ft).fold(0.0, f64::max);
    let residual = f.last().unwrap().ft;
    let energy = peak * peak / (2.0 * case.contact.kt);
    [residual / peak, ratchet::net_work(rows, f) / energy]
}

fn ratchet(peer: MotionPeer) {
    if !loaded(peer) {
        return;
    }
    let mut case = case_of(peer);
    case.contact.gamman = 0.0;
    case.contact.gammat = 0.0;
    let (x, radius) = kinematics::pair_of(&case).unwrap();
    let n0 = (x[1] - x[0]).normalize();
    let along = tangent_axis(n0).cross(&n0);
    let overlap = radius[0] + radius[1] - (x[1] - x[0]).norm();
    let dx = 0.5 * case.contact.mu * case.contact.kn * overlap / case.contact.kt;
    let (mut table, mut reimplemented) = (Vec::new(), Vec::new());
    for (label, axis) in [("rotation about n", n0), ("rotation about t", along)] {
        let mut residuals = Vec::new();
        for load in [1.0, 2.0] {
            let rows = ratchet::motion(&case, axis, load * overlap, dx).unwrap();
            let real = motion::drive(peer, &case, &rows, Increment::Positions).unwrap();
            let ours = verdem(&case, &rows);
            let d = difference(&real, &ours);
            let name = format!("ratchet {} {label} load x{load}", peer.name());
            eprintln!(
                "{name}: difference {d:.2e} (bound {:.2e})",
                bound(rows.len())
            );
            assert!(d <= bound(rows.len()), "{name}: difference {d:e}");
            let [res, work] = ratchet_measures(&case, &rows, &real);
            let [res_v, work_v] = ratchet_measures(&case, &rows, &ours);
            // residual and work are differences of forces and energies of the cycle's scale
            assert_agree(&name, res, res_v, bound(rows.len()));
            assert_agree(&name, work, work_v, bound(rows.len()));
            if load == 1.0 {
                let name = format!("ratchet {} (binary) {label}", peer.name());
                let row =
                    |q: &str, m: f64| row_abs(&name, q, 0.0, m, ROW_TOLERANCE).gating_if(false);
                table.push(row("residual |Ft| / peak |Ft|", res));
                table.push(row("net work / peak elastic energy", work));
                reimplemented.push(row("residual |Ft| / peak |Ft|", res_v));
                reimplemented.push(row("net work / peak elastic energy", work_v));
            }
            residuals.push(real.last().unwrap().ft);
        }
        if label == "rotation about n" {
            // the spring does not twist with the pair: a residual independent of the load
            let exponent = (residuals[1] / residuals[0]).log2();
            eprintln!(
                "{} ratchet {label}: load exponent {exponent:.2e}",
                peer.name()
            );
            assert!(exponent.abs() < 0.05, "load exponent {exponent}");
        }
    }
    assert_defects(peer, &table, &reimplemented);
}

#[test]
fn lammps_ratchet() {
    ratchet(MotionPeer::Lammps);
}

#[test]
fn lammps_hooke_history_ratchet() {
    ratchet(MotionPeer::LammpsHookeHistory);
}

#[test]
fn liggghts_ratchet() {
    ratchet(MotionPeer::Liggghts);
}

fn objectivity(peer: MotionPeer) {
    if !loaded(peer) {
        return;
    }
    let case = case_of(peer);
    let (mut table, mut ours_rows) = (Vec::new(), Vec::new());
    for (label, axis) in axes(&case) {
        let (rows, loaded) = objectivity_motion(&case, axis);
        let real = motion::drive(peer, &case, &rows, Increment::Positions).unwrap();
        let ours = verdem(&case, &rows);
        let d = difference(&real, &ours);
        let name = format!("objectivity {} (binary) {label}", peer.name());
        eprintln!(
            "{name}: difference {d:.2e} (bound {:.2e})",
            bound(rows.len())
        );
        assert!(d <= bound(rows.len()), "{name}: difference {d:e}");
        let measured = drifts(&case, &real, loaded, axis);
        let reimplemented =
            verdem::verify::objectivity::drifts(&case, axis, &verdem::verify::driver::OWN).unwrap();
        // the drifts are differences of forces relative to the loaded state's; the direction
        // error is an arc cosine, resolved to about √(2ε) ≈ 2e-8 near zero
        let tolerances = [bound(rows.len()), bound(rows.len()), 1e-7];
        let quantities = [
            "Fn drift per rad",
            "|Ft| drift per rad",
            "Ft direction error per rad",
        ];
        for k in 0..3 {
            let what = format!("{name}: {}", quantities[k]);
            assert_agree(
                &what,
                measured[k],
                reimplemented[k],
                tolerances[k] * (1.0 + reimplemented[k].abs()),
            );
        }
        // the binary's largest drift is the row its convention fails
        let worst = (0..3)
            .max_by(|&a, &b| measured[a].abs().total_cmp(&measured[b].abs()))
            .unwrap();
        let row =
            |m: f64| row_abs(&name, quantities[worst], 0.0, m, ROW_TOLERANCE).gating_if(false);
        table.push(row(measured[worst]));
        ours_rows.push(row(reimplemented[worst]));
    }
    assert_defects(peer, &table, &ours_rows);
}

#[test]
fn lammps_objectivity() {
    objectivity(MotionPeer::Lammps);
}

#[test]
fn lammps_hooke_history_objectivity() {
    objectivity(MotionPeer::LammpsHookeHistory);
}

#[test]
fn liggghts_objectivity() {
    objectivity(MotionPeer::Liggghts);
}

/// `verdem kinematics --peer NAME` has the interface of `verdem kinematics`: the same motion
/// file in, the forces file the library gives out; with either increment, the binary agrees
/// with the re-implementation of its convention.
#[test]
fn the_command_line_drives_the_peers_with_either_increment() {
    let dir = tempfile::tempdir().unwrap();
    for peer in MotionPeer::ALL {
        if !loaded(peer) {
            continue;
        }
        let case = case_of(peer);
        let (x, _) = kinematics::pair_of(&case).unwrap();
        let n0 = (x[1] - x[0]).normalize();
        let mut rows = vec![MotionRow {
            t: 0.0,
            x,
            q: [UnitQuaternion::identity(); 2],
            v: [Vec3::zeros(); 2],
            w: [Vec3::zeros(); 2],
        }];
        spin_sphere_2(&mut rows, tangent_axis(n0), 1e-3, 50, 5, case.dt());
        rigid_rotation(&mut rows, n0 + tangent_axis(n0), 0.01, 500, case.dt());
        let motion_file = dir.path().join("motion.csv");
        std::fs::write(&motion_file, kinematics::motion_csv(&rows)).unwrap();
        // as the command reads them (its reader normalises the quaternions)
        let rows = kinematics::parse_motion("motion.csv", &kinematics::motion_csv(&rows)).unwrap();
        for increment in Increment::ALL {
            let out = dir
                .path()
                .join(format!("{}.{}.csv", peer.name(), increment.name()));
            let printed = common::verdem_ok([
                "kinematics".as_ref(),
                common::root()
                    .join("cases/verify/objectivity.toml")
                    .as_os_str(),
                motion_file.as_os_str(),
                "--out".as_ref(),
                out.as_os_str(),
                "--peer".as_ref(),
                peer.name().as_ref(),
                "--increment".as_ref(),
                increment.name().as_ref(),
            ]);
            let printed = String::from_utf8_lossy(&printed.stdout);
            assert!(
                printed.contains(&format!(
                    "{} rows of objectivity ({} through its library, {} convention)",
                    rows.len(),
                    peer.name(),
                    peer.convention().name()
                )),
                "{printed}"
            );
            let real = motion::drive(peer, &case, &rows, increment).unwrap();
            let written = std::fs::read_to_string(&out).unwrap();
            let expected = kinematics::forces_csv(&real);
            let first = written
                .lines()
                .zip(expected.lines())
                .position(|(a, b)| a != b);
            assert_eq!(
                first,
                None,
                "{peer:?} {increment:?}: {:?} {:?}",
                first.map(|k| written.lines().nth(k)),
                first.map(|k| expected.lines().nth(k))
            );
            assert_eq!(written.lines().count(), expected.lines().count());
            let (_, radius) = kinematics::pair_of(&case).unwrap();
            let law = kinematics::law_of(&case).unwrap();
            let ours = kinematics::drive(law.as_ref(), radius, &rows, increment);
            let d = difference(&real, &ours);
            assert!(d <= bound(rows.len()), "{peer:?} {increment:?}: {d:e}");
            assert!(real.iter().any(|r| r.ft > 0.0));
        }
    }
}

/// A law LAMMPS' input cannot express (tangential damping without normal damping: LAMMPS
/// gives the tangential damping relative to the normal one) is refused with the case's name
/// before the library sees it, instead of the library ending the process.
#[test]
fn a_law_lammps_cannot_express_is_refused() {
    if !loaded(MotionPeer::Lammps) {
        return;
    }
    let mut case = case_of(MotionPeer::Lammps);
    case.contact.gamman = 0.0;
    let (x, _) = kinematics::pair_of(&case).unwrap();
    let rows = [MotionRow {
        t: 0.0,
        x,
        q: [UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    }];
    let e = motion::drive(MotionPeer::Lammps, &case, &rows, Increment::Positions)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("objectivity.toml: the case's law has no finite lammps input"),
        "{e}"
    );
    assert!(e.contains("gammat needs gamman > 0"), "{e}");
}

/// Rows unevenly spaced in time: each step of the library is the rows' spacing (a time step
/// the code did not take would scale the spring's increments, velocity times its dt, away from
/// the rows' displacements).
#[test]
fn the_peers_time_step_is_the_rows_spacing() {
    for peer in MotionPeer::ALL {
        if !loaded(peer) {
            continue;
        }
        let case = case_of(peer);
        let (x, _) = kinematics::pair_of(&case).unwrap();
        let mut rows = vec![MotionRow {
            t: 0.0,
            x,
            q: [UnitQuaternion::identity(); 2],
            v: [Vec3::zeros(); 2],
            w: [Vec3::zeros(); 2],
        }];
        // sphere 2 slides along x at 0.05, in steps of 1e-4 and 3e-4 alternately
        for k in 1..=40 {
            let mut row = rows[k - 1];
            row.t += if k % 2 == 0 { 1e-4 } else { 3e-4 };
            row.x[1].x = 0.05 * row.t;
            row.v[1].x = 0.05;
            rows.push(row);
        }
        let real = motion::drive(peer, &case, &rows, Increment::Positions).unwrap();
        let ours = verdem(&case, &rows);
        for k in 0..6 {
            eprintln!("{peer:?} {k} {} {}", real[k].ft, ours[k].ft);
        }
        let d = difference(&real, &ours);
        assert!(d <= bound(rows.len()), "{peer:?}: {d:e}");
        // the spring carries the whole slide, kt·0.05·t at the end (below the sliding limit),
        // plus the dashpot's gammat·0.05; the slide tilts the normal by 4e-4 rad, whose
        // projections take a part of order 1e-7 off
        let end = real.last().unwrap();
        let spring = case.contact.kt * 0.05 * end.t;
        assert!(spring < case.contact.mu * end.fn_signed);
        assert!(
            (end.ft - (spring + case.contact.gammat * 0.05)).abs() < 1e-6 * spring,
            "{peer:?}: {} vs {spring}",
            end.ft
        );
    }
}

/// A contact that opens and closes again: both codes forget the spring when the spheres part,
/// as verdem's driver does, and start a new one when they touch again.
#[test]
fn the_peers_forget_the_spring_when_the_contact_opens() {
    for peer in MotionPeer::ALL {
        if !loaded(peer) {
            continue;
        }
        let case = case_of(peer);
        let (x, _) = kinematics::pair_of(&case).unwrap();
        let dt = case.dt();
        let mut rows = vec![MotionRow {
            t: 0.0,
            x,
            q: [UnitQuaternion::identity(); 2],
            v: [Vec3::zeros(); 2],
            w: [Vec3::zeros(); 2],
        }];
        // slide sphere 2 along x, lift it 3e-3 along z (a gap of 2e-3), bring it back, slide on
        let mut step = |d: Vec3, n: usize| {
            for _ in 0..n {
                let mut row = *rows.last().unwrap();
                row.t += dt;
                row.x[1] += d;
                row.v[1] = d / dt;
                rows.push(row);
            }
        };
        step(Vec3::new(1e-5, 0.0, 0.0), 20);
        step(Vec3::new(0.0, 0.0, 1e-4), 30);
        step(Vec3::new(0.0, 0.0, -1e-4), 30);
        step(Vec3::new(1e-5, 0.0, 0.0), 20);
        let real = motion::drive(peer, &case, &rows, Increment::Positions).unwrap();
        let ours = verdem(&case, &rows);
        let d = difference(&real, &ours);
        assert!(d <= bound(rows.len()), "{peer:?}: {d:e}");
        assert!(real
            .iter()
            .any(|r| r.delta < 0.0 && r.ft == 0.0 && r.fn_signed == 0.0));
        // after the gap the spring starts from zero: the last slide's 20 steps of 1e-5, plus
        // the 10 steps of the approach in contact, whose 1e-4 along z have a tangential part
        // 1e-4·2e-4 each (the normal is tilted by the first slide, 2e-4); the normal dashpot
        // adds below 1e-4 of it
        let end = real.last().unwrap();
        let spring = case.contact.kt * (20.0 * 1e-5 + 10.0 * 1e-4 * 2e-4);
        assert!(
            (end.ft - (spring + case.contact.gammat * 1e-5 / dt)).abs() < 1e-4 * spring,
            "{peer:?}: {} vs {spring}",
            end.ft
        );
    }
}
