//! The run loop: advance the simulation between saves and checkpoints, write MercuryCG files and
//! the diagnostics table, report progress, and summarise the run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context};

use crate::io::diagnostics::{Diagnostics, CSV_HEADER};
use crate::io::{atomic, csv_table, mercury};
use crate::step::{Engine, StageTimes};

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
            "case = {case:?}\nstep = {}\ntime = {}\nhash = {:?}\nthreads = {threads}\nsteps_per_second = {}\n",
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
) -> anyhow::Result<()> {
    let p = summary_path(dir, name);
    atomic::write(&p, summary.toml(name, threads).as_bytes())
        .with_context(|| p.display().to_string())
}

/// Path of the run's checkpoint.
pub fn checkpoint_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.checkpoint"))
}

/// Runs `engine` to `opts.end_step`. `resumed` says the current step's save already exists.
pub fn run(
    engine: &mut dyn Engine,
    opts: &RunOptions,
    resumed: bool,
) -> anyhow::Result<RunSummary> {
    std::fs::create_dir_all(&opts.out_dir)
        .with_context(|| format!("{}: cannot create output folder", opts.out_dir.display()))?;
    let diag = diagnostics_path(&opts.out_dir, &opts.name);
    if opts.write_saves {
        prepare_diagnostics(&diag, engine.state().step, opts.save_every, resumed)?;
    }
    let start_step = engine.state().step;
    let bar = progress_bar(opts, start_step);
    let t0 = Instant::now();
    let mut saves = 0;
    let mut first = true;
    // What a stop by the run guard leaves: the last save and checkpoint of this run.
    let mut kept = Kept::default();
    let interrupted = loop {
        let step = engine.state().step;
        if opts.write_saves && step.is_multiple_of(opts.save_every) && !(first && resumed) {
            if !engine.state().forces_ready {
                engine.advance(0).map_err(|f| kept.stopped(f))?;
            }
            kept.save = Some(write_save(engine, opts, &diag)?);
            saves += 1;
        }
        if opts.checkpoint_every > 0
            && step.is_multiple_of(opts.checkpoint_every)
            && step != start_step
        {
            write_checkpoint(engine, opts)?;
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
            write_checkpoint(engine, opts)?;
            break true;
        }
        let mut next = opts.end_step.min(step + 2000);
        if opts.write_saves {
            next = next.min((step / opts.save_every + 1) * opts.save_every);
        }
        if let Some(k) = step.checked_div(opts.checkpoint_every) {
            next = next.min((k + 1) * opts.checkpoint_every);
        }
        engine.advance(next - step).map_err(|f| kept.stopped(f))?;
        if let Some(b) = &bar {
            b.set_position(engine.state().step);
            b.set_message(format!("t = {:.3}", engine.state().time));
        }
    };
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
    })
}

fn write_checkpoint(engine: &dyn Engine, opts: &RunOptions) -> anyhow::Result<()> {
    crate::io::checkpoint::write(
        &checkpoint_path(&opts.out_dir, &opts.name),
        &engine.snapshot(),
        engine.params().dt,
        &opts.tag,
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
    fn stopped(&self, mut f: crate::step::guard::Failure) -> anyhow::Error {
        let name = |p: &Option<PathBuf>| {
            p.as_ref()
                .map_or("none".to_string(), |p| p.display().to_string())
        };
        f.kept = Some(format!(
            "nothing was written after the last good state: last save {}, last checkpoint {}",
            name(&self.save),
            name(&self.checkpoint)
        ));
        anyhow::Error::new(f)
    }
}

/// Writes the save of the current step; returns the path of its `.data` file.
fn write_save(engine: &dyn Engine, opts: &RunOptions, diag: &Path) -> anyhow::Result<PathBuf> {
    let core = &engine.snapshot();
    let k = core.step / opts.save_every;
    let data = mercury::save_path(&opts.out_dir, &opts.name, "data", k);
    atomic::write(&data, mercury::data_text(core).as_bytes())
        .with_context(|| format!("{}: cannot write", data.display()))?;
    let fstat = mercury::save_path(&opts.out_dir, &opts.name, "fstat", k);
    atomic::write(&fstat, mercury::fstat_text(core).as_bytes())
        .with_context(|| format!("{}: cannot write", fstat.display()))?;
    atomic::append(diag, Diagnostics::of(core, k).csv_row().as_bytes())
        .with_context(|| format!("{}: cannot append", diag.display()))?;
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
) -> anyhow::Result<()> {
    let mut kept = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(CSV_HEADER.as_bytes().to_vec());
    if resumed {
        let old = std::fs::read_to_string(path).unwrap_or_default();
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
                let written_every = match row_step.checked_div(save) {
                    Some(e) if e * save == row_step => format!("--save-every {e}"),
                    _ => "the --save-every of the run that wrote it".into(),
                };
                bail!(
                    "{file}:{line}: save {save} is at step {row_step}, but this run saves every \
                     {save_every} steps; resume with {written_every}"
                );
            }
            kept.write_record(&record)?;
        }
    }
    let text = kept.into_inner()?;
    atomic::write(path, &text).with_context(|| format!("{}: cannot write", path.display()))
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
