//! The library's dependencies run one way: every `crate::` path in `src/` (the library; the
//! command line in `src/main.rs` and `src/cli/` sits above it all) names a module on a lower line
//! of the layer list in `docs/architecture.md`, read from there so that the document and this
//! test cannot drift apart. Unit-test modules (`#[cfg(test)] mod … { … }`) may use any layer for
//! their fixtures and are not read; neither are comments.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// An import of a module from one on the same line or above it.
#[derive(Debug, PartialEq)]
struct Upward {
    file: String,
    line: usize,
    from: String,
    to: String,
}

impl std::fmt::Display for Upward {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}:{}: `{}` uses `{}`, which is not below it in docs/architecture.md's layers",
            self.file, self.line, self.from, self.to
        )
    }
}

/// The layers of `doc` (the text of docs/architecture.md), top first: the lines of its fenced
/// block opened by "```layers", each a layer of module names separated by spaces. Each module
/// is mapped to its layer's depth (0 at the top).
fn layers(doc: &str) -> BTreeMap<String, usize> {
    let block = doc
        .split("```layers\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("docs/architecture.md has a ```layers block");
    let mut depth = BTreeMap::new();
    for (k, line) in block.lines().filter(|l| !l.trim().is_empty()).enumerate() {
        for module in line.split_whitespace() {
            let again = depth.insert(module.to_string(), k);
            assert!(again.is_none(), "layers: `{module}` is listed twice");
        }
    }
    depth
}

/// The module path of a library file (`src/a/b.rs` and `src/a/b/mod.rs`: `a::b`).
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .skip(1)
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file under src/");
    let stem = last.trim_end_matches(".rs");
    if stem != "mod" {
        parts.push(stem.to_string());
    }
    parts
}

/// The code of `text`: its lines with comments cut and `#[cfg(test)]` modules blanked (line
/// numbers kept).
fn code_of(text: &str) -> String {
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let code = line.split("//").next().unwrap_or("");
        out.push(code);
        if code.trim() != "#[cfg(test)]" {
            continue;
        }
        let Some(opening) = lines.next() else { break };
        if !(opening.trim_start().starts_with("mod ") && opening.trim_end().ends_with('{')) {
            out.push(opening.split("//").next().unwrap_or(""));
            continue;
        }
        // rustfmt closes a module with a `}` at its own indentation
        let indent = &opening[..opening.len() - opening.trim_start().len()];
        let closing = format!("{indent}}}");
        out.push("");
        for l in lines.by_ref() {
            out.push("");
            if l.trim_end() == closing {
                break;
            }
        }
    }
    out.join("\n")
}

/// The top-level modules that `code` (see [`code_of`]) of the file of `module` (its module
/// path) names, each with the line (from 1) of its path: `crate::m…`, `crate::{m…, n::…}` (on
/// one line or several) and the `super::` paths that climb to the crate's root.
fn named_modules(code: &str, module: &[String]) -> Vec<(usize, String)> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let line_of = |at: usize| code[..at].matches('\n').count() + 1;
    let mut out = Vec::new();
    // The module a path names from `at`: its first segment, or those of a `{…}` group.
    let first_segments = |at: usize| {
        let rest = &code[at..];
        let Some(group) = rest.strip_prefix('{') else {
            let name: String = rest.chars().take_while(|&c| ident(c)).collect();
            return vec![(at, name)];
        };
        let (mut depth, mut item_start, mut items) = (0, 0, Vec::new());
        for (k, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    items.push(item_start);
                    break;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    items.push(item_start);
                    item_start = k + 1;
                }
                _ => {}
            }
        }
        items
            .into_iter()
            .map(|k| {
                let item = &group[k..];
                let skip = item.len() - item.trim_start().len();
                let name: String = item
                    .trim_start()
                    .chars()
                    .take_while(|&c| ident(c))
                    .collect();
                (at + 1 + k + skip, name)
            })
            .collect()
    };
    let mut paths = Vec::new();
    for (at, _) in code.match_indices("crate::") {
        if !code[..at].ends_with(|c: char| ident(c) || c == '$' || c == ':') {
            paths.push(at + "crate::".len());
        }
    }
    let mut from = 0;
    while let Some(k) = code[from..].find("super::") {
        let start = from + k;
        let mut end = start;
        let mut climbs = 0;
        while code[end..].starts_with("super::") {
            end += "super::".len();
            climbs += 1;
        }
        from = end;
        let prefixed = code[..start].ends_with(|c: char| ident(c) || c == ':');
        if !prefixed && climbs >= module.len() {
            paths.push(end);
        }
    }
    for at in paths {
        for (at, name) in first_segments(at) {
            // lower case: a module; upper case: an item of the crate's root (`crate::Vec3`)
            if name.starts_with(|c: char| c.is_ascii_lowercase()) {
                out.push((line_of(at), name));
            }
        }
    }
    out.sort();
    out
}

/// The imports of `files` (path relative to the repository, text) that run against `depth`.
fn upward_imports(depth: &BTreeMap<String, usize>, files: &[(PathBuf, String)]) -> Vec<Upward> {
    let mut out = Vec::new();
    for (rel, text) in files {
        let module = module_path(rel);
        let Some(from) = module.first() else { continue };
        let mine = depth
            .get(from)
            .unwrap_or_else(|| panic!("{}: module `{from}` is not in the layers", rel.display()));
        for (line, to) in named_modules(&code_of(text), &module) {
            if &to == from {
                continue;
            }
            let theirs = depth.get(&to).unwrap_or_else(|| {
                panic!(
                    "{}:{line}: module `{to}` is not in the layers",
                    rel.display()
                )
            });
            if theirs <= mine {
                out.push(Upward {
                    file: rel.display().to_string(),
                    line,
                    from: from.clone(),
                    to,
                });
            }
        }
    }
    out
}

/// The library's files (`src/` but the crate's root, `main.rs` and `cli/`), relative to `root`.
fn library_files(root: &Path) -> Vec<(PathBuf, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let mut paths = Vec::new();
    walk(&root.join("src"), &mut paths);
    paths.sort();
    paths
        .into_iter()
        .map(|p| p.strip_prefix(root).unwrap().to_path_buf())
        .filter(|rel| {
            let outside = ["src/lib.rs", "src/main.rs"].map(Path::new);
            !outside.contains(&rel.as_path()) && !rel.starts_with("src/cli")
        })
        .map(|rel| {
            let text = std::fs::read_to_string(root.join(&rel)).unwrap();
            (rel, text)
        })
        .collect()
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn documented_layers() -> BTreeMap<String, usize> {
    layers(&std::fs::read_to_string(root().join("docs/architecture.md")).unwrap())
}

#[test]
fn every_import_runs_down_the_documented_layers() {
    let depth = documented_layers();
    let files = library_files(&root());
    assert!(files.len() > 50, "the library's files are read");
    let upward = upward_imports(&depth, &files);
    let lines: Vec<String> = upward.iter().map(Upward::to_string).collect();
    assert!(
        upward.is_empty(),
        "imports against the order:\n{}",
        lines.join("\n")
    );
}

/// Every top-level module of the library is in the layers, and every module listed exists.
#[test]
fn the_layers_list_the_library_s_modules() {
    let depth = documented_layers();
    let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    let declared: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';'))
        .collect();
    let mut listed: Vec<&str> = depth.keys().map(String::as_str).collect();
    let mut sorted = declared.clone();
    sorted.sort_unstable();
    listed.sort_unstable();
    assert_eq!(
        listed, sorted,
        "docs/architecture.md's layers against src/lib.rs"
    );
}

/// A planted import of a module from one below it is caught, naming the file, the line and
/// both modules, through each form of path; a downward one, a comment and a unit test are not.
#[test]
fn a_planted_upward_import_is_caught() {
    let depth = layers("text\n```layers\nrun\nio\nstep\nstate neighbor\n```\n");
    let file = |path: &str, text: &str| (PathBuf::from(path), text.to_string());
    let files = [
        file(
            "src/state/particles.rs",
            "use crate::state::Domain;\n// crate::run, in a comment\nuse crate::step::Core;\n",
        ),
        file("src/neighbor/mod.rs", "fn f() { let _ = crate::{io::open, state::X}; }\n"),
        file("src/neighbor/grid.rs", "use crate::{\n    state::X,\n    step::{Core, Y},\n};\n"),
        file("src/step/core.rs", "use super::super::run::Observer;\nuse super::Core;\n"),
        file("src/io.rs", "use crate::state::Snapshot;\nuse crate::Vec3;\n"),
        file(
            "src/state/domain.rs",
            "fn f() {}\n\n#[cfg(test)]\nmod tests {\n    use crate::run;\n}\nuse crate::neighbor::X;\n",
        ),
    ];
    let found = upward_imports(&depth, &files);
    let at = |file: &str, line, from: &str, to: &str| Upward {
        file: file.into(),
        line,
        from: from.into(),
        to: to.into(),
    };
    assert_eq!(
        found,
        [
            at("src/state/particles.rs", 3, "state", "step"),
            at("src/neighbor/mod.rs", 1, "neighbor", "io"),
            at("src/neighbor/mod.rs", 1, "neighbor", "state"),
            at("src/neighbor/grid.rs", 2, "neighbor", "state"),
            at("src/neighbor/grid.rs", 3, "neighbor", "step"),
            at("src/step/core.rs", 1, "step", "run"),
            at("src/state/domain.rs", 7, "state", "neighbor"),
        ]
    );
    assert_eq!(
        found[0].to_string(),
        "src/state/particles.rs:3: `state` uses `step`, which is not below it in \
         docs/architecture.md's layers"
    );
}

/// The solver and its files (`run` and every layer below it) return their own error types, so
/// that a program embedding the library can match on them: none of their code uses `anyhow`
/// (the tools above may).
#[test]
fn the_solver_s_layers_return_their_own_error_types() {
    let depth = documented_layers();
    let run = depth["run"];
    let files = library_files(&root());
    let solver: Vec<&(PathBuf, String)> = files
        .iter()
        .filter(|(rel, _)| depth.get(&module_path(rel)[0]).is_some_and(|&d| d >= run))
        .collect();
    assert!(solver.len() > 40, "the solver's files are read");
    let users: Vec<String> = solver
        .iter()
        .filter(|(_, text)| code_of(text).contains("anyhow"))
        .map(|(rel, _)| rel.display().to_string())
        .collect();
    assert!(users.is_empty(), "anyhow in the solver's layers: {users:?}");
}
