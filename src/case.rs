//! Case files: the TOML schema, its validation, and derived quantities (collision time,
//! restitution). Every error names the file, the line and the field.

use std::path::{Path, PathBuf};

use serde::Deserialize;

pub use crate::contact::Tangential;

/// An error in a case file: `file:line: field: message`.
#[derive(Debug, thiserror::Error)]
#[error("{file}:{line}: {field}: {msg}")]
pub struct CaseError {
    pub file: String,
    pub line: usize,
    pub field: String,
    pub msg: String,
}

/// A whole case file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Base name of the output files (`NAME.data.NNNN`).
    pub name: String,
    pub run: Run,
    #[serde(default)]
    pub neighbor: Neighbor,
    pub domain: DomainSpec,
    pub material: Material,
    pub contact: Contact,
    pub scene: Scene,
    #[serde(default)]
    pub guard: Guard,
    #[serde(default)]
    pub output: Output,
    /// Directory the case was read from (relative paths in the case resolve against it).
    #[serde(skip)]
    pub dir: PathBuf,
    /// Path the case was read from.
    #[serde(skip)]
    pub path: PathBuf,
}

/// `[run]`: time stepping and output.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Run {
    /// Number of time steps.
    pub steps: u64,
    /// A save (`.data`/`.fstat`) every this many steps, starting with step 0.
    pub save_every: u64,
    /// Time step (time units). Give exactly one of `dt` and `steps_per_collision`.
    pub dt: Option<f64>,
    /// dt = tc / steps_per_collision, tc the free–free collision time of the contact law.
    pub steps_per_collision: Option<f64>,
    /// Worker threads of the time step (default 2).
    #[serde(default = "default_threads")]
    pub threads: usize,
    /// Seed of the random initial configuration.
    #[serde(default)]
    pub seed: u64,
    /// Initial configuration file (official `GranularShearFlow.data` format or a MercuryCG
    /// `.data` save); relative to the case file. Without it the scene is generated.
    pub init: Option<String>,
    /// Gravity (acceleration); none when absent or zero.
    pub gravity: Option<[f64; 3]>,
}

fn default_threads() -> usize {
    2
}

/// `[neighbor]`: the Verlet pair list.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Neighbor {
    /// Skin added to the contact distance (length); the list is rebuilt when a particle has
    /// moved more than skin/2.
    #[serde(default = "default_skin")]
    pub skin: f64,
    /// Cell edge (length); raised to 2 r_max + skin when smaller (0 = automatic).
    #[serde(default)]
    pub cell: f64,
    /// `cells` (default) or `all-pairs`.
    #[serde(default = "default_search")]
    pub search: Search,
}

/// `[guard]`: limits of the run guard, which stops a run whose numbers can no longer be
/// trusted (non-finite velocities and positions are always refused).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Guard {
    /// Largest overlap allowed, as a fraction of the smaller radius of the pair (0 < overlap
    /// ≤ 1; default [`DEFAULT_GUARD_OVERLAP`]).
    #[serde(default = "default_guard_overlap")]
    pub overlap: f64,
    /// Largest gain of the free particles' mechanical energy over a window of steps beyond what
    /// the walls and gravity supplied, as a fraction of the energy at play (> 0; default
    /// [`DEFAULT_GUARD_ENERGY`]).
    #[serde(default = "default_guard_energy")]
    pub energy: f64,
}

/// Default of `[guard] overlap`. The benchmark's largest overlaps are about 1 % of the radius
/// (δ ≈ v·√(m_eff/kn) with relative speeds of a few wall speeds: 2·√(0.26/2e5) ≈ 2.3e-3 against
/// r = 0.5); a linear spring whose overlap reaches a tenth of the radius is far outside the
/// regime the law describes, and usually a sign of a time step too large for the stiffness.
pub const DEFAULT_GUARD_OVERLAP: f64 = 0.1;

fn default_guard_overlap() -> f64 {
    DEFAULT_GUARD_OVERLAP
}

/// Default of `[guard] energy`. Within a contact the explicit scheme's energy departs from the
/// true one by about (ω·dt)²/4 of the contact's energy (0.1 % at tc/50, 2.5 % at tc/10, 20 %
/// at tc/3.5), and a window may end inside contacts; an instability or a law that gives back
/// more than it took grows without bound. `docs/verification.md` lists the gains measured.
pub const DEFAULT_GUARD_ENERGY: f64 = 0.05;

fn default_guard_energy() -> f64 {
    DEFAULT_GUARD_ENERGY
}

impl Default for Guard {
    fn default() -> Self {
        Guard {
            overlap: DEFAULT_GUARD_OVERLAP,
            energy: DEFAULT_GUARD_ENERGY,
        }
    }
}

/// `[output]`: files a run writes beside its MercuryCG saves.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Also write each save as a ParaView file (`NAME.NNNN.vtu`, listed in `NAME.pvd`).
    #[serde(default)]
    pub vtk: bool,
}

/// How candidate pairs are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Search {
    /// Cell grid of edge ≥ 2 r_max + skin (the default).
    Cells,
    /// Every pair is tested (O(N²); a reference for tests).
    AllPairs,
}

fn default_skin() -> f64 {
    0.1
}
fn default_search() -> Search {
    Search::Cells
}

impl Default for Neighbor {
    fn default() -> Self {
        Neighbor {
            skin: default_skin(),
            cell: 0.0,
            search: default_search(),
        }
    }
}

/// `[domain]`: the box.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub periodic: [bool; 3],
}

/// `[material]`: one species for all spheres.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Particle density (mass/length³).
    pub density: f64,
    /// Particle diameter (length).
    pub diameter: f64,
}

/// `[contact]`: the contact law.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// Normal spring stiffness (force/length).
    pub kn: f64,
    /// Absolute normal damping (mass/time).
    pub gamman: f64,
    /// Tangential spring stiffness (force/length).
    #[serde(default)]
    pub kt: f64,
    /// Absolute tangential damping (mass/time).
    #[serde(default)]
    pub gammat: f64,
    /// Coulomb friction coefficient; 0 switches friction (and rotation) off.
    #[serde(default)]
    pub mu: f64,
    /// Tangential convention (default `mercury`).
    #[serde(default = "default_tangential")]
    pub tangential: Tangential,
    /// Clip the attractive tail of the normal force, fn = max(fn, 0) (default false).
    #[serde(default)]
    pub clip_normal: bool,
}

fn default_tangential() -> Tangential {
    Tangential::Mercury
}

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
    /// Reads and validates a case file.
    pub fn load(path: &Path) -> Result<Case, CaseError> {
        let text = std::fs::read_to_string(path).map_err(|e| CaseError {
            file: path.display().to_string(),
            line: 0,
            field: "-".into(),
            msg: format!("cannot read: {e}"),
        })?;
        let mut case = Case::parse(&text, &path.display().to_string())?;
        case.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        case.path = path.to_path_buf();
        Ok(case)
    }

    /// Parses and validates case text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Case, CaseError> {
        let case: Case = toml::from_str(text).map_err(|e| {
            let mut line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
                .unwrap_or(0);
            let mut field = field_on_line(text, line);
            let msg = e.message().trim().to_string();
            // A tagged table (`[scene]`) is read whole, and its error points at the header:
            // find the unknown key in it.
            let unknown = msg
                .strip_prefix("unknown field `")
                .and_then(|m| m.split('`').next());
            if let (Some(key), Some(table)) = (unknown, table_header(text_line(text, line))) {
                let at = locate(text, &table, key);
                if at != line {
                    (line, field) = (at, format!("{table}.{key}"));
                }
            }
            CaseError {
                file: file.into(),
                line,
                field,
                msg,
            }
        })?;
        case.validate(text, file)?;
        Ok(case)
    }

    fn validate(&self, text: &str, file: &str) -> Result<(), CaseError> {
        let err = |table: &str, key: &str, msg: String| CaseError {
            file: file.into(),
            line: locate(text, table, key),
            field: if table.is_empty() {
                key.to_string()
            } else {
                format!("{table}.{key}")
            },
            msg,
        };
        let positive = |table: &str, key: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(err(table, key, format!("must be > 0, got {v}")))
            }
        };
        let non_negative = |table: &str, key: &str, v: f64| {
            if v >= 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(err(table, key, format!("must be >= 0, got {v}")))
            }
        };
        if self.name.is_empty() || self.name.contains('/') {
            return Err(err(
                "",
                "name",
                format!("must be a plain file name, got {:?}", self.name),
            ));
        }
        if self.run.save_every == 0 {
            return Err(err("run", "save_every", "must be > 0, got 0".into()));
        }
        if self.run.threads == 0 {
            return Err(err("run", "threads", "must be > 0, got 0".into()));
        }
        match (self.run.dt, self.run.steps_per_collision) {
            (Some(dt), None) => positive("run", "dt", dt)?,
            (None, Some(s)) => positive("run", "steps_per_collision", s)?,
            _ => {
                return Err(err(
                    "run",
                    "dt",
                    "give exactly one of dt and steps_per_collision".into(),
                ))
            }
        }
        if let Some(g) = self.run.gravity {
            if g.iter().any(|c| !c.is_finite()) {
                return Err(err("run", "gravity", format!("must be finite, got {g:?}")));
            }
        }
        positive("neighbor", "skin", self.neighbor.skin)?;
        positive("guard", "overlap", self.guard.overlap)?;
        positive("guard", "energy", self.guard.energy)?;
        if self.guard.overlap > 1.0 {
            return Err(err(
                "guard",
                "overlap",
                format!(
                    "a fraction of the smaller radius at most 1, got {}",
                    self.guard.overlap
                ),
            ));
        }
        non_negative("neighbor", "cell", self.neighbor.cell)?;
        for k in 0..3 {
            if self.domain.hi[k] <= self.domain.lo[k] || self.domain.hi[k].is_nan() {
                return Err(err(
                    "domain",
                    "hi",
                    format!(
                        "must exceed lo on every axis, got lo {:?} hi {:?}",
                        self.domain.lo, self.domain.hi
                    ),
                ));
            }
        }
        positive("material", "density", self.material.density)?;
        positive("material", "diameter", self.material.diameter)?;
        let c = &self.contact;
        positive("contact", "kn", c.kn)?;
        non_negative("contact", "gamman", c.gamman)?;
        non_negative("contact", "mu", c.mu)?;
        if c.mu > 0.0 {
            positive("contact", "kt", c.kt)?;
            non_negative("contact", "gammat", c.gammat)?;
        }
        if self.tc_free_free().is_none() {
            return Err(err(
                "contact",
                "gamman",
                format!(
                    "overdamped: gamman = {} leaves no oscillation (kn/meff < (gamman/2meff)^2)",
                    c.gamman
                ),
            ));
        }
        match &self.scene {
            Scene::BumpyShear {
                free,
                wall_rows,
                wall_per_row,
                bottom_z,
                top_z,
                ..
            } => {
                if *free == 0 {
                    return Err(err("scene", "free", "must be > 0, got 0".into()));
                }
                if *wall_rows == 0 || *wall_per_row == 0 {
                    return Err(err(
                        "scene",
                        "wall_rows",
                        "walls need rows and spheres per row".into(),
                    ));
                }
                if top_z <= bottom_z || top_z.is_nan() {
                    return Err(err(
                        "scene",
                        "top_z",
                        format!("must exceed bottom_z, got {top_z} <= {bottom_z}"),
                    ));
                }
            }
            Scene::Gas { count, speed } => {
                if *count == 0 {
                    return Err(err("scene", "count", "must be > 0, got 0".into()));
                }
                non_negative("scene", "speed", *speed)?;
            }
            Scene::Spheres { sphere } => {
                if sphere.is_empty() {
                    return Err(err("scene", "sphere", "needs at least one sphere".into()));
                }
                for s in sphere {
                    if let Some(r) = s.radius {
                        positive("scene", "radius", r)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Mass of one sphere, 4/3 π r³ ρ.
    pub fn particle_mass(&self) -> f64 {
        let r = 0.5 * self.material.diameter;
        4.0 / 3.0 * std::f64::consts::PI * r * r * r * self.material.density
    }

    /// Collision time of the linear spring–dashpot for effective mass `meff`,
    /// tc = π / √(kn/meff − (γn/(2 meff))²); `None` when overdamped.
    pub fn collision_time(&self, meff: f64) -> Option<f64> {
        let (kn, g) = (self.contact.kn, self.contact.gamman);
        // Evaluated as MercuryDPM does for the benchmark's dt: π/√(kn/meff − (γn/(2meff))²).
        let w2 = kn / meff - (g / (2.0 * meff)) * (g / (2.0 * meff));
        (w2 > 0.0).then(|| std::f64::consts::PI / w2.sqrt())
    }

    /// Free–free collision time (meff = m/2).
    pub fn tc_free_free(&self) -> Option<f64> {
        self.collision_time(0.5 * self.particle_mass())
    }

    /// Normal restitution coefficient for effective mass `meff`, e = exp(−γn/(2 meff)·tc).
    pub fn restitution(&self, meff: f64) -> Option<f64> {
        self.collision_time(meff)
            .map(|tc| (-self.contact.gamman / (2.0 * meff) * tc).exp())
    }

    /// The time step: `dt` as given, or tc/steps_per_collision.
    pub fn dt(&self) -> f64 {
        match (self.run.dt, self.run.steps_per_collision) {
            (Some(dt), _) => dt,
            (None, Some(s)) => self.tc_free_free().expect("validated") / s,
            (None, None) => unreachable!("validated"),
        }
    }

    /// Gravity, or `None` when absent or zero.
    pub fn gravity(&self) -> Option<[f64; 3]> {
        self.run.gravity.filter(|g| g.iter().any(|c| *c != 0.0))
    }

    /// Resolves a path given in the case (relative to the case file).
    pub fn resolve(&self, p: &str) -> PathBuf {
        let path = Path::new(p);
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.dir.join(path)
        }
    }
}

/// Line (1-based) where `key` is set inside `[table]` (top level for ""), or the table header's
/// line, or 0 when neither is found.
fn locate(text: &str, table: &str, key: &str) -> usize {
    let mut current = String::new();
    let mut header = 0;
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if let Some(name) = table_header(l) {
            current = name;
            if current == table {
                header = n + 1;
            }
            continue;
        }
        if current == table {
            if let Some((k, _)) = l.split_once('=') {
                if k.trim() == key {
                    return n + 1;
                }
            }
        }
    }
    header
}

/// The table a header line `[name]` or `[[name]]` opens.
fn table_header(line: &str) -> Option<String> {
    let rest = line.strip_prefix('[')?;
    Some(
        rest.trim_start_matches('[')
            .split(']')
            .next()
            .unwrap_or("")
            .trim()
            .to_string(),
    )
}

/// Line `line` (1-based) of `text`, trimmed; empty past the end.
fn text_line(text: &str, line: usize) -> &str {
    text.lines().nth(line.wrapping_sub(1)).unwrap_or("").trim()
}

/// The dotted name of what line `line` (1-based) of `text` holds: `table.key` for a key, the
/// table for a header line, "-" for anything else.
fn field_on_line(text: &str, line: usize) -> String {
    let mut table = String::new();
    for l in text.lines().take(line.saturating_sub(1)) {
        if let Some(name) = table_header(l.trim()) {
            table = name;
        }
    }
    let l = text_line(text, line);
    if let Some(name) = table_header(l) {
        return name;
    }
    match l.split_once('=') {
        Some((k, _)) if table.is_empty() => k.trim().to_string(),
        Some((k, _)) => format!("{table}.{}", k.trim()),
        None => "-".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CASE: &str = include_str!("../cases/shear_flow_quick.toml");

    #[test]
    fn benchmark_time_step_is_mercurys_exact_tc_over_50() {
        let case = Case::parse(CASE, "q.toml").unwrap();
        let tc = case.tc_free_free().unwrap();
        assert!((tc - 3.5963e-3).abs() < 1e-7);
        assert_eq!(tc / 50.0, 7.192545031528827e-05);
        assert_eq!(case.dt(), 7.192545031528827e-05);
        assert!((case.restitution(0.5 * case.particle_mass()).unwrap() - 0.90210).abs() < 1e-5);
        assert!((case.restitution(case.particle_mass()).unwrap() - 0.92976).abs() < 1e-5);
    }

    #[test]
    fn invalid_value_names_file_line_and_field() {
        let bad = CASE.replace("kn = 2e5", "kn = -3.0");
        let e = Case::parse(&bad, "bad.toml").unwrap_err();
        let line = bad.lines().position(|l| l.starts_with("kn =")).unwrap() + 1;
        assert_eq!(
            e.to_string(),
            format!("bad.toml:{line}: contact.kn: must be > 0, got -3")
        );
    }

    /// An unknown key, one in the tagged `[scene]` table, and a value of the wrong type.
    #[test]
    fn a_parse_error_names_its_line_and_field() {
        for (from, to, at, field, msg) in [
            (
                "mu = 0.3",
                "mu = 0.3\nfriction = 0.5",
                "friction",
                "contact.friction",
                "unknown field `friction`",
            ),
            (
                "top_vx = 1.0",
                "top_vx = 1.0\nbogus = 1",
                "bogus",
                "scene.bogus",
                "unknown field `bogus`",
            ),
            (
                "skin = 0.1",
                "skin = \"wide\"",
                "skin =",
                "neighbor.skin",
                "invalid type",
            ),
        ] {
            let bad = CASE.replace(from, to);
            let e = Case::parse(&bad, "bad.toml").unwrap_err();
            let line = bad.lines().position(|l| l.starts_with(at)).unwrap() + 1;
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
        }
    }

    #[test]
    fn dt_must_be_given_exactly_once() {
        let bad = CASE.replace(
            "dt = 7.192545031528827e-05",
            "dt = 1e-5\nsteps_per_collision = 50.0",
        );
        let e = Case::parse(&bad, "bad.toml").unwrap_err();
        assert_eq!(e.field, "run.dt");
    }
}
