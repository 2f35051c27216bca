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
    Ok((end.v[1] - end.v[0]).x / v0)
}

/// Rows of the binary collisions in `peer` against the closed forms, both partners, speeds
/// 1e-3 … 10, at the case's dt.
pub fn rows(peer: &dyn Peer, case: &Case, dir: &Path) -> anyhow::Result<Vec<Row>> {
    let m = case.particle_mass();
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    let mut rows = Vec::new();
    for (label, wall, meff) in [("free-free", false, 0.5 * m), ("free-wall", true, m)] {
        let cf = closed_form(case, meff);
        for v0 in [1e-3, 1e-1, 1.0, 10.0] {
            let sub = dir.join(format!("{label}-{v0}"));
            let e = restitution(peer, case, v0, wall, &sub)?;
            rows.push(row(
                &format!("{} {label} v0={v0} dt=tc/{per_tc}", peer.binary()),
                "restitution e",
                cf.e,
                e,
                2e-3,
            ));
        }
    }
    Ok(rows)
}
