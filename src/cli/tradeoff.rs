//! `verdem tradeoff`: the speed/accuracy trade of the case's variants, as a table.

use std::path::PathBuf;

use anyhow::Context;

use verdem::contact::named;
use verdem::io::atomic;
use verdem::run;
use verdem::tradeoff::{self, Plan};

use super::args::{count, fraction, lock_output_folder, positive};
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    /// Case file.
    #[arg(default_value = "cases/shear_flow_quick.toml")]
    case: PathBuf,
    /// State to start from.
    #[arg(long, default_value = "data/states/mercury_t143.85.data")]
    from: PathBuf,
    /// Simulated time of every run (time units); profiles are averaged in-run over its second
    /// half.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true, value_parser = positive)]
    time: f64,
    /// Replicas of every variant (seeded perturbations of the start, as `verdem ensemble`
    /// makes them; one thread each, run one after the other). Two or more are merged per
    /// variant into their mean with the ensemble's standard error (R − 1 degrees of freedom).
    #[arg(long, default_value_t = 1, value_parser = count::<u64>)]
    replicas: u64,
    /// Base seed of the replicas' perturbations (default: the case's `run.seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// Root-mean-square speed of each replica's random velocity perturbation of the free
    /// particles (velocity units).
    #[arg(long, default_value_t = 1e-6, value_parser = positive)]
    perturbation: f64,
    /// A variant is free only when every profile's 95 % interval is narrower than ± this
    /// fraction of the reference's core mean (vx: of the walls' speed).
    #[arg(long, default_value_t = 0.02, value_parser = fraction)]
    resolution: f64,
    #[arg(long, default_value = "out/tradeoff")]
    out: PathBuf,
    /// The two-sphere case whose restitution each variant's law is measured on.
    #[arg(long, default_value = "cases/verify/binary_collision.toml")]
    pair: PathBuf,
    /// Replace the files of an earlier tradeoff in OUT's variant folders (without it, such a
    /// folder is refused and nothing is written).
    #[arg(long)]
    force: bool,
    /// Run nothing: print the table of the outcomes in this CSV (the `tradeoff.csv` of an
    /// earlier tradeoff of CASE), judged at --resolution.
    #[arg(long)]
    table: Option<PathBuf>,
}

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let case = named::load(&a.case)?;
    if let Some(path) = &a.table {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        let outcomes = tradeoff::read_csv(&text, path)?;
        print!(
            "{}",
            tradeoff::markdown(&outcomes, tradeoff::wall_speed(&case), a.resolution)
        );
        return Ok(Finished::Done);
    }
    let pair = named::load(&a.pair)?;
    let lock = lock_output_folder(&a.out)?;
    for variant in std::fs::read_dir(&a.out).into_iter().flatten().flatten() {
        if !variant.path().is_dir() {
            continue;
        }
        run::claim_output_folder(&variant.path(), &case.name, a.force, "--force", &lock)?;
        for replica in std::fs::read_dir(variant.path())
            .into_iter()
            .flatten()
            .flatten()
        {
            run::claim_output_folder(&replica.path(), &case.name, a.force, "--force", &lock)?;
        }
    }
    let plan = Plan {
        time: a.time,
        replicas: a.replicas,
        base_seed: a.seed.unwrap_or(case.run.seed),
        perturbation: a.perturbation,
    };
    let outcomes = tradeoff::run(&case, &pair, &a.from, &plan, &a.out, &mut |o| {
        eprintln!(
            "{}: {} steps x {} replicas, {:.1} CPU s, {:.1} wall s",
            o.name, o.steps, o.replicas, o.cpu_seconds, o.wall_seconds
        )
    })?;
    let table = tradeoff::markdown(&outcomes, tradeoff::wall_speed(&case), a.resolution);
    atomic::write(&a.out.join("tradeoff.md"), table.as_bytes())?;
    atomic::write(
        &a.out.join("tradeoff.csv"),
        tradeoff::csv(&outcomes).as_bytes(),
    )?;
    atomic::write(
        &a.out.join("replicas.csv"),
        tradeoff::replicas_csv(&outcomes).as_bytes(),
    )?;
    print!("{table}");
    Ok(Finished::Done)
}
