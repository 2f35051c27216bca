//! Timing comparisons on this machine: verdem and the installed peers run the same case from the
//! same state, alternating (A B A B …) so that drift of a shared machine cancels, with no file
//! output in the timed region. Each code's own loop time is used (verdem: `advance`; a peer:
//! [`Peer::run`], e.g. LAMMPS's "Loop time"), so set-up and file reading are excluded for all.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;

use crate::analysis::stats::{hinges, median, median_interval};
use crate::analysis::{Limit, Outcome, Verdict};
use crate::case::Case;
use crate::engine::{self, Overrides};
use crate::peers::Peer;
use crate::step::StageTimes;
use crate::team::{Bound, SpinBarrier};

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
    std::fs::create_dir_all(work).with_context(|| work.display().to_string())?;
    // each peer's state file in `work`, by peer name, written once before the rounds
    let mut states: Vec<(&str, String)> = Vec::new();
    for c in configs {
        if let Config::Peer { peer, .. } = c {
            if states.iter().all(|(name, _)| *name != peer.name()) {
                let e = engine::build(
                    case,
                    crate::scene::build(case, Some(state))?,
                    &Overrides::default(),
                );
                let file = peer.write_state(&e.snapshot(), case.material.density, work, "state")?;
                let path = work.join(file).canonicalize()?;
                states.push((peer.name(), path.display().to_string()));
            }
        }
    }
    let mut out: Vec<Measured> = configs
        .iter()
        .map(|c| Measured {
            config: c.clone(),
            rates: Vec::new(),
            copy_rates: Vec::new(),
            stages: None,
        })
        .collect();
    for _ in 0..rounds {
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
                            );
                            e.advance(0)?;
                            *e.counters_mut() = StageTimes::default();
                            e.params_mut().meet = barrier
                                .clone()
                                .map(|b| Arc::new(move || b.wait()) as crate::step::MeetHook);
                            Ok(e)
                        })
                        .collect::<anyhow::Result<Vec<_>>>()?;
                    let copies = *copies;
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
                        .map(|(_, path)| path.as_str())
                        .expect("every peer's state is written before the rounds");
                    let script = peer.input_script(case, data, steps, None)?;
                    let seconds = peer.run(*np, &dir, &script)?;
                    m.rates.push(steps as f64 / seconds);
                }
            }
        }
    }
    Ok(out)
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
/// apart, so a drift of the machine cancels).
fn paired_ratios(a: &Measured, b: &Measured) -> Vec<f64> {
    a.rates.iter().zip(&b.rates).map(|(x, y)| y / x).collect()
}

/// The speed-up of 2 threads over 1 asked of verdem; the table counts the rounds that reach it.
const SPEEDUP_GOAL: f64 = 1.7;

/// The rate on 2 threads asked of verdem, in multiples of a peer's rate on 2 ranks.
const PEER_GOAL: f64 = 5.0;

/// The confidence of the intervals of the median.
const CONFIDENCE: f64 = 0.95;

/// An interval of the median, in words.
fn interval(found: Option<(f64, f64)>) -> String {
    let pct = 100.0 * CONFIDENCE;
    match found {
        Some((lo, hi)) => format!("{pct:.0} % interval of the median {lo:.3}–{hi:.3}"),
        None => format!("a {pct:.0} % interval of the median needs 6 rounds or more"),
    }
}

/// Whether the median of the distribution the ratios `r` are drawn from reaches `goal`:
/// [`Outcome::Pass`] when all of its interval of the median does, [`Outcome::Fail`] when none
/// does, [`Outcome::Undecided`] when it holds the goal or there are too few values for one. The
/// measured value is the median (NaN for no values), the interval is its text; a goal does not
/// gate.
fn goal_verdict(quantity: &str, r: &[f64], goal: f64) -> Verdict {
    let found = median_interval(r, CONFIDENCE);
    let outcome = match found {
        Some((lo, _)) if lo >= goal => Outcome::Pass,
        Some((_, hi)) if hi < goal => Outcome::Fail,
        _ => Outcome::Undecided,
    };
    let measured = if r.is_empty() { f64::NAN } else { median(r) };
    Verdict {
        outcome,
        gate: false,
        ..Verdict::judge("", quantity, measured, Limit::AtLeast(goal))
    }
    .described(interval(found), format!("≥ {goal}"))
}

/// A goal's verdict in words: "met", "not met" or "undecided", followed by the interval.
fn in_words(v: &Verdict) -> String {
    let word = match v.outcome {
        Outcome::Pass => "met",
        Outcome::Fail => "not met",
        Outcome::Undecided | Outcome::Reported => "undecided",
    };
    format!("{word} ({})", v.measured_text)
}

/// The table as markdown: code, processes/threads, steps/s (median and all rounds),
/// particle-steps/s, and verdem's best rate over the code's.
pub fn markdown(m: &[Measured], particles: usize) -> String {
    let best = m
        .iter()
        .filter(|x| matches!(x.config, Config::Verdem { copies: 1, .. }))
        .map(Measured::median)
        .fold(0.0, f64::max);
    let mut s = String::from("| code | procs/threads | steps/s (median) | rounds | particle-steps/s | verdem best / this |\n|---|---|---|---|---|---|\n");
    for x in m {
        let (code, n) = x.config.label();
        let rounds: Vec<String> = x.rates.iter().map(|r| format!("{r:.0}")).collect();
        s.push_str(&format!(
            "| {code} | {n} | {:.0} | {} | {:.3e} | {:.2} |\n",
            x.median(),
            rounds.join(", "),
            x.median() * particles as f64,
            best / x.median()
        ));
    }
    let find = |threads: usize, copies: usize, lockstep: bool| {
        m.iter().find(|x| {
            x.config
                == Config::Verdem {
                    threads,
                    copies,
                    lockstep,
                }
        })
    };
    if let (Some(one), Some(two)) = (find(1, 1, false), find(2, 1, false)) {
        let ratios = paired_ratios(one, two);
        let speedup = median(&ratios);
        let (lo, hi) = hinges(&ratios);
        let reached = ratios.iter().filter(|&&r| r >= SPEEDUP_GOAL).count();
        s.push_str(&format!(
            "\nverdem 2 threads / 1 thread: {speedup:.2} (median over the rounds of the ratio within a round; middle half of the rounds {lo:.2}–{hi:.2}; ≥ {SPEEDUP_GOAL} in {reached} of {} rounds; goal ≥ {SPEEDUP_GOAL}: {})",
            ratios.len(),
            in_words(&goal_verdict(
                "verdem 2 threads / 1 thread",
                &ratios,
                SPEEDUP_GOAL
            ))
        ));
        // A ceiling row against 1 thread alone, and verdem's 2 threads against the ceiling.
        let ceiling = |row: &Measured, runs: &str, gives: &str| {
            let ratios = paired_ratios(one, row);
            let ceiling = median(&ratios);
            format!(
                "; {runs} / 1 run alone: {ceiling:.2} ({}), what this machine gives {gives}; verdem's 2 threads reach {:.0} % of that",
                interval(median_interval(&ratios, CONFIDENCE)),
                100.0 * speedup / ceiling
            )
        };
        if let Some(pair) = find(1, 2, false) {
            s.push_str(&ceiling(
                pair,
                "2 independent 1-thread runs at once",
                "two jobs that share nothing",
            ));
            let cpus: Vec<f64> = pair.copy_rates.iter().map(|r| r[1] / r[0]).collect();
            if !cpus.is_empty() {
                let (lo, hi) = hinges(&cpus);
                s.push_str(&format!(
                    " (the run on CPU 1 ran at {:.2}× the rate of the run on CPU 0, middle half of the rounds {lo:.2}–{hi:.2}: a fixed half of the work each would run at the slower one's pace)",
                    median(&cpus)
                ));
            }
        }
        if let Some(coupled) = find(1, 2, true) {
            s.push_str(&ceiling(
                coupled,
                "the same two runs waiting for each other once a step",
                "two jobs that share no data but meet once a step, as a team's threads do",
            ));
        }
        s.push('\n');
    }
    if let Some(two) = find(2, 1, false) {
        for peer in m
            .iter()
            .filter(|x| matches!(x.config, Config::Peer { np: 2, .. }))
        {
            let ratios = paired_ratios(peer, two);
            let quantity = format!("verdem 2 threads / {} 2 ranks", peer.config.label().0);
            let verdict = goal_verdict(&quantity, &ratios, PEER_GOAL);
            s.push_str(&format!(
                "\n{quantity}: {:.2} (median over the rounds of the ratio within a round); goal ≥ {PEER_GOAL}: {}\n",
                verdict.measured,
                in_words(&verdict)
            ));
        }
    }
    for x in m {
        if let (
            Config::Verdem {
                threads, copies: 1, ..
            },
            Some(st),
        ) = (&x.config, &x.stages)
        {
            let total = (st.neighbor + st.forces + st.integrate + st.wait).max(1) as f64;
            let pct = |v: u64| 100.0 * v as f64 / total;
            s.push_str(&format!(
                "\nverdem, {threads} thread(s), last round, thread 0: neighbour list {:.1} % ({} rebuilds), pair forces {:.1} %, gather + integration {:.1} %, waiting for the other threads {:.1} %; output 0 % (none in the timed region)\n",
                pct(st.neighbor),
                st.rebuilds,
                pct(st.forces),
                pct(st.integrate),
                pct(st.wait)
            ));
        }
    }
    s
}

/// The table as CSV: code, processes/threads, median steps/s, particle-steps/s, the rounds'
/// steps/s separated by spaces; fields quoted (RFC 4180) when they hold a comma, a quote or a
/// line break.
pub fn csv(m: &[Measured], particles: usize) -> String {
    let mut w = ::csv::Writer::from_writer(Vec::new());
    let fail = "a CSV table is written to memory";
    w.write_record([
        "code",
        "procs",
        "median_steps_per_s",
        "particle_steps_per_s",
        "rounds",
    ])
    .expect(fail);
    for x in m {
        let (code, n) = x.config.label();
        let rounds: Vec<String> = x.rates.iter().map(|r| format!("{r:.1}")).collect();
        w.write_record([
            code,
            n,
            format!("{:.1}", x.median()),
            format!("{:.1}", x.median() * particles as f64),
            rounds.join(" "),
        ])
        .expect(fail);
    }
    String::from_utf8(w.into_inner().expect(fail)).expect("CSV of UTF-8 fields")
}

/// The first lines of `bench.md`: what was timed (`steps` steps of `case` from the state file
/// `from`, `rounds` alternating rounds) and on what (the CPUs this process may use and
/// [`cpu_model`]).
pub fn header(case: &str, from: &Path, steps: u64, rounds: usize) -> String {
    format!(
        "{steps} steps of {case} from {}, {rounds} alternating rounds, {} cores ({}), no file output in the timed region\n\n",
        from.display(),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0),
        cpu_model()
    )
}

/// The CPU's model name from `/proc/cpuinfo` (empty where there is none, e.g. off Linux).
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|c| {
            c.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(threads: usize, copies: usize, rates: &[f64]) -> Measured {
        Measured {
            config: Config::Verdem {
                threads,
                copies,
                lockstep: false,
            },
            rates: rates.to_vec(),
            copy_rates: Vec::new(),
            stages: None,
        }
    }

    #[test]
    fn the_csv_has_one_record_per_configuration() {
        let mut peer = measured(1, 1, &[1.0, 3.0]);
        peer.config = Config::Peer {
            peer: crate::peers::by_name("lammps").unwrap(),
            np: 2,
        };
        let m = [measured(1, 2, &[100.0, 110.05]), peer];
        assert_eq!(
            csv(&m, 10),
            "code,procs,median_steps_per_s,particle_steps_per_s,rounds\n\
             2 independent verdem runs at once (summed),2×1,105.0,1050.2,100.0 110.0\n\
             lammps,2,2.0,20.0,1.0 3.0\n"
        );
    }

    #[test]
    fn the_paired_ratio_is_the_median_of_the_ratios_within_rounds() {
        // ratios 3, 1, 0.5: median 1; the ratio of the medians would be 3/2
        let (a, b) = (
            measured(1, 1, &[1.0, 2.0, 10.0]),
            measured(2, 1, &[3.0, 2.0, 5.0]),
        );
        assert_eq!(b.median() / a.median(), 1.5);
        assert!(markdown(&[a, b], 10).contains("verdem 2 threads / 1 thread: 1.00 (median"));
    }

    #[test]
    fn the_verdict_says_met_only_when_the_whole_interval_reaches_the_goal() {
        let at = |v: &[f64]| in_words(&goal_verdict("2/1", v, 1.7));
        assert_eq!(
            at(&[1.8, 1.75, 1.9, 2.0, 1.71, 1.85]),
            "met (95 % interval of the median 1.710–2.000)"
        );
        assert_eq!(
            at(&[1.5, 1.6, 1.65, 1.69, 1.4, 1.55]),
            "not met (95 % interval of the median 1.400–1.690)"
        );
        assert!(at(&[1.5, 1.6, 1.65, 1.69, 1.4, 1.75]).starts_with("undecided (95 %"));
        assert_eq!(
            at(&[2.0, 2.0, 2.0]),
            "undecided (a 95 % interval of the median needs 6 rounds or more)"
        );
    }

    #[test]
    fn the_table_judges_verdem_against_each_peer_on_two_ranks() {
        let peer = |np: usize, rates: &[f64]| Measured {
            config: Config::Peer {
                peer: crate::peers::by_name("lammps").unwrap(),
                np,
            },
            rates: rates.to_vec(),
            copy_rates: Vec::new(),
            stages: None,
        };
        let m = [
            measured(2, 1, &[60.0, 55.0, 70.0, 50.0, 65.0, 58.0]),
            peer(1, &[9.0; 6]),
            peer(2, &[10.0, 10.0, 10.0, 10.0, 10.0, 12.0]),
        ];
        let md = markdown(&m, 10);
        // ratios 6, 5.5, 7, 5, 6.5, 4.83: median 5.75, interval 4.83–7
        assert!(
            md.contains("verdem 2 threads / lammps 2 ranks: 5.75 (median over the rounds of the ratio within a round); goal ≥ 5: undecided (95 % interval of the median 4.833–7.000)"),
            "{md}"
        );
        assert!(!md.contains("lammps 1 ranks"), "{md}");
    }

    #[test]
    fn the_table_counts_the_rounds_that_reach_the_goal() {
        let m = [
            measured(1, 1, &[100.0, 100.0, 100.0, 100.0]),
            measured(2, 1, &[169.0, 170.0, 180.0, 150.0]),
        ];
        assert!(markdown(&m, 10).contains("≥ 1.7 in 2 of 4 rounds"));
    }

    #[test]
    fn the_table_puts_the_two_thread_ratio_against_the_ceiling() {
        let mut pair = measured(1, 2, &[190.0, 198.0, 180.0]);
        pair.copy_rates = vec![vec![100.0, 90.0], vec![100.0, 98.0], vec![90.0, 90.0]];
        let m = [
            measured(1, 1, &[100.0, 110.0, 90.0]),
            measured(2, 1, &[150.0, 143.0, 126.0]),
            pair,
        ];
        let md = markdown(&m, 10);
        // CPU 1 / CPU 0: 0.9, 0.98, 1
        assert!(md.contains("CPU 1 ran at 0.98× the rate of the run on CPU 0, middle half of the rounds 0.94–0.99"), "{md}");
        // 2/1 ratios 1.5, 1.3, 1.4; ceiling ratios 1.9, 1.8, 2.0
        assert!(md.contains("verdem 2 threads / 1 thread: 1.40"), "{md}");
        assert!(md.contains("middle half of the rounds 1.35–1.45; ≥ 1.7 in 0 of 3 rounds"));
        assert!(
            md.contains("at once / 1 run alone: 1.90 (a 95 % interval of the median needs 6"),
            "{md}"
        );
        assert!(md.contains("reach 74 % of that"), "{md}");
        assert!(md.contains("| 2 independent verdem runs at once (summed) | 2×1 | 190 |"));
        // the ceiling row is not a verdem configuration: "verdem best" is the 2-thread rate
        assert!(md.contains("| verdem (deterministic) | 1 | 100 | 100, 110, 90 | 1.000e3 | 1.43 |"));
        assert!(!md.contains("once a step"), "{md}");
    }

    #[test]
    fn the_table_puts_the_two_thread_ratio_against_runs_that_meet_once_a_step() {
        let mut coupled = measured(1, 2, &[160.0, 154.0, 144.0]);
        coupled.config = Config::Verdem {
            threads: 1,
            copies: 2,
            lockstep: true,
        };
        let m = [
            measured(1, 1, &[100.0, 110.0, 90.0]),
            measured(2, 1, &[150.0, 143.0, 126.0]),
            coupled,
        ];
        let md = markdown(&m, 10);
        // coupled ratios 1.6, 1.4, 1.6: median 1.6; 2/1 median 1.4
        assert!(
            md.contains(
                "meet once a step, as a team's threads do; verdem's 2 threads reach 88 % of that"
            ),
            "{md}"
        );
        assert!(
            md.contains(
                "| 2 independent verdem runs in lockstep: one barrier a step (summed) | 2×1 | 154 |"
            ),
            "{md}"
        );
        assert!(!md.contains("share nothing"), "{md}");
    }
}
