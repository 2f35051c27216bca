//! LIGGGHTS (Debian package `liggghts`, LAMMPS 2013 syntax) with `gran model hooke/stiffness
//! tangential history absolute_damping on`, in SI units; coefficients per pair of atom types.

use super::lammps_family::{boundary, neighbor, Dialect, DUMP_COLUMNS, GROUPS};
use super::libraries::MotionPeer;
use crate::case::Case;
use crate::contact::Tangential;
use crate::state::Snapshot;
use crate::Vec3;

/// LIGGGHTS.
pub struct Liggghts;

impl Dialect for Liggghts {
    const NAME: &'static str = "liggghts";
    const BINARY: &'static str = "liggghts";
    const CONVENTION: Tangential = Tangential::Liggghts;
    const CONTACT_COLUMNS: usize = 5;
    const MOTION: &'static [MotionPeer] = &[MotionPeer::Liggghts];
    /// LIGGGHTS 3.8 refuses `fix ave/time`'s `format` keyword ("Illegal fix ave/time
    /// command"): its means keep the default `%g`, 6 significant digits.
    const WALLS_FORMAT: Option<&'static str> = None;

    /// Each coefficient is a `property/global` for all 3×3 pairs of atom types;
    /// `contact_distance_factor 1.01` resets a tangential spring when its contact ends.
    fn setup_and_law(case: &Case, data: &str) -> String {
        let c = &case.contact;
        let m = |name: &str, v: f64| {
            format!(
                "fix  {name} all property/global {name} peratomtypepair 3{}\n",
                format!(" {v:?}").repeat(9)
            )
        };
        format!(
            "units           si\n\
atom_style      granular\n\
atom_modify     map array\n\
boundary        {}\n\
newton          off\n\
communicate     single vel yes\n\
read_data       {data}\n\
{GROUPS}{}{}{}{}{}\
# absolute damping (gamman_abs, gammat_abs), not scaled by the effective mass\n\
pair_style      gran model hooke/stiffness tangential history absolute_damping on\n\
pair_coeff      * *\n\
# contact_distance_factor 1.01: reset a tangential spring when its contact ends\n\
{}",
            boundary(case),
            m("kn", c.kn),
            m("kt", c.kt),
            m("gamman_abs", c.gamman),
            m("gammat_abs", c.gammat),
            m("coefficientFriction", c.mu),
            neighbor(case, " contact_distance_factor 1.01"),
        )
    }

    /// One format string for the whole line (LAMMPS 2013 syntax).
    fn dump_format() -> String {
        format!(
            "format \"%d %d{}\"",
            " %.17g".repeat(DUMP_COLUMNS.len() - 2)
        )
    }

    /// `pair/gran/local` gives the ids and the force vector, re-evaluated at the end of the
    /// step.
    fn contact_dump(every: u64) -> String {
        format!(
            "compute         pairs all pair/gran/local id force\n\
dump            contacts all local {every} contacts.*.txt c_pairs[1] c_pairs[2] c_pairs[4] c_pairs[5] c_pairs[6]\n\
dump_modify     contacts format \"{}\"\n",
            ["%.17g"; 5].join(" ")
        )
    }

    /// The force vector on a, as dumped.
    fn force_on_first(r: &[f64], _: &Snapshot, _: usize, _: usize) -> Vec3 {
        Vec3::new(r[2], r[3], r[4])
    }
}
