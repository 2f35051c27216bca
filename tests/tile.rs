//! `verdem tile`: the steady benchmark cell tiled 3 × 2 (unequal counts, so a swap of x and y
//! shows) from the full run's final state is the same packing repeated: every contact of the
//! cell appears once per tile with the same overlap (a periodic image that became a neighbour
//! tile sits where the image sat), walls keep their ids first and the box grows by whole cells.

mod common;

use verdem::case::{Case, Scene};
use verdem::state::{Motion, Snapshot};
use verdem::step::engine::Overrides;

/// The overlaps (length) of the contacts found by a force evaluation of the state, ascending.
fn overlaps(s: &Snapshot) -> Vec<f64> {
    let p = &s.particles;
    let mut out: Vec<f64> = s
        .contacts
        .iter()
        .map(|c| {
            let (a, b) = (c.p as usize, c.i as usize);
            p.radius[a] + p.radius[b] - s.domain.min_image(p.x[a] - p.x[b]).norm()
        })
        .collect();
    out.sort_by(f64::total_cmp);
    out
}

/// The state of `case` from its `run.init` after the set-up force evaluation.
fn set_up(case: &Case) -> Snapshot {
    let mut e = common::engine(case, None, Overrides::default());
    e.advance(0).unwrap();
    e.snapshot()
}

/// `verdem tile` of the steady case `nx` × `ny` into `dir`: what it printed, and the tiled case.
fn tile_steady(dir: &std::path::Path, nx: usize, ny: usize) -> (String, std::path::PathBuf) {
    let (nx_arg, ny_arg) = (nx.to_string(), ny.to_string());
    let out = common::verdem_ok([
        "tile".as_ref(),
        "cases/shear_flow_steady.toml".as_ref(),
        "--nx".as_ref(),
        nx_arg.as_ref(),
        "--ny".as_ref(),
        ny_arg.as_ref(),
        "--out".as_ref(),
        dir.as_os_str(),
    ]);
    let printed = String::from_utf8_lossy(&out.stdout).to_string();
    (
        printed,
        dir.join(format!("shear_flow_steady_{nx}x{ny}.toml")),
    )
}

#[test]
fn a_tiled_state_repeats_every_contact_of_the_cell_once_per_tile() {
    let dir = tempfile::tempdir().unwrap();
    let (listed, case_path) = tile_steady(dir.path(), 3, 2);
    assert!(listed.contains("shear_flow_steady_3x2.toml"), "{listed}");
    assert!(listed.contains("shear_flow_steady_3x2.data"), "{listed}");

    let cell_case = Case::load(&common::root().join("cases/shear_flow_steady.toml")).unwrap();
    let tiled_case = Case::load(&case_path).unwrap();
    let (cell, tiled) = (set_up(&cell_case), set_up(&tiled_case));
    let tiles = 6;

    // box: x and y by whole cells, z unchanged
    let (lc, lt) = (cell.domain.lengths(), tiled.domain.lengths());
    assert_eq!(lt.x, 3.0 * lc.x);
    assert_eq!(lt.y, 2.0 * lc.y);
    assert_eq!(lt.z, lc.z);
    assert_eq!(tiled.time, cell.time);

    // ids: 1440 bottom wall spheres, then 1440 top ones (at their walls' heights), then free
    let p = &tiled.particles;
    assert_eq!(p.len(), tiles * 3480);
    let Scene::BumpyShear {
        bottom_z, top_z, ..
    } = tiled_case.scene
    else {
        panic!("a bumpy-shear case expected");
    };
    let per_wall = tiles * 240;
    for a in 0..p.len() {
        let (motion, z) = match a {
            a if a < per_wall => (Motion::Prescribed(0), Some(bottom_z)),
            a if a < 2 * per_wall => (Motion::Prescribed(1), Some(top_z)),
            _ => (Motion::Free, None),
        };
        assert_eq!(p.motion[a], motion, "particle {}", a + 1);
        if let Some(z) = z {
            assert_eq!(p.x[a].z, z, "wall particle {}", a + 1);
        }
    }

    // contacts: the cell's, once per tile, with the same overlaps; shifting by whole cells
    // rounds a distance by a few ulps of the box length, far below 1e-12
    let (oc, ot) = (overlaps(&cell), overlaps(&tiled));
    assert!(!oc.is_empty());
    assert_eq!(ot.len(), tiles * oc.len());
    let repeated: Vec<f64> = oc
        .iter()
        .flat_map(|&d| std::iter::repeat_n(d, tiles))
        .collect();
    let worst = repeated
        .iter()
        .zip(&ot)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "overlaps differ by up to {worst:e}");
    assert!((ot[ot.len() - 1] - oc[oc.len() - 1]).abs() < 1e-12);
}

#[test]
fn a_case_that_is_not_bumpy_shear_is_refused_with_its_file_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .args([
            "tile",
            "cases/verify/binary_collision.toml",
            "--nx",
            "2",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("binary_collision.toml") && err.contains("bumpy-shear"),
        "{err}"
    );
}

/// A system of more than a chunk's most particles runs in several chunks on one thread, and in
/// more than the team's 16 on two or three: the tiled state keeps its bits on 1, 2 and 3 threads
/// across rebuilds (a small skin makes them frequent).
#[test]
fn a_system_of_several_chunks_keeps_its_bits_on_one_two_and_three_threads() {
    let dir = tempfile::tempdir().unwrap();
    let case = Case::load(&tile_steady(dir.path(), 5, 4).1).unwrap();
    let run = |threads| {
        let mut e = common::engine(
            &case,
            None,
            Overrides {
                threads: Some(threads),
                skin: Some(0.02),
                ..Overrides::default()
            },
        );
        let hash = common::hash_after(e.as_mut(), 400);
        (hash, e.counters().rebuilds, e.state().particles.len())
    };
    let (reference, rebuilds, particles) = run(1);
    // 69600 particles: three chunks on one thread
    assert!(particles > 2 * verdem::step::neighbor::rebuild::CHUNK_PARTICLES);
    assert!(rebuilds >= 2, "{rebuilds} rebuilds");
    assert_eq!(run(2).0, reference, "2 threads");
    assert_eq!(run(3).0, reference, "3 threads");
}
