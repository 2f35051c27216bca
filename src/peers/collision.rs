//! Binary collisions run in a peer: the same two spheres, law and time step as verdem's
//! verification case, the restitution coefficient read from the peer's dump after the contact.

use std::path::Path;

use anyhow::Context;

use super::Peer;
use crate::case::Case;
use crate::verify::collision::{closed_form, head_on, impact_setup};
use crate::verify::{row, Row};

/// The restitution coefficient `peer` gives for a head-on collision at speed `v0` (onto a fixed
/// sphere when `wall`) under `case`'s law at its dt, run in `dir`.
pub fn restitution(
    peer: &dyn Peer,
    case: &Case,
    v0: f64,
    wall: bool,
    dir: &Path,
) -> anyhow::Result<f64> {
    Ok(collide(peer, case, v0, wall, dir)?.e)
}

/// What a peer's head-on collision gives.
struct Collision {
    e: f64,
    /// The steps the pair overlapped at the end of a step, where the peer records it.
    contact_steps: Option<u64>,
    dt: f64,
}

/// Runs the head-on collision of [`restitution`] in `peer`.
fn collide(
    peer: &dyn Peer,
    case: &Case,
    v0: f64,
    wall: bool,
    dir: &Path,
) -> anyhow::Result<Collision> {
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    let mut timed = case.clone();
    timed.run.dt = None;
    timed.run.steps_per_collision = Some(per_tc);
    let dt = timed.dt();
    let (timed, e) = impact_setup(&timed, head_on(v0, wall, dt, 0.5), per_tc)?;
    std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    let data = peer.write_state(&e.snapshot(), case.material.density, dir, "pair")?;
    // the contact with a fixed sphere lasts tc_fw = √2·tc_ff at most; then free flight
    let tc_fw = closed_form(&timed, timed.particle_mass()).tc;
    let steps = (tc_fw / dt * 1.5).ceil() as u64 + 5;
    peer.run(1, dir, &peer.collision_script(&timed, &data, steps))?;
    let end = peer.read_frame(dir, steps)?;
    Ok(Collision {
        e: (end.v[1] - end.v[0]).x / v0,
        contact_steps: peer.contact_steps(dir)?,
        dt,
    })
}

/// Rows of the binary collisions in `peer` against the closed forms, both partners, speeds
/// 1e-3 … 10, at the case's dt: the restitution (of the clipped law for a peer that clips the
/// normal force) and, where the peer records it, the contact time.
pub fn rows(peer: &dyn Peer, case: &Case, dir: &Path) -> anyhow::Result<Vec<Row>> {
    let m = case.particle_mass();
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    let mut rows = Vec::new();
    for (label, wall, meff) in [("free-free", false, 0.5 * m), ("free-wall", true, m)] {
        let cf = closed_form(case, meff);
        for v0 in [1e-3, 1e-1, 1.0, 10.0] {
            let sub = dir.join(format!("{label}-{v0}"));
            let got = collide(peer, case, v0, wall, &sub)?;
            let name = format!("{} {label} v0={v0} dt=tc/{per_tc}", peer.binary());
            let (quantity, expected) = if peer.clips_normal() {
                ("restitution e (force ends at Fn = 0)", cf.e_clipped)
            } else {
                ("restitution e", cf.e)
            };
            rows.push(row(&name, quantity, expected, got.e, 2e-3));
            if let Some(n) = got.contact_steps {
                // counted in whole steps: known to one step, as verdem's own row
                let duration = n as f64 * got.dt;
                rows.push(row(
                    &name,
                    "contact time",
                    cf.tc,
                    duration,
                    1.01 * got.dt / cf.tc,
                ));
            }
        }
    }
    Ok(rows)
}
