//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use verdem::case::Case;
use verdem::scene;
use verdem::step::engine::{self, Overrides};
use verdem::step::Engine;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file of the repository's reference data (`data/...`, see `data/README.md`).
pub fn data(rel: &str) -> PathBuf {
    let p = root().join("data").join(rel);
    assert!(p.exists(), "{} is missing from the repository", p.display());
    p
}

/// Runs the verdem binary with `args` from the repository root and returns its output, once it
/// has exited successfully (its stderr is the failure message otherwise).
pub fn verdem_ok<S: AsRef<std::ffi::OsStr>>(args: impl IntoIterator<Item = S>) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The quick shear case.
pub fn quick_case() -> Case {
    Case::load(&root().join("cases/shear_flow_quick.toml")).expect("case loads")
}

/// An engine for `case` starting from `init` (or the generated scene), with overrides.
pub fn engine(case: &Case, init: Option<&Path>, o: Overrides) -> Box<dyn Engine> {
    let s = scene::build(case, init).expect("scene builds");
    engine::build(case, s, &o).expect("the case names a convention")
}

/// State hash after `steps` steps.
pub fn hash_after(engine: &mut dyn Engine, steps: u64) -> String {
    engine.advance(steps).unwrap();
    verdem::io::hash::state_hash(&engine.snapshot())
}

/// Runs `engine` to step `end_step` with a save every `save_every` into `dir`, saves named
/// `name`, no progress bar and no checkpoints.
pub fn run_with_saves(
    engine: &mut dyn Engine,
    dir: &Path,
    name: &str,
    end_step: u64,
    save_every: u64,
) -> verdem::run::RunSummary {
    let opts = run_options(dir, name, end_step, save_every);
    verdem::run::run(engine, &opts, false).expect("run")
}

/// The options of a run `name` in `dir` to `end_step` with a save every `save_every` steps, no
/// checkpoints and no progress bar.
pub fn run_options(
    dir: &Path,
    name: &str,
    end_step: u64,
    save_every: u64,
) -> verdem::run::RunOptions {
    verdem::run::RunOptions {
        end_step,
        save_every,
        checkpoint_every: 0,
        out_dir: dir.to_path_buf(),
        name: name.into(),
        tag: name.into(),
        progress: false,
        write_saves: true,
        vtk: false,
        stop: None,
    }
}

/// The diagnostics table of a run resumed from a checkpoint (`resumed`) against the same run
/// uninterrupted (`straight`): the same lines, byte for byte, ledger columns included (the
/// checkpoint holds the ledgers' flows and their reading at the last save, and a contact closed
/// by a pair-list rebuild is booked as the pair pass books it, so the rebuilds a resume moves
/// change nothing). A differing line is reported by column.
pub fn assert_resumed_diagnostics(resumed: &str, straight: &str) {
    let (resumed, straight): (Vec<&str>, Vec<&str>) =
        (resumed.lines().collect(), straight.lines().collect());
    assert_eq!(resumed.len(), straight.len());
    let header: Vec<&str> = straight[0].split(',').collect();
    for (k, (a, b)) in resumed.iter().zip(&straight).enumerate() {
        let (a, b): (Vec<&str>, Vec<&str>) = (a.split(',').collect(), b.split(',').collect());
        assert_eq!(a.len(), b.len(), "line {k}");
        for c in 0..b.len() {
            assert_eq!(a[c], b[c], "line {k}, {}", header[c]);
        }
    }
}

/// Asserts that every column of the profiles `other` equals that of `reference` at every grid
/// point to `tol` times the column's largest |value| in `reference`; `names` label the two in
/// the message. Returns the sum of those largest values over the contact-stress columns, which
/// is positive when there were contacts to compare.
pub fn assert_columns_agree(
    reference: &[verdem::analysis::cg::fields::Derived],
    other: &[verdem::analysis::cg::fields::Derived],
    tol: f64,
    names: (&str, &str),
) -> f64 {
    use verdem::analysis::cg::{columns, COLUMNS};
    assert_eq!(reference.len(), other.len(), "grid points");
    let mut contacts = 0.0;
    for (c, column) in COLUMNS.iter().enumerate() {
        let scale = reference
            .iter()
            .map(|d| columns(d)[c].abs())
            .fold(0.0, f64::max);
        for (k, (r, o)) in reference.iter().zip(other).enumerate() {
            let (x, y) = (columns(r)[c], columns(o)[c]);
            assert!(
                (x - y).abs() <= tol * scale,
                "{column} at slice {k}: {} {x}, {} {y}",
                names.0,
                names.1
            );
        }
        if column.starts_with("con_") {
            contacts += scale;
        }
    }
    contacts
}
