//! Kratos DEM (PyPI `KratosMultiphysics` and `KratosDEMApplication` 10.4.4) run from Python:
//! verdem writes the state as an MDPA file (its forces beside it), the run's settings as
//! `kratos.json` and a driver script (`kratos/driver.py`) that sets Kratos' DEM analysis up from
//! them, runs it and writes its saves in the LAMMPS dump layout
//! ([`crate::peers::lammps_family::dump`]).
//!
//! The Python is [`crate::python::python`]'s (`$VERDEM_PYTHON`, else the virtual environment
//! `target/venv` that `ci/test.sh` makes, else `python3`); Kratos DEM is installed into it with
//! [`install_command`]. The mapping of the benchmark's law onto Kratos' (with the Kratos sources
//! of each parameter) is in the driver's header and in `docs/verification.md` ("Kratos DEM as a peer"): the normal law is the
//! benchmark's with the force clipped at zero; the absolute normal damping is exact for
//! spheres of one mass; the tangential dashpot is γn·√(kt/kn) instead of γt and the Coulomb
//! cap splits the force between spring and dashpot in Kratos' own way, so no verdem convention
//! integrates the same tangential equations; per-contact forces are not reachable from Python.

use std::fmt::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use anyhow::{bail, ensure, Context};

use super::lammps_family::dump;
use super::{Frame, Installed, Lacks, Launch, Peer, Run, Save};
use crate::case::Case;
use crate::child::{self, OnParentDeath};
use crate::contact::Tangential;
use crate::io::atomic;
use crate::python::{python, Python, Source, VENV};
use crate::state::{Contact, Motion, Snapshot};
use crate::Vec3;

/// Kratos DEM.
pub struct Kratos;

/// The driver script, written into every run folder as [`DRIVER_NAME`].
const DRIVER: &str = include_str!("kratos/driver.py");

/// The driver's file name in a run folder.
const DRIVER_NAME: &str = "verdem_kratos.py";

/// The settings file the driver reads, in the run folder.
const SETTINGS: &str = "kratos.json";

/// Kratos' own output (and the driver's), in the run folder.
const LOG: &str = "kratos.log";

/// The packages and versions verdem's driver is written for.
pub const PACKAGES: [&str; 2] = ["KratosMultiphysics", "KratosDEMApplication"];

/// How Kratos DEM is installed into a given Python: the arguments after the program.
pub const PIP_INSTALL: &str =
    "-m pip install KratosMultiphysics==10.4.4 KratosDEMApplication==10.4.4";

/// The line of the driver's output that carries the solution loop's wall time.
const LOOP_LINE: &str = "verdem-kratos loop seconds: ";

/// The file in which the driver counts the steps a collision's pair overlaps.
const CONTACT_STEPS: &str = "contact_steps.txt";

/// The shell command that installs Kratos DEM for `python`: [`PIP_INSTALL`] into a Python that
/// was named (`$VERDEM_PYTHON`) or found (a virtual environment); for the default `python3`
/// (whose system-wide pip Debian refuses), the virtual environment `ci/test.sh` makes, from
/// the clone's root, where verdem then finds it.
pub fn install_command(python: &Python) -> String {
    match python.source {
        Source::Default => format!(
            "python3 -m venv {VENV} && {VENV}/bin/python -m pip install -r ci/requirements.txt"
        ),
        Source::Env | Source::CurrentDir | Source::BesideBinary => {
            format!("{} {PIP_INSTALL}", python.program.display())
        }
    }
}

/// What is missing when `python` lacks Kratos DEM: which Python (and why that one) and what
/// failed (`why`).
fn lacks(python: &Python, why: &str) -> String {
    format!("Kratos DEM is not installed for {python}: {why}")
}

/// A Python without Kratos DEM, for `verdem peers` ([`lacks`], [`install_command`]).
fn missing(python: &Python, why: &str) -> Installed {
    Installed::No {
        missing: lacks(python, why),
        install: install_command(python),
    }
}

/// The error of a run whose Python lacks Kratos DEM: [`lacks`] and how to install it.
fn not_installed(python: &Python, why: &str) -> anyhow::Error {
    anyhow::anyhow!(
        "{}; install it with `{}` (or set VERDEM_PYTHON to a Python that has it)",
        lacks(python, why),
        install_command(python)
    )
}

/// A state as an MDPA file: nodes 1…N in verdem's order, one `SphericParticle3D` element per
/// node, the radius and the velocities as nodal data, and the sub-model parts `free`,
/// `bottom` (wall group 0) and `top` (the other wall groups). Numbers round-trip.
pub fn mdpa(s: &Snapshot) -> String {
    let p = &s.particles;
    let n = p.len();
    let mut out = String::from(
        "// verdem state for Kratos DEM\nBegin ModelPartData\nEnd ModelPartData\n\n\
         Begin Properties 0\nEnd Properties\n\nBegin Nodes\n",
    );
    for a in 0..n {
        let x = p.x[a];
        let _ = writeln!(out, "{} {:?} {:?} {:?}", a + 1, x.x, x.y, x.z);
    }
    out.push_str("End Nodes\n\nBegin Elements SphericParticle3D\n");
    for a in 1..=n {
        let _ = writeln!(out, "{a} 0 {a}");
    }
    out.push_str("End Elements\n");
    let nodal = |out: &mut String, name: &str, value: &dyn Fn(usize) -> f64| {
        let _ = writeln!(out, "\nBegin NodalData {name}");
        for a in 0..n {
            let _ = writeln!(out, "{} 0 {:?}", a + 1, value(a));
        }
        out.push_str("End NodalData\n");
    };
    nodal(&mut out, "RADIUS", &|a| p.radius[a]);
    for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
        nodal(&mut out, &format!("VELOCITY_{axis}"), &|a| p.v[a][k]);
    }
    for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
        nodal(&mut out, &format!("ANGULAR_VELOCITY_{axis}"), &|a| {
            p.w[a][k]
        });
    }
    for (group, wanted) in [
        ("free", (|m| m == Motion::Free) as fn(Motion) -> bool),
        ("bottom", |m| m == Motion::Prescribed(0)),
        ("top", |m| matches!(m, Motion::Prescribed(g) if g > 0)),
    ] {
        let ids: Vec<usize> = (0..n).filter(|&a| wanted(p.motion[a])).collect();
        if ids.is_empty() {
            continue;
        }
        let list: String = ids.iter().map(|a| format!("{}\n", a + 1)).collect();
        let _ = write!(
            out,
            "\nBegin SubModelPart {group}\nBegin SubModelPartNodes\n{list}End SubModelPartNodes\n\
             Begin SubModelPartElements\n{list}End SubModelPartElements\nEnd SubModelPart\n"
        );
    }
    out
}

/// The force and torque on each sphere from the contacts of `s` (their last evaluation), one
/// line `id fx fy fz tx ty tz` per sphere with a contact. Numbers round-trip.
pub fn forces(s: &Snapshot) -> String {
    let n = s.particles.len();
    let mut f = vec![(Vec3::zeros(), Vec3::zeros()); n];
    for c in &s.contacts {
        let (p, i) = (c.p as usize, c.i as usize);
        f[p].0 += c.force.f;
        f[p].1 += c.force.torque_p;
        f[i].0 -= c.force.f;
        f[i].1 += c.force.torque_i;
    }
    let mut out = String::new();
    for (a, (force, torque)) in f.iter().enumerate() {
        if *force != Vec3::zeros() || *torque != Vec3::zeros() {
            let _ = writeln!(
                out,
                "{} {:?} {:?} {:?} {:?} {:?} {:?}",
                a + 1,
                force.x,
                force.y,
                force.z,
                torque.x,
                torque.y,
                torque.z
            );
        }
    }
    out
}

/// The settings of a run of `case` from `state` for `steps` steps, a save every `every` steps
/// (0: none), as the JSON object the driver reads; `count_contact` makes it count the steps
/// at whose end the first two spheres overlap. Numbers round-trip.
fn settings(case: &Case, state: &str, steps: u64, every: u64, count_contact: bool) -> String {
    let c = &case.contact;
    let d = &case.domain;
    let v3 = |v: [f64; 3]| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
    format!(
        "{{\n \"case\": {:?},\n \"state\": {:?},\n \"dt\": {:?},\n \"steps\": {steps},\n \
         \"every\": {every},\n \"count_contact\": {count_contact},\n \"lo\": {},\n \"hi\": {},\n \
         \"periodic\": [{}, {}, {}],\n \"margin\": {:?},\n \"skin\": {:?},\n \"density\": {:?},\n \
         \"kn\": {:?},\n \"kt\": {:?},\n \"gamman\": {:?},\n \"mu\": {:?}\n}}\n",
        case.name,
        state,
        case.dt(),
        v3(d.lo),
        v3(d.hi),
        d.periodic[0],
        d.periodic[1],
        d.periodic[2],
        2.0 * case.material.diameter,
        case.neighbor.skin,
        case.material.density,
        c.kn,
        c.kt,
        c.gamman,
        c.mu,
    )
}

impl Peer for Kratos {
    fn name(&self) -> &'static str {
        "kratos"
    }

    fn binary(&self) -> &'static str {
        "kratos"
    }

    /// `pip show` of [`PACKAGES`] in [`python`], after which the Python is named with why it
    /// is that one.
    fn installed(&self) -> Installed {
        let py = python();
        let out = match child::output(
            Command::new(&py.program)
                .args(["-m", "pip", "show"])
                .args(PACKAGES),
            OnParentDeath::Kill,
        ) {
            Ok(out) => out,
            Err(e) => return missing(&py, &format!("cannot start it: {e}")),
        };
        let text = String::from_utf8_lossy(&out.stdout);
        let mut found = Vec::new();
        let mut name = None;
        for line in text.lines() {
            if let Some(n) = line.strip_prefix("Name: ") {
                name = Some(n.trim().to_string());
            } else if let (Some(v), Some(n)) = (line.strip_prefix("Version: "), name.take()) {
                found.push(format!("{n} {}", v.trim()));
            }
        }
        if !out.status.success() || found.len() != PACKAGES.len() {
            return missing(
                &py,
                String::from_utf8_lossy(&out.stderr)
                    .lines()
                    .next()
                    .unwrap_or("pip show found neither package"),
            );
        }
        Installed::Yes(format!("{} in {py}", found.join(", ")))
    }

    /// No verdem convention integrates Kratos' tangential law (its dashpot is γn·√(kt/kn),
    /// its Coulomb cap splits the force between spring and dashpot): MercuryDPM's, which caps
    /// spring and dashpot together as Kratos does while the spring alone is below the cap,
    /// follows it as closely as any (`docs/verification.md` ("Kratos DEM as a peer")).
    fn convention(&self) -> Tangential {
        Tangential::Mercury
    }

    /// Kratos has no set-up force evaluation: its first step computes the forces at the
    /// initial positions and moves on.
    fn setup_advances_history(&self) -> bool {
        false
    }

    fn clips_normal_force(&self) -> bool {
        true
    }

    /// The MDPA file ([`mdpa`]) `stem.mdpa`, which the driver copies to the name Kratos reads,
    /// and beside it the state's forces ([`forces`]) `stem.forces.txt`, from which the driver
    /// turns the state's velocities into the half-step ones Kratos' scheme starts from. The
    /// density enters through the settings ([`Peer::input_script`]).
    fn write_state(
        &self,
        s: &Snapshot,
        _density: f64,
        dir: &Path,
        stem: &str,
    ) -> anyhow::Result<String> {
        let name = format!("{stem}.mdpa");
        atomic::write(&dir.join(&name), mdpa(s).as_bytes())?;
        atomic::write(
            &dir.join(format!("{stem}.forces.txt")),
            forces(s).as_bytes(),
        )?;
        Ok(name)
    }

    /// The settings (`kratos.json`) of the run; the wall spheres move at the state's
    /// velocities.
    fn input_script(
        &self,
        case: &Case,
        state: &str,
        steps: u64,
        dump_every: Option<u64>,
    ) -> anyhow::Result<String> {
        super::wall_speeds(case)?;
        Ok(settings(case, state, steps, dump_every.unwrap_or(0), false))
    }

    /// Saves at the start and at step `steps`; the driver also counts the steps at whose end
    /// the two spheres overlap ([`Peer::contact_steps`]).
    fn collision_script(&self, case: &Case, state: &str, steps: u64) -> Result<String, Lacks> {
        Ok(settings(case, state, steps, steps, true))
    }

    /// The driver run by [`python`] with `np` OpenMP threads (Kratos' MPI build needs a
    /// partitioned model; verdem runs its shared-memory one); Kratos' output goes to
    /// `kratos.log` in the run folder.
    fn launch(&self, np: usize) -> Launch {
        Launch {
            env: vec![("OMP_NUM_THREADS", np.to_string())],
            program: python().program,
            args: vec![DRIVER_NAME.into()],
            reads: Some(SETTINGS),
            log: Some(LOG),
        }
    }

    /// Writes the settings and the driver into the run folder, then runs [`Peer::launch`]'s
    /// command there.
    fn run(&self, run: &Run, input: &str) -> anyhow::Result<f64> {
        let dir = &run
            .dir
            .canonicalize()
            .with_context(|| run.dir.display().to_string())?;
        atomic::write(&dir.join(SETTINGS), input.as_bytes())?;
        atomic::write(&dir.join(DRIVER_NAME), DRIVER.as_bytes())?;
        let log_path = dir.join(LOG);
        let log =
            std::fs::File::create(&log_path).with_context(|| log_path.display().to_string())?;
        let py = python();
        let status = child::status(
            self.launch(run.np)
                .command(dir)
                .stdin(Stdio::null())
                .stdout(log.try_clone()?)
                .stderr(log),
            OnParentDeath::Kill,
        )
        .map_err(|e| not_installed(&py, &format!("cannot start it: {e}")))?;
        let text =
            std::fs::read_to_string(&log_path).with_context(|| log_path.display().to_string())?;
        if text.contains("No module named 'KratosMultiphysics") {
            return Err(not_installed(&py, "no module KratosMultiphysics"));
        }
        if !status.success() {
            bail!(
                "Kratos failed ({status}); the end of {}:\n{}",
                log_path.display(),
                text.lines()
                    .rev()
                    .take(15)
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .collect::<Vec<_>>()
                    .join("\n")
            );
        }
        text.lines()
            .find_map(|l| {
                l.strip_prefix(LOOP_LINE)
                    .and_then(|t| t.trim().parse().ok())
            })
            .with_context(|| format!("{}: no '{LOOP_LINE}' line", log_path.display()))
    }

    /// `dump.STEP.txt` in the run folder. Kratos' symplectic Euler step keeps the velocity
    /// that moved the sphere over the last step: verdem's half-step velocity v(t − dt/2), not
    /// v(t).
    fn read_frame(&self, run: &Run, save: Save) -> anyhow::Result<Frame> {
        Ok(dump::read(
            &run.dir.join(format!("dump.{}.txt", save.step)),
        )?)
    }

    /// Kratos DEM keeps a sphere's contact forces inside the sphere's element and gives
    /// Python no access to them; its contact mesh (`ContactMeshOption`) is built for the
    /// bonded (continuum) strategies only. So there are none to read.
    fn read_contacts(
        &self,
        _run: &Run,
        _save: Save,
        _s: &Snapshot,
    ) -> anyhow::Result<Vec<Contact>> {
        Err(Lacks(
            "Kratos DEM 10.4.4 gives no per-contact forces: the sphere strategy keeps them inside \
             each sphere's element, not reachable from Python, and its contact mesh \
             (ContactMeshOption) is built for bonded (continuum) strategies only",
        )
        .into())
    }

    /// About 100 times slower than LAMMPS here: the default rounds of `verdem bench` would take
    /// hours.
    fn timed_by_default(&self) -> bool {
        false
    }

    /// `contact_steps.txt` of a collision run.
    fn contact_steps(&self, run: &Run) -> anyhow::Result<Option<u64>> {
        let path = run.dir.join(CONTACT_STEPS);
        let text = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
        let n = text
            .trim()
            .parse()
            .with_context(|| format!("{}: expected a whole number", path.display()))?;
        ensure!(n > 0, "{}: the spheres never touched", path.display());
        Ok(Some(n))
    }
}
