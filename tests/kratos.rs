//! Kratos DEM as a peer (PyPI KratosMultiphysics and KratosDEMApplication 10.4.4 in verdem's
//! Python: VERDEM_PYTHON, else the virtual environment target/venv that ci/test.sh makes): the
//! binary collisions against the closed forms, a short cross-run on the quick case, the threads
//! of a timing run and the error of a Python without Kratos.

mod common;

use verdem::peers::{self, Peer, Run, Save};

fn kratos() -> &'static dyn Peer {
    peers::by_name("kratos").unwrap()
}

/// Kratos clips the normal force at zero, so its restitution is that of the clipped closed
/// form (the force ends at Fn = 0; the unclipped one differs by 2.0e-3 free–free, beyond the
/// tolerance), and its spheres overlap for the closed form's contact time to a step. Its scheme is verdem's
/// (its velocity is verdem's half-step one), so it gives verdem's clipped restitution to
/// round-off.
#[test]
fn kratos_collisions_follow_the_clipped_closed_form_and_verdem() {
    let case = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let rows = peers::collision::rows(kratos(), &case, dir.path()).unwrap();
    assert_eq!(rows.len(), 16, "{rows:?}");
    assert_eq!(
        rows.iter()
            .filter(|r| r.quantity == "restitution e (force ends at Fn = 0)")
            .count(),
        8
    );
    assert_eq!(
        rows.iter().filter(|r| r.quantity == "overlap time").count(),
        8
    );
    for r in &rows {
        assert!(r.passed(), "{r:?}");
    }
    let mut clipped = case.clone();
    clipped.contact.clip_normal = true;
    for (v0, wall) in [(1.0, false), (0.1, true)] {
        let own = verdem::verify::collide(&clipped, v0, wall, 50.0).unwrap().e;
        let theirs =
            peers::collision::restitution(kratos(), &case, v0, wall, &dir.path().join("one"))
                .unwrap();
        assert!(((theirs - own) / own).abs() < 1e-9, "{theirs} vs {own}");
    }
}

/// From MercuryDPM's developed state the wall spheres of Kratos move as verdem's to round-off
/// (they are moved at their fixed velocity, never integrated), while the free spheres part by
/// the tangential laws' differences (measured 2.4e-6 after 100 steps, 1.3e-5 after 200); the
/// profiles are not compared, Kratos giving no contact forces.
#[test]
fn kratos_runs_the_shear_case_from_a_state() {
    use verdem::peers::cross::cross;
    let case = common::quick_case();
    let state = common::data("states/mercury_t143.85.data");
    let dir = tempfile::tempdir().unwrap();
    let r = cross(
        kratos(),
        &case,
        kratos().convention(),
        &state,
        200,
        100,
        1,
        dir.path(),
    )
    .unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(r.saves.len(), 3);
    assert_eq!(r.profiles_chi2, None);
    assert!(r.markdown().contains("profiles not compared"));
    assert_eq!(r.saves[0].dx.max, 0.0);
    for s in &r.saves[1..] {
        // 480 of the 3480 spheres are walls: the median sphere is not one, so check them apart
        assert!(s.dx.max < 1e-3 && s.dx.max > 1e-9, "{s:?}");
    }
    let run_dir = dir.path().join("kratos");
    let run = Run {
        dir: &run_dir,
        np: 1,
    };
    let save = |k: u64| kratos().read_frame(&run, Save::every(100, k)).unwrap();
    let snap = common::engine(&case, Some(&state), Default::default()).snapshot();
    let own = verdem::io::mercury::read_data(&dir.path().join("verdem/shear_flow_quick.data.0002"))
        .unwrap();
    let theirs = save(2);
    for a in 0..480 {
        let d = snap.domain.min_image(own.rows[a].x - theirs.x[a]);
        assert!(d.norm() < 1e-12, "wall sphere {a}: {d:?}");
    }
    let e = kratos()
        .read_contacts(&run, Save::every(100, 2), &snap)
        .unwrap_err();
    assert!(peers::lacks(&e).is_some(), "{e:#}");
    assert!(e.to_string().contains("no per-contact forces"), "{e}");
}

/// A timing run without saves on 1 and 2 OpenMP threads: Kratos reports the threads it was
/// given and verdem reads its loop time.
#[test]
fn kratos_times_its_loop_on_the_threads_it_is_given() {
    let case = common::quick_case();
    let e = common::engine(
        &case,
        Some(&common::data("states/mercury_t143.85.data")),
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let state = kratos()
        .write_state(&e.snapshot(), 1.0, dir.path(), "state")
        .unwrap();
    let script = kratos().input_script(&case, &state, 20, None).unwrap();
    for np in [1, 2] {
        let seconds = kratos()
            .run(
                &Run {
                    dir: dir.path(),
                    np,
                },
                &script,
            )
            .unwrap_or_else(|e| panic!("{np} thread(s): {e:#}"));
        assert!(seconds > 0.0 && seconds.is_finite(), "{seconds}");
        let log = std::fs::read_to_string(dir.path().join("kratos.log")).unwrap();
        assert!(
            log.contains(&format!("Maximum number of threads: {np}.")),
            "{log}"
        );
        assert!(!dir.path().join("dump.0.txt").exists());
    }
}

/// A Python without Kratos: `verdem peers` says how to install it, and a run fails with the
/// same advice instead of a Python traceback.
#[test]
fn a_python_without_kratos_is_named_with_the_pip_line() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .args(["peers", "kratos"])
        .env("VERDEM_PYTHON", "/nonexistent/python3")
        .current_dir(common::root())
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("not installed: Kratos DEM is not installed for /nonexistent/python3")
            && text.contains(
                "/nonexistent/python3 -m pip install KratosMultiphysics==10.4.4 KratosDEMApplication==10.4.4"
            ),
        "{text}"
    );
}

/// What Kratos cannot express, shown with one step of two touching spheres (the force on the
/// free one read from its velocity change: F(0) = m·(u(1) − u(0))/dt, the save at step 0
/// holding (u(0) + u(1))/2): the free sphere slides past a fixed one at 0.01 with an overlap of
/// 1e-3. The normal force is kn·δ; the tangential one is the dashpot's alone at the first step
/// (no displacement yet), and its coefficient is Kratos' 2·DAMPING_GAMMA·√(m_eq·kt) =
/// γn·√(kt/kn), not the benchmark's γt = 2/7·γn: Kratos has one damping ratio for both.
#[test]
fn kratos_tangential_dashpot_is_tied_to_the_normal_one() {
    use verdem::verify::collision::{impact_setup, Body};
    use verdem::Vec3;
    let case = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let (v, overlap) = (0.01, 1e-3);
    let body = |x: f64, vy: f64, fixed: bool| Body {
        x: Vec3::new(x, 0.0, 0.0),
        v: Vec3::new(0.0, vy, 0.0),
        w: Vec3::zeros(),
        radius: None,
        fixed,
    };
    let bodies = [
        body(-0.5 + overlap / 2.0, v, false),
        body(0.5 - overlap / 2.0, 0.0, true),
    ];
    let (timed, e) = impact_setup(&case, bodies, 50.0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let state = kratos()
        .write_state(&e.snapshot(), 1.0, dir.path(), "pair")
        .unwrap();
    let run = Run {
        dir: dir.path(),
        np: 1,
    };
    kratos()
        .run(&run, &kratos().collision_script(&timed, &state, 1).unwrap())
        .unwrap_or_else(|e| panic!("{e:#}"));
    let save = kratos()
        .read_frame(&run, Save { index: 0, step: 0 })
        .unwrap();
    let (m, dt) = (timed.particle_mass(), timed.dt());
    let f = (save.v[0] - Vec3::new(0.0, v, 0.0)) * (2.0 * m / dt);
    let c = &timed.contact;
    let kratos_gt = c.gamman * (c.kt / c.kn).sqrt();
    assert!(
        ((-f.x - c.kn * overlap) / (c.kn * overlap)).abs() < 1e-6,
        "normal {f:?}"
    );
    assert!(
        ((-f.y / v - kratos_gt) / kratos_gt).abs() < 1e-6,
        "tangential {f:?}"
    );
    assert!((kratos_gt / c.gammat - 1.87).abs() < 0.01);
}
