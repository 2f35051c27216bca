//! The run loop: advance the simulation between saves and checkpoints, write MercuryCG files and
//! the diagnostics table, report progress, and summarise the run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use crate::io::checkpoint::{CheckpointError, Ledgers, Resumed, RunRecord};
use crate::io::diagnostics::{Diagnostics, CSV_HEADER};
use crate::io::{atomic, csv_table, mercury, vtk, FormatError};
use crate::state::SampledContact;
use crate::step::guard::Failure;
use crate::step::{Engine, Reading, StageTimes};

/// Options of one run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The run ends at this step (also after a resume).
    pub end_step: u64,
    pub save_every: u64,
    /// Write a checkpoint every this many steps (0 = never).
    pub checkpoint_every: u64,
    pub out_dir: PathBuf,
    pub name: String,
    /// Identifies the case in checkpoints.
    pub tag: String,
    /// Show a progress bar.
    pub progress: bool,
    /// Write `.data`/`.fstat` saves and diagnostics (false for timing runs).
    pub write_saves: bool,
    /// Also write each save as a ParaView file ([`crate::io::vtk`]).
    pub vtk: bool,
    /// A request to stop (set by a signal handler): the run stops at the end of the block of
    /// steps under way (at most 2000), writes a checkpoint there and returns.
    pub stop: Option<Arc<AtomicBool>>,
}

/// What a finished run reports.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub step: u64,
    pub time: f64,
    pub hash: String,
    /// Steps advanced in this invocation and the wall time they took (seconds), saves included.
    pub steps_run: u64,
    pub seconds: f64,
    pub stages: StageTimes,
    pub saves: u64,
    /// The run stopped before `end_step` on request, with a checkpoint at `step`.
    pub interrupted: bool,
    /// Largest overlap of any contact, as a fraction of the pair's smaller radius.
    pub deepest_overlap: f64,
    /// Largest excess of a contact's energy account, as a fraction of the energy it took.
    pub largest_excess: f64,
}

/// Steps of the full bumpy-shear benchmark (`cases/shear_flow.toml`, `docs/benchmark.md`: Nt).
pub const BENCHMARK_STEPS: u64 = 200_000_000;

impl RunSummary {
    /// Steps per second of this invocation.
    pub fn rate(&self) -> f64 {
        self.steps_run as f64 / self.seconds.max(1e-12)
    }

    /// Wall time (hours) `steps` steps would take at this invocation's [`rate`](Self::rate).
    pub fn hours_for(&self, steps: u64) -> f64 {
        steps as f64 / self.rate() / 3600.0
    }

    /// The summary file's text (TOML): the case's name, the final step, time and state hash,
    /// the run's `threads` and its rate (steps per second).
    pub fn toml(&self, case: &str, threads: usize) -> String {
        format!(
            "case = {}\nstep = {}\ntime = {}\nhash = {:?}\nthreads = {threads}\nsteps_per_second = {}\n",
            crate::io::toml_string(case),
            self.step,
            self.time,
            self.hash,
            self.rate()
        )
    }
}

/// Path of the diagnostics table.
pub fn diagnostics_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.diagnostics.csv"))
}

/// Path of the run summary ([`RunSummary::toml`]).
pub fn summary_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.summary.toml"))
}

/// Writes the summary of the run `name` on `threads` threads into `dir` (atomically).
pub fn write_summary(
    dir: &Path,
    name: &str,
    summary: &RunSummary,
    threads: usize,
) -> Result<(), RunError> {
    let p = summary_path(dir, name);
    atomic::write(&p, summary.toml(name, threads).as_bytes()).map_err(RunError::Write)
}

/// Path of the run's checkpoint.
pub fn checkpoint_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.checkpoint"))
}

/// The save numbers of the series `dir/name` that have both a `.data` and a `.fstat` file,
/// increasing (none when the folder does not exist).
pub fn saves_of(dir: &Path, name: &str) -> Result<Vec<u64>, RunError> {
    let mut saves: Vec<u64> = run_files(dir, name)?
        .iter()
        .filter_map(|p| {
            let file = p.file_name()?.to_str()?;
            let k: u64 = file.strip_prefix(&format!("{name}.data."))?.parse().ok()?;
            mercury::save_path(dir, name, "fstat", k)
                .exists()
                .then_some(k)
        })
        .collect();
    saves.sort_unstable();
    Ok(saves)
}

/// The files of the run `name` in `dir`, sorted: its saves (`NAME.data.NNNN`, `NAME.fstat.NNNN`,
/// `NAME.NNNN.vtu`, `NAME.pvd`), checkpoint, diagnostics, summary, profiles, checks and
/// pictures. Files of runs with other names are not among them.
pub fn run_files(dir: &Path, name: &str) -> Result<Vec<PathBuf>, RunError> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(Vec::new());
    };
    let numbered = |s: &str| s.len() >= 4 && s.bytes().all(|b| b.is_ascii_digit());
    let prefix = format!("{name}.");
    let mut found = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|source| RunError::Io {
            path: dir.to_path_buf(),
            what: "cannot list",
            source,
        })?;
        let file = entry.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else {
            continue;
        };
        let ours = match rest.split_once('.') {
            Some(("data" | "fstat", k)) => numbered(k),
            Some((k, "vtu")) => numbered(k),
            _ => OWN_FILES.contains(&rest),
        };
        if ours {
            found.push(entry.path());
        }
    }
    found.sort();
    Ok(found)
}

/// The files of a run besides its numbered saves, after `NAME.`.
const OWN_FILES: [&str; 11] = [
    "pvd",
    "checkpoint",
    "diagnostics.csv",
    "summary.toml",
    "profiles.csv",
    "profiles_inrun.csv",
    "profiles_inrun_errors.csv",
    "profiles.png",
    "checks.txt",
    "particles.png",
    "profiles.part.png",
];

/// Makes `dir` ready for a new run named `name`: a folder that holds the files of an earlier
/// run of that name ([`run_files`]) is refused, naming the folder and the files, unless `force`
/// is set; then those files are removed first (so no save of the earlier run is mistaken for
/// one of the new run). `flag` is the option that sets `force` (for the message). `_held` is
/// the lock of `dir`, or of a folder that holds it, taken first ([`crate::io::lock`]), so that
/// no other run writes there meanwhile. Returns the number of files removed.
pub fn claim_output_folder(
    dir: &Path,
    name: &str,
    force: bool,
    flag: &str,
    _held: &crate::io::lock::FolderLock,
) -> Result<usize, RunError> {
    let found = run_files(dir, name)?;
    if found.is_empty() {
        return Ok(0);
    }
    if !force {
        return Err(RunError::Occupied {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            found,
            flag: flag.to_string(),
        });
    }
    for p in &found {
        std::fs::remove_file(p).map_err(|source| RunError::Remove {
            path: p.clone(),
            flag: flag.to_string(),
            source,
        })?;
    }
    Ok(found.len())
}

/// Something that looks at the engine between steps without changing it (in-run averaging,
/// `crate::analysis::inrun`): the run loop stops at each step it asks for and calls it there,
/// with that step's forces evaluated. Where the loop stops does not change the steps.
pub trait Observer {
    /// The first step after `step` the observer wants to look at, if any.
    fn next_after(&self, step: u64) -> Option<u64>;
    /// Looks at the engine's step when the run starts (nothing by default).
    fn start(&mut self, _engine: &dyn Engine) {}
    /// Looks at the engine's current step.
    fn observe(&mut self, engine: &dyn Engine);
    /// The interval of the contact samples it wants the engine to take inside its runs, without
    /// a stop ([`Engine::sample_contacts_every`]; 0, the default: none).
    fn contact_every(&self) -> u64 {
        0
    }
    /// Takes the contact samples (by step, in step order) the engine took since the run loop's
    /// last stop; handed over at every stop, before anything else happens there.
    fn contacts(&mut self, _samples: &[(u64, Vec<SampledContact>)]) {}
    /// Everything it has gathered, as bytes its owner can restore it from: written into the
    /// run's checkpoints, so that a resumed run's observer continues where it was.
    fn state(&self) -> Vec<u8>;
}

/// Why a run stopped short of its end step, or its output folder was refused. Every message
/// names the file or folder.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The run guard stopped it: a number it could no longer trust (`verdem run` exits with
    /// status 3). Its message names what is kept on disk.
    #[error(transparent)]
    Guard(#[from] Failure),
    /// A file of the run could not be written (a full disk, a read-only folder): the run
    /// stopped there, and the files it had written in `dir` are intact (`kept`: its last save
    /// and checkpoint). The source says which file and why.
    #[error("the run stopped; the files already in {} are intact ({kept} of this run)", dir.display())]
    Stopped {
        dir: PathBuf,
        kept: String,
        #[source]
        source: Box<RunError>,
    },
    /// Save `save` (at step `step`) could not be written whole, and its files were removed.
    #[error("save {save} (step {step}) was not written")]
    Save {
        save: u64,
        step: u64,
        #[source]
        source: std::io::Error,
    },
    /// A checkpoint that could not be written.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// A file or folder that cannot be created, read or listed (`what`: "cannot list").
    #[error("{}: {what}", path.display())]
    Io {
        path: PathBuf,
        what: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// A file not written ([`atomic::write`]'s error, which names it).
    #[error(transparent)]
    Write(std::io::Error),
    /// A malformed file of the run read back (its diagnostics table, a save's header).
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The diagnostics table's rows could not be kept for a resumed run.
    #[error("{}: its rows cannot be kept", path.display())]
    Table {
        path: PathBuf,
        #[source]
        source: csv::Error,
    },
    /// The output folder holds the files of an earlier run named `name` (all of them in
    /// `found`), and `flag` (the option that replaces them) was not given.
    #[error(
        "{}: already holds the files of a run named {name:?} ({}); nothing was written. Choose \
         another output folder, continue that run with --resume CHECKPOINT, or replace its \
         files with {flag}",
        dir.display(),
        listed_files(found)
    )]
    Occupied {
        dir: PathBuf,
        name: String,
        found: Vec<PathBuf>,
        flag: String,
    },
    /// A file of an earlier run that `flag` asked to replace but cannot be removed.
    #[error(
        "{}: cannot remove (replacing the files of an earlier run, {flag})",
        path.display()
    )]
    Remove {
        path: PathBuf,
        flag: String,
        #[source]
        source: std::io::Error,
    },
    /// A resumed run's diagnostics table (`file`, its `line`) holds save `save` at step `step`,
    /// which this run, saving every `save_every` steps, would number otherwise; `written_every`
    /// is the interval that wrote it, when one whole interval did.
    #[error(
        "{file}:{line}: save {save} is at step {step}, but this run saves every {save_every} \
         steps; resume with {}",
        written_every.map_or("the --save-every of the run that wrote it".into(), |e| format!(
            "--save-every {e}"
        ))
    )]
    SaveInterval {
        file: String,
        line: usize,
        save: u64,
        step: u64,
        save_every: u64,
        written_every: Option<u64>,
    },
    /// A checkpoint's ledgers read at the save of step `read_at`, while saves every
    /// `save_every` steps put the last save before the resumed step `step` at `last_save`.
    #[error(
        "the checkpoint's ledgers were read at the save of step {read_at}, but with a save \
         every {save_every} steps the last save before step {step} is at step {last_save}: \
         resume with the --save-every of the run that wrote it"
    )]
    LedgersAt {
        read_at: u64,
        save_every: u64,
        step: u64,
        last_save: u64,
    },
}

/// The first four of `found` by name and how many there are, for [`RunError::Occupied`].
fn listed_files(found: &[PathBuf]) -> String {
    let shown: Vec<String> = found
        .iter()
        .take(4)
        .filter_map(|p| p.file_name().map(|f| f.to_string_lossy().into_owned()))
        .collect();
    let more = match found.len() - shown.len() {
        0 => String::new(),
        m => format!(" and {m} more"),
    };
    format!("{}{more}; {} files", shown.join(", "), found.len())
}

/// Where a run starts.
#[derive(Clone, Copy)]
enum Start<'a> {
    Fresh,
    /// From a checkpoint at the current step, with its ledgers when it holds them.
    Resumed(Option<&'a Ledgers>),
}

/// Runs `engine` to `opts.end_step`. `resumed` says the current step's save already exists
/// (a resume without the checkpoint's ledgers: [`run_resumed`] has them).
pub fn run(
    engine: &mut dyn Engine,
    opts: &RunOptions,
    resumed: bool,
) -> Result<RunSummary, RunError> {
    run_observed(engine, opts, resumed, None)
}

/// [`run`], stopping also at the steps `observer` asks for and showing it the engine there.
pub fn run_observed(
    engine: &mut dyn Engine,
    opts: &RunOptions,
    resumed: bool,
    observer: Option<&mut dyn Observer>,
) -> Result<RunSummary, RunError> {
    let start = if resumed {
        Start::Resumed(None)
    } else {
        Start::Fresh
    };
    run_from(engine, opts, start, observer)
}

/// Continues the run `resumed` from (restored into `engine`) to `opts.end_step`, its ledgers
/// from those of the checkpoint when it holds them, so that its diagnostics rows are those of a
/// run never stopped; `observer` as in [`run_observed`] (restored by its owner).
pub fn run_resumed(
    engine: &mut dyn Engine,
    opts: &RunOptions,
    resumed: &Resumed,
    observer: Option<&mut dyn Observer>,
) -> Result<RunSummary, RunError> {
    run_from(
        engine,
        opts,
        Start::Resumed(resumed.record.ledgers.as_ref()),
        observer,
    )
}

/// The ledgers' reading at the last save before a run that starts at the current step of
/// `engine` (`start`), a save every `save_every` steps: the checkpoint's when it holds them
/// (refused when at another step than that save's), else the current step's when it is a save,
/// else none until the first save.
fn reading_at_start(
    engine: &dyn Engine,
    start: Start<'_>,
    save_every: u64,
) -> Result<Option<Reading>, RunError> {
    let step = engine.state().step;
    Ok(match start {
        Start::Fresh => None,
        Start::Resumed(Some(l)) => {
            let last_save = step / save_every * save_every;
            if let Some(r) = l.last_save.filter(|r| r.step != last_save) {
                return Err(RunError::LedgersAt {
                    read_at: r.step,
                    save_every,
                    step,
                    last_save,
                });
            }
            l.last_save
        }
        Start::Resumed(None) => (engine.state().forces_ready && step.is_multiple_of(save_every))
            .then(|| engine.ledger()),
    })
}

/// The run loop of [`run_observed`] and [`run_resumed`].
fn run_from(
    engine: &mut dyn Engine,
    opts: &RunOptions,
    start: Start<'_>,
    mut observer: Option<&mut dyn Observer>,
) -> Result<RunSummary, RunError> {
    let resumed = matches!(start, Start::Resumed(_));
    std::fs::create_dir_all(&opts.out_dir).map_err(|source| RunError::Io {
        path: opts.out_dir.clone(),
        what: "cannot create output folder",
        source,
    })?;
    let diag = diagnostics_path(&opts.out_dir, &opts.name);
    // What a stop leaves: the last save and checkpoint of this run.
    let mut kept = Kept::default();
    // The ledgers' reading at the last save.
    let mut last_reading = if opts.write_saves {
        reading_at_start(engine, start, opts.save_every)?
    } else {
        None
    };
    if opts.write_saves {
        prepare_diagnostics(&diag, engine.state().step, opts.save_every, resumed)
            .map_err(|e| kept.not_written(e, &opts.out_dir))?;
    }
    let start_step = engine.state().step;
    let mut vtk_series = match (opts.vtk && opts.write_saves, resumed) {
        (false, _) => None,
        (true, false) => Some(vtk::Series::new(&opts.out_dir, &opts.name)),
        (true, true) => Some(vtk::Series::resume(
            &opts.out_dir,
            &opts.name,
            start_step / opts.save_every,
        )?),
    };
    let bar = progress_bar(opts, start_step);
    engine.sample_contacts_every(observer.as_deref().map_or(0, |o| o.contact_every()));
    engine.take_contact_samples();
    if let Some(o) = observer.as_deref_mut() {
        o.start(engine);
    }
    let t0 = Instant::now();
    let mut saves = 0;
    let mut first = true;
    let interrupted = loop {
        let step = engine.state().step;
        if opts.write_saves && step.is_multiple_of(opts.save_every) && !(first && resumed) {
            if !engine.state().forces_ready {
                engine.advance(0).map_err(|f| kept.stopped(f))?;
            }
            let reading = engine.ledger();
            let ledger = last_reading.map(|before| reading.since(&before));
            last_reading = Some(reading);
            let save = write_save(engine, opts, &diag, vtk_series.as_mut(), ledger)
                .map_err(|e| kept.not_written(e, &opts.out_dir))?;
            kept.save = Some(save);
            saves += 1;
        }
        // The observer looks at a step before its checkpoint, which then holds what it saw.
        if let Some(o) = observer.as_deref_mut() {
            if step != start_step && o.next_after(step - 1) == Some(step) {
                if !engine.state().forces_ready {
                    engine.advance(0).map_err(|f| kept.stopped(f))?;
                }
                o.observe(engine);
            }
        }
        let record = |engine: &dyn Engine, observer: Option<&dyn Observer>| RunRecord {
            ledgers: Some(Ledgers {
                flows: engine.flows(),
                last_save: last_reading,
            }),
            observer: observer.map(Observer::state),
        };
        if opts.checkpoint_every > 0
            && step.is_multiple_of(opts.checkpoint_every)
            && step != start_step
        {
            let r = record(engine, observer.as_deref());
            write_checkpoint(engine, opts, &r).map_err(|e| kept.not_written(e, &opts.out_dir))?;
            kept.checkpoint = Some(checkpoint_path(&opts.out_dir, &opts.name));
        }
        first = false;
        if step >= opts.end_step {
            break false;
        }
        if opts
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            let r = record(engine, observer.as_deref());
            write_checkpoint(engine, opts, &r).map_err(|e| kept.not_written(e, &opts.out_dir))?;
            break true;
        }
        let mut next = opts.end_step.min(step + 2000);
        if opts.write_saves {
            next = next.min((step / opts.save_every + 1) * opts.save_every);
        }
        if let Some(k) = step.checked_div(opts.checkpoint_every) {
            next = next.min((k + 1) * opts.checkpoint_every);
        }
        if let Some(s) = observer.as_deref().and_then(|o| o.next_after(step)) {
            next = next.min(s);
        }
        engine.advance(next - step).map_err(|f| kept.stopped(f))?;
        let samples = engine.take_contact_samples();
        if let Some(o) = observer.as_deref_mut() {
            o.contacts(&samples);
        }
        if let Some(b) = &bar {
            b.set_position(engine.state().step);
            b.set_message(format!("t = {:.3}", engine.state().time));
        }
    };
    engine.sample_contacts_every(0);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let state = engine.state();
    Ok(RunSummary {
        step: state.step,
        time: state.time,
        hash: crate::io::hash::state_hash(&engine.snapshot()),
        steps_run: state.step - start_step,
        seconds: t0.elapsed().as_secs_f64(),
        stages: *engine.counters(),
        saves,
        interrupted,
        deepest_overlap: engine.deepest_overlap(),
        largest_excess: engine.largest_excess(),
    })
}

/// Writes the run's checkpoint of the current step, with its run record `record`.
fn write_checkpoint(
    engine: &dyn Engine,
    opts: &RunOptions,
    record: &RunRecord,
) -> Result<(), CheckpointError> {
    crate::io::checkpoint::write_run(
        &checkpoint_path(&opts.out_dir, &opts.name),
        &engine.snapshot(),
        engine.params().dt,
        &opts.tag,
        record,
    )
}

/// The files a run has written that a stop by the run guard leaves intact.
#[derive(Default)]
struct Kept {
    save: Option<PathBuf>,
    checkpoint: Option<PathBuf>,
}

impl Kept {
    /// The error of a run stopped by the run guard: its failure and what is kept on disk.
    fn stopped(&self, mut f: Failure) -> RunError {
        f.kept = Some(format!(
            "nothing was written after the last good state: {}",
            self.listed()
        ));
        RunError::Guard(f)
    }

    /// The error of a run stopped because a file could not be written (a full disk, a
    /// read-only folder): the file and the system's error, then what is kept on disk.
    fn not_written(&self, e: impl Into<RunError>, dir: &Path) -> RunError {
        RunError::Stopped {
            dir: dir.to_path_buf(),
            kept: self.listed(),
            source: Box::new(e.into()),
        }
    }

    fn listed(&self) -> String {
        let name = |p: &Option<PathBuf>| {
            p.as_ref()
                .map_or("none".to_string(), |p| p.display().to_string())
        };
        format!(
            "last save {}, last checkpoint {}",
            name(&self.save),
            name(&self.checkpoint)
        )
    }
}

/// Writes the save of the current step (`.data`, `.fstat`, the `.vtu` when asked, then its
/// diagnostics row, with the ledgers `ledger` since the previous save); returns the path of its
/// `.data` file. A save that cannot be written whole is removed, so the folder holds whole
/// saves only.
fn write_save(
    engine: &dyn Engine,
    opts: &RunOptions,
    diag: &Path,
    vtk_series: Option<&mut vtk::Series>,
    ledger: Option<crate::step::LedgerRow>,
) -> Result<PathBuf, RunError> {
    let core = &engine.snapshot();
    let k = core.step / opts.save_every;
    let data = mercury::save_path(&opts.out_dir, &opts.name, "data", k);
    let fstat = mercury::save_path(&opts.out_dir, &opts.name, "fstat", k);
    // the files of this save replaced so far: removed again if the save cannot be completed
    let mut replaced: Vec<PathBuf> = Vec::new();
    let written = (|| {
        atomic::write(&data, mercury::data_text(core).as_bytes())?;
        replaced.push(data.clone());
        atomic::write(&fstat, mercury::fstat_text(core).as_bytes())?;
        replaced.push(fstat.clone());
        if let Some(series) = vtk_series {
            replaced.push(series.write(k, &vtk::Frame::of_snapshot(core))?);
        }
        let row = Diagnostics {
            ledger,
            ..Diagnostics::of(core, k)
        };
        atomic::append(diag, row.csv_row().as_bytes())
    })();
    if let Err(e) = written {
        for p in &replaced {
            let _ = std::fs::remove_file(p);
        }
        return Err(RunError::Save {
            save: k,
            step: core.step,
            source: e,
        });
    }
    Ok(data)
}

/// A fresh run starts a new table; a resumed one keeps the rows up to its step, which must have
/// been saved every `save_every` steps as this run saves (else its saves would be numbered
/// differently from those already in the folder).
fn prepare_diagnostics(
    path: &Path,
    step: u64,
    save_every: u64,
    resumed: bool,
) -> Result<(), RunError> {
    let mut kept = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(CSV_HEADER.as_bytes().to_vec());
    if resumed {
        // A folder without the table (a resume into another folder) starts a new one; a table
        // that cannot be read is an error, never taken for an empty one.
        let old = match std::fs::read_to_string(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            read => read.map_err(|source| RunError::Io {
                path: path.to_path_buf(),
                what: "cannot read",
                source,
            })?,
        };
        let file = path.display().to_string();
        for record in csv_table::records(&file, &old, false) {
            let (line, record) = record?;
            let field = |k: usize| record.get(k).and_then(|f| f.parse::<u64>().ok());
            let (true, Some(save), Some(row_step)) = (line > 1, field(0), field(1)) else {
                continue;
            };
            if row_step > step {
                continue;
            }
            if save * save_every != row_step {
                return Err(RunError::SaveInterval {
                    file: file.clone(),
                    line,
                    save,
                    step: row_step,
                    save_every,
                    written_every: row_step.checked_div(save).filter(|e| e * save == row_step),
                });
            }
            kept.write_record(&record)
                .map_err(|source| RunError::Table {
                    path: path.to_path_buf(),
                    source,
                })?;
        }
    }
    let text = kept.into_inner().map_err(|e| RunError::Table {
        path: path.to_path_buf(),
        source: e.into_error().into(),
    })?;
    atomic::write(path, &text).map_err(RunError::Write)
}

fn progress_bar(opts: &RunOptions, start: u64) -> Option<indicatif::ProgressBar> {
    if !opts.progress {
        return None;
    }
    let bar = indicatif::ProgressBar::new(opts.end_step);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:30} {pos}/{len} steps  {per_sec}  {msg}  ETA {eta}",
        )
        .expect("valid template"),
    );
    bar.set_position(start);
    bar.reset_eta();
    Some(bar)
}
