//! Cross-runs: a peer and verdem on the same case, from the same state, for the same steps,
//! compared particle by particle at every save.
//!
//! verdem runs with the peer's tangential convention ([`Peer::convention`]: LAMMPS `granular …
//! linear_history` → `lammps-granular`, LIGGGHTS `tangential history` → `liggghts`), so that
//! the two codes integrate the same equations; what remains is the summation order of forces,
//! so the trajectories agree to round-off at first and part by chaos later. The step at which
//! the largest position difference first exceeds 1e-6 measures that onset. Both series are
//! written as MercuryCG `.data`/`.fstat` saves (the peer's contact forces from its contact
//! dumps), coarse-grained by verdem into `PEER.profiles.csv` and `verdem.profiles.csv`,
//! overlaid in `profiles.png`, and compared profile by profile (χ²/dof). A peer without contact
//! forces (Kratos DEM: [`Peer::read_contacts`] says it lacks them) is compared particle by
//! particle only; its
//! normal force is clipped, so verdem's is too ([`Peer::clips_normal_force`]).
//!
//! With in-run averaging ([`super::inrun`]) the peer also dumps its samples every K and KP
//! steps, verdem in the peer's convention and verdem in the case's own convention average the
//! same steps, and the three codes' profiles are compared by their core means with 95 %
//! intervals.

use std::fmt::Write;
use std::path::Path;

use anyhow::{ensure, Context};

use super::inrun as peer_inrun;
use super::{lacks, Peer, Run, Save};
use crate::analysis::cg::{self, table::Table};
use crate::analysis::difference::{differences, Difference};
use crate::analysis::inrun::{self, InrunResult, Sampling};
use crate::analysis::stats::quantile;
use crate::analysis::{Limit, Verdict};
use crate::case::Case;
use crate::contact::Tangential;
use crate::io::atomic;
use crate::io::mercury::{data_text, fstat_text};
use crate::step::engine::{self, Overrides};

/// Largest, median and 99th-percentile value of a sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spread {
    pub max: f64,
    pub median: f64,
    pub p99: f64,
}

impl Spread {
    /// The spread of `v` (nearest-rank quantiles; all 0 for no values).
    fn of(v: &[f64]) -> Spread {
        Spread {
            max: quantile(v, 1.0),
            median: quantile(v, 0.5),
            p99: quantile(v, 0.99),
        }
    }
}

/// Differences of the peer from verdem at one save: |Δx| (minimum image), |Δv|, |Δω| over all
/// particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SaveDiff {
    pub step: u64,
    pub dx: Spread,
    pub dv: Spread,
    pub dw: Spread,
}

/// The in-run profiles of a cross-run, over the same steps.
#[derive(Clone, Debug)]
pub struct InrunReport {
    pub sampling: Sampling,
    /// The peer's, from its dumps.
    pub peer: InrunResult,
    /// verdem's in the peer's convention (the same equations).
    pub verdem_as_peer: InrunResult,
    /// verdem's in the case's own convention `own_convention`.
    pub verdem: InrunResult,
    pub own_convention: Tangential,
}

impl InrunReport {
    /// The comparisons of a cross-run `(A, B, differences of A from B)`: the peer against
    /// verdem in the case's convention, verdem in the peer's convention against verdem (what
    /// the convention changes), and the peer against verdem in its own convention (the same
    /// equations: a real difference there says the intervals are not honest).
    pub fn comparisons(&self, peer: &str) -> Vec<(String, String, Vec<Difference>)> {
        let own = format!("verdem ({})", self.own_convention.name());
        let as_peer = format!("verdem as {peer}");
        vec![
            (
                peer.to_string(),
                own.clone(),
                differences(&self.peer, &self.verdem),
            ),
            (
                as_peer.clone(),
                own,
                differences(&self.verdem_as_peer, &self.verdem),
            ),
            (
                peer.to_string(),
                as_peer,
                differences(&self.peer, &self.verdem_as_peer),
            ),
        ]
    }

    /// The sampling and the comparisons, as markdown.
    pub fn markdown(&self, peer: &str) -> String {
        let s = self.sampling;
        format!(
            "in-run averaging over steps {}..={}: contact stress and wall forces every {} \
             steps ({} samples), particle fields every {} steps ({} samples), bins of {} steps\n\n{}",
            s.from + 1,
            s.to,
            s.every,
            self.peer.contact_samples,
            s.particle_every,
            self.peer.particle_samples,
            self.peer.bin_steps,
            peer_inrun::markdown(&self.comparisons(peer))
        )
    }
}

/// A cross-run's outcome.
#[derive(Clone, Debug)]
pub struct Report {
    pub peer: &'static dyn Peer,
    pub np: usize,
    pub convention: Tangential,
    pub saves: Vec<SaveDiff>,
    /// χ²/dof of each profile of [`cg::FIELDS`] of the peer's series against verdem's (all
    /// saves coarse-grained, block standard errors); none when the peer gives no contact
    /// forces ([`Peer::read_contacts`] lacks them), without which its stresses are unknown.
    pub profiles_chi2: Option<[f64; 5]>,
    /// The in-run profiles, when asked for.
    pub inrun: Option<InrunReport>,
}

impl Report {
    /// The first save step whose largest position difference exceeds `threshold`.
    pub fn diverged_at(&self, threshold: f64) -> Option<u64> {
        self.saves
            .iter()
            .find(|s| s.dx.max > threshold)
            .map(|s| s.step)
    }

    /// The χ²/dof of each profile of [`cg::FIELDS`] against verdem's, as reported verdicts
    /// (≈ 1 when the two differ by noise only; the quantity is the profile's name, the case
    /// the peer's).
    pub fn profile_verdicts(&self) -> Vec<Verdict> {
        let Some(chi2) = self.profiles_chi2 else {
            return Vec::new();
        };
        cg::FIELDS
            .iter()
            .zip(chi2)
            .map(|((name, _), c)| Verdict::reported(self.peer.binary(), name, c, Limit::None))
            .collect()
    }

    /// The comparison as a markdown table with a summary line.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "{} ({} rank{}) against verdem with convention `{}`\n\n\
             | step | max dx | median dx | p99 dx | max dv | p99 dv | max dw |\n\
             |---|---|---|---|---|---|---|\n",
            self.peer.binary(),
            self.np,
            if self.np == 1 { "" } else { "s" },
            self.convention.name()
        );
        for d in &self.saves {
            let _ = writeln!(
                s,
                "| {} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} |",
                d.step, d.dx.max, d.dx.median, d.dx.p99, d.dv.max, d.dv.p99, d.dw.max
            );
        }
        let last = self.saves.last().map_or(0, |d| d.step);
        let _ = match self.diverged_at(1e-6) {
            Some(step) => writeln!(s, "\nlargest |dx| first exceeds 1e-6 at step {step}"),
            None => writeln!(s, "\nlargest |dx| stays within 1e-6 up to step {last}"),
        };
        let chi2: Vec<String> = self
            .profile_verdicts()
            .iter()
            .map(|v| format!("{} {:.2}", v.quantity, v.measured))
            .collect();
        let _ = if self.profiles_chi2.is_some() {
            writeln!(
                s,
                "profiles over all saves, chi2/dof against verdem (1 = noise): {}",
                chi2.join(", ")
            )
        } else {
            writeln!(
                s,
                "profiles not compared: {} gives no per-contact forces, so its stresses are unknown",
                self.peer.binary()
            )
        };
        if let Some(r) = &self.inrun {
            let _ = write!(s, "\n{}", r.markdown(self.peer.binary()));
        }
        s
    }
}

/// Runs `peer` on `np` processes and verdem (one thread per process, tangential `convention`,
/// normally [`Peer::convention`], the normal force clipped where the peer's is) on `case` from `state` for `steps` steps, a save every
/// `every` steps, in `out` (`out/PEER/` holds its data file, input script, dumps and converted
/// saves; `out/verdem/` verdem's saves). The peer's contacts in its saves are re-evaluated
/// at the end of the step and carry no tangential spring ([`Peer::read_contacts`]), so the
/// `.fstat`'s spring column reads 0.
#[allow(clippy::too_many_arguments)]
pub fn cross(
    peer: &'static dyn Peer,
    case: &Case,
    convention: Tangential,
    state: &Path,
    steps: u64,
    every: u64,
    np: usize,
    out: &Path,
) -> anyhow::Result<Report> {
    cross_inrun(peer, case, convention, state, steps, every, np, out, None)
}

/// [`cross`], and with `inrun` = (K, KP), the contact stress and wall forces every K steps and the particle
/// fields every KP steps (a multiple of K; K divides `every`) are averaged in-run over steps
/// 1..=`steps` by the peer (from its dumps; its particle dumps `particles.STEP.txt` are removed
/// once read), by verdem in `convention` and by verdem in `case`'s own convention (a third
/// run), and written as `PEER.profiles_inrun.csv`, `verdem.profiles_inrun.csv` and
/// `verdem_own.profiles_inrun.csv` in `out`, their comparison ([`InrunReport::markdown`]) as
/// `inrun.md`.
#[allow(clippy::too_many_arguments)]
pub fn cross_inrun(
    peer: &'static dyn Peer,
    case: &Case,
    convention: Tangential,
    state: &Path,
    steps: u64,
    every: u64,
    np: usize,
    out: &Path,
    inrun: Option<(u64, u64)>,
) -> anyhow::Result<Report> {
    ensure!(
        every > 0 && steps.is_multiple_of(every),
        "--every must divide --steps"
    );
    let sampling = inrun
        .map(|(k, kp)| {
            ensure!(
                k > 0 && kp > 0 && kp.is_multiple_of(k) && every.is_multiple_of(k),
                "in-run intervals: the contact interval ({k}) must be at least 1 and divide the \
                 particle interval ({kp}) and --every ({every})"
            );
            Ok(peer_inrun::sampling(steps, k, kp))
        })
        .transpose()?;
    let own_case = case;
    let mut case = case.clone();
    case.contact.tangential = convention.into();
    case.contact.clip_normal = peer.clips_normal_force();
    let overrides = Overrides {
        threads: Some(np),
        ..Overrides::default()
    };
    let mut e = engine::build(&case, crate::scene::build(&case, Some(state))?, &overrides)?;
    e.params_mut().setup_advances_history = peer.setup_advances_history();
    e.advance(0)?;
    let template = e.snapshot();
    let (peer_dir, own_dir) = (out.join(peer.binary()), out.join("verdem"));
    for d in [&peer_dir, &own_dir] {
        std::fs::create_dir_all(d).with_context(|| d.display().to_string())?;
    }
    let data = peer.write_state(&e.snapshot(), case.material.density, &peer_dir, "state")?;
    let script = match sampling {
        None => peer.input_script(&case, &data, steps, Some(every))?,
        Some(s) => peer
            .inrun_script(&case, &data, steps, every, s.every, s.particle_every)
            .with_context(|| format!("{} has no in-run dumps", peer.name()))??,
    };
    let run = Run { dir: &peer_dir, np };
    peer.run(&run, &script)?;
    let o = cg::CgOptions::for_case(&case);
    let mut own_inrun = sampling
        .map(|s| {
            inrun::Inrun::new(&o, &template.domain, s).map(|a| a.with_reference_tau(case.dt()))
        })
        .transpose()?;
    let mut saves = Vec::new();
    let mut with_forces = true;
    for k in 0..=steps / every {
        if k > 0 {
            match own_inrun.as_mut() {
                Some(acc) => peer_inrun::advance_observed(e.as_mut(), every, acc)?,
                None => e.advance(every)?,
            }
        }
        let own = e.snapshot();
        let name = format!("{}.data.{k:04}", case.name);
        atomic::write(&own_dir.join(&name), data_text(&own).as_bytes())?;
        let fstat = format!("{}.fstat.{k:04}", case.name);
        atomic::write(&own_dir.join(&fstat), fstat_text(&own).as_bytes())?;
        let save = Save::every(every, k);
        let frame = peer.read_frame(&run, save)?;
        ensure!(
            frame.x.len() == own.particles.len(),
            "{}: {} atoms, the state has {}",
            peer.binary(),
            frame.x.len(),
            own.particles.len()
        );
        let mut theirs = own.clone();
        theirs.contacts.clear();
        theirs.particles.x = frame.x;
        theirs.particles.v = frame.v;
        theirs.particles.w = frame.w;
        theirs.particles.radius = frame.radius;
        atomic::write(&peer_dir.join(&name), data_text(&theirs).as_bytes())?;
        if with_forces {
            match peer.read_contacts(&run, save, &theirs) {
                Ok(contacts) => {
                    theirs.contacts = contacts;
                    atomic::write(&peer_dir.join(&fstat), fstat_text(&theirs).as_bytes())?;
                }
                Err(e) if lacks(&e).is_some() => with_forces = false,
                Err(e) => return Err(e),
            }
        }
        let (a, b) = (&own.particles, &theirs.particles);
        let n = a.len();
        let diff = |f: &dyn Fn(usize) -> f64| Spread::of(&(0..n).map(f).collect::<Vec<_>>());
        saves.push(SaveDiff {
            step: k * every,
            dx: diff(&|i| own.domain.min_image(b.x[i] - a.x[i]).norm()),
            dv: diff(&|i| (b.v[i] - a.v[i]).norm()),
            dw: diff(&|i| (b.w[i] - a.w[i]).norm()),
        });
    }
    let inrun = match (sampling, own_inrun) {
        (Some(s), Some(acc)) => Some(InrunReport {
            sampling: s,
            peer: peer_profiles(peer, &run, &o, &template, s, case.dt())?,
            verdem_as_peer: acc.result().context("verdem: no in-run sample")?,
            verdem: own_profiles(own_case, state, np, s)?,
            own_convention: Tangential::of(own_case)?,
        }),
        _ => None,
    };
    if let Some(r) = &inrun {
        atomic::write(&out.join("inrun.md"), r.markdown(peer.binary()).as_bytes())?;
        for (name, result) in [
            (peer.binary(), &r.peer),
            ("verdem", &r.verdem_as_peer),
            ("verdem_own", &r.verdem),
        ] {
            atomic::write(&inrun::csv_path(out, name), inrun::csv(result).as_bytes())?;
        }
    }
    let mut o = o;
    o.from = Some(0);
    o.blocks = saves.len().div_ceil(4).clamp(2, 10);
    let series = |dir: &Path| cg::Series::find(&dir.join(&case.name));
    let own = cg::coarse_grain(&series(&own_dir)?, &o)?;
    let own_table = Table::of(&own);
    atomic::write(&out.join("verdem.profiles.csv"), own_table.csv().as_bytes())?;
    let profiles_chi2 = if with_forces {
        let theirs = cg::coarse_grain(&series(&peer_dir)?, &o)?;
        let their_table = Table::of(&theirs);
        atomic::write(
            &out.join(format!("{}.profiles.csv", peer.binary())),
            their_table.csv().as_bytes(),
        )?;
        cg::plot::overlay_png(
            &[(peer.binary(), &their_table), ("verdem", &own_table)],
            &out.join("profiles.png"),
        )?;
        Some(cg::FIELDS.map(|(_, col)| cg::chi2(&theirs, &own, col)))
    } else {
        None
    };
    let report = Report {
        peer,
        np,
        convention: Tangential::of(&case)?,
        saves,
        profiles_chi2,
        inrun,
    };
    atomic::write(&out.join("cross.md"), report.markdown().as_bytes())?;
    Ok(report)
}

/// The peer's in-run profiles from its dumps in `run`'s folder ([`peer_inrun::peer_profiles`]);
/// its particle dumps are removed once read (0.7 MB each on the benchmark).
fn peer_profiles(
    peer: &dyn Peer,
    run: &Run,
    o: &cg::CgOptions,
    template: &crate::state::Snapshot,
    s: Sampling,
    dt: f64,
) -> anyhow::Result<InrunResult> {
    let r = peer_inrun::peer_profiles(peer, run, o, template, s, dt)?;
    let dir = run.dir;
    for entry in std::fs::read_dir(dir).with_context(|| dir.display().to_string())? {
        let path = entry?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("particles.") && name.ends_with(".txt") {
            std::fs::remove_file(&path).with_context(|| path.display().to_string())?;
        }
    }
    Ok(r)
}

/// verdem's in-run profiles of `case` as given (its own convention and clipping), on `np`
/// threads, from `state`, sampled as `s`; no saves.
fn own_profiles(case: &Case, state: &Path, np: usize, s: Sampling) -> anyhow::Result<InrunResult> {
    let overrides = Overrides {
        threads: Some(np),
        ..Overrides::default()
    };
    let mut e = engine::build(case, crate::scene::build(case, Some(state))?, &overrides)?;
    e.advance(0)?;
    let mut acc = inrun::Inrun::new(&cg::CgOptions::for_case(case), &e.state().domain, s)?
        .with_reference_tau(case.dt());
    peer_inrun::advance_observed(e.as_mut(), s.to, &mut acc)?;
    acc.result().context("verdem: no in-run sample")
}
