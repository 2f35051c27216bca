//! `verdem bench`: time verdem against the installed peers on the same case and state, and
//! write the table; with `--scale`, the same at several system sizes (the case tiled n × n).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};
use verdem::bench::{self, AtSize, Config, Size};
use verdem::case::Case;
use verdem::child::{self, OnParentDeath};
use verdem::contact::named;
use verdem::io::atomic;
use verdem::peers::Peer;
use verdem::scene;

use super::args::count;
use super::Finished;

/// The state a single-size bench starts from: MercuryDPM's developing state.
const DEVELOPING: &str = "data/states/mercury_t143.85.data";

/// The state a sweep tiles: verdem's full run's final state, so that every code starts steady.
const STEADY: &str = "golden/full_run/shear_flow.final.data";

#[derive(clap::Args)]
pub struct Args {
    /// Case file (default: cases/shear_flow_quick.toml).
    case: Option<PathBuf>,
    /// State to start from (default: MercuryDPM's developed state data/states/mercury_t143.85.data;
    /// with --scale, the one tiled: the full run's final state golden/full_run/shear_flow.final.data).
    #[arg(long)]
    from: Option<PathBuf>,
    #[arg(long, default_value_t = 20_000, value_parser = count::<u64>)]
    steps: u64,
    /// Sweep system sizes: the case and its state tiled n × n in x–y for each n listed
    /// (1,2,4,8: 3480 to 222720 spheres of the benchmark), each timed with every configuration.
    #[arg(long, value_delimiter = ',', value_parser = count::<usize>, conflicts_with = "steps")]
    scale: Vec<usize>,
    /// With --scale: particle-steps of each run (steps at a size = this / its particles, so
    /// that every run takes about the same time).
    #[arg(long, default_value_t = 69_600_000, value_parser = count::<u64>)]
    particle_steps: u64,
    /// verdem thread counts.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = count::<usize>)]
    threads: Vec<usize>,
    #[arg(long, help = peers_help())]
    peers: Option<String>,
    /// MPI ranks (Yade: OpenMP threads) for the peers.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = count::<usize>)]
    np: Vec<usize>,
    /// Alternating rounds.
    #[arg(long, default_value_t = 3, value_parser = count::<usize>)]
    rounds: usize,
    /// Skip the ceiling rows: two independent 1-thread verdem runs at once, which measures
    /// what this machine gives two jobs that share nothing, and the same two runs waiting
    /// for each other once a step, which measures what it gives two that meet once a step
    /// as a team's threads do.
    #[arg(long)]
    no_ceiling: bool,
    /// Where the table (bench.md, bench.csv; with --scale also bench.png) and the peers' inputs
    /// go.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
    /// Draw a sweep's cost plot again from its `bench.csv` (a recorded sweep's, say), into the
    /// PNG of the same name beside it, and time nothing.
    #[arg(long, value_name = "BENCH_CSV", conflicts_with_all = ["scale", "probe", "junit", "json"])]
    plot: Option<PathBuf>,
    /// Run one configuration (`verdem:THREADS` or `PEER:NP`) once and print its peak resident
    /// memory: the child process a sweep measures memory with.
    #[arg(long, hide = true)]
    probe: Option<String>,
    /// Also write the goals the tables judge as a JUnit XML report to this file: one test case
    /// per goal, its goal, median and interval in the message; a goal not met is a failure, an
    /// undecided one is skipped with the reason (the exit status stays 0).
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also write the goals as a JSON table to this file (docs/cli.md, "Reports for CI").
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// The names of the known peers that `pick` selects, in the registry's order, joined by `sep`.
fn names(pick: impl Fn(&dyn Peer) -> bool, sep: &str) -> String {
    let picked: Vec<&str> = verdem::peers::all()
        .iter()
        .filter(|p| pick(**p))
        .map(|p| p.name())
        .collect();
    picked.join(sep)
}

/// `names` as a sentence lists them: `a`, `a and b`, `a, b and c`.
fn and_list(names: &str) -> String {
    match names.rsplit_once(", ") {
        Some((head, last)) => format!("{head} and {last}"),
        None => names.to_string(),
    }
}

/// The help of `--peers`: which peers the defaults leave out, from what each declares
/// ([`Peer::timed_by_default`], [`Peer::swept_by_default`]).
fn peers_help() -> String {
    let slow = names(|p| !p.timed_by_default(), ", ");
    let timed = match (slow.is_empty(), slow.contains(", ")) {
        (true, _) => "The default times every peer".to_string(),
        (false, many) => format!(
            "The default leaves out {}, too slow for its rounds: name {}, with fewer --steps",
            and_list(&slow),
            if many { "them" } else { "it" }
        ),
    };
    let unswept = names(|p| !p.swept_by_default(), ", ");
    let named = if unswept.is_empty() {
        String::new()
    } else {
        format!(" (name {} to sweep them too)", and_list(&unswept))
    };
    format!(
        "Peers to run, comma-separated (`verdem peers` lists them; none: --peers ''). {timed}; \
         with --scale it is {}{named}",
        names(|p| p.swept_by_default(), ",")
    )
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    if let Some(csv) = &a.plot {
        let png = csv.with_extension("png");
        bench::draw_cost(&bench::cost_lines(csv)?, &png)?;
        println!("plot: {}", png.display());
        return Ok(Finished::Done);
    }
    let case_path = a
        .case
        .clone()
        .unwrap_or_else(|| PathBuf::from("cases/shear_flow_quick.toml"));
    let case = named::load(&case_path)?;
    if let Some(probe) = &a.probe {
        let from = a.from.clone().unwrap_or_else(|| DEVELOPING.into());
        return run_probe(&case, &from, a.steps, probe, &a.out);
    }
    for warning in a
        .threads
        .iter()
        .filter_map(|&t| verdem::step::team::oversubscribed(t))
    {
        eprintln!("warning: {warning}");
    }
    let mut configs: Vec<Config> = a
        .threads
        .iter()
        .map(|&t| Config::Verdem {
            threads: t,
            copies: 1,
            lockstep: false,
        })
        .collect();
    if !a.no_ceiling {
        configs.extend([false, true].map(|lockstep| Config::Verdem {
            threads: 1,
            copies: 2,
            lockstep,
        }));
    }
    let peers = a.peers.clone().unwrap_or_else(|| {
        if a.scale.is_empty() {
            verdem::peers::bench_names()
        } else {
            names(|p| p.swept_by_default(), ",")
        }
    });
    for peer in verdem::peers::parse_list(&peers).context("--peers")? {
        configs.extend(a.np.iter().map(|&n| Config::Peer { peer, np: n }));
    }
    if !a.scale.is_empty() {
        return sweep(&a, &case_path, &configs);
    }
    let from = a.from.clone().unwrap_or_else(|| DEVELOPING.into());
    let measured = bench::run(&case, &from, a.steps, &configs, a.rounds, &a.out)?;
    let particles = scene::build(&case, Some(&from))?.particles.len();
    let md = bench::header(&case.name, &from, a.steps, a.rounds)
        + &bench::markdown(&measured, particles);
    print!("{md}");
    atomic::write(&a.out.join("bench.md"), md.as_bytes())?;
    let goals = bench::goals(&measured, particles);
    let at = AtSize::without_memory(particles, a.steps, measured);
    atomic::write(&a.out.join("bench.csv"), bench::csv(&[at]).as_bytes())?;
    write_goals(&a, &goals)?;
    Ok(Finished::Done)
}

/// `--scale`: tiles the case for each size into OUT/NxN, times every configuration at every
/// size, measures each code's peak memory in a child process, and writes the tables and the
/// plot.
fn sweep(a: &Args, case_path: &Path, configs: &[Config]) -> anyhow::Result<Finished> {
    let from = a.from.clone().unwrap_or_else(|| STEADY.into());
    let mut sizes = Vec::new();
    for &n in &a.scale {
        let work = a.out.join(format!("{n}x{n}"));
        let (case_file, state) = verdem::scene::tile::write(case_path, &from, n, n, &work)?;
        let case = named::load(&case_file)?;
        let particles = scene::build(&case, Some(&state))?.particles.len();
        sizes.push(Size {
            case,
            state,
            particles,
            steps: bench::steps_for(a.particle_steps, particles),
            work,
        });
    }
    let mut measured = bench::sweep(&sizes, configs, a.rounds)?;
    for (z, at) in sizes.iter().zip(measured.iter_mut()) {
        for (k, c) in configs.iter().enumerate() {
            if let Some(procs) = bench::processes(c) {
                at.peak_rss[k] = Some(procs as f64 * probe_memory(z, c)?);
            }
        }
    }
    let md = sweep_header(a, case_path, &from, &sizes) + &bench::sweep_markdown(&measured);
    print!("{md}");
    atomic::write(&a.out.join("bench.md"), md.as_bytes())?;
    atomic::write(&a.out.join("bench.csv"), bench::csv(&measured).as_bytes())?;
    bench::cost_png(&measured, &a.out.join("bench.png"))?;
    write_goals(a, &bench::sweep_goals(&measured))?;
    Ok(Finished::Done)
}

/// Writes the goals `goals` to the reports `--junit` and `--json` ask for ([`bench::report`]).
fn write_goals(a: &Args, goals: &[bench::Goal]) -> anyhow::Result<()> {
    if a.junit.is_some() || a.json.is_some() {
        bench::report("verdem bench", goals).write(a.junit.as_deref(), a.json.as_deref())?;
    }
    Ok(())
}

/// What a sweep timed, how, and on what.
fn sweep_header(a: &Args, case_path: &Path, from: &Path, sizes: &[Size]) -> String {
    let list: Vec<String> = a
        .scale
        .iter()
        .zip(sizes)
        .map(|(n, z)| format!("{n}×{n}: {} particles, {} steps", z.particles, z.steps))
        .collect();
    format!(
        "{} tiled n × n in x–y from {} ({}); each run about {} particle-steps; {} alternating rounds (each round every size in turn, each size every configuration in turn); {} cores ({}); no file output in the timed region.\n\
Peak resident memory: one more run of each configuration at each size ({} steps at most) in a child process, its peak resident set (verdem: the child's own, VmHWM, state reading and scene included; a peer: the largest of mpirun and its ranks from getrusage, times the ranks, as the kernel does not sum them), over the particles.\n\n",
        case_path.display(),
        from.display(),
        list.join("; "),
        a.particle_steps,
        a.rounds,
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0),
        bench::cpu_model(),
        PROBE_STEPS
    )
}

/// The most steps a memory probe runs (the peak is reached at set-up and the first rebuilds).
const PROBE_STEPS: u64 = 200;

/// The peak resident memory (bytes) of one process of configuration `c` run at size `z`, from a
/// child `verdem bench --probe` (a peer's probe reads the peer's state file written here, so
/// that the probe itself stays small: its children count its peak).
fn probe_memory(z: &Size, c: &Config) -> anyhow::Result<f64> {
    let dir = |probe: &str| z.work.join(format!("probe-{}", probe.replace(':', "-")));
    let (probe, from) = match c {
        Config::Verdem { threads, .. } => (format!("verdem:{threads}"), z.state.clone()),
        Config::Peer { peer, np } => {
            let probe = format!("{}:{np}", peer.name());
            let data = bench::write_peer_state(&z.case, &z.state, *peer, &z.work, "probe")?;
            (probe, data)
        }
    };
    let exe = std::env::current_exe().context("the path of the verdem program")?;
    let out = child::output(
        Command::new(&exe)
            .arg("bench")
            .arg(&z.case.path)
            .arg("--from")
            .arg(&from)
            .args(["--steps", &z.steps.min(PROBE_STEPS).to_string()])
            .args(["--probe", &probe])
            .arg("--out")
            .arg(dir(&probe)),
        OnParentDeath::Kill,
    )
    .with_context(|| format!("cannot start {}", exe.display()))?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        bail!(
            "the memory probe {probe} at {} particles failed: {}",
            z.particles,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    text.lines()
        .find_map(|l| l.strip_prefix("peak_rss_bytes "))
        .and_then(|v| v.trim().parse().ok())
        .with_context(|| format!("the memory probe {probe} printed no peak_rss_bytes: {text}"))
}

/// `--probe`: runs one configuration once and prints `peak_rss_bytes B`: verdem from the state
/// `from`, its own peak ([`bench::own_peak_rss`]); a peer from its own state file `from`, its
/// largest process's peak ([`bench::children_peak_rss`]).
fn run_probe(
    case: &Case,
    from: &Path,
    steps: u64,
    probe: &str,
    out: &Path,
) -> anyhow::Result<Finished> {
    let (code, n) = probe
        .split_once(':')
        .with_context(|| format!("--probe {probe}: CODE:N expected"))?;
    let n: usize = count(n).map_err(anyhow::Error::msg)?;
    let bytes = if code == "verdem" {
        let config = Config::Verdem {
            threads: n,
            copies: 1,
            lockstep: false,
        };
        bench::run(case, from, steps, &[config], 1, out)?;
        bench::own_peak_rss()
    } else {
        let peer = verdem::peers::by_name(code)?;
        bench::run_peer(case, peer, n, from, steps, out)?;
        bench::children_peak_rss()
    };
    let bytes = bytes.context("no peak resident memory (/proc/self/status, getrusage)")?;
    println!("peak_rss_bytes {bytes:.0}");
    Ok(Finished::Done)
}
