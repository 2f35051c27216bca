//! `verdem ensemble`: run R independent replicas of a case on this machine or on Slurm, and
//! merge their profiles with ensemble error bars and the coverage test of their own error bars.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;

use verdem::contact::named;
use verdem::ensemble::{self, local, slurm, Plan, ReplicaCommand};

use super::args::{count, lock_output_folder, named, non_negative, positive};
use super::signals::{self, Graceful};
use super::Finished;

/// Where the replicas run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EngineChoice {
    Local,
    Slurm,
}

impl EngineChoice {
    const ALL: [EngineChoice; 2] = [EngineChoice::Local, EngineChoice::Slurm];

    fn name(self) -> &'static str {
        match self {
            EngineChoice::Local => "local",
            EngineChoice::Slurm => "slurm",
        }
    }
}

#[derive(clap::Args)]
pub struct Args {
    /// Case file (TOML).
    case: PathBuf,
    /// Number of replicas (2 or more for error bars; default with --starts: one per file).
    #[arg(long, value_parser = count::<u64>, required_unless_present = "starts")]
    replicas: Option<u64>,
    /// Where the replicas run: `local` (child processes on this machine's cores, one thread
    /// each) or `slurm` (a job array submitted with sbatch).
    #[arg(long, default_value = "local", value_parser = named(&EngineChoice::ALL, EngineChoice::name))]
    engine: EngineChoice,
    /// Initial configuration (default: the case's `run.init`), perturbed for each replica.
    #[arg(long)]
    init: Option<PathBuf>,
    /// Replica K starts from the K-th of these state files (MercuryCG `.data`, as --init reads),
    /// e.g. saves of a long run spaced by many correlation times; perturbed as with --init.
    #[arg(long, num_args = 1..)]
    starts: Vec<PathBuf>,
    /// Each replica ends at this step (default: the case's `run.steps`).
    #[arg(long, value_parser = count::<u64>)]
    steps: Option<u64>,
    /// A save every M steps (default: the case's `run.save_every`).
    #[arg(long, value_parser = count::<u64>)]
    every: Option<u64>,
    /// The ensemble's folder (default: out/NAME_ensemble); replica K runs in DIR/replica_K.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Base seed of the replicas' perturbations (default: the case's `run.seed`); replica K's
    /// seed is the (K+1)-th output of SplitMix64 seeded with it.
    #[arg(long)]
    seed: Option<u64>,
    /// Root-mean-square speed of each replica's random velocity perturbation of the free
    /// particles (velocity units; 0: none, e.g. with --starts).
    #[arg(long, default_value_t = 1e-6, value_parser = non_negative)]
    perturbation: f64,
    /// Local engine: at most this many replicas at once (default: the CPUs this process may use).
    #[arg(long, value_parser = count::<usize>)]
    jobs: Option<usize>,
    /// Slurm engine: an option for sbatch (repeat it: `--sbatch-arg=--partition=short
    /// --sbatch-arg=--time=02:00:00`); it overrides the script's `#SBATCH` lines.
    #[arg(long, allow_hyphen_values = true)]
    sbatch_arg: Vec<String>,
    /// Slurm engine: seconds between two polls of squeue.
    #[arg(long, default_value_t = 5.0, value_parser = positive)]
    poll: f64,
    /// Replace an earlier ensemble in the folder (without it, such a folder is refused).
    #[arg(long)]
    force: bool,
    /// Only merge the replicas already in the folder (e.g. after rerunning one with --replica).
    #[arg(long, conflicts_with_all = ["replica", "force"])]
    merge: bool,
    /// Only run replica K into DIR/replica_K, replacing its files there (what each local
    /// process and each Slurm array task runs).
    #[arg(long)]
    replica: Option<u64>,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = named::load(&a.case)?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}_ensemble", case.name)));
    let replicas = a.replicas.unwrap_or(a.starts.len() as u64);
    let plan = Plan {
        case: absolute(&a.case)?,
        init: a.init.as_deref().map(absolute).transpose()?,
        starts: a
            .starts
            .iter()
            .map(|p| absolute(p))
            .collect::<anyhow::Result<_>>()?,
        replicas,
        base_seed: a.seed.unwrap_or(case.run.seed),
        perturbation: a.perturbation,
        steps: a.steps,
        save_every: a.every,
        out: absolute(&out)?,
    };
    plan.validate()?;
    if let Some(k) = a.replica {
        let r = plan.run_replica(k)?;
        println!(
            "replica {k}: seed {}, start {}, start hash {}, step {}, state hash {}",
            r.seed,
            r.start_file.as_deref().unwrap_or("generated"),
            r.start_hash,
            r.step,
            r.hash
        );
        return Ok(Finished::Done);
    }
    if replicas < 2 {
        anyhow::bail!(
            "--replicas {replicas}: an ensemble needs 2 replicas or more for its error bars"
        );
    }
    if !a.merge {
        plan.check()?;
    }
    // Held until the merged files are written.
    let _lock = lock_output_folder(&plan.out)?;
    let engine = if a.merge {
        "merge"
    } else {
        plan.claim(&case.name, a.force)?;
        let cmd = replica_command(&plan)?;
        let outcomes = match a.engine {
            EngineChoice::Local => {
                let jobs = a
                    .jobs
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
                println!(
                    "{replicas} replicas of {} on {jobs} local processes, into {}",
                    case.name,
                    plan.out.display()
                );
                local::run(&cmd, replicas, jobs, &plan.out)?
            }
            EngineChoice::Slurm => {
                let o = slurm::Options {
                    sbatch_args: a.sbatch_arg.clone(),
                    poll: Duration::from_secs_f64(a.poll),
                    stop: Some(stop_on_signal()?),
                };
                slurm::run(&cmd, replicas, &plan.out, &case.name, &o)?.1
            }
        };
        if let Some(report) = ensemble::failures(&outcomes) {
            anyhow::bail!("{report}");
        }
        a.engine.name()
    };
    let merged = plan.merge(&case.name, engine)?;
    for r in &merged.records {
        println!(
            "replica {}: seed {}, start {}, state hash {}",
            r.replica,
            r.seed,
            r.start_file.as_deref().unwrap_or("generated"),
            r.hash
        );
    }
    print!("{}", merged.report());
    println!(
        "profiles: {}\nsummary: {}",
        ensemble::merged_path(&plan.out, &case.name).display(),
        ensemble::summary_path(&plan.out, &case.name).display()
    );
    Ok(Finished::Done)
}

/// The command that runs one replica of `plan`: this binary, `ensemble`, and every option of
/// the plan written out (absolute paths, the seed and perturbation explicit), so that a task
/// on another node runs exactly this replica.
fn replica_command(plan: &Plan) -> anyhow::Result<ReplicaCommand> {
    let program = std::env::current_exe().context("cannot find the verdem binary")?;
    let mut args = vec![
        "ensemble".to_string(),
        plan.case.display().to_string(),
        "--replicas".into(),
        plan.replicas.to_string(),
        "--out".into(),
        plan.out.display().to_string(),
        "--seed".into(),
        plan.base_seed.to_string(),
        "--perturbation".into(),
        format!("{:e}", plan.perturbation),
    ];
    if let Some(init) = &plan.init {
        args.extend(["--init".into(), init.display().to_string()]);
    }
    if !plan.starts.is_empty() {
        args.push("--starts".into());
        args.extend(plan.starts.iter().map(|p| p.display().to_string()));
    }
    if let Some(steps) = plan.steps {
        args.extend(["--steps".into(), steps.to_string()]);
    }
    if let Some(every) = plan.save_every {
        args.extend(["--every".into(), every.to_string()]);
    }
    Ok(ReplicaCommand { program, args })
}

/// `p` made absolute against the current folder (it need not exist yet).
fn absolute(p: &Path) -> anyhow::Result<PathBuf> {
    std::path::absolute(p)
        .with_context(|| format!("{}: cannot make the path absolute", p.display()))
}

/// A flag raised by SIGINT, SIGTERM or SIGHUP ([`signals`]) while waiting for Slurm: the job is
/// then cancelled.
fn stop_on_signal() -> anyhow::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    signals::graceful(Graceful {
        flag: Arc::clone(&stop),
        notice: None,
        second_exits: false,
    })?;
    Ok(stop)
}
