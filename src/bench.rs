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
use crate::team::{round_trip_ns, Bound, SpinBarrier};

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

/// Hand-overs of the core-to-core probe before and after each run on two or more CPUs: ~2–7 ms
/// at 80–350 ns a round trip.
const PROBE_TRIPS: u64 = 20_000;

/// The probes of a bench fall into placements of the two CPUs: sorted, they are cut wherever
/// one exceeds the one below it by more than this ratio. In the 30 benches recorded in `docs/`
/// (2026-11-24 to 11-29) the probes fell at 28–32, 51–151 and 300–500 ns; the two nearest
/// placements were 1.76× apart at their closest, while consecutive probes within one placement
/// were never more than 1.3× apart.
const PLACEMENT_GAP: f64 = 1.5;

/// The placements of the two CPUs that the probes `probes` (ns) show: the probes sorted and cut
/// at every gap of more than [`PLACEMENT_GAP`]×, each group as its lowest and highest probe,
/// nearest first; empty without probes.
fn placements(probes: &[f64]) -> Vec<(f64, f64)> {
    let mut p: Vec<f64> = probes
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    p.sort_by(f64::total_cmp);
    let mut groups: Vec<(f64, f64)> = Vec::new();
    for x in p {
        match groups.last_mut() {
            Some((_, hi)) if x / *hi <= PLACEMENT_GAP => *hi = x,
            _ => groups.push((x, x)),
        }
    }
    groups
}

/// The placement (an index into `groups`, [`placements`]) of a run whose probes before and
/// after are `probes`: `None` when they fall in different groups (the host moved a CPU during
/// the run) or in none.
fn placed(groups: &[(f64, f64)], probes: [f64; 2]) -> Option<usize> {
    let group = |p: f64| groups.iter().position(|(lo, hi)| (*lo..=*hi).contains(&p));
    match (group(probes[0]), group(probes[1])) {
        (Some(a), Some(b)) if a == b => Some(a),
        _ => None,
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
fn unmeasured(configs: &[Config]) -> Vec<Measured> {
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
fn peer_states(
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
    peer.run(np, dir, &script)
}

/// One round: every configuration of `out` once, in order, `steps` steps from `state`; each
/// appends its rate. Peers read their state files `states` ([`peer_states`]) and run in
/// `work`.
fn round(
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
/// apart, so a drift of the machine cancels).
fn paired_ratios(a: &Measured, b: &Measured) -> Vec<f64> {
    a.rates.iter().zip(&b.rates).map(|(x, y)| y / x).collect()
}

/// The speed-up of 2 threads over 1 asked of verdem; the table counts the rounds that reach it.
const SPEEDUP_GOAL: f64 = 1.7;

/// The same on the benchmark's own cell ([`BENCHMARK_PARTICLES`]), from the steady and the
/// developing state.
const BENCHMARK_PEER_GOAL: f64 = 10.0;

/// Spheres of the benchmark's cell: 3000 free and 480 in the walls.
const BENCHMARK_PARTICLES: usize = 3480;

/// The rate on 2 threads asked of verdem, as a fraction of the lockstep pair's in the same round.
const LOCKSTEP_GOAL: f64 = 0.95;

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
    limit_verdict(quantity, r, Limit::AtLeast(goal), format!("≥ {goal}"))
}

/// As [`goal_verdict`] for any one-sided `limit` (a [`Limit::AtLeast`] or [`Limit::Below`]),
/// shown as `expected`.
fn limit_verdict(quantity: &str, r: &[f64], limit: Limit, expected: String) -> Verdict {
    let found = median_interval(r, CONFIDENCE);
    let outcome = match found {
        Some((lo, hi)) if limit.admits(lo) && limit.admits(hi) => Outcome::Pass,
        Some((lo, hi)) if !limit.admits(lo) && !limit.admits(hi) => Outcome::Fail,
        _ => Outcome::Undecided,
    };
    let measured = if r.is_empty() { f64::NAN } else { median(r) };
    Verdict {
        outcome,
        gate: false,
        ..Verdict::judge("", quantity, measured, limit)
    }
    .described(interval(found), expected)
}

/// A goal's verdict in a word or two: "met", "not met" or "undecided".
fn outcome_word(v: &Verdict) -> &'static str {
    match v.outcome {
        Outcome::Pass => "met",
        Outcome::Fail => "not met",
        Outcome::Undecided | Outcome::Reported => "undecided",
    }
}

/// A goal's verdict in words ([`outcome_word`]), followed by the interval.
fn in_words(v: &Verdict) -> String {
    format!("{} ({})", outcome_word(v), v.measured_text)
}

/// verdem's configuration of `copies` runs of `threads` threads each (`lockstep`: meeting once
/// a step) among `m`.
fn verdem_row(m: &[Measured], threads: usize, copies: usize, lockstep: bool) -> Option<&Measured> {
    m.iter().find(|x| {
        x.config
            == Config::Verdem {
                threads,
                copies,
                lockstep,
            }
    })
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
    if let (Some(one), Some(two)) = (verdem_row(m, 1, 1, false), verdem_row(m, 2, 1, false)) {
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
        if let Some(pair) = verdem_row(m, 1, 2, false) {
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
        if let Some(coupled) = verdem_row(m, 1, 2, true) {
            s.push_str(&ceiling(
                coupled,
                "the same two runs waiting for each other once a step",
                "two jobs that share no data but meet once a step, as a team's threads do",
            ));
            let verdict = goal_verdict(
                "verdem 2 threads / the lockstep pair",
                &paired_ratios(coupled, two),
                LOCKSTEP_GOAL,
            );
            s.push_str(&format!(
                " (median over the rounds of 2 threads / that pair within a round: {:.2}; goal ≥ {LOCKSTEP_GOAL}: {})",
                verdict.measured,
                in_words(&verdict)
            ));
        }
        s.push('\n');
    }
    if let Some(two) = verdem_row(m, 2, 1, false) {
        for peer in m
            .iter()
            .filter(|x| matches!(x.config, Config::Peer { np: 2, .. }))
        {
            let ratios = paired_ratios(peer, two);
            let quantity = format!("verdem 2 threads / {} 2 ranks", peer.config.label().0);
            let verdict = goal_verdict(&quantity, &ratios, PEER_GOAL);
            let goals = if particles == BENCHMARK_PARTICLES {
                format!(
                    "{}, ≥ {BENCHMARK_PEER_GOAL} on the benchmark's cell: {}",
                    outcome_word(&verdict),
                    in_words(&goal_verdict(&quantity, &ratios, BENCHMARK_PEER_GOAL))
                )
            } else {
                in_words(&verdict)
            };
            s.push_str(&format!(
                "\n{quantity}: {:.2} (median over the rounds of the ratio within a round); goal ≥ {PEER_GOAL}: {goals}\n",
                verdict.measured,
            ));
        }
    }
    if let Some(line) = verdem_row(m, 2, 1, false).and_then(|two| placement(m, two)) {
        s.push_str(&line);
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

/// What the core-to-core probes say of the rounds of `team` (verdem's 2 threads): the median
/// round trip, the placements of the two CPUs that all the probes of `m` show ([`placements`]),
/// how many of the team's rounds ran in each with the team's median rate there, and, when the
/// rounds ran in more than one, verdem's 2 threads over 1 thread (and over the lockstep pair,
/// when `m` has them) in the rounds of the placement that most of them ran in. `None` without
/// probes.
fn placement(m: &[Measured], team: &Measured) -> Option<String> {
    let all: Vec<f64> = m
        .iter()
        .flat_map(|x| x.round_trips.iter().flatten())
        .copied()
        .collect();
    let probes: Vec<f64> = team.round_trips.iter().flatten().copied().collect();
    if probes.is_empty() || team.round_trips.len() != team.rates.len() {
        return None;
    }
    let (lo, hi) = (
        probes.iter().copied().fold(f64::INFINITY, f64::min),
        probes.iter().copied().fold(0.0, f64::max),
    );
    let by_round: Vec<String> = team
        .round_trips
        .iter()
        .map(|p| format!("{:.0}/{:.0}", p[0], p[1]))
        .collect();
    let mut line = format!(
        "\ncore-to-core round trip around verdem's 2-thread rounds (before/after each, ns): {}; median {:.0} ns ({lo:.0}–{hi:.0} ns); ",
        by_round.join(", "),
        median(&probes)
    );
    let groups = placements(&all);
    if groups.len() < 2 {
        line.push_str(&format!(
            "the bench's probes show one placement of the two CPUs (no gap between them over {PLACEMENT_GAP}×)\n"
        ));
        return Some(line);
    }
    let at: Vec<Option<usize>> = team
        .round_trips
        .iter()
        .map(|p| placed(&groups, *p))
        .collect();
    let rounds_in =
        |g: usize| -> Vec<usize> { (0..at.len()).filter(|&r| at[r] == Some(g)).collect() };
    let each: Vec<String> = groups
        .iter()
        .enumerate()
        .map(|(g, (a, b))| {
            let rounds = rounds_in(g);
            let rates: Vec<f64> = rounds.iter().map(|&r| team.rates[r]).collect();
            match rounds.len() {
                0 => format!("{a:.0}–{b:.0} ns: no round (other configurations' probes)"),
                n => format!(
                    "{a:.0}–{b:.0} ns: {n} round{} at {:.0} steps/s",
                    if n == 1 { "" } else { "s" },
                    median(&rates)
                ),
            }
        })
        .collect();
    line.push_str(&format!(
        "the bench's probes show {} placements of the two CPUs (cut at every gap over {PLACEMENT_GAP}×); verdem's 2-thread rounds by the placement of both their probes: {}",
        groups.len(),
        each.join("; ")
    ));
    let moved = at.iter().filter(|g| g.is_none()).count();
    if moved > 0 {
        line.push_str(&format!(
            "; {moved} moved from one placement to another during the run"
        ));
    }
    // the placement most rounds ran in (the nearest of a tie); there are two or more
    let common = (0..groups.len())
        .max_by_key(|&g| (rounds_in(g).len(), usize::MAX - g))
        .unwrap_or(0);
    let rounds = rounds_in(common);
    if rounds.is_empty() {
        return Some(line + "\n");
    }
    if rounds.len() == at.len() {
        line.push_str(": every ratio above is of that placement\n");
        return Some(line);
    }
    line.push_str("; the ratios above include every round");
    if let Some(one) = verdem_row(m, 1, 1, false) {
        let (a, b) = groups[common];
        let of = |x: &Measured, rounds: &[usize]| -> Vec<f64> {
            rounds
                .iter()
                .filter_map(|&r| Some(x.rates.get(r)? / one.rates.get(r)?))
                .collect()
        };
        let speedup = of(team, &rounds);
        line.push_str(&format!(
            ". In the {} rounds placed as most were ({a:.0}–{b:.0} ns): verdem 2 threads / 1 thread {:.2} ({})",
            rounds.len(),
            median(&speedup),
            interval(median_interval(&speedup, CONFIDENCE))
        ));
        if let Some(pair) = verdem_row(m, 1, 2, true) {
            let both: Vec<usize> = rounds
                .iter()
                .copied()
                .filter(|&r| {
                    pair.round_trips.get(r).and_then(|p| placed(&groups, *p)) == Some(common)
                })
                .collect();
            if !both.is_empty() {
                line.push_str(&format!(
                    "; in the {} of them whose lockstep pair ran there too, verdem's 2 threads reach {:.0} % of that pair",
                    both.len(),
                    100.0 * median(&of(team, &both)) / median(&of(pair, &both))
                ));
            }
        }
    }
    line.push('\n');
    Some(line)
}

/// One system size of a sweep: a (tiled) case, its state, and the steps each run takes there.
#[derive(Clone, Debug)]
pub struct Size {
    pub case: Case,
    pub state: std::path::PathBuf,
    pub particles: usize,
    pub steps: u64,
    /// Where its peers' inputs and runs go.
    pub work: std::path::PathBuf,
}

/// The steps that make about `particle_steps` particle-steps with `particles` particles
/// (rounded, at least 1): runs of one sweep then take about the same time at every size when
/// the cost per particle-step is flat.
pub fn steps_for(particle_steps: u64, particles: usize) -> u64 {
    ((particle_steps as f64 / particles.max(1) as f64).round() as u64).max(1)
}

/// The measurements at one size: the rates of every configuration and, where measured, the
/// peak resident memory of a run of each (bytes, over all its processes: [`processes`]).
#[derive(Clone, Debug)]
pub struct AtSize {
    pub particles: usize,
    pub steps: u64,
    pub measured: Vec<Measured>,
    pub peak_rss: Vec<Option<f64>>,
}

impl AtSize {
    /// The measurements of one size without memory figures.
    pub fn without_memory(particles: usize, steps: u64, measured: Vec<Measured>) -> AtSize {
        let peak_rss = vec![None; measured.len()];
        AtSize {
            particles,
            steps,
            measured,
            peak_rss,
        }
    }
}

/// The processes a configuration runs as: a peer's MPI ranks when it is started by `mpirun`
/// (else 1: Yade's threads share one process), one for verdem; `None` for the ceiling rows,
/// whose memory is not a code's.
pub fn processes(c: &Config) -> Option<usize> {
    match c {
        Config::Verdem { copies: 1, .. } => Some(1),
        Config::Verdem { .. } => None,
        Config::Peer { peer, np } => Some(if peer.command_line(*np).starts_with("mpirun") {
            *np
        } else {
            1
        }),
    }
}

/// Runs every size of `sizes` with every configuration, `rounds` times: each round runs every
/// size in turn and, at each size, every configuration in turn (so that a drift of the machine
/// falls alike on all, and the ratios across sizes are paired by round too).
pub fn sweep(sizes: &[Size], configs: &[Config], rounds: usize) -> anyhow::Result<Vec<AtSize>> {
    let states = sizes
        .iter()
        .map(|z| peer_states(&z.case, &z.state, configs, &z.work))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut out: Vec<AtSize> = sizes
        .iter()
        .map(|z| AtSize::without_memory(z.particles, z.steps, unmeasured(configs)))
        .collect();
    for _ in 0..rounds {
        for ((z, st), at) in sizes.iter().zip(&states).zip(out.iter_mut()) {
            round(&z.case, &z.state, z.steps, st, &z.work, &mut at.measured)
                .with_context(|| format!("{} particles", z.particles))?;
        }
    }
    Ok(out)
}

/// The peak resident memory (bytes) of this process's own address space (`VmHWM` in
/// `/proc/self/status`): unlike `getrusage`'s, it starts afresh at `exec`, so that a process
/// started by a large one (`fork` and `exec`, as [`crate::child::spawn`] does) does not
/// inherit its parent's resident memory. `None` where the file or the line is missing.
pub fn own_peak_rss() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .strip_suffix("kB")?
        .trim()
        .parse()
        .ok()?;
    Some(kib * 1024.0)
}

/// The peak resident memory (bytes) of the largest of this process's waited-for descendants,
/// from `getrusage(RUSAGE_CHILDREN)` (the kernel keeps the largest one's, not their sum; a
/// child started by `fork` and `exec` counts this process's resident memory at that moment
/// too);
/// `None` where it fails.
pub fn children_peak_rss() -> Option<f64> {
    // SAFETY: getrusage writes one `rusage` into the zeroed struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    let done = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) } == 0;
    // ru_maxrss is in KiB on Linux
    (done && u.ru_maxrss > 0).then_some(u.ru_maxrss as f64 * 1024.0)
}

/// The speed-up of 2 threads over 1 asked of verdem in a sweep, at sizes of at least
/// [`SCALE_SPEEDUP_FROM`] particles (where the meeting once a step is amortised).
const SCALE_SPEEDUP_GOAL: f64 = 1.8;

/// The smallest size at which a sweep judges [`SCALE_SPEEDUP_GOAL`] (the 4×4 tiling).
const SCALE_SPEEDUP_FROM: usize = 55_680;

/// The largest spread of verdem's cost per particle-step across the sizes of a sweep (the
/// costliest size's over the cheapest's).
const SPREAD_GOAL: f64 = 1.5;

/// The fastest (highest median) of the configurations of `m` that `keep` selects.
fn fastest(m: &[Measured], keep: impl Fn(&Config) -> bool) -> Option<&Measured> {
    m.iter()
        .filter(|x| keep(&x.config))
        .max_by(|a, b| a.median().total_cmp(&b.median()))
}

/// Cost per particle-step (ns) at the rate `steps_per_s` with `particles` particles.
fn ns_per_particle_step(steps_per_s: f64, particles: usize) -> f64 {
    1e9 / (steps_per_s * particles as f64)
}

/// The sweep's tables as markdown: one summary row per size and configuration (particles,
/// steps, code, processes/threads, steps/s, particle-steps/s, ns per particle-step, verdem's
/// best rate over the code's, peak memory per particle), the goals judged with intervals,
/// then each size's own table ([`markdown`]).
pub fn sweep_markdown(sizes: &[AtSize]) -> String {
    let mut s = String::from("| particles | steps | code | procs/threads | steps/s (median) | particle-steps/s | ns per particle-step | verdem best / this | peak RSS per particle (bytes) |\n|---|---|---|---|---|---|---|---|---|\n");
    for at in sizes {
        let best = fastest(&at.measured, |c| {
            matches!(c, Config::Verdem { copies: 1, .. })
        })
        .map_or(f64::NAN, Measured::median);
        for (x, rss) in at.measured.iter().zip(&at.peak_rss) {
            let (code, n) = x.config.label();
            let memory = rss.map_or("–".to_string(), |b| {
                format!("{:.0}", b / at.particles as f64)
            });
            s.push_str(&format!(
                "| {} | {} | {code} | {n} | {:.1} | {:.3e} | {:.2} | {:.2} | {memory} |\n",
                at.particles,
                at.steps,
                x.median(),
                x.median() * at.particles as f64,
                ns_per_particle_step(x.median(), at.particles),
                best / x.median()
            ));
        }
    }
    s.push_str("\nGoals (medians over the rounds of ratios within a round, 95 % intervals of the median; a goal is met when all of its interval is):\n");
    for at in sizes {
        let verdem = fastest(&at.measured, |c| {
            matches!(c, Config::Verdem { copies: 1, .. })
        });
        let peer = fastest(&at.measured, |c| matches!(c, Config::Peer { .. }));
        if let (Some(v), Some(p)) = (verdem, peer) {
            let (vc, vn) = v.config.label();
            let (pc, pn) = p.config.label();
            let quantity = format!(
                "{} particles: {vc} {vn} / the fastest peer, {pc} {pn}",
                at.particles
            );
            let verdict = goal_verdict(&quantity, &paired_ratios(p, v), PEER_GOAL);
            s.push_str(&format!(
                "- {quantity}: {:.2}; goal ≥ {PEER_GOAL}: {}\n",
                verdict.measured,
                in_words(&verdict)
            ));
        }
    }
    let threads: Vec<usize> = sizes
        .first()
        .map(|at| {
            at.measured
                .iter()
                .filter_map(|x| match x.config {
                    Config::Verdem {
                        threads, copies: 1, ..
                    } => Some(threads),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default();
    if sizes.len() > 1 {
        for t in threads {
            let rows: Vec<(&Measured, usize)> = sizes
                .iter()
                .filter_map(|at| verdem_row(&at.measured, t, 1, false).map(|m| (m, at.particles)))
                .collect();
            let rounds = rows.iter().map(|(m, _)| m.rates.len()).min().unwrap_or(0);
            let spread: Vec<f64> = (0..rounds)
                .map(|r| {
                    let cost: Vec<f64> = rows
                        .iter()
                        .map(|(m, n)| ns_per_particle_step(m.rates[r], *n))
                        .collect();
                    let hi = cost.iter().cloned().fold(0.0, f64::max);
                    let lo = cost.iter().cloned().fold(f64::INFINITY, f64::min);
                    hi / lo
                })
                .collect();
            let quantity = format!(
                "verdem {t} thread(s): cost per particle-step of the costliest size over the cheapest's"
            );
            let verdict = limit_verdict(
                &quantity,
                &spread,
                Limit::Below(SPREAD_GOAL),
                format!("< {SPREAD_GOAL}"),
            );
            s.push_str(&format!(
                "- {quantity}: {:.2}; goal < {SPREAD_GOAL}: {}\n",
                verdict.measured,
                in_words(&verdict)
            ));
        }
    }
    for at in sizes.iter().filter(|at| at.particles >= SCALE_SPEEDUP_FROM) {
        if let (Some(one), Some(two)) = (
            verdem_row(&at.measured, 1, 1, false),
            verdem_row(&at.measured, 2, 1, false),
        ) {
            let quantity = format!("{} particles: verdem 2 threads / 1 thread", at.particles);
            let verdict = goal_verdict(&quantity, &paired_ratios(one, two), SCALE_SPEEDUP_GOAL);
            s.push_str(&format!(
                "- {quantity}: {:.2}; goal ≥ {SCALE_SPEEDUP_GOAL}: {}",
                verdict.measured,
                in_words(&verdict)
            ));
            // What the machine gives two jobs of this size that share nothing, when the ceiling
            // rows ran: a 2-thread code exceeds it only by what halving each core's working set
            // saves, much at sizes beyond a core's cache, little below.
            if let Some(pair) = verdem_row(&at.measured, 1, 2, false) {
                let apart = goal_verdict("", &paired_ratios(one, pair), SCALE_SPEEDUP_GOAL);
                s.push_str(&format!(
                    "; two independent 1-thread runs at once / 1 run alone, what this machine gives two jobs of this size that share nothing (a split that halves each core's working set can exceed it): {:.2}, ≥ {SCALE_SPEEDUP_GOAL} {}",
                    apart.measured,
                    in_words(&apart)
                ));
            }
            s.push('\n');
        }
    }
    for at in sizes {
        s.push_str(&format!(
            "\n## {} particles, {} steps\n\n{}",
            at.particles,
            at.steps,
            markdown(&at.measured, at.particles)
        ));
    }
    s
}

/// The table as CSV, one record per size and configuration: code, processes/threads, median
/// steps/s, particle-steps/s, the rounds' steps/s separated by spaces, then particles, steps
/// per run, ns per particle-step, verdem's best rate over the code's, verdem's 2-thread rate
/// over its 1-thread rate at that size (median of the ratios within a round), and the peak
/// resident memory per particle (bytes; empty where not measured). Fields quoted (RFC 4180)
/// when they hold a comma, a quote or a line break.
pub fn csv(sizes: &[AtSize]) -> String {
    let mut w = ::csv::Writer::from_writer(Vec::new());
    let fail = "a CSV table is written to memory";
    w.write_record([
        "code",
        "procs",
        "median_steps_per_s",
        "particle_steps_per_s",
        "rounds",
        "particles",
        "steps",
        "ns_per_particle_step",
        "verdem_best_over_this",
        "verdem_2_over_1_threads",
        "peak_rss_bytes_per_particle",
    ])
    .expect(fail);
    for at in sizes {
        let n = at.particles;
        let best = fastest(&at.measured, |c| {
            matches!(c, Config::Verdem { copies: 1, .. })
        })
        .map_or(f64::NAN, Measured::median);
        let two_over_one = match (
            verdem_row(&at.measured, 1, 1, false),
            verdem_row(&at.measured, 2, 1, false),
        ) {
            (Some(one), Some(two)) => format!("{:.3}", median(&paired_ratios(one, two))),
            _ => String::new(),
        };
        for (x, rss) in at.measured.iter().zip(&at.peak_rss) {
            let (code, procs) = x.config.label();
            let rounds: Vec<String> = x.rates.iter().map(|r| format!("{r:.1}")).collect();
            w.write_record([
                code,
                procs,
                format!("{:.1}", x.median()),
                format!("{:.1}", x.median() * n as f64),
                rounds.join(" "),
                n.to_string(),
                at.steps.to_string(),
                format!("{:.3}", ns_per_particle_step(x.median(), n)),
                if best.is_nan() {
                    String::new()
                } else {
                    format!("{:.3}", best / x.median())
                },
                two_over_one.clone(),
                rss.map_or(String::new(), |b| format!("{:.0}", b / n as f64)),
            ])
            .expect(fail);
        }
    }
    String::from_utf8(w.into_inner().expect(fail)).expect("CSV of UTF-8 fields")
}

/// One line of the cost plot: its label (code, process count) and its points (particles, ns
/// per particle-step).
pub type CostLine = (String, Vec<(f64, f64)>);

/// Draws the cost per particle-step (ns) against the particles, both on log axes, one line per
/// code and process count (verdem's ceiling rows left out), into the PNG `path`.
pub fn cost_png(sizes: &[AtSize], path: &Path) -> anyhow::Result<()> {
    let Some(first) = sizes.first() else {
        anyhow::bail!("{}: no sizes to plot", path.display());
    };
    let lines: Vec<CostLine> = (0..first.measured.len())
        .filter(|&k| processes(&first.measured[k].config).is_some())
        .map(|k| {
            let (code, n) = first.measured[k].config.label();
            let points = sizes
                .iter()
                .map(|at| {
                    let m = &at.measured[k];
                    (
                        at.particles as f64,
                        ns_per_particle_step(m.median(), at.particles),
                    )
                })
                .filter(|(_, c)| c.is_finite() && *c > 0.0)
                .collect();
            (format!("{code}, {n}"), points)
        })
        .collect();
    draw_cost(&lines, path)
}

/// The lines of the cost plot from a sweep's `bench.csv` (columns `code`, `procs`, `particles`
/// and `ns_per_particle_step`, one row per configuration and size, as [`csv`] writes them), in
/// the order the rows name them; the ceiling rows (processes `2×1`) are left out, as in
/// [`cost_png`]. A missing column or a field that is not a positive number is an error that
/// names the file, the line and the field.
pub fn cost_lines(path: &Path) -> Result<Vec<CostLine>, crate::io::FormatError> {
    let (file, text) = crate::io::read_text(path)?;
    let fail = |line: usize, msg: String| crate::io::FormatError {
        file: file.clone(),
        line,
        msg,
    };
    let mut records = crate::io::csv_table::records(&file, &text, false);
    let Some((_, header)) = records.next().transpose()? else {
        return Err(fail(0, "empty: no header".into()));
    };
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| fail(1, format!("no column {name}")))
    };
    let (code_at, procs_at) = (column("code")?, column("procs")?);
    let (n_at, ns_at) = (column("particles")?, column("ns_per_particle_step")?);
    let mut lines: Vec<CostLine> = Vec::new();
    for record in records {
        let (line, row) = record?;
        let cell = |at: usize| row.get(at).unwrap_or_default();
        let procs = cell(procs_at);
        if procs.contains('×') {
            continue;
        }
        let number = |at: usize, name: &str| {
            cell(at)
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| {
                    fail(
                        line,
                        format!("field {name}: not a positive number: {:?}", cell(at)),
                    )
                })
        };
        number(procs_at, "procs")?;
        let point = (
            number(n_at, "particles")?,
            number(ns_at, "ns_per_particle_step")?,
        );
        let label = format!("{}, {procs}", cell(code_at));
        match lines.iter_mut().find(|(l, _)| *l == label) {
            Some((_, points)) => points.push(point),
            None => lines.push((label, vec![point])),
        }
    }
    if lines.is_empty() {
        return Err(fail(0, "no row to plot".into()));
    }
    Ok(lines)
}

/// Draws `lines` (particles, ns per particle-step) on log axes into the PNG `path`.
pub fn draw_cost(lines: &[CostLine], path: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    crate::analysis::cg::plot::register_font()?;
    let all = || lines.iter().flat_map(|(_, p)| p.iter());
    let (nlo, nhi) = all().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    });
    let (clo, chi) = all().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.1), hi.max(p.1))
    });
    if !(nlo.is_finite() && clo.is_finite()) {
        anyhow::bail!("{}: no measured rate to plot", path.display());
    }
    // the log axes span a factor 1.5 beyond the points: both ends normal positive numbers
    for (what, lo, hi) in [("particles", nlo, nhi), ("ns per particle-step", clo, chi)] {
        anyhow::ensure!(
            lo / 1.5 >= f64::MIN_POSITIVE && (hi * 1.5).is_finite(),
            "{}: cannot draw {what} from {lo:e} to {hi:e} on a log axis",
            path.display()
        );
    }
    let colours = [
        BLUE,
        RED,
        GREEN,
        MAGENTA,
        BLACK,
        CYAN,
        RGBColor(230, 140, 0),
    ];
    let tmp = path.with_extension("part.png");
    let drawn = (|| -> anyhow::Result<Vec<u8>> {
        {
            let root = BitMapBackend::new(&tmp, (900, 600)).into_drawing_area();
            root.fill(&WHITE)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(
                    "cost per particle-step against system size",
                    ("sans-serif", 20),
                )
                .margin(12)
                .x_label_area_size(44)
                .y_label_area_size(64)
                .build_cartesian_2d(
                    (nlo / 1.5..nhi * 1.5)
                        .log_scale()
                        .with_key_points(one_two_five(nlo / 1.5, nhi * 1.5)),
                    (clo / 1.5..chi * 1.5)
                        .log_scale()
                        .with_key_points(one_two_five(clo / 1.5, chi * 1.5)),
                )?;
            chart
                .configure_mesh()
                .x_desc("particles")
                .y_desc("ns per particle-step")
                .x_label_formatter(&|v| format!("{v}"))
                .y_label_formatter(&|v| format!("{v}"))
                .label_style(("sans-serif", 13))
                .draw()?;
            for ((label, points), colour) in lines.iter().zip(colours.iter().cycle()) {
                chart
                    .draw_series(LineSeries::new(points.iter().copied(), colour))?
                    .label(label.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font(("sans-serif", 13))
                .draw()?;
            root.present()?;
        }
        std::fs::read(&tmp).with_context(|| format!("{}: cannot read back", tmp.display()))
    })();
    // the scratch file goes whatever happened; a failure to remove it is not the error to report
    let _ = std::fs::remove_file(&tmp);
    crate::io::atomic::write(path, &drawn?)
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// The values 1, 2 and 5 times a power of ten in `lo..=hi` (lo > 0): the labelled ticks of a log
/// axis, which has some in any range wider than a factor 2.5.
fn one_two_five(lo: f64, hi: f64) -> Vec<f64> {
    let mut decade = 10f64.powi(lo.log10().floor() as i32);
    let mut ticks = Vec::new();
    while decade <= hi {
        ticks.extend(
            [1.0, 2.0, 5.0]
                .map(|m| m * decade)
                .into_iter()
                .filter(|v| (lo..=hi).contains(v)),
        );
        decade *= 10.0;
    }
    ticks
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

    #[test]
    fn cost_lines_group_a_sweeps_rows_by_code_and_processes_and_name_a_bad_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bench.csv");
        let header = "code,procs,median_steps_per_s,particles,ns_per_particle_step";
        let rows = [
            "verdem (deterministic),1,80000,3480,3.6",
            "verdem (deterministic),2,99000,3480,2.9",
            "2 independent verdem runs at once (summed),2×1,150000,3480,1.9",
            "lammps,2,10000,3480,28.3",
            "verdem (deterministic),1,800,222720,5.6",
            "verdem (deterministic),2,1500,222720,3.0",
            "lammps,2,210,222720,21.3",
        ];
        std::fs::write(&path, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
        let lines = cost_lines(&path).unwrap();
        let expected: Vec<CostLine> = vec![
            (
                "verdem (deterministic), 1".into(),
                vec![(3480.0, 3.6), (222720.0, 5.6)],
            ),
            (
                "verdem (deterministic), 2".into(),
                vec![(3480.0, 2.9), (222720.0, 3.0)],
            ),
            ("lammps, 2".into(), vec![(3480.0, 28.3), (222720.0, 21.3)]),
        ];
        assert_eq!(lines, expected);
        let bad = rows.map(|r| r.replace("lammps,2,210,222720,21.3", "lammps,2,210,222720,"));
        std::fs::write(&path, format!("{header}\n{}\n", bad.join("\n"))).unwrap();
        let e = cost_lines(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("bench.csv:8: field ns_per_particle_step: not a positive number: \"\""),
            "{e}"
        );
        std::fs::write(&path, "code,procs,particles\nlammps,1,3480\n").unwrap();
        let e = cost_lines(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("bench.csv:1: no column ns_per_particle_step"),
            "{e}"
        );
    }

    #[test]
    fn a_log_axis_is_labelled_at_one_two_and_five_times_powers_of_ten() {
        assert_eq!(one_two_five(1.4, 60.0), [2.0, 5.0, 10.0, 20.0, 50.0]);
        assert_eq!(
            one_two_five(2320.0, 334080.0),
            [5e3, 1e4, 2e4, 5e4, 1e5, 2e5]
        );
        assert_eq!(one_two_five(1.0, 1.9), [1.0]);
    }

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
            round_trips: Vec::new(),
        }
    }

    #[test]
    fn probes_are_cut_into_placements_at_every_gap_over_the_ratio() {
        assert!(placements(&[]).is_empty());
        assert_eq!(placements(&[50.0]), [(50.0, 50.0)]);
        // the three placements of the AMD EPYC VM, in any order, with a gap of exactly 2× (32 to
        // 64 ns) that a cut at the widest gap alone missed
        assert_eq!(
            placements(&[455.0, 64.0, 29.0, 87.0, 32.0, 472.0, 70.0]),
            [(29.0, 32.0), (64.0, 87.0), (455.0, 472.0)]
        );
        // consecutive probes 1.3× apart stay in one placement however far its ends are
        assert_eq!(
            placements(&[60.0, 78.0, 101.0, 131.0, 170.0]),
            [(60.0, 170.0)]
        );
        let groups = placements(&[29.0, 31.0, 66.0, 84.0]);
        assert_eq!(placed(&groups, [29.0, 31.0]), Some(0));
        assert_eq!(placed(&groups, [84.0, 66.0]), Some(1));
        assert_eq!(placed(&groups, [31.0, 66.0]), None);
        assert_eq!(placed(&groups, [31.0, 500.0]), None);
    }

    #[test]
    fn each_placement_is_named_with_its_rounds_and_rate_and_the_ratios_of_the_commonest() {
        let one = measured(1, 1, &[100.0; 8]);
        let mut two = measured(
            2,
            1,
            &[180.0, 170.0, 120.0, 175.0, 185.0, 110.0, 160.0, 190.0],
        );
        two.round_trips = vec![
            [70.0, 75.0],
            [72.0, 80.0],
            [29.0, 31.0],
            [75.0, 71.0],
            [78.0, 74.0],
            [30.0, 29.0],
            [73.0, 430.0],
            [76.0, 79.0],
        ];
        let line = placement(&[one.clone(), two.clone()], &two).unwrap();
        assert!(
            line.contains(
                "(before/after each, ns): 70/75, 72/80, 29/31, 75/71, 78/74, 30/29, 73/430, 76/79; median 74 ns (29–430 ns)"
            ),
            "{line}"
        );
        assert!(
            line.contains(
                "3 placements of the two CPUs (cut at every gap over 1.5×); verdem's 2-thread rounds by the placement of both their probes: 29–31 ns: 2 rounds at 115 steps/s; 70–80 ns: 5 rounds at 180 steps/s; 430–430 ns: no round (other configurations' probes); 1 moved from one placement to another during the run; the ratios above include every round"
            ),
            "{line}"
        );
        // rounds 0, 1, 3, 4 and 7: ratios 1.80, 1.70, 1.75, 1.85, 1.90
        assert!(
            line.contains(
                ". In the 5 rounds placed as most were (70–80 ns): verdem 2 threads / 1 thread 1.80 (a 95 % interval of the median needs 6 rounds or more)"
            ),
            "{line}"
        );
        assert!(markdown(&[one.clone(), two.clone()], 1).contains(&line));
        // the lockstep pair's rounds in the same placement: 0, 1 and 4 of those five
        let mut pair = measured(
            1,
            2,
            &[190.0, 180.0, 150.0, 100.0, 190.0, 150.0, 150.0, 150.0],
        );
        pair.config = Config::Verdem {
            threads: 1,
            copies: 2,
            lockstep: true,
        };
        pair.round_trips = vec![
            [70.0, 72.0],
            [71.0, 74.0],
            [70.0, 72.0],
            [29.0, 30.0],
            [73.0, 74.0],
            [70.0, 72.0],
            [70.0, 72.0],
            [30.0, 70.0],
        ];
        let line = placement(&[one.clone(), two.clone(), pair.clone()], &two).unwrap();
        // team 1.80, 1.70, 1.85 (median 1.80) over the pair's 1.90, 1.80, 1.90 (median 1.90)
        assert!(
            line.contains(
                "; in the 3 of them whose lockstep pair ran there too, verdem's 2 threads reach 95 % of that pair\n"
            ),
            "{line}"
        );
        // every round of the team in the commonest placement: no second set of ratios
        two.round_trips = vec![[70.0, 75.0]; 8];
        let line = placement(&[one.clone(), two.clone(), pair.clone()], &two).unwrap();
        assert!(
            line.contains("70–75 ns: 8 rounds at 172 steps/s")
                && line.ends_with(": every ratio above is of that placement\n")
                && !line.contains("In the"),
            "{line}"
        );
        // one placement only, or no probes
        two.round_trips = vec![[60.0, 70.0]; 8];
        assert!(placement(&[two.clone()], &two)
            .unwrap()
            .contains("the bench's probes show one placement"));
        two.round_trips.clear();
        assert_eq!(placement(&[two.clone()], &two), None);
    }

    #[test]
    fn the_csv_has_one_record_per_configuration() {
        let mut peer = measured(1, 1, &[1.0, 3.0]);
        peer.config = Config::Peer {
            peer: crate::peers::by_name("lammps").unwrap(),
            np: 2,
        };
        let m = [measured(1, 2, &[100.0, 110.05]), peer];
        let mut at = AtSize::without_memory(10, 500, m.to_vec());
        at.peak_rss[1] = Some(2048.0);
        // no verdem row of one copy: no "verdem best", no 2/1 ratio; ns = 1e9 / (105.025 × 10)
        // and 1e9 / (2 × 10); 2048 bytes over 10 particles
        assert_eq!(
            csv(&[at]),
            "code,procs,median_steps_per_s,particle_steps_per_s,rounds,particles,steps,\
             ns_per_particle_step,verdem_best_over_this,verdem_2_over_1_threads,\
             peak_rss_bytes_per_particle\n\
             2 independent verdem runs at once (summed),2×1,105.0,1050.2,100.0 110.0,10,500,952154.249,,,\n\
             lammps,2,2.0,20.0,1.0 3.0,10,500,50000000.000,,,205\n"
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
            round_trips: Vec::new(),
        };
        let m = [
            measured(2, 1, &[60.0, 55.0, 70.0, 50.0, 65.0, 58.0]),
            peer(1, &[9.0; 6]),
            peer(2, &[10.0, 10.0, 10.0, 10.0, 10.0, 12.0]),
        ];
        let md = markdown(&m, 3480);
        // ratios 6, 5.5, 7, 5, 6.5, 4.83: median 5.75, interval 4.83–7
        assert!(
            md.contains("verdem 2 threads / lammps 2 ranks: 5.75 (median over the rounds of the ratio within a round); goal ≥ 5: undecided, ≥ 10 on the benchmark's cell: not met (95 % interval of the median 4.833–7.000)"),
            "{md}"
        );
        // another case: the benchmark's goal of 10 is not judged
        let md = markdown(&m, 10);
        assert!(
            md.contains("lammps 2 ranks: 5.75 (median over the rounds of the ratio within a round); goal ≥ 5: undecided (95 % interval of the median 4.833–7.000)\n"),
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
        // 150/160, 143/154, 126/144: 0.9375, 0.9286, 0.875
        assert!(
            md.contains(
                "(median over the rounds of 2 threads / that pair within a round: 0.93; goal ≥ 0.95: undecided (a 95 % interval of the median needs 6 rounds or more))"
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

    /// A configuration's measurement with `rates`.
    fn of(config: Config, rates: &[f64]) -> Measured {
        Measured {
            config,
            rates: rates.to_vec(),
            copy_rates: Vec::new(),
            stages: None,
            round_trips: Vec::new(),
        }
    }

    /// Two sizes, six rounds each: verdem on 1 and 2 threads and LAMMPS on 2 ranks.
    fn two_sizes() -> Vec<AtSize> {
        let lammps = || Config::Peer {
            peer: crate::peers::by_name("lammps").unwrap(),
            np: 2,
        };
        let size = |n: usize, one: f64, two: f64, peer: f64| {
            AtSize::without_memory(
                n,
                100,
                vec![
                    measured(1, 1, &[one; 6]),
                    measured(2, 1, &[two; 6]),
                    of(lammps(), &[peer; 6]),
                ],
            )
        };
        vec![
            size(3480, 1000.0, 1800.0, 300.0),
            size(55680, 50.0, 64.0, 20.0),
        ]
    }

    #[test]
    fn a_sweep_judges_the_peers_the_spread_across_sizes_and_the_large_sizes_threads() {
        let md = sweep_markdown(&two_sizes());
        // 1800 / 300 and 64 / 20
        assert!(md.contains("- 3480 particles: verdem (deterministic) 2 / the fastest peer, lammps 2: 6.00; goal ≥ 5: met (95 % interval of the median 6.000–6.000)"), "{md}");
        assert!(md.contains("- 55680 particles: verdem (deterministic) 2 / the fastest peer, lammps 2: 3.20; goal ≥ 5: not met"), "{md}");
        // 1 thread: 1e9/(50·55680) = 359.2 ns over 1e9/(1000·3480) = 287.4 ns
        assert!(md.contains("verdem 1 thread(s): cost per particle-step of the costliest size over the cheapest's: 1.25; goal < 1.5: met"), "{md}");
        // 2 threads: 1e9/(64·55680) = 280.6 ns over 1e9/(1800·3480) = 159.6 ns
        assert!(md.contains("verdem 2 thread(s): cost per particle-step of the costliest size over the cheapest's: 1.76; goal < 1.5: not met"), "{md}");
        // 2/1 judged from 55680 particles on only: 64/50
        assert!(
            md.contains(
                "- 55680 particles: verdem 2 threads / 1 thread: 1.28; goal ≥ 1.8: not met"
            ),
            "{md}"
        );
        assert!(
            !md.contains("- 3480 particles: verdem 2 threads / 1 thread"),
            "{md}"
        );
        // without the ceiling rows the line ends there; with them it gives two independent
        // runs over one
        assert!(
            md.contains("goal ≥ 1.8: not met (95 % interval of the median 1.280–1.280)\n"),
            "{md}"
        );
        let mut sizes = two_sizes();
        sizes[1]
            .measured
            .push(measured(1, 2, &[85.0, 90.0, 95.0, 100.0, 105.0, 110.0]));
        let md = sweep_markdown(&sizes);
        // 85/50 … 110/50: 1.70 … 2.20, median 1.95, its interval 1.70–2.20 holds 1.8
        assert!(
            md.contains("1.280–1.280); two independent 1-thread runs at once / 1 run alone, what this machine gives two jobs of this size that share nothing (a split that halves each core's working set can exceed it): 1.95, ≥ 1.8 undecided (95 % interval of the median 1.700–2.200)\n"),
            "{md}"
        );
        // the summary row: 1e9 / (20 · 55680) ns and 64 / 20
        assert!(
            md.contains("| 55680 | 100 | lammps | 2 | 20.0 | 1.114e6 | 897.99 | 3.20 | – |"),
            "{md}"
        );
        assert!(md.contains("## 3480 particles, 100 steps"), "{md}");
    }

    #[test]
    fn the_csv_gives_each_size_its_rows_and_its_two_thread_ratio() {
        let mut sizes = two_sizes();
        sizes[1].peak_rss[0] = Some(55680.0 * 300.0);
        let csv = csv(&sizes);
        let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), 7);
        assert!(rows.iter().all(|r| r.len() == 11), "{csv}");
        assert_eq!(rows[4][..2], ["verdem (deterministic)", "1"]);
        assert_eq!(
            rows[4][5..],
            ["55680", "100", "359.195", "1.280", "1.280", "300"]
        );
        assert_eq!(rows[1][9], "1.800");
    }

    #[test]
    fn the_cost_plot_is_a_png_of_the_stated_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cost.png");
        cost_png(&two_sizes(), &path).unwrap();
        let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let info = decoder.read_info().unwrap().info().clone();
        assert_eq!((info.width, info.height), (900, 600));
        assert!(!dir.path().join("cost.part.png").exists());
    }

    #[test]
    fn steps_per_size_keep_the_particle_steps() {
        assert_eq!(steps_for(69_600_000, 3480), 20_000);
        assert_eq!(steps_for(69_600_000, 222_720), 313);
        assert_eq!(steps_for(10, 3480), 1);
    }
}
