//! Flat walls: a sphere bouncing on a plane as on a fixed sphere of infinite radius, the run
//! guard stopping a sphere through a wall, and a run with wall contacts checkpointed and
//! resumed bit for bit on one and two threads.

mod common;

use common::*;
use verdem::case::Case;
use verdem::io::checkpoint;
use verdem::step::engine::Overrides;

fn wall_case() -> Case {
    Case::load(&root().join("cases/verify/wall_impact.toml")).unwrap()
}

/// A gas of spheres in a closed box of six flat walls, the floor moving along y: many wall
/// contacts opening and closing, sliding and rolling.
fn boxed_gas(threads: usize) -> Case {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        12.0 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    };
    let mut spheres = String::new();
    for k in 0..64 {
        let at = |c: usize| -2.25 + 1.5 * c as f64;
        spheres.push_str(&format!(
            "[[scene.sphere]]\nx = [{}, {}, {}]\nv = [{}, {}, {}]\n",
            at(k % 4),
            at(k / 4 % 4),
            at(k / 16),
            next(),
            next(),
            next()
        ));
    }
    let text = format!(
        r#"name = "boxed"
[run]
steps = 3000
save_every = 3000
steps_per_collision = 50.0
threads = {threads}
gravity = [0.0, 0.0, -10.0]
[domain]
lo = [-4.0, -4.0, -4.0]
hi = [4.0, 4.0, 4.0]
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
{spheres}[[wall]]
point = [0.0, 0.0, -3.0]
normal = [0.0, 0.0, 1.0]
velocity = [0.0, 0.5, 0.0]
[[wall]]
point = [0.0, 0.0, 3.0]
normal = [0.0, 0.0, -1.0]
[[wall]]
point = [-3.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[wall]]
point = [3.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
[[wall]]
point = [0.0, -3.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[wall]]
point = [0.0, 3.0, 0.0]
normal = [0.0, -1.0, 0.0]
"#
    );
    Case::parse(&text, "boxed.toml").unwrap()
}

/// A head-on impact on a plane rebounds with the free–wall restitution of the linear
/// spring–dashpot (m* = m): e = 0.92976 (binary_collision.toml), to the scheme's error at 50
/// steps a collision.
#[test]
fn a_sphere_rebounds_from_a_plane_with_the_free_wall_restitution() {
    let case = wall_case();
    let mut e = engine(&case, None, Overrides::default());
    e.advance(1000).unwrap();
    let snap = e.snapshot();
    let v = snap.particles.v[0];
    assert!(snap.wall_contacts.is_empty(), "still in contact");
    assert!((v.x - 0.92976).abs() < 2e-3, "rebound {v}");
    assert_eq!(v.y, 0.0);
    assert!(e.deepest_overlap() == 0.0 || e.deepest_overlap() < 0.1);
}

/// A sphere driven through a wall faster than the contact can stop it is a named failure of
/// the run guard (the step, the particle, the overlap with the wall), never a number.
#[test]
fn a_sphere_through_a_wall_stops_the_run_naming_it() {
    let mut case = wall_case();
    if let verdem::case::Scene::Spheres { sphere } = &mut case.scene {
        sphere[0].v = [-400.0, 0.0, 0.0];
    }
    let mut e = engine(&case, None, Overrides::default());
    let err = e.advance(1000).unwrap_err();
    let text = err.to_string();
    assert!(err.ids == vec![1], "{text}");
    assert!(
        text.contains("wall[0]") && text.contains("overlap"),
        "{text}"
    );
}

/// The boxed gas on one and on two threads gives the same bits, wall contacts and all; a run
/// checkpointed half way and resumed gives the bits of the straight run.
#[test]
fn wall_contacts_resume_bit_for_bit_on_one_and_two_threads() {
    let one = boxed_gas(1);
    let mut straight = engine(&one, None, Overrides::default());
    straight.advance(4000).unwrap();
    let want = verdem::io::hash::state_hash(&straight.snapshot());
    let mut two = engine(&boxed_gas(2), None, Overrides::default());
    two.advance(4000).unwrap();
    assert_eq!(verdem::io::hash::state_hash(&two.snapshot()), want);

    let mut first = engine(&one, None, Overrides::default());
    first.advance(2000).unwrap();
    let half = first.snapshot();
    assert!(
        !half.wall_contacts.is_empty(),
        "no wall contact at the checkpoint"
    );
    let dir = tempfile::tempdir().unwrap();
    let ck = dir.path().join("boxed.ck");
    let tag = checkpoint::tag(&one);
    checkpoint::write(&ck, &half, one.dt(), &tag).unwrap();
    let mut resumed = engine(&one, None, Overrides::default());
    checkpoint::read(&ck, resumed.as_mut(), &tag).unwrap();
    assert_eq!(resumed.snapshot().wall_contacts, half.wall_contacts);
    resumed.advance(2000).unwrap();
    assert_eq!(verdem::io::hash::state_hash(&resumed.snapshot()), want);
    // the hash sees the walls' contacts: the same particles without them hash otherwise
    let mut bare = half.clone();
    bare.wall_contacts.clear();
    let with = verdem::io::hash::state_hash(&half);
    assert_ne!(verdem::io::hash::state_hash(&bare), with);
}

/// `verdem verify`'s plane rows: every one passes and gates, head-on, oblique and rolling for
/// every tangential convention; the recurrence rows hold the plane to the scheme's own
/// free–wall numbers at round-off.
#[test]
fn the_plane_rows_pass() {
    let case = wall_case();
    let rows = verdem::verify::walls::rows(&case).unwrap();
    let conventions = verdem::contact::Tangential::with_constant_kt().count();
    // 3 speeds × 6 quantities, the order, 2 oblique and 4 rolling rows per convention
    assert_eq!(rows.len(), 19 + 6 * conventions);
    for r in &rows {
        assert!(r.passed(), "{r:?}");
    }
    assert!(
        rows.iter()
            .filter(|r| r.case.contains("recurrence"))
            .count()
            == 9
    );
}
