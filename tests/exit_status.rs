//! Every exit status docs/cli.md documents ("Exit statuses"), each provoked through the real
//! binary: 0 for work done, 1 for an error (a bad case file, an unreadable initial file, a
//! corrupt checkpoint, an earlier run's folder) or a failed verification row, 2 for a usage
//! error, 3 for the run guard's stop, 130 for a run a signal stopped after its checkpoint, and
//! the signal itself (a shell's 128 + N) for a command without a graceful stop. Each error's
//! message names its file, field, option, step or particle.

mod common;

use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// verdem with `args` from the repository's root, with the default action of the signals it
/// handles (a shell may start the tests with SIGINT ignored).
fn verdem(args: &[&str]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_verdem"));
    cmd.current_dir(common::root()).args(args);
    // SAFETY: the closure runs in the forked child before exec and calls only signal(2),
    // which is async-signal-safe, with valid signal numbers and the default action.
    unsafe {
        cmd.pre_exec(|| {
            for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
                libc::signal(s, libc::SIG_DFL);
            }
            Ok(())
        });
    }
    cmd
}

/// Runs verdem with `args`; its exit status, stdout and stderr.
fn ended(args: &[&str]) -> (ExitStatus, String, String) {
    let o = verdem(args).output().unwrap();
    (
        o.status,
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A two-sphere case `pair.toml` in `dir` (the binary collision's law): the spheres at x =
/// `x1` and `x2`, approaching at 5 length/time each, `steps` steps, a save every `every`.
fn pair_case(dir: &Path, x: [f64; 2], steps: u64, every: u64) -> String {
    let text = format!(
        r#"name = "pair"
[run]
steps = {steps}
save_every = {every}
steps_per_collision = 50
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
v = [5.0, 0.0, 0.0]
[[scene.sphere]]
x = [{}, 0.0, 0.0]
v = [-5.0, 0.0, 0.0]
"#,
        x[0], x[1]
    );
    let path = dir.join("pair.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Waits until `done`, for at most a minute.
fn wait_for(what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < Duration::from_secs(60), "{what}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_command_that_did_its_work_exits_with_0() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(dir.path(), [-1.0, 1.0], 200, 100);
    let out = dir.path().join("out");
    let (status, stdout, stderr) =
        ended(&["run", &case, "--quiet", "--out", out.to_str().unwrap()]);
    assert_eq!(status.code(), Some(0), "{stderr}");
    assert!(stdout.contains("done: step 200"), "{stdout}");
}

/// A case file with a bad field: status 1, the file, its line and the field named.
#[test]
fn a_bad_case_file_exits_with_1_naming_its_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(dir.path(), [-1.0, 1.0], 200, 100);
    let text = std::fs::read_to_string(&case).unwrap();
    std::fs::write(&case, text.replace("kn = 2e5", "kn = -3")).unwrap();
    let line = 1 + text.lines().position(|l| l == "kn = 2e5").unwrap();
    let (status, _, stderr) = ended(&["hash", &case, "--steps", "1"]);
    assert_eq!(status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "error: {case}:{line}: contact.kn: must be > 0, got -3"
        )),
        "{stderr}"
    );
}

/// An initial file that cannot be read, and one whose particles are not the case's: status 1,
/// the file named (and the line of the particle).
#[test]
fn an_unreadable_or_wrong_initial_file_exits_with_1_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let shear = "cases/shear_flow_quick.toml";
    let missing = dir.path().join("missing.data");
    let missing = missing.to_str().unwrap();
    let (status, _, stderr) = ended(&["hash", shear, "--init", missing, "--steps", "1"]);
    assert_eq!(status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!("error: {missing}: cannot read")),
        "{stderr}"
    );
    let pair_state = dir.path().join("pair.data");
    std::fs::write(
        &pair_state,
        "2 0 0 0 0 20 10.3923048454133 22\n1 1 1 0 0 0 0.5 0 0 0 0 0 0 0\n\
         1 1 30 0 0 0 0.5 0 0 0 0 0 0 0\n",
    )
    .unwrap();
    let state = pair_state.to_str().unwrap();
    let (status, _, stderr) = ended(&["hash", shear, "--init", state, "--steps", "1"]);
    assert_eq!(status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "error: {state}: has 2 particles, the case expects"
        )),
        "{stderr}"
    );
}

/// A checkpoint changed since it was written (one flipped bit): `run --resume` exits with 1,
/// naming the checkpoint and both digests, before anything is written.
#[test]
fn a_corrupt_checkpoint_exits_with_1_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(dir.path(), [-1.0, 1.0], 200, 100);
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let (status, _, stderr) = ended(&[
        "run",
        &case,
        "--quiet",
        "--out",
        out,
        "--checkpoint-every",
        "100",
    ]);
    assert_eq!(status.code(), Some(0), "{stderr}");
    let ck = format!("{out}/pair.checkpoint");
    let mut bytes = std::fs::read(&ck).unwrap();
    bytes[40] ^= 1;
    std::fs::write(&ck, &bytes).unwrap();
    let (status, _, stderr) = ended(&["run", &case, "--quiet", "--resume", &ck]);
    assert_eq!(status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "error: {ck}: refused, a corrupted checkpoint (changed or truncated since it was \
             written): its checksum says SHA-256 "
        )),
        "{stderr}"
    );
}

/// A folder that holds an earlier run's files: status 1, the folder and the option that
/// replaces them named, nothing written.
#[test]
fn an_earlier_run_s_folder_exits_with_1_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(dir.path(), [-1.0, 1.0], 200, 100);
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let args = ["run", &case, "--quiet", "--out", out];
    assert_eq!(ended(&args).0.code(), Some(0));
    let (status, _, stderr) = ended(&args);
    assert_eq!(status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "error: {out}: already holds the files of a run named \"pair\""
        )) && stderr.contains("or replace its files with --force"),
        "{stderr}"
    );
}

/// `verdem verify` with a row that is not a pass (a program that does not exist gets an
/// ERROR row): status 1.
#[test]
fn a_verification_row_that_fails_exits_with_1() {
    let dir = tempfile::tempdir().unwrap();
    let cases = common::root().join("cases/verify");
    let (status, stdout, stderr) = ended(&[
        "verify",
        "--only",
        "load-unload",
        "--code",
        "/nonexistent/law",
        "--out",
        dir.path().to_str().unwrap(),
        "--cases",
        cases.to_str().unwrap(),
    ]);
    assert_eq!(status.code(), Some(1), "{stdout}{stderr}");
    let row = stdout
        .lines()
        .find(|l| l.starts_with("tangential code:law load-unload"))
        .unwrap_or_else(|| panic!("no row of the program: {stdout}"));
    assert!(row.ends_with("ERROR"), "{row}");
}

/// A command line that does not parse, or an option out of range: clap's usage error, status
/// 2, naming the option; `--help` is no error.
#[test]
fn a_usage_error_exits_with_2_naming_the_option() {
    let (status, _, stderr) = ended(&["run", "cases/shear_flow_quick.toml", "--threads", "0"]);
    assert_eq!(status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("error: invalid value '0' for '--threads <THREADS>'"),
        "{stderr}"
    );
    let (status, _, stderr) = ended(&["no-such-command"]);
    assert_eq!(status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("'no-such-command'"), "{stderr}");
    let (status, stdout, _) = ended(&["run", "--help"]);
    assert_eq!(status.code(), Some(0));
    assert!(stdout.contains("Usage: verdem run"), "{stdout}");
}

/// Two spheres at the same place: the run guard stops the run at step 0, status 3, naming the
/// step, the particles and what is kept.
#[test]
fn the_run_guard_s_stop_exits_with_3_naming_step_and_particles() {
    let dir = tempfile::tempdir().unwrap();
    let case = pair_case(dir.path(), [0.0, 0.0], 200, 100);
    let out = dir.path().join("out");
    let (status, _, stderr) = ended(&["run", &case, "--quiet", "--out", out.to_str().unwrap()]);
    assert_eq!(status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("step 0") && stderr.contains("particle 1 and 2"),
        "{stderr}"
    );
    assert!(stderr.contains("last save none"), "{stderr}");
    // `hash` advances a simulation under the same guard, without a run loop around it
    let (status, _, stderr) = ended(&["hash", &case, "--steps", "10"]);
    assert_eq!(status.code(), Some(3), "{stderr}");
}

/// SIGTERM to `verdem run`: it writes its checkpoint at the end of the block under way and
/// exits with 130, printing the command that continues it.
#[test]
fn a_run_stopped_by_a_signal_exits_with_130_after_its_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    // the spheres never meet: a long run of cheap steps
    let case = pair_case(dir.path(), [-4.0, 4.0], 1_000_000_000, 100_000_000);
    let text = std::fs::read_to_string(&case).unwrap();
    std::fs::write(&case, text.replace("5.0, 0.0, 0.0]", "0.0, 0.0, 0.0]")).unwrap();
    let out = dir.path().join("out");
    let child = verdem(&["run", &case, "--quiet", "--out", out.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = out.join("pair.data.0000");
    wait_for("the run's first save", || first.exists());
    // SAFETY: kill(2) with the pid of our own live child and a valid signal number.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let o = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(130),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("continue with: "), "{stdout}");
    assert!(out.join("pair.checkpoint").exists());
}

/// SIGTERM to a command without a graceful stop (`verify` running a program): it stops the
/// program, then ends by the signal itself (a shell reports 128 + 15).
#[test]
fn a_command_without_a_graceful_stop_ends_by_the_signal() {
    let dir = tempfile::tempdir().unwrap();
    let started = dir.path().join("started");
    // the program's arguments (case, motion, forces file) go to the script, which ignores them
    let script = dir.path().join("hang.sh");
    std::fs::write(
        &script,
        format!("touch '{}'\nexec sleep 1000\n", started.display()),
    )
    .unwrap();
    let code = format!("exec sh '{}'", script.display());
    let mut child = verdem(&[
        "verify",
        "--only",
        "load-unload",
        "--code",
        &code,
        "--out",
        dir.path().join("out").to_str().unwrap(),
    ])
    .stdout(Stdio::null())
    .stderr(Stdio::null())
    .spawn()
    .unwrap();
    wait_for("the program's start", || started.exists());
    // SAFETY: kill(2) with the pid of our own live child and a valid signal number.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), None, "{status}");
    assert_eq!(status.signal(), Some(libc::SIGTERM), "{status}");
}

/// The library's errors are typed: a program embedding verdem tells them apart by matching, not
/// by reading their text.
#[test]
fn the_library_s_errors_are_matched_by_their_types() {
    use verdem::io::checkpoint::{self, CheckpointError};
    use verdem::run::RunError;
    use verdem::scene::SceneError;

    let dir = tempfile::tempdir().unwrap();
    let case = common::quick_case();
    let mut e = common::engine(&case, None, Default::default());
    let tag = checkpoint::tag(&case);
    let ck = dir.path().join("q.checkpoint");
    checkpoint::write(&ck, &e.snapshot(), e.params().dt, &tag).unwrap();
    let bytes = std::fs::read(&ck).unwrap();
    let mut flipped = bytes.clone();
    flipped[100] ^= 1;
    let restored = |b: &[u8], e: &mut dyn verdem::step::Engine| {
        checkpoint::restore("c.ck", b, e, &tag).unwrap_err()
    };
    assert!(matches!(
        restored(&flipped, e.as_mut()),
        CheckpointError::Corrupt { len, .. } if len == bytes.len() - 32
    ));
    assert!(matches!(
        restored(b"VERDEMC1 and the rest", e.as_mut()),
        CheckpointError::Version { version: 1, .. }
    ));
    assert!(matches!(
        restored(b"GARBAGE!", e.as_mut()),
        CheckpointError::NotCheckpoint { .. }
    ));
    let other = checkpoint::read(&ck, e.as_mut(), "case=\"other\"").unwrap_err();
    assert!(
        matches!(&other, CheckpointError::OtherRun { differs, .. } if differs.len() == 2),
        "{other}"
    );
    let missing = checkpoint::read(&dir.path().join("none"), e.as_mut(), &tag).unwrap_err();
    assert!(matches!(missing, CheckpointError::Read { .. }), "{missing}");

    let two = dir.path().join("two.data");
    std::fs::write(
        &two,
        "2 0 0 0 0 20 10.3923048454133 22\n1 1 1 0 0 0 0.5 0 0 0 0 0 0 0\n\
         2 2 2 0 0 0 0.5 0 0 0 0 0 0 0\n",
    )
    .unwrap();
    let Err(count) = verdem::scene::build(&case, Some(&two)) else {
        panic!("a scene of the two spheres was built");
    };
    assert!(
        matches!(
            count,
            SceneError::Count {
                found: 2,
                wall: 480,
                free: 3000,
                ..
            }
        ),
        "{count}"
    );
    let Err(unread) = verdem::scene::build(&case, Some(&dir.path().join("none"))) else {
        panic!("a scene of no file was built");
    };
    assert!(matches!(unread, SceneError::Format(_)), "{unread}");

    let out = dir.path().join("out");
    let lock = verdem::io::lock::lock_folder(&out).unwrap();
    std::fs::write(out.join("q.summary.toml"), "").unwrap();
    let occupied = verdem::run::claim_output_folder(&out, "q", false, "--force", &lock);
    assert!(
        matches!(&occupied, Err(RunError::Occupied { found, .. }) if found.len() == 1),
        "{occupied:?}"
    );
}
