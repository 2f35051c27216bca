//! `verdem bench` end to end: verdem, the ceiling rows and the installed peers (Debian's LAMMPS
//! and LIGGGHTS under OpenMPI's mpirun, and Yade) run on the same state, and the tables list every
//! configuration with a measured rate. Rates are not judged here (no timings in tests).

mod common;

#[test]
fn bench_runs_verdem_and_both_peers_on_one_state_and_writes_both_tables() {
    let dir = tempfile::tempdir().unwrap();
    let state = common::data("states/mercury_t143.85.data");
    let args = [
        "bench",
        "--steps",
        "300",
        "--rounds",
        "1",
        "--np",
        "1,2",
        "--peers",
        "lammps,liggghts,yade",
        "--out",
    ];
    let mut args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
    args.extend([dir.path().as_os_str(), "--from".as_ref(), state.as_os_str()]);
    let out = common::verdem_ok(args);
    let csv = std::fs::read_to_string(dir.path().join("bench.csv")).unwrap();
    let rows: Vec<(String, String, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].to_string(), f[1].to_string(), f[2].parse().unwrap())
        })
        .collect();
    let labels: Vec<(&str, &str)> = rows
        .iter()
        .map(|(c, n, _)| (c.as_str(), n.as_str()))
        .collect();
    assert_eq!(
        labels,
        [
            ("verdem (deterministic)", "1"),
            ("verdem (deterministic)", "2"),
            ("2 independent verdem runs at once (summed)", "2×1"),
            (
                "2 independent verdem runs in lockstep: one barrier a step (summed)",
                "2×1"
            ),
            ("lammps", "1"),
            ("lammps", "2"),
            ("liggghts", "1"),
            ("liggghts", "2"),
            ("yade", "1"),
            ("yade", "2"),
        ]
    );
    assert!(rows.iter().all(|r| r.2.is_finite() && r.2 > 0.0), "{csv}");
    let md = std::fs::read_to_string(dir.path().join("bench.md")).unwrap();
    assert_eq!(md, String::from_utf8_lossy(&out.stdout));
    assert!(md.contains("verdem 2 threads / 1 thread: "), "{md}");
    assert!(
        md.contains("the same two runs waiting for each other once a step / 1 run alone: "),
        "{md}"
    );
    assert!(md.contains("the run on CPU 1 ran at "), "{md}");
    for peer in ["lammps", "liggghts", "yade"] {
        assert!(
            md.contains(&format!("verdem 2 threads / {peer} 2 ranks: ")),
            "{md}"
        );
    }
    // one round: too few for an interval, so no goal is judged met or not met
    assert!(
        md.contains(
            "goal ≥ 5: undecided, ≥ 10 on the benchmark's cell: undecided (a 95 % interval"
        ),
        "{md}"
    );
    assert!(md.contains("neighbour list"), "{md}");
}
