//! McNamara's ratcheting cycle with a change of normal load between the rotations (McNamara,
//! García-Rojo & Herrmann, "Microscopic origin of granular ratcheting", PRE 77, 031304, 2008,
//! arXiv:0708.1389: the energy stored in a contact is path dependent for the usual tangential
//! laws, "there exist closed paths that change the stored energy, even if the particles remain
//! in contact and do not slide"), per tangential convention, through a [`MotionDriver`]: verdem's
//! law, an external program (`verdem verify --code`) or a peer's library.
//!
//! The cycle, as Yade's `Ig2_Sphere_Sphere_ScGeom::avoidGranularRatcheting` documents it: at
//! the overlap δ1 (normal load fn1 = kn δ1) (1) rotate by θ, (2) press along the normal to δ2,
//! (3) rotate back by −θ, (4) return to δ1. Every position and orientation is back where it
//! started, dashpots are off and nothing slides, so an elastic contact must end with its
//! initial (zero) tangential force and zero net work. A law whose slip depends on the overlap
//! turns the two rotations into tangential displacements of different lengths, θ·ℓ(δ1) and
//! −θ·ℓ(δ2): the residual spring is θ·(ℓ(δ1) − ℓ(δ2)), the cycle's integral of the slip's
//! non-integrable term u_n·ω (u_n the normal displacement, ω the rotation rate), so
//! |Ft| = c·kt·θ·|δ2 − δ1| = c·kt·θ·|fn2 − fn1|/kn. Two rotations show the two ways it enters:
//! - `spin`: sphere 2 spins about a tangent axis in place. Lever arms to the contact point,
//!   ℓ = R − δ/2 (MercuryDPM, LIGGGHTS, Yade's ViscEl law), leave c = 1/2; full radii and the
//!   objective slip use R, constant: no residual.
//! - `rigid`: the pair rotates rigidly about a tangent axis. The full-radius slip (LAMMPS,
//!   Cundall) sees −δ·Ω×n of a rigid rotation (its arms R_1 + R_2 exceed the distance by δ):
//!   c = 1; lever arms R − δ/2 sum to the distance and the objective slip is built to vanish.

use nalgebra::UnitQuaternion;

use super::diagnosis::{Property, Tests};
use super::driver::{MotionDriver, OWN};
use super::objectivity::{rigid_rotation, spin_sphere_2, tangent_axis};
use super::ratchet::net_work;
use super::{row_abs, Row, Subject};
use crate::case::Case;
use crate::contact::{Arms, Tangential};
use crate::verify::kinematics::{pair_of, MotionRow};
use crate::Vec3;

/// Steps of each leg of the cycle.
const STEPS_PER_LEG: usize = 2000;

/// Which rotation the cycle's legs (1) and (3) make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rotation {
    /// Sphere 2 spins in place about a tangent axis.
    Spin,
    /// The pair rotates rigidly about a tangent axis through sphere 1's centre.
    Rigid,
}

impl Rotation {
    /// Both.
    pub const ALL: [Rotation; 2] = [Rotation::Spin, Rotation::Rigid];

    /// "spin" or "rigid".
    pub const fn name(self) -> &'static str {
        match self {
            Rotation::Spin => "spin",
            Rotation::Rigid => "rigid",
        }
    }
}

/// The factor c of the theory's residual c·kt·θ·|δ2 − δ1| for a convention's slip under a
/// rotation (this module's head), from the lever arms of its slip ([`Tangential::geometry`]):
/// 1/2 for lever arms R − δ/2 under a spin, 1 for full radii without the objective scaling of
/// the centres' velocity under a rigid rotation, 0 otherwise.
pub fn theory_factor(conv: Tangential, rotation: Rotation) -> f64 {
    let g = conv.geometry();
    match rotation {
        Rotation::Spin if g.slip == Arms::HalfOverlap => 0.5,
        Rotation::Rigid if g.slip == Arms::FullRadius && !g.slip_scales_centres => 1.0,
        _ => 0.0,
    }
}

/// One cycle's parameters: overlaps δ1 and δ2 (length), rotation angle θ (rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loads {
    pub delta1: f64,
    pub delta2: f64,
    pub theta: f64,
}

/// What one cycle left behind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    /// Tangential force at the end (force units).
    pub residual: f64,
    /// Largest tangential force during the cycle (force units).
    pub peak: f64,
    /// Net work done by the contact's forces and torques on the two spheres over the cycle
    /// (force·length): minus the energy the contact took up.
    pub work: f64,
}

/// Appends `steps` rows translating sphere 2 along the current normal (from sphere 1 to 2) so
/// that the overlap changes by `-push` (length; positive `push` presses), from the last row;
/// sphere 1 and both orientations are still (zero velocity and spins, whatever the last
/// row's).
fn press(rows: &mut Vec<MotionRow>, push: f64, steps: usize, dt: f64) {
    let from = *rows.last().expect("a starting row");
    let n = (from.x[1] - from.x[0]).normalize();
    let v = -n * (push / (steps as f64 * dt));
    for k in 1..=steps {
        let mut row = from;
        row.t = from.t + k as f64 * dt;
        row.x[1] = from.x[1] + v * (k as f64 * dt);
        row.v = [Vec3::zeros(), v];
        row.w = [Vec3::zeros(); 2];
        rows.push(row);
    }
}

/// The motion of one cycle of `case`'s pair (sphere 2 moved along the normal to the overlap
/// `loads.delta1` first).
pub fn motion(case: &Case, rotation: Rotation, loads: Loads) -> anyhow::Result<Vec<MotionRow>> {
    let (mut x, radius) = pair_of(case)?;
    let dt = case.dt();
    let n0 = (x[1] - x[0]).normalize();
    x[1] = x[0] + n0 * (radius[0] + radius[1] - loads.delta1);
    let axis = tangent_axis(n0);
    let mut rows = vec![MotionRow {
        t: 0.0,
        x,
        q: [UnitQuaternion::identity(); 2],
        v: [Vec3::zeros(); 2],
        w: [Vec3::zeros(); 2],
    }];
    let turn = |rows: &mut Vec<MotionRow>, angle: f64| match rotation {
        Rotation::Spin => spin_sphere_2(rows, axis, angle, STEPS_PER_LEG, 0, dt),
        Rotation::Rigid => rigid_rotation(rows, axis, angle, STEPS_PER_LEG, dt),
    };
    let push = loads.delta2 - loads.delta1;
    turn(&mut rows, loads.theta);
    press(&mut rows, push, STEPS_PER_LEG, dt);
    turn(&mut rows, -loads.theta);
    press(&mut rows, -push, STEPS_PER_LEG, dt);
    Ok(rows)
}

/// One cycle of `case`'s law (dashpots switched off) with the rotation `rotation` and the
/// overlaps and angle `loads`, driven by `driver`.
pub fn cycle(
    case: &Case,
    rotation: Rotation,
    loads: Loads,
    driver: &dyn MotionDriver,
) -> anyhow::Result<Cycle> {
    let mut elastic = case.clone();
    elastic.contact.gamman = 0.0;
    elastic.contact.gammat = 0.0;
    let rows = motion(&elastic, rotation, loads)?;
    let f = driver.drive(&elastic, &rows)?;
    anyhow::ensure!(
        f.len() == rows.len(),
        "{}: {} rows of forces for {} rows of motion",
        driver.name(),
        f.len(),
        rows.len()
    );
    Ok(Cycle {
        residual: f.last().map_or(0.0, |r| r.ft),
        peak: f.iter().map(|r| r.ft).fold(0.0, f64::max),
        work: net_work(&rows, &f),
    })
}

/// The cycle's loads for `case`: δ1 its pair's overlap, δ2 = 2δ1, and θ such that the spring
/// reaches about a quarter of the sliding limit μ·kn·δ1 at δ1 (a spin loads it by kt·R2·θ, a
/// rigid rotation of the full-radius slip by kt·δ1·θ, capped at 0.1 rad).
pub fn loads(case: &Case, rotation: Rotation) -> anyhow::Result<Loads> {
    let (x, radius) = pair_of(case)?;
    let delta1 = radius[0] + radius[1] - (x[1] - x[0]).norm();
    let c = &case.contact;
    let limit = c.mu * c.kn * delta1;
    let theta = match rotation {
        Rotation::Spin => 0.25 * limit / (c.kt * radius[1]),
        Rotation::Rigid => (0.25 * limit / (c.kt * delta1)).min(0.1),
    };
    Ok(Loads {
        delta1,
        delta2: 2.0 * delta1,
        theta,
    })
}

/// Whether a convention's torques use the lever arms its slip uses (R − δ/2 for both, or R
/// for both) and its centres exchange the force its slip is conjugate to (the slip does not
/// scale their velocity), so that the work of the force and torques is that of the spring
/// (from [`Tangential::geometry`]). The objective slips use R
/// (McNamara et al.'s form) with torques to the contact point, R − δ/2, as LAMMPS `granular`
/// does with its full-radius slip: a spin cycle then does net work −kt·R·θ²·(δ2 − δ1)/4 on
/// the spheres though the force returns to zero. McNamara et al. make the pair exchange α·Ft
/// at the centres (α = (R_1 + R_2)/d) with torques R × Ft, conjugate to their slip, which
/// keeps both the work and the angular momentum.
pub fn torques_conjugate_to_slip(conv: Tangential) -> bool {
    let g = conv.geometry();
    g.torque == g.slip && !g.slip_scales_centres
}

/// The cycles' names, one per [`Rotation`]: the variants of the verification table's case.
pub const CYCLES: [&str; 2] = [Rotation::Spin.name(), Rotation::Rigid.name()];

/// The name of the cycle `variant` (one of [`CYCLES`]) of `subject`'s contact.
pub fn case_name(subject: &str, variant: &str) -> String {
    format!("mcnamara {subject} {variant} fn x2")
}

/// The McNamara-cycle rows of `subject` for the cycle `variant` (one of [`CYCLES`]): the
/// residual tangential force in units of kt·θ·|δ2 − δ1| (the theory's residual with c = 1) and
/// the net work per cycle in units of the largest normal elastic energy ½·kn·δ2², both
/// expected 0; and, where the theory predicts a residual for the subject's convention, the
/// residual against c·kt·θ·|δ2 − δ1|. The residual gates for a subject that claims
/// objectivity and documents the others (FAIL* where they ratchet); the net work gates only
/// for a law whose torques are conjugate to its slip and which claims objectivity (none yet:
/// the objective law's torques use R − δ/2).
pub fn cycle_rows(base: &Case, subject: &Subject, variant: &str) -> anyhow::Result<Vec<Row>> {
    let rotation = Rotation::ALL
        .into_iter()
        .find(|r| r.name() == variant)
        .ok_or_else(|| anyhow::anyhow!("no McNamara cycle is called {variant:?}"))?;
    let (_, radius) = pair_of(base)?;
    let reach = radius[0] + radius[1];
    let case = subject.case(base);
    let conv = subject.tangential;
    let l = loads(&case, rotation)?;
    let c = cycle(&case, rotation, l, subject.driver)?;
    let name = case_name(&subject.label, variant);
    let (kn, kt) = (case.contact.kn, case.contact.kt);
    let dd = (l.delta2 - l.delta1).abs();
    let force = kt * l.theta * dd;
    let energy = 0.5 * kn * l.delta2 * l.delta2;
    // round-off: positions of size R1 + R2 carry ε·(R1 + R2) each, the spring as much; 100
    // times that against the scale kt·θ·|δ2 − δ1|
    let force_round_off = 100.0 * f64::EPSILON * reach / (l.theta * dd);
    // the work sums 4·STEPS_PER_LEG terms fn·dx, each with ε·fn2·(R1 + R2)
    let steps = 4.0 * STEPS_PER_LEG as f64;
    let work_round_off = steps * f64::EPSILON * kn * l.delta2 * reach / energy;
    let objective = subject.properties.objective;
    let mut rows = vec![
        row_abs(
            &name,
            "residual |Ft| / (kt theta |d delta|)",
            0.0,
            c.residual / force,
            force_round_off,
        )
        .gating_if(objective)
        .tests(Property::ClosedCycleEnergy),
        row_abs(
            &name,
            "net work / (kn delta2^2 / 2)",
            0.0,
            c.work / energy,
            work_round_off,
        )
        .gating_if(objective && torques_conjugate_to_slip(conv))
        .tests(Property::ClosedCycleEnergy),
    ];
    let factor = theory_factor(conv, rotation);
    if factor > 0.0 {
        // higher orders: O(θ²) = 1e-2 of the rigid rotation's chord and frame
        rows.push(
            super::row(
                &name,
                "residual / (c kt theta |d delta|)",
                1.0,
                c.residual / (factor * force),
                1e-2,
            )
            .tests(Property::ClosedCycleEnergy),
        );
    }
    Ok(rows)
}

/// A fitted power-law exponent: the least-squares slope of ln y against ln x, and the
/// smallest and largest slope between neighbouring points (its fit interval).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exponent {
    pub fit: f64,
    pub lo: f64,
    pub hi: f64,
}

/// The exponent of y ∝ x^p through `points` (x, y), all positive.
pub fn exponent(points: &[(f64, f64)]) -> Exponent {
    let logs: Vec<(f64, f64)> = points.iter().map(|(x, y)| (x.ln(), y.ln())).collect();
    let local = logs
        .windows(2)
        .map(|w| (w[1].1 - w[0].1) / (w[1].0 - w[0].0));
    Exponent {
        fit: crate::analysis::stats::slope(&logs),
        lo: local.clone().fold(f64::INFINITY, f64::min),
        hi: local.fold(f64::NEG_INFINITY, f64::max),
    }
}

/// How the residual of `case`'s law scales, for scale factors 1, 2, 4, 8 of one parameter
/// each from [`loads`]: the load (δ1 and δ2 = 2δ1 together, so fn1, fn2 and |fn2 − fn1| ∝ s,
/// kn fixed), the stiffness kn (fn fixed, so δ ∝ 1/s; kt fixed) and the rotation θ (θ·s/8).
/// The theory (this module's head) gives the exponents 1, −1 and 1.
pub fn scaling(case: &Case, rotation: Rotation) -> anyhow::Result<[Exponent; 3]> {
    let base = loads(case, rotation)?;
    let scales = [1.0, 2.0, 4.0, 8.0];
    let residual = |case: &Case, l: Loads| cycle(case, rotation, l, &OWN).map(|c| c.residual);
    let mut load = Vec::new();
    let mut stiffness = Vec::new();
    let mut amplitude = Vec::new();
    for s in scales {
        let more = Loads {
            delta1: s * base.delta1,
            delta2: s * base.delta2,
            ..base
        };
        load.push((s, residual(case, more)?));
        let mut stiffer = case.clone();
        stiffer.contact.kn *= s;
        let softer = Loads {
            delta1: base.delta1 / s,
            delta2: base.delta2 / s,
            ..base
        };
        stiffness.push((s, residual(&stiffer, softer)?));
        let turned = Loads {
            theta: base.theta * s / 8.0,
            ..base
        };
        amplitude.push((s, residual(case, turned)?));
    }
    Ok([exponent(&load), exponent(&stiffness), exponent(&amplitude)])
}
