//! `verdem bench --scale`: tiny sweeps over two sizes (the cell and its 2 × 2 tiling) write the
//! csv with its columns per size and configuration, the memory of each code's run and the cost
//! plot. Rates are not judged here (no timings in tests).

mod common;

use std::ffi::OsStr;
use std::path::Path;

/// Runs a sweep of sizes 1 and 2 of 139200 particle-steps per run (40 and 10 steps) into
/// `out` with the extra arguments `extra`; returns the csv's records as maps of column to field.
fn sweep(out: &Path, extra: &[&str]) -> Vec<std::collections::HashMap<String, String>> {
    let mut args: Vec<&OsStr> = [
        "bench",
        "--scale",
        "1,2",
        "--particle-steps",
        "139200",
        "--rounds",
        "1",
        "--no-ceiling",
    ]
    .iter()
    .chain(extra)
    .map(OsStr::new)
    .collect();
    args.extend([OsStr::new("--out"), out.as_os_str()]);
    let printed = common::verdem_ok(args);
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert_eq!(md, String::from_utf8_lossy(&printed.stdout));
    assert!(
        md.contains("1×1: 3480 particles, 40 steps; 2×2: 13920 particles, 10 steps"),
        "{md}"
    );
    assert!(md.contains("## 13920 particles, 10 steps"), "{md}");
    let png = png::Decoder::new(std::fs::File::open(out.join("bench.png")).unwrap());
    assert!(png.read_info().unwrap().info().width > 0);
    for n in ["1x1", "2x2"] {
        assert!(out
            .join(n)
            .join(format!("shear_flow_quick_{n}.toml"))
            .exists());
    }
    let mut r = csv::Reader::from_path(out.join("bench.csv")).unwrap();
    let head: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(
        head,
        [
            "code",
            "procs",
            "median_steps_per_s",
            "particle_steps_per_s",
            "rounds",
            "particles",
            "steps",
            "ns_per_particle_step",
            "verdem_best_over_this",
            "verdem_2_over_1_threads",
            "peak_rss_bytes_per_particle"
        ]
    );
    r.records()
        .map(|rec| {
            head.iter()
                .cloned()
                .zip(rec.unwrap().iter().map(String::from))
                .collect()
        })
        .collect()
}

fn number(row: &std::collections::HashMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column}: {:?} is not a number", row[column]))
}

#[test]
fn a_sweep_of_verdem_alone_writes_every_size_with_memory_and_the_plot() {
    let dir = tempfile::tempdir().unwrap();
    let rows = sweep(dir.path(), &["--peers", ""]);
    let labels: Vec<(&str, &str, &str, &str)> = rows
        .iter()
        .map(|r| {
            (
                r["code"].as_str(),
                r["procs"].as_str(),
                r["particles"].as_str(),
                r["steps"].as_str(),
            )
        })
        .collect();
    let v = "verdem (deterministic)";
    assert_eq!(
        labels,
        [
            (v, "1", "3480", "40"),
            (v, "2", "3480", "40"),
            (v, "1", "13920", "10"),
            (v, "2", "13920", "10"),
        ]
    );
    for r in &rows {
        let (steps_per_s, n) = (number(r, "median_steps_per_s"), number(r, "particles"));
        assert!(steps_per_s > 0.0);
        // the columns agree with each other
        let ps = number(r, "particle_steps_per_s");
        assert!((ps / (steps_per_s * n) - 1.0).abs() < 1e-3, "{r:?}");
        let ns = number(r, "ns_per_particle_step");
        assert!((ns * ps / 1e9 - 1.0).abs() < 1e-2, "{r:?}");
        assert!(number(r, "verdem_2_over_1_threads") > 0.0);
        // a process holds at least a megabyte (its program and libraries)
        assert!(number(r, "peak_rss_bytes_per_particle") * n > 1e6, "{r:?}");
    }
    // each probe's own memory, not the sweep's: four times the particles hold more (positions,
    // velocities, spins, contacts: far over 100 bytes each of the 10440 more)
    let total =
        |k: usize| number(&rows[k], "peak_rss_bytes_per_particle") * number(&rows[k], "particles");
    for (small, large) in [(0, 2), (1, 3)] {
        assert!(total(large) > total(small) + 1e6, "{rows:?}");
    }
    // the plot drawn again from the table alone, beside it
    let png = dir.path().join("bench.png");
    std::fs::remove_file(&png).unwrap();
    let csv = dir.path().join("bench.csv");
    let printed = common::verdem_ok([OsStr::new("bench"), OsStr::new("--plot"), csv.as_os_str()]);
    let said = String::from_utf8_lossy(&printed.stdout);
    assert_eq!(said.trim(), format!("plot: {}", png.display()));
    let png = png::Decoder::new(std::fs::File::open(png).unwrap());
    assert_eq!(png.read_info().unwrap().info().size(), (900, 600));
}

#[test]
fn a_sweep_with_lammps_measures_its_ranks_memory_at_every_size() {
    let dir = tempfile::tempdir().unwrap();
    let rows = sweep(
        dir.path(),
        &["--threads", "1", "--peers", "lammps", "--np", "1,2"],
    );
    let lammps: Vec<_> = rows.iter().filter(|r| r["code"] == "lammps").collect();
    assert_eq!(lammps.len(), 4);
    for r in lammps {
        assert!(number(r, "median_steps_per_s") > 0.0);
        assert!(number(r, "verdem_best_over_this") > 0.0);
        assert!(number(r, "peak_rss_bytes_per_particle") * number(r, "particles") > 1e6);
    }
    let md = std::fs::read_to_string(dir.path().join("bench.md")).unwrap();
    assert!(
        md.contains("13920 particles: verdem (deterministic) 1 / the fastest peer, lammps"),
        "{md}"
    );
}
