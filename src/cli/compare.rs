//! `verdem compare`: compare profiles tables with a reference over the core, and optionally
//! overlay their profiles in a plot.

use std::path::PathBuf;

use verdem::analysis::cg::{compare, plot, table::Table};

use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// The reference table.
    reference: PathBuf,
    /// The tables to compare with it (same grid).
    #[arg(required = true)]
    others: Vec<PathBuf>,
    /// Also overlay all the tables' profiles (±2 SE bands) in this PNG.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Labels of the tables in the plot and the table, reference first (default: the
    /// file names).
    #[arg(long, value_delimiter = ',')]
    labels: Vec<String>,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let paths: Vec<&PathBuf> = std::iter::once(&a.reference).chain(&a.others).collect();
    anyhow::ensure!(
        a.labels.is_empty() || a.labels.len() == paths.len(),
        "--labels: {} labels for {} tables",
        a.labels.len(),
        paths.len()
    );
    let mut tables = Vec::new();
    for (k, p) in paths.iter().enumerate() {
        let label = a
            .labels
            .get(k)
            .cloned()
            .unwrap_or_else(|| p.display().to_string());
        tables.push((label, Table::read(p)?));
    }
    let rows = compare::compare(&tables[0].1, &tables[1..])?;
    print!("{}", compare::markdown(&tables[0].0, &rows));
    if let Some(png) = a.plot {
        let runs: Vec<(&str, &Table)> = tables.iter().map(|(l, t)| (l.as_str(), t)).collect();
        plot::overlay_png(&runs, &png)?;
        println!("(overlay in {})", png.display());
    }
    Ok(Finished::Done)
}
