//! LAMMPS (Debian package `lammps`, binary `lmp`) with `pair_style granular`: Hooke normal
//! force, `linear_history` tangential spring, absolute damping (`damping velocity`), in LJ
//! units.

use super::lammps_family::{boundary, neighbor, Dialect, GROUPS};
use super::libraries::MotionPeer;
use crate::case::Case;
use crate::contact::Tangential;
use crate::state::Snapshot;
use crate::Vec3;

/// LAMMPS.
pub struct Lammps;

impl Dialect for Lammps {
    const NAME: &'static str = "lammps";
    const BINARY: &'static str = "lmp";
    const CONVENTION: Tangential = Tangential::LammpsGranular;
    const CONTACT_COLUMNS: usize = 6;
    const MOTION: &'static [MotionPeer] = &[MotionPeer::Lammps, MotionPeer::LammpsHookeHistory];
    /// `fix ave/time … format " %.17g"` (its default is `%g` after a space).
    const WALLS_FORMAT: Option<&'static str> = Some("\" %.17g\"");

    /// The tangential damping is given relative to the normal one (`eta_t = x * eta_n`).
    fn setup_and_law(case: &Case, data: &str) -> String {
        let c = &case.contact;
        format!(
            "units           lj\n\
atom_style      sphere\n\
boundary        {}\n\
comm_modify     vel yes\n\
read_data       {data}\n\
{GROUPS}# absolute damping: 'damping velocity' (LAMMPS pair_style granular); eta_t = {gt:?}/{gn:?} * eta_n\n\
pair_style      granular\n\
pair_coeff      * * hooke {kn:?} {gn:?} tangential linear_history {kt:?} {xgt:?} {mu:?} damping velocity\n\
{}",
            boundary(case),
            neighbor(case, ""),
            kn = c.kn,
            gn = c.gamman,
            kt = c.kt,
            gt = c.gammat,
            // no tangential damping is x = 0 whatever the normal one (also when that is 0)
            xgt = if c.gammat == 0.0 { 0.0 } else { c.gammat / c.gamman },
            mu = c.mu,
        )
    }

    /// `format float` (LAMMPS since 2017) applies to every float column.
    fn dump_format() -> String {
        "format float %.17g".to_string()
    }

    /// `pair/local` gives the normal force over the distance and the tangential force vector,
    /// re-evaluated at the end of the step.
    fn contact_dump(every: u64) -> String {
        format!(
            "compute         pairs all pair/local force p1 p2 p3\n\
compute         ids all property/local patom1 patom2\n\
dump            contacts all local {every} contacts.*.txt c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4]\n\
dump_modify     contacts format float %.17g\n"
        )
    }

    /// The normal force over the distance times x_a − x_b, plus the tangential force on a.
    fn force_on_first(r: &[f64], s: &Snapshot, a: usize, b: usize) -> Vec3 {
        let x = &s.particles.x;
        s.domain.min_image(x[a] - x[b]) * r[2] + Vec3::new(r[3], r[4], r[5])
    }
}
