//! ParaView output read back by an independent reader (Python's meshio, in the virtual
//! environment `ci/test.sh` makes; its Python is verdem's, `verdem::python::python`) and
//! compared with the MercuryCG save it shows: positions, radii, velocities and spins bit for
//! bit, the wall spheres, and one line per contact of the `.fstat` carrying its normal and
//! tangential force. A run's `.pvd` is also opened by ParaView's own reader.

mod common;

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

use verdem::io::mercury::{read_data, read_fstat, save_path};

/// Prints each array of a `.vtu` as `NAME v v v …` (shortest round-trip decimals), the lines'
/// point pairs, the field TimeValue.
const READ_VTU: &str = r#"
import sys, meshio
m = meshio.read(sys.argv[1])
def out(name, values):
    print(name, " ".join(repr(float(v)) for v in values.ravel()))
out("points", m.points)
for name in ["id", "radius", "wall", "velocity", "angular_velocity"]:
    out(name, m.point_data[name])
out("time", m.field_data["TimeValue"])
kinds = [block.type for block in m.cells]
assert set(kinds) <= {"vertex", "line"}, kinds
vertices = sum(len(b.data) for b in m.cells if b.type == "vertex")
print("vertices", vertices)
if "line" in kinds:
    k = kinds.index("line")
    out("lines", m.cells[k].data)
    for name in ["normal_force", "tangential_force", "periodic"]:
        out(name, m.cell_data[name][k])
else:
    for name in ["lines", "normal_force", "tangential_force", "periodic"]:
        print(name)
"#;

/// Lists a `.pvd`'s data sets as `timestep file` lines (Python's own XML parser).
const READ_PVD: &str = r#"
import sys, xml.etree.ElementTree as ET
for d in ET.parse(sys.argv[1]).getroot().iter("DataSet"):
    print(repr(float(d.get("timestep"))), d.get("file"))
"#;

fn run_python(script: &str, file: &Path) -> String {
    let python = verdem::python::python();
    let o = Command::new(&python.program)
        .args(["-c", script])
        .arg(file)
        .output()
        .unwrap_or_else(|e| panic!("{python}: {e}"));
    assert!(
        o.status.success(),
        "{}: {python}: {} (these tests read the VTK files with meshio: `bash ci/test.sh` makes \
         the virtual environment target/venv from ci/requirements.txt)",
        file.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// The arrays meshio read from a `.vtu`, by name.
fn meshio(vtu: &Path) -> HashMap<String, Vec<f64>> {
    run_python(READ_VTU, vtu)
        .lines()
        .map(|l| {
            let mut words = l.split_whitespace();
            let name = words.next().unwrap().to_string();
            (name, words.map(|w| w.parse().unwrap()).collect())
        })
        .collect()
}

/// Compares save `k` of the series `dir/name` with its `.vtu`; returns the number of contacts.
fn same_as_the_save(dir: &Path, name: &str, k: u64) -> usize {
    let vtu = dir.join(format!("{name}.{k:04}.vtu"));
    let m = meshio(&vtu);
    let data = read_data(&save_path(dir, name, "data", k)).unwrap();
    let fstat = read_fstat(&save_path(dir, name, "fstat", k)).unwrap();
    let n = data.rows.len();
    let column = |f: &dyn Fn(&verdem::io::mercury::DataRow) -> Vec<f64>| -> Vec<f64> {
        data.rows.iter().flat_map(f).collect()
    };
    let at = vtu.display();
    assert_eq!(m["time"], vec![data.time], "{at}");
    assert_eq!(m["vertices"], vec![n as f64], "{at}");
    assert_eq!(
        m["points"],
        column(&|r| r.x.iter().copied().collect()),
        "{at}"
    );
    assert_eq!(m["radius"], column(&|r| vec![r.radius]), "{at}");
    assert_eq!(
        m["velocity"],
        column(&|r| r.v.iter().copied().collect()),
        "{at}"
    );
    assert_eq!(
        m["angular_velocity"],
        column(&|r| r.w.iter().copied().collect()),
        "{at}"
    );
    assert_eq!(
        m["id"],
        (0..n).map(|i| i as f64).collect::<Vec<_>>(),
        "{at}"
    );
    // The benchmark's wall spheres are the ones on the two wall planes, z = 0.5 and 21.5
    // (the case's bottom_z and top_z), and only they.
    let on_a_wall = column(&|r| vec![f64::from(u8::from(r.x.z == 0.5 || r.x.z == 21.5))]);
    assert_eq!(m["wall"], on_a_wall, "{at}");
    assert_eq!(on_a_wall.iter().sum::<f64>(), 480.0);

    // one line per contact: the .fstat lists a free–free contact from both sides
    let mut pairs: Vec<(usize, usize)> = fstat
        .rows
        .iter()
        .map(|r| (r.i.min(r.j), r.i.max(r.j)))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let lines = &m["lines"];
    assert_eq!(
        lines.len(),
        2 * pairs.len(),
        "{at}: {} contacts",
        pairs.len()
    );
    for (c, ends) in lines.chunks(2).enumerate() {
        let (a, b) = (ends[0] as usize, ends[1] as usize);
        let row = fstat
            .rows
            .iter()
            .find(|r| r.i == a && r.j == b)
            .unwrap_or_else(|| panic!("{at}: line {a}-{b} is not a contact of the .fstat"));
        let close = |got: &[f64], want: verdem::Vec3| {
            let scale = want.norm().max(1e-300);
            got.iter()
                .zip(want.iter())
                .all(|(g, w)| (g - w).abs() <= 1e-12 * scale)
        };
        let normal = &m["normal_force"][3 * c..3 * c + 3];
        let tangential = &m["tangential_force"][3 * c..3 * c + 3];
        assert!(
            close(normal, row.fn_signed * row.n),
            "{at}: {a}-{b} normal {normal:?}"
        );
        assert!(
            close(tangential, row.ft * row.t),
            "{at}: {a}-{b} tangential {tangential:?}"
        );
        let apart =
            (data.rows[a].x - data.rows[b].x).norm() >= data.rows[a].radius + data.rows[b].radius;
        assert_eq!(
            m["periodic"][c],
            f64::from(u8::from(apart)),
            "{at}: {a}-{b}"
        );
    }
    pairs.len()
}

/// Opens `dir/name.pvd` with ParaView's own reader (Debian's `python3-paraview`, which
/// `ci/test.sh` installs): its time steps are the saves' times, and its last step has every
/// particle as a point and a vertex, and every contact of that save as a line.
fn opens_in_paraview(dir: &Path, name: &str, saves: u64) {
    const OPEN_PVD: &str = r#"
import sys
try:
    from paraview.simple import PVDReader
except ImportError as e:
    sys.exit(f"ParaView's Python module is missing ({e}): apt-get install python3-paraview")
r = PVDReader(FileName=sys.argv[1])
print("times", " ".join(repr(t) for t in r.TimestepValues))
r.UpdatePipeline(r.TimestepValues[-1])
d = r.GetDataInformation()
print("points", d.GetNumberOfPoints())
print("cells", d.GetNumberOfCells())
print("point_arrays", " ".join(sorted(r.PointData.keys())))
print("cell_arrays", " ".join(sorted(r.CellData.keys())))
"#;
    let pvd = dir.join(format!("{name}.pvd"));
    let o = Command::new("/usr/bin/python3")
        .args(["-c", OPEN_PVD])
        .arg(&pvd)
        .output()
        .expect("/usr/bin/python3 runs");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{}: {}{text}",
        pvd.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    let field = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key).map(|v| v.trim().to_string()))
            .unwrap_or_else(|| panic!("no {key} in {text}"))
    };
    let times: Vec<f64> = (0..saves)
        .map(|k| read_data(&save_path(dir, name, "data", k)).unwrap().time)
        .collect();
    let read: Vec<f64> = field("times ")
        .split(' ')
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(read, times);
    let last = saves - 1;
    let n = read_data(&save_path(dir, name, "data", last))
        .unwrap()
        .rows
        .len();
    let mut pairs: Vec<(usize, usize)> = read_fstat(&save_path(dir, name, "fstat", last))
        .unwrap()
        .rows
        .iter()
        .map(|r| (r.i.min(r.j), r.i.max(r.j)))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    assert_eq!(field("points "), n.to_string());
    assert_eq!(field("cells "), (n + pairs.len()).to_string());
    assert_eq!(
        field("point_arrays "),
        "angular_velocity id radius velocity wall"
    );
    assert_eq!(
        field("cell_arrays "),
        "normal_force periodic tangential_force"
    );
}

/// The `.pvd`'s data sets: (time, file).
fn collection(pvd: &Path) -> Vec<(f64, String)> {
    run_python(READ_PVD, pvd)
        .lines()
        .map(|l| {
            let (t, f) = l.split_once(' ').unwrap();
            (t.parse().unwrap(), f.to_string())
        })
        .collect()
}

#[test]
fn a_run_with_vtk_reads_back_as_its_saves() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    common::verdem_ok([
        "run",
        "cases/shear_flow_steady.toml",
        "--steps",
        "20",
        "--save-every",
        "10",
        "--vtk",
        "--quiet",
        "--out",
        out,
    ]);
    let name = "shear_flow_steady";
    let contacts: usize = (0..3).map(|k| same_as_the_save(dir.path(), name, k)).sum();
    assert!(contacts > 0, "the steady flow has contacts");
    opens_in_paraview(dir.path(), name, 3);
    let series = collection(&dir.path().join(format!("{name}.pvd")));
    let times: Vec<(f64, String)> = (0..3)
        .map(|k| {
            let data = read_data(&save_path(dir.path(), name, "data", k)).unwrap();
            (data.time, format!("{name}.{k:04}.vtu"))
        })
        .collect();
    assert_eq!(series, times);

    // the same saves converted by `verdem vtk`, from the files alone
    let copy = tempfile::tempdir().unwrap();
    for k in 0..3 {
        for ext in ["data", "fstat"] {
            std::fs::copy(
                save_path(dir.path(), name, ext, k),
                save_path(copy.path(), name, ext, k),
            )
            .unwrap();
        }
    }
    let base = copy.path().join(name);
    common::verdem_ok([
        "vtk",
        base.to_str().unwrap(),
        "--case",
        "cases/shear_flow_steady.toml",
    ]);
    let converted: usize = (0..3).map(|k| same_as_the_save(copy.path(), name, k)).sum();
    assert_eq!(converted, contacts);
    assert_eq!(collection(&copy.path().join(format!("{name}.pvd"))), times);
}

/// `[output] vtk = true` in a case writes the same files as `--vtk`.
#[test]
fn the_case_file_can_ask_for_vtk() {
    let dir = tempfile::tempdir().unwrap();
    let root = common::root();
    let text = std::fs::read_to_string(root.join("cases/shear_flow_steady.toml")).unwrap();
    let case = dir.path().join("steady_vtk.toml");
    std::fs::write(&case, format!("{text}\n[output]\nvtk = true\n")).unwrap();
    let out = dir.path().join("out");
    common::verdem_ok([
        "run",
        case.to_str().unwrap(),
        "--init",
        "golden/full_run/shear_flow.final.data",
        "--steps",
        "10",
        "--save-every",
        "10",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    same_as_the_save(&out, "shear_flow_steady", 1);
    assert_eq!(collection(&out.join("shear_flow_steady.pvd")).len(), 2);
}

/// Copies MercuryDPM's own save 0 of the benchmark (`Mercury_out.data.0000`, `.fstat.0000`)
/// into `dir`.
fn copy_mercury_save_0(dir: &Path) {
    for ext in ["data", "fstat"] {
        let file = format!("Mercury_out.{ext}.0000");
        std::fs::copy(
            common::data(&format!("outputs_example/{file}")),
            dir.join(&file),
        )
        .unwrap();
    }
}

/// `verdem vtk` converts another code's series: MercuryDPM's own save 0 of the benchmark.
#[test]
fn verdem_vtk_converts_mercurydpm_saves() {
    let dir = tempfile::tempdir().unwrap();
    copy_mercury_save_0(dir.path());
    let base = dir.path().join("Mercury_out");
    let o = common::verdem_ok(["vtk".as_ref(), base.as_os_str()]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("1 saves written"));
    same_as_the_save(dir.path(), "Mercury_out", 0);
    let series = collection(&dir.path().join("Mercury_out.pvd"));
    assert_eq!(series.len(), 1);
    assert_eq!(series[0].1, "Mercury_out.0000.vtu");
}

/// A resumed run keeps the saves before its checkpoint in the `.pvd` and adds its own.
#[test]
fn a_resumed_run_continues_the_time_series() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let name = "shear_flow_steady";
    let args = [
        "run",
        "cases/shear_flow_steady.toml",
        "--save-every",
        "10",
        "--vtk",
        "--quiet",
        "--out",
        out,
    ];
    common::verdem_ok([&args[..], &["--steps", "10", "--checkpoint-every", "10"]].concat());
    let ck = dir.path().join(format!("{name}.checkpoint"));
    common::verdem_ok(
        [
            &args[..],
            &["--steps", "20", "--resume", ck.to_str().unwrap()],
        ]
        .concat(),
    );
    let times: Vec<(f64, String)> = (0..3)
        .map(|k| {
            same_as_the_save(dir.path(), name, k);
            let data = read_data(&save_path(dir.path(), name, "data", k)).unwrap();
            (data.time, format!("{name}.{k:04}.vtu"))
        })
        .collect();
    assert_eq!(collection(&dir.path().join(format!("{name}.pvd"))), times);
}

/// A save with its `.data` but not its `.fstat` is an error naming the missing file; with
/// `--skip-incomplete` it is skipped with a warning naming it and the others are converted.
#[test]
fn an_incomplete_save_is_said_or_skipped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    copy_mercury_save_0(dir.path());
    std::fs::copy(
        dir.path().join("Mercury_out.data.0000"),
        dir.path().join("Mercury_out.data.0001"),
    )
    .unwrap();
    let base = dir.path().join("Mercury_out");
    let out = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("vtk")
        .arg(&base)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("Mercury_out.fstat.0001: missing (save 1 has ")
            && err.contains("--skip-incomplete"),
        "{err}"
    );
    assert!(!dir.path().join("Mercury_out.pvd").exists());
    let o = common::verdem_ok([
        "vtk".as_ref(),
        base.as_os_str(),
        "--skip-incomplete".as_ref(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning: save 1 skipped: ") && err.contains("Mercury_out.fstat.0001"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("1 saves written"));
    let pvd = std::fs::read_to_string(dir.path().join("Mercury_out.pvd")).unwrap();
    assert!(pvd.contains("Mercury_out.0000.vtu") && !pvd.contains("Mercury_out.0001.vtu"));
    assert!(!dir.path().join("Mercury_out.0001.vtu").exists());
}
