//! The verification tolerances catch a small error in the law: a law whose kn, γn or μ is off
//! by 0.1 %, judged against the answers of the case's own values, fails the collision and
//! oblique rows that test that parameter, and a law of any tangential convention whose kn, kt,
//! γn, γt or μ is off by 0.01 % fails the prescribed-motion history row that tests it, as
//! verdem's own law and as a program naming its convention; the case itself passes them.

mod common;

use verdem::case::Case;
use verdem::contact::Tangential;
use verdem::verify::driver::{MotionDriver, OWN};
use verdem::verify::histories;
use verdem::verify::kinematics::{ForceRow, MotionRow};
use verdem::verify::{Row, Subject};

fn load(name: &str) -> Case {
    Case::load(&common::root().join("cases/verify").join(name)).unwrap()
}

/// The binary-collision rows of `case`'s law with `change` applied, judged against `case`.
fn collisions_with(change: impl Fn(&mut Case)) -> Vec<Row> {
    let case = load("binary_collision.toml");
    let mut wrong = case.clone();
    change(&mut wrong);
    verdem::verify::collision::binary_collisions_against(&case, &wrong).unwrap()
}

fn failed<'a>(rows: &'a [Row], quantity: &str, case_has: &str) -> Vec<&'a Row> {
    rows.iter()
        .filter(|r| r.quantity.starts_with(quantity) && r.case.contains(case_has))
        .filter(|r| !r.passed())
        .collect()
}

fn count(rows: &[Row], quantity: &str, case_has: &str) -> usize {
    rows.iter()
        .filter(|r| r.quantity.starts_with(quantity) && r.case.contains(case_has))
        .count()
}

#[test]
fn the_case_itself_passes_every_collision_row() {
    let rows = collisions_with(|_| {});
    let failed: Vec<_> = rows.iter().filter(|r| !r.passed()).collect();
    assert!(failed.is_empty(), "{failed:#?}");
    // 2 partners × 4 speeds × (closed form and recurrence) × (e, duration, δmax, clipped e)
    assert_eq!(count(&rows, "", "dt=tc/50"), 32);
    assert_eq!(count(&rows, "", "recurrence"), 32);
}

#[test]
fn a_law_with_kn_off_by_a_tenth_of_a_percent_fails_restitution_and_overlap() {
    // e depends on kn only through the damping ratio: 1e-3 in kn moves e by 5e-5, δmax by 5e-4
    let rows = collisions_with(|c| c.contact.kn *= 1.001);
    for (quantity, n) in [("restitution e", 16), ("max overlap", 8)] {
        assert_eq!(count(&rows, quantity, "recurrence"), n, "{quantity}");
        assert_eq!(
            failed(&rows, quantity, "recurrence").len(),
            n,
            "{quantity}: {rows:#?}"
        );
    }
}

#[test]
fn a_law_with_gamman_off_by_a_tenth_of_a_percent_fails_restitution() {
    // ln e ∝ γn: 1e-3 in γn moves e by 1e-4 (0.1 of e's own size, ln e ≈ −0.1)
    let rows = collisions_with(|c| c.contact.gamman *= 1.001);
    assert_eq!(count(&rows, "restitution e", "recurrence"), 16);
    assert_eq!(
        failed(&rows, "restitution e", "recurrence").len(),
        16,
        "{rows:#?}"
    );
}

#[test]
fn a_law_with_mu_off_by_a_tenth_of_a_percent_fails_the_coulomb_rows_of_every_convention() {
    let case = load("oblique_impact.toml");
    let impulse = "impulse ratio Jt/Jn = mu";
    let right = verdem::verify::oblique::rows(&case).unwrap();
    let failed_right: Vec<_> = right.iter().filter(|r| r.gate && !r.passed()).collect();
    assert!(failed_right.is_empty(), "{failed_right:#?}");
    assert!(failed(&right, impulse, "").is_empty());
    let mut wrong = case.clone();
    wrong.contact.mu *= 1.001;
    let rows = verdem::verify::oblique::rows_against(&case, &wrong).unwrap();
    let n = count(&rows, impulse, "");
    // 3 sliding incidences and a spin-only slide per convention
    assert_eq!(
        n,
        4 * verdem::contact::Tangential::with_constant_kt().count()
    );
    assert_eq!(failed(&rows, impulse, "").len(), n, "{rows:#?}");
}

/// verdem's law of the case with one parameter changed: a wrong law behind the prescribed
/// motions, judged against the answers of the case's own values.
struct Wrong(fn(&mut Case));

impl MotionDriver for Wrong {
    fn drive(&self, case: &Case, motion: &[MotionRow]) -> anyhow::Result<Vec<ForceRow>> {
        let mut wrong = case.clone();
        (self.0)(&mut wrong);
        OWN.drive(&wrong, motion)
    }
    fn name(&self) -> String {
        "wrong".into()
    }
}

/// The tangential histories (load-unload, Coulomb limit, contact loss, dashpots) of
/// `subject`, judged as the table judges them (a program's failed rows again at dt/2 and
/// dt/4).
fn histories(subject: &Subject) -> Vec<Row> {
    let dir = common::root().join("cases/verify");
    let case = verdem::verify::MOTION_CASES
        .into_iter()
        .find(|c| c.variants == histories::HISTORIES)
        .unwrap();
    let mut rows = Vec::new();
    for label in histories::HISTORIES {
        rows.extend(case.judge(&dir, subject, label).unwrap());
    }
    rows
}

/// For every tangential convention, verdem's law with `change` applied and a program of that
/// law naming the convention fail the history row `catching` (case ending in `variant`),
/// which the convention's own law passes, and pass every other row where the right law
/// passes it unless `others` (rows a change of this parameter is expected to move too).
fn a_law_off_by_1e_4_fails(change: fn(&mut Case), variant: &str, catching: &str, others: &[&str]) {
    let wrong = Wrong(change);
    for conv in Tangential::with_constant_kt() {
        let right = histories(&Subject::own(conv));
        assert!(right.iter().all(|r| r.passed() || !r.gate), "{right:#?}");
        for subject in [
            Subject::own(conv).driven_by(&wrong),
            Subject::code(&wrong, Some(conv)),
        ] {
            let rows = histories(&subject);
            assert_eq!(rows.len(), right.len(), "{}", subject.label);
            let caught = |r: &Row| r.case.ends_with(variant) && r.quantity.starts_with(catching);
            let (row, own) = rows
                .iter()
                .zip(&right)
                .find(|(r, _)| caught(r))
                .unwrap_or_else(|| panic!("no row {catching:?} of {variant:?}"));
            assert!(own.passed(), "{own:?}");
            assert!(row.gate && row.failed(), "{}: {row:#?}", subject.label);
            // the program's row was judged again at finer steps where its property is refined
            // (not the normal force's): the error stays
            let refined = row
                .property
                .as_ref()
                .and_then(|k| verdem::verify::diagnosis::Property::of_key(k))
                .is_none_or(|p| p.refines());
            if subject.refines && refined {
                assert!(row.measured_text.contains("at dt/4"), "{row:#?}");
            }
            for (r, o) in rows.iter().zip(&right) {
                let expected_to_move =
                    caught(r) || others.iter().any(|q| r.quantity.starts_with(q));
                if o.passed() && !expected_to_move {
                    assert!(r.passed(), "{}: {r:#?}", subject.label);
                }
            }
        }
    }
}

#[test]
fn a_law_with_kt_off_by_1e_4_fails_the_spring_row_of_every_convention() {
    a_law_off_by_1e_4_fails(
        |c| c.contact.kt *= 1.0001,
        "load-unload",
        "F2.(t x n) / (kt l2 phi)",
        &["|Ft| / (mu fn) back by mu fn/kt"],
    );
}

#[test]
fn a_law_with_kn_off_by_1e_4_fails_the_normal_force_row_of_every_convention() {
    // the normal force sets the sliding limit too
    a_law_off_by_1e_4_fails(
        |c| c.contact.kn *= 1.0001,
        "load-unload",
        "fn / (kn delta)",
        &["fn back / (kn delta)", "|Ft| / (mu fn)"],
    );
}

#[test]
fn a_law_with_gamman_off_by_1e_4_fails_the_normal_dashpot_row_of_every_convention() {
    a_law_off_by_1e_4_fails(
        |c| c.contact.gamman *= 1.0001,
        "dashpots",
        "(fn pressing - fn held) / (gamman u)",
        &[],
    );
}

#[test]
fn a_law_with_gammat_off_by_1e_4_fails_the_tangential_dashpot_row_of_every_convention() {
    a_law_off_by_1e_4_fails(
        |c| c.contact.gammat *= 1.0001,
        "dashpots",
        "(Ft spinning - Ft held) / (gammat l2 omega)",
        &[],
    );
}

#[test]
fn a_law_with_mu_off_by_1e_4_fails_the_sliding_row_of_every_convention() {
    a_law_off_by_1e_4_fails(
        |c| c.contact.mu *= 1.0001,
        "coulomb limit",
        "|Ft| / (mu fn) after sliding",
        &["|Ft| / (mu fn)"],
    );
}

/// verdem's own laws pass the dashpots' rows at round-off, far inside their tolerance of 1e-9:
/// the dashpot's part is the difference of two forces of the same spring, of size 1/3 and 1/10
/// of those forces.
#[test]
fn every_convention_measures_its_dashpots_to_round_off() {
    for conv in Tangential::with_constant_kt() {
        let rows = histories(&Subject::own(conv));
        let dashpots: Vec<_> = rows
            .iter()
            .filter(|r| r.case.ends_with("dashpots"))
            .collect();
        assert_eq!(dashpots.len(), 2);
        for r in dashpots {
            let e = (r.measured - r.limit.expected()).abs();
            assert!(e <= 1e-12, "{}: {e:e} {r:#?}", conv.name());
        }
    }
}
