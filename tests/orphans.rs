//! No program verdem starts outlives it: a signal to verdem stops its children with their
//! process groups (`verify --code`, the local ensemble engine), SIGKILL of verdem kills its
//! direct children (their death signal), and [`verdem::child`] keeps its promises on its own
//! (the death signal on the end of the starting thread, mpirun's ranks, a dropped child).

mod common;

use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use verdem::child::{self, OnParentDeath};

/// How long a test waits for a process to start or to end before it fails.
const PATIENCE: Duration = Duration::from_secs(60);

/// Sends `signal` to the process `pid`.
fn signal(pid: u32, signal: libc::c_int) {
    // SAFETY: kill(2) with the id of a process this test started and a valid signal number.
    assert_eq!(
        unsafe { libc::kill(pid as libc::pid_t, signal) },
        0,
        "kill {pid}"
    );
}

/// The fields of `/proc/PID/stat` after the command's name (state, parent, group, …), or
/// `None` once the process is gone.
fn stat(pid: u32) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let after = &text[text.rfind(')')? + 1..];
    Some(after.split_whitespace().map(String::from).collect())
}

/// Whether `pid` has ended: no such process, or a zombie (ended, not yet reaped by whoever
/// inherited it).
fn ended(pid: u32) -> bool {
    stat(pid).is_none_or(|f| f[0] == "Z")
}

/// Polls `done` until it holds, failing with `what` after [`PATIENCE`].
fn wait_for(what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < PATIENCE, "{what}: not after {PATIENCE:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The process id written into `path`, once it is there.
fn pid_in(path: &Path) -> u32 {
    let mut pid = None;
    wait_for(&format!("a process id in {}", path.display()), || {
        pid = std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.trim().parse().ok());
        pid.is_some()
    });
    pid.unwrap()
}

/// The live (not zombie) processes whose parent is `parent`.
fn children_of(parent: u32) -> Vec<u32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|&pid| stat(pid).is_some_and(|f| f[0] != "Z" && f[1] == parent.to_string()))
        .collect()
}

/// The process group of `pid`.
fn group_of(pid: u32) -> u32 {
    stat(pid).expect("a live process")[2].parse().unwrap()
}

/// A verdem process that is SIGKILLed when dropped, so that a failed test leaves none running.
struct Verdem(std::process::Child);

impl Drop for Verdem {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Verdem {
    /// verdem with `args`, from the repository's root, with the default action of every
    /// signal it handles (a signal ignored when it starts stays ignored, as under `nohup`, and
    /// this test may be run by a shell that ignores SIGINT in background jobs).
    fn start(args: &[&str]) -> Verdem {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_verdem"));
        cmd.current_dir(common::root())
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null());
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
        Verdem(cmd.spawn().expect("verdem starts"))
    }

    fn id(&self) -> u32 {
        self.0.id()
    }

    /// Its exit status, once it has ended.
    fn ended(&mut self) -> std::process::ExitStatus {
        let mut status = None;
        wait_for("verdem's end", || {
            status = self.0.try_wait().unwrap();
            status.is_some()
        });
        status.unwrap()
    }
}

/// `verdem verify --code` running `body` as a shell script in `dir` (which records its own
/// process id in `child.pid` and starts `sleep 1000` in the background, recording its id in
/// `grandchild.pid`, then waits); returns verdem, the program (verdem's direct child: the
/// shell `exec`s it) and its `sleep`, once both run.
fn hanging_program(dir: &Path, prelude: &str) -> (Verdem, u32, u32) {
    let script = dir.join("hang.sh");
    let (child_pid, grandchild_pid) = (dir.join("child.pid"), dir.join("grandchild.pid"));
    std::fs::write(
        &script,
        format!(
            "{prelude}\necho $$ > '{}'\nsleep 1000 &\necho $! > '{}'\nwait\n",
            child_pid.display(),
            grandchild_pid.display()
        ),
    )
    .unwrap();
    let code = format!("exec sh '{}'", script.display());
    let out = dir.join("out");
    let verdem = Verdem::start(&[
        "verify",
        "--only",
        "load-unload",
        "--code",
        &code,
        "--out",
        out.to_str().unwrap(),
    ]);
    let (child, grandchild) = (pid_in(&child_pid), pid_in(&grandchild_pid));
    assert_eq!(stat(child).unwrap()[1], verdem.id().to_string());
    (verdem, child, grandchild)
}

/// SIGTERM, SIGINT or SIGHUP to `verdem verify --code`: the program and what it started end
/// (SIGTERM to their group; SIGKILL after the grace for a program that ignores SIGTERM), then
/// verdem ends by the same signal.
#[test]
fn a_signal_to_verdem_verify_ends_the_program_and_its_children() {
    for (sig, prelude) in [
        (libc::SIGTERM, ""),
        (libc::SIGINT, ""),
        (libc::SIGHUP, ""),
        (libc::SIGTERM, "trap '' TERM"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let (mut verdem, child, grandchild) = hanging_program(dir.path(), prelude);
        assert_eq!(group_of(grandchild), child, "the program leads its group");
        signal(verdem.id(), sig);
        let status = verdem.ended();
        assert_eq!(status.signal(), Some(sig), "{prelude:?}: {status}");
        wait_for(&format!("{prelude:?}: the program's end"), || ended(child));
        wait_for(&format!("{prelude:?}: its sleep's end"), || {
            ended(grandchild)
        });
    }
}

/// SIGKILL of `verdem verify --code`: the kernel kills the program (its death signal); its
/// own children are left in its process group, where `kill -- -PGID` finds them.
#[test]
fn sigkill_of_verdem_kills_the_program_it_runs() {
    let dir = tempfile::tempdir().unwrap();
    let (mut verdem, child, grandchild) = hanging_program(dir.path(), "");
    signal(verdem.id(), libc::SIGKILL);
    assert_eq!(verdem.ended().signal(), Some(libc::SIGKILL));
    wait_for("the program's end", || ended(child));
    assert_eq!(group_of(grandchild), child);
    // SAFETY: kill(2) of the group this test's program led, which still holds its sleep.
    assert_eq!(
        unsafe { libc::kill(-(child as libc::pid_t), libc::SIGKILL) },
        0
    );
    wait_for("its sleep's end", || ended(grandchild));
}

/// `verdem ensemble` on the local engine with two long replicas, once both replica processes
/// run: verdem and its replicas.
fn running_ensemble(out: &Path) -> (Verdem, Vec<u32>) {
    let verdem = Verdem::start(&[
        "ensemble",
        "cases/shear_flow_quick.toml",
        "--replicas",
        "2",
        "--jobs",
        "2",
        "--steps",
        "100000000",
        "--out",
        out.to_str().unwrap(),
    ]);
    let mut replicas = Vec::new();
    wait_for("two replica processes", || {
        replicas = children_of(verdem.id());
        replicas.len() == 2
    });
    (verdem, replicas)
}

/// A signal to `verdem ensemble` ends its replicas, then verdem by the same signal; SIGKILL of
/// it ends them by their death signal.
#[test]
fn the_local_ensembles_replicas_end_with_verdem() {
    for sig in [libc::SIGTERM, libc::SIGKILL] {
        let dir = tempfile::tempdir().unwrap();
        let (mut verdem, replicas) = running_ensemble(&dir.path().join("ens"));
        signal(verdem.id(), sig);
        assert_eq!(verdem.ended().signal(), Some(sig));
        for r in replicas {
            wait_for(&format!("signal {sig}: replica {r}'s end"), || ended(r));
        }
    }
}

/// A child gets its death signal when the thread that started it ends, whether that thread
/// lets it run (here: forgets it) or not: the promise behind SIGKILL of verdem.
#[test]
fn a_child_is_killed_when_the_thread_that_started_it_ends() {
    let pid = std::thread::spawn(|| {
        let c = child::spawn(Command::new("sleep").arg("1000"), OnParentDeath::Kill).unwrap();
        let pid = c.id();
        assert!(!ended(pid));
        std::mem::forget(c);
        pid
    })
    .join()
    .unwrap();
    wait_for("the child's end", || ended(pid));
}

/// A child dropped before it was waited for is killed with its process group.
#[test]
fn a_dropped_child_is_killed_with_its_group() {
    let dir = tempfile::tempdir().unwrap();
    let pid_file = dir.path().join("grandchild.pid");
    let c = child::spawn(
        Command::new("sh")
            .arg("-c")
            .arg("sleep 1000 & echo $! > \"$1\"; wait")
            .arg("sh")
            .arg(&pid_file),
        OnParentDeath::Kill,
    )
    .unwrap();
    let grandchild = pid_in(&pid_file);
    assert_eq!(group_of(grandchild), c.id());
    drop(c);
    wait_for("the grandchild's end", || ended(grandchild));
}

/// With [`OnParentDeath::Terminate`], mpirun's end on its death signal stops its ranks, each in
/// a process group of its own (SIGKILL of mpirun would leave them running). Skipped, saying so,
/// where mpirun is not installed.
#[test]
fn mpiruns_ranks_end_with_the_thread_that_started_mpirun() {
    let installed = Command::new("sh")
        .args(["-c", "command -v mpirun"])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !installed {
        eprintln!("skipped: no mpirun");
        return;
    }
    let (mpirun, ranks) = std::thread::spawn(|| {
        let c = child::spawn(
            Command::new("mpirun")
                .args(["--allow-run-as-root", "--oversubscribe", "-np", "2"])
                .args(["sleep", "1000"])
                .stdout(Stdio::null())
                .stderr(Stdio::null()),
            OnParentDeath::Terminate,
        )
        .unwrap();
        let mut ranks = Vec::new();
        wait_for("mpirun's two ranks", || {
            ranks = children_of(c.id());
            ranks.len() == 2
        });
        let pid = c.id();
        std::mem::forget(c);
        (pid, ranks)
    })
    .join()
    .unwrap();
    for r in ranks {
        wait_for(&format!("rank {r}'s end"), || ended(r));
    }
    wait_for("mpirun's end", || ended(mpirun));
}
