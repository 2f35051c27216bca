//! In-run averaging in a cross-run (`verdem cross … --inrun`): the peer and verdem average the
//! benchmark's profiles over the same steps, with the same accumulator
//! ([`crate::analysis::inrun::Inrun`]: the slices, kernel and definitions of `verdem cg`). The
//! peer dumps its contact forces and the positions of the spheres in contact every K steps and
//! all particles every KP steps ([`Peer::inrun_script`]); verdem reads each dump as a state
//! ([`Peer::read_sample`]) and adds it to the accumulator as it adds its own engine's state, so
//! every code's contact stress is coarse-grained by the same lines. The profiles of two codes
//! are then compared by their core means, each with its own per-field block error
//! ([`crate::analysis::difference`]).

use std::fmt::Write;
use std::path::Path;

use anyhow::{ensure, Context};

use super::{Peer, Run, Save};
use crate::analysis::cg::CgOptions;
use crate::analysis::difference::Difference;
use crate::analysis::inrun::{Inrun, InrunResult, Sampling};
use crate::io::{parse_fields, read_text, FormatError};
use crate::run::Observer;
use crate::state::Snapshot;
use crate::step::Engine;
use crate::Vec3;

/// The file of a peer's in-run folder with the walls' every-step mean forces
/// ([`read_wall_means`]).
pub const WALLS_FILE: &str = "walls.txt";

/// The columns of [`WALLS_FILE`].
const WALL_COLUMNS: [&str; 7] = [
    "step",
    "bottom fx",
    "bottom fy",
    "bottom fz",
    "top fx",
    "top fy",
    "top fz",
];

/// One line of [`WALLS_FILE`]: the walls' mean force over the K steps ending at `step`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallMean {
    /// Its line in the file (from 1).
    pub line: usize,
    pub step: u64,
    /// The mean over steps `step` − K + 1..=`step` of the force the free particles exert on the
    /// bottom [0] and top [1] wall spheres (force units).
    pub force: [Vec3; 2],
}

/// The walls' every-step mean forces of `path` ([`WALLS_FILE`]) written every `every` steps:
/// after `#` comment lines, one line per interval, the step s and the mean over steps
/// s − `every` + 1..=s of the force on the bottom wall's spheres (x, y, z), then the top wall's.
/// A line without seven finite numbers, a step that is not a whole multiple of `every`, or a
/// step other than the previous line's plus `every` is refused, naming the line and field.
pub fn read_wall_means(path: &Path, every: u64) -> Result<Vec<WallMean>, FormatError> {
    let (file, text) = read_text(path)?;
    let err = |line: usize, msg: String| FormatError {
        file: file.clone(),
        line,
        msg,
    };
    let mut out: Vec<WallMean> = Vec::new();
    let mut v = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        parse_fields(&file, line, t, &WALL_COLUMNS, &mut v)?;
        if v.len() != WALL_COLUMNS.len() {
            return Err(err(
                line,
                format!(
                    "{} numbers, expected {} ({})",
                    v.len(),
                    WALL_COLUMNS.len(),
                    WALL_COLUMNS.join(", ")
                ),
            ));
        }
        let step = v[0];
        if step < 0.0 || step.fract() != 0.0 || step > u64::MAX as f64 {
            return Err(err(
                line,
                format!("column 1 (step): {step} is not a step number"),
            ));
        }
        let step = step as u64;
        // after the last step number that can be followed, none is expected (`Some(None)`)
        let expected = out.last().map(|m| m.step.checked_add(every));
        if expected.is_some_and(|e| e != Some(step)) || !step.is_multiple_of(every.max(1)) {
            return Err(err(
                line,
                format!(
                    "column 1 (step): step {step}, expected {} (a mean every {every} steps)",
                    match expected {
                        None => format!("a multiple of {every}"),
                        Some(Some(e)) => e.to_string(),
                        Some(None) => "none: the step numbers end".into(),
                    }
                ),
            ));
        }
        out.push(WallMean {
            line,
            step,
            force: [Vec3::new(v[1], v[2], v[3]), Vec3::new(v[4], v[5], v[6])],
        });
    }
    Ok(out)
}

/// The sampling of a cross-run of `steps` steps: contact stress and wall forces every `every`
/// steps, particle fields every `particle_every` steps (a multiple of `every`), at steps
/// 1..=`steps`.
pub fn sampling(steps: u64, every: u64, particle_every: u64) -> Sampling {
    Sampling {
        every,
        particle_every,
        from: 0,
        to: steps,
    }
}

/// The in-run profiles of `peer`'s run `run` (made by [`Peer::inrun_script`] with the
/// intervals of `sampling`): its sample at every sampling step, read as a state of `template`
/// ([`Peer::read_sample`]), added to an accumulator of the coarse-graining `o`, with the walls'
/// every-step means of its [`WALLS_FILE`] when the peer writes one ([`Peer::writes_wall_means`]) (else the wall forces are
/// those at the contact samples), its errors with the benchmark's reference τ at the time step
/// `dt` ([`Inrun::with_reference_tau`]). A file of means that lacks an interval of the window is
/// refused, naming it.
pub fn peer_profiles(
    peer: &dyn Peer,
    run: &Run,
    o: &CgOptions,
    template: &Snapshot,
    sampling: Sampling,
    dt: f64,
) -> anyhow::Result<InrunResult> {
    let mut acc = Inrun::new(o, &template.domain, sampling)?.with_reference_tau(dt);
    if peer.writes_wall_means() {
        let file = run.dir.join(WALLS_FILE);
        book_wall_means(&mut acc, &file, &read_wall_means(&file, sampling.every)?)?;
    }
    let first = (sampling.from / sampling.every + 1) * sampling.every;
    for step in (first..=sampling.to).step_by(sampling.every as usize) {
        let particles = step.is_multiple_of(sampling.particle_every);
        let s = peer
            .read_sample(
                run,
                Save::every(sampling.every, step / sampling.every),
                template,
                particles,
            )
            .with_context(|| format!("{}: in-run sample at step {step}", peer.name()))?;
        acc.sample(&s, particles);
    }
    acc.result().with_context(|| {
        format!(
            "{}: no in-run sample of both particles and contacts in steps {}..={}",
            peer.name(),
            sampling.from + 1,
            sampling.to
        )
    })
}

/// Books the walls' means `means` of `file` ([`read_wall_means`]) into `acc`
/// ([`Inrun::book_wall_mean`]): those of the intervals inside its window, which must all be
/// there.
fn book_wall_means(acc: &mut Inrun, file: &Path, means: &[WallMean]) -> anyhow::Result<()> {
    let s = acc.sampling();
    let booked = means
        .iter()
        .filter(|m| acc.book_wall_mean(m.step, s.every, m.force))
        .count() as u64;
    let needed = s.to / s.every - s.from.div_ceil(s.every);
    let last = means.last().map_or("no line of means".to_string(), |m| {
        format!("line {}: column 1 (step): the last step {}", m.line, m.step)
    });
    ensure!(
        booked == needed,
        "{}: {last}; {booked} means of {} steps in steps {}..={}, the in-run window needs {needed}",
        file.display(),
        s.every,
        s.from + 1,
        s.to
    );
    Ok(())
}

/// Advances `e` by `steps` steps, stopping at the steps `observer` asks for and showing it the
/// engine there, its forces evaluated (as `verdem run` does: the observer first looks at the
/// step it starts from, where an in-run accumulator marks the walls' impulse, and takes the
/// contact samples the engine took inside its steps at every stop); where it stops does not
/// change the steps.
pub fn advance_observed(
    e: &mut dyn Engine,
    steps: u64,
    observer: &mut dyn Observer,
) -> anyhow::Result<()> {
    e.sample_contacts_every(observer.contact_every());
    e.take_contact_samples();
    observer.start(e);
    let end = e.state().step + steps;
    while e.state().step < end {
        let step = e.state().step;
        let next = observer.next_after(step).map_or(end, |s| s.min(end));
        e.advance(next - step)?;
        observer.contacts(&e.take_contact_samples());
        if observer.next_after(next - 1) == Some(next) {
            if !e.state().forces_ready {
                e.advance(0)?;
            }
            observer.observe(e);
        }
    }
    e.sample_contacts_every(0);
    Ok(())
}

/// Comparisons as one markdown table: a row per profile of each comparison `(a, b,
/// differences of a from b)`.
pub fn markdown(rows: &[(String, String, Vec<Difference>)]) -> String {
    let mut s = String::from(
        "Core slices (z in [3, 19]); each core mean ± its standard error from the series of \
         the core mean, no τ below the benchmark's core reference (in-run averaging, \
         docs/statistics.md); Δ = A − B with its 95 % interval (Student's t, \
         Welch's degrees of freedom); real = the interval excludes 0; χ²/dof of the profiles \
         over the core slices (1 = noise); the walls' mean x-force per area (on the wall \
         from the free spheres, the mean over every step: verdem's from its impulse, a peer's \
         from its walls.txt). \"errors not trusted\": a core mean whose run is shorter than \
         five of its correlation times (vx's: the bed's drift), whose interval says little.\n\n\
         | A | B | profile | A core mean | B core mean | Δ (95 % interval) | Δ / B | χ²/dof | real? |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (a, b, diffs) in rows {
        for d in diffs {
            let rel = if d.b.mean != 0.0 {
                format!("{:+.2} %", 100.0 * d.delta() / d.b.mean.abs())
            } else {
                "—".into()
            };
            let verdict = match (d.real(), d.errors_trusted()) {
                (true, true) => "**yes**",
                (false, true) => "no",
                (true, false) => "**yes** (errors not trusted)",
                (false, false) => "no (errors not trusted)",
            };
            let chi2 = if d.chi2.is_nan() {
                "—".to_string()
            } else {
                format!("{:.2}", d.chi2)
            };
            let _ = writeln!(
                s,
                "| {a} | {b} | {} | {:+.5e} ± {:.2e} | {:+.5e} ± {:.2e} | {:+.3e} ± {:.2e} | {rel} | {chi2} | {verdict} |",
                d.field,
                d.a.mean,
                d.a.se,
                d.b.mean,
                d.b.se,
                d.delta(),
                d.half_width(),
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_marks_real_differences_and_too_small_errors() {
        let mut d = Difference::of_pressure_means((1.0, 0.01, 10), (0.9, 0.01, 10));
        let md = markdown(&[("lmp".into(), "verdem".into(), vec![d.clone()])]);
        assert!(md.contains("| lmp | verdem | pressure |"), "{md}");
        assert!(md.contains("| +11.11 % |"), "{md}");
        assert!(md.ends_with("| **yes** |\n"), "{md}");
        d.a.long_enough = false;
        d.a.mean = 0.9;
        let md = markdown(&[("lmp".into(), "verdem".into(), vec![d])]);
        assert!(md.ends_with("| no (errors not trusted) |\n"), "{md}");
    }
}
