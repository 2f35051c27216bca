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
    /// In the plot, also overlay each table's in-run profiles: the `NAME.profiles_inrun.csv`
    /// that `verdem run` writes beside `NAME.profiles.csv`, labelled `LABEL (in-run)`.
    #[arg(long, requires = "plot")]
    inrun: bool,
}

/// The in-run table `verdem run` writes beside the profiles table `path`
/// (`NAME.profiles.csv` → `NAME.profiles_inrun.csv`), or an error naming what is missing.
fn inrun_beside(path: &std::path::Path) -> anyhow::Result<PathBuf> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    let Some(base) = name.strip_suffix(".profiles.csv") else {
        anyhow::bail!(
            "--inrun: {} is not a run's NAME.profiles.csv, beside which its in-run table would be",
            path.display()
        );
    };
    let inrun = path.with_file_name(format!("{base}.profiles_inrun.csv"));
    anyhow::ensure!(
        inrun.exists(),
        "--inrun: {} has no in-run table beside it ({} is missing)",
        path.display(),
        inrun.display()
    );
    Ok(inrun)
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
        let mut inrun = Vec::new();
        if a.inrun {
            for (p, (label, _)) in paths.iter().zip(&tables) {
                inrun.push((format!("{label} (in-run)"), Table::read(&inrun_beside(p)?)?));
            }
        }
        let runs: Vec<(&str, &Table)> = tables
            .iter()
            .chain(&inrun)
            .map(|(l, t)| (l.as_str(), t))
            .collect();
        plot::overlay_png(&runs, &png)?;
        println!("(overlay in {})", png.display());
    }
    Ok(Finished::Done)
}
