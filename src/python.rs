//! The Python verdem runs (Kratos DEM's driver, [`crate::peers::kratos`]) and its tests run
//! (meshio, the example contact laws): one choice, made by [`python`].
//!
//! In this order, the first that applies:
//!
//! 1. `$VERDEM_PYTHON`, when it is set and not empty;
//! 2. the virtual environment `ci/test.sh` makes, [`VENV`]`/bin/python` under the current
//!    directory (verdem run from the clone's root, as the README's commands are);
//! 3. the same environment in the target folder of the running binary (`<clone>/target/release/verdem`
//!    or `<clone>/target/ci/verdem` → `<clone>/target/venv/bin/python`), for a binary run from
//!    elsewhere;
//! 4. `python3`, found on PATH.
//!
//! A virtual environment's Python must exist as a file (a dangling link does not count) and is
//! named by its absolute path (not resolved: a link into the environment stays one), so that
//! it runs in any folder.

use std::ffi::OsString;
use std::fmt;
use std::path::{Path, PathBuf};

/// The virtual environment `ci/test.sh` makes, relative to a clone's root.
pub const VENV: &str = "target/venv";

/// A Python to run, and why it is that one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Python {
    /// The program: `$VERDEM_PYTHON` as given, a virtual environment's absolute path, or
    /// `python3`.
    pub program: PathBuf,
    /// Which rule chose it.
    pub source: Source,
}

/// The rule that chose a [`Python`] (the module's list, in its order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// `$VERDEM_PYTHON`.
    Env,
    /// [`VENV`]`/bin/python` under the current directory.
    CurrentDir,
    /// `venv/bin/python` in the running binary's target folder.
    BesideBinary,
    /// `python3` on PATH: none of the others applies.
    Default,
}

/// The Python verdem runs ([the module's rules](self)); the environment, the current
/// directory and the running binary's path are read on each call.
pub fn python() -> Python {
    let cwd = std::env::current_dir().ok();
    let exe = std::env::current_exe().ok();
    choose(
        std::env::var_os("VERDEM_PYTHON"),
        cwd.as_deref(),
        exe.as_deref(),
    )
}

/// The module's rules for the value of `$VERDEM_PYTHON` `env`, the current directory `cwd` and
/// the running binary `exe`.
fn choose(env: Option<OsString>, cwd: Option<&Path>, exe: Option<&Path>) -> Python {
    let found = |program: PathBuf, source| program.is_file().then_some(Python { program, source });
    env.filter(|e| !e.is_empty())
        .map(|e| Python {
            program: e.into(),
            source: Source::Env,
        })
        .or_else(|| cwd.and_then(|d| found(d.join(VENV).join("bin/python"), Source::CurrentDir)))
        .or_else(|| {
            let target = exe?.parent()?.parent()?;
            found(target.join("venv/bin/python"), Source::BesideBinary)
        })
        .unwrap_or_else(|| Python {
            program: "python3".into(),
            source: Source::Default,
        })
}

/// The program and why it was chosen:
/// `/clone/target/venv/bin/python (target/venv/bin/python in the current directory, …)`.
impl fmt::Display for Python {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let why = match self.source {
            Source::Env => "VERDEM_PYTHON".to_string(),
            Source::CurrentDir => format!(
                "{VENV}/bin/python in the current directory, the virtual environment ci/test.sh \
                 makes; VERDEM_PYTHON unset"
            ),
            Source::BesideBinary => "venv/bin/python in the running verdem's target folder, the \
                 virtual environment ci/test.sh makes; VERDEM_PYTHON unset and no \
                 target/venv in the current directory"
                .to_string(),
            Source::Default => format!(
                "VERDEM_PYTHON unset, no {VENV}/bin/python in the current directory nor in the \
                 running verdem's target folder"
            ),
        };
        write!(f, "{} ({why})", self.program.display())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each rule applies only when the ones before it do not, and an empty `VERDEM_PYTHON`
    /// counts as unset.
    #[test]
    fn the_rules_apply_in_their_order() {
        let dir = tempfile::tempdir().unwrap();
        let (cwd, clone) = (dir.path().join("cwd"), dir.path().join("clone"));
        let exe = clone.join("target/ci/verdem");
        let choice = |env: Option<&str>| choose(env.map(Into::into), Some(&cwd), Some(&exe));
        let python3 = Python {
            program: "python3".into(),
            source: Source::Default,
        };
        assert_eq!(choice(None), python3);
        let beside = clone.join("target/venv/bin/python");
        std::fs::create_dir_all(beside.parent().unwrap()).unwrap();
        std::fs::write(&beside, "").unwrap();
        let beside = Python {
            program: beside,
            source: Source::BesideBinary,
        };
        assert_eq!(choice(None), beside);
        let here = cwd.join("target/venv/bin/python");
        std::fs::create_dir_all(here.parent().unwrap()).unwrap();
        std::fs::write(&here, "").unwrap();
        let here = Python {
            program: here,
            source: Source::CurrentDir,
        };
        assert_eq!(choice(None), here);
        assert_eq!(choice(Some("")), here);
        assert_eq!(
            choice(Some("/opt/py")),
            Python {
                program: "/opt/py".into(),
                source: Source::Env,
            }
        );
        assert_eq!(
            choose(None, None, None),
            python3,
            "no current directory, no binary path"
        );
    }
}
