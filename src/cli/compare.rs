//! `verdem compare`: compare profiles tables with a reference over the core, and optionally
//! overlay their profiles in a plot.

use std::path::PathBuf;

use verdem::analysis::cg::compare::Comparison;
use verdem::analysis::cg::{compare, plot, table::Table, FIELDS};
use verdem::analysis::report::{Case, Detail, Report};
use verdem::analysis::{Limit, Outcome, Verdict};

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
    /// Also write the comparison as a JUnit XML report to this file: one test case per table
    /// and profile, its χ²/dof against the reference judged below 3 with the difference of
    /// the core means in the JSON; a profile without error bars in either table is skipped
    /// with the reason (the exit status stays 0).
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also write the comparison as a JSON table to this file: each case's χ²/dof, difference
    /// of the core means and, for vx, χ²/dof less the common offset and that offset
    /// (docs/cli.md, "Reports for CI").
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// The χ²/dof of a profile against the reference's below which a report passes it: the limit of
/// `verdem cg`'s χ² checks (1 is noise; 3 leaves room for slices not quite independent).
pub const CHI2_LIMIT: f64 = 3.0;

/// Why a χ² with no error bar in either table is undefined (as the markdown says it).
const NO_ERROR_BARS: &str =
    "no error bars in either table: without them no difference can be told from noise";

/// The cases of the report `suite` for each profile of [`FIELDS`] of the table `table` against
/// the reference `reference`, from its χ²/dof `chi2` and, where known, the differences of the
/// core means relative to the reference's `rel_mean`: judged below [`CHI2_LIMIT`], grouped by
/// `table`, each case's word `PASS`, `FAIL` or `undefined` (no error bars: skipped).
pub fn profile_cases(
    suite: &str,
    table: &str,
    reference: &str,
    chi2: &[f64; 5],
    rel_mean: Option<&[f64; 5]>,
) -> Vec<Case> {
    FIELDS
        .iter()
        .enumerate()
        .map(|(f, (field, _))| {
            let quantity = format!("{field}: χ²/dof against {reference}");
            let judged = Verdict::judge(table, &quantity, chi2[f], Limit::Below(CHI2_LIMIT));
            let (v, why) = if chi2[f].is_nan() {
                let unjudged = Verdict {
                    outcome: Outcome::Reported,
                    gate: false,
                    ..judged
                };
                (unjudged, Some(NO_ERROR_BARS))
            } else {
                (judged, None)
            };
            let word = match v.outcome {
                Outcome::Pass => "PASS",
                Outcome::Fail => "FAIL",
                Outcome::Undecided | Outcome::Reported => "undefined",
            };
            let mut details = vec![Detail::new("chi2_per_dof", chi2[f], NO_ERROR_BARS)];
            if let Some(rel) = rel_mean {
                details.push(Detail::new("relative_core_mean_difference", rel[f], ""));
            }
            Case::skipped_because(suite, &v, word, why)
                .undefined_because(NO_ERROR_BARS)
                .with_details(details)
        })
        .collect()
}

/// The comparisons `rows` against the table labelled `reference` as the report `verdem
/// compare`: [`profile_cases`] of each table, vx's details with its χ²/dof less the common
/// offset and that offset.
fn report(reference: &str, rows: &[Comparison]) -> Report {
    let suite = "verdem compare";
    let vx = FIELDS.iter().position(|(n, _)| *n == "vx");
    let mut cases = Vec::new();
    for r in rows {
        let mut own = profile_cases(suite, &r.name, reference, &r.chi2, Some(&r.rel_mean));
        if let Some(c) = vx.map(|f| &mut own[f]) {
            c.details.extend([
                Detail::new(
                    "chi2_per_dof_less_offset",
                    r.vx_shape.chi2,
                    "fewer than two slices with an error bar",
                ),
                Detail::new("offset", r.vx_shape.offset, "no slice with an error bar"),
            ]);
        }
        cases.extend(own);
    }
    Report::of_cases(suite, cases)
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
    if a.junit.is_some() || a.json.is_some() {
        report(&tables[0].0, &rows).write(a.junit.as_deref(), a.json.as_deref())?;
    }
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
