//! Tiled bumpy-shear cases: the benchmark cell repeated nx × ny times in x–y (same gap, walls
//! tiled with the cell) and a state tiled from a save of the cell, for timing against system
//! size (`verdem tile`, `verdem bench --scale`).
//!
//! Ids of the tiled state follow the convention every reader in verdem identifies walls by
//! (`scene::build`, `analysis::cg`): the bottom wall's spheres first (every tile's), then the top
//! wall's, then the free spheres; within each group tile after tile (x fastest), each tile in
//! the order of the cell.

use std::path::{Path, PathBuf};

use super::SceneError;
use crate::case::{Case, Scene as SceneSpec};
use crate::contact::named;
use crate::io::{atomic, mercury};
use crate::state::{Domain, Motion, Particles, Snapshot};
use crate::Vec3;

/// The name of the tiled case of `name`: `NAME_NXxNY`.
pub fn tiled_name(name: &str, nx: usize, ny: usize) -> String {
    format!("{name}_{nx}x{ny}")
}

/// The state `s` of one cell tiled `nx` × `ny` times in x–y: the box's x and y lengths
/// multiplied, tile (i, j) shifted by (i Lx, j Ly, 0), ids as the module says. Every particle
/// keeps its velocity, spin, radius and motion (its mass from `density`, mass/length³); contacts are not carried (a run re-finds them).
/// The x and y axes of `s` must be periodic: the cell's periodic images become the tiles.
pub fn tile_state(
    s: &Snapshot,
    density: f64,
    nx: usize,
    ny: usize,
) -> Result<Snapshot, SceneError> {
    if nx == 0 || ny == 0 {
        return Err(SceneError::NoTiles { nx, ny });
    }
    let spheres = s.particles.len() as f64 * nx as f64 * ny as f64;
    // The tiled state, its `.data` text (~200 bytes a sphere) and the run that follows.
    crate::state::memory::check(
        &format!(
            "tiles {nx} × {ny} of {} spheres ({spheres:.3e} spheres)",
            s.particles.len()
        ),
        spheres * (crate::state::memory::BYTES_PER_SPHERE + 200.0),
    )?;
    if !(s.domain.periodic[0] && s.domain.periodic[1]) {
        return Err(SceneError::NotPeriodic {
            periodic: s.domain.periodic,
        });
    }
    let l = s.domain.lengths();
    let lo = s.domain.lo;
    let hi = Vec3::new(
        lo.x + nx as f64 * l.x,
        lo.y + ny as f64 * l.y,
        s.domain.hi.z,
    );
    let p = &s.particles;
    // wall groups in order (0 bottom, 1 top, …), then the free spheres
    let mut groups: Vec<u8> = p
        .motion
        .iter()
        .filter_map(|m| match m {
            Motion::Prescribed(g) => Some(*g),
            Motion::Free => None,
        })
        .collect();
    groups.sort_unstable();
    groups.dedup();
    let order: Vec<Motion> = groups
        .into_iter()
        .map(Motion::Prescribed)
        .chain([Motion::Free])
        .collect();
    let mut out = Particles::default();
    for kind in order {
        for j in 0..ny {
            for i in 0..nx {
                let shift = Vec3::new(i as f64 * l.x, j as f64 * l.y, 0.0);
                for a in (0..p.len()).filter(|&a| p.motion[a] == kind) {
                    out.push(p.x[a] + shift, p.v[a], p.w[a], p.radius[a], density, kind);
                }
            }
        }
    }
    Ok(Snapshot {
        step: 0,
        time: s.time,
        domain: Domain::new(lo, hi, s.domain.periodic),
        particles: out,
        contacts: Vec::new(),
        walls: Vec::new(),
        wall_contacts: Vec::new(),
    })
}

/// The text of the tiled case of the bumpy-shear case file `text` (named `file` in errors): its
/// name [`tiled_name`], its box's x and y lengths times `nx` and `ny`, `nx·ny` times the free
/// spheres, the walls' spheres per row times `nx` and rows times `ny` (rows come in pairs, so
/// the hexagonal pattern continues across the seam), and `run.init` the state file `init`
/// (relative to the case file). Every other key is kept; comments are not.
pub fn tile_case_text(
    text: &str,
    file: &str,
    nx: usize,
    ny: usize,
    init: &str,
) -> Result<String, SceneError> {
    let case = Case::parse(text, file)?;
    let SceneSpec::BumpyShear {
        free,
        wall_rows,
        wall_per_row,
        ..
    } = case.scene
    else {
        return Err(not_tileable(
            file,
            "scene.kind",
            "tiles are made of bumpy-shear cases".into(),
        ));
    };
    if wall_rows % 2 != 0 && ny > 1 {
        return Err(not_tileable(
            file,
            "scene.wall_rows",
            format!(
                "an even number of rows continues the hexagonal walls across tiles in y, got \
                 {wall_rows}"
            ),
        ));
    }
    let mut t: toml::Table = toml::from_str(text).map_err(|source| SceneError::Toml {
        file: file.to_string(),
        source,
    })?;
    let table = |t: &mut toml::Table, key: &str| -> Result<toml::Table, SceneError> {
        match t.remove(key) {
            Some(toml::Value::Table(x)) => Ok(x),
            None => Ok(toml::Table::new()),
            Some(_) => Err(not_tileable(file, key, "a table expected".into())),
        }
    };
    let (lo, hi) = (case.domain.lo, case.domain.hi);
    let mut domain = table(&mut t, "domain")?;
    domain.insert(
        "hi".into(),
        toml::Value::Array(
            [
                lo[0] + nx as f64 * (hi[0] - lo[0]),
                lo[1] + ny as f64 * (hi[1] - lo[1]),
                hi[2],
            ]
            .map(toml::Value::Float)
            .to_vec(),
        ),
    );
    let mut scene = table(&mut t, "scene")?;
    let count = |n: usize| toml::Value::Integer(n as i64);
    scene.insert("free".into(), count(free * nx * ny));
    scene.insert("wall_rows".into(), count(wall_rows * ny));
    scene.insert("wall_per_row".into(), count(wall_per_row * nx));
    let mut run = table(&mut t, "run")?;
    run.insert("init".into(), toml::Value::String(init.into()));
    t.insert(
        "name".into(),
        toml::Value::String(tiled_name(&case.name, nx, ny)),
    );
    t.insert("run".into(), toml::Value::Table(run));
    t.insert("domain".into(), toml::Value::Table(domain));
    t.insert("scene".into(), toml::Value::Table(scene));
    let body = toml::to_string(&t).map_err(SceneError::TomlWrite)?;
    let out = format!("# {file} tiled {nx} × {ny} in x–y by `verdem tile`; state {init}\n{body}");
    Case::parse(&out, file).map_err(|source| SceneError::TiledInvalid {
        file: file.to_string(),
        source,
    })?;
    Ok(out)
}

/// The error of a case `file` that cannot be tiled: its `field` and why.
fn not_tileable(file: &str, field: &str, msg: String) -> SceneError {
    SceneError::NotTileable {
        file: file.to_string(),
        field: field.to_string(),
        msg,
    }
}

/// Writes the case `case_path` tiled `nx` × `ny` from the state file `from` (a MercuryCG `.data`
/// save or the official file, read as the case reads its `run.init`) into `out`:
/// `NAME_NXxNY.toml` and its state `NAME_NXxNY.data`. Returns the two paths.
pub fn write(
    case_path: &Path,
    from: &Path,
    nx: usize,
    ny: usize,
    out: &Path,
) -> Result<(PathBuf, PathBuf), SceneError> {
    let case = named::load(case_path)?;
    let (_, text) = crate::io::read_text(case_path)?;
    let name = tiled_name(&case.name, nx, ny);
    let data = format!("{name}.data");
    let case_text = tile_case_text(&text, &case_path.display().to_string(), nx, ny, &data)?;
    let scene = crate::scene::build(&case, Some(from))?;
    let cell = Snapshot {
        step: 0,
        time: scene.time,
        domain: scene.domain,
        particles: scene.particles,
        contacts: Vec::new(),
        walls: Vec::new(),
        wall_contacts: Vec::new(),
    };
    let tiled =
        tile_state(&cell, case.material.density, nx, ny).map_err(|e| SceneError::CannotTile {
            path: case_path.to_path_buf(),
            source: Box::new(e),
        })?;
    std::fs::create_dir_all(out).map_err(|source| SceneError::Folder {
        path: out.to_path_buf(),
        source,
    })?;
    let (case_out, data_out) = (out.join(format!("{name}.toml")), out.join(&data));
    atomic::write(&data_out, mercury::data_text(&tiled).as_bytes()).map_err(SceneError::Write)?;
    atomic::write(&case_out, case_text.as_bytes()).map_err(SceneError::Write)?;
    Ok((case_out, data_out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell() -> Snapshot {
        let mut p = Particles::default();
        let z = Vec3::zeros();
        p.push(
            Vec3::new(0.5, 0.5, 0.5),
            z,
            z,
            0.5,
            1.0,
            Motion::Prescribed(0),
        );
        p.push(
            Vec3::new(1.0, 1.0, 3.0),
            Vec3::new(0.1, 0.2, 0.3),
            z,
            0.5,
            1.0,
            Motion::Free,
        );
        p.push(
            Vec3::new(0.5, 0.5, 5.5),
            z,
            z,
            0.5,
            1.0,
            Motion::Prescribed(1),
        );
        Snapshot {
            step: 7,
            time: 2.5,
            domain: Domain::new(z, Vec3::new(2.0, 3.0, 6.0), [true, true, false]),
            particles: p,
            contacts: Vec::new(),
            walls: Vec::new(),
            wall_contacts: Vec::new(),
        }
    }

    #[test]
    fn tiles_put_walls_first_by_group_and_shift_by_whole_cells() {
        let t = tile_state(&cell(), 1.0, 2, 3).unwrap();
        let p = &t.particles;
        assert_eq!(p.len(), 18);
        assert_eq!(t.domain.hi, Vec3::new(4.0, 9.0, 6.0));
        assert_eq!(t.time, 2.5);
        let kinds: Vec<Motion> = p.motion.clone();
        assert!(kinds[..6].iter().all(|m| *m == Motion::Prescribed(0)));
        assert!(kinds[6..12].iter().all(|m| *m == Motion::Prescribed(1)));
        assert!(kinds[12..].iter().all(|m| *m == Motion::Free));
        // tile (1, 2) of the bottom wall is its sixth: x + 2, y + 6
        assert_eq!(p.x[5], Vec3::new(2.5, 6.5, 0.5));
        assert_eq!(p.x[13], Vec3::new(3.0, 1.0, 3.0));
        assert_eq!(p.v[17], Vec3::new(0.1, 0.2, 0.3));
    }

    #[test]
    fn a_box_closed_in_x_cannot_be_tiled() {
        let mut c = cell();
        c.domain.periodic = [false, true, false];
        assert!(tile_state(&c, 1.0, 2, 1).is_err());
        assert!(tile_state(&cell(), 1.0, 0, 1).is_err());
    }

    #[test]
    fn the_tiled_case_scales_box_walls_and_free_spheres() {
        let text = std::fs::read_to_string("cases/shear_flow_steady.toml").unwrap();
        let out = tile_case_text(&text, "steady.toml", 4, 2, "s.data").unwrap();
        let c = Case::parse(&out, "t").unwrap();
        assert_eq!(c.name, "shear_flow_steady_4x2");
        assert_eq!(c.domain.hi, [80.0, 2.0 * 10.3923048454133, 22.0]);
        assert_eq!(c.run.init.as_deref(), Some("s.data"));
        let SceneSpec::BumpyShear {
            free,
            wall_rows,
            wall_per_row,
            ..
        } = c.scene
        else {
            panic!("bumpy shear expected");
        };
        assert_eq!((free, wall_rows, wall_per_row), (3000 * 8, 24, 80));
        let orig = Case::parse(&text, "s").unwrap();
        assert_eq!(c.contact, orig.contact);
        assert_eq!(c.dt(), orig.dt());
    }
}
