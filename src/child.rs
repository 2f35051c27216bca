//! Child processes that do not outlive verdem: every program verdem starts (a peer, `mpirun`,
//! a program under `verify --code`, a replica, a Slurm client) is started by [`spawn`] (or
//! [`output`], [`status`]), which puts it in a process group of its own (its process id is the
//! group's id) and records the group while it runs, so that [`stop_all`] can stop every live
//! child with whatever it started in its group.
//!
//! When verdem ends without stopping them (SIGKILL, a crash), the kernel sends each direct
//! child the signal of its [`OnParentDeath`] (Linux's `PR_SET_PDEATHSIG`). That signal is sent
//! when the *thread* that started the child ends, not the process: a [`Child`] cannot be moved to
//! another thread (it is not `Send`), and dropping one that has not been waited for kills its
//! group and waits for it, so a child always ends before the thread that started it does. The
//! processes a child starts itself are not signalled by the kernel when verdem dies.

use std::collections::BTreeSet;
use std::io::{self, Read};
use std::marker::PhantomData;
use std::os::unix::process::CommandExt;
use std::process::{Command, ExitStatus, Output, Stdio};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// The process groups (the ids of their leaders, verdem's direct children) of the children
/// started by [`spawn`] that have not been reaped yet. A group's id cannot be taken by another
/// process while its leader is alive or a zombie, so signalling a group listed here reaches only
/// that child and what it started in its group.
static LIVE: Mutex<BTreeSet<i32>> = Mutex::new(BTreeSet::new());

fn live() -> MutexGuard<'static, BTreeSet<i32>> {
    // The set stays consistent through a panic of a holder: each holder inserts or removes
    // one element.
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The signal the kernel sends a child when verdem ends without stopping it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnParentDeath {
    /// SIGKILL: the child cannot delay or ignore it.
    Kill,
    /// SIGTERM: for a child that stops processes outside its own group when it is asked to
    /// (`mpirun` puts each rank in a group of its own and stops them on SIGTERM; a SIGKILL of
    /// `mpirun` would leave them running).
    Terminate,
}

impl OnParentDeath {
    fn signal(self) -> libc::c_int {
        match self {
            OnParentDeath::Kill => libc::SIGKILL,
            OnParentDeath::Terminate => libc::SIGTERM,
        }
    }
}

/// A running child started by [`spawn`]. Not `Send`: it is waited for on the thread that
/// started it (see the module's documentation). Dropped before it has been waited for, it
/// kills its process group and waits for it.
#[derive(Debug)]
pub struct Child {
    process: std::process::Child,
    /// Its exit status, once reaped.
    status: Option<ExitStatus>,
    not_send: PhantomData<*const ()>,
}

/// Starts `cmd` in a process group of its own, with `on_death` as its signal when verdem ends
/// without stopping it (the check that verdem is still its parent comes after that signal is
/// set: a child whose parent ended before ends at once) and with no signal blocked (verdem
/// blocks the signals it takes on one thread, and a blocked mask is inherited through `exec`).
/// Every other setting of `cmd` (its arguments, folder, environment, standard streams) is
/// kept. Errors are those of [`Command::spawn`].
pub fn spawn(cmd: &mut Command, on_death: OnParentDeath) -> io::Result<Child> {
    let parent = std::process::id() as libc::pid_t;
    let signal = on_death.signal();
    // SAFETY: an all-zero `sigset_t` is a valid value of this plain C type; sigemptyset
    // initialises it as the empty set.
    let mut none: libc::sigset_t = unsafe { std::mem::zeroed() };
    // SAFETY: `none` is a valid `sigset_t` owned by this frame.
    unsafe { libc::sigemptyset(&mut none) };
    cmd.process_group(0);
    // SAFETY: the closure runs in the forked child before `exec`, where only async-signal-safe
    // functions may be called: it calls `sigprocmask` (reading its own copy of `none`), `prctl`
    // and `getppid`, and builds an `io::Error` from an errno value, which allocates nothing.
    unsafe {
        cmd.pre_exec(move || {
            if libc::sigprocmask(libc::SIG_SETMASK, &none, std::ptr::null_mut()) != 0
                || libc::prctl(libc::PR_SET_PDEATHSIG, signal as libc::c_ulong, 0, 0, 0) != 0
            {
                return Err(io::Error::last_os_error());
            }
            // verdem ended between the fork and the prctl: no signal will come
            if libc::getppid() != parent {
                return Err(io::Error::from_raw_os_error(libc::ESRCH));
            }
            Ok(())
        });
    }
    // Held across the start, so that stop_all never misses a child that has started.
    let mut live = live();
    let process = cmd.spawn()?;
    live.insert(process.id() as i32);
    Ok(Child {
        process,
        status: None,
        not_send: PhantomData,
    })
}

/// Runs `cmd` to its end as [`Command::output`] does (standard output and error captured,
/// standard input empty), started by [`spawn`].
pub fn output(cmd: &mut Command, on_death: OnParentDeath) -> io::Result<Output> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    spawn(cmd, on_death)?.wait_with_output()
}

/// Runs `cmd` to its end as [`Command::status`] does (standard streams as `cmd` sets them,
/// else inherited), started by [`spawn`].
pub fn status(cmd: &mut Command, on_death: OnParentDeath) -> io::Result<ExitStatus> {
    spawn(cmd, on_death)?.wait()
}

impl Child {
    /// The child's process id, also the id of its process group.
    pub fn id(&self) -> u32 {
        self.process.id()
    }

    /// Its exit status if it has ended (reaping it), else `None`.
    pub fn try_wait(&mut self) -> io::Result<Option<ExitStatus>> {
        if self.status.is_none() && !self.has_exited(false)? {
            return Ok(None);
        }
        self.reap().map(Some)
    }

    /// Waits for it to end and returns its exit status.
    pub fn wait(&mut self) -> io::Result<ExitStatus> {
        if self.status.is_none() {
            self.has_exited(true)?;
        }
        self.reap()
    }

    /// Sends SIGKILL to its process group: the child and what it started in its group. Does
    /// nothing once it has been reaped.
    pub fn kill_group(&self) {
        if self.status.is_none() {
            // SAFETY: kill(2) on a group whose leader, our child, is not reaped yet, so the
            // id is still that group's; an error (the group is gone) changes nothing.
            unsafe { libc::kill(-(self.id() as libc::pid_t), libc::SIGKILL) };
        }
    }

    /// Reads its standard output and error to their ends (those that `cmd` piped), then waits
    /// for it, as [`std::process::Child::wait_with_output`] does.
    pub fn wait_with_output(mut self) -> io::Result<Output> {
        let (stdout, stderr) = (self.process.stdout.take(), self.process.stderr.take());
        // both at once: a child blocked on a full pipe would never end
        let (stdout, stderr) = std::thread::scope(|s| {
            let err = s.spawn(move || read_all(stderr));
            let out = read_all(stdout);
            (out, err.join().expect("reading a pipe does not panic"))
        });
        let status = self.wait()?;
        Ok(Output {
            status,
            stdout: stdout?,
            stderr: stderr?,
        })
    }

    /// Whether the child has ended, without reaping it, so that its group id stays reserved
    /// until [`Child::reap`]; `block` waits for the end.
    fn has_exited(&self, block: bool) -> io::Result<bool> {
        loop {
            match exited(self.id() as libc::pid_t, block) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                r => return r,
            }
        }
    }

    /// Takes the ended child off the registry, then reaps it (its status stays known).
    fn reap(&mut self) -> io::Result<ExitStatus> {
        if let Some(s) = self.status {
            return Ok(s);
        }
        live().remove(&(self.id() as i32));
        let s = self.process.wait()?;
        self.status = Some(s);
        Ok(s)
    }
}

impl Drop for Child {
    fn drop(&mut self) {
        if self.status.is_none() {
            self.kill_group();
            let _ = self.wait();
        }
    }
}

/// What [`stop_all`] leaves: the registry held, so that no child starts and no stopped child is
/// reaped (its group id stays reserved) until it is dropped.
pub struct Stopped {
    _live: MutexGuard<'static, BTreeSet<i32>>,
}

/// How long [`stop_all`] lets the children end on SIGTERM before SIGKILL: `mpirun` takes a few
/// seconds to stop its ranks.
pub const GRACE: Duration = Duration::from_secs(5);

/// Stops every live child started by [`spawn`], on any thread, with its process group: SIGTERM
/// to each group (a program may stop what it started elsewhere, as `mpirun` its ranks, and
/// remove its temporary files), then, once every child has ended or after `grace`, SIGKILL to
/// each group (what ignored SIGTERM, and what a child left in its group). Returns with the
/// registry held (see [`Stopped`]).
pub fn stop_all(grace: Duration) -> Stopped {
    let live = live();
    let signal_all = |signal: libc::c_int| {
        for &group in live.iter() {
            // SAFETY: kill(2) on a listed group, whose leader is not reaped while the registry
            // is held (the id is still that group's); an error (the group is gone) changes
            // nothing.
            unsafe { libc::kill(-group, signal) };
        }
    };
    signal_all(libc::SIGTERM);
    let deadline = Instant::now() + grace;
    while Instant::now() < deadline && live.iter().any(|&pid| running(pid)) {
        std::thread::sleep(Duration::from_millis(10));
    }
    signal_all(libc::SIGKILL);
    Stopped { _live: live }
}

/// Whether verdem's child `pid` has not ended yet.
fn running(pid: i32) -> bool {
    matches!(exited(pid, false), Ok(false))
}

/// Whether verdem's child `pid` (of any of its threads) has ended, without reaping it (`waitid`
/// with `WNOWAIT`); `block` waits for the end.
fn exited(pid: libc::pid_t, block: bool) -> io::Result<bool> {
    let flags = libc::WEXITED | libc::WNOWAIT | if block { 0 } else { libc::WNOHANG };
    // SAFETY: an all-zero `siginfo_t` is a valid value of this plain C struct.
    let mut info: libc::siginfo_t = unsafe { std::mem::zeroed() };
    // SAFETY: waitid(2) writes at most one `siginfo_t` into `info`, which it is given.
    if unsafe { libc::waitid(libc::P_PID, pid as libc::id_t, &mut info, flags) } != 0 {
        return Err(io::Error::last_os_error());
    }
    // SAFETY: for a child's state change waitid sets `si_pid` (the union's field for SIGCHLD);
    // with WNOHANG and no change it leaves the zeroed struct, whose `si_pid` reads 0.
    Ok(unsafe { info.si_pid() } != 0)
}

/// All of `pipe`, or nothing without one.
fn read_all(pipe: Option<impl Read>) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    if let Some(mut p) = pipe {
        p.read_to_end(&mut bytes)?;
    }
    Ok(bytes)
}
