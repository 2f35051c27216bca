//! Friction at its extremes, on a sphere hitting a wall sphere of radius 500 (the oblique
//! impact case) head-on with an initial spin: mu = 0 (no tangential force at all), mu = 1e6
//! (always sticking), and mu lowered mid-contact through a checkpoint.

use super::{g3, load, parse, set, Did, Inputs, MapRow};
use crate::case::{Case, Scene as SceneSpec, SphereSpec};
use crate::io::checkpoint;
use crate::verify::collision::{closed_form, impact, Body};
use crate::Vec3;

pub const CASE: &str = "friction";

/// Radius of the wall sphere, in sphere radii.
const WALL_RADII: f64 = 1000.0;

/// Contact-point slip speed over the normal speed of the impacts: gross sliding at the
/// benchmark's mu = 0.3 (ψ ≥ 7μ(1 + e)/2 ≈ 2.0), sticking at mu = 1e6 (ψ ≤ 7μ/2).
const PSI: f64 = 3.0;

/// The sphere (normal speed 1 along +x, spin about −y giving the contact point a slip PSI
/// along +z) and the wall sphere.
fn bodies(case: &Case) -> [Body; 2] {
    let r = 0.5 * case.material.diameter;
    let gap = 2.5 * case.dt();
    [
        Body {
            x: Vec3::new(-r - gap, 0.0, 0.0),
            v: Vec3::new(1.0, 0.0, 0.0),
            w: Vec3::new(0.0, -PSI / r, 0.0),
            radius: None,
            fixed: false,
        },
        Body {
            x: Vec3::new(WALL_RADII * r, 0.0, 0.0),
            v: Vec3::zeros(),
            w: Vec3::zeros(),
            radius: Some(WALL_RADII * r),
            fixed: true,
        },
    ]
}

/// `text` and `case` with friction coefficient `mu`.
fn with_mu(text: &str, case: &Case, mu: f64) -> (String, Case) {
    let mut c = case.clone();
    c.contact.mu = mu;
    (set(text, "contact", "mu", &format!("{mu:?}")), c)
}

/// What verdem's command line does with `text`.
fn did(text: &str, path: &std::path::Path) -> Did {
    super::did(text, path, &Ok::<(), crate::step::guard::Failure>(()))
}

/// The friction rows.
pub fn rows(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let path = inputs.verify_dir.join("oblique_impact.toml");
    let (text, base) = load(&path)?;
    let r = 0.5 * base.material.diameter;
    let per_tc = base.run.steps_per_collision.unwrap_or(50.0);
    let mut rows = Vec::new();

    // mu = 0: the frictionless law has no tangential force and no torque at all
    let (t, case) = with_mu(&text, &base, 0.0);
    let out = impact(&case, bodies(&case), per_tc)?;
    let spin = (out.w[0] - Vec3::new(0.0, -PSI / r, 0.0)).norm();
    let tangential = out.v[0].y.abs().max(out.v[0].z.abs());
    rows.push(MapRow {
        case: CASE.into(),
        parameter: "mu = 0".into(),
        theory: "spin and tangential velocity unchanged (exactly)".into(),
        measured: format!(
            "spin change {}, tangential speed {}",
            g3(spin),
            g3(tangential)
        ),
        pass: spin == 0.0 && tangential == 0.0,
        did: did(&t, &path),
    });

    // mu = 1e6: sticking, the contact point's slip is restored like the normal velocity
    let (t, case) = with_mu(&text, &base, 1e6);
    let e = closed_form(&case, case.particle_mass()).e;
    let out = impact(&case, bodies(&case), per_tc)?;
    let beta = -(out.v[0].z - r * out.w[0].y) / PSI;
    rows.push(MapRow {
        case: CASE.into(),
        parameter: format!("mu = 1e6, psi = {PSI}"),
        theory: format!("sticking: beta = e = {e:.5} (+-1e-2)"),
        measured: format!("beta {beta:.5}"),
        pass: (beta - e).abs() <= 1e-2,
        did: did(&t, &path),
    });

    rows.push(mu_changed(inputs, &text, &base, &path)?);
    Ok(rows)
}

/// |Ft|/|fn| of the contact of a two-sphere state.
fn ratio(s: &crate::state::Snapshot) -> Option<f64> {
    let c = s.contacts.first()?;
    let n = s
        .domain
        .min_image(s.particles.x[c.p as usize] - s.particles.x[c.i as usize])
        .normalize();
    let ft = c.force.f - c.force.fn_signed * n;
    Some(ft.norm() / c.force.fn_signed.abs())
}

/// Mid-contact change of mu: the impact at mu = 1e6 (sticking, |Ft|/|fn| = 2ψ/7 ≈ 0.86) run to
/// half its contact, a checkpoint written, the case's mu set to 0.1 and the run resumed from
/// the checkpoint: one step later the Coulomb cap holds the contact at |Ft| = 0.1 |fn|.
fn mu_changed(
    inputs: &Inputs,
    text: &str,
    base: &Case,
    path: &std::path::Path,
) -> anyhow::Result<MapRow> {
    let (mu_before, mu_after) = (1e6, 0.1);
    let (_, mut sticking) = with_mu(text, base, mu_before);
    sticking.run.steps_per_collision = base.run.steps_per_collision;
    let spheres: Vec<SphereSpec> = bodies(&sticking)
        .iter()
        .map(|b| SphereSpec {
            x: b.x.into(),
            v: b.v.into(),
            w: b.w.into(),
            radius: b.radius,
            fixed: b.fixed,
        })
        .collect();
    sticking.scene = SceneSpec::Spheres { sphere: spheres };
    let scene = crate::scene::build(&sticking, None)?;
    let mut e = super::engine_of(&sticking, scene)?;
    let half = (closed_form(&sticking, sticking.particle_mass()).tc / (2.0 * sticking.dt())) as u64;
    let mut in_contact = 0;
    while in_contact < half {
        e.advance(1)?;
        if !e.snapshot().contacts.is_empty() {
            in_contact += 1;
        }
    }
    let before = ratio(&e.snapshot()).unwrap_or(f64::NAN);
    std::fs::create_dir_all(&inputs.out)?;
    let ck = inputs.out.join("friction_mu.checkpoint");
    let tag = format!("{}:2", sticking.name);
    checkpoint::write(&ck, &e.snapshot(), e.params().dt, &tag)?;

    // the case with mu changed, as a user would edit it, then resumed
    let (t, _) = with_mu(text, base, mu_after);
    let (after, did) = match parse(&t, path) {
        Err(refused) => (f64::NAN, refused),
        Ok(accepted) => {
            let mut case = accepted.case.clone();
            case.scene = sticking.scene.clone();
            let scene = crate::scene::build(&case, None)?;
            let mut resumed = super::engine_of(&case, scene)?;
            match checkpoint::read(&ck, resumed.as_mut(), &tag) {
                Err(err) => (f64::NAN, Did::Refused(format!("{err:#}"))),
                Ok(_) => {
                    let run = resumed.advance(1);
                    let after = ratio(&resumed.snapshot()).filter(|_| run.is_ok());
                    (after.unwrap_or(f64::NAN), accepted.after(&run))
                }
            }
        }
    };
    Ok(MapRow {
        case: CASE.into(),
        parameter: format!("mu {mu_before:e} -> {mu_after} mid-contact (checkpoint)"),
        theory: format!("|Ft|/|fn| > {mu_after} before, = {mu_after} one step after"),
        measured: format!("{before:.4} before, {after:.12} after"),
        pass: before > mu_after && ((after - mu_after) / mu_after).abs() <= 1e-9,
        did,
    })
}
