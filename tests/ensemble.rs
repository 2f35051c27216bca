//! `verdem ensemble` end to end: the same replicas through the local engine and through a real
//! Slurm cluster (ci/slurm_local.sh sets up a one-node cluster on localhost; ci/test.sh runs it
//! and sets VERDEM_SLURM=1), the same state hashes and merged profiles from both, and failed
//! replicas reported with their task id, log and exit code.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{root, verdem_ok};
use verdem::io::mercury::{read_data, DataFile};

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

/// Two states of the steady case's geometry that differ: a save of MercuryDPM's reference run
/// (time 143.85) and verdem's state after the full run (the case's own `run.init`).
const STARTS: [&str; 2] = [
    "data/states/mercury_t143.85.data",
    "golden/full_run/shear_flow.final.data",
];

/// Runs a 2-replica ensemble of 1000 steps (a save every 500) of the steady case from
/// [`STARTS`] into `out` on `engine`, with `extra` options.
fn starts_ensemble(out: &Path, engine: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "ensemble", CASE, "--starts", STARTS[0], STARTS[1], "--steps", "1000", "--every", "500",
        "--engine", engine, "--poll", "0.5", "--out",
    ];
    args.push(out.to_str().unwrap());
    args.extend(extra);
    verdem_ok(&args)
}

/// The wall spheres of the steady case (2 walls × 12 rows × 20), the first lines of a state.
const WALL_SPHERES: usize = 480;

/// Replica `k`'s first save in the ensemble folder `out` and its start file `start`, which
/// have the same time and number of particles.
fn first_save_and_start(out: &Path, k: u64, start: &str) -> (DataFile, DataFile) {
    let first = read_data(&out.join(format!("replica_{k}/shear_flow_steady.data.0000"))).unwrap();
    let want = read_data(&root().join(start)).unwrap();
    assert_eq!(first.time, want.time, "replica {k}");
    assert_eq!(first.rows.len(), want.rows.len(), "replica {k}");
    (first, want)
}

/// Hex SHA-256 of a file.
fn sha256(path: &Path) -> String {
    use sha2::{Digest, Sha256};
    let bytes = std::fs::read(path).unwrap();
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The state hash of the steady case from `init` after `steps` steps (`verdem hash`).
fn hash_from(init: &str, steps: u64) -> String {
    let out = verdem_ok(["hash", CASE, "--init", init, "--steps", &steps.to_string()]);
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// Whether an ensemble command fails with a message that contains `needle`; `out` must then
/// not have been created (nothing ran).
fn refused(args: &[&str], out: &Path, needle: &str) {
    let o = verdem(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(err.contains(needle), "no {needle:?} in {err}");
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn replicas_start_from_their_own_files() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    starts_ensemble(&a, "local", &[]);
    for (k, start) in STARTS.iter().enumerate() {
        let k = k as u64;
        let file = root().join(start);
        // the record names the start file and its content
        assert_eq!(
            record_field(&a, k, "start_file"),
            file.display().to_string()
        );
        assert_eq!(record_field(&a, k, "start_sha256"), sha256(&file));
        // the first save is the start: its time and every particle's position; the free
        // particles' velocities perturbed (by about 1e-6), the walls' as they were
        let (first, want) = first_save_and_start(&a, k, start);
        for (a, (r, w)) in first.rows.iter().zip(&want.rows).enumerate() {
            assert_eq!(r.x, w.x, "replica {k}, line {}", r.line);
            if a < WALL_SPHERES {
                assert_eq!(r.v, w.v, "replica {k}, wall sphere at line {}", r.line);
            } else {
                let dv = (r.v - w.v).norm();
                assert!(dv > 0.0 && dv < 1e-4, "replica {k}, line {}: {dv}", r.line);
            }
        }
    }
    // merged again with the same starts: the same table; with other starts: refused
    let csv = merged(&a);
    let merge = |first: &str, second: &str| {
        verdem(&[
            "ensemble",
            CASE,
            "--starts",
            first,
            second,
            "--merge",
            "--out",
            a.to_str().unwrap(),
        ])
    };
    let again = merge(STARTS[0], STARTS[1]);
    assert!(
        again.status.success(),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    assert_eq!(merged(&a), csv);
    let swapped = merge(STARTS[1], STARTS[0]);
    let err = String::from_utf8_lossy(&swapped.stderr);
    assert!(!swapped.status.success(), "merged with swapped starts");
    assert!(
        err.contains("replica 0 started from ")
            && err.contains(STARTS[0].rsplit('/').next().unwrap())
            && err.contains("another ensemble's replica"),
        "{err}"
    );
    // without a perturbation, replica K is exactly a plain run from its start file
    let b = dir.path().join("b");
    starts_ensemble(&b, "local", &["--perturbation", "0"]);
    for (k, start) in STARTS.iter().enumerate() {
        let k = k as u64;
        let (first, want) = first_save_and_start(&b, k, start);
        for (r, w) in first.rows.iter().zip(&want.rows) {
            assert_eq!((r.x, r.v), (w.x, w.v), "replica {k}, line {}", r.line);
        }
        assert_eq!(record_field(&b, k, "hash"), hash_from(start, 1000));
    }
}

#[test]
fn bad_starts_are_refused_before_any_replica_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    refused(
        &[
            "ensemble",
            CASE,
            "--starts",
            STARTS[0],
            STARTS[1],
            "--replicas",
            "3",
            "--out",
            o,
        ],
        &out,
        "--replicas 3 but --starts names 2 files",
    );
    refused(
        &[
            "ensemble", CASE, "--starts", STARTS[0], STARTS[1], "--init", STARTS[0], "--out", o,
        ],
        &out,
        "--starts and --init",
    );
    let missing = dir.path().join("missing.data");
    refused(
        &[
            "ensemble",
            CASE,
            "--starts",
            STARTS[0],
            missing.to_str().unwrap(),
            "--out",
            o,
        ],
        &out,
        &format!("{}: cannot read", missing.display()),
    );
    // a start that does not parse: its file, line and field
    let bad = dir.path().join("bad.data");
    let text = std::fs::read_to_string(root().join(STARTS[1])).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[5] = "1 2 x 0 0 0 0.5 0 0 0 0 0 0 0";
    std::fs::write(&bad, lines.join("\n")).unwrap();
    refused(
        &[
            "ensemble",
            CASE,
            "--starts",
            STARTS[0],
            bad.to_str().unwrap(),
            "--out",
            o,
        ],
        &out,
        &format!("{}:6: column 3 (rz)", bad.display()),
    );
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

#[test]
fn slurm_replicas_start_from_their_own_files_as_local_ones() {
    if !slurm_enabled() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let local = dir.path().join("local");
    let slurm = dir.path().join("slurm");
    starts_ensemble(&local, "local", &[]);
    starts_ensemble(&slurm, "slurm", &[]);
    let script = std::fs::read_to_string(slurm.join("shear_flow_steady.sbatch")).unwrap();
    assert!(script.contains(" --starts "), "{script}");
    for k in 0..2 {
        for field in ["start_file", "start_sha256", "start_hash", "hash"] {
            assert_eq!(
                record_field(&slurm, k, field),
                record_field(&local, k, field),
                "replica {k}: {field}"
            );
        }
    }
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

/// Replicas whose values are finite but too large for their mean and spread: the merge is
/// refused, naming the field and the number, rather than written with infinities.
#[test]
fn a_merge_that_overflows_is_refused() {
    use verdem::analysis::cg::{table::Table, COLUMNS};
    let flat = |value: f64| {
        let z: Vec<f64> = (0..10).map(|k| 0.5 + k as f64).collect();
        Table {
            mean: z.iter().map(|_| vec![value; COLUMNS.len()]).collect(),
            se: z.iter().map(|_| vec![0.1; COLUMNS.len()]).collect(),
            z,
        }
    };
    let e = verdem::analysis::ensemble::merge(&[flat(1e308), flat(1.5e308)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the merge of 2 replicas: nu at z = 0.5 is inf, not a finite number"),
        "{e}"
    );
    assert!(verdem::analysis::ensemble::merge(&[flat(1e100), flat(1.5e100)]).is_ok());
}
