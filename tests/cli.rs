//! The command line: bad values are refused with the option named, before any work; what a
//! run prints and writes at its edges (a resume, a scene other than the shear cell).

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
/// end of a run: a two-sphere collision has no mid-plane, walls or kinetic theory to check.
#[test]
fn a_run_of_another_scene_writes_no_shear_profiles() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let case = "cases/verify/binary_collision.toml";
    let args = ["run", case, "--steps", "10", "--quiet", "--out", out];
    let Outcome { ok, out: text, .. } = verdem(&args);
    assert!(ok, "{text}");
    assert!(text.contains("profiles: none"), "{text}");
    assert!(!text.contains("PASS") && !text.contains("FAIL"), "{text}");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n.ends_with(".data.0000")), "{names:?}");
    assert!(!names.iter().any(|n| n.contains("profiles")), "{names:?}");
}
