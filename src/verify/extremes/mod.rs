//! The stability map (`verdem extremes`): verdem at the extremes of its parameters, each row
//! with the theory where one exists, the measurement, what verdem did with the case (ran,
//! warned, refused it, or its run guard stopped the run) and a verdict.
//!
//! A row passes when verdem's action fits what the measurement and the theory show: a case
//! the scheme integrates accurately runs; one whose numbers are off says so (a warning); one
//! beyond the scheme's stability limit is refused or stopped; no row may run silently into
//! numbers that cannot be trusted, and no stable case may be refused for being coarse.
//! "What verdem did" comes from the command line's path: the case text parsed by
//! [`Case::parse`], then the run under the guard. The measurement comes from the same engine
//! built with the library, with the time step or the law changed in code where the case file
//! would be refused.
//!
//! - [`timestep`]: dt from tc/400 to beyond 2 tc, binary collisions and the shear case, and the
//!   measured stability limit of a sustained contact;
//! - [`scales`]: stiffness 1e2 … 1e9 at a fixed tc/dt, impact speeds 1e-6 … 1e2;
//! - [`damping`]: elastic, critical, over-critical and explicitly unstable damping;
//! - [`friction`]: mu = 0, mu = 1e6, and mu changed mid-contact through a checkpoint;
//! - [`packing`]: a jammed periodic packing held static, the shear case at a mean volume
//!   fraction of 0.6, and the frictionless gas's momentum over 1e7 steps.

pub mod damping;
pub mod friction;
pub mod packing;
pub mod scales;
pub mod timestep;

use std::path::{Path, PathBuf};

use crate::case::Case;
use crate::step::engine::{self, Overrides};
use crate::step::guard::Failure;
use crate::step::Engine;

/// What verdem did with a case.
#[derive(Clone, Debug, PartialEq)]
pub enum Did {
    /// Parsed and ran to the end without a word.
    Ran,
    /// Parsed with a warning (its first line), and ran.
    Warned(String),
    /// Refused by the case validation (the error's first line).
    Refused(String),
    /// Parsed, and stopped by the run guard (the failure's first line).
    Stopped(String),
}

impl Did {
    /// Ran or warned: the case was accepted and ran to the end.
    pub fn ran(&self) -> bool {
        matches!(self, Did::Ran | Did::Warned(_))
    }

    /// Whether verdem said something: warned, refused or stopped.
    pub fn spoke(&self) -> bool {
        !matches!(self, Did::Ran)
    }

    /// One word and the message's first line.
    pub fn text(&self) -> String {
        let first = |m: &str| m.lines().next().unwrap_or("").to_string();
        match self {
            Did::Ran => "ran".into(),
            Did::Warned(m) => format!("warned: {}", first(m)),
            Did::Refused(m) => format!("refused: {}", first(m)),
            Did::Stopped(m) => format!("stopped: {}", first(m)),
        }
    }
}

/// One row of the map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapRow {
    /// The case (also the group `--only` selects by).
    pub case: String,
    /// The parameter of this row and its value.
    pub parameter: String,
    /// What theory says, in words with numbers; "-" where there is none.
    pub theory: String,
    /// What was measured, in words with numbers.
    pub measured: String,
    pub did: Did,
    pub pass: bool,
}

impl MapRow {
    /// "PASS" or "FAIL".
    pub fn verdict(&self) -> &'static str {
        if self.pass {
            "PASS"
        } else {
            "FAIL"
        }
    }
}

/// Where the map's inputs are.
#[derive(Clone, Debug)]
pub struct Inputs {
    /// The verification cases (binary_collision.toml, oblique_impact.toml, conservation.toml).
    pub verify_dir: PathBuf,
    /// The shear case (its text is what "what verdem did" parses).
    pub shear: PathBuf,
    /// The state the shear rows start from.
    pub shear_state: PathBuf,
    /// Where files the map writes go (checkpoints).
    pub out: PathBuf,
}

impl Inputs {
    /// The inputs of a checkout rooted at `root`, writing into `out`.
    pub fn at(root: &Path, out: &Path) -> Inputs {
        Inputs {
            verify_dir: root.join("cases/verify"),
            shear: root.join("cases/shear_flow.toml"),
            shear_state: root.join("data/states/mercury_t143.85.data"),
            out: out.to_path_buf(),
        }
    }
}

/// A group of rows: its case name and what makes it.
type Group = (&'static str, fn(&Inputs) -> anyhow::Result<Vec<MapRow>>);

/// Every group of the map, in the order of the table.
pub const GROUPS: &[Group] = &[
    (timestep::FREE_FREE, timestep::free_free),
    (timestep::FREE_WALL, timestep::free_wall),
    (timestep::SHEAR, timestep::shear),
    (scales::STIFFNESS, scales::stiffness),
    (scales::SPEED, scales::speed),
    (damping::CASE, damping::rows),
    (friction::CASE, friction::rows),
    (packing::JAMMED, packing::jammed),
    (packing::DENSE_SHEAR, packing::dense_shear),
    (packing::GAS, packing::gas),
];

/// The map, or the rows whose "case parameter" contains `only` (groups that cannot hold such
/// a row are not run).
pub fn map(inputs: &Inputs, only: Option<&str>) -> anyhow::Result<Vec<MapRow>> {
    let mut rows = Vec::new();
    for (name, group) in GROUPS {
        if only.is_some_and(|o| !name.contains(o) && !o.starts_with(name)) {
            continue;
        }
        rows.extend(group(inputs)?);
    }
    if let Some(o) = only {
        rows.retain(|r| format!("{} {}", r.case, r.parameter).contains(o));
    }
    Ok(rows)
}

/// The map as text, a row a line: verdict, case, parameter, then theory, measurement and what
/// verdem did separated by `|`.
pub fn table(rows: &[MapRow]) -> String {
    let mut s = format!(
        "{:<6}{:<20} {:<40} | theory | measured | verdem\n",
        "", "case", "parameter"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<6}{:<20} {:<40} | {} | {} | {}\n",
            r.verdict(),
            r.case,
            r.parameter,
            r.theory,
            r.measured,
            r.did.text()
        ));
    }
    s
}

/// The map as CSV: case, parameter, theory, measured, verdem (what it did), verdict.
pub fn csv(rows: &[MapRow]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let fail = "a CSV table is written to memory";
    w.write_record([
        "case",
        "parameter",
        "theory",
        "measured",
        "verdem",
        "verdict",
    ])
    .expect(fail);
    for r in rows {
        w.write_record([
            r.case.as_str(),
            &r.parameter,
            &r.theory,
            &r.measured,
            &r.did.text(),
            r.verdict(),
        ])
        .expect(fail);
    }
    String::from_utf8(w.into_inner().expect(fail)).expect("CSV of UTF-8 fields")
}

/// `text` with `key = value` set in `[table]`: the key's line replaced, or added after the
/// table's header. `value` is TOML.
pub fn set(text: &str, table: &str, key: &str, value: &str) -> String {
    let mut out = Vec::new();
    let (mut current, mut done) = (String::new(), false);
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            current = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
            out.push(line.to_string());
            if current == table && !done {
                out.push(format!("{key} = {value}"));
                done = true;
            }
            continue;
        }
        let is_key = t.split_once('=').is_some_and(|(k, _)| k.trim() == key);
        if !(current == table && is_key) {
            out.push(line.to_string());
        }
    }
    out.join("\n") + "\n"
}

/// `text` without the key `key` of `[table]`.
pub fn unset(text: &str, table: &str, key: &str) -> String {
    let mut out = Vec::new();
    let mut current = String::new();
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            current = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
        }
        let is_key = t.split_once('=').is_some_and(|(k, _)| k.trim() == key);
        if !(current == table && is_key) {
            out.push(line);
        }
    }
    out.join("\n") + "\n"
}

/// The case file `path` as text and parsed.
pub fn load(path: &Path) -> anyhow::Result<(String, Case)> {
    let (_, text) = crate::io::read_text(path)?;
    Ok((text, Case::load(path)?))
}

/// A case text the command line accepted, and its first warning.
pub struct Accepted {
    pub case: Case,
    pub warning: Option<String>,
}

impl Accepted {
    /// What verdem did with the accepted case whose run ended with `run`.
    pub fn after<T>(&self, run: &Result<T, Failure>) -> Did {
        match (run, &self.warning) {
            (Err(f), _) => stopped(f),
            (Ok(_), Some(w)) => Did::Warned(w.clone()),
            (Ok(_), None) => Did::Ran,
        }
    }
}

/// What verdem's command line does with the case text `text` (read as `path`): the accepted
/// case, or the refusal.
pub fn parse(text: &str, path: &Path) -> Result<Accepted, Did> {
    match Case::parse(text, &path.display().to_string()) {
        Ok(mut case) => {
            case.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
            case.path = path.to_path_buf();
            Ok(Accepted {
                warning: case.warnings().first().cloned(),
                case,
            })
        }
        Err(e) => Err(Did::Refused(e.to_string())),
    }
}

/// What verdem did with the case text `text` (read as `path`) whose run, when accepted, ended
/// with `run`.
pub fn did<T>(text: &str, path: &Path, run: &Result<T, Failure>) -> Did {
    parse(text, path).map_or_else(|refused| refused, |a| a.after(run))
}

/// The first line of a guard failure, shortened to its step and quantity.
pub fn stopped(f: &Failure) -> Did {
    Did::Stopped(format!("step {}: {}", f.step, f.what))
}

/// An engine of `scene` under `case` on one thread; an error when the case names no
/// tangential convention.
pub fn engine_of(
    case: &Case,
    scene: crate::scene::Scene,
) -> Result<Box<dyn Engine>, crate::case::CaseError> {
    let o = Overrides {
        threads: Some(1),
        bind: Some(false),
        ..Overrides::default()
    };
    engine::build(case, scene, &o)
}

/// `x` with 3 significant digits.
pub fn g3(x: f64) -> String {
    format!("{x:.3e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_replaces_a_key_in_its_table_only_and_adds_a_missing_one() {
        let text = "name = \"a\"\n[run]\ndt = 1.0\nsteps = 3\n[contact]\ndt = 7\n";
        let t = set(
            &unset(text, "run", "dt"),
            "run",
            "steps_per_collision",
            "2.5",
        );
        assert_eq!(
            t,
            "name = \"a\"\n[run]\nsteps_per_collision = 2.5\nsteps = 3\n[contact]\ndt = 7\n"
        );
        assert_eq!(
            set(text, "contact", "dt", "8"),
            "name = \"a\"\n[run]\ndt = 1.0\nsteps = 3\n[contact]\ndt = 8\n"
        );
    }
}
