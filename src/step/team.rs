//! A persistent team of threads for the time step: every thread runs the same step loop on its
//! own share of the work (SPMD) and they meet at barriers between phases. A step of this small
//! system takes tens of microseconds, so a fork–join per phase (rayon) would cost a large
//! fraction of it; a spinning barrier costs well under a microsecond.

use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long a thread spins at a barrier before it starts yielding its core: longer than most
/// waits of a step on an idle machine (10 µs was not: a yield or a wake costs more than the
/// wait), far shorter than a scheduler time slice.
const SPIN: Duration = Duration::from_micros(50);

/// How long a thread yields its core, after spinning, before it sleeps. A sleeping thread on a
/// virtual machine halts its virtual CPU, and waking it costs tens to hundreds of microseconds,
/// after which the partner that woke it often waits past its own spin: one late arrival
/// cascades. Yielding keeps the CPU awake through the waits a step has (the longest is a
/// pair-list rebuild's serial phase, well under a millisecond) while still giving the core to
/// any other runnable thread (measured: `docs/performance.md`).
const YIELD: Duration = Duration::from_millis(2);

/// A reusable barrier for a fixed number of threads. Threads spin for up to [`SPIN`], then
/// yield their core for up to [`YIELD`], then sleep on a futex until the last one arrives. On an
/// idle machine nobody sleeps; on a busy one (more runnable threads than cores) a thread whose
/// partner has lost its core gives its own core back instead of spinning through its time
/// slice, which would stall every step for milliseconds, and sleeps when the partner stays away.
pub struct SpinBarrier {
    threads: usize,
    waiting: AtomicUsize,
    /// Rounds completed; the futex the sleepers wait on.
    round: AtomicU32,
    /// Threads asleep, or about to sleep, on `round`.
    sleepers: AtomicU32,
}

impl SpinBarrier {
    /// A barrier for `threads` threads (a barrier of one never waits).
    pub fn new(threads: usize) -> Self {
        SpinBarrier {
            threads,
            waiting: AtomicUsize::new(0),
            round: AtomicU32::new(0),
            sleepers: AtomicU32::new(0),
        }
    }

    /// Rounds completed so far (wrapping at 2³²); always 0 for a barrier of one thread.
    pub fn rounds(&self) -> u32 {
        self.round.load(Ordering::Acquire)
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
            if spins.is_multiple_of(64) {
                let waited = start.elapsed();
                if waited > SPIN + YIELD {
                    self.sleep(round);
                    return;
                }
                if waited > SPIN {
                    std::thread::yield_now();
                    continue;
                }
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

/// The chunks of one pass, handed out so that no thread waits for another at the pass's end
/// while work is left: thread `t` has home chunks (an equal share, in order), takes them from
/// one end and, once they are done, takes the remaining chunks of the others from the other
/// end. Even threads walk their home chunks forward and odd ones backward, so that thread 0 and
/// thread 1 meet where their homes meet and a thief takes the chunk nearest its own (the chunks
/// of a pass are in memory, so space, order). Which thread runs a chunk never changes a result:
/// every chunk writes only its own outputs.
pub struct WorkQueue {
    /// Remaining home chunks of each thread, `lo | hi << 32`.
    left: Vec<Padded>,
    chunks: usize,
}

/// An atomic on a cache line of its own: the threads' counters never share one.
#[repr(align(128))]
struct Padded(AtomicU64);

/// Whether thread `tid` walks its home chunks forward (even threads) or backward.
fn forward(tid: usize) -> bool {
    tid.is_multiple_of(2)
}

fn pack(lo: usize, hi: usize) -> u64 {
    lo as u64 | (hi as u64) << 32
}

impl WorkQueue {
    /// A queue of `chunks` chunks for `threads` threads, every home full.
    pub fn new(threads: usize, chunks: usize) -> Self {
        let q = WorkQueue {
            left: (0..threads).map(|_| Padded(AtomicU64::new(0))).collect(),
            chunks,
        };
        for tid in 0..threads {
            q.refill(tid);
        }
        q
    }

    /// Home chunks of thread `tid`.
    fn home(&self, tid: usize) -> (usize, usize) {
        let threads = self.left.len();
        (
            self.chunks * tid / threads,
            self.chunks * (tid + 1) / threads,
        )
    }

    /// Restores thread `tid`'s home for the next pass. Only its owner calls this, once every
    /// thread is done taking chunks of the queue's last pass (after a barrier that follows that
    /// pass) and before its own next pass. A thread that looks at this home before it is
    /// refilled finds it empty and leaves its chunks to the owner; a home that is not empty
    /// (a queue that has not run a pass yet) must not be refilled.
    pub fn refill(&self, tid: usize) {
        let (lo, hi) = self.home(tid);
        self.left[tid].0.store(pack(lo, hi), Ordering::Relaxed);
    }

    /// The next chunk for thread `tid`: its own first, then the others', nearest home first;
    /// `None` when every chunk of the pass is taken.
    #[inline]
    pub fn next(&self, tid: usize) -> Option<usize> {
        let threads = self.left.len();
        let own = self.take(tid, forward(tid));
        own.or_else(|| {
            (1..threads)
                .flat_map(|d| [tid + d, tid + threads - d])
                .map(|v| v % threads)
                .find_map(|v| self.take(v, !forward(v)))
        })
    }

    /// Takes the first (`front`) or the last remaining home chunk of thread `v`.
    fn take(&self, v: usize, front: bool) -> Option<usize> {
        let slot = &self.left[v].0;
        let mut cur = slot.load(Ordering::Relaxed);
        loop {
            let (lo, hi) = ((cur & 0xffff_ffff) as usize, (cur >> 32) as usize);
            if lo >= hi {
                return None;
            }
            let (next, chunk) = if front {
                (pack(lo + 1, hi), lo)
            } else {
                (pack(lo, hi - 1), hi - 1)
            };
            // Relaxed: the chunk's inputs and outputs are published by the barriers around the
            // pass or by the chunks' marks; this only decides who runs it, and every update of
            // `slot` is one atomic step.
            match slot.compare_exchange_weak(cur, next, Ordering::Relaxed, Ordering::Relaxed) {
                Ok(_) => return Some(chunk),
                Err(seen) => cur = seen,
            }
        }
    }
}

/// Completion marks of the chunks of a pass: a thread marks each chunk it finishes with the
/// round (step) it finished it for, and a thread that needs a chunk's outputs waits for its mark
/// instead of for the whole team at a barrier.
pub struct Marks {
    marks: Vec<Padded>,
}

impl Marks {
    /// `chunks` marks, all at round 0.
    pub fn new(chunks: usize) -> Self {
        Marks {
            marks: (0..chunks).map(|_| Padded(AtomicU64::new(0))).collect(),
        }
    }

    /// Marks chunk `chunk` done for `round`; its outputs are published to [`Marks::wait`].
    #[inline]
    pub fn set(&self, chunk: usize, round: u64) {
        self.marks[chunk].0.store(round, Ordering::Release);
    }

    /// Returns once every chunk of `chunks` is marked done for `round` or a later one, with the
    /// time it waited (zero, unmeasured, when nothing was left to wait for). Spins for up to
    /// [`SPIN`], then yields its core between checks (a mark has no sleepers to wake: its chunk
    /// is run by a thread that is not waiting on marks).
    #[inline]
    pub fn wait(&self, chunks: std::ops::Range<usize>, round: u64) -> Duration {
        let done = |c: usize| self.marks[c].0.load(Ordering::Acquire) >= round;
        if chunks.clone().all(done) {
            return Duration::ZERO;
        }
        let start = Instant::now();
        let mut spins = 0u32;
        while !chunks.clone().all(done) {
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(64) && start.elapsed() > SPIN {
                std::thread::yield_now();
            } else {
                std::hint::spin_loop();
            }
        }
        start.elapsed()
    }
}

/// The CPUs the calling thread may run on, in increasing order (empty if the kernel does not
/// say).
pub fn allowed_cpus() -> Vec<usize> {
    affinity().map_or_else(Vec::new, |set| cpus_of(&set).collect())
}

/// Binds the calling thread to one CPU while it lives, then gives it back the CPUs it had. A
/// team left to the scheduler loses time when a thread is moved, or starts on its partner's
/// CPU (each run spawns its threads anew); binding saves both (measured:
/// `docs/performance.md`). Open MPI's `mpirun` binds ranks to cores the same way when it starts
/// two or fewer.
pub struct Bound {
    previous: libc::cpu_set_t,
}

/// The calling thread's affinity mask, if the kernel gives it.
fn affinity() -> Option<libc::cpu_set_t> {
    // SAFETY: a zeroed cpu_set_t is an empty set; the call writes at most its size.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        let size = std::mem::size_of::<libc::cpu_set_t>();
        (libc::sched_getaffinity(0, size, &mut set) == 0).then_some(set)
    }
}

/// The CPUs of `set`, in increasing order.
fn cpus_of(set: &libc::cpu_set_t) -> impl Iterator<Item = usize> + '_ {
    // SAFETY: CPU_ISSET reads the set within CPU_SETSIZE.
    (0..libc::CPU_SETSIZE as usize).filter(move |&c| unsafe { libc::CPU_ISSET(c, set) })
}

impl Bound {
    /// Binds the calling thread to the `n`-th CPU (from 0) of its current affinity mask when
    /// `threads` threads fit on distinct CPUs of that mask; `None` (and nothing changed)
    /// otherwise.
    pub fn to_nth_cpu(n: usize, threads: usize) -> Option<Bound> {
        let previous = affinity()?;
        if cpus_of(&previous).count() < threads {
            return None;
        }
        let cpu = cpus_of(&previous).nth(n)?;
        // SAFETY: a zeroed cpu_set_t is an empty set; the call reads `size` bytes of it.
        unsafe {
            let mut one: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_SET(cpu, &mut one);
            let size = std::mem::size_of::<libc::cpu_set_t>();
            (libc::sched_setaffinity(0, size, &one) == 0).then_some(Bound { previous })
        }
    }
}

impl Drop for Bound {
    fn drop(&mut self) {
        let size = std::mem::size_of::<libc::cpu_set_t>();
        // SAFETY: restores the mask read in `to_nth_cpu`.
        unsafe { libc::sched_setaffinity(0, size, &self.previous) };
    }
}

/// The warning for a team of `threads` threads when the process may run on fewer CPUs
/// (affinity mask or CPU quota, as `std::thread::available_parallelism` reads them), else
/// `None`. Such a team waits at every barrier for threads that are not running (measured:
/// `docs/performance.md`).
pub fn oversubscribed(threads: usize) -> Option<String> {
    let cpus = std::thread::available_parallelism().ok()?.get();
    (threads > cpus).then(|| {
        format!(
            "{threads} threads, but this process may run on {cpus} CPU(s) (affinity mask or CPU \
             quota): every step waits for threads that are not running, and 2 threads on 1 CPU \
             ran about 4× slower than 1 thread; --threads {cpus} gives the same bits"
        )
    })
}

/// Who runs a phased job such as a pair-list rebuild: the team, each thread between the same
/// barriers, or one thread alone (outside a run), which then does every chunk of each parallel
/// phase itself.
#[derive(Clone, Copy)]
pub enum Crew<'b> {
    Solo,
    Member {
        tid: usize,
        barrier: &'b SpinBarrier,
        /// The chunks of the parallel phases.
        queue: &'b WorkQueue,
    },
}

impl Crew<'_> {
    /// Whether this thread does the serial phases.
    pub fn leads(self) -> bool {
        matches!(self, Crew::Solo | Crew::Member { tid: 0, .. })
    }

    /// Waits for the whole crew.
    pub fn sync(self) {
        if let Crew::Member { barrier, .. } = self {
            barrier.wait();
        }
    }

    /// A parallel phase: runs `job` on each of the `chunks` chunks this thread takes (all of
    /// them, alone), then waits for the whole crew.
    pub fn share(self, chunks: usize, mut job: impl FnMut(usize)) {
        match self {
            Crew::Solo => (0..chunks).for_each(job),
            Crew::Member {
                tid,
                barrier,
                queue,
            } => {
                while let Some(c) = queue.next(tid) {
                    job(c);
                }
                barrier.wait();
                // The next parallel phase starts after a serial one and its barrier.
                queue.refill(tid);
            }
        }
    }
}

/// A value the team's threads take turns on: in a serial phase one thread has it exclusively
/// while the others wait at a barrier; in a parallel phase every thread may read it (and writes
/// only through [`SharedSlice`]s to its own chunks' elements).
pub struct Shared<T>(UnsafeCell<T>);

// SAFETY: access follows the phase rules of `read` and `exclusive`; the acquire/release orderings
// of the barrier and of the marks publish each phase's writes to the next phase.
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T> Shared<T> {
    /// Shares `value` among a team's threads.
    pub fn new(value: T) -> Self {
        Shared(UnsafeCell::new(value))
    }

    /// Read access during a parallel phase.
    ///
    /// # Safety
    /// No thread holds the value from [`Shared::exclusive`] while the reference lives.
    #[inline(always)]
    pub unsafe fn read(&self) -> &T {
        &*self.0.get()
    }

    /// Exclusive access during a serial phase.
    ///
    /// # Safety
    /// No other reference to the value, from `read` or `exclusive`, lives while this one does:
    /// the other threads wait at a barrier and take fresh references after it.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn exclusive(&self) -> &mut T {
        &mut *self.0.get()
    }
}

/// A raw view of an array that the team's threads read and write element-wise during a phase,
/// each writing only the elements of the chunks it takes. Taken from the array by the thread that
/// owns it exclusively, between barriers; valid until the array is next resized, re-allocated or
/// swapped (the next pair-list rebuild), after which a fresh view must be taken.
pub struct SharedSlice<T> {
    ptr: *mut T,
    len: usize,
}

impl<T> Clone for SharedSlice<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for SharedSlice<T> {}

impl<T> Default for SharedSlice<T> {
    fn default() -> Self {
        SharedSlice {
            ptr: std::ptr::NonNull::dangling().as_ptr(),
            len: 0,
        }
    }
}

// SAFETY: a view is only a pointer and a length; every access through it is an `unsafe` call
// whose caller states which thread owns the elements it touches in that phase.
unsafe impl<T: Send> Send for SharedSlice<T> {}
unsafe impl<T: Send> Sync for SharedSlice<T> {}

impl<T> SharedSlice<T> {
    /// A view of `v`'s elements (no reference to them is kept).
    pub fn of(v: &mut [T]) -> Self {
        SharedSlice {
            ptr: v.as_mut_ptr(),
            len: v.len(),
        }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the view has no elements.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Element `k`, copied out.
    ///
    /// # Safety
    /// `k < len`; the view is valid; no thread writes element `k` during the read.
    #[inline(always)]
    pub unsafe fn get(&self, k: usize) -> T
    where
        T: Copy,
    {
        debug_assert!(k < self.len);
        self.ptr.add(k).read()
    }

    /// The elements `range`, read-only.
    ///
    /// # Safety
    /// `range` lies within the view; the view is valid; no thread writes these elements while
    /// the slice lives.
    #[inline(always)]
    pub unsafe fn slice(&self, range: std::ops::Range<usize>) -> &[T] {
        debug_assert!(range.start <= range.end && range.end <= self.len);
        std::slice::from_raw_parts(self.ptr.add(range.start), range.end - range.start)
    }

    /// The elements `range`, writable.
    ///
    /// # Safety
    /// `range` lies within the view; the view is valid; no other thread reads or writes these
    /// elements, and no other reference to them lives, while the slice lives.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn slice_mut(&self, range: std::ops::Range<usize>) -> &mut [T] {
        debug_assert!(range.start <= range.end && range.end <= self.len);
        std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.end - range.start)
    }

    /// Element `k`, writable.
    ///
    /// # Safety
    /// As [`SharedSlice::slice_mut`] for the one element `k`.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn at_mut(&self, k: usize) -> &mut T {
        debug_assert!(k < self.len);
        &mut *self.ptr.add(k)
    }
}

/// Splits `0..n` into `parts` contiguous ranges of nearly equal total `weight(k)`.
pub fn balanced_ranges(
    n: usize,
    parts: usize,
    weight: impl Fn(usize) -> u64,
    out: &mut Vec<(usize, usize)>,
) {
    out.clear();
    let total: u64 = (0..n).map(&weight).sum();
    let mut start = 0;
    let mut acc = 0u64;
    let mut k = 0;
    for part in 0..parts {
        let target = total * (part as u64 + 1) / parts as u64;
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
        balanced_ranges(10, 3, |k| if k < 5 { 1 } else { 3 }, &mut r);
        assert_eq!(r.first().unwrap().0, 0);
        assert_eq!(r.last().unwrap().1, 10);
        assert!(r.windows(2).all(|w| w[0].1 == w[1].0));
        let w: Vec<u64> = r
            .iter()
            .map(|&(a, b)| (a..b).map(|k| if k < 5 { 1 } else { 3 }).sum())
            .collect();
        assert!(w.iter().all(|&x| (6..=9).contains(&x)), "{w:?}");
        balanced_ranges(100, 4, |_| 1, &mut r);
        assert_eq!(r, [(0, 25), (25, 50), (50, 75), (75, 100)]);
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
                            std::thread::sleep(2 * (SPIN + YIELD));
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
    fn a_lone_thread_takes_its_chunks_in_order_and_then_the_others_nearest_first() {
        let q = WorkQueue::new(2, 8);
        let taken: Vec<usize> = std::iter::from_fn(|| q.next(0)).collect();
        // home 0..4 forward, then thread 1's home (walked backward by its owner) from its front
        assert_eq!(taken, [0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(q.next(1), None);
        q.refill(1);
        let taken: Vec<usize> = std::iter::from_fn(|| q.next(1)).collect();
        assert_eq!(taken, [7, 6, 5, 4]);
    }

    #[test]
    fn racing_threads_take_every_chunk_exactly_once() {
        for threads in [2, 3] {
            let chunks = 1000;
            let q = WorkQueue::new(threads, chunks);
            let barrier = SpinBarrier::new(threads);
            let count: Vec<AtomicUsize> = (0..chunks).map(|_| AtomicUsize::new(0)).collect();
            let rounds = 20;
            std::thread::scope(|s| {
                for tid in 0..threads {
                    let (q, barrier, count) = (&q, &barrier, &count);
                    s.spawn(move || {
                        for _ in 0..rounds {
                            while let Some(c) = q.next(tid) {
                                count[c].fetch_add(1, Ordering::Relaxed);
                            }
                            barrier.wait();
                            q.refill(tid);
                            barrier.wait();
                        }
                    });
                }
            });
            assert!(count.iter().all(|c| c.load(Ordering::Relaxed) == rounds));
        }
    }

    #[test]
    fn a_bound_thread_runs_on_its_cpu_and_gets_its_cpus_back() {
        std::thread::spawn(|| {
            let before = allowed_cpus();
            assert!(!before.is_empty(), "sched_getaffinity");
            let n = before.len() - 1;
            {
                let _bound = Bound::to_nth_cpu(n, before.len()).expect("binding failed");
                assert_eq!(allowed_cpus(), [before[n]]);
            }
            assert_eq!(allowed_cpus(), before);
            // more threads than CPUs: left alone
            assert!(Bound::to_nth_cpu(0, before.len() + 1).is_none());
            assert_eq!(allowed_cpus(), before);
        })
        .join()
        .unwrap();
    }

    #[test]
    fn a_wait_on_marks_returns_once_every_chunk_is_marked_and_sees_its_writes() {
        let marks = Marks::new(4);
        marks.set(1, 7);
        assert_eq!(marks.wait(1..2, 7), Duration::ZERO, "already marked");
        assert_eq!(marks.wait(0..0, 9), Duration::ZERO, "nothing to wait for");
        let written = AtomicUsize::new(0);
        std::thread::scope(|s| {
            s.spawn(|| {
                for c in [0, 2, 1] {
                    std::thread::sleep(Duration::from_millis(20));
                    written.fetch_add(1, Ordering::Relaxed);
                    marks.set(c, 8);
                }
            });
            let waited = marks.wait(0..3, 8);
            assert_eq!(
                written.load(Ordering::Relaxed),
                3,
                "returned before the last mark"
            );
            assert!(waited >= Duration::from_millis(50), "{waited:?}");
        });
        // a chunk marked for a later round is done for an earlier one
        assert_eq!(marks.wait(0..3, 5), Duration::ZERO);
    }

    #[test]
    fn only_a_team_larger_than_the_cpus_is_oversubscribed() {
        let cpus = std::thread::available_parallelism().unwrap().get();
        assert_eq!(oversubscribed(1), None);
        assert_eq!(oversubscribed(cpus), None);
        let warning = oversubscribed(cpus + 1).expect("one thread too many");
        assert!(
            warning.contains(&format!("run on {cpus} CPU(s)")),
            "{warning}"
        );
    }

    #[test]
    fn barrier_orders_phases_across_threads() {
        run_phases(2, 1000, |_, _| false);
    }

    #[test]
    fn barrier_orders_phases_when_threads_sleep() {
        // One thread in three is late every fourth round, so the others yield and then take the
        // futex path.
        run_phases(3, 200, |tid, round| tid == round % 3 && round % 4 == 0);
    }
}
