//! The speed/accuracy trade: the verdict on constructed biases, what each variant changes on a
//! short run, and what docs/performance.md says of the recorded trade.

mod common;

use verdem::analysis::difference::{CoreMean, Difference};
use verdem::tradeoff::{self, call, Bias, Call, Outcome, Plan, CONTROL, REFERENCE};

/// A bias of a variant (mean `delta` above a reference at 1.0) with both core means' standard
/// error `se` with 19 degrees of freedom, relative to 1.0.
fn bias(field: &'static str, delta: f64, se: f64, trusted: bool) -> Bias {
    let m = |mean| CoreMean {
        mean,
        se,
        dof: 19.0,
        long_enough: trusted,
    };
    Bias {
        diff: Difference {
            field,
            a: m(1.0 + delta),
            b: m(1.0),
            chi2: f64::NAN,
        },
        scale: 1.0,
    }
}

#[test]
fn a_five_sigma_bias_costs_and_a_wide_zero_bias_is_undecided() {
    // the combined error of two errors of 0.002 is 0.00283; Welch's 38 degrees of freedom give
    // t = 2.024: the interval's half-width is 0.57 %
    let narrow = |field| bias(field, 0.0, 0.002, true);
    // a bias of 5 combined standard errors in pressure: costs, named with its bias
    let five_sigma = 5.0 * 0.002f64.hypot(0.002);
    let mut b = vec![narrow("vx"), narrow("nu"), narrow("T"), narrow("shear")];
    b.insert(3, bias("pressure", five_sigma, 0.002, true));
    match call(&b, false, 0.02) {
        Call::Costs(c) => {
            assert_eq!(c.len(), 1, "{c:?}");
            assert_eq!(c[0].0, "pressure");
            assert!((c[0].1 - five_sigma).abs() < 1e-12, "{c:?}");
            assert!((c[0].2 - 2.024 * 0.00283).abs() < 1e-4, "{c:?}");
        }
        other => panic!("a 5-sigma bias is not a cost: {other}"),
    }
    // every bias 0 and every interval within ±2 %: free
    let all: Vec<Bias> = ["vx", "nu", "T", "pressure", "shear"]
        .into_iter()
        .map(narrow)
        .collect();
    assert_eq!(call(&all, false, 0.02), Call::Free { same_bits: false });
    // a zero bias whose interval (±5.7 %) is wider than the resolution: undecided, naming it
    let mut wide = all.clone();
    wide[4] = bias("shear", 0.0, 0.02, true);
    match call(&wide, false, 0.02) {
        Call::Undecided {
            wide, too_small, ..
        } => {
            assert_eq!(wide.len(), 1, "{wide:?}");
            assert_eq!(wide[0].0, "shear");
            assert!(too_small.is_empty());
        }
        other => panic!("a wide interval is settled: {other}"),
    }
    // the same at a resolution of ±6 %: free
    assert_eq!(call(&wide, false, 0.06), Call::Free { same_bits: false });
    // errors too small are never settled: neither free nor a cost
    let mut small = all.clone();
    small[1] = bias("nu", 0.0, 0.002, false);
    assert!(
        matches!(call(&small, false, 0.02), Call::Undecided { ref too_small, .. } if too_small == &["nu"])
    );
    small[1] = bias("nu", five_sigma, 0.002, false);
    assert!(matches!(call(&small, false, 0.02), Call::Undecided { .. }));
    // the reference's bits are free whatever the intervals say
    assert_eq!(call(&wide, true, 0.02), Call::Free { same_bits: true });
    // a control with one interval of five missing 0 passes; with two it fails, and then no
    // verdict but the reference's bits is settled
    let mut control = all.clone();
    control[0] = bias("vx", five_sigma, 0.002, true);
    assert!(tradeoff::control_passes(&control));
    control[3] = bias("pressure", -five_sigma, 0.002, true);
    assert!(!tradeoff::control_passes(&control));
    let failed = Some(tradeoff::coverage(&control));
    assert_eq!(failed, Some((3, 5)));
    assert!(tradeoff::judged(&b, false, 0.02, failed).starts_with("undecided: the control fails"));
    assert!(tradeoff::judged(&all, false, 0.02, failed).starts_with("undecided"));
    assert_eq!(
        tradeoff::judged(&all, true, 0.02, failed),
        "free (same bits)"
    );
    assert!(tradeoff::judged(&b, false, 0.02, Some((4, 5))).starts_with("**costs** pressure"));
}

#[test]
fn replicas_merge_into_their_mean_with_the_ensembles_error() {
    let c = |mean, se, dof, long_enough| CoreMean {
        mean,
        se,
        dof,
        long_enough,
    };
    // one replica is its own
    let one = c(1.0, 0.03, 9.0, false);
    assert_eq!(tradeoff::merge_core(&[one]), one);
    // three: their mean; the spread of 1, 2, 3 (sd 1) over √3; 2 degrees of freedom; trusted
    // although one replica's errors were not
    let m = tradeoff::merge_core(&[
        c(1.0, 0.03, 9.0, true),
        c(2.0, 0.04, 5.0, false),
        c(3.0, 0.01, 7.0, true),
    ]);
    assert!((m.mean - 2.0).abs() < 1e-15);
    assert!((m.se - 1.0 / 3f64.sqrt()).abs() < 1e-15, "{}", m.se);
    assert_eq!(m.dof, 2.0);
    assert!(m.long_enough);
}

#[test]
fn each_replica_has_its_own_row_of_core_means() {
    let c = |mean| CoreMean {
        mean,
        se: 0.5,
        dof: 6.5,
        long_enough: true,
    };
    let path = common::root().join("golden/tradeoff/tradeoff.csv");
    let mut out = tradeoff::read_csv(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    out.truncate(2);
    let fields = out[0].core.len();
    out[0].replica_core = vec![vec![c(1.0); fields], vec![c(2.0); fields]];
    out[1].replica_core = vec![vec![c(3.0); fields]];
    let text = tradeoff::replicas_csv(&out);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    assert!(lines[0].starts_with("variant,replica,vx_mean,vx_se,vx_dof,vx_trusted,nu_mean"));
    assert!(
        lines[1].starts_with("reference,0,1e0,5e-1,6.5,true,1e0"),
        "{}",
        lines[1]
    );
    assert!(lines[2].starts_with("reference,1,2e0,"), "{}", lines[2]);
    assert!(
        lines[3].starts_with(&format!("{},0,3e0,", out[1].name)),
        "{}",
        lines[3]
    );
    assert_eq!(lines[1].split(',').count(), 2 + 4 * fields);
}

#[test]
fn variants_change_what_they_should_and_nothing_else() {
    let case = common::quick_case();
    let pair = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let plan = Plan {
        time: 3.0,
        replicas: 1,
        base_seed: 1,
        perturbation: 1e-6,
    };
    let mut shown = Vec::new();
    let out = tradeoff::run(
        &case,
        &pair,
        &common::data("states/mercury_t143.85.data"),
        &plan,
        dir.path(),
        &mut |o| shown.push(o.name.clone()),
    )
    .unwrap();
    let names: Vec<String> = out.iter().map(|o| o.name.clone()).collect();
    assert_eq!(shown, names);
    assert_eq!(names[0], REFERENCE);
    assert_eq!(names[1], CONTROL);
    let by = |name: &str| out.iter().find(|o| o.name == name).unwrap();
    let reference = by(REFERENCE);
    // skin and thread count change no bit (deterministic mode): free
    for name in ["skin=0.05", "skin=0.2", "2 threads"] {
        let o = by(name);
        assert_eq!(o.hash, reference.hash, "{name}");
        assert_eq!(o.core, reference.core, "{name}");
        let b = tradeoff::biases(o, reference, 1.0);
        assert_eq!(call(&b, true, 0.02), Call::Free { same_bits: true });
    }
    // a finer dt changes the trajectory and shrinks the restitution error
    let errors: Vec<f64> = ["dt=tc/25", REFERENCE, "dt=tc/100", "dt=tc/200"]
        .iter()
        .map(|n| by(n).restitution_error.abs())
        .collect();
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
    assert_ne!(by("dt=tc/100").hash, reference.hash);
    // softer contacts keep e and tc/dt: the same restitution error, fewer steps per time unit
    for name in ["kn/10", "kn/100"] {
        let o = by(name);
        assert!(
            (o.restitution_error - reference.restitution_error).abs() < 1e-9,
            "{name}: {} vs {}",
            o.restitution_error,
            reference.restitution_error
        );
        assert!(
            o.steps_per_time() < reference.steps_per_time() / 3.0,
            "{name}"
        );
    }
    // the control repeats the reference's physics under another seed: same law and steps,
    // other bits and other core means
    let control = by(CONTROL);
    assert_eq!(control.steps, reference.steps);
    assert_eq!(control.restitution_error, reference.restitution_error);
    assert_ne!(control.hash, reference.hash);
    assert_ne!(control.core, reference.core);
    // every run measured its own CPU time
    assert!(out.iter().all(|o| o.cpu_seconds > 0.0), "{out:?}");
    // the CSV gives back what was written, and the table has a row per run
    let csv = tradeoff::csv(&out);
    let back: Vec<Outcome> = tradeoff::read_csv(&csv, std::path::Path::new("t.csv")).unwrap();
    assert_eq!(tradeoff::csv(&back), csv);
    let table = tradeoff::markdown(&back, 1.0, 0.02);
    assert_eq!(
        table.lines().filter(|l| l.starts_with("| ")).count(),
        1 + 10
    );
}

/// The resolution the recorded trade is judged at (golden/tradeoff/provenance.toml).
const RECORDED_RESOLUTION: f64 = 0.02;

/// The recorded trade (golden/tradeoff, see its provenance.toml): its table is what
/// `verdem tradeoff --table` makes of its CSV, docs/performance.md quotes that table row by row,
/// and what the docs say of it holds.
#[test]
fn the_recorded_trade_says_what_the_docs_say() {
    let root = common::root();
    let dir = root.join("golden/tradeoff");
    let path = dir.join("tradeoff.csv");
    let out = tradeoff::read_csv(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    let case = verdem::case::Case::load(&root.join("cases/shear_flow_steady.toml")).unwrap();
    let speed = tradeoff::wall_speed(&case);
    let table = tradeoff::markdown(&out, speed, RECORDED_RESOLUTION);
    assert_eq!(
        table,
        std::fs::read_to_string(dir.join("tradeoff.md")).unwrap()
    );
    let docs = std::fs::read_to_string(root.join("docs/performance.md")).unwrap();
    for row in table.lines().filter(|l| l.starts_with("| ")) {
        assert!(
            docs.contains(row),
            "docs/performance.md lacks the row {row}"
        );
    }
    let by = |name: &str| out.iter().find(|o| o.name == name).unwrap();
    let reference = by(REFERENCE);
    let verdict = |name: &str| {
        let o = by(name);
        call(
            &tradeoff::biases(o, reference, speed),
            o.hash == reference.hash,
            RECORDED_RESOLUTION,
        )
    };
    let rel = |name: &str, field: &str| {
        let b = tradeoff::biases(by(name), reference, speed);
        let b = b.into_iter().find(|b| b.diff.field == field).unwrap();
        (
            b.relative(),
            b.relative_half_width(),
            b.diff.errors_trusted(),
        )
    };
    // six replicas of each variant that changes the physics; one of each that gives the
    // reference's bits
    for name in [REFERENCE, CONTROL, "dt=tc/25", "kn/100"] {
        assert_eq!(by(name).replicas, 6, "{name}");
    }
    for name in ["skin=0.05", "skin=0.2", "2 threads"] {
        assert_eq!(by(name).replicas, 1, "{name}");
    }
    // the control passes: all 5 of its intervals contain 0
    let control = tradeoff::biases(by(CONTROL), reference, speed);
    assert_eq!(tradeoff::coverage(&control), (5, 5));
    assert!(tradeoff::control_passes(&control));
    let coverage = Some(tradeoff::coverage(&control));
    // softer contacts cost pressure: kn/100 in pressure (lower) and shear stress (toward 0),
    // kn/10 in pressure only; both keep vx, ν and T, ν's interval within ±0.25 %
    for (name, costly) in [
        ("kn/10", vec!["pressure"]),
        ("kn/100", vec!["pressure", "shear"]),
    ] {
        let b = tradeoff::biases(by(name), reference, speed);
        let shown = tradeoff::judged(&b, false, RECORDED_RESOLUTION, coverage);
        assert!(shown.starts_with("**costs**"), "{name}: {shown}");
        match verdict(name) {
            Call::Costs(c) => {
                let fields: Vec<&str> = c.iter().map(|c| c.0).collect();
                assert_eq!(fields, costly, "{name}");
                assert!(c[0].1 < 0.0, "{name}: {c:?}");
                assert!(c.iter().skip(1).all(|c| c.1 > 0.0), "{name}: {c:?}");
            }
            other => panic!("{name}: {other}"),
        }
        let (nu, h, _) = rel(name, "nu");
        assert!(nu.abs() + h < 0.0025, "{name}: nu {nu} ± {h}");
    }
    // the time steps: every interval contains 0, vx and ν biases under 0.2 % with intervals of
    // at most ±0.32 %, T, p and τ intervals of ±1.9–3.1 %, so undecided at ±2 % through T and τ
    for name in ["dt=tc/25", "dt=tc/100", "dt=tc/200"] {
        let b = tradeoff::biases(by(name), reference, speed);
        assert!(b.iter().all(|b| b.contains_zero()), "{name}");
        for field in ["vx", "nu"] {
            let (x, h, _) = rel(name, field);
            assert!(x.abs() < 0.002 && h <= 0.0032, "{name} {field}: {x} ± {h}");
        }
        for field in ["T", "pressure", "shear"] {
            let (_, h, _) = rel(name, field);
            assert!((0.0185..0.0315).contains(&h), "{name} {field}: ± {h}");
        }
        match verdict(name) {
            Call::Undecided { wide, .. } => {
                let fields: Vec<&str> = wide.iter().map(|w| w.0).collect();
                assert!(
                    fields.contains(&"T") && fields.contains(&"shear"),
                    "{name}: {fields:?}"
                );
            }
            other => panic!("{name}: {other}"),
        }
    }
    // skin and threads change no bit: free
    for name in ["skin=0.05", "skin=0.2", "2 threads"] {
        assert_eq!(verdict(name), Call::Free { same_bits: true }, "{name}");
    }
    // cost in CPU time relative to the reference's: a step is cheaper at a finer dt, dearer
    // with softer contacts; skin 0.05 is cheaper, skin 0.2 dearer; 2 threads take more CPU
    let cpu = |name: &str| by(name).cpu_per_time() / reference.cpu_per_time();
    let steps = |name: &str| by(name).steps_per_time() / reference.steps_per_time();
    for name in ["dt=tc/100", "dt=tc/200"] {
        assert!(cpu(name) > 1.0 && cpu(name) < steps(name), "{name}");
    }
    assert!(cpu("dt=tc/25") < 1.0);
    for name in ["kn/10", "kn/100"] {
        assert!(cpu(name) > steps(name) && cpu(name) < 1.0, "{name}");
    }
    assert!(cpu("kn/100") > 2.0 * steps("kn/100"));
    assert!(cpu("skin=0.05") < 0.95 && cpu("skin=0.2") > 1.0);
    assert!(cpu("2 threads") > 1.3);
    // the restitution error halves with each halving of dt; softer contacts keep it
    let e = |name: &str| by(name).restitution_error.abs();
    for (coarse, fine) in [
        ("dt=tc/25", REFERENCE),
        (REFERENCE, "dt=tc/100"),
        ("dt=tc/100", "dt=tc/200"),
    ] {
        assert!((e(coarse) / e(fine) - 2.0).abs() < 0.2, "{coarse} {fine}");
    }
    for name in ["kn/10", "kn/100"] {
        assert!((e(name) - e(REFERENCE)).abs() < 1e-9, "{name}");
    }
}

/// The cost of determinism (golden/tradeoff/gather_callgrind.toml): the closure that holds the
/// ordered gather takes under 5 % of a step's instructions in both states, the share
/// docs/performance.md quotes.
#[test]
fn the_ordered_gather_bounds_what_a_non_deterministic_step_could_save() {
    let root = common::root();
    let text = std::fs::read_to_string(root.join("golden/tradeoff/gather_callgrind.toml")).unwrap();
    let record: toml::Table = text.parse().unwrap();
    let docs = std::fs::read_to_string(root.join("docs/performance.md")).unwrap();
    for state in ["steady", "developing"] {
        let s = record[state].as_table().unwrap();
        let n = |key: &str| s[key].as_integer().unwrap() as f64;
        let step = (n("total_3000") - n("total_1000")) / 2000.0;
        let gather = (n("closure_3000") - n("closure_1000")) / 2000.0;
        let calls = (n("closure_calls_3000") - n("closure_calls_1000")) / 2000.0;
        // a step is 1e5 instructions or more, of which the particles that touched something
        // (a few dozen of 3000) take a few thousand
        assert!(
            step > 1e5 && (10.0..100.0).contains(&calls),
            "{state}: {step} {calls}"
        );
        let share = gather / step;
        assert!(share > 0.0 && share < 0.05, "{state}: {share}");
        let quoted = format!("at most {:.1} % of a step ({state}", 100.0 * share);
        assert!(
            docs.contains(&quoted),
            "docs/performance.md lacks {quoted:?}"
        );
    }
}

/// `verdem tradeoff --table` on a table without its reference row is an error naming the
/// file and the row, not an empty table.
#[test]
fn a_table_without_its_reference_row_is_refused() {
    let golden = common::root().join("golden/tradeoff/tradeoff.csv");
    let text = std::fs::read_to_string(&golden).unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("reference,"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(without.lines().count() + 1, text.lines().count());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    std::fs::write(&path, without).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .arg("tradeoff")
        .arg("--table")
        .arg(&path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains(&format!("{}: no `reference` row", path.display())),
        "{err}"
    );
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let e = tradeoff::read_csv(text.lines().next().unwrap(), &path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no `reference` row") && e.contains("no row"),
        "{e}"
    );
}

/// Degrees of freedom that are negative or not finite, and other fields out of their range,
/// are refused naming the file, the line and the field.
#[test]
fn degrees_of_freedom_out_of_range_are_refused_with_file_line_and_field() {
    let golden = common::root().join("golden/tradeoff/tradeoff.csv");
    let text = std::fs::read_to_string(&golden).unwrap();
    let path = std::path::Path::new("t.csv");
    assert!(tradeoff::read_csv(&text, path).is_ok());
    // line 3, the control: its vx degrees of freedom (field 11) and its first standard error
    let with = |from: &str, to: &str| {
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        assert!(lines[2].contains(from), "{}", lines[2]);
        lines[2] = lines[2].replacen(from, to, 1);
        lines.join("\n")
    };
    for (to, says) in [
        (
            ",-5,true,",
            "t.csv: line 3: field 11 (vx_dof) is -5: it must be 0 or more",
        ),
        (
            ",NaN,true,",
            "t.csv: line 3: field 11 (vx_dof) is not finite: \"NaN\"",
        ),
        (
            ",inf,true,",
            "t.csv: line 3: field 11 (vx_dof) is not finite: \"inf\"",
        ),
    ] {
        let e = tradeoff::read_csv(&with(",5,true,", to), path)
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{to}: {e}");
    }
    let e = tradeoff::read_csv(&with(",6.42251135311506e-4,", ",-6.4e-4,"), path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.csv: line 3: field 10 (vx_se) is -0.00064: it must be 0 or more"),
        "{e}"
    );
}
