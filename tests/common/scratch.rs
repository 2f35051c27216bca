//! A scratch copy of the crate for tests that apply a documented recipe to the sources, check
//! that the change is exactly the recipe's and build the result: the copy has its own target
//! directory, seeded with the running test's build of the dependencies so that only verdem
//! rebuilds, and never touches the binary the other tests run.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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

/// A copy of the crate in a temporary directory (removed when dropped).
pub struct Scratch {
    dir: tempfile::TempDir,
    origin: PathBuf,
}

impl Scratch {
    /// Copies `Cargo.toml`, `Cargo.lock`, `benches/` and `src/` of the crate at `origin`.
    pub fn copy_crate(origin: &Path) -> Scratch {
        let dir = tempfile::tempdir().expect("a temporary directory");
        for rel in CRATE_FILES.into_iter().chain(["src"]) {
            copy_tree(&origin.join(rel), &dir.path().join(rel));
        }
        Scratch {
            dir,
            origin: origin.to_path_buf(),
        }
    }

    /// The copy's root.
    pub fn path(&self) -> &Path {
        self.dir.path()
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
    /// own target directory seeded with the running test's dependencies (everything of the
    /// profile's `deps`, `build` and `.fingerprint` but verdem's own), and returns the binary.
    pub fn build(&self) -> PathBuf {
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
                if !is_verdem(&name) {
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
                "--bin",
                "verdem",
                "--profile",
                &profile,
            ])
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&out.stderr);
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
        bin
    }
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
