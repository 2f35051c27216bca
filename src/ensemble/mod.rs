//! Ensembles: R independent replicas of one case, run side by side on this machine's cores
//! ([`local`]) or as a Slurm job array ([`slurm`]), then merged into profiles with ensemble
//! error bars ([`crate::analysis::ensemble`]).
//!
//! Replica k starts from the case's initial state, or from its own state file (`starts[k]`,
//! e.g. saves of a long run spaced by many correlation times, so that the replicas do not share
//! the start's slow modes), with every free particle's velocity perturbed by a tiny random
//! amount drawn from its own seed ([`replica_seed`], [`perturb`]); the flow's chaos grows the
//! perturbation until the replicas are independent. Both engines run
//! a replica the same way, as a `verdem ensemble CASE --replica k` process that calls
//! [`run_replica`], so replica k gives the same state hash whichever engine ran it.
//! Layout of an ensemble's folder `DIR`: `DIR/replica_K/` holds replica K's run (saves,
//! diagnostics, summary, profiles), its record `NAME.replica.toml`, its log `replica.log`; `DIR`
//! holds the merged `NAME.profiles_ensemble.csv` and the summary `NAME.ensemble.toml`.

pub mod local;
pub mod slurm;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use serde::Deserialize;
use sha2::{Digest, Sha256};

use crate::analysis::cg::blocking;
use crate::analysis::cg::table::Table;
use crate::analysis::cg::{self, CgOptions};
use crate::analysis::ensemble::{self as merge, CoreCoverage, Coverage};
use crate::analysis::inrun::{self, Inrun};
use crate::case::Case;
use crate::io::lock;
use crate::io::{atomic, hash};
use crate::run::{self, RunOptions};
use crate::scene;
use crate::state::Particles;
use crate::step::engine::{self, Overrides};

/// What an ensemble is: the case, its start and the replicas' perturbation, how long each
/// replica runs and where their files go.
#[derive(Clone, Debug)]
pub struct Plan {
    pub case: PathBuf,
    /// Initial state of every replica (default: the case's `run.init`, else its generated
    /// scene); `None` when `starts` is given.
    pub init: Option<PathBuf>,
    /// Replica k's own initial state, `starts[k]` (MercuryCG `.data` or official file, as
    /// `init`); empty: every replica starts from `init`. Else one file per replica.
    pub starts: Vec<PathBuf>,
    pub replicas: u64,
    /// Base seed of the replicas' seeds ([`replica_seed`]).
    pub base_seed: u64,
    /// Root-mean-square speed of each replica's velocity perturbation (velocity units; 0: none).
    pub perturbation: f64,
    /// Each replica ends at this step (default: the case's `run.steps`).
    pub steps: Option<u64>,
    /// A save every this many steps (default: the case's `run.save_every`).
    pub save_every: Option<u64>,
    pub out: PathBuf,
}

/// Seed of replica `k` of an ensemble with base seed `base`: the (k+1)-th output of SplitMix64
/// seeded with `base` (Steele, Lea and Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014), so that nearby replicas and nearby base seeds get unrelated seeds.
pub fn replica_seed(base: u64, k: u64) -> u64 {
    let mut z = base.wrapping_add(k.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Adds to the velocity of every free particle (in id order) a random velocity from
/// [`scene::random_velocities`]`(free, amplitude, seed)`: uniform in a cube, zero mean and
/// root-mean-square speed `amplitude` over the free particles (so equal masses keep their total
/// momentum). Wall spheres keep their prescribed velocities; positions and spins are untouched.
/// Fewer than two free particles cannot be given a zero-mean perturbation: an error. An
/// `amplitude` of 0 leaves the particles untouched (the start as it is, bit for bit).
pub fn perturb(particles: &mut Particles, amplitude: f64, seed: u64) -> anyhow::Result<()> {
    if amplitude == 0.0 {
        return Ok(());
    }
    let free: Vec<usize> = (0..particles.len())
        .filter(|&a| particles.is_free(a))
        .collect();
    if free.len() < 2 {
        bail!(
            "the replicas' perturbation needs two free particles or more, the case has {}",
            free.len()
        );
    }
    let dv = scene::random_velocities(free.len(), amplitude, seed);
    for (a, dv) in free.into_iter().zip(dv) {
        particles.v[a] += dv;
    }
    Ok(())
}

/// Folder of replica `k` in the ensemble's folder `out`.
pub fn replica_dir(out: &Path, k: u64) -> PathBuf {
    out.join(format!("replica_{k}"))
}

/// The log of replica `k` (its process's standard output and error, on either engine).
pub fn log_path(out: &Path, k: u64) -> PathBuf {
    replica_dir(out, k).join("replica.log")
}

/// Path of the merged profiles, `DIR/NAME.profiles_ensemble.csv`.
pub fn merged_path(out: &Path, name: &str) -> PathBuf {
    out.join(format!("{name}.profiles_ensemble.csv"))
}

/// Path of the ensemble's summary, `DIR/NAME.ensemble.toml`.
pub fn summary_path(out: &Path, name: &str) -> PathBuf {
    out.join(format!("{name}.ensemble.toml"))
}

fn record_path(out: &Path, name: &str, k: u64) -> PathBuf {
    replica_dir(out, k).join(format!("{name}.replica.toml"))
}

/// What a finished replica records (`DIR/replica_K/NAME.replica.toml`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Record {
    pub replica: u64,
    /// Seeds are written as quoted decimal text: TOML integers stop at 2^63 − 1.
    #[serde(deserialize_with = "u64_text")]
    pub seed: u64,
    #[serde(deserialize_with = "u64_text")]
    pub base_seed: u64,
    pub perturbation: f64,
    /// The file the replica started from (absent for a generated scene) and its SHA-256 (hex).
    #[serde(default)]
    pub start_file: Option<String>,
    #[serde(default)]
    pub start_sha256: Option<String>,
    /// State hash after the perturbation, before the first step.
    pub start_hash: String,
    /// State hash at the end of the run.
    pub hash: String,
    pub step: u64,
    /// Saves coarse-grained into the replica's profiles and the blocks of their errors.
    pub saves: usize,
    pub blocks: usize,
    /// Per benchmark profile ([`cg::FIELDS`]): the degrees of freedom of its in-run standard
    /// error ([`blocking::degrees_of_freedom`]); empty when the replica has no in-run profiles.
    #[serde(default)]
    pub inrun_dof: Vec<f64>,
}

/// A u64 written as quoted decimal text.
fn u64_text<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    let text = String::deserialize(d)?;
    text.parse()
        .map_err(|_| serde::de::Error::custom(format!("not a seed: {text:?}")))
}

impl Record {
    fn toml(&self) -> String {
        format!(
            "replica = {}\nseed = \"{}\"\nbase_seed = \"{}\"\nperturbation = {:e}\n{}start_hash = {:?}\nhash = {:?}\nstep = {}\nsaves = {}\nblocks = {}\ninrun_dof = {:?}\n",
            self.replica,
            self.seed,
            self.base_seed,
            self.perturbation,
            self.start_lines(),
            self.start_hash,
            self.hash,
            self.step,
            self.saves,
            self.blocks,
            self.inrun_dof
        )
    }

    /// The `start_file` and `start_sha256` lines (TOML), none for a generated scene.
    fn start_lines(&self) -> String {
        match (&self.start_file, &self.start_sha256) {
            (Some(file), Some(sha)) => format!(
                "start_file = {}\nstart_sha256 = {sha:?}\n",
                crate::io::toml_string(file)
            ),
            _ => String::new(),
        }
    }

    fn read(path: &Path) -> anyhow::Result<Record> {
        let (_, text) = crate::io::read_text(path).context("cannot read the replica's record")?;
        toml::from_str(&text).with_context(|| format!("{}: not a replica record", path.display()))
    }
}

impl Plan {
    /// The case's name (its output files' prefix).
    pub fn name(&self) -> anyhow::Result<String> {
        Ok(Case::load(&self.case)?.name)
    }

    /// Refuses a plan whose start files do not fit it: `starts` together with `init`, or a
    /// number of start files other than the number of replicas.
    pub fn validate(&self) -> anyhow::Result<()> {
        // Each replica's folder, record and profiles are held for the merge: some 1 MiB each.
        crate::state::memory::check(
            &format!("--replicas {}", self.replicas),
            self.replicas as f64 * (1u64 << 20) as f64,
        )?;
        if self.starts.is_empty() {
            return Ok(());
        }
        if let Some(init) = &self.init {
            bail!(
                "--starts and --init {} together: with --starts each replica starts from its own \
                 file; give one of the two",
                init.display()
            );
        }
        if self.starts.len() as u64 != self.replicas {
            bail!(
                "--replicas {} but --starts names {} files: replica K starts from the K-th file, \
                 so give as many replicas as start files (or leave --replicas out)",
                self.replicas,
                self.starts.len()
            );
        }
        Ok(())
    }

    /// The initial state file replica `k` starts from: `starts[k]`, else `init`, else the
    /// case's `run.init`; `None` when it starts from the case's generated scene.
    pub fn start_file(&self, case: &Case, k: u64) -> Option<PathBuf> {
        if !from_file(case) {
            return None;
        }
        self.starts
            .get(k as usize)
            .or(self.init.as_ref())
            .cloned()
            .or_else(|| case.run.init.as_deref().map(|p| case.resolve(p)))
    }

    /// Builds the start of replica 0, or of every replica when they start from their own
    /// files (the case, the initial state, the perturbation), so that bad input is reported
    /// once, before any replica is started or submitted.
    pub fn check(&self) -> anyhow::Result<()> {
        self.validate()?;
        let case = Case::load(&self.case)?;
        let checked = if self.starts.is_empty() {
            1
        } else {
            self.replicas
        };
        for k in 0..checked {
            self.start(&case, k)?;
        }
        Ok(())
    }

    /// Replica `k`'s start: its initial state ([`Plan::start_file`]) perturbed with
    /// [`replica_seed`]`(base_seed, k)`, and that seed.
    fn start(&self, case: &Case, k: u64) -> anyhow::Result<(scene::Scene, u64)> {
        let init = self.starts.get(k as usize).or(self.init.as_ref());
        if let Some(init) = init.filter(|_| !from_file(case)) {
            bail!(
                "{}: the case {} generates its scene, it cannot start from a file",
                init.display(),
                self.case.display()
            );
        }
        let mut start = scene::build(case, init.map(PathBuf::as_path))?;
        let seed = replica_seed(self.base_seed, k);
        perturb(&mut start.particles, self.perturbation, seed)?;
        Ok((start, seed))
    }

    /// Runs replica `k` on one thread into [`replica_dir`], replacing an earlier run of it
    /// there: its initial state ([`Plan::start_file`]), perturbed with
    /// [`replica_seed`]`(base_seed, k)`, run to the end step with saves, its summary, its
    /// coarse-grained profiles ([`cg::write_all`], the case's defaults: the second half of the
    /// saves) and its [`Record`].
    pub fn run_replica(&self, k: u64) -> anyhow::Result<Record> {
        self.validate()?;
        if k >= self.replicas {
            bail!(
                "replica {k} does not exist: the ensemble has {} (0 to {})",
                self.replicas,
                self.replicas - 1
            );
        }
        let case = Case::load(&self.case)?;
        let (start, seed) = self.start(&case, k)?;
        let start_file = self.start_file(&case, k);
        let start_sha256 = start_file.as_deref().map(file_sha256).transpose()?;
        let mut engine = engine::build(
            &case,
            start,
            &Overrides {
                threads: Some(1),
                ..Overrides::default()
            },
        )?;
        let start_hash = hash::state_hash(&engine.snapshot());
        let dir = replica_dir(&self.out, k);
        let lock = lock::lock_folder(&dir)?;
        run::claim_output_folder(&dir, &case.name, true, "--replica", &lock)?;
        let opts = RunOptions {
            end_step: self.steps.unwrap_or(case.run.steps),
            save_every: self.save_every.unwrap_or(case.run.save_every),
            checkpoint_every: 0,
            out_dir: dir.clone(),
            name: case.name.clone(),
            tag: crate::io::checkpoint::tag(&case),
            progress: false,
            write_saves: true,
            vtk: false,
            stop: None,
        };
        let mut inrun = in_run(&case, engine.as_ref(), &opts)?;
        let s = run::run_observed(
            engine.as_mut(),
            &opts,
            false,
            inrun.as_mut().map(|i| i as &mut dyn run::Observer),
        )?;
        run::write_summary(&dir, &case.name, &s, 1)?;
        let (profiles, _, _) = cg::write_all(&dir.join(&case.name), &CgOptions::for_case(&case))?;
        let mut inrun_dof = Vec::new();
        if let Some(r) = inrun.as_ref().and_then(Inrun::result) {
            atomic::write(
                &inrun::csv_path(&dir, &case.name),
                inrun::csv(&r).as_bytes(),
            )?;
            atomic::write(
                &inrun::errors_csv_path(&dir, &case.name),
                inrun::errors_csv(&r).as_bytes(),
            )?;
            // A column without fluctuations (τ = 0) would have infinite degrees of freedom: a
            // variance from n units has at most n − 1, which keeps the record finite.
            let most = (r.units.len() as f64 - 1.0).max(1.0);
            inrun_dof = cg::FIELDS
                .iter()
                .map(|&(_, c)| blocking::degrees_of_freedom(&r.errors, c, r.units.len()).min(most))
                .collect();
        }
        let record = Record {
            replica: k,
            seed,
            base_seed: self.base_seed,
            perturbation: self.perturbation,
            start_file: start_file.map(|p| p.display().to_string()),
            start_sha256,
            start_hash,
            hash: s.hash,
            step: s.step,
            saves: profiles.saves.len(),
            blocks: profiles.blocks,
            inrun_dof,
        };
        atomic::write(
            &record_path(&self.out, &case.name, k),
            record.toml().as_bytes(),
        )?;
        Ok(record)
    }

    /// Makes the ensemble's folder ready for a new ensemble of case `name`: a folder that holds
    /// an earlier one (merged files, or replica folders with a run or a record) is refused,
    /// naming it, unless `force` is set; then their files are removed first. Creates the
    /// replicas' folders.
    pub fn claim(&self, name: &str, force: bool) -> anyhow::Result<()> {
        let mut found: Vec<PathBuf> = [merged_path(&self.out, name), summary_path(&self.out, name)]
            .into_iter()
            .filter(|p| p.exists())
            .collect();
        for k in replica_folders(&self.out)? {
            let dir = replica_dir(&self.out, k);
            found.extend(run::run_files(&dir, name)?);
            found.extend(
                [
                    record_path(&self.out, name, k),
                    log_path(&self.out, k),
                    slurm::exit_path(&self.out, k),
                ]
                .into_iter()
                .filter(|p| p.exists()),
            );
        }
        if !found.is_empty() && !force {
            bail!(
                "{}: already holds an ensemble of {name:?} ({} files, e.g. {}); nothing was \
                 written. Choose another folder with --out, merge it again with --merge, or \
                 replace it with --force",
                self.out.display(),
                found.len(),
                found[0].display()
            );
        }
        for p in &found {
            std::fs::remove_file(p)
                .with_context(|| format!("{}: cannot remove (--force)", p.display()))?;
        }
        for k in 0..self.replicas {
            let dir = replica_dir(&self.out, k);
            std::fs::create_dir_all(&dir)
                .with_context(|| format!("{}: cannot create", dir.display()))?;
        }
        Ok(())
    }

    /// Merges the replicas' profiles: writes `NAME.profiles_ensemble.csv` (the columns of
    /// `NAME.profiles.csv`: ensemble mean and its standard error, [`merge::merge`]) and the
    /// summary `NAME.ensemble.toml`, and returns what they hold. Every replica must have
    /// finished with this plan's seeds and perturbation.
    pub fn merge(&self, name: &str, engine: &str) -> anyhow::Result<Merged> {
        self.validate()?;
        let case = Case::load(&self.case)?;
        let mut records = Vec::new();
        let mut tables = Vec::new();
        for k in 0..self.replicas {
            let path = record_path(&self.out, name, k);
            if !path.exists() {
                bail!(
                    "replica {k} has not finished: {} is missing (run it with --replica {k}, \
                     its log is {})",
                    path.display(),
                    log_path(&self.out, k).display()
                );
            }
            let r = Record::read(&path)?;
            self.check_start(&case, k, &r, &path)?;
            let seed = replica_seed(self.base_seed, k);
            if r.replica != k || r.seed != seed || r.perturbation != self.perturbation {
                bail!(
                    "{}: replica {} with seed {} and perturbation {:e}, this ensemble's replica \
                     {k} has seed {seed} and perturbation {:e} (base seed {}): the folder holds \
                     another ensemble's replica",
                    path.display(),
                    r.replica,
                    r.seed,
                    r.perturbation,
                    self.perturbation,
                    self.base_seed
                );
            }
            let profiles = replica_dir(&self.out, k).join(format!("{name}.profiles.csv"));
            tables.push(Table::read(&profiles)?);
            records.push(r);
        }
        let blocks = records.iter().map(|r| r.blocks).min().unwrap_or(0);
        let table = merge::merge(&tables)?;
        let coverage = merge::coverage(&tables, &table, blocks)?;
        let inrun = merge_inrun(self, name, &records)?;
        let merged = Merged {
            engine: engine.to_string(),
            records,
            coverage,
            blocks,
            table,
            inrun,
        };
        atomic::write(&merged_path(&self.out, name), merged.table.csv().as_bytes())?;
        if let Some((t, _, _)) = &merged.inrun {
            atomic::write(&merged_inrun_path(&self.out, name), t.csv().as_bytes())?;
        }
        atomic::write(&summary_path(&self.out, name), merged.toml(self).as_bytes())?;
        Ok(merged)
    }

    /// Refuses replica `k`'s record (read from `path`) when the replica started from another
    /// file than this plan's (by content: SHA-256), or from a file when this plan's starts from
    /// the generated scene, or the other way round.
    fn check_start(&self, case: &Case, k: u64, r: &Record, path: &Path) -> anyhow::Result<()> {
        let file = self.start_file(case, k);
        let sha = file.as_deref().map(file_sha256).transpose()?;
        if r.start_sha256 != sha {
            let named = |f: Option<String>, sha: &Option<String>, none: &str| match (f, sha) {
                (Some(f), Some(sha)) => format!("{f} (SHA-256 {sha})"),
                _ => none.to_string(),
            };
            bail!(
                "{}: replica {k} started from {}, this ensemble's replica {k} starts from {}: the \
                 folder holds another ensemble's replica (give the --starts or --init it was \
                 run with)",
                path.display(),
                named(
                    r.start_file.clone(),
                    &r.start_sha256,
                    "no recorded file (a generated scene)"
                ),
                named(
                    file.map(|f| f.display().to_string()),
                    &sha,
                    "the case's generated scene"
                )
            );
        }
        Ok(())
    }
}

/// Whether `case` starts from a file when given one (its scene is bumpy shear; the other
/// scenes are generated).
fn from_file(case: &Case) -> bool {
    matches!(case.scene, crate::case::Scene::BumpyShear { .. })
}

/// Hex SHA-256 of the file at `path`.
pub fn file_sha256(path: &Path) -> anyhow::Result<String> {
    let mut f = std::fs::File::open(path)
        .with_context(|| format!("{}: cannot read the start file", path.display()))?;
    let mut h = Sha256::new();
    std::io::copy(&mut f, &mut h)
        .with_context(|| format!("{}: cannot read the start file", path.display()))?;
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

/// The in-run averaging of a replica of a bumpy-shear `case` (none for other scenes), as
/// `verdem run` samples by default: over the steps of the second half of the saves the replica
/// writes from the engine's current step, with the benchmark's reference τ as the errors' floor.
fn in_run(
    case: &Case,
    engine: &dyn crate::step::Engine,
    opts: &RunOptions,
) -> anyhow::Result<Option<Inrun>> {
    if !matches!(case.scene, crate::case::Scene::BumpyShear { .. }) {
        return Ok(None);
    }
    Ok(Some(Inrun::for_run(
        case,
        engine,
        opts,
        inrun::intervals(case, None, None),
        engine.state().step.div_ceil(opts.save_every),
    )?))
}

/// The ensemble of the replicas' in-run profiles and the coverage of their own errors, the
/// expected coverage from each profile's fewest degrees of freedom over the replicas, and the
/// coverage of their core means' own errors (none when a replica's error table has no core
/// columns); `None` when a replica has no in-run profiles.
fn merge_inrun(plan: &Plan, name: &str, records: &[Record]) -> anyhow::Result<Option<InrunMerged>> {
    let paths: Vec<PathBuf> = (0..plan.replicas)
        .map(|k| inrun::csv_path(&replica_dir(&plan.out, k), name))
        .collect();
    if records
        .iter()
        .any(|r| r.inrun_dof.len() != cg::FIELDS.len())
        || paths.iter().any(|p| !p.exists())
    {
        return Ok(None);
    }
    let tables = paths
        .iter()
        .map(|p| Table::read(p))
        .collect::<Result<Vec<Table>, _>>()?;
    let table = merge::merge(&tables)?;
    let mut coverage = merge::coverage(&tables, &table, 2)?;
    for (f, c) in coverage.iter_mut().enumerate() {
        let dof = records
            .iter()
            .map(|r| r.inrun_dof[f])
            .fold(f64::INFINITY, f64::min);
        c.expected = merge::expected_coverage_dof(tables.len(), dof);
    }
    let mut per_replica = Vec::new();
    for k in 0..plan.replicas {
        match inrun::read_core_means(&inrun::errors_csv_path(&replica_dir(&plan.out, k), name))? {
            Some(m) => per_replica.push(m),
            None => return Ok(Some((table, coverage, Vec::new()))),
        }
    }
    let core = cg::FIELDS
        .iter()
        .enumerate()
        .map(|(f, &(field, _))| {
            let means: Vec<(f64, f64)> = per_replica.iter().map(|m| m[f]).collect();
            merge::core_coverage(field, &means)
        })
        .collect();
    Ok(Some((table, coverage, core)))
}

/// The ensemble of the replicas' in-run profiles, the coverage of their per-slice errors and
/// that of their core means' errors.
pub type InrunMerged = (Table, Vec<Coverage>, Vec<CoreCoverage>);

/// Path of the merged in-run profiles, `DIR/NAME.profiles_inrun_ensemble.csv`.
pub fn merged_inrun_path(out: &Path, name: &str) -> PathBuf {
    out.join(format!("{name}.profiles_inrun_ensemble.csv"))
}

/// The replica numbers K of the folders `replica_K` in `out`, increasing.
fn replica_folders(out: &Path) -> anyhow::Result<Vec<u64>> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(Vec::new());
    };
    let mut ks = Vec::new();
    for e in entries {
        let e = e.with_context(|| format!("{}: cannot list", out.display()))?;
        if let Some(k) = e
            .file_name()
            .to_str()
            .and_then(|f| f.strip_prefix("replica_"))
            .and_then(|k| k.parse().ok())
        {
            ks.push(k);
        }
    }
    ks.sort_unstable();
    Ok(ks)
}

/// The TOML line `key = ratio`, or, for a ratio that is not finite (the replicas' own errors
/// are 0), a comment saying it is undefined: the summary holds no non-finite number.
fn ratio_line(key: &str, ratio: f64) -> String {
    if ratio.is_finite() {
        format!("{key} = {ratio}")
    } else {
        format!("# {key} undefined: the replicas' own errors are 0")
    }
}

/// A merged ensemble.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The engine that ran the replicas (`local`, `slurm`, or `merge` when only merged).
    pub engine: String,
    pub records: Vec<Record>,
    /// The ensemble's profiles ([`merge::merge`]).
    pub table: Table,
    pub coverage: Vec<Coverage>,
    /// The fewest blocks any replica's errors came from.
    pub blocks: usize,
    /// The ensemble of the replicas' in-run profiles, the coverage of their own (per-field)
    /// errors and of their core means' errors, when every replica has in-run profiles.
    pub inrun: Option<InrunMerged>,
}

impl Merged {
    /// The summary file's text (TOML): the plan, each replica's seed, start file and hashes, and per
    /// benchmark profile its core mean with the ensemble error and the coverage test.
    pub fn toml(&self, plan: &Plan) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "replicas = {}", plan.replicas);
        let _ = writeln!(s, "engine = {:?}", self.engine);
        let _ = writeln!(s, "base_seed = \"{}\"", plan.base_seed);
        let _ = writeln!(s, "perturbation = {:e}", plan.perturbation);
        let _ = writeln!(s, "blocks = {}", self.blocks);
        for r in &self.records {
            let _ = writeln!(
                s,
                "\n[[replica]]\nreplica = {}\nseed = \"{}\"\n{}start_hash = {:?}\nhash = {:?}\nstep = {}\nsaves = {}",
                r.replica,
                r.seed,
                r.start_lines(),
                r.start_hash,
                r.hash,
                r.step,
                r.saves
            );
        }
        let inrun = self.inrun.iter().flat_map(|(_, c, _)| c);
        for (table, c) in std::iter::repeat_n("field", self.coverage.len())
            .zip(&self.coverage)
            .chain(std::iter::repeat("field_inrun").zip(inrun))
        {
            let (lo, hi) = merge::wilson_interval(c.inside, c.pairs);
            let _ = writeln!(
                s,
                "\n[[{table}]]\nname = {:?}\ncore_mean = {:e}\ncore_se = {:e}\ncoverage = {}\ncoverage_interval = [{lo}, {hi}]\npairs = {}\nexpected_coverage = {}\n{}",
                c.field,
                c.core_mean,
                c.core_se,
                c.fraction(),
                c.pairs,
                c.expected,
                ratio_line("spread_over_block_error", c.spread_ratio)
            );
        }
        for c in self.inrun.iter().flat_map(|(_, _, c)| c) {
            let _ = writeln!(
                s,
                "\n[[core_inrun]]\nname = {:?}\ninside = {}\nreplicas = {}\n{}",
                c.field,
                c.inside,
                c.replicas,
                ratio_line("spread_over_error", c.spread_ratio)
            );
        }
        s
    }

    /// The report printed at the end: per profile, the core mean with its ensemble error, and
    /// the coverage of the replicas' own block errors against what honest errors give.
    pub fn report(&self) -> String {
        let r = self.records.len();
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{r} replicas, {} saves each, block errors from {} blocks; core slices only",
            self.records.first().map_or(0, |r| r.saves),
            self.blocks
        );
        if self.blocks < 2 {
            let _ = writeln!(
                s,
                "the replicas' profiles come from one block of saves and have no block errors: \
                 the coverage test needs more saves per replica (--every)"
            );
        }
        s.push_str(&coverage_table(&self.coverage));
        if let Some((_, c, core)) = &self.inrun {
            let _ = writeln!(
                s,
                "in-run profiles, each field's own errors (no tau below the benchmark's reference):"
            );
            s.push_str(&coverage_table(c));
            if !core.is_empty() {
                let _ = writeln!(
                    s,
                    "in-run core means, each replica's own error (the series of its core mean): \
                     replicas within ±2 errors of their mean, and their spread over those errors"
                );
                for c in core {
                    let _ = writeln!(
                        s,
                        "{:<9} {:>3} of {:<3} spread/SE {:.2}",
                        c.field, c.inside, c.replicas, c.spread_ratio
                    );
                }
            }
        }
        let _ = writeln!(
            s,
            "coverage: the fraction of (replica, core slice) pairs whose value lies within ±2 of \
             the replica's own standard error of the ensemble mean, with its 95 % binomial \
             (Wilson) interval; expected: that fraction when the errors are honest (P(|t| ≤ \
             2/√(1 − 1/R)), t with the errors' degrees of freedom: blocks − 1); spread/SE: the \
             replicas' scatter over their own error bars (1 when honest)"
        );
        s
    }
}

/// The coverage lines of one set of profiles: per benchmark profile, the core mean with its
/// ensemble error, the coverage with its interval, the expected coverage and the spread ratio.
fn coverage_table(coverage: &[Coverage]) -> String {
    let mut s = format!(
        "{:<9} {:>13} {:>11} {:>9} {:>15} {:>9} {:>9}\n",
        "field", "core mean", "ensemble SE", "coverage", "95% interval", "expected", "spread/SE"
    );
    for c in coverage {
        let (lo, hi) = merge::wilson_interval(c.inside, c.pairs);
        let _ = writeln!(
            s,
            "{:<9} {:>13.5e} {:>11.2e} {:>8.1}% {:>6.1}-{:>5.1}% {:>8.1}% {:>9.2}",
            c.field,
            c.core_mean,
            c.core_se,
            100.0 * c.fraction(),
            100.0 * lo,
            100.0 * hi,
            100.0 * c.expected,
            c.spread_ratio
        );
    }
    s
}

/// How the process running one replica ended, on either engine.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskOutcome {
    pub replica: u64,
    /// Its standard output and error.
    pub log: PathBuf,
    /// Its exit code, or why there is none (killed by a signal, cancelled, timed out).
    pub exit: Result<i32, String>,
}

impl TaskOutcome {
    pub fn ok(&self) -> bool {
        self.exit == Ok(0)
    }
}

/// The command that runs one replica (`verdem ensemble … --replica K` on either engine): the
/// program and its arguments; the engines append `--replica K`.
#[derive(Clone, Debug)]
pub struct ReplicaCommand {
    pub program: PathBuf,
    pub args: Vec<String>,
}

/// A report of the tasks that failed, one a line: replica (array task) id, exit code or why
/// there is none, its log and the log's last line; `None` when all succeeded.
pub fn failures(outcomes: &[TaskOutcome]) -> Option<String> {
    let failed: Vec<&TaskOutcome> = outcomes.iter().filter(|o| !o.ok()).collect();
    if failed.is_empty() {
        return None;
    }
    let mut s = format!("{} of {} replicas failed:", failed.len(), outcomes.len());
    for o in failed {
        let exit = match &o.exit {
            Ok(code) => format!("exit code {code}"),
            Err(why) => why.clone(),
        };
        let last = std::fs::read_to_string(&o.log)
            .ok()
            .and_then(|t| {
                t.lines()
                    .rev()
                    .find(|l| !l.trim().is_empty())
                    .map(String::from)
            })
            .unwrap_or_else(|| "(empty or missing)".into());
        let _ = write!(
            s,
            "\n  task {}: {exit}; log {}: {last}",
            o.replica,
            o.log.display()
        );
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::Motion;
    use crate::Vec3;

    #[test]
    fn replica_seeds_are_splitmix64() {
        // SplitMix64 seeded with 0: first outputs 0xe220a8397b1dcdaf, 0x6e789e6aa1b965f4
        // (the reference implementation's published sequence)
        assert_eq!(replica_seed(0, 0), 0xe220_a839_7b1d_cdaf);
        assert_eq!(replica_seed(0, 1), 0x6e78_9e6a_a1b9_65f4);
        assert_ne!(replica_seed(1, 0), replica_seed(0, 1));
    }

    #[test]
    fn the_perturbation_moves_free_particles_only_with_its_rms_and_no_net_momentum() {
        let mut p = Particles::default();
        for a in 0..50 {
            let motion = if a < 10 {
                Motion::Prescribed(0)
            } else {
                Motion::Free
            };
            p.push(
                Vec3::new(a as f64, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::zeros(),
                0.5,
                1.0,
                motion,
            );
        }
        let before = p.clone();
        perturb(&mut p, 1e-6, replica_seed(1, 3)).unwrap();
        for a in 0..10 {
            assert_eq!(p.v[a], before.v[a]);
        }
        let dv: Vec<Vec3> = (10..50).map(|a| p.v[a] - before.v[a]).collect();
        let sum: Vec3 = dv.iter().sum();
        let rms = (dv.iter().map(|d| d.norm_squared()).sum::<f64>() / 40.0).sqrt();
        // zero within the rounding of v = 1 + dv (40 × 1.1e-16), against a sum of 40 × 1e-6
        assert!(sum.norm() < 1e-14, "{sum:?}");
        assert!((rms - 1e-6).abs() < 1e-12, "{rms}");
        assert_eq!(p.x, before.x);
        let mut again = before.clone();
        perturb(&mut again, 1e-6, replica_seed(1, 3)).unwrap();
        assert_eq!(again.v, p.v);
        let mut other = before;
        perturb(&mut other, 1e-6, replica_seed(1, 4)).unwrap();
        assert_ne!(other.v, p.v);
    }

    #[test]
    fn a_zero_perturbation_leaves_every_velocity_bit_for_bit() {
        let mut p = Particles::default();
        // one free particle (too few for a perturbation) moving at -0 along x: adding a zero
        // perturbation would turn -0 into +0
        p.push(
            Vec3::zeros(),
            Vec3::new(-0.0, 1.0, 0.0),
            Vec3::zeros(),
            0.5,
            1.0,
            Motion::Free,
        );
        perturb(&mut p, 0.0, replica_seed(1, 0)).unwrap();
        assert!(p.v[0].x.is_sign_negative(), "{:?}", p.v[0]);
        assert!(perturb(&mut p, 1e-6, replica_seed(1, 0)).is_err());
    }
}
