//! What LAMMPS and LIGGGHTS share: the data file of a state, the input script's frame, the
//! dump commands and files of a save, `mpirun` and the "Loop time of" line of the log. A code
//! of the family is a [`Dialect`]: its names and the lines in which its input differs (units,
//! atom style, contact law, dump formats, the contact-force columns); every dialect is a
//! [`Peer`].
//!
//! Parameter mapping (LAMMPS docs, `pair_style granular`; LIGGGHTS docs, `gran model
//! hooke/stiffness`): absolute damping needs `damping velocity` in LAMMPS (the classic
//! `gran/hooke/history` scales damping by the effective mass and gives a frozen partner its own
//! mass) and `absolute_damping on` in LIGGGHTS; wall spheres are moved by `fix move linear` and so
//! act as infinite mass; LIGGGHTS needs `neigh_modify contact_distance_factor 1.01` so that a
//! tangential spring is reset when its contact ends (`docs/benchmark.md`, known pitfalls).

use std::fmt::Write;
use std::path::Path;

use anyhow::{bail, ensure, Context};

pub mod dump;

use super::inrun::WALLS_FILE;
use super::libraries::MotionPeer;
use super::{
    placed_contacts, wall_speeds, Frame, Installed, Lacks, Launch, Naming, Peer, Program, Run,
    Save, MPIRUN,
};
use crate::case::Case;
use crate::child::{self, OnParentDeath};
use crate::contact::Tangential;
use crate::io::atomic;
use crate::state::Motion;
use crate::state::{Contact, Snapshot};
use crate::Vec3;

/// A code of the LAMMPS family: what its input and output have of their own.
pub trait Dialect: Sync {
    /// Its name on the command line, lower case; the Debian package it comes from.
    const NAME: &'static str;
    /// The installed program.
    const BINARY: &'static str;
    /// The verdem convention of its contact law.
    const CONVENTION: Tangential;
    /// Numbers per line of its contact dump ([`Dialect::contact_dump`]).
    const CONTACT_COLUMNS: usize;
    /// The libraries of its contact law verdem drives through a prescribed motion
    /// ([`Peer::motion`]).
    const MOTION: &'static [MotionPeer];

    /// The script from its units to its neighbour settings: units, atom style, boundary,
    /// `read_data data`, the groups ([`GROUPS`]) and the contact law of `case`.
    fn setup_and_law(case: &Case, data: &str) -> String;

    /// The value of `fix ave/time`'s `format` keyword that prints each number with 17
    /// significant digits after a space; `None` when the code has no such keyword.
    const WALLS_FORMAT: Option<&'static str>;

    /// The `dump_modify` keywords that print every float of a [`DUMP_COLUMNS`] line with 17
    /// significant digits.
    fn dump_format() -> String;

    /// The commands that dump the contact forces every `every` steps into `contacts.STEP.txt`,
    /// one line per pair in contact with the two ids first.
    fn contact_dump(every: u64) -> String;

    /// The force on atom `a` from a line `r` of its contact dump, whose ids are `a` and `b`
    /// (0-based indices into `s`).
    fn force_on_first(r: &[f64], s: &Snapshot, a: usize, b: usize) -> Vec3;
}

/// The groups every input defines: type 1 free, 2 bottom wall, 3 top wall.
pub const GROUPS: &str =
    "group           free   type 1\ngroup           bottom type 2\ngroup           top    type 3\n";

/// The columns of a save's particle dump.
pub const DUMP_COLUMNS: [&str; 12] = [
    "id", "type", "radius", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
];

/// The `boundary` arguments of `case`'s domain: `p` periodic, `f` fixed, per axis.
pub fn boundary(case: &Case) -> String {
    case.domain
        .periodic
        .iter()
        .map(|p| if *p { "p " } else { "f " })
        .collect()
}

/// The neighbour settings: bins of `skin`, rebuilt whenever a sphere moved half of it, no
/// pairs between wall spheres; `extra` adds `neigh_modify` keywords.
pub fn neighbor(case: &Case, extra: &str) -> String {
    format!(
        "neighbor        {:?} bin\n\
neigh_modify    delay 0 every 1 check yes{extra} exclude type 2 2 exclude type 3 3 exclude type 2 3\n",
        case.neighbor.skin
    )
}

/// A data file of a state: atom types 1 free, 2 bottom wall, 3 top wall; `Atoms` lines
/// `id type diameter density x y z` (atom_style sphere / granular), `Velocities` lines
/// `id vx vy vz wx wy wz`. Numbers round-trip.
pub fn data_file(s: &Snapshot, density: f64) -> String {
    let p = &s.particles;
    let mut out = String::from("verdem state for LAMMPS/LIGGGHTS\n\n");
    let _ = writeln!(out, "{} atoms\n3 atom types\n", p.len());
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let _ = writeln!(
            out,
            "{:?} {:?} {axis}lo {axis}hi",
            s.domain.lo[k], s.domain.hi[k]
        );
    }
    out.push_str("\nAtoms # sphere\n\n");
    for a in 0..p.len() {
        let t = match p.motion[a] {
            Motion::Free => 1,
            Motion::Prescribed(0) => 2,
            Motion::Prescribed(_) => 3,
        };
        let x = p.x[a];
        let _ = writeln!(
            out,
            "{} {t} {:?} {density:?} {:?} {:?} {:?}",
            a + 1,
            2.0 * p.radius[a],
            x.x,
            x.y,
            x.z
        );
    }
    out.push_str("\nVelocities\n\n");
    for a in 0..p.len() {
        let (v, w) = (p.v[a], p.w[a]);
        let _ = writeln!(
            out,
            "{} {:?} {:?} {:?} {:?} {:?} {:?}",
            a + 1,
            v.x,
            v.y,
            v.z,
            w.x,
            w.y,
            w.z
        );
    }
    out
}

/// The name a script header gives the code: its name capitalised (`Lammps`).
fn title<D: Dialect>() -> String {
    let mut c = D::NAME.chars();
    c.next()
        .map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}

/// The dump a save writes every `every` steps: `dump.STEP.txt`, one file per save, atoms
/// sorted by id, columns [`DUMP_COLUMNS`], every float with 17 significant digits (round trip),
/// then the contact dump every `contact_every` steps.
fn dump_commands<D: Dialect>(every: u64, contact_every: u64) -> String {
    format!(
        "dump            traj all custom {every} dump.*.txt {}\n\
dump_modify     traj sort id {}\n\
{}",
        DUMP_COLUMNS.join(" "),
        D::dump_format(),
        D::contact_dump(contact_every)
    )
}

/// The walls' every-step mean forces of in-run averaging: `compute reduce sum` of the per-atom
/// force over the groups `bottom` and `top`, averaged by `fix ave/time 1 K K` over every step
/// and written every K = `contact_every` steps to [`WALLS_FILE`]: at step s the mean over steps
/// s − K + 1..s (with K = 1 also a line at step 0, the set-up forces) of the force on the
/// bottom wall's spheres (x, y, z), then the top wall's, in `format` (`None`: the code's
/// default). The per-atom force of a wall sphere at the end of a step is the pair style's alone:
/// `fix move linear` with all three velocities given sets x and v and only reads f (LAMMPS
/// `src/fix_move.cpp`, `initial_integrate`/`final_integrate`; LIGGGHTS has the same fix), and
/// wall–wall pairs are excluded ([`neighbor`]), so it is the force the free spheres exert on
/// the wall.
fn wall_means(contact_every: u64, format: Option<&str>) -> String {
    let k = contact_every;
    let format = format.map_or(String::new(), |f| format!(" format {f}"));
    format!(
        "compute         inrun_fb bottom reduce sum fx fy fz\n\
compute         inrun_ft top reduce sum fx fy fz\n\
fix             inrun_walls all ave/time 1 {k} {k} c_inrun_fb[1] c_inrun_fb[2] c_inrun_fb[3] \
c_inrun_ft[1] c_inrun_ft[2] c_inrun_ft[3] file {WALLS_FILE}{format}\n"
    )
}

/// The dumps of in-run averaging besides the contact dump: every `contact_every` steps the
/// spheres with a contact (`compute contact/atom`, kept by `dump_modify thresh`; LAMMPS and
/// LIGGGHTS docs, `compute contact/atom`, `dump_modify`) in `positions.STEP.txt`, every
/// `particle_every` steps all particles in `particles.STEP.txt`; the columns and format of a
/// save's dump; the walls' every-step mean forces ([`wall_means`]).
fn inrun_dumps<D: Dialect>(contact_every: u64, particle_every: u64) -> String {
    let columns = DUMP_COLUMNS.join(" ");
    let format = D::dump_format();
    format!(
        "compute         inrun_nc all contact/atom\n\
dump            inrun_x all custom {contact_every} positions.*.txt {columns}\n\
dump_modify     inrun_x thresh c_inrun_nc > 0 sort id {format}\n\
dump            inrun_p all custom {particle_every} particles.*.txt {columns}\n\
dump_modify     inrun_p sort id {format}\n\
{}",
        wall_means(contact_every, D::WALLS_FORMAT)
    )
}

/// The bumpy-shear script of `steps` steps from the data file `data`, walls moved rigidly,
/// with the dump commands `dump` (`output` describes them in the header).
fn shear_script<D: Dialect>(
    case: &Case,
    data: &str,
    steps: u64,
    output: &str,
    dump: &str,
) -> anyhow::Result<String> {
    let (vb, vt) = wall_speeds(case)?;
    let dt = case.dt();
    Ok(format!(
        "# {} input generated by verdem from case {:?}: {steps} steps, {output}.\n\
         # Types: 1 free, 2 bottom wall, 3 top wall (moved rigidly by fix move: infinite mass).\n\
{}\
timestep        {dt:?}\n\
velocity        bottom set {vb:?} 0 0 units box\n\
velocity        top    set {vt:?} 0 0 units box\n\
fix             wbot bottom move linear {vb:?} 0 0\n\
fix             wtop top    move linear {vt:?} 0 0\n\
{}",
        title::<D>(),
        case.name,
        D::setup_and_law(case, data),
        integrate_and_run(dump, steps),
    ))
}

/// The free spheres integrated with `nve/sphere`, the dump commands, then the run.
fn integrate_and_run(dump: &str, steps: u64) -> String {
    format!(
        "fix             integ free nve/sphere\n\
{dump}\
thermo          {steps}\n\
run             {steps}\n"
    )
}

/// The arguments of `mpirun` that start `binary` on `np` ranks with the script `script`.
fn mpirun_args(binary: &str, np: usize, script: &str) -> Vec<String> {
    [
        "--allow-run-as-root",
        "--oversubscribe",
        "-np",
        &np.to_string(),
        binary,
        "-in",
        script,
        "-log",
        "none",
    ]
    .map(String::from)
    .to_vec()
}

/// The script file of `binary`'s runs in its run folder.
fn script_name(binary: &str) -> String {
    format!("in.{binary}")
}

/// Runs `launch` (`binary` on MPI ranks, [`mpirun_args`]) in `dir` with `input` (written to
/// [`script_name`]); returns the seconds of its time loop ("Loop time of T on N procs for S
/// steps").
fn run(
    binary: &str,
    package: &str,
    launch: &Launch,
    dir: &Path,
    input: &str,
) -> anyhow::Result<f64> {
    let dir = &dir
        .canonicalize()
        .with_context(|| dir.display().to_string())?;
    let script = dir.join(script_name(binary));
    std::fs::write(&script, input).with_context(|| script.display().to_string())?;
    // SIGTERM when verdem dies: mpirun then stops its ranks, each in a process group of its own
    let out =
        child::output(&mut launch.command(dir), OnParentDeath::Terminate).with_context(|| {
            format!(
                "cannot start mpirun {binary} (install: apt-get install -y {package} {})",
                MPIRUN.package
            )
        })?;
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        bail!(
            "{binary} failed ({}):\n{}",
            out.status,
            text.lines().rev().take(15).collect::<Vec<_>>().join("\n")
        );
    }
    text.lines()
        .find_map(|l| {
            l.strip_prefix("Loop time of ")
                .and_then(|r| r.split_whitespace().next())
                .and_then(|t| t.parse().ok())
        })
        .with_context(|| format!("{binary}: no 'Loop time' line in its output"))
}

impl<D: Dialect> Peer for D {
    fn name(&self) -> &'static str {
        D::NAME
    }

    fn binary(&self) -> &'static str {
        D::BINARY
    }

    /// Its program from its Debian package (named as the peer) and [`MPIRUN`], which starts
    /// it.
    fn installed(&self) -> Installed {
        super::debian(&[
            Program {
                name: D::BINARY,
                package: D::NAME,
            },
            MPIRUN,
        ])
    }

    fn convention(&self) -> Tangential {
        D::CONVENTION
    }

    fn motion(&self) -> Result<&'static [MotionPeer], Lacks> {
        Ok(D::MOTION)
    }

    /// The family computes its set-up forces without advancing the tangential history
    /// (`update->setupflag`).
    fn setup_advances_history(&self) -> bool {
        false
    }

    /// The data file ([`data_file`]) `stem.lmp`.
    fn write_state(
        &self,
        s: &Snapshot,
        density: f64,
        dir: &Path,
        stem: &str,
    ) -> anyhow::Result<String> {
        let name = format!("{stem}.lmp");
        atomic::write(&dir.join(&name), data_file(s, density).as_bytes())?;
        Ok(name)
    }

    /// Walls moved rigidly by `fix move` (infinite mass); thermo only at the start and the
    /// end.
    fn input_script(
        &self,
        case: &Case,
        data: &str,
        steps: u64,
        dump_every: Option<u64>,
    ) -> anyhow::Result<String> {
        let (output, dump) = match dump_every {
            None => ("no file output".to_string(), String::new()),
            Some(every) => (
                format!("a dump every {every} steps"),
                dump_commands::<D>(every, every),
            ),
        };
        shear_script::<D>(case, data, steps, &output, &dump)
    }

    /// The contact dump every `contact_every` steps (so `every` must be a multiple of it),
    /// then [`inrun_dumps`].
    fn inrun_script(
        &self,
        case: &Case,
        data: &str,
        steps: u64,
        every: u64,
        contact_every: u64,
        particle_every: u64,
    ) -> Option<anyhow::Result<String>> {
        if contact_every == 0 || particle_every == 0 || !every.is_multiple_of(contact_every) {
            return Some(Err(anyhow::anyhow!(
                "the save interval ({every}) must be a multiple of the in-run contact sampling \
                 interval ({contact_every}), both at least 1, and the particle interval \
                 ({particle_every}) at least 1"
            )));
        }
        let output = format!(
            "a dump every {every} steps; in-run dumps: contacts every {contact_every} steps, \
             particles every {particle_every} steps"
        );
        let dump = dump_commands::<D>(every, contact_every)
            + &inrun_dumps::<D>(contact_every, particle_every);
        Some(shear_script::<D>(case, data, steps, &output, &dump))
    }

    /// `positions.STEP.txt` for the spheres in contact, `particles.STEP.txt` for all, and
    /// `contacts.STEP.txt`; a contact with a sphere missing from `positions.STEP.txt` is an
    /// error.
    fn read_sample(
        &self,
        run: &Run,
        save: Save,
        template: &Snapshot,
        particles: bool,
    ) -> anyhow::Result<Snapshot> {
        let (dir, step) = (run.dir, save.step);
        let mut s = template.clone();
        s.step = step;
        s.contacts.clear();
        let n = s.particles.len();
        if particles {
            let path = dir.join(format!("particles.{step}.txt"));
            let f = dump::read(&path)?;
            ensure!(
                f.x.len() == n && f.step == step,
                "{}: step {} with {} atoms, expected step {step} with {n}",
                path.display(),
                f.step,
                f.x.len()
            );
            let p = &mut s.particles;
            (p.radius, p.x, p.v, p.w) = (f.radius, f.x, f.v, f.w);
        }
        let path = dir.join(format!("positions.{step}.txt"));
        let (at, atoms) = dump::read_atoms(&path)?;
        ensure!(at == step, "{}: step {at}, expected {step}", path.display());
        let mut placed = Vec::with_capacity(atoms.len());
        for a in atoms {
            ensure!(
                a.id <= n,
                "{}: atom id {} out of range (the state has {n})",
                path.display(),
                a.id
            );
            placed.push((a.id - 1, a.x));
        }
        let atoms = Naming {
            a: "an atom",
            many: "atoms",
            base: 1,
            hint: " (compute contact/atom did not count it)",
        };
        placed_contacts(self, run, save, s, (&path, placed), &atoms)
    }

    fn has_inrun_dumps(&self) -> bool {
        true
    }

    /// [`WALLS_FILE`] of `fix ave/time` ([`wall_means`]).
    fn writes_wall_means(&self) -> bool {
        true
    }

    /// The fixed spheres (types 2 and 3) are held still by `fix move`.
    fn collision_script(&self, case: &Case, data: &str, steps: u64) -> Result<String, Lacks> {
        Ok(format!(
            "# {} input generated by verdem from case {:?}: a two-sphere collision, {steps} steps.\n\
         # Types: 1 free, 2 and 3 fixed spheres (held still by fix move: infinite mass).\n\
{}\
timestep        {dt:?}\n\
fix             still1 bottom move linear 0 0 0\n\
fix             still2 top    move linear 0 0 0\n\
{}",
            title::<D>(),
            case.name,
            D::setup_and_law(case, data),
            integrate_and_run(&dump_commands::<D>(steps, steps), steps),
            dt = case.dt(),
        ))
    }

    /// `mpirun` of the binary on `np` ranks with the script [`script_name`].
    fn launch(&self, np: usize) -> Launch {
        Launch {
            env: Vec::new(),
            program: MPIRUN.name.into(),
            args: mpirun_args(D::BINARY, np, &script_name(D::BINARY)),
            reads: None,
            log: None,
        }
    }

    fn run(&self, run: &Run, input: &str) -> anyhow::Result<f64> {
        self::run(D::BINARY, D::NAME, &self.launch(run.np), run.dir, input)
    }

    /// `dump.STEP.txt` in the run folder.
    fn read_frame(&self, run: &Run, save: Save) -> anyhow::Result<Frame> {
        Ok(dump::read(
            &run.dir.join(format!("dump.{}.txt", save.step)),
        )?)
    }

    /// `contacts.STEP.txt` in the run folder: the contact forces are re-evaluated at the end of
    /// the step, with full-step velocities in the dashpots where the step itself used half-step
    /// velocities; the tangential springs are not dumped, so `xi` is zero.
    fn read_contacts(&self, run: &Run, save: Save, s: &Snapshot) -> anyhow::Result<Vec<Contact>> {
        let path = run.dir.join(format!("contacts.{}.txt", save.step));
        let x = &s.particles.x;
        let mut out = Vec::new();
        for r in dump::read_entries(&path, D::CONTACT_COLUMNS)? {
            let (a, b) = (r[0] as usize, r[1] as usize);
            ensure!(
                (1..=x.len()).contains(&a) && (1..=x.len()).contains(&b),
                "{}: atom ids {a} {b} out of range",
                path.display()
            );
            ensure!(
                a != b,
                "{}: a contact of atom {a} with itself (two different atom ids expected)",
                path.display()
            );
            let (a, b) = (a - 1, b - 1);
            let on_a = D::force_on_first(&r, s, a, b);
            if on_a == Vec3::zeros() {
                continue;
            }
            out.push(super::contact_of(s, a, b, on_a, Vec3::zeros()));
        }
        out.sort_unstable_by_key(|c| (c.p, c.i));
        Ok(out)
    }
}
