//! Scales: the stiffness from 1e2 to 1e9 at a fixed tc/dt (the restitution must not change),
//! and impact speeds from 1e-6 to 1e2 (overlaps from negligible to beyond the guard's limit).

use super::timestep::{failure, judge, sweep, Sweep, TRUST};
use super::{g3, load, parse, set, stopped, Did, Inputs, MapRow};
use crate::case::Case;
use crate::verify::collision::{closed_form, collide_with_phase};

pub const STIFFNESS: &str = "stiffness";
pub const SPEED: &str = "impact speed";

/// tc/dt of the stiffness and speed rows (the benchmark's).
const PER_TC: f64 = 50.0;

/// The collision's numbers in words, and whether they are trustworthy.
fn describe(s: &Sweep) -> (String, bool) {
    (
        format!(
            "e {:.6} (err {}), dmax {} (err {})",
            s.e_mean,
            g3(s.e_error),
            g3(s.delta_mean),
            g3(s.delta_error)
        ),
        s.e_error.max(s.delta_error) <= TRUST,
    )
}

/// What verdem does with `text` and, when it accepts it, the free–free collision at speed
/// `v0` of the parsed case.
fn did(text: &str, path: &std::path::Path, v0: f64) -> Did {
    match parse(text, path) {
        Err(refused) => refused,
        Ok(a) => a.after(&collide_with_phase(&a.case, v0, false, PER_TC, 0.5).map_err(failure)),
    }
}

/// kn from 1e2 to 1e9 with γn ∝ √kn (same damping ratio, so the same restitution) and the
/// tangential spring and dashpot scaled alike, at tc/dt = 50, free–free at speed 0.1; and the
/// spread of the restitution over them.
pub fn stiffness(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let path = inputs.verify_dir.join("binary_collision.toml");
    let (text, base) = load(&path)?;
    let v0 = 0.1;
    let mut rows = Vec::new();
    let mut restitutions = Vec::new();
    for k in 2..=9 {
        let kn = 10f64.powi(k);
        let scale = (kn / base.contact.kn).sqrt();
        let mut case: Case = base.clone();
        case.contact.kn = kn;
        case.contact.gamman *= scale;
        case.contact.kt *= scale * scale;
        case.contact.gammat *= scale;
        let cf = closed_form(&case, 0.5 * case.particle_mass());
        let t = set(&text, "contact", "kn", &format!("{kn:e}"));
        let mut t = t;
        for (key, v) in [
            ("gamman", case.contact.gamman),
            ("kt", case.contact.kt),
            ("gammat", case.contact.gammat),
        ] {
            t = set(&t, "contact", key, &format!("{v:e}"));
        }
        let (measured, trustworthy) = match sweep(&case, false, PER_TC, v0) {
            Ok(s) => {
                restitutions.push(s.e_mean);
                describe(&s)
            }
            Err(f) => (stopped(&f).text(), false),
        };
        let did = did(&t, &path, v0);
        rows.push(MapRow {
            case: STIFFNESS.into(),
            parameter: format!("kn = {kn:e}, gamman = {:.4e}", case.contact.gamman),
            theory: format!("e {:.6}, dmax {}", cf.e, g3(cf.delta_max_per_speed * v0)),
            measured,
            pass: judge(true, trustworthy, &did),
            did,
        });
    }
    // The scheme is invariant under kn → s²kn, γn → s γn, dt → dt/s: the restitution may
    // differ only by the rounding of positions of order 1 against overlaps down to 1e-6.
    let spread = restitutions.iter().cloned().fold(f64::MIN, f64::max)
        - restitutions.iter().cloned().fold(f64::MAX, f64::min);
    rows.push(MapRow {
        case: STIFFNESS.into(),
        parameter: "kn = 1e2..1e9".into(),
        theory: "restitution unchanged (spread <= 1e-6)".into(),
        measured: format!("spread of e {}", g3(spread)),
        did: Did::Ran,
        pass: restitutions.len() == 8 && spread <= 1e-6,
    });
    Ok(rows)
}

/// Head-on free–free impacts at speeds 1e-6 … 1e2 at tc/dt = 50: below the guard's overlap
/// limit the collision runs and matches the closed form; beyond it the guard stops it, naming
/// the overlap.
pub fn speed(inputs: &Inputs) -> anyhow::Result<Vec<MapRow>> {
    let path = inputs.verify_dir.join("binary_collision.toml");
    let (text, base) = load(&path)?;
    let cf = closed_form(&base, 0.5 * base.particle_mass());
    let limit = base.guard.overlap * 0.5 * base.material.diameter;
    let mut rows = Vec::new();
    for v0 in [1e-6, 1e-4, 1e-2, 1.0, 10.0, 30.0, 100.0] {
        let delta = cf.delta_max_per_speed * v0;
        let within = delta < limit;
        let (measured, trustworthy) = match sweep(&base, false, PER_TC, v0) {
            Ok(s) => describe(&s),
            Err(f) => (stopped(&f).text(), false),
        };
        let did = did(&text, &path, v0);
        let pass = if within {
            judge(true, trustworthy, &did)
        } else {
            matches!(&did, Did::Stopped(m) if m.contains("overlap"))
        };
        rows.push(MapRow {
            case: SPEED.into(),
            parameter: format!("v0 = {v0:e}"),
            theory: format!(
                "e {:.6}, dmax {} {} guard limit {}",
                cf.e,
                g3(delta),
                if within { "<" } else { ">" },
                g3(limit)
            ),
            measured,
            pass,
            did,
        });
    }
    Ok(rows)
}
