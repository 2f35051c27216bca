//! A persistent team of threads for the time step: every thread runs the same step loop on its
//! own share of the work (SPMD) and they meet at barriers between phases. A step of this small
//! system takes tens of microseconds, so a fork–join per phase (rayon) would cost a large
//! fraction of it; a spinning barrier costs well under a microsecond.

use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long a thread spins at a barrier before it sleeps: longer than most waits of a step on
/// an idle machine (10 µs was not: waking a sleeper costs more than the wait), far shorter than
/// a scheduler time slice.
const SPIN: Duration = Duration::from_micros(50);

/// A reusable barrier for a fixed number of threads. Threads spin for up to [`SPIN`], then
/// sleep on a futex until the last one arrives. On an idle machine nobody sleeps but a thread
/// waiting out a pair-list rebuild; on a busy one (more runnable threads than cores) a thread
/// whose partner has lost its core gives its own core back instead of spinning through its
/// time slice, which would stall every step for milliseconds.
pub struct SpinBarrier {
    threads: usize,
    waiting: AtomicUsize,
    /// Rounds completed; the futex the sleepers wait on.
    round: AtomicU32,
    /// Threads asleep, or about to sleep, on `round`.
    sleepers: AtomicU32,
}

impl SpinBarrier {
    pub fn new(threads: usize) -> Self {
        SpinBarrier {
            threads,
            waiting: AtomicUsize::new(0),
            round: AtomicU32::new(0),
            sleepers: AtomicU32::new(0),
        }
    }

    /// Blocks until all `threads` threads have called `wait` for this round.
    #[inline]
    pub fn wait(&self) {
        if self.threads == 1 {
            return;
        }
        // No thread can complete this round before this one arrives: `round` is current.
        let round = self.round.load(Ordering::Acquire);
        if self.waiting.fetch_add(1, Ordering::AcqRel) + 1 == self.threads {
            self.waiting.store(0, Ordering::Relaxed);
            // SeqCst with the load of `sleepers` below and the sleepers' increment before their
            // futex check: either the last thread sees a sleeper and wakes it, or the sleeper's
            // futex check sees the new round and returns at once.
            self.round.store(round.wrapping_add(1), Ordering::SeqCst);
            if self.sleepers.load(Ordering::SeqCst) > 0 {
                atomic_wait::wake_all(&self.round);
            }
            return;
        }
        let start = Instant::now();
        let mut spins = 0u32;
        while self.round.load(Ordering::Acquire) == round {
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(64) && start.elapsed() > SPIN {
                self.sleep(round);
                return;
            }
            std::hint::spin_loop();
        }
    }

    /// Sleeps until `round` has passed.
    #[cold]
    fn sleep(&self, round: u32) {
        while self.round.load(Ordering::Acquire) == round {
            self.sleepers.fetch_add(1, Ordering::SeqCst);
            atomic_wait::wait(&self.round, round);
            self.sleepers.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

/// A value shared by the team whose parts are written by one thread at a time, as arranged by
/// the step's phases and barriers (each thread writes only its own index range between two
/// barriers; reads of data written by others happen only after a barrier).
pub struct Shared<T>(UnsafeCell<T>);

// SAFETY: access is coordinated by the phase structure described above; the barrier's
// acquire/release orderings publish each phase's writes to the next phase.
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T> Shared<T> {
    pub fn new(value: T) -> Self {
        Shared(UnsafeCell::new(value))
    }

    /// Shared access.
    ///
    /// # Safety
    /// No thread may be writing the parts read, in the same phase.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn get(&self) -> &mut T {
        &mut *self.0.get()
    }
}

/// Splits `0..n` into one contiguous range per entry of `speeds`, the total `weight(k)` of each
/// range proportional to its speed (equal speeds: equal weights).
pub fn balanced_ranges(
    n: usize,
    speeds: &[f64],
    weight: impl Fn(usize) -> u64,
    out: &mut Vec<(usize, usize)>,
) {
    out.clear();
    let parts = speeds.len();
    let total: u64 = (0..n).map(&weight).sum();
    let all: f64 = speeds.iter().sum();
    let mut start = 0;
    let mut acc = 0u64;
    let mut k = 0;
    let mut cumulative = 0.0;
    for part in 0..parts {
        cumulative += speeds[part];
        let target = (total as f64 * cumulative / all) as u64;
        while k < n && (acc < target || part + 1 == parts) {
            acc += weight(k);
            k += 1;
        }
        out.push((start, k));
        start = k;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balanced_ranges_cover_everything_once() {
        let mut r = Vec::new();
        balanced_ranges(10, &[1.0; 3], |k| if k < 5 { 1 } else { 3 }, &mut r);
        assert_eq!(r.first().unwrap().0, 0);
        assert_eq!(r.last().unwrap().1, 10);
        assert!(r.windows(2).all(|w| w[0].1 == w[1].0));
        let w: Vec<u64> = r
            .iter()
            .map(|&(a, b)| (a..b).map(|k| if k < 5 { 1 } else { 3 }).sum())
            .collect();
        assert!(w.iter().all(|&x| (6..=9).contains(&x)), "{w:?}");
        // a part twice as fast gets about twice the weight
        balanced_ranges(100, &[2.0, 1.0], |_| 1, &mut r);
        assert!(
            matches!(r[0], (0, 66..=67)) && r[1].0 == r[0].1 && r[1].1 == 100,
            "{r:?}"
        );
    }

    /// Runs `threads` threads through `rounds` rounds of two phases; `late(tid, round)` makes a
    /// thread arrive later than the spin time. Each phase must see every thread's increment.
    fn run_phases(threads: usize, rounds: usize, late: impl Fn(usize, usize) -> bool + Sync) {
        let barrier = SpinBarrier::new(threads);
        let counter = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for tid in 0..threads {
                let (barrier, counter, late) = (&barrier, &counter, &late);
                s.spawn(move || {
                    for round in 0..rounds {
                        if late(tid, round) {
                            std::thread::sleep(4 * SPIN);
                        }
                        counter.fetch_add(1, Ordering::Relaxed);
                        barrier.wait();
                        assert_eq!(counter.load(Ordering::Relaxed), threads * (round + 1));
                        barrier.wait();
                    }
                });
            }
        });
        assert_eq!(
            barrier.sleepers.load(Ordering::Relaxed),
            0,
            "a thread left asleep"
        );
    }

    #[test]
    fn barrier_orders_phases_across_threads() {
        run_phases(2, 1000, |_, _| false);
    }

    #[test]
    fn barrier_orders_phases_when_threads_sleep() {
        // One thread in three is late every fourth round, so the others take the futex path.
        run_phases(3, 200, |tid, round| tid == round % 3 && round % 4 == 0);
    }
}
