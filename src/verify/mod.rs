//! Verification cases with analytical or published answers, run through the same contact laws
//! and solver as the benchmark: a table of expected against measured values with tolerances.
//!
//! - [`collision`]: binary normal collisions against the closed forms (clipped and not);
//! - [`oblique`]: oblique impacts, the sticking and sliding regimes of the linear spring and
//!   Coulomb slider (Walton; Chung & Ooi 2011), per tangential convention;
//! - [`objectivity`]: a loaded contact rotated rigidly, per convention (kinematics driver);
//! - [`ratchet`]: closed cycles of relative motion below the sliding limit (McNamara et al.
//!   2008), per convention (kinematics driver);
//! - [`conservation`]: energy and momentum of a periodic gas, angular momentum of a cluster.

pub mod collision;
pub mod conservation;
pub mod extremes;
pub mod mcnamara;
pub mod objectivity;
pub mod oblique;
pub mod ratchet;

use std::path::Path;

use crate::analysis::{Limit, Verdict};
use crate::case::Case;
pub use collision::{binary_collisions, closed_form, collide, ClosedForm, Measured};

/// One line of the verification table: a case's quantity judged against its expected value
/// with a relative ([`row`]) or absolute ([`row_abs`]) tolerance.
pub type Row = Verdict;

/// A row judged by the relative error |measured − expected|/|expected|.
pub fn row(case: &str, quantity: &str, expected: f64, measured: f64, tolerance: f64) -> Row {
    Verdict::judge(
        case,
        quantity,
        measured,
        Limit::Relative {
            expected,
            tolerance,
        },
    )
}

/// A row judged by the absolute error |measured − expected|.
pub fn row_abs(case: &str, quantity: &str, expected: f64, measured: f64, tolerance: f64) -> Row {
    Verdict::judge(
        case,
        quantity,
        measured,
        Limit::Absolute {
            expected,
            tolerance,
        },
    )
}

/// Every verification case of the folder `dir` (cases/verify): the table `verdem verify`
/// prints.
pub fn all(dir: &Path) -> anyhow::Result<Vec<Row>> {
    let load = |name: &str| Case::load(&dir.join(name));
    let mut rows = binary_collisions(&load("binary_collision.toml")?)?;
    rows.extend(oblique::rows(&load("oblique_impact.toml")?)?);
    // one contact, driven by rigid rotations (objectivity) and by the ratcheting cycle
    let pair = load("objectivity.toml")?;
    rows.extend(objectivity::rows(&pair)?);
    rows.extend(ratchet::rows(&pair)?);
    rows.extend(mcnamara::rows(&pair)?);
    rows.extend(conservation::rows(&load("conservation.toml")?, 1_000_000)?);
    Ok(rows)
}

/// Rows that gate and failed.
pub use crate::analysis::verdict::failures;

/// The table as text; tolerances marked `abs` are absolute, the others relative. A failed row
/// that documents a peer convention's known defect reads `FAIL*`.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<56} {:<40} {:>13} {:>13} {:>13}  result\n",
        "case", "quantity", "expected", "measured", "tolerance"
    );
    for r in rows {
        let tol = match r.limit {
            Limit::Relative { tolerance, .. } => format!("{tolerance:.1e} rel"),
            Limit::Absolute { tolerance, .. } => format!("{tolerance:.1e} abs"),
            _ => String::new(),
        };
        s.push_str(&format!(
            "{:<56} {:<40} {:>13.6e} {:>13.6e} {:>13}  {}\n",
            r.case,
            r.quantity,
            r.limit.expected(),
            r.measured,
            tol,
            match (r.pass(), r.gate) {
                (Some(true), _) => "PASS",
                (Some(false), true) => "FAIL",
                (Some(false), false) => "FAIL*",
                (None, _) => "info",
            }
        ));
    }
    s
}
