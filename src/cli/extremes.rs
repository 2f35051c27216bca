//! `verdem extremes`: the stability map, printed as a table and written to OUT/extremes.csv.

use std::path::PathBuf;

use verdem::io::atomic;
use verdem::verify::extremes::{self, Inputs};

use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// The folder of the verification cases (binary_collision.toml, oblique_impact.toml,
    /// conservation.toml).
    #[arg(long, default_value = "cases/verify")]
    cases: PathBuf,
    /// The shear case.
    #[arg(long, default_value = "cases/shear_flow.toml")]
    shear: PathBuf,
    /// The state the shear rows start from.
    #[arg(long, default_value = "data/states/mercury_t143.85.data")]
    from: PathBuf,
    /// Only the rows whose case and parameter contain this text.
    #[arg(long)]
    only: Option<String>,
    /// Output folder: extremes.csv, the friction rows' checkpoint and the dense shear's
    /// initial file.
    #[arg(long, default_value = "out/extremes")]
    out: PathBuf,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let inputs = Inputs {
        verify_dir: a.cases,
        shear: a.shear,
        shear_state: a.from,
        out: a.out.clone(),
    };
    std::fs::create_dir_all(&a.out)
        .map_err(|e| anyhow::anyhow!("{}: cannot create output folder: {e}", a.out.display()))?;
    let rows = extremes::map(&inputs, a.only.as_deref())?;
    if rows.is_empty() {
        anyhow::bail!(
            "--only {:?}: no row's case and parameter contain it",
            a.only.unwrap_or_default()
        );
    }
    let path = a.out.join("extremes.csv");
    atomic::write(&path, extremes::csv(&rows).as_bytes())
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    print!("{}", extremes::table(&rows));
    let failed = rows.iter().filter(|r| !r.pass).count();
    println!(
        "{} passed, {failed} failed; the map: {}",
        rows.len() - failed,
        path.display()
    );
    Ok(if failed > 0 {
        Finished::ChecksFailed
    } else {
        Finished::Done
    })
}
