//! The solver against MercuryDPM's reference output, and the equivalences its design promises.

mod common;

use common::*;
use verdem::case::Search;
use verdem::io::mercury;
use verdem::step::engine::Overrides;

/// MercuryDPM's save 1 of the benchmark (t = 3.596, 50000 steps from its save 0) holds one
/// contact, 948–1334, written to 10 significant digits. verdem started from the same save 0
/// must reproduce it to round-off growth: a wrong lever arm, tangential update, damping or dt
/// shows at the 1e-4 level (the size of LAMMPS' convention difference).
#[test]
fn reproduces_mercurydpm_contact_at_save_1() {
    let case = quick_case();
    let mut e = engine(
        &case,
        Some(&data("outputs_example/Mercury_out.data.0000")),
        Overrides::default(),
    );
    e.advance(50_000).unwrap();
    let snap = e.snapshot();
    assert!((snap.time - 3.596272516).abs() < 1e-9, "time {}", snap.time);
    let dir = tempfile::tempdir().unwrap();
    let ours = dir.path().join("ours.fstat");
    std::fs::write(&ours, mercury::fstat_text(&snap)).unwrap();
    let ours = mercury::read_fstat(&ours).unwrap();
    let theirs = mercury::read_fstat(&data("outputs_example/Mercury_out.fstat.0001")).unwrap();
    assert_eq!(ours.rows.len(), theirs.rows.len(), "contact count");
    for (a, b) in ours.rows.iter().zip(&theirs.rows) {
        assert_eq!((a.i, a.j), (b.i, b.j));
        let close = |x: f64, y: f64, what: &str| {
            assert!(
                (x - y).abs() <= 2e-9 * y.abs().max(1e-3),
                "{what}: verdem {x} MercuryDPM {y}"
            );
        };
        close(a.delta, b.delta, "delta");
        close(a.deltat, b.deltat, "deltat");
        close(a.fn_signed, b.fn_signed, "fn");
        close(a.ft, b.ft, "ft");
        for k in 0..3 {
            close(a.c[k], b.c[k], "contact point");
            close(a.n[k], b.n[k], "normal");
            close(a.t[k], b.t[k], "tangent");
        }
    }
}

/// The cell grid with a skin finds exactly what an all-pairs search finds: identical bits.
#[test]
fn cell_list_gives_the_same_trajectory_as_all_pairs() {
    let case = quick_case();
    let state = data("states/mercury_t143.85.data");
    let mut cells = engine(&case, Some(&state), Overrides::default());
    let mut all = {
        let mut c = case.clone();
        c.neighbor.search = Search::AllPairs;
        engine(&c, Some(&state), Overrides::default())
    };
    let a = hash_after(cells.as_mut(), 3000);
    let b = hash_after(all.as_mut(), 3000);
    assert!(cells.contact_count() > 0, "a contact-rich state");
    assert_eq!(a, b);
}

/// Deterministic mode: the same bits for 1, 2 and 3 threads, bound to CPUs or not, any skin and
/// any cell size, over 20000 steps of the developed, contact-rich state.
#[test]
fn threads_skin_and_cell_size_do_not_change_a_bit() {
    let case = quick_case();
    let state = data("states/mercury_t143.85.data");
    let run = |threads, bind, skin, cell| {
        let mut e = engine(
            &case,
            Some(&state),
            Overrides {
                threads: Some(threads),
                bind: Some(bind),
                skin: Some(skin),
                cell: Some(cell),
            },
        );
        hash_after(e.as_mut(), 20_000)
    };
    let reference = run(1, true, 0.1, 0.0);
    assert_eq!(run(2, true, 0.1, 0.0), reference, "2 threads");
    assert_eq!(run(2, false, 0.1, 0.0), reference, "2 threads, not bound");
    // more threads than cores: chunks of every pass and phase change hands
    assert_eq!(run(3, true, 0.1, 0.0), reference, "3 threads");
    assert_eq!(run(2, true, 0.35, 0.0), reference, "skin 0.35");
    assert_eq!(run(2, true, 0.05, 2.7), reference, "skin 0.05, cell 2.7");
}

/// Runs coupled by a lockstep barrier (`verdem bench`'s ceiling row of runs that meet once a
/// step) wait on it once a step, in every call, and keep the bits of a run alone.
#[test]
fn runs_in_lockstep_meet_once_a_step_and_keep_the_bits() {
    let case = quick_case();
    let state = data("states/mercury_t143.85.data");
    let reference = hash_after(
        engine(&case, Some(&state), Overrides::default()).as_mut(),
        700,
    );
    let barrier = std::sync::Arc::new(verdem::step::team::SpinBarrier::new(2));
    let hashes: Vec<String> = std::thread::scope(|s| {
        let runs: Vec<_> = (0..2)
            .map(|_| {
                let barrier = barrier.clone();
                let (case, state) = (&case, &state);
                s.spawn(move || {
                    let mut e = engine(case, Some(state), Overrides::default());
                    e.params_mut().meet = Some(std::sync::Arc::new(move || barrier.wait()));
                    // several calls, each a run of its own (the first with a rebuild)
                    e.advance(300).unwrap();
                    hash_after(e.as_mut(), 400)
                })
            })
            .collect();
        runs.into_iter().map(|r| r.join().unwrap()).collect()
    });
    assert_eq!(barrier.rounds(), 700);
    assert_eq!(hashes, [reference.clone(), reference]);
}

/// The hash sees every bit: one ulp in one velocity changes it.
#[test]
fn one_ulp_in_one_velocity_changes_the_hash() {
    let case = quick_case();
    let e = engine(
        &case,
        Some(&data("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    let mut snap = e.snapshot();
    let before = verdem::io::hash::state_hash(&snap);
    snap.particles.v[2000].y = f64::from_bits(snap.particles.v[2000].y.to_bits() + 1);
    assert_ne!(verdem::io::hash::state_hash(&snap), before);
}

/// The hash sees a change of summation order: the contact forces of the developed state summed
/// in reverse order give other bits, and a particle kicked from rest with the two sums gives
/// states that hash differently.
#[test]
fn reordered_force_summation_changes_the_hash() {
    let case = quick_case();
    let mut e = engine(
        &case,
        Some(&data("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    e.advance(100).unwrap();
    let snap = e.snapshot();
    let terms: Vec<_> = snap.contacts.iter().map(|c| c.force.f).collect();
    assert!(terms.len() >= 3);
    let forward = terms.iter().fold(verdem::Vec3::zeros(), |s, f| s + f);
    let backward = terms.iter().rev().fold(verdem::Vec3::zeros(), |s, f| s + f);
    assert_ne!(forward, backward, "these sums depend on the order");
    let a = 2000;
    let kick = |f: verdem::Vec3| {
        let mut s = snap.clone();
        // a particle starting from rest: its velocity is the kick alone
        s.particles.v[a] = f * s.particles.inv_mass[a] * 0.5 * e.params().dt;
        verdem::io::hash::state_hash(&s)
    };
    assert_ne!(kick(forward), kick(backward));
}

/// A team larger than the CPUs the process may use is warned about (it waits at every barrier
/// for threads that are not running) and still gives the bits of one thread.
#[test]
fn a_team_larger_than_its_cpus_is_warned_about_and_keeps_the_bits() {
    let state = data("states/mercury_t143.85.data");
    let case = root().join("cases/shear_flow_quick.toml");
    let cpu = verdem::step::team::allowed_cpus()
        .first()
        .expect("sched_getaffinity")
        .to_string();
    let hash_on_one_cpu = |threads: &str| {
        let out = std::process::Command::new("taskset")
            .args(["-c", &cpu, env!("CARGO_BIN_EXE_verdem"), "hash"])
            .args(["--steps", "50"])
            .args(["--threads", threads, "--init"])
            .args([&state, &case])
            .output()
            .expect("taskset (util-linux) runs");
        assert!(out.status.success(), "{out:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        (String::from_utf8(out.stdout).unwrap(), err)
    };
    let (one, quiet) = hash_on_one_cpu("1");
    let (two, warned) = hash_on_one_cpu("2");
    assert!(!quiet.contains("warning"), "{quiet}");
    assert!(
        warned.contains("warning: 2 threads, but this process may run on 1 CPU(s)"),
        "{warned}"
    );
    assert_eq!(one, two);
}
