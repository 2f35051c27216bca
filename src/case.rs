//! Case files: the TOML schema, its validation, and derived quantities (collision time,
//! restitution). Every error names the file, the line and the field.

use std::path::{Path, PathBuf};

use serde::Deserialize;

pub use crate::contact::{Normal, Tangential};
use crate::stability::{self, Direction, Limit, Pair, Spring};

/// Steps per free–free collision time below which a case is accepted with a warning naming the
/// expected restitution error.
pub const COARSE_STEPS_PER_COLLISION: f64 = 10.0;

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
    /// What validation found acceptable but worth saying, as read (see [`Case::warnings`]).
    #[serde(skip)]
    warnings: Vec<String>,
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
/// trusted (non-finite velocities and positions are always refused). The step runs with it as
/// it is (`step::Params::guard`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
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
    /// Largest energy a contact may give its particles beyond what it took from them and what
    /// its springs held, as a fraction of what it took (> 0; default [`DEFAULT_GUARD_CONTACT`]).
    #[serde(default = "default_guard_contact")]
    pub contact: f64,
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

/// Default of `[guard] contact`.
pub const DEFAULT_GUARD_CONTACT: f64 = 0.01;

fn default_guard_contact() -> f64 {
    DEFAULT_GUARD_CONTACT
}

impl Default for Guard {
    fn default() -> Self {
        Guard {
            overlap: DEFAULT_GUARD_OVERLAP,
            energy: DEFAULT_GUARD_ENERGY,
            contact: DEFAULT_GUARD_CONTACT,
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
    /// Normal law (default `linear`: the spring–dashpot with absolute damping).
    #[serde(default = "default_normal")]
    pub normal: Normal,
    /// Clip the attractive tail of the normal force, fn = max(fn, 0) (default false).
    #[serde(default)]
    pub clip_normal: bool,
}

fn default_tangential() -> Tangential {
    Tangential::Mercury
}

fn default_normal() -> Normal {
    Normal::Linear
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

/// The largest case file (bytes) read: its spheres listed one by one included, a case is text
/// a person writes or a tool generates, far below this.
pub const MAX_CASE_BYTES: u64 = 64 << 20;

/// What a case is read for, which decides the checks it gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Purpose {
    /// Integrated by verdem's scheme: every check, the time step's against the scheme's
    /// stability limit included.
    Run,
    /// Its contact law driven through a prescribed motion, which integrates nothing: every
    /// check but the time step's against the scheme ([`Case::validate_time_step`]).
    PrescribedMotion,
}

impl Case {
    /// Reads and validates a case file.
    pub fn load(path: &Path) -> Result<Case, CaseError> {
        Case::load_for(path, Purpose::Run)
    }

    /// Reads and validates a case file whose contact law is driven through a prescribed
    /// motion (`verdem kinematics`, the prescribed-motion cases of `verdem verify`): as
    /// [`Case::load`], but a time step beyond the scheme's stability limit is not refused nor
    /// a coarse one warned about, since the motion's rows, not `run.dt`, set the steps the law
    /// sees. The law's own parameters are checked as for a run (finite, `kn`, `density`,
    /// `diameter`, radii > 0; `gamman`, `kt`, `gammat`, `mu` >= 0; a collision time, a mass
    /// and an elastic energy a double holds); [`Case::warnings`] is empty.
    pub fn load_for_prescribed_motion(path: &Path) -> Result<Case, CaseError> {
        Case::load_for(path, Purpose::PrescribedMotion)
    }

    fn load_for(path: &Path, purpose: Purpose) -> Result<Case, CaseError> {
        use std::io::Read;
        let file = path.display().to_string();
        let whole = |msg: String| CaseError {
            file: file.clone(),
            line: 0,
            field: "-".into(),
            msg,
        };
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_CASE_BYTES + 1).read_to_end(&mut bytes))
            .map_err(|e| whole(format!("cannot read: {e}")))?;
        if bytes.len() as u64 > MAX_CASE_BYTES {
            return Err(whole(format!(
                "larger than the {MAX_CASE_BYTES} bytes a case file may have (not a case file?)"
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            CaseError {
                file: file.clone(),
                line: valid.iter().filter(|&&b| b == b'\n').count() + 1,
                field: "-".into(),
                msg: format!(
                    "UTF-8 text expected, got the byte {:#04x} (byte {} of the file)",
                    e.as_bytes()[valid.len()],
                    valid.len() + 1
                ),
            }
        })?;
        let mut case = Case::parse_for(&text, &file, purpose)?;
        case.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        case.path = path.to_path_buf();
        Ok(case)
    }

    /// Parses and validates case text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Case, CaseError> {
        Case::parse_for(text, file, Purpose::Run)
    }

    /// Parses and validates case text for a prescribed motion, with the checks of
    /// [`Case::load_for_prescribed_motion`]; `file` names it in errors.
    pub fn parse_for_prescribed_motion(text: &str, file: &str) -> Result<Case, CaseError> {
        Case::parse_for(text, file, Purpose::PrescribedMotion)
    }

    fn parse_for(text: &str, file: &str, purpose: Purpose) -> Result<Case, CaseError> {
        let mut case: Case = toml::from_str(text).map_err(|e| {
            let mut line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
                .unwrap_or(0);
            let mut field = field_on_line(text, line);
            let msg = e.message().trim().to_string();
            // A tagged table (`[scene]`) is read whole, and its error points at the header: find
            // the unknown key, or the key holding the value of the wrong type, in it.
            if let Some(table) = table_header(text_line(text, line)) {
                let unknown = msg
                    .strip_prefix("unknown field `")
                    .and_then(|m| m.split('`').next());
                let length = msg
                    .strip_prefix("invalid length ")
                    .and_then(|m| m.split(',').next()?.parse::<usize>().ok());
                let found = match (unknown, offending_value(&msg), length) {
                    (Some(key), _, _) => find_under(text, &table, |k, _| k == key),
                    (None, Some(value), _) => find_under(text, &table, |_, v| same_value(v, value)),
                    (None, None, Some(n)) => {
                        find_under(text, &table, |_, v| array_of(v) == Some(n))
                    }
                    (None, None, None) => None,
                };
                if let Some(at) = found {
                    (line, field) = at;
                }
            }
            // A missing key is reported at its table's header: name the key, and the element
            // of an array of tables under it that lacks it.
            if let Some(key) = msg
                .strip_prefix("missing field `")
                .and_then(|m| m.split('`').next())
            {
                match lacking(text, &field, key) {
                    Some(element) => {
                        line = locate_path(text, &segments(&element));
                        field = format!("{element}.{key}");
                    }
                    None if field == "-" => field = key.to_string(),
                    None => field = format!("{field}.{key}"),
                }
            }
            CaseError {
                file: file.into(),
                line,
                field,
                msg: msg.split('\n').collect::<Vec<_>>().join("; "),
            }
        })?;
        let at = Locator { text, file };
        if let Some((field, value)) = toml::from_str::<toml::Value>(text)
            .ok()
            .and_then(|v| non_finite(&v, ""))
        {
            return Err(at.error(&field, format!("a finite number expected, got {value}")));
        }
        case.warnings = case.validate(&at, purpose)?;
        Ok(case)
    }

    /// What validation accepted with a warning (`file:line: field: message`), for the case as
    /// read: a coarse time step and the restitution error it is expected to cost.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Checks what the schema cannot, as `purpose` needs; returns the warnings.
    fn validate(&self, at: &Locator<'_>, purpose: Purpose) -> Result<Vec<String>, CaseError> {
        let err = |table: &str, key: &str, msg: String| {
            if table.is_empty() {
                at.error(key, msg)
            } else {
                at.error(&format!("{table}.{key}"), msg)
            }
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
        if !crate::io::plain_file_name(&self.name) {
            return Err(err(
                "",
                "name",
                format!(
                    "must be a plain file name (1 to {} bytes, no '/', no control character, not \
                     '.' or '..'), got {:?}",
                    crate::io::NAME_BYTES,
                    self.name
                ),
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
        positive("guard", "contact", self.guard.contact)?;
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
        non_negative("contact", "kt", c.kt)?;
        non_negative("contact", "gammat", c.gammat)?;
        non_negative("contact", "mu", c.mu)?;
        if c.mu > 0.0 {
            positive("contact", "kt", c.kt)?;
        }
        self.validate_derived(at)?;
        if self.tc_free_free().is_none() && self.run.steps_per_collision.is_some() {
            return Err(err(
                "run",
                "steps_per_collision",
                format!(
                    "a collision time to divide expected, but gamman = {} over-damps the free–free \
                     contact (kn/meff < (gamman/2meff)^2: it never rebounds); give run.dt instead",
                    c.gamman
                ),
            ));
        }
        self.validate_scene(at)?;
        match purpose {
            Purpose::Run => self.validate_time_step(at),
            Purpose::PrescribedMotion => Ok(Vec::new()),
        }
    }

    /// Refuses parameters whose derived quantities a double cannot hold: a sphere's mass, the
    /// collision time and the time step zero, subnormal or infinite, tc/dt not finite, or the
    /// elastic energy at the guard's overlap limit overflowing. Each error names the field
    /// the quantity comes from.
    fn validate_derived(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        let representable = |v: f64| v.is_finite() && v >= f64::MIN_POSITIVE;
        let m = self.particle_mass();
        if !representable(m) {
            return Err(at.error(
                "material.density",
                format!(
                    "the sphere's mass 4/3 pi r^3 rho = {m:e} (diameter {}, density {}) is not \
                     a representable positive number",
                    self.material.diameter, self.material.density
                ),
            ));
        }
        let tc = self.tc_free_free();
        if let Some(tc) = tc.filter(|&tc| !representable(tc)) {
            return Err(at.error(
                "contact.kn",
                format!(
                    "the free–free collision time pi/sqrt(kn/meff - (gamman/2meff)^2) = {tc:e} \
                     (kn = {:e}, meff = {:e}) is not a representable positive number",
                    self.contact.kn,
                    0.5 * m
                ),
            ));
        }
        let (_, largest) = self.largest_diameters();
        let reach = self.guard.overlap * 0.5 * largest;
        let elastic = 0.5 * self.contact.kn * reach * reach;
        if !elastic.is_finite() {
            return Err(at.error(
                "contact.kn",
                format!(
                    "the elastic energy 1/2 kn delta^2 at the guard's overlap limit (delta = \
                     {reach:e}) overflows: kn = {:e} is too stiff to be represented",
                    self.contact.kn
                ),
            ));
        }
        let field = if self.run.dt.is_some() {
            "run.dt"
        } else if tc.is_some() {
            "run.steps_per_collision"
        } else {
            // No collision time to divide: refused next, as an over-damped contact.
            return Ok(());
        };
        let dt = self.dt();
        if !representable(dt) {
            return Err(at.error(
                field,
                format!("the time step dt = {dt:e} is not a representable positive number"),
            ));
        }
        if let Some(tc) = tc.filter(|tc| !(tc / dt).is_finite()) {
            return Err(at.error(field, format!("tc/dt = {tc:e}/{dt:e} is not finite")));
        }
        Ok(())
    }

    /// The box against the spheres, the walls against each other and the box, the number of
    /// spheres against the room the scene gives them, and the walls' prescribed velocities.
    fn validate_scene(&self, at: &Locator<'_>) -> Result<(), CaseError> {
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

    /// Refuses a time step beyond the stability limit of the stiffest contact the scene can
    /// have; warns about a coarse one (tc/dt below [`COARSE_STEPS_PER_COLLISION`]).
    fn validate_time_step(&self, at: &Locator<'_>) -> Result<Vec<String>, CaseError> {
        let field = if self.run.dt.is_some() {
            "run.dt"
        } else {
            "run.steps_per_collision"
        };
        let dt = self.dt();
        let Some(limit) = self.stability_limit() else {
            return Ok(Vec::new());
        };
        // An over-damped contact has no collision time: the limit is stated as a dt only.
        let Some(tc) = self.tc_free_free() else {
            if dt > limit.dt {
                return Err(at.error(
                    field,
                    format!(
                        "at most the stability limit of the {} contact, dt = {:.5e} \
                         (docs/stability.md) expected, got dt = {dt:.5e}",
                        limit.contact(),
                        limit.dt,
                    ),
                ));
            }
            return Ok(vec![at
                .error(
                    "contact.gamman",
                    format!(
                        "over-damped contact: gamman = {} leaves no oscillation, so colliding \
                         spheres do not rebound (with clip_normal = false the dashpot also pulls \
                         them together as they part)",
                        self.contact.gamman
                    ),
                )
                .to_string()]);
        };
        if dt > limit.dt {
            return Err(at.error(
                field,
                format!(
                    "at most the stability limit of the {} contact, dt = {:.5e} (tc/dt = {:.4}; \
                     docs/stability.md) expected, got dt = {dt:.5e} (tc/dt = {:.4})",
                    limit.contact(),
                    limit.dt,
                    tc / limit.dt,
                    tc / dt
                ),
            ));
        }
        let per_tc = tc / dt;
        if per_tc >= COARSE_STEPS_PER_COLLISION * (1.0 - 1e-12) {
            return Ok(Vec::new());
        }
        let normal = stability::Spring {
            k: self.contact.kn,
            gamma: self.contact.gamman,
        };
        let errors: Vec<String> = self
            .pairs()
            .into_iter()
            .map(|(pair, meff)| {
                format!(
                    "{:.1e} {}",
                    stability::restitution_error(meff, normal, dt),
                    pair.name()
                )
            })
            .collect();
        let warning = at.error(
            field,
            format!(
                "coarse time step, tc/dt = {per_tc:.3} (below {COARSE_STEPS_PER_COLLISION}): \
                 relative restitution error up to {} (verdem's scheme run on one head-on \
                 collision, worst onset within a step; docs/stability.md)",
                errors.join(", ")
            ),
        );
        Ok(vec![warning.to_string()])
    }

    /// The contacts the scene can have, each with its normal effective mass (mass): free–free
    /// with two or more free spheres (the two lightest), free–wall with wall spheres (the
    /// lightest free sphere). The material's diameter stands for the spheres of an initial
    /// file.
    pub fn pairs(&self) -> Vec<(Pair, f64)> {
        let m = self.particle_mass();
        let (free, walls) = match &self.scene {
            Scene::BumpyShear { free, .. } => (vec![m; (*free).min(2)], true),
            Scene::Gas { count, .. } => (vec![m; (*count).min(2)], false),
            Scene::Spheres { sphere } => {
                let density = self.material.density;
                let d = self.material.diameter;
                let mut free: Vec<f64> = sphere
                    .iter()
                    .filter(|s| !s.fixed)
                    .map(|s| sphere_volume(2.0 * s.radius.unwrap_or(0.5 * d)) * density)
                    .collect();
                free.sort_by(f64::total_cmp);
                (free, sphere.iter().any(|s| s.fixed))
            }
        };
        let mut pairs = Vec::new();
        if let [m1, m2, ..] = free[..] {
            pairs.push((Pair::FreeFree, m1 * m2 / (m1 + m2)));
        }
        if let (true, Some(&m)) = (walls, free.first()) {
            pairs.push((Pair::FreeWall, m));
        }
        pairs
    }

    /// The stability limit of every contact the scene can have ([`Case::pairs`]): normal, and
    /// tangential when mu > 0.
    pub fn stability_limits(&self) -> Vec<Limit> {
        let c = &self.contact;
        let normal = Spring {
            k: c.kn,
            gamma: c.gamman,
        };
        let tangential = Spring {
            k: c.kt,
            gamma: c.gammat,
        };
        let mut limits = Vec::new();
        for (pair, meff) in self.pairs() {
            limits.push(Limit::of(pair, Direction::Normal, meff, normal));
            if c.mu > 0.0 {
                limits.push(Limit::of(pair, Direction::Tangential, meff, tangential));
            }
        }
        limits
    }

    /// The smallest of [`Case::stability_limits`], `None` when the scene has no contact; of
    /// limits equal to round-off (kt/kn = γt/γn = 2/7 makes the tangential one the normal
    /// one), the first: normal before tangential, free–free before free–wall.
    pub fn stability_limit(&self) -> Option<Limit> {
        self.stability_limits().into_iter().reduce(|best, l| {
            if l.dt < best.dt * (1.0 - 1e-12) {
                l
            } else {
                best
            }
        })
    }

    /// The largest diameters (length) of a free sphere and of any sphere.
    fn largest_diameters(&self) -> (f64, f64) {
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

/// Volume of a sphere of diameter `d`, π d³/6.
fn sphere_volume(d: f64) -> f64 {
    std::f64::consts::PI / 6.0 * d * d * d
}

/// Where errors about a case text point: its file, and the line of a field.
struct Locator<'a> {
    text: &'a str,
    file: &'a str,
}

impl Locator<'_> {
    /// The error `msg` about `field`, a dotted path with indices (`scene.sphere[1].x`), at the
    /// line that sets it.
    fn error(&self, field: &str, msg: String) -> CaseError {
        CaseError {
            file: self.file.into(),
            line: locate_path(self.text, &segments(field)),
            field: field.into(),
            msg,
        }
    }
}

/// One step of a path into a TOML document.
#[derive(Clone, Debug, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// The steps of a dotted path with indices: `scene.sphere[1].x` → scene, sphere, 1, x.
fn segments(field: &str) -> Vec<Seg> {
    let mut out = Vec::new();
    for part in field.split('.') {
        let mut pieces = part.split('[');
        out.push(Seg::Key(pieces.next().unwrap_or("").to_string()));
        for p in pieces {
            if let Ok(n) = p.trim_end_matches(']').parse() {
                out.push(Seg::Index(n));
            }
        }
    }
    out
}

/// The first number in `v` that is not finite (NaN or ±inf), with its dotted path.
fn non_finite(v: &toml::Value, path: &str) -> Option<(String, f64)> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some((path.to_string(), *x)),
        toml::Value::Table(t) => t.iter().find_map(|(k, v)| {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            non_finite(v, &p)
        }),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(n, v)| non_finite(v, &format!("{path}[{n}]"))),
        _ => None,
    }
}

/// Line (1-based) of the key line that sets `path` (or a value it is inside of, as `x` holds
/// `x[1]`), else of the header of the deepest table holding it, else 0. A `[[name]]` header
/// opens element n of the array `name`, counted from 0.
fn locate_path(text: &str, path: &[Seg]) -> usize {
    let mut table: Vec<Seg> = Vec::new();
    let mut count: std::collections::HashMap<String, usize> = Default::default();
    let (mut header, mut header_depth) = (0, 0);
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if let Some(name) = table_header(l) {
            table = name
                .split('.')
                .map(|k| Seg::Key(k.trim().trim_matches('"').to_string()))
                .collect();
            if l.starts_with("[[") {
                let c = count.entry(name).or_insert(0);
                table.push(Seg::Index(*c));
                *c += 1;
            }
            if path.starts_with(&table) && table.len() > header_depth {
                (header, header_depth) = (n + 1, table.len());
            }
            continue;
        }
        if l.starts_with('#') {
            continue;
        }
        if let Some((k, _)) = l.split_once('=') {
            let mut full = table.clone();
            full.extend(
                k.split('.')
                    .map(|k| Seg::Key(k.trim().trim_matches('"').to_string())),
            );
            if path.starts_with(&full) {
                return n + 1;
            }
        }
    }
    header
}

/// The first key line inside `[table]` or the tables under it (`[[table.sub]]`) for which
/// `pick(key, value text)` holds: its line (1-based) and its dotted field with indices.
fn find_under(
    text: &str,
    table: &str,
    pick: impl Fn(&str, &str) -> bool,
) -> Option<(usize, String)> {
    let mut current: Vec<Seg> = Vec::new();
    let mut count: std::collections::HashMap<String, usize> = Default::default();
    let top = segments(table);
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if let Some(name) = table_header(l) {
            current = segments(&name);
            if l.starts_with("[[") {
                let c = count.entry(name).or_insert(0);
                current.push(Seg::Index(*c));
                *c += 1;
            }
            continue;
        }
        let Some((k, v)) = l.split_once('=') else {
            continue;
        };
        let value = v.split(" #").next().unwrap_or("").trim();
        if l.starts_with('#') || !current.starts_with(&top) || !pick(k.trim(), value) {
            continue;
        }
        let mut field = String::new();
        for seg in &current {
            match seg {
                Seg::Key(k) if field.is_empty() => field.push_str(k),
                Seg::Key(k) => field.push_str(&format!(".{k}")),
                Seg::Index(i) => field.push_str(&format!("[{i}]")),
            }
        }
        return Some((n + 1, format!("{field}.{}", k.trim())));
    }
    None
}

/// The first element `table.name[i]` of an array of tables under `table` (a table's dotted
/// name) that lacks `key`, when `table` itself has it or is not a table.
fn lacking(text: &str, table: &str, key: &str) -> Option<String> {
    let doc: toml::Value = toml::from_str(text).ok()?;
    let mut t = &doc;
    for k in table.split('.') {
        t = t.get(k)?;
    }
    let t = t.as_table()?;
    t.iter().find_map(|(name, v)| {
        let elements = v.as_array()?;
        let i = elements
            .iter()
            .position(|e| e.as_table().is_some_and(|e| !e.contains_key(key)))?;
        Some(format!("{table}.{name}[{i}]"))
    })
}

/// The length of the array a key line's value text holds, if it is one.
fn array_of(text: &str) -> Option<usize> {
    let v: toml::Value = toml::from_str(&format!("v = {text}")).ok()?;
    v.get("v")?.as_array().map(Vec::len)
}

/// The value a serde "invalid type/value" message quotes: `2.5` of "invalid type: floating
/// point `2.5`, expected usize", or "one" (with its quotes) of a string.
fn offending_value(msg: &str) -> Option<&str> {
    let rest = msg
        .strip_prefix("invalid type: ")
        .or_else(|| msg.strip_prefix("invalid value: "))?;
    let rest = rest.split(", expected").next()?;
    if let Some(start) = rest.find('`') {
        return rest[start + 1..].split('`').next();
    }
    let start = rest.find('"')?;
    Some(&rest[start..])
}

/// Whether the value text of a key line is the value `quoted` from an error message (numbers
/// compared as numbers: `2_000` is `2000`).
fn same_value(text: &str, quoted: &str) -> bool {
    let number = |s: &str| s.replace('_', "").parse::<f64>().ok();
    text == quoted || matches!((number(text), number(quoted)), (Some(a), Some(b)) if a == b)
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

    /// A prescribed motion integrates nothing: the time step's checks against the scheme are
    /// a run's only, the law's are every reader's.
    #[test]
    fn a_prescribed_motion_gets_the_laws_checks_and_not_the_time_steps() {
        let dt = |v: &str| CASE.replace("dt = 7.192545031528827e-05", &format!("dt = {v}"));
        // tc/5, then tc/1, beyond the limit tc/1.62
        let coarse = dt("7.192545031528827e-04");
        assert_eq!(Case::parse(&coarse, "c.toml").unwrap().warnings().len(), 1);
        let read = Case::parse_for_prescribed_motion(&coarse, "c.toml").unwrap();
        assert!(read.warnings().is_empty());
        let beyond = dt("3.6e-3");
        let e = Case::parse(&beyond, "b.toml").unwrap_err().to_string();
        assert!(e.contains("at most the stability limit"), "{e}");
        let read = Case::parse_for_prescribed_motion(&beyond, "b.toml").unwrap();
        assert_eq!(read.dt(), 3.6e-3);
        for (from, to, msg) in [
            ("kn = 2e5", "kn = -3.0", "contact.kn: must be > 0, got -3"),
            (
                "kn = 2e5",
                "kn = 1e308",
                "contact.kn: the free–free collision time",
            ),
            (
                "density = 1.0",
                "density = nan",
                "material.density: a finite number expected, got NaN",
            ),
        ] {
            let bad = beyond.replacen(from, to, 1);
            let e = Case::parse_for_prescribed_motion(&bad, "b.toml")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("b.toml:") && e.contains(msg), "{e}");
        }
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

    const PAIR: &str = include_str!("../cases/verify/binary_collision.toml");
    const WALL: &str = include_str!("../cases/verify/oblique_impact.toml");

    /// The line of the second `[[scene.sphere]]`'s `x`, and of a key of a plain table.
    #[test]
    fn a_field_is_located_in_its_table_and_array_element() {
        let second_x = PAIR
            .lines()
            .position(|l| l.starts_with("x = [0.5005"))
            .unwrap()
            + 1;
        let path = segments("scene.sphere[1].x[2]");
        assert_eq!(locate_path(PAIR, &path), second_x);
        let kn = PAIR.lines().position(|l| l.starts_with("kn =")).unwrap() + 1;
        assert_eq!(locate_path(PAIR, &segments("contact.kn")), kn);
        // absent key: the header of the deepest table that would hold it
        let header = PAIR.lines().position(|l| l == "[contact]").unwrap() + 1;
        assert_eq!(locate_path(PAIR, &segments("contact.bogus")), header);
    }

    /// Two free spheres have a free–free contact only; a free sphere and a wall sphere a
    /// free–wall one; with kt/kn = γt/γn = 2/7 the normal limit is named.
    #[test]
    fn the_contacts_of_the_scene_set_the_limit() {
        let pair = Case::parse(PAIR, "p.toml").unwrap();
        let m = pair.particle_mass();
        assert_eq!(pair.pairs(), vec![(Pair::FreeFree, 0.5 * m)]);
        assert_eq!(pair.stability_limits().len(), 2);
        let limit = pair.stability_limit().unwrap();
        assert_eq!(
            (limit.pair, limit.direction),
            (Pair::FreeFree, Direction::Normal)
        );
        let wall = Case::parse(WALL, "w.toml").unwrap();
        assert_eq!(wall.pairs(), vec![(Pair::FreeWall, m)]);
        assert!(wall.stability_limit().unwrap().dt > limit.dt);
        let quick = Case::parse(CASE, "q.toml").unwrap();
        let kinds: Vec<Pair> = quick.pairs().iter().map(|p| p.0).collect();
        assert_eq!(kinds, [Pair::FreeFree, Pair::FreeWall]);
    }
}
