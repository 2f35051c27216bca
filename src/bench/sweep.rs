//! The size sweep: the configurations timed at several system sizes (the case tiled), round by
//! round, and the CSV table of the measurements, one record per size and configuration.

use anyhow::Context;

use super::rounds::{fastest, paired_ratios, peer_states, round, unmeasured, verdem_row};
use super::rounds::{Config, Measured};
use crate::analysis::stats::median;
use crate::case::Case;

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
        Config::Peer { peer, np } => Some(if peer.launch(*np).by_mpirun() { *np } else { 1 }),
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

/// Cost per particle-step (ns) at the rate `steps_per_s` with `particles` particles.
pub(super) fn ns_per_particle_step(steps_per_s: f64, particles: usize) -> f64 {
    1e9 / (steps_per_s * particles as f64)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::fixtures::{measured, two_sizes};

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
    fn steps_per_size_keep_the_particle_steps() {
        assert_eq!(steps_for(69_600_000, 3480), 20_000);
        assert_eq!(steps_for(69_600_000, 222_720), 313);
        assert_eq!(steps_for(10, 3480), 1);
    }
}
