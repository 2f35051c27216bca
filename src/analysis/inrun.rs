//! In-run averaging: the coarse-grained raw fields of `verdem cg` (the same slices, kernels and
//! definitions, [`Raw::add_particle`] and [`Raw::add_contact`]) accumulated while a run
//! advances, from the engine's own contacts and forces rather than from saves: the contact
//! stress of the contacts alive every `every` steps, the mean force each wall receives over
//! every step (its impulse from the engine's ledger over the time; from a peer, the means over
//! every K steps it writes, [`Inrun::book_wall_mean`], else the force at the sampled steps),
//! and the particle fields every
//! `particle_every` steps. Samples go into bins of
//! consecutive steps (at most [`MAX_BINS`]; two neighbours merge when more would be needed), and
//! the bins are the series the profiles' standard errors are taken from, with blocks as long as
//! each field's own correlation ([`blocking::field_errors`]).

use std::path::{Path, PathBuf};

use anyhow::bail;

use crate::analysis::cg::blocking::{self, FieldErrors, Unit};
use crate::analysis::cg::fields::{derive, Grid, Raw};
use crate::analysis::cg::kernel::Kernel;
use crate::analysis::cg::{checks, core_range, table::Table, CgOptions, Profiles, COLUMNS, FIELDS};
use crate::analysis::stats::integrated_autocorrelation;
use crate::analysis::{Limit, Verdict};
use crate::case::Case;
use crate::contact::PairInput;
use crate::io::checkpoint::Reader;
use crate::io::{csv_table, read_text, FormatError};
use crate::run::Observer;
use crate::state::{Domain, SampledContact, Snapshot};
use crate::step::Engine;
use crate::Vec3;

/// Most bins kept: a run's samples are binned in at most this many bins of equal length.
pub const MAX_BINS: usize = 4096;

/// Most contact samples whose core means are kept one by one, for the contact stress's
/// autocorrelation time at the sampling interval.
pub const TRACE_SAMPLES: usize = 200_000;

/// Free–free contact durations tc between two contact-stress samples. A contact's force is a
/// pulse of duration tc, so the contact stress decorrelates within ~tc (a half sine gives an
/// integrated autocorrelation time 4tc/π²) and samples 8 tc apart are independent; closer
/// samples would carry more information per step, but each costs the engine a sample inside its
/// step, which at 8 tc stays a small fraction of the step's cost (docs/statistics.md; measured:
/// docs/performance.md).
pub const CONTACTS_PER_SAMPLE: f64 = 8.0;

/// Contact durations between two samples of the particle fields: they change on the time
/// between a particle's collisions, many contact durations (docs/statistics.md).
pub const CONTACTS_PER_PARTICLE_SAMPLE: f64 = 20.0;

/// The sampling intervals of `case`, in steps: `every` and `particle_every` when given, else
/// the contact stress every [`CONTACTS_PER_SAMPLE`] free–free contact durations and the
/// particle fields at the multiple of `every` nearest to [`CONTACTS_PER_PARTICLE_SAMPLE`]
/// durations (50 steps per duration when the case has none).
pub fn intervals(case: &Case, every: Option<u64>, particle_every: Option<u64>) -> (u64, u64) {
    let tc_steps = case.tc_free_free().map_or(50.0, |tc| tc / case.dt());
    let every = every.unwrap_or_else(|| (tc_steps * CONTACTS_PER_SAMPLE).round().max(1.0) as u64);
    let particle_every = particle_every.unwrap_or_else(|| {
        let target = CONTACTS_PER_PARTICLE_SAMPLE * tc_steps;
        ((target / every.max(1) as f64).round().max(1.0) as u64) * every
    });
    (every, particle_every)
}

/// The sampling of a run that starts at step `start` and ends at `end_step`, a save every
/// `save_every` steps, its folder's first save `first_save`: the steps of the saves `verdem cg`
/// averages by default (the second half of the run's saves, after the first save of that half),
/// at the intervals `every` and `particle_every` (steps).
fn second_half(
    (every, particle_every): (u64, u64),
    first_save: u64,
    start: u64,
    end_step: u64,
    save_every: u64,
) -> Sampling {
    let n = (end_step / save_every + 1).saturating_sub(first_save);
    let from = (first_save + n.div_ceil(2).min(n.saturating_sub(1))) * save_every;
    Sampling {
        every,
        particle_every,
        from: from.max(start),
        to: end_step,
    }
}

/// When to sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampling {
    /// Contact stress and wall forces at every step that is a multiple of this.
    pub every: u64,
    /// Particle fields at every step that is a multiple of this (a multiple of `every`).
    pub particle_every: u64,
    /// Samples are taken at steps in (`from`, `to`].
    pub from: u64,
    pub to: u64,
}

/// The accumulator of a run's in-run profiles; it is the run loop's [`Observer`].
pub struct Inrun {
    sampling: Sampling,
    grid: Grid,
    kernel: Kernel,
    walls: usize,
    density: f64,
    domain: Domain,
    area: f64,
    /// Steps per bin (a multiple of `particle_every`).
    bin_steps: u64,
    bins: Vec<Unit>,
    /// Per bin: the sum over its contact samples of the force of the free particles on the
    /// bottom [0] and top [1] wall spheres.
    wall: Vec<[Vec3; 2]>,
    /// Per bin: the impulse the free particles gave the bottom [0] and top [1] wall spheres
    /// over the steps it covers, divided by the time step (force × steps), and those steps;
    /// zero steps when the samples come without an engine or a peer's means.
    impulse: Vec<[Vec3; 2]>,
    impulse_steps: Vec<u64>,
    /// The step the engine was last observed at and the walls' impulse since its first step
    /// there ([`crate::step::Flows::wall_impulse`]).
    mark: Option<(u64, [Vec3; 2])>,
    /// The contact stress of the sample under way.
    scratch: Raw,
    /// Per contact sample (the first [`TRACE_SAMPLES`]): the core means of the contact pressure
    /// and of the contact σxz.
    trace: Vec<[f64; 2]>,
    free: usize,
    free_volume: f64,
    /// The time step, when the errors take no τ below the benchmark's reference
    /// ([`blocking::REFERENCE_TAU`]).
    reference_dt: Option<f64>,
}

impl Inrun {
    /// An accumulator for the saves' coarse-graining `o` (its slices, kernel, wall spheres,
    /// density and periodicity) of a run in `domain`. Refuses a `particle_every` that is not a
    /// multiple of `every`, or a zero interval.
    pub fn new(o: &CgOptions, domain: &Domain, sampling: Sampling) -> anyhow::Result<Inrun> {
        if sampling.every == 0 || sampling.particle_every == 0 {
            bail!("in-run sampling intervals must be at least 1 step");
        }
        if !sampling.particle_every.is_multiple_of(sampling.every) {
            bail!(
                "the particle fields' sampling interval ({}) must be a multiple of the contacts' \
                 ({})",
                sampling.particle_every,
                sampling.every
            );
        }
        let (domain, grid, kernel) = o.frame(domain.lo, domain.hi);
        let l = domain.lengths();
        Ok(Inrun {
            sampling,
            scratch: Raw::zeros(grid.n),
            grid,
            kernel,
            walls: o.walls,
            density: o.density,
            area: l.x * l.y,
            domain,
            bin_steps: sampling.particle_every,
            bins: Vec::new(),
            wall: Vec::new(),
            impulse: Vec::new(),
            impulse_steps: Vec::new(),
            mark: None,
            trace: Vec::new(),
            free: 0,
            free_volume: 0.0,
            reference_dt: None,
        })
    }

    /// The accumulator of the bumpy-shear run `opts` of `case` on `engine` (from its current
    /// step), its folder's first save `first_save`: the saves' window ([`second_half`]) at
    /// `intervals` (steps), the case's coarse-graining ([`CgOptions::for_case`]) and errors with
    /// the benchmark's reference τ ([`Inrun::with_reference_tau`]).
    pub fn for_run(
        case: &Case,
        engine: &dyn Engine,
        opts: &crate::run::RunOptions,
        intervals: (u64, u64),
        first_save: u64,
    ) -> anyhow::Result<Inrun> {
        let sampling = second_half(
            intervals,
            first_save,
            engine.state().step,
            opts.end_step,
            opts.save_every,
        );
        let o = CgOptions::for_case(case);
        Ok(Inrun::new(&o, &engine.state().domain, sampling)?.with_reference_tau(case.dt()))
    }

    /// When it samples.
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// The same accumulator whose errors take no τ below the bumpy-shear benchmark's reference
    /// ([`blocking::REFERENCE_TAU`], in time units; the run's time step is `dt`): one run of a
    /// few of its slow fluctuations measures their τ too small.
    pub fn with_reference_tau(mut self, dt: f64) -> Inrun {
        self.reference_dt = Some(dt);
        self
    }

    /// Adds the sample of the state `snap` (its step in the window, its forces evaluated) to
    /// the bin of its step: the contact stress and wall forces, and the particle fields when
    /// `particles`. Samples must come in the order of their steps, each in (`from`, `to`].
    pub fn sample(&mut self, snap: &Snapshot, particles: bool) {
        if particles {
            let b = self.bin_of(snap.step);
            let p = &snap.particles;
            let (grid, kernel, area, density) = (&self.grid, self.kernel, self.area, self.density);
            let unit = &mut self.bins[b];
            for i in self.walls..p.x.len() {
                unit.sum
                    .add_particle(p.x[i].z, p.v[i], p.radius[i], density, grid, kernel, area);
            }
            unit.particle_samples += 1;
            self.free = p.x.len().saturating_sub(self.walls);
            self.free_volume = p.radius[self.walls.min(p.x.len())..]
                .iter()
                .map(|r| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
                .sum();
        }
        self.sample_contacts(snap.step, &snap.sampled_contacts());
    }

    /// Adds the contacts alive at `step` (in the window; in the order of a snapshot's) to the bin
    /// of the step: their contact stress, and the force of those with a wall sphere on its wall.
    pub fn sample_contacts(&mut self, step: u64, contacts: &[SampledContact]) {
        let b = self.bin_of(step);
        let (grid, kernel, area) = (&self.grid, self.kernel, self.area);
        self.scratch.contact.fill(Default::default());
        let mid = 0.5 * (self.domain.lo.z + self.domain.hi.z);
        for c in contacts {
            let (wall_a, wall_o) = (c.p < self.walls as u32, c.i < self.walls as u32);
            if wall_a && wall_o {
                continue;
            }
            // The contact point exactly as the force pass and the .fstat rows have it.
            let Some(g) = (PairInput::at_rest(
                self.domain.min_image(c.x[0] - c.x[1]),
                c.radius[0],
                c.radius[1],
            ))
            .kinematics() else {
                continue;
            };
            let point = c.x[0] + g.arm_p;
            // As `verdem cg`: f on the lower-indexed free particle, the branch from the
            // partner's centre (free–free) or from the contact point (free–wall) to it.
            let (x, f, start) = match (wall_a, wall_o) {
                (false, false) => (c.x[0], c.force.f, c.x[1]),
                (false, true) => (c.x[0], c.force.f, point),
                _ => (c.x[1], -c.force.f, point),
            };
            let branch = self.domain.min_image(x - start);
            self.scratch.add_contact(x.z, branch, f, grid, kernel, area);
            if wall_a || wall_o {
                let w = if wall_a { c.x[0] } else { c.x[1] };
                self.wall[b][usize::from(w.z > mid)] -= f;
            }
        }
        let unit = &mut self.bins[b];
        for (sum, s) in unit.sum.contact.iter_mut().zip(&self.scratch.contact) {
            *sum += s;
        }
        unit.contact_samples += 1;
        let core = core_range(&self.grid);
        if self.trace.len() < TRACE_SAMPLES && !core.is_empty() {
            let n = core.len() as f64;
            let (mut pressure, mut shear) = (0.0, 0.0);
            for k in core {
                pressure += self.scratch.contact[k].trace() / 3.0;
                shear += self.scratch.contact[k][(0, 2)];
            }
            self.trace.push([pressure / n, shear / n]);
        }
    }

    /// The bin of `step` (in (`from`, `to`]), made with the bins before it if it is new.
    fn bin_of(&mut self, step: u64) -> usize {
        let mut b = ((step - self.sampling.from - 1) / self.bin_steps) as usize;
        while b >= MAX_BINS {
            self.merge_neighbours();
            b = ((step - self.sampling.from - 1) / self.bin_steps) as usize;
        }
        while self.bins.len() <= b {
            self.bins.push(Unit::empty(self.grid.n));
            self.wall.push([Vec3::zeros(); 2]);
            self.impulse.push([Vec3::zeros(); 2]);
            self.impulse_steps.push(0);
        }
        b
    }

    /// Books the walls' impulse since the engine was last observed into the bin of its
    /// current step, and marks that step.
    fn book_impulse(&mut self, engine: &dyn Engine) {
        let now = (engine.state().step, engine.flows().wall_impulse());
        if let Some((before, at_before)) = self.mark {
            if now.0 > before {
                let b = self.bin_of(now.0);
                let dt = engine.params().dt;
                for g in 0..2 {
                    self.impulse[b][g] += (now.1[g] - at_before[g]) / dt;
                }
                self.impulse_steps[b] += now.0 - before;
            }
        }
        self.mark = Some(now);
    }

    /// Books the walls' mean force over the `steps` steps ending at step `step` (s − steps + 1..s;
    /// `mean`: the force the free particles exert on the bottom [0] and top [1] wall spheres,
    /// averaged over those steps, in the run's force units) into the bin of `step`, as
    /// [`Inrun::observe`] books the engine's impulse over the same steps: `steps` × `mean` to
    /// the bin's impulse sum, `steps` to its steps. Only an interval inside the window
    /// (`from`, `to`] is booked; returns whether it was.
    pub fn book_wall_mean(&mut self, step: u64, steps: u64, mean: [Vec3; 2]) -> bool {
        let s = self.sampling;
        if steps == 0 || step > s.to || step < s.from.saturating_add(steps) {
            return false;
        }
        let b = self.bin_of(step);
        for (j, m) in self.impulse[b].iter_mut().zip(mean) {
            *j += m * steps as f64;
        }
        self.impulse_steps[b] += steps;
        true
    }

    /// Halves the number of bins: bins 2j and 2j + 1 become bin j, twice as long.
    fn merge_neighbours(&mut self) {
        let bins = std::mem::take(&mut self.bins);
        let wall = std::mem::take(&mut self.wall);
        let impulse = std::mem::take(&mut self.impulse);
        let steps = std::mem::take(&mut self.impulse_steps);
        for (k, pair) in bins.chunks(2).enumerate() {
            let mut u = pair[0].clone();
            let (mut f, mut j, mut n) = (wall[2 * k], impulse[2 * k], steps[2 * k]);
            if let Some(second) = pair.get(1) {
                u.merge(second);
                for g in 0..2 {
                    f[g] += wall[2 * k + 1][g];
                    j[g] += impulse[2 * k + 1][g];
                }
                n += steps[2 * k + 1];
            }
            self.bins.push(u);
            self.wall.push(f);
            self.impulse.push(j);
            self.impulse_steps.push(n);
        }
        self.bin_steps *= 2;
    }

    /// The profiles of the samples so far, with their per-field errors and the averaging
    /// facts; `None` before the first sample of both the particles and the contacts.
    pub fn result(&self) -> Option<InrunResult> {
        let kept: Vec<usize> = (0..self.bins.len())
            .filter(|&b| self.bins[b].particle_samples > 0 && self.bins[b].contact_samples > 0)
            .collect();
        if kept.is_empty() {
            return None;
        }
        let units: Vec<Unit> = kept.iter().map(|&b| self.bins[b].clone()).collect();
        // The walls' every-step mean forces when the engine's impulse covers every bin kept.
        let every_step = kept.iter().all(|&b| self.impulse_steps[b] > 0);
        let floor = match self.reference_dt {
            Some(dt) => {
                let s = self.sampling;
                let (k, kp) = (s.every as f64 * dt, s.particle_every as f64 * dt);
                blocking::Floor::inrun(self.bin_steps as f64 * dt, k, kp)
            }
            None => blocking::Floor::none(),
        };
        let errors = blocking::field_errors_with_floor(&units, &self.grid, &floor);
        let blocks = blocking::common_blocks(&errors);
        let all = blocking::merged(&units);
        let col = |name: &str| COLUMNS.iter().position(|c| *c == name).expect("column");
        let tau_energy = ["kin_xx", "kin_yy", "kin_zz"]
            .iter()
            .map(|c| errors.tau[col(c)])
            .fold(f64::NAN, f64::max);
        let profiles = Profiles {
            grid: self.grid.clone(),
            kernel: self.kernel,
            saves: kept.iter().map(|&b| b as u64).collect(),
            blocks,
            mean: derive(&all.mean()),
            block_columns: blocking::block_columns(&units, blocks),
            se: errors.se.clone(),
            per_save: units.iter().map(Unit::mean).collect(),
            wall_force: kept
                .iter()
                .map(|&b| {
                    if every_step {
                        let n = self.impulse_steps[b] as f64;
                        [self.impulse[b][0] / n, self.impulse[b][1] / n]
                    } else {
                        let n = self.bins[b].contact_samples as f64;
                        [self.wall[b][0] / n, self.wall[b][1] / n]
                    }
                })
                .collect(),
            wall_force_every_step: every_step,
            domain: self.domain.clone(),
            free: self.free,
            free_volume: self.free_volume,
            tau_shear: errors.tau[col("shear_xz")],
            tau_energy,
            trusted: errors.calibrated.clone(),
        };
        let trace_tau = |k: usize| {
            let x: Vec<f64> = self.trace.iter().map(|t| t[k]).collect();
            integrated_autocorrelation(&x)
        };
        Some(InrunResult {
            sampling: self.sampling,
            bin_steps: self.bin_steps,
            contact_samples: all.contact_samples,
            particle_samples: all.particle_samples,
            contact_tau: [trace_tau(0), trace_tau(1)],
            trace_len: self.trace.len(),
            density: self.density,
            profiles,
            units,
            errors,
        })
    }
}

/// The run loop stops at `from`, where the walls' impulse starts to count, and at each particle
/// sample after it (the end of a bin), where the impulse since the last stop is booked; the
/// engine takes the contact samples between them inside its runs.
impl Observer for Inrun {
    fn next_after(&self, step: u64) -> Option<u64> {
        let s = self.sampling;
        if step < s.from {
            return Some(s.from);
        }
        let next = (step / s.particle_every + 1) * s.particle_every;
        (next <= s.to).then_some(next)
    }

    fn contact_every(&self) -> u64 {
        self.sampling.every
    }

    /// Books the contact samples in the window but those of a particle sample's step, which
    /// [`Inrun::observe`] takes with the particles.
    fn contacts(&mut self, samples: &[(u64, Vec<SampledContact>)]) {
        let s = self.sampling;
        for (step, contacts) in samples {
            if *step > s.from && *step <= s.to && !step.is_multiple_of(s.particle_every) {
                self.sample_contacts(*step, contacts);
            }
        }
    }

    /// Marks the walls' impulse where the run starts in the window, unless a checkpoint's
    /// sums brought their mark (the ledgers' sums continue from the checkpoint too).
    fn start(&mut self, engine: &dyn Engine) {
        let step = engine.state().step;
        if self.mark.is_none() && step >= self.sampling.from && step < self.sampling.to {
            self.book_impulse(engine);
        }
    }

    fn observe(&mut self, engine: &dyn Engine) {
        let step = engine.state().step;
        if step < self.sampling.from || step > self.sampling.to {
            return;
        }
        self.book_impulse(engine);
        if step == self.sampling.from {
            return;
        }
        if step.is_multiple_of(self.sampling.particle_every) {
            self.sample(&engine.snapshot(), true);
        }
    }

    /// The sums so far ([`Inrun::restore`] reads them back). Layout (little-endian u64 and
    /// f64): a format number, the frame as `key=value` lines ([`Inrun::frame_tag`]), the
    /// sampling (every, particle_every, from, to), the steps per bin, the bins (each: its
    /// particle and contact sample counts, then per grid point ν, ρ, momentum, kinetic flux and
    /// contact stress, then the two sampled wall-force sums, the two walls' impulse sums and
    /// the steps they cover), the trace (its length and pairs), the free particles' count and
    /// volume, and the impulse mark (0, or 1 then its step and the two walls' impulse).
    fn state(&self) -> Vec<u8> {
        let mut b = Vec::new();
        let u = |b: &mut Vec<u8>, v: u64| b.extend_from_slice(&v.to_le_bytes());
        let f = |b: &mut Vec<u8>, v: f64| b.extend_from_slice(&v.to_le_bytes());
        u(&mut b, STATE_FORMAT);
        let frame = self.frame_tag();
        u(&mut b, frame.len() as u64);
        b.extend_from_slice(frame.as_bytes());
        let s = self.sampling;
        for v in [s.every, s.particle_every, s.from, s.to, self.bin_steps] {
            u(&mut b, v);
        }
        u(&mut b, self.bins.len() as u64);
        for (k, (unit, wall)) in self.bins.iter().zip(&self.wall).enumerate() {
            u(&mut b, unit.particle_samples);
            u(&mut b, unit.contact_samples);
            let sum = &unit.sum;
            for k in 0..self.grid.n {
                let values = [sum.nu[k], sum.rho[k]]
                    .into_iter()
                    .chain(sum.momentum[k].iter().copied())
                    .chain(sum.flux[k].iter().copied())
                    .chain(sum.contact[k].iter().copied());
                for v in values {
                    f(&mut b, v);
                }
            }
            for v in wall.iter().chain(&self.impulse[k]).flat_map(|w| w.iter()) {
                f(&mut b, *v);
            }
            u(&mut b, self.impulse_steps[k]);
        }
        u(&mut b, self.trace.len() as u64);
        for v in self.trace.iter().flatten() {
            f(&mut b, *v);
        }
        u(&mut b, self.free as u64);
        f(&mut b, self.free_volume);
        match self.mark {
            None => u(&mut b, 0),
            Some((step, impulse)) => {
                u(&mut b, 1);
                u(&mut b, step);
                for v in impulse.iter().flat_map(|w| w.iter()) {
                    f(&mut b, *v);
                }
            }
        }
        b
    }
}

/// The format number of [`Inrun`]'s state in a checkpoint.
const STATE_FORMAT: u64 = 1;

impl Inrun {
    /// What the sums depend on besides the sampling, as `key=value` lines: the slices, the
    /// kernel, the wall spheres, the density and the area (f64 written to round-trip).
    fn frame_tag(&self) -> String {
        let g = &self.grid;
        format!(
            "slices={}\nz0={:?}\nz1={:?}\nkernel={:?}\nwall spheres={}\ndensity={:?}\narea={:?}",
            g.n, g.z0, g.z1, self.kernel, self.walls, self.density, self.area
        )
    }

    /// Continues from the sums `bytes` ([`Observer::state`]) that a checkpoint of the same run
    /// at step `step` holds, from byte `at` of `file`: afterwards the accumulator is the one the
    /// run that wrote the checkpoint had there, and the result is `None`. Sums taken in another
    /// frame (slices, kernel, wall spheres, density, area), at other intervals or over another
    /// window than this run's (a run resumed with another `--steps` averages another second
    /// half; this run's window starts at the resume when it is past the checkpoint's start)
    /// are not taken: the accumulator is left as it was and the result says why. Malformed
    /// sums are refused, naming the file and the byte.
    pub fn restore(
        &mut self,
        file: &str,
        at: usize,
        bytes: &[u8],
        step: u64,
    ) -> anyhow::Result<Option<String>> {
        let mut r = Reader::new(file, bytes, at, "in-run sums of the checkpoint");
        let what = |w: &'static str| move || format!("in-run sums: {w}");
        let format = r.u64()?;
        if format != STATE_FORMAT {
            bail!(
                "{file}: byte {at}: in-run sums of format {format}, this verdem reads format \
                 {STATE_FORMAT}"
            );
        }
        let len = r.count(bytes.len(), &what("frame length"))?;
        let frame = String::from_utf8_lossy(r.take(len)?).to_string();
        let ours = self.frame_tag();
        if frame != ours {
            let differs: Vec<String> = ours
                .lines()
                .zip(frame.lines().chain(std::iter::repeat("(none)")))
                .filter(|(a, b)| a != b)
                .map(|(a, b)| {
                    let (key, value) = a.split_once('=').unwrap_or((a, ""));
                    let theirs = b.split_once('=').map_or(b, |(_, v)| v);
                    format!("{key} {theirs}, this run's {value}")
                })
                .collect();
            let differs = if differs.is_empty() {
                vec![format!("frame {frame:?}, this run's {ours:?}")]
            } else {
                differs
            };
            return Ok(Some(format!(
                "in-run sums of another coarse-graining: {}",
                differs.join("; ")
            )));
        }
        let mut taken = [0u64; 5];
        for v in &mut taken {
            *v = r.u64()?;
        }
        let [every, particle_every, from, to, bin_steps] = taken;
        let s = self.sampling;
        let mut differs = Vec::new();
        if every != s.every {
            differs.push(format!(
                "contact samples every {every} steps, this run every {} (--inrun-every)",
                s.every
            ));
        }
        if particle_every != s.particle_every {
            differs.push(format!(
                "particle samples every {particle_every} steps, this run every {} \
                 (--inrun-particle-every)",
                s.particle_every
            ));
        }
        if to != s.to {
            differs.push(format!(
                "samples up to step {to}, this run up to step {} (--steps)",
                s.to
            ));
        }
        if from.max(step) != s.from {
            differs.push(format!(
                "samples after step {from}, this run after step {} (the saves' second half)",
                s.from
            ));
        }
        if !differs.is_empty() {
            return Ok(Some(format!(
                "in-run sums taken otherwise than this run takes them: {}",
                differs.join("; ")
            )));
        }
        if bin_steps == 0 || !bin_steps.is_multiple_of(particle_every) {
            bail!(
                "{file}: in-run sums: {bin_steps} steps per bin, not a multiple of the particle \
                 samples' {particle_every}"
            );
        }
        let n = self.grid.n;
        let bins = r.count(MAX_BINS, &what("bin count"))?;
        let mut units = Vec::with_capacity(bins);
        let mut wall = Vec::with_capacity(bins);
        let (mut impulse, mut impulse_steps) = (Vec::with_capacity(bins), Vec::with_capacity(bins));
        for b in 0..bins {
            let mut unit = Unit::empty(n);
            unit.particle_samples = r.u64()?;
            unit.contact_samples = r.u64()?;
            let here =
                |q: &'static str, k: usize| move || format!("in-run sums: bin {b}, point {k}: {q}");
            let sum = &mut unit.sum;
            for k in 0..n {
                sum.nu[k] = r.f64(&here("nu", k))?;
                sum.rho[k] = r.f64(&here("rho", k))?;
                sum.momentum[k] = r.vec(&here("momentum", k))?;
                for (q, m) in [
                    ("kinetic flux", &mut sum.flux[k]),
                    ("contact stress", &mut sum.contact[k]),
                ] {
                    for v in m.iter_mut() {
                        *v = r.f64(&here(q, k))?;
                    }
                }
            }
            let mut w = [Vec3::zeros(); 2];
            for (g, wg) in w.iter_mut().enumerate() {
                *wg = r.vec(&|| format!("in-run sums: bin {b}: force on wall {g}"))?;
            }
            let mut j = [Vec3::zeros(); 2];
            for (g, jg) in j.iter_mut().enumerate() {
                *jg = r.vec(&|| format!("in-run sums: bin {b}: impulse on wall {g}"))?;
            }
            impulse_steps.push(r.u64()?);
            units.push(unit);
            wall.push(w);
            impulse.push(j);
        }
        let len = r.count(TRACE_SAMPLES, &what("trace length"))?;
        let mut trace = Vec::with_capacity(len);
        for _ in 0..len {
            trace.push([r.f64(&what("trace"))?, r.f64(&what("trace"))?]);
        }
        let free = r.count(usize::MAX, &what("free particles"))?;
        let free_volume = r.f64(&what("free volume"))?;
        let mark = match r.u64()? {
            0 => None,
            1 => {
                let step = r.u64()?;
                let bottom = r.vec(&what("walls' impulse at the mark"))?;
                let top = r.vec(&what("walls' impulse at the mark"))?;
                Some((step, [bottom, top]))
            }
            flag => bail!("{file}: in-run sums: impulse mark flag {flag}, expected 0 or 1"),
        };
        r.end()?;
        self.sampling.from = from;
        self.bin_steps = bin_steps;
        self.bins = units;
        self.wall = wall;
        self.impulse = impulse;
        self.impulse_steps = impulse_steps;
        self.mark = mark;
        self.trace = trace;
        self.free = free;
        self.free_volume = free_volume;
        Ok(None)
    }
}

/// In-run profiles and how they were averaged.
#[derive(Clone, Debug)]
pub struct InrunResult {
    pub sampling: Sampling,
    /// Steps per bin at the end.
    pub bin_steps: u64,
    pub contact_samples: u64,
    pub particle_samples: u64,
    /// Integrated autocorrelation time, in contact samples, of the core means of the contact
    /// pressure [0] and contact σxz [1], over the first `trace_len` samples.
    pub contact_tau: [f64; 2],
    pub trace_len: usize,
    /// Particle density (for the kinetic-theory check).
    pub density: f64,
    /// The profiles: `saves` holds bin numbers, `per_save` and `wall_force` the bins' means.
    pub profiles: Profiles,
    pub errors: FieldErrors,
    /// The bins the profiles were averaged from.
    pub units: Vec<Unit>,
}

/// Path of the in-run profiles of the run `name` in `dir`.
pub fn csv_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.profiles_inrun.csv"))
}

/// Path of the in-run profiles' error table ([`blocking::errors_csv`]) of the run `name` in `dir`.
pub fn errors_csv_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.profiles_inrun_errors.csv"))
}

/// The in-run profiles' error table: per column, its τ (measured, reference, used), blocks and
/// how its error was taken, and its core mean with its error ([`blocking::errors_csv`]).
pub fn errors_csv(r: &InrunResult) -> String {
    let core = blocking::core_means(&r.units, &r.profiles.grid, &r.errors);
    blocking::errors_csv(&r.errors, r.units.len(), &core)
}

/// Per benchmark profile of [`FIELDS`], the core mean and its own standard error in an error
/// table written by [`errors_csv`]; `None` when the table has no core columns (an error table
/// written by a verdem older than those columns). A missing row, or a core mean or error that is not a finite
/// number, is refused, naming the file, the line and the field.
pub fn read_core_means(path: &Path) -> Result<Option<Vec<(f64, f64)>>, FormatError> {
    let (file, text) = read_text(path)?;
    let fail = |line: usize, msg: String| FormatError {
        file: file.clone(),
        line,
        msg,
    };
    let mut records = csv_table::records(&file, &text, false);
    let Some((_, header)) = records.next().transpose()? else {
        return Err(fail(0, "empty: no header".into()));
    };
    let at = |name: &str| header.iter().position(|h| h == name);
    let (Some(mean_at), Some(se_at)) = (at("core_mean"), at("core_se")) else {
        return Ok(None);
    };
    let rows = records.collect::<Result<Vec<_>, _>>()?;
    FIELDS
        .iter()
        .map(|&(field, col)| {
            let column = COLUMNS[col];
            let (line, row) = rows
                .iter()
                .find(|(_, r)| r.get(0) == Some(column))
                .ok_or_else(|| fail(0, format!("no row of column {column} ({field})")))?;
            let value = |at: usize, name: &str| {
                let cell = row.get(at).unwrap_or_default();
                cell.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        fail(
                            *line,
                            format!("field {name} of {column}: not a finite number: {cell:?}"),
                        )
                    })
            };
            Ok((value(mean_at, "core_mean")?, value(se_at, "core_se")?))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// The in-run profiles as CSV: the columns of `NAME.profiles.csv`.
pub fn csv(r: &InrunResult) -> String {
    Table::of(&r.profiles).csv()
}

/// The in-run part of `checks.txt`: how the samples were taken, each field's autocorrelation
/// time and blocks, the checks of the in-run profiles, and the core means of the pressure and
/// shear stress beside those of the saves (`saves`, with the saves' own per-field errors
/// `save_errors`), with the ratio of their standard errors. Also returns their verdicts, in the
/// report's order: the in-run checks (case `in-run`), the core means (case `saves vs in-run`).
pub fn report(
    r: &InrunResult,
    saves: &Profiles,
    save_errors: &FieldErrors,
) -> (String, Vec<Verdict>) {
    let s = r.sampling;
    let p = &r.profiles;
    let mut out = format!(
        "\nin-run averaging: steps {}..{} (after {}), contact stress and wall forces every {} \
         steps ({} samples), particle fields every {} steps ({} samples), {} bins of {} steps; \
         autocorrelation time of the core contact stress over its first {} samples: {} \
         samples (pressure), {} (shear)\n",
        s.from + 1,
        s.to,
        s.from,
        s.every,
        r.contact_samples,
        s.particle_every,
        r.particle_samples,
        p.saves.len(),
        r.bin_steps,
        r.trace_len,
        blocking::shown(r.contact_tau[0]),
        blocking::shown(r.contact_tau[1]),
    );
    out.push_str("per-field errors of the saves (tau in saves):\n");
    out.push_str(&blocking::describe(save_errors, saves.saves.len(), "saves"));
    out.push_str(&format!(
        "per-field errors in-run (tau in bins of {} steps{}):\n",
        r.bin_steps,
        if r.errors.floor.iter().any(|&f| f > 0.0) {
            "; no tau below the benchmark's reference, docs/statistics.md"
        } else {
            ""
        }
    ));
    out.push_str(&blocking::describe(&r.errors, p.saves.len(), "bins"));
    if r.errors.floor.iter().any(|&f| f > 0.0) {
        out.push_str(blocking::SLOW_MODE_NOTE);
    }
    out.push_str("checks of the in-run profiles:\n");
    let in_run_checks = checks::run(p, r.density);
    let report = checks::report(p, &in_run_checks);
    let mut verdicts: Vec<Verdict> = in_run_checks
        .into_iter()
        .map(|c| Verdict {
            case: "in-run".into(),
            ..c
        })
        .collect();
    // The first line of the saves' report speaks of saves; the in-run one is above, and the
    // in-run series is one of bins.
    for line in report.lines().skip(1) {
        out.push_str(&line.replace(" saves", " bins"));
        out.push('\n');
    }
    out.push_str(
        "core means, saves vs in-run, each with its error from the series of its core mean \
         (no tau below the core's reference, docs/statistics.md), judged equal within 3 \
         combined SE:\n",
    );
    if core_range(&p.grid).is_empty() {
        return (out, verdicts);
    }
    let save_units: Vec<Unit> = saves.per_save.iter().cloned().map(Unit::of_save).collect();
    let of_saves = blocking::core_means(&save_units, &saves.grid, save_errors);
    let in_run = blocking::core_means(&r.units, &p.grid, &r.errors);
    for name in ["nu", "T", "pressure", "shear_xz", "con_xz", "con_zz"] {
        let c = COLUMNS.iter().position(|x| *x == name).expect("column");
        let (s, i) = (of_saves[c], in_run[c]);
        let (a, sa, b, sb) = (s.mean, s.se, i.mean, i.se);
        let tol = 3.0 * (sa * sa + sb * sb).sqrt();
        let verdict = Verdict::judge(
            "",
            name,
            a - b,
            Limit::Absolute {
                expected: 0.0,
                tolerance: tol,
            },
        )
        .judged_if(s.long_enough && i.long_enough);
        let shown = match verdict.pass() {
            Some(true) => "PASS",
            Some(false) => "FAIL",
            None => "info",
        };
        let ratio = if sb > 0.0 {
            format!("{:.1}", sa / sb)
        } else {
            "undefined".into()
        };
        out.push_str(&format!(
            "{shown:4}  {name:9} saves {a:+.5} +- {sa:.2e} ({:.1} dof)   in-run {b:+.5} +- \
             {sb:.2e} ({:.1} dof)   SE ratio {ratio}\n",
            s.dof, i.dof
        ));
        verdicts.push(Verdict {
            case: "saves vs in-run".into(),
            ..verdict
        });
    }
    (out, verdicts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn core_means_are_read_back_from_the_error_table_or_refused_naming_line_and_field() {
        let dir = std::env::temp_dir().join(format!("verdem_core_means_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.profiles_inrun_errors.csv");
        let header = "column,tau_measured,tau_reference,tau_used,blocks,degrees_of_freedom,\
                      method,core_mean,core_se,core_degrees_of_freedom,core_trusted";
        // one row per benchmark profile, its core mean k + 1 and error (k + 1)/100, in another
        // order than FIELDS', with a column the reader does not need between them
        let rows = ["pressure", "rho", "shear_xz", "T", "nu", "vx"]
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{c},1,1,1,5,4,tau,{}e0,{}e-2,9.0,true", k + 1, k + 1))
            .collect::<Vec<_>>()
            .join("\n");
        std::fs::write(&path, format!("{header}\n{rows}\n")).unwrap();
        let got = read_core_means(&path).unwrap().unwrap();
        // FIELDS: vx, nu, T, pressure, shear
        assert_eq!(
            got,
            vec![
                (6.0, 0.06),
                (5.0, 0.05),
                (4.0, 0.04),
                (1.0, 0.01),
                (3.0, 0.03)
            ]
        );
        // a table written before the core columns: none
        std::fs::write(&path, "column,tau_measured\nnu,1\n").unwrap();
        assert_eq!(read_core_means(&path).unwrap(), None);
        // an empty core mean (what the writer leaves for a non-finite one) is refused
        let bad = rows.replace("T,1,1,1,5,4,tau,4e0", "T,1,1,1,5,4,tau,");
        std::fs::write(&path, format!("{header}\n{bad}\n")).unwrap();
        let e = read_core_means(&path).unwrap_err().to_string();
        assert!(
            e.contains(":5: field core_mean of T: not a finite number"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A wall mean is booked as the engine's impulse over the same steps would be: into the bin
    /// of its last step, K times the mean with K steps, and only when all its steps are in
    /// (`from`, `to`].
    #[test]
    fn a_wall_mean_is_booked_only_inside_the_window_into_its_last_steps_bin() {
        let domain = Domain::new(
            Vec3::zeros(),
            Vec3::new(20.0, 20.0, 22.0),
            [true, true, false],
        );
        let sampling = Sampling {
            every: 10,
            particle_every: 20,
            from: 100,
            to: 200,
        };
        let mut acc = Inrun::new(&CgOptions::default(), &domain, sampling).unwrap();
        let mean = [Vec3::new(1.0, 2.0, -3.0), Vec3::new(-0.5, 0.0, 4.0)];
        // steps 91..=100 end at `from`, 96..=105 start before it, 201..=210 end after `to`
        assert!(!acc.book_wall_mean(100, 10, mean));
        assert!(!acc.book_wall_mean(105, 10, mean));
        assert!(!acc.book_wall_mean(210, 10, mean));
        assert!(!acc.book_wall_mean(150, 0, mean));
        assert!(acc.bins.is_empty());
        // the first steps after `from` and the last ones up to `to`: bins 0 and 4 of 20 steps
        assert!(acc.book_wall_mean(110, 10, mean));
        assert!(acc.book_wall_mean(120, 10, mean));
        assert!(acc.book_wall_mean(200, 10, mean));
        assert_eq!(acc.impulse_steps, vec![20, 0, 0, 0, 10]);
        for g in 0..2 {
            assert_eq!(acc.impulse[0][g], mean[g] * 20.0);
            assert_eq!(acc.impulse[4][g], mean[g] * 10.0);
            assert_eq!(acc.impulse[2][g], Vec3::zeros());
        }
        // one interval of the whole window
        let mut whole = Inrun::new(&CgOptions::default(), &domain, sampling).unwrap();
        assert!(whole.book_wall_mean(200, 100, mean));
        assert_eq!(whole.impulse_steps, vec![0, 0, 0, 0, 100]);
    }
}
