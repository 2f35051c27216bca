//! ParaView output: one VTK XML UnstructuredGrid file (`NAME.NNNN.vtu`) per save and a
//! `NAME.pvd` collection that lists them with their times, so a run opens as a time series.
//!
//! Written by hand in the ASCII flavour of the XML format ("VTK File Formats", VTK User's Guide,
//! section "XML File Formats"): every number in the shortest form that reads back to the same
//! f64, so a `.vtu` holds exactly what the `.data`/`.fstat` save holds.
//!
//! Layout of a `.vtu`: one point per particle, in id order (point k is the particle of `.fstat`
//! index k); point arrays `id` (0-based, as in `.fstat`), `radius`, `wall` (1 for a wall
//! sphere), `velocity`, `angular_velocity`. Cells: first one `vertex` per particle (cell k is
//! point k), then one `line` per contact, from the particle the force acts on to its partner.
//! Cell arrays `normal_force` and `tangential_force` are that force's normal and tangential
//! parts, and `periodic` is 1 for a contact across a periodic boundary (its line joins the two
//! centres across the box; ParaView's Threshold on `periodic` hides it); the vertex cells carry
//! zeros in all three. The `.vtu`'s field array `TimeValue` is the save's time.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use super::mercury::{DataFile, FstatFile};
use super::{fmt_f64, FormatError};
use crate::contact::PairInput;
use crate::state::{Motion, Snapshot};
use crate::Vec3;

/// One particle of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Particle {
    pub x: Vec3,
    pub v: Vec3,
    pub w: Vec3,
    pub radius: f64,
    pub wall: bool,
}

/// One contact of a frame: the force on particle `a` from particle `b`, split into its normal
/// and tangential parts.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactLine {
    pub a: usize,
    pub b: usize,
    pub normal: Vec3,
    pub tangential: Vec3,
    /// The two centres are further apart than the sum of the radii: the contact is through a
    /// periodic boundary.
    pub periodic: bool,
}

/// What one `.vtu` file shows: a save's time, particles and contacts.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub time: f64,
    pub particles: Vec<Particle>,
    pub contacts: Vec<ContactLine>,
}

impl Frame {
    /// The frame of a state: its particles (wall spheres are the prescribed ones) and the
    /// contacts of its last force evaluation that touch (as the `.fstat` save lists them).
    pub fn of_snapshot(core: &Snapshot) -> Frame {
        let p = &core.particles;
        let particles = (0..p.len())
            .map(|a| Particle {
                x: p.x[a],
                v: p.v[a],
                w: p.w[a],
                radius: p.radius[a],
                wall: p.motion[a] != Motion::Free,
            })
            .collect();
        let mut contacts = Vec::with_capacity(core.contacts.len());
        for c in &core.contacts {
            let (a, b) = (c.p as usize, c.i as usize);
            let touching = PairInput::at_rest(
                core.domain.min_image(p.x[a] - p.x[b]),
                p.radius[a],
                p.radius[b],
            )
            .kinematics();
            let Some(g) = touching else { continue };
            let normal = c.force.fn_signed * g.n;
            contacts.push(ContactLine {
                a,
                b,
                normal,
                tangential: c.force.f - normal,
                periodic: across_boundary(&p.x[a], &p.x[b], p.radius[a] + p.radius[b]),
            });
        }
        Frame {
            time: core.time,
            particles,
            contacts,
        }
    }

    /// The frame of a MercuryCG save: particles with index below `walls` are wall spheres; each
    /// contact once (the `.fstat` lists a free–free contact twice, the second time from its
    /// other side, which is skipped).
    pub fn of_mercury(data: &DataFile, fstat: &FstatFile, walls: usize) -> Frame {
        let particles: Vec<Particle> = data
            .rows
            .iter()
            .enumerate()
            .map(|(k, r)| Particle {
                x: r.x,
                v: r.v,
                w: r.w,
                radius: r.radius,
                wall: k < walls,
            })
            .collect();
        let mut seen = HashSet::new();
        let mut contacts = Vec::new();
        for r in &fstat.rows {
            if !seen.insert((r.i.min(r.j), r.i.max(r.j))) {
                continue;
            }
            let periodic = match (particles.get(r.i), particles.get(r.j)) {
                (Some(a), Some(b)) => across_boundary(&a.x, &b.x, a.radius + b.radius),
                _ => false,
            };
            contacts.push(ContactLine {
                a: r.i,
                b: r.j,
                normal: r.fn_signed * r.n,
                tangential: r.ft * r.t,
                periodic,
            });
        }
        Frame {
            time: data.time,
            particles,
            contacts,
        }
    }

    /// The first contact whose particle index is not one of the frame's particles, as
    /// `(a, b)`: such a frame has no `.vtu` (its lines would point nowhere).
    pub fn dangling_contact(&self) -> Option<(usize, usize)> {
        let n = self.particles.len();
        self.contacts
            .iter()
            .find(|c| c.a >= n || c.b >= n)
            .map(|c| (c.a, c.b))
    }
}

/// Two spheres in contact whose centres are further apart than the sum of their radii touch
/// through a periodic boundary.
fn across_boundary(a: &Vec3, b: &Vec3, radii: f64) -> bool {
    (a - b).norm_squared() >= radii * radii
}

/// Path of save `k`'s `.vtu` of the series `dir/name`: `dir/name.NNNN.vtu`.
pub fn vtu_path(dir: &Path, name: &str, k: u64) -> PathBuf {
    dir.join(vtu_name(name, k))
}

fn vtu_name(name: &str, k: u64) -> String {
    format!("{name}.{k:04}.vtu")
}

/// Path of the series' collection file: `dir/name.pvd`.
pub fn pvd_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.pvd"))
}

/// Appends `<DataArray …>values</DataArray>` with the values of `each` (one or three numbers
/// per item).
fn array<T>(
    s: &mut String,
    kind: &str,
    name: &str,
    components: usize,
    items: &[T],
    mut each: impl FnMut(&T, &mut Vec<f64>),
) {
    s.push_str(&format!(
        "        <DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"ascii\">\n         "
    ));
    let mut values = Vec::with_capacity(3);
    for item in items {
        values.clear();
        each(item, &mut values);
        for v in &values {
            s.push(' ');
            if kind == "Float64" {
                fmt_f64(s, *v);
            } else {
                s.push_str(&(*v as i64).to_string());
            }
        }
    }
    s.push_str("\n        </DataArray>\n");
}

/// One entry of a frame's cells: a particle's vertex or a contact's line.
enum Cell<'a> {
    Vertex(usize),
    Line(&'a ContactLine),
}

/// Text of the `.vtu` file of a frame (layout in the module's documentation).
pub fn vtu_text(frame: &Frame) -> String {
    let n = frame.particles.len();
    let cells: Vec<Cell> = (0..n)
        .map(Cell::Vertex)
        .chain(frame.contacts.iter().map(Cell::Line))
        .collect();
    let mut s = String::with_capacity(250 * n + 200 * frame.contacts.len() + 2000);
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    s.push_str("  <UnstructuredGrid>\n    <FieldData>\n");
    // field arrays need their tuple count (VTK's XML reader skips a field array without it)
    s.push_str("        <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">\n          ");
    fmt_f64(&mut s, frame.time);
    s.push_str("\n        </DataArray>\n    </FieldData>\n");
    s.push_str(&format!(
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">\n",
        cells.len()
    ));
    let p = &frame.particles;
    s.push_str("      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n");
    array(&mut s, "Int64", "id", 1, p, {
        let mut k = 0.0;
        move |_, o| {
            o.push(k);
            k += 1.0;
        }
    });
    array(&mut s, "Float64", "radius", 1, p, |q, o| o.push(q.radius));
    array(&mut s, "UInt8", "wall", 1, p, |q, o| {
        o.push(f64::from(u8::from(q.wall)))
    });
    array(&mut s, "Float64", "velocity", 3, p, |q, o| {
        o.extend(q.v.iter())
    });
    array(&mut s, "Float64", "angular_velocity", 3, p, |q, o| {
        o.extend(q.w.iter())
    });
    s.push_str("      </PointData>\n");
    s.push_str("      <CellData Vectors=\"normal_force\">\n");
    let vector = |pick: fn(&ContactLine) -> Vec3| {
        move |c: &Cell, o: &mut Vec<f64>| match c {
            Cell::Vertex(_) => o.extend([0.0; 3]),
            Cell::Line(l) => o.extend(pick(l).iter()),
        }
    };
    array(
        &mut s,
        "Float64",
        "normal_force",
        3,
        &cells,
        vector(|l| l.normal),
    );
    array(
        &mut s,
        "Float64",
        "tangential_force",
        3,
        &cells,
        vector(|l| l.tangential),
    );
    array(&mut s, "UInt8", "periodic", 1, &cells, |c, o| {
        o.push(match c {
            Cell::Line(l) if l.periodic => 1.0,
            _ => 0.0,
        })
    });
    s.push_str("      </CellData>\n      <Points>\n");
    array(&mut s, "Float64", "Points", 3, p, |q, o| {
        o.extend(q.x.iter())
    });
    s.push_str("      </Points>\n      <Cells>\n");
    array(&mut s, "Int64", "connectivity", 1, &cells, |c, o| match c {
        Cell::Vertex(k) => o.push(*k as f64),
        Cell::Line(l) => o.extend([l.a as f64, l.b as f64]),
    });
    array(&mut s, "Int64", "offsets", 1, &cells, {
        let mut end = 0.0;
        move |c, o| {
            end += if matches!(c, Cell::Vertex(_)) {
                1.0
            } else {
                2.0
            };
            o.push(end);
        }
    });
    // VTK cell types: 1 = VTK_VERTEX, 3 = VTK_LINE (vtkCellType.h)
    array(&mut s, "UInt8", "types", 1, &cells, |c, o| {
        o.push(if matches!(c, Cell::Vertex(_)) {
            1.0
        } else {
            3.0
        })
    });
    s.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// Text of a `.pvd` collection listing `(time, file name)` in order (the names relative to the
/// `.pvd`'s folder).
pub fn pvd_text(entries: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (time, file) in entries {
        s.push_str("    <DataSet timestep=\"");
        fmt_f64(&mut s, *time);
        s.push_str(&format!(
            "\" group=\"\" part=\"0\" file=\"{}\"/>\n",
            super::xml_escaped(file)
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// The VTK files of a series as it is written, save by save: each save's `.vtu`, then the
/// `.pvd` rewritten with every save so far (both atomically, [`super::atomic::write`]).
#[derive(Clone, Debug)]
pub struct Series {
    dir: PathBuf,
    name: String,
    entries: Vec<(u64, f64)>,
}

impl Series {
    /// A new series `dir/name` with no saves yet.
    pub fn new(dir: &Path, name: &str) -> Series {
        Series {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            entries: Vec::new(),
        }
    }

    /// The series `dir/name` continued after save `last` (a resumed run): the saves up to
    /// `last` that have a `.vtu` are kept in the `.pvd`, with the times of their `.data` saves.
    pub fn resume(dir: &Path, name: &str, last: u64) -> Result<Series, FormatError> {
        let mut series = Series::new(dir, name);
        for k in 0..=last {
            if !vtu_path(dir, name, k).exists() {
                continue;
            }
            let data = super::mercury::save_path(dir, name, "data", k);
            series.entries.push((k, data_time(&data)?));
        }
        Ok(series)
    }

    /// Writes save `k`'s `.vtu` and the `.pvd`; returns the `.vtu`'s path.
    pub fn write(&mut self, k: u64, frame: &Frame) -> std::io::Result<PathBuf> {
        let vtu = vtu_path(&self.dir, &self.name, k);
        super::atomic::write(&vtu, vtu_text(frame).as_bytes())?;
        self.entries.retain(|(j, _)| *j < k);
        self.entries.push((k, frame.time));
        let listed: Vec<(f64, String)> = self
            .entries
            .iter()
            .map(|(j, t)| (*t, vtu_name(&self.name, *j)))
            .collect();
        if let Err(e) = super::atomic::write(
            &pvd_path(&self.dir, &self.name),
            pvd_text(&listed).as_bytes(),
        ) {
            self.entries.pop();
            let _ = std::fs::remove_file(&vtu);
            return Err(e);
        }
        Ok(vtu)
    }
}

/// The time in the header of a `.data` file (its second number), read without the rest.
fn data_time(path: &Path) -> Result<f64, FormatError> {
    let mut lines = super::open(path)?;
    let head = lines
        .next_line()?
        .map_or(String::new(), |(_, l)| l.to_string());
    head.split_whitespace()
        .nth(1)
        .and_then(|t| t.parse::<f64>().ok())
        .filter(|t| t.is_finite())
        .ok_or_else(|| lines.error(1, "no time in the header"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        let particle = |x: f64, wall: bool| Particle {
            x: Vec3::new(x, 0.5, 1.0),
            v: Vec3::new(0.25, -1e-7, 3.0),
            w: Vec3::new(0.0, 1.0, 0.0),
            radius: 0.5,
            wall,
        };
        Frame {
            time: 1.5,
            particles: vec![particle(0.0, true), particle(0.9, false)],
            contacts: vec![ContactLine {
                a: 1,
                b: 0,
                normal: Vec3::new(2.0, 0.0, 0.0),
                tangential: Vec3::new(0.0, 0.0, -0.125),
                periodic: false,
            }],
        }
    }

    #[test]
    fn a_name_with_markup_is_escaped_in_the_collection() {
        let s = pvd_text(&[(0.5, vtu_name("a<b&c\"d", 3))]);
        assert!(s.contains("file=\"a&lt;b&amp;c&quot;d.0003.vtu\""), "{s}");
        assert!(!s.contains("a<b"), "{s}");
    }

    #[test]
    fn cells_are_the_vertices_then_the_contact_lines() {
        let s = vtu_text(&frame());
        assert!(
            s.contains("NumberOfPoints=\"2\" NumberOfCells=\"3\""),
            "{s}"
        );
        assert!(s.contains("Name=\"connectivity\" NumberOfComponents=\"1\" format=\"ascii\">\n          0 1 1 0\n"), "{s}");
        assert!(
            s.contains(
                "Name=\"offsets\" NumberOfComponents=\"1\" format=\"ascii\">\n          1 2 4\n"
            ),
            "{s}"
        );
        assert!(
            s.contains(
                "Name=\"types\" NumberOfComponents=\"1\" format=\"ascii\">\n          1 1 3\n"
            ),
            "{s}"
        );
        assert!(s.contains("0 0 0 0 0 0 2 0 0\n"), "{s}");
    }

    #[test]
    fn the_collection_lists_each_save_once_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let mut series = Series::new(dir.path(), "c");
        let mut f = frame();
        series.write(0, &f).unwrap();
        f.time = 2.5;
        series.write(1, &f).unwrap();
        series.write(1, &f).unwrap();
        let pvd = std::fs::read_to_string(pvd_path(dir.path(), "c")).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), 2, "{pvd}");
        let first = pvd.find("file=\"c.0000.vtu\"").unwrap();
        assert!(pvd[first..].contains("timestep=\"2.5\" group=\"\" part=\"0\" file=\"c.0001.vtu\""));
    }
}
