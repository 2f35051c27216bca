//! Verification cases with analytical or published answers, run through the same contact laws
//! and solver as the benchmark: a table of expected against measured values with tolerances.
//!
//! - [`collision`]: binary normal collisions against the closed forms (clipped and not);
//! - [`oblique`]: oblique impacts, the sticking and sliding regimes of the linear spring and
//!   Coulomb slider (Walton; Chung & Ooi 2011), per tangential convention;
//! - [`objectivity`]: a loaded contact rotated rigidly, per convention;
//! - [`ratchet`]: closed cycles of relative motion below the sliding limit (McNamara et al.
//!   2008), per convention;
//! - [`histories`]: the tangential spring loaded and unloaded, taken to the Coulomb limit and
//!   back, and reset when the contact opens, per convention;
//! - [`conservation`]: energy and momentum of a periodic gas, angular momentum of a cluster;
//! - [`mindlin_loop`]: Mindlin–Deresiewicz's hysteresis loop at constant normal load, per
//!   Mindlin convention, against its closed form ([`mindlin`]);
//! - [`mindlin_histories`]: held tangential displacement under a changing overlap, closed cycles
//!   of normal and tangential load (net work), rigid rotations, per Mindlin convention.
//!
//! Each prescribed-motion row declares the property of a contact law it tests
//! ([`diagnosis::Property`]): the summary after the table maps the failed rows to them.

//! - [`hertz_impact`]: Hertz head-on impacts against Johnson's closed forms, and the
//!   restitution of the dampings set from one.
//!
//! The table is a list of named [`Entry`]s, selected by name before any of them runs. The
//! prescribed-motion cases (objectivity, ratchet, histories) drive their contact through a
//! [`driver::MotionDriver`]: verdem's own law, or an external program ([`code_entries`]).

pub mod collision;
pub mod conservation;
pub mod diagnosis;
pub mod driver;
pub mod extremes;
pub mod hertz_impact;
pub mod histories;
pub mod kinematics;
pub mod mcnamara;
pub mod mindlin;
pub mod mindlin_histories;
pub mod mindlin_loop;
pub mod objectivity;
pub mod oblique;
pub mod ratchet;
pub mod refinement;
pub mod walls;

use std::path::Path;

use crate::analysis::verdict::Outcome;
use crate::analysis::{Limit, Verdict};
use crate::case::{Case, COARSE_STEPS_PER_COLLISION};
use crate::contact::registry::Properties;
use crate::contact::Tangential;
pub use collision::{binary_collisions, closed_form, collide, ClosedForm, Measured};
use driver::{MotionDriver, OWN};

/// One line of the verification table: a case's quantity judged against its expected value
/// with a relative ([`row`]) or absolute ([`row_abs`]) tolerance.
pub type Row = Verdict;

/// A row judged by the relative error |measured − expected|/|expected|.
pub fn row(case: &str, quantity: &str, expected: f64, measured: f64, tolerance: f64) -> Row {
    Verdict::judge(
        case,
        quantity,
        measured,
        Limit::Relative {
            expected,
            tolerance,
        },
    )
}

/// A row judged by the absolute error |measured − expected|.
pub fn row_abs(case: &str, quantity: &str, expected: f64, measured: f64, tolerance: f64) -> Row {
    Verdict::judge(
        case,
        quantity,
        measured,
        Limit::Absolute {
            expected,
            tolerance,
        },
    )
}

/// A row saying that a case could not be measured: `error` in words, failing and gating.
pub fn error_row(case: &str, error: &anyhow::Error) -> Row {
    Verdict::judge(case, "could not be measured", f64::NAN, Limit::None)
        .described(format!("{error:#}"), String::new())
}

/// A row saying that a case was not run because a peer lacks what it needs (`why`, in words:
/// `toy: it has no two-sphere collision run`): not judged (`info`), gating nothing.
pub fn lacking_row(case: &str, why: &str) -> Row {
    Verdict::reported(case, "not run: the peer lacks it", f64::NAN, Limit::None)
        .described(why.into(), String::new())
}

/// Whether `r` is a [`lacking_row`].
pub fn is_lacking(r: &Row) -> bool {
    r.limit == Limit::None && r.outcome == Outcome::Reported && r.measured.is_nan()
}

/// Whether `r` is an [`error_row`].
pub fn is_error(r: &Row) -> bool {
    r.limit == Limit::None && r.outcome == Outcome::Fail
}

/// Who drives a prescribed-motion case and what it is held to.
pub struct Subject<'a> {
    /// Its name in the case column: a convention's name, or `code:NAME` for a program.
    pub label: String,
    /// The tangential convention written into the case it drives.
    pub tangential: Tangential,
    /// What it promises: the rows of the promises it does not make are documentation.
    pub properties: Properties,
    /// The convention it claims to implement: where verdem's law of that convention misses a
    /// row's expected value (a documented defect), the subject is held to verdem's number
    /// instead, with the same tolerance.
    pub gated_as: Option<Tangential>,
    /// The convention whose lever arms and slip the rows' expected values use, where they
    /// differ between conventions: verdem's own law's, or the one a program claims; none for a
    /// program that claims none (those rows then allow the spread between conventions).
    pub declared: Option<Tangential>,
    /// Whether a row it fails at the motion's step is judged again at finer steps
    /// ([`refinement`]): for a program, whose time discretisation is its own.
    pub refines: bool,
    pub driver: &'a dyn MotionDriver,
}

impl Subject<'static> {
    /// verdem's own law in the convention `conv`, held to the promises of its properties.
    pub fn own(conv: Tangential) -> Subject<'static> {
        Subject {
            label: conv.name().into(),
            tangential: conv,
            properties: conv.properties(),
            gated_as: None,
            declared: Some(conv),
            refines: false,
            driver: &OWN,
        }
    }
}

impl<'a> Subject<'a> {
    /// An external program behind `driver`. Claiming the convention `claim`, it runs the
    /// case with `tangential = claim` and is held to verdem's numbers of that convention on
    /// the rows that convention fails; claiming none, it runs the objective convention and
    /// every row gates against its expected value (the promises of an objective law).
    pub fn code(driver: &'a dyn MotionDriver, claim: Option<Tangential>) -> Subject<'a> {
        Subject {
            label: format!("code:{}", driver.name()),
            tangential: claim.unwrap_or(Tangential::Objective),
            properties: claim.unwrap_or(Tangential::Objective).properties(),
            gated_as: claim,
            declared: claim,
            refines: true,
            driver,
        }
    }

    /// The same subject driven through `driver`.
    pub fn driven_by<'b>(&self, driver: &'b dyn MotionDriver) -> Subject<'b> {
        Subject {
            label: self.label.clone(),
            tangential: self.tangential,
            properties: self.properties,
            gated_as: self.gated_as,
            declared: self.declared,
            refines: self.refines,
            driver,
        }
    }

    /// `base` with this subject's tangential convention.
    pub fn case(&self, base: &Case) -> Case {
        let mut case = base.clone();
        case.contact.tangential = self.tangential.into();
        case
    }
}

/// A case that drives one contact through a prescribed motion, in several variants (axes,
/// rotations, histories).
#[derive(Clone, Copy)]
pub struct MotionCase {
    /// Its case file in the verification folder.
    pub file: &'static str,
    /// Its variants' names.
    pub variants: &'static [&'static str],
    /// The name of a variant's case for a subject's label.
    pub name: fn(&str, &str) -> String,
    /// The rows of a variant for a subject.
    pub rows: fn(&Case, &Subject, &str) -> anyhow::Result<Vec<Row>>,
}

/// Every prescribed-motion case, in the table's order.
pub const MOTION_CASES: [MotionCase; 4] = [
    MotionCase {
        file: "objectivity.toml",
        variants: &objectivity::AXES,
        name: objectivity::case_name,
        rows: objectivity::axis_rows,
    },
    MotionCase {
        file: "objectivity.toml",
        variants: &ratchet::ROTATIONS,
        name: ratchet::case_name,
        rows: ratchet::rotation_rows,
    },
    MotionCase {
        file: "objectivity.toml",
        variants: &histories::HISTORIES,
        name: histories::case_name,
        rows: histories::history_rows,
    },
    MotionCase {
        file: "objectivity.toml",
        variants: &mcnamara::CYCLES,
        name: mcnamara::case_name,
        rows: mcnamara::cycle_rows,
    },
];

impl MotionCase {
    /// The rows of `variant` for `subject`, every one gating; a subject gated as a convention
    /// is held to verdem's number of that convention where that convention misses the
    /// expected value (the quantity then ends in `= verdem NAME`). For a subject that
    /// [`Subject::refines`], the rows it fails at the motion's step are judged again by
    /// [`refinement`] (the same motion at dt/2 and dt/4, verdem's numbers too), but for
    /// the rows of a property without a discretisation to choose
    /// ([`diagnosis::Property::refines`]).
    pub fn judge(&self, dir: &Path, subject: &Subject, variant: &str) -> anyhow::Result<Vec<Row>> {
        let base = Case::load_for_prescribed_motion(&dir.join(self.file))?;
        let rows = self.judge_at(&base, subject, variant, 1)?;
        let refine = |r: &Row| {
            r.gate
                && r.failed()
                && !is_error(r)
                && diagnosis::property(r).is_none_or(diagnosis::Property::refines)
        };
        if !subject.refines || !rows.iter().any(refine) {
            return Ok(rows);
        }
        let [_, half, quarter] = refinement::FINE;
        let half = self.judge_at(&base, subject, variant, half)?;
        let quarter = self.judge_at(&base, subject, variant, quarter)?;
        let mut judged = Vec::with_capacity(rows.len());
        // the same quantity, whether or not verdem's number stands in for the expected value
        // at that step (` = verdem NAME`)
        let base = |r: &Row| {
            r.quantity
                .split(" = verdem ")
                .next()
                .unwrap_or("")
                .to_string()
        };
        for ((r, h), q) in rows.into_iter().zip(&half).zip(&quarter) {
            anyhow::ensure!(
                base(h) == base(&r) && base(q) == base(&r),
                "{}: the refined motions gave other rows ({:?}, {:?}) than the motion ({:?})",
                r.case,
                h.quantity,
                q.quantity,
                r.quantity
            );
            judged.push(if refine(&r) {
                refinement::judged_by_refinement(r, h, q)
            } else {
                r
            });
        }
        Ok(judged)
    }

    /// The rows of `variant` for `subject` with the motion driven at `fine` rows per row.
    fn judge_at(
        &self,
        base: &Case,
        subject: &Subject,
        variant: &str,
        fine: usize,
    ) -> anyhow::Result<Vec<Row>> {
        let refined = driver::Refined {
            inner: subject.driver,
            fine,
        };
        let mut rows = (self.rows)(base, &subject.driven_by(&refined), variant)?;
        if let Some(conv) = subject.gated_as {
            let own_refined = driver::Refined { inner: &OWN, fine };
            let own = Subject::own(conv);
            let own = (self.rows)(base, &own.driven_by(&own_refined), variant)?;
            for (r, o) in rows.iter_mut().zip(&own) {
                *r = if o.passed() {
                    Verdict {
                        gate: true,
                        ..r.clone()
                    }
                } else {
                    let limit = match o.limit {
                        Limit::Relative { tolerance, .. } => Limit::Relative {
                            expected: o.measured,
                            tolerance,
                        },
                        Limit::Absolute { tolerance, .. } => Limit::Absolute {
                            expected: o.measured,
                            tolerance,
                        },
                        other => other,
                    };
                    let quantity = format!("{} = verdem {}", r.quantity, conv.name());
                    Verdict {
                        property: r.property,
                        ..Verdict::judge(&r.case, &quantity, r.measured, limit)
                    }
                };
            }
        }
        Ok(rows)
    }
}

/// One case of the verification table (or a group of cases run together), run only when
/// selected.
pub struct Entry<'a> {
    /// The names of the cases its rows belong to, or their beginnings.
    pub names: Vec<String>,
    run: Box<dyn Fn() -> anyhow::Result<Vec<Row>> + 'a>,
}

impl<'a> Entry<'a> {
    /// An entry named `names` whose rows `run` measures.
    pub fn new<S: ToString>(
        names: impl IntoIterator<Item = S>,
        run: impl Fn() -> anyhow::Result<Vec<Row>> + 'a,
    ) -> Entry<'a> {
        Entry {
            names: names.into_iter().map(|n| n.to_string()).collect(),
            run: Box::new(run),
        }
    }

    /// Whether `only` selects it: one of its names contains `only`, or `only` begins with one
    /// of them (`free-wall v0=1` selects the entry `free-wall`).
    pub fn selected(&self, only: &str) -> bool {
        self.names
            .iter()
            .any(|n| n.contains(only) || only.starts_with(n.as_str()))
    }

    /// Measures its rows.
    pub fn run(&self) -> anyhow::Result<Vec<Row>> {
        (self.run)()
    }
}

/// Every verification case of the folder `dir` (cases/verify), in the table's order, none
/// run yet.
pub fn entries(dir: &Path) -> Vec<Entry<'_>> {
    let load = move |name: &str| Case::load(&dir.join(name));
    // the beginnings of the rows' case names, per convention where a case has one
    let per_convention = |kinds: &[&str]| -> Vec<String> {
        let each = Tangential::with_constant_kt().map(|c| c.name());
        each.flat_map(|c| kinds.iter().map(move |k| format!("{k} {c}")))
            .collect()
    };
    let mut list = vec![
        Entry::new(["free-free", "free-wall"], move || {
            binary_collisions(&load("binary_collision.toml")?)
        }),
        Entry::new(per_convention(&["oblique", "opposite spins"]), move || {
            oblique::rows(&load("oblique_impact.toml")?)
        }),
        Entry::new(["plane"], move || walls::rows(&load("wall_impact.toml")?)),
    ];
    for case in MOTION_CASES {
        for conv in Tangential::with_constant_kt() {
            for &variant in case.variants {
                list.push(Entry::new([(case.name)(conv.name(), variant)], move || {
                    case.judge(dir, &Subject::own(conv), variant)
                }));
            }
        }
    }
    let conservation = ["conservation gas".to_string()].into_iter();
    let clusters = per_convention(&["conservation cluster"]);
    list.push(Entry::new(conservation.chain(clusters), move || {
        conservation::rows(&load("conservation.toml")?, 1_000_000)
    }));
    let loops = Tangential::with_mindlin_stiffness()
        .flat_map(|c| mindlin_loop::pairs().map(move |(p, _)| mindlin_loop::case_name(c, p)));
    list.push(Entry::new(loops, || Ok(mindlin_loop::rows())));
    let histories = Tangential::with_mindlin_stiffness().flat_map(|c| {
        mindlin_histories::HISTORIES.map(move |h| mindlin_histories::case_name(c, h))
    });
    list.push(Entry::new(histories, || Ok(mindlin_histories::rows())));

    list.push(Entry::new(
        ["hertz", "hertz-restitution", "hertz-tsuji"],
        move || hertz_impact::rows(&load("hertz_impact.toml")?),
    ));
    list
}

/// The prescribed-motion cases of the folder `dir` driven by the program `subject`: a case
/// the program fails (does not start, exits non-zero, writes a malformed forces file) gives
/// one [`error_row`] instead of its rows.
pub fn code_entries<'a>(dir: &'a Path, subject: &'a Subject<'a>) -> Vec<Entry<'a>> {
    let mut list = Vec::new();
    for case in MOTION_CASES {
        for &variant in case.variants {
            let name = (case.name)(&subject.label, variant);
            list.push(Entry::new([name.clone()], move || {
                Ok(case
                    .judge(dir, subject, variant)
                    .unwrap_or_else(|e| vec![error_row(&name, &e)]))
            }));
        }
    }
    list
}

/// A warning for each prescribed-motion case of the folder `dir` whose motions are coarse for
/// its law: every motion steps by the case's time step, so its rows are `run.dt` apart, and
/// they are coarse when [`kinematics::coarse`] for the law's [`kinematics::collision_time`].
/// A case that does not load gives none (its rows say why); each file is named once.
pub fn coarse_motion_warnings(dir: &Path) -> Vec<String> {
    let mut files: Vec<&str> = Vec::new();
    for case in MOTION_CASES {
        if !files.contains(&case.file) {
            files.push(case.file);
        }
    }
    let mut warnings = Vec::new();
    for file in files {
        let path = dir.join(file);
        let Ok(case) = Case::load_for_prescribed_motion(&path) else {
            continue;
        };
        let dt = case.dt();
        let Some(tc) = kinematics::collision_time(&case).filter(|&tc| kinematics::coarse(dt, tc))
        else {
            continue;
        };
        let field = if case.run.dt.is_some() {
            "run.dt"
        } else {
            "run.steps_per_collision"
        };
        warnings.push(format!(
            "{}: {field}: the prescribed motions' rows, dt = {dt:.4e} apart, are coarse for this \
             law's collision time tc = {tc:.4e} (tc/dt = {:.3}, below \
             {COARSE_STEPS_PER_COLLISION}): the forces are the law's at these rows, not an \
             integration's, and the collision's course between them is not seen; run.dt <= \
             {:.4e} (tc/{COARSE_STEPS_PER_COLLISION}) or run.steps_per_collision >= \
             {COARSE_STEPS_PER_COLLISION} resolves it",
            path.display(),
            tc / dt,
            tc / COARSE_STEPS_PER_COLLISION
        ));
    }
    warnings
}

/// The entries `only` selects (all of them without it); an error listing every name when it
/// selects none.
pub fn select<'a>(entries: Vec<Entry<'a>>, only: Option<&str>) -> anyhow::Result<Vec<Entry<'a>>> {
    let Some(only) = only else {
        return Ok(entries);
    };
    let names: Vec<String> = entries.iter().flat_map(|e| e.names.clone()).collect();
    let chosen: Vec<Entry> = entries.into_iter().filter(|e| e.selected(only)).collect();
    if chosen.is_empty() {
        anyhow::bail!(
            "--only {only:?}: no verification row's case contains it; the cases are:\n  {}",
            names.join("\n  ")
        );
    }
    Ok(chosen)
}

/// The rows of `entries`, in order.
pub fn run(entries: &[Entry]) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for e in entries {
        rows.extend(e.run()?);
    }
    Ok(rows)
}

/// Every verification case of the folder `dir` (cases/verify): the table `verdem verify`
/// prints.
pub fn all(dir: &Path) -> anyhow::Result<Vec<Row>> {
    run(&entries(dir))
}

/// Rows that gate and failed.
pub use crate::analysis::verdict::failures;

/// The table as text; tolerances marked `abs` are absolute, the others relative. A failed row
/// that documents a peer convention's known defect reads `FAIL*`; an [`error_row`] and a
/// [`lacking_row`] have no numbers, their words on the lines below.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<56} {:<48} {:>13} {:>13} {:>13}  result\n",
        "case", "quantity", "expected", "measured", "tolerance"
    );
    for r in rows {
        if is_error(r) || is_lacking(r) {
            s.push_str(&format!(
                "{:<56} {:<48} {:>55}  {}\n",
                r.case,
                r.quantity,
                "",
                result(r)
            ));
            for line in r.measured_text.lines() {
                s.push_str(&format!("    {line}\n"));
            }
            continue;
        }
        let tol = match r.limit {
            Limit::Relative { tolerance, .. } => format!("{tolerance:.1e} rel"),
            Limit::Absolute { tolerance, .. } => format!("{tolerance:.1e} abs"),
            _ => String::new(),
        };
        s.push_str(&format!(
            "{:<56} {:<48} {:>13.6e} {:>13.6e} {:>13}  {}\n",
            r.case,
            r.quantity,
            r.limit.expected(),
            r.measured,
            tol,
            result(r)
        ));
        // a row judged by refinement: its measurements at the finer steps and their order
        if !r.measured_text.is_empty() {
            s.push_str(&format!("    {}\n", r.measured_text));
        }
    }
    s
}

/// The table's word for `r`: `PASS`, `FAIL`, `FAIL*` (a failure that documents a peer
/// convention's known defect), `ERROR` ([`is_error`]) or `info` (not judged).
pub fn result(r: &Row) -> &'static str {
    match (is_error(r), r.pass(), r.gate) {
        (true, _, _) => "ERROR",
        (false, Some(true), _) => "PASS",
        (false, Some(false), true) => "FAIL",
        (false, Some(false), false) => "FAIL*",
        (false, None, _) => "info",
    }
}
