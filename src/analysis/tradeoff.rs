//! The speed/accuracy trade (`verdem tradeoff`): the shear case under variants that change cost
//! (time step, contact stiffness, neighbour skin, threads), each run from the same state for
//! the same simulated time, with its cost and two accuracy measures:
//! (a) the relative error of the free–free restitution coefficient at the variant's law and dt
//!     (head-on, v0 = 1, against the closed form);
//! (b) the deviation of each z-profile (velocity, concentration, granular temperature, pressure,
//!     shear stress) from the reference variant's, slice by slice over the core, divided by the
//!     combined standard error (block averages). Block errors of a short series miss the
//!     flow's slow fluctuations, so even the same physics gives χ²/dof above 1: the "replica"
//!     row, the reference's physics over the next stretch of time (started from the
//!     reference's last save, which holds no tangential springs: the few contacts open at that
//!     instant restart theirs from zero), measures that noise floor; a variant is within noise
//!     when its χ²/dof is comparable to the replica's.
//!
//! Softer contacts keep the restitution coefficient (γ scaled with √k, so η/ω is unchanged)
//! and the resolution tc/dt (dt scaled with 1/√k).

use std::path::Path;

use crate::analysis::cg::{self, CgOptions, Series};
use crate::case::Case;
use crate::engine::{self, Overrides};
use crate::run::{self, RunOptions};
use crate::verify::{closed_form, collide};

/// One variant of the reference case.
#[derive(Clone, Debug)]
pub struct Variant {
    pub name: String,
    pub case: Case,
    pub overrides: Overrides,
}

/// The variants of `base` (the reference first): dt = tc/25, tc/100, tc/200; kn/10 and kn/100;
/// skins 0.05 and 0.2; 1 thread.
pub fn variants(base: &Case) -> Vec<Variant> {
    let per_tc = base.tc_free_free().unwrap_or(0.0) / base.dt();
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
        ..Overrides::default()
    };
    vec![
        with("reference", &|_| {}, Overrides::default()),
        with("dt=tc/25", &resolution(25.0), Overrides::default()),
        with("dt=tc/100", &resolution(100.0), Overrides::default()),
        with("dt=tc/200", &resolution(200.0), Overrides::default()),
        with("kn/10", &softer(10.0), Overrides::default()),
        with("kn/100", &softer(100.0), Overrides::default()),
        with("skin=0.05", &|_| {}, skin(0.05)),
        with("skin=0.2", &|_| {}, skin(0.2)),
        with(
            "1 thread",
            &|_| {},
            Overrides {
                threads: Some(1),
                ..Overrides::default()
            },
        ),
    ]
}

pub use cg::FIELDS;

/// Name of the row that repeats the reference's physics over the next stretch of time.
pub const REPLICA: &str = "replica (next stretch)";

/// Cost and accuracy of one variant.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub name: String,
    pub dt: f64,
    pub steps: u64,
    /// Wall time of the run (including its few saves), seconds.
    pub seconds: f64,
    /// Relative error of the free–free restitution coefficient.
    pub restitution_error: f64,
    /// χ²/dof of each profile of [`FIELDS`] against the reference (0 for the reference).
    pub chi2: [f64; 5],
    /// Final state hash; equal to the reference's when the variant changes no bit.
    pub hash: String,
}

impl Outcome {
    /// Simulated time per wall-clock second.
    pub fn time_per_second(&self) -> f64 {
        self.steps as f64 * self.dt / self.seconds
    }
}

/// Runs every variant of `base` from `state` for `time` time units with `saves` saves each
/// (written under `out/VARIANT/`), and the replica of the reference from the reference's last
/// save, coarse-grains all their saves, and compares them with the reference's; the
/// restitution is measured on the two spheres of `pair` (a `spheres` case) under each variant's
/// material and law.
pub fn run(
    base: &Case,
    pair: &Case,
    state: &Path,
    time: f64,
    saves: u64,
    out: &Path,
) -> anyhow::Result<Vec<Outcome>> {
    let mut runs = Vec::new();
    let mut all = variants(base);
    // the replica runs after the reference, from its last save
    let replica = Variant {
        name: REPLICA.into(),
        ..all[0].clone()
    };
    all.insert(1, replica);
    let mut replica_start: Option<std::path::PathBuf> = None;
    for v in all {
        let dt = v.case.dt();
        let steps = ((time / dt / saves as f64).round() as u64).max(1) * saves;
        let start = match &replica_start {
            Some(path) if v.name == REPLICA => path.as_path(),
            _ => state,
        };
        let mut e = engine::build(
            &v.case,
            crate::scene::build(&v.case, Some(start))?,
            &v.overrides,
        );
        let dir = out.join(v.name.replace(['/', ' ', '=', '(', ')'], "_"));
        let summary = run::run(
            e.as_mut(),
            &RunOptions {
                end_step: steps,
                save_every: steps / saves,
                checkpoint_every: 0,
                out_dir: dir.clone(),
                name: v.case.name.clone(),
                tag: v.name.clone(),
                progress: false,
                write_saves: true,
                vtk: false,
                stop: None,
            },
            false,
        )?;
        if replica_start.is_none() {
            replica_start = Some(dir.join(format!("{}.data.{saves:04}", v.case.name)));
        }
        let mut o = CgOptions::for_case(&v.case);
        o.from = Some(0);
        o.blocks = (saves as usize / 4).clamp(2, 10);
        let profiles = cg::coarse_grain(&Series::find(&dir.join(&v.case.name))?, &o)?;
        let m = v.case.particle_mass();
        let e_ref = closed_form(&v.case, 0.5 * m).e;
        let per_tc = v.case.tc_free_free().unwrap_or(0.0) / dt;
        let mut two = pair.clone();
        two.contact = v.case.contact.clone();
        two.material = v.case.material.clone();
        let e = collide(&two, 1.0, false, per_tc)?.e;
        runs.push((
            Outcome {
                name: v.name,
                dt,
                steps,
                seconds: summary.seconds,
                restitution_error: (e - e_ref) / e_ref,
                chi2: [0.0; 5],
                hash: summary.hash,
            },
            profiles,
        ));
    }
    let reference = runs[0].1.clone();
    Ok(runs
        .into_iter()
        .map(|(mut o, p)| {
            for (f, (_, col)) in FIELDS.iter().enumerate() {
                o.chi2[f] = cg::chi2(&p, &reference, *col);
            }
            o
        })
        .collect())
}

/// The table as markdown: cost (steps, wall time, simulated time per second relative to the
/// reference) and accuracy (restitution error, χ²/dof per profile, bitwise identity).
pub fn markdown(outcomes: &[Outcome]) -> String {
    let mut s = String::from(
        "| variant | dt | steps | wall s | sim. time/s vs ref | e error | χ² vx | χ² ν | χ² T | χ² p | χ² τ | same bits as ref |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let reference = outcomes.first().map_or(1.0, Outcome::time_per_second);
    let ref_hash = outcomes.first().map(|o| o.hash.clone()).unwrap_or_default();
    for o in outcomes {
        s.push_str(&format!(
            "| {} | {:.3e} | {} | {:.1} | {:.2} | {:+.3e} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} |\n",
            o.name,
            o.dt,
            o.steps,
            o.seconds,
            o.time_per_second() / reference,
            o.restitution_error,
            o.chi2[0],
            o.chi2[1],
            o.chi2[2],
            o.chi2[3],
            o.chi2[4],
            if o.hash == ref_hash { "yes" } else { "no" }
        ));
    }
    s
}
