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
pub mod libraries;
pub mod liggghts;
pub mod motion;
pub mod yade;

use self::libraries::MotionPeer;
use crate::case::{Case, Scene};
use crate::child::{self, OnParentDeath};
use crate::contact::Tangential;
use crate::io::mercury;
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
/// how its saves are read back. What a code may lack (a two-sphere collision run, per-contact
/// forces, a library driven through a prescribed motion, in-run dumps) has a default that says
/// it lacks it ([`Lacks`]); `verdem verify --peers` reports that as an `info` row and
/// `verdem cross` compares what remains.
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
    /// history, as verdem's does by default (the default: yes).
    fn setup_advances_history(&self) -> bool {
        true
    }

    /// Whether its normal force is clipped at zero (no attractive tail at the end of a
    /// contact), as verdem's `clip_normal` (the default: no).
    fn clips_normal_force(&self) -> bool {
        false
    }

    /// Whether `verdem bench` times it when no `--peers` are given (the default: yes); no for
    /// a peer so slow that the default rounds would take hours (it is timed when named).
    fn timed_by_default(&self) -> bool {
        true
    }

    /// Whether `verdem bench --scale` sweeps it when no `--peers` are given (the default: when
    /// [`Peer::timed_by_default`]); no for a peer whose runs at the sweep's largest sizes would
    /// take hours (it is swept when named).
    fn swept_by_default(&self) -> bool {
        self.timed_by_default()
    }

    /// Whether it has the dumps of in-run averaging, [`Peer::inrun_script`] (the default: no;
    /// a peer that implements it says yes here, for the help of `verdem cross --inrun`).
    fn has_inrun_dumps(&self) -> bool {
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
    /// (for timing), else a save of particles and contacts every so many steps, step 0 included
    /// (save index k at step k·`dump_every`), that [`Peer::read_frame`] and
    /// [`Peer::read_contacts`] read.
    fn input_script(
        &self,
        case: &Case,
        state: &str,
        steps: u64,
        dump_every: Option<u64>,
    ) -> anyhow::Result<String>;

    /// An input script running `steps` steps of a two-sphere `case` from `state` (a fixed
    /// sphere held still, with infinite mass), saving at the start (save 0) and at step `steps`
    /// (save 1); the default: it has no such run.
    fn collision_script(&self, _case: &Case, _state: &str, _steps: u64) -> Result<String, Lacks> {
        Err(Lacks("it has no two-sphere collision run"))
    }

    /// How long the normal force of the collision run `run` ([`Peer::collision_script`]) was
    /// positive (time), if the peer records it (the default: it does not).
    fn collision_duration(&self, _run: &Run) -> Option<anyhow::Result<f64>> {
        None
    }

    /// The number of steps the pair of the collision run `run` ([`Peer::collision_script`])
    /// overlapped at the end of a step, where the peer records it (the default: it does not).
    fn contact_steps(&self, _run: &Run) -> anyhow::Result<Option<u64>> {
        Ok(None)
    }

    /// How [`Peer::run`] starts it on `np` processes or threads in its run folder; its text
    /// ([`Launch`]'s `Display`) is the command line of provenance.
    fn launch(&self, np: usize) -> Launch;

    /// Runs `input` as [`Peer::launch`] on `run.np` processes or threads in `run.dir` (where
    /// its files are written); returns the seconds of its own time loop, without set-up and
    /// file reading.
    fn run(&self, run: &Run, input: &str) -> anyhow::Result<f64>;

    /// Its particles at `save` of a run, in id order.
    fn read_frame(&self, run: &Run, save: Save) -> anyhow::Result<Frame>;

    /// Its contacts at `save` of a run, as verdem contacts of the state `s` (its particles at
    /// that save): P the lower index, the force on P, sorted by `(p, i)` ([`contact_of`];
    /// [`mercury_contacts`] for a MercuryCG `.fstat` save). The default: a [`Lacks`] error,
    /// the peer gives no per-contact forces (a cross-run then compares particles only).
    fn read_contacts(
        &self,
        _run: &Run,
        _save: Save,
        _s: &Snapshot,
    ) -> anyhow::Result<Vec<Contact>> {
        Err(Lacks("it gives no per-contact forces").into())
    }

    /// The libraries of its contact law that verdem drives through a prescribed motion in
    /// process (`verdem verify --peers` runs the prescribed-motion cases through them); the
    /// default: none.
    fn motion(&self) -> Result<&'static [MotionPeer], Lacks> {
        Err(Lacks(
            "verdem drives no library of its contact law through a prescribed motion",
        ))
    }

    /// An input script as [`Peer::input_script`] with a save every `every` steps, that also
    /// dumps what in-run averaging samples ([`Peer::read_sample`]): the contact forces and the
    /// positions of the spheres in contact every `contact_every` steps, all particles every
    /// `particle_every` steps; `None` (the default) when the peer has no such dumps.
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

    /// The in-run sample at `save` (index k at step k·`contact_every`) of a run of
    /// [`Peer::inrun_script`], as a snapshot of `template`'s particles (ids, motion, domain) at
    /// that step: the spheres in contact at their dumped positions with the peer's contacts (as
    /// [`Peer::read_contacts`]), and, when `particles`, every particle's radius, position,
    /// velocity and spin; the other particles keep `template`'s values.
    fn read_sample(
        &self,
        _run: &Run,
        _save: Save,
        _template: &Snapshot,
        _particles: bool,
    ) -> anyhow::Result<Snapshot> {
        bail!("{} has no in-run dumps", self.name())
    }

    /// Whether a run of [`Peer::inrun_script`] writes the walls' every-step mean forces to
    /// [`inrun::WALLS_FILE`] in its folder ([`inrun::read_wall_means`]: every `contact_every`
    /// steps the mean over those steps of the force the free particles exert on the bottom [0]
    /// and top [1] wall spheres, force units); the default: no.
    fn writes_wall_means(&self) -> bool {
        false
    }
}

/// Why a peer cannot do what verdem asks of it, in words ("it has no two-sphere collision
/// run"): a capability it lacks, not a failure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Lacks(pub &'static str);

/// What it lacks, when `e` says a peer lacks a capability ([`Lacks`]).
pub fn lacks(e: &anyhow::Error) -> Option<Lacks> {
    e.downcast_ref::<Lacks>().copied()
}

/// Where a peer runs: its run folder and its number of processes (MPI ranks) or threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run<'a> {
    pub dir: &'a Path,
    pub np: usize,
}

/// One save of a peer's run: `index` its place in the run's sequence of saves (0 the one at
/// step 0), `step` the step it was made at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Save {
    pub index: u64,
    pub step: u64,
}

impl Save {
    /// Save `index` of a run saving every `every` steps from step 0.
    pub fn every(every: u64, index: u64) -> Save {
        Save {
            index,
            step: index * every,
        }
    }
}

/// How a peer is started in its run folder ([`Peer::launch`]): environment variables, program
/// and arguments, and the files the command line names besides them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Launch {
    pub env: Vec<(&'static str, String)>,
    pub program: PathBuf,
    pub args: Vec<String>,
    /// An input file it reads that its arguments do not name (`kratos.json`).
    pub reads: Option<&'static str>,
    /// The file its standard output and error go to, when not to verdem.
    pub log: Option<&'static str>,
}

impl Launch {
    /// The command, to be run in `dir`; standard output and error are the caller's to direct
    /// (to [`Launch::log`] when it names one).
    pub fn command(&self, dir: &Path) -> Command {
        let mut c = Command::new(&self.program);
        c.args(&self.args)
            .envs(self.env.iter().map(|(k, v)| (k, v)))
            .current_dir(dir);
        c
    }

    /// Whether it is started by `mpirun`: its processes are MPI ranks.
    pub fn by_mpirun(&self) -> bool {
        self.program == Path::new(MPIRUN.name)
    }
}

/// `VAR=VALUE … PROGRAM ARGS… [(reads FILE)] [> LOG 2>&1]`.
impl fmt::Display for Launch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, v) in &self.env {
            write!(f, "{k}={v} ")?;
        }
        write!(f, "{}", self.program.display())?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        if let Some(file) = self.reads {
            write!(f, " (reads {file})")?;
        }
        if let Some(log) = self.log {
            write!(f, " > {log} 2>&1")?;
        }
        Ok(())
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

/// The contacts of the MercuryCG `.fstat` save `path` (the format verdem writes,
/// [`mercury::fstat_text`]) as verdem contacts of the state `s` (its particles at that save,
/// the file's indices): a line's force on its particle i is fn·n + ft·t, a pair written from
/// both sides is taken once ([`contact_of`]), and as the file gives the spring's length only,
/// springs are zero. Sorted by `(p, i)`; an index beyond `s`'s particles is an error naming the
/// file and line.
pub fn mercury_contacts(path: &Path, s: &Snapshot) -> anyhow::Result<Vec<Contact>> {
    let file = mercury::parse_fstat(&mut crate::io::open(path)?, Some(s.particles.len()))?;
    let mut pairs = std::collections::BTreeMap::new();
    for r in &file.rows {
        pairs
            .entry((r.i.min(r.j), r.i.max(r.j)))
            .or_insert_with(|| {
                contact_of(s, r.i, r.j, r.fn_signed * r.n + r.ft * r.t, Vec3::zeros())
            });
    }
    Ok(pairs.into_values().collect())
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

/// The names of all known peers, comma- and space-separated (`lammps, liggghts`), for help
/// texts.
pub fn listed() -> String {
    known(", ")
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
                p.launch(1),
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

/// The end of a peer's in-run sample at `save` of `run` ([`Peer::read_sample`]): the particles
/// in contact moved to the positions `placed` (index, position) that its positions file `path`
/// gives, then `peer`'s contacts on that state. A contact with a particle `placed` lacks is an
/// error naming the file and both particles.
pub(crate) fn placed_contacts<P: Peer + ?Sized>(
    peer: &P,
    run: &Run,
    save: Save,
    mut s: Snapshot,
    (path, placed): (&Path, Vec<(usize, Vec3)>),
    name: &Naming,
) -> anyhow::Result<Snapshot> {
    let mut seen = vec![false; s.particles.len()];
    for (a, x) in placed {
        s.particles.x[a] = x;
        seen[a] = true;
    }
    s.contacts = peer.read_contacts(run, save, &s)?;
    if let Some(c) = s
        .contacts
        .iter()
        .find(|c| !seen[c.p as usize] || !seen[c.i as usize])
    {
        bail!(
            "{}: the contact of {} {} and {} in contacts.{}.txt has {} missing here{}",
            path.display(),
            name.many,
            c.p + name.base,
            c.i + name.base,
            save.step,
            name.a,
            name.hint
        );
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names of [`all`], in its order, by the text every listing is made of.
    fn all_names() -> Vec<&'static str> {
        all().iter().map(|p| p.name()).collect()
    }

    #[test]
    fn names_are_parsed_once_and_unknown_ones_listed() {
        let names_of_all = all_names();
        assert!(names_of_all.len() >= 2, "{names_of_all:?}");
        assert_eq!(names(), names_of_all.join(","));
        assert_eq!(listed(), names_of_all.join(", "));
        for p in all() {
            assert_eq!(by_name(p.name()).unwrap(), *p);
        }
        let e = by_name("mechsys").unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "unknown peer \"mechsys\" (known: {})",
                names_of_all.join(", ")
            )
        );
        let (first, last) = (names_of_all[0], names_of_all[names_of_all.len() - 1]);
        let list = parse_list(&format!("{last},{first}")).unwrap();
        assert_eq!(
            list.iter().map(|p| p.name()).collect::<Vec<_>>(),
            [last, first]
        );
        assert!(parse_list("").unwrap().is_empty());
        assert!(parse_list(&format!("{first},{first}x")).is_err());
    }

    /// A `.fstat` save verdem writes reads back as the same contacts: each pair once, P the
    /// lower index, the same force on it; a free–wall pair written from one side only.
    #[test]
    fn mercury_contacts_read_back_what_fstat_text_wrote() {
        use crate::state::{Domain, Motion, Particles};
        let mut p = Particles::default();
        for (x, m) in [
            (1.0, Motion::Free),
            (1.9, Motion::Free),
            (2.8, Motion::Prescribed(0)),
        ] {
            p.push(
                Vec3::new(x, 2.0, 2.0),
                Vec3::zeros(),
                Vec3::zeros(),
                0.5,
                1.0,
                m,
            );
        }
        let mut s = Snapshot {
            step: 0,
            time: 0.0,
            domain: Domain::new(Vec3::zeros(), Vec3::new(4.0, 4.0, 4.0), [false; 3]),
            particles: p,
            contacts: Vec::new(),
            walls: Vec::new(),
            wall_contacts: Vec::new(),
        };
        let on_p = [Vec3::new(-3.0, 0.25, 0.0), Vec3::new(-1.0, 0.0, 0.5)];
        s.contacts = [(0, 1), (1, 2)]
            .into_iter()
            .zip(on_p)
            .map(|((a, b), f)| contact_of(&s, a, b, f, Vec3::zeros()))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.fstat.0000");
        std::fs::write(&path, mercury::fstat_text(&s)).unwrap();
        let back = mercury_contacts(&path, &s).unwrap();
        assert_eq!(back.len(), 2);
        for (c, want) in back.iter().zip(&s.contacts) {
            assert_eq!((c.p, c.i), (want.p, want.i));
            assert!((c.force.f - want.force.f).norm() < 1e-12, "{c:?} {want:?}");
            assert!((c.force.fn_signed - want.force.fn_signed).abs() < 1e-12);
        }
        // the contact (1, 2) names particle 2, which a two-particle state lacks
        let mut few = s.clone();
        few.particles.x.truncate(2);
        let e = mercury_contacts(&path, &few).unwrap_err();
        assert!(format!("{e:#}").contains("t.fstat.0000"), "{e:#}");
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

    /// What a peer declares about its in-run dumps (the help of `verdem cross --inrun` lists
    /// the peers from it) is what its [`Peer::inrun_script`] does.
    #[test]
    fn every_peer_declares_the_in_run_dumps_it_has() {
        let case = crate::contact::named::load(Path::new("cases/shear_flow_quick.toml")).unwrap();
        for p in all() {
            let script = p.inrun_script(&case, "state", 100, 50, 10, 50);
            assert_eq!(p.has_inrun_dumps(), script.is_some(), "{}", p.name());
        }
    }
}
