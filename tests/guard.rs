//! The run guard stops a run whose numbers cannot be trusted, names the step, the particles
//! and the quantity, exits with its own status (3), and writes no NaN or infinity into any file.

mod common;

use std::path::Path;

/// A two-sphere case: the binary collision's law and box, the spheres at `x1`, `x2` with
/// velocities `v1`, `v2` along x, dt = tc / `per_tc`, `steps` steps, a save every `every`.
fn two_spheres(
    dir: &Path,
    x: [f64; 2],
    v: [f64; 2],
    per_tc: f64,
    steps: u64,
    every: u64,
) -> String {
    let text = format!(
        r#"name = "pair"
[run]
steps = {steps}
save_every = {every}
steps_per_collision = {per_tc}
threads = 1
[domain]
lo = [-5.0, -5.0, -5.0]
hi = [5.0, 5.0, 5.0]
periodic = [false, false, false]
[material]
density = 1.0
diameter = 1.0
[contact]
kn = 2e5
gamman = 15.0
kt = 57142.857142857145
gammat = 4.285714285714286
mu = 0.3
[scene]
kind = "spheres"
[[scene.sphere]]
x = [{}, 0.0, 0.0]
v = [{}, 0.0, 0.0]
[[scene.sphere]]
x = [{}, 0.0, 0.0]
v = [{}, 0.0, 0.0]
"#,
        x[0], v[0], x[1], v[1]
    );
    let path = dir.join("pair.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Runs `verdem run CASE --out DIR --quiet`; returns the exit status and stderr.
fn run(case: &str, out: &Path) -> (Option<i32>, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .args(["run", case, "--quiet", "--out"])
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// No file of `dir` holds a NaN or an infinity.
fn no_garbage(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if let Ok(text) = std::fs::read_to_string(&p) {
            let lower = text.to_lowercase();
            assert!(
                !lower.contains("nan") && !lower.contains("inf"),
                "{} holds a NaN or an infinity",
                p.display()
            );
        }
    }
}

#[test]
fn coincident_spheres_are_stopped_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [0.0, 0.0], [0.0, 0.0], 50.0, 100, 10);
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("step 0"), "{err}");
    assert!(err.contains("particle 1 and 2"), "{err}");
    assert!(err.contains("overlap"), "{err}");
    assert!(err.contains("last save none"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    no_garbage(&out);
}

/// dt = tc/1.3: within the stability limit of one free–wall contact (tc/1.137), which the case
/// validation checks, but beyond that of a free sphere squeezed between two wall spheres (two
/// springs at once: √2 times the frequency; the spectral radius of its step is 3.8). Unstable
/// runs used to end with exit status 0.
#[test]
fn an_unstable_time_step_is_stopped_with_its_step_and_particles() {
    let dir = tempfile::tempdir().unwrap();
    let pair = two_spheres(dir.path(), [0.0, -0.98], [-0.1, 0.0], 1.3, 2000, 10);
    let text = std::fs::read_to_string(&pair).unwrap().replace(
        "x = [-0.98, 0.0, 0.0]\nv = [0, 0.0, 0.0]\n",
        "x = [-0.98, 0.0, 0.0]\nfixed = true\n[[scene.sphere]]\nx = [0.98, 0.0, 0.0]\nfixed = true\n",
    );
    assert!(text.contains("fixed"), "{text}");
    let case = dir.path().join("squeeze.toml");
    std::fs::write(&case, text).unwrap();
    let case = case.display().to_string();
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("the run guard stopped the run at step"),
        "{err}"
    );
    assert!(
        err.contains("particle 1 and 2")
            || err.contains("particle 1:")
            || err.contains("particle 2:"),
        "{err}"
    );
    assert!(
        err.contains("last save ") && err.contains("pair.data.00"),
        "the last good save is named: {err}"
    );
    no_garbage(&out);
}

/// The same collision at the benchmark's dt = tc/50 runs to its end: the guard does not stop a
/// sound run.
#[test]
fn a_sound_collision_runs_to_its_end() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [-1.0, 1.0], [5.0, -5.0], 50.0, 2000, 500);
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(0), "{err}");
    no_garbage(&out);
}

#[test]
fn the_overlap_limit_is_read_from_the_case_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [-1.0, 1.0], [5.0, -5.0], 50.0, 2000, 500);
    let text = std::fs::read_to_string(&case).unwrap();
    // At 5 units of speed the overlap peaks near 5·√(0.26/2e5) ≈ 5.7e-3, above 1e-3 of r.
    std::fs::write(&case, format!("{text}[guard]\noverlap = 0.002\n")).unwrap();
    let (code, err) = run(&case, &dir.path().join("tight"));
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("exceeds the limit 1e-3"), "{err}");
    std::fs::write(&case, format!("{text}[guard]\noverlap = 1.5\n")).unwrap();
    let (code, err) = run(&case, &dir.path().join("wide"));
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("guard.overlap: a fraction of the smaller radius at most 1"),
        "{err}"
    );
}
