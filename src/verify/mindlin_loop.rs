//! Mindlin–Deresiewicz's hysteresis loop at constant normal load, per Mindlin convention: a
//! first loading to T* = 0.8μN, unloading to −T*, reloading to T* and a second cycle, driven
//! as prescribed tangential displacements at a fixed overlap ([`super::mindlin::sliding`]).
//! The reference law ([`crate::contact::Properties::partial_slip`]) is judged against the closed form
//! ([`super::mindlin`]): each branch's largest force error and the energy each cycle
//! dissipates. The no-slip variants are shown against the same closed form, reported and not
//! judged: they are not meant to follow it (a no-slip spring below the cap dissipates nothing).
//!
//! Tolerances: the reference law integrates its stiffness at each step's midpoint force, an
//! error of second order in the increment; at [`STEPS`] increments per quarter cycle the
//! largest branch error measured is 1.5e-8 μN and falls fourfold when the increments halve
//! (`tests/verify_mindlin.rs` holds the order), so the rows allow 1e-7 μN; the energy a cycle
//! dissipates (a quadrature of the recorded loop, also of second order) is measured 2e-7 off
//! the closed form, and the rows allow 1e-6 relative.

use super::mindlin::{self, drive, slide, sliding, Pair, DT};
use super::{Row, Verdict};
use crate::analysis::Limit;
use crate::contact::Tangential;
use crate::Vec3;

/// Tangential increments per quarter cycle (from 0 to δ*).
pub const STEPS: usize = 1000;

/// The turning point's force as a fraction of μN.
pub const TURN: f64 = 0.8;

/// Tolerance of a branch's largest force error, as a fraction of μN.
const FORCE_TOL: f64 = 1e-7;
/// Relative tolerance of the energy a cycle dissipates.
const ENERGY_TOL: f64 = 1e-6;

/// The pairs of the loop rows, by name: equal spheres, unlike sizes (R_I = 2R_P) and unlike
/// materials (glass on limestone).
pub fn pairs() -> [(&'static str, Pair); 3] {
    [
        ("equal", Pair::aluminium(0.01)),
        ("unlike", Pair::aluminium(0.02)),
        ("glass-limestone", Pair::glass_limestone()),
    ]
}

/// The loop of one convention measured against the closed form.
#[derive(Clone, Copy, Debug)]
pub struct LoopMeasure {
    /// Largest |T − T_MD|/(μN) on the first loading, the unloading and the reloading.
    pub branches: [f64; 3],
    /// The energy dissipated by the first and the second cycle, over the closed form's W.
    pub cycles: [f64; 2],
}

/// The loop of `conv` for `pair` at `steps` increments per quarter cycle.
pub fn measure(conv: Tangential, pair: &Pair, steps: usize) -> LoopMeasure {
    let (n, s) = (Vec3::z(), Vec3::x());
    let limit = pair.mu * pair.normal_force(pair.delta);
    let k = pair.stiffness(pair.delta);
    let t_star = TURN * limit;
    let d_star = mindlin::loading_displacement(t_star, limit, k);
    let delta = pair.delta;
    let path: Vec<(f64, f64)> = slide(delta, d_star, steps)
        .chain(slide(delta, -2.0 * d_star, 2 * steps))
        .chain(slide(delta, 2.0 * d_star, 2 * steps))
        .chain(slide(delta, -2.0 * d_star, 2 * steps))
        .chain(slide(delta, 2.0 * d_star, 2 * steps))
        .collect();
    let motions = sliding(conv, pair, n, s, &path);
    let start = pair.separation(delta, n);
    let rec = drive(conv, pair, start, &motions, DT);
    // the displacement after each step and the force resisting it
    let mut d = 0.0;
    let mut points = vec![(0.0, 0.0)];
    for (&(_, du), r) in path.iter().zip(&rec) {
        d += du;
        points.push((d, -r.ft.dot(&s)));
    }
    let error = |range: std::ops::Range<usize>, closed: &dyn Fn(f64) -> f64| {
        points[range]
            .iter()
            .map(|&(d, t)| (t - closed(d)).abs() / limit)
            .fold(0.0, f64::max)
    };
    let (q1, q3, q5) = (steps, 3 * steps, 5 * steps);
    let branches = [
        error(0..q1 + 1, &|d| mindlin::loading_force(d, limit, k)),
        error(q1..q3 + 1, &|d| {
            mindlin::unloading_force(d, d_star, t_star, limit, k)
        }),
        error(q3..q5 + 1, &|d| {
            mindlin::reloading_force(d, d_star, t_star, limit, k)
        }),
    ];
    // the work done on the contact over a cycle, ∮ T dδt (trapezoids)
    let work = |range: std::ops::Range<usize>| {
        points[range]
            .windows(2)
            .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
            .sum::<f64>()
    };
    let w = mindlin::dissipated_per_cycle(t_star, limit, k);
    LoopMeasure {
        branches,
        cycles: [work(q1..q5 + 1) / w, work(q5..9 * steps + 1) / w],
    }
}

/// The name of the loop case of convention `conv` for the pair named `pair`.
pub fn case_name(conv: Tangential, pair: &str) -> String {
    format!("mindlin loop {} {pair}", conv.name())
}

/// The loop rows of every Mindlin convention, for each of [`pairs`].
pub fn rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for conv in Tangential::with_mindlin_stiffness() {
        rows.extend(convention_rows(conv));
    }
    rows
}

/// The loop rows of `conv`: judged for the reference law, reported for the others.
pub fn convention_rows(conv: Tangential) -> Vec<Row> {
    let judged = conv.properties().partial_slip;
    let mut rows = Vec::new();
    for (label, pair) in pairs() {
        let name = case_name(conv, label);
        let m = measure(conv, &pair, STEPS);
        let row = |quantity: &str, limit: Limit, measured: f64| {
            Verdict::judge(&name, quantity, measured, limit).judged_if(judged)
        };
        let force = |expected| Limit::Absolute {
            expected,
            tolerance: FORCE_TOL,
        };
        let energy = Limit::Relative {
            expected: 1.0,
            tolerance: ENERGY_TOL,
        };
        for (branch, err) in ["loading", "unloading", "reloading"].iter().zip(m.branches) {
            rows.push(row(
                &format!("max |T - T_MD| / (mu N), {branch}"),
                force(0.0),
                err,
            ));
        }
        rows.push(row("W first cycle / W_MD", energy, m.cycles[0]));
        rows.push(row("W second cycle / W_MD", energy, m.cycles[1]));
    }
    rows
}
