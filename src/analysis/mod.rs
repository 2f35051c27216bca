//! Judging results: the statistics the reports share ([`stats`]), the one verdict type that
//! the verification table, the profile checks, the timing goals and the cross-runs report
//! ([`verdict`]), coarse-graining of saves into profiles with their checks ([`cg`]), two in-run
//! results compared by their core means ([`difference`]), the merge of an ensemble's profiles
//! ([`ensemble`]), a picture of a save's particles
//! ([`particles`]), verdicts as JUnit XML and JSON reports for CI systems ([`report`]).

pub mod cg;
pub mod difference;
pub mod ensemble;
pub mod inrun;
pub mod ledger;
pub mod particles;
pub mod report;
pub mod stats;
pub mod verdict;

pub use verdict::{Limit, Outcome, Verdict};
