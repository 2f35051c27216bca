//! Binary collisions run in a peer: the same two spheres, law and time step as verdem's
//! verification case, the restitution coefficient read from the peer's dump after the contact
//! and, where the peer records it, how long the normal force acted. A peer whose normal force
//! is clipped at zero ([`Peer::clips_normal_force`]) is held to the clipped closed forms; a
//! peer without a collision run ([`Peer::collision_script`]) gets one `info` row saying so.

use std::path::Path;

use anyhow::Context;

use super::{lacks, Peer, Run, Save};
use crate::case::Case;
use crate::verify::collision::{closed_form, head_on, impact_setup};
use crate::verify::{lacking_row, row, Row};

/// What a peer's head-on collision gave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// The restitution coefficient.
    pub e: f64,
    /// How long its normal force was positive (time), if the peer records it
    /// ([`Peer::collision_duration`]).
    pub duration: Option<f64>,
    /// How long the spheres overlapped at the end of a step (time, whole steps), if the peer
    /// records it ([`Peer::contact_steps`]).
    pub overlapped: Option<f64>,
}

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

/// A head-on collision at speed `v0` (onto a fixed sphere when `wall`) in `peer` under `case`'s
/// law at its dt, run in `dir` on one process; a [`super::Lacks`] error when the peer has no
/// collision run.
pub fn collide(
    peer: &dyn Peer,
    case: &Case,
    v0: f64,
    wall: bool,
    dir: &Path,
) -> anyhow::Result<Outcome> {
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
    let script = peer.collision_script(&timed, &data, steps)?;
    let run = Run { dir, np: 1 };
    peer.run(&run, &script)?;
    let end = peer.read_frame(
        &run,
        Save {
            index: 1,
            step: steps,
        },
    )?;
    Ok(Outcome {
        e: (end.v[1] - end.v[0]).x / v0,
        duration: peer.collision_duration(&run).transpose()?,
        overlapped: peer.contact_steps(&run)?.map(|n| n as f64 * dt),
    })
}

/// Rows of the binary collisions in `peer` against the closed forms, both partners, speeds
/// 1e-3 … 10, at the case's dt: the restitution, and the contact time where the peer records
/// it (known to one step, as verdem's own rows). A peer without a collision run gets one
/// [`lacking_row`] instead.
pub fn rows(peer: &dyn Peer, case: &Case, dir: &Path) -> anyhow::Result<Vec<Row>> {
    let m = case.particle_mass();
    let per_tc = case.run.steps_per_collision.unwrap_or(50.0);
    let clipped = peer.clips_normal_force();
    let dt = {
        let mut timed = case.clone();
        timed.run.dt = None;
        timed.run.steps_per_collision = Some(per_tc);
        timed.dt()
    };
    let mut rows = Vec::new();
    for (label, wall, meff) in [("free-free", false, 0.5 * m), ("free-wall", true, m)] {
        let cf = closed_form(case, meff);
        let (e, tc, kind) = if clipped {
            (cf.e_clipped, cf.tc_clipped, " (force ends at Fn = 0)")
        } else {
            (cf.e, cf.tc, "")
        };
        for v0 in [1e-3, 1e-1, 1.0, 10.0] {
            let sub = dir.join(format!("{label}-{v0}"));
            let got = match collide(peer, case, v0, wall, &sub) {
                Ok(got) => got,
                Err(e) => match lacks(&e) {
                    Some(why) => {
                        let name = format!("{} binary collisions", peer.binary());
                        return Ok(vec![lacking_row(&name, &format!("{}: {why}", peer.name()))]);
                    }
                    None => return Err(e),
                },
            };
            let name = format!("{} {label} v0={v0} dt=tc/{per_tc}", peer.binary());
            rows.push(row(&name, &format!("restitution e{kind}"), e, got.e, 2e-3));
            if let Some(duration) = got.duration {
                rows.push(row(
                    &name,
                    &format!("contact time{kind}"),
                    tc,
                    duration,
                    1.01 * dt / tc,
                ));
            }
            if let Some(overlapped) = got.overlapped {
                // counted in whole steps: known to one step, as verdem's own row
                rows.push(row(
                    &name,
                    "overlap time",
                    cf.tc,
                    overlapped,
                    1.01 * dt / cf.tc,
                ));
            }
        }
    }
    Ok(rows)
}
