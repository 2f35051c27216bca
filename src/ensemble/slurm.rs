//! The Slurm engine: a batch script whose job array runs one replica per array task
//! (`sbatch --array=0-(R-1)`, task K runs replica `$SLURM_ARRAY_TASK_ID`), submitted with
//! `sbatch`, waited for by polling `squeue`, then each task's exit code read from the file the
//! script writes beside the replica (Slurm's own accounting, `sacct`, is often disabled on
//! small clusters; `scontrol show job` says why a task that wrote none ended).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};

use crate::child::{self, OnParentDeath};

use super::{log_path, replica_dir, ReplicaCommand, TaskOutcome};

/// How to submit and wait.
#[derive(Clone, Debug)]
pub struct Options {
    /// Passed to `sbatch` before the script (partition, account, time limit, …); they take
    /// precedence over the script's `#SBATCH` lines.
    pub sbatch_args: Vec<String>,
    /// Time between two `squeue` polls.
    pub poll: Duration,
    /// A request to stop waiting (a signal): the job is cancelled (`scancel`).
    pub stop: Option<Arc<AtomicBool>>,
}

/// The file in which array task `k`'s exit code is written by the batch script.
pub fn exit_path(out: &Path, k: u64) -> PathBuf {
    replica_dir(out, k).join("replica.exit")
}

/// Path of the batch script, `DIR/NAME.sbatch`.
pub fn script_path(out: &Path, name: &str) -> PathBuf {
    out.join(format!("{name}.sbatch"))
}

/// The batch script of the ensemble: a job array of `replicas` tasks of one CPU each; task K
/// runs `cmd --replica K` with its output in replica K's log, then writes its exit code.
/// `out` must be absolute (the tasks may start in another folder on another node).
pub fn script(cmd: &ReplicaCommand, replicas: u64, out: &Path, name: &str) -> String {
    let dir = out.display().to_string();
    let mut command: Vec<String> = std::iter::once(cmd.program.display().to_string())
        .chain(cmd.args.iter().cloned())
        .map(|a| quote(&a))
        .collect();
    command.push("--replica".into());
    command.push("\"$SLURM_ARRAY_TASK_ID\"".into());
    let job = quote(&format!("verdem-{name}"));
    let log = quote(&format!("{dir}/replica_%a/replica.log"));
    let exit = format!(
        "{}/replica_\"$SLURM_ARRAY_TASK_ID\"/replica.exit",
        quote(&dir)
    );
    format!(
        "#!/bin/bash\n\
         # verdem ensemble of {name}: array task K runs replica K (docs/ensembles.md)\n\
         #SBATCH --job-name={job}\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --output={log}\n\
         {command}\n\
         status=$?\n\
         echo \"$status\" > {exit}\n\
         exit \"$status\"\n",
        last = replicas - 1,
        command = command.join(" "),
    )
}

/// Writes the batch script into `out`, submits it, waits for every array task to end and
/// returns the job's id and how each task ended, in replica order. `out` must be absolute and
/// its replica folders must exist.
pub fn run(
    cmd: &ReplicaCommand,
    replicas: u64,
    out: &Path,
    name: &str,
    o: &Options,
) -> anyhow::Result<(String, Vec<TaskOutcome>)> {
    let path = script_path(out, name);
    crate::io::atomic::write(&path, script(cmd, replicas, out, name).as_bytes())?;
    let submitted = child::output(
        Command::new("sbatch")
            .arg("--parsable")
            .args(&o.sbatch_args)
            .arg(&path),
        OnParentDeath::Kill,
    )
    .context("cannot run sbatch (is Slurm's client installed? else use --engine local)")?;
    if !submitted.status.success() {
        bail!(
            "sbatch {} refused the job ({}): {}",
            path.display(),
            submitted.status,
            String::from_utf8_lossy(&submitted.stderr).trim()
        );
    }
    // --parsable prints "JOBID" or "JOBID;CLUSTER"
    let text = String::from_utf8_lossy(&submitted.stdout);
    let job = text
        .trim()
        .split(';')
        .next()
        .filter(|j| !j.is_empty() && j.bytes().all(|b| b.is_ascii_digit()))
        .with_context(|| format!("sbatch printed {text:?}, not a job id"))?
        .to_string();
    println!(
        "submitted {}: Slurm job {job}, array tasks 0-{}",
        path.display(),
        replicas - 1
    );
    wait(&job, o)?;
    let outcomes = (0..replicas)
        .map(|k| TaskOutcome {
            replica: k,
            log: log_path(out, k),
            exit: exit_code(out, &job, k),
        })
        .collect();
    Ok((job, outcomes))
}

/// Polls `squeue` until the job has no task left pending or running; prints the counts when
/// they change. A stop request cancels the job (between two polls, within 0.1 s).
fn wait(job: &str, o: &Options) -> anyhow::Result<()> {
    let mut last = String::new();
    let mut failures = 0;
    loop {
        if stop_requested(o) {
            let cancelled = child::status(Command::new("scancel").arg(job), OnParentDeath::Kill);
            bail!(
                "stopped waiting for Slurm job {job}; {}",
                match cancelled {
                    Ok(s) if s.success() => "the job was cancelled (scancel)".to_string(),
                    _ => format!("it could not be cancelled: cancel it with `scancel {job}`"),
                }
            );
        }
        let q = child::output(
            Command::new("squeue").args(["-h", "-r", "-j", job, "-o", "%T"]),
            OnParentDeath::Kill,
        )
        .context("cannot run squeue")?;
        let stderr = String::from_utf8_lossy(&q.stderr);
        if !q.status.success() {
            // a job that ended long ago is no longer known to squeue
            if stderr.contains("Invalid job id") {
                return Ok(());
            }
            failures += 1;
            if failures >= 5 {
                bail!(
                    "squeue fails while waiting for Slurm job {job} ({}): {}",
                    q.status,
                    stderr.trim()
                );
            }
        } else {
            failures = 0;
            let states = String::from_utf8_lossy(&q.stdout);
            let (mut pending, mut running, mut other) = (0, 0, 0);
            for s in states.lines().map(str::trim).filter(|s| !s.is_empty()) {
                match s {
                    "PENDING" => pending += 1,
                    "RUNNING" | "CONFIGURING" | "COMPLETING" => running += 1,
                    _ => other += 1,
                }
            }
            if pending + running + other == 0 {
                return Ok(());
            }
            let now = format!(
                "Slurm job {job}: {running} running, {pending} pending{}",
                if other > 0 {
                    format!(", {other} in other states")
                } else {
                    String::new()
                }
            );
            if now != last {
                println!("{now}");
                last = now;
            }
        }
        pause(o);
    }
}

/// Whether a stop was requested.
fn stop_requested(o: &Options) -> bool {
    o.stop.as_ref().is_some_and(|s| s.load(Ordering::Relaxed))
}

/// Sleeps for the time between two polls, or until a stop is requested (within 0.1 s).
fn pause(o: &Options) {
    let end = Instant::now() + o.poll;
    loop {
        let now = Instant::now();
        if now >= end || stop_requested(o) {
            return;
        }
        std::thread::sleep((end - now).min(Duration::from_millis(100)));
    }
}

/// Array task `k`'s exit code from the file the script wrote, or why there is none (Slurm's
/// state of the task, when it still knows it).
fn exit_code(out: &Path, job: &str, k: u64) -> Result<i32, String> {
    let path = exit_path(out, k);
    if let Ok(text) = std::fs::read_to_string(&path) {
        return text
            .trim()
            .parse()
            .map_err(|_| format!("{}: not an exit code: {:?}", path.display(), text.trim()));
    }
    let task = format!("{job}_{k}");
    let shown = child::output(
        Command::new("scontrol").args(["-o", "show", "job", &task]),
        OnParentDeath::Kill,
    )
    .ok()
    .filter(|o| o.status.success())
    .map(|o| String::from_utf8_lossy(&o.stdout).into_owned());
    let field = |text: &str, key: &str| {
        text.split_whitespace()
            .find_map(|w| w.strip_prefix(key))
            .map(String::from)
    };
    Err(match shown {
        Some(text) => format!(
            "task {task} wrote no exit code: Slurm reports JobState={} ExitCode={} Reason={}",
            field(&text, "JobState=").unwrap_or_default(),
            field(&text, "ExitCode=").unwrap_or_default(),
            field(&text, "Reason=").unwrap_or_default()
        ),
        None => format!(
            "task {task} wrote no exit code (cancelled, out of time, or its node failed; Slurm \
             no longer reports it)"
        ),
    })
}

/// Quotes `a` for a POSIX shell (single quotes unless it is plain).
fn quote(a: &str) -> String {
    let plain = !a.is_empty()
        && a.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+%".contains(c));
    if plain {
        a.to_string()
    } else {
        format!("'{}'", a.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_runs_one_replica_per_array_task_and_records_its_exit_code() {
        let cmd = ReplicaCommand {
            program: PathBuf::from("/opt/verdem bin/verdem"),
            args: vec![
                "ensemble".into(),
                "/c/case.toml".into(),
                "--seed".into(),
                "7".into(),
            ],
        };
        let s = script(&cmd, 4, Path::new("/scratch/ens"), "shear");
        assert!(s.starts_with("#!/bin/bash\n"), "{s}");
        assert!(s.contains("\n#SBATCH --array=0-3\n"), "{s}");
        assert!(
            s.contains("\n#SBATCH --output=/scratch/ens/replica_%a/replica.log\n"),
            "{s}"
        );
        assert!(
            s.contains("\n'/opt/verdem bin/verdem' ensemble /c/case.toml --seed 7 --replica \"$SLURM_ARRAY_TASK_ID\"\n"),
            "{s}"
        );
        assert!(
            s.contains(
                "echo \"$status\" > /scratch/ens/replica_\"$SLURM_ARRAY_TASK_ID\"/replica.exit\n"
            ),
            "{s}"
        );
        assert!(s.ends_with("exit \"$status\"\n"), "{s}");
    }

    #[test]
    fn a_stop_request_ends_the_pause_between_two_polls() {
        let stop = Arc::new(AtomicBool::new(false));
        let o = Options {
            sbatch_args: Vec::new(),
            poll: Duration::from_secs(600),
            stop: Some(Arc::clone(&stop)),
        };
        let started = Instant::now();
        std::thread::scope(|s| {
            s.spawn(|| pause(&o));
            std::thread::sleep(Duration::from_millis(50));
            stop.store(true, Ordering::Relaxed);
        });
        // within the 0.1 s slice, not after the 600 s poll (a loaded machine allowing)
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "{:?}",
            started.elapsed()
        );
    }

    #[test]
    fn quoting_survives_the_shell() {
        for a in ["plain-1.toml", "with space", "it's", "$HOME", ""] {
            let out = Command::new("sh")
                .arg("-c")
                .arg(format!("printf %s {}", quote(a)))
                .output()
                .unwrap();
            assert_eq!(String::from_utf8_lossy(&out.stdout), a);
        }
    }
}
