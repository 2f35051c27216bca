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
    let (xml, json) = (dir.path().join("r.xml"), dir.path().join("r.json"));
    let run = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("verify")
        .args(args)
        .arg("--cases")
        .arg(common::root().join("cases/verify"))
        .arg("--out")
        .arg(dir.path().join("out"))
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

/// The JSON, junitparser's and the text table's rows agree one for one, and so do the counts.
fn same_rows(stdout: &str, first: &str, table: &Value, python: &Value) {
    let rows = text_rows(stdout, first);
    let cases = table["cases"].as_array().unwrap();
    assert_eq!(cases.len(), rows.len(), "{stdout}");
    assert_eq!(table["tests"], rows.len());
    // Python's json reads the same table
    assert_eq!(&python["json"], table);
    let suites = python["junit"].as_array().unwrap();
    assert_eq!(suites.len(), 1, "{python}");
    let suite = &suites[0];
    assert_eq!(suite["name"], "verdem verify");
    for key in ["tests", "failures", "skipped"] {
        assert_eq!(suite[key], table[key], "{key}");
    }
    assert_eq!(suite["errors"], 0);
    let xml_cases = suite["cases"].as_array().unwrap();
    assert_eq!(xml_cases.len(), cases.len());
    let count = |s: &str| cases.iter().filter(|c| c["status"] == s).count();
    for ((line, word), (c, x)) in rows.iter().zip(cases.iter().zip(xml_cases)) {
        // the row's case and quantity begin the table's line, its word ends it
        assert!(
            line.starts_with(c["group"].as_str().unwrap()),
            "{line}\n{c}"
        );
        assert!(line.contains(c["name"].as_str().unwrap()), "{line}\n{c}");
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
    // the summary line counts the same
    let summary = format!("{} passed, {} failed", count("passed"), count("failed"));
    assert!(stdout.contains(&summary), "{summary}\n{stdout}");
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
