//! `docs/extending.md`'s recipes for a tangential convention and a normal law, applied
//! literally to a copy of the crate: a toy convention (the objective law with a 1.0001 × kt
//! spring) as one registry line, a toy damping (the linear spring with a 1.0001 × γn dashpot)
//! as one new file and one registry line. The change must be exactly those (beside the toy
//! peer of `tests/recipe_peer.rs`, which shares the copy: `scratch::every_recipe`), the copy
//! must build, its `verdem verify` must judge the toy convention's rows and its `verdem run` of
//! a case naming the toy damping must run under the run guard.

mod common;
#[path = "common/scratch.rs"]
mod scratch;

use std::collections::BTreeMap;
use std::path::Path;

use scratch::{Change, TOY_CONVENTION, TOY_DAMPING, TOY_DAMPING_FILE};

/// The rows of a `verdem verify` table: case, quantity and result, by case and quantity. A row
/// ends in five words (expected, measured, tolerance, its kind, result); before them the case
/// and the quantity are padded cells, apart by two spaces or more.
fn table(stdout: &str) -> BTreeMap<(String, String), String> {
    stdout
        .lines()
        .skip(1)
        .filter_map(|line| {
            let result = line.split_whitespace().last()?.to_string();
            let mut head = line.trim_end();
            for _ in 0..5 {
                head = head[..head.rfind(' ')?].trim_end();
            }
            let cells: Vec<&str> = head
                .split("  ")
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .collect();
            match cells[..] {
                [case, quantity] => Some(((case.to_string(), quantity.to_string()), result)),
                _ => None,
            }
        })
        .collect()
}

/// Runs `bin` on a tiny case, the binary collision with `[contact] normal = "NORMAL"`, in a
/// folder of its own under `dir` named `label`, and returns its output once it succeeded.
fn run_collision(bin: &Path, dir: &Path, label: &str, normal: &str) -> String {
    let text = std::fs::read_to_string(common::root().join("cases/verify/binary_collision.toml"))
        .unwrap()
        .replace(
            "[contact]\n",
            &format!("[contact]\nnormal = \"{normal}\"\n"),
        );
    let folder = dir.join(label);
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("case.toml"), text).unwrap();
    let out = scratch::run(bin, &folder, &["run", "case.toml"]);
    assert!(
        out.status.success(),
        "{label}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The state hash a `verdem run` printed.
fn state_hash(stdout: &str) -> String {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix("state hash: "))
        .unwrap_or_else(|| panic!("no state hash in {stdout}"))
        .to_string()
}

#[test]
fn the_documented_recipes_add_a_tangential_convention_and_a_damping_that_verify_and_run_judge() {
    let started = std::time::Instant::now();
    let root = common::root();
    let docs = std::fs::read_to_string(root.join("docs/extending.md")).unwrap();
    for form in [
        "Variant = \"name\", |p| Model::new(p.kt, p.gammat, p.mu), [properties], \"one-line description\";",
        "Variant = \"name\", mod FILE, reads [Kn, Gamman], |p| Damped { spring: Linear { kn: p.kn }, damping: FILE::Model { gamman: p.gamman } }, \"one-line description\";",
        "`src/contact/normal_laws/FILE.rs`",
    ] {
        assert!(docs.contains(form), "docs/extending.md no longer gives {form}");
    }

    let shared = scratch::every_recipe(&root);
    let changes = shared.scratch.changes();
    assert_eq!(changes, scratch::expected_changes());
    // this test's recipes: one line in each registry, one new file
    let one_line = |line: &str| Change::Lines {
        added: vec![line.to_string()],
        removed: vec![],
    };
    let ours = BTreeMap::from([
        ("src/contact/normal_laws.rs", one_line(TOY_DAMPING)),
        ("src/contact/normal_laws/toy_damping.rs", Change::New),
        ("src/contact/registry.rs", one_line(TOY_CONVENTION)),
    ]);
    for (file, change) in &ours {
        assert_eq!(changes.get(*file), Some(change), "{file}");
    }
    let bin = shared.bin;
    let built = started.elapsed();

    // verify: every row of the objective law has the toy's, judged; the rows the toy's
    // properties (objective, twists_spring) promise gate and pass
    let own = common::verdem_ok(["verify"]);
    let out = scratch::run(&bin, &root, &["verify"]);
    let (own, theirs) = (
        table(&String::from_utf8_lossy(&own.stdout)),
        table(&String::from_utf8_lossy(&out.stdout)),
    );
    let objective: Vec<_> = own
        .keys()
        .filter(|(case, _)| case.split_whitespace().any(|w| w == "objective"))
        .collect();
    assert!(
        objective.len() > 40,
        "{} rows of the objective law",
        objective.len()
    );
    let mut toy_rows = 0;
    for (case, quantity) in &objective {
        let toy_case = case
            .replace(" objective ", " toy-stiffer ")
            .replace(" objective", " toy-stiffer");
        let result = theirs
            .get(&(toy_case.clone(), quantity.clone()))
            .unwrap_or_else(|| panic!("no row {toy_case:?} {quantity:?} for the toy"));
        assert!(
            ["PASS", "FAIL", "FAIL*"].contains(&result.as_str()),
            "{toy_case}: {result}"
        );
        if ["objectivity", "ratchet"]
            .iter()
            .any(|k| case.starts_with(k))
            || quantity.starts_with("residual |Ft|")
        {
            assert_eq!(result, "PASS", "{toy_case} {quantity}");
        }
        toy_rows += 1;
    }
    assert_eq!(theirs.len(), own.len() + toy_rows);
    for (key, result) in &own {
        assert_eq!(
            theirs.get(key),
            Some(result),
            "{key:?} changed with the toys"
        );
    }
    let verified = started.elapsed();

    // run: a case naming the toy damping runs under the run guard, and differs from the linear
    // law's run only by its damping
    let dir = tempfile::tempdir().unwrap();
    let mut hashes = Vec::new();
    for normal in ["linear", "toy-damping"] {
        let stdout = run_collision(&bin, dir.path(), normal, normal);
        assert!(stdout.contains("run guard: largest overlap"), "{stdout}");
        hashes.push(state_hash(&stdout));
    }
    let own_bin = Path::new(env!("CARGO_BIN_EXE_verdem"));
    let own_hash = state_hash(&run_collision(own_bin, dir.path(), "own", "linear"));
    assert_eq!(hashes[0], own_hash, "the default law changed with the toys");
    assert_ne!(hashes[1], hashes[0], "the toy damping had no effect");
    eprintln!(
        "recipe: the toy convention is 1 registry line, the toy damping 1 registry line and a \
         file of {} lines",
        TOY_DAMPING_FILE.lines().count()
    );
    eprintln!(
        "recipe: copy and build {:.0} s ({}), verify {:.0} s, runs {:.0} s",
        built.as_secs_f64(),
        if shared.built_here {
            "built here"
        } else {
            "the suite's build, reused"
        },
        (verified - built).as_secs_f64(),
        (started.elapsed() - verified).as_secs_f64()
    );
}
