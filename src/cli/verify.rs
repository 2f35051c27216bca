//! `verdem verify`: run the verification cases (and the peers' binary collisions) and print
//! expected, measured, tolerance and PASS/FAIL.

use std::path::PathBuf;

use verdem::case::Case;
use verdem::peers::{self, Peer};
use verdem::verify;

use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// The folder of the verification cases.
    #[arg(long, default_value = "cases/verify")]
    cases: PathBuf,
    /// Only the rows whose case name contains this text.
    #[arg(long)]
    only: Option<String>,
    /// Also run the binary collisions in these installed peers (lammps, liggghts, yade,
    /// kratos), against
    /// the same closed forms.
    #[arg(long, value_parser = peers::by_name, value_delimiter = ',')]
    peers: Vec<&'static dyn Peer>,
    /// Where the peers' collision runs go.
    #[arg(long, default_value = "out/verify")]
    out: PathBuf,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let mut rows = verify::all(&a.cases)?;
    let collision = Case::load(&a.cases.join("binary_collision.toml"))?;
    for peer in a.peers {
        let dir = a.out.join(peer.binary());
        rows.extend(peers::collision::rows(peer, &collision, &dir)?);
    }
    if let Some(only) = a.only {
        rows.retain(|r| r.case.contains(&only));
        if rows.is_empty() {
            anyhow::bail!("--only {only:?}: no verification row's case contains it");
        }
    }
    print!("{}", verify::table(&rows));
    let passed = rows.iter().filter(|r| r.passed()).count();
    let failed = verify::failures(&rows);
    println!(
        "{passed} passed, {failed} failed, {} known defects of peer conventions (FAIL*)",
        rows.len() - passed - failed
    );
    Ok(if failed > 0 {
        Finished::ChecksFailed
    } else {
        Finished::Done
    })
}
