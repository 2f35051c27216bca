//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use verdem::case::Case;
use verdem::engine::{self, Overrides};
use verdem::scene;
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
    engine::build(case, s, &o)
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
/// uninterrupted (`straight`), `line` being the line (header = 0) of the first save after the
/// resume: the state columns agree bit for bit on every line; the ledgers, which the
/// checkpoint does not hold, agree bit for bit before `line` and are empty on `line` when
/// `empty_at_resume` (a resume between saves). After that every ledger column agrees bit for
/// bit except the slider's (and with it the residual), which agree to 1e-3 of the line's
/// largest ledger value: a contact that separates at a step where the pair list is rebuilt is
/// closed by the rebuild without the slider's booking of what its spring held, and a resumed
/// run rebuilds at other steps (docs/statistics.md, "Open").
pub fn assert_resumed_diagnostics(
    resumed: &str,
    straight: &str,
    line: usize,
    empty_at_resume: bool,
) {
    let (resumed, straight): (Vec<&str>, Vec<&str>) =
        (resumed.lines().collect(), straight.lines().collect());
    assert_eq!(resumed.len(), straight.len());
    let header: Vec<&str> = straight[0].split(',').collect();
    let ledger = header
        .iter()
        .position(|c| *c == "work_walls")
        .expect("ledger columns");
    let loose = |c: usize| matches!(header[c], "diss_slide" | "ledger_residual");
    for (k, (a, b)) in resumed.iter().zip(&straight).enumerate() {
        let (a, b): (Vec<&str>, Vec<&str>) = (a.split(',').collect(), b.split(',').collect());
        assert_eq!(a[..ledger], b[..ledger], "line {k}");
        if k < line {
            assert_eq!(a, b, "line {k}");
        } else if k == line && empty_at_resume {
            assert!(a[ledger..].iter().all(|f| f.is_empty()), "{a:?}");
        } else {
            let num = |f: &str| f.parse::<f64>().unwrap();
            let scale = b[ledger..].iter().map(|f| num(f).abs()).fold(0.0, f64::max);
            for c in ledger..b.len() {
                if loose(c) {
                    let (x, y) = (num(a[c]), num(b[c]));
                    assert!(
                        (x - y).abs() <= 1e-3 * scale,
                        "line {k}, {}: {x} vs {y}",
                        header[c]
                    );
                } else {
                    assert_eq!(a[c], b[c], "line {k}, {}", header[c]);
                }
            }
        }
    }
}
