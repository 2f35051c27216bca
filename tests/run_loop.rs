//! The run loop: saves, diagnostics, checkpoints and resumption, and the generated scene.

mod common;

use common::*;
use verdem::io::mercury;
use verdem::run::{self, RunOptions};
use verdem::step::engine::Overrides;

fn options(dir: &std::path::Path, end: u64, checkpoint_every: u64) -> RunOptions {
    RunOptions {
        end_step: end,
        save_every: 1000,
        checkpoint_every,
        out_dir: dir.to_path_buf(),
        name: "q".into(),
        tag: "q:3480".into(),
        progress: false,
        write_saves: true,
        vtk: false,
        stop: None,
    }
}

/// A run stopped at a checkpoint and resumed ends in the same bits as an uninterrupted one,
/// with the same saves and diagnostics.
#[test]
fn resumed_run_matches_uninterrupted_run_bit_for_bit() {
    let case = quick_case();
    let state = data("states/mercury_t143.85.data");
    let full_dir = tempfile::tempdir().unwrap();
    let mut full = engine(&case, Some(&state), Overrides::default());
    let reference = run::run(full.as_mut(), &options(full_dir.path(), 3000, 0), false).unwrap();

    let dir = tempfile::tempdir().unwrap();
    let mut first = engine(&case, Some(&state), Overrides::default());
    run::run(first.as_mut(), &options(dir.path(), 1700, 1500), false).unwrap();
    let ck = run::checkpoint_path(dir.path(), "q");
    assert!(ck.exists());
    let mut second = engine(
        &case,
        Some(&state),
        Overrides {
            threads: Some(1),
            ..Overrides::default()
        },
    );
    let from = verdem::io::checkpoint::read_run(&ck, second.as_mut(), "q:3480").unwrap();
    assert_eq!(from.step, 1500);
    assert!(from.lacks().is_empty(), "{:?}", from.lacks());
    let resumed = run::run_resumed(
        second.as_mut(),
        &options(dir.path(), 3000, 1500),
        &from,
        None,
    )
    .unwrap();
    assert_eq!(resumed.step, 3000);
    assert_eq!(resumed.hash, reference.hash);
    for k in 0..=3 {
        for ext in ["data", "fstat"] {
            let a = std::fs::read(mercury::save_path(full_dir.path(), "q", ext, k)).unwrap();
            let b = std::fs::read(mercury::save_path(dir.path(), "q", ext, k)).unwrap();
            assert!(a == b, "save {k} .{ext} differs");
        }
    }
    let diag =
        |d: &std::path::Path| std::fs::read_to_string(run::diagnostics_path(d, "q")).unwrap();
    // The resume is at step 1500, between saves 1 and 2.
    common::assert_resumed_diagnostics(&diag(dir.path()), &diag(full_dir.path()));
}

/// A checkpoint of another case, a truncated one and a file that is none are refused.
#[test]
fn checkpoint_of_another_case_is_refused() {
    let case = quick_case();
    let dir = tempfile::tempdir().unwrap();
    let e = engine(
        &case,
        Some(&data("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    let p = dir.path().join("x.checkpoint");
    verdem::io::checkpoint::write(&p, &e.snapshot(), e.params().dt, "q:3480").unwrap();
    let mut other = engine(&case, None, Overrides::default());
    let err = verdem::io::checkpoint::read(&p, other.as_mut(), "other:3480").unwrap_err();
    assert!(err.to_string().contains("checkpoint of case"), "{err}");
    // a truncated checkpoint fails its checksum; a short foreign file is no checkpoint
    let bytes = std::fs::read(&p).unwrap();
    let cut = dir.path().join("cut.checkpoint");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = verdem::io::checkpoint::read(&cut, other.as_mut(), "q:3480").unwrap_err();
    assert!(
        err.to_string()
            .contains("cut.checkpoint: refused, a corrupted checkpoint"),
        "{err}"
    );
    for junk in [&b"garbage"[..], b"garbage and more"] {
        std::fs::write(&cut, junk).unwrap();
        let err = verdem::io::checkpoint::read(&cut, other.as_mut(), "q:3480").unwrap_err();
        assert!(
            err.to_string().ends_with("not a verdem checkpoint"),
            "{err}"
        );
    }
}

/// Saves are MercuryCG files that read back to the state that was written, bit for bit, with
/// every free–free contact twice and every free–wall contact once (free particle first).
#[test]
fn saves_round_trip_and_follow_mercurydpm_conventions() {
    let case = quick_case();
    let dir = tempfile::tempdir().unwrap();
    let mut e = engine(
        &case,
        Some(&data("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    run::run(e.as_mut(), &options(dir.path(), 1000, 0), false).unwrap();
    let snap = e.snapshot();
    let data = mercury::read_data(&mercury::save_path(dir.path(), "q", "data", 1)).unwrap();
    assert_eq!(data.time.to_bits(), snap.time.to_bits());
    assert_eq!(data.rows.len(), 3480);
    for (a, row) in data.rows.iter().enumerate() {
        assert_eq!(row.x, snap.particles.x[a]);
        assert_eq!(row.v, snap.particles.v[a]);
        assert_eq!(row.w, snap.particles.w[a]);
    }
    let fstat = mercury::read_fstat(&mercury::save_path(dir.path(), "q", "fstat", 1)).unwrap();
    let free = |k: usize| k >= 480;
    let expected: usize = snap
        .contacts
        .iter()
        .map(|c| {
            if free(c.p as usize) && free(c.i as usize) {
                2
            } else {
                1
            }
        })
        .sum();
    assert!(expected > 0);
    assert_eq!(fstat.rows.len(), expected);
    for r in &fstat.rows {
        assert!(free(r.i), "first index is a free particle");
        assert!(r.ft >= 0.0 && r.deltat <= 0.0 && r.delta > 0.0);
        // n points from j to i: the first particle lies on the n side of the contact point
        let xi = snap.particles.x[r.i];
        let d = snap.domain.min_image(xi - r.c);
        assert!(d.dot(&r.n) > 0.0);
        assert!((r.n.norm() - 1.0).abs() < 1e-12);
    }
}

/// The generated scene: walls as specified, free spheres without any overlap, and a
/// concentration profile flat away from the walls (a lattice that was not randomised fails).
#[test]
fn generated_scene_has_no_overlap_and_a_flat_profile() {
    let case = quick_case();
    let s = verdem::scene::build(&case, None).unwrap();
    let p = &s.particles;
    assert_eq!(p.len(), 3480);
    assert_eq!(p.free_count(), 3000);
    for a in 0..p.len() {
        for b in a + 1..p.len() {
            if p.is_free(a) || p.is_free(b) {
                let d = s.domain.min_image(p.x[a] - p.x[b]).norm();
                assert!(d >= 1.0, "particles {a} and {b} overlap: distance {d}");
            }
        }
    }
    // Fine slices of the core (z in [3, 19]): counts consistent with a uniform density
    // (chi-square per slice near 1; a simple cubic lattice gives layers, far above).
    let (z0, z1, bins) = (3.0, 19.0, 64);
    let mut counts = vec![0f64; bins];
    for a in 480..p.len() {
        let z = p.x[a].z;
        if z >= z0 && z < z1 {
            counts[((z - z0) / (z1 - z0) * bins as f64) as usize] += 1.0;
        }
    }
    let mean = counts.iter().sum::<f64>() / bins as f64;
    let chi2: f64 = counts
        .iter()
        .map(|c| (c - mean).powi(2) / mean)
        .sum::<f64>()
        / (bins - 1) as f64;
    assert!(
        chi2 < 2.0,
        "reduced chi-square {chi2}: not homogeneous ({counts:?})"
    );
    // and the mean density of the core is that of the whole gap
    let expected = 3000.0 / 20.0 * (z1 - z0) / bins as f64;
    assert!(
        (mean - expected).abs() < 0.08 * expected,
        "mean {mean} expected {expected}"
    );
}
