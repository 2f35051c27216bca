//! The cost plot: the cost per particle-step against the particles, on log axes, drawn from a
//! sweep's measurements or from its `bench.csv` read back.

use std::path::Path;

use anyhow::Context;

use super::sweep::{ns_per_particle_step, processes, AtSize};

/// One line of the cost plot: its label (code, process count) and its points (particles, ns
/// per particle-step).
pub type CostLine = (String, Vec<(f64, f64)>);

/// Draws the cost per particle-step (ns) against the particles, both on log axes, one line per
/// code and process count (verdem's ceiling rows left out), into the PNG `path`.
pub fn cost_png(sizes: &[AtSize], path: &Path) -> anyhow::Result<()> {
    let Some(first) = sizes.first() else {
        anyhow::bail!("{}: no sizes to plot", path.display());
    };
    let lines: Vec<CostLine> = (0..first.measured.len())
        .filter(|&k| processes(&first.measured[k].config).is_some())
        .map(|k| {
            let (code, n) = first.measured[k].config.label();
            let points = sizes
                .iter()
                .map(|at| {
                    let m = &at.measured[k];
                    (
                        at.particles as f64,
                        ns_per_particle_step(m.median(), at.particles),
                    )
                })
                .filter(|(_, c)| c.is_finite() && *c > 0.0)
                .collect();
            (format!("{code}, {n}"), points)
        })
        .collect();
    draw_cost(&lines, path)
}

/// The lines of the cost plot from a sweep's `bench.csv` (columns `code`, `procs`, `particles`
/// and `ns_per_particle_step`, one row per configuration and size, as [`csv`] writes them), in
/// the order the rows name them; the ceiling rows (processes `2×1`) are left out, as in
/// [`cost_png`]. A missing column or a field that is not a positive number is an error that
/// names the file, the line and the field.
pub fn cost_lines(path: &Path) -> Result<Vec<CostLine>, crate::io::FormatError> {
    let (file, text) = crate::io::read_text(path)?;
    let fail = |line: usize, msg: String| crate::io::FormatError {
        file: file.clone(),
        line,
        msg,
    };
    let mut records = crate::io::csv_table::records(&file, &text, false);
    let Some((_, header)) = records.next().transpose()? else {
        return Err(fail(0, "empty: no header".into()));
    };
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| fail(1, format!("no column {name}")))
    };
    let (code_at, procs_at) = (column("code")?, column("procs")?);
    let (n_at, ns_at) = (column("particles")?, column("ns_per_particle_step")?);
    let mut lines: Vec<CostLine> = Vec::new();
    for record in records {
        let (line, row) = record?;
        let cell = |at: usize| row.get(at).unwrap_or_default();
        let procs = cell(procs_at);
        if procs.contains('×') {
            continue;
        }
        let number = |at: usize, name: &str| {
            cell(at)
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| {
                    fail(
                        line,
                        format!("field {name}: not a positive number: {:?}", cell(at)),
                    )
                })
        };
        number(procs_at, "procs")?;
        let point = (
            number(n_at, "particles")?,
            number(ns_at, "ns_per_particle_step")?,
        );
        let label = format!("{}, {procs}", cell(code_at));
        match lines.iter_mut().find(|(l, _)| *l == label) {
            Some((_, points)) => points.push(point),
            None => lines.push((label, vec![point])),
        }
    }
    if lines.is_empty() {
        return Err(fail(0, "no row to plot".into()));
    }
    Ok(lines)
}

/// Draws `lines` (particles, ns per particle-step) on log axes into the PNG `path`.
pub fn draw_cost(lines: &[CostLine], path: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    crate::analysis::cg::plot::register_font()?;
    let all = || lines.iter().flat_map(|(_, p)| p.iter());
    let (nlo, nhi) = all().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    });
    let (clo, chi) = all().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.1), hi.max(p.1))
    });
    if !(nlo.is_finite() && clo.is_finite()) {
        anyhow::bail!("{}: no measured rate to plot", path.display());
    }
    // the log axes span a factor 1.5 beyond the points: both ends normal positive numbers
    for (what, lo, hi) in [("particles", nlo, nhi), ("ns per particle-step", clo, chi)] {
        anyhow::ensure!(
            lo / 1.5 >= f64::MIN_POSITIVE && (hi * 1.5).is_finite(),
            "{}: cannot draw {what} from {lo:e} to {hi:e} on a log axis",
            path.display()
        );
    }
    let colours = [
        BLUE,
        RED,
        GREEN,
        MAGENTA,
        BLACK,
        CYAN,
        RGBColor(230, 140, 0),
    ];
    let tmp = path.with_extension("part.png");
    let drawn = (|| -> anyhow::Result<Vec<u8>> {
        {
            let root = BitMapBackend::new(&tmp, (900, 600)).into_drawing_area();
            root.fill(&WHITE)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(
                    "cost per particle-step against system size",
                    ("sans-serif", 20),
                )
                .margin(12)
                .x_label_area_size(44)
                .y_label_area_size(64)
                .build_cartesian_2d(
                    (nlo / 1.5..nhi * 1.5)
                        .log_scale()
                        .with_key_points(one_two_five(nlo / 1.5, nhi * 1.5)),
                    (clo / 1.5..chi * 1.5)
                        .log_scale()
                        .with_key_points(one_two_five(clo / 1.5, chi * 1.5)),
                )?;
            chart
                .configure_mesh()
                .x_desc("particles")
                .y_desc("ns per particle-step")
                .x_label_formatter(&|v| format!("{v}"))
                .y_label_formatter(&|v| format!("{v}"))
                .label_style(("sans-serif", 13))
                .draw()?;
            for ((label, points), colour) in lines.iter().zip(colours.iter().cycle()) {
                chart
                    .draw_series(LineSeries::new(points.iter().copied(), colour))?
                    .label(label.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font(("sans-serif", 13))
                .draw()?;
            root.present()?;
        }
        std::fs::read(&tmp).with_context(|| format!("{}: cannot read back", tmp.display()))
    })();
    // the scratch file goes whatever happened; a failure to remove it is not the error to report
    let _ = std::fs::remove_file(&tmp);
    crate::io::atomic::write(path, &drawn?)
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// The values 1, 2 and 5 times a power of ten in `lo..=hi` (lo > 0): the labelled ticks of a log
/// axis, which has some in any range wider than a factor 2.5.
fn one_two_five(lo: f64, hi: f64) -> Vec<f64> {
    let mut decade = 10f64.powi(lo.log10().floor() as i32);
    let mut ticks = Vec::new();
    while decade <= hi {
        ticks.extend(
            [1.0, 2.0, 5.0]
                .map(|m| m * decade)
                .into_iter()
                .filter(|v| (lo..=hi).contains(v)),
        );
        decade *= 10.0;
    }
    ticks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::fixtures::two_sizes;

    #[test]
    fn cost_lines_group_a_sweeps_rows_by_code_and_processes_and_name_a_bad_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bench.csv");
        let header = "code,procs,median_steps_per_s,particles,ns_per_particle_step";
        let rows = [
            "verdem (deterministic),1,80000,3480,3.6",
            "verdem (deterministic),2,99000,3480,2.9",
            "2 independent verdem runs at once (summed),2×1,150000,3480,1.9",
            "lammps,2,10000,3480,28.3",
            "verdem (deterministic),1,800,222720,5.6",
            "verdem (deterministic),2,1500,222720,3.0",
            "lammps,2,210,222720,21.3",
        ];
        std::fs::write(&path, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
        let lines = cost_lines(&path).unwrap();
        let expected: Vec<CostLine> = vec![
            (
                "verdem (deterministic), 1".into(),
                vec![(3480.0, 3.6), (222720.0, 5.6)],
            ),
            (
                "verdem (deterministic), 2".into(),
                vec![(3480.0, 2.9), (222720.0, 3.0)],
            ),
            ("lammps, 2".into(), vec![(3480.0, 28.3), (222720.0, 21.3)]),
        ];
        assert_eq!(lines, expected);
        let bad = rows.map(|r| r.replace("lammps,2,210,222720,21.3", "lammps,2,210,222720,"));
        std::fs::write(&path, format!("{header}\n{}\n", bad.join("\n"))).unwrap();
        let e = cost_lines(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("bench.csv:8: field ns_per_particle_step: not a positive number: \"\""),
            "{e}"
        );
        std::fs::write(&path, "code,procs,particles\nlammps,1,3480\n").unwrap();
        let e = cost_lines(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("bench.csv:1: no column ns_per_particle_step"),
            "{e}"
        );
    }

    #[test]
    fn a_log_axis_is_labelled_at_one_two_and_five_times_powers_of_ten() {
        assert_eq!(one_two_five(1.4, 60.0), [2.0, 5.0, 10.0, 20.0, 50.0]);
        assert_eq!(
            one_two_five(2320.0, 334080.0),
            [5e3, 1e4, 2e4, 5e4, 1e5, 2e5]
        );
        assert_eq!(one_two_five(1.0, 1.9), [1.0]);
    }

    #[test]
    fn the_cost_plot_is_a_png_of_the_stated_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cost.png");
        cost_png(&two_sizes(), &path).unwrap();
        let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let info = decoder.read_info().unwrap().info().clone();
        assert_eq!((info.width, info.height), (900, 600));
        assert!(!dir.path().join("cost.part.png").exists());
    }
}
