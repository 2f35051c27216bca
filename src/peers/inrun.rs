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

use anyhow::Context;

use super::Peer;
use crate::analysis::cg::CgOptions;
use crate::analysis::difference::Difference;
use crate::analysis::inrun::{Inrun, InrunResult, Sampling};
use crate::run::Observer;
use crate::state::Snapshot;
use crate::step::Engine;

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

/// The in-run profiles of `peer`'s run in `dir` (made by [`Peer::inrun_script`] with the
/// intervals of `sampling`): its sample at every sampling step, read as a state of `template`
/// ([`Peer::read_sample`]), added to an accumulator of the coarse-graining `o`.
pub fn peer_profiles(
    peer: &dyn Peer,
    dir: &Path,
    o: &CgOptions,
    template: &Snapshot,
    sampling: Sampling,
) -> anyhow::Result<InrunResult> {
    let mut acc = Inrun::new(o, &template.domain, sampling)?;
    let mut step = sampling.from;
    while let Some(next) = acc.next_after(step) {
        step = next;
        let particles = step.is_multiple_of(sampling.particle_every);
        let s = peer
            .read_sample(dir, step, template, particles)
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

/// Advances `e` by `steps` steps, stopping at the steps `observer` asks for and showing it the
/// engine there, its forces evaluated (as `verdem run` does); where it stops does not change
/// the steps.
pub fn advance_observed(
    e: &mut dyn Engine,
    steps: u64,
    observer: &mut dyn Observer,
) -> anyhow::Result<()> {
    let end = e.state().step + steps;
    while e.state().step < end {
        let step = e.state().step;
        let next = observer.next_after(step).map_or(end, |s| s.min(end));
        e.advance(next - step)?;
        if observer.next_after(next - 1) == Some(next) {
            if !e.state().forces_ready {
                e.advance(0)?;
            }
            observer.observe(e);
        }
    }
    Ok(())
}

/// Comparisons as one markdown table: a row per profile of each comparison `(a, b,
/// differences of a from b)`.
pub fn markdown(rows: &[(String, String, Vec<Difference>)]) -> String {
    let mut s = String::from(
        "Core slices (z in [3, 19]); each core mean ± its standard error from its own blocks \
         (in-run averaging, docs/statistics.md); Δ = A − B with its 95 % interval (Student's t, \
         Welch's degrees of freedom); real = the interval excludes 0; χ²/dof of the profiles \
         over the core slices (1 = noise); the walls' mean x-force per area (on the wall \
         from the free spheres: verdem's the mean over every step, from its impulse; a peer's \
         at the contact samples). \"errors too small\": a field whose blocks are shorter than \
         its correlation asks, whose interval is then too narrow.\n\n\
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
                (true, false) => "**yes** (errors too small)",
                (false, false) => "no (errors too small)",
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
        assert!(md.ends_with("| no (errors too small) |\n"), "{md}");
    }
}
