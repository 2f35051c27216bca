//! `verdem tradeoff`: the speed/accuracy trade of the case's variants, as a table.

use std::path::PathBuf;

use verdem::analysis::tradeoff;
use verdem::case::Case;
use verdem::io::atomic;
use verdem::run;

use super::args::{count, positive};
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Case file.
    #[arg(default_value = "cases/shear_flow_quick.toml")]
    case: PathBuf,
    /// State to start from.
    #[arg(long, default_value = "data/states/mercury_t143.85.data")]
    from: PathBuf,
    /// Simulated time of every variant (time units).
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true, value_parser = positive)]
    time: f64,
    /// Saves of every variant (all are coarse-grained).
    #[arg(long, default_value_t = 40, value_parser = count::<u64>)]
    saves: u64,
    #[arg(long, default_value = "out/tradeoff")]
    out: PathBuf,
    /// The two-sphere case whose restitution each variant's law is measured on.
    #[arg(long, default_value = "cases/verify/binary_collision.toml")]
    pair: PathBuf,
    /// Replace the saves of an earlier tradeoff in OUT's variant folders (without it, such a
    /// folder is refused and nothing is written).
    #[arg(long)]
    force: bool,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = Case::load(&a.case)?;
    let pair = Case::load(&a.pair)?;
    for variant in std::fs::read_dir(&a.out).into_iter().flatten().flatten() {
        run::claim_output_folder(&variant.path(), &case.name, a.force, "--force")?;
    }
    let outcomes = tradeoff::run(&case, &pair, &a.from, a.time, a.saves, &a.out)?;
    let table = tradeoff::markdown(&outcomes);
    atomic::write(&a.out.join("tradeoff.md"), table.as_bytes())?;
    print!("{table}");
    Ok(Finished::Done)
}
