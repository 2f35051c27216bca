//! The peer recipe of `docs/extending.md` ("A new peer code"), applied literally: a copy of the
//! crate gets one new file `src/peers/toy.rs` (`tests/recipe_peer/toy.rs`: verdem itself as the
//! other code, without a collision run) and the two registry lines, and nothing else (beside the
//! toy convention and damping of `tests/recipe.rs`, which share the copy:
//! `scratch::every_recipe`); built with its own target folder (seeded from this one's, so only
//! verdem is compiled), its `verdem peers`, `verdem verify --peers toy` and `verdem cross toy`
//! know the toy, say what it lacks, and find it agreeing with verdem.

mod common;
#[path = "common/scratch.rs"]
mod scratch;

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use scratch::{Change, TOY_PEER, TOY_PEER_LINES};

/// Runs the scratch `verdem` with `args` in the crate's root; its output, which must succeed.
fn run_ok(verdem: &Path, args: &[&str]) -> String {
    let out = Command::new(verdem)
        .args(args)
        .current_dir(common::root())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{args:?}: {}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

#[test]
fn a_toy_peer_added_by_the_documented_recipe_runs_in_verify_and_cross() {
    let start = Instant::now();
    let root = common::root();
    let recipe = std::fs::read_to_string(root.join("docs/extending.md")).unwrap();
    for promise in [
        "one file `src/peers/NAME.rs` plus two lines in `src/peers/mod.rs`: `pub mod NAME;`",
        "after the other `pub mod` lines, and `&NAME::Type,` as the last entry of the `ALL` registry",
    ] {
        let promise = promise.split_whitespace().collect::<Vec<_>>().join(" ");
        let text = recipe.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(text.contains(&promise), "docs/extending.md no longer says: {promise}");
    }
    let shared = scratch::every_recipe(&root);
    // the recipes' change is exactly theirs; this one's: one new file, two lines in the
    // registry (`register_peer` puts them where the recipe says)
    let changes = shared.scratch.changes();
    assert_eq!(changes, scratch::expected_changes());
    assert_eq!(changes.get("src/peers/toy.rs"), Some(&Change::New));
    let registry = std::fs::read_to_string(root.join("src/peers/mod.rs")).unwrap();
    let registered = scratch::register_peer(&registry);
    let copied = std::fs::read_to_string(shared.scratch.path().join("src/peers/mod.rs")).unwrap();
    assert_eq!(copied, registered);
    assert_eq!(
        changes.get("src/peers/mod.rs"),
        Some(&Change::Lines {
            added: TOY_PEER_LINES.map(String::from).to_vec(),
            removed: vec![],
        })
    );
    let copied_toy =
        std::fs::read_to_string(shared.scratch.path().join("src/peers/toy.rs")).unwrap();
    assert_eq!(copied_toy, TOY_PEER);
    let log = &shared.log;
    let compiled: Vec<&str> = log.lines().filter(|l| l.contains("Compiling")).collect();
    assert_eq!(compiled.len(), 1, "only verdem is compiled: {log}");
    assert!(compiled[0].contains("verdem"), "{log}");
    let verdem = shared.bin.clone();
    let built = start.elapsed();

    let listing = run_ok(&verdem, &["peers", "toy"]);
    assert!(
        listing.starts_with("toy\ttoy\tmercury\tNP=1 sh in.toy.sh\tverdem "),
        "{listing}"
    );

    let scratch_out = tempfile::tempdir().unwrap();
    let out = scratch_out.path().join("out");
    let verify_out = out.join("verify");
    let verified = Command::new(&verdem)
        .args(["verify", "--peers", "toy", "--out"])
        .arg(&verify_out)
        .current_dir(common::root())
        .output()
        .unwrap();
    let table = String::from_utf8_lossy(&verified.stdout).to_string();
    // the shared copy also holds tests/recipe.rs's toy convention, whose prescribed-motion rows
    // against the case's kt may fail (that test judges them); no other row fails
    let failed: Vec<&str> = table
        .lines()
        .filter(|l| l.trim_end().ends_with(" FAIL"))
        .collect();
    assert!(
        failed
            .iter()
            .all(|l| l.starts_with("tangential toy-stiffer ")),
        "{failed:#?}"
    );
    assert_eq!(
        verified.status.success(),
        failed.is_empty(),
        "{}\n{table}",
        verified.status
    );
    for (case, why) in [
        (
            "toy binary collisions",
            "toy: it has no two-sphere collision run",
        ),
        (
            "toy prescribed motion",
            "toy: verdem drives no library of its contact law through a prescribed motion",
        ),
    ] {
        let line = table
            .lines()
            .position(|l| l.starts_with(case))
            .unwrap_or_else(|| panic!("no row {case:?}: {table}"));
        let lines: Vec<&str> = table.lines().collect();
        assert!(
            lines[line].contains("not run: the peer lacks it"),
            "{}",
            lines[line]
        );
        assert!(lines[line].trim_end().ends_with("info"), "{}", lines[line]);
        assert_eq!(lines[line + 1].trim(), why);
    }
    assert!(
        table.contains(&format!(" {} failed, ", failed.len()))
            && table.contains(", 2 not run: what a peer lacks (info)"),
        "{table}"
    );

    let cross_out = out.join("cross");
    let report = run_ok(
        &verdem,
        &[
            "cross",
            "toy",
            "cases/shear_flow_quick.toml",
            "--steps",
            "200",
            "--every",
            "100",
            "--np",
            "1",
            "--out",
            cross_out.to_str().unwrap(),
        ],
    );
    assert!(
        report.contains("largest |dx| stays within 1e-6 up to step 200"),
        "{report}"
    );
    let chi2 = report
        .lines()
        .find_map(|l| {
            l.strip_prefix("profiles over all saves, chi2/dof against verdem (1 = noise): ")
        })
        .unwrap_or_else(|| panic!("no profiles compared: {report}"));
    for field in chi2.split(", ") {
        let (name, value) = field.rsplit_once(' ').unwrap();
        let value: f64 = value.parse().unwrap();
        assert!(
            value < 1e-3,
            "{name}: chi2/dof {value} of verdem against itself"
        );
    }
    eprintln!(
        "recipe: the toy peer is a file of {} lines and {} registry lines",
        TOY_PEER.lines().count(),
        TOY_PEER_LINES.len()
    );
    eprintln!(
        "recipe: copy and build {:.0} s ({}), verify and cross {:.0} s",
        built.as_secs_f64(),
        if shared.built_here {
            "built here"
        } else {
            "the suite's build, reused"
        },
        (start.elapsed() - built).as_secs_f64()
    );
}
