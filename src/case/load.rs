//! Reading a case: the file's size and encoding, the parser, the non-finite numbers, and the
//! checks of every section in order (the first failing one is the error).

use std::path::Path;

use super::locate::Locator;
use super::{Case, CaseError};

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
    /// check but the time step's against the scheme ([`Case::check_time_step`]).
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
        let at = Locator::new(text, file);
        let mut case: Case = toml::from_str(text).map_err(|e| at.parse_error(&e))?;
        let value = toml::from_str::<toml::Value>(text).ok();
        if let Some((field, value)) = value.as_ref().and_then(|v| non_finite(v, "")) {
            return Err(at.error(&field, format!("a finite number expected, got {value}")));
        }
        if let Some(toml::Value::Table(t)) = value.as_ref().and_then(|v| v.get("contact")) {
            case.contact.given = super::Given {
                keys: t.keys().cloned().collect(),
                file: file.into(),
                line: at.line("contact"),
            };
        }
        case.contact.tangential.file = file.into();
        case.contact.tangential.line = at.line("contact.tangential");
        case.contact.normal.file = file.into();
        case.contact.normal.line = at.line("contact.normal");
        case.warnings = case.validate(&at, purpose)?;
        Ok(case)
    }

    /// Checks what the schema cannot, section by section, as `purpose` needs; returns the
    /// warnings.
    fn validate(&self, at: &Locator<'_>, purpose: Purpose) -> Result<Vec<String>, CaseError> {
        if !crate::file_name::plain_file_name(&self.name) {
            return Err(at.error(
                "name",
                format!(
                    "must be a plain file name (1 to {} bytes, no '/', no control character, not \
                     '.' or '..'), got {:?}",
                    crate::file_name::NAME_BYTES,
                    self.name
                ),
            ));
        }
        self.run.check(at)?;
        self.neighbor.check_skin(at)?;
        self.guard.check(at)?;
        self.neighbor.check_cell(at)?;
        self.domain.check(at)?;
        self.material.check(at)?;
        self.contact.check(at)?;
        self.check_derived(at)?;
        if self.tc_free_free().is_none() && self.run.steps_per_collision.is_some() {
            return Err(at.error(
                "run.steps_per_collision",
                format!(
                    "a collision time to divide expected, but gamman = {} over-damps the free–free \
                     contact (kn/meff < (gamman/2meff)^2: it never rebounds); give run.dt instead",
                    self.contact.gamman
                ),
            ));
        }
        self.check_scene(at)?;
        self.check_walls(at)?;
        match purpose {
            Purpose::Run => self.check_time_step(at),
            Purpose::PrescribedMotion => Ok(Vec::new()),
        }
    }
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
