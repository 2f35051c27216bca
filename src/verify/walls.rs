//! Flat walls (cases/verify/wall_impact.toml): a sphere against an infinite plane through the
//! solver, R* = R and m* = m.
//!
//! - head-on impacts: restitution, contact time and maximum overlap against the linear
//!   spring–dashpot's closed form with m* = m (the free–wall numbers of binary_collision.toml,
//!   tc = 5.0845e-3, e = 0.92976), to 1.5 times the scheme's own error at this dt, and against
//!   the scheme's recurrence ([`crate::stability::discrete_collision`]) to round-off; the order
//!   of the restitution error in dt;
//! - oblique impacts per tangential convention (the answers of [`super::oblique`], there on a
//!   fixed sphere of radius 1000 R): sticking, β = e; sliding, Jt/Jn = μ;
//! - a sphere rolling on a plane without resistance, on a wall at rest and on a moving one: the
//!   contact's spring stays at round-off (a wrong sign of ω × arm at a wall, Lethe #889, makes
//!   it slide at twice the speed).

use super::collision::{impact_rows, Measured};
use super::{closed_form, row, row_abs, Row};
use crate::analysis::stats::slope;
use crate::case::{Case, Scene, WallSpec};
use crate::contact::{Arms, Tangential};
use crate::step::engine::{self, Overrides};
use crate::Vec3;

/// Where the impacts first touch: half a step into a step, as [`super::collision::collide`].
const ONSET: f64 = 0.5;

/// The state after the sphere's contact with the wall ended.
struct Bounce {
    v: Vec3,
    w: Vec3,
    steps_in_contact: u64,
    delta_max: f64,
}

/// `base` with dt = tc_ff/`per_tc`, one free sphere at `x` with velocity `v` and spin `w`, and
/// one wall: the plane x = 0 with normal +x moving with `u` (or, with `floor`, z = 0 with
/// normal +z), under `gravity`.
fn plane_case(base: &Case, per_tc: f64, body: [Vec3; 3], floor: bool, u: Vec3) -> Case {
    let mut case = base.clone();
    case.run.dt = None;
    case.run.steps_per_collision = Some(per_tc);
    case.scene = Scene::Spheres {
        sphere: vec![crate::case::SphereSpec {
            x: body[0].into(),
            v: body[1].into(),
            w: body[2].into(),
            radius: None,
            fixed: false,
        }],
    };
    let normal = if floor {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    case.wall = vec![WallSpec {
        point: [0.0; 3],
        normal,
        velocity: u.into(),
        material: None,
    }];
    case
}

/// Simulates the sphere of `case` ([`plane_case`]) until its wall contact ends.
fn bounce(case: &Case) -> anyhow::Result<Bounce> {
    let scene = crate::scene::build(case, None)?;
    let mut e = engine::build(case, scene, &Overrides::default())?;
    let (mut started, mut steps_in_contact, mut delta_max) = (false, 0u64, 0.0f64);
    let r = 0.5 * case.material.diameter;
    for _ in 0..100_000 {
        e.advance(1)?;
        let s = e.snapshot();
        if !s.wall_contacts.is_empty() {
            started = true;
            steps_in_contact += 1;
            delta_max = delta_max.max(r - s.particles.x[0].x);
        } else if started {
            return Ok(Bounce {
                v: s.particles.v[0],
                w: s.particles.w[0],
                steps_in_contact,
                delta_max,
            });
        }
    }
    anyhow::bail!("{}: no complete impact on the wall", case.path.display())
}

/// A head-on impact at `v0` with dt = tc_ff/`per_tc`, first touching `phase` into a step.
fn head_on(base: &Case, v0: f64, per_tc: f64, phase: f64) -> anyhow::Result<Bounce> {
    let mut probe = base.clone();
    probe.run.dt = None;
    probe.run.steps_per_collision = Some(per_tc);
    let gap = (2.0 + phase) * v0 * probe.dt();
    let r = 0.5 * base.material.diameter;
    let body = [
        Vec3::new(r + gap, 0.0, 0.0),
        Vec3::new(-v0, 0.0, 0.0),
        Vec3::zeros(),
    ];
    bounce(&plane_case(base, per_tc, body, false, Vec3::zeros()))
}

/// Every wall row of the case `base` (wall_impact.toml).
pub fn rows(base: &Case) -> anyhow::Result<Vec<Row>> {
    let mut rows = head_on_rows(base)?;
    rows.extend(oblique_rows(base)?);
    rows.extend(rolling_rows(base)?);
    Ok(rows)
}

/// The head-on rows: each speed at the case's dt, and the order in dt.
fn head_on_rows(case: &Case) -> anyhow::Result<Vec<Row>> {
    use crate::stability::{discrete_collision, Spring};
    let m = case.particle_mass();
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    let dt = case.dt();
    let spring = Spring {
        k: case.contact.kn,
        gamma: case.contact.gamman,
    };
    // m* = m: the sphere against a plane of infinite mass
    let cf = closed_form(case, m);
    let ours = discrete_collision(m, spring, dt, 1.0 - ONSET, false)
        .ok_or_else(|| anyhow::anyhow!("the scheme is unstable at dt = {dt}"))?;
    let mut rows = Vec::new();
    for v0 in [1e-3, 1.0, 10.0] {
        let got = head_on(case, v0, per_tc, ONSET)?;
        let e = got.v.x / v0;
        let duration = got.steps_in_contact as f64 * dt;
        let name = format!("plane v0={v0} dt=tc/{per_tc}");
        let scheme = format!("plane v0={v0} leapfrog recurrence at tc/{per_tc}");
        // the overlap is a difference of positions of size R: ~ε·R a step, over the overlap
        let tiny = 1e-12 + 100.0 * f64::EPSILON * case.material.diameter / got.delta_max;
        let measured = Measured {
            e,
            duration,
            delta_max: got.delta_max,
        };
        rows.extend(impact_rows(
            [&name, &scheme],
            "restitution e (m* = m)",
            (&cf, &ours),
            v0,
            dt,
            &measured,
            tiny,
        ));
    }
    // First order, as the free–wall sphere's. Averaged over 8 onset phases in the middle of
    // their eighths of a step: an onset exactly at a step's end (phase 0) is decided by the
    // round-off of the positions (touching is strict), which moves a step in or out of the
    // contact and the fitted slope by 0.3.
    let mut pts = Vec::new();
    for n in [10.0, 20.0, 50.0, 100.0, 200.0, 400.0] {
        let mut mean = 0.0;
        for k in 0..8 {
            mean += head_on(case, 1.0, n, (k as f64 + 0.5) / 8.0)?.v.x / 8.0;
        }
        pts.push((
            (1.0 / n).ln(),
            ((mean - cf.e) / cf.e).abs().max(1e-300).ln(),
        ));
    }
    rows.push(row_abs(
        "plane v0=1 dt=tc/10..tc/400",
        "order of the restitution error in dt",
        1.0,
        slope(&pts),
        0.15,
    ));
    Ok(rows)
}

/// Absolute tolerance of β = e while sticking on a plane: the scheme's first-order error in e
/// (8.8e-4 at tc/50, free–wall) and the lever arm R − δ/2, O(δmax/R) = 2e-3, as
/// [`super::oblique`]'s on a wall sphere (whose curvature adds nothing measurable at 1000 R).
const STICK_TOLERANCE: f64 = 4e-3;

/// Relative tolerance of Jt/Jn = μ while sliding: the sticking first and last steps, as
/// [`super::oblique`]'s.
const MU_TOLERANCE: f64 = 1e-4;

/// Oblique impacts on the plane at 15° (sticking) and 75° (sliding, clipped) per tangential
/// convention; the law must have kt = 2/7 kn and γt = 2/7 γn.
fn oblique_rows(base: &Case) -> anyhow::Result<Vec<Row>> {
    let c = &base.contact;
    anyhow::ensure!(
        (c.kt / c.kn - 2.0 / 7.0).abs() < 1e-9 && (c.gammat / c.gamman - 2.0 / 7.0).abs() < 1e-9,
        "{}: the oblique answers need kt = 2/7 kn and gammat = 2/7 gamman",
        base.path.display()
    );
    let cf = closed_form(base, base.particle_mass());
    let (mu, per_tc, r) = (c.mu, 50.0, 0.5 * base.material.diameter);
    let mut rows = Vec::new();
    for conv in Tangential::with_constant_kt() {
        let name = conv.name();
        let mut law = base.clone();
        law.contact.tangential = conv.into();
        law.contact.clip_normal = false;
        for (deg, clip) in [(15.0f64, false), (75.0, true)] {
            law.contact.clip_normal = clip;
            let (vn, vt) = (deg.to_radians().cos(), deg.to_radians().sin());
            let mut probe = law.clone();
            probe.run.dt = None;
            probe.run.steps_per_collision = Some(per_tc);
            let gap = 2.5 * vn * probe.dt();
            // towards the plane x = 0 along −x, sliding along +z
            let body = [
                Vec3::new(r + gap, 0.0, 0.0),
                Vec3::new(-vn, 0.0, vt),
                Vec3::zeros(),
            ];
            let out = bounce(&plane_case(&law, per_tc, body, false, Vec3::zeros()))?;
            // contact point at x − (R − δ/2) x̂ moves along z with vz + R ωy (arm −R x̂)
            let u1 = out.v.z + r * out.w.y;
            if clip {
                let ratio = (out.v.z - vt).abs() / (out.v.x + vn).abs();
                rows.push(row(
                    &format!("plane oblique {name} {deg}deg slide clipped"),
                    "impulse ratio Jt/Jn = mu",
                    mu,
                    ratio,
                    MU_TOLERANCE,
                ));
            } else {
                let r = row_abs(
                    &format!("plane oblique {name} {deg}deg stick"),
                    "tangential restitution beta = e",
                    cf.e,
                    -u1 / vt,
                    STICK_TOLERANCE,
                );
                rows.push(r.gating_if(!conv.properties().drops_dashpot_while_sliding));
            }
        }
    }
    Ok(rows)
}

/// Steps of the rolling rows: several contact times.
const ROLLING_STEPS: u64 = 2000;

/// A sphere rolling on the floor z = 0 under gravity, from its resting overlap m·g/kn, with
/// the spin of rolling without slip on its convention's lever arm, on a floor at rest and on
/// one moving along x: the spring's largest length over the run, which rolling leaves at
/// round-off, and the sphere's speed, which it leaves as it was.
fn rolling_rows(base: &Case) -> anyhow::Result<Vec<Row>> {
    let (r, g) = (0.5 * base.material.diameter, 10.0);
    let delta = base.particle_mass() * g / base.contact.kn;
    let mut rows = Vec::new();
    for conv in Tangential::with_constant_kt() {
        // the arm along which the spin enters the convention's slip
        let arm = match conv.geometry().slip {
            Arms::HalfOverlap => r - 0.5 * delta,
            Arms::FullRadius => r,
        };
        for u in [0.0, 0.3] {
            let mut case = base.clone();
            case.contact.tangential = conv.into();
            case.run.gravity = Some([0.0, 0.0, -g]);
            let (v, wall) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(u, 0.0, 0.0));
            // v + ω × (−arm ẑ) = U: ω_y = (v − U)_x/arm
            let w = Vec3::new(0.0, (v.x - u) / arm, 0.0);
            let body = [Vec3::new(0.0, 0.0, r - delta), v, w];
            let case = plane_case(&case, 50.0, body, true, wall);
            let scene = crate::scene::build(&case, None)?;
            let mut e = engine::build(&case, scene, &Overrides::default())?;
            let mut spring = 0.0f64;
            for _ in 0..ROLLING_STEPS {
                e.advance(1)?;
                let s = e.snapshot();
                anyhow::ensure!(
                    s.wall_contacts.len() == 1,
                    "plane rolling {}: the sphere left the floor",
                    conv.name()
                );
                spring = spring.max(s.wall_contacts[0].spring.norm());
            }
            let speed = e.snapshot().particles.v[0].x;
            let name = format!("plane rolling {} wall u={u}", conv.name());
            // round-off of ξ += slip·dt with a slip of ε·|v| a step, over the run's steps
            let tolerance = 10.0 * f64::EPSILON * v.x * case.dt() * ROLLING_STEPS as f64;
            rows.push(row_abs(&name, "spring |xi| = 0", 0.0, spring, tolerance));
            rows.push(row_abs(&name, "speed change = 0", 0.0, speed - v.x, 1e-12));
        }
    }
    Ok(rows)
}
