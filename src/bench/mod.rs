//! Timing comparisons on this machine: verdem and the installed peers run the same case from the
//! same state, alternating (A B A B …) so that drift of a shared machine cancels, with no file
//! output in the timed region ([`rounds`]); the same at several system sizes ([`sweep`]); the
//! tables with the goals they judge ([`goals`]), the core-to-core probe ([`probe`]), where the
//! two CPUs sat ([`cpus`]), the cost plot ([`cost`]) and what the machine is ([`machine`]).

mod cost;
mod cpus;
#[cfg(test)]
mod fixtures;
mod goals;
mod machine;
mod probe;
mod rounds;
mod sweep;

pub use cost::{cost_lines, cost_png, draw_cost, CostLine};
pub use goals::{goals, markdown, report, sweep_goals, sweep_markdown, Goal};
pub use machine::{children_peak_rss, cpu_model, header, own_peak_rss};
pub use rounds::{run, run_peer, write_peer_state, Config, Measured};
pub use sweep::{csv, processes, steps_for, sweep, AtSize, Size};
