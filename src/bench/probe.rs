//! The core-to-core round trip: how long a cache line takes between the two CPUs a bench runs
//! on, probed before and after each run on two or more CPUs.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::Instant;

use crate::step::team::{allowed_cpus, Bound};

/// The counter the probe's two threads hand to each other, on a cache line of its own: no other
/// datum travels with it.
#[repr(align(128))]
struct Line(AtomicU64);

/// Hand-overs of the core-to-core probe before and after each run on two or more CPUs: few
/// enough that the probe takes milliseconds beside a run of seconds, enough that each of its
/// five batches averages 4000 (what it took: `docs/performance.md`).
pub(super) const PROBE_TRIPS: u64 = 20_000;

/// The time one cache line takes to go from the first CPU of this process's affinity mask to
/// the second and back, nanoseconds: two threads, one bound to each, hand one atomic counter to
/// each other `trips` times in five batches (each waits for the other's increment, then
/// increments), and the median batch's mean is returned, so that one preemption does not set
/// it. `None` with fewer than two CPUs, a thread that could not be bound, or `trips` < 5. This is
/// the price of every datum one of a team's threads writes and the other then reads; a virtual
/// machine's two CPUs can be placed near each other or far apart (another core complex or
/// socket of the host), which changes it severalfold from one minute to the next (measured:
/// `docs/performance.md`).
pub(super) fn round_trip_ns(trips: u64) -> Option<f64> {
    const BATCHES: u64 = 5;
    let per_batch = trips / BATCHES;
    if allowed_cpus().len() < 2 || per_batch == 0 {
        return None;
    }
    let line = Line(AtomicU64::new(0));
    let bound = AtomicUsize::new(0);
    let start = std::sync::Barrier::new(2);
    // Thread k waits for the counter to reach an even (k = 0) or odd (k = 1) value, then
    // increments it: two hand-overs a trip, each a transfer of the line to the other CPU.
    let play = |k: u64| -> Option<Vec<f64>> {
        let pinned = Bound::to_nth_cpu(k as usize, 2);
        if pinned.is_some() {
            bound.fetch_add(1, Ordering::Relaxed);
        }
        start.wait();
        // Both threads see the same count after the barrier: both play or neither does (two
        // spinning threads on one CPU would take a time slice a hand-over).
        if bound.load(Ordering::Relaxed) < 2 {
            return None;
        }
        let mut means = Vec::with_capacity(BATCHES as usize);
        for b in 0..BATCHES {
            let t0 = Instant::now();
            for i in b * per_batch..(b + 1) * per_batch {
                let turn = 2 * i + k;
                while line.0.load(Ordering::Acquire) != turn {
                    std::hint::spin_loop();
                }
                line.0.store(turn + 1, Ordering::Release);
            }
            means.push(t0.elapsed().as_secs_f64() * 1e9 / per_batch as f64);
        }
        Some(means)
    };
    let mut means = std::thread::scope(|s| {
        let other = s.spawn(|| play(1));
        let mine = play(0);
        other.join().ok().flatten().and(mine)
    })?;
    means.sort_by(f64::total_cmp);
    Some(means[means.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_round_trip_probe_needs_two_cpus_and_measures_a_positive_time() {
        assert_eq!(round_trip_ns(4), None, "fewer trips than batches");
        let cpus = allowed_cpus().len();
        let t = round_trip_ns(5_000);
        if cpus >= 2 {
            let t = t.expect("two CPUs: a round trip");
            // a hand-over is at least a few cache accesses and far below a time slice
            assert!(t.is_finite() && t > 1.0 && t < 1e6, "{t} ns");
        } else {
            assert_eq!(t, None);
        }
        // bound to one CPU, this thread's mask has one: no probe (two spinners on one CPU would
        // take a time slice a hand-over)
        let _one = Bound::to_nth_cpu(0, 1).expect("binding to the first CPU");
        assert_eq!(round_trip_ns(5_000), None);
    }
}
