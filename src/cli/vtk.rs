//! `verdem vtk`: convert a MercuryCG series into ParaView files.

use std::path::PathBuf;

use anyhow::bail;

use verdem::analysis::cg::CgOptions;
use verdem::contact::named;
use verdem::io::{mercury, vtk};

use super::args::complete_series;
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Series base name: DIR/NAME for DIR/NAME.data.NNNN and DIR/NAME.fstat.NNNN (verdem's
    /// saves or a peer's converted ones). DIR/NAME.NNNN.vtu and DIR/NAME.pvd are written
    /// beside them (replacing earlier ones: they are made from the saves, which are kept).
    base: PathBuf,
    /// Case file telling which particles are walls (default: the benchmark's, ids 1-480).
    #[arg(long)]
    case: Option<PathBuf>,
    /// Skip, with a warning naming each, the saves that have a `.data` or a `.fstat` file only
    /// (without it such a save is an error).
    #[arg(long)]
    skip_incomplete: bool,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let walls = match &a.case {
        Some(c) => CgOptions::for_case(&named::load(c)?).walls,
        None => CgOptions::default().walls,
    };
    let series = complete_series(&a.base, a.skip_incomplete)?;
    let mut out = vtk::Series::new(&series.dir, &series.name);
    for &k in &series.saves {
        let path = |ext| mercury::save_path(&series.dir, &series.name, ext, k);
        let data = mercury::read_data(&path("data"))?;
        let fstat = mercury::read_fstat(&path("fstat"))?;
        let frame = vtk::Frame::of_mercury(&data, &fstat, walls);
        if let Some((i, j)) = frame.dangling_contact() {
            bail!(
                "{}: contact {i}-{j} names a particle the {} particles of {} do not have",
                path("fstat").display(),
                data.rows.len(),
                path("data").display()
            );
        }
        out.write(k, &frame)?;
    }
    println!(
        "{} saves written as {} (open it in ParaView)",
        series.saves.len(),
        vtk::pvd_path(&series.dir, &series.name).display()
    );
    Ok(Finished::Done)
}
