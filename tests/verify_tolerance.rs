//! The verification tolerances catch a small error in the law: a law whose kn, γn or μ is off
//! by 0.1 %, judged against the answers of the case's own values, fails the rows that test
//! that parameter, while the case itself passes them.

mod common;

use verdem::case::Case;
use verdem::verify::Row;

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

impl verdem::verify::driver::MotionDriver for Wrong {
    fn drive(
        &self,
        case: &Case,
        motion: &[verdem::verify::kinematics::MotionRow],
    ) -> anyhow::Result<Vec<verdem::verify::kinematics::ForceRow>> {
        let mut wrong = case.clone();
        (self.0)(&mut wrong);
        verdem::verify::driver::OWN.drive(&wrong, motion)
    }
    fn name(&self) -> String {
        "wrong".into()
    }
}

/// The tangential-history rows of every convention's law, driven by `driver`.
fn histories(driver: &dyn verdem::verify::driver::MotionDriver) -> Vec<Row> {
    let base =
        Case::load_for_prescribed_motion(&common::root().join("cases/verify/objectivity.toml"))
            .unwrap();
    let mut rows = Vec::new();
    for conv in verdem::contact::Tangential::with_constant_kt() {
        let subject = verdem::verify::Subject::own(conv).driven_by(driver);
        for label in verdem::verify::histories::HISTORIES {
            rows.extend(verdem::verify::histories::history_rows(&base, &subject, label).unwrap());
        }
    }
    rows
}

#[test]
fn a_law_with_kt_kn_or_mu_off_by_1e_4_fails_a_history_row_of_every_convention() {
    // every gating row passes with the case's own values (the peers' known defects aside)
    let right = histories(&verdem::verify::driver::OWN);
    assert!(right.iter().all(|r| r.passed() || !r.gate), "{right:#?}");
    for (parameter, change) in [
        (
            "kt",
            (|c: &mut Case| c.contact.kt *= 1.0001) as fn(&mut Case),
        ),
        ("kn", |c: &mut Case| c.contact.kn *= 1.0001),
        ("mu", |c: &mut Case| c.contact.mu *= 1.0001),
    ] {
        let rows = histories(&Wrong(change));
        assert_eq!(rows.len(), right.len());
        for conv in verdem::contact::Tangential::with_constant_kt() {
            let label = format!("tangential {} ", conv.name());
            let failed: Vec<_> = rows
                .iter()
                .zip(&right)
                .filter(|(r, o)| r.case.starts_with(&label) && o.passed() && !r.passed())
                .collect();
            assert!(!failed.is_empty(), "{parameter} {}: {rows:#?}", conv.name());
        }
    }
}
