//! `verdem ensemble` end to end: the same replicas through the local engine and through a real
//! Slurm cluster (ci/slurm_local.sh sets up a one-node cluster on localhost; ci/test.sh runs it
//! and sets VERDEM_SLURM=1), the same state hashes and merged profiles from both, and failed
//! replicas reported with their task id, log and exit code.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{root, verdem_ok};

const CASE: &str = "cases/shear_flow_steady.toml";

/// Whether the Slurm tests run: only with VERDEM_SLURM=1 (then a Slurm that does not work
/// fails them); without it they are skipped, saying so.
fn slurm_enabled() -> bool {
    if std::env::var("VERDEM_SLURM").as_deref() == Ok("1") {
        return true;
    }
    eprintln!(
        "skipped: VERDEM_SLURM is not 1 (ci/test.sh starts a one-node Slurm cluster with \
         ci/slurm_local.sh and sets it)"
    );
    false
}

fn verdem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

/// Runs a 3-replica ensemble of 3000 steps (a save every 500) of the steady case into `out`
/// on `engine`.
fn small_ensemble(out: &Path, engine: &str) -> Output {
    let mut args = vec![
        "ensemble",
        CASE,
        "--replicas",
        "3",
        "--steps",
        "3000",
        "--every",
        "500",
        "--engine",
        engine,
        "--out",
        out.to_str().unwrap(),
    ];
    if engine == "slurm" {
        args.extend(["--poll", "0.5"]);
    }
    verdem_ok(&args)
}

/// A field of a replica's record (`replica_K/NAME.replica.toml`), unquoted.
fn record_field(out: &Path, k: u64, field: &str) -> String {
    let path = out.join(format!("replica_{k}/shear_flow_steady.replica.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    text.lines()
        .find_map(|l| l.strip_prefix(&format!("{field} = ")))
        .unwrap_or_else(|| panic!("{}: no {field}", path.display()))
        .trim_matches('"')
        .to_string()
}

fn merged(out: &Path) -> String {
    std::fs::read_to_string(out.join("shear_flow_steady.profiles_ensemble.csv")).unwrap()
}

/// The unperturbed start's state hash.
fn unperturbed_start() -> String {
    let out = verdem_ok(["hash", CASE, "--steps", "0"]);
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

#[test]
fn local_replicas_are_perturbed_reproducible_and_merged() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    small_ensemble(&a, "local");
    let plain = unperturbed_start();
    let mut starts = Vec::new();
    for k in 0..3 {
        let start = record_field(&a, k, "start_hash");
        assert_ne!(start, plain, "replica {k} starts unperturbed");
        assert!(!starts.contains(&start), "replica {k} starts as another");
        starts.push(start);
    }
    // one replica run by itself is the same replica
    verdem_ok([
        "ensemble",
        CASE,
        "--replicas",
        "3",
        "--steps",
        "3000",
        "--every",
        "500",
        "--out",
        b.to_str().unwrap(),
        "--replica",
        "2",
    ]);
    assert_eq!(record_field(&b, 2, "hash"), record_field(&a, 2, "hash"));
    assert_eq!(record_field(&b, 2, "start_hash"), starts[2]);
    // the merged table: three replicas' mean and spread, re-merged identically
    let csv = merged(&a);
    assert!(csv.starts_with("z,nu,nu_se,rho,rho_se,"), "{}", &csv[..60]);
    assert_eq!(csv.lines().count(), 101);
    let summary = std::fs::read_to_string(a.join("shear_flow_steady.ensemble.toml")).unwrap();
    assert!(summary.contains("replicas = 3\n") && summary.contains("engine = \"local\""));
    assert_eq!(summary.matches("[[field]]").count(), 5, "{summary}");
    verdem_ok([
        "ensemble",
        CASE,
        "--replicas",
        "3",
        "--merge",
        "--out",
        a.to_str().unwrap(),
    ]);
    assert_eq!(merged(&a), csv);
    // a folder holding an ensemble is not overwritten without --force
    let again = verdem(&[
        "ensemble",
        CASE,
        "--replicas",
        "3",
        "--out",
        a.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(!again.status.success() && err.contains("--force"), "{err}");
    assert_eq!(merged(&a), csv);
}

#[test]
fn slurm_and_local_give_the_same_replicas_and_profiles() {
    if !slurm_enabled() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let local = dir.path().join("local");
    let slurm = dir.path().join("slurm");
    small_ensemble(&local, "local");
    let out = small_ensemble(&slurm, "slurm");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Slurm job "), "{text}");
    let script = std::fs::read_to_string(slurm.join("shear_flow_steady.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --array=0-2\n"), "{script}");
    let mut finals = Vec::new();
    for k in 0..3 {
        for field in ["seed", "start_hash", "hash"] {
            assert_eq!(
                record_field(&slurm, k, field),
                record_field(&local, k, field),
                "replica {k}: {field}"
            );
        }
        assert_eq!(
            std::fs::read_to_string(slurm.join(format!("replica_{k}/replica.exit")))
                .unwrap()
                .trim(),
            "0"
        );
        finals.push(record_field(&slurm, k, "hash"));
    }
    assert!(finals[0] != finals[1] && finals[1] != finals[2] && finals[0] != finals[2]);
    assert_eq!(merged(&slurm), merged(&local));
}

/// The quick case (generated start) with a run-guard overlap limit that its first contacts
/// exceed within a few steps: every replica stops with the guard's exit status 3.
fn failing_case(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(root().join("cases/shear_flow_quick.toml")).unwrap();
    let path = dir.join("failing.toml");
    std::fs::write(&path, format!("{text}\n[guard]\noverlap = 1e-6\n")).unwrap();
    path
}

/// Runs an ensemble of `failing_case` on `engine`, checks that it fails and that its message
/// names each task, its exit code 3 and its log, which holds the guard's message.
fn failures_are_reported(engine: &str) {
    let dir = tempfile::tempdir().unwrap();
    let case = failing_case(dir.path());
    let out = dir.path().join("out");
    let o = verdem(&[
        "ensemble",
        case.to_str().unwrap(),
        "--replicas",
        "2",
        "--steps",
        "200",
        "--every",
        "100",
        "--engine",
        engine,
        "--poll",
        "0.5",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("2 of 2 replicas failed"), "{err}");
    for k in 0..2 {
        let log = out.join(format!("replica_{k}/replica.log"));
        let line = format!(
            "task {k}: exit code 3; log {}: error: the run guard stopped",
            log.display()
        );
        assert!(err.contains(&line), "no {line:?} in {err}");
    }
    assert!(!out.join("shear_flow_quick.profiles_ensemble.csv").exists());
}

#[test]
fn local_failures_are_reported_with_task_log_and_exit_code() {
    failures_are_reported("local");
}

#[test]
fn slurm_failures_are_reported_with_task_log_and_exit_code() {
    if slurm_enabled() {
        failures_are_reported("slurm");
    }
}
