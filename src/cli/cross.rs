//! `verdem cross`: run a peer and verdem on the same case and state and compare them save by
//! save.

use std::path::PathBuf;

use verdem::contact::named;
use verdem::contact::Tangential;
use verdem::peers::{cross, Peer};
use verdem::run;

use super::args::{count, described, lock_output_folder};
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// The peer, by name (`verdem peers` lists them: lammps, liggghts, yade, kratos).
    #[arg(value_parser = verdem::peers::by_name)]
    peer: &'static dyn Peer,
    /// Case file (default: cases/shear_flow_quick.toml).
    #[arg(default_value = "cases/shear_flow_quick.toml")]
    case: PathBuf,
    /// State to start from.
    #[arg(long, default_value = "data/states/mercury_t143.85.data")]
    from: PathBuf,
    #[arg(long, default_value_t = 20000, value_parser = count::<u64>)]
    steps: u64,
    /// A save every N steps.
    #[arg(long, default_value_t = 2000, value_parser = count::<u64>)]
    every: u64,
    /// MPI ranks (Yade: OpenMP threads) of the peer, and verdem's threads.
    #[arg(long, default_value_t = 2, value_parser = count::<usize>)]
    np: usize,
    #[arg(long, default_value = "out/cross")]
    out: PathBuf,
    /// Run verdem with this tangential convention instead of the peer's (to see what a
    /// convention changes).
    #[arg(
        long,
        value_parser = described(&Tangential::ALL, Tangential::name, Tangential::description)
    )]
    convention: Option<Tangential>,
    /// Average in-run too (LAMMPS, LIGGGHTS and Yade), in the peer (from dumps every K and KP
    /// steps), in verdem with the peer's convention and in verdem with the case's own
    /// convention, over the same steps; writes PEER.profiles_inrun.csv,
    /// verdem.profiles_inrun.csv, verdem_own.profiles_inrun.csv and inrun.md, their core means
    /// compared with 95 % intervals (docs/peers-inrun.md).
    #[arg(long)]
    inrun: bool,
    /// With --inrun: contact stress and wall forces every K steps (default: 8 contact
    /// durations, as `verdem run`); K must divide --every.
    #[arg(long, value_name = "K", requires = "inrun", value_parser = count::<u64>)]
    inrun_every: Option<u64>,
    /// With --inrun: particle fields every KP steps, a multiple of K (default: the multiple
    /// nearest to 20 contact durations).
    #[arg(long, value_name = "KP", requires = "inrun", value_parser = count::<u64>)]
    inrun_particle_every: Option<u64>,
    /// Replace the saves of an earlier cross-run in OUT/PEER (without it, such a folder is
    /// refused and nothing is written).
    #[arg(long)]
    force: bool,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = named::load(&a.case)?;
    let out = a.out.join(a.peer.binary());
    let lock = lock_output_folder(&out)?;
    for series in [a.peer.binary(), "verdem"] {
        run::claim_output_folder(&out.join(series), &case.name, a.force, "--force", &lock)?;
    }
    let convention = a.convention.unwrap_or(a.peer.convention());
    let inrun = a
        .inrun
        .then(|| verdem::analysis::inrun::intervals(&case, a.inrun_every, a.inrun_particle_every));
    let report = cross::cross_inrun(
        a.peer, &case, convention, &a.from, a.steps, a.every, a.np, &out, inrun,
    )?;
    print!("{}", report.markdown());
    println!("(saves and tables in {})", out.display());
    Ok(Finished::Done)
}
