//! LAMMPS and LIGGGHTS on the same case: their data file and input script generated from a
//! verdem case and state, and the installed binaries (Debian packages `lammps`, `liggghts`:
//! `apt-get install -y lammps liggghts`) run with `mpirun -np N`.
//!
//! Parameter mapping (LAMMPS docs, `pair_style granular`; LIGGGHTS docs, `gran model
//! hooke/stiffness`): absolute damping needs `damping velocity` in LAMMPS (the classic
//! `gran/hooke/history` scales damping by the effective mass and gives a frozen partner its own
//! mass) and `absolute_damping on` in LIGGGHTS; wall spheres are moved by `fix move linear` and so
//! act as infinite mass; LIGGGHTS needs `neigh_modify contact_distance_factor 1.01` so that a
//! tangential spring is reset when its contact ends (`docs/benchmark.md`, known pitfalls).

use std::fmt::Write;
use std::path::Path;
use std::process::Command;

use anyhow::{bail, Context};

pub mod collision;
pub mod cross;
pub mod dump;

use crate::case::{Case, Scene};
use crate::sim::Snapshot;
use crate::state::Motion;

/// A peer code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Peer {
    Lammps,
    Liggghts,
}

impl Peer {
    /// Every peer.
    pub const ALL: [Peer; 2] = [Peer::Lammps, Peer::Liggghts];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Peer::Lammps => "lammps",
            Peer::Liggghts => "liggghts",
        }
    }

    /// Name of the installed binary.
    pub fn binary(self) -> &'static str {
        match self {
            Peer::Lammps => "lmp",
            Peer::Liggghts => "liggghts",
        }
    }
}

/// A LAMMPS data file of a state: atom types 1 free, 2 bottom wall, 3 top wall; `Atoms` lines
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

fn wall_speeds(case: &Case) -> anyhow::Result<(f64, f64)> {
    match case.scene {
        Scene::BumpyShear {
            bottom_vx, top_vx, ..
        } => Ok((bottom_vx, top_vx)),
        Scene::Spheres { .. } | Scene::Gas { .. } => {
            bail!("peer inputs are generated for bumpy-shear cases")
        }
    }
}

/// The dump a cross-run writes every `every` steps: `dump.STEP.txt`, one file per save, atoms
/// sorted by id, columns [`DUMP_COLUMNS`], every float with 17 significant digits (round trip).
fn dump_commands(peer: Peer, every: u64) -> String {
    let cols = DUMP_COLUMNS.join(" ");
    let format = match peer {
        // LAMMPS (since 2017): `format float` applies to every float column
        Peer::Lammps => "format float %.17g".to_string(),
        // LIGGGHTS 3.8 (LAMMPS 2013 syntax): one format string for the whole line
        Peer::Liggghts => format!(
            "format \"%d %d{}\"",
            " %.17g".repeat(DUMP_COLUMNS.len() - 2)
        ),
    };
    // Contact forces, one line per pair in contact: `contacts.STEP.txt` with the two ids and
    // the force on the first (LAMMPS: `pair/local` gives the normal force over the distance
    // and the tangential force vector; LIGGGHTS: `pair/gran/local` the force vector). Both
    // computes re-evaluate the forces at the end of the step, with full-step velocities in the
    // dashpots, where the step itself used half-step velocities.
    let contacts = match peer {
        Peer::Lammps => "compute         pairs all pair/local force p1 p2 p3\n\
compute         ids all property/local patom1 patom2\n\
dump            contacts all local {every} contacts.*.txt c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4]\n\
dump_modify     contacts format float %.17g\n"
            .to_string(),
        Peer::Liggghts => format!(
            "compute         pairs all pair/gran/local id force\n\
dump            contacts all local {{every}} contacts.*.txt c_pairs[1] c_pairs[2] c_pairs[4] c_pairs[5] c_pairs[6]\n\
dump_modify     contacts format \"{}\"\n",
            ["%.17g"; 5].join(" ")
        ),
    }
    .replace("{every}", &every.to_string());
    format!(
        "dump            traj all custom {every} dump.*.txt {cols}\n\
dump_modify     traj sort id {format}\n\
{contacts}"
    )
}

/// The columns of a cross-run dump.
pub const DUMP_COLUMNS: [&str; 12] = [
    "id", "type", "radius", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
];

/// The common part of every generated input: units, atom style, boundaries, the data file, the
/// groups (1 free, 2 bottom wall, 3 top wall) and the contact law with its neighbour settings.
fn setup_and_law(peer: Peer, case: &Case, data: &str) -> String {
    let c = &case.contact;
    let skin = case.neighbor.skin;
    let periodic: String = case
        .domain
        .periodic
        .iter()
        .map(|p| if *p { "p " } else { "f " })
        .collect();
    let groups = "group           free   type 1\ngroup           bottom type 2\ngroup           top    type 3\n";
    match peer {
        Peer::Lammps => format!(
            "units           lj\n\
atom_style      sphere\n\
boundary        {periodic}\n\
comm_modify     vel yes\n\
read_data       {data}\n\
{groups}# absolute damping: 'damping velocity' (LAMMPS pair_style granular); eta_t = {gt:?}/{gn:?} * eta_n\n\
pair_style      granular\n\
pair_coeff      * * hooke {kn:?} {gn:?} tangential linear_history {kt:?} {xgt:?} {mu:?} damping velocity\n\
neighbor        {skin:?} bin\n\
neigh_modify    delay 0 every 1 check yes exclude type 2 2 exclude type 3 3 exclude type 2 3\n",
            kn = c.kn,
            gn = c.gamman,
            kt = c.kt,
            gt = c.gammat,
            xgt = c.gammat / c.gamman,
            mu = c.mu,
        ),
        Peer::Liggghts => {
            let m = |name: &str, v: f64| format!("fix  {name} all property/global {name} peratomtypepair 3{}\n", format!(" {v:?}").repeat(9));
            format!(
                "units           si\n\
atom_style      granular\n\
atom_modify     map array\n\
boundary        {periodic}\n\
newton          off\n\
communicate     single vel yes\n\
read_data       {data}\n\
{groups}{}{}{}{}{}\
# absolute damping (gamman_abs, gammat_abs), not scaled by the effective mass\n\
pair_style      gran model hooke/stiffness tangential history absolute_damping on\n\
pair_coeff      * *\n\
# contact_distance_factor 1.01: reset a tangential spring when its contact ends\n\
neighbor        {skin:?} bin\n\
neigh_modify    delay 0 every 1 check yes contact_distance_factor 1.01 exclude type 2 2 exclude type 3 3 exclude type 2 3\n",
                m("kn", c.kn),
                m("kt", c.kt),
                m("gamman_abs", c.gamman),
                m("gammat_abs", c.gammat),
                m("coefficientFriction", c.mu),
            )
        }
    }
}

/// An input script for `peer` running `steps` steps of the bumpy-shear `case` from `data`: with
/// `dump_every` `None` no file output (for timing; thermo only at the start and the end), else a
/// dump every so many steps (cross-runs, [`cross`]).
pub fn input_script(
    peer: Peer,
    case: &Case,
    data: &str,
    steps: u64,
    dump_every: Option<u64>,
) -> anyhow::Result<String> {
    let (vb, vt) = wall_speeds(case)?;
    let dt = case.dt();
    let (output, dump) = match dump_every {
        None => ("no file output".to_string(), String::new()),
        Some(every) => (
            format!("a dump every {every} steps"),
            dump_commands(peer, every),
        ),
    };
    Ok(format!(
        "# {peer:?} input generated by verdem from case {:?}: {steps} steps, {output}.\n\
         # Types: 1 free, 2 bottom wall, 3 top wall (moved rigidly by fix move: infinite mass).\n\
{}\
timestep        {dt:?}\n\
velocity        bottom set {vb:?} 0 0 units box\n\
velocity        top    set {vt:?} 0 0 units box\n\
fix             wbot bottom move linear {vb:?} 0 0\n\
fix             wtop top    move linear {vt:?} 0 0\n\
{}",
        case.name,
        setup_and_law(peer, case, data),
        integrate_and_run(&dump, steps),
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

/// An input script for `peer` running `steps` steps of a two-sphere `case` (a fixed sphere is
/// held still by `fix move`: infinite mass) from `data`, dumping the state at the start and at
/// the end.
pub fn collision_script(peer: Peer, case: &Case, data: &str, steps: u64) -> String {
    format!(
        "# {peer:?} input generated by verdem from case {:?}: a two-sphere collision, {steps} steps.\n\
         # Types: 1 free, 2 and 3 fixed spheres (held still by fix move: infinite mass).\n\
{}\
timestep        {dt:?}\n\
fix             still1 bottom move linear 0 0 0\n\
fix             still2 top    move linear 0 0 0\n\
{}",
        case.name,
        setup_and_law(peer, case, data),
        integrate_and_run(&dump_commands(peer, steps), steps),
        dt = case.dt(),
    )
}

/// Runs `peer` on `np` MPI ranks in `dir` with `input`; returns the seconds of its time loop
/// ("Loop time of T on N procs for S steps").
pub fn run(peer: Peer, np: usize, dir: &Path, input: &str) -> anyhow::Result<f64> {
    let dir = &dir
        .canonicalize()
        .with_context(|| dir.display().to_string())?;
    let script = dir.join(format!("in.{}", peer.binary()));
    std::fs::write(&script, input).with_context(|| script.display().to_string())?;
    let mut cmd = Command::new("mpirun");
    cmd.args([
        "--allow-run-as-root",
        "--oversubscribe",
        "-np",
        &np.to_string(),
        peer.binary(),
        "-in",
    ])
    .arg(&script)
    .args(["-log", "none"])
    .current_dir(dir);
    let out = cmd.output().with_context(|| {
        format!(
            "cannot start mpirun {} (install: apt-get install -y lammps liggghts)",
            peer.binary()
        )
    })?;
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        bail!(
            "{} failed ({}):\n{}",
            peer.binary(),
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
        .with_context(|| format!("{}: no 'Loop time' line in its output", peer.binary()))
}
