//! `verdem cross`: run a peer and verdem on the same case and state and compare them save by
//! save.

use std::path::PathBuf;

use verdem::analysis::difference::Difference;
use verdem::analysis::report::{Case as ReportCase, Detail, Report};
use verdem::analysis::{Limit, Outcome, Verdict};
use verdem::contact::named;
use verdem::contact::Tangential;
use verdem::peers::{cross, Peer};
use verdem::run;

use super::args::{count, described, lock_output_folder};
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    #[arg(
        value_parser = verdem::peers::by_name,
        help = format!("The peer, by name (`verdem peers` lists them: {})", verdem::peers::listed())
    )]
    peer: &'static dyn Peer,
    /// Case file (default: cases/shear_flow_quick.toml).
    #[arg(default_value = "cases/shear_flow_quick.toml")]
    case: PathBuf,
    /// State to start from.
    #[arg(long, default_value = "data/states/mercury_t143.85.data")]
    from: PathBuf,
    #[arg(long, default_value_t = 20000, value_parser = count::<u64>)]
    steps: u64,
    /// A save every N steps.
    #[arg(long, default_value_t = 2000, value_parser = count::<u64>)]
    every: u64,
    /// MPI ranks (Yade: OpenMP threads) of the peer, and verdem's threads.
    #[arg(long, default_value_t = 2, value_parser = count::<usize>)]
    np: usize,
    #[arg(long, default_value = "out/cross")]
    out: PathBuf,
    /// Run verdem with this tangential convention instead of the peer's (to see what a
    /// convention changes).
    #[arg(
        long,
        value_parser = described(&Tangential::ALL, Tangential::name, Tangential::description)
    )]
    convention: Option<Tangential>,
    #[arg(long, help = inrun_help())]
    inrun: bool,
    /// With --inrun: contact stress and wall forces every K steps (default: 8 contact
    /// durations, as `verdem run`); K must divide --every.
    #[arg(long, value_name = "K", requires = "inrun", value_parser = count::<u64>)]
    inrun_every: Option<u64>,
    /// With --inrun: particle fields every KP steps, a multiple of K (default: the multiple
    /// nearest to 20 contact durations).
    #[arg(long, value_name = "KP", requires = "inrun", value_parser = count::<u64>)]
    inrun_particle_every: Option<u64>,
    /// Replace the saves of an earlier cross-run in OUT/PEER (without it, such a folder is
    /// refused and nothing is written).
    #[arg(long)]
    force: bool,
    /// Also write the comparison as a JUnit XML report to this file: one test case per save
    /// (its differences reported, not judged), per profile (χ²/dof against verdem's judged
    /// below 3) and, with --inrun, per compared core mean (the peer against verdem in the
    /// peer's convention judged: its 95 % interval holds 0; the others reported); the exit
    /// status stays 0.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also write the comparison as a JSON table to this file, every number of each row
    /// (docs/cli.md, "Reports for CI").
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// Why a save's differences are not judged.
const SAVES_REPORTED: &str = "reported, not judged: the codes agree to round-off at first and \
                              part by chaos later";

/// The cross-run `r` as the report `verdem cross`: its saves (group `PEER saves`), its profiles
/// (group `PEER profiles`, [`super::compare::profile_cases`]) and its in-run core means (group
/// `A vs B`, one case per profile).
fn report(r: &cross::Report) -> Report {
    let suite = "verdem cross";
    let peer = r.peer.binary();
    let mut cases = Vec::new();
    let saves = format!("{peer} saves");
    for d in &r.saves {
        let v = Verdict::reported(
            &saves,
            &format!("step {}: largest |dx|", d.step),
            d.dx.max,
            Limit::None,
        );
        let details = [
            ("dx_max", d.dx.max),
            ("dx_median", d.dx.median),
            ("dx_p99", d.dx.p99),
            ("dv_max", d.dv.max),
            ("dv_p99", d.dv.p99),
            ("dw_max", d.dw.max),
        ]
        .map(|(name, value)| Detail::new(name, value, "not a finite number"));
        cases.push(
            ReportCase::skipped_because(suite, &v, "info", Some(SAVES_REPORTED))
                .undefined_because("not a finite number")
                .with_details(details.to_vec()),
        );
    }
    let profiles = format!("{peer} profiles");
    match r.profiles_chi2 {
        Some(chi2) => cases.extend(super::compare::profile_cases(
            suite, &profiles, "verdem", &chi2, None,
        )),
        None => {
            let why = format!("{peer} gives no per-contact forces, so its stresses are unknown");
            let v = Verdict::reported(&profiles, "profiles", f64::NAN, Limit::None);
            cases.push(
                ReportCase::skipped_because(suite, &v, "info", Some(&why)).undefined_because(&why),
            );
        }
    }
    if let Some(inrun) = &r.inrun {
        // the last comparison is of the peer and verdem in its convention: the same equations
        let comparisons = inrun.comparisons(peer);
        let same_equations = comparisons.len() - 1;
        for (k, (a, b, diffs)) in comparisons.iter().enumerate() {
            for d in diffs {
                cases.push(core_mean_case(suite, a, b, d, k == same_equations));
            }
        }
    }
    Report::of_cases(suite, cases)
}

/// The in-run core means of one profile of `a` and `b` (`d`) as a report's case: A − B judged
/// against its 95 % interval (it holds 0: passed) when `judged` and both errors are trusted,
/// else reported with the reason.
fn core_mean_case(suite: &str, a: &str, b: &str, d: &Difference, judged: bool) -> ReportCase {
    let limit = Limit::Absolute {
        expected: 0.0,
        tolerance: d.half_width(),
    };
    let v = Verdict::judge(
        &format!("{a} vs {b}"),
        &format!("{}: core mean A − B", d.field),
        d.delta(),
        limit,
    );
    let why = if !d.errors_trusted() {
        Some(
            "errors not trusted: a run shorter than five correlation times of a core mean, whose \
             interval says little",
        )
    } else if !judged {
        Some("what the tangential conventions change: reported, not judged")
    } else {
        None
    };
    let v = match why {
        Some(_) => Verdict {
            outcome: Outcome::Reported,
            gate: false,
            ..v
        },
        None => v,
    };
    // the in-run table's "real?" word
    let word = match (d.real(), d.errors_trusted()) {
        (true, true) => "yes",
        (false, true) => "no",
        (true, false) => "yes (errors not trusted)",
        (false, false) => "no (errors not trusted)",
    };
    let undefined = "not a finite number";
    ReportCase::skipped_because(suite, &v, word, why)
        .undefined_because(undefined)
        .with_details(vec![
            Detail::new("a_core_mean", d.a.mean, undefined),
            Detail::new("a_se", d.a.se, undefined),
            Detail::new("b_core_mean", d.b.mean, undefined),
            Detail::new("b_se", d.b.se, undefined),
            Detail::new("half_width_95", d.half_width(), undefined),
            Detail::new("chi2_per_dof", d.chi2, "no error bars"),
        ])
}

/// The help of `--inrun`, naming the peers that declare in-run dumps
/// ([`Peer::has_inrun_dumps`]).
fn inrun_help() -> String {
    let with: Vec<&str> = verdem::peers::all()
        .iter()
        .filter(|p| p.has_inrun_dumps())
        .map(|p| p.name())
        .collect();
    let listed = match with.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, head)) => format!("{} and {last}", head.join(", ")),
        None => "no peer has its dumps yet".into(),
    };
    format!(
        "Average in-run too ({listed}), in the peer (from dumps every K and KP steps), in verdem \
         with the peer's convention and in verdem with the case's own convention, over the same \
         steps; writes PEER.profiles_inrun.csv, verdem.profiles_inrun.csv, \
         verdem_own.profiles_inrun.csv and inrun.md, their core means compared with 95 % \
         intervals (docs/peers-inrun.md)"
    )
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = named::load(&a.case)?;
    let out = a.out.join(a.peer.binary());
    let lock = lock_output_folder(&out)?;
    for series in [a.peer.binary(), "verdem"] {
        run::claim_output_folder(&out.join(series), &case.name, a.force, "--force", &lock)?;
    }
    let convention = a.convention.unwrap_or(a.peer.convention());
    let inrun = a
        .inrun
        .then(|| verdem::analysis::inrun::intervals(&case, a.inrun_every, a.inrun_particle_every));
    let report = cross::cross_inrun(
        a.peer, &case, convention, &a.from, a.steps, a.every, a.np, &out, inrun,
    )?;
    print!("{}", report.markdown());
    println!("(saves and tables in {})", out.display());
    if a.junit.is_some() || a.json.is_some() {
        self::report(&report).write(a.junit.as_deref(), a.json.as_deref())?;
    }
    Ok(Finished::Done)
}
