//! `verdem hash`: the SHA-256 of the full state after N steps, no files written.

use verdem::io::hash;

use super::args::Common;
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    common: Common,
    #[arg(long)]
    steps: u64,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let (_, mut engine) = a.common.load()?;
    engine.advance(a.steps)?;
    println!("{}", hash::state_hash(&engine.snapshot()));
    Ok(Finished::Done)
}
