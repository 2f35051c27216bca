//! The bench's tables as markdown, with the goals they judge: each goal a median over the rounds
//! of a ratio within a round, met when all of its interval of the median reaches the goal.

use super::cpus::placement;
use super::rounds::{fastest, interval, paired_ratios, verdem_row, Config, Measured, CONFIDENCE};
use super::sweep::{ns_per_particle_step, AtSize};
use crate::analysis::report::{Case, Detail, Report};
use crate::analysis::stats::{hinges, median, median_interval};
use crate::analysis::{Limit, Outcome, Verdict};

/// A goal the tables judged: its verdict, the interval of the median it was judged by (`None`
/// with too few rounds for one) and the number of ratios (rounds) behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct Goal {
    pub verdict: Verdict,
    pub interval: Option<(f64, f64)>,
    pub rounds: usize,
}

/// Keeps the goal `v`, judged from the ratios `r`, in `goals`, and returns it.
fn noted(goals: &mut Vec<Goal>, r: &[f64], v: Verdict) -> Verdict {
    goals.push(Goal {
        verdict: v.clone(),
        interval: median_interval(r, CONFIDENCE),
        rounds: r.len(),
    });
    v
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

/// The table as markdown: code, processes/threads, steps/s (median and all rounds),
/// particle-steps/s, and verdem's best rate over the code's.
pub fn markdown(m: &[Measured], particles: usize) -> String {
    tables(m, particles, &mut Vec::new())
}

/// The goals [`markdown`] judges, in the order it gives them.
pub fn goals(m: &[Measured], particles: usize) -> Vec<Goal> {
    let mut goals = Vec::new();
    tables(m, particles, &mut goals);
    goals
}

/// [`markdown`], keeping each goal it judges in `goals`.
fn tables(m: &[Measured], particles: usize, goals: &mut Vec<Goal>) -> String {
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
            in_words(&noted(
                goals,
                &ratios,
                goal_verdict("verdem 2 threads / 1 thread", &ratios, SPEEDUP_GOAL)
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
            let ratios = paired_ratios(coupled, two);
            let verdict = noted(
                goals,
                &ratios,
                goal_verdict(
                    "verdem 2 threads / the lockstep pair",
                    &ratios,
                    LOCKSTEP_GOAL,
                ),
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
            let verdict = noted(goals, &ratios, goal_verdict(&quantity, &ratios, PEER_GOAL));
            let judged = if particles == BENCHMARK_PARTICLES {
                let cell = format!("{quantity}, on the benchmark's cell");
                format!(
                    "{}, ≥ {BENCHMARK_PEER_GOAL} on the benchmark's cell: {}",
                    outcome_word(&verdict),
                    in_words(&noted(
                        goals,
                        &ratios,
                        goal_verdict(&cell, &ratios, BENCHMARK_PEER_GOAL)
                    ))
                )
            } else {
                in_words(&verdict)
            };
            s.push_str(&format!(
                "\n{quantity}: {:.2} (median over the rounds of the ratio within a round); goal ≥ {PEER_GOAL}: {judged}\n",
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

/// The speed-up of 2 threads over 1 asked of verdem in a sweep, at sizes of at least
/// [`SCALE_SPEEDUP_FROM`] particles (where the meeting once a step is amortised).
const SCALE_SPEEDUP_GOAL: f64 = 1.8;

/// The smallest size at which a sweep judges [`SCALE_SPEEDUP_GOAL`] (the 4×4 tiling).
const SCALE_SPEEDUP_FROM: usize = 55_680;

/// The largest spread of verdem's cost per particle-step across the sizes of a sweep (the
/// costliest size's over the cheapest's).
const SPREAD_GOAL: f64 = 1.5;

/// The sweep's tables as markdown: one summary row per size and configuration (particles,
/// steps, code, processes/threads, steps/s, particle-steps/s, ns per particle-step, verdem's
/// best rate over the code's, peak memory per particle), the goals judged with intervals,
/// then each size's own table ([`markdown`]).
pub fn sweep_markdown(sizes: &[AtSize]) -> String {
    sweep_tables(sizes, &mut Vec::new())
}

/// The goals [`sweep_markdown`] judges, in the order it gives them: the sweep's, then each
/// size's table's, whose verdicts name their size as their case.
pub fn sweep_goals(sizes: &[AtSize]) -> Vec<Goal> {
    let mut goals = Vec::new();
    sweep_tables(sizes, &mut goals);
    goals
}

/// [`sweep_markdown`], keeping each goal it judges in `goals`.
fn sweep_tables(sizes: &[AtSize], goals: &mut Vec<Goal>) -> String {
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
            let ratios = paired_ratios(p, v);
            let verdict = noted(goals, &ratios, goal_verdict(&quantity, &ratios, PEER_GOAL));
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
            let verdict = noted(
                goals,
                &spread,
                limit_verdict(
                    &quantity,
                    &spread,
                    Limit::Below(SPREAD_GOAL),
                    format!("< {SPREAD_GOAL}"),
                ),
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
            let ratios = paired_ratios(one, two);
            let verdict = noted(
                goals,
                &ratios,
                goal_verdict(&quantity, &ratios, SCALE_SPEEDUP_GOAL),
            );
            s.push_str(&format!(
                "- {quantity}: {:.2}; goal ≥ {SCALE_SPEEDUP_GOAL}: {}",
                verdict.measured,
                in_words(&verdict)
            ));
            // What the machine gives two jobs of this size that share nothing, when the ceiling
            // rows ran: a 2-thread code exceeds it only by what halving each core's working set
            // saves, much at sizes beyond a core's cache, little below.
            if let Some(pair) = verdem_row(&at.measured, 1, 2, false) {
                let ratios = paired_ratios(one, pair);
                let apart = goal_verdict("", &ratios, SCALE_SPEEDUP_GOAL);
                // the machine's ceiling beside the goal: reported, not a goal of verdem's
                let quantity = format!(
                    "{} particles: two independent 1-thread runs at once / 1 run alone",
                    at.particles
                );
                noted(
                    goals,
                    &ratios,
                    Verdict {
                        quantity,
                        outcome: Outcome::Reported,
                        ..apart.clone()
                    },
                );
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
            {
                let mut own = Vec::new();
                let table = tables(&at.measured, at.particles, &mut own);
                let case = format!("{} particles", at.particles);
                goals.extend(own.into_iter().map(|mut g| {
                    g.verdict.case = case.clone();
                    g
                }));
                table
            }
        ));
    }
    s
}

/// The goals `goals` ([`goals`], [`sweep_goals`]) as the report `suite` for a CI system: one
/// case per goal in the tables' order, its word the tables' (`met`, `not met`, `undecided`;
/// `info` for the machine's ceiling shown beside a goal). A goal not met is a failure (the
/// command's exit status does not change: the goals are a report), an undecided one is skipped
/// with the reason. The message gives the goal, the median of the ratios within a round and
/// its interval in words; the JSON also the interval's ends and the number of rounds.
pub fn report(suite: &str, goals: &[Goal]) -> Report {
    let needs_rounds = interval(None);
    let cases = goals
        .iter()
        .map(|g| {
            let v = &g.verdict;
            let median = if v.measured.is_finite() {
                format!("{:.3}", v.measured)
            } else {
                "undefined".into()
            };
            let judged = Verdict {
                gate: true,
                measured_text: format!("{median} ({})", interval(g.interval)),
                expected_text: String::new(),
                ..v.clone()
            };
            let word = match v.outcome {
                Outcome::Reported => "info",
                _ => outcome_word(v),
            };
            let (lo, hi) = g.interval.unwrap_or((f64::NAN, f64::NAN));
            Case::of(suite, &judged, word)
                .undefined_because("no round measured: no median")
                .with_details(vec![
                    Detail::new("interval_low", lo, &needs_rounds),
                    Detail::new("interval_high", hi, &needs_rounds),
                    Detail::new("rounds", g.rounds as f64, ""),
                ])
        })
        .collect();
    Report::of_cases(suite, cases)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::Status;
    use crate::bench::fixtures::{measured, two_sizes};

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
    fn the_report_fails_a_goal_not_met_and_skips_an_undecided_one_and_the_ceiling() {
        let mut sizes = two_sizes();
        sizes[1]
            .measured
            .push(measured(1, 2, &[85.0, 90.0, 95.0, 100.0, 105.0, 110.0]));
        let judged = sweep_goals(&sizes);
        let md = sweep_markdown(&sizes);
        // every goal the tables judge is in them, in words
        for g in &judged {
            let v = &g.verdict;
            assert!(md.contains(&in_words(v)), "{v:?}");
        }
        let r = report("verdem bench", &judged);
        let case = |name: &str| {
            r.cases
                .iter()
                .find(|c| c.name == name)
                .unwrap_or_else(|| panic!("{name}: {:#?}", r.cases))
        };
        let peer = case("55680 particles: verdem (deterministic) 2 / the fastest peer, lammps 2");
        assert_eq!(
            (peer.status, peer.result.as_str()),
            (Status::Failed, "not met")
        );
        assert_eq!(
            peer.message,
            "expected at least 5, measured 3.200 (95 % interval of the median 3.200–3.200)"
        );
        assert_eq!((peer.expected, peer.measured), (Some(5.0), Some(3.2)));
        let met = case("3480 particles: verdem (deterministic) 2 / the fastest peer, lammps 2");
        assert_eq!((met.status, met.result.as_str()), (Status::Passed, "met"));
        let ceiling = case("55680 particles: two independent 1-thread runs at once / 1 run alone");
        assert_eq!(ceiling.status, Status::Skipped);
        assert!(ceiling
            .message
            .ends_with("; skipped: reported for information, not judged"));
        // each size's own table's goals, named by their size: 2/1 at 3480 with six rounds
        let own = r
            .cases
            .iter()
            .find(|c| c.group == "3480 particles" && c.name == "verdem 2 threads / 1 thread")
            .unwrap();
        assert_eq!(own.status, Status::Passed, "{own:?}");
        assert_eq!(own.details[2].value, Some(6.0));
        // three rounds give no interval: undecided, skipped, the interval's ends null with why
        let few = [measured(1, 1, &[1.0; 3]), measured(2, 1, &[1.0; 3])];
        let r = report("verdem bench", &goals(&few, 10));
        assert_eq!(r.cases[0].status, Status::Skipped);
        assert_eq!(r.cases[0].details[0].value, None);
        assert_eq!(
            r.cases[0].details[0].undefined.as_deref(),
            Some("a 95 % interval of the median needs 6 rounds or more")
        );
        let json = r.json();
        assert_eq!(
            crate::io::atomic::non_finite(json.as_bytes()),
            None,
            "{json}"
        );
    }
}
