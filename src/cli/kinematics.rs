//! `verdem kinematics`: drive one contact of the case's law through a prescribed motion and
//! write the forces and torques at every row; with `--peer`, the contact law of the real LAMMPS
//! or LIGGGHTS, through its library.

use std::path::PathBuf;

use verdem::case::COARSE_STEPS_PER_COLLISION;
use verdem::contact::named;
use verdem::io::{self, atomic};
use verdem::peers::motion::{self, MotionPeer};
use verdem::verify::kinematics::{self, Increment};

use super::args::described;
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Case file: material, radii (from its two spheres) and contact law.
    case: PathBuf,
    /// Motion file (CSV with a header line).
    motion: PathBuf,
    /// Forces file to write.
    #[arg(long)]
    out: PathBuf,
    /// Velocities of the increment over a step: from positions and quaternions (what
    /// verdem's integrator feeds its law) or the mean of the two rows' velocities.
    #[arg(
        long,
        default_value = Increment::Positions.name(),
        value_parser = described(&Increment::ALL, Increment::name, Increment::description)
    )]
    increment: Increment,
    /// Drive the contact law of a peer's library instead of verdem's (the case gives radii,
    /// density and kn, gamman, kt, gammat, mu; the peer's own convention replaces
    /// `tangential`, and its normal force is not clipped).
    #[arg(
        long,
        value_parser = described(&MotionPeer::ALL, MotionPeer::name, MotionPeer::description)
    )]
    peer: Option<MotionPeer>,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    // no integration: the law's checks, not the scheme's stability limit on run.dt
    let case = named::load_for_prescribed_motion(&a.case)?;
    let (file, text) = io::read_text(&a.motion)?;
    let (lines, rows): (Vec<usize>, Vec<_>) = kinematics::parse_motion_lines(&file, &text)?
        .into_iter()
        .unzip();
    let (_, radius) = kinematics::pair_of(&case)?;
    let tc = kinematics::collision_time(&case);
    if let (Some(tc), Some((k, dt))) = (tc, kinematics::widest_contact_step(radius, &rows)) {
        if kinematics::coarse(dt, tc) {
            eprintln!(
                "warning: {file}:{}: rows up to Δt = {dt:.4e} apart while the spheres touch, \
                 coarse for the collision time of the law of {}, tc = {tc:.4e} (tc/Δt = {:.3}, \
                 below {COARSE_STEPS_PER_COLLISION}): the forces are the law's at these rows, \
                 not an integration's, and the collision's course between them is not seen; \
                 rows at most tc/{COARSE_STEPS_PER_COLLISION} = {:.4e} apart resolve it",
                lines[k],
                a.case.display(),
                tc / dt,
                tc / COARSE_STEPS_PER_COLLISION
            );
        }
    }
    let forces = match a.peer {
        None => {
            let law = kinematics::law_of(&case)?;
            kinematics::drive(law.as_ref(), radius, &rows, a.increment)
        }
        Some(peer) => motion::drive(peer, &case, &rows, a.increment)?,
    };
    let finite = |r: &kinematics::ForceRow| {
        let vectors = r.f.iter().chain(&r.torque).flat_map(|v| v.iter().copied());
        [r.t, r.delta, r.fn_signed, r.ft]
            .into_iter()
            .chain(vectors)
            .all(f64::is_finite)
    };
    if let Some(k) = forces.iter().position(|r| !finite(r)) {
        anyhow::bail!(
            "{file}:{}: the law's forces or overlap at t = {} are not finite (numbers too large \
             for the law, or rows too close in time); {} not written",
            lines[k],
            rows[k].t,
            a.out.display()
        );
    }
    atomic::write(&a.out, kinematics::forces_csv(&forces).as_bytes())?;
    let law = match a.peer {
        None => format!(
            "{} convention{}",
            case.contact.tangential.name(),
            if case.contact.clip_normal {
                ", clipped normal force"
            } else {
                ""
            }
        ),
        Some(peer) => format!(
            "{} through its library, {} convention",
            peer.name(),
            peer.convention().name()
        ),
    };
    println!(
        "{} rows of {} ({law}) -> {}",
        forces.len(),
        case.name,
        a.out.display()
    );
    Ok(Finished::Done)
}
