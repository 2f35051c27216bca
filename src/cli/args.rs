//! Arguments and value parsers shared by several commands.

use std::path::{Path, PathBuf};

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};

use verdem::analysis::cg::{self, Series};
use verdem::analysis::report::{Diagnosis, Report};
use verdem::analysis::Verdict;
use verdem::case::Case;
use verdem::contact::named;
use verdem::io::lock::{self, FolderLock};
use verdem::scene;
use verdem::step::engine::{self, Overrides};
use verdem::step::Engine;

/// The case and how to run it (`run`, `hash`).
#[derive(clap::Args, Clone)]
pub struct Common {
    /// Case file (TOML).
    case: PathBuf,
    /// Initial configuration: official `GranularShearFlow.data` or a MercuryCG `.data` save.
    #[arg(long)]
    init: Option<PathBuf>,
    /// Worker threads of the time step.
    #[arg(long, value_parser = count::<usize>)]
    threads: Option<usize>,
    /// Leave the threads to the scheduler: by default thread t of a team of two or more runs on
    /// the t-th CPU the process may use (start two multi-threaded runs side by side with
    /// `taskset -c` on disjoint CPUs).
    #[arg(long)]
    no_bind: bool,
    /// Pair-list skin (length).
    #[arg(long, allow_negative_numbers = true, value_parser = positive)]
    skin: Option<f64>,
    /// Cell edge of the neighbour grid (length; raised to 2 r_max + skin).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative)]
    cell: Option<f64>,
    /// The run guard's largest overlap, as a fraction of the smaller radius (0 < F ≤ 1;
    /// replaces the case's `[guard] overlap`).
    #[arg(long, allow_negative_numbers = true, value_parser = fraction)]
    guard_overlap: Option<f64>,
    /// The run guard's largest energy gain over a window beyond the walls' and gravity's work,
    /// as a fraction of the energy at play (> 0; replaces the case's `[guard] energy`).
    #[arg(long, allow_negative_numbers = true, value_parser = positive)]
    guard_energy: Option<f64>,
    /// The run guard's largest energy a contact may give beyond what it took and its springs
    /// held, as a fraction of what it took (> 0; replaces the case's `[guard] contact`).
    #[arg(long, allow_negative_numbers = true, value_parser = positive)]
    guard_contact: Option<f64>,
}

/// Where a command that judges writes its verdicts for a CI system (`--junit`, `--json`).
#[derive(clap::Args, Clone)]
pub struct Reports {
    /// Also write the verdicts as a JUnit XML report to this file: one test case per row, its
    /// expected, measured and tolerance in the message; rows that do not gate (FAIL*, info)
    /// are skipped with the reason.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also write the verdicts as a JSON table to this file (docs/cli.md, "Reports for CI").
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

impl Reports {
    /// Writes the suite `suite` of `verdicts` to the files asked for (none: nothing), each
    /// with the word `result` gives it in the command's text table.
    pub fn write(
        &self,
        suite: &str,
        verdicts: &[Verdict],
        result: impl Fn(&Verdict) -> String,
    ) -> anyhow::Result<()> {
        self.write_diagnosed(suite, verdicts, result, Vec::new())
    }

    /// As [`Reports::write`], the JSON report also carrying `diagnosis`, the failed verdicts
    /// by the property they test (absent when empty).
    pub fn write_diagnosed(
        &self,
        suite: &str,
        verdicts: &[Verdict],
        result: impl Fn(&Verdict) -> String,
        diagnosis: Vec<Diagnosis>,
    ) -> anyhow::Result<()> {
        if self.junit.is_some() || self.json.is_some() {
            Report::new(suite, verdicts, result)
                .diagnosed(diagnosis)
                .write(self.junit.as_deref(), self.json.as_deref())?;
        }
        Ok(())
    }
}

impl Common {
    /// The case and its engine, built with the command line's overrides; warns when the team
    /// has more threads than the process may use CPUs.
    pub fn load(&self) -> anyhow::Result<(Case, Box<dyn Engine>)> {
        let mut case = named::load(&self.case)?;
        if let Some(overlap) = self.guard_overlap {
            case.guard.overlap = overlap;
        }
        if let Some(energy) = self.guard_energy {
            case.guard.energy = energy;
        }
        if let Some(contact) = self.guard_contact {
            case.guard.contact = contact;
        }
        let scene = scene::build(&case, self.init.as_deref())?;
        let o = Overrides {
            threads: self.threads,
            bind: self.no_bind.then_some(false),
            skin: self.skin,
            cell: self.cell,
        };
        let engine = engine::build(&case, scene, &o)?;
        if let Some(warning) = verdem::step::team::oversubscribed(engine.params().threads) {
            eprintln!("warning: {warning}");
        }
        Ok((case, engine))
    }
}

/// Makes the output folder `dir` and takes its lock ([`lock::lock_folder`]) before anything
/// is written there; says on stderr when it takes over the lock of a run that did not end.
pub fn lock_output_folder(dir: &Path) -> anyhow::Result<FolderLock> {
    let lock = lock::lock_folder(dir)?;
    if let Some(holder) = lock.stale() {
        eprintln!(
            "warning: {}: a run that did not end (killed, or its machine stopped) had locked \
             this folder ({holder}); its lock is taken over",
            dir.display()
        );
    }
    Ok(lock)
}

/// The saves of the series `base` (`DIR/NAME`) for a command that reads both files of every
/// save: a save with one of them only is an error naming the missing file, or with
/// `skip_incomplete` (`--skip-incomplete`) is skipped with a warning naming it.
pub fn complete_series(base: &Path, skip_incomplete: bool) -> anyhow::Result<Series> {
    let (series, incomplete) = Series::scan(base)?;
    if incomplete.is_empty() {
        return Ok(series);
    }
    if !skip_incomplete {
        anyhow::bail!(
            "{} (--skip-incomplete skips such saves)",
            cg::incomplete_saves(&incomplete)
        );
    }
    for save in &incomplete {
        eprintln!("warning: save {} skipped: {save}", save.save);
    }
    Ok(series)
}

/// A count of one or more (threads, ranks, rounds, slices, blocks, steps between saves).
pub fn count<T: std::str::FromStr<Err = std::num::ParseIntError> + PartialOrd + From<u8>>(
    s: &str,
) -> Result<T, String> {
    let v: T = s.parse().map_err(|e| format!("{e}"))?;
    if v >= T::from(1) {
        Ok(v)
    } else {
        Err(format!("must be 1 or more, got {s}"))
    }
}

/// A length or time that must be positive and finite.
pub fn positive(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be positive and finite, got {s}"))
    }
}

/// A fraction above 0 and at most 1.
pub fn fraction(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v > 0.0 && v <= 1.0 {
        Ok(v)
    } else {
        Err(format!("must be above 0 and at most 1, got {s}"))
    }
}

/// A length that must be zero or positive, and finite.
pub fn non_negative(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be zero or positive and finite, got {s}"))
    }
}

/// A value named by `name`, one of `all`; `--help` and the error for any other name list the
/// names.
pub fn named<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    one_of(all, name, |_| None)
}

/// As [`named`], and `--help` gives each value's `description`.
pub fn described<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
    description: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    one_of(all, name, move |v| Some(description(v)))
}

fn one_of<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
    help: impl Fn(T) -> Option<&'static str>,
) -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(
        all.iter()
            .map(|&v| PossibleValue::new(name(v)).help(help(v))),
    )
    .map(move |s| *all.iter().find(|&&v| name(v) == s).expect("a listed name"))
}
