//! Prescribed motions in the real LAMMPS and LIGGGHTS: the same two-sphere motions that
//! [`crate::verify::kinematics::drive`] runs through verdem's laws, run through the peers' own contact
//! laws, in process, through their C library interfaces ([`library`], loaded at run time).
//!
//! The input is the one the peers' cross-runs and binary collisions use
//! ([`super::lammps_family::Dialect::setup_and_law`]: LAMMPS `pair_style granular` hooke /
//! `linear_history` / `damping velocity`, LIGGGHTS `gran model hooke/stiffness tangential
//! history absolute_damping on`), or LAMMPS' classic `gran/hooke/history` (`hooke_history`),
//! read from a data file of the case's two spheres in a
//! non-periodic box that holds every row of the motion, with no time integration fix: nothing
//! moves the atoms but this driver. Per row it sets both spheres' positions, velocities and
//! spins (orientations: a sphere's force does not depend on them), then lets the code evaluate
//! its forces, and reads the forces and torques back:
//!
//! - row 0: `run 0`, the set-up force evaluation. Both codes skip the tangential history
//!   update there (LAMMPS `src/GRANULAR/pair_granular.cpp`, `PairGranular::compute`:
//!   `if (update->setupflag) history_update = 0`, and `pair_gran_hooke_history.cpp`:
//!   `if (update->setupflag) shearupdate = 0`; LIGGGHTS `tangential_model_history.h`:
//!   `if (sidata.shearupdate && sidata.computeflag)`, with `shearupdate` false during set-up),
//!   which is verdem's row 0: the row's own velocities, no increment.
//! - row k ≥ 1: `run 1 pre no post no`: one step of `Verlet::run`, whose force evaluation
//!   advances the history by the velocities set times dt (so `run 0` would not do: it never
//!   advances it), with the neighbour list rebuilt from all pairs every step (`neighbor SKIN
//!   nsq`, `neigh_modify every 1 delay 0 check no`; the history follows the pair across
//!   rebuilds). The velocities are the step averages of [`Increment`], as verdem's. The
//!   code's dt is the rows' spacing t_k − t_(k−1):
//!   where the spacing changes (beyond the rounding of the times, `SAME_STEP`) a `timestep`
//!   command and a run with its set-up (`run 1 post no`), since LAMMPS' pair keeps its own
//!   copy of dt.
//!
//! Sphere 1 is atom 1 (i), sphere 2 atom 2 (j); forces and torques are each atom's `f` and
//! `torque` after the step; the overlap, the signed normal force (the force on sphere 2 along n
//! from 1 to 2) and the tangential magnitude are formed as in [`crate::verify::kinematics`]. The case
//! gives the radii, the density and kn, gamman, kt, gammat, mu; its `tangential` and
//! `clip_normal` are the peer's own (its [`MotionPeer::convention`], not clipped).

pub mod library;

use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::{ensure, Context};

use self::library::{Flavour, Instance};
use super::lammps::Lammps;
use super::lammps_family::{boundary, data_file, neighbor, Dialect, GROUPS};
use super::liggghts::Liggghts;
use crate::case::{Case, Scene};
use crate::contact::Tangential;
use crate::state::Snapshot;
use crate::verify::driver::MotionDriver;
use crate::verify::kinematics::{pair_of, ForceRow, Increment, MotionRow};
use crate::Vec3;

pub use super::libraries::MotionPeer;

/// What each library is and how it is set up: its name, convention and input lines come from
/// its peer's dialect.
impl MotionPeer {
    /// Its name on the command line (that of the peer in [`super::all`]).
    pub fn name(self) -> &'static str {
        match self {
            MotionPeer::Lammps => Lammps::NAME,
            MotionPeer::LammpsHookeHistory => "lammps-hooke-history",
            MotionPeer::Liggghts => Liggghts::NAME,
        }
    }

    /// One line saying which library and contact law (for help texts).
    pub fn description(self) -> &'static str {
        match self {
            MotionPeer::Lammps => {
                "LAMMPS' library (liblammps.so.0), pair_style granular hooke linear_history"
            }
            MotionPeer::LammpsHookeHistory => {
                "LAMMPS' library (liblammps.so.0), pair_style gran/hooke/history"
            }
            MotionPeer::Liggghts => {
                "LIGGGHTS' library (libliggghts.so.3), gran model hooke/stiffness tangential history"
            }
        }
    }

    /// The peer called `name`, if it can be driven so.
    pub fn named(name: &str) -> Option<MotionPeer> {
        MotionPeer::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The verdem convention that re-implements its contact law.
    pub fn convention(self) -> Tangential {
        match self {
            MotionPeer::Lammps => Lammps::CONVENTION,
            MotionPeer::LammpsHookeHistory => Tangential::LammpsHookeHistory,
            MotionPeer::Liggghts => Liggghts::CONVENTION,
        }
    }

    fn flavour(self) -> Flavour {
        match self {
            MotionPeer::Lammps | MotionPeer::LammpsHookeHistory => Flavour::Lammps,
            MotionPeer::Liggghts => Flavour::Liggghts,
        }
    }

    fn setup_and_law(self, case: &Case, data: &str) -> String {
        match self {
            MotionPeer::Lammps => Lammps::setup_and_law(case, data),
            MotionPeer::LammpsHookeHistory => hooke_history(case, data),
            MotionPeer::Liggghts => Liggghts::setup_and_law(case, data),
        }
    }

    /// Loads its library: an error saying how to install it when it is absent.
    pub fn load(self) -> anyhow::Result<()> {
        library::api(self.flavour()).map(|_| ())
    }
}

/// LAMMPS' set-up for `pair_style gran/hooke/history`, whose dashpots are γ·meff·v with
/// meff = m1 m2/(m1 + m2) (`src/GRANULAR/pair_gran_hooke_history.cpp`): verdem's absolute
/// dashpots γ become γ/meff of the case's two spheres (masses 4π/3 r³ ρ, as LAMMPS' `read_data`
/// sets them for `atom_style sphere`); `dampflag` 1 keeps the tangential dashpot.
fn hooke_history(case: &Case, data: &str) -> String {
    let c = &case.contact;
    let mass = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r * r * r * case.material.density;
    let [m1, m2] = pair_of(case).map_or([f64::NAN; 2], |(_, r)| r.map(mass));
    let meff = m1 * m2 / (m1 + m2);
    format!(
        "units           lj\n\
atom_style      sphere\n\
boundary        {}\n\
comm_modify     vel yes\n\
read_data       {data}\n\
{GROUPS}# dashpots gamma/meff with meff = {meff:?}: gran/hooke/history multiplies them by meff\n\
pair_style      gran/hooke/history {:?} {:?} {:?} {:?} {:?} 1\n\
pair_coeff      * *\n\
{}",
        boundary(case),
        c.kn,
        c.kt,
        c.gamman / meff,
        c.gammat / meff,
        c.mu,
        neighbor(case, ""),
    )
}

/// Row spacings closer than this, relative, are one time step: they differ by the rounding of
/// the rows' times (t/dt·ε ≈ 1e-11 after 1e5 rows), and a new step size costs a run's set-up.
/// The velocities are scaled by the spacing over the code's step, so that the code's increment
/// is the row's; its dashpots then see velocities off by as much, relative.
const SAME_STEP: f64 = 1e-9;

/// One library instance at a time in the process (they share MPI's world and process state).
static RUNNING: Mutex<()> = Mutex::new(());

/// The step-average velocities of both spheres and the step of row `k` (row 0: its own
/// velocities and no step), as [`crate::verify::kinematics::drive`] takes them.
fn step_velocities(
    rows: &[MotionRow],
    k: usize,
    increment: Increment,
) -> ([Vec3; 2], [Vec3; 2], f64) {
    let row = &rows[k];
    if k == 0 {
        return (row.v, row.w, 0.0);
    }
    let prev = &rows[k - 1];
    let dt = row.t - prev.t;
    match increment {
        Increment::Positions => {
            let spin = |s: usize| (row.q[s] * prev.q[s].inverse()).scaled_axis() / dt;
            (
                [(row.x[0] - prev.x[0]) / dt, (row.x[1] - prev.x[1]) / dt],
                [spin(0), spin(1)],
                dt,
            )
        }
        Increment::Trapezoid => {
            let mean = |a: [Vec3; 2], b: [Vec3; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            (mean(prev.v, row.v), mean(prev.w, row.w), dt)
        }
    }
}

/// `case` with its two spheres free, at rest at row 0's positions, in a non-periodic box that
/// holds both spheres' whole path with a margin of a diameter plus the neighbour skin.
fn peer_case(case: &Case, motion: &[MotionRow], radius: [f64; 2]) -> anyhow::Result<Case> {
    let mut c = case.clone();
    let margin = 2.0 * radius[0].max(radius[1]) + case.neighbor.skin;
    for row in motion {
        for x in row.x {
            for k in 0..3 {
                c.domain.lo[k] = c.domain.lo[k].min(x[k] - margin);
                c.domain.hi[k] = c.domain.hi[k].max(x[k] + margin);
            }
        }
    }
    c.domain.periodic = [false; 3];
    let Scene::Spheres { sphere } = &mut c.scene else {
        anyhow::bail!("{}: needs a spheres scene", case.path.display());
    };
    for (s, x) in sphere.iter_mut().zip(motion[0].x) {
        s.x = x.into();
        s.v = [0.0; 3];
        s.w = [0.0; 3];
        s.fixed = false;
    }
    Ok(c)
}

/// A folder of its own under the system's temporary folder, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new() -> anyhow::Result<TempDir> {
        static COUNT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("verdem-motion-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).with_context(|| dir.display().to_string())?;
        Ok(TempDir(dir))
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A peer's library drives the verification's prescribed-motion cases (`verdem verify --peers`)
/// with the increments verdem's integrator feeds its own law.
impl MotionDriver for MotionPeer {
    fn drive(&self, case: &Case, motion: &[MotionRow]) -> anyhow::Result<Vec<ForceRow>> {
        drive(*self, case, motion, Increment::Positions)
    }

    fn name(&self) -> String {
        format!("{} library", MotionPeer::name(*self))
    }
}

/// Drives one contact of `case`'s two spheres through `motion` in `peer`'s library, with the
/// increments of `increment`: the forces and torques at every row, with the semantics of
/// [`crate::verify::kinematics::drive`] (module doc). Times and lengths in the case's units.
pub fn drive(
    peer: MotionPeer,
    case: &Case,
    motion: &[MotionRow],
    increment: Increment,
) -> anyhow::Result<Vec<ForceRow>> {
    let (_, radius) = pair_of(case)?;
    if motion.is_empty() {
        return Ok(Vec::new());
    }
    let placed = peer_case(case, motion, radius)?;
    let scene = crate::scene::build(&placed, None)?;
    let state = Snapshot {
        step: 0,
        time: 0.0,
        domain: scene.domain,
        particles: scene.particles,
        contacts: Vec::new(),
        walls: Vec::new(),
        wall_contacts: Vec::new(),
    };
    let api = library::api(peer.flavour())?;
    let dir = TempDir::new()?;
    let data = dir.0.join("pair.data");
    std::fs::write(&data, data_file(&state, case.material.density))
        .with_context(|| data.display().to_string())?;
    let data = data.display().to_string();
    ensure!(
        !data.contains(char::is_whitespace),
        "the temporary folder {data} has a space in its path, which the peers' read_data cannot take"
    );
    let first_dt = motion.get(1).map_or(case.dt(), |r| r.t - motion[0].t);

    let _running = RUNNING.lock().unwrap_or_else(|e| e.into_inner());
    let script = peer.setup_and_law(&placed, &data);
    // a number the code cannot read would end the process (library::Instance::command)
    if let Some(line) = script.lines().find(|l| {
        l.split_whitespace()
            .any(|w| w.parse::<f64>().is_ok_and(|x| !x.is_finite()))
    }) {
        anyhow::bail!(
            "{}: the case's law has no finite {} input: `{line}`{}",
            case.path.display(),
            peer.name(),
            if peer == MotionPeer::Lammps {
                " (LAMMPS' pair granular gives the tangential damping relative to the normal \
                 one: gammat needs gamman > 0)"
            } else {
                ""
            }
        );
    }
    let mut lmp = Instance::open(api)?;
    lmp.script(&script)?;
    // read: the data file is no longer needed
    drop(dir);
    // a full rebuild of the neighbour list every step, whatever the atoms moved, by looking at
    // all pairs (no bins over a box that may be large: it holds the whole motion)
    lmp.command(&format!("neighbor        {:?} nsq", case.neighbor.skin))?;
    lmp.command("neigh_modify    delay 0 every 1 check no")?;
    lmp.command(&format!("timestep        {first_dt:?}"))?;
    let mut dt_now = first_dt;
    ensure!(
        lmp.nlocal()? == 2,
        "{}: {} atoms read, 2 expected",
        peer.name(),
        lmp.nlocal()?
    );

    let mut out = Vec::with_capacity(motion.len());
    for (k, row) in motion.iter().enumerate() {
        let (mut v, mut w, dt) = step_velocities(motion, k, increment);
        let mut run = "run 1 pre no post no";
        if k > 0 {
            if (dt - dt_now).abs() > SAME_STEP * dt_now {
                // LAMMPS 20220106's `timestep` sets only `update->dt`; pair granular keeps the
                // copy `PairGranular::init_style` took: a new step size needs a set-up run
                lmp.command(&format!("timestep {dt:?}"))?;
                dt_now = dt;
                run = "run 1 post no";
            }
            // the code's increment is velocity × its own step: that of the row
            let scale = dt / dt_now;
            v = v.map(|x| x * scale);
            w = w.map(|x| x * scale);
        }
        let local = local_indices(&lmp)?;
        for s in 0..2 {
            lmp.set("x", local[s], row.x[s].into())?;
            lmp.set("v", local[s], v[s].into())?;
            lmp.set("omega", local[s], w[s].into())?;
        }
        lmp.command(if k == 0 { "run 0 post no" } else { run })?;
        let local = local_indices(&lmp)?;
        let read = |name: &str, s: usize| lmp.get(name, local[s]).map(Vec3::from);
        let f = [read("f", 0)?, read("f", 1)?];
        let torque = [read("torque", 0)?, read("torque", 1)?];
        let r = row.x[1] - row.x[0];
        let n = r.normalize();
        let fn_signed = f[1].dot(&n);
        out.push(ForceRow {
            t: row.t,
            f,
            torque,
            delta: radius[0] + radius[1] - r.norm(),
            fn_signed,
            ft: (f[1] - fn_signed * n).norm(),
        });
    }
    Ok(out)
}

/// The local indices of atoms 1 and 2 (a code may reorder its atoms when it sorts them).
fn local_indices(lmp: &Instance) -> anyhow::Result<[usize; 2]> {
    let tags = lmp.tags()?;
    let find = |id: i32| {
        tags.iter()
            .position(|&t| t == id)
            .with_context(|| format!("atom {id} is gone (ids {tags:?})"))
    };
    Ok([find(1)?, find(2)?])
}
