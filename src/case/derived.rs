//! Quantities derived from the parameters: a sphere's mass, the normal spring the keys give,
//! the collision time tc, the restitution e and the time step dt, and the check that a double
//! holds them.

use super::locate::Locator;
use super::{Case, CaseError, Scene};

/// The normal spring a case's keys give: `[contact] kn` a linear one; without it, `[material]
/// youngs` and `poisson` Hertz's. The normal law the case names must be built on it (the
/// contact layer checks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stiffness {
    /// F = kn·δ, kn in force/length.
    Linear { kn: f64 },
    /// F = (4/3)·E*·√R*·δ^{3/2}, E* (force/length²) of two spheres of the material.
    Hertz { e_star: f64 },
}

/// Hertz's elastic head-on collision at relative speed v lasts tc = HERTZ_TC_PER_DELTA·δmax/v:
/// from m*v²/2 = (8/15)E*√R*·δmax^{5/2} (energy), tc = 2∫₀^δmax dδ/δ̇ = 2(δmax/v)∫₀¹
/// dx/√(1 − x^{5/2}) = (4/5)·B(2/5, 1/2)·δmax/v = (4/5)·Γ(2/5)Γ(1/2)/Γ(9/10)·δmax/v (Johnson,
/// Contact Mechanics, 1985, §11.4, whose 2.87 is this times (15/16)^{2/5}).
pub const HERTZ_TC_PER_DELTA: f64 = 2.943_275_184_324_704_7;

impl Case {
    /// The normal spring the case's keys give ([`Stiffness`]): linear when `[contact] kn` is
    /// given or no elastic constants are (validation refuses a case with neither).
    pub fn stiffness(&self) -> Stiffness {
        match self.material.e_star() {
            Some(e_star) if !self.contact.given.has("kn") => Stiffness::Hertz { e_star },
            _ => Stiffness::Linear {
                kn: self.contact.kn,
            },
        }
    }

    /// The largest relative speed (length/time) two spheres of the scene can meet at, taken as
    /// the sum of the two largest speeds its spheres are listed with (fixed ones included),
    /// plus √(2·|g|·L) with gravity, L the box's longest side (what a fall across the box
    /// adds); `None` for a generated scene (bumpy shear, gas), which lists no velocities.
    pub fn largest_speed(&self) -> Option<f64> {
        let Scene::Spheres { sphere } = &self.scene else {
            return None;
        };
        let mut speeds: Vec<f64> = sphere
            .iter()
            .map(|s| s.v.iter().map(|c| c * c).sum::<f64>().sqrt())
            .collect();
        speeds.sort_by(|a, b| b.total_cmp(a));
        let listed: f64 = speeds.iter().take(2).sum();
        let fall = self.gravity().map_or(0.0, |g| {
            let g = g.iter().map(|c| c * c).sum::<f64>().sqrt();
            let l = (0..3)
                .map(|k| self.domain.hi[k] - self.domain.lo[k])
                .fold(0.0, f64::max);
            (2.0 * g * l).sqrt()
        });
        Some(listed + fall)
    }

    /// Hertz's largest overlap (length) of an elastic head-on collision of effective mass
    /// `meff` (mass), effective radius `r_star` (length) and modulus `e_star` (force/length²)
    /// at relative speed `speed` (length/time): δmax = (15·m*·v²/(16·E*·√R*))^{2/5} (Johnson,
    /// Contact Mechanics, 1985, §11.4).
    pub fn hertz_delta_max(meff: f64, r_star: f64, e_star: f64, speed: f64) -> f64 {
        // m*v²/2 = (8/15) E* √R* δmax^{5/2} (Johnson 1985, §11.4)
        (15.0 * meff * speed * speed / (16.0 * e_star * r_star.sqrt())).powf(0.4)
    }

    /// Hertz's contact time (time) of that collision, [`HERTZ_TC_PER_DELTA`]·δmax/v.
    pub fn hertz_collision_time(meff: f64, r_star: f64, e_star: f64, speed: f64) -> f64 {
        HERTZ_TC_PER_DELTA * Case::hertz_delta_max(meff, r_star, e_star, speed) / speed
    }

    /// Mass of one sphere, 4/3 π r³ ρ.
    pub fn particle_mass(&self) -> f64 {
        let r = 0.5 * self.material.diameter;
        4.0 / 3.0 * std::f64::consts::PI * r * r * r * self.material.density
    }

    /// Collision time of the linear spring–dashpot for effective mass `meff`,
    /// tc = π / √(kn/meff − (γn/(2 meff))²); `None` when overdamped.
    pub fn collision_time(&self, meff: f64) -> Option<f64> {
        let (kn, g) = (self.contact.kn, self.contact.gamman);
        // Evaluated as MercuryDPM does for the benchmark's dt: π/√(kn/meff − (γn/(2meff))²).
        let w2 = kn / meff - (g / (2.0 * meff)) * (g / (2.0 * meff));
        (w2 > 0.0).then(|| std::f64::consts::PI / w2.sqrt())
    }

    /// Free–free collision time (meff = m/2): of the linear spring–dashpot
    /// ([`Case::collision_time`]), or of Hertz's elastic spring between two spheres of the
    /// material's diameter (R* = d/4) at the scene's largest speed ([`Case::largest_speed`];
    /// `None` without one, or at rest). Hertz's damping is left out: it lengthens the contact.
    pub fn tc_free_free(&self) -> Option<f64> {
        let meff = 0.5 * self.particle_mass();
        match self.stiffness() {
            Stiffness::Linear { .. } => self.collision_time(meff),
            Stiffness::Hertz { e_star } => {
                let v = self.largest_speed().filter(|&v| v > 0.0)?;
                let r_star = 0.25 * self.material.diameter;
                Some(Case::hertz_collision_time(meff, r_star, e_star, v))
            }
        }
    }

    /// Normal restitution coefficient for effective mass `meff`, e = exp(−γn/(2 meff)·tc).
    pub fn restitution(&self, meff: f64) -> Option<f64> {
        self.collision_time(meff)
            .map(|tc| (-self.contact.gamman / (2.0 * meff) * tc).exp())
    }

    /// The time step: `dt` as given, or tc/steps_per_collision.
    pub fn dt(&self) -> f64 {
        match (self.run.dt, self.run.steps_per_collision) {
            (Some(dt), _) => dt,
            (None, Some(s)) => self.tc_free_free().expect("validated") / s,
            (None, None) => unreachable!("validated"),
        }
    }

    /// Refuses parameters whose derived quantities a double cannot hold: a sphere's mass, the
    /// collision time and the time step zero, subnormal or infinite, tc/dt not finite, or the
    /// elastic energy at the guard's overlap limit overflowing. Each error names the field
    /// the quantity comes from.
    pub(super) fn check_derived(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        self.check_spring(at)?;
        let representable = |v: f64| v.is_finite() && v >= f64::MIN_POSITIVE;
        let m = self.particle_mass();
        if !representable(m) {
            return Err(at.error(
                "material.density",
                format!(
                    "the sphere's mass 4/3 pi r^3 rho = {m:e} (diameter {}, density {}) is not \
                     a representable positive number",
                    self.material.diameter, self.material.density
                ),
            ));
        }
        let tc = self.tc_free_free();
        let hertz = match self.stiffness() {
            Stiffness::Hertz { e_star } => Some(e_star),
            Stiffness::Linear { .. } => None,
        };
        if let (Some(tc), Some(e_star)) = (tc.filter(|&tc| !representable(tc)), hertz) {
            return Err(at.error(
                "material.youngs",
                format!(
                    "Hertz's free–free collision time at the largest impact speed {:e} is                      {tc:e} (E* = {e_star:e}, meff = {:e}): not a representable positive number",
                    self.largest_speed().unwrap_or(0.0),
                    0.5 * m
                ),
            ));
        }
        if let Some(tc) = tc.filter(|&tc| !representable(tc)) {
            return Err(at.error(
                "contact.kn",
                format!(
                    "the free–free collision time pi/sqrt(kn/meff - (gamman/2meff)^2) = {tc:e} \
                     (kn = {:e}, meff = {:e}) is not a representable positive number",
                    self.contact.kn,
                    0.5 * m
                ),
            ));
        }
        let (_, largest) = self.largest_diameters();
        let reach = self.guard.overlap * 0.5 * largest;
        let elastic = match hertz {
            // (8/15) E* √R* δ^{5/2} (Johnson 1985), R* at most the largest radius
            Some(e_star) => 8.0 / 15.0 * e_star * (0.5 * largest * reach).sqrt() * reach * reach,
            None => 0.5 * self.contact.kn * reach * reach,
        };
        if let (false, Some(e_star)) = (elastic.is_finite(), hertz) {
            return Err(at.error(
                "material.youngs",
                format!(
                    "the elastic energy of Hertz's spring at the guard's overlap limit (delta = \
                     {reach:e}) overflows: E* = {e_star:e} is too stiff to be represented"
                ),
            ));
        }
        if !elastic.is_finite() {
            return Err(at.error(
                "contact.kn",
                format!(
                    "the elastic energy 1/2 kn delta^2 at the guard's overlap limit (delta = \
                     {reach:e}) overflows: kn = {:e} is too stiff to be represented",
                    self.contact.kn
                ),
            ));
        }
        let field = if self.run.dt.is_some() {
            "run.dt"
        } else if tc.is_some() {
            "run.steps_per_collision"
        } else {
            // No collision time to divide: refused next, as an over-damped contact.
            return Ok(());
        };
        let dt = self.dt();
        if !representable(dt) {
            return Err(at.error(
                field,
                format!("the time step dt = {dt:e} is not a representable positive number"),
            ));
        }
        if let Some(tc) = tc.filter(|tc| !(tc / dt).is_finite()) {
            return Err(at.error(field, format!("tc/dt = {tc:e}/{dt:e} is not finite")));
        }
        Ok(())
    }
}

impl Case {
    /// A normal spring the keys give: `[contact] kn`, or `[material] youngs` and `poisson`;
    /// with Hertz's, a scene that lists the spheres' velocities and moves at least one (the
    /// collision time and the stability limit depend on the impact speed).
    fn check_spring(&self, at: &Locator<'_>) -> Result<(), CaseError> {
        if !self.contact.given.has("kn") && self.material.elastic().is_none() {
            return Err(at.error(
                "contact.kn",
                "missing field `kn` (a linear spring's stiffness; a Hertz law takes \
                 material.youngs and material.poisson instead)"
                    .into(),
            ));
        }
        if let Stiffness::Linear { .. } = self.stiffness() {
            return Ok(());
        }
        match self.largest_speed() {
            None => Err(at.error(
                "scene.kind",
                "a Hertz spring's collision time and stability limit depend on the largest \
                 impact speed, which verdem takes from a `spheres` scene's listed velocities; \
                 a generated scene lists none (not supported yet)"
                    .into(),
            )),
            Some(v) if v <= 0.0 => Err(at.error(
                "scene.sphere",
                "no sphere moves and there is no gravity: a Hertz spring's collision time at \
                 the largest impact speed is unbounded; give a sphere a velocity"
                    .into(),
            )),
            Some(_) => Ok(()),
        }
    }
}

/// Volume of a sphere of diameter `d`, π d³/6.
pub(super) fn sphere_volume(d: f64) -> f64 {
    std::f64::consts::PI / 6.0 * d * d * d
}
