//! Where the two CPUs a bench ran on sat: the placements of the two CPUs that a bench's
//! core-to-core probes ([`super::probe`]) show, and each placement's rounds and rates.

use super::rounds::{interval, verdem_row, Measured, CONFIDENCE};
use crate::analysis::stats::{median, median_interval};

/// The probes of a bench fall into placements of the two CPUs: sorted, they are cut wherever
/// one exceeds the one below it by more than this ratio: above the ratio of consecutive probes
/// within one placement, below that of the two nearest placements, in the benches recorded
/// (`docs/performance.md`, "Measurements that were code comments").
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

/// What the core-to-core probes say of the rounds of `team` (verdem's 2 threads): the median
/// round trip, the placements of the two CPUs that all the probes of `m` show ([`placements`]),
/// how many of the team's rounds ran in each with the team's median rate there, and, when the
/// rounds ran in more than one, verdem's 2 threads over 1 thread (and over the lockstep pair,
/// when `m` has them) in the rounds of the placement that most of them ran in. `None` without
/// probes.
pub(super) fn placement(m: &[Measured], team: &Measured) -> Option<String> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::fixtures::measured;
    use crate::bench::goals::markdown;
    use crate::bench::rounds::Config;

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
}
