//! `[scene]`: what is in the box, and its checks against the box and the material.

use serde::Deserialize;

use super::derived::sphere_volume;
use super::locate::Locator;
use super::{Case, CaseError};

/// `[scene]`: what is in the box.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Scene {
    /// Two hexagonal bumpy walls of glued spheres moving rigidly in x, and free spheres between.
    BumpyShear {
        /// Number of free spheres.
        free: usize,
        /// Rows of each wall (along y, spacing √3/2·d) and spheres per row (along x, spacing d).
        wall_rows: usize,
        wall_per_row: usize,
        /// Centre heights of the bottom and top wall spheres.
        bottom_z: f64,
        top_z: f64,
        /// Prescribed x velocities of the bottom and top wall.
        bottom_vx: f64,
        top_vx: f64,
    },
    /// An explicit list of spheres (verification cases).
    Spheres { sphere: Vec<SphereSpec> },
    /// A gas filling the whole box: `count` spheres placed without overlap (lattice and
    /// hard-sphere Monte Carlo, seeded by `run.seed`), velocities uniform random with the rms
    /// speed `speed` and zero total momentum, no spin.
    Gas { count: usize, speed: f64 },
}

/// One sphere of a `spheres` scene.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    pub x: [f64; 3],
    #[serde(default)]
    pub v: [f64; 3],
    #[serde(default)]
    pub w: [f64; 3],
    /// Radius (length; default half the material diameter). A fixed sphere of large radius
    /// stands in for a flat wall.
    #[serde(default)]
    pub radius: Option<f64>,
    /// Moved with its prescribed velocity, never integrated (infinite mass).
    #[serde(default)]
    pub fixed: bool,
}

impl Case {
    /// The box against the spheres, the walls against each other and the box, the number of
    /// spheres against the room the scene gives them, and the walls' prescribed velocities.
    pub(super) fn check_scene(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        let (lo, hi, periodic) = (self.domain.lo, self.domain.hi, self.domain.periodic);
        let d = self.material.diameter;
        let axis = ["x", "y", "z"];
        let (d_free, d_max) = self.largest_diameters();
        for k in 0..3 {
            let l = hi[k] - lo[k];
            // minimum image: no sphere may touch two images of one neighbour
            if periodic[k] && l <= 2.0 * d_max {
                return Err(at.error(
                    "domain.hi",
                    format!(
                        "a periodic length along {} above twice the largest sphere diameter \
                         ({}) expected, got {l}",
                        axis[k],
                        2.0 * d_max
                    ),
                ));
            }
            if !periodic[k] && l < d_free {
                return Err(at.error(
                    "domain.hi",
                    format!(
                        "a box at least one free sphere's diameter ({d_free}) long along {} \
                         expected, got {l}",
                        axis[k]
                    ),
                ));
            }
        }
        let generated = self.run.init.is_none();
        match &self.scene {
            Scene::BumpyShear {
                free,
                wall_rows,
                wall_per_row,
                bottom_z,
                top_z,
                bottom_vx,
                top_vx,
            } => {
                if *free == 0 {
                    return Err(at.error("scene.free", "must be > 0, got 0".into()));
                }
                if *wall_rows == 0 || *wall_per_row == 0 {
                    return Err(at.error(
                        "scene.wall_rows",
                        "walls need rows and spheres per row".into(),
                    ));
                }
                // rows along y at √3/2 d, spheres along x at d (scene::bumpy_wall): a wall
                // wider than the box overlaps itself across the periodic seam or leaves it
                let extent = [
                    ("wall_per_row", *wall_per_row as f64 * d),
                    ("wall_rows", *wall_rows as f64 * 3f64.sqrt() / 2.0 * d),
                ];
                for (k, (key, width)) in extent.into_iter().enumerate() {
                    let l = hi[k] - lo[k];
                    if width > l * (1.0 + 1e-9) {
                        return Err(at.error(
                            &format!("scene.{key}"),
                            format!(
                                "walls within the box: a width along {} of at most {l} \
                                 expected, got {width}",
                                axis[k]
                            ),
                        ));
                    }
                }
                // the free spheres need a gap of one diameter between the two walls' spheres
                if top_z - bottom_z < 2.0 * d {
                    return Err(at.error(
                        "scene.top_z",
                        format!(
                            "the walls' spheres must leave a free sphere's diameter between \
                             them: top_z >= bottom_z + 2 diameters = {} expected, got {top_z}",
                            bottom_z + 2.0 * d
                        ),
                    ));
                }
                for (key, z) in [("bottom_z", bottom_z), ("top_z", top_z)] {
                    if !periodic[2] && (*z < lo[2] || *z > hi[2]) {
                        return Err(at.error(
                            &format!("scene.{key}"),
                            format!(
                                "a wall inside the box, {} <= {key} <= {} expected, got {z}",
                                lo[2], hi[2]
                            ),
                        ));
                    }
                }
                for (key, vx) in [("bottom_vx", bottom_vx), ("top_vx", top_vx)] {
                    if *vx != 0.0 && !periodic[0] {
                        return Err(at.error(
                            &format!("scene.{key}"),
                            format!(
                                "the walls move along x, which must then be periodic: 0 \
                                 expected with domain.periodic = {periodic:?}, got {vx}"
                            ),
                        ));
                    }
                }
                if generated {
                    let n_wall = 2 * wall_rows * wall_per_row;
                    let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
                    // the walls' spheres reach half into the space between their centres
                    let room = area * (top_z - bottom_z) - n_wall as f64 * sphere_volume(d) / 2.0;
                    self.check_fill(
                        at,
                        "scene.free",
                        *free,
                        room,
                        (bottom_z + 0.5 * d, top_z - 0.5 * d),
                    )?;
                }
            }
            Scene::Gas { count, speed } => {
                if *count == 0 {
                    return Err(at.error("scene.count", "must be > 0, got 0".into()));
                }
                if *speed < 0.0 {
                    return Err(at.error("scene.speed", format!("must be >= 0, got {speed}")));
                }
                let room = (0..3).map(|k| hi[k] - lo[k]).product::<f64>();
                self.check_fill(
                    at,
                    "scene.count",
                    *count,
                    room,
                    (lo[2] + 0.5 * d, hi[2] - 0.5 * d),
                )?;
            }
            Scene::Spheres { sphere } => {
                if sphere.is_empty() {
                    return Err(at.error("scene.sphere", "needs at least one sphere".into()));
                }
                let end = self.run.steps as f64 * self.dt();
                for (n, s) in sphere.iter().enumerate() {
                    let field = |key: &str| format!("scene.sphere[{n}].{key}");
                    if let Some(r) = s.radius {
                        if r <= 0.0 {
                            return Err(at.error(&field("radius"), format!("must be > 0, got {r}")));
                        }
                    }
                    for k in (0..3).filter(|&k| !periodic[k]) {
                        let (x, v) = (s.x[k], s.v[k]);
                        if !s.fixed && (x < lo[k] || x > hi[k]) {
                            return Err(at.error(
                                &field("x"),
                                format!(
                                    "a free sphere's centre inside the box, {} <= {} <= {} \
                                     expected, got {x}",
                                    lo[k], axis[k], hi[k]
                                ),
                            ));
                        }
                        // a fixed sphere moves with its velocity for the whole run
                        let to = x + v * end;
                        if s.fixed && ((v > 0.0 && to > hi[k]) || (v < 0.0 && to < lo[k])) {
                            return Err(at.error(
                                &field("v"),
                                format!(
                                    "a wall sphere that stays in the box along the non-periodic \
                                     {} axis for the run's {} steps (t = {end}) expected, got \
                                     v = {v}, which takes its centre from {x} to {to}",
                                    axis[k], self.run.steps
                                ),
                            ));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Refuses `n` spheres of the material's diameter in a generated scene whose spheres have
    /// the volume `room` and centres in `z_range`: more than the densest packing of equal
    /// spheres holds (π/(3√2) of the volume), or more than the random fill's lattice has sites
    /// (`scene::random_fill`: simple cubic, spacing 1.0001 d, at least two layers).
    fn check_fill(
        &self,
        at: &Locator<'_>,
        field: &str,
        n: usize,
        room: f64,
        z_range: (f64, f64),
    ) -> Result<(), CaseError> {
        let d = self.material.diameter;
        // Kepler's bound, the fraction of space the densest packing of equal spheres fills
        let densest = std::f64::consts::PI / (3.0 * 2f64.sqrt());
        let fraction = n as f64 * sphere_volume(d) / room;
        if fraction > densest {
            return Err(at.error(
                field,
                format!(
                    "at most {} spheres fit (volume fraction {densest:.4}, the densest packing), \
                     got {n} (volume fraction {fraction:.4})",
                    (densest * room / sphere_volume(d)).floor()
                ),
            ));
        }
        // as scene::random_fill lays out its lattice
        let spacing = d * 1.0001;
        let (lo, hi) = (self.domain.lo, self.domain.hi);
        let per_layer = [0, 1].map(|k| ((hi[k] - lo[k]) / spacing).floor() as usize);
        let height = (z_range.1 - z_range.0) - spacing;
        let layers = (height / spacing).floor().max(-1.0) as i64 + 1;
        if layers < 2 {
            return Err(at.error(
                field,
                format!(
                    "the random fill needs two layers of spheres: a height of {} for the \
                     centres expected, got {}",
                    2.0 * spacing,
                    z_range.1 - z_range.0
                ),
            ));
        }
        let sites = per_layer[0] * per_layer[1] * layers as usize;
        if n > sites {
            return Err(at.error(
                field,
                format!(
                    "at most {sites} spheres for the random fill's lattice ({} × {} × {layers}, \
                     spacing 1.0001 diameters), got {n}",
                    per_layer[0], per_layer[1]
                ),
            ));
        }
        Ok(())
    }

    /// The largest diameters (length) of a free sphere and of any sphere.
    pub(super) fn largest_diameters(&self) -> (f64, f64) {
        let d = self.material.diameter;
        match &self.scene {
            Scene::Spheres { sphere } => {
                let diameter = |s: &SphereSpec| s.radius.map_or(d, |r| 2.0 * r);
                let max = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0, f64::max);
                (
                    max(&mut sphere.iter().filter(|s| !s.fixed).map(diameter)),
                    max(&mut sphere.iter().map(diameter)),
                )
            }
            _ => (d, d),
        }
    }
}
