//! Counters of the time step: wall-clock time per stage, measured on thread 0, and rebuilds.

use std::time::Instant;

/// Wall-clock time spent in each stage, in nanoseconds, measured on thread 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageTimes {
    /// Pair-list rebuilds (including the re-ordering of particles in memory).
    pub neighbor: u64,
    /// Pair forces.
    pub forces: u64,
    /// Gather of pair forces, kicks and drifts (per-particle pass).
    pub integrate: u64,
    /// Waiting for the other threads: at barriers, and for the pair chunks a gather needs.
    pub wait: u64,
    /// Number of pair-list rebuilds.
    pub rebuilds: u64,
}

impl StageTimes {
    /// Adds the times of `other` (not its rebuilds).
    pub fn add_times(&mut self, other: &StageTimes) {
        self.neighbor += other.neighbor;
        self.forces += other.forces;
        self.integrate += other.integrate;
        self.wait += other.wait;
    }

    /// Moves `waited` ns, spent inside the particle pass waiting for pair chunks, from
    /// `integrate` to `wait`.
    pub fn count_wait_in_integrate(&mut self, waited: u64) {
        let waited = waited.min(self.integrate);
        self.integrate -= waited;
        self.wait += waited;
    }
}

/// A stopwatch that charges the time since its last lap to a stage, on the timing thread only.
pub struct Laps {
    timing: bool,
    last: Instant,
}

impl Laps {
    /// A stopwatch started now; `timing` false makes every lap a no-op (threads other than 0).
    pub fn new(timing: bool) -> Self {
        Laps {
            timing,
            last: Instant::now(),
        }
    }

    /// Adds the nanoseconds since the last lap to `stage`.
    #[inline(always)]
    pub fn lap(&mut self, stage: &mut u64) {
        if self.timing {
            let now = Instant::now();
            *stage += (now - self.last).as_nanos() as u64;
            self.last = now;
        }
    }
}
