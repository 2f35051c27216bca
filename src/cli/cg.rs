//! `verdem cg`: coarse-grain a MercuryCG series into z-profiles with error bars, checks and a
//! plot.

use std::path::PathBuf;

use verdem::analysis::cg::{self, CgOptions, KernelChoice};
use verdem::contact::named;
use verdem::state::memory;

use super::args::{complete_series, count, named, positive};
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Series base name: DIR/NAME for DIR/NAME.data.NNNN and DIR/NAME.fstat.NNNN.
    base: PathBuf,
    /// First save (default: the second half of the series).
    #[arg(long)]
    from: Option<u64>,
    /// Last save (default: the last).
    #[arg(long)]
    to: Option<u64>,
    #[arg(long, default_value_t = CgOptions::default().slices, value_parser = count::<usize>)]
    slices: usize,
    /// Kernel: heaviside slices; gauss (cut off at 3 widths, renormalised); mercury-gauss
    /// (MercuryCG's Gauss: the same for particles, a contact's branch weighed by the uncut
    /// Gaussian); lucy.
    #[arg(
        long,
        default_value = CgOptions::default().kernel.name(),
        value_parser = named(&KernelChoice::ALL, KernelChoice::name)
    )]
    kernel: KernelChoice,
    /// Kernel width: Gauss (and MercuryCG Gauss) standard deviation or Lucy cutoff (default: the
    /// slice height).
    #[arg(long, allow_negative_numbers = true, value_parser = positive)]
    width: Option<f64>,
    /// Case file telling which particles are walls and the density (default: the
    /// benchmark's, ids 1-480 walls, density 1).
    #[arg(long)]
    case: Option<PathBuf>,
    /// Blocks of saves for the standard errors.
    #[arg(long, default_value_t = CgOptions::default().blocks, value_parser = count::<usize>)]
    blocks: usize,
    /// Skip, with a warning naming each, the saves that have a `.data` or a `.fstat` file only
    /// (without it such a save is an error).
    #[arg(long)]
    skip_incomplete: bool,
    #[command(flatten)]
    reports: super::args::Reports,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let saves = match a.case {
        Some(c) => CgOptions::for_case(&named::load(&c)?),
        None => CgOptions::default(),
    };
    let o = CgOptions {
        from: a.from,
        to: a.to,
        slices: a.slices,
        kernel: a.kernel,
        width: a.width,
        blocks: a.blocks,
        ..saves
    };
    let series = complete_series(&a.base, a.skip_incomplete)?;
    // Each save's raw fields and each block's profiles: some 64 numbers a slice.
    memory::check(
        &format!("--slices {} over {} saves", a.slices, series.saves.len()),
        a.slices as f64 * 64.0 * 8.0 * (series.saves.len() + a.blocks) as f64,
    )?;
    let (_, checks, report) = cg::write_series(&series, &o)?;
    print!("{report}");
    a.reports
        .write("verdem cg", &checks, |c| cg::checks::result(c).into())?;
    Ok(Finished::Done)
}
