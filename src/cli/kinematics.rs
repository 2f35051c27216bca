//! `verdem kinematics`: drive one contact of the case's law through a prescribed motion and
//! write the forces and torques at every row.

use std::path::PathBuf;

use verdem::case::Case;
use verdem::io::{self, atomic};
use verdem::kinematics::{self, Increment};

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
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = Case::load(&a.case)?;
    let (file, text) = io::read_text(&a.motion)?;
    let (lines, rows): (Vec<usize>, Vec<_>) = kinematics::parse_motion_lines(&file, &text)?
        .into_iter()
        .unzip();
    let (_, radius) = kinematics::pair_of(&case)?;
    let law = kinematics::law_of(&case);
    let forces = kinematics::drive(law.as_ref(), radius, &rows, a.increment);
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
    println!(
        "{} rows of {} ({} convention{}) -> {}",
        forces.len(),
        case.name,
        case.contact.tangential.name(),
        if case.contact.clip_normal {
            ", clipped normal force"
        } else {
            ""
        },
        a.out.display()
    );
    Ok(Finished::Done)
}
