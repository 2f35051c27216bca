//! The time step against the scheme's stability limit for the contacts the scene can have
//! (`stability`), and the warning about a coarse one.

use super::derived::{sphere_volume, Stiffness};
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
        if let Stiffness::Hertz { .. } = self.stiffness() {
            let warning = at.error(
                field,
                format!(
                    "coarse time step, tc/dt = {per_tc:.3} (below {COARSE_STEPS_PER_COLLISION}) \
                     for Hertz's free–free collision at the largest impact speed \
                     (`verdem verify`'s Hertz rows measure the error this costs)"
                ),
            );
            return Ok(vec![warning.to_string()]);
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
    /// tangential when mu > 0. A Hertz spring's normal stiffness is taken at its stiffest, the
    /// tangent Sn = 2E*√(R*·δmax) at the largest impact speed ([`Case::largest_speed`]) with
    /// the pair's largest R* ([`Case::hertz_radius`]), the heaviest damping the case's dashpot
    /// and restitution give it ([`Case::hertz_spring`]).
    pub fn stability_limits(&self) -> Vec<Limit> {
        let c = &self.contact;
        let tangential = Spring {
            k: c.kt,
            gamma: c.gammat,
        };
        let mut limits = Vec::new();
        for (pair, meff) in self.pairs() {
            let normal = match self.stiffness() {
                Stiffness::Linear { kn } => Spring {
                    k: kn,
                    gamma: c.gamman,
                },
                Stiffness::Hertz { e_star } => self.hertz_spring(pair, meff, e_star),
            };
            limits.push(Limit::of(pair, Direction::Normal, meff, normal));
            if c.mu > 0.0 {
                limits.push(Limit::of(pair, Direction::Tangential, meff, tangential));
            }
        }
        limits
    }

    /// The linear spring that stands for a Hertz contact of kind `pair` (effective mass `meff`,
    /// modulus `e_star`) at its stiffest: k = Sn = 2E*√(R*·δmax) at the scene's largest impact
    /// speed and the pair's largest R*, and γ = γn + 2ζ√(k·meff) with ζ = −ln e/√(ln² e + π²)
    /// for a restitution e (the damping ratio that gives e to a linear spring, for the dampings
    /// set from one), the larger the damping the smaller the limit (`stability::critical_dt`).
    pub fn hertz_spring(&self, pair: Pair, meff: f64, e_star: f64) -> Spring {
        let r_star = self.hertz_radius(pair);
        let v = self.largest_speed().unwrap_or(0.0);
        let delta = Case::hertz_delta_max(meff, r_star, e_star, v);
        // Sn = 2 E* √(R* δ) (Johnson 1985, §4.2)
        let k = 2.0 * e_star * (r_star * delta).sqrt();
        let zeta = self.contact.restitution.map_or(0.0, |e| {
            let ln_e = e.ln();
            -ln_e / (ln_e * ln_e + std::f64::consts::PI * std::f64::consts::PI).sqrt()
        });
        Spring {
            k,
            gamma: self.contact.gamman + 2.0 * zeta * (k * meff).sqrt(),
        }
    }

    /// The largest effective radius R* = r₁r₂/(r₁ + r₂) (length) of a `pair` contact the scene
    /// can have: of its two largest free spheres, or of its largest free and largest wall
    /// sphere (the material's diameter for a sphere without a radius).
    pub fn hertz_radius(&self, pair: Pair) -> f64 {
        let d = self.material.diameter;
        let (mut free, mut wall) = (Vec::new(), Vec::new());
        if let Scene::Spheres { sphere } = &self.scene {
            for s in sphere {
                let r = s.radius.unwrap_or(0.5 * d);
                if s.fixed {
                    wall.push(r)
                } else {
                    free.push(r)
                }
            }
        }
        free.sort_by(|a, b| b.total_cmp(a));
        let big = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.5 * d);
        let wall_max = wall
            .iter()
            .copied()
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let (r1, r2) = match pair {
            Pair::FreeFree => (big(&free, 0), big(&free, 1)),
            Pair::FreeWall => (
                big(&free, 0),
                if wall.is_empty() { 0.5 * d } else { wall_max },
            ),
        };
        r1 * r2 / (r1 + r2)
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
