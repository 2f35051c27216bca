//! Measurements of made-up rounds for the bench's unit tests.

use super::rounds::{Config, Measured};
use super::sweep::AtSize;

/// verdem's measurement on `threads` threads in `copies` copies (not in lockstep) with `rates`.
pub(super) fn measured(threads: usize, copies: usize, rates: &[f64]) -> Measured {
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
pub(super) fn two_sizes() -> Vec<AtSize> {
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
