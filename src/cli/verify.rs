//! `verdem verify`: run the verification cases (and the peers' binary collisions) and print
//! expected, measured, tolerance and PASS/FAIL, and after them, when rows failed, the
//! property each failed row tests; with `--code`, run the prescribed-motion cases through an
//! external program instead.

use std::path::PathBuf;
use std::time::Duration;

use verdem::contact::named;
use verdem::contact::Tangential;
use verdem::peers::motion::MotionPeer;
use verdem::peers::{self, Peer};
use verdem::verify::driver::External;
use verdem::verify::{self, diagnosis, Subject};

use super::args::described;
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// The folder of the verification cases.
    #[arg(long, default_value = "cases/verify")]
    cases: PathBuf,
    /// Only the cases whose name contains this text (or that it begins with): the others
    /// are not run.
    #[arg(long)]
    only: Option<String>,
    #[arg(
        long,
        value_parser = peers::by_name,
        value_delimiter = ',',
        help = format!(
            "Also run the binary collisions in these installed peers ({}), against the same \
             closed forms",
            peers::listed()
        )
    )]
    peers: Vec<&'static dyn Peer>,
    /// Run the prescribed-motion cases (objectivity, ratchet, tangential histories) through
    /// this program instead of verdem's laws: it is run as `CMD CASE.toml MOTION.csv --out
    /// FORCES.csv`, like `verdem kinematics` (docs/code-interface.md).
    #[arg(long, value_name = "CMD")]
    code: Option<String>,
    /// The program's name in the table (default: the file name of its script or program).
    #[arg(long, requires = "code")]
    code_name: Option<String>,
    /// How long one run of the program may take, in seconds, before it is stopped and its
    /// case reported as an ERROR row.
    #[arg(long, requires = "code", default_value_t = 600.0, value_parser = super::args::positive)]
    code_timeout: f64,
    /// The verdem convention the program implements: the case it gets names it, and its
    /// rows gate where verdem's law of that convention passes them (without it, every row
    /// gates: the promises of an objective law).
    #[arg(
        long,
        requires = "code",
        value_parser = described(&Tangential::ALL, Tangential::name, Tangential::description)
    )]
    convention: Option<Tangential>,
    /// Where the peers' collision runs and the program's files go.
    #[arg(long, default_value = "out/verify")]
    out: PathBuf,
    #[command(flatten)]
    reports: super::args::Reports,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let only = a.only.as_deref();
    let mut rows = match &a.code {
        Some(cmd) => {
            let name = a
                .code_name
                .clone()
                .unwrap_or_else(|| External::default_name(cmd));
            let program = External::new(cmd, &name, &a.out.join("code"))
                .with_timeout(Duration::from_secs_f64(a.code_timeout));
            for warning in verify::coarse_motion_warnings(&a.cases) {
                eprintln!("warning: {warning}");
            }
            let subject = Subject::code(&program, a.convention);
            let entries = verify::select(verify::code_entries(&a.cases, &subject), only)?;
            let rows = verify::run(&entries)?;
            println!(
                "{}: the prescribed-motion cases through `{cmd}`, {}; not run (they need a full \
                 solver): binary collisions, oblique impacts, conservation",
                subject.label,
                match a.convention {
                    Some(c) => format!(
                        "gated as verdem's `{}` (rows that convention fails read FAIL*)",
                        c.name()
                    ),
                    None => "every row gating".into(),
                }
            );
            rows
        }
        None => verify::run(&verify::select(verify::entries(&a.cases), only)?)?,
    };
    let collision = named::load(&a.cases.join("binary_collision.toml"))?;
    let mut chosen = Vec::new();
    for &peer in &a.peers {
        let dir = a.out.join(peer.binary());
        rows.extend(peers::collision::rows(peer, &collision, &dir)?);
        match peer.motion() {
            Ok(libraries) => chosen.extend_from_slice(libraries),
            Err(why) => rows.push(verify::lacking_row(
                &format!("{} prescribed motion", peer.binary()),
                &format!("{}: {why}", peer.name()),
            )),
        }
    }
    // The prescribed-motion cases in the peers' libraries, held to verdem's re-implementation of
    // each convention where it has a known defect. After every binary has run: an MPI library
    // started in this process leaves an environment that MPI programs started from it inherit
    // and fail on.
    let libraries = MotionPeer::ALL.into_iter().filter(|m| chosen.contains(m));
    for library in libraries {
        let subject = Subject::code(&library, Some(library.convention()));
        let entries: Vec<_> = verify::code_entries(&a.cases, &subject)
            .into_iter()
            .filter(|e| only.is_none_or(|o| e.selected(o)))
            .collect();
        rows.extend(verify::run(&entries)?);
    }
    if let Some(only) = only {
        rows.retain(|r| r.case.contains(only));
        if rows.is_empty() {
            anyhow::bail!("--only {only:?}: no verification row's case contains it");
        }
    }
    print!("{}", verify::table(&rows));
    let passed = rows.iter().filter(|r| r.passed()).count();
    let failed = verify::failures(&rows);
    let errors = rows.iter().filter(|r| verify::is_error(r)).count();
    let lacking = rows.iter().filter(|r| verify::is_lacking(r)).count();
    println!(
        "{passed} passed, {failed} failed{}, {} known defects of peer conventions (FAIL*){}",
        if errors > 0 {
            format!(" ({errors} could not be measured: ERROR)")
        } else {
            String::new()
        },
        rows.len() - passed - failed - lacking,
        if lacking > 0 {
            format!(", {lacking} not run: what a peer lacks (info)")
        } else {
            String::new()
        }
    );
    // the failed rows by the property they test; nothing when every row passed
    let diagnosis = diagnosis::diagnose(&rows);
    print!("{}", diagnosis.summary());
    a.reports.write_diagnosed(
        "verdem verify",
        &rows,
        |r| verify::result(r).into(),
        diagnosis.report(),
    )?;
    Ok(if failed > 0 {
        Finished::ChecksFailed
    } else {
        Finished::Done
    })
}
