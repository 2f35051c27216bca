//! Scenes: the bumpy-wall shear geometry (generated or read from a file) and explicit sphere
//! lists; [`tile`], the benchmark cell tiled for timing against system size.

pub mod tile;

use std::path::{Path, PathBuf};

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};

use crate::case::{Case, CaseError, Scene as SceneSpec, Search};
use crate::io::{mercury, official, FormatError};
use crate::state::Domain;
use crate::state::{memory, Motion, Particles};
pub use crate::step::engine::Scene;
use crate::step::neighbor::{NeighborBuilder, PairList};
use crate::Vec3;

/// Why a scene was not built or a case not tiled ([`build`], [`tile`]). An initial file's
/// errors name the file and the line; a case's, its file, line and field.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A malformed initial file, or one whose box is not the case's.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// A case file refused when read (by [`tile::write`]).
    #[error(transparent)]
    Case(#[from] CaseError),
    /// A size whose memory the machine does not have: spheres, tiles, the neighbour list.
    #[error(transparent)]
    Memory(#[from] memory::TooLarge),
    /// An initial file with another number of particles than the case's scene.
    #[error("{}: has {found} particles, the case expects {wall} wall + {free} free", path.display())]
    Count {
        path: PathBuf,
        found: usize,
        wall: usize,
        free: usize,
    },
    /// A wall sphere of an initial file that moves otherwise than the case prescribes
    /// (velocities, length/time).
    #[error(
        "{}:{line}: wall sphere {id} moves at {found:?}, the case prescribes {prescribed:?}",
        path.display()
    )]
    WallMotion {
        path: PathBuf,
        line: usize,
        /// The sphere's id (from 1, in file order).
        id: usize,
        found: [f64; 3],
        prescribed: [f64; 3],
    },
    /// A centre of an initial file outside the case's box along `axis`.
    #[error(
        "{}:{line}: particle {id}: {axis} = {value} is outside the case's box [{lo}, {hi}]",
        path.display()
    )]
    Outside {
        path: PathBuf,
        line: usize,
        id: usize,
        axis: &'static str,
        value: f64,
        lo: f64,
        hi: f64,
    },
    /// Two spheres of an initial file that overlap beyond the run guard's limit (`msg` names
    /// them, their lines and the overlap).
    #[error("{}:{line}: {msg}", path.display())]
    Overlap {
        path: PathBuf,
        line: usize,
        msg: String,
    },
    /// More spheres than the random fill's lattice holds between the walls (`d`: diameter).
    #[error(
        "cannot fit {n} spheres of diameter {d} between the walls (room for {room} on a lattice)"
    )]
    NoRoom { n: usize, d: f64, room: usize },
    /// A tiling asked for no tiles.
    #[error("tiles: nx and ny must be 1 or more, got {nx} × {ny}")]
    NoTiles { nx: usize, ny: usize },
    /// A state whose box is not periodic in x and y cannot be tiled.
    #[error("tiles: the box must be periodic in x and y, got periodic = {periodic:?}")]
    NotPeriodic { periodic: [bool; 3] },
    /// A case that cannot be tiled: `field` of `file` says why.
    #[error("{file}: {field}: {msg}")]
    NotTileable {
        file: String,
        field: String,
        msg: String,
    },
    /// A case file's text that is not TOML.
    #[error("{file}")]
    Toml {
        file: String,
        #[source]
        source: toml::de::Error,
    },
    /// The tiled case's table could not be written as TOML.
    #[error("a case table is written as TOML")]
    TomlWrite(#[source] toml::ser::Error),
    /// The tiled case is refused by the checks of a case file.
    #[error("{file}: the tiled case is not valid")]
    TiledInvalid {
        file: String,
        #[source]
        source: CaseError,
    },
    /// The case of `path` whose state cannot be tiled (the source says why).
    #[error("{}: cannot be tiled", path.display())]
    CannotTile {
        path: PathBuf,
        #[source]
        source: Box<SceneError>,
    },
    /// A folder that cannot be made.
    #[error("{}: cannot create the folder", path.display())]
    Folder {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file not written ([`crate::io::atomic::write`]'s error, which names it).
    #[error(transparent)]
    Write(std::io::Error),
}

/// The box of a case.
pub fn domain_of(case: &Case) -> Domain {
    Domain::new(
        Vec3::from(case.domain.lo),
        Vec3::from(case.domain.hi),
        case.domain.periodic,
    )
}

/// Builds the initial scene of a case; `init` overrides the case's `run.init`.
pub fn build(case: &Case, init: Option<&Path>) -> Result<Scene, SceneError> {
    let domain = domain_of(case);
    let d = case.material.diameter;
    let rho = case.material.density;
    let mut particles = Particles::default();
    let mut time = 0.0;
    // An initial file and the line of each of its particles, checked once they are placed.
    let mut from_file = None;
    match &case.scene {
        SceneSpec::BumpyShear {
            free,
            wall_rows,
            wall_per_row,
            bottom_z,
            top_z,
            bottom_vx,
            top_vx,
        } => {
            let walls = [
                (
                    bumpy_wall(*wall_rows, *wall_per_row, d, *bottom_z),
                    *bottom_vx,
                ),
                (bumpy_wall(*wall_rows, *wall_per_row, d, *top_z), *top_vx),
            ];
            let n_wall = 2 * wall_rows * wall_per_row;
            memory::check(
                &format!("scene: {n_wall} wall + {free} free spheres"),
                (n_wall as f64 + *free as f64) * memory::BYTES_PER_SPHERE,
            )?;
            let wall_of = |a: usize| (a < n_wall).then(|| (a / (wall_rows * wall_per_row)) as u8);
            let init_path = init
                .map(Path::to_path_buf)
                .or_else(|| case.run.init.as_deref().map(|p| case.resolve(p)));
            if let Some(path) = init_path {
                let loaded = load_init(&path, &domain)?;
                if loaded.x.len() != n_wall + free {
                    return Err(SceneError::Count {
                        path,
                        found: loaded.x.len(),
                        wall: n_wall,
                        free: *free,
                    });
                }
                time = loaded.time;
                for a in 0..loaded.x.len() {
                    match wall_of(a) {
                        Some(g) => {
                            let v = Vec3::new(walls[g as usize].1, 0.0, 0.0);
                            if let Some(fv) = loaded.v.get(a) {
                                if (fv - v).amax() > 1e-9 {
                                    return Err(SceneError::WallMotion {
                                        path,
                                        line: loaded.line[a],
                                        id: a + 1,
                                        found: [fv.x, fv.y, fv.z],
                                        prescribed: [v.x, v.y, v.z],
                                    });
                                }
                            }
                            particles.push(
                                loaded.x[a],
                                v,
                                Vec3::zeros(),
                                loaded.radius[a],
                                rho,
                                Motion::Prescribed(g),
                            );
                        }
                        None => particles.push(
                            loaded.x[a],
                            loaded.v.get(a).copied().unwrap_or_else(Vec3::zeros),
                            loaded.w.get(a).copied().unwrap_or_else(Vec3::zeros),
                            loaded.radius[a],
                            rho,
                            Motion::Free,
                        ),
                    }
                }
                from_file = Some((path, loaded.line));
            } else {
                for (g, (pos, vx)) in walls.iter().enumerate() {
                    for x in pos {
                        particles.push(
                            *x,
                            Vec3::new(*vx, 0.0, 0.0),
                            Vec3::zeros(),
                            0.5 * d,
                            rho,
                            Motion::Prescribed(g as u8),
                        );
                    }
                }
                let wall_x: Vec<Vec3> = walls.iter().flat_map(|w| w.0.iter().copied()).collect();
                let zr = (bottom_z + 0.5 * d, top_z - 0.5 * d);
                for x in random_fill(&domain, &wall_x, *free, d, zr, case.run.seed)? {
                    particles.push(x, Vec3::zeros(), Vec3::zeros(), 0.5 * d, rho, Motion::Free);
                }
            }
        }
        SceneSpec::Gas { count, speed } => {
            memory::check(
                &format!("scene.count: {count} spheres"),
                *count as f64 * memory::BYTES_PER_SPHERE,
            )?;
            let z = (domain.lo.z + 0.5 * d, domain.hi.z - 0.5 * d);
            let x = random_fill(&domain, &[], *count, d, z, case.run.seed)?;
            for (x, v) in x
                .into_iter()
                .zip(random_velocities(*count, *speed, case.run.seed))
            {
                particles.push(x, v, Vec3::zeros(), 0.5 * d, rho, Motion::Free);
            }
        }
        SceneSpec::Spheres { sphere } => {
            for (k, s) in sphere.iter().enumerate() {
                let motion = if s.fixed {
                    Motion::Prescribed(k.min(255) as u8)
                } else {
                    Motion::Free
                };
                particles.push(
                    Vec3::from(s.x),
                    Vec3::from(s.v),
                    Vec3::from(s.w),
                    s.radius.unwrap_or(0.5 * d),
                    rho,
                    motion,
                );
            }
        }
    }
    // before any pair is searched: the overlaps of an initial file's spheres below
    pairs_fit(&particles, case.neighbor.skin)?;
    if let Some((path, line)) = &from_file {
        check_loaded(path, line, &particles, &domain, case.guard.overlap)?;
    }
    for x in particles.x.iter_mut() {
        domain.wrap(x);
    }
    Ok(Scene {
        domain,
        particles,
        time,
        walls: walls_of(case),
    })
}

/// Refuses spheres whose neighbour list (with skin `skin`) would not fit in memory, before it is
/// built ([`memory::candidate_pairs`]).
fn pairs_fit(p: &Particles, skin: f64) -> Result<(), memory::TooLarge> {
    let pairs = memory::candidate_pairs(&p.x, &p.radius, skin);
    memory::check(
        &format!(
            "the neighbour list of {} spheres (up to {pairs:.3e} pairs in reach: spheres \
             piled on each other?)",
            p.len()
        ),
        pairs * memory::BYTES_PER_PAIR,
    )
}

/// What an initial file provides.
struct Loaded {
    time: f64,
    x: Vec<Vec3>,
    radius: Vec<f64>,
    v: Vec<Vec3>,
    w: Vec<Vec3>,
    /// The line of each particle in the file.
    line: Vec<usize>,
}

/// Reads an official initial file or a MercuryCG `.data` file (told apart by their first
/// word, read line by line), checking its box against the case's.
fn load_init(path: &Path, domain: &Domain) -> Result<Loaded, FormatError> {
    let mut lines = crate::io::open(path)?;
    let file = path.display().to_string();
    if official::looks_official(lines.peek()?) {
        let f = official::parse(&mut lines)?;
        mercury::check_box(&file, &f.lo, &f.hi, domain, 1e-6)?;
        Ok(Loaded {
            time: 0.0,
            x: f.x,
            radius: f.radius,
            v: Vec::new(),
            w: Vec::new(),
            line: f.line,
        })
    } else {
        let f = mercury::parse_data(&mut lines)?;
        mercury::check_box(&file, &f.domain_lo, &f.domain_hi, domain, 1e-6)?;
        Ok(Loaded {
            time: f.time,
            x: f.rows.iter().map(|r| r.x).collect(),
            radius: f.rows.iter().map(|r| r.radius).collect(),
            v: f.rows.iter().map(|r| r.v).collect(),
            w: f.rows.iter().map(|r| r.w).collect(),
            line: f.rows.iter().map(|r| r.line).collect(),
        })
    }
}

/// Refuses a loaded state that the run guard would stop at its first step, naming the file,
/// the lines and the particle ids (from 1, in file order): a centre outside the box (along
/// every axis: a file's positions lie in its box, periodic or not), and a free particle
/// overlapping another particle by more than `overlap` times the smaller radius of the two
/// (two particles at the same place, e.g. a repeated line, included).
fn check_loaded(
    path: &Path,
    line: &[usize],
    p: &Particles,
    domain: &Domain,
    overlap: f64,
) -> Result<(), SceneError> {
    for a in 0..p.len() {
        if let Some(k) = (0..3).find(|&k| !(p.x[a][k] >= domain.lo[k] && p.x[a][k] <= domain.hi[k]))
        {
            return Err(SceneError::Outside {
                path: path.to_path_buf(),
                line: line[a],
                id: a + 1,
                axis: ["x", "y", "z"][k],
                value: p.x[a][k],
                lo: domain.lo[k],
                hi: domain.hi[k],
            });
        }
    }
    let free = |a: usize| matches!(p.motion[a], Motion::Free);
    for (a, b) in overlapping_pairs(p, domain) {
        if !free(a) && !free(b) {
            continue;
        }
        let gap = domain.min_image(p.x[b] - p.x[a]).norm();
        let delta = p.radius[a] + p.radius[b] - gap;
        let limit = overlap * p.radius[a].min(p.radius[b]);
        if delta > limit {
            let kind = |a: usize| if free(a) { "free" } else { "wall" };
            let what = if gap == 0.0 {
                "are at the same place (a repeated line?)".to_string()
            } else {
                format!("overlap by {delta:e}")
            };
            return Err(SceneError::Overlap {
                path: path.to_path_buf(),
                line: line[a.max(b)],
                msg: format!(
                    "particles {} ({}, line {}) and {} ({}, line {}) {what}, beyond the limit \
                     {limit:e} ([guard] overlap = {overlap} times the smaller radius); the run \
                     guard would stop the first step",
                    a + 1,
                    kind(a),
                    line[a],
                    b + 1,
                    kind(b),
                    line[b],
                ),
            });
        }
    }
    Ok(())
}

/// The pairs (a < b, in that order) of overlapping particles, found by the solver's own cell
/// search (positions in the box).
fn overlapping_pairs(p: &Particles, domain: &Domain) -> Vec<(usize, usize)> {
    let r_max = p.radius.iter().cloned().fold(0.0, f64::max);
    let mut builder = NeighborBuilder::new(0.0, 0.0, r_max, Search::Cells);
    let id: Vec<u32> = (0..p.len() as u32).collect();
    let mut order = Vec::new();
    builder.order(domain, &p.x, &id, &mut order);
    let x: Vec<Vec3> = order.iter().map(|&a| p.x[a as usize]).collect();
    let radius: Vec<f64> = order.iter().map(|&a| p.radius[a as usize]).collect();
    let mut list = PairList::default();
    builder.build(&mut list, domain, &x, &radius, &order, |_, _| true);
    let mut out: Vec<(usize, usize)> = list
        .p
        .iter()
        .zip(&list.i)
        .map(|(&m, &n)| {
            let (a, b) = (order[m as usize] as usize, order[n as usize] as usize);
            (a.min(b), a.max(b))
        })
        .collect();
    out.sort_unstable();
    out
}

/// Centres of one hexagonal bumpy wall at height `z`, in the order of the official file:
/// for each of `per_row` columns along x, the `rows` rows along y; row k at y = d/2 + k·√3/2·d,
/// even rows shifted by d/2 in x.
pub fn bumpy_wall(rows: usize, per_row: usize, d: f64, z: f64) -> Vec<Vec3> {
    let dy = 3f64.sqrt() / 2.0 * d;
    let mut out = Vec::with_capacity(rows * per_row);
    for i in 0..per_row {
        for k in 0..rows {
            let shift = if k % 2 == 0 { 0.5 * d } else { 0.0 };
            out.push(Vec3::new(i as f64 * d + shift, 0.5 * d + k as f64 * dy, z));
        }
    }
    out
}

/// `n` velocities uniform in a cube, shifted to zero mean and scaled to the rms speed `speed`
/// (seeded; a different stream from the positions').
pub fn random_velocities(n: usize, speed: f64, seed: u64) -> Vec<Vec3> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed ^ 0x05ee_d0f7_e10c_17e5);
    let mut v: Vec<Vec3> = (0..n)
        .map(|_| {
            Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
        })
        .collect();
    let mean = v.iter().sum::<Vec3>() / n as f64;
    let rms = (v.iter().map(|u| (u - mean).norm_squared()).sum::<f64>() / n as f64).sqrt();
    for u in v.iter_mut() {
        *u = (*u - mean) * (speed / rms);
    }
    v
}

/// `n` non-overlapping spheres of diameter `d`, placed randomly and homogeneously with centres
/// in `z_range` and not overlapping `fixed`: start from a random subset of a simple cubic lattice
/// (spacing ≥ d) and randomise it with hard-sphere Monte Carlo moves (random sequential addition
/// would stall near its saturation volume fraction ≈ 0.38).
pub fn random_fill(
    domain: &Domain,
    fixed: &[Vec3],
    n: usize,
    d: f64,
    z_range: (f64, f64),
    seed: u64,
) -> Result<Vec<Vec3>, SceneError> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let l = domain.lengths();
    let spacing = d * 1.0001;
    let (z0, z1) = (z_range.0 + 0.5 * spacing, z_range.1 - 0.5 * spacing);
    let nx = (l.x / spacing).floor() as usize;
    let ny = (l.y / spacing).floor() as usize;
    // As few layers as hold n spheres, spread over the whole height: the most room to move.
    let nz_max = ((z1 - z0) / spacing).floor() as usize + 1;
    let nz = n.div_ceil((nx * ny).max(1)).clamp(2, nz_max.max(2));
    let dz = (z1 - z0) / (nz - 1) as f64;
    let mut sites = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let x = Vec3::new(
                    domain.lo.x + (i as f64 + 0.5) * l.x / nx as f64,
                    domain.lo.y + (j as f64 + 0.5) * l.y / ny as f64,
                    z0 + k as f64 * dz,
                );
                if fixed
                    .iter()
                    .all(|f| domain.min_image(x - f).norm() >= spacing)
                {
                    sites.push(x);
                }
            }
        }
    }
    if sites.len() < n {
        return Err(SceneError::NoRoom {
            n,
            d,
            room: sites.len(),
        });
    }
    sites.shuffle(&mut rng);
    sites.truncate(n);
    let mut grid = HardSphereGrid::new(domain, d, fixed, &sites);
    let sweeps = 400;
    let step = 0.3 * d;
    for _ in 0..sweeps {
        for a in 0..n {
            let trial = {
                let mut t = sites[a]
                    + Vec3::new(
                        rng.gen_range(-step..step),
                        rng.gen_range(-step..step),
                        rng.gen_range(-step..step),
                    );
                domain.wrap(&mut t);
                t
            };
            if trial.z < z_range.0 || trial.z > z_range.1 {
                continue;
            }
            if grid.free_at(domain, &trial, a, d) {
                grid.relocate(domain, a, &sites[a], &trial);
                sites[a] = trial;
            }
        }
    }
    Ok(sites)
}

/// Cell lists for hard-sphere moves: fixed spheres and movable ones (by index).
struct HardSphereGrid {
    n: [usize; 3],
    edge: Vec3,
    cells: Vec<Vec<(bool, usize, Vec3)>>,
}

impl HardSphereGrid {
    fn new(domain: &Domain, d: f64, fixed: &[Vec3], movable: &[Vec3]) -> Self {
        let l = domain.lengths();
        let n = [0, 1, 2].map(|k| ((l[k] / d).floor() as usize).max(1));
        let edge = Vec3::new(l.x / n[0] as f64, l.y / n[1] as f64, l.z / n[2] as f64);
        let mut g = HardSphereGrid {
            n,
            edge,
            cells: vec![Vec::new(); n[0] * n[1] * n[2]],
        };
        for (a, x) in fixed.iter().enumerate() {
            let c = g.cell(domain, x);
            g.cells[c].push((false, a, *x));
        }
        for (a, x) in movable.iter().enumerate() {
            let c = g.cell(domain, x);
            g.cells[c].push((true, a, *x));
        }
        g
    }

    fn coords(&self, domain: &Domain, x: &Vec3) -> [i64; 3] {
        [0, 1, 2].map(|k| {
            let c = ((x[k] - domain.lo[k]) / self.edge[k]).floor() as i64;
            c.clamp(0, self.n[k] as i64 - 1)
        })
    }

    fn cell(&self, domain: &Domain, x: &Vec3) -> usize {
        let c = self.coords(domain, x);
        ((c[2] as usize * self.n[1]) + c[1] as usize) * self.n[0] + c[0] as usize
    }

    /// True when a sphere at `x` overlaps nothing but movable sphere `me`.
    fn free_at(&self, domain: &Domain, x: &Vec3, me: usize, d: f64) -> bool {
        let c = self.coords(domain, x);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let mut cc = [0usize; 3];
                    let mut inside = true;
                    for (k, o) in [dx, dy, dz].into_iter().enumerate() {
                        let m = self.n[k] as i64;
                        let v = c[k] + o;
                        if domain.periodic[k] {
                            cc[k] = v.rem_euclid(m) as usize;
                        } else if v < 0 || v >= m {
                            inside = false;
                        } else {
                            cc[k] = v as usize;
                        }
                    }
                    if !inside {
                        continue;
                    }
                    let idx = (cc[2] * self.n[1] + cc[1]) * self.n[0] + cc[0];
                    for (movable, a, y) in &self.cells[idx] {
                        if *movable && *a == me {
                            continue;
                        }
                        if domain.min_image(x - y).norm_squared() < d * d * 1.0000001 {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }

    fn relocate(&mut self, domain: &Domain, a: usize, from: &Vec3, to: &Vec3) {
        let (c0, c1) = (self.cell(domain, from), self.cell(domain, to));
        let pos = self.cells[c0]
            .iter()
            .position(|e| e.0 && e.1 == a)
            .expect("sphere is in its cell");
        self.cells[c0].swap_remove(pos);
        self.cells[c1].push((true, a, *to));
    }
}

/// The flat walls of `case` at the start (`[[wall]]`): unit normals, points and velocities
/// as given.
pub fn walls_of(case: &Case) -> Vec<crate::state::Wall> {
    case.wall
        .iter()
        .map(|w| crate::state::Wall {
            point: Vec3::from(w.point),
            normal: Vec3::from(w.unit_normal()),
            velocity: Vec3::from(w.velocity),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bumpy_wall_matches_the_official_layout() {
        let w = bumpy_wall(12, 20, 1.0, 0.5);
        assert_eq!(w.len(), 240);
        assert_eq!(w[0], Vec3::new(0.5, 0.5, 0.5));
        assert!((w[1] - Vec3::new(0.0, 1.36602540378444, 0.5)).norm() < 1e-13);
        assert!((w[12] - Vec3::new(1.5, 0.5, 0.5)).norm() < 1e-13);
        assert!((w[239] - Vec3::new(19.0, 10.0262794416288, 0.5)).norm() < 1e-13);
    }
}
