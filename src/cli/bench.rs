//! `verdem bench`: time verdem against the installed peers on the same case and state, and
//! write the table.

use std::path::PathBuf;

use anyhow::Context;
use verdem::bench::{self, Config};
use verdem::case::Case;
use verdem::io::atomic;
use verdem::scene;

use super::args::count;
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Case file (default: cases/shear_flow_quick.toml).
    case: Option<PathBuf>,
    /// State to start from (default: MercuryDPM's developed state).
    #[arg(long, default_value = "data/states/mercury_t143.85.data")]
    from: PathBuf,
    #[arg(long, default_value_t = 20_000, value_parser = count::<u64>)]
    steps: u64,
    /// verdem thread counts.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = count::<usize>)]
    threads: Vec<usize>,
    /// Peers to run, comma-separated (`verdem peers` lists them; none: --peers ''). The default
    /// leaves out Kratos DEM, about 100 times slower than LAMMPS: name it, with fewer --steps.
    #[arg(long, default_value_t = verdem::peers::bench_names())]
    peers: String,
    /// MPI ranks (Yade: OpenMP threads) for the peers.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = count::<usize>)]
    np: Vec<usize>,
    /// Alternating rounds.
    #[arg(long, default_value_t = 3, value_parser = count::<usize>)]
    rounds: usize,
    /// Skip the ceiling rows: two independent 1-thread verdem runs at once, which measures
    /// what this machine gives two jobs that share nothing, and the same two runs waiting
    /// for each other once a step, which measures what it gives two that meet once a step
    /// as a team's threads do.
    #[arg(long)]
    no_ceiling: bool,
    /// Where the table (bench.md, bench.csv) and the peers' inputs go.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = Case::load(
        &a.case
            .unwrap_or_else(|| PathBuf::from("cases/shear_flow_quick.toml")),
    )?;
    for warning in a
        .threads
        .iter()
        .filter_map(|&t| verdem::team::oversubscribed(t))
    {
        eprintln!("warning: {warning}");
    }
    let mut configs: Vec<Config> = a
        .threads
        .iter()
        .map(|&t| Config::Verdem {
            threads: t,
            copies: 1,
            lockstep: false,
        })
        .collect();
    if !a.no_ceiling {
        configs.extend([false, true].map(|lockstep| Config::Verdem {
            threads: 1,
            copies: 2,
            lockstep,
        }));
    }
    for peer in verdem::peers::parse_list(&a.peers).context("--peers")? {
        configs.extend(a.np.iter().map(|&n| Config::Peer { peer, np: n }));
    }
    let measured = bench::run(&case, &a.from, a.steps, &configs, a.rounds, &a.out)?;
    let particles = scene::build(&case, Some(&a.from))?.particles.len();
    let md = bench::header(&case.name, &a.from, a.steps, a.rounds)
        + &bench::markdown(&measured, particles);
    print!("{md}");
    atomic::write(&a.out.join("bench.md"), md.as_bytes())?;
    atomic::write(
        &a.out.join("bench.csv"),
        bench::csv(&measured, particles).as_bytes(),
    )?;
    Ok(Finished::Done)
}
