//! `verdem peers`: list the known peer codes, one a line.

use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Only these peers, comma-separated (an unknown name is an error).
    #[arg(default_value_t = verdem::peers::names())]
    names: String,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let peers = verdem::peers::parse_list(&a.names)?;
    print!("{}", verdem::peers::listing(&peers));
    Ok(Finished::Done)
}
