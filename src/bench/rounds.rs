//! The alternating timing rounds: verdem and the installed peers run the same case from the same
//! state, one configuration after the other in every round (A B A B …), so that a drift of a
//! shared machine falls alike on all and the ratios within a round cancel it. Each code's own
//! loop time is used (verdem: `advance`; a peer: [`Peer::run`], e.g. LAMMPS's "Loop time"), so
//! set-up and file reading are excluded for all.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;

use super::probe::{round_trip_ns, PROBE_TRIPS};
use crate::analysis::stats::median;
use crate::case::Case;
use crate::peers::Peer;
use crate::step::engine::{self, Overrides};
use crate::step::team::{Bound, SpinBarrier};
use crate::step::StageTimes;

/// One configuration: a code and its number of threads or MPI ranks.
#[derive(Clone, Debug, PartialEq)]
pub enum Config {
    /// `copies` independent verdem runs of `threads` threads each, started together in one
    /// process, copy k bound to the k-th CPU the process may use (as a team's thread k is) when
    /// there are more copies than one; their rate is the sum of each copy's own rate (its steps
    /// over the time from the common start to its own end), so a CPU that finishes early does
    /// not count as idle. Two copies of one thread measure what this machine gives two fully
    /// independent jobs: the ceiling of any 2-thread speed-up. With `lockstep` the copies wait
    /// for each other once a step at a shared barrier: they share no data but meet once a step
    /// with a fixed half of the work each, as a statically split code's threads or ranks do.
    Verdem {
        threads: usize,
        copies: usize,
        lockstep: bool,
    },
    Peer {
        peer: &'static dyn Peer,
        np: usize,
    },
}

impl Config {
    /// The code's name and its processes/threads column.
    pub fn label(&self) -> (String, String) {
        match self {
            Config::Verdem {
                threads, copies: 1, ..
            } => ("verdem (deterministic)".into(), threads.to_string()),
            Config::Verdem {
                threads,
                copies,
                lockstep: false,
            } => (
                format!("{copies} independent verdem runs at once (summed)"),
                format!("{copies}×{threads}"),
            ),
            Config::Verdem {
                threads,
                copies,
                lockstep: true,
            } => (
                format!(
                    "{copies} independent verdem runs in lockstep: one barrier a step (summed)"
                ),
                format!("{copies}×{threads}"),
            ),
            Config::Peer { peer, np } => (peer.name().to_string(), np.to_string()),
        }
    }
}

/// Measured rates of one configuration over the rounds, and verdem's stage times.
#[derive(Clone, Debug)]
pub struct Measured {
    pub config: Config,
    pub rates: Vec<f64>,
    /// Each copy's own rate in each round, when the configuration runs several copies (copy k
    /// on CPU k); empty otherwise.
    pub copy_rates: Vec<Vec<f64>>,
    pub stages: Option<StageTimes>,
    /// For a configuration on two or more CPUs, the core-to-core round trip
    /// ([`round_trip_ns`], nanoseconds) just before and just after each round's run.
    pub round_trips: Vec<[f64; 2]>,
}

impl Measured {
    /// Median steps per second.
    pub fn median(&self) -> f64 {
        median(&self.rates)
    }
}

/// Runs every configuration `rounds` times, alternating, `steps` steps each, from `state`.
pub fn run(
    case: &Case,
    state: &Path,
    steps: u64,
    configs: &[Config],
    rounds: usize,
    work: &Path,
) -> anyhow::Result<Vec<Measured>> {
    let states = peer_states(case, state, configs, work)?;
    let mut out = unmeasured(configs);
    for _ in 0..rounds {
        round(case, state, steps, &states, work, &mut out)?;
    }
    Ok(out)
}

/// Each configuration with no rate yet.
pub(super) fn unmeasured(configs: &[Config]) -> Vec<Measured> {
    configs
        .iter()
        .map(|c| Measured {
            config: c.clone(),
            rates: Vec::new(),
            copy_rates: Vec::new(),
            stages: None,
            round_trips: Vec::new(),
        })
        .collect()
}

/// Each peer's state file in `work` (created), by peer name, for the peers of `configs`.
pub(super) fn peer_states(
    case: &Case,
    state: &Path,
    configs: &[Config],
    work: &Path,
) -> anyhow::Result<Vec<(&'static str, String)>> {
    std::fs::create_dir_all(work).with_context(|| work.display().to_string())?;
    let mut states: Vec<(&str, String)> = Vec::new();
    for c in configs {
        if let Config::Peer { peer, .. } = c {
            if states.iter().all(|(name, _)| *name != peer.name()) {
                let path = write_peer_state(case, state, *peer, work, "state")?;
                states.push((peer.name(), path.display().to_string()));
            }
        }
    }
    Ok(states)
}

/// Writes the state file `state` of `case` in `peer`'s format into `work` under the stem
/// `stem`; returns its absolute path.
pub fn write_peer_state(
    case: &Case,
    state: &Path,
    peer: &dyn Peer,
    work: &Path,
    stem: &str,
) -> anyhow::Result<std::path::PathBuf> {
    let e = engine::build(
        case,
        crate::scene::build(case, Some(state))?,
        &Overrides::default(),
    )?;
    let file = peer.write_state(&e.snapshot(), case.material.density, work, stem)?;
    let path = work.join(file);
    path.canonicalize()
        .with_context(|| path.display().to_string())
}

/// Runs `peer` once on `np` processes in `dir` (created), `steps` steps of `case` from its own
/// state file `data` ([`write_peer_state`]), no file output; returns its loop's seconds.
pub fn run_peer(
    case: &Case,
    peer: &dyn Peer,
    np: usize,
    data: &Path,
    steps: u64,
    dir: &Path,
) -> anyhow::Result<f64> {
    std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    let script = peer.input_script(case, &data.display().to_string(), steps, None)?;
    peer.run(&crate::peers::Run { dir, np }, &script)
}

/// One round: every configuration of `out` once, in order, `steps` steps from `state`; each
/// appends its rate. Peers read their state files `states` ([`peer_states`]) and run in
/// `work`.
pub(super) fn round(
    case: &Case,
    state: &Path,
    steps: u64,
    states: &[(&'static str, String)],
    work: &Path,
    out: &mut [Measured],
) -> anyhow::Result<()> {
    for m in out.iter_mut() {
        match &m.config {
            Config::Verdem {
                threads,
                copies,
                lockstep,
            } => {
                let barrier = lockstep.then(|| Arc::new(SpinBarrier::new(*copies)));
                let mut engines = (0..*copies)
                    .map(|_| {
                        let mut e = engine::build(
                            case,
                            crate::scene::build(case, Some(state))?,
                            &Overrides {
                                threads: Some(*threads),
                                ..Overrides::default()
                            },
                        )?;
                        e.advance(0)?;
                        *e.counters_mut() = StageTimes::default();
                        e.params_mut().meet = barrier
                            .clone()
                            .map(|b| Arc::new(move || b.wait()) as crate::step::MeetHook);
                        Ok(e)
                    })
                    .collect::<anyhow::Result<Vec<_>>>()?;
                let copies = *copies;
                let probed = threads * copies > 1;
                let before = probed.then(|| round_trip_ns(PROBE_TRIPS)).flatten();
                let start = std::sync::Barrier::new(copies);
                let time_copy = |k: usize, e: &mut dyn crate::step::Engine| {
                    let _bound = (copies > 1).then(|| Bound::to_nth_cpu(k, copies)).flatten();
                    start.wait();
                    let t0 = Instant::now();
                    advance_in_chunks(e, steps)?;
                    Ok::<f64, crate::step::guard::Failure>(
                        steps as f64 / t0.elapsed().as_secs_f64(),
                    )
                };
                let own: Vec<f64> = std::thread::scope(|s| {
                    let (first, rest) = engines.split_at_mut(1);
                    let others: Vec<_> = rest
                        .iter_mut()
                        .enumerate()
                        .map(|(k, e)| {
                            let time_copy = &time_copy;
                            s.spawn(move || time_copy(k + 1, e.as_mut()))
                        })
                        .collect();
                    let mut own = vec![time_copy(0, first[0].as_mut())];
                    own.extend(others.into_iter().map(|h| h.join().expect("copy runs")));
                    own.into_iter().collect::<Result<Vec<f64>, _>>()
                })?;
                m.rates.push(own.iter().sum());
                if let (Some(b), Some(a)) =
                    (before, probed.then(|| round_trip_ns(PROBE_TRIPS)).flatten())
                {
                    m.round_trips.push([b, a]);
                }
                if copies > 1 {
                    m.copy_rates.push(own);
                }
                m.stages = Some(*engines[0].counters());
            }
            Config::Peer { peer, np } => {
                let dir = work.join(format!("{}-{np}", peer.binary()));
                std::fs::create_dir_all(&dir)?;
                let data = states
                    .iter()
                    .find(|(name, _)| *name == peer.name())
                    .map(|(_, path)| Path::new(path))
                    .expect("every peer's state is written before the rounds");
                let seconds = run_peer(case, *peer, *np, data, steps, &dir)?;
                m.rates.push(steps as f64 / seconds);
            }
        }
    }
    Ok(())
}

/// Advances `steps` steps in chunks as a run does (progress and saves happen between them).
fn advance_in_chunks(
    e: &mut dyn crate::step::Engine,
    steps: u64,
) -> Result<(), crate::step::guard::Failure> {
    let mut left = steps;
    while left > 0 {
        let k = left.min(2000);
        e.advance(k)?;
        left -= k;
    }
    Ok(())
}

/// The rate of `b` over that of `a` in each round (paired: the runs of one round are seconds
/// The confidence of the intervals of the median.
pub(super) const CONFIDENCE: f64 = 0.95;

/// An interval of the median, in words.
pub(super) fn interval(found: Option<(f64, f64)>) -> String {
    let pct = 100.0 * CONFIDENCE;
    match found {
        Some((lo, hi)) => format!("{pct:.0} % interval of the median {lo:.3}–{hi:.3}"),
        None => format!("a {pct:.0} % interval of the median needs 6 rounds or more"),
    }
}

/// apart, so a drift of the machine cancels).
pub(super) fn paired_ratios(a: &Measured, b: &Measured) -> Vec<f64> {
    a.rates.iter().zip(&b.rates).map(|(x, y)| y / x).collect()
}

/// verdem's configuration of `copies` runs of `threads` threads each (`lockstep`: meeting once
/// a step) among `m`.
pub(super) fn verdem_row(
    m: &[Measured],
    threads: usize,
    copies: usize,
    lockstep: bool,
) -> Option<&Measured> {
    m.iter().find(|x| {
        x.config
            == Config::Verdem {
                threads,
                copies,
                lockstep,
            }
    })
}

/// The fastest (highest median) of the configurations of `m` that `keep` selects.
pub(super) fn fastest(m: &[Measured], keep: impl Fn(&Config) -> bool) -> Option<&Measured> {
    m.iter()
        .filter(|x| keep(&x.config))
        .max_by(|a, b| a.median().total_cmp(&b.median()))
}
