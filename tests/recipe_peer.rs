//! The peer recipe of `docs/extending.md` ("A new peer code"), applied literally: a copy of the
//! crate gets one new file `src/peers/toy.rs` (`tests/recipe_peer/toy.rs`: verdem itself as the
//! other code, without a collision run) and the two registry lines, and nothing else; built
//! with its own target folder (seeded from this one's, so only verdem is compiled), its
//! `verdem peers`, `verdem verify --peers toy` and `verdem cross toy` know the toy, say what it
//! lacks, and find it agreeing with verdem.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The toy peer's file.
const TOY: &str = include_str!("recipe_peer/toy.rs");

/// What of the crate a build of its binary reads: the manifest, the lock file, the sources and
/// the benchmarks the manifest declares.
const CRATE: [&str; 4] = ["Cargo.toml", "Cargo.lock", "src", "benches"];

/// Copies `from` into `to` (created), folders recursively, keeping modification times.
fn copy_tree(from: &Path, to: &Path) {
    let status = Command::new("cp")
        .arg("-a")
        .arg(from)
        .arg(to)
        .status()
        .unwrap();
    assert!(
        status.success(),
        "cp -a {} {}",
        from.display(),
        to.display()
    );
}

/// The relative paths of the files under `dir`, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// The recipe's two lines in `mod.rs`: `pub mod toy;` after the other `pub mod` lines and
/// `&toy::Toy,` as the last entry of `ALL`.
fn register(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let last_mod = lines
        .iter()
        .rposition(|l| l.starts_with("pub mod "))
        .unwrap();
    let all = lines
        .iter()
        .position(|l| l.starts_with("static ALL: &[&dyn Peer] = &["))
        .unwrap();
    let end = all + lines[all..].iter().position(|l| *l == "];").unwrap();
    let mut out: Vec<&str> = Vec::new();
    for (k, l) in lines.iter().enumerate() {
        if k == end {
            out.push("    &toy::Toy,");
        }
        out.push(l);
        if k == last_mod {
            out.push("pub mod toy;");
        }
    }
    out.join("\n") + "\n"
}

/// The profile folder of this test binary (`target/PROFILE/deps/recipe_peer-…`) and the
/// profile's name for `cargo --profile` (`debug` is `dev`).
fn profile() -> (PathBuf, String) {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().parent().unwrap().to_path_buf();
    let name = dir.file_name().unwrap().to_str().unwrap();
    let cargo_name = if name == "debug" { "dev" } else { name }.to_string();
    (dir, cargo_name)
}

/// A target folder under `to` seeded with this build's compiled dependencies, build-script
/// outputs and fingerprints (not verdem's own artefacts nor the test binaries), so that a build
/// there compiles verdem only and never writes into this build's folder.
fn seeded_target(to: &Path) -> PathBuf {
    let (profile_dir, _) = profile();
    let target = to.join("target");
    let seeded = target.join(profile_dir.file_name().unwrap());
    std::fs::create_dir_all(seeded.join("deps")).unwrap();
    for sub in ["build", ".fingerprint"] {
        copy_tree(&profile_dir.join(sub), &seeded.join(sub));
    }
    let deps: Vec<PathBuf> = std::fs::read_dir(profile_dir.join("deps"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_str().unwrap();
            name.starts_with("lib") && !name.starts_with("libverdem")
        })
        .collect();
    let status = Command::new("cp")
        .arg("-a")
        .args(&deps)
        .arg(seeded.join("deps"))
        .status()
        .unwrap();
    assert!(status.success());
    target
}

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
    let scratch = tempfile::tempdir().unwrap();
    let copy = scratch.path().join("verdem");
    std::fs::create_dir(&copy).unwrap();
    for item in CRATE {
        copy_tree(&root.join(item), &copy.join(item));
    }
    // the recipe: one new file, two lines in the registry
    std::fs::write(copy.join("src/peers/toy.rs"), TOY).unwrap();
    let registry = root.join("src/peers/mod.rs");
    let original = std::fs::read_to_string(&registry).unwrap();
    std::fs::write(copy.join("src/peers/mod.rs"), register(&original)).unwrap();
    // the diff is exactly that
    let (before, after) = (files(&root.join("src")), files(&copy.join("src")));
    let added: Vec<&PathBuf> = after.iter().filter(|p| !before.contains(p)).collect();
    assert_eq!(added, [&PathBuf::from("peers/toy.rs")]);
    assert!(before.iter().all(|p| after.contains(p)));
    for p in &before {
        let (a, b) = (
            std::fs::read(root.join("src").join(p)).unwrap(),
            std::fs::read(copy.join("src").join(p)).unwrap(),
        );
        if p != Path::new("peers/mod.rs") {
            assert!(a == b, "{} differs", p.display());
        }
    }
    let changed = std::fs::read_to_string(copy.join("src/peers/mod.rs")).unwrap();
    let mut added_lines: Vec<&str> = changed.lines().collect();
    for l in original.lines() {
        let k = added_lines.iter().position(|m| *m == l).unwrap();
        added_lines.remove(k);
    }
    assert_eq!(added_lines, ["pub mod toy;", "    &toy::Toy,"]);

    let target = seeded_target(scratch.path());
    let (profile_dir, profile) = profile();
    let build = Command::new(env!("CARGO"))
        .args([
            "build",
            "--offline",
            "--locked",
            "--profile",
            &profile,
            "--bin",
            "verdem",
        ])
        .current_dir(&copy)
        .env("CARGO_TARGET_DIR", &target)
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&build.stderr);
    assert!(build.status.success(), "{log}");
    let compiled: Vec<&str> = log.lines().filter(|l| l.contains("Compiling")).collect();
    assert_eq!(compiled.len(), 1, "only verdem is compiled: {log}");
    assert!(compiled[0].contains("verdem"), "{log}");
    let verdem = target.join(profile_dir.file_name().unwrap()).join("verdem");
    let built = start.elapsed();

    let listing = run_ok(&verdem, &["peers", "toy"]);
    assert!(
        listing.starts_with("toy\ttoy\tmercury\tNP=1 sh in.toy.sh\tverdem "),
        "{listing}"
    );

    let out = scratch.path().join("out");
    let verify_out = out.join("verify");
    let table = run_ok(
        &verdem,
        &[
            "verify",
            "--peers",
            "toy",
            "--out",
            verify_out.to_str().unwrap(),
        ],
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
        table.contains(" 0 failed, ") && table.contains(", 2 not run: what a peer lacks (info)"),
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
        "recipe: copy and build {:.0} s, verify and cross {:.0} s",
        built.as_secs_f64(),
        (start.elapsed() - built).as_secs_f64()
    );
}
