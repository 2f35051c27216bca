//! The time step from tc/400 to beyond 2 tc: binary collisions against their closed form, the
//! stability limit of a sustained contact measured against the theory, and the shear case.

use std::path::Path;

use super::{g3, load, parse, set, stopped, unset, Did, Inputs, MapRow};
use crate::case::{Case, Scene as SceneSpec, SphereSpec};
use crate::stability::{critical_dt, restitution_error, Spring};
use crate::step::guard::Failure;
use crate::verify::collision::{closed_form, collide_with_phase};

pub const FREE_FREE: &str = "collision free-free";
pub const FREE_WALL: &str = "collision free-wall";
pub const SHEAR: &str = "shear";

/// The time steps of the sweep, as tc_ff/dt (tc_ff: the free–free collision time).
pub const PER_TC: [f64; 11] = [
    400.0, 100.0, 50.0, 20.0, 10.0, 5.0, 3.0, 2.0, 1.5, 1.0, 0.45,
];

/// Onset phases a collision is measured at: the first touch (k + 1/2)/8 of a step into the
/// step (not at a step's end, where rounding decides whether the dashpot acts a step earlier).
const PHASES: usize = 8;

/// Relative error of the restitution and the maximum overlap, averaged over the onset phases
/// (as the collisions of a flow average them), beyond which a collision's numbers are not to
/// be trusted without a word from verdem.
pub const TRUST: f64 = 0.01;

/// Whether a row passes: a case stable by theory whose numbers are trustworthy must run; one
/// whose numbers are not must be warned about or stopped (not refused: it is stable); one
/// beyond the limit must not run silently.
pub fn judge(stable: bool, trustworthy: bool, did: &Did) -> bool {
    match (stable, trustworthy) {
        (false, _) => !did.ran(),
        (true, true) => did.ran(),
        (true, false) => did.spoke() && !matches!(did, Did::Refused(_)),
    }
}

/// The limit of tc_ff/dt for a pair of effective mass `meff` under `case`'s law: smaller
/// values are beyond the scheme's stability limit.
pub fn limit_per_tc(case: &Case, meff: f64) -> f64 {
    let tc = case.tc_free_free().unwrap_or(f64::NAN);
    let spring = Spring {
        k: case.contact.kn,
        gamma: case.contact.gamman,
    };
    tc / critical_dt(meff, spring)
}

/// A collision measured over [`PHASES`] onset phases.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    pub e_min: f64,
    pub e_max: f64,
    pub e_mean: f64,
    /// Mean over the phases of the largest overlap seen at a step.
    pub delta_mean: f64,
    /// Relative error of the mean restitution.
    pub e_error: f64,
    /// Relative error of the mean largest overlap.
    pub delta_error: f64,
}

/// The collision of `case` (head-on at speed `v0`, on a wall sphere when `wall`) at tc_ff/dt =
/// `per_tc`, over the onset phases, against the closed form.
pub fn sweep(case: &Case, wall: bool, per_tc: f64, v0: f64) -> Result<Sweep, Failure> {
    let m = case.particle_mass();
    let cf = closed_form(case, if wall { m } else { 0.5 * m });
    let mut s = Sweep {
        e_min: f64::INFINITY,
        e_max: f64::NEG_INFINITY,
        e_mean: 0.0,
        delta_mean: 0.0,
        e_error: 0.0,
        delta_error: 0.0,
    };
    for k in 0..PHASES {
        let phase = (k as f64 + 0.5) / PHASES as f64;
        let got = collide_with_phase(case, v0, wall, per_tc, phase).map_err(failure)?;
        s.e_min = s.e_min.min(got.e);
        s.e_max = s.e_max.max(got.e);
        s.e_mean += got.e / PHASES as f64;
        s.delta_mean += got.delta_max / PHASES as f64;
    }
    let delta = cf.delta_max_per_speed * v0;
    s.e_error = ((s.e_mean - cf.e) / cf.e).abs();
    s.delta_error = ((s.delta_mean - delta) / delta).abs();
    Ok(s)
}

/// The guard's failure inside an error, or a failure that names the other error.
pub fn failure(e: anyhow::Error) -> Failure {
    match e.downcast::<Failure>() {
        Ok(f) => f,
        Err(e) => Failure {
            step: 0,
            time: 0.0,
            ids: Vec::new(),
            what: format!("{e:#}"),
            remedy: "",
            kept: None,
        },
    }
}

/// Case text `text` with its time step given as `steps_per_collision = per_tc` (its `dt`, if
/// any, removed).
fn per_collision(text: &str, per_tc: f64) -> String {
    set(
        &unset(text, "run", "dt"),
        "run",
        "steps_per_collision",
        &format!("{per_tc:?}"),
    )
}

/// The collision case text of `base_text` with sphere 2 fixed when `wall`.
fn collision_text(base_text: &str, wall: bool) -> String {
    if !wall {
        return base_text.to_string();
    }
    // the second [[scene.sphere]] is the last table of the file
    format!("{}\nfixed = true\n", base_text.trim_end())
}

fn collisions(inputs: &Inputs, wall: bool) -> anyhow::Result<Vec<MapRow>> {
    let path = inputs.verify_dir.join("binary_collision.toml");
    let (base_text, base) = load(&path)?;
    let m = base.particle_mass();
    let meff = if wall { m } else { 0.5 * m };
    let cf = closed_form(&base, meff);
    let limit = limit_per_tc(&base, meff);
    let name = if wall { FREE_WALL } else { FREE_FREE };
    let text = collision_text(&base_text, wall);
    let mut rows = Vec::new();
    for per_tc in PER_TC {
        let stable = per_tc > limit;
        let t = per_collision(&text, per_tc);
        let measured = sweep(&base, wall, per_tc, 1.0);
        let did = match parse(&t, &path) {
            Err(refused) => refused,
            Ok(a) => a.after(&collide_with_phase(&a.case, 1.0, wall, per_tc, 0.5).map_err(failure)),
        };
        let (text, trustworthy) = match &measured {
            Ok(s) => (
                format!(
                    "e {:.4} ({:.4}..{:.4}, err {}), dmax {} (err {})",
                    s.e_mean,
                    s.e_min,
                    s.e_max,
                    g3(s.e_error),
                    g3(s.delta_mean),
                    g3(s.delta_error)
                ),
                s.e_error.max(s.delta_error) <= TRUST,
            ),
            Err(f) => (stopped(f).text(), false),
        };
        rows.push(MapRow {
            case: name.into(),
            parameter: format!("tc/dt = {per_tc}"),
            // the restitution error a coarse step's warning names, for comparison
            theory: format!(
                "e {:.4}, dmax {}; {} (limit {limit:.3}); estimated err {}",
                cf.e,
                g3(cf.delta_max_per_speed),
                if stable { "stable" } else { "unstable" },
                g3(restitution_error(
                    meff,
                    Spring {
                        k: base.contact.kn,
                        gamma: base.contact.gamman
                    },
                    base.tc_free_free().unwrap_or(f64::NAN) / per_tc
                ))
            ),
            measured: text,
            pass: judge(stable, trustworthy, &did),
            did,
        });
    }
    let measured = measured_limit(&base, wall)?;
    rows.push(limit_row(name, limit, measured));
    Ok(rows)
}

/// The row of a measured stability limit (tc/dt) against the theory's.
pub fn limit_row(name: &str, theory: f64, measured: f64) -> MapRow {
    let error = (measured - theory) / theory;
    MapRow {
        case: name.into(),
        parameter: "stability limit of tc/dt".into(),
        theory: format!("{theory:.5} (kick-drift-kick, linear)"),
        measured: format!(
            "{measured:.5} (sustained contact, bisection), rel. diff {}",
            g3(error)
        ),
        did: Did::Ran,
        pass: error.abs() <= 1e-3,
    }
}

/// The free–free rows.
pub fn free_free(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    collisions(inputs, false)
}

/// The free–wall rows.
pub fn free_wall(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    collisions(inputs, true)
}

/// Overlap of a sustained contact at rest (length), and the displacement it starts from.
const PRELOAD: f64 = 1e-3;
const NUDGE: f64 = 1e-5;

/// Whether a sustained contact of `base`'s law, nudged from rest, is stable at tc_ff/dt =
/// `per_tc`: its displacement after 2000 steps is no larger than the nudge. Free–wall: a
/// sphere pressed onto a wall sphere by gravity (overlap [`PRELOAD`] at rest). Free–free: a
/// sphere between two wall spheres overlapping it by [`PRELOAD`], whose equation,
/// m ẍ = −2kn x − 2γn ẋ, is that of a free pair's relative motion (m/2 ẍ = −kn x − γn ẋ).
pub fn sustained_stable(base: &Case, wall: bool, per_tc: f64) -> anyhow::Result<bool> {
    let mut case = base.clone();
    case.run.dt = None;
    case.run.steps_per_collision = Some(per_tc);
    let d = case.material.diameter;
    let sphere = |x: f64, fixed: bool| SphereSpec {
        x: [x, 0.0, 0.0],
        v: [0.0; 3],
        w: [0.0; 3],
        radius: None,
        fixed,
    };
    let (spheres, rest) = if wall {
        // gravity +x presses sphere 1 onto the wall sphere at x = 0 with overlap PRELOAD
        case.run.gravity = Some([case.contact.kn * PRELOAD / case.particle_mass(), 0.0, 0.0]);
        let rest = -(d - PRELOAD);
        (vec![sphere(rest + NUDGE, false), sphere(0.0, true)], rest)
    } else {
        case.run.gravity = None;
        let gap = d - PRELOAD;
        (
            vec![sphere(NUDGE, false), sphere(-gap, true), sphere(gap, true)],
            0.0,
        )
    };
    case.scene = SceneSpec::Spheres { sphere: spheres };
    let scene = crate::scene::build(&case, None)?;
    let mut e = super::engine_of(&case, scene)?;
    let mut largest = 0.0f64;
    for step in 0..2000 {
        if e.advance(1).is_err() {
            return Ok(false);
        }
        if step >= 1800 {
            let s = e.snapshot();
            largest = largest.max((s.particles.x[0].x - rest).abs());
        }
    }
    Ok(largest <= NUDGE)
}

/// The limit of tc_ff/dt measured by bisection (in log space) between a stable tc/dt of 10 and
/// an unstable one of 0.3.
pub fn measured_limit(base: &Case, wall: bool) -> anyhow::Result<f64> {
    bisect(10.0, 0.3, 30, |per_tc| sustained_stable(base, wall, per_tc))
}

/// The boundary between `good` (where `ok` holds) and `bad` (where it does not), by `n`
/// geometric bisections.
fn bisect(
    mut good: f64,
    mut bad: f64,
    n: usize,
    mut ok: impl FnMut(f64) -> anyhow::Result<bool>,
) -> anyhow::Result<f64> {
    anyhow::ensure!(
        ok(good)? && !ok(bad)?,
        "the bisection's ends {good} and {bad} do not bracket the limit"
    );
    for _ in 0..n {
        let mid = (good * bad).sqrt();
        if ok(mid)? {
            good = mid;
        } else {
            bad = mid;
        }
    }
    Ok((good * bad).sqrt())
}

/// Steps of each shear run.
pub const SHEAR_STEPS: u64 = 2000;

/// Largest growth of the free spheres' kinetic energy over a shear run that is still trusted:
/// the walls feed the steady flow, whose kinetic energy changes by a few per cent over the
/// 0.14 time units of a run at the benchmark's step.
pub const SHEAR_GROWTH: f64 = 1.5;

/// One shear run of [`SHEAR_STEPS`] from `state` at tc_ff/dt = `per_tc`: the growth of the
/// free kinetic energy, or the guard's failure.
pub fn shear_run(base: &Case, state: &Path, per_tc: f64) -> anyhow::Result<Result<f64, Failure>> {
    let mut case = base.clone();
    case.run.dt = None;
    case.run.steps_per_collision = Some(per_tc);
    let scene = crate::scene::build(&case, Some(state))?;
    let mut e = super::engine_of(&case, scene)?;
    let kinetic = |e: &dyn crate::step::Engine| {
        let p = &e.state().particles;
        (0..p.len())
            .filter(|&a| p.inv_mass[a] > 0.0)
            .map(|a| 0.5 * p.v[a].norm_squared() / p.inv_mass[a])
            .sum::<f64>()
    };
    let k0 = kinetic(e.as_ref());
    Ok(e.advance(SHEAR_STEPS).map(|_| kinetic(e.as_ref()) / k0))
}

/// The shear rows: each time step, and the measured threshold against the pair's limit.
pub fn shear(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let (text, base) = load(&inputs.shear)?;
    let limit = limit_per_tc(&base, 0.5 * base.particle_mass());
    let state = &inputs.shear_state;
    let trusted = |r: &Result<f64, Failure>| matches!(r, Ok(g) if *g <= SHEAR_GROWTH);
    let mut rows = Vec::new();
    for per_tc in [50.0, 10.0, 5.0, 3.0, 2.0, 1.7, 1.5, 1.0, 0.45] {
        let stable = per_tc > limit;
        let t = per_collision(&text, per_tc);
        let measured = shear_run(&base, state, per_tc)?;
        // an accepted case is the base with this step: its run is the measured one
        let did = super::did(&t, &inputs.shear, &measured);
        rows.push(MapRow {
            case: SHEAR.into(),
            parameter: format!("tc/dt = {per_tc}"),
            theory: format!(
                "pair {} (limit {limit:.3})",
                if stable { "stable" } else { "unstable" }
            ),
            measured: match &measured {
                Ok(g) => format!("{SHEAR_STEPS} steps, kinetic energy x{g:.3}"),
                Err(f) => stopped(f).text(),
            },
            pass: judge(stable, trusted(&measured), &did),
            did,
        });
    }
    let threshold = bisect(50.0, 0.45, 12, |per_tc| {
        Ok(trusted(&shear_run(&base, state, per_tc)?))
    })?;
    rows.push(MapRow {
        case: SHEAR.into(),
        parameter: "threshold of tc/dt".into(),
        theory: format!("free-free pair limit {limit:.3}"),
        measured: format!(
            "{threshold:.3} (runs {SHEAR_STEPS} steps above it), ratio to the pair's {:.3}",
            threshold / limit
        ),
        did: Did::Ran,
        pass: threshold >= limit,
    });
    Ok(rows)
}
