//! Judging results: the statistics the reports share ([`stats`]) and the one verdict type that
//! the verification table, the profile checks, the timing goals and the cross-runs report
//! ([`verdict`]).

pub mod stats;
pub mod verdict;

pub use verdict::{Limit, Outcome, Verdict};
