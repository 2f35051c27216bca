//! Conservation laws, through the solver.
//!
//! - A dense periodic gas (`conservation.toml`, no walls, no gravity) with γn = γt = 0 and
//!   mu = 0 is a Hamiltonian system: the leapfrog scheme keeps the energy (kinetic + ½ kn δ²)
//!   within an oscillation of relative size ~ (ω dt)²/8 of the contact energy (4.9e-4 at
//!   dt = tc/50), the bound both the deviation and the drift over the run are held to. The
//!   force is not smooth where a contact begins and ends (δ = 0), so each collision leaves a
//!   small energy error of either sign: the energy walks randomly (measured +6.9e-5 over 1e6
//!   steps at tc/50, −2.7e-5 at tc/100), it does not oscillate exactly. Pair forces are equal
//!   and opposite, so the total momentum stays zero to round-off, with friction and dashpots
//!   too.
//! - An isolated cluster of touching spheres in an open box, with friction, dashpots and spins:
//!   the total angular momentum Σ x × m v + I ω about the origin is conserved when each pair's
//!   torques balance the moment of its force, (c − x_P) × F + (c − x_I) × (−F) + r × F = 0,
//!   which holds for lever arms to a common contact point. Conventions with full-radius lever
//!   arms (LAMMPS `gran/hooke/history`, Cundall 1979) leave δ n × Ft per contact.
//!   (Angular momentum is not conserved in a periodic box, whose images break the rotational
//!   symmetry; hence the open cluster.)

use super::{row_abs, Row};
use crate::case::Case;
use crate::contact::Tangential;
use crate::scene::{self, random_velocities, Scene};
use crate::state::Domain;
use crate::state::Snapshot;
use crate::state::{Motion, Particles};
use crate::step::engine::{self, Overrides};
use crate::Vec3;

/// Energy, momentum and angular momentum (about the origin) of a snapshot. The energy is the
/// kinetic energy of translation and rotation plus ½ kn δ² of every contact.
pub fn totals(s: &Snapshot, kn: f64) -> (f64, Vec3, Vec3) {
    let p = &s.particles;
    let (mut energy, mut momentum, mut angular) = (0.0, Vec3::zeros(), Vec3::zeros());
    for a in 0..p.len() {
        let (m, inertia) = (1.0 / p.inv_mass[a], 1.0 / p.inv_inertia[a]);
        energy += 0.5 * m * p.v[a].norm_squared() + 0.5 * inertia * p.w[a].norm_squared();
        momentum += m * p.v[a];
        angular += p.x[a].cross(&(m * p.v[a])) + inertia * p.w[a];
    }
    for c in &s.contacts {
        let (a, b) = (c.p as usize, c.i as usize);
        let r = s.domain.min_image(p.x[a] - p.x[b]);
        let delta = p.radius[a] + p.radius[b] - r.norm();
        energy += 0.5 * kn * delta * delta;
    }
    (energy, momentum, angular)
}

/// What a gas run kept: the largest relative energy deviation, the relative energy drift over
/// the run (least-squares line), and the momentum change relative to M·v_rms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GasRun {
    pub energy_deviation: f64,
    pub energy_drift: f64,
    pub momentum_change: f64,
}

/// Runs the gas of `case` for `steps` steps, sampling the totals every `steps/100`.
pub fn gas(case: &Case, steps: u64) -> anyhow::Result<GasRun> {
    let sc = scene::build(case, None)?;
    let mut e = engine::build(case, sc, &Overrides::default())?;
    e.advance(0)?;
    let first = e.snapshot();
    let (e0, p0, _) = totals(&first, case.contact.kn);
    let mass: f64 = first.particles.inv_mass.iter().map(|im| 1.0 / im).sum();
    let v_rms = (2.0 * e0 / mass).sqrt();
    let every = (steps / 100).max(1);
    let (mut pts, mut deviation, mut dp) = (vec![(0.0, 0.0)], 0.0f64, 0.0f64);
    let mut done = 0;
    while done < steps {
        let n = every.min(steps - done);
        e.advance(n)?;
        done += n;
        let (en, p, _) = totals(&e.snapshot(), case.contact.kn);
        let rel = (en - e0) / e0;
        deviation = deviation.max(rel.abs());
        dp = dp.max((p - p0).norm() / (mass * v_rms));
        pts.push((done as f64 / steps as f64, rel));
    }
    Ok(GasRun {
        energy_deviation: deviation,
        energy_drift: crate::analysis::stats::slope(&pts),
        momentum_change: dp,
    })
}

/// An isolated cubic cluster of 3×3×3 spheres of `case`'s material, overlapping by 1e-3, with
/// seeded random velocities (rms 0.1) and spins (rms 1), in an open box.
pub fn cluster(case: &Case) -> Scene {
    let d = case.material.diameter;
    let spacing = d - 1e-3;
    let mut particles = Particles::default();
    let v = random_velocities(27, 0.1, 1);
    let w = random_velocities(27, 1.0, 2);
    let mut k = 0;
    for i in 0..3 {
        for j in 0..3 {
            for l in 0..3 {
                let x = Vec3::new(i as f64, j as f64, l as f64) * spacing;
                particles.push(x, v[k], w[k], 0.5 * d, case.material.density, Motion::Free);
                k += 1;
            }
        }
    }
    Scene {
        domain: Domain::new(
            Vec3::new(-5.0, -5.0, -5.0),
            Vec3::new(7.0, 7.0, 7.0),
            [false; 3],
        ),
        particles,
        time: 0.0,
        walls: Vec::new(),
    }
}

/// Relative change of the cluster's angular momentum over `steps` steps of `case`'s law.
pub fn cluster_angular_momentum(case: &Case, steps: u64) -> anyhow::Result<f64> {
    let mut e = engine::build(case, cluster(case), &Overrides::default())?;
    e.advance(0)?;
    let first = e.snapshot();
    let (_, _, l0) = totals(&first, case.contact.kn);
    let p = &first.particles;
    let scale: f64 = (0..p.len())
        .map(|a| {
            let (m, inertia) = (1.0 / p.inv_mass[a], 1.0 / p.inv_inertia[a]);
            p.x[a].cross(&(m * p.v[a])).norm() + inertia * p.w[a].norm()
        })
        .sum();
    e.advance(steps)?;
    let (_, _, l1) = totals(&e.snapshot(), case.contact.kn);
    Ok((l1 - l0).norm() / scale)
}

/// The conservation rows: the gas frictionless and elastic over `steps` steps, the gas with
/// friction and dashpots, and the cluster for every tangential convention.
pub fn rows(base: &Case, steps: u64) -> anyhow::Result<Vec<Row>> {
    let mut elastic = base.clone();
    elastic.contact.gamman = 0.0;
    elastic.contact.gammat = 0.0;
    elastic.contact.mu = 0.0;
    let g = gas(&elastic, steps)?;
    let name = format!("conservation gas elastic frictionless {steps} steps");
    // leapfrog's bounded energy error for a contact, second order: (ω dt)²/8 at
    // dt = tc/steps_per_collision (4.9e-4 at tc/50; measured deviation 8.8e-5, drift 6.9e-5)
    let per_tc = base.tc_free_free().unwrap_or(0.0) / base.dt();
    let bound = (std::f64::consts::PI / per_tc).powi(2) / 8.0;
    let mut rows = vec![
        row_abs(&name, "max |E - E0| / E0", 0.0, g.energy_deviation, bound),
        row_abs(
            &name,
            "energy drift over the run / E0",
            0.0,
            g.energy_drift,
            bound,
        ),
        // equal and opposite pair forces: round-off only, a random walk of ε per step,
        // √(1e6)·ε ≈ 2e-13 (measured 6.8e-16)
        row_abs(&name, "|P - P0| / (M v_rms)", 0.0, g.momentum_change, 1e-12),
    ];
    let friction = gas(base, steps / 10)?;
    // round-off only, as above (measured 7.5e-17)
    rows.push(row_abs(
        &format!("conservation gas with friction {} steps", steps / 10),
        "|P - P0| / (M v_rms)",
        0.0,
        friction.momentum_change,
        1e-12,
    ));
    for conv in Tangential::with_constant_kt() {
        let mut case = base.clone();
        case.contact.tangential = conv.into();
        let dl = cluster_angular_momentum(&case, 2000)?;
        // lever arms to a common contact point: round-off only (measured 1.7e-13 over 2000
        // steps); full-radius lever arms lose δ n × Ft per contact, 3.8e-5 here
        let r = row_abs(
            &format!("conservation cluster {} 2000 steps", conv.name()),
            "|L - L0| / sum |L_i|",
            0.0,
            dl,
            1e-12,
        );
        rows.push(r.gating_if(conv.properties().conserves_angular_momentum));
    }
    Ok(rows)
}
