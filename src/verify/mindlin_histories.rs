//! Histories that tell the Mindlin conventions apart, per convention, each as prescribed
//! motions of one contact ([`super::mindlin`]):
//!
//! - **held**: the tangential displacement held while the overlap doubles and comes back: does
//!   Ft change with no tangential motion? A stored displacement's force follows kt(a) (×√2 for
//!   a doubled overlap), a stored force stays, a rescaled one follows a/a_prev on unloading;
//! - **work**: closed cycles of normal and tangential load (load tangentially, change the
//!   overlap, unload tangentially, change it back, in both orders): the net work ∮T·dδt done on
//!   the contact over the cycle may not be negative (no law may create energy), a table per
//!   convention;
//! - **rotation**: a loaded contact turned rigidly by 90° (tilt, twist, a mixed axis) in
//!   [`ROTATION_STEPS`] steps: |Ft| kept and turned with the pair (objectivity), to the
//!   scheme's second-order error ([`ROTATION_TOL`]);
//! - **mcnamara**: McNamara's cycle (`super::mcnamara`): from no tangential force, turn by θ,
//!   double the overlap, turn back, return to the first overlap, under a spin of P and under a
//!   rigid rotation of the pair; the force left. Reported: for a Mindlin law the contact grows
//!   between the legs, so no closed form says the force must return to zero (a stored force
//!   unloads at the larger stiffness), and the numbers show how each store and slip answer.
//!
//! The reference law ([`crate::contact::Properties::partial_slip`]) is held to each: its force
//! is stored, scaled by a/a_prev when the contact shrinks, and follows the contact frame
//! exactly. The no-slip variants' numbers are evidence of their treatments: the energy rows are
//! judged for them too (no law may create energy) but do not gate (FAIL*), the others are
//! reported against the reference law's expectation.

use super::mindlin::{drive, press, slide, sliding, Motion, Pair, DT};
use super::{Row, Verdict};
use crate::analysis::Limit;
use crate::contact::Tangential;
use crate::Vec3;

/// The histories, by their names in the table.
pub const HISTORIES: [&str; 4] = ["held", "work", "rotation", "mcnamara"];

/// Increments per leg of a history.
const STEPS: usize = 200;

/// Steps of the rigid rotation by 90°: the objective slip cancels a rigid rotation's chord to
/// third order per step, so the force a rotation leaves is of second order in the step; at
/// 2000 steps the reference law keeps |Ft| to 1.7e-3 (0.17 at 200 steps: the order is 2), and
/// the rows allow [`ROTATION_TOL`].
const ROTATION_STEPS: usize = 2000;

/// Tolerance of the rigid-rotation rows (relative to |Ft|): three times the reference law's
/// measured error at [`ROTATION_STEPS`].
const ROTATION_TOL: f64 = 5e-3;

/// The name of `history` for convention `conv`.
pub fn case_name(conv: Tangential, history: &str) -> String {
    format!("mindlin {history} {}", conv.name())
}

/// The rows of every history of every Mindlin convention.
pub fn rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for conv in Tangential::with_mindlin_stiffness() {
        for history in HISTORIES {
            rows.extend(history_rows(conv, history));
        }
    }
    rows
}

/// The force resisting the slip along `s`: −Ft·s.
fn resisting(ft: Vec3, s: Vec3) -> f64 {
    -ft.dot(&s)
}

/// The rows of `history` (one of [`HISTORIES`]) for `conv`.
pub fn history_rows(conv: Tangential, history: &str) -> Vec<Row> {
    let pair = Pair::aluminium(0.01);
    let reference = conv.properties().partial_slip;
    let name = case_name(conv, history);
    let (n, s) = (Vec3::z(), Vec3::x());
    let d1 = pair.delta;
    let d2 = 2.0 * d1;
    let limit = pair.mu * pair.normal_force(d1);
    // a tangential displacement well below the sliding limit at the smaller overlap
    let u = 0.2 * limit / pair.stiffness(d1);
    let start = pair.separation(d1, n);
    let run = |path: &[(f64, f64)]| {
        let motions = sliding(conv, &pair, n, s, path);
        drive(conv, &pair, start, &motions, DT)
    };
    match history {
        "held" => {
            let path: Vec<_> = slide(d1, u, STEPS)
                .chain(press(d1, d2, STEPS))
                .chain(press(d2, d1, STEPS))
                .collect();
            let rec = run(&path);
            let at = |j: usize| resisting(rec[j].ft, s);
            let (loaded, up, down) = (at(STEPS - 1), at(2 * STEPS - 1), at(3 * STEPS - 1));
            let shrink = (d1 / d2).sqrt();
            vec![
                held_row(
                    &name,
                    "Ft after delta x2 / Ft before",
                    1.0,
                    up / loaded,
                    reference,
                ),
                held_row(
                    &name,
                    "Ft back at delta / (Ft at 2 delta * a1/a2)",
                    1.0,
                    down / (up * shrink),
                    reference,
                ),
            ]
        }
        "work" => {
            let mut rows = Vec::new();
            for (order, (first, second)) in [("up", (d1, d2)), ("down", (d2, d1))] {
                let path: Vec<_> = slide(first, u, STEPS)
                    .chain(press(first, second, STEPS))
                    .chain(slide(second, -u, STEPS))
                    .chain(press(second, first, STEPS))
                    .collect();
                let rec = run(&path);
                let (mut work, mut input) = (0.0, 0.0);
                let mut last = 0.0;
                for (j, (&(_, du), r)) in path.iter().zip(&rec).enumerate() {
                    let t = resisting(r.ft, s);
                    let dw = 0.5 * (last + t) * du;
                    work += dw;
                    if j < STEPS {
                        input += dw;
                    }
                    last = t;
                }
                let quantity = format!("net work / loading work, overlap {order} while held");
                rows.push(
                    Verdict::judge(&name, &quantity, work / input, Limit::AtLeast(-1e-9))
                        .gating_if(reference),
                );
                rows.push(Verdict::reported(
                    &name,
                    &format!("|Ft| / (mu fn) after the cycle, overlap {order}"),
                    rec[rec.len() - 1].ft.norm() / limit,
                    Limit::None,
                ));
            }
            rows
        }
        "mcnamara" => {
            let sum = pair.radius[0] + pair.radius[1];
            let y = Vec3::y();
            // the spin that loads the spring to a quarter of the sliding limit, and 0.1 rad
            let spin = 0.25 * limit / (pair.stiffness(d1) * pair.radius[0]);
            let mut rows = Vec::new();
            for (label, theta, rigid) in [("spin", spin, false), ("rigid", 0.1, true)] {
                let omega = theta / (STEPS as f64 * DT) * y;
                let turned = |angle: f64, delta: f64| {
                    let along = if rigid {
                        nalgebra::Rotation3::new(angle * y) * n
                    } else {
                        n
                    };
                    (sum - delta) * along
                };
                let mut motions = Vec::new();
                let leg = |motions: &mut Vec<Motion>, f: &dyn Fn(f64) -> (Vec3, Vec3)| {
                    for j in 1..=STEPS {
                        let (r, w) = f(j as f64 / STEPS as f64);
                        let w_i = if rigid { w } else { Vec3::zeros() };
                        motions.push(Motion { r, w_p: w, w_i });
                    }
                };
                leg(&mut motions, &|x| (turned(x * theta, d1), omega));
                leg(&mut motions, &|x| {
                    (turned(theta, d1 + x * (d2 - d1)), Vec3::zeros())
                });
                leg(&mut motions, &|x| (turned((1.0 - x) * theta, d2), -omega));
                leg(&mut motions, &|x| {
                    (turned(0.0, d2 + x * (d1 - d2)), Vec3::zeros())
                });
                let rec = drive(conv, &pair, start, &motions, DT);
                let peak = rec.iter().map(|r| r.ft.norm()).fold(0.0, f64::max);
                rows.push(Verdict::reported(
                    &name,
                    &format!("residual |Ft| / peak |Ft|, {label}"),
                    rec[rec.len() - 1].ft.norm() / peak,
                    Limit::None,
                ));
            }
            rows
        }
        _ => {
            let mut rows = Vec::new();
            let axes = [
                ("tilt", Vec3::y()),
                ("twist", Vec3::z()),
                ("mixed", Vec3::new(1.0, 1.0, 1.0).normalize()),
            ];
            for (label, axis) in axes {
                let loaded = sliding(conv, &pair, n, s, &slide(d1, u, STEPS).collect::<Vec<_>>());
                let turn = std::f64::consts::FRAC_PI_2;
                let omega = turn / (ROTATION_STEPS as f64 * DT) * axis;
                let mut motions = loaded;
                for j in 1..=ROTATION_STEPS {
                    let angle = j as f64 / ROTATION_STEPS as f64 * turn;
                    let rotation = nalgebra::Rotation3::new(angle * axis);
                    motions.push(Motion {
                        r: rotation * start,
                        w_p: omega,
                        w_i: omega,
                    });
                }
                let rec = drive(conv, &pair, start, &motions, DT);
                let before = rec[STEPS - 1].ft;
                let after = rec[rec.len() - 1].ft;
                let turned = nalgebra::Rotation3::new(turn * axis) * before;
                let tol = ROTATION_TOL;
                let kept = Limit::Relative {
                    expected: 1.0,
                    tolerance: tol,
                };
                let turned_with = Limit::Absolute {
                    expected: 0.0,
                    tolerance: tol,
                };
                rows.push(rotation_row(
                    &name,
                    &format!("|Ft| after / before, {label}"),
                    after.norm() / before.norm(),
                    kept,
                    reference,
                ));
                rows.push(rotation_row(
                    &name,
                    &format!("|Ft - R Ft0| / |Ft0|, {label}"),
                    (after - turned).norm() / before.norm(),
                    turned_with,
                    reference,
                ));
            }
            rows
        }
    }
}

/// A held-displacement row: the reference law's expectation, judged for it, reported for the
/// others (which of them change Ft is what the row shows).
fn held_row(name: &str, quantity: &str, expected: f64, measured: f64, judged: bool) -> Row {
    let limit = Limit::Relative {
        expected,
        tolerance: 1e-12,
    };
    Verdict::judge(name, quantity, measured, limit).judged_if(judged)
}

/// A rigid-rotation row: gating for the reference law, documenting for the others.
fn rotation_row(name: &str, quantity: &str, measured: f64, limit: Limit, judged: bool) -> Row {
    Verdict::judge(name, quantity, measured, limit).gating_if(judged)
}
