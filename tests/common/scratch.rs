//! A scratch copy of the crate for tests that apply a documented recipe to the sources, check
//! that the change is exactly the recipe's and build the result: the copy has its own target
//! directory, seeded with the running test's build of the dependencies so that only verdem
//! rebuilds, and never touches the binary the other tests run.
//!
//! The recipe tests (`tests/recipe.rs`: a toy convention and a toy damping; `tests/recipe_peer.rs`:
//! a toy peer) share one copy with every recipe applied ([`every_recipe`]), built once for the
//! whole suite: the first test to ask builds it under `CARGO_TARGET_TMPDIR`, keyed by the crate's
//! sources and the toys, and the others reuse it.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::fs;
use std::os::fd::AsRawFd;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sha2::{Digest, Sha256};

/// What a build needs besides `src/`: the manifest, the lock file and the declared bench.
const CRATE_FILES: [&str; 3] = ["Cargo.toml", "Cargo.lock", "benches"];

/// How one file of the copy differs from the repository's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Change {
    /// A file the repository does not have.
    New,
    /// Lines the copy has more of (`added`) or fewer of (`removed`) than the repository's file,
    /// each in the copy's (or the original's) order.
    Lines {
        added: Vec<String>,
        removed: Vec<String>,
    },
}

/// A copy of the crate in the folder `dir`.
pub struct Scratch {
    dir: PathBuf,
    origin: PathBuf,
}

impl Scratch {
    /// Copies `Cargo.toml`, `Cargo.lock`, `benches/` and `src/` of the crate at `origin` into
    /// the new folder `dir`.
    pub fn copy_crate(origin: &Path, dir: &Path) -> Scratch {
        for rel in CRATE_FILES.into_iter().chain(["src"]) {
            copy_tree(&origin.join(rel), &dir.join(rel));
        }
        Scratch {
            dir: dir.to_path_buf(),
            origin: origin.to_path_buf(),
        }
    }

    /// The copy's root.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Writes a new file `rel` (relative to the root) with `text`.
    pub fn create(&self, rel: &str, text: &str) {
        let path = self.path().join(rel);
        assert!(!path.exists(), "{rel} exists already");
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(path, text).unwrap();
    }

    /// Inserts `line` into the file `rel` before the first line equal to `before` that follows
    /// the first line equal to `after` (both without the newline).
    pub fn insert_line(&self, rel: &str, after: &str, before: &str, line: &str) {
        let path = self.path().join(rel);
        let text = fs::read_to_string(&path).unwrap();
        let mut lines: Vec<&str> = text.lines().collect();
        let start = lines
            .iter()
            .position(|l| *l == after)
            .unwrap_or_else(|| panic!("{rel} has no line {after:?}"));
        let at = start
            + lines[start..]
                .iter()
                .position(|l| *l == before)
                .unwrap_or_else(|| panic!("{rel} has no line {before:?} after {after:?}"));
        lines.insert(at, line);
        fs::write(path, lines.join("\n") + "\n").unwrap();
    }

    /// Every file of the copy that differs from the repository's, by its path relative to the
    /// root (files the copy lacks are listed as removing all their lines).
    pub fn changes(&self) -> BTreeMap<String, Change> {
        let mut files = Vec::new();
        for rel in CRATE_FILES.into_iter().chain(["src"]) {
            list_files(self.path(), Path::new(rel), &mut files);
            list_files(&self.origin, Path::new(rel), &mut files);
        }
        files.sort();
        files.dedup();
        let mut changes = BTreeMap::new();
        for rel in files {
            let copy = fs::read(self.path().join(&rel)).ok();
            let original = fs::read(self.origin.join(&rel)).ok();
            let change = match (&original, &copy) {
                (None, Some(_)) => Change::New,
                (a, b) if a == b => continue,
                (a, b) => {
                    let text = |t: &Option<Vec<u8>>| {
                        String::from_utf8_lossy(t.as_deref().unwrap_or_default()).into_owned()
                    };
                    let (a, b) = (text(a), text(b));
                    Change::Lines {
                        added: surplus(&b, &a),
                        removed: surplus(&a, &b),
                    }
                }
            };
            changes.insert(rel.to_string_lossy().into_owned(), change);
        }
        changes
    }

    /// Builds the copy's `verdem` with the profile of the running test, offline, in the copy's
    /// own target directory seeded with the running test's dependencies (the libraries of the
    /// profile's `deps`, and its `build` and `.fingerprint`, but verdem's own), and returns the
    /// binary and cargo's log.
    pub fn build(&self) -> (PathBuf, String) {
        let (target, profile) = running_target();
        let dir = self.path().join("target");
        let profile_dir = if profile == "dev" { "debug" } else { &profile };
        for sub in ["deps", "build", ".fingerprint"] {
            let from = target.join(profile_dir).join(sub);
            let to = dir.join(profile_dir).join(sub);
            fs::create_dir_all(&to).unwrap();
            for entry in fs::read_dir(&from).unwrap() {
                let entry = entry.unwrap();
                let name = entry.file_name().to_string_lossy().into_owned();
                // of `deps`, the compiled libraries only (not the test binaries)
                if !is_verdem(&name) && (sub != "deps" || name.starts_with("lib")) {
                    copy_tree(&entry.path(), &to.join(&name));
                }
            }
        }
        let out = Command::new(env!("CARGO"))
            .current_dir(self.path())
            .env("CARGO_TARGET_DIR", &dir)
            .args([
                "build",
                "--offline",
                "--locked",
                "--bin",
                "verdem",
                "--profile",
                &profile,
            ])
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "the scratch build failed:\n{log}");
        // The seed holds the dependencies as `cargo build` compiles them only where this
        // profile's binary was built before the tests (ci/test.sh does); after a `cargo test`
        // alone, whose dependencies carry the dev-dependencies' features, they are compiled
        // again here, which costs time and nothing else.
        let again: Vec<_> = log
            .lines()
            .filter(|l| l.contains("Compiling ") && !l.contains("Compiling verdem "))
            .collect();
        if !again.is_empty() {
            eprintln!(
                "the scratch build compiled {} dependencies again",
                again.len()
            );
        }
        let bin = dir.join(profile_dir).join("verdem");
        assert_ne!(bin, Path::new(env!("CARGO_BIN_EXE_verdem")));
        (bin, log)
    }
}

/// The recipe's registry line of the toy convention (`docs/extending.md`, "A new tangential
/// convention"): the objective law with a 1.0001 × kt spring.
pub const TOY_CONVENTION: &str = r#"    Stiffer = "toy-stiffer", |p| Objective::new(1.0001 * p.kt, p.gammat, p.mu), [objective, twists_spring], "Toy: the objective law with a 1.0001 x kt spring";"#;

/// The recipe's registry line of the toy damping ("A new normal law or damping"): the linear
/// spring with a 1.0001 × γn dashpot.
pub const TOY_DAMPING: &str = r#"    ToyDamping = "toy-damping", mod toy_damping, reads [Kn, Gamman], |p| Damped { spring: Linear { kn: p.kn }, damping: toy_damping::ToyDamping { gamman: 1.0001 * p.gamman } }, "Toy: the linear spring with a 1.0001 x gamman dashpot";"#;

/// The recipe's new file of the toy damping: an absolute dashpot.
pub const TOY_DAMPING_FILE: &str = r#"//! A toy damping: an absolute dashpot γn (mass/time).

use crate::contact::{Damping, PairKinematics, Spring};

/// Absolute dashpot γn (mass/time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToyDamping {
    pub gamman: f64,
}

impl Damping for ToyDamping {
    fn gamma<S: Spring>(&self, _: &S, _: f64, _: &PairKinematics) -> f64 {
        self.gamman
    }
}
"#;

/// The toy peer's file ("A new peer code"): verdem itself as the other code, without a
/// collision run.
pub const TOY_PEER: &str = include_str!("../recipe_peer/toy.rs");

/// The peer recipe's two lines in `src/peers/mod.rs`.
pub const TOY_PEER_LINES: [&str; 2] = ["pub mod toy;", "    &toy::Toy,"];

/// The peer recipe applied to the text of `src/peers/mod.rs`: `pub mod toy;` after the other
/// `pub mod` lines and `&toy::Toy,` as the last entry of `ALL`.
pub fn register_peer(text: &str) -> String {
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
            out.push(TOY_PEER_LINES[1]);
        }
        out.push(l);
        if k == last_mod {
            out.push(TOY_PEER_LINES[0]);
        }
    }
    out.join("\n") + "\n"
}

/// Applies every recipe's toy to the copy `s`: the toy convention's registry line, the toy
/// damping's file and registry line, the toy peer's file and its two registry lines.
fn apply_every_recipe(s: &Scratch) {
    s.insert_line(
        "src/contact/registry.rs",
        "conventions! {",
        "}",
        TOY_CONVENTION,
    );
    s.insert_line(
        "src/contact/normal_laws.rs",
        "normal_laws! {",
        "}",
        TOY_DAMPING,
    );
    s.create("src/contact/normal_laws/toy_damping.rs", TOY_DAMPING_FILE);
    s.create("src/peers/toy.rs", TOY_PEER);
    let registry = s.path().join("src/peers/mod.rs");
    let text = fs::read_to_string(&registry).unwrap();
    fs::write(&registry, register_peer(&text)).unwrap();
}

/// What the recipes change, file by file: exactly their lines and files.
pub fn expected_changes() -> BTreeMap<String, Change> {
    let lines = |added: &[&str]| Change::Lines {
        added: added.iter().map(|l| l.to_string()).collect(),
        removed: vec![],
    };
    BTreeMap::from([
        ("src/contact/normal_laws.rs".into(), lines(&[TOY_DAMPING])),
        ("src/contact/normal_laws/toy_damping.rs".into(), Change::New),
        ("src/contact/registry.rs".into(), lines(&[TOY_CONVENTION])),
        ("src/peers/mod.rs".into(), lines(&TOY_PEER_LINES)),
        ("src/peers/toy.rs".into(), Change::New),
    ])
}

/// The suite's one scratch build with every recipe applied.
pub struct Shared {
    /// The copy of the crate, the recipes applied.
    pub scratch: Scratch,
    /// Its `verdem`.
    pub bin: PathBuf,
    /// Cargo's log of its build.
    pub log: String,
    /// Whether this test built it (else an earlier test of the suite did, for the same
    /// sources).
    pub built_here: bool,
}

/// The copy of the crate at `origin` with every recipe applied ([`apply_every_recipe`]) and its
/// binary, built by the first test that asks for it and reused by the others: under
/// `CARGO_TARGET_TMPDIR/recipes`, in a folder named by the SHA-256 of the profile, the crate's
/// files and the toys, taken under a lock (`flock(2)`) so that two tests never build at once;
/// the folders of other sources are removed when a new one is built.
pub fn every_recipe(origin: &Path) -> Shared {
    let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("recipes");
    fs::create_dir_all(&cache).unwrap();
    let lock = fs::File::create(cache.join(".lock")).unwrap();
    // SAFETY: flock(2) on the descriptor of a file this function holds open.
    assert_eq!(unsafe { libc::flock(lock.as_raw_fd(), libc::LOCK_EX) }, 0);
    let dir = cache.join(sources_key(origin));
    let copy = dir.join("crate");
    let (bin_file, log_file, done) = (dir.join("bin"), dir.join("build.log"), dir.join("done"));
    if done.exists() {
        return Shared {
            scratch: Scratch {
                dir: copy,
                origin: origin.to_path_buf(),
            },
            bin: PathBuf::from(fs::read_to_string(&bin_file).unwrap()),
            log: fs::read_to_string(&log_file).unwrap(),
            built_here: false,
        };
    }
    for entry in fs::read_dir(&cache).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            fs::remove_dir_all(&path).unwrap();
        }
    }
    fs::create_dir_all(&copy).unwrap();
    let scratch = Scratch::copy_crate(origin, &copy);
    apply_every_recipe(&scratch);
    let (bin, log) = scratch.build();
    fs::write(&bin_file, bin.to_str().unwrap()).unwrap();
    fs::write(&log_file, &log).unwrap();
    fs::write(&done, "").unwrap();
    Shared {
        scratch,
        bin,
        log,
        built_here: true,
    }
}

/// The SHA-256 (first 16 hex digits) of what a scratch build depends on: the running test's
/// profile, every file of the crate at `origin` that the copy takes (path and bytes) and the
/// toys.
fn sources_key(origin: &Path) -> String {
    let mut files = Vec::new();
    for rel in CRATE_FILES.into_iter().chain(["src"]) {
        list_files(origin, Path::new(rel), &mut files);
    }
    files.sort();
    let mut h = Sha256::new();
    h.update(running_target().1.as_bytes());
    for rel in files {
        h.update(rel.to_string_lossy().as_bytes());
        h.update(fs::read(origin.join(&rel)).unwrap());
    }
    for toy in [TOY_CONVENTION, TOY_DAMPING, TOY_DAMPING_FILE, TOY_PEER] {
        h.update(toy.as_bytes());
    }
    h.finalize()[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Runs `bin` with `args` from the directory `cwd` and returns its output, whatever its status.
pub fn run(bin: &Path, cwd: &Path, args: &[&str]) -> Output {
    Command::new(bin)
        .current_dir(cwd)
        .args(args)
        .output()
        .unwrap()
}

/// Whether a file of a target directory's `deps`, `build` or `.fingerprint` is verdem's own.
fn is_verdem(name: &str) -> bool {
    ["verdem-", "libverdem-", "verdem.", "libverdem."]
        .iter()
        .any(|p| name.starts_with(p))
}

/// The target directory and the profile the running test binary was built in: the binary is
/// `TARGET/PROFILE_DIR/deps/NAME`, where the directory `debug` is the profile `dev`.
fn running_target() -> (PathBuf, String) {
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("TARGET/PROFILE/deps");
    let name = profile_dir
        .file_name()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    let profile = if name == "debug" { "dev".into() } else { name };
    (profile_dir.parent().unwrap().to_path_buf(), profile)
}

/// The lines of `a` beyond those of `b`, counted with multiplicity, in `a`'s order.
fn surplus(a: &str, b: &str) -> Vec<String> {
    let mut left: BTreeMap<&str, usize> = BTreeMap::new();
    for l in b.lines() {
        *left.entry(l).or_default() += 1;
    }
    let mut out = Vec::new();
    for l in a.lines() {
        match left.get_mut(l) {
            Some(n) if *n > 0 => *n -= 1,
            _ => out.push(l.to_string()),
        }
    }
    out
}

/// Copies the file or directory `from` to `to`, recursively, keeping the files' modification
/// times (cargo compares them to decide what is fresh).
fn copy_tree(from: &Path, to: &Path) {
    if from.is_dir() {
        fs::create_dir_all(to).unwrap();
        for entry in fs::read_dir(from).unwrap() {
            let entry = entry.unwrap();
            copy_tree(&entry.path(), &to.join(entry.file_name()));
        }
    } else {
        fs::copy(from, to).unwrap_or_else(|e| panic!("{}: {e}", from.display()));
        let modified = fs::metadata(from).and_then(|m| m.modified()).unwrap();
        let file = fs::File::options().write(true).open(to).unwrap();
        file.set_modified(modified).unwrap();
    }
}

/// Appends the files under `root/rel` to `out`, as paths relative to `root`.
fn list_files(root: &Path, rel: &Path, out: &mut Vec<PathBuf>) {
    let path = root.join(rel);
    if path.is_dir() {
        for entry in fs::read_dir(&path).unwrap() {
            list_files(root, &rel.join(entry.unwrap().file_name()), out);
        }
    } else if path.is_file() {
        out.push(rel.to_path_buf());
    }
}
