//! Timing comparisons on this machine: verdem and the installed peers run the same case from the
//! same state, alternating (A B A B …) so that drift of a shared machine cancels, with no file
//! output in the timed region. Each code's own loop time is used (verdem: `advance`; LAMMPS and
//! LIGGGHTS: their "Loop time"), so set-up and file reading are excluded for all.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;

use crate::case::Case;
use crate::engine::{self, Overrides};
use crate::peers::{self, Peer};
use crate::sim::StageTimes;

/// One configuration: a code and its number of threads or MPI ranks.
#[derive(Clone, Debug, PartialEq)]
pub enum Config {
    Verdem { threads: usize },
    Peer { peer: Peer, np: usize },
}

impl Config {
    pub fn label(&self) -> (String, usize) {
        match self {
            Config::Verdem { threads } => ("verdem (deterministic)".into(), *threads),
            Config::Peer { peer, np } => (format!("{peer:?}").to_lowercase(), *np),
        }
    }
}

/// Measured rates of one configuration over the rounds, and verdem's stage times.
#[derive(Clone, Debug)]
pub struct Measured {
    pub config: Config,
    pub rates: Vec<f64>,
    pub stages: Option<StageTimes>,
}

impl Measured {
    /// Median steps per second.
    pub fn median(&self) -> f64 {
        let mut r = self.rates.clone();
        r.sort_by(f64::total_cmp);
        let n = r.len();
        if n % 2 == 1 {
            r[n / 2]
        } else {
            0.5 * (r[n / 2 - 1] + r[n / 2])
        }
    }
}

/// Runs every configuration `rounds` times, alternating, `steps` steps each, from `state`.
pub fn run(
    case: &Case,
    state: &Path,
    steps: u64,
    configs: &[Config],
    rounds: usize,
    work: &Path,
) -> anyhow::Result<Vec<Measured>> {
    std::fs::create_dir_all(work).with_context(|| work.display().to_string())?;
    let data_path: PathBuf = work.join("state.lmp");
    {
        let e = engine::build(
            case,
            crate::scene::build(case, Some(state))?,
            &Overrides::default(),
        );
        crate::io::atomic::write(
            &data_path,
            peers::data_file(&e.core().snapshot(), case.material.density).as_bytes(),
        )?;
    }
    let mut out: Vec<Measured> = configs
        .iter()
        .map(|c| Measured {
            config: c.clone(),
            rates: Vec::new(),
            stages: None,
        })
        .collect();
    for _ in 0..rounds {
        for m in out.iter_mut() {
            match &m.config {
                Config::Verdem { threads } => {
                    let mut e = engine::build(
                        case,
                        crate::scene::build(case, Some(state))?,
                        &Overrides {
                            threads: Some(*threads),
                            ..Overrides::default()
                        },
                    );
                    e.advance(0);
                    e.core_mut().times = StageTimes::default();
                    let t0 = Instant::now();
                    // chunks as in a run (progress and saves happen between them)
                    let mut left = steps;
                    while left > 0 {
                        let k = left.min(2000);
                        e.advance(k);
                        left -= k;
                    }
                    m.rates.push(steps as f64 / t0.elapsed().as_secs_f64());
                    m.stages = Some(e.core().times);
                }
                Config::Peer { peer, np } => {
                    let dir = work.join(format!("{}-{np}", peer.binary()));
                    std::fs::create_dir_all(&dir)?;
                    let script = peers::input_script(
                        *peer,
                        case,
                        &data_path.canonicalize()?.display().to_string(),
                        steps,
                        None,
                    )?;
                    let seconds = peers::run(*peer, *np, &dir, &script)?;
                    m.rates.push(steps as f64 / seconds);
                }
            }
        }
    }
    Ok(out)
}

/// The table as markdown: code, processes/threads, steps/s (median and all rounds),
/// particle-steps/s, and verdem's best rate over the code's.
pub fn markdown(m: &[Measured], particles: usize) -> String {
    let best = m
        .iter()
        .filter(|x| matches!(x.config, Config::Verdem { .. }))
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
    for x in m {
        if let (Config::Verdem { threads }, Some(st)) = (&x.config, &x.stages) {
            let total = (st.neighbor + st.forces + st.integrate + st.wait).max(1) as f64;
            let pct = |v: u64| 100.0 * v as f64 / total;
            s.push_str(&format!(
                "\nverdem, {threads} thread(s), last round, thread 0: neighbour list {:.1} % ({} rebuilds), pair forces {:.1} %, gather + integration {:.1} %, barrier waits {:.1} %; output 0 % (none in the timed region)\n",
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

/// The table as CSV.
pub fn csv(m: &[Measured], particles: usize) -> String {
    let mut s = String::from("code,procs,median_steps_per_s,particle_steps_per_s,rounds\n");
    for x in m {
        let (code, n) = x.config.label();
        let rounds: Vec<String> = x.rates.iter().map(|r| format!("{r:.1}")).collect();
        s.push_str(&format!(
            "{code},{n},{:.1},{:.1},{}\n",
            x.median(),
            x.median() * particles as f64,
            rounds.join(" ")
        ));
    }
    s
}
