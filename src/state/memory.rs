//! What the sizes a user gives cost in memory, checked before anything of that size is
//! allocated: a count of spheres, tiles, slices or replicas, or the neighbour list a scene
//! implies. A size whose estimate exceeds the memory this machine has available is refused with
//! a message naming the estimate, instead of an abort or an exhausted machine.

use std::collections::HashMap;

use crate::Vec3;

/// Bytes a sphere costs in the solver: its arrays (position, velocity, spin, forces, torques,
/// mass, inertia, radius, motion, id), the cell lists and the saves' buffers, rounded up.
pub const BYTES_PER_SPHERE: f64 = 512.0;

/// Bytes a candidate pair of the neighbour list costs: its indices, its slot in each
/// particle's list, its force and history words, rounded up.
pub const BYTES_PER_PAIR: f64 = 128.0;

/// The environment variable that sets the memory budget in bytes (else the machine's
/// available memory, `MemAvailable` of `/proc/meminfo`).
pub const BUDGET_VAR: &str = "VERDEM_MEMORY_BUDGET";

/// A size whose memory estimate exceeds the budget.
#[derive(Debug, thiserror::Error)]
#[error(
    "{what}: needs an estimated {:.1} GiB of memory, more than the {:.1} GiB available \
     ({source_of}); nothing was allocated",
    bytes / GIB,
    *budget as f64 / GIB
)]
pub struct TooLarge {
    /// What was asked for (a field or option and its value).
    pub what: String,
    pub bytes: f64,
    pub budget: u64,
    /// Where the budget comes from.
    pub source_of: String,
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The memory budget (bytes) and where it comes from: [`BUDGET_VAR`] when set to a whole
/// number, else the available memory the kernel reports, else 8 GiB.
pub fn budget() -> (u64, String) {
    if let Some(b) = std::env::var(BUDGET_VAR)
        .ok()
        .and_then(|v| v.trim().parse().ok())
    {
        return (b, BUDGET_VAR.to_string());
    }
    let available = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|m| {
            m.lines()
                .find_map(|l| l.strip_prefix("MemAvailable:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        })
        .map(|kib| kib.saturating_mul(1024));
    match available {
        Some(b) => (b, "MemAvailable in /proc/meminfo".into()),
        None => (
            8 << 30,
            "a default of 8 GiB: /proc/meminfo not readable".into(),
        ),
    }
}

/// Refuses `bytes` (an estimate, any non-negative number, possibly huge or infinite) for
/// `what` when it exceeds the [`budget`].
pub fn check(what: &str, bytes: f64) -> Result<(), TooLarge> {
    let (budget, source_of) = budget();
    if bytes.is_nan() || bytes > budget as f64 {
        return Err(TooLarge {
            what: what.into(),
            bytes,
            budget,
            source_of,
        });
    }
    Ok(())
}

/// An upper bound of the pairs a neighbour list of spheres at `x` with radii `radius` and
/// skin `skin` (lengths) can hold: spheres binned into cubic cells of edge 2·r_max + skin,
/// every two spheres in the same or adjacent cells counted (periodic images are not, which the
/// bound's slack covers). Non-finite positions are left out (the guard refuses them).
pub fn candidate_pairs(x: &[Vec3], radius: &[f64], skin: f64) -> f64 {
    let r_max = radius.iter().cloned().fold(0.0, f64::max);
    let cell = 2.0 * r_max + skin;
    if !(cell > 0.0 && cell.is_finite()) {
        return 0.5 * x.len() as f64 * x.len() as f64;
    }
    let mut count: HashMap<[i64; 3], f64> = HashMap::new();
    for p in x.iter().filter(|p| (p.x + p.y + p.z).is_finite()) {
        let key = [0, 1, 2].map(|k| (p[k] / cell).floor() as i64);
        *count.entry(key).or_insert(0.0) += 1.0;
    }
    let mut pairs = 0.0;
    for (c, &n) in &count {
        pairs += 0.5 * n * (n - 1.0);
        for d in HALF_STENCIL {
            let other = [
                c[0].saturating_add(d[0]),
                c[1].saturating_add(d[1]),
                c[2].saturating_add(d[2]),
            ];
            if let Some(&m) = count.get(&other) {
                pairs += n * m;
            }
        }
    }
    pairs
}

/// Thirteen of the 26 neighbours of a cell, one of each opposite pair.
const HALF_STENCIL: [[i64; 3]; 13] = [
    [1, 0, 0],
    [-1, 1, 0],
    [0, 1, 0],
    [1, 1, 0],
    [-1, -1, 1],
    [0, -1, 1],
    [1, -1, 1],
    [-1, 0, 1],
    [0, 0, 1],
    [1, 0, 1],
    [-1, 1, 1],
    [0, 1, 1],
    [1, 1, 1],
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bound_counts_every_pair_of_one_cell_and_of_adjacent_cells() {
        let x = vec![Vec3::new(0.1, 0.1, 0.1); 4];
        assert_eq!(candidate_pairs(&x, &[0.5; 4], 0.1), 6.0);
        let mut y = x.clone();
        y.push(Vec3::new(1.2, 0.1, 0.1));
        y.push(Vec3::new(-0.3, -0.3, -0.3));
        y.push(Vec3::new(50.0, 0.0, 0.0));
        // 6 in the cell, 4 with the cell above in x, 4 with the one below, the far one alone
        assert_eq!(candidate_pairs(&y, &[0.5; 7], 0.1), 14.0);
    }

    #[test]
    fn the_bound_is_at_least_the_true_number_of_pairs_in_reach() {
        let mut x = Vec::new();
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 6.0
        };
        for _ in 0..400 {
            x.push(Vec3::new(next(), next(), next()));
        }
        let (r, skin) = (0.3, 0.05);
        let mut within = 0.0;
        for a in 0..x.len() {
            for b in a + 1..x.len() {
                if (x[a] - x[b]).norm() < 2.0 * r + skin {
                    within += 1.0;
                }
            }
        }
        let bound = candidate_pairs(&x, &vec![r; x.len()], skin);
        assert!(bound >= within && bound < 20.0 * within, "{bound} {within}");
    }

    #[test]
    fn an_estimate_beyond_the_budget_is_refused_naming_it() {
        let e = check("tile: 100000 x 100000", f64::INFINITY).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("tile: 100000 x 100000: needs an estimated"),
            "{e}"
        );
        assert!(check("one sphere", BYTES_PER_SPHERE).is_ok());
    }
}
