//! Per-save diagnostics: kinetic energy of the free particles, contact count, and the total
//! force the free particles exert on each wall group.

use crate::state::Motion;
use crate::state::Snapshot;
use crate::Vec3;

/// One row of the diagnostics table.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostics {
    pub save: u64,
    pub step: u64,
    pub time: f64,
    /// Translational kinetic energy of the free particles, Σ ½ m v².
    pub ke_trans: f64,
    /// Rotational kinetic energy of the free particles, Σ ½ I ω².
    pub ke_rot: f64,
    /// Contacts at this step (free–free and free–wall).
    pub contacts: usize,
    /// Force exerted by the free particles on wall group 0 (bottom) and 1 (top).
    pub wall_force: [Vec3; 2],
}

/// Column names of [`Diagnostics::csv_row`].
pub const CSV_HEADER: &str =
    "save,step,time,ke_trans,ke_rot,contacts,bottom_fx,bottom_fz,top_fx,top_fz\n";

impl Diagnostics {
    /// Diagnostics of a state (forces of the last evaluation).
    pub fn of(core: &Snapshot, save: u64) -> Self {
        let p = &core.particles;
        let (mut ke_trans, mut ke_rot) = (0.0, 0.0);
        for a in 0..p.len() {
            if p.inv_mass[a] > 0.0 {
                ke_trans += 0.5 * p.v[a].norm_squared() / p.inv_mass[a];
                ke_rot += 0.5 * p.w[a].norm_squared() / p.inv_inertia[a];
            }
        }
        let mut wall_force = [Vec3::zeros(); 2];
        for c in &core.contacts {
            let (pp, ii) = (c.p as usize, c.i as usize);
            let f = c.force.f;
            if let Motion::Prescribed(g) = p.motion[pp] {
                wall_force[g.min(1) as usize] += f;
            }
            if let Motion::Prescribed(g) = p.motion[ii] {
                wall_force[g.min(1) as usize] -= f;
            }
        }
        Diagnostics {
            save,
            step: core.step,
            time: core.time,
            ke_trans,
            ke_rot,
            contacts: core.contacts.len(),
            wall_force,
        }
    }

    /// One CSV row (numbers round-trip).
    pub fn csv_row(&self) -> String {
        let mut s = format!("{},{},", self.save, self.step);
        let [b, t] = self.wall_force;
        for (k, v) in [self.time, self.ke_trans, self.ke_rot].iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            crate::io::fmt_f64(&mut s, *v);
        }
        s.push_str(&format!(",{}", self.contacts));
        for v in [b.x, b.z, t.x, t.z] {
            s.push(',');
            crate::io::fmt_f64(&mut s, v);
        }
        s.push('\n');
        s
    }
}
