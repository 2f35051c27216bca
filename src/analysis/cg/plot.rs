//! The five benchmark profiles against z, with error bands, as a PNG.

use std::path::Path;

use anyhow::Context;
use plotters::prelude::*;

use super::table::Table;
use super::{Profiles, COLUMNS};

/// The TrueType font used for labels (Debian package `fonts-dejavu-core`).
pub const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Registers [`FONT`] as plotters' "sans-serif" (once per process).
pub fn register_font() -> anyhow::Result<()> {
    static DONE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        let bytes = std::fs::read(FONT)
            .map_err(|e| format!("{FONT}: {e} (install the Debian package fonts-dejavu-core)"))?;
        plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            Box::leak(bytes.into_boxed_slice()),
        )
        .map_err(|_| format!("{FONT}: not a usable font"))
    })
    .clone()
    .map_err(anyhow::Error::msg)
}

/// One panel: a column against z, with a band of ±2 standard errors.
pub struct Curve<'a> {
    pub label: &'a str,
    pub z: Vec<f64>,
    pub value: Vec<f64>,
    pub se: Vec<f64>,
}

/// The curves of the five benchmark panels for one table of profiles, labelled `label`.
pub fn benchmark_curves<'a>(t: &Table, label: &'a str) -> Vec<(String, Curve<'a>)> {
    let panels = [
        ("vx", "velocity vx"),
        ("nu", "volume fraction"),
        ("T", "granular temperature"),
        ("pressure", "pressure"),
        ("shear_xz", "shear stress xz"),
    ];
    panels
        .iter()
        .map(|(col, title)| {
            let c = COLUMNS.iter().position(|n| n == col).expect("known column");
            (
                title.to_string(),
                Curve {
                    label,
                    z: t.z.clone(),
                    value: t.mean.iter().map(|m| m[c]).collect(),
                    se: t.se.iter().map(|s| s[c]).collect(),
                },
            )
        })
        .collect()
}

/// Draws panels of curves (one or more codes per panel) into a PNG.
pub fn panels_png(panels: &[(String, Vec<Curve<'_>>)], path: &Path) -> anyhow::Result<()> {
    register_font()?;
    // Drawn beside the target, then written durably in its place (`io::atomic`): an
    // interrupted run or a full disk never leaves half a picture or the scratch file.
    let tmp = path.with_extension("part.png");
    let drawn = draw(panels, &tmp)
        .with_context(|| format!("{}: cannot draw", path.display()))
        .and_then(|()| {
            std::fs::read(&tmp).with_context(|| format!("{}: cannot read back", tmp.display()))
        });
    // the scratch file goes whatever happened; a failure to remove it is not the error to report
    let _ = std::fs::remove_file(&tmp);
    crate::io::atomic::write(path, &drawn?)
        .with_context(|| format!("{}: cannot write", path.display()))
}

fn draw(panels: &[(String, Vec<Curve<'_>>)], path: &Path) -> anyhow::Result<()> {
    let root = BitMapBackend::new(path, (360 * panels.len() as u32, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((1, panels.len()));
    let colours = [BLUE, RED, GREEN, MAGENTA, BLACK];
    for ((title, curves), area) in panels.iter().zip(areas.iter()) {
        let values = curves.iter().flat_map(|c| {
            c.value
                .iter()
                .zip(&c.se)
                .flat_map(|(v, s)| [v - 2.0 * s, v + 2.0 * s])
        });
        let (lo, hi) = extent(values).with_context(|| format!("panel {title}"))?;
        let x = axis_range(lo, hi).with_context(|| format!("panel {title}"))?;
        let (_, zmax) = extent(curves.iter().flat_map(|c| c.z.iter().copied()))
            .with_context(|| format!("panel {title}: z"))?;
        let zmax = zmax.max(0.0) + 0.5;
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 18))
            .margin(8)
            .x_label_area_size(36)
            .y_label_area_size(52)
            .build_cartesian_2d(x, 0.0..zmax)?;
        chart
            .configure_mesh()
            .x_labels(4)
            .y_desc("z")
            .label_style(("sans-serif", 13))
            .draw()?;
        for (c, colour) in curves.iter().zip(colours.iter().cycle()) {
            let band: Vec<(f64, f64)> =
                c.z.iter()
                    .zip(c.value.iter().zip(&c.se))
                    .map(|(z, (v, s))| (v - 2.0 * s, *z))
                    .chain(
                        c.z.iter()
                            .zip(c.value.iter().zip(&c.se))
                            .rev()
                            .map(|(z, (v, s))| (v + 2.0 * s, *z)),
                    )
                    .collect();
            chart.draw_series(std::iter::once(Polygon::new(band, colour.mix(0.25))))?;
            let line = chart.draw_series(LineSeries::new(
                c.value.iter().zip(&c.z).map(|(v, z)| (*v, *z)),
                colour,
            ))?;
            if !c.label.is_empty() {
                line.label(c.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
            }
        }
        if curves.iter().any(|c| !c.label.is_empty()) {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }
    }
    root.present()
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// The smallest and largest of `values` (in the values' units); an error naming the first
/// value that is NaN or infinite, or when there is none.
pub fn extent(values: impl IntoIterator<Item = f64>) -> anyhow::Result<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (k, v) in values.into_iter().enumerate() {
        anyhow::ensure!(v.is_finite(), "value {} is {v}: cannot draw it", k + 1);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    anyhow::ensure!(lo <= hi, "no value to draw");
    Ok((lo, hi))
}

/// The range of a linear axis that shows the values from `lo` to `hi` (in the values' units)
/// with a margin of 5 % of the width on each side: total and prompt for any input. A zero width
/// is widened to ± 5 % of the value (± 0.5 about 0), a width below a millionth of the values'
/// magnitude to that millionth (plotters' tick search needs a width well above the spacing of
/// the numbers there); a margin beyond the largest number is cut at it. An error, never a
/// range, for a bound that is NaN or infinite, and for values so far apart that the axis's
/// width is not a finite number.
pub fn axis_range(lo: f64, hi: f64) -> anyhow::Result<std::ops::Range<f64>> {
    anyhow::ensure!(
        lo.is_finite() && hi.is_finite(),
        "cannot draw an axis from {lo} to {hi}: not finite"
    );
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    let magnitude = lo.abs().max(hi.abs());
    let half = if hi == lo {
        if magnitude == 0.0 {
            0.5
        } else {
            0.05 * magnitude
        }
    } else {
        (0.5 * hi - 0.5 * lo).max(1e-6 * magnitude)
    };
    let centre = 0.5 * lo + 0.5 * hi;
    // a margin beyond the largest number is cut at it
    let (a, b) = (
        (centre - 1.1 * half).max(-f64::MAX),
        (centre + 1.1 * half).min(f64::MAX),
    );
    anyhow::ensure!(
        (b - a).is_finite() && b > a,
        "cannot draw an axis from {lo:e} to {hi:e}: its width is beyond the largest number"
    );
    Ok(a..b)
}

/// The five benchmark profiles of one run.
pub fn profiles_png(p: &Profiles, path: &Path) -> anyhow::Result<()> {
    overlay_png(&[("", &Table::of(p))], path)
}

/// The legend of a run's profiles from its saves, in [`run_png`].
pub const SAVES_LABEL: &str = "saves";

/// The legend of a run's in-run profiles, in [`run_png`].
pub const INRUN_LABEL: &str = "in-run";

/// A run's picture of what it knows: the five benchmark profiles from its saves and those it
/// averaged in the run (narrower bands for the stresses), each with its ±2 SE band, labelled
/// [`SAVES_LABEL`] and [`INRUN_LABEL`].
pub fn run_png(saves: &Table, inrun: &Table, path: &Path) -> anyhow::Result<()> {
    overlay_png(&[(SAVES_LABEL, saves), (INRUN_LABEL, inrun)], path)
}

/// The five benchmark profiles of several runs, one labelled curve per run in each panel.
pub fn overlay_png(runs: &[(&str, &Table)], path: &Path) -> anyhow::Result<()> {
    let mut panels: Vec<(String, Vec<Curve<'_>>)> = Vec::new();
    for (label, t) in runs {
        for (k, (title, curve)) in benchmark_curves(t, label).into_iter().enumerate() {
            if k == panels.len() {
                panels.push((title, Vec::new()));
            }
            panels[k].1.push(curve);
        }
    }
    panels_png(&panels, path)
}
