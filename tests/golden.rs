//! Golden snapshots (golden/*.snap, insta): state hashes, diagnostics tables and the first lines
//! of saves of short runs of every case. A change of physics or of bits shows here as a diff.
//! Re-bless on purpose only, with `bash ci/bless.sh`, and say why in the commit message.

mod common;

use common::*;
use verdem::io::mercury;
use verdem::run;
use verdem::step::engine::Overrides;

fn golden(name: &str, how: &str, body: String) {
    insta::with_settings!({
        snapshot_path => root().join("golden"),
        prepend_module_to_snapshot => false,
        description => format!("verdem {}; produced by `bash ci/bless.sh` (tests/golden.rs): {how}", env!("CARGO_PKG_VERSION")),
        omit_expression => true,
    }, {
        insta::assert_snapshot!(name, body);
    });
}

/// Runs `steps` steps with a save every `save_every`, on 1 and 2 threads; both must agree.
fn short_run(
    init: Option<&std::path::Path>,
    steps: u64,
    save_every: u64,
) -> (String, String, String, String, String) {
    let case = quick_case();
    let mut outputs = Vec::new();
    for threads in [1, 2] {
        let dir = tempfile::tempdir().unwrap();
        let mut e = engine(
            &case,
            init,
            Overrides {
                threads: Some(threads),
                ..Overrides::default()
            },
        );
        let s = run_with_saves(e.as_mut(), dir.path(), "g", steps, save_every);
        let last = steps / save_every;
        let head = |ext: &str, n: usize| -> String {
            std::fs::read_to_string(mercury::save_path(dir.path(), "g", ext, last))
                .unwrap()
                .lines()
                .take(n)
                .collect::<Vec<_>>()
                .join("\n")
        };
        let diag = std::fs::read_to_string(run::diagnostics_path(dir.path(), "g")).unwrap();
        outputs.push((
            s.hash,
            diag,
            head("data", 4),
            head("fstat", 9),
            profiles(&dir.path().join("g")),
        ));
    }
    assert_eq!(outputs[0], outputs[1], "1 and 2 threads differ");
    outputs.remove(0)
}

/// Coarse-grained profiles of all saves (20 Heaviside slices, 2 blocks), every number rounded to
/// 6 significant digits.
fn profiles(base: &std::path::Path) -> String {
    let o = verdem::analysis::cg::CgOptions {
        from: Some(0),
        to: None,
        slices: 20,
        kernel: verdem::analysis::cg::KernelChoice::Heaviside,
        width: None,
        walls: 480,
        density: 1.0,
        periodic: [true, true, false],
        blocks: 2,
    };
    let p =
        verdem::analysis::cg::coarse_grain(&verdem::analysis::cg::Series::find(base).unwrap(), &o)
            .unwrap();
    verdem::analysis::cg::csv(&p)
        .lines()
        .map(|l| {
            l.split(',')
                .map(|v| {
                    v.parse::<f64>()
                        .map(|x| format!("{x:.5e}"))
                        .unwrap_or_else(|_| v.to_string())
                })
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn check(tag: &str, init: Option<&std::path::Path>, what: &str) {
    let (steps, every) = (4000, 1000);
    let (hash, diag, data, fstat, cg) = short_run(init, steps, every);
    let how = format!(
        "cases/shear_flow_quick.toml {what}, {steps} steps, a save every {every}, 1 and 2 threads"
    );
    golden(
        &format!("{tag}_hash"),
        &how,
        format!("steps = {steps}\nhash = {hash}\n"),
    );
    golden(&format!("{tag}_diagnostics"), &how, diag);
    golden(&format!("{tag}_data_head"), &how, data);
    golden(&format!("{tag}_fstat_head"), &how, fstat);
    golden(
        &format!("{tag}_profiles"),
        &format!(
            "{how}; `verdem cg` of all saves, 20 Heaviside slices, 2 blocks, rounded to 6 digits"
        ),
        cg,
    );
}

#[test]
fn quick_shear_from_generated_scene() {
    check("generated", None, "from the generated scene (seed 1)");
}

#[test]
fn quick_shear_from_official_file() {
    check(
        "official",
        Some(&data("GranularShearFlow.data")),
        "--init GranularShearFlow.data",
    );
}

#[test]
fn quick_shear_from_developed_state() {
    check(
        "developed",
        Some(&data("states/mercury_t143.85.data")),
        "--init states/mercury_t143.85.data",
    );
}
