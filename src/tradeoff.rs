//! The speed/accuracy trade (`verdem tradeoff`): the shear case under variants that change cost
//! (time step, contact stiffness, neighbour skin, threads), each run from the same state for
//! the same simulated time with in-run averaging (the accumulator of `verdem run`,
//! [`Inrun::for_run`]), and for each variant:
//! - its cost: steps per time unit, and the CPU time (user + system, all its threads) and wall
//!   time per simulated time unit;
//! - the relative error of the free–free restitution coefficient at its law and dt (head-on,
//!   v0 = 1, against the closed form);
//! - the bias of each profile's core mean (vx, ν, T, pressure, shear stress) against the
//!   reference's, with its 95 % interval ([`Difference`]: Student's t with Welch's degrees of
//!   freedom, each core mean's error from the series of the core mean), and a verdict ([`Call`]).
//!
//! A **control** row runs the reference's physics again from the same state under another seed
//! of the replicas' perturbation: its biases are noise, so about 95 % of its intervals must
//! contain 0 — the check of the intervals themselves: when it fails ([`control_passes`]), no
//! verdict but the reference's bits is settled ([`judged`]).
//!
//! Replica k of every variant starts from the state with every free particle's velocity
//! perturbed as replica k of `verdem ensemble` ([`perturb`], [`replica_seed`]); the control's
//! replicas take the seeds after the variants'. Every run has one thread, but the threads
//! variant. Softer contacts keep the restitution coefficient (γ scaled with √k, so η/ω is
//! unchanged) and the resolution tc/dt (dt scaled with 1/√k).

use std::fmt;
use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context};

use crate::analysis::cg::blocking;
use crate::analysis::cg::FIELDS;
use crate::analysis::difference::{CoreMean, Difference};
use crate::analysis::inrun::{self, Inrun};
use crate::analysis::stats::standard_error;
use crate::case::{Case, Scene};
use crate::ensemble::{perturb, replica_seed};
use crate::io::atomic;
use crate::run::{self, Observer, RunOptions};
use crate::step::engine::{self, Overrides};
use crate::verify::{closed_form, collide};

/// One variant of the reference case.
#[derive(Clone, Debug)]
pub struct Variant {
    pub name: String,
    pub case: Case,
    pub overrides: Overrides,
}

/// Name of the reference variant.
pub const REFERENCE: &str = "reference";

/// Name of the row that repeats the reference's physics under another seed.
pub const CONTROL: &str = "control (reference physics, other seed)";

/// Threads of the threads variant (every other run has one).
pub const TEAM: usize = 2;

/// Saves a run's in-run window is placed by: as `verdem run` with this many saves, the second
/// half of the run (the first half lets a variant's flow settle into its own steady state).
pub const SAVES: u64 = 40;

/// The variants of `base` (the reference first): dt = tc/25, tc/100, tc/200; kn/10 and kn/100;
/// skins 0.05 and 0.2; [`TEAM`] threads. All but the last run on one thread.
pub fn variants(base: &Case) -> Vec<Variant> {
    let per_tc = base.tc_free_free().unwrap_or(0.0) / base.dt();
    let one = Overrides {
        threads: Some(1),
        ..Overrides::default()
    };
    let with = |name: &str, f: &dyn Fn(&mut Case), o: Overrides| {
        let mut case = base.clone();
        f(&mut case);
        Variant {
            name: name.into(),
            case,
            overrides: o,
        }
    };
    let resolution = |n: f64| {
        move |c: &mut Case| {
            c.run.dt = None;
            c.run.steps_per_collision = Some(n);
        }
    };
    let softer = |factor: f64| {
        move |c: &mut Case| {
            let s = factor.sqrt();
            c.contact.kn /= factor;
            c.contact.kt /= factor;
            c.contact.gamman /= s;
            c.contact.gammat /= s;
            c.run.dt = None;
            c.run.steps_per_collision = Some(per_tc);
        }
    };
    let skin = |s: f64| Overrides {
        skin: Some(s),
        ..one.clone()
    };
    vec![
        with(REFERENCE, &|_| {}, one.clone()),
        with("dt=tc/25", &resolution(25.0), one.clone()),
        with("dt=tc/100", &resolution(100.0), one.clone()),
        with("dt=tc/200", &resolution(200.0), one.clone()),
        with("kn/10", &softer(10.0), one.clone()),
        with("kn/100", &softer(100.0), one.clone()),
        with("skin=0.05", &|_| {}, skin(0.05)),
        with("skin=0.2", &|_| {}, skin(0.2)),
        with(
            &format!("{TEAM} threads"),
            &|_| {},
            Overrides {
                threads: Some(TEAM),
                ..Overrides::default()
            },
        ),
    ]
}

/// How long each variant runs and how its replicas start.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    /// Simulated time of every run (time units).
    pub time: f64,
    /// Replicas of every variant (one thread each, merged per variant).
    pub replicas: u64,
    /// Base seed of the replicas' perturbations ([`replica_seed`]).
    pub base_seed: u64,
    /// Root-mean-square speed of each replica's velocity perturbation (velocity units).
    pub perturbation: f64,
}

/// Cost and accuracy of one variant, over its replicas.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub name: String,
    pub dt: f64,
    /// Steps of each replica.
    pub steps: u64,
    pub replicas: u64,
    /// CPU time (user + system, all threads of the process while the runs advanced) of all
    /// replicas, seconds.
    pub cpu_seconds: f64,
    /// Wall time of all replicas, seconds.
    pub wall_seconds: f64,
    /// Relative error of the free–free restitution coefficient.
    pub restitution_error: f64,
    /// Final state hash of replica 0; equal to the reference's when the variant changes no bit.
    pub hash: String,
    /// Per profile of [`FIELDS`]: its core mean over the in-run window, merged over the
    /// replicas ([`merge_core`]).
    pub core: Vec<CoreMean>,
    /// Each replica's own core means (per profile of [`FIELDS`]), what `core` merges; empty
    /// when read back from [`csv`].
    pub replica_core: Vec<Vec<CoreMean>>,
}

impl Outcome {
    /// Simulated time of all replicas (time units).
    pub fn simulated(&self) -> f64 {
        self.steps as f64 * self.dt * self.replicas as f64
    }

    /// Steps per simulated time unit (1/dt).
    pub fn steps_per_time(&self) -> f64 {
        1.0 / self.dt
    }

    /// CPU seconds per simulated time unit.
    pub fn cpu_per_time(&self) -> f64 {
        self.cpu_seconds / self.simulated()
    }

    /// Wall seconds per simulated time unit.
    pub fn wall_per_time(&self) -> f64 {
        self.wall_seconds / self.simulated()
    }

    /// The first of its numbers (what [`csv`] and [`replicas_csv`] write) that is NaN or
    /// infinite, named; `None` when all are finite.
    pub fn first_non_finite(&self) -> Option<(String, f64)> {
        let times = [
            ("dt", self.dt),
            ("CPU time", self.cpu_seconds),
            ("wall time", self.wall_seconds),
            ("restitution error", self.restitution_error),
        ];
        let core = |c: &[CoreMean], of: &str| {
            c.iter()
                .zip(FIELDS)
                .flat_map(|(m, (field, _))| {
                    [
                        ("core mean", m.mean),
                        ("standard error", m.se),
                        ("dof", m.dof),
                    ]
                    .map(|(what, x)| (format!("{what} of {field}{of}"), x))
                })
                .collect::<Vec<_>>()
        };
        times
            .into_iter()
            .map(|(what, x)| (what.to_string(), x))
            .chain(core(&self.core, ""))
            .chain(
                self.replica_core
                    .iter()
                    .enumerate()
                    .flat_map(|(k, c)| core(c, &format!(" in replica {k}"))),
            )
            .find(|(_, x)| !x.is_finite())
    }
}

/// The core means of independent replicas merged. One replica: its own. R ≥ 2: their mean,
/// with the ensemble's standard error sd/√R (sd over the replicas' means; R − 1 degrees of
/// freedom), trusted whatever each replica's blocks were — independent replicas
/// sample the slow fluctuations that one run's blocks are too short for.
pub fn merge_core(parts: &[CoreMean]) -> CoreMean {
    match parts {
        [] => CoreMean {
            mean: f64::NAN,
            se: f64::NAN,
            dof: f64::NAN,
            long_enough: false,
        },
        [one] => *one,
        _ => {
            let means: Vec<f64> = parts.iter().map(|c| c.mean).collect();
            CoreMean {
                mean: means.iter().sum::<f64>() / means.len() as f64,
                se: standard_error(&means),
                dof: means.len() as f64 - 1.0,
                long_enough: true,
            }
        }
    }
}

/// CPU time (user + system, all threads) this process has used so far, seconds
/// (`getrusage(RUSAGE_SELF)`).
pub fn process_cpu_seconds() -> anyhow::Result<f64> {
    // SAFETY: rusage is plain data; getrusage writes one into the zeroed struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        bail!(
            "getrusage: cannot read this process's CPU time: {}",
            std::io::Error::last_os_error()
        );
    }
    let s = |t: libc::timeval| t.tv_sec as f64 + 1e-6 * t.tv_usec as f64;
    Ok(s(u.ru_utime) + s(u.ru_stime))
}

/// The bumpy-shear walls' speed, half the difference of their prescribed x velocities: the
/// scale of the vx bias (the core mean of vx is near 0); 1 for other scenes.
pub fn wall_speed(case: &Case) -> f64 {
    match case.scene {
        Scene::BumpyShear {
            bottom_vx, top_vx, ..
        } => 0.5 * (top_vx - bottom_vx).abs(),
        _ => 1.0,
    }
}

/// Runs every variant of `base` and the control from `state` as `plan` says (each replica's
/// in-run profiles and their errors written under `out/VARIANT/replica_K/`), and measures the
/// restitution on the two spheres of `pair` (a `spheres` case) under each variant's material
/// and law. `done` is shown each outcome as it is finished. The reference comes first, the
/// control second.
pub fn run(
    base: &Case,
    pair: &Case,
    state: &Path,
    plan: &Plan,
    out: &Path,
    done: &mut dyn FnMut(&Outcome),
) -> anyhow::Result<Vec<Outcome>> {
    if plan.replicas == 0 {
        bail!("the trade needs at least one replica of every variant");
    }
    let mut all = variants(base);
    let control = Variant {
        name: CONTROL.into(),
        ..all[0].clone()
    };
    all.insert(1, control);
    let mut outcomes = Vec::new();
    for v in all {
        let dt = v.case.dt();
        let steps = ((plan.time / dt / SAVES as f64).round() as u64).max(1) * SAVES;
        let mut parts = Vec::new();
        let (mut cpu, mut wall) = (0.0, 0.0);
        let mut hash = String::new();
        for k in 0..plan.replicas {
            let seed = if v.name == CONTROL {
                replica_seed(plan.base_seed, plan.replicas + k)
            } else {
                replica_seed(plan.base_seed, k)
            };
            let mut start = crate::scene::build(&v.case, Some(state))?;
            perturb(&mut start.particles, plan.perturbation, seed)?;
            let mut e = engine::build(&v.case, start, &v.overrides)?;
            let dir = out
                .join(v.name.replace(['/', ' ', '=', '(', ')', ','], "_"))
                .join(format!("replica_{k}"));
            let first = e.state().step;
            let opts = RunOptions {
                end_step: first + steps,
                save_every: steps / SAVES,
                checkpoint_every: 0,
                out_dir: dir.clone(),
                name: v.case.name.clone(),
                tag: v.name.clone(),
                progress: false,
                write_saves: false,
                vtk: false,
                stop: None,
            };
            let intervals = inrun::intervals(&v.case, None, None);
            let mut acc = Inrun::for_run(
                &v.case,
                e.as_ref(),
                &opts,
                intervals,
                first.div_ceil(opts.save_every),
            )?;
            let (cpu0, wall0) = (process_cpu_seconds()?, Instant::now());
            let summary = run::run_observed(
                e.as_mut(),
                &opts,
                false,
                Some(&mut acc as &mut dyn Observer),
            )?;
            wall += wall0.elapsed().as_secs_f64();
            cpu += process_cpu_seconds()? - cpu0;
            let r = acc.result().with_context(|| {
                format!(
                    "{} replica {k}: no in-run sample of both particles and contacts in {steps} \
                     steps; run longer (--time)",
                    v.name
                )
            })?;
            atomic::write(
                &inrun::csv_path(&dir, &v.case.name),
                inrun::csv(&r).as_bytes(),
            )?;
            atomic::write(
                &inrun::errors_csv_path(&dir, &v.case.name),
                inrun::errors_csv(&r).as_bytes(),
            )?;
            let core = blocking::core_means(&r.units, &r.profiles.grid, &r.errors);
            parts.push(FIELDS.iter().map(|&(_, c)| core[c]).collect::<Vec<_>>());
            if k == 0 {
                hash = summary.hash;
            }
            if same_bits(&v.name, &hash, &outcomes) {
                break;
            }
        }
        let core = (0..FIELDS.len())
            .map(|f| merge_core(&parts.iter().map(|p| p[f]).collect::<Vec<_>>()))
            .collect();
        let m = v.case.particle_mass();
        let e_ref = closed_form(&v.case, 0.5 * m).e;
        let per_tc = v.case.tc_free_free().unwrap_or(0.0) / dt;
        let mut two = pair.clone();
        two.contact = v.case.contact.clone();
        two.material = v.case.material.clone();
        let e = collide(&two, 1.0, false, per_tc)?.e;
        let o = Outcome {
            name: v.name,
            dt,
            steps,
            replicas: parts.len() as u64,
            cpu_seconds: cpu,
            wall_seconds: wall,
            restitution_error: (e - e_ref) / e_ref,
            hash,
            core,
            replica_core: parts,
        };
        if let Some((what, x)) = o.first_non_finite() {
            bail!(
                "{}: the {what} is {x}, not a finite number; nothing written",
                o.name
            );
        }
        done(&o);
        outcomes.push(o);
    }
    Ok(outcomes)
}

/// Whether a variant's first replica gave the reference's bits (`hash` equal to the reference
/// row's, the first of `done`). Its further replicas would then repeat the reference's, so the
/// trade runs one replica of it; the reference and the control run every replica.
fn same_bits(name: &str, hash: &str, done: &[Outcome]) -> bool {
    name != CONTROL
        && done
            .first()
            .is_some_and(|r| r.name == REFERENCE && r.hash == hash)
}

/// The bias of one profile's core mean: variant (A) − reference (B), with its 95 % interval,
/// relative to `scale` (the reference's core mean, or the walls' speed for vx).
#[derive(Clone, Debug, PartialEq)]
pub struct Bias {
    pub diff: Difference,
    pub scale: f64,
}

impl Bias {
    /// The bias relative to the scale.
    pub fn relative(&self) -> f64 {
        self.diff.delta() / self.scale
    }

    /// Half the width of the 95 % interval relative to the scale.
    pub fn relative_half_width(&self) -> f64 {
        self.diff.half_width() / self.scale
    }

    /// Whether the 95 % interval contains 0.
    pub fn contains_zero(&self) -> bool {
        !self.diff.real()
    }
}

/// The biases of `variant` against `reference` in each profile of [`FIELDS`]; vx relative to
/// `wall_speed`, the others to the reference's core mean.
pub fn biases(variant: &Outcome, reference: &Outcome, wall_speed: f64) -> Vec<Bias> {
    FIELDS
        .iter()
        .enumerate()
        .map(|(f, &(field, _))| {
            let b = reference.core[f];
            Bias {
                diff: Difference {
                    field,
                    a: variant.core[f],
                    b,
                    chi2: f64::NAN,
                },
                scale: if field == "vx" {
                    wall_speed
                } else {
                    b.mean.abs()
                },
            }
        })
        .collect()
}

/// The verdict on a variant.
#[derive(Clone, Debug, PartialEq)]
pub enum Call {
    /// Every profile's interval contains 0 and is narrower than the resolution, with trusted
    /// errors; or the variant gives the reference's bits (`same_bits`).
    Free { same_bits: bool },
    /// Profiles whose interval excludes 0 with trusted errors: (profile, relative bias,
    /// relative half-width).
    Costs(Vec<(&'static str, f64, f64)>),
    /// No trusted interval excludes 0, but not all are settled: the profiles whose interval is
    /// wider than ±`resolution` (relative half-widths), and those whose errors are too small.
    Undecided {
        resolution: f64,
        wide: Vec<(&'static str, f64)>,
        too_small: Vec<&'static str>,
    },
}

/// The verdict on a variant with biases `biases`: "free" when it gives the reference's bits
/// (`same_bits`) or when every interval contains 0, is narrower than ±`resolution` (relative)
/// and comes from errors that are not too small; it "costs" in each profile whose interval
/// excludes 0 with trusted errors; else it is undecided.
pub fn call(biases: &[Bias], same_bits: bool, resolution: f64) -> Call {
    if same_bits {
        return Call::Free { same_bits: true };
    }
    let costs: Vec<_> = biases
        .iter()
        .filter(|b| !b.contains_zero() && b.diff.errors_trusted())
        .map(|b| (b.diff.field, b.relative(), b.relative_half_width()))
        .collect();
    if !costs.is_empty() {
        return Call::Costs(costs);
    }
    let wide: Vec<_> = biases
        .iter()
        .filter(|b| b.relative_half_width().is_nan() || b.relative_half_width() > resolution)
        .map(|b| (b.diff.field, b.relative_half_width()))
        .collect();
    let too_small: Vec<_> = biases
        .iter()
        .filter(|b| !b.diff.errors_trusted())
        .map(|b| b.diff.field)
        .collect();
    if wide.is_empty() && too_small.is_empty() {
        Call::Free { same_bits: false }
    } else {
        Call::Undecided {
            resolution,
            wide,
            too_small,
        }
    }
}

/// `x` as a percentage with two decimals; "undefined" when it is not a finite number (a
/// relative size against a reference of 0).
fn percent(x: f64) -> String {
    if x.is_finite() {
        format!("{:.2} %", 100.0 * x)
    } else {
        "undefined".into()
    }
}

/// `a / b` with two decimals; "undefined" when it is not a finite number.
fn ratio(a: f64, b: f64) -> String {
    let r = a / b;
    if r.is_finite() {
        format!("{r:.2}")
    } else {
        "undefined".into()
    }
}

impl fmt::Display for Call {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Call::Free { same_bits: true } => write!(f, "free (same bits)"),
            Call::Free { same_bits: false } => write!(f, "free"),
            Call::Costs(c) => {
                let list: Vec<String> = c
                    .iter()
                    .map(|(field, b, h)| format!("{field} {:+.2} % ± {}", 100.0 * b, percent(*h)))
                    .collect();
                write!(f, "**costs** {}", list.join(", "))
            }
            Call::Undecided {
                resolution,
                wide,
                too_small,
            } => {
                let mut parts: Vec<String> = wide
                    .iter()
                    .map(|(field, h)| format!("{field} ± {}", percent(*h)))
                    .collect();
                if !too_small.is_empty() {
                    parts.push(format!("errors too small: {}", too_small.join(", ")));
                }
                write!(
                    f,
                    "undecided (resolution ± {}): {}",
                    percent(*resolution),
                    parts.join("; ")
                )
            }
        }
    }
}

/// How many of `biases`' intervals contain 0, and of how many.
pub fn coverage(biases: &[Bias]) -> (usize, usize) {
    (
        biases.iter().filter(|b| b.contains_zero()).count(),
        biases.len(),
    )
}

/// Whether a control's intervals pass: at most one of its five excludes 0 (right 95 %
/// intervals of a same-physics run pass with probability 0.95⁵ + 5·0.05·0.95⁴ = 97.7 %);
/// generally, at least all but a fifth of them contain 0.
pub fn control_passes(control: &[Bias]) -> bool {
    let (inside, of) = coverage(control);
    5 * (of - inside) <= of
}

/// The verdict on a variant as the table gives it: [`call`]'s, unless the control fails
/// ([`control_passes`]; `control_coverage` = its intervals containing 0, of how many): then
/// the intervals are too narrow to settle anything but the reference's bits, and the verdict is
/// "undecided", with what [`call`] would say at face value.
pub fn judged(
    biases: &[Bias],
    same_bits: bool,
    resolution: f64,
    control: Option<(usize, usize)>,
) -> String {
    let c = call(biases, same_bits, resolution);
    match control {
        Some((inside, of)) if 5 * (of - inside) > of && c != (Call::Free { same_bits: true }) => {
            format!(
                "undecided: the control fails ({inside} of {of} of its intervals contain 0); at face value {c}"
            )
        }
        _ => c.to_string(),
    }
}

/// The table as markdown: per variant its cost (steps and CPU seconds per time unit, CPU and
/// wall time relative to the reference's), restitution error, the bias of each profile with its
/// 95 % interval (relative), whether it gives the reference's bits, and its verdict at
/// `resolution`; then the control's coverage. vx is relative to `wall_speed`.
pub fn markdown(outcomes: &[Outcome], wall_speed: f64, resolution: f64) -> String {
    let replicas = outcomes
        .iter()
        .find(|o| o.name == REFERENCE)
        .map_or(1, |o| o.replicas);
    let errors = if replicas >= 2 {
        format!(
            "each core mean's error from the spread of its {replicas} replicas' own core means, \
             sd/√{replicas} with {} degrees of freedom; a variant that gives the reference's bits \
             runs one",
            replicas - 1
        )
    } else {
        String::from("each core mean's error from the series of the core mean")
    };
    let mut s = format!(
        "Bias = core mean (z in [3, 19]) of the variant − the reference's, relative to the \
         reference's (vx: to the walls' speed {wall_speed}), ± half its 95 % interval \
         (Student's t, Welch's degrees of freedom; {errors}; in-run averaging over the second \
         half of each run); † = errors too small \
         (blocks shorter than the field's correlation asks: not settled). Verdict: free = every \
         interval contains 0 and is narrower than ± {}; costs = the profiles whose interval \
         excludes 0; both only when the control passes (at most one of its five intervals excludes \
         0), else undecided. Cost: CPU time (user + system, all threads of the run) per simulated time \
         unit, relative to the reference's; wall time beside it.\n\n\
         | variant | dt | steps / t.u. | CPU s / t.u. | CPU vs ref | wall vs ref | e error | vx | ν | T | p | τ | same bits | verdict |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        percent(resolution)
    );
    let Some(reference) = outcomes.iter().find(|o| o.name == REFERENCE) else {
        return s;
    };
    let control = outcomes
        .iter()
        .find(|o| o.name == CONTROL)
        .map(|c| coverage(&biases(c, reference, wall_speed)));
    for o in outcomes {
        let b = biases(o, reference, wall_speed);
        let same = o.hash == reference.hash;
        let cells: Vec<String> = b
            .iter()
            .map(|b| {
                let mark = if b.diff.errors_trusted() { "" } else { " †" };
                if o.name == REFERENCE {
                    "—".to_string()
                } else if same {
                    "0 (same bits)".to_string()
                } else if !b.relative().is_finite() {
                    format!("undefined (the scale is {}){mark}", b.scale)
                } else {
                    format!(
                        "{:+.2} ± {}{mark}",
                        100.0 * b.relative(),
                        percent(b.relative_half_width())
                    )
                }
            })
            .collect();
        let verdict = if o.name == REFERENCE {
            "—".to_string()
        } else if o.name == CONTROL {
            let (n, of) = coverage(&b);
            let passes = if control_passes(&b) {
                "passes"
            } else {
                "**fails**"
            };
            format!("control: {n} of {of} intervals contain 0 ({passes})")
        } else {
            judged(&b, same, resolution, control)
        };
        s.push_str(&format!(
            "| {} | {:.3e} | {:.0} | {:.3} | {} | {} | {:+.2e} | {} | {} | {} |\n",
            o.name,
            o.dt,
            o.steps_per_time(),
            o.cpu_per_time(),
            ratio(o.cpu_per_time(), reference.cpu_per_time()),
            ratio(o.wall_per_time(), reference.wall_per_time()),
            o.restitution_error,
            cells.join(" | "),
            if same { "yes" } else { "no" },
            verdict
        ));
    }
    s
}

/// The outcomes as CSV, one row per variant: what [`markdown`] needs, each core mean with its
/// standard error, its degrees of freedom and whether its errors are trusted.
pub fn csv(outcomes: &[Outcome]) -> String {
    let mut s =
        core_header("variant,dt,steps,replicas,cpu_seconds,wall_seconds,restitution_error,hash");
    for o in outcomes {
        s.push_str(&format!(
            "{},{:e},{},{},{:e},{:e},{:e},{}",
            o.name,
            o.dt,
            o.steps,
            o.replicas,
            o.cpu_seconds,
            o.wall_seconds,
            o.restitution_error,
            o.hash
        ));
        push_core(&mut s, &o.core);
    }
    s
}

/// Each replica's core means as CSV, one row per replica run (a variant that gave the
/// reference's bits has only its first): the variant, the replica, then per profile of
/// [`FIELDS`] its core mean, standard error, degrees of freedom and whether its errors are
/// trusted — what
/// [`merge_core`] merged into [`csv`]'s row.
pub fn replicas_csv(outcomes: &[Outcome]) -> String {
    let mut s = core_header("variant,replica");
    for o in outcomes {
        for (k, part) in o.replica_core.iter().enumerate() {
            s.push_str(&format!("{},{k}", o.name));
            push_core(&mut s, part);
        }
    }
    s
}

/// A CSV header line: `first`, then per profile of [`FIELDS`] its core mean, standard error,
/// degrees-of-freedom and trust columns.
fn core_header(first: &str) -> String {
    let mut s = String::from(first);
    for (field, _) in FIELDS {
        s.push_str(&format!(
            ",{field}_mean,{field}_se,{field}_dof,{field}_trusted"
        ));
    }
    s.push('\n');
    s
}

/// Ends a CSV row with the cells of `core` in [`core_header`]'s order.
fn push_core(s: &mut String, core: &[CoreMean]) {
    for c in core {
        s.push_str(&format!(
            ",{:e},{:e},{},{}",
            c.mean, c.se, c.dof, c.long_enough
        ));
    }
    s.push('\n');
}

/// Reads what [`csv`] wrote (the variant's name is all before the other fields, commas
/// included); `path` names the file in errors, with the line and the field: a field that is
/// not a number, is not finite or is out of its range (dt not positive; CPU and wall seconds,
/// standard errors and degrees of freedom negative; no step or replica), and a table without
/// the [`REFERENCE`] row every bias is measured against.
pub fn read_csv(text: &str, path: &Path) -> anyhow::Result<Vec<Outcome>> {
    let mut out = Vec::new();
    let columns = 8 + 4 * FIELDS.len();
    let names: Vec<String> =
        core_header("variant,dt,steps,replicas,cpu_seconds,wall_seconds,restitution_error,hash")
            .trim_end()
            .split(',')
            .map(String::from)
            .collect();
    for (n, line) in text.lines().enumerate().skip(1) {
        let at = |what: &str| format!("{}: line {}: {what}", path.display(), n + 1);
        // the variant's name may hold commas: the other fields are the last ones
        let mut v: Vec<&str> = line.rsplitn(columns, ',').collect();
        v.reverse();
        if v.len() != columns {
            bail!(at(&format!("{} fields, expected {columns}", v.len())));
        }
        let field = |k: usize| format!("field {} ({})", k + 1, names[k]);
        // a finite number; `least` the smallest it may be, and whether that bound is allowed
        let num = |k: usize, least: Option<(f64, bool)>| -> anyhow::Result<f64> {
            let x: f64 = v[k]
                .parse()
                .with_context(|| at(&format!("{} is not a number: {:?}", field(k), v[k])))?;
            if !x.is_finite() {
                bail!(at(&format!("{} is not finite: {:?}", field(k), v[k])));
            }
            match least {
                Some((bound, true)) if x < bound => bail!(at(&format!(
                    "{} is {x}: it must be {bound} or more",
                    field(k)
                ))),
                Some((bound, false)) if x <= bound => bail!(at(&format!(
                    "{} is {x}: it must be above {bound}",
                    field(k)
                ))),
                _ => Ok(x),
            }
        };
        let int = |k: usize| -> anyhow::Result<u64> {
            let x: u64 = v[k]
                .parse()
                .with_context(|| at(&format!("{} is not a count: {:?}", field(k), v[k])))?;
            if x == 0 {
                bail!(at(&format!("{} is 0: it must be 1 or more", field(k))));
            }
            Ok(x)
        };
        let non_negative = Some((0.0, true));
        let core = (0..FIELDS.len())
            .map(|f| {
                let k = 8 + 4 * f;
                Ok(CoreMean {
                    mean: num(k, None)?,
                    se: num(k + 1, non_negative)?,
                    dof: num(k + 2, non_negative)?,
                    long_enough: v[k + 3].parse().with_context(|| {
                        at(&format!(
                            "{} is not true/false: {:?}",
                            field(k + 3),
                            v[k + 3]
                        ))
                    })?,
                })
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        out.push(Outcome {
            name: v[0].to_string(),
            dt: num(1, Some((0.0, false)))?,
            steps: int(2)?,
            replicas: int(3)?,
            cpu_seconds: num(4, non_negative)?,
            wall_seconds: num(5, non_negative)?,
            restitution_error: num(6, None)?,
            hash: v[7].to_string(),
            core,
            replica_core: Vec::new(),
        });
    }
    if !out.iter().any(|o| o.name == REFERENCE) {
        bail!(
            "{}: no `{REFERENCE}` row: every bias is measured against the reference variant's \
             row, and the table has {}",
            path.display(),
            if out.is_empty() {
                "no row".to_string()
            } else {
                format!(
                    "only {}",
                    out.iter()
                        .map(|o| format!("`{}`", o.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(name: &str, hash: &str) -> Outcome {
        Outcome {
            name: name.into(),
            dt: 1.0,
            steps: 1,
            replicas: 1,
            cpu_seconds: 0.0,
            wall_seconds: 0.0,
            restitution_error: 0.0,
            hash: hash.into(),
            core: Vec::new(),
            replica_core: Vec::new(),
        }
    }

    #[test]
    fn a_number_that_is_not_finite_is_named() {
        let finite = CoreMean {
            mean: 1.0,
            se: 0.1,
            dof: 4.0,
            long_enough: true,
        };
        let mut o = outcome(REFERENCE, "abc");
        o.core = vec![finite; FIELDS.len()];
        o.replica_core = vec![vec![finite; FIELDS.len()]; 2];
        assert_eq!(o.first_non_finite(), None);
        o.replica_core[1][2].se = f64::INFINITY;
        let (what, x) = o.first_non_finite().unwrap();
        assert_eq!(
            (what.as_str(), x),
            ("standard error of T in replica 1", f64::INFINITY)
        );
        o.core[0].mean = f64::NAN;
        assert_eq!(o.first_non_finite().unwrap().0, "core mean of vx");
    }

    #[test]
    fn only_a_variant_with_the_references_bits_stops_after_one_replica() {
        let done = [outcome(REFERENCE, "abc")];
        assert!(same_bits("skin=0.05", "abc", &done));
        assert!(!same_bits("kn/10", "abd", &done));
        // the control repeats the reference's physics on purpose, under other seeds
        assert!(!same_bits(CONTROL, "abc", &done));
        // the reference itself (nothing done yet) and a first row that is not the reference
        assert!(!same_bits(REFERENCE, "abc", &[]));
        assert!(!same_bits("skin=0.05", "abc", &[outcome("kn/10", "abc")]));
    }
}
