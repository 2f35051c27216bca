//! The command line: bad values are refused with the option named, before any work; what a
//! run prints and writes at its edges (a resume, a scene other than the shear cell).

mod common;

use std::process::Command;

/// What a run of `verdem` ended with.
struct Outcome {
    ok: bool,
    out: String,
    err: String,
}

/// Runs `verdem ARGS`.
fn verdem(args: &[&str]) -> Outcome {
    let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .args(args)
        .output()
        .expect("verdem runs");
    Outcome {
        ok: o.status.success(),
        out: String::from_utf8(o.stdout).unwrap(),
        err: String::from_utf8(o.stderr).unwrap(),
    }
}

#[test]
fn out_of_range_options_are_refused_with_the_option_named() {
    let refused = [
        ("run cases/shear_flow_quick.toml --threads 0", "1 or more"),
        (
            "run cases/shear_flow_quick.toml --save-every 0",
            "1 or more",
        ),
        (
            "run cases/shear_flow_quick.toml --skin -1",
            "positive and finite",
        ),
        (
            "run cases/shear_flow_quick.toml --skin nan",
            "positive and finite",
        ),
        (
            "hash cases/shear_flow_quick.toml --steps 1 --cell inf",
            "finite",
        ),
        ("bench --threads 1,0", "1 or more"),
        ("bench --rounds 0", "1 or more"),
        ("cg out/none --slices 0", "1 or more"),
        ("cg out/none --width 0", "positive"),
        ("tradeoff --time -3", "positive"),
        ("cross lammps --np 0", "1 or more"),
    ];
    for (line, why) in refused {
        let args: Vec<&str> = line.split(' ').collect();
        // clap names the option as `'--save-every <SAVE_EVERY>'`
        let flag = args.iter().rev().find(|a| a.starts_with("--")).unwrap();
        let option = format!("'{flag} <{}>'", flag[2..].replace('-', "_").to_uppercase());
        let Outcome { ok, err, .. } = verdem(&args);
        assert!(!ok, "{line} was accepted");
        assert!(
            err.contains("invalid value") && err.contains(&option) && err.contains(why),
            "{line}: {err}"
        );
    }
}

/// The smallest allowed values pass the parser (the run then ends at once).
#[test]
fn the_smallest_allowed_values_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let args = [
        "run",
        "cases/shear_flow_quick.toml",
        "--steps",
        "2",
        "--threads",
        "1",
        "--save-every",
        "1",
        "--cell",
        "0",
        "--quiet",
        "--out",
        out,
    ];
    let Outcome { ok, err, .. } = verdem(&args);
    assert!(ok, "{err}");
    assert!(dir.path().join("shear_flow_quick.data.0002").exists());
}

/// Resuming a checkpoint with an end before it is refused, naming both steps; ending at it runs
/// nothing and says so, without a rate.
#[test]
fn a_resume_that_would_end_before_its_checkpoint_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let case = "cases/shear_flow_quick.toml";
    let common = ["--save-every", "100", "--quiet", "--out", out];
    let Outcome { ok, err, .. } = verdem(
        &[
            &["run", case, "--steps", "4", "--checkpoint-every", "4"],
            &common[..],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let ck = dir.path().join("shear_flow_quick.checkpoint");
    let ck = ck.to_str().unwrap();
    let Outcome { ok, err, .. } =
        verdem(&[&["run", case, "--steps", "2", "--resume", ck], &common[..]].concat());
    assert!(!ok);
    assert!(
        err.contains("the run would end at step 2 (--steps), before the checkpoint's step 4"),
        "{err}"
    );
    let at_it = verdem(&[&["run", case, "--steps", "4", "--resume", ck], &common[..]].concat());
    assert!(
        at_it.ok && at_it.out.contains("rate: no steps run"),
        "{}",
        at_it.out
    );
}

/// A resume that would number its saves differently from those already in the folder is
/// refused, naming the diagnostics row and the interval that wrote them.
#[test]
fn a_resume_with_another_save_interval_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let case = "cases/shear_flow_quick.toml";
    let first = ["run", case, "--steps", "4", "--save-every", "2"];
    let Outcome { ok, err, .. } = verdem(
        &[
            &first[..],
            &["--checkpoint-every", "4", "--quiet", "--out", out],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let ck = dir.path().join("shear_flow_quick.checkpoint");
    let resume = [
        "run",
        case,
        "--steps",
        "8",
        "--resume",
        ck.to_str().unwrap(),
    ];
    let again = |every: &str| {
        verdem(
            &[
                &resume[..],
                &["--save-every", every, "--quiet", "--out", out],
            ]
            .concat(),
        )
    };
    let Outcome { ok, err, .. } = again("1");
    assert!(!ok);
    assert!(
        err.contains("shear_flow_quick.diagnostics.csv:3: save 1 is at step 2, but this run saves every 1 steps; resume with --save-every 2"),
        "{err}"
    );
    let Outcome { ok, err, .. } = again("2");
    assert!(ok, "{err}");
    assert!(dir.path().join("shear_flow_quick.data.0004").exists());
}

#[test]
fn a_verify_filter_that_matches_nothing_is_an_error() {
    let Outcome { ok, err, .. } = verdem(&["verify", "--only", "no such case"]);
    assert!(!ok);
    assert!(
        err.contains("no verification row's case contains it"),
        "{err}"
    );
}

/// Only the bumpy-shear scene is coarse-grained into the benchmark's profiles and checks at the
/// end of a run, and only its rate is projected to the benchmark's 2e8 steps: a two-sphere
/// collision has no mid-plane, walls or kinetic theory to check.
#[test]
fn a_run_of_another_scene_writes_no_shear_profiles() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let case = "cases/verify/binary_collision.toml";
    let args = ["run", case, "--steps", "10", "--quiet", "--out", out];
    let Outcome { ok, out: text, .. } = verdem(&args);
    assert!(ok, "{text}");
    assert!(text.contains("profiles: none"), "{text}");
    assert!(!text.contains("2e8-step benchmark"), "{text}");
    assert!(!text.contains("PASS") && !text.contains("FAIL"), "{text}");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n.ends_with(".data.0000")), "{names:?}");
    assert!(!names.iter().any(|n| n.contains("profiles")), "{names:?}");
}

/// A run stopped by SIGTERM (a batch scheduler's time limit) or SIGINT (Ctrl-C) writes a
/// checkpoint where it stops, keeps its saves, exits with 130 and prints the command that
/// continues it; that command ends in the bits and files of a run never stopped.
#[test]
fn a_run_stopped_by_a_signal_continues_bit_for_bit() {
    let case = "cases/shear_flow_quick.toml";
    let state = "data/states/mercury_t143.85.data";
    let run_args = |out: &str| {
        [
            "run",
            case,
            "--init",
            state,
            "--steps",
            "40000",
            "--save-every",
            "1000",
            "--threads",
            "1",
            "--quiet",
            "--out",
            out,
        ]
        .map(String::from)
    };
    let stopped = tempfile::tempdir().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .args(run_args(stopped.path().to_str().unwrap()))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("verdem runs");
    let first_save = stopped.path().join("shear_flow_quick.data.0001");
    while !first_save.exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before its 1st save"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    // SAFETY: kill(2) with the pid of our own live child and a valid signal number.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let o = child.wait_with_output().unwrap();
    let text = String::from_utf8(o.stdout).unwrap();
    assert_eq!(o.status.code(), Some(130), "{text}");
    let step: u64 = text
        .split("interrupted at step ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no step in {text}"));
    // save 1 is at step 1000: the run stops there or at a later block's end, before its last
    assert!((1000..40000).contains(&step), "{text}");
    assert!(stopped.path().join("shear_flow_quick.checkpoint").exists());
    let continued = text
        .lines()
        .find_map(|l| l.strip_prefix("continue with: "))
        .unwrap_or_else(|| panic!("no command in {text}"));
    // The printed command starts with the program; its other words are plain paths here.
    let words: Vec<&str> = continued.split(' ').skip(1).collect();
    assert!(continued.contains("--resume"), "{continued}");
    let resumed = verdem(&words);
    assert!(resumed.ok, "{}", resumed.err);
    assert!(resumed.out.contains(&format!("resumed at step {step}")));
    assert!(resumed
        .out
        .contains("the full 2e8-step benchmark would take"));

    let straight_dir = tempfile::tempdir().unwrap();
    let straight_args = run_args(straight_dir.path().to_str().unwrap());
    let straight = verdem(&straight_args.each_ref().map(String::as_str));
    assert!(straight.ok, "{}", straight.err);
    let hash = |t: &str| {
        t.lines()
            .find(|l| l.starts_with("state hash:"))
            .map(String::from)
    };
    assert!(hash(&straight.out).is_some());
    assert_eq!(hash(&resumed.out), hash(&straight.out));
    for name in [
        "shear_flow_quick.data.0040",
        "shear_flow_quick.fstat.0003",
        "shear_flow_quick.profiles_inrun.csv",
        "shear_flow_quick.profiles_inrun_errors.csv",
    ] {
        let a = std::fs::read(stopped.path().join(name)).unwrap();
        let b = std::fs::read(straight_dir.path().join(name)).unwrap();
        assert!(a == b, "{name} differs");
    }
    let diagnostics = |d: &std::path::Path| {
        std::fs::read_to_string(d.join("shear_flow_quick.diagnostics.csv")).unwrap()
    };
    common::assert_resumed_diagnostics(
        &diagnostics(stopped.path()),
        &diagnostics(straight_dir.path()),
    );
}
