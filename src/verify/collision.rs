//! Verification cases with analytical answers, run through the same solver as the benchmark.
//!
//! Binary normal collision (cases/verify/binary_collision.toml): restitution, contact time and
//! maximum overlap of the linear spring–dashpot with absolute damping against the closed forms,
//! free–free (m_eff = m/2) and free–wall sphere (m_eff = m), for impact speeds 1e-3 … 10, and
//! the convergence order of the restitution error in dt.

use super::{row, Row};
use crate::analysis::stats::slope;
use crate::case::{Case, Scene};
use crate::step::engine::{self, Overrides};
use crate::Vec3;

/// Closed-form collision of the linear spring–dashpot for effective mass `meff`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm {
    pub tc: f64,
    pub e: f64,
    /// Maximum overlap per unit impact speed.
    pub delta_max_per_speed: f64,
    /// Restitution when the attractive tail is clipped: the contact force ends when
    /// kn δ + γn δ̇ reaches 0, at t₀ = (π − atan(2ηω/(ω² − η²)))/ω (for ω > η), and
    /// e = e^(−η t₀)(η/ω·sin ωt₀ − cos ωt₀).
    pub e_clipped: f64,
    /// The duration of the clipped contact force, t₀ above.
    pub tc_clipped: f64,
}

/// The closed form for `case`'s law and effective mass `meff` (`benchmark.md`; e.g. Schwager &
/// Pöschel, Phys. Rev. E 78, 051304, 2008, for the linear dashpot and its clipped variant).
pub fn closed_form(case: &Case, meff: f64) -> ClosedForm {
    let w0sq = case.contact.kn / meff;
    let eta = case.contact.gamman / (2.0 * meff);
    let w = (w0sq - eta * eta).sqrt();
    let tc = std::f64::consts::PI / w;
    let tstar = (w / eta).atan() / w;
    // δ(t) = (v0/ω) e^(−ηt) sin ωt; the force kn δ + γn δ̇ vanishes where
    // tan ωt = −2ηω/(ω² − η²).
    let t0 = (std::f64::consts::PI - (2.0 * eta * w).atan2(w * w - eta * eta)) / w;
    ClosedForm {
        tc,
        e: (-eta * tc).exp(),
        delta_max_per_speed: (-eta * tstar).exp() * (w * tstar).sin() / w,
        e_clipped: (-eta * t0).exp() * (eta / w * (w * t0).sin() - (w * t0).cos()),
        tc_clipped: t0,
    }
}

/// One sphere of a two-body impact (lab frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    pub x: Vec3,
    pub v: Vec3,
    pub w: Vec3,
    /// Radius (default: half the material diameter).
    pub radius: Option<f64>,
    /// A wall sphere: moved with its velocity, infinite mass.
    pub fixed: bool,
}

/// The state after the contact ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    pub v: [Vec3; 2],
    pub w: [Vec3; 2],
    pub steps_in_contact: u64,
    pub delta_max: f64,
    /// The largest normal force (force units) of the contact at the ends of steps.
    pub fn_max: f64,
    pub dt: f64,
}

/// Simulates two spheres of `base`'s material and contact law, with dt = tc_ff/`per_tc`, until
/// their contact ends.
pub fn impact(base: &Case, bodies: [Body; 2], per_tc: f64) -> anyhow::Result<Outcome> {
    let (case, mut e) = impact_setup(base, bodies, per_tc)?;
    let dt = case.dt();
    let reach = e.state().particles.radius[0] + e.state().particles.radius[1];
    let (mut started, mut steps_in_contact, mut delta_max) = (false, 0u64, 0.0f64);
    let mut fn_max = 0.0f64;
    for _ in 0..100_000 {
        e.advance(1)?;
        let s = e.snapshot();
        let d = reach - (s.particles.x[1] - s.particles.x[0]).norm();
        if !s.contacts.is_empty() {
            started = true;
            steps_in_contact += 1;
            delta_max = delta_max.max(d);
            fn_max = fn_max.max(s.contacts[0].force.fn_signed);
        } else if started {
            let p = &s.particles;
            return Ok(Outcome {
                v: [p.v[0], p.v[1]],
                w: [p.w[0], p.w[1]],
                steps_in_contact,
                delta_max,
                fn_max,
                dt,
            });
        }
    }
    anyhow::bail!("{}: no complete collision", base.path.display())
}

/// The case (dt = tc_ff/`per_tc`) and a simulation of the two spheres `bodies` of `base`'s
/// material and law, at step 0.
pub fn impact_setup(
    base: &Case,
    bodies: [Body; 2],
    per_tc: f64,
) -> anyhow::Result<(Case, Box<dyn crate::step::Engine>)> {
    let mut case = base.clone();
    case.run.dt = None;
    case.run.steps_per_collision = Some(per_tc);
    let Scene::Spheres { sphere } = &mut case.scene else {
        anyhow::bail!("{}: an impact needs a spheres scene", base.path.display());
    };
    anyhow::ensure!(
        sphere.len() == 2,
        "{}: needs exactly two spheres",
        base.path.display()
    );
    for (s, b) in sphere.iter_mut().zip(bodies) {
        s.x = b.x.into();
        s.v = b.v.into();
        s.w = b.w.into();
        s.radius = b.radius;
        s.fixed = b.fixed;
    }
    let scene = crate::scene::build(&case, None)?;
    let e = engine::build(&case, scene, &Overrides::default())?;
    Ok((case, e))
}

/// Two spheres on the x axis, sphere 1 moving at `v0` towards sphere 2 (fixed when `wall`),
/// a gap of (2 + `phase`)·v0·dt apart, so that the contact begins within a few steps.
pub fn head_on(v0: f64, wall: bool, dt: f64, phase: f64) -> [Body; 2] {
    let gap = (2.0 + phase) * v0 * dt;
    let body = |x: f64, v: f64, fixed: bool| Body {
        x: Vec3::new(x, 0.0, 0.0),
        v: Vec3::new(v, 0.0, 0.0),
        w: Vec3::zeros(),
        radius: None,
        fixed,
    };
    [
        body(-0.5 - 0.5 * gap, v0, false),
        body(0.5 + 0.5 * gap, 0.0, wall),
    ]
}

/// What one simulated head-on collision gave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    pub e: f64,
    pub duration: f64,
    pub delta_max: f64,
}

/// Simulates one head-on collision at relative speed `v0` with `dt = tc_ff / per_tc`.
pub fn collide(base: &Case, v0: f64, wall: bool, per_tc: f64) -> anyhow::Result<Measured> {
    collide_with_phase(base, v0, wall, per_tc, 0.5)
}

/// As [`collide`], with the first touch `phase` ∈ [0, 1) of a step into the step.
pub fn collide_with_phase(
    base: &Case,
    v0: f64,
    wall: bool,
    per_tc: f64,
    phase: f64,
) -> anyhow::Result<Measured> {
    let mut case = base.clone();
    case.run.dt = None;
    case.run.steps_per_collision = Some(per_tc);
    let out = impact(base, head_on(v0, wall, case.dt(), phase), per_tc)?;
    Ok(Measured {
        e: (out.v[1] - out.v[0]).x / v0,
        duration: out.steps_in_contact as f64 * out.dt,
        delta_max: out.delta_max,
    })
}

/// Where the verification's collisions first touch: half a step into a step ([`collide`]).
const ONSET: f64 = 0.5;

/// Round-off bound (relative) of a quantity of a collision whose largest overlap is
/// `delta_max` (length) between spheres `reach` (length) apart: the overlap is the difference
/// of positions of size `reach`, so each step's overlap carries ~ε·reach; 100 times that over
/// the overlap, plus 1e-12 for the sums over the contact's steps. The engine and
/// [`crate::stability::discrete_collision`] agree to 1e-10 at v0 = 1e-3 (δmax ≈ 1e-6) and to
/// 1e-13 at v0 ≥ 1.
/// The six rows of one head-on impact at speed `v0` (length/time) and step `dt` (time),
/// measured `got`: restitution (named `e_quantity`), contact time and largest overlap against
/// the closed form `cf` (case `names[0]`), each held to 1.5 times the error the scheme's
/// recurrence `ours` makes at this dt (first order in dt: e.g. 3.4e-4 free–free, 8.8e-4
/// free–wall at tc/50 for e; 6.2e-4 free–wall for δmax, sampled at the ends of steps, O(dt²)
/// below the peak), the contact time to one step; and against that recurrence (case
/// `names[1]`) to `tiny`, the contact time to half a step (its count of steps is exact).
pub fn impact_rows(
    names: [&str; 2],
    e_quantity: &str,
    (cf, ours): (&ClosedForm, &crate::stability::DiscreteCollision),
    v0: f64,
    dt: f64,
    got: &Measured,
    tiny: f64,
) -> [Row; 6] {
    let [name, scheme] = names;
    let error = |got: f64, exact: f64| (got / exact - 1.0).abs();
    let steps = ours.steps_in_contact as f64;
    [
        row(name, e_quantity, cf.e, got.e, 1.5 * error(ours.e, cf.e)),
        row(scheme, "restitution e", ours.e, got.e, tiny),
        row(name, "contact time", cf.tc, got.duration, 1.01 * dt / cf.tc),
        row(
            scheme,
            "contact time",
            steps * dt,
            got.duration,
            0.5 / steps,
        ),
        row(
            name,
            "max overlap",
            cf.delta_max_per_speed * v0,
            got.delta_max,
            1.5 * error(ours.delta_max_per_speed, cf.delta_max_per_speed),
        ),
        row(
            scheme,
            "max overlap",
            ours.delta_max_per_speed * v0,
            got.delta_max,
            tiny,
        ),
    ]
}

fn round_off(reach: f64, delta_max: f64) -> f64 {
    1e-12 + 100.0 * f64::EPSILON * reach / delta_max
}

/// The binary-collision rows: each speed at the case's dt, and the convergence order.
pub fn binary_collisions(case: &Case) -> anyhow::Result<Vec<Row>> {
    binary_collisions_against(case, case)
}

/// The binary-collision rows of `simulated`'s law (its dt from its own tc and the case's
/// steps per collision, as a run would take it) judged against the answers for `reference`'s
/// law: with `simulated` = `reference` the table's rows; with a law off by a small error, the
/// rows that must catch it.
///
/// Two kinds of expected value per quantity:
/// - the closed form (the physics): held to 1.5 times the error verdem's scheme makes at this
///   dt and onset, which is first order in dt (the dashpot lags by dt/2; where the contact starts
///   and ends within a step adds another O(dt) term), computed by the scheme's recurrence
///   ([`crate::stability::discrete_collision`]);
/// - that recurrence itself (the same scheme run on the overlap alone, an implementation
///   independent of the engine's): held to round-off, so that an error of 1e-3 in kn (5e-5 in
///   e, 5e-4 in δmax) or γn (1e-4 in e) fails.
pub fn binary_collisions_against(reference: &Case, simulated: &Case) -> anyhow::Result<Vec<Row>> {
    use crate::stability::{discrete_collision, Spring};
    let case = reference;
    let m = case.particle_mass();
    let mut rows = Vec::new();
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    let spring = Spring {
        k: case.contact.kn,
        gamma: case.contact.gamman,
    };
    let scheme = |meff: f64, dt: f64, phase: f64, clip: bool| {
        discrete_collision(meff, spring, dt, phase, clip).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: the scheme is unstable at dt = {dt}",
                case.path.display()
            )
        })
    };
    let reach = case.material.diameter;
    let dt = case.dt();
    for (label, wall, meff) in [("free-free", false, 0.5 * m), ("free-wall", true, m)] {
        let cf = closed_form(case, meff);
        // `collide` touches ONSET into a step: the recurrence's overlap at that step's end is
        // (1 − ONSET)·u·dt
        let ours = scheme(meff, dt, 1.0 - ONSET, false)?;
        let ours_clipped = scheme(meff, dt, 1.0 - ONSET, true)?;
        let error = |got: f64, exact: f64| (got / exact - 1.0).abs();
        for v0 in [1e-3, 1e-1, 1.0, 10.0] {
            let got = collide(simulated, v0, wall, per_tc)?;
            let name = format!("{label} v0={v0} dt=tc/{per_tc}");
            let scheme_name = format!("{label} v0={v0} leapfrog recurrence at tc/{per_tc}");
            let tiny = round_off(reach, ours.delta_max_per_speed * v0);
            rows.extend(impact_rows(
                [&name, &scheme_name],
                "restitution e",
                (&cf, &ours),
                v0,
                dt,
                &got,
                tiny,
            ));
            let mut clipped = simulated.clone();
            clipped.contact.clip_normal = true;
            let got = collide(&clipped, v0, wall, per_tc)?;
            let quantity = "restitution e (force ends at Fn = 0)";
            // first order in dt, as unclipped: e.g. 1.1e-4 free–free, 1.8e-4 free–wall
            rows.push(row(
                &format!("{name} clipped"),
                quantity,
                cf.e_clipped,
                got.e,
                1.5 * error(ours_clipped.e, cf.e_clipped),
            ));
            rows.push(row(
                &format!("{scheme_name} clipped"),
                quantity,
                ours_clipped.e,
                got.e,
                tiny,
            ));
        }
        // Convergence of the restitution error in dt. The dashpot sees the half-step velocity
        // v_(n+1/2) (MercuryDPM's scheme, also LAMMPS' nve/sphere), a lag of dt/2 in the
        // dissipation: the expected order is 1, not velocity Verlet's 2 for conservative
        // forces. Where the contact starts and ends within a step adds an error that
        // oscillates with tc/dt; it is averaged out over 8 onset phases.
        let steps = [10.0, 20.0, 50.0, 100.0, 200.0, 400.0];
        let mut pts = Vec::new();
        for n in steps {
            let mut mean = 0.0;
            for k in 0..8 {
                mean += collide_with_phase(simulated, 1.0, wall, n, k as f64 / 8.0)?.e / 8.0;
            }
            pts.push((
                (1.0 / n).ln(),
                ((mean - cf.e) / cf.e).abs().max(1e-300).ln(),
            ));
        }
        // first order; the phase-averaged onset term and the O(dt²) remainder bend the fitted
        // slope over tc/10 … tc/400 to 0.91 (free–free) and 0.93 (free–wall). A law 1e-3 off
        // in kn or γn leaves an error that does not vanish with dt: slope ≤ 0.81.
        rows.push(super::row_abs(
            &format!("{label} v0=1 dt=tc/10..tc/400"),
            "order of the restitution error in dt",
            1.0,
            slope(&pts),
            0.15,
        ));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_gives_the_benchmark_values() {
        let case = Case::parse(
            include_str!("../../cases/verify/binary_collision.toml"),
            "b.toml",
        )
        .unwrap();
        let m = case.particle_mass();
        let ff = closed_form(&case, 0.5 * m);
        let fw = closed_form(&case, m);
        assert!((ff.tc - 3.5963e-3).abs() < 1e-7 && (ff.e - 0.90210).abs() < 1e-5);
        assert!((fw.tc - 5.0845e-3).abs() < 1e-7 && (fw.e - 0.92976).abs() < 1e-5);
    }
}
