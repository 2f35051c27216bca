//! Bad case files are refused by `verdem run` with `file:line: field: message` and a non-zero
//! exit status, never a panic; a time step beyond the scheme's stability limit is refused with
//! the limit, a coarse one is run with a warning. Each bad case is a valid case of `cases/`
//! with one line changed.

mod common;

use std::path::Path;
use std::process::Command;

/// `verdem run CASE --steps 0 --quiet --out DIR/out`: exit status, stdout and stderr.
fn run(case: &Path) -> (Option<i32>, String, String) {
    let out = case.parent().unwrap().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .arg("run")
        .arg(case)
        .args(["--steps", "0", "--quiet", "--force", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The case `cases/NAME` with its one line that starts with `line` (after indentation)
/// replaced by `with`, written as `DIR/bad.toml`; returns its path and its text.
fn edited(dir: &Path, name: &str, line: &str, with: &str) -> (std::path::PathBuf, String) {
    let text = std::fs::read_to_string(common::root().join("cases").join(name)).unwrap();
    let hits = text
        .lines()
        .filter(|l| l.trim_start().starts_with(line))
        .count();
    assert_eq!(hits, 1, "{name}: {hits} lines start with {line:?}");
    let bad: Vec<&str> = text
        .lines()
        .map(|l| {
            if l.trim_start().starts_with(line) {
                with
            } else {
                l
            }
        })
        .collect();
    let bad = bad.join("\n") + "\n";
    let path = dir.join("bad.toml");
    std::fs::write(&path, &bad).unwrap();
    (path, bad)
}

/// One bad case: the case it starts from, the line it changes and how, the line of the result
/// the error must point at (the first one starting with `at`), the field it must name and a
/// part of the message.
struct Bad {
    case: &'static str,
    line: &'static str,
    with: &'static str,
    at: &'static str,
    field: &'static str,
    says: &'static str,
}

const QUICK: &str = "shear_flow_quick.toml";
const PAIR: &str = "verify/binary_collision.toml";
const WALL: &str = "verify/oblique_impact.toml";
const GAS: &str = "verify/conservation.toml";

fn bad(
    case: &'static str,
    line: &'static str,
    with: &'static str,
    at: &'static str,
    field: &'static str,
    says: &'static str,
) -> Bad {
    Bad {
        case,
        line,
        with,
        at,
        field,
        says,
    }
}

/// Runs every bad case; each must fail with status 1 and `bad.toml:LINE: FIELD: ...SAYS...`.
fn refused(cases: &[Bad]) {
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for b in cases {
        let (path, text) = edited(dir.path(), b.case, b.line, b.with);
        let line = text
            .lines()
            .position(|l| l.trim_start().starts_with(b.at))
            .unwrap_or_else(|| panic!("no line starts with {:?}", b.at))
            + 1;
        let (code, _, err) = run(&path);
        let head = format!("{}:{line}: {}: ", path.display(), b.field);
        let ok = code == Some(1)
            && err.contains(&head)
            && err.contains(b.says)
            && !err.contains("panicked");
        if !ok {
            failures.push(format!(
                "{} with {:?}: status {code:?}, expected {head:?} … {:?}; got:\n{err}",
                b.case, b.with, b.says
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn malformed_toml_unknown_missing_and_mistyped_fields() {
    refused(&[
        bad(
            QUICK,
            "kn = ",
            "kn = = 2e5",
            "kn = ",
            "contact.kn",
            "invalid",
        ),
        bad(
            QUICK,
            "[contact]",
            "[contact",
            "[contact",
            "contact",
            "invalid",
        ),
        bad(
            QUICK,
            "mu = ",
            "muu = 0.3",
            "muu",
            "contact.muu",
            "unknown field `muu`",
        ),
        bad(
            QUICK,
            "top_vx = ",
            "top_v = 1.0",
            "top_v",
            "scene.top_v",
            "unknown field",
        ),
        bad(
            PAIR,
            "v = [1.0",
            "vv = [1.0, 0.0, 0.0]",
            "vv",
            "scene.sphere[0].vv",
            "unknown field",
        ),
        bad(
            QUICK,
            "kn = ",
            "",
            "[contact]",
            "contact.kn",
            "missing field `kn`",
        ),
        bad(
            PAIR,
            "x = [0.5005",
            "x = [0.5005, 0.0]",
            "x = [0.5005",
            "scene.sphere[1].x",
            "invalid length 2",
        ),
        bad(
            QUICK,
            "name = ",
            "",
            "# Quick",
            "name",
            "missing field `name`",
        ),
        bad(
            QUICK,
            "density = ",
            "density = \"one\"",
            "density",
            "material.density",
            "invalid type",
        ),
        bad(
            QUICK,
            "steps = ",
            "steps = -5",
            "steps",
            "run.steps",
            "invalid value",
        ),
        bad(
            QUICK,
            "free = ",
            "free = 2.5",
            "free",
            "scene.free",
            "invalid type",
        ),
        bad(QUICK, "kn = ", "kn = 1e999", "kn", "contact.kn", "invalid"),
        bad(
            QUICK,
            "seed = ",
            "seed = 1\nseed = 2",
            "seed = 2",
            "run.seed",
            "duplicate key",
        ),
    ]);
}

/// A key missing from the second element of an array of tables is named with its index, at
/// that element's header.
#[test]
fn a_key_missing_from_an_array_element_names_the_element() {
    let dir = tempfile::tempdir().unwrap();
    let (path, text) = edited(dir.path(), PAIR, "x = [0.5005", "fixed = false");
    let line = text
        .lines()
        .enumerate()
        .filter(|(_, l)| *l == "[[scene.sphere]]")
        .nth(1)
        .unwrap()
        .0
        + 1;
    let (code, _, err) = run(&path);
    assert_eq!(code, Some(1), "{err}");
    let head = format!(
        "{}:{line}: scene.sphere[1].x: missing field `x`",
        path.display()
    );
    assert!(err.contains(&head), "{err}");
}

#[test]
fn non_physical_values() {
    refused(&[
        bad(
            QUICK,
            "kn = ",
            "kn = 0.0",
            "kn",
            "contact.kn",
            "must be > 0, got 0",
        ),
        bad(
            QUICK,
            "kn = ",
            "kn = -2e5",
            "kn",
            "contact.kn",
            "must be > 0, got -200000",
        ),
        bad(
            QUICK,
            "kt = ",
            "kt = -1.0",
            "kt",
            "contact.kt",
            "must be >= 0, got -1",
        ),
        bad(
            QUICK,
            "gammat = ",
            "gammat = -1.0",
            "gammat",
            "contact.gammat",
            "must be >= 0",
        ),
        bad(
            QUICK,
            "density = ",
            "density = 0.0",
            "density",
            "material.density",
            "must be > 0",
        ),
        bad(
            QUICK,
            "diameter = ",
            "diameter = -1.0",
            "diameter",
            "material.diameter",
            "must be > 0",
        ),
        bad(
            WALL,
            "radius = ",
            "radius = 0.0",
            "radius",
            "scene.sphere[1].radius",
            "must be > 0, got 0",
        ),
        bad(
            QUICK,
            "mu = ",
            "mu = -0.1",
            "mu",
            "contact.mu",
            "must be >= 0, got -0.1",
        ),
        bad(
            QUICK,
            "dt = ",
            "dt = 0.0",
            "dt",
            "run.dt",
            "must be > 0, got 0",
        ),
        bad(QUICK, "dt = ", "dt = -1e-5", "dt", "run.dt", "must be > 0"),
        bad(
            PAIR,
            "steps_per_collision = ",
            "steps_per_collision = 0.0",
            "steps_per",
            "run.steps_per_collision",
            "must be > 0",
        ),
        bad(
            QUICK,
            "save_every = ",
            "save_every = 0",
            "save_every",
            "run.save_every",
            "must be > 0",
        ),
        bad(
            QUICK,
            "threads = ",
            "threads = 0",
            "threads",
            "run.threads",
            "must be > 0",
        ),
        bad(
            PAIR,
            "gamman = ",
            "gamman = 1e3",
            "steps_per_collision",
            "run.steps_per_collision",
            "over-damps the free–free contact",
        ),
    ]);
}

#[test]
fn nan_and_infinity_anywhere() {
    refused(&[
        bad(
            QUICK,
            "skin = ",
            "skin = nan",
            "skin",
            "neighbor.skin",
            "a finite number expected, got NaN",
        ),
        bad(
            QUICK,
            "kn = ",
            "kn = inf",
            "kn",
            "contact.kn",
            "a finite number expected, got inf",
        ),
        bad(
            QUICK,
            "lo = ",
            "lo = [0.0, -inf, 0.0]",
            "lo",
            "domain.lo[1]",
            "got -inf",
        ),
        bad(
            QUICK,
            "top_vx = ",
            "top_vx = nan",
            "top_vx",
            "scene.top_vx",
            "got NaN",
        ),
        bad(
            PAIR,
            "x = [0.5005",
            "x = [0.5005, nan, 0.0]",
            "x = [0.5005",
            "scene.sphere[1].x[1]",
            "got NaN",
        ),
        bad(
            PAIR,
            "v = [1.0",
            "v = [1.0, 0.0, +inf]",
            "v = ",
            "scene.sphere[0].v[2]",
            "got inf",
        ),
        bad(
            QUICK,
            "threads = ",
            "gravity = [0.0, 0.0, nan]",
            "gravity",
            "run.gravity[2]",
            "got NaN",
        ),
    ]);
}

#[test]
fn geometry_that_cannot_be_built() {
    refused(&[
        // bumpy walls whose spheres leave less than a diameter between them
        bad(
            QUICK,
            "top_z = ",
            "top_z = 1.5",
            "top_z",
            "scene.top_z",
            "got 1.5",
        ),
        bad(
            QUICK,
            "top_z = ",
            "top_z = 30.0",
            "top_z",
            "scene.top_z",
            "a wall inside the box",
        ),
        // bumpy walls wider than the box: their spheres overlap across the periodic seam
        bad(
            QUICK,
            "wall_rows = ",
            "wall_rows = 13",
            "wall_rows",
            "scene.wall_rows",
            "width along y",
        ),
        bad(
            QUICK,
            "wall_per_row = ",
            "wall_per_row = 4000000000000000000",
            "wall_per_row",
            "scene.wall_per_row",
            "at most 20",
        ),
        // a box smaller than a sphere, a periodic length that makes a sphere touch two images
        bad(
            PAIR,
            "hi = ",
            "hi = [5.0, 5.0, -4.5]",
            "hi",
            "domain.hi",
            "got 0.5",
        ),
        bad(
            GAS,
            "hi = ",
            "hi = [10.0, 10.0, 1.5]",
            "hi",
            "domain.hi",
            "periodic length along z",
        ),
        // more spheres than fit: beyond the densest packing, beyond the random fill's lattice
        bad(
            QUICK,
            "free = ",
            "free = 300000",
            "free",
            "scene.free",
            "densest packing",
        ),
        bad(
            QUICK,
            "free = ",
            "free = 3700",
            "free",
            "scene.free",
            "at most 3610 spheres",
        ),
        bad(
            GAS,
            "count = ",
            "count = 5000",
            "count",
            "scene.count",
            "densest packing",
        ),
        // a free sphere outside the box
        bad(
            PAIR,
            "x = [-0.5005",
            "x = [-50.0, 0.0, 0.0]",
            "x = [-50",
            "scene.sphere[0].x",
            "inside the box",
        ),
        // walls that cannot move as prescribed
        bad(
            QUICK,
            "periodic = ",
            "periodic = [false, true, false]",
            "bottom_vx",
            "scene.bottom_vx",
            "must then be periodic",
        ),
        bad(
            WALL,
            "radius = ",
            "radius = 500.0\nv = [0.0, 0.0, 100.0]",
            "v = [0.0, 0.0, 100",
            "scene.sphere[1].v",
            "stays in the box",
        ),
    ]);
}

#[test]
fn a_time_step_beyond_the_stability_limit_is_refused_with_the_limit() {
    refused(&[
        // the dt = 2 tc, two free spheres
        bad(
            PAIR,
            "steps_per_collision = ",
            "steps_per_collision = 0.5",
            "steps_per",
            "run.steps_per_collision",
            "free–free normal contact, dt = 2.21446e-3 (tc/dt = 1.6240",
        ),
        bad(
            QUICK,
            "dt = ",
            "dt = 3e-3",
            "dt = ",
            "run.dt",
            "got dt = 3.00000e-3",
        ),
        // one free sphere against a wall sphere: the free–wall limit, tc/1.137
        bad(
            WALL,
            "steps_per_collision = ",
            "steps_per_collision = 1.1",
            "steps_per",
            "run.steps_per_collision",
            "free–wall normal contact, dt = 3.16191e-3 (tc/dt = 1.1374",
        ),
        // a stiffer law at the benchmark's dt: the normal spring, then the tangential one
        bad(
            QUICK,
            "kn = ",
            "kn = 1e9",
            "dt = ",
            "run.dt",
            "free–free normal contact, dt = 3.23",
        ),
        bad(
            QUICK,
            "kt = ",
            "kt = 1e8",
            "dt = ",
            "run.dt",
            "free–free tangential contact",
        ),
    ]);
}

/// An over-damped contact (no collision time) with an explicit dt within its stability limit
/// runs, with a warning that its spheres do not rebound; beyond the limit it is refused.
#[test]
fn an_over_damped_contact_runs_with_an_explicit_time_step() {
    let dir = tempfile::tempdir().unwrap();
    let (path, text) = edited(dir.path(), PAIR, "gamman = ", "gamman = 1e3");
    let text = text.replace("steps_per_collision = 50.0", "dt = 1e-5");
    std::fs::write(&path, &text).unwrap();
    let (code, _, err) = run(&path);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("contact.gamman: over-damped contact"), "{err}");
    // 4/(c + √(c² + 4ω²)) with c = γ/meff, ω² = kn/meff: 5.0e-4 for meff = m/2
    std::fs::write(&path, text.replace("dt = 1e-5", "dt = 1e-3")).unwrap();
    let (code, _, err) = run(&path);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("run.dt: at most the stability limit"), "{err}");
}

/// A time step within the pair limit but coarse (tc/dt below 10) runs, with a warning on stderr
/// naming the expected restitution error; at tc/10 and finer nothing is said.
#[test]
fn a_coarse_time_step_runs_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    // one free sphere and a wall sphere: tc/1.3 is beyond the free–free limit, within free–wall
    let (path, text) = edited(
        dir.path(),
        WALL,
        "steps_per_collision = ",
        "steps_per_collision = 1.3",
    );
    let line = text
        .lines()
        .position(|l| l.starts_with("steps_per"))
        .unwrap()
        + 1;
    let (code, _, err) = run(&path);
    assert_eq!(code, Some(0), "{err}");
    let head = format!(
        "warning: {}:{line}: run.steps_per_collision: coarse time step, tc/dt = 1.300",
        path.display()
    );
    assert!(err.contains(&head), "{err}");
    // the error of the scheme on one collision, for the free–wall contact only (no free–free
    // contact in this scene)
    let named = |case_path: &std::path::Path, meff_of: fn(f64) -> f64| {
        let case = verdem::case::Case::load(case_path).unwrap();
        let spring = verdem::stability::Spring {
            k: case.contact.kn,
            gamma: case.contact.gamman,
        };
        let meff = meff_of(case.particle_mass());
        format!(
            "{:.1e}",
            verdem::stability::restitution_error(meff, spring, case.dt())
        )
    };
    let wall_error = named(&path, |m| m);
    assert!(err.contains(&format!("{wall_error} free–wall")), "{err}");
    assert!(!err.contains("free–free"), "{err}");

    let (path, _) = edited(
        dir.path(),
        PAIR,
        "steps_per_collision = ",
        "steps_per_collision = 8.0",
    );
    let (code, _, err) = run(&path);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("tc/dt = 8.000 (below 10)"), "{err}");
    // named only where the contacts exist: two free spheres
    let pair_error = named(&path, |m| 0.5 * m);
    assert!(err.contains(&format!("{pair_error} free–free")), "{err}");
    assert!(!err.contains("free–wall"), "{err}");

    for per_tc in ["10.0", "50.0"] {
        let (path, _) = edited(
            dir.path(),
            PAIR,
            "steps_per_collision = ",
            &format!("steps_per_collision = {per_tc}"),
        );
        let (code, _, err) = run(&path);
        assert_eq!(code, Some(0), "{err}");
        assert!(!err.contains("warning"), "tc/{per_tc}: {err}");
    }
}

#[test]
fn a_file_that_is_not_utf8_is_refused_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read(common::root().join("cases").join(PAIR)).unwrap();
    let at = text.windows(4).position(|w| w == b"kn =").unwrap();
    let mut bytes = text.clone();
    bytes[at] = 0xff;
    let line = text[..at].iter().filter(|&&b| b == b'\n').count() + 1;
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, bytes).unwrap();
    let (code, _, err) = run(&path);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "{}:{line}: -: UTF-8 text expected, got the byte 0xff",
            path.display()
        )),
        "{err}"
    );
}

/// Every case of the repository loads without an error or a warning.
#[test]
fn the_repositorys_cases_are_accepted_without_a_warning() {
    for name in [
        "shear_flow.toml",
        "shear_flow_quick.toml",
        "shear_flow_steady.toml",
        "verify/binary_collision.toml",
        "verify/conservation.toml",
        "verify/objectivity.toml",
        "verify/oblique_impact.toml",
    ] {
        let case = verdem::case::Case::load(&common::root().join("cases").join(name))
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(case.warnings().is_empty(), "{name}: {:?}", case.warnings());
    }
}
