//! The real peers (Debian packages `lammps` and `liggghts`, installed by ci/test.sh) run the
//! inputs verdem generates from the quick case and MercuryDPM's developed state.

mod common;

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

use verdem::peers::{self, lammps_family::data_file, Peer};
use verdem::step::engine::Overrides;

/// LAMMPS and LIGGGHTS, from the registry.
fn lammps_and_liggghts() -> [&'static dyn Peer; 2] {
    ["lammps", "liggghts"].map(|name| peers::by_name(name).unwrap())
}

/// The generated input of the long cross-runs is byte for byte the one golden/peers/ recorded
/// with (`ci/record_peers.sh`: the full case, a dump every 50000 steps, from `state.lmp`).
#[test]
fn generated_inputs_are_those_of_the_recorded_cross_runs() {
    let case = verdem::case::Case::load(&common::root().join("cases/shear_flow.toml")).unwrap();
    for peer in lammps_and_liggghts() {
        let recorded = common::root().join(format!("golden/peers/{}.in", peer.name()));
        let recorded = std::fs::read_to_string(&recorded).unwrap();
        let script = peer
            .input_script(&case, "state.lmp", 10_000_000, Some(50_000))
            .unwrap();
        assert_eq!(script, recorded, "{peer:?}");
    }
}

/// `verdem peers` lists every known peer ([`peers::all`], in its order), or those named; a name
/// it does not know is refused with the list.
#[test]
fn the_command_line_knows_the_peers_of_the_registry() {
    let all = peers::all();
    let known: Vec<&str> = all.iter().map(|p| p.name()).collect();
    assert!(known.len() >= 2, "{known:?}");
    let out = common::verdem_ok(["peers"]);
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), all.len(), "{text}");
    for (line, p) in lines.iter().zip(all) {
        let fields: Vec<&str> = line.split('\t').collect();
        assert_eq!(fields.len(), 5, "{line}");
        assert_eq!(
            fields[..3],
            [p.name(), p.binary(), p.convention().name()],
            "{line}"
        );
        // the program's path may differ between this process and verdem's (Kratos' Python)
        let launch = p.launch(1);
        assert!(fields[3].contains(&launch.args.join(" ")), "{line}");
    }
    let second = all[1];
    let out = common::verdem_ok(["peers", second.name()]);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with(&format!(
        "{}\t{}\t{}\t",
        second.name(),
        second.binary(),
        second.convention().name()
    )));
    let (with_first, with_second) = (
        format!("{},mechsys", known[0]),
        format!("{},mechsys", known[1]),
    );
    for args in [
        &["cross", "mechsys"][..],
        &["verify", "--peers", &with_first],
        &["peers", &with_second],
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_verdem"))
            .args(args)
            .current_dir(common::root())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        let message = format!("unknown peer \"mechsys\" (known: {})", known.join(", "));
        assert!(err.contains(&message), "{args:?}: {err}");
    }
}

/// The help texts that name the peers name every peer of [`peers::all`].
#[test]
fn the_help_texts_name_the_peers_of_the_registry() {
    let listed = peers::all()
        .iter()
        .map(|p| p.name())
        .collect::<Vec<_>>()
        .join(", ");
    for command in ["cross", "verify"] {
        let out = common::verdem_ok([command, "--help"]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains(&format!("{listed})")), "{command}: {text}");
    }
}

/// A fake Python at `path`: a shell script answering `-m pip show` as pip does, with `tag` as
/// the version of both Kratos packages.
fn fake_python(path: &Path, tag: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(
        path,
        format!(
            "#!/bin/sh\nprintf 'Name: KratosMultiphysics\\nVersion: {tag}\\n\
             Name: KratosDEMApplication\\nVersion: {tag}\\n'\n"
        ),
    )
    .unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// A copy of the verdem binary at `dir/target/ci/verdem` (a clone's build), returned.
fn copied_verdem(dir: &Path) -> PathBuf {
    let exe = dir.join("target/ci/verdem");
    std::fs::create_dir_all(exe.parent().unwrap()).unwrap();
    std::fs::copy(env!("CARGO_BIN_EXE_verdem"), &exe).unwrap();
    exe
}

/// `exe peers NAMES` run in `cwd` with `VERDEM_PYTHON` `python` (unset when `None`) and, when
/// given, `PATH`; its output, once it has exited successfully.
fn peers_in(
    exe: &Path,
    names: &str,
    cwd: &Path,
    python: Option<&str>,
    path: Option<&str>,
) -> String {
    let mut c = std::process::Command::new(exe);
    c.args(["peers", names]).current_dir(cwd);
    match python {
        Some(p) => c.env("VERDEM_PYTHON", p),
        None => c.env_remove("VERDEM_PYTHON"),
    };
    if let Some(path) = path {
        c.env("PATH", path);
    }
    let out = c.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Kratos' Python is `VERDEM_PYTHON` when set (not empty), else `target/venv/bin/python` under
/// the current directory, else the one in the running binary's target folder, else `python3`;
/// `verdem peers kratos` runs it (the fake's versions) and says which it is and why.
#[test]
fn the_python_is_verdem_python_else_a_virtual_environment_else_python3() {
    let tmp = tempfile::tempdir().unwrap();
    let (clone, built, bare, elsewhere) = (
        tmp.path().join("clone"),
        tmp.path().join("built"),
        tmp.path().join("bare"),
        tmp.path().join("elsewhere"),
    );
    std::fs::create_dir_all(&elsewhere).unwrap();
    let venv = clone.join("target/venv/bin/python");
    fake_python(&venv, "in-current-dir");
    let named = tmp.path().join("named/python");
    fake_python(&named, "named");
    let test_binary = Path::new(env!("CARGO_BIN_EXE_verdem"));
    let installed = |tag: &str, python: &Path, why: &str| {
        format!(
            "\tKratosMultiphysics {tag}, KratosDEMApplication {tag} in {} ({why})\n",
            python.display()
        )
    };
    let here = "target/venv/bin/python in the current directory, the virtual environment \
                ci/test.sh makes; VERDEM_PYTHON unset";
    for python in [None, Some("")] {
        let line = peers_in(test_binary, "kratos", &clone, python, None);
        assert!(
            line.ends_with(&installed("in-current-dir", &venv, here)),
            "{python:?}: {line}"
        );
        assert!(
            line.contains(&format!(
                "\tOMP_NUM_THREADS=1 {} verdem_kratos.py",
                venv.display()
            )),
            "{line}"
        );
    }
    let line = peers_in(test_binary, "kratos", &clone, named.to_str(), None);
    assert!(
        line.ends_with(&installed("named", &named, "VERDEM_PYTHON")),
        "{line}"
    );

    let exe = copied_verdem(&built);
    let beside = built.join("target/venv/bin/python");
    fake_python(&beside, "beside-binary");
    let line = peers_in(&exe, "kratos", &elsewhere, None, None);
    assert!(
        line.ends_with(&installed(
            "beside-binary",
            &beside,
            "venv/bin/python in the running verdem's target folder, the virtual environment \
             ci/test.sh makes; VERDEM_PYTHON unset and no target/venv in the current directory"
        )),
        "{line}"
    );
    let line = peers_in(&exe, "kratos", &clone, None, None);
    assert!(
        line.ends_with(&installed("in-current-dir", &venv, here)),
        "{line}"
    );

    let exe = copied_verdem(&bare);
    let line = peers_in(&exe, "kratos", &elsewhere, None, None);
    assert!(
        line.contains("\tOMP_NUM_THREADS=1 python3 verdem_kratos.py")
            && line.contains(
                "python3 (VERDEM_PYTHON unset, no target/venv/bin/python in the current \
                 directory nor in the running verdem's target folder)"
            ),
        "{line}"
    );
}

/// With nothing on PATH and no virtual environment every peer is listed as not installed, with
/// the exact command that installs what it lacks.
#[test]
fn a_missing_peer_is_listed_with_the_command_that_installs_it() {
    let tmp = tempfile::tempdir().unwrap();
    let exe = copied_verdem(&tmp.path().join("bare"));
    let text = peers_in(
        &exe,
        &peers::names(),
        tmp.path(),
        None,
        Some("/nonexistent"),
    );
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), peers::all().len(), "{text}");
    for (line, peer) in lines.iter().zip(peers::all()) {
        let fields: Vec<&str> = line.split('\t').collect();
        assert_eq!(fields[0], peer.name(), "{text}");
        assert!(
            fields[4].starts_with("not installed: ") && fields[4].contains("; install it with `"),
            "{line}"
        );
    }
    let status = |name: &str| {
        let line = lines
            .iter()
            .find(|l| l.starts_with(&format!("{name}\t")))
            .unwrap();
        line.rsplit('\t').next().unwrap().to_string()
    };
    for (name, binary) in [("lammps", "lmp"), ("liggghts", "liggghts")] {
        assert_eq!(
            status(name),
            format!(
                "not installed: {binary} and mpirun are not on PATH; install it with \
                 `apt-get install -y {name} openmpi-bin`"
            )
        );
    }
    assert_eq!(
        status("yade"),
        "not installed: yade is not on PATH; install it with `apt-get install -y yade`"
    );
    let kratos = status("kratos");
    assert!(
        kratos.starts_with(
            "not installed: Kratos DEM is not installed for python3 (VERDEM_PYTHON unset, no \
             target/venv/bin/python in the current directory nor in the running verdem's target \
             folder): cannot start it: "
        ) && kratos.ends_with(
            "; install it with `python3 -m venv target/venv && target/venv/bin/python -m pip \
             install -r ci/requirements.txt`"
        ),
        "{kratos}"
    );
}

#[test]
fn lammps_and_liggghts_run_the_generated_inputs() {
    let case = common::quick_case();
    let e = common::engine(
        &case,
        Some(&common::data("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("state.lmp");
    std::fs::write(&data, data_file(&e.snapshot(), 1.0)).unwrap();
    for peer in lammps_and_liggghts() {
        let script = peer
            .input_script(&case, &data.display().to_string(), 200, None)
            .unwrap();
        for np in [1, 2] {
            let seconds = peer
                .run(
                    &peers::Run {
                        dir: dir.path(),
                        np,
                    },
                    &script,
                )
                .unwrap_or_else(|e| panic!("{peer:?} on {np} rank(s): {e:#}"));
            assert!(
                seconds > 0.0 && seconds.is_finite(),
                "{peer:?}: loop time {seconds}"
            );
        }
    }
}

#[test]
fn data_file_carries_every_particle_with_its_type_and_velocity() {
    let case = common::quick_case();
    let e = common::engine(
        &case,
        Some(&common::data("states/mercury_t143.85.data")),
        Overrides::default(),
    );
    let snap = e.snapshot();
    let text = data_file(&snap, 1.0);
    let atoms: Vec<&str> = text
        .split("Atoms # sphere\n\n")
        .nth(1)
        .unwrap()
        .split("\n\nVelocities")
        .next()
        .unwrap()
        .lines()
        .collect();
    assert_eq!(atoms.len(), 3480);
    let types: Vec<&str> = atoms
        .iter()
        .map(|l| l.split_whitespace().nth(1).unwrap())
        .collect();
    assert!(types[..240].iter().all(|t| *t == "2") && types[240..480].iter().all(|t| *t == "3"));
    assert!(types[480..].iter().all(|t| *t == "1"));
    let x: f64 = atoms[2000]
        .split_whitespace()
        .nth(4)
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(x, snap.particles.x[2000].x);
}

/// With the peer's tangential convention, verdem and the peer integrate the same equations: over
/// 2000 steps of the developed shear state they agree to round-off (measured ~1e-12), far from
/// the 1e-6 that marks divergence; with MercuryDPM's convention instead, they do not.
#[test]
fn cross_runs_agree_to_round_off_with_the_peers_convention_and_not_without() {
    use verdem::peers::cross::cross;
    let case = common::quick_case();
    let state = common::data("states/mercury_t143.85.data");
    let dir = tempfile::tempdir().unwrap();
    for peer in lammps_and_liggghts() {
        let out = dir.path().join(peer.binary());
        let r = cross(peer, &case, peer.convention(), &state, 2000, 500, 1, &out)
            .unwrap_or_else(|e| panic!("{peer:?}: {e:#}"));
        assert_eq!(r.saves.len(), 5);
        for s in &r.saves {
            assert!(s.dx.max < 1e-10 && s.dv.max < 1e-9, "{peer:?} {s:?}");
        }
        // both series were written as MercuryCG saves; the peer's contacts are verdem's, with
        // normal forces within the dashpot's share (the peers re-evaluate them with full-step
        // velocities)
        let fstat = |sub: &str| {
            let save = out.join(sub).join("shear_flow_quick.data.0004");
            verdem::io::mercury::read_data(&save).unwrap();
            let f = out.join(sub).join("shear_flow_quick.fstat.0004");
            let mut rows: Vec<_> = verdem::io::mercury::read_fstat(&f)
                .unwrap()
                .rows
                .into_iter()
                .filter(|r| r.i < r.j)
                .map(|r| (r.i, r.j, r.fn_signed))
                .collect();
            rows.sort_by_key(|r| (r.0, r.1));
            rows
        };
        let (own, theirs) = (fstat("verdem"), fstat(peer.binary()));
        assert!(!own.is_empty());
        assert_eq!(own.len(), theirs.len(), "{peer:?}");
        for (a, b) in own.iter().zip(&theirs) {
            assert_eq!((a.0, a.1), (b.0, b.1), "{peer:?}");
            assert!(
                (a.2 - b.2).abs() < 0.02 * a.2.abs() + 1e-6,
                "{peer:?} {a:?} {b:?}"
            );
        }
        assert_eq!(r.profiles_chi2.map(|c| c.len()), Some(5));
    }
    let out = dir.path().join("mismatched");
    let r = cross(
        peers::by_name("lammps").unwrap(),
        &case,
        verdem::contact::Tangential::Mercury,
        &state,
        2000,
        1000,
        1,
        &out,
    )
    .unwrap();
    assert!(r.saves[2].dv.max > 1e-6, "{:?}", r.saves[2]);
}

/// The binary collisions of the verification case, run in each peer: the same restitution as
/// the closed form within the tolerance, and the same as verdem's to 1e-9 (same scheme, same
/// first touch within a step).
#[test]
fn peers_give_the_restitution_of_the_closed_form_and_of_verdem() {
    let case = verdem::case::Case::load(&common::root().join("cases/verify/binary_collision.toml"))
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    for peer in lammps_and_liggghts() {
        let rows = peers::collision::rows(peer, &case, &dir.path().join(peer.binary())).unwrap();
        assert_eq!(rows.len(), 8);
        for r in &rows {
            assert!(r.passed(), "{r:?}");
        }
        for (v0, wall) in [(1.0, false), (0.1, true)] {
            let own = verdem::verify::collide(&case, v0, wall, 50.0).unwrap().e;
            let theirs =
                peers::collision::restitution(peer, &case, v0, wall, &dir.path().join("one"))
                    .unwrap();
            assert!(
                ((theirs - own) / own).abs() < 1e-9,
                "{peer:?}: {theirs} vs {own}"
            );
        }
    }
}
