//! Yade (Debian package `yade`, installed by ci/test.sh) runs the scripts verdem generates: the
//! binary collisions of the verification case against the clipped closed forms, a short
//! cross-run from MercuryDPM's developed state against verdem in Yade's convention, and a short
//! in-run cross-run (`verdem cross yade --inrun`) read from Yade's in-run dumps.

mod common;

use verdem::case::Case;
use verdem::contact::Tangential;
use verdem::peers::{self, Peer, Run, Save};

fn yade() -> &'static dyn Peer {
    peers::by_name("yade").unwrap()
}

fn collision_case() -> Case {
    Case::load(&common::root().join("cases/verify/binary_collision.toml")).unwrap()
}

/// Yade's law clips the normal force: its restitution and the duration of its force are those
/// of the clipped closed forms (Schwager & Pöschel 2008) within the tolerances of verdem's own
/// rows, and the restitution is verdem's with the clipped normal force and Yade's convention to
/// 1e-9 (the same scheme and first touch), much closer to the clipped closed form than to the
/// unclipped one (1.1e-3 and 2.2e-3 apart).
#[test]
fn yade_collisions_give_the_clipped_closed_forms_and_verdems_restitution() {
    let case = collision_case();
    let dir = tempfile::tempdir().unwrap();
    let rows = peers::collision::rows(yade(), &case, dir.path()).unwrap();
    assert_eq!(rows.len(), 16, "{rows:#?}");
    for r in &rows {
        assert!(r.passed(), "{r:?}");
    }
    assert!(rows.iter().any(|r| r.quantity.starts_with("contact time")));
    let mut clipped = case.clone();
    clipped.contact.clip_normal = true;
    clipped.contact.tangential = Tangential::YadeViscEl.into();
    let m = case.particle_mass();
    for (v0, wall, meff) in [(1.0, false, 0.5 * m), (0.1, true, m)] {
        let own = verdem::verify::collide(&clipped, v0, wall, 50.0).unwrap().e;
        let theirs =
            peers::collision::restitution(yade(), &case, v0, wall, &dir.path().join("one"))
                .unwrap();
        assert!(((theirs - own) / own).abs() < 1e-9, "{theirs} vs {own}");
        let cf = verdem::verify::collision::closed_form(&case, meff);
        assert!(
            (theirs - cf.e_clipped).abs() < 0.25 * (theirs - cf.e).abs(),
            "{theirs}: clipped {}, unclipped {}",
            cf.e_clipped,
            cf.e
        );
    }
}

/// From the steady state of verdem's full run, Yade and verdem with Yade's law (convention
/// `yade-viscel`, clipped normal force, springs advanced at set-up) integrate the same
/// equations: over 600 steps they agree to round-off (positions 1e-10, velocities 1e-9, where
/// chaos has only begun to amplify the last bits), contact by contact in the saves. With the
/// nearest other convention (LIGGGHTS', which projects the spring instead of turning it) the
/// velocities differ by more than 1e-7 within the same steps.
#[test]
fn a_short_cross_run_agrees_to_round_off_in_yades_convention_only() {
    use verdem::peers::cross::cross;
    let case = Case::load(&common::root().join("cases/shear_flow_steady.toml")).unwrap();
    let state = common::root().join("golden/full_run/shear_flow.final.data");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("matched");
    let r = cross(
        yade(),
        &case,
        yade().convention(),
        &state,
        600,
        200,
        1,
        &out,
    )
    .unwrap();
    assert_eq!(r.convention, Tangential::YadeViscEl);
    assert_eq!(r.saves.len(), 4);
    for s in &r.saves {
        assert!(
            s.dx.max < 1e-10 && s.dv.max < 1e-9 && s.dw.max < 1e-9,
            "{s:?}"
        );
    }
    // the saves' contacts: the same pairs, normal forces and springs to round-off
    let fstat = |sub: &str| {
        let f = out.join(sub).join("shear_flow_steady.fstat.0003");
        let mut rows: Vec<_> = verdem::io::mercury::read_fstat(&f)
            .unwrap()
            .rows
            .into_iter()
            .filter(|r| r.i < r.j)
            .map(|r| (r.i, r.j, r.fn_signed, r.ft))
            .collect();
        rows.sort_by_key(|r| (r.0, r.1));
        rows
    };
    let (own, theirs) = (fstat("verdem"), fstat("yade"));
    assert!(!own.is_empty());
    assert_eq!(own.len(), theirs.len());
    for (a, b) in own.iter().zip(&theirs) {
        assert_eq!((a.0, a.1), (b.0, b.1));
        assert!(
            (a.2 - b.2).abs() < 1e-8 && (a.3 - b.3).abs() < 1e-8,
            "{a:?} {b:?}"
        );
    }
    let r = cross(
        yade(),
        &case,
        Tangential::Liggghts,
        &state,
        600,
        200,
        1,
        &dir.path().join("mismatched"),
    )
    .unwrap();
    assert!(r.saves[3].dv.max > 1e-7, "{:?}", r.saves[3]);
}

/// The in-run dumps of Yade (contacts and the positions of the bodies in contact every K steps,
/// all bodies every KP steps) over 4800 steps of the benchmark from the full run's final state:
/// every sample is read; Yade and verdem in its convention follow the same trajectory to
/// round-off over these steps, so their in-run profiles agree to round-off in every column
/// (which fails if a dump is taken at another instant than the step's forces, or with half-step
/// velocities); the walls' forces are every step's mean from `walls.txt` (the means of its
/// lines per bin), equal to verdem's from its engine's impulse, and not those of the dumped
/// contacts at the samples (the force on each wall sphere, summed per wall, averaged per bin);
/// a `walls.txt` with a line missing is refused, naming the file and line; verdem in MercuryDPM's convention has a core
/// pressure of the same sign within 20 % (the conventions differ by clipping and the tangential
/// cap, a few per cent over 1e6 steps, `golden/peers/compare_inrun.md`); a contact whose body
/// the position dump lacks is refused, by file.
#[test]
fn yades_inrun_dumps_give_its_profiles_and_wall_forces() {
    use verdem::peers::cross::cross_inrun;
    use verdem::state::Motion;
    use verdem::Vec3;
    let case = Case::load(&common::root().join("cases/shear_flow.toml")).unwrap();
    let state = common::root().join("golden/full_run/shear_flow.final.data");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("inrun");
    // contacts every 50 steps, particles every 150: a wall has a contact in about one sample
    // of 23 at the benchmark's sampling, so each wall has some in 96 samples
    let (k, kp) = (50, 150);
    let r = cross_inrun(
        yade(),
        &case,
        yade().convention(),
        &state,
        4800,
        2400,
        1,
        &out,
        Some((k, kp)),
    )
    .unwrap_or_else(|e| panic!("{e:#}"));
    for s in &r.saves {
        assert!(s.dx.max < 1e-9 && s.dv.max < 1e-8, "{s:?}");
    }
    let inrun = r.inrun.as_ref().expect("in-run profiles");
    let (peer, own) = (&inrun.peer, &inrun.verdem_as_peer);
    assert_eq!((peer.contact_samples, peer.particle_samples), (96, 32));
    assert_eq!(peer.bin_steps, kp);
    let contacts = common::assert_columns_agree(
        &own.profiles.mean,
        &peer.profiles.mean,
        1e-6,
        ("verdem as yade", "yade"),
    );
    assert!(contacts > 0.0, "no contact stress");
    // the walls' forces from the dumped contacts: the force on each wall sphere (group 0
    // bottom, 1 top), summed per wall, averaged over the samples of each bin
    let template = common::engine(&case, Some(&state), Default::default()).snapshot();
    let group = |id: usize| match template.particles.motion[id] {
        Motion::Prescribed(g) => Some(usize::from(g)),
        Motion::Free => None,
    };
    let yade_dir = out.join("yade");
    let per_bin = (kp / k) as f64;
    let mut bins = vec![[Vec3::zeros(); 2]; 32];
    for step in (k..=4800).step_by(k as usize) {
        let text = std::fs::read_to_string(yade_dir.join(format!("contacts.{step}.txt"))).unwrap();
        for line in text.lines().filter(|l| !l.starts_with('#')) {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            let on_first = Vec3::new(v[2], v[3], v[4]);
            let (a, b) = (v[0] as usize, v[1] as usize);
            let bin = &mut bins[((step - 1) / kp) as usize];
            match (group(a), group(b)) {
                (Some(g), None) => bin[g] += on_first / per_bin,
                (None, Some(g)) => bin[g] -= on_first / per_bin,
                _ => {}
            }
        }
    }
    assert!(bins.iter().any(|w| w[0].x != 0.0) && bins.iter().any(|w| w[1].x != 0.0));
    let walls = &peer.profiles.wall_force;
    assert!(peer.profiles.wall_force_every_step);
    assert_eq!(walls.len(), 32);
    // walls.txt: a line every k steps, three per bin
    let text = std::fs::read_to_string(yade_dir.join("walls.txt")).unwrap();
    let lines: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
        .collect();
    assert_eq!(lines.len(), 96);
    for (b, got) in walls.iter().enumerate() {
        let mut want = [Vec3::zeros(); 2];
        for v in &lines[3 * b..3 * b + 3] {
            assert_eq!(v.len(), 7);
            want[0] += Vec3::new(v[1], v[2], v[3]) / per_bin;
            want[1] += Vec3::new(v[4], v[5], v[6]) / per_bin;
        }
        assert_eq!(lines[3 * b + 2][0], ((b as u64 + 1) * kp) as f64);
        for g in 0..2 {
            assert!(
                (want[g] - got[g]).norm() <= 1e-12 * want[g].norm(),
                "wall {g}: walls.txt {want:?}, in-run {got:?}"
            );
        }
    }
    for g in 0..2 {
        let apart = bins
            .iter()
            .zip(walls)
            .filter(|(s, w)| (s[g] - w[g]).norm() > 1e-3 * w[g].norm())
            .count();
        assert!(
            apart > 0,
            "wall {g}'s every-step means are the sampled forces"
        );
    }
    for (w, v) in walls.iter().zip(&own.profiles.wall_force) {
        for g in 0..2 {
            assert!(
                (w[g] - v[g]).norm() <= 1e-9 * v[g].norm() + 1e-12,
                "wall {g}: yade {w:?}, verdem as yade {v:?}"
            );
        }
    }
    // verdem in MercuryDPM's convention: the core pressure of the same sign and within 20 %
    let pressure = |res| verdem::analysis::difference::CoreMean::of(res, "pressure").mean;
    let (p_yade, p_own) = (pressure(peer), pressure(&inrun.verdem));
    assert!(
        p_yade > 0.0 && p_own > 0.0 && (p_yade / p_own - 1.0).abs() < 0.2,
        "core pressure: yade {p_yade}, verdem {p_own}"
    );
    // the particle dumps are removed once read, the tables written
    assert!(!yade_dir.join("particles.150.txt").exists());
    for csv in ["yade", "verdem", "verdem_own"] {
        assert!(out.join(format!("{csv}.profiles_inrun.csv")).exists());
    }
    assert!(std::fs::read_to_string(out.join("inrun.md"))
        .unwrap()
        .contains("| yade | verdem as yade | pressure |"));
    // a contact whose body is missing from the position dump is refused, by file
    let positions = yade_dir.join("positions.400.txt");
    let text = std::fs::read_to_string(&positions).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() > 2, "no body in contact at step 400");
    lines.remove(1);
    std::fs::write(&positions, lines.join("\n") + "\n").unwrap();
    let mut template = template;
    template.contacts.clear();
    let yade_run = Run {
        dir: &yade_dir,
        np: 1,
    };
    let e = yade()
        .read_sample(&yade_run, Save::every(k, 400 / k), &template, false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("positions.400.txt") && e.contains("missing"),
        "{e}"
    );
    // a walls.txt without its line of step 200 is refused, naming the file and the line
    let walls_txt = yade_dir.join("walls.txt");
    let text = std::fs::read_to_string(&walls_txt).unwrap();
    let kept: Vec<&str> = text.lines().filter(|l| !l.starts_with("200 ")).collect();
    std::fs::write(&walls_txt, kept.join("\n") + "\n").unwrap();
    let e = peers::inrun::peer_profiles(
        yade(),
        &yade_run,
        &verdem::analysis::cg::CgOptions::for_case(&case),
        &template,
        peers::inrun::sampling(4800, k, kp),
        case.dt(),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("walls.txt:5: column 1 (step): step 250, expected 200"),
        "{e}"
    );
}

/// Contacts sampled every step (K = 1) over 300 steps, in which the bottom wall is hit from step
/// ~270: the walls' every-step means of `walls.txt` are then the means of the forces of the
/// contacts dumped at every step (both are the forces of the step's InteractionLoop), to
/// round-off.
#[test]
fn yades_wall_forces_every_step_are_its_sampled_ones_when_every_step_is_sampled() {
    use verdem::analysis::inrun::Inrun;
    use verdem::peers::cross::cross_inrun;
    let case = Case::load(&common::root().join("cases/shear_flow.toml")).unwrap();
    let state = common::root().join("golden/full_run/shear_flow.final.data");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("inrun");
    let r = cross_inrun(
        yade(),
        &case,
        yade().convention(),
        &state,
        300,
        150,
        1,
        &out,
        Some((1, 150)),
    )
    .unwrap_or_else(|e| panic!("{e:#}"));
    let walls = &r.inrun.as_ref().expect("in-run profiles").peer.profiles;
    assert!(walls.wall_force_every_step);
    let walls = &walls.wall_force;
    assert!(walls[1][0].x != 0.0, "the bottom wall was not hit");
    // the same run's forces at the samples (every step), from its contact dumps (the particle
    // dumps are removed once read: the particle fields here are the template's, only the walls
    // are compared)
    let mut template = common::engine(&case, Some(&state), Default::default()).snapshot();
    template.contacts.clear();
    let sampling = peers::inrun::sampling(300, 1, 150);
    let o = verdem::analysis::cg::CgOptions::for_case(&case);
    let mut sampled = Inrun::new(&o, &template.domain, sampling).unwrap();
    for step in 1..=300 {
        let dir = out.join("yade");
        let s = yade()
            .read_sample(
                &Run { dir: &dir, np: 1 },
                Save::every(1, step),
                &template,
                false,
            )
            .unwrap_or_else(|e| panic!("step {step}: {e:#}"));
        sampled.sample(&s, step % 150 == 0);
    }
    let sampled = sampled.result().unwrap();
    assert!(!sampled.profiles.wall_force_every_step);
    for (s, w) in sampled.profiles.wall_force.iter().zip(walls) {
        for g in 0..2 {
            assert!(
                (s[g] - w[g]).norm() <= 1e-12 * w[g].norm().max(1e-300),
                "wall {g}: sampled {s:?}, every step {w:?}"
            );
        }
    }
}
