//! The `verdem` command line: parses the arguments and hands them to the command's glue in
//! [`cli`], one file per command.

mod cli;

use clap::{Parser, Subcommand};

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
    if let Err(e) = cli::signals::install() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
    let outcome = match Cli::parse().command {
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
    };
    match outcome {
        Ok(Finished::Done) => {}
        Ok(Finished::Interrupted) => std::process::exit(EXIT_INTERRUPTED),
        Ok(Finished::ChecksFailed) => std::process::exit(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            let guard = e.downcast_ref::<verdem::step::guard::Failure>().is_some();
            std::process::exit(if guard { EXIT_GUARD } else { 1 });
        }
    }
}
