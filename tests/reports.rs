//! `--junit FILE` and `--json FILE`: the verification table written for a CI system, read back
//! by independent readers — the JUnit XML by Python's junitparser (in the virtual environment
//! `ci/test.sh` makes; its Python is verdem's, `verdem::python::python`), the JSON by serde_json
//! and by Python's json — and compared with the text table the same run printed: `verify`,
//! `run` and `cg`'s checks, `compare`'s profiles, `cross`'s saves, profiles and core means, and
//! `bench`'s goals.

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
    read_alike(suite_name, table, python);
    let xml_cases = python["junit"][0]["cases"].as_array().unwrap();
    let count = |s: &str| cases.iter().filter(|c| c["status"] == s).count();
    for ((line, word), c) in rows.iter().zip(cases) {
        assert_eq!(c["result"], word.as_str(), "{line}");
        let status = match word.as_str() {
            "PASS" => "passed",
            "FAIL" | "ERROR" => "failed",
            _ => "skipped",
        };
        assert_eq!(c["status"], status, "{line}");
    }
    assert_eq!(xml_cases.len(), cases.len());
    assert_eq!(table["passed"], count("passed"));
    assert_eq!(table["failures"], count("failed"));
    assert_eq!(table["skipped"], count("skipped"));
}

/// junitparser's suite `suite_name` and Python's json read what serde_json read in `table`:
/// the same counts, and case for case the same status, classname, name and message.
fn read_alike(suite_name: &str, table: &Value, python: &Value) {
    let cases = table["cases"].as_array().unwrap();
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
    for (c, x) in cases.iter().zip(xml_cases) {
        // junitparser's classname, name, status and message are the JSON's
        assert_eq!(x[0], c["status"], "{x}");
        assert_eq!(x[1], c["group"], "{x}");
        assert_eq!(x[2], c["name"], "{x}");
        if c["status"] == "passed" {
            assert!(x[3].is_null(), "{x}");
        } else {
            assert_eq!(x[3], c["message"], "{x}");
        }
    }
    assert_eq!(table["tests"], cases.len());
    assert_eq!(table["passed"], count("passed"));
    assert_eq!(table["failures"], count("failed"));
    assert_eq!(table["skipped"], count("skipped"));
}

/// The expected, measured and tolerance of a message `expected E, measured M, tolerance T
/// (absolute)…`, read back to numbers (M the measure at the motion's step where a refined row
/// goes on `M at dt; … at dt/2; …`).
fn said(message: &str) -> [f64; 3] {
    let numbers = message
        .split(" (absolute)")
        .next()
        .unwrap()
        .split(", ")
        .map(|part| {
            let (_, said) = part.split_once(' ').unwrap();
            let number = said.split(' ').next().unwrap();
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
        // A refined row's message gives its measures to seven digits (`M at dt; …`).
        let [expected, measured, tolerance] = said(m);
        assert_eq!([expected, tolerance], [0.0, t], "{m}");
        assert!((measured - v).abs() <= 5e-7 * v.abs(), "{m}");
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

/// A detail of the case `c` by name: its value (`None` for null).
fn detail(c: &Value, name: &str) -> Option<f64> {
    let d = c["details"].as_array().unwrap_or_else(|| panic!("{c}"));
    let found = d.iter().find(|d| d["name"] == name);
    found.unwrap_or_else(|| panic!("{name}: {c}"))["value"].as_f64()
}

/// `verdem compare` writes one case per table and profile, its χ²/dof the text table's, judged
/// below 3: the recorded cross-runs' vx against verdem's own is a failure (exit status 0, as
/// without the reports); tables without error bars are skipped with the reason, their χ² null.
#[test]
fn compare_writes_each_profile_of_each_table_and_fails_a_chi2_over_three() {
    let golden = |f: &str| common::root().join("golden").join(f);
    let reference = golden("peers/verdem.profiles.csv");
    let others = [
        golden("peers/lammps.profiles.csv"),
        golden("peers/verdem_as_lammps.profiles.csv"),
        golden("full_run/shear_flow.profiles.csv"),
    ];
    let dir = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command.arg("compare").arg(&reference).args(&others);
    let (status, stdout, table, python) = reports(command, dir.path());
    assert_eq!(status, Some(0), "{stdout}");
    read_alike("verdem compare", &table, &python);
    let cases = table["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 3 * 5, "{table}");
    // the text table's rows: the χ² columns of each table, in the order vx, nu, T, pressure,
    // shear, then their differences of the core means (in %)
    let fields = ["vx", "nu", "T", "pressure", "shear"];
    for (row, other) in others.iter().enumerate() {
        let label = other.display().to_string();
        let line = stdout
            .lines()
            .find(|l| l.starts_with(&format!("| {label} |")))
            .unwrap_or_else(|| panic!("{label}: {stdout}"));
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        for (f, field) in fields.iter().enumerate() {
            let c = &cases[5 * row + f];
            assert_eq!(c["group"], label.as_str());
            let reference = reference.display();
            assert_eq!(c["name"], format!("{field}: χ²/dof against {reference}"));
            let chi2 = c["measured"].as_f64().unwrap();
            assert_eq!(format!("{chi2:.2}"), cells[2 + f], "{line}\n{c}");
            assert_eq!(detail(c, "chi2_per_dof"), Some(chi2));
            let delta = detail(c, "relative_core_mean_difference").unwrap();
            assert_eq!(
                format!("{:+.2} %", 100.0 * delta),
                cells[7 + f],
                "{line}\n{c}"
            );
            let (word, status) = if chi2 < 3.0 {
                ("PASS", "passed")
            } else {
                ("FAIL", "failed")
            };
            assert_eq!((&c["result"], &c["status"]), (&word.into(), &status.into()));
            assert_eq!(c["expected"], 3.0);
            assert_eq!(c["limit"], "below");
            let m = c["message"].as_str().unwrap();
            let said = m
                .strip_prefix("expected below 3, measured ")
                .unwrap_or_else(|| panic!("{m}"));
            assert_eq!(said.parse::<f64>().unwrap(), chi2, "{m}");
            if *field == "vx" {
                let less = detail(c, "chi2_per_dof_less_offset").unwrap();
                assert_eq!(format!("{less:.2}"), cells[12], "{line}");
                let offset = detail(c, "offset").unwrap();
                assert_eq!(format!("{offset:+.2e}"), cells[13], "{line}");
            }
        }
    }
    // vx of the verdem-as-lammps and of the full run's tables: 3.32 and 4.03
    assert_eq!(table["failures"], 2, "{table}");
    // without error bars in either table a χ² is undefined: skipped, null, with the reason
    let bare = dir.path().join("bare.profiles.csv");
    let text = std::fs::read_to_string(&reference).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut zeroed = vec![header.join(",")];
    for line in lines {
        let row: Vec<&str> = line.split(',').collect();
        let row: Vec<&str> = row
            .iter()
            .zip(&header)
            .map(|(v, h)| if h.ends_with("_se") { "0" } else { v })
            .collect();
        zeroed.push(row.join(","));
    }
    std::fs::write(&bare, zeroed.join("\n") + "\n").unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command.arg("compare").arg(&bare).arg(&bare);
    let (status, stdout, table, python) = reports(command, dir.path());
    assert_eq!(status, Some(0), "{stdout}");
    read_alike("verdem compare", &table, &python);
    assert!(
        stdout.contains("χ² undefined: no error bars in either table"),
        "{stdout}"
    );
    let json = std::fs::read_to_string(dir.path().join("r.json")).unwrap();
    assert!(!json.contains("NaN") && !json.contains("inf"), "{json}");
    for c in table["cases"].as_array().unwrap() {
        assert_eq!(
            (&c["status"], &c["result"]),
            (&"skipped".into(), &"undefined".into())
        );
        assert!(c["measured"].is_null(), "{c}");
        let why = "no error bars in either table: without them no difference can be told from \
                   noise";
        assert_eq!(c["undefined"], why, "{c}");
        assert!(c["message"]
            .as_str()
            .unwrap()
            .ends_with(&format!("; skipped: {why}")));
        assert_eq!(detail(c, "chi2_per_dof"), None);
        assert_eq!(detail(c, "relative_core_mean_difference"), Some(0.0));
    }
}

/// `verdem cross lammps … --inrun` writes its saves (reported), its profiles (judged: the same
/// equations, χ² ≈ 0, passed) and its in-run core means, the peer against verdem in the peer's
/// convention judged by its interval; the numbers are the text tables'.
#[test]
fn cross_writes_its_saves_profiles_and_core_means() {
    let dir = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command
        .args(["cross", "lammps"])
        .arg(common::root().join("cases/shear_flow_quick.toml"))
        .arg("--from")
        .arg(common::data("states/mercury_t143.85.data"))
        .args(["--steps", "2000", "--every", "500", "--np", "1", "--inrun"])
        .args([
            "--inrun-every",
            "50",
            "--inrun-particle-every",
            "100",
            "--out",
        ])
        .arg(dir.path().join("out"));
    let (status, stdout, table, python) = reports(command, dir.path());
    assert_eq!(status, Some(0), "{stdout}");
    read_alike("verdem cross", &table, &python);
    let cases = table["cases"].as_array().unwrap();
    let of =
        |group: &str| -> Vec<&Value> { cases.iter().filter(|c| c["group"] == group).collect() };
    let saves = of("lmp saves");
    assert_eq!(saves.len(), 5, "{table}");
    for (k, c) in saves.iter().enumerate() {
        let step = 500 * k;
        assert_eq!(c["name"], format!("step {step}: largest |dx|"));
        assert_eq!(
            (&c["status"], &c["result"]),
            (&"skipped".into(), &"info".into())
        );
        let dx = c["measured"].as_f64().unwrap();
        assert_eq!(detail(c, "dx_max"), Some(dx));
        let row = format!(
            "| {step} | {dx:.3e} | {:.3e} |",
            detail(c, "dx_median").unwrap()
        );
        assert!(stdout.contains(&row), "{row}\n{stdout}");
    }
    let profiles = of("lmp profiles");
    assert_eq!(profiles.len(), 5, "{table}");
    let chi2: Vec<String> = profiles
        .iter()
        .map(|c| {
            let name = c["name"].as_str().unwrap();
            let field = name.strip_suffix(": χ²/dof against verdem").unwrap();
            assert_eq!(c["status"], "passed", "{c}");
            format!("{field} {:.2}", c["measured"].as_f64().unwrap())
        })
        .collect();
    let line = format!("chi2/dof against verdem (1 = noise): {}", chi2.join(", "));
    assert!(stdout.contains(&line), "{line}\n{stdout}");
    // three comparisons of seven core means each; only the same equations' are judged
    let judged = of("lmp vs verdem as lmp");
    assert_eq!(judged.len(), 7, "{table}");
    for group in [
        "lmp vs verdem (mercury)",
        "verdem as lmp vs verdem (mercury)",
    ] {
        for c in of(group) {
            assert_eq!(c["status"], "skipped", "{c}");
        }
    }
    for c in judged {
        let (delta, half) = (
            c["measured"].as_f64().unwrap(),
            c["tolerance"].as_f64().unwrap(),
        );
        assert_eq!(detail(c, "half_width_95"), Some(half));
        let m = c["message"].as_str().unwrap();
        let trusted = !c["result"].as_str().unwrap().contains("not trusted");
        match (trusted, delta.abs() <= half) {
            (true, true) => assert_eq!(c["status"], "passed", "{c}"),
            (true, false) => assert_eq!(c["status"], "failed", "{c}"),
            (false, _) => assert!(m.contains("skipped: errors not trusted"), "{c}"),
        }
        assert_eq!(said(m), [0.0, delta, half], "{m}");
    }
    assert_eq!(cases.len(), 5 + 5 + 3 * 7);
}

/// `verdem bench` writes the goals its table judges, each with the table's word and the
/// status it gives (met: passed, not met: failed, undecided: skipped), whatever the machine's
/// rates; its exit status stays 0.
#[test]
fn bench_writes_the_goals_its_table_judges() {
    let dir = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_verdem"));
    command
        .arg("bench")
        .arg(common::root().join("cases/shear_flow_quick.toml"))
        .arg("--from")
        .arg(common::data("states/mercury_t143.85.data"))
        .args(["--steps", "100", "--rounds", "6", "--peers", "", "--out"])
        .arg(dir.path().join("out"));
    let (status, stdout, table, python) = reports(command, dir.path());
    assert_eq!(status, Some(0), "{stdout}");
    read_alike("verdem bench", &table, &python);
    let cases = table["cases"].as_array().unwrap();
    let names: Vec<&str> = cases.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "verdem 2 threads / 1 thread",
            "verdem 2 threads / the lockstep pair"
        ]
    );
    for (c, goal) in cases.iter().zip([1.7, 0.95]) {
        let word = c["result"].as_str().unwrap();
        // the table's verdict of the goal, in its words
        let judged = format!("goal ≥ {goal}: {word} (");
        assert!(stdout.contains(&judged), "{judged}\n{stdout}");
        let status = match word {
            "met" => "passed",
            "not met" => "failed",
            _ => "skipped",
        };
        assert_eq!(c["status"], status, "{c}");
        assert_eq!(
            (c["expected"].as_f64(), &c["limit"]),
            (Some(goal), &"at least".into())
        );
        assert_eq!(detail(c, "rounds"), Some(6.0));
        let (lo, hi) = (
            detail(c, "interval_low").unwrap(),
            detail(c, "interval_high").unwrap(),
        );
        let interval = format!("95 % interval of the median {lo:.3}–{hi:.3}");
        let m = c["message"].as_str().unwrap();
        let median = c["measured"].as_f64().unwrap();
        assert!(
            m.starts_with(&format!(
                "expected at least {goal}, measured {median:.3} ({interval})"
            )),
            "{m}"
        );
        assert!(stdout.contains(&interval), "{interval}\n{stdout}");
    }
}
