//! The time step against the scheme's stability limit for the contacts the scene can have
//! (`stability`), and the warning about a coarse one.

use super::derived::sphere_volume;
use super::locate::Locator;
use super::{Case, CaseError, Scene};
use crate::stability::{self, Direction, Limit, Pair, Spring};

/// Steps per free–free collision time below which a case is accepted with a warning naming the
/// expected restitution error.
pub const COARSE_STEPS_PER_COLLISION: f64 = 10.0;

impl Case {
    /// Refuses a time step beyond the stability limit of the stiffest contact the scene can
    /// have; warns about a coarse one (tc/dt below [`COARSE_STEPS_PER_COLLISION`]).
    pub(super) fn check_time_step(&self, at: &Locator<'_>) -> Result<Vec<String>, CaseError> {
        let field = self.run.dt_field();
        let dt = self.dt();
        let Some(limit) = self.stability_limit() else {
            return Ok(Vec::new());
        };
        // An over-damped contact has no collision time: the limit is stated as a dt only.
        let Some(tc) = self.tc_free_free() else {
            if dt > limit.dt {
                return Err(at.error(
                    field,
                    format!(
                        "at most the stability limit of the {} contact, dt = {:.5e} \
                         (docs/stability.md) expected, got dt = {dt:.5e}",
                        limit.contact(),
                        limit.dt,
                    ),
                ));
            }
            return Ok(vec![at
                .error(
                    "contact.gamman",
                    format!(
                        "over-damped contact: gamman = {} leaves no oscillation, so colliding \
                         spheres do not rebound (with clip_normal = false the dashpot also pulls \
                         them together as they part)",
                        self.contact.gamman
                    ),
                )
                .to_string()]);
        };
        if dt > limit.dt {
            return Err(at.error(
                field,
                format!(
                    "at most the stability limit of the {} contact, dt = {:.5e} (tc/dt = {:.4}; \
                     docs/stability.md) expected, got dt = {dt:.5e} (tc/dt = {:.4})",
                    limit.contact(),
                    limit.dt,
                    tc / limit.dt,
                    tc / dt
                ),
            ));
        }
        let per_tc = tc / dt;
        if per_tc >= COARSE_STEPS_PER_COLLISION * (1.0 - 1e-12) {
            return Ok(Vec::new());
        }
        let normal = stability::Spring {
            k: self.contact.kn,
            gamma: self.contact.gamman,
        };
        let errors: Vec<String> = self
            .pairs()
            .into_iter()
            .map(|(pair, meff)| {
                format!(
                    "{:.1e} {}",
                    stability::restitution_error(meff, normal, dt),
                    pair.name()
                )
            })
            .collect();
        let warning = at.error(
            field,
            format!(
                "coarse time step, tc/dt = {per_tc:.3} (below {COARSE_STEPS_PER_COLLISION}): \
                 relative restitution error up to {} (verdem's scheme run on one head-on \
                 collision, worst onset within a step; docs/stability.md)",
                errors.join(", ")
            ),
        );
        Ok(vec![warning.to_string()])
    }

    /// The contacts the scene can have, each with its normal effective mass (mass): free–free
    /// with two or more free spheres (the two lightest), free–wall with wall spheres (the
    /// lightest free sphere). The material's diameter stands for the spheres of an initial
    /// file.
    pub fn pairs(&self) -> Vec<(Pair, f64)> {
        let m = self.particle_mass();
        let (free, walls) = match &self.scene {
            Scene::BumpyShear { free, .. } => (vec![m; (*free).min(2)], true),
            Scene::Gas { count, .. } => (vec![m; (*count).min(2)], false),
            Scene::Spheres { sphere } => {
                let density = self.material.density;
                let d = self.material.diameter;
                let mut free: Vec<f64> = sphere
                    .iter()
                    .filter(|s| !s.fixed)
                    .map(|s| sphere_volume(2.0 * s.radius.unwrap_or(0.5 * d)) * density)
                    .collect();
                free.sort_by(f64::total_cmp);
                (free, sphere.iter().any(|s| s.fixed))
            }
        };
        let mut pairs = Vec::new();
        if let [m1, m2, ..] = free[..] {
            pairs.push((Pair::FreeFree, m1 * m2 / (m1 + m2)));
        }
        if let (true, Some(&m)) = (walls, free.first()) {
            pairs.push((Pair::FreeWall, m));
        }
        pairs
    }

    /// The stability limit of every contact the scene can have ([`Case::pairs`]): normal, and
    /// tangential when mu > 0.
    pub fn stability_limits(&self) -> Vec<Limit> {
        let c = &self.contact;
        let normal = Spring {
            k: c.kn,
            gamma: c.gamman,
        };
        let tangential = Spring {
            k: c.kt,
            gamma: c.gammat,
        };
        let mut limits = Vec::new();
        for (pair, meff) in self.pairs() {
            limits.push(Limit::of(pair, Direction::Normal, meff, normal));
            if c.mu > 0.0 {
                limits.push(Limit::of(pair, Direction::Tangential, meff, tangential));
            }
        }
        limits
    }

    /// The smallest of [`Case::stability_limits`], `None` when the scene has no contact; of
    /// limits equal to round-off (kt/kn = γt/γn = 2/7 makes the tangential one the normal
    /// one), the first: normal before tangential, free–free before free–wall.
    pub fn stability_limit(&self) -> Option<Limit> {
        self.stability_limits().into_iter().reduce(|best, l| {
            if l.dt < best.dt * (1.0 - 1e-12) {
                l
            } else {
                best
            }
        })
    }
}
