//! The seam through which every prescribed-motion case drives its contact: a [`MotionDriver`]
//! turns a case (two spheres and a contact law) and a motion into the forces and torques at
//! every row, in the conventions of [`crate::verify::kinematics`] (lab frame, n from sphere 1 to
//! sphere 2, torques about each sphere's centre, row k from row k's motion). [`Own`] is
//! verdem's law; [`External`] runs another program through files, with the interface of
//! `verdem kinematics` (`docs/code-interface.md`).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;

use crate::case::Case;
use crate::child::{self, OnParentDeath};
use crate::io::{self, atomic};
use crate::verify::kinematics::{self, ForceRow, Increment, MotionRow};

/// Something that drives one contact of two spheres through a prescribed motion.
pub trait MotionDriver {
    /// The forces and torques at every row of `motion` for one contact between the two
    /// spheres of `case` (radii from its `spheres` scene) under its contact law, one row per
    /// motion row, at the same times.
    fn drive(&self, case: &Case, motion: &[MotionRow]) -> anyhow::Result<Vec<ForceRow>>;
    /// Its name in the verification table.
    fn name(&self) -> String;
}

/// verdem's own contact law of the case, driven in process ([`kinematics::drive`]).
#[derive(Clone, Copy, Debug)]
pub struct Own {
    pub increment: Increment,
}

/// verdem's law with the increments its integrator feeds it: the driver of verdem's rows.
pub const OWN: Own = Own {
    increment: Increment::Positions,
};

impl MotionDriver for Own {
    fn drive(&self, case: &Case, motion: &[MotionRow]) -> anyhow::Result<Vec<ForceRow>> {
        let (_, radius) = kinematics::pair_of(case)?;
        let law = kinematics::law_of(case)?;
        Ok(kinematics::drive(
            law.as_ref(),
            radius,
            motion,
            self.increment,
        ))
    }

    fn name(&self) -> String {
        "verdem".into()
    }
}

/// `inner` driven through the same motion at a finer step: `fine` rows per row of the motion
/// ([`kinematics::refine`], the refined motion is what `inner` reads, e.g. in its MOTION.csv),
/// with the forces of the motion's own rows returned (every `fine`-th row of `inner`'s).
pub struct Refined<'a> {
    pub inner: &'a dyn MotionDriver,
    pub fine: usize,
}

impl MotionDriver for Refined<'_> {
    fn drive(&self, case: &Case, motion: &[MotionRow]) -> anyhow::Result<Vec<ForceRow>> {
        let rows = kinematics::refine(motion, self.fine);
        let forces = self.inner.drive(case, &rows)?;
        anyhow::ensure!(
            forces.len() == rows.len(),
            "{}: {} rows of forces for {} rows of the refined motion",
            self.inner.name(),
            forces.len(),
            rows.len()
        );
        Ok(forces.into_iter().step_by(self.fine).collect())
    }

    fn name(&self) -> String {
        self.inner.name()
    }
}

/// An external program with the command-line interface of `verdem kinematics`: invoked as
/// `CMD CASE.toml MOTION.csv --out FORCES.csv` through `sh -c` (so `cmd` may hold arguments
/// and quotes), in the current directory, with the files in a fresh folder under `scratch`.
/// A folder is removed when its run succeeded and kept, for inspection, when it failed.
#[derive(Debug)]
pub struct External {
    /// The command, e.g. `python3 mylaw.py` or `verdem kinematics --increment trapezoid`.
    pub cmd: String,
    /// Its name in the verification table.
    pub name: String,
    /// Where each run's folder is made.
    pub scratch: PathBuf,
    /// How long one run may take before it is stopped and reported.
    pub timeout: Duration,
    runs: AtomicUsize,
}

/// How long one run of an external program may take by default: the longest prescribed
/// motion has 1e5 rows, which a script in an interpreted language handles in seconds.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(600);

impl External {
    /// The program `cmd`, named `name` in the table, running in folders under `scratch`, each
    /// run stopped after [`DEFAULT_TIMEOUT`] (see [`External::with_timeout`]).
    pub fn new(cmd: &str, name: &str, scratch: &Path) -> External {
        External {
            cmd: cmd.into(),
            name: name.into(),
            scratch: scratch.into(),
            timeout: DEFAULT_TIMEOUT,
            runs: AtomicUsize::new(0),
        }
    }

    /// The same with each run stopped after `timeout`.
    pub fn with_timeout(self, timeout: Duration) -> External {
        External { timeout, ..self }
    }

    /// A short name for the command: the file name of its first word that names an existing
    /// file after the program (a script), else of the program.
    pub fn default_name(cmd: &str) -> String {
        let words: Vec<&str> = cmd.split_whitespace().collect();
        let file_name = |w: &str| {
            Path::new(w)
                .file_name()
                .map_or(w.to_string(), |f| f.to_string_lossy().into_owned())
        };
        words
            .iter()
            .skip(1)
            .find(|w| Path::new(w).is_file())
            .or(words.first())
            .map_or("code".into(), |w| file_name(w))
    }
}

impl MotionDriver for External {
    fn drive(&self, case: &Case, motion: &[MotionRow]) -> anyhow::Result<Vec<ForceRow>> {
        let start = motion.first().context("a motion of no rows")?;
        let run = self.runs.fetch_add(1, Ordering::Relaxed);
        let dir = self.scratch.join(format!("run{run:03}"));
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot make the folder {}", dir.display()))?;
        let (case_file, motion_file, forces_file) = (
            dir.join("CASE.toml"),
            dir.join("MOTION.csv"),
            dir.join("FORCES.csv"),
        );
        atomic::write(&case_file, case_text(case, start)?.as_bytes())?;
        atomic::write(&motion_file, kinematics::motion_csv(motion).as_bytes())?;
        let forces = self
            .run(&case_file, &motion_file, &forces_file, motion)
            .with_context(|| format!("{}: its files are kept in {}", self.name, dir.display()))?;
        std::fs::remove_dir_all(&dir)
            .with_context(|| format!("cannot remove the folder {}", dir.display()))?;
        Ok(forces)
    }

    fn name(&self) -> String {
        self.name.clone()
    }
}

impl External {
    /// Runs the program on the files and reads its forces back, checked row by row against
    /// the motion's times.
    fn run(
        &self,
        case_file: &Path,
        motion_file: &Path,
        forces_file: &Path,
        motion: &[MotionRow],
    ) -> anyhow::Result<Vec<ForceRow>> {
        let dir = forces_file.parent().unwrap_or(Path::new("."));
        let (stdout_file, stderr_file) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
        let create = |p: &Path| {
            std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))
        };
        // in its own process group, so that a run past its time is stopped with its children;
        // waited for on this thread
        let mut child = child::spawn(
            Command::new("sh")
                .arg("-c")
                .arg(format!("{} \"$@\"", self.cmd))
                .arg("sh")
                .arg(case_file)
                .arg(motion_file)
                .arg("--out")
                .arg(forces_file)
                .stdin(std::process::Stdio::null())
                .stdout(create(&stdout_file)?)
                .stderr(create(&stderr_file)?),
            OnParentDeath::Kill,
        )
        .context("cannot start `sh -c` to run the program")?;
        let started = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().context("cannot wait for the program")? {
                break status;
            }
            if started.elapsed() > self.timeout {
                // SIGKILL to the group: the shell and whatever it started
                child.kill_group();
                let _ = child.wait();
                anyhow::bail!(
                    "`{} {} {} --out {}` did not end within {} s and was stopped (its output: {})",
                    self.cmd,
                    case_file.display(),
                    motion_file.display(),
                    forces_file.display(),
                    self.timeout.as_secs_f64(),
                    stderr_file.display()
                );
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        if !status.success() {
            let stderr = std::fs::read(&stderr_file).unwrap_or_default();
            let stderr = String::from_utf8_lossy(&stderr);
            let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
            let status = match status.code() {
                Some(127) => "exit code 127 (the command was not found)".to_string(),
                Some(c) => format!("exit code {c}"),
                None => "a signal".to_string(),
            };
            anyhow::bail!(
                "`{} {} {} --out {}` ended with {status}{}",
                self.cmd,
                case_file.display(),
                motion_file.display(),
                forces_file.display(),
                if tail.is_empty() {
                    String::new()
                } else {
                    let lines: Vec<&str> = tail.into_iter().rev().collect();
                    format!("; its last error lines:\n  {}", lines.join("\n  "))
                }
            );
        }
        let (file, text) = io::read_text(forces_file)?;
        let rows = kinematics::parse_forces_lines(&file, &text)?;
        if rows.len() != motion.len() {
            anyhow::bail!(
                "{file}: {} rows of forces for {} rows of motion",
                rows.len(),
                motion.len()
            );
        }
        for ((line, f), m) in rows.iter().zip(motion) {
            // the program echoes each row's time; 1e-12 relative allows for printing
            if (f.t - m.t).abs() > 1e-12 * m.t.abs().max(f64::MIN_POSITIVE) {
                anyhow::bail!(
                    "{file}:{line}: t: {} is not the motion's time {} of this row",
                    f.t,
                    m.t
                );
            }
        }
        Ok(rows.into_iter().map(|(_, f)| f).collect())
    }
}

/// The case text handed to a program: the case's own file with the contact law the case
/// runs (`[contact]`, every key written) and the two spheres at the motion's first row with
/// their radii written out. It loads back to the same contact law and radii.
pub fn case_text(case: &Case, start: &MotionRow) -> anyhow::Result<String> {
    let (file, text) = io::read_text(&case.path)?;
    let mut doc: toml::Table = text
        .parse()
        .with_context(|| format!("{file}: not a TOML table"))?;
    let (_, radius) = kinematics::pair_of(case)?;
    let c = &case.contact;
    let mut contact = toml::Table::new();
    for (key, value) in [
        ("kn", c.kn),
        ("gamman", c.gamman),
        ("kt", c.kt),
        ("gammat", c.gammat),
        ("mu", c.mu),
    ] {
        contact.insert(key.into(), value.into());
    }
    contact.insert("tangential".into(), c.tangential.name().into());
    contact.insert("clip_normal".into(), c.clip_normal.into());
    doc.insert("contact".into(), contact.into());
    let spheres: Vec<toml::Value> = (0..2)
        .map(|s| {
            let mut t = toml::Table::new();
            let x: Vec<toml::Value> = start.x[s].iter().map(|&v| v.into()).collect();
            t.insert("x".into(), x.into());
            t.insert("radius".into(), radius[s].into());
            t.into()
        })
        .collect();
    let mut scene = toml::Table::new();
    scene.insert("kind".into(), "spheres".into());
    scene.insert("sphere".into(), spheres.into());
    doc.insert("scene".into(), scene.into());
    let out = toml::to_string(&doc).context("the case as TOML")?;
    let back = Case::parse_for_prescribed_motion(&out, &file)?;
    let (_, back_radius) = kinematics::pair_of(&back)?;
    anyhow::ensure!(
        back.contact == case.contact && back_radius == radius,
        "{file}: the case written for the program does not load back to the same law"
    );
    Ok(out)
}
