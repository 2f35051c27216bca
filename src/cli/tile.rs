//! `verdem tile`: a bumpy-shear case and its state tiled nx × ny in x–y.

use std::path::PathBuf;

use super::args::count;
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Case file of one cell (a bumpy-shear case).
    case: PathBuf,
    /// State of the cell to tile: a MercuryCG `.data` save or the official file.
    #[arg(long, default_value = "golden/full_run/shear_flow.final.data")]
    from: PathBuf,
    /// Tiles along x.
    #[arg(long, default_value_t = 1, value_parser = count::<usize>)]
    nx: usize,
    /// Tiles along y.
    #[arg(long, default_value_t = 1, value_parser = count::<usize>)]
    ny: usize,
    /// Folder of the tiled case (NAME_NXxNY.toml) and its state (NAME_NXxNY.data).
    #[arg(long, default_value = "out/tile")]
    out: PathBuf,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let (case, state) = verdem::scene::tile::write(&a.case, &a.from, a.nx, a.ny, &a.out)?;
    println!("{}\n{}", case.display(), state.display());
    Ok(Finished::Done)
}
