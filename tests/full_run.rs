//! The recorded full benchmark run (golden/full_run/, made by ci/record_full_run.sh): its final
//! state is the recorded one, and it is a steady state of verdem's physics — a short run from it
//! gives profiles that deviate from the full run's steady profiles (saves 2001..4000) no more than
//! windows of the same length of the full run itself do (golden/full_run/window_chi2.toml, made
//! by ci/window_chi2.sh: the block errors of a short series miss the flow's slow fluctuations,
//! so χ²/dof of the same physics is well above 1).

mod common;

use sha2::{Digest, Sha256};
use verdem::cg::{self, table::Table, CgOptions};
use verdem::engine::Overrides;

fn golden(name: &str) -> std::path::PathBuf {
    common::root().join("golden/full_run").join(name)
}

/// The value of `key = "…"` in the provenance file.
fn provenance(key: &str) -> String {
    let text = std::fs::read_to_string(golden("provenance.toml")).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    table[key].as_str().unwrap().to_string()
}

#[test]
fn final_state_is_the_recorded_one() {
    let bytes = std::fs::read(golden("shear_flow.final.data")).unwrap();
    let digest: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(digest, provenance("final_state_sha256"));
}

/// χ²/dof of each benchmark profile of `a` against `b` over the core.
fn chi2s(a: &Table, b: &Table, window: (f64, f64)) -> Vec<(&'static str, f64)> {
    cg::FIELDS
        .iter()
        .map(|&(name, col)| (name, cg::table::chi2(a, b, col, window).unwrap()))
        .collect()
}

#[test]
fn a_short_run_from_the_final_state_matches_the_steady_profiles() {
    let case = common::quick_case();
    let mut e = common::engine(
        &case,
        Some(&golden("shear_flow.final.data")),
        Overrides {
            threads: Some(2),
            ..Overrides::default()
        },
    );
    let dir = tempfile::tempdir().unwrap();
    common::run_with_saves(e.as_mut(), dir.path(), "s", STEPS, STEPS / SAVES);
    let mut o = CgOptions::for_case(&case);
    o.from = Some(1);
    let series = cg::Series::find(&dir.path().join("s")).unwrap();
    let profiles = cg::coarse_grain(&series, &o).unwrap();
    let short = Table::of(&profiles);
    let steady = Table::read(&golden("shear_flow.profiles.csv")).unwrap();
    let window = cg::core_window(&profiles.grid);
    let windows: toml::Table =
        toml::from_str(&std::fs::read_to_string(golden("window_chi2.toml")).unwrap()).unwrap();
    let limit = |name: &str| MARGIN * windows[name].as_float().unwrap();
    for (name, c) in chi2s(&short, &steady, window) {
        assert!(
            c < limit(name),
            "{name}: chi2/dof {c:.2} against the steady profiles (limit {:.2})",
            limit(name)
        );
    }
    // The yardstick can fail: the same short run against steady profiles whose core velocity is
    // off by 0.05 (5 % of the wall speed).
    let mut shifted = steady.clone();
    let vx = cg::FIELDS[0].1;
    for row in &mut shifted.mean {
        row[vx] += 0.05;
    }
    let (_, c) = chi2s(&short, &shifted, window)[0];
    assert!(
        c > limit("vx"),
        "a 0.05 shift of vx gives only chi2/dof {c:.2}"
    );
}

/// Steps of the short run (72 time units) and its saves: the length of the calibration windows.
const STEPS: u64 = 1_000_000;
const SAVES: u64 = 20;
/// Allowed χ²/dof: this times the largest of the full run's own windows.
const MARGIN: f64 = 1.5;
