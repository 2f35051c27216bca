//! Many bodies: a jammed periodic packing held static stays static, and the total momentum of
//! a frictionless periodic gas over 1e7 steps.

use rand::{Rng, SeedableRng};

use super::{g3, load, set, stopped, Did, Inputs, MapRow};
use crate::case::{DomainSpec, Scene as SceneSpec, Search};
use crate::scene::Scene;
use crate::state::{Domain, Motion, Particles};
use crate::Vec3;

pub const JAMMED: &str = "jammed packing";
pub const GAS: &str = "periodic gas";

/// Spheres of the gas and its steps.
pub const GAS_COUNT: usize = 4;
pub const GAS_STEPS: u64 = 10_000_000;
/// Edge of the gas's periodic box (room for the random fill's two layers).
const GAS_EDGE: f64 = 3.5;

/// The frictionless elastic gas of `conservation.toml` cut down to [`GAS_COUNT`] spheres in a
/// periodic box of edge [`GAS_EDGE`] for [`GAS_STEPS`] steps: the change of the total momentum relative
/// to M v_rms. Pair forces are equal and opposite, so only the rounding of the velocity
/// updates moves it: at most ε|v| per particle and half-kick, 2 S ε v_max/v_rms relative.
pub fn gas(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let path = inputs.verify_dir.join("conservation.toml");
    let (text, base) = load(&path)?;
    let mut case = base.clone();
    case.contact.gamman = 0.0;
    case.contact.mu = 0.0;
    case.domain = DomainSpec {
        lo: [0.0; 3],
        hi: [GAS_EDGE; 3],
        periodic: [true; 3],
    };
    case.neighbor.search = Search::AllPairs;
    case.scene = SceneSpec::Gas {
        count: GAS_COUNT,
        speed: 1.0,
    };
    let t = set(&text, "contact", "gamman", "0.0");
    let t = set(&t, "contact", "mu", "0.0");
    let t = set(&t, "domain", "hi", &format!("{:?}", [GAS_EDGE; 3]));
    let t = set(&t, "neighbor", "search", "\"all-pairs\"");
    let t = set(&t, "scene", "count", &GAS_COUNT.to_string());
    let scene = crate::scene::build(&case, None)?;
    let mut e = super::engine_of(&case, scene)?;
    let totals = |e: &dyn crate::step::Engine| {
        let p = &e.state().particles;
        let (mut mom, mut mass, mut ke, mut vmax) = (Vec3::zeros(), 0.0, 0.0, 0.0f64);
        for a in 0..p.len() {
            let m = 1.0 / p.inv_mass[a];
            mom += m * p.v[a];
            mass += m;
            ke += 0.5 * m * p.v[a].norm_squared();
            vmax = vmax.max(p.v[a].norm());
        }
        (mom, mass, (2.0 * ke / mass).sqrt(), vmax)
    };
    let (p0, mass, v_rms, v_max) = totals(e.as_ref());
    let outcome = e.advance(GAS_STEPS);
    let change = (totals(e.as_ref()).0 - p0).norm() / (mass * v_rms);
    let bound = 2.0 * GAS_STEPS as f64 * f64::EPSILON / 2.0 * v_max / v_rms;
    let did = super::did(&t, &path, &outcome);
    Ok(vec![MapRow {
        case: GAS.into(),
        parameter: format!("{GAS_COUNT} spheres, {GAS_STEPS} steps, frictionless elastic"),
        theory: format!("|P-P0|/(M v_rms) <= 2 S eps v_max/v_rms = {}", g3(bound)),
        measured: format!("|P-P0|/(M v_rms) {}", g3(change)),
        pass: outcome.is_ok() && change <= bound && did.ran(),
        did,
    }])
}

/// Spheres of the jammed packing, its volume fraction and the steps it is held.
pub const JAMMED_COUNT: usize = 200;
pub const JAMMED_FRACTION: f64 = 0.64;
pub const JAMMED_STEPS: u64 = 20_000;

/// Harmonic overlap forces (unit stiffness) on spheres of diameter `d` at `x` in `domain`,
/// through the pair list `pairs`; spheres from `free` on are fixed (no force is kept on
/// them); centres below `z_range.0` or above `z_range.1` are pushed back the same way.
fn harmonic(
    domain: &Domain,
    x: &[Vec3],
    d: f64,
    free: usize,
    z_range: (f64, f64),
    pairs: &[(usize, usize)],
    f: &mut [Vec3],
) {
    f.iter_mut().for_each(|v| *v = Vec3::zeros());
    for &(a, b) in pairs {
        let r = domain.min_image(x[a] - x[b]);
        let dist = r.norm();
        if dist < d {
            let push = r * ((d - dist) / dist);
            f[a] += push;
            f[b] -= push;
        }
    }
    for (a, p) in x.iter().enumerate().take(free) {
        f[a].z += (z_range.0 - p.z).max(0.0) - (p.z - z_range.1).max(0.0);
    }
    f.iter_mut().skip(free).for_each(|v| *v = Vec3::zeros());
}

/// Pairs closer than `reach`, at least one of them free (index below `free`).
fn near(domain: &Domain, x: &[Vec3], free: usize, reach: f64) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for a in 0..free {
        for b in a + 1..x.len() {
            if domain.min_image(x[a] - x[b]).norm() < reach {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// Moves the first `free` spheres (diameter `d`) of `x` to a minimum of the harmonic overlap
/// energy by FIRE (Bitzek et al., Phys. Rev. Lett. 97, 170201, 2006), the others fixed,
/// centres kept in `z_range`, until the largest net force is below 1e-15 of the diameter
/// (unit stiffness) or after 200000 iterations.
fn relax(domain: &Domain, x: &mut [Vec3], free: usize, d: f64, z_range: (f64, f64)) {
    let n = x.len();
    let mut v = vec![Vec3::zeros(); n];
    let mut f = vec![Vec3::zeros(); n];
    let (mut dt, dt_max, mut alpha, mut since) = (0.02, 0.1, 0.1, 0);
    let mut pairs = near(domain, x, free, 1.3 * d);
    let mut anchor = x.to_vec();
    for _ in 0..200_000 {
        if x.iter()
            .zip(&anchor)
            .any(|(a, b)| domain.min_image(a - b).norm() > 0.1 * d)
        {
            pairs = near(domain, x, free, 1.3 * d);
            anchor = x.to_vec();
        }
        harmonic(domain, x, d, free, z_range, &pairs, &mut f);
        if f.iter().map(|v| v.norm()).fold(0.0, f64::max) < 1e-15 * d {
            break;
        }
        let power: f64 = v.iter().zip(&f).map(|(v, f)| v.dot(f)).sum();
        let (vn, fnorm) = (
            v.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt(),
            f.iter().map(|f| f.norm_squared()).sum::<f64>().sqrt(),
        );
        if power > 0.0 {
            for (v, f) in v.iter_mut().zip(&f) {
                *v = (1.0 - alpha) * *v + alpha * vn / fnorm.max(1e-300) * f;
            }
            since += 1;
            if since > 5 {
                dt = (dt * 1.1f64).min(dt_max);
                alpha *= 0.99;
            }
        } else {
            v.iter_mut().for_each(|v| *v = Vec3::zeros());
            dt *= 0.5;
            alpha = 0.1;
            since = 0;
        }
        for a in 0..free {
            v[a] += dt * f[a];
            x[a] += dt * v[a];
            domain.wrap(&mut x[a]);
        }
    }
}

/// A jammed packing: `n` spheres of diameter `d` at random in a periodic cube of volume
/// fraction `phi`, relaxed to a minimum of the harmonic overlap energy.
pub fn jammed_packing(n: usize, d: f64, phi: f64, seed: u64) -> (Domain, Vec<Vec3>) {
    let edge = (n as f64 * std::f64::consts::PI / 6.0 * d.powi(3) / phi).cbrt();
    let domain = Domain::new(Vec3::zeros(), Vec3::from([edge; 3]), [true; 3]);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut x: Vec<Vec3> = (0..n)
        .map(|_| Vec3::from([(); 3].map(|_| rng.gen_range(0.0..edge))))
        .collect();
    relax(&domain, &mut x, n, d, (f64::MIN, f64::MAX));
    (domain, x)
}

/// The jammed packing held static under the conservation case's law (friction and dashpots)
/// for [`JAMMED_STEPS`] steps: the net forces at rest against the contact forces, and the
/// kinetic energy over the run.
pub fn jammed(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let path = inputs.verify_dir.join("conservation.toml");
    let (_, base) = load(&path)?;
    let d = base.material.diameter;
    let (domain, x) = jammed_packing(JAMMED_COUNT, d, JAMMED_FRACTION, 11);
    let mut particles = Particles::default();
    for p in &x {
        particles.push(
            *p,
            Vec3::zeros(),
            Vec3::zeros(),
            0.5 * d,
            base.material.density,
            Motion::Free,
        );
    }
    let mut case = base.clone();
    case.domain = DomainSpec {
        lo: domain.lo.into(),
        hi: domain.hi.into(),
        periodic: [true; 3],
    };
    let scene = Scene {
        domain,
        particles,
        time: 0.0,
        walls: Vec::new(),
    };
    let mut e = super::engine_of(&case, scene)?;
    let outcome = e.advance(0);
    let s = e.snapshot();
    let contacts = s.contacts.len();
    let force_scale = s
        .contacts
        .iter()
        .map(|c| c.force.fn_signed.abs())
        .sum::<f64>()
        / contacts.max(1) as f64;
    let net = s.particles.f.iter().map(|f| f.norm()).fold(0.0, f64::max);
    let elastic: f64 = s
        .contacts
        .iter()
        .map(|c| 0.5 * c.force.fn_signed.powi(2) / base.contact.kn)
        .sum();
    let kinetic = |e: &dyn crate::step::Engine| {
        let p = &e.state().particles;
        (0..p.len())
            .map(|a| 0.5 * p.v[a].norm_squared() / p.inv_mass[a])
            .sum::<f64>()
    };
    let mut ke = Vec::new();
    let mut stop = outcome.err();
    for _ in 0..10 {
        if stop.is_some() {
            break;
        }
        stop = e.advance(JAMMED_STEPS / 10).err();
        ke.push(kinetic(e.as_ref()) / elastic.max(1e-300));
    }
    let ke_max = ke.iter().cloned().fold(0.0, f64::max);
    // What the residual forces could give over the whole run, undamped: v = F t / m per sphere.
    let t = JAMMED_STEPS as f64 * case.dt();
    let m = case.particle_mass();
    let reach = JAMMED_COUNT as f64 * 0.5 * m * (net * t / m).powi(2) / elastic.max(1e-300);
    let did = stop.as_ref().map_or(Did::Ran, stopped);
    let phi = JAMMED_COUNT as f64 * case.particle_mass()
        / case.material.density
        / domain_volume(&case.domain);
    Ok(vec![
        MapRow {
            case: JAMMED.into(),
            parameter: format!(
                "N = {JAMMED_COUNT}, phi = {phi:.3}, {:.2} contacts/sphere",
                2.0 * contacts as f64 / JAMMED_COUNT as f64
            ),
            theory: "net forces 0 to round-off (<= 1e-12 of a contact force)".into(),
            measured: format!("max |F|/<|fn|> {}", g3(net / force_scale)),
            pass: contacts > 0 && net / force_scale <= 1e-12 && did.ran(),
            did: did.clone(),
        },
        MapRow {
            case: JAMMED.into(),
            parameter: format!("held {JAMMED_STEPS} steps"),
            theory: format!(
                "KE/E_el <= what the residual forces give undamped: {}",
                g3(reach)
            ),
            measured: format!(
                "KE/E_el max {}, last {}",
                g3(ke_max),
                g3(ke.last().copied().unwrap_or(f64::NAN))
            ),
            pass: ke.len() == 10 && ke_max <= reach.max(f64::MIN_POSITIVE) && did.ran(),
            did,
        },
    ])
}

fn domain_volume(d: &DomainSpec) -> f64 {
    (0..3).map(|k| d.hi[k] - d.lo[k]).product()
}

pub const DENSE_SHEAR: &str = "dense shear";

/// Mean volume fraction of the dense shear rows, between the walls' sphere centres less a
/// diameter; the distance of the walls; the steps they are sheared.
pub const SHEAR_FRACTION: f64 = 0.6;
const SHEAR_GAP: f64 = 11.0;
pub const SHEAR_STEPS: u64 = 20_000;

/// The shear case with its walls [`SHEAR_GAP`] apart and as many spheres as make a mean volume
/// fraction of [`SHEAR_FRACTION`], placed at random and relaxed (FIRE) to rest, sheared for
/// [`SHEAR_STEPS`] steps at the case's time step.
pub fn dense_shear(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let (text, base) = load(&inputs.shear)?;
    let crate::case::Scene::BumpyShear {
        wall_rows,
        wall_per_row,
        bottom_z,
        bottom_vx,
        top_vx,
        ..
    } = base.scene
    else {
        anyhow::bail!("{}: needs a bumpy-shear scene", inputs.shear.display());
    };
    let d = base.material.diameter;
    let top_z = bottom_z + SHEAR_GAP;
    let domain = crate::scene::domain_of(&base);
    let l = domain.lengths();
    let height = SHEAR_GAP - d;
    let count = (SHEAR_FRACTION * l.x * l.y * height / (std::f64::consts::PI / 6.0 * d.powi(3)))
        .round() as usize;
    let t = set(&text, "scene", "top_z", &format!("{top_z:?}"));
    let t = set(&t, "scene", "free", &count.to_string());
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    let mut x: Vec<Vec3> = (0..count)
        .map(|_| {
            Vec3::new(
                domain.lo.x + rng.gen_range(0.0..l.x),
                domain.lo.y + rng.gen_range(0.0..l.y),
                rng.gen_range(bottom_z + d..top_z - d),
            )
        })
        .collect();
    let walls = [
        (
            crate::scene::bumpy_wall(wall_rows, wall_per_row, d, bottom_z),
            bottom_vx,
        ),
        (
            crate::scene::bumpy_wall(wall_rows, wall_per_row, d, top_z),
            top_vx,
        ),
    ];
    for (w, _) in &walls {
        x.extend(w.iter().copied());
    }
    relax(
        &domain,
        &mut x,
        count,
        d,
        (bottom_z + 0.5 * d, top_z - 0.5 * d),
    );
    let mut particles = Particles::default();
    let rho = base.material.density;
    // the order of a bumpy-shear file: the walls' spheres, then the free ones
    for (g, (w, vx)) in walls.iter().enumerate() {
        for p in w {
            let v = Vec3::new(*vx, 0.0, 0.0);
            particles.push(
                *p,
                v,
                Vec3::zeros(),
                0.5 * d,
                rho,
                Motion::Prescribed(g as u8),
            );
        }
    }
    for p in x.iter().take(count) {
        particles.push(*p, Vec3::zeros(), Vec3::zeros(), 0.5 * d, rho, Motion::Free);
    }
    let scene = Scene {
        domain,
        particles,
        time: 0.0,
        walls: Vec::new(),
    };
    // the relaxed state as an initial file, which the case text names as a user's would
    let relaxed = super::engine_of(&base, scene)?.snapshot();
    std::fs::create_dir_all(&inputs.out)?;
    let init = inputs.out.join("dense_shear.data");
    crate::io::atomic::write(&init, crate::io::mercury::data_text(&relaxed).as_bytes())?;
    let t = set(
        &t,
        "run",
        "init",
        &format!("{:?}", init.display().to_string()),
    );
    let accepted = super::parse(&t, &inputs.shear);
    let mut case = base.clone();
    if let Ok(a) = &accepted {
        case = a.case.clone();
    } else {
        case.run.init = Some(init.display().to_string());
        case.scene = crate::case::Scene::BumpyShear {
            free: count,
            wall_rows,
            wall_per_row,
            bottom_z,
            top_z,
            bottom_vx,
            top_vx,
        };
    }
    let mut e = super::engine_of(&case, crate::scene::build(&case, None)?)?;
    let mut largest = 0.0f64;
    let mut outcome = e.advance(0);
    for _ in 0..20 {
        if outcome.is_err() {
            break;
        }
        outcome = e.advance(SHEAR_STEPS / 20);
        let s = e.snapshot();
        for c in &s.contacts {
            let r = s
                .domain
                .min_image(s.particles.x[c.p as usize] - s.particles.x[c.i as usize]);
            largest = largest.max(d - r.norm());
        }
    }
    let did = accepted.map_or_else(|refused| refused, |a| a.after(&outcome));
    Ok(vec![MapRow {
        case: DENSE_SHEAR.into(),
        parameter: format!("{count} spheres, walls {SHEAR_GAP} apart, mean phi {SHEAR_FRACTION}"),
        theory: "runs (no guard stop)".into(),
        measured: format!(
            "{SHEAR_STEPS} steps, largest overlap at the saves {} of the radius",
            g3(largest / (0.5 * d))
        ),
        pass: did == Did::Ran,
        did,
    }])
}
