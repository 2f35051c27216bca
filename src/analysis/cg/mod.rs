//! Coarse-graining of a MercuryCG-format series (`NAME.data.NNNN` + `NAME.fstat.NNNN`) into
//! z-profiles, time-averaged as MercuryCG's `-timeaverage` (raw fields first, derived fields from
//! the averages), with standard errors from block averaging over saves, built-in physics checks
//! and a plot. Any code's output in this format is judged by the same yardstick.

pub mod blocking;
pub mod checks;
pub mod compare;
pub mod fields;
pub mod kernel;
pub mod plot;
pub mod table;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use rayon::prelude::*;

use crate::analysis::stats::{block, integrated_autocorrelation, standard_error};
use crate::io::mercury;
use crate::state::Domain;
use checks::Check;
use fields::{derive, raw_fields, Derived, Grid, Raw};
use kernel::Kernel;
use table::Table;

/// What to coarse-grain and how.
#[derive(Clone, Debug)]
pub struct CgOptions {
    /// First save (default: the second half of the series).
    pub from: Option<u64>,
    /// Last save (default: the last one).
    pub to: Option<u64>,
    pub slices: usize,
    pub kernel: KernelChoice,
    /// Kernel width (Gauss and MercuryGauss: standard deviation; Lucy: cutoff); default the
    /// slice height.
    pub width: Option<f64>,
    /// Particles with index < `walls` are wall spheres (the benchmark: 480).
    pub walls: usize,
    /// Particle density.
    pub density: f64,
    /// Periodicity of x, y, z (the box itself comes from the files).
    pub periodic: [bool; 3],
    /// Number of blocks for the standard errors.
    pub blocks: usize,
}

/// The benchmark's saves: ids 1-480 walls, density 1, periodic in x and y; 100 slices,
/// Heaviside kernel of the slice height, 10 blocks, the second half of the series.
impl Default for CgOptions {
    fn default() -> Self {
        CgOptions {
            from: None,
            to: None,
            slices: 100,
            kernel: KernelChoice::Heaviside,
            width: None,
            walls: 480,
            density: 1.0,
            periodic: [true, true, false],
            blocks: 10,
        }
    }
}

impl CgOptions {
    /// The defaults for a case's saves: its wall spheres, density and periodicity; the rest as
    /// [`CgOptions::default`].
    pub fn for_case(case: &crate::case::Case) -> CgOptions {
        use crate::case::Scene;
        let walls = match &case.scene {
            Scene::BumpyShear {
                wall_rows,
                wall_per_row,
                ..
            } => 2 * wall_rows * wall_per_row,
            Scene::Spheres { sphere } => sphere.iter().take_while(|s| s.fixed).count(),
            Scene::Gas { .. } => 0,
        };
        CgOptions {
            walls,
            density: case.material.density,
            periodic: case.domain.periodic,
            ..CgOptions::default()
        }
    }
}

impl CgOptions {
    /// Where and how these options coarse-grain a box from `lo` to `hi` (length): the box with
    /// these options' periodic axes, `slices` slices along z, and the kernel on them (Heaviside
    /// slices of the slices' height, or a Gauss, MercuryCG Gauss or Lucy kernel of `width`,
    /// default the slice height). The saves' coarse-graining and in-run averaging both take it from here.
    pub fn frame(&self, lo: crate::Vec3, hi: crate::Vec3) -> (Domain, Grid, Kernel) {
        let grid = Grid {
            z0: lo.z,
            z1: hi.z,
            n: self.slices,
        };
        let kernel = self.kernel_on(&grid);
        (Domain::new(lo, hi, self.periodic), grid, kernel)
    }

    /// The kernel of these options on `grid` (see [`CgOptions::frame`]).
    fn kernel_on(&self, grid: &Grid) -> Kernel {
        let h = grid.h();
        let width = self.width.unwrap_or(h);
        match self.kernel {
            KernelChoice::Heaviside => Kernel::Heaviside { h },
            KernelChoice::Gauss => Kernel::Gauss { w: width },
            KernelChoice::MercuryGauss => Kernel::MercuryGauss { w: width },
            KernelChoice::Lucy => Kernel::Lucy { c: width },
        }
    }
}

/// Kernel families.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelChoice {
    Heaviside,
    Gauss,
    /// MercuryCG's Gaussian ([`Kernel::MercuryGauss`]).
    MercuryGauss,
    Lucy,
}

impl KernelChoice {
    /// Every family.
    pub const ALL: [KernelChoice; 4] = [
        KernelChoice::Heaviside,
        KernelChoice::Gauss,
        KernelChoice::MercuryGauss,
        KernelChoice::Lucy,
    ];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            KernelChoice::Heaviside => "heaviside",
            KernelChoice::Gauss => "gauss",
            KernelChoice::MercuryGauss => "mercury-gauss",
            KernelChoice::Lucy => "lucy",
        }
    }
}

/// A series of saves on disk.
#[derive(Clone, Debug)]
pub struct Series {
    pub dir: PathBuf,
    pub name: String,
    /// Save numbers present (both `.data` and `.fstat`), increasing.
    pub saves: Vec<u64>,
}

/// A save of a series with one of its two files only.
#[derive(Clone, Debug, PartialEq)]
pub struct Incomplete {
    pub save: u64,
    /// The file that is there and the one that is not.
    pub present: PathBuf,
    pub missing: PathBuf,
}

impl std::fmt::Display for Incomplete {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: missing (save {} has {} only)",
            self.missing.display(),
            self.save,
            self.present.display()
        )
    }
}

impl Series {
    /// Finds the saves of `base` = `DIR/NAME`; a save with one of its two files only is an
    /// error naming the missing file ([`Series::scan`] lists them instead).
    pub fn find(base: &Path) -> anyhow::Result<Series> {
        let (series, incomplete) = Series::scan(base)?;
        if !incomplete.is_empty() {
            bail!("{}", incomplete_saves(&incomplete));
        }
        Ok(series)
    }

    /// Finds the saves of `base` = `DIR/NAME` that have both files, and the saves that have
    /// one of them only (by save number); an error when no save has both.
    pub fn scan(base: &Path) -> anyhow::Result<(Series, Vec<Incomplete>)> {
        let dir = base
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf();
        let name = base
            .file_name()
            .and_then(|n| n.to_str())
            .with_context(|| format!("{}: not a series base name", base.display()))?
            .to_string();
        let (mut data, mut fstat) = (BTreeSet::new(), BTreeSet::new());
        for entry in
            std::fs::read_dir(&dir).with_context(|| format!("{}: cannot list", dir.display()))?
        {
            let file = entry?.file_name();
            let Some(file) = file.to_str() else {
                continue;
            };
            let number = |ext: &str| {
                file.strip_prefix(&format!("{name}.{ext}."))?
                    .parse::<u64>()
                    .ok()
            };
            if let Some(k) = number("data") {
                data.insert(k);
            } else if let Some(k) = number("fstat") {
                fstat.insert(k);
            }
        }
        let path = |ext: &str, k: u64| mercury::save_path(&dir, &name, ext, k);
        let incomplete: Vec<Incomplete> = data
            .symmetric_difference(&fstat)
            .map(|&k| {
                let (present, missing) = if data.contains(&k) {
                    ("data", "fstat")
                } else {
                    ("fstat", "data")
                };
                Incomplete {
                    save: k,
                    present: path(present, k),
                    missing: path(missing, k),
                }
            })
            .collect();
        let saves: Vec<u64> = data.intersection(&fstat).copied().collect();
        if saves.is_empty() {
            bail!(
                "{}: no {name}.data.NNNN with a matching .fstat.NNNN",
                dir.display()
            );
        }
        Ok((Series { dir, name, saves }, incomplete))
    }

    fn path(&self, ext: &str, k: u64) -> PathBuf {
        mercury::save_path(&self.dir, &self.name, ext, k)
    }
}

/// The incomplete saves `list` in words, for an error or a warning: the first three (the
/// missing file of each), and how many more there are.
pub fn incomplete_saves(list: &[Incomplete]) -> String {
    let mut s = list
        .iter()
        .take(3)
        .map(Incomplete::to_string)
        .collect::<Vec<_>>()
        .join("; ");
    if list.len() > 3 {
        s.push_str(&format!("; and {} more incomplete saves", list.len() - 3));
    }
    s
}

/// Profiles with standard errors.
#[derive(Clone, Debug)]
pub struct Profiles {
    pub grid: Grid,
    pub kernel: Kernel,
    pub saves: Vec<u64>,
    pub blocks: usize,
    /// Time-averaged derived fields.
    pub mean: Vec<Derived>,
    /// Per block of saves, per grid point: the [`columns`] derived from the block's average.
    pub block_columns: Vec<Vec<Vec<f64>>>,
    /// Standard error of each column of [`columns`], per grid point.
    pub se: Vec<Vec<f64>>,
    /// Per save: the raw fields (for the checks).
    pub per_save: Vec<Raw>,
    /// Per save: force of the free particles on the bottom and top walls: the mean over the
    /// save's interval of the force of every step (the ledger columns of the run's diagnostics,
    /// when they cover every save), else the force at the save (from the fstat rows).
    pub wall_force: Vec<[crate::Vec3; 2]>,
    /// Whether `wall_force` holds every-step means (true) or the forces at the saves.
    pub wall_force_every_step: bool,
    pub domain: Domain,
    /// Number of free particles and their total volume.
    pub free: usize,
    pub free_volume: f64,
    /// Integrated autocorrelation time (in saves) of the core-averaged shear stress and of the
    /// core-averaged kinetic energy density.
    pub tau_shear: f64,
    pub tau_energy: f64,
    /// Per column of [`columns`]: whether its standard errors can be trusted where a check
    /// judges by them (false for an in-run sampling its reference τ was not calibrated at,
    /// [`blocking::Method::Uncalibrated`]).
    pub trusted: Vec<bool>,
}

/// The five profiles of the benchmark, as (label, index in [`COLUMNS`]).
pub const FIELDS: [(&str, usize); 5] = [
    ("vx", 2),
    ("nu", 0),
    ("T", 5),
    ("pressure", 24),
    ("shear", 25),
];

/// χ²/dof of profile `col` of `a` against `b` (same grid) over the core slices: the mean of
/// (a − b)²/(se_a² + se_b²), ≈ 1 when they differ by noise only.
pub fn chi2(a: &Profiles, b: &Profiles, col: usize) -> f64 {
    table::chi2(&Table::of(a), &Table::of(b), col, core_window(&a.grid))
        .expect("profiles of one grid")
}

/// The z-interval of the core: at least two diameters from the walls' surfaces (z ∈ [3, 19]
/// for the benchmark's box [0, 22]).
pub fn core_window(grid: &Grid) -> (f64, f64) {
    (grid.z0 + 3.0, grid.z1 - 3.0)
}

/// Column names of [`columns`] (after `z`).
pub const COLUMNS: [&str; 26] = [
    "nu", "rho", "vx", "vy", "vz", "T", "kin_xx", "kin_xy", "kin_xz", "kin_yx", "kin_yy", "kin_yz",
    "kin_zx", "kin_zy", "kin_zz", "con_xx", "con_xy", "con_xz", "con_yx", "con_yy", "con_yz",
    "con_zx", "con_zy", "con_zz", "pressure", "shear_xz",
];

/// The values of [`COLUMNS`] for one grid point.
pub fn columns(d: &Derived) -> Vec<f64> {
    let mut c = vec![
        d.nu,
        d.rho,
        d.velocity.x,
        d.velocity.y,
        d.velocity.z,
        d.temperature,
    ];
    for m in [&d.kinetic, &d.contact] {
        for r in 0..3 {
            for s in 0..3 {
                c.push(m[(r, s)]);
            }
        }
    }
    c.push(d.pressure);
    c.push(d.shear);
    c
}

/// The mean force of every step on the bottom and top walls over the interval ending at each
/// of `saves`, from the ledger columns of the series' diagnostics table, when it has them for
/// every one of those saves; `None` otherwise (no table, an older table, a save without a
/// ledger).
fn every_step_wall_forces(
    series: &Series,
    saves: &[u64],
) -> anyhow::Result<Option<Vec<[crate::Vec3; 2]>>> {
    let path = series.dir.join(format!("{}.diagnostics.csv", series.name));
    if !path.exists() {
        return Ok(None);
    }
    let Some(records) = crate::io::diagnostics::read_ledgers(&path)? else {
        return Ok(None);
    };
    Ok(saves
        .iter()
        .map(|&k| {
            let r = records.iter().find(|r| r.save == k)?;
            r.ledger.as_ref().map(|l| l.mean_wall_force)
        })
        .collect())
}

/// Coarse-grains a series.
pub fn coarse_grain(series: &Series, o: &CgOptions) -> anyhow::Result<Profiles> {
    let n = series.saves.len();
    let first = o.from.unwrap_or(series.saves[n.div_ceil(2).min(n - 1)]);
    let last = o.to.unwrap_or(series.saves[n - 1]);
    let saves: Vec<u64> = series
        .saves
        .iter()
        .copied()
        .filter(|&k| k >= first && k <= last)
        .collect();
    if saves.is_empty() {
        bail!(
            "no saves between {first} and {last} in {}",
            series.dir.display()
        );
    }
    let head = mercury::read_data(&series.path("data", saves[0]))?;
    let (domain, grid, kernel) = o.frame(head.domain_lo, head.domain_hi);
    let walls = o.walls;
    let is_wall = move |i: usize| i < walls;
    let per: Vec<anyhow::Result<(Raw, [crate::Vec3; 2])>> = saves
        .par_iter()
        .map(|&k| {
            let (data, fstat) =
                mercury::read_save(&series.path("data", k), &series.path("fstat", k))?;
            if data.rows.len() != head.rows.len() {
                bail!(
                    "{}: {} particles, save {} has {}",
                    series.path("data", k).display(),
                    data.rows.len(),
                    saves[0],
                    head.rows.len()
                );
            }
            let (data_path, fstat_path) = (series.path("data", k), series.path("fstat", k));
            usable(
                &data,
                &fstat,
                &is_wall,
                &domain,
                o.density,
                &data_path,
                &fstat_path,
            )?;
            let raw = raw_fields(&data, &fstat, &is_wall, &domain, &grid, kernel, o.density);
            if let Some((field, at, v)) = first_non_finite(&raw) {
                bail!(
                    "{}: the coarse-grained {field} at z = {} is {v}: the save's numbers add up \
                     beyond the largest number{}",
                    data_path.display(),
                    grid.z(at),
                    fastest(&data, &is_wall)
                );
            }
            let forces = wall_forces(&fstat, &is_wall, &data);
            if forces.iter().any(|f| !f.iter().all(|c| c.is_finite())) {
                bail!(
                    "{}: the force on a wall is not a finite number: its contacts' forces add up \
                     beyond the largest number",
                    fstat_path.display()
                );
            }
            Ok((raw, forces))
        })
        .collect();
    let mut per_save = Vec::with_capacity(saves.len());
    let mut wall_force = Vec::with_capacity(saves.len());
    for r in per {
        let (raw, wf) = r?;
        per_save.push(raw);
        wall_force.push(wf);
    }
    let every_step = every_step_wall_forces(series, &saves)?;
    let wall_force_every_step = every_step.is_some();
    let wall_force = every_step.unwrap_or(wall_force);
    let mean_raw = average(&per_save);
    let mean = derive(&mean_raw);
    let blocks = o.blocks.clamp(1, per_save.len());
    let block_cols: Vec<Vec<Vec<f64>>> = (0..blocks)
        .map(|b| {
            derive(&average(&per_save[block(b, blocks, per_save.len())]))
                .iter()
                .map(columns)
                .collect()
        })
        .collect();
    let se = (0..grid.n)
        .map(|k| {
            (0..COLUMNS.len())
                .map(|c| {
                    let vals: Vec<f64> = block_cols.iter().map(|b| b[k][c]).collect();
                    standard_error(&vals)
                })
                .collect()
        })
        .collect();
    let free = head.rows.len().saturating_sub(walls);
    let free_volume = head.rows[walls.min(head.rows.len())..]
        .iter()
        .map(|r| fields::sphere_volume(r.radius))
        .sum();
    let core = core_range(&grid);
    let derived: Vec<Vec<Derived>> = per_save.iter().map(derive).collect();
    let series_of = |f: &dyn Fn(&Derived) -> f64| -> Vec<f64> {
        derived
            .iter()
            .map(|d| core.clone().map(|k| f(&d[k])).sum::<f64>() / core.len() as f64)
            .collect()
    };
    let tau_shear = integrated_autocorrelation(&series_of(&|d| d.shear));
    let tau_energy = integrated_autocorrelation(&series_of(&|d| d.kinetic.trace()));
    let profiles = Profiles {
        grid,
        kernel,
        saves,
        blocks,
        block_columns: block_cols,
        mean,
        se,
        per_save,
        wall_force,
        wall_force_every_step,
        domain,
        free,
        free_volume,
        tau_shear,
        tau_energy,
        trusted: vec![true; COLUMNS.len()],
    };
    Table::of(&profiles).ensure_finite(
        &format!(
            "{}: the profiles of saves {first} to {last}",
            series.dir.join(&series.name).display()
        ),
        "the saves' numbers are too large for the averages and their spread",
    )?;
    Ok(profiles)
}

/// Refuses a save whose numbers the coarse-graining cannot carry, naming the file, the line or
/// contact, the column and the value: a free particle whose mass (from its radius and
/// `density`, mass/length³) or whose mass times the square of a velocity component (the
/// momentum flux it adds, mass·length²/time²) is not a finite number, and a contact whose
/// force or whose force times its branch (f⊗l, force·length) is not.
fn usable(
    data: &mercury::DataFile,
    fstat: &mercury::FstatFile,
    is_wall: &dyn Fn(usize) -> bool,
    domain: &Domain,
    density: f64,
    data_path: &Path,
    fstat_path: &Path,
) -> anyhow::Result<()> {
    for (i, p) in data.rows.iter().enumerate() {
        if is_wall(i) {
            continue;
        }
        let m = fields::sphere_volume(p.radius) * density;
        if !m.is_finite() {
            bail!(
                "{}:{}: particle {i}: column 7 (radius): {:e} is too large to coarse-grain: its \
                 mass is not a finite number",
                data_path.display(),
                p.line,
                p.radius
            );
        }
        for (c, name) in ["vx", "vy", "vz"].iter().enumerate() {
            let v = p.v[c];
            if !(m * v * v).is_finite() {
                bail!(
                    "{}:{}: particle {i}: column {} ({name}): {v:e} is too large to coarse-grain: \
                     its momentum flux m·{name}² is not a finite number",
                    data_path.display(),
                    p.line,
                    4 + c
                );
            }
        }
    }
    for (k, r) in fstat.rows.iter().enumerate() {
        let f = r.fn_signed * r.n + r.ft * r.t;
        let start = if is_wall(r.j) { r.c } else { data.rows[r.j].x };
        let branch = domain.min_image(data.rows[r.i].x - start);
        let tensor = f * branch.transpose();
        if !(f.iter().chain(tensor.iter()).all(|x| x.is_finite())) {
            bail!(
                "{}: contact {} (particles {} and {}): fn = {:e}, ft = {:e}, branch length {:e}: \
                 too large to coarse-grain: its force or its f⊗l is not a finite number",
                fstat_path.display(),
                k + 1,
                r.i,
                r.j,
                r.fn_signed,
                r.ft,
                branch.norm()
            );
        }
    }
    Ok(())
}

/// The first raw field of `raw` that is NaN or infinite: (its name, its grid point, the value).
fn first_non_finite(raw: &Raw) -> Option<(&'static str, usize, f64)> {
    (0..raw.nu.len()).find_map(|k| {
        let fields: [(&'static str, Vec<f64>); 5] = [
            ("volume fraction", vec![raw.nu[k]]),
            ("density", vec![raw.rho[k]]),
            ("momentum", raw.momentum[k].iter().copied().collect()),
            ("momentum flux", raw.flux[k].iter().copied().collect()),
            ("contact stress", raw.contact[k].iter().copied().collect()),
        ];
        fields.into_iter().find_map(|(name, values)| {
            values
                .into_iter()
                .find(|v| !v.is_finite())
                .map(|v| (name, k, v))
        })
    })
}

/// The fastest free particle of a save (by its largest velocity component in magnitude) in
/// words, for messages: "; the fastest: particle I (line L), largest velocity component V"
/// (empty without free particles).
fn fastest(data: &mercury::DataFile, is_wall: &dyn Fn(usize) -> bool) -> String {
    data.rows
        .iter()
        .enumerate()
        .filter(|(i, _)| !is_wall(*i))
        .max_by(|a, b| a.1.v.amax().total_cmp(&b.1.v.amax()))
        .map_or(String::new(), |(i, p)| {
            format!(
                "; the fastest: particle {i} (line {}), largest velocity component {:e}",
                p.line,
                p.v.amax()
            )
        })
}

/// Grid points of the core (see [`core_window`]).
pub fn core_range(grid: &Grid) -> std::ops::Range<usize> {
    let (lo, hi) = core_window(grid);
    let first = (0..grid.n).find(|&k| grid.z(k) >= lo).unwrap_or(0);
    let last = (0..grid.n)
        .rev()
        .find(|&k| grid.z(k) <= hi)
        .unwrap_or(grid.n - 1);
    first..last + 1
}

/// Force of the free particles on the bottom (0) and top (1) wall spheres (below or above the
/// box's mid-height), from the fstat rows (each free–wall contact once, free particle first; the
/// wall gets the opposite of the force on the free particle).
fn wall_forces(
    fstat: &mercury::FstatFile,
    is_wall: &dyn Fn(usize) -> bool,
    data: &mercury::DataFile,
) -> [crate::Vec3; 2] {
    let mid = 0.5 * (data.domain_lo.z + data.domain_hi.z);
    let mut out = [crate::Vec3::zeros(); 2];
    for r in &fstat.rows {
        if !is_wall(r.i) && is_wall(r.j) {
            let g = usize::from(data.rows[r.j].x.z > mid);
            out[g] -= r.fn_signed * r.n + r.ft * r.t;
        }
    }
    out
}

fn average(raws: &[Raw]) -> Raw {
    let mut m = Raw::zeros(raws[0].nu.len());
    for r in raws {
        m.add_scaled(r, 1.0 / raws.len() as f64);
    }
    m
}

/// The profiles as CSV: z, then every column of [`COLUMNS`] followed by its standard error.
pub fn csv(p: &Profiles) -> String {
    Table::of(p).csv()
}

/// Coarse-grains `base` and writes `NAME.profiles.csv`, `NAME.profiles.png` and
/// `NAME.checks.txt` beside it; returns the profiles, the checks (the profiles' and the
/// ledgers', in the report's order) and the checks' report.
pub fn write_all(base: &Path, o: &CgOptions) -> anyhow::Result<(Profiles, Vec<Check>, String)> {
    write_series(&Series::find(base)?, o)
}

/// As [`write_all`], for the saves of `series`.
pub fn write_series(
    series: &Series,
    o: &CgOptions,
) -> anyhow::Result<(Profiles, Vec<Check>, String)> {
    let p = coarse_grain(series, o)?;
    let out = |ext: &str| series.dir.join(format!("{}.{ext}", series.name));
    crate::io::atomic::write(&out("profiles.csv"), csv(&p).as_bytes())?;
    let mut checks = checks::run(&p, o.density);
    let mut report = checks::report(&p, &checks);
    let (ledgers, ledger_checks) =
        crate::analysis::ledger::section(&series.dir, &series.name, &p.saves)?;
    report.push_str(&ledgers);
    checks.extend(ledger_checks);
    crate::io::atomic::write(&out("checks.txt"), report.as_bytes())?;
    plot::profiles_png(&p, &out("profiles.png"))?;
    Ok((p, checks, report))
}
