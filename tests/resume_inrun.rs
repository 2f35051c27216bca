//! A run interrupted inside its in-run averaging window and resumed from its checkpoint writes
//! the same in-run profiles, error table and diagnostics, byte for byte, as the run never
//! stopped: the checkpoint holds the in-run sums and the ledgers.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use common::*;
use verdem::analysis::cg::CgOptions;
use verdem::analysis::inrun::{self, Inrun};
use verdem::io::checkpoint;
use verdem::run::{self, Observer, RunOptions};
use verdem::state::SampledContact;
use verdem::step::engine::Overrides;
use verdem::step::Engine;

/// Steps of the run, a save every [`SAVE_EVERY`]: saves 0 to 8, the in-run window over the
/// steps of saves 5 to 8 (the second half, `verdem cg`'s default).
const END: u64 = 8000;
const SAVE_EVERY: u64 = 1000;
/// In-run sampling intervals (steps): contacts and walls, particles.
const INTERVALS: (u64, u64) = (50, 200);

fn options(dir: &std::path::Path, stop: Option<Arc<AtomicBool>>) -> RunOptions {
    RunOptions {
        tag: checkpoint::tag(&quick_case()),
        stop,
        ..run_options(dir, "q", END, SAVE_EVERY)
    }
}

fn quick_engine() -> Box<dyn Engine> {
    engine(
        &quick_case(),
        Some(&data("states/mercury_t143.85.data")),
        Overrides {
            threads: Some(1),
            ..Overrides::default()
        },
    )
}

/// The in-run accumulator of a run of the quick case on `e` whose folder's first save is
/// `first_save`.
fn accumulator(e: &dyn Engine, opts: &RunOptions, first_save: u64) -> Inrun {
    Inrun::for_run(&quick_case(), e, opts, INTERVALS, first_save).unwrap()
}

/// The run's observer, which also raises the run's stop flag at step `at` (as a signal would):
/// the run loop then writes a checkpoint there and returns.
struct StopAt {
    inrun: Inrun,
    at: u64,
    stop: Arc<AtomicBool>,
}

impl Observer for StopAt {
    fn next_after(&self, step: u64) -> Option<u64> {
        let own = (step < self.at).then_some(self.at);
        match (self.inrun.next_after(step), own) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
    fn observe(&mut self, engine: &dyn Engine) {
        let step = engine.state().step;
        if self.inrun.next_after(step - 1) == Some(step) {
            self.inrun.observe(engine);
        }
        if step == self.at {
            self.stop.store(true, Ordering::Relaxed);
        }
    }
    fn contact_every(&self) -> u64 {
        self.inrun.contact_every()
    }
    fn contacts(&mut self, samples: &[(u64, Vec<SampledContact>)]) {
        self.inrun.contacts(samples);
    }
    fn state(&self) -> Vec<u8> {
        self.inrun.state()
    }
}

/// The in-run profiles and error table (CSV) of `inrun`, and the diagnostics of folder `dir`.
fn outputs(inrun: &Inrun, dir: &std::path::Path) -> [String; 3] {
    let r = inrun.result().expect("in-run samples");
    let diagnostics = std::fs::read_to_string(run::diagnostics_path(dir, "q")).unwrap();
    [inrun::csv(&r), inrun::errors_csv(&r), diagnostics]
}

/// Runs the quick case to [`END`] stopped at step `at` and resumed from its checkpoint; returns
/// its outputs.
fn interrupted_at(at: u64) -> [String; 3] {
    let dir = tempfile::tempdir().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let opts = options(dir.path(), Some(Arc::clone(&stop)));
    let mut first = quick_engine();
    let mut observer = StopAt {
        inrun: accumulator(first.as_ref(), &opts, 0),
        at,
        stop,
    };
    let s = run::run_observed(first.as_mut(), &opts, false, Some(&mut observer)).unwrap();
    assert!(s.interrupted && s.step == at, "stopped at {}", s.step);
    let ck = run::checkpoint_path(dir.path(), "q");
    let mut second = quick_engine();
    let tag = checkpoint::tag(&quick_case());
    let resumed = checkpoint::read_run(&ck, second.as_mut(), &tag).unwrap();
    assert!(resumed.lacks().is_empty(), "{:?}", resumed.lacks());
    let opts = options(dir.path(), None);
    let mut inrun = accumulator(second.as_ref(), &opts, 0);
    let sums = resumed.record.observer.as_ref().expect("in-run sums");
    let file = ck.display().to_string();
    let not_taken = inrun
        .restore(&file, resumed.observer_at, sums, resumed.step)
        .unwrap();
    assert_eq!(not_taken, None);
    run::run_resumed(second.as_mut(), &opts, &resumed, Some(&mut inrun)).unwrap();
    outputs(&inrun, dir.path())
}

#[test]
fn a_resumed_run_writes_the_in_run_profiles_of_a_straight_run() {
    let dir = tempfile::tempdir().unwrap();
    let opts = options(dir.path(), None);
    let mut e = quick_engine();
    let mut inrun = accumulator(e.as_ref(), &opts, 0);
    assert_eq!(inrun.sampling().from, 5000);
    run::run_observed(e.as_mut(), &opts, false, Some(&mut inrun)).unwrap();
    let straight = outputs(&inrun, dir.path());
    // between saves 6 and 7, and at save 6: both inside the window
    for at in [6550, 6000] {
        let resumed = interrupted_at(at);
        for (k, name) in ["profiles_inrun.csv", "profiles_inrun_errors.csv"]
            .iter()
            .enumerate()
        {
            assert!(resumed[k] == straight[k], "stopped at {at}: {name} differs");
        }
        common::assert_resumed_diagnostics(&resumed[2], &straight[2]);
    }
}

/// In-run sums taken at other intervals, up to another step or on other slices are not taken,
/// with the fields that differ (the run averages in-run after the resume only, and says so);
/// truncated sums are refused naming the byte.
#[test]
fn in_run_sums_of_another_sampling_are_not_taken() {
    let dir = tempfile::tempdir().unwrap();
    let opts = options(dir.path(), None);
    let e = quick_engine();
    let mut taken = accumulator(e.as_ref(), &opts, 0);
    let bytes = taken.state();
    let mut other = Inrun::for_run(&quick_case(), e.as_ref(), &opts, (100, 200), 0).unwrap();
    let why = other.restore("c.ck", 40, &bytes, 0).unwrap().unwrap();
    assert!(
        why.starts_with("in-run sums taken otherwise")
            && why.contains("contact samples every 50 steps, this run every 100 (--inrun-every)"),
        "{why}"
    );
    assert_eq!(other.state(), fresh_state(e.as_ref(), &opts, (100, 200)));
    let later = RunOptions {
        end_step: END + SAVE_EVERY,
        ..options(dir.path(), None)
    };
    let mut longer = Inrun::for_run(&quick_case(), e.as_ref(), &later, INTERVALS, 0).unwrap();
    let why = longer.restore("c.ck", 40, &bytes, 0).unwrap().unwrap();
    assert!(
        why.contains("samples up to step 8000, this run up to step 9000 (--steps)"),
        "{why}"
    );
    let err = taken
        .restore("c.ck", 40, &bytes[..bytes.len() - 1], 0)
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("c.ck: in-run sums of the checkpoint truncated at byte"),
        "{err}"
    );
    let coarser = CgOptions {
        slices: 50,
        ..CgOptions::for_case(&quick_case())
    };
    let mut other_frame = Inrun::new(&coarser, &e.state().domain, taken.sampling()).unwrap();
    let why = other_frame.restore("c.ck", 40, &bytes, 0).unwrap().unwrap();
    assert!(
        why.starts_with("in-run sums of another coarse-graining: slices 100, this run's 50"),
        "{why}"
    );
    taken.restore("c.ck", 40, &bytes, 0).unwrap();
    assert_eq!(taken.state(), bytes);
}

/// A checkpoint of format version 2 (an earlier verdem: no ledgers, no in-run sums) still
/// resumes, and `verdem run` names on stderr what the resumed run lacks.
#[test]
fn a_checkpoint_of_format_2_resumes_naming_what_it_lacks() {
    let corpus = root().join("tests/corpus");
    let dir = tempfile::tempdir().unwrap();
    let out = verdem_ok([
        "run",
        corpus.join("small.toml").to_str().unwrap(),
        "--init",
        corpus.join("small.data").to_str().unwrap(),
        "--resume",
        corpus.join("small.checkpoint").to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
        "--steps",
        "20",
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(
            "small.checkpoint: a checkpoint of format version 2 holds no ledgers: the ledgers' \
             flows start again at zero"
        ),
        "{stderr}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("resumed at step 10"));
}

/// A resume whose saves would fall elsewhere than those of the run that wrote the checkpoint
/// (another --save-every) is refused before anything is written: its ledgers were read at a
/// save this run does not have.
#[test]
fn a_resume_at_another_save_interval_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let opts = RunOptions {
        end_step: 1500,
        checkpoint_every: 1500,
        ..options(dir.path(), None)
    };
    let mut first = quick_engine();
    run::run(first.as_mut(), &opts, false).unwrap();
    let ck = run::checkpoint_path(dir.path(), "q");
    let mut second = quick_engine();
    let resumed = checkpoint::read_run(&ck, second.as_mut(), &opts.tag).unwrap();
    let table = std::fs::read(run::diagnostics_path(dir.path(), "q")).unwrap();
    let other = RunOptions {
        save_every: 700,
        ..opts
    };
    let err = run::run_resumed(second.as_mut(), &other, &resumed, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("read at the save of step 1000, but with a save every 700 steps the last save before step 1500 is at step 1400"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(run::diagnostics_path(dir.path(), "q")).unwrap(),
        table
    );
}

/// The sums of an accumulator at `intervals` that has taken nothing.
fn fresh_state(e: &dyn Engine, opts: &RunOptions, intervals: (u64, u64)) -> Vec<u8> {
    Inrun::for_run(&quick_case(), e, opts, intervals, 0)
        .unwrap()
        .state()
}
