//! The one handler of SIGINT, SIGTERM and SIGHUP, for every command: a signal first stops the
//! programs verdem started ([`child::stop_all`]: SIGTERM to their process groups, SIGKILL after
//! [`child::GRACE`] or as soon as they have ended), then either asks the command to stop
//! gracefully (a command that registered a [`Graceful`] stop: `run`, `ensemble` waiting for
//! Slurm) or ends verdem by the same signal, as that signal's default action would have (the
//! shell reports 128 + its number). A signal that is ignored when verdem starts (`nohup`'s
//! SIGHUP, SIGINT of a background job started by a script) stays ignored.
//!
//! The signals are blocked in every thread and taken by one thread with `sigwait`, so that the
//! handling runs as ordinary code (locks, printing, waiting) rather than in a signal handler.
//! The programs verdem starts begin with no signal blocked ([`child::spawn`] clears the mask in
//! the child).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use anyhow::Context;

use verdem::child;

use super::EXIT_INTERRUPTED;

/// The signals handled.
const SIGNALS: [libc::c_int; 3] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP];

/// A command's graceful stop: what a signal does after the children are stopped.
pub struct Graceful {
    /// Raised by the first signal; the command stops when it sees it.
    pub flag: Arc<AtomicBool>,
    /// Printed on standard error at the first signal.
    pub notice: Option<&'static str>,
    /// Whether a second signal ends verdem at once, with [`EXIT_INTERRUPTED`].
    pub second_exits: bool,
}

static GRACEFUL: OnceLock<Graceful> = OnceLock::new();

/// Takes SIGINT, SIGTERM and SIGHUP for the whole process (see the module's documentation).
/// Must be called before any other thread is started (the threads started later inherit the
/// blocked signals; one started before would take them with their default action).
pub fn install() -> anyhow::Result<()> {
    // SAFETY: an all-zero `sigset_t` is a valid value of this plain C type; sigemptyset
    // initialises it.
    let mut set: libc::sigset_t = unsafe { std::mem::zeroed() };
    // SAFETY: `set` is a valid `sigset_t` owned by this frame.
    unsafe { libc::sigemptyset(&mut set) };
    for signal in SIGNALS.into_iter().filter(|&s| !ignored(s)) {
        // SAFETY: `set` is an initialised `sigset_t` and `signal` a valid signal number.
        unsafe { libc::sigaddset(&mut set, signal) };
    }
    // SAFETY: pthread_sigmask reads the initialised `set`; the old mask is not asked for.
    let blocked = unsafe { libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) };
    if blocked != 0 {
        return Err(std::io::Error::from_raw_os_error(blocked))
            .context("cannot block SIGINT, SIGTERM and SIGHUP");
    }
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || loop {
            let mut signal = 0;
            // SAFETY: sigwait reads the initialised `set` (this thread's copy) and writes one
            // signal number into `signal`; every signal of `set` is blocked in every thread.
            if unsafe { libc::sigwait(&set, &mut signal) } == 0 {
                on_signal(signal);
            }
        })
        .context("cannot start the thread that takes the signals")?;
    Ok(())
}

/// Registers the running command's graceful stop. Errors when one is registered already (one
/// command runs per process).
pub fn graceful(stop: Graceful) -> anyhow::Result<()> {
    GRACEFUL
        .set(stop)
        .map_err(|_| anyhow::anyhow!("a graceful stop on signals is registered twice"))
}

/// Whether `signal` is ignored (as `nohup` leaves SIGHUP for the program it starts).
fn ignored(signal: libc::c_int) -> bool {
    // SAFETY: an all-zero `sigaction` is a valid value of this plain C struct.
    let mut old: libc::sigaction = unsafe { std::mem::zeroed() };
    // SAFETY: with a null new action, sigaction only writes the current one into `old`.
    let read = unsafe { libc::sigaction(signal, std::ptr::null(), &mut old) } == 0;
    read && old.sa_sigaction == libc::SIG_IGN
}

/// What `signal` does: the children stopped, then the command's graceful stop, or the end.
fn on_signal(signal: libc::c_int) {
    let stopped = child::stop_all(child::GRACE);
    let Some(g) = GRACEFUL.get() else {
        // the registry stays held: no child starts before the end
        end_by(signal)
    };
    drop(stopped);
    if g.flag.swap(true, Ordering::Relaxed) {
        if g.second_exits {
            std::process::exit(EXIT_INTERRUPTED);
        }
    } else if let Some(notice) = g.notice {
        eprintln!("{notice}");
    }
}

/// Ends the process by `signal`'s default action (each of [`SIGNALS`] terminates it).
fn end_by(signal: libc::c_int) -> ! {
    // SAFETY: an all-zero `sigset_t` is a valid value; sigemptyset initialises it.
    let mut set: libc::sigset_t = unsafe { std::mem::zeroed() };
    // SAFETY: `set` is a valid `sigset_t` owned by this frame and `signal` a valid number;
    // signal(2) sets that signal's action back to the default (it was not changed, but a
    // library may have); pthread_sigmask unblocks it in this thread only and raise(3) sends it
    // to this thread, where its default action ends the process.
    unsafe {
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, signal);
        libc::signal(signal, libc::SIG_DFL);
        libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut());
        libc::raise(signal);
    }
    // not reached: the default action of each handled signal ends the process
    std::process::exit(128 + signal)
}
