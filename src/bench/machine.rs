//! What a bench ran on and what it took: the CPU's model, the header of `bench.md`, and the peak
//! resident memory of this process and of its children.

use std::path::Path;

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
