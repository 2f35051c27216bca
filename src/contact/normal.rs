//! Normal force models. Sign convention: the returned force is the signed normal force on P
//! along n (n from I to P); positive is repulsive.

/// A normal force model: signed normal force from the overlap δ > 0 and the normal relative
/// velocity vn = (v_P − v_I)·n at the contact point (negative while approaching).
pub trait NormalModel: Send + Sync {
    /// The signed normal force on P along n (force units; positive repulsive) for the overlap
    /// `delta` (length, > 0) and the normal relative velocity `vn` (length/time).
    fn force(&self, delta: f64, vn: f64) -> f64;

    /// Elastic energy stored at overlap `delta` (length, > 0), in energy units: what the spring
    /// can give back; the dashpot stores none.
    fn stored_energy(&self, delta: f64) -> f64;

    /// Whether [`NormalModel::dissipated`] is implemented (false by default: the law's
    /// dissipation is then not split).
    const SPLITS_DISSIPATION: bool = false;

    /// The energy (energy units) the non-elastic part of the force `fn_signed` (this model's at
    /// `delta`, `vn`) takes from the pair over a step `dt` (time) at the normal relative
    /// velocity `vn`: −(fn − fn_elastic)·vn·dt. Zero by default (not split).
    fn dissipated(&self, _delta: f64, _vn: f64, _fn_signed: f64, _dt: f64) -> f64 {
        0.0
    }
}

/// Linear spring with an absolute dashpot, fn = kn·δ − γn·vn (force units; γn in mass/time,
/// not scaled by the effective mass). Source: MercuryDPM `LinearViscoelasticNormalSpecies`.
/// The attractive tail at the end of a collision is kept (MercuryDPM does not clip); wrap it in
/// [`Clipped`] to remove it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearSpringDashpot {
    pub kn: f64,
    pub gamman: f64,
}

impl NormalModel for LinearSpringDashpot {
    #[inline(always)]
    fn force(&self, delta: f64, vn: f64) -> f64 {
        self.kn * delta - self.gamman * vn
    }

    /// ½·kn·δ², the potential of the linear spring.
    fn stored_energy(&self, delta: f64) -> f64 {
        0.5 * self.kn * delta * delta
    }

    const SPLITS_DISSIPATION: bool = true;

    /// γn·vn²·dt: the dashpot's force −γn·vn against the velocity vn.
    #[inline(always)]
    fn dissipated(&self, _delta: f64, vn: f64, _fn_signed: f64, dt: f64) -> f64 {
        self.gamman * vn * vn * dt
    }
}

/// Wraps a normal model and clips its attractive part: max(fn, 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clipped<N>(pub N);

impl<N: NormalModel> NormalModel for Clipped<N> {
    #[inline(always)]
    fn force(&self, delta: f64, vn: f64) -> f64 {
        self.0.force(delta, vn).max(0.0)
    }

    /// The wrapped model's: clipping acts on the dashpot's pull at the end of a collision,
    /// while the spring itself still holds ½·kn·δ².
    fn stored_energy(&self, delta: f64) -> f64 {
        self.0.stored_energy(delta)
    }

    const SPLITS_DISSIPATION: bool = N::SPLITS_DISSIPATION;

    /// The wrapped model's while the force is not clipped; clipped to zero, the non-elastic part
    /// is minus the elastic force, taken as the wrapped force at vn = 0 (a dashpot gives no
    /// force at rest), so the energy taken is fn_elastic·vn·dt.
    #[inline(always)]
    fn dissipated(&self, delta: f64, vn: f64, _fn_signed: f64, dt: f64) -> f64 {
        let unclipped = self.0.force(delta, vn);
        if unclipped >= 0.0 {
            self.0.dissipated(delta, vn, unclipped, dt)
        } else {
            self.0.force(delta, 0.0) * vn * dt
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dashpot_is_absolute_and_tail_is_kept_unless_clipped() {
        let m = LinearSpringDashpot {
            kn: 2e5,
            gamman: 15.0,
        };
        assert_eq!(m.force(1e-3, -1.0), 200.0 + 15.0);
        assert!(m.force(1e-6, 1.0) < 0.0);
        assert_eq!(Clipped(m).force(1e-6, 1.0), 0.0);
    }
}
