//! A run never loses finished work: a folder holding an earlier run's files is refused unless
//! `--force`; a full disk or a read-only folder stops the run with a message naming the file
//! and the system's error, and leaves the files written before it as they were. And the
//! picture of the particles a run draws of its last save.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Exit status, stdout and stderr of `verdem ARGS` run from the repository root.
fn verdem(args: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .current_dir(common::root())
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Every file of `dir` by name, with its bytes.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

/// No temporary or partial file, and no NaN or infinity in any text file of `dir`.
fn clean(dir: &Path) {
    for (name, bytes) in files(dir) {
        assert!(
            !name.ends_with(".tmp") && !name.contains(".part."),
            "{name} is left in {}",
            dir.display()
        );
        if let Ok(text) = String::from_utf8(bytes) {
            let lower = text.to_lowercase();
            assert!(
                !lower.contains("nan") && !lower.contains("inf"),
                "{name} holds a NaN or an infinity"
            );
        }
    }
}

const PAIR: &str = "cases/verify/binary_collision.toml";

/// The shear case from its steady state: saves of ~0.6 MB.
const SHEAR: &str = "cases/shear_flow_steady.toml";

#[test]
fn a_folder_holding_an_earlier_run_is_refused_and_force_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let first = [
        "run",
        PAIR,
        "--steps",
        "20",
        "--save-every",
        "10",
        "--checkpoint-every",
        "20",
        "--quiet",
    ];
    let (code, _, err) = verdem(&[&first[..], &["--out", out]].concat());
    assert_eq!(code, Some(0), "{err}");
    let before = files(dir.path());
    assert!(before.contains_key("binary_collision.data.0002"));

    let again = [
        "run",
        PAIR,
        "--steps",
        "10",
        "--save-every",
        "10",
        "--quiet",
    ];
    let (code, _, err) = verdem(&[&again[..], &["--out", out]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "{out}: already holds the files of a run named \"binary_collision\""
        )),
        "{err}"
    );
    // every file of the folder is the earlier run's, and each is counted
    assert!(err.contains("(binary_collision."), "{err}");
    assert!(err.contains(&format!("; {} files)", before.len())), "{err}");
    assert!(err.contains("--force"), "{err}");
    assert!(
        files(dir.path()) == before,
        "a refused run changed the folder"
    );

    // a resume continues in its checkpoint's folder; into another one it is checked as a new run
    let ck = dir.path().join("binary_collision.checkpoint");
    let resume = [
        "run",
        PAIR,
        "--steps",
        "30",
        "--save-every",
        "10",
        "--quiet",
        "--resume",
        ck.to_str().unwrap(),
    ];
    let elsewhere = tempfile::tempdir().unwrap();
    let elsewhere = elsewhere.path().to_str().unwrap();
    let (code, _, err) = verdem(&[&again[..], &["--out", elsewhere]].concat());
    assert_eq!(code, Some(0), "{err}");
    let (code, _, err) = verdem(&[&resume[..], &["--out", elsewhere]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("already holds the files of a run"), "{err}");
    let (code, _, err) = verdem(&[&resume[..], &["--out", out]].concat());
    assert_eq!(code, Some(0), "{err}");
    let resumed = files(dir.path());
    for (name, bytes) in &before {
        if name.contains(".data.") || name.contains(".fstat.") {
            assert!(
                resumed.get(name) == Some(bytes),
                "the resume changed {name}"
            );
        }
    }
    assert!(resumed.contains_key("binary_collision.data.0003"));

    // another run name in the same folder is not the earlier run's
    let other = dir.path().join("other.toml");
    let text = std::fs::read_to_string(common::root().join(PAIR)).unwrap();
    std::fs::write(
        &other,
        text.replace("name = \"binary_collision\"", "name = \"other\""),
    )
    .unwrap();
    let (code, _, err) = verdem(&[
        "run",
        other.to_str().unwrap(),
        "--steps",
        "10",
        "--quiet",
        "--out",
        out,
    ]);
    assert_eq!(code, Some(0), "{err}");

    let (code, text, err) = verdem(&[&again[..], &["--out", out, "--force"]].concat());
    assert_eq!(code, Some(0), "{err}");
    assert!(text.contains("removed the "), "{text}");
    let after = files(dir.path());
    // the earlier run's save 2 is gone: the folder holds one run's series, not a mixture
    assert!(
        !after.contains_key("binary_collision.data.0002"),
        "{after:?}"
    );
    assert!(after.contains_key("binary_collision.data.0001"));
    assert!(after.contains_key("other.data.0000"));
    clean(dir.path());
}

/// A mounted tmpfs, unmounted when dropped.
struct Mount(PathBuf);

impl Mount {
    /// Mounts a tmpfs of `size` (mount(8)'s syntax) on a new folder in `parent`; `None` with the
    /// reason when mounting is not allowed here (not root, no CAP_SYS_ADMIN).
    fn tmpfs(parent: &Path, size: &str) -> Result<Mount, String> {
        let at = parent.join("mnt");
        std::fs::create_dir(&at).unwrap();
        let o = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(&at)
            .output()
            .map_err(|e| format!("cannot start mount: {e}"))?;
        if !o.status.success() {
            return Err(format!(
                "mount -t tmpfs failed: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ));
        }
        Ok(Mount(at))
    }

    fn read_only(&self) {
        let o = Command::new("mount")
            .args(["-o", "remount,ro"])
            .arg(&self.0)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

impl Drop for Mount {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// The folder a tmpfs of `size` is mounted on, or `None` after printing why the test is skipped.
fn mounted(parent: &Path, size: &str) -> Option<Mount> {
    match Mount::tmpfs(parent, size) {
        Ok(m) => Some(m),
        Err(why) => {
            eprintln!("SKIPPED: a full or read-only disk needs a tmpfs mount: {why}");
            None
        }
    }
}

#[test]
fn a_full_disk_stops_the_run_naming_the_file_and_keeps_the_saves_before() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "run",
        SHEAR,
        "--steps",
        "30",
        "--save-every",
        "10",
        "--quiet",
    ];
    let reference = dir.path().join("reference");
    let (code, _, err) = verdem(&[&args[..], &["--out", reference.to_str().unwrap()]].concat());
    assert_eq!(code, Some(0), "{err}");
    let Some(disk) = mounted(dir.path(), "900k") else {
        return;
    };
    // save 0 (a .data of ~0.6 MB and its .fstat) fits, save 1 does not
    let out = disk.0.to_str().unwrap();
    let (code, _, err) = verdem(&[&args[..], &["--out", out]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("shear_flow_steady.data.0001: cannot write"),
        "{err}"
    );
    assert!(err.contains("No space left on device"), "{err}");
    assert!(err.contains("save 1 (step 10) was not written"), "{err}");
    assert!(
        err.contains(&format!("last save {out}/shear_flow_steady.data.0000")),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    let left = files(&disk.0);
    let want = files(&reference);
    for name in [
        "shear_flow_steady.data.0000",
        "shear_flow_steady.fstat.0000",
    ] {
        assert!(
            left.get(name) == want.get(name),
            "{name} differs from the reference run's"
        );
    }
    let rows = |f: &BTreeMap<String, Vec<u8>>| {
        String::from_utf8(f["shear_flow_steady.diagnostics.csv"].clone()).unwrap()
    };
    assert!(
        rows(&want).starts_with(&rows(&left)) && rows(&left).lines().count() == 2,
        "the diagnostics table holds the header and save 0's row: {}",
        rows(&left)
    );
    assert!(!left.keys().any(|n| n.contains(".0001")), "{left:?}");
    clean(&disk.0);
}

#[test]
fn a_read_only_folder_stops_the_run_naming_the_file_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let Some(disk) = mounted(dir.path(), "8m") else {
        return;
    };
    let out = disk.0.to_str().unwrap();
    let args = ["run", PAIR, "--save-every", "10", "--quiet", "--out", out];
    let (code, _, err) =
        verdem(&[&args[..], &["--steps", "20", "--checkpoint-every", "20"]].concat());
    assert_eq!(code, Some(0), "{err}");
    disk.read_only();
    let before = files(&disk.0);
    let ck = disk.0.join("binary_collision.checkpoint");

    // continuing the run: its folder cannot take the next save
    let resume = ["--steps", "40", "--resume", ck.to_str().unwrap()];
    let (code, _, err) = verdem(&[&args[..], &resume[..]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("Read-only file system"), "{err}");
    assert!(
        err.contains(&format!(
            "{out}/binary_collision.diagnostics.csv: cannot write"
        )),
        "{err}"
    );
    assert!(
        err.contains(&format!("the files already in {out} are intact")),
        "{err}"
    );

    // replacing the run: its files cannot be removed
    let (code, _, err) = verdem(&[&args[..], &["--steps", "20", "--force"]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("Read-only file system"), "{err}");
    assert!(
        err.contains(&format!("{out}/binary_collision.")) && err.contains("cannot remove"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(files(&disk.0) == before, "the read-only folder changed");
    clean(&disk.0);
}

/// Width, height and RGB bytes of a PNG.
fn decode(png: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut reader = png::Decoder::new(png).read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// The picture of the last save: 1000 × 900 pixels (docs/cli.md); the shear flow's upper half
/// moves with the top wall (+x, red on the cool-warm map), its lower half with the bottom wall
/// (−x, blue); wall spheres in grey; the same save draws the same bytes.
#[test]
fn the_particles_picture_shows_the_shear_flow() {
    let dirs = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
    let mut pictures = Vec::new();
    for d in &dirs {
        let args = [
            "run",
            SHEAR,
            "--steps",
            "10",
            "--save-every",
            "10",
            "--quiet",
            "--out",
        ];
        let (code, text, err) = verdem(&[&args[..], &[d.path().to_str().unwrap()]].concat());
        assert_eq!(code, Some(0), "{err}");
        assert!(text.contains("particles: "), "{text}");
        pictures.push(std::fs::read(d.path().join("shear_flow_steady.particles.png")).unwrap());
    }
    assert!(
        pictures[0] == pictures[1],
        "two runs of the same save drew different bytes"
    );
    let (w, h, rgb) = decode(&pictures[0]);
    assert_eq!((w, h), (1000, 900));
    let px = |x: u32, y: u32| {
        let k = 3 * (y * w + x) as usize;
        [rgb[k], rgb[k + 1], rgb[k + 2]].map(i32::from)
    };
    // mean red minus blue of the coloured pixels (not white, grey or black) left of the colour
    // bar, in the rows [from, to)
    let warmth = |from: u32, to: u32| {
        let (mut sum, mut n) = (0i64, 0i64);
        for y in from..to {
            for x in 0..w - 150 {
                let [r, g, b] = px(x, y);
                if r.max(g).max(b) - r.min(g).min(b) > 40 {
                    sum += i64::from(r - b);
                    n += 1;
                }
            }
        }
        assert!(n > 1000, "rows {from}..{to}: only {n} coloured pixels");
        sum as f64 / n as f64
    };
    let (upper, lower) = (warmth(0, h / 2), warmth(h / 2, h));
    assert!(
        upper > 20.0 && lower < -20.0,
        "upper half {upper}, lower half {lower}"
    );
    // mid greys: the wall spheres (the map's neutral colour is a lighter grey, 221)
    let grey = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let [r, g, b] = px(x, y);
            r == g && g == b && (100..=200).contains(&r)
        })
        .count();
    assert!(grey > 10_000, "{grey} grey pixels");
}

/// `verdem cross` and `verdem tradeoff` write saves too: a folder of theirs that holds an
/// earlier run's saves is refused before any peer or variant runs.
#[test]
fn cross_and_tradeoff_refuse_an_earlier_runs_saves() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let earlier = |sub: &str| {
        let folder = dir.path().join(sub);
        std::fs::create_dir_all(&folder).unwrap();
        let save = folder.join("shear_flow_quick.data.0000");
        std::fs::write(&save, "earlier\n").unwrap();
        save
    };
    for (args, sub) in [
        (vec!["cross", "lammps", "--out", out], "lmp/verdem"),
        (vec!["tradeoff", "--out", out], "reference"),
    ] {
        let save = earlier(sub);
        let (code, _, err) = verdem(&args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(
            err.contains("already holds the files of a run named \"shear_flow_quick\""),
            "{args:?}: {err}"
        );
        assert!(err.contains("--force"), "{err}");
        assert_eq!(std::fs::read_to_string(&save).unwrap(), "earlier\n");
        std::fs::remove_file(save).unwrap();
    }
}
