//! Yade (Debian package `yade`, installed by ci/test.sh) runs the scripts verdem generates: the
//! binary collisions of the verification case against the clipped closed forms, and a short
//! cross-run from MercuryDPM's developed state against verdem in Yade's convention.

mod common;

use verdem::case::{Case, Tangential};
use verdem::peers::{self, Peer};

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
    clipped.contact.tangential = Tangential::YadeViscEl;
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
