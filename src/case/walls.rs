//! `[[wall]]`: flat walls, infinite planes the spheres touch (LAMMPS `fix wall/gran`,
//! MercuryDPM `InfiniteWall`, Yade's `Wall`), and their checks.

use serde::Deserialize;

use super::locate::Locator;
use super::{Case, CaseError, Scene};

/// One `[[wall]]`: an infinite plane through `point` with the unit normal along `normal`,
/// pointing to the side the spheres are on, moving rigidly with `velocity`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// A point of the plane at the start (length).
    pub point: [f64; 3],
    /// Its normal, towards the spheres (any length but zero; normalised when built).
    pub normal: [f64; 3],
    /// Its constant velocity (length/time; default at rest).
    #[serde(default)]
    pub velocity: [f64; 3],
    /// The material it is made of: the case's material, the only one a case has today.
    #[serde(default)]
    pub material: Option<String>,
}

/// The material name a wall may give while a case has one material.
pub const CASE_MATERIAL: &str = "material";

impl WallSpec {
    /// The unit normal (finite and nonzero: checked with the case).
    pub fn unit_normal(&self) -> [f64; 3] {
        let [x, y, z] = self.normal;
        let norm = (x * x + y * y + z * z).sqrt();
        [x / norm, y / norm, z / norm]
    }
}

impl Case {
    /// Each wall's normal nonzero and its material the case's; every explicit free sphere on
    /// its side of every wall and touching it by no more than the run guard's overlap limit
    /// (`guard.overlap` times its radius).
    pub(super) fn check_walls(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        for (w, wall) in self.wall.iter().enumerate() {
            let field = |key: &str| format!("wall[{w}].{key}");
            let [x, y, z] = wall.normal;
            let norm = (x * x + y * y + z * z).sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return Err(at.error(
                    &field("normal"),
                    format!(
                        "a nonzero normal towards the spheres expected, got {:?} (length {norm})",
                        wall.normal
                    ),
                ));
            }
            let periodic = self.domain.periodic;
            if let Some(k) = (0..3).find(|&k| periodic[k] && wall.normal[k] != 0.0) {
                return Err(at.error(
                    &field("normal"),
                    format!(
                        "a wall across a periodic axis cuts every image of the box: a normal \
                         without a component along {} (periodic) expected, got {:?}",
                        ["x", "y", "z"][k],
                        wall.normal
                    ),
                ));
            }
            if let Some(m) = &wall.material {
                if m != CASE_MATERIAL {
                    return Err(at.error(
                        &field("material"),
                        format!(
                            "the case has one material, {CASE_MATERIAL:?} ([material]); got {m:?}"
                        ),
                    ));
                }
            }
            let Scene::Spheres { sphere } = &self.scene else {
                continue;
            };
            let n = wall.unit_normal();
            for (s, sp) in sphere.iter().enumerate().filter(|(_, s)| !s.fixed) {
                let r = sp.radius.unwrap_or(0.5 * self.material.diameter);
                let height: f64 = (0..3).map(|k| (sp.x[k] - wall.point[k]) * n[k]).sum();
                let limit = self.guard.overlap * r;
                if r - height > limit {
                    return Err(at.error(
                        &format!("scene.sphere[{s}].x"),
                        format!(
                            "a sphere on the spheres' side of wall[{w}] expected, overlapping it \
                             by at most {limit} (guard.overlap times its radius {r}); its centre \
                             is {height} from the wall along the normal, an overlap of {}",
                            r - height
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::case::Case;

    fn case_with(walls: &str) -> Result<Case, crate::case::CaseError> {
        let base = std::fs::read_to_string("cases/verify/binary_collision.toml").unwrap();
        Case::parse(&format!("{base}\n{walls}"), "walls.toml")
    }

    #[test]
    fn a_wall_is_read_with_its_normal_normalised_and_at_rest_by_default() {
        let case =
            case_with("[[wall]]\npoint = [0.0, 0.0, -1.0]\nnormal = [0.0, 0.0, 2.0]\n").unwrap();
        assert_eq!(case.wall.len(), 1);
        assert_eq!(case.wall[0].unit_normal(), [0.0, 0.0, 1.0]);
        assert_eq!(case.wall[0].velocity, [0.0; 3]);
    }

    #[test]
    fn a_zero_normal_is_refused_at_its_line() {
        let e = case_with("[[wall]]\npoint = [0.0, 0.0, -1.0]\nnormal = [0.0, 0.0, 0.0]\n")
            .unwrap_err();
        assert_eq!(e.field, "wall[0].normal");
        let text = std::fs::read_to_string("cases/verify/binary_collision.toml").unwrap();
        assert_eq!(e.line, text.lines().count() + 4, "{e}");
    }

    #[test]
    fn a_sphere_through_a_wall_and_another_material_are_refused() {
        // the spheres sit at x = ±0.5005: a wall at x = 0 facing +x cuts the first
        let e =
            case_with("[[wall]]\npoint = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n").unwrap_err();
        assert_eq!(e.field, "scene.sphere[0].x", "{e}");
        let e = case_with(
            "[[wall]]\npoint = [0.0, 0.0, -1.0]\nnormal = [0.0, 0.0, 1.0]\nmaterial = \"steel\"\n",
        )
        .unwrap_err();
        assert_eq!(e.field, "wall[0].material", "{e}");
        let e =
            case_with("[[wall]]\npoint = [0.0, 0.0, -1.0]\nnormal = [0.0, 0.0, 1.0]\nfoo = 1\n")
                .unwrap_err();
        assert!(e.to_string().contains("foo"), "{e}");
    }
}
