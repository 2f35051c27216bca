//! The run guard stops a run whose numbers cannot be trusted, names the step, the particles
//! and the quantity, exits with its own status (3), and writes no NaN or infinity into any file.

mod common;

use std::path::Path;

/// A two-sphere case: the binary collision's law and box, the spheres at `x1`, `x2` with
/// velocities `v1`, `v2` along x, dt = tc / `per_tc`, `steps` steps, a save every `every`.
fn two_spheres(
    dir: &Path,
    x: [f64; 2],
    v: [f64; 2],
    per_tc: f64,
    steps: u64,
    every: u64,
) -> String {
    let text = format!(
        r#"name = "pair"
[run]
steps = {steps}
save_every = {every}
steps_per_collision = {per_tc}
threads = 1
[domain]
lo = [-5.0, -5.0, -5.0]
hi = [5.0, 5.0, 5.0]
periodic = [false, false, false]
[material]
density = 1.0
diameter = 1.0
[contact]
kn = 2e5
gamman = 15.0
kt = 57142.857142857145
gammat = 4.285714285714286
mu = 0.3
[scene]
kind = "spheres"
[[scene.sphere]]
x = [{}, 0.0, 0.0]
v = [{}, 0.0, 0.0]
[[scene.sphere]]
x = [{}, 0.0, 0.0]
v = [{}, 0.0, 0.0]
"#,
        x[0], v[0], x[1], v[1]
    );
    let path = dir.join("pair.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Runs `verdem run CASE --out DIR --quiet`; returns the exit status and stderr.
fn run(case: &str, out: &Path) -> (Option<i32>, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .args(["run", case, "--quiet", "--out"])
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// No file of `dir` holds a NaN or an infinity.
fn no_garbage(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if let Ok(text) = std::fs::read_to_string(&p) {
            let lower = text.to_lowercase();
            assert!(
                !lower.contains("nan") && !lower.contains("inf"),
                "{} holds a NaN or an infinity",
                p.display()
            );
        }
    }
}

#[test]
fn coincident_spheres_are_stopped_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [0.0, 0.0], [0.0, 0.0], 50.0, 100, 10);
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("step 0"), "{err}");
    assert!(err.contains("particle 1 and 2"), "{err}");
    assert!(err.contains("overlap"), "{err}");
    assert!(err.contains("last save none"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    no_garbage(&out);
}

/// dt = tc/1.3: within the stability limit of one free–wall contact (tc/1.137), which the case
/// validation checks, but beyond that of a free sphere squeezed between two wall spheres (two
/// springs at once: √2 times the frequency; the spectral radius of its step is 3.8). Unstable
/// runs used to end with exit status 0.
#[test]
fn an_unstable_time_step_is_stopped_with_its_step_and_particles() {
    let dir = tempfile::tempdir().unwrap();
    let pair = two_spheres(dir.path(), [0.0, -0.98], [-0.1, 0.0], 1.3, 2000, 10);
    let text = std::fs::read_to_string(&pair).unwrap().replace(
        "x = [-0.98, 0.0, 0.0]\nv = [0, 0.0, 0.0]\n",
        "x = [-0.98, 0.0, 0.0]\nfixed = true\n[[scene.sphere]]\nx = [0.98, 0.0, 0.0]\nfixed = true\n",
    );
    assert!(text.contains("fixed"), "{text}");
    let case = dir.path().join("squeeze.toml");
    std::fs::write(&case, text).unwrap();
    let case = case.display().to_string();
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("the run guard stopped the run at step"),
        "{err}"
    );
    assert!(
        err.contains("particle 1 and 2")
            || err.contains("particle 1:")
            || err.contains("particle 2:"),
        "{err}"
    );
    assert!(
        err.contains("last save ") && err.contains("pair.data.00"),
        "the last good save is named: {err}"
    );
    no_garbage(&out);
}

/// The same collision at the benchmark's dt = tc/50 runs to its end: the guard does not stop a
/// sound run.
#[test]
fn a_sound_collision_runs_to_its_end() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [-1.0, 1.0], [5.0, -5.0], 50.0, 2000, 500);
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(0), "{err}");
    no_garbage(&out);
}

#[test]
fn the_overlap_limit_is_read_from_the_case_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [-1.0, 1.0], [5.0, -5.0], 50.0, 2000, 500);
    let text = std::fs::read_to_string(&case).unwrap();
    // At 5 units of speed the overlap peaks near 5·√(0.26/2e5) ≈ 5.7e-3, above 1e-3 of r.
    std::fs::write(&case, format!("{text}[guard]\noverlap = 0.002\n")).unwrap();
    let (code, err) = run(&case, &dir.path().join("tight"));
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("exceeds the limit 1e-3"), "{err}");
    std::fs::write(&case, format!("{text}[guard]\noverlap = 1.5\n")).unwrap();
    let (code, err) = run(&case, &dir.path().join("wide"));
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("guard.overlap: a fraction of the smaller radius at most 1"),
        "{err}"
    );
}

/// The command line replaces the case's limits: `--guard-overlap` tightens the overlap limit of
/// a sound collision until it stops (and, less tight, until the run is warned about),
/// `--guard-energy` loosens the energy limit until the heating gas runs; values out of range are
/// refused by the parser.
#[test]
fn the_guard_limits_are_set_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [-1.0, 1.0], [5.0, -5.0], 50.0, 2000, 500);
    let with = |case: &str, out: &str, flags: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
            .current_dir(common::root())
            .args(["run", case, "--quiet", "--out"])
            .arg(dir.path().join(out))
            .args(flags)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = with(&case, "tight", &["--guard-overlap", "0.002"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("exceeds the limit 1e-3"), "{err}");
    // the overlap peaks near 1.1e-2, 2.2e-2 of the radius: beyond half of 0.03, a warning; not
    // beyond half of 0.1
    let (code, err) = with(&case, "warned", &["--guard-overlap", "0.03"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning: the largest overlap reached 2.1")
            && err.contains("beyond 0.5 of the run guard's limit 0.03"),
        "{err}"
    );
    let (code, err) = with(&case, "quiet", &[]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("largest overlap"), "{err}");
    let (code, err) = with(&case, "wide", &["--guard-overlap", "1.5"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("must be above 0 and at most 1"), "{err}");
    let gas = elastic_gas(dir.path(), 2.0, 2000);
    let (code, err) = with(&gas, "gas", &["--guard-energy", "100"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("the contact gave its particles"), "{err}");
    let loose = ["--guard-energy", "100", "--guard-contact", "1e30"];
    let (code, err) = with(&gas, "gas-loose", &loose);
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = with(&gas, "gas0", &["--guard-energy", "0"]);
    assert_eq!(code, Some(2), "{err}");
    let (code, err) = with(&gas, "gas0", &["--guard-contact", "0"]);
    assert_eq!(code, Some(2), "{err}");
}

/// A periodic gas of 500 spheres with the benchmark's spring and no dissipation at all
/// (γn = γt = 0, frictionless), dt = tc/`per_tc`, `steps` steps.
fn elastic_gas(dir: &Path, per_tc: f64, steps: u64) -> String {
    let text = std::fs::read_to_string(common::root().join("cases/verify/conservation.toml"))
        .unwrap()
        .replace(
            "steps_per_collision = 50.0",
            &format!("steps_per_collision = {per_tc}"),
        )
        .replace("steps = 1000000", &format!("steps = {steps}"))
        .replace("save_every = 10000", &format!("save_every = {steps}"))
        .replace("gamman = 15.0", "gamman = 0.0")
        .replace("gammat = 4.285714285714286", "gammat = 0.0")
        .replace("mu = 0.3", "mu = 0.0");
    assert!(text.contains("gamman = 0.0") && text.contains("mu = 0.0"));
    let path = dir.join("gas.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// At tc/dt = 2 (stable for the pair's spring alone, ω·dt = 1.57 < 2) each collision of the
/// elastic gas returns more energy than it received: the gas heats fivefold in 2000 steps. With
/// the contacts' accounts set aside, the energy balance stops it at the end of its first window,
/// naming the most energetic particle.
#[test]
fn a_gas_whose_collisions_create_energy_is_stopped_by_the_energy_balance() {
    let dir = tempfile::tempdir().unwrap();
    let case = elastic_gas(dir.path(), 2.0, 2000);
    let text = std::fs::read_to_string(&case).unwrap();
    assert!(!text.contains("[guard]"));
    std::fs::write(&case, format!("{text}\n[guard]\ncontact = 1e30\n")).unwrap();
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("at step 2000 "), "{err}");
    assert!(
        err.contains("the energy of the free particles went from"),
        "{err}"
    );
    assert!(
        err.contains("a contact gave back more energy than it received"),
        "{err}"
    );
    assert!(err.contains("last save ") && err.contains("conservation.data.0000"));
    no_garbage(&out);
}

/// The same gas as it is, with the contacts' accounts: one of its first collisions gives back
/// more than it took, and the run stops there, long before the window ends, naming the pair.
#[test]
fn a_gas_whose_collisions_create_energy_is_stopped_at_the_contact() {
    let dir = tempfile::tempdir().unwrap();
    let case = elastic_gas(dir.path(), 2.0, 2000);
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("the contact gave its particles"), "{err}");
    assert!(err.contains("particle ") && err.contains(" and "), "{err}");
    let step: u64 = err
        .split("at step ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{err}"));
    assert!(step < 2000, "stopped at step {step}: {err}");
    no_garbage(&out);
}

/// The same gas at tc/dt = 5 is coarse but sound: its energy stays within the scheme's
/// truncation, and it runs to its end.
#[test]
fn a_coarse_but_stable_elastic_gas_runs_to_its_end() {
    let dir = tempfile::tempdir().unwrap();
    let case = elastic_gas(dir.path(), 5.0, 3000);
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(0), "{err}");
    no_garbage(&out);
}

/// A wall sphere moving at 1 along x strikes a resting free sphere and sends it off at about
/// (1 + e): the free sphere's kinetic energy comes from the wall. The balance counts the wall's
/// work, so even a limit of 1 % of the energy at play passes; without that work the gain would
/// be all of the sphere's final energy.
#[test]
fn the_work_of_a_moving_wall_is_counted_in_the_energy_balance() {
    let dir = tempfile::tempdir().unwrap();
    let case = two_spheres(dir.path(), [-1.0, 0.0], [1.0, 0.0], 50.0, 2000, 1000);
    let text = std::fs::read_to_string(&case).unwrap();
    let fixed_first = text.replacen(
        "v = [1, 0.0, 0.0]\n",
        "v = [1, 0.0, 0.0]\nfixed = true\n",
        1,
    );
    assert_ne!(fixed_first, text, "the first sphere is made a wall sphere");
    std::fs::write(&case, format!("{fixed_first}[guard]\nenergy = 0.01\n")).unwrap();
    let out = dir.path().join("out");
    let (code, err) = run(&case, &out);
    assert_eq!(code, Some(0), "{err}");
    let last = std::fs::read_to_string(out.join("pair.data.0002")).unwrap();
    let vx: f64 = last
        .lines()
        .nth(2)
        .unwrap()
        .split_whitespace()
        .nth(3)
        .unwrap()
        .parse()
        .unwrap();
    assert!(vx > 1.5, "the free sphere was struck: vx = {vx}\n{last}");
}

/// A contact law that is not dissipative (a dashpot of negative γn: restitution
/// exp(|γn|·tc/2m_eff) = 1.11 for γn = −15) run at the benchmark's dt = tc/50, with overlaps far
/// below the overlap limit. The contact's account stops the run within the collision (about 50
/// steps from step 139), naming both spheres; with the accounts set aside, the energy balance
/// stops it at the end of its window (the whole advance of 1000 steps). The same law with
/// γn > 0 runs.
#[test]
fn a_law_that_gives_back_more_than_it_received_is_stopped() {
    use verdem::contact::normal::LinearSpringDashpot;
    use verdem::contact::tangential::Frictionless;
    use verdem::contact::Composed;
    use verdem::state::{Domain, Motion, Particles};
    use verdem::step::neighbor::NeighborBuilder;
    use verdem::step::{Core, Engine, Simulation};
    use verdem::Vec3;

    let run = |gamman: f64, contact: f64| {
        let domain = Domain::new(
            Vec3::new(-50.0, -5.0, -5.0),
            Vec3::new(50.0, 5.0, 5.0),
            [false; 3],
        );
        let mut p = Particles::default();
        // Two unit-density spheres of diameter 1 (m = π/6), head-on at ±0.5.
        let m = std::f64::consts::PI / 6.0;
        for (x, v) in [(-0.505, 0.5), (0.505, -0.5)] {
            p.push(
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(v, 0.0, 0.0),
                Vec3::zeros(),
                0.5,
                m,
                Motion::Free,
            );
        }
        let (kn, meff) = (2e5, 0.5 * m);
        let tc = std::f64::consts::PI / (kn / meff).sqrt();
        let builder = NeighborBuilder::new(0.1, 0.0, 0.5, verdem::case::Search::AllPairs);
        let mut core = Core::new(domain, p, tc / 50.0, None, builder, 1);
        core.params.guard.contact = contact;
        let law = Composed {
            normal: LinearSpringDashpot { kn, gamman },
            tangential: Frictionless,
        };
        let mut sim = Simulation::new(law, core);
        sim.advance(1000).map(|()| sim.largest_excess())
    };
    let failure = run(-15.0, 0.01).expect_err("a law that creates energy is stopped");
    assert!(
        failure.what.contains("the contact gave its particles"),
        "{failure}"
    );
    assert!(
        (139..200).contains(&failure.step),
        "stopped within the collision: {failure}"
    );
    assert_eq!(failure.ids, vec![1, 2], "{failure}");
    let failure = run(-15.0, f64::INFINITY).expect_err("the energy balance stops it too");
    assert!(
        failure.what.contains("the energy of the free particles"),
        "{failure}"
    );
    assert_eq!(failure.step, 1000, "{failure}");
    assert!(
        failure.ids == vec![1] || failure.ids == vec![2],
        "{failure}"
    );
    let excess = run(15.0, 0.01).expect("the dissipative law runs");
    assert_eq!(
        excess, 0.0,
        "a dissipative collision never gives out more than it took"
    );
}

/// A periodic gas of 500 spheres whose law gives back about 2 % more energy than each collision
/// received (γn = −1.5 against the benchmark's +15: restitution about 1.01). The gas heats, but
/// by so little a window that the energy balance alone lets it run; the contacts' accounts stop
/// it at one of its first collisions. So a single law's excess is found however large the
/// system it hides in.
#[test]
fn a_slightly_creative_law_is_found_in_a_large_gas() {
    use verdem::contact::normal::LinearSpringDashpot;
    use verdem::contact::tangential::Frictionless;
    use verdem::contact::Composed;
    use verdem::step::neighbor::NeighborBuilder;
    use verdem::step::{Core, Engine, Simulation};

    let case =
        verdem::case::Case::load(&common::root().join("cases/verify/conservation.toml")).unwrap();
    let steps = 6000;
    let run = |contact: f64| {
        let scene = verdem::scene::build(&case, None).unwrap();
        let builder = NeighborBuilder::new(case.neighbor.skin, 0.0, 0.5, case.neighbor.search);
        let mut core = Core::new(scene.domain, scene.particles, case.dt(), None, builder, 1);
        core.params.guard.contact = contact;
        let law = Composed {
            normal: LinearSpringDashpot {
                kn: case.contact.kn,
                gamman: -1.5,
            },
            tangential: Frictionless,
        };
        let mut sim = Simulation::new(law, core);
        let kinetic = |sim: &Simulation<_>| {
            let pt = &sim.state().particles;
            (0..pt.len())
                .map(|a| 0.5 * pt.v[a].norm_squared() / pt.inv_mass[a])
                .sum::<f64>()
        };
        let before = kinetic(&sim);
        sim.advance(steps).map(|()| kinetic(&sim) / before)
    };
    let heated = run(f64::INFINITY).expect("the energy balance alone lets it run");
    assert!(heated > 1.001, "the gas heated by {heated}");
    let failure = run(0.01).expect_err("the contacts' accounts stop it");
    assert!(
        failure.what.contains("the contact gave its particles"),
        "{failure}"
    );
    assert_eq!(failure.ids.len(), 2, "{failure}");
    assert!(failure.step < steps, "{failure}");
}

/// A sphere falling freely under gravity with a component along a periodic axis (x, where it
/// wraps around the box) and one along a walled axis (z): the balance counts the first as work
/// step by step and the second as potential energy, so it closes to round-off (a limit of 1e-9
/// of the energy at play passes). Counting either from the wrapped position would fail it.
#[test]
fn gravity_along_periodic_and_walled_axes_closes_the_energy_balance() {
    let dir = tempfile::tempdir().unwrap();
    let text = r#"name = "fall"
[run]
steps = 20000
save_every = 10000
steps_per_collision = 50.0
threads = 1
gravity = [1.0, 0.0, -1.0]
[domain]
lo = [0.0, 0.0, 0.0]
hi = [10.0, 10.0, 100.0]
periodic = [true, true, false]
[material]
density = 1.0
diameter = 1.0
[contact]
kn = 2e5
gamman = 15.0
kt = 57142.857142857145
gammat = 4.285714285714286
mu = 0.3
[scene]
kind = "spheres"
[[scene.sphere]]
x = [9.5, 5.0, 50.0]
[guard]
energy = 1e-9
"#;
    let case = dir.path().join("fall.toml");
    std::fs::write(&case, text).unwrap();
    let out = dir.path().join("out");
    let (code, err) = run(&case.display().to_string(), &out);
    assert_eq!(code, Some(0), "{err}");
    let last = std::fs::read_to_string(out.join("fall.data.0002")).unwrap();
    let x: f64 = last
        .lines()
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        x < 9.5,
        "the sphere wrapped around the periodic x axis: x = {x}"
    );
}
