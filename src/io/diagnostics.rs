//! Per-save diagnostics: kinetic energy of the free particles, contact count, and the total
//! force the free particles exert on each wall group; then the energy and momentum ledgers of
//! the steps since the previous save ([`LedgerRow`]).

use std::path::Path;

use super::FormatError;
use crate::state::Motion;
use crate::state::Snapshot;
use crate::step::LedgerRow;
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
    /// The ledgers of the steps since the previous save; `None` at the first save of a run (or
    /// of a resumed run not resumed at a save), whose fields are left empty.
    pub ledger: Option<LedgerRow>,
}

/// Column names of [`Diagnostics::csv_row`]: the state at the save, then the ledgers since the
/// previous save (`docs/statistics.md`, "The diagnostics table").
pub const CSV_HEADER: &str =
    "save,step,time,ke_trans,ke_rot,contacts,bottom_fx,bottom_fz,top_fx,top_fz,\
work_walls,work_gravity,diss_normal,diss_tangential,diss_slide,d_ke_trans,d_ke_rot,d_elastic,\
ledger_residual,mean_bottom_fx,mean_bottom_fy,mean_bottom_fz,mean_top_fx,mean_top_fy,mean_top_fz,\
momentum_residual_x,momentum_residual_y,momentum_residual_z\n";

/// Number of ledger columns at the end of [`CSV_HEADER`].
pub const LEDGER_COLUMNS: usize = 18;

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
            ledger: None,
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
        for v in ledger_fields(self.ledger.as_ref()) {
            s.push(',');
            if let Some(v) = v {
                crate::io::fmt_f64(&mut s, v);
            }
        }
        s.push('\n');
        s
    }
}

/// The ledger columns of a row, in the header's order; `None` for a field left empty.
fn ledger_fields(l: Option<&LedgerRow>) -> [Option<f64>; LEDGER_COLUMNS] {
    let Some(l) = l else {
        return [None; LEDGER_COLUMNS];
    };
    let d = l.dissipated.map_or([None; 3], |d| d.map(Some));
    let [b, t] = l.mean_wall_force;
    let m = l.momentum_residual;
    [
        Some(l.work_walls),
        Some(l.work_gravity),
        d[0],
        d[1],
        d[2],
        Some(l.d_trans),
        Some(l.d_rot),
        Some(l.d_elastic),
        l.residual,
        Some(b.x),
        Some(b.y),
        Some(b.z),
        Some(t.x),
        Some(t.y),
        Some(t.z),
        Some(m.x),
        Some(m.y),
        Some(m.z),
    ]
}

/// A row of a diagnostics table read back: its save, step and time, and its ledgers (`None`
/// when its ledger fields are empty: the first save of a run).
#[derive(Clone, Debug, PartialEq)]
pub struct LedgerRecord {
    pub save: u64,
    pub step: u64,
    pub time: f64,
    pub ledger: Option<LedgerRow>,
}

/// The ledgers of the diagnostics table at `path`, row by row; `None` when its header has no
/// ledger columns (a table written before they existed). A field that is not a number, or a
/// ledger that is only partly filled in, is an error naming the file, line and column.
pub fn read_ledgers(path: &Path) -> Result<Option<Vec<LedgerRecord>>, FormatError> {
    let (file, text) = super::read_text(path)?;
    let names: Vec<&str> = CSV_HEADER.trim_end().split(',').collect();
    let mut rows = Vec::new();
    let mut at: Option<Vec<usize>> = None;
    for record in super::csv_table::records(&file, &text, false) {
        let (line, record) = record?;
        let Some(at) = &at else {
            let found: Option<Vec<usize>> = names
                .iter()
                .map(|n| record.iter().position(|f| f == *n))
                .collect();
            match found {
                Some(found) => at = Some(found),
                None => return Ok(None),
            }
            continue;
        };
        let error = |msg: String| FormatError {
            file: file.clone(),
            line,
            msg,
        };
        let field = |k: usize| -> Result<Option<f64>, FormatError> {
            let text = record.get(at[k]).unwrap_or("");
            if text.is_empty() {
                return Ok(None);
            }
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(error(format!(
                    "{}: {text:?} is not a finite number",
                    names[k]
                ))),
            }
        };
        let whole = |k: usize| -> Result<u64, FormatError> {
            let text = record.get(at[k]).unwrap_or("");
            text.parse()
                .map_err(|e| error(format!("{}: {text:?} is not a count: {e}", names[k])))
        };
        let first = names.len() - LEDGER_COLUMNS;
        let v: Vec<Option<f64>> = (first..names.len()).map(field).collect::<Result<_, _>>()?;
        // the dissipation (2..5) and the residual (8) are empty for a law that does not split it
        let optional = |k: usize| (2..5).contains(&k) || k == 8;
        let ledger = if v.iter().all(Option::is_none) {
            None
        } else {
            if let Some(k) = (0..LEDGER_COLUMNS).find(|&k| !optional(k) && v[k].is_none()) {
                return Err(error(format!(
                    "{}: empty in a row with a ledger",
                    names[first + k]
                )));
            }
            let x = |k: usize| v[k].unwrap_or(0.0);
            let split = (2..5).all(|k| v[k].is_some());
            Some(LedgerRow {
                work_walls: x(0),
                work_gravity: x(1),
                dissipated: split.then(|| [x(2), x(3), x(4)]),
                d_trans: x(5),
                d_rot: x(6),
                d_elastic: x(7),
                residual: v[8],
                mean_wall_force: [
                    Vec3::new(x(9), x(10), x(11)),
                    Vec3::new(x(12), x(13), x(14)),
                ],
                momentum_residual: Vec3::new(x(15), x(16), x(17)),
            })
        };
        rows.push(LedgerRecord {
            save: whole(0)?,
            step: whole(1)?,
            time: field(2)?.ok_or_else(|| error("time: empty".into()))?,
            ledger,
        });
    }
    Ok(Some(rows))
}
