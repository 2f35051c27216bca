//! The local engine: the replicas as child processes of the verdem binary, at most `jobs` at
//! once, each on one thread. Processes rather than threads of this one: a replica is then run
//! exactly as a Slurm array task runs it (the same command, the same one-replica process, its
//! own log and exit code), and a replica that fails, even by a crash, leaves the others running
//! and is reported by its exit code.

use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use anyhow::Context;

use crate::child::{self, OnParentDeath};

use super::{log_path, ReplicaCommand, TaskOutcome};

/// Runs replicas 0..`replicas` with `cmd` (plus `--replica K`), at most `jobs` at once, each
/// process's standard output and error into its log ([`log_path`] under `out`, whose replica
/// folders must exist); returns how each ended, in replica order.
pub fn run(
    cmd: &ReplicaCommand,
    replicas: u64,
    jobs: usize,
    out: &Path,
) -> anyhow::Result<Vec<TaskOutcome>> {
    let next = AtomicU64::new(0);
    let outcomes = Mutex::new(Vec::new());
    let workers = jobs.clamp(1, replicas.max(1) as usize);
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                s.spawn(|| -> anyhow::Result<()> {
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        if k >= replicas {
                            return Ok(());
                        }
                        let o = run_one(cmd, k, out)?;
                        println!(
                            "replica {k}: {}",
                            match &o.exit {
                                Ok(0) => "done".to_string(),
                                Ok(code) => format!("failed, exit code {code}"),
                                Err(why) => format!("failed, {why}"),
                            }
                        );
                        outcomes.lock().expect("no worker panics").push(o);
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .try_for_each(|h| h.join().expect("a worker does not panic"))
    })?;
    let mut outcomes = outcomes.into_inner().expect("no worker panics");
    outcomes.sort_by_key(|o| o.replica);
    Ok(outcomes)
}

/// Runs replica `k` and waits for it, on the calling thread (its worker, which outlives it).
fn run_one(cmd: &ReplicaCommand, k: u64, out: &Path) -> anyhow::Result<TaskOutcome> {
    let log = log_path(out, k);
    let file = File::create(&log).with_context(|| format!("{}: cannot create", log.display()))?;
    let err = file
        .try_clone()
        .with_context(|| format!("{}: cannot open twice", log.display()))?;
    let status = child::status(
        Command::new(&cmd.program)
            .args(&cmd.args)
            .args(["--replica", &k.to_string()])
            .stdin(Stdio::null())
            .stdout(file)
            .stderr(err),
        OnParentDeath::Kill,
    )
    .with_context(|| format!("cannot start {}", cmd.program.display()))?;
    let exit = match status.code() {
        Some(code) => Ok(code),
        None => Err(signal_of(&status)),
    };
    Ok(TaskOutcome {
        replica: k,
        log,
        exit,
    })
}

/// How a process that has no exit code ended.
fn signal_of(status: &std::process::ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match status.signal() {
        Some(sig) => format!("killed by signal {sig}"),
        None => format!("ended without an exit code ({status})"),
    }
}
