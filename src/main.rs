//! The `verdem` command line: parses the arguments and hands them to the command's glue in
//! [`cli`], one file per command.

mod cli;

use std::error::Error;

use clap::{Parser, Subcommand};
use verdem::run::RunError;
use verdem::step::guard::Failure;

use cli::{Finished, EXIT_GUARD, EXIT_INTERRUPTED};

#[derive(Parser)]
#[command(
    name = "verdem",
    version,
    about = "Deterministic DEM solver, verification harness and benchmark suite"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case: MercuryCG saves, diagnostics table, final state hash.
    Run(cli::run::Args),
    /// Coarse-grain a MercuryCG series into z-profiles with error bars, checks and a plot.
    Cg(cli::cg::Args),
    /// Time verdem against the installed LAMMPS, LIGGGHTS and Yade on the same case and state.
    Bench(cli::bench::Args),
    /// Run the verification cases and print expected, measured, tolerance and PASS/FAIL.
    Verify(cli::verify::Args),
    /// Compare profiles tables (`verdem cg` output, e.g. golden/peers/*.profiles.csv) with a
    /// reference over the core: χ²/dof and relative difference of the core means of each
    /// benchmark profile.
    Compare(cli::compare::Args),
    /// Run LAMMPS or LIGGGHTS and verdem (with the peer's tangential convention) on the same
    /// case and state; compare positions, velocities and spins at every save; write both
    /// series as MercuryCG saves and the table as OUT/cross.md.
    Cross(cli::cross::Args),
    /// List the known peers, one a line, tab-separated: name, binary, tangential convention,
    /// the command of a 1-process run, installed version.
    Peers(cli::peers::Args),
    /// The speed/accuracy trade: the case under variants (dt, softer contacts, skin, threads)
    /// from the same state for the same simulated time; cost, restitution error and the
    /// deviation of each profile from the reference in units of its standard error.
    Tradeoff(cli::tradeoff::Args),
    /// Drive one contact of the case's law through a prescribed motion (MOTION.csv: t, then
    /// x,y,z, qw,qx,qy,qz, vx,vy,vz, wx,wy,wz of sphere 1 and of sphere 2) and write the forces
    /// and torques on each sphere at every row (FORCES.csv).
    Kinematics(cli::kinematics::Args),
    /// The stability map: dt, stiffness, speed, damping, friction and packing at their
    /// extremes, each row with theory, measurement, what verdem did and a verdict.
    Extremes(cli::extremes::Args),
    /// Run R independent replicas of a case (seeded velocity perturbations of its start) on
    /// this machine or as a Slurm job array, and merge their profiles with ensemble error bars
    /// and the coverage test of the replicas' own error bars.
    Ensemble(cli::ensemble::Args),
    /// Print the SHA-256 of the full state after N steps (no files written).
    Hash(cli::hash::Args),
    /// Tile a bumpy-shear case and its state nx × ny in x–y (same gap, walls tiled with the
    /// cell): writes OUT/NAME_NXxNY.toml and its state OUT/NAME_NXxNY.data.
    Tile(cli::tile::Args),
    /// Convert a MercuryCG series (verdem's or a peer's) into ParaView files: NAME.NNNN.vtu per
    /// save (particles and contact lines) and the NAME.pvd time series.
    Vtk(cli::vtk::Args),
}

fn main() {
    // first, before any thread starts (cli::signals)
    let outcome = cli::signals::install()
        .and_then(|()| Ok(Cli::try_parse()?))
        .and_then(|cli| dispatch(cli.command));
    if let Err(e) = &outcome {
        match e.downcast_ref::<clap::Error>() {
            // clap's own text: the usage error on stderr, or the help or version on stdout
            Some(usage) => {
                let _ = usage.print();
            }
            None => eprintln!("error: {e:#}"),
        }
    }
    match exit_status(&outcome) {
        0 => {}
        status => std::process::exit(status),
    }
}

/// Runs the command `command`.
fn dispatch(command: Command) -> anyhow::Result<Finished> {
    match command {
        Command::Run(a) => cli::run::exec(a),
        Command::Cg(a) => cli::cg::exec(a),
        Command::Bench(a) => cli::bench::exec(a),
        Command::Verify(a) => cli::verify::exec(a),
        Command::Compare(a) => cli::compare::exec(a),
        Command::Cross(a) => cli::cross::exec(a),
        Command::Peers(a) => cli::peers::exec(a),
        Command::Tradeoff(a) => cli::tradeoff::exec(a),
        Command::Kinematics(a) => cli::kinematics::exec(a),
        Command::Ensemble(a) => cli::ensemble::exec(a),
        Command::Hash(a) => cli::hash::exec(a),
        Command::Tile(a) => cli::tile::exec(a),
        Command::Vtk(a) => cli::vtk::exec(a),
        Command::Extremes(a) => cli::extremes::exec(a),
    }
}

/// The exit status of a command that ended with `outcome` (docs/cli.md, "Exit statuses"), the
/// one place it is decided: 0 when done, [`EXIT_INTERRUPTED`] for a run a signal stopped, 1
/// when checks failed; for an error, by its type however the layers above wrapped it: clap's
/// (a command line that does not parse or an option out of range) its own status, 2 (0 for
/// `--help` and `--version`), [`EXIT_GUARD`] for the run guard's stop ([`guard_stopped`]), 1
/// for any other. A command ended by a signal N does not come here: it ends by the signal
/// itself (`cli::signals`), which a shell reports as 128 + N.
fn exit_status(outcome: &anyhow::Result<Finished>) -> i32 {
    match outcome {
        Ok(Finished::Done) => 0,
        Ok(Finished::Interrupted) => EXIT_INTERRUPTED,
        Ok(Finished::ChecksFailed) => 1,
        Err(e) => match e.downcast_ref::<clap::Error>() {
            Some(usage) => usage.exit_code(),
            None if e.chain().any(guard_stopped) => EXIT_GUARD,
            None => 1,
        },
    }
}

/// Whether the error `e` (one link of a chain of causes) is the run guard's stop: a
/// [`Failure`], or the run loop's [`RunError::Guard`].
fn guard_stopped(e: &(dyn Error + 'static)) -> bool {
    matches!(e.downcast_ref::<RunError>(), Some(RunError::Guard(_))) || e.is::<Failure>()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn failure() -> Failure {
        Failure {
            step: 7,
            time: 0.5,
            ids: vec![3],
            what: "a velocity is not finite".into(),
            remedy: "a smaller time step",
            kept: None,
        }
    }

    #[test]
    fn a_command_that_ends_without_an_error_exits_by_how_it_finished() {
        assert_eq!(exit_status(&Ok(Finished::Done)), 0);
        assert_eq!(exit_status(&Ok(Finished::Interrupted)), EXIT_INTERRUPTED);
        assert_eq!(exit_status(&Ok(Finished::ChecksFailed)), 1);
    }

    /// The run guard's stop exits with [`EXIT_GUARD`] however it is carried: as it is, inside
    /// the run loop's error, under context added by the layers above; every other error exits
    /// with 1, the run loop's other errors included.
    #[test]
    fn the_guard_s_stop_exits_with_its_status_however_it_is_wrapped() {
        use anyhow::Context;
        let status = |e: anyhow::Error| exit_status(&Err(e));
        assert_eq!(status(failure().into()), EXIT_GUARD);
        assert_eq!(status(RunError::Guard(failure()).into()), EXIT_GUARD);
        let wrapped = Err::<(), _>(RunError::Guard(failure())).context("replica 2");
        assert_eq!(status(wrapped.unwrap_err()), EXIT_GUARD);
        let carried = Err::<(), _>(failure())
            .context("the reference run")
            .context("variant dt/2");
        assert_eq!(status(carried.unwrap_err()), EXIT_GUARD);
        assert_eq!(status(anyhow::anyhow!("cannot read a.data")), 1);
        let disk = std::io::Error::new(std::io::ErrorKind::StorageFull, "disk full");
        let stopped = RunError::Stopped {
            dir: "out/x".into(),
            kept: "last save none, last checkpoint none".into(),
            source: Box::new(RunError::Write(disk)),
        };
        assert_eq!(status(stopped.into()), 1);
        // a failure flattened into text is an error like any other: the reason for the types
        assert_eq!(status(anyhow::anyhow!("{}", failure())), 1);
    }

    /// A command line that does not parse exits with clap's usage status, 2; `--help` with 0.
    #[test]
    fn a_usage_error_exits_with_clap_s_status() {
        let status = |args: &[&str]| {
            let e = Cli::try_parse_from(args).err().expect("no command ran");
            exit_status(&Err(e.into()))
        };
        assert_eq!(status(&["verdem", "run", "--threads", "0", "c.toml"]), 2);
        assert_eq!(status(&["verdem", "no-such-command"]), 2);
        assert_eq!(status(&["verdem", "--help"]), 0);
    }

    /// The run loop's error says what the guard's failure says, to the letter; a file it could
    /// not write is said with what is kept, then the file's error.
    #[test]
    fn the_run_loop_s_error_keeps_the_failure_s_message() {
        let f = failure();
        let e: anyhow::Error = RunError::Guard(f.clone()).into();
        assert_eq!(format!("{e:#}"), f.to_string());
        let disk = std::io::Error::new(std::io::ErrorKind::StorageFull, "disk full");
        let save = RunError::Save {
            save: 3,
            step: 30,
            source: disk,
        };
        let e: anyhow::Error = RunError::Stopped {
            dir: "out/x".into(),
            kept: "last save none, last checkpoint none".into(),
            source: Box::new(save),
        }
        .into();
        assert_eq!(
            format!("{e:#}"),
            "the run stopped; the files already in out/x are intact (last save none, last \
             checkpoint none of this run): save 3 (step 30) was not written: disk full"
        );
    }
}
