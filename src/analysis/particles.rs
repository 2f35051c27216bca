//! A picture of the particles of one save: a side view of the box (x to the right, z up, seen
//! along +y), each sphere a disc of its radius coloured by its velocity vx on a diverging colour
//! map with a colour bar, wall spheres grey. Nearer spheres (smaller y) are drawn over farther
//! ones. The PNG's bytes depend only on the save (no time stamp, no randomness).

use std::path::Path;

use anyhow::Context;
use plotters::prelude::*;

use super::cg::plot::register_font;
use crate::io::vtk::Particle;
use crate::Vec3;

/// Size of the picture in pixels (width, height).
pub const SIZE: (u32, u32) = (1000, 900);

/// Width of the colour bar's panel on the right (pixels).
const BAR_PANEL: u32 = 130;

/// Grey of the wall spheres.
const WALL: RGBColor = RGBColor(150, 150, 150);

/// Moreland's cool-warm diverging map (K. Moreland, "Diverging Color Maps for Scientific
/// Visualization", ISVC 2009, table of the map in 8-bit RGB) at 0, 1/4, 1/2, 3/4 and 1,
/// interpolated linearly between them: blue for negative, light grey for 0, red for positive.
const COOL_WARM: [[f64; 3]; 5] = [
    [59.0, 76.0, 192.0],
    [141.0, 176.0, 254.0],
    [221.0, 221.0, 221.0],
    [244.0, 154.0, 123.0],
    [180.0, 4.0, 38.0],
];

/// The colour of `s` ∈ [0, 1] (clamped) on [`COOL_WARM`].
fn cool_warm(s: f64) -> RGBColor {
    let at = s.clamp(0.0, 1.0) * 4.0;
    let k = (at.floor() as usize).min(3);
    let f = at - k as f64;
    let c =
        |j: usize| (COOL_WARM[k][j] + f * (COOL_WARM[k + 1][j] - COOL_WARM[k][j])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// The velocity that gets the map's ends: the wall spheres' largest |vx| (the shear cell's wall
/// speed), or the free spheres' largest |vx| when the walls are at rest; 1 when everything is.
/// Faster spheres get the end colours.
pub fn colour_scale(particles: &[Particle]) -> f64 {
    let largest = |wall: bool| {
        particles
            .iter()
            .filter(|p| p.wall == wall && p.v.x.is_finite())
            .fold(0.0_f64, |m, p| m.max(p.v.x.abs()))
    };
    let (walls, free) = (largest(true), largest(false));
    if walls > 0.0 {
        walls
    } else if free > 0.0 {
        free
    } else {
        1.0
    }
}

/// Draws the side view of `particles` in the box `lo`..`hi` with the caption `title` and writes
/// it as a PNG of [`SIZE`] to `path` (atomically, [`crate::io::atomic::write`]).
pub fn particles_png(
    particles: &[Particle],
    lo: &Vec3,
    hi: &Vec3,
    title: &str,
    path: &Path,
) -> anyhow::Result<()> {
    register_font()?;
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    draw(particles, lo, hi, title, &mut rgb)
        .with_context(|| format!("{}: cannot draw", path.display()))?;
    let mut png = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png, w, h);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder
            .write_header()
            .with_context(|| format!("{}: cannot encode", path.display()))?;
        writer
            .write_image_data(&rgb)
            .with_context(|| format!("{}: cannot encode", path.display()))?;
    }
    Ok(crate::io::atomic::write(path, &png)?)
}

fn draw(
    particles: &[Particle],
    lo: &Vec3,
    hi: &Vec3,
    title: &str,
    rgb: &mut [u8],
) -> anyhow::Result<()> {
    let (w, h) = SIZE;
    let root = BitMapBackend::with_buffer(rgb, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let (view, bar) = root.split_horizontally(w - BAR_PANEL);
    // Equal scales on both axes: the box, widened along one axis to fill the plotting area.
    let (margin, x_labels, y_labels) = (10, 40, 50);
    let (view_w, view_h) = view.dim_in_pixel();
    let plot_w = f64::from(view_w - 2 * margin - y_labels);
    let plot_h = f64::from(view_h - 2 * margin - x_labels);
    let (lx, lz) = ((hi.x - lo.x).max(1e-12), (hi.z - lo.z).max(1e-12));
    let scale = (plot_w / lx).min(plot_h / lz);
    let (cx, cz) = (0.5 * (lo.x + hi.x), 0.5 * (lo.z + hi.z));
    let (half_x, half_z) = (0.5 * plot_w / scale, 0.5 * plot_h / scale);
    let axes = (cx - half_x..cx + half_x, cz - half_z..cz + half_z);
    anyhow::ensure!(
        [&axes.0, &axes.1]
            .iter()
            .all(|r| (r.end - r.start).is_finite() && r.end > r.start),
        "the box {:?}..{:?} gives axes that are not finite: cannot draw it",
        lo.as_slice(),
        hi.as_slice()
    );
    let mut chart = ChartBuilder::on(&view)
        .margin(margin)
        .x_label_area_size(x_labels)
        .y_label_area_size(y_labels)
        .build_cartesian_2d(axes.0, axes.1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x")
        .y_desc("z")
        .label_style(("sans-serif", 15))
        .draw()?;
    let outline = |a: f64, b: f64, c: f64, d: f64| {
        PathElement::new(
            vec![(a, c), (b, c), (b, d), (a, d), (a, c)],
            BLACK.stroke_width(1),
        )
    };
    chart.draw_series(std::iter::once(outline(lo.x, hi.x, lo.z, hi.z)))?;
    let vmax = colour_scale(particles);
    let mut order: Vec<&Particle> = particles
        .iter()
        .filter(|p| p.x.iter().all(|c| c.is_finite()) && p.radius.is_finite())
        .collect();
    // far to near along the line of sight (+y), so the nearer sphere covers the farther one
    order.sort_by(|a, b| b.x.y.total_cmp(&a.x.y));
    for p in order {
        let r = (p.radius * scale).round().max(1.0) as u32;
        let fill = if p.wall {
            WALL
        } else {
            cool_warm(0.5 + 0.5 * p.v.x / vmax)
        };
        let centre = (p.x.x, p.x.z);
        chart.draw_series([
            Circle::new(centre, r, fill.filled()),
            Circle::new(centre, r, RGBColor(60, 60, 60).stroke_width(1)),
        ])?;
    }
    colour_bar(&bar, vmax, h)?;
    root.present()?;
    Ok(())
}

/// The colour bar: the map from −`vmax` (bottom) to +`vmax` (top), labelled, and the key of the
/// wall spheres' grey.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    vmax: f64,
    height: u32,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let (x0, x1) = (20, 50);
    let (top, bottom) = (60, (height as i32) - 200);
    let steps = bottom - top;
    for k in 0..steps {
        let s = 1.0 - f64::from(k) / f64::from(steps - 1);
        area.draw(&Rectangle::new(
            [(x0, top + k), (x1, top + k + 1)],
            cool_warm(s).filled(),
        ))?;
    }
    area.draw(&Rectangle::new(
        [(x0, top), (x1, bottom)],
        BLACK.stroke_width(1),
    ))?;
    let style = ("sans-serif", 15).into_font().color(&BLACK);
    area.draw(&Text::new("vx", (x0, top - 30), style.clone()))?;
    for (label, y) in [
        (format!("{:+.3}", vmax), top),
        ("0".to_string(), (top + bottom) / 2),
        (format!("{:+.3}", -vmax), bottom),
    ] {
        area.draw(&PathElement::new(
            vec![(x1, y), (x1 + 5, y)],
            BLACK.stroke_width(1),
        ))?;
        area.draw(&Text::new(label, (x1 + 8, y - 7), style.clone()))?;
    }
    let key = bottom + 40;
    area.draw(&Circle::new((x0 + 10, key), 10, WALL.filled()))?;
    area.draw(&Circle::new(
        (x0 + 10, key),
        10,
        RGBColor(60, 60, 60).stroke_width(1),
    ))?;
    area.draw(&Text::new("wall", (x0 + 28, key - 8), style))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_runs_from_blue_through_grey_to_red() {
        let (RGBColor(r0, _, b0), RGBColor(r1, g1, b1), RGBColor(r2, _, b2)) =
            (cool_warm(0.0), cool_warm(0.5), cool_warm(1.0));
        assert!(b0 > r0 && r2 > b2);
        assert!(r1 == g1 && g1 == b1);
        assert_eq!(cool_warm(-3.0), cool_warm(0.0));
        assert_eq!(cool_warm(7.0), cool_warm(1.0));
    }
}
