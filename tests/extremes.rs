//! The stability map (`verdem extremes`): every row of every group must pass, and the verdicts
//! must be able to fail — a wrong theory, a dt beyond the limit run silently, a stable case
//! refused or a wrong closed form do not pass.

mod common;

use verdem::case::Case;
use verdem::verify::extremes::damping::clipped_overdamped_restitution;
use verdem::verify::extremes::timestep::{
    judge, limit_per_tc, limit_row, measured_limit, sustained_stable,
};
use verdem::verify::extremes::{self, Did, Inputs, MapRow};

/// The rows of the group named `name`, written into a fresh folder.
fn group(name: &str) -> Vec<MapRow> {
    let out = tempfile::tempdir().unwrap();
    let inputs = Inputs::at(&common::root(), out.path());
    let (_, make) = extremes::GROUPS
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("no group {name}"));
    let rows = make(&inputs).unwrap();
    assert!(!rows.is_empty(), "group {name} has no rows");
    rows
}

/// Every row of the group `name` passes.
fn all_pass(name: &str) -> Vec<MapRow> {
    let rows = group(name);
    assert!(
        rows.iter().all(|r| r.pass),
        "failed rows:\n{}",
        extremes::table(&rows.iter().filter(|r| !r.pass).cloned().collect::<Vec<_>>())
    );
    rows
}

fn binary_collision() -> Case {
    Case::load(&common::root().join("cases/verify/binary_collision.toml")).unwrap()
}

#[test]
fn free_free_collisions_match_the_closed_form_and_the_limit() {
    let rows = all_pass(extremes::timestep::FREE_FREE);
    // every dt beyond the limit was refused or stopped, never run silently
    assert!(rows
        .iter()
        .filter(|r| r.theory.contains("unstable"))
        .all(|r| !r.did.ran()));
}

#[test]
fn free_wall_collisions_match_the_closed_form_and_the_limit() {
    all_pass(extremes::timestep::FREE_WALL);
}

#[test]
fn shear_is_stopped_or_refused_where_unstable_and_its_threshold_is_above_the_pairs() {
    let rows = all_pass(extremes::timestep::SHEAR);
    let threshold = rows.last().unwrap();
    assert_eq!(threshold.parameter, "threshold of tc/dt");
}

#[test]
fn restitution_does_not_depend_on_the_stiffness_at_a_fixed_tc_over_dt() {
    all_pass(extremes::scales::STIFFNESS);
}

#[test]
fn extreme_impact_speeds_run_or_are_stopped_by_the_overlap_guard() {
    let rows = all_pass(extremes::scales::SPEED);
    let fastest = rows.last().unwrap();
    assert!(
        matches!(&fastest.did, Did::Stopped(m) if m.contains("overlap")),
        "{fastest:?}"
    );
}

#[test]
fn damping_from_none_to_beyond_the_schemes_limit() {
    all_pass(extremes::damping::CASE);
}

#[test]
fn friction_at_zero_infinite_and_changed_mid_contact() {
    all_pass(extremes::friction::CASE);
}

#[test]
fn a_jammed_packing_held_static_stays_static() {
    all_pass(extremes::packing::JAMMED);
}

#[test]
fn the_shear_case_at_a_volume_fraction_of_0_6_runs() {
    all_pass(extremes::packing::DENSE_SHEAR);
}

#[test]
fn the_periodic_gas_keeps_its_momentum_over_1e7_steps() {
    all_pass(extremes::packing::GAS);
}

/// The measured limit of a sustained contact agrees with the theory's, and the row fails for a
/// theory 1 % off either way.
#[test]
fn a_wrong_stability_theory_does_not_pass() {
    let case = binary_collision();
    let m = case.particle_mass();
    for (wall, meff) in [(false, 0.5 * m), (true, m)] {
        let theory = limit_per_tc(&case, meff);
        let measured = measured_limit(&case, wall).unwrap();
        assert!(limit_row("pair", theory, measured).pass);
        for wrong in [0.99 * theory, 1.01 * theory] {
            assert!(!limit_row("pair", wrong, measured).pass, "{wrong}");
        }
    }
}

/// Just beyond the limit a sustained contact grows; just within it, it does not.
#[test]
fn a_dt_beyond_the_limit_is_unstable_and_one_within_is_not() {
    let case = binary_collision();
    let m = case.particle_mass();
    for (wall, meff) in [(false, 0.5 * m), (true, m)] {
        let limit = limit_per_tc(&case, meff);
        assert!(sustained_stable(&case, wall, 1.01 * limit).unwrap());
        assert!(!sustained_stable(&case, wall, 0.99 * limit).unwrap());
    }
}

/// A dt beyond the limit that runs silently fails, whatever the measurement; a stable case
/// must run, and may not be refused for being coarse; a coarse one that runs silently fails.
#[test]
fn the_verdict_fails_silent_runs_and_refused_stable_cases() {
    let said = || Did::Warned("coarse".into());
    let refused = || Did::Refused("beyond".into());
    let stopped = || Did::Stopped("overlap".into());
    assert!(!judge(false, true, &Did::Ran));
    assert!(!judge(false, false, &said()));
    assert!(judge(false, false, &refused()));
    assert!(judge(false, true, &stopped()));
    assert!(judge(true, true, &Did::Ran));
    assert!(judge(true, true, &said()));
    assert!(!judge(true, true, &refused()));
    assert!(!judge(true, false, &Did::Ran));
    assert!(judge(true, false, &said()));
    assert!(!judge(true, false, &refused()));
}

/// The clipped restitution of critical and over-critical damping against a direct
/// integration of m δ'' = −kn δ − γn δ' (RK4, 1e6 steps) up to the time the force vanishes.
#[test]
fn the_clipped_overdamped_restitution_matches_an_integration_of_the_ode() {
    for zeta in [1.0, 1.5, 2.0, 4.0] {
        // units ω0 = 1, v0 = 1: δ'' = −δ − 2ζ δ'
        let acc = |x: f64, v: f64| -x - 2.0 * zeta * v;
        let (mut x, mut v, h) = (0.0f64, 1.0f64, 1e-5);
        while x + 2.0 * zeta * v > 0.0 || x == 0.0 {
            let (k1x, k1v) = (v, acc(x, v));
            let (k2x, k2v) = (v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
            let (k3x, k3v) = (v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
            let (k4x, k4v) = (v + h * k3v, acc(x + h * k3x, v + h * k3v));
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
        let e = clipped_overdamped_restitution(zeta);
        assert!((e - (-v)).abs() < 1e-4, "zeta {zeta}: {e} vs {}", -v);
    }
    assert_eq!(clipped_overdamped_restitution(1.0), (-2.0f64).exp());
}

/// `--only` keeps the rows whose case and parameter contain the text, writes them to
/// OUT/extremes.csv and prints them; a text that matches nothing is an error.
#[test]
fn the_command_writes_the_map_and_selects_with_only() {
    let out = tempfile::tempdir().unwrap();
    let o = common::verdem_ok([
        "extremes",
        "--only",
        "friction",
        "--out",
        out.path().to_str().unwrap(),
    ]);
    let printed = String::from_utf8_lossy(&o.stdout);
    assert!(printed.contains("mu = 1e6") && printed.contains("3 passed, 0 failed"));
    let csv = std::fs::read_to_string(out.path().join("extremes.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(csv.starts_with("case,parameter,theory,measured,verdem,verdict\n"));
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .args(["extremes", "--only", "no such row", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no such row"));
}
