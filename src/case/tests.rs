//! The case's reading, checks and derived quantities, on the shipped cases.

use super::*;
use crate::stability::{Direction, Pair};

const CASE: &str = include_str!("../../cases/shear_flow_quick.toml");

#[test]
fn benchmark_time_step_is_mercurys_exact_tc_over_50() {
    let case = Case::parse(CASE, "q.toml").unwrap();
    let tc = case.tc_free_free().unwrap();
    assert!((tc - 3.5963e-3).abs() < 1e-7);
    assert_eq!(tc / 50.0, 7.192545031528827e-05);
    assert_eq!(case.dt(), 7.192545031528827e-05);
    assert!((case.restitution(0.5 * case.particle_mass()).unwrap() - 0.90210).abs() < 1e-5);
    assert!((case.restitution(case.particle_mass()).unwrap() - 0.92976).abs() < 1e-5);
}

#[test]
fn invalid_value_names_file_line_and_field() {
    let bad = CASE.replace("kn = 2e5", "kn = -3.0");
    let e = Case::parse(&bad, "bad.toml").unwrap_err();
    let line = bad.lines().position(|l| l.starts_with("kn =")).unwrap() + 1;
    assert_eq!(
        e.to_string(),
        format!("bad.toml:{line}: contact.kn: must be > 0, got -3")
    );
}

/// A prescribed motion integrates nothing: the time step's checks against the scheme are
/// a run's only, the law's are every reader's.
#[test]
fn a_prescribed_motion_gets_the_laws_checks_and_not_the_time_steps() {
    let dt = |v: &str| CASE.replace("dt = 7.192545031528827e-05", &format!("dt = {v}"));
    // tc/5, then tc/1, beyond the limit tc/1.62
    let coarse = dt("7.192545031528827e-04");
    assert_eq!(Case::parse(&coarse, "c.toml").unwrap().warnings().len(), 1);
    let read = Case::parse_for_prescribed_motion(&coarse, "c.toml").unwrap();
    assert!(read.warnings().is_empty());
    let beyond = dt("3.6e-3");
    let e = Case::parse(&beyond, "b.toml").unwrap_err().to_string();
    assert!(e.contains("at most the stability limit"), "{e}");
    let read = Case::parse_for_prescribed_motion(&beyond, "b.toml").unwrap();
    assert_eq!(read.dt(), 3.6e-3);
    for (from, to, msg) in [
        ("kn = 2e5", "kn = -3.0", "contact.kn: must be > 0, got -3"),
        (
            "kn = 2e5",
            "kn = 1e308",
            "contact.kn: the free–free collision time",
        ),
        (
            "density = 1.0",
            "density = nan",
            "material.density: a finite number expected, got NaN",
        ),
    ] {
        let bad = beyond.replacen(from, to, 1);
        let e = Case::parse_for_prescribed_motion(&bad, "b.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("b.toml:") && e.contains(msg), "{e}");
    }
}

/// An unknown key, one in the tagged `[scene]` table, and a value of the wrong type.
#[test]
fn a_parse_error_names_its_line_and_field() {
    for (from, to, at, field, msg) in [
        (
            "mu = 0.3",
            "mu = 0.3\nfriction = 0.5",
            "friction",
            "contact.friction",
            "unknown field `friction`",
        ),
        (
            "top_vx = 1.0",
            "top_vx = 1.0\nbogus = 1",
            "bogus",
            "scene.bogus",
            "unknown field `bogus`",
        ),
        (
            "skin = 0.1",
            "skin = \"wide\"",
            "skin =",
            "neighbor.skin",
            "invalid type",
        ),
    ] {
        let bad = CASE.replace(from, to);
        let e = Case::parse(&bad, "bad.toml").unwrap_err();
        let line = bad.lines().position(|l| l.starts_with(at)).unwrap() + 1;
        assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
        assert!(e.msg.contains(msg), "{e}");
    }
}

#[test]
fn dt_must_be_given_exactly_once() {
    let bad = CASE.replace(
        "dt = 7.192545031528827e-05",
        "dt = 1e-5\nsteps_per_collision = 50.0",
    );
    let e = Case::parse(&bad, "bad.toml").unwrap_err();
    assert_eq!(e.field, "run.dt");
}

const PAIR: &str = include_str!("../../cases/verify/binary_collision.toml");
const WALL: &str = include_str!("../../cases/verify/oblique_impact.toml");

/// Two free spheres have a free–free contact only; a free sphere and a wall sphere a
/// free–wall one; with kt/kn = γt/γn = 2/7 the normal limit is named.
#[test]
fn the_contacts_of_the_scene_set_the_limit() {
    let pair = Case::parse(PAIR, "p.toml").unwrap();
    let m = pair.particle_mass();
    assert_eq!(pair.pairs(), vec![(Pair::FreeFree, 0.5 * m)]);
    assert_eq!(pair.stability_limits().len(), 2);
    let limit = pair.stability_limit().unwrap();
    assert_eq!(
        (limit.pair, limit.direction),
        (Pair::FreeFree, Direction::Normal)
    );
    let wall = Case::parse(WALL, "w.toml").unwrap();
    assert_eq!(wall.pairs(), vec![(Pair::FreeWall, m)]);
    assert!(wall.stability_limit().unwrap().dt > limit.dt);
    let quick = Case::parse(CASE, "q.toml").unwrap();
    let kinds: Vec<Pair> = quick.pairs().iter().map(|p| p.0).collect();
    assert_eq!(kinds, [Pair::FreeFree, Pair::FreeWall]);
}

/// A value of the wrong type or length inside a sphere of the tagged `[scene]` table is found
/// at the key holding it, and a wrong element of a multi-line array at its key.
#[test]
fn a_bad_value_inside_a_tagged_table_or_an_array_is_found_at_its_key() {
    let x = "x = [0.5005, 0.0, 0.0]";
    let line = PAIR.lines().position(|l| l == x).unwrap() + 1;
    for (to, msg) in [
        ("x = [0.5005, 0.0, \"a\"]", "invalid type: string \"a\""),
        ("x = [0.5005, 0.0]", "invalid length 2"),
    ] {
        let e = Case::parse(&PAIR.replace(x, to), "p.toml").unwrap_err();
        assert_eq!(
            (e.line, e.field.as_str()),
            (line, "scene.sphere[1].x"),
            "{e}"
        );
        assert!(e.msg.starts_with(msg), "{e}");
    }
    let periodic = "periodic = [false, false, false]";
    let line = PAIR.lines().position(|l| l == periodic).unwrap() + 1;
    let bad = PAIR.replace(periodic, "periodic = [false,\n  false,\n  0]");
    let e = Case::parse(&bad, "p.toml").unwrap_err();
    assert_eq!(
        (e.line, e.field.as_str()),
        (line + 2, "domain.periodic"),
        "{e}"
    );
}
