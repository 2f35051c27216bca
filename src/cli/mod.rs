//! The commands' glue: each command's arguments (clap types live only here) and the calls into
//! the library that carry it out, one file per command; [`args`] holds what several share.

pub mod args;
pub mod bench;
pub mod cg;
pub mod compare;
pub mod cross;
pub mod ensemble;
pub mod extremes;
pub mod hash;
pub mod kinematics;
pub mod peers;
pub mod run;
pub mod signals;
pub mod tile;
pub mod tradeoff;
pub mod verify;
pub mod vtk;

/// Exit status of a run stopped by a signal after writing its checkpoint (128 + SIGINT, as a
/// shell reports a process that SIGINT ended).
pub const EXIT_INTERRUPTED: i32 = 130;

/// Exit status of a run the run guard stopped: a number it could no longer trust (a
/// non-finite velocity, an overlap beyond the limit, a particle outside the box).
pub const EXIT_GUARD: i32 = 3;

/// How a command ended, when it did not fail.
pub enum Finished {
    Done,
    /// A run stopped by a signal, its checkpoint written.
    Interrupted,
    /// Checks failed; the command has reported which (exit status 1).
    ChecksFailed,
}
