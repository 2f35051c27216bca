//! Criterion benchmarks: the pair-force kernel (with MercuryDPM's friction, and the frictionless
//! law a `mu = 0` case runs), the pair-list rebuild, one full time step of
//! MercuryDPM's developed shear state (1 and 2 threads), the team's barrier (the fixed cost of
//! synchronising two threads, paid twice a step), the coarse-graining of one save, and the
//! writer's scan of a save's text for non-finite numbers against making that text.
//! Reads `data/states/mercury_t143.85.data`. Run: `cargo bench`.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use verdem::analysis::cg::fields::{raw_fields, Grid};
use verdem::analysis::cg::kernel::Kernel;
use verdem::case::Case;
use verdem::contact::{
    ContactLaw, Frictionless, FrictionlessLaw, LinearSpringDashpot, MercuryLaw,
    MercurySlidingFriction, PairInput,
};
use verdem::step::engine::{self, Overrides};
use verdem::step::Engine;
use verdem::Vec3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn developed(threads: usize) -> (Case, Box<dyn Engine>) {
    let case = Case::load(&root().join("cases/shear_flow_quick.toml")).unwrap();
    let init = root().join("data/states/mercury_t143.85.data");
    let scene = verdem::scene::build(&case, Some(&init)).unwrap();
    let mut e = engine::build(
        &case,
        scene,
        &Overrides {
            threads: Some(threads),
            ..Overrides::default()
        },
    )
    .unwrap();
    e.advance(1).unwrap();
    (case, e)
}

fn pair_kernel(c: &mut Criterion) {
    let law: MercuryLaw = verdem::contact::Composed {
        normal: LinearSpringDashpot {
            kn: 2e5,
            gamman: 15.0,
        },
        tangential: MercurySlidingFriction::new(2e5 * 2.0 / 7.0, 15.0 * 2.0 / 7.0, 0.3),
    };
    let input = PairInput {
        r: Vec3::new(0.1, 0.2, 0.97),
        rad_p: 0.5,
        rad_i: 0.5,
        inv_mass_p: 1.0 / std::f64::consts::FRAC_PI_6,
        inv_mass_i: 1.0 / std::f64::consts::FRAC_PI_6,
        v_p: Vec3::new(0.3, -0.1, -0.2),
        v_i: Vec3::new(-0.1, 0.0, 0.1),
        w_p: Vec3::new(1.0, 0.5, -0.2),
        w_i: Vec3::new(0.0, -0.3, 0.4),
    };
    c.bench_function("pair force (kinematics + MercuryDPM law)", |b| {
        let mut xi = Vec3::new(1e-5, -2e-5, 0.0);
        b.iter(|| {
            let k = black_box(&input).kinematics().unwrap();
            black_box(law.evaluate(&k, &mut xi, 7.192545031528827e-05))
        })
    });
    let frictionless: FrictionlessLaw = verdem::contact::Composed {
        normal: law.normal,
        tangential: Frictionless,
    };
    c.bench_function("pair force (kinematics + frictionless law, mu = 0)", |b| {
        let mut xi = Vec3::zeros();
        b.iter(|| {
            let k = black_box(&input).kinematics().unwrap();
            black_box(frictionless.evaluate(&k, &mut xi, 7.192545031528827e-05))
        })
    });
}

fn rebuild(c: &mut Criterion) {
    let (_, mut e) = developed(1);
    c.bench_function("pair-list rebuild, developed state", |b| {
        b.iter(|| e.rebuild())
    });
}

fn step(c: &mut Criterion) {
    for threads in [1, 2] {
        let (_, mut e) = developed(threads);
        c.bench_function(
            &format!("1000 steps, developed state, {threads} thread(s)"),
            |b| b.iter(|| e.advance(1000)),
        );
    }
}

fn barrier(c: &mut Criterion) {
    c.bench_function("barrier, 2 threads (one round)", |b| {
        b.iter_custom(|rounds| {
            let barrier = verdem::step::team::SpinBarrier::new(2);
            std::thread::scope(|s| {
                s.spawn(|| (0..rounds).for_each(|_| barrier.wait()));
                // both threads are in the loop before the clock starts
                barrier.wait();
                let t0 = std::time::Instant::now();
                (1..rounds).for_each(|_| barrier.wait());
                t0.elapsed()
            })
        })
    });
}

fn coarse_grain(c: &mut Criterion) {
    let (_, e) = developed(1);
    let snap = e.snapshot();
    let dir = tempfile::tempdir().unwrap();
    let (dp, fp) = (dir.path().join("b.data"), dir.path().join("b.fstat"));
    std::fs::write(&dp, verdem::io::mercury::data_text(&snap)).unwrap();
    std::fs::write(&fp, verdem::io::mercury::fstat_text(&snap)).unwrap();
    let data = verdem::io::mercury::read_data(&dp).unwrap();
    let fstat = verdem::io::mercury::read_fstat(&fp).unwrap();
    let grid = Grid {
        z0: 0.0,
        z1: 22.0,
        n: 100,
    };
    c.bench_function("coarse-graining of one save (100 slices)", |b| {
        b.iter(|| {
            black_box(raw_fields(
                &data,
                &fstat,
                &|i| i < 480,
                &snap.domain,
                &grid,
                Kernel::Heaviside { h: 0.22 },
                1.0,
            ))
        })
    });
}

fn save_text(c: &mut Criterion) {
    let (_, e) = developed(1);
    let snap = e.snapshot();
    let text = verdem::io::mercury::data_text(&snap);
    c.bench_function("a save's .data text made", |b| {
        b.iter(|| black_box(verdem::io::mercury::data_text(&snap)))
    });
    c.bench_function("a save's .data text scanned for non-finite numbers", |b| {
        b.iter(|| black_box(verdem::io::atomic::non_finite(text.as_bytes())))
    });
}

criterion_group! {
    name = benches;
    // no HTML plots: they would need a font registered with plotters
    config = Criterion::default().without_plots();
    targets = pair_kernel, rebuild, step, barrier, coarse_grain, save_text
}
criterion_main!(benches);
