//! What a hostile or careless user tries (issue 46): runs that mix in one folder, links planted
//! in an output folder, parameters whose derived quantities a double cannot hold, velocities
//! whose energy overflows, sizes that would exhaust memory, names that are markup. Each is
//! refused with a message naming what and where, and no file holds a non-finite number.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The exit status, stdout and stderr of verdem run with `args` from the repository root, with
/// the extra environment `env`.
fn verdem_env(args: &[&str], env: &[(&str, &str)]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .args(args)
        .envs(env.iter().copied())
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn verdem(args: &[&str]) -> (Option<i32>, String, String) {
    verdem_env(args, &[])
}

const PAIR: &str = "cases/verify/binary_collision.toml";
const SHEAR: &str = "cases/shear_flow_steady.toml";

/// The binary-collision case with `from` replaced by `to` (once), written into `dir` as `name`.
fn pair_case(dir: &Path, name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(common::root().join(PAIR)).unwrap();
    assert!(text.contains(from), "{from} is not in {PAIR}");
    let p = dir.join(name);
    std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
    p.to_str().unwrap().to_string()
}

/// No text file of `dir` holds a non-finite number, as a reader would parse one.
fn all_finite(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if let Ok(bytes) = std::fs::read(&p) {
            assert_eq!(
                verdem::io::atomic::non_finite(&bytes),
                None,
                "{} holds a non-finite number",
                p.display()
            );
        }
    }
}

/// A child process killed when dropped, so that a failed assertion leaves no run behind.
struct Killed(std::process::Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn a_second_run_into_a_busy_folder_is_refused_naming_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let mut first = Killed(
        Command::new(env!("CARGO_BIN_EXE_verdem"))
            .current_dir(common::root())
            .args([
                "run",
                SHEAR,
                "--steps",
                "100000000",
                "--save-every",
                "1000000",
                "--quiet",
                "--out",
                out,
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let lock = dir.path().join(verdem::io::lock::LOCK_FILE);
    let deadline = Instant::now() + Duration::from_secs(60);
    while !std::fs::read_to_string(&lock).is_ok_and(|t| t.ends_with('\n')) {
        assert!(Instant::now() < deadline, "the first run took no lock");
        std::thread::sleep(Duration::from_millis(20));
    }
    for force in [false, true] {
        let mut args = vec!["run", SHEAR, "--steps", "10", "--quiet", "--out", out];
        if force {
            args.push("--force");
        }
        let (code, _, err) = verdem(&args);
        assert_eq!(code, Some(1), "{err}");
        assert!(
            err.contains(&format!(
                "{out}: another verdem run is writing into this folder (PID {}: ",
                first.0.id()
            )) && err.contains("--steps 100000000"),
            "{err}"
        );
    }
    // killed, the first run leaves its lock file, which the next run says and takes over
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    assert!(lock.exists());
    let (code, _, err) = verdem(&[
        "run", SHEAR, "--steps", "10", "--quiet", "--out", out, "--force",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("a run that did not end") && err.contains(&format!("PID {}", first.0.id())),
        "{err}"
    );
    assert!(!lock.exists(), "a finished run leaves no lock file");
}

#[test]
fn a_resume_without_out_continues_in_the_checkpoint_s_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("series");
    let args = ["run", PAIR, "--save-every", "10", "--quiet"];
    let first = ["--steps", "20", "--checkpoint-every", "20"];
    let (code, _, err) = verdem(&[&args[..], &first, &["--out", out.to_str().unwrap()]].concat());
    assert_eq!(code, Some(0), "{err}");
    let ck = out.join("binary_collision.checkpoint");
    let resume = ["--steps", "40", "--resume", ck.to_str().unwrap()];
    let (code, text, err) = verdem(&[&args[..], &resume].concat());
    assert_eq!(code, Some(0), "{err}");
    assert!(
        text.contains(&format!("saves 2 in {}", out.display())),
        "{text}"
    );
    assert!(out.join("binary_collision.data.0004").exists());
}

#[test]
fn a_link_planted_in_the_output_folder_is_not_written_through() {
    let dir = tempfile::tempdir().unwrap();
    let victim = dir.path().join("victim.txt");
    std::fs::write(&victim, "keep").unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // a link at a run file's name makes the folder one of an earlier run's; --force removes the
    // link itself, never what it points to (the writer refuses to append through one that
    // appears later: src/io/atomic.rs)
    let diag = out.join("binary_collision.diagnostics.csv");
    std::os::unix::fs::symlink(&victim, &diag).unwrap();
    let run = [
        "run",
        PAIR,
        "--steps",
        "10",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    let (code, _, err) = verdem(&run);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("already holds the files of a run"), "{err}");
    let (code, _, err) = verdem(&[&run[..], &["--force"]].concat());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
    assert!(!std::fs::symlink_metadata(&diag).unwrap().is_symlink());
    // a save is replaced atomically: a link at its name is replaced, never followed
    let out2 = dir.path().join("out2");
    std::fs::create_dir(&out2).unwrap();
    std::os::unix::fs::symlink(&victim, out2.join("binary_collision.summary.toml")).unwrap();
    let (code, _, err) = verdem(&[
        "run",
        PAIR,
        "--steps",
        "10",
        "--quiet",
        "--out",
        out2.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
    all_finite(&out2);
}

#[test]
fn parameters_whose_derived_quantities_are_not_representable_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (from, to, field) in [
        ("kn = 2e5", "kn = 1e308", "contact.kn"),
        ("density = 1.0", "density = 1e-320", "material.density"),
        ("steps_per_collision = 50.0", "dt = 1e-310", "run.dt"),
    ] {
        let case = pair_case(dir.path(), "c.toml", from, to);
        let out = dir.path().join("o");
        let (code, _, err) = verdem(&["run", &case, "--quiet", "--out", out.to_str().unwrap()]);
        assert_eq!(code, Some(1), "{to}: {err}");
        assert!(err.contains(&format!(": {field}: ")), "{to}: {err}");
        assert!(err.contains("represent"), "{to}: {err}");
        assert!(!out.join("binary_collision.data.0000").exists());
    }
}

#[test]
fn a_speed_whose_energy_overflows_stops_at_the_guard_and_writes_no_infinity() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(
        dir.path(),
        "c.toml",
        "v = [1.0, 0.0, 0.0]",
        "v = [1e300, 0.0, 0.0]",
    );
    let out = dir.path().join("o");
    let (code, _, err) = verdem(&["run", &case, "--quiet", "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("step 0") && err.contains("particle 1: velocity (or its kinetic energy"),
        "{err}"
    );
    all_finite(&out);
}

#[test]
fn hostile_sizes_are_refused_with_their_estimate_before_they_are_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let out = out.to_str().unwrap();
    // an initial file without line ends
    let (code, _, err) = verdem(&["run", SHEAR, "--init", "/dev/zero", "--quiet", "--out", out]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("/dev/zero:1: a line longer than"), "{err}");
    // a case file that never ends
    let (code, _, err) = verdem(&["run", "/dev/zero", "--quiet", "--out", out]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("/dev/zero") && err.contains("larger than the"),
        "{err}"
    );
    // tiles
    let (code, _, err) = verdem(&[
        "tile", SHEAR, "--nx", "100000", "--ny", "100000", "--out", out,
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("tiles 100000 × 100000") && err.contains("needs an estimated"),
        "{err}"
    );
    // spheres piled on one point: their neighbour list, against a small budget
    let text = std::fs::read_to_string(common::root().join(PAIR)).unwrap();
    let head = &text[..text.find("[[scene.sphere]]").unwrap()];
    let pile: String = std::iter::once(head.to_string())
        .chain((0..3000).map(|_| "[[scene.sphere]]\nx = [0.0, 0.0, 0.0]\n".to_string()))
        .collect();
    let case = dir.path().join("pile.toml");
    std::fs::write(&case, pile).unwrap();
    let budget = [(verdem::state::memory::BUDGET_VAR, "100000000")];
    let (code, _, err) = verdem_env(
        &["run", case.to_str().unwrap(), "--quiet", "--out", out],
        &budget,
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("the neighbour list of 3000 spheres (up to 4.498e6 pairs in reach")
            && err.contains(verdem::state::memory::BUDGET_VAR),
        "{err}"
    );
    assert!(!Path::new(out).join("binary_collision.data.0000").exists());
}

#[test]
fn coarse_graining_into_too_many_slices_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let (code, _, err) = verdem(&[
        "run",
        SHEAR,
        "--steps",
        "20",
        "--save-every",
        "10",
        "--quiet",
        "--out",
        out,
    ]);
    assert_eq!(code, Some(0), "{err}");
    let base = dir.path().join("shear_flow_steady");
    let (code, _, err) = verdem(&["cg", base.to_str().unwrap(), "--slices", "100000000"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--slices 100000000 over 3 saves: needs an estimated"),
        "{err}"
    );
}

#[test]
fn a_name_with_markup_is_escaped_and_one_with_control_characters_refused() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(
        dir.path(),
        "c.toml",
        "name = \"binary_collision\"",
        "name = \"a<b&c\\\"d\"",
    );
    let out = dir.path().join("o");
    let (code, _, err) = verdem(&[
        "run",
        &case,
        "--steps",
        "20",
        "--save-every",
        "10",
        "--vtk",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let pvd = std::fs::read_to_string(out.join("a<b&c\"d.pvd")).unwrap();
    assert!(
        pvd.contains("file=\"a&lt;b&amp;c&quot;d.0000.vtu\""),
        "{pvd}"
    );
    let summary: toml::Table = std::fs::read_to_string(out.join("a<b&c\"d.summary.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(summary["case"].as_str(), Some("a<b&c\"d"));
    let case = pair_case(
        dir.path(),
        "d.toml",
        "name = \"binary_collision\"",
        "name = \"a\\u001b[31mb\"",
    );
    let (code, _, err) = verdem(&["run", &case, "--quiet", "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains(": name: must be a plain file name"), "{err}");
}

#[test]
fn every_text_writer_s_output_with_a_non_finite_value_is_refused_by_the_one_writer() {
    use verdem::io::{atomic, csv_table, diagnostics, mercury, vtk};
    let case = verdem::case::Case::load(&common::root().join(PAIR)).unwrap();
    let mut engine = common::engine(&case, None, Default::default());
    engine.advance(5).unwrap();
    let mut snap = engine.snapshot();
    snap.particles.v[0].x = f64::NAN;
    snap.particles.w[1].y = f64::INFINITY;
    let dir = tempfile::tempdir().unwrap();
    let texts = [
        ("a.data.0000", mercury::data_text(&snap)),
        ("a.0000.vtu", vtk::vtu_text(&vtk::Frame::of_snapshot(&snap))),
        ("a.pvd", vtk::pvd_text(&[(f64::NAN, "a.0000.vtu".into())])),
        (
            "a.diagnostics.csv",
            diagnostics::Diagnostics::of(&snap, 0).csv_row(),
        ),
        ("a.csv", csv_table::write(["x"], [[-f64::INFINITY]])),
    ];
    for (name, text) in texts {
        let p = dir.path().join(name);
        let e = atomic::write(&p, text.as_bytes()).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: not written: line ", p.display())),
            "{name}: {e}"
        );
        let e = atomic::append(&p, text.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("non-finite number"), "{name}: {e}");
        assert!(!p.exists(), "{name} was written");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
