//! Histories of the tangential spring of one contact at constant overlap, per tangential
//! convention (or for an external program), through a [`super::driver::MotionDriver`]: loaded
//! and unloaded below the sliding limit, taken to the Coulomb limit and back, carried through
//! a contact loss, and its dashpots' parts at a prescribed press and spin.
//!
//! Sphere 1 stays still; sphere 2 spins in place about a tangent axis t (the normal n stays
//! put, so no frame update acts), dashpots off but in the history that measures them.
//! Spinning sphere 2 by φ slides its contact point by l₂φ, l₂ = R₂ − δ/2 the arm to the
//! contact point in the middle of the overlap, and the spring pushes sphere 2 along t × n
//! with kt·l₂·φ, up to the Coulomb limit mu·fn. Both torques about the spheres' centres
//! oppose the spin: −l·|Ft| along t. Conventions that take the full radius as slip arm or
//! lever arm differ from these by δ/(2R) relative: for a subject whose convention is known
//! ([`Subject::declared`]) the rows that depend on the arm expect that convention's own arms
//! ([`arms`]) to round-off, so that a stiffness or a dashpot off by 1e-4 fails; for a program
//! that names none they allow the spread δ/R between conventions.
//!
//! The dashpots' history presses sphere 2 onto sphere 1 at a constant speed u and holds it,
//! then spins it at a constant rate ω and holds it: the force while moving less the force held
//! at the same overlap and spring is the dashpot's alone, γn·u along n and γt times the slip
//! along t × n, below the cap for every convention (fn = kn·δ − γn·vn, Ft = −kt·ξ − γt·slip
//! while sticking, `src/contact/normal.rs`, `tangential/cap.rs`).

use super::diagnosis::{Property, Tests};
use super::objectivity::{spin_sphere_2, tangent_axis};
use super::{row, row_abs, Row, Subject};
use crate::case::Case;
use crate::contact::{Arms, Tangential};
use crate::verify::kinematics::{pair_of, ForceRow, MotionRow};
use crate::Vec3;

/// The arms a convention uses when sphere 2 spins about a tangent axis at a fixed normal, as
/// multiples of R2 − δ/2 (the arm to the contact point in the middle of the overlap): its
/// slip arm (how far the contact point slides per radian) and its torque arm, as the model's
/// parts declare them ([`Tangential::geometry`]): 1 for arms to the contact point, R − δ/2
/// (the slip of MercuryDPM, LIGGGHTS and Yade's ViscEl law; the torques of all but two),
/// R2/(R2 − δ/2) for full radii (the slip of LAMMPS, Cundall, Yade's and the objective law; the
/// torques of LAMMPS `gran/hooke/history` and Cundall).
pub fn arms(conv: Tangential, radius: f64, delta: f64) -> (f64, f64) {
    let full = radius / (radius - 0.5 * delta);
    let factor = |arms| match arms {
        Arms::HalfOverlap => 1.0,
        Arms::FullRadius => full,
    };
    let g = conv.geometry();
    (factor(g.slip), factor(g.torque))
}

/// The histories, by their names in the table.
pub const HISTORIES: [&str; 4] = ["load-unload", "coulomb limit", "contact loss", "dashpots"];

/// The name of the history named `label` of `subject`'s contact.
pub fn case_name(subject: &str, label: &str) -> String {
    format!("tangential {subject} {label}")
}

/// Appends a row one step after the last with sphere 2 moved by `shift` (the velocity of that
/// step, shift/dt), then `hold` still rows.
fn jump_sphere_2(rows: &mut Vec<MotionRow>, shift: Vec3, hold: usize, dt: f64) {
    let from = *rows.last().expect("a starting row");
    let mut moved = from;
    moved.t = from.t + dt;
    moved.x[1] = from.x[1] + shift;
    moved.v[1] = shift / dt;
    rows.push(moved);
    for k in 1..=hold {
        let mut still = moved;
        still.t = moved.t + k as f64 * dt;
        still.v[1] = Vec3::zeros();
        rows.push(still);
    }
}

/// Tangential part of the force on sphere 2, magnitude.
fn ft2(f: &ForceRow, n: Vec3) -> f64 {
    (f.f[1] - f.f[1].dot(&n) * n).norm()
}

/// The rows of the history named `label` (one of [`HISTORIES`]) of `subject`'s contact.
pub fn history_rows(base: &Case, subject: &Subject, label: &str) -> anyhow::Result<Vec<Row>> {
    let mut case = subject.case(base);
    if label != "dashpots" {
        case.contact.gamman = 0.0;
        case.contact.gammat = 0.0;
    }
    let (x, radius) = pair_of(&case)?;
    let dt = case.dt();
    let r = x[1] - x[0];
    let (n, dist) = (r.normalize(), r.norm());
    let delta = radius[0] + radius[1] - dist;
    anyhow::ensure!(
        delta > 0.0,
        "{}: scene: the tangential histories need two overlapping spheres",
        case.path.display()
    );
    let c = &case.contact;
    let fn0 = c.kn * delta;
    let limit = c.mu * fn0;
    let t = tangent_axis(n);
    let along = t.cross(&n);
    let lever = [radius[0] - 0.5 * delta, radius[1] - 0.5 * delta];
    // the expected slip and torque arms (in units of R − δ/2) and their tolerance: the
    // convention's own to round-off, or the spread between conventions
    let (slip_arm, torque_arm, arm_tol) = match subject.declared {
        Some(conv) => {
            let (slip, torque2) = arms(conv, radius[1], delta);
            let (_, torque1) = arms(conv, radius[0], delta);
            (slip, [torque1, torque2], 1e-9)
        }
        None => (1.0, [1.0; 2], delta / radius[1]),
    };
    // the spin of sphere 2 that loads the spring to the force `force`
    let spin = |force: f64| force / (c.kt * lever[1]);
    let mut rows = vec![MotionRow {
        t: 0.0,
        x,
        q: [nalgebra::UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    }];
    let name = case_name(&subject.label, label);
    let drive = |rows: &[MotionRow]| subject.driver.drive(&case, rows);
    Ok(match label {
        "load-unload" => {
            spin_sphere_2(&mut rows, t, spin(0.5 * limit), 100, 10, dt);
            let peak = rows.len() - 1;
            spin_sphere_2(&mut rows, t, -spin(0.5 * limit), 100, 10, dt);
            let f = drive(&rows)?;
            let p = &f[peak];
            let ft = ft2(p, n);
            // angular momentum about sphere 1's centre: T1 + T2 + r × F2
            let balance = (p.torque[0] + p.torque[1] + r.cross(&p.f[1])).norm() / (dist * ft);
            vec![
                row(
                    &name,
                    "F2.(t x n) / (kt l2 phi)",
                    slip_arm,
                    p.f[1].dot(&along) / (0.5 * limit),
                    arm_tol,
                )
                .tests(Property::Stiffness),
                row(&name, "fn / (kn delta)", 1.0, p.fn_signed / fn0, 1e-9)
                    .tests(Property::NormalForce),
                row(
                    &name,
                    "fn / (F2.n)",
                    1.0,
                    p.fn_signed / p.f[1].dot(&n),
                    1e-9,
                )
                .tests(Property::ForcesFile),
                row(&name, "ft / |F2 - (F2.n) n|", 1.0, p.ft / ft, 1e-9)
                    .tests(Property::ForcesFile),
                row_abs(
                    &name,
                    "|F1 + F2| / |F2|",
                    0.0,
                    (p.f[0] + p.f[1]).norm() / p.f[1].norm(),
                    1e-12,
                )
                .tests(Property::ForcesFile),
                row(
                    &name,
                    "T1.t / (l1 |Ft|)",
                    -torque_arm[0],
                    p.torque[0].dot(&t) / (lever[0] * ft),
                    arm_tol,
                )
                .tests(Property::Torques),
                row(
                    &name,
                    "T2.t / (l2 |Ft|)",
                    -torque_arm[1],
                    p.torque[1].dot(&t) / (lever[1] * ft),
                    arm_tol,
                )
                .tests(Property::Torques),
                row_abs(&name, "|T1 + T2 + r x F2| / (d |Ft|)", 0.0, balance, 1e-9)
                    .gating_if(subject.properties.conserves_angular_momentum)
                    .tests(Property::AngularMomentum),
                row_abs(
                    &name,
                    "|Ft| unloaded / peak |Ft|",
                    0.0,
                    ft2(&f[f.len() - 1], n) / ft,
                    1e-9,
                )
                .tests(Property::ClosedCycleEnergy),
            ]
        }
        "coulomb limit" => {
            spin_sphere_2(&mut rows, t, spin(2.0 * limit), 200, 10, dt);
            let sliding = rows.len() - 1;
            spin_sphere_2(&mut rows, t, -spin(limit), 100, 10, dt);
            let f = drive(&rows)?;
            vec![
                row(
                    &name,
                    "|Ft| / (mu fn) after sliding",
                    1.0,
                    ft2(&f[sliding], n) / limit,
                    1e-9,
                )
                .tests(Property::CoulombCap),
                row_abs(
                    &name,
                    "|Ft| / (mu fn) back by mu fn/kt",
                    slip_arm - 1.0,
                    ft2(&f[f.len() - 1], n) / limit,
                    arm_tol,
                )
                .tests(Property::CoulombCap),
            ]
        }
        "dashpots" => {
            anyhow::ensure!(
                c.gamman > 0.0 && c.gammat > 0.0,
                "{}: contact: the dashpots' history needs gamman > 0 and gammat > 0",
                case.path.display()
            );
            // pressed by a tenth of the overlap a row for two rows, then held: the overlap
            // and the spring of the last press row, at rest
            let press = 0.1 * delta;
            let u = press / dt;
            jump_sphere_2(&mut rows, -press * n, 0, dt);
            jump_sphere_2(&mut rows, -press * n, 10, dt);
            let (pressing, pressed) = (2, rows.len() - 1);
            // spun for two rows at the slip rate that loads spring + dashpot to half the
            // sliding limit of the pressed overlap, then held; the arms are those of the
            // pressed overlap
            let pressed_delta = delta + 2.0 * press;
            let arm = radius[1] - 0.5 * pressed_delta;
            let slip_arm = match subject.declared {
                Some(conv) => arms(conv, radius[1], pressed_delta).0,
                None => 1.0,
            };
            let sliding = c.mu * c.kn * pressed_delta;
            let omega = 0.5 * sliding / ((2.0 * c.kt * dt + c.gammat) * arm);
            spin_sphere_2(&mut rows, t, omega * 2.0 * dt, 2, 10, dt);
            let (spinning, spun) = (pressed + 2, rows.len() - 1);
            let f = drive(&rows)?;
            let along_t = |k: usize| f[k].f[1].dot(&along);
            // fn = kn·δ − γn·vn (MercuryDPM's LinearViscoelasticNormalSpecies) and, below the
            // cap, Ft = −kt·ξ − γt·slip (every convention's cap, src/contact/tangential/cap.rs)
            vec![
                row(
                    &name,
                    "(fn pressing - fn held) / (gamman u)",
                    1.0,
                    (f[pressing].fn_signed - f[pressed].fn_signed) / (c.gamman * u),
                    1e-9,
                )
                .tests(Property::Dashpots),
                row(
                    &name,
                    "(Ft spinning - Ft held) / (gammat l2 omega)",
                    slip_arm,
                    (along_t(spinning) - along_t(spun)) / (c.gammat * arm * omega),
                    arm_tol,
                )
                .tests(Property::Dashpots),
            ]
        }
        _ => {
            spin_sphere_2(&mut rows, t, spin(0.5 * limit), 100, 10, dt);
            let gone = rows.len();
            jump_sphere_2(&mut rows, 2.0 * delta * n, 10, dt);
            let back = rows.len();
            jump_sphere_2(&mut rows, -2.0 * delta * n, 10, dt);
            let f = drive(&rows)?;
            let apart = f[gone..back]
                .iter()
                .map(|r| r.f[1].norm().max(r.f[0].norm()))
                .fold(0.0, f64::max);
            let last = &f[f.len() - 1];
            vec![
                row(
                    &name,
                    "delta apart / -delta",
                    1.0,
                    -f[gone].delta / delta,
                    1e-9,
                )
                .tests(Property::ForcesFile),
                row_abs(&name, "max |F| apart / (mu fn)", 0.0, apart / limit, 1e-12)
                    .tests(Property::ResetAtLoss),
                row(
                    &name,
                    "fn back / (kn delta)",
                    1.0,
                    last.fn_signed / fn0,
                    1e-9,
                )
                .tests(Property::NormalForce),
                row_abs(
                    &name,
                    "|Ft| back / (mu fn)",
                    0.0,
                    ft2(last, n) / limit,
                    1e-9,
                )
                .tests(Property::ResetAtLoss),
            ]
        }
    })
}
