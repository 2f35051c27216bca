//! Verification cases with analytical answers, run through the same solver as the benchmark.
//!
//! Binary normal collision (cases/verify/binary_collision.toml): restitution, contact time and
//! maximum overlap of the linear spring–dashpot with absolute damping against the closed forms,
//! free–free (m_eff = m/2) and free–wall sphere (m_eff = m), for impact speeds 1e-3 … 10, and
//! the convergence order of the restitution error in dt.

use crate::case::{Case, Scene};
use crate::engine::{self, Overrides};

/// One line of the verification table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub case: String,
    pub quantity: String,
    pub expected: f64,
    pub measured: f64,
    /// Allowed relative error (absolute for orders).
    pub tolerance: f64,
    pub pass: bool,
}

/// Closed-form collision of the linear spring–dashpot (not clipped) for effective mass `meff`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm {
    pub tc: f64,
    pub e: f64,
    /// Maximum overlap per unit impact speed.
    pub delta_max_per_speed: f64,
}

/// The closed form for `case`'s law and effective mass `meff` (`benchmark.md`; e.g. Schwager &
/// Pöschel, Phys. Rev. E 78, 051304, 2008, for the linear dashpot).
pub fn closed_form(case: &Case, meff: f64) -> ClosedForm {
    let w0sq = case.contact.kn / meff;
    let eta = case.contact.gamman / (2.0 * meff);
    let w = (w0sq - eta * eta).sqrt();
    let tc = std::f64::consts::PI / w;
    let tstar = (w / eta).atan() / w;
    ClosedForm {
        tc,
        e: (-eta * tc).exp(),
        delta_max_per_speed: (-eta * tstar).exp() * (w * tstar).sin() / w,
    }
}

/// What one simulated collision gave.
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
    let dt = case.dt();
    // start a little apart, so the contact begins within a few steps at any speed
    let gap = (2.0 + phase) * v0 * dt;
    let Scene::Spheres { sphere } = &mut case.scene else {
        anyhow::bail!(
            "{}: the binary collision case needs a spheres scene",
            base.path.display()
        );
    };
    anyhow::ensure!(
        sphere.len() == 2,
        "{}: needs exactly two spheres",
        base.path.display()
    );
    sphere[0].x = [-0.5 - 0.5 * gap, 0.0, 0.0];
    sphere[0].v = [v0, 0.0, 0.0];
    sphere[1].x = [0.5 + 0.5 * gap, 0.0, 0.0];
    sphere[1].v = [0.0; 3];
    sphere[1].fixed = wall;
    let scene = crate::scene::build(&case, None)?;
    let mut e = engine::build(&case, scene, &Overrides::default());
    let (mut started, mut steps_in_contact, mut delta_max) = (false, 0u64, 0.0f64);
    let rel = |e: &dyn crate::sim::Engine| {
        let s = e.core().snapshot();
        (s.particles.v[1] - s.particles.v[0]).x
    };
    let before = -rel(e.as_ref());
    for _ in 0..100_000 {
        e.advance(1);
        let s = e.core().snapshot();
        let d = 1.0 - (s.particles.x[1] - s.particles.x[0]).norm();
        if !s.contacts.is_empty() {
            started = true;
            steps_in_contact += 1;
            delta_max = delta_max.max(d);
        } else if started {
            let after = rel(e.as_ref());
            return Ok(Measured {
                e: after / before,
                duration: steps_in_contact as f64 * dt,
                delta_max,
            });
        }
    }
    anyhow::bail!("no complete collision at v0 = {v0}")
}

fn row(case: &str, quantity: &str, expected: f64, measured: f64, tolerance: f64) -> Row {
    let err = ((measured - expected) / expected).abs();
    Row {
        case: case.into(),
        quantity: quantity.into(),
        expected,
        measured,
        tolerance,
        pass: err <= tolerance,
    }
}

/// The binary-collision rows: each speed at the case's dt, and the convergence order.
pub fn binary_collisions(case: &Case) -> anyhow::Result<Vec<Row>> {
    let m = case.particle_mass();
    let mut rows = Vec::new();
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    for (label, wall, meff) in [("free-free", false, 0.5 * m), ("free-wall", true, m)] {
        let cf = closed_form(case, meff);
        for v0 in [1e-3, 1e-1, 1.0, 10.0] {
            let got = collide(case, v0, wall, per_tc)?;
            let name = format!("{label} v0={v0} dt=tc/{per_tc}");
            rows.push(row(&name, "restitution e", cf.e, got.e, 2e-3));
            // the duration is counted in whole steps: it is known to one step
            let dt = case.dt();
            rows.push(row(
                &name,
                "contact time",
                cf.tc,
                got.duration,
                1.01 * dt / cf.tc,
            ));
            rows.push(row(
                &name,
                "max overlap",
                cf.delta_max_per_speed * v0,
                got.delta_max,
                2e-3,
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
                mean += collide_with_phase(case, 1.0, wall, n, k as f64 / 8.0)?.e / 8.0;
            }
            pts.push((
                (1.0 / n).ln(),
                ((mean - cf.e) / cf.e).abs().max(1e-300).ln(),
            ));
        }
        let order = slope(&pts);
        rows.push(Row {
            case: format!("{label} v0=1 dt=tc/10..tc/400"),
            quantity: "order of the restitution error in dt".into(),
            expected: 1.0,
            measured: order,
            tolerance: 0.25,
            pass: (order - 1.0).abs() <= 0.25,
        });
    }
    Ok(rows)
}

/// Least-squares slope of (x, y) points.
fn slope(p: &[(f64, f64)]) -> f64 {
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|q| q.0).sum::<f64>() / n,
        p.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let sxy: f64 = p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// The table as text.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<34} {:<38} {:>13} {:>13} {:>9}  result\n",
        "case", "quantity", "expected", "measured", "tolerance"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<34} {:<38} {:>13.6e} {:>13.6e} {:>9.2e}  {}\n",
            r.case,
            r.quantity,
            r.expected,
            r.measured,
            r.tolerance,
            if r.pass { "PASS" } else { "FAIL" }
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_gives_the_benchmark_values() {
        let case = Case::parse(
            include_str!("../cases/verify/binary_collision.toml"),
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
