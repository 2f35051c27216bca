//! Quantities derived from the parameters: a sphere's mass, the collision time tc, the
//! restitution e and the time step dt, and the check that a double holds them.

use super::locate::Locator;
use super::{Case, CaseError};

impl Case {
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

    /// Free–free collision time (meff = m/2).
    pub fn tc_free_free(&self) -> Option<f64> {
        self.collision_time(0.5 * self.particle_mass())
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
        let elastic = 0.5 * self.contact.kn * reach * reach;
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

/// Volume of a sphere of diameter `d`, π d³/6.
pub(super) fn sphere_volume(d: f64) -> f64 {
    std::f64::consts::PI / 6.0 * d * d * d
}
