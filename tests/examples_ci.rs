//! examples/ci: the contact-law wrappers a user copies (Python, and C++ built with the system
//! `g++`) pass `verdem verify --code`, and the GitHub Actions workflow and GitLab CI job that
//! run them are valid YAML holding the steps that build verdem, judge the wrapper and publish
//! its reports.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_yaml::Value;

fn examples() -> PathBuf {
    common::root().join("examples/ci")
}

/// The table rows of `verdem verify --code CMD --convention objective [--only ONLY]`, run in
/// `dir` as from a user's repository, for the program named `name`; each ends in its result.
/// Checks that the command exited with 0 and that its summary counts every row as passed.
fn verify(cmd: &str, name: &str, only: Option<&str>, dir: &Path) -> Vec<String> {
    let mut verify = Command::new(env!("CARGO_BIN_EXE_verdem"));
    verify
        .current_dir(dir)
        .args(["verify", "--code", cmd, "--convention", "objective"])
        .arg("--cases")
        .arg(common::root().join("cases/verify"))
        .arg("--out")
        .arg(dir.join("out"));
    if let Some(only) = only {
        verify.args(["--only", only]);
    }
    let run = verify.output().unwrap();
    let text = String::from_utf8_lossy(&run.stdout);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{text}{err}");
    let rows: Vec<String> = text
        .lines()
        .filter(|l| l.contains(&format!(" code:{name} ")))
        .map(String::from)
        .collect();
    assert!(
        text.contains(&format!("{} passed, 0 failed", rows.len())),
        "{text}"
    );
    rows
}

/// Every row of `rows` passed, and there are `count` of them.
fn all_pass(rows: &[String], count: usize) {
    assert_eq!(rows.len(), count, "{rows:#?}");
    assert!(rows.iter().all(|r| r.ends_with("  PASS")), "{rows:#?}");
}

/// The Python wrapper, run as `python3 law.py` (standard library only). Objectivity's three
/// rotations of 1e5 rows each take it 20 s; the C++ wrapper, the same law, runs them below.
#[test]
fn the_python_wrapper_passes_verify_code() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = format!("python3 {}", examples().join("python/law.py").display());
    // tangential: load-unload 9, coulomb limit 2, contact loss 4, dashpots 2
    for (only, count) in [("ratchet", 4), ("tangential", 17), ("mcnamara", 4)] {
        all_pass(&verify(&cmd, "law.py", Some(only), dir.path()), count);
    }
}

/// The C++ wrapper, built with the system compiler as its header says, passes every row.
#[test]
fn the_cpp_wrapper_built_with_gxx_passes_verify_code() {
    let dir = tempfile::tempdir().unwrap();
    let law = dir.path().join("law");
    let source = examples().join("cpp/law.cpp");
    let header = std::fs::read_to_string(&source).unwrap();
    assert!(header.contains("g++ -std=c++17 -O2 -o law law.cpp"));
    let build = Command::new("g++")
        .args(["-std=c++17", "-O2", "-o"])
        .arg(&law)
        .arg(&source)
        .output()
        .unwrap();
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let rows = verify(&law.display().to_string(), "law", None, dir.path());
    // objectivity, ratchet, the four tangential histories, McNamara
    all_pass(&rows, 3 * 3 + 2 * 2 + 9 + 2 + 4 + 2 + 2 * 2);
}

fn yaml(file: &str) -> Value {
    let text = std::fs::read_to_string(examples().join(file)).unwrap();
    serde_yaml::from_str(&text).unwrap_or_else(|e| panic!("examples/ci/{file}: {e}"))
}

fn text(v: &Value) -> &str {
    v.as_str().unwrap_or_default()
}

/// The pipelines' `verdem verify` command: it judges `$LAW` against verdem's cases, writes
/// both reports, and every option it gives is one of `verdem verify`'s (`--junit` and `--json`
/// are added by issue 50's first item, on their own branch).
fn check_verify_command(cmd: &str) {
    for part in [
        ".verdem/target/release/verdem verify",
        "--code \"$LAW\"",
        "--convention \"$CONVENTION\"",
        "--cases .verdem/cases/verify",
        "--junit verify.xml",
        "--json verify.json",
    ] {
        assert!(cmd.contains(part), "{part:?} is not in {cmd:?}");
    }
    let help = common::verdem_ok(["verify", "--help"]).stdout;
    let help = String::from_utf8_lossy(&help);
    for flag in cmd.split_whitespace().filter(|w| w.starts_with("--")) {
        assert!(
            help.contains(&format!("{flag} ")) || ["--junit", "--json"].contains(&flag),
            "{flag} is not an option of verdem verify:\n{help}"
        );
    }
}

/// The pipelines' variables: the verdem revision and the law, the example's own wrapper.
fn check_variables(vars: &Value) {
    assert!(!text(&vars["VERDEM_REV"]).is_empty(), "{vars:?}");
    assert_eq!(text(&vars["CONVENTION"]), "objective");
    let law = text(&vars["LAW"]);
    let script = law.strip_prefix("python3 ").unwrap();
    assert!(common::root().join(script).is_file(), "{law}");
}

#[test]
fn the_github_actions_workflow_builds_verdem_judges_the_law_and_publishes_the_reports() {
    let doc = yaml("github-actions.yml");
    check_variables(&doc["env"]);
    assert!(["push", "pull_request"]
        .iter()
        .all(|event| doc["on"].get(event).is_some()));
    let steps = doc["jobs"]["verify"]["steps"].as_sequence().unwrap();
    let uses = |prefix: &str| {
        steps
            .iter()
            .find(|s| text(&s["uses"]).starts_with(prefix))
            .unwrap_or_else(|| panic!("no step uses {prefix}"))
    };
    let run = |part: &str| {
        steps
            .iter()
            .map(|s| text(&s["run"]))
            .find(|r| r.contains(part))
            .unwrap_or_else(|| panic!("no step runs {part}"))
    };
    // verdem checked out at the pinned revision, built
    let verdem = steps
        .iter()
        .find(|s| text(&s["with"]["path"]) == ".verdem")
        .unwrap();
    assert!(text(&verdem["uses"]).starts_with("actions/checkout@"));
    assert_eq!(text(&verdem["with"]["ref"]), "${{ env.VERDEM_REV }}");
    run("cargo build --release --manifest-path .verdem/Cargo.toml");
    check_verify_command(run("verdem verify"));
    // the reports published even when the verification failed
    let report = uses("mikepenz/action-junit-report@");
    assert_eq!(text(&report["with"]["report_paths"]), "verify.xml");
    assert_eq!(text(&report["if"]), "${{ !cancelled() }}");
    let artifact = uses("actions/upload-artifact@");
    assert!(text(&artifact["with"]["path"])
        .lines()
        .any(|p| p == "verify.json"));
    assert_eq!(text(&artifact["if"]), "${{ !cancelled() }}");
    assert_eq!(
        text(&doc["jobs"]["verify"]["permissions"]["checks"]),
        "write"
    );
}

#[test]
fn the_gitlab_ci_job_builds_verdem_judges_the_law_and_publishes_the_junit_report() {
    let doc = yaml("gitlab-ci.yml");
    check_variables(&doc["variables"]);
    let job = &doc["verdem-verify"];
    let lines = |key: &str| -> Vec<&str> {
        job[key]
            .as_sequence()
            .unwrap_or_else(|| panic!("no {key}"))
            .iter()
            .map(text)
            .collect()
    };
    let before = lines("before_script");
    assert!(before.iter().any(|l| l.contains("\"$VERDEM_REV\"")));
    assert!(before.contains(&"cargo build --release --manifest-path .verdem/Cargo.toml"));
    let script = lines("script");
    let verify = script.iter().find(|l| l.contains("verdem verify")).unwrap();
    check_verify_command(verify);
    // the reports kept even when the verification failed; the JUnit one shown in the MR
    let artifacts = &job["artifacts"];
    assert_eq!(text(&artifacts["when"]), "always");
    assert_eq!(text(&artifacts["reports"]["junit"]), "verify.xml");
    assert!(artifacts["paths"]
        .as_sequence()
        .unwrap()
        .iter()
        .any(|p| text(p) == "verify.json"));
}
