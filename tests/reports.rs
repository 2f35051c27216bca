//! `--junit FILE` and `--json FILE`: the verification table written for a CI system, read back
//! by independent readers — the JUnit XML by Python's junitparser (in the virtual environment
//! `ci/test.sh` makes; its Python is verdem's, `verdem::python::python`), the JSON by serde_json
//! and by Python's json — and compared with the text table the same run printed.

mod common;

use std::path::Path;
use std::process::Command;

use serde_json::Value;

/// Reads the JUnit report argv[1] with junitparser and the JSON report argv[2] with json, and
/// prints what each holds as one JSON object: the suites' counts and every case's status,
/// classname, name and message.
const READ: &str = r#"
import json, sys
import junitparser
xml = junitparser.JUnitXml.fromfile(sys.argv[1])
suites = []
for suite in xml:
    cases = []
    for case in suite:
        results = list(case.result)
        assert len(results) <= 1, results
        status = "passed"
        message = None
        if results:
            r = results[0]
            if isinstance(r, junitparser.Failure):
                status = "failed"
            elif isinstance(r, junitparser.Skipped):
                status = "skipped"
            else:
                status = type(r).__name__
            message = r.message
        cases.append([status, case.classname, case.name, message])
    suites.append({"name": suite.name, "tests": suite.tests, "failures": suite.failures,
                   "errors": suite.errors, "skipped": suite.skipped, "cases": cases})
with open(sys.argv[2]) as f:
    table = json.load(f)
print(json.dumps({"junit": suites, "json": table}))
"#;

/// What junitparser read from `xml` and Python's json from `json`.
fn python_reads(xml: &Path, json: &Path) -> Value {
    let python = verdem::python::python();
    let o = Command::new(&python.program)
        .args(["-c", READ])
        .arg(xml)
        .arg(json)
        .output()
        .unwrap_or_else(|e| panic!("{python}: {e}"));
    assert!(
        o.status.success(),
        "{python}: {} (these tests read the JUnit reports with junitparser: `bash ci/test.sh` \
         makes the virtual environment target/venv from ci/requirements.txt, or `python3 -m \
         venv VENV && VENV/bin/pip install junitparser==5.0.3` and VERDEM_PYTHON=VENV/bin/python)",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

/// `verdem verify ARGS --junit --json` in a scratch folder: exit code, standard output, the
/// JSON report read with serde_json, and both reports as Python read them.
fn verify(args: &[&str]) -> (Option<i32>, String, Value, Value) {
    let dir = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command
        .arg("verify")
        .args(args)
        .arg("--cases")
        .arg(common::root().join("cases/verify"))
        .arg("--out")
        .arg(dir.path().join("out"));
    reports(command, dir.path())
}

/// `command` run with `--junit` and `--json` files in `dir`: as [`verify`].
fn reports(mut command: Command, dir: &Path) -> (Option<i32>, String, Value, Value) {
    let (xml, json) = (dir.join("r.xml"), dir.join("r.json"));
    let run = command
        .arg("--junit")
        .arg(&xml)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let table: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let python = python_reads(&xml, &json);
    (run.status.code(), stdout, table, python)
}

/// The table's rows (`case quantity … result`) as (line, result word), header and summary
/// excluded; an ERROR row's indented message lines are not rows.
fn text_rows(stdout: &str, first: &str) -> Vec<(String, String)> {
    stdout
        .lines()
        .filter(|l| l.starts_with(first))
        .map(|l| {
            (
                l.to_string(),
                l.split_whitespace().last().unwrap().to_string(),
            )
        })
        .collect()
}

/// The JSON, junitparser's and the verification table's rows agree one for one, and so do the
/// counts with the table's summary line.
fn same_rows(stdout: &str, first: &str, table: &Value, python: &Value) {
    let rows = text_rows(stdout, first);
    same_cases(&rows, "verdem verify", table, python);
    let cases = table["cases"].as_array().unwrap();
    let count = |s: &str| cases.iter().filter(|c| c["status"] == s).count();
    for ((line, _), c) in rows.iter().zip(cases) {
        // the row's case and quantity begin the table's line
        assert!(
            line.starts_with(c["group"].as_str().unwrap()),
            "{line}\n{c}"
        );
        assert!(line.contains(c["name"].as_str().unwrap()), "{line}\n{c}");
    }
    // the summary line counts the same
    let summary = format!("{} passed, {} failed", count("passed"), count("failed"));
    assert!(stdout.contains(&summary), "{summary}\n{stdout}");
}

/// The JSON's and junitparser's cases of the suite `suite_name` agree one for one with the
/// command's text `rows` (line, result word), and so do the counts.
fn same_cases(rows: &[(String, String)], suite_name: &str, table: &Value, python: &Value) {
    let cases = table["cases"].as_array().unwrap();
    assert_eq!(cases.len(), rows.len(), "{rows:?}");
    assert_eq!(table["tests"], rows.len());
    // Python's json reads the same table
    assert_eq!(&python["json"], table);
    let suites = python["junit"].as_array().unwrap();
    assert_eq!(suites.len(), 1, "{python}");
    let suite = &suites[0];
    assert_eq!(suite["name"], suite_name);
    for key in ["tests", "failures", "skipped"] {
        assert_eq!(suite[key], table[key], "{key}");
    }
    assert_eq!(suite["errors"], 0);
    let xml_cases = suite["cases"].as_array().unwrap();
    assert_eq!(xml_cases.len(), cases.len());
    let count = |s: &str| cases.iter().filter(|c| c["status"] == s).count();
    for ((line, word), (c, x)) in rows.iter().zip(cases.iter().zip(xml_cases)) {
        assert_eq!(c["result"], word.as_str(), "{line}");
        let status = match word.as_str() {
            "PASS" => "passed",
            "FAIL" | "ERROR" => "failed",
            _ => "skipped",
        };
        assert_eq!(c["status"], status, "{line}");
        // junitparser's classname, name, status and message are the JSON's
        assert_eq!(x[0], c["status"], "{x}");
        assert_eq!(x[1], c["group"], "{x}");
        assert_eq!(x[2], c["name"], "{x}");
        if status == "passed" {
            assert!(x[3].is_null(), "{x}");
        } else {
            assert_eq!(x[3], c["message"], "{x}");
        }
    }
    assert_eq!(table["passed"], count("passed"));
    assert_eq!(table["failures"], count("failed"));
    assert_eq!(table["skipped"], count("skipped"));
}

/// The expected, measured and tolerance of a message `expected E, measured M, tolerance T
/// (absolute)…`, read back to numbers.
fn said(message: &str) -> [f64; 3] {
    let numbers = message
        .split(" (absolute)")
        .next()
        .unwrap()
        .split(", ")
        .map(|part| {
            let (_, number) = part.split_once(' ').unwrap();
            number
                .parse::<f64>()
                .unwrap_or_else(|e| panic!("{message}: {e}"))
        })
        .collect::<Vec<_>>();
    numbers.try_into().unwrap()
}

/// verdem's own objectivity rows: every convention's law, the peers' known defects FAIL*.
#[test]
fn verify_writes_its_table_with_the_fail_star_rows_skipped() {
    let (status, stdout, table, python) = verify(&["--only", "objectivity"]);
    assert_eq!(status, Some(0), "{stdout}");
    same_rows(&stdout, "objectivity", &table, &python);
    let cases = table["cases"].as_array().unwrap();
    assert!(table["failures"] == 0 && table["passed"].as_u64() > Some(0));
    let skipped: Vec<_> = cases.iter().filter(|c| c["status"] == "skipped").collect();
    assert!(!skipped.is_empty(), "{table}");
    for c in skipped {
        assert_eq!(c["result"], "FAIL*");
        let m = c["message"].as_str().unwrap();
        assert!(m.contains("known defect of a peer convention"), "{m}");
    }
    // the numbers are the row's, and the message says them
    for c in cases {
        assert_eq!(c["limit"], "absolute", "{c}");
        let m = c["message"].as_str().unwrap();
        let said = said(m);
        let numbers = [&c["expected"], &c["measured"], &c["tolerance"]].map(|v| v.as_f64());
        assert_eq!(said.map(Some), numbers, "{m}");
    }
}

/// A law with a defect fails rows (exit status 1, as without the reports): they are failures
/// whose message holds expected, measured and tolerance; a program that crashes gets a failing
/// ERROR row whose message is the error.
#[test]
fn verify_code_failures_are_junit_failures_with_their_numbers() {
    let law = |script: &str, args: &str| {
        format!(
            "{} {} {args}",
            verdem::python::python().program.display(),
            common::root().join("tests/code").join(script).display()
        )
    };
    let cmd = law("contact_law.py", "--defect rotation");
    let (status, stdout, table, python) = verify(&[
        "--code",
        &cmd,
        "--code-name",
        "law",
        "--only",
        "objectivity",
    ]);
    assert_eq!(status, Some(1), "{stdout}");
    same_rows(&stdout, "objectivity", &table, &python);
    let failed: Vec<_> = table["cases"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["status"] == "failed")
        .collect();
    assert!(!failed.is_empty(), "{table}");
    for c in failed {
        let m = c["message"].as_str().unwrap();
        let t = c["tolerance"].as_f64().unwrap();
        let v = c["measured"].as_f64().unwrap();
        assert!(v.abs() > t, "{c}");
        assert!(m.ends_with(" (absolute)"), "{m}");
        assert_eq!(said(m), [0.0, v, t], "{m}");
    }
    let (status, stdout, table, python) = verify(&[
        "--code",
        &law("faulty.py", "crash"),
        "--only",
        "load-unload",
    ]);
    assert_eq!(status, Some(1), "{stdout}");
    same_rows(&stdout, "tangential", &table, &python);
    let error = &table["cases"][0];
    assert_eq!(error["result"], "ERROR", "{table}");
    assert!(error["measured"].is_null() && error["expected"].is_null());
    let m = error["message"].as_str().unwrap();
    assert!(
        m.starts_with("could not be measured: ") && m.contains("RuntimeError: the law diverged"),
        "{m}"
    );
}

/// The lines of a checks report (`cg`'s, `run`'s): (the line after its word, the word `PASS`,
/// `FAIL` or `info`).
fn check_lines(stdout: &str) -> Vec<(String, String)> {
    stdout
        .lines()
        .filter_map(|l| {
            let (word, rest) = l.split_at_checked(6)?;
            let word = word.trim_end();
            ["PASS", "FAIL", "info"]
                .contains(&word)
                .then(|| (rest.to_string(), word.to_string()))
        })
        .collect()
}

/// `verdem run` writes the checks it prints: the saves' profiles and ledgers, the in-run
/// profiles' and the core means of the two beside each other, in that order; its exit status
/// stays 0 with failing checks.
#[test]
fn run_writes_its_checks_of_saves_and_in_run_profiles() {
    let dir = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command
        .arg("run")
        .arg(common::root().join("cases/shear_flow_quick.toml"))
        .arg("--init")
        .arg(common::data("states/mercury_t143.85.data"))
        .args([
            "--steps",
            "4000",
            "--save-every",
            "500",
            "--inrun-every",
            "10",
            "--quiet",
            "--out",
        ])
        .arg(dir.path().join("out"));
    let (status, stdout, table, python) = reports(command, dir.path());
    assert_eq!(status, Some(0), "{stdout}");
    let rows = check_lines(&stdout);
    same_cases(&rows, "verdem run", &table, &python);
    let groups: Vec<&str> = table["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["group"].as_str().unwrap())
        .collect();
    let mut order = groups.clone();
    order.dedup();
    assert_eq!(order, ["saves", "in-run", "saves vs in-run"], "{groups:?}");
    // the six core means compared
    assert_eq!(
        groups.iter().filter(|g| **g == "saves vs in-run").count(),
        6
    );
    assert!(table["failures"].as_u64() > Some(0), "{table}");
}

/// `verdem cg` writes the checks it prints (`PASS  QUANTITY: …`), a FAIL as a failure and an
/// info line as a skipped case, without changing its exit status (the checks are a report).
#[test]
fn cg_writes_its_checks() {
    let case = common::quick_case();
    let dir = tempfile::tempdir().unwrap();
    let mut e = common::engine(
        &case,
        Some(&common::data("states/mercury_t143.85.data")),
        Default::default(),
    );
    common::run_with_saves(e.as_mut(), dir.path(), "s", 2000, 500);
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command.arg("cg").arg(dir.path().join("s"));
    let (status, stdout, table, python) = reports(command, dir.path());
    assert_eq!(status, Some(0), "{stdout}");
    // the check lines: the word, two spaces, `QUANTITY: MEASURED (expected EXPECTED)`
    let rows = check_lines(&stdout);
    same_cases(&rows, "verdem cg", &table, &python);
    for ((line, _), c) in rows.iter().zip(table["cases"].as_array().unwrap()) {
        // the check's quantity begins its line, and its measurement in words is the message's
        let name = c["name"].as_str().unwrap();
        let measured = line
            .strip_prefix(&format!("{name}: "))
            .unwrap_or_else(|| panic!("{line}\n{c}"));
        assert_eq!(c["group"], "verdem cg");
        let measured = measured.split(" (expected ").next().unwrap();
        assert!(
            c["message"].as_str().unwrap().contains(measured),
            "{line}\n{c}"
        );
    }
    let cases = table["cases"].as_array().unwrap();
    let mass = cases
        .iter()
        .find(|c| c["name"].as_str().unwrap().starts_with("mass"));
    assert_eq!(mass.unwrap()["status"], "passed", "{table}");
    // the ledgers' checks, printed after the profiles', are cases too
    assert!(cases
        .iter()
        .any(|c| c["name"].as_str().unwrap().starts_with("energy ledger")));
    assert!(table["tests"].as_u64() > Some(3), "{table}");
}
