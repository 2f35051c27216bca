//! Peer codes: other DEM codes run on verdem's cases, for timing (`verdem bench`), cross-runs
//! (`verdem cross`, [`cross`]) and binary collisions (`verdem verify --peers`, [`collision`]).
//!
//! A peer is one implementation of [`Peer`] plus one line in [`all`]: it writes a verdem state
//! and an input script in its own format, runs them, and reads its saves back as verdem
//! particles and contacts. LAMMPS ([`lammps`]) and LIGGGHTS ([`liggghts`]) share what the
//! LAMMPS family has in common (data file, dump files, `mpirun`, the log's loop time) in
//! [`lammps_family`]. Names are parsed here once ([`by_name`], [`parse_list`]).

use std::fmt;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};

pub mod collision;
pub mod cross;
pub mod inrun;
pub mod kratos;
pub mod lammps;
pub mod lammps_family;
pub mod liggghts;
pub mod motion;
pub mod yade;

use crate::case::{Case, Scene};
use crate::child::{self, OnParentDeath};
use crate::contact::Tangential;
use crate::state::{Contact, PairForce, Snapshot};
use crate::Vec3;

/// Every known peer, in the order of listings and default runs. A new peer is one line here.
static ALL: &[&dyn Peer] = &[
    &lammps::Lammps,
    &liggghts::Liggghts,
    &yade::Yade,
    &kratos::Kratos,
];

/// A peer code: how it is installed and started, how it reads verdem's cases and states, and
/// how its saves are read back.
pub trait Peer: Sync {
    /// Its name on the command line and in tables, lower case (`lammps`).
    fn name(&self) -> &'static str;

    /// The installed program it runs (`lmp`); also the folder of its runs in an output folder.
    fn binary(&self) -> &'static str;

    /// Whether it is installed: its version, or what is missing and the command that installs
    /// it.
    fn installed(&self) -> Installed;

    /// The verdem tangential convention that integrates the same equations as its contact law.
    fn convention(&self) -> Tangential;

    /// Whether its set-up force evaluation (before the first step) advances the tangential
    /// history, as verdem's does by default.
    fn setup_advances_history(&self) -> bool;

    /// Whether its normal force is clipped at zero (no attractive tail at the end of a
    /// contact), as verdem's `clip_normal`.
    fn clips_normal_force(&self) -> bool {
        false
    }

    /// Writes the state `s` (spheres of mass density `density`) in its own format into `dir`
    /// under the stem `stem`; returns the file name an input script reads.
    fn write_state(
        &self,
        s: &Snapshot,
        density: f64,
        dir: &Path,
        stem: &str,
    ) -> anyhow::Result<String>;

    /// An input script running `steps` steps of the bumpy-shear `case` from the state file
    /// `state` (a [`Peer::write_state`] name or path): with `dump_every` `None` no file output
    /// (for timing), else a save of particles and contacts every so many steps, step 0 included,
    /// that [`Peer::read_frame`] and [`Peer::read_contacts`] read.
    fn input_script(
        &self,
        case: &Case,
        state: &str,
        steps: u64,
        dump_every: Option<u64>,
    ) -> anyhow::Result<String>;

    /// An input script running `steps` steps of a two-sphere `case` from `state` (a fixed
    /// sphere held still, with infinite mass), saving at the start and at step `steps`.
    fn collision_script(&self, case: &Case, state: &str, steps: u64) -> String;

    /// How long the normal force of the collision run in `dir` ([`Peer::collision_script`])
    /// was positive (time), if the peer records it.
    fn collision_duration(&self, _dir: &Path) -> Option<anyhow::Result<f64>> {
        None
    }

    /// Runs `input` on `np` processes in `dir` (where its files are written); returns the
    /// seconds of its own time loop, without set-up and file reading.
    fn run(&self, np: usize, dir: &Path, input: &str) -> anyhow::Result<f64>;

    /// How [`Peer::run`] starts it on `np` processes, as a command line (for provenance).
    fn command_line(&self, np: usize) -> String;

    /// Its particles at save `step` of a run in `dir`, in id order.
    fn read_frame(&self, dir: &Path, step: u64) -> anyhow::Result<Frame>;

    /// Its contacts at save `step` of a run in `dir`, as verdem contacts of the state `s` (its
    /// particles at that save): P the lower index, the force on P, sorted by `(p, i)`.
    fn read_contacts(&self, dir: &Path, step: u64, s: &Snapshot) -> anyhow::Result<Vec<Contact>>;

    /// An input script as [`Peer::input_script`] with a save every `every` steps, that also
    /// dumps what in-run averaging samples ([`Peer::read_sample`]): the contact forces and the
    /// positions of the spheres in contact every `contact_every` steps, all particles every
    /// `particle_every` steps; `None` when the peer has no such dumps.
    fn inrun_script(
        &self,
        _case: &Case,
        _state: &str,
        _steps: u64,
        _every: u64,
        _contact_every: u64,
        _particle_every: u64,
    ) -> Option<anyhow::Result<String>> {
        None
    }

    /// The in-run sample at `step` of a run of [`Peer::inrun_script`] in `dir`, as a snapshot
    /// of `template`'s particles (ids, motion, domain) at that step: the spheres in contact at
    /// their dumped positions with the peer's contacts (as [`Peer::read_contacts`]), and, when
    /// `particles`, every particle's radius, position, velocity and spin; the other particles
    /// keep `template`'s values.
    fn read_sample(
        &self,
        _dir: &Path,
        _step: u64,
        _template: &Snapshot,
        _particles: bool,
    ) -> anyhow::Result<Snapshot> {
        bail!("{} has no in-run dumps", self.name())
    }

    /// Whether a run of [`Peer::inrun_script`] writes the walls' every-step mean forces to
    /// [`inrun::WALLS_FILE`] in its folder ([`inrun::read_wall_means`]: every `contact_every`
    /// steps the mean over those steps of the force the free particles exert on the bottom [0]
    /// and top [1] wall spheres, force units).
    fn writes_wall_means(&self) -> bool {
        false
    }

    /// Whether [`Peer::read_contacts`] can give its contact forces at all (a cross-run without
    /// them compares particles only).
    fn has_contact_forces(&self) -> bool {
        true
    }

    /// The number of steps the pair of a collision run in `dir` ([`Peer::collision_script`])
    /// overlapped at the end of a step, where the peer records it.
    fn contact_steps(&self, _dir: &Path) -> anyhow::Result<Option<u64>> {
        Ok(None)
    }

    /// Whether `verdem bench` times it when no `--peers` are given: false for a peer so slow
    /// that the default rounds would take hours (it is timed when named).
    fn timed_by_default(&self) -> bool {
        true
    }
}

impl fmt::Debug for dyn Peer + '_ {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Peers are equal when their names are.
impl PartialEq for dyn Peer + '_ {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

/// Whether a peer is installed ([`Peer::installed`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Installed {
    /// Installed: its version, after the package it comes from
    /// (`lammps 20220106.git7586adbb6a+ds1-2+b2, openmpi-bin 4.1.4-3`).
    Yes(String),
    /// Not installed: what is missing, and the exact shell command that installs it.
    No { missing: String, install: String },
}

/// The version, or `not installed: MISSING; install it with `COMMAND``.
impl fmt::Display for Installed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Installed::Yes(version) => f.write_str(version),
            Installed::No { missing, install } => {
                write!(f, "not installed: {missing}; install it with `{install}`")
            }
        }
    }
}

/// A program a peer starts by name, and the Debian package it comes from (as `ci/test.sh`
/// installs it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Program {
    pub name: &'static str,
    pub package: &'static str,
}

/// OpenMPI's `mpirun`, which starts the LAMMPS family.
pub const MPIRUN: Program = Program {
    name: "mpirun",
    package: "openmpi-bin",
};

/// The first executable file `name` in the directories of `$PATH`: the program a child
/// started by that name runs; `None` when there is none.
fn on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| {
            std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        })
}

/// Whether all of `programs` are installed: when each is on PATH ([`on_path`]), the versions of
/// their Debian packages (`PACKAGE VERSION`, comma-separated; a program that no installed
/// package holds is named with its path instead); else the ones missing, and the
/// `apt-get install -y` of their packages.
pub fn debian(programs: &[Program]) -> Installed {
    let found: Vec<Option<PathBuf>> = programs.iter().map(|p| on_path(p.name)).collect();
    let missing: Vec<&Program> = programs
        .iter()
        .zip(&found)
        .filter(|(_, f)| f.is_none())
        .map(|(p, _)| p)
        .collect();
    if !missing.is_empty() {
        let names: Vec<&str> = missing.iter().map(|p| p.name).collect();
        let packages: Vec<&str> = missing.iter().map(|p| p.package).collect();
        return Installed::No {
            missing: format!(
                "{} {} not on PATH",
                names.join(" and "),
                if names.len() == 1 { "is" } else { "are" }
            ),
            install: format!("apt-get install -y {}", packages.join(" ")),
        };
    }
    Installed::Yes(
        programs
            .iter()
            .zip(found.into_iter().flatten())
            .map(|(p, path)| {
                package_version(p.package)
                    .unwrap_or_else(|e| format!("{} at {} ({e:#})", p.name, path.display()))
            })
            .collect::<Vec<_>>()
            .join(", "),
    )
}

/// The version of the installed Debian package `package`, after its name.
fn package_version(package: &str) -> anyhow::Result<String> {
    let out = child::output(
        Command::new("dpkg-query").args(["-W", "-f=${Version}", package]),
        OnParentDeath::Kill,
    )
    .context("cannot start dpkg-query")?;
    anyhow::ensure!(
        out.status.success(),
        "dpkg-query: {}",
        String::from_utf8_lossy(&out.stderr).trim()
    );
    Ok(format!(
        "{package} {}",
        String::from_utf8_lossy(&out.stdout)
    ))
}

/// One save of a peer: particles in id order (id 1 first); lengths and times in the case's
/// units.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub step: u64,
    pub radius: Vec<f64>,
    pub x: Vec<Vec3>,
    pub v: Vec<Vec3>,
    pub w: Vec<Vec3>,
}

/// A peer's contact between particles `a` and `b` (indices of `s`) as a verdem contact: the
/// lower index is P, and `on_a` (force on `a`) and `spring_on_a` (its elastic spring, length)
/// are turned to act on P; `fn_signed` is the force along the normal from I to P. Peers give
/// no history and no torques here.
pub fn contact_of(s: &Snapshot, a: usize, b: usize, on_a: Vec3, spring_on_a: Vec3) -> Contact {
    let (p, i, f, spring) = if a < b {
        (a, b, on_a, spring_on_a)
    } else {
        (b, a, -on_a, -spring_on_a)
    };
    let x = &s.particles.x;
    let n = s.domain.min_image(x[p] - x[i]).normalize();
    Contact {
        p: p as u32,
        i: i as u32,
        history: Vec::new(),
        spring,
        force: PairForce {
            f,
            fn_signed: f.dot(&n),
            torque_p: Vec3::zeros(),
            torque_i: Vec3::zeros(),
        },
    }
}

/// Every known peer.
pub fn all() -> &'static [&'static dyn Peer] {
    ALL
}

/// The names of all known peers, comma-separated (`lammps,liggghts`).
pub fn names() -> String {
    known(",")
}

/// The names of the peers `verdem bench` times by default ([`Peer::timed_by_default`]), joined
/// by commas.
pub fn bench_names() -> String {
    ALL.iter()
        .filter(|p| p.timed_by_default())
        .map(|p| p.name())
        .collect::<Vec<_>>()
        .join(",")
}

/// The names of all known peers, joined by `sep`.
fn known(sep: &str) -> String {
    ALL.iter().map(|p| p.name()).collect::<Vec<_>>().join(sep)
}

/// The peer named `name`; the error lists the known names.
pub fn by_name(name: &str) -> anyhow::Result<&'static dyn Peer> {
    match ALL.iter().find(|p| p.name() == name) {
        Some(p) => Ok(*p),
        None => bail!("unknown peer {name:?} (known: {})", known(", ")),
    }
}

/// The peers of a comma-separated list of names (`lammps,liggghts`), in its order; empty
/// entries are skipped, so an empty list names none.
pub fn parse_list(list: &str) -> anyhow::Result<Vec<&'static dyn Peer>> {
    list.split(',')
        .filter(|n| !n.is_empty())
        .map(by_name)
        .collect()
}

/// One line per peer of `peers`, tab-separated: name, binary, convention, the command line
/// of a 1-process run, and whether it is installed ([`Installed`]: its version, or
/// `not installed: …; install it with `COMMAND``).
pub fn listing(peers: &[&dyn Peer]) -> String {
    peers
        .iter()
        .map(|p| {
            format!(
                "{}\t{}\t{}\t{}\t{}\n",
                p.name(),
                p.binary(),
                p.convention().name(),
                p.command_line(1),
                p.installed()
            )
        })
        .collect()
}

/// The bottom and top wall speeds of a bumpy-shear `case` (the only scene peers run).
pub fn wall_speeds(case: &Case) -> anyhow::Result<(f64, f64)> {
    match case.scene {
        Scene::BumpyShear {
            bottom_vx, top_vx, ..
        } => Ok((bottom_vx, top_vx)),
        Scene::Spheres { .. } | Scene::Gas { .. } => {
            bail!("peer inputs are generated for bumpy-shear cases")
        }
    }
}

/// How a peer names its particles in a message: `a` with its article ("an atom"), `many` the
/// plural, `base` its first id (a particle's index plus `base` is its id), `hint` what a missing
/// one means (empty, or starting with a space).
pub(crate) struct Naming {
    pub a: &'static str,
    pub many: &'static str,
    pub base: u32,
    pub hint: &'static str,
}

/// The end of a peer's in-run sample at `step` in `dir` ([`Peer::read_sample`]): the particles
/// in contact moved to the positions `placed` (index, position) that its positions file `path`
/// gives, then `peer`'s contacts on that state. A contact with a particle `placed` lacks is an
/// error naming the file and both particles.
pub(crate) fn placed_contacts<P: Peer + ?Sized>(
    peer: &P,
    dir: &Path,
    step: u64,
    mut s: Snapshot,
    (path, placed): (&Path, Vec<(usize, Vec3)>),
    name: &Naming,
) -> anyhow::Result<Snapshot> {
    let mut seen = vec![false; s.particles.len()];
    for (a, x) in placed {
        s.particles.x[a] = x;
        seen[a] = true;
    }
    s.contacts = peer.read_contacts(dir, step, &s)?;
    if let Some(c) = s
        .contacts
        .iter()
        .find(|c| !seen[c.p as usize] || !seen[c.i as usize])
    {
        bail!(
            "{}: the contact of {} {} and {} in contacts.{step}.txt has {} missing here{}",
            path.display(),
            name.many,
            c.p + name.base,
            c.i + name.base,
            name.a,
            name.hint
        );
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_parsed_once_and_unknown_ones_listed() {
        assert_eq!(names(), "lammps,liggghts,yade,kratos");
        assert_eq!(by_name("liggghts").unwrap().binary(), "liggghts");
        let e = by_name("mechsys").unwrap_err().to_string();
        assert_eq!(
            e,
            "unknown peer \"mechsys\" (known: lammps, liggghts, yade, kratos)"
        );
        let list = parse_list("liggghts,lammps").unwrap();
        assert_eq!(
            list.iter().map(|p| p.name()).collect::<Vec<_>>(),
            ["liggghts", "lammps"]
        );
        assert!(parse_list("").unwrap().is_empty());
        assert!(parse_list("lammps,lmp").is_err());
    }

    #[test]
    fn every_peer_has_its_own_name_and_binary() {
        for (k, a) in all().iter().enumerate() {
            assert_eq!(a.name(), a.name().to_lowercase());
            for b in &all()[k + 1..] {
                assert!(a.name() != b.name() && a.binary() != b.binary());
            }
        }
    }
}
