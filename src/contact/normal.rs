//! Normal force models. Sign convention: the returned force is the signed normal force on P
//! along n (n from I to P); positive is repulsive.
//!
//! A law is a [`NormalModel`]. The benchmark's is [`LinearSpringDashpot`], kept as one part;
//! the others are a [`Spring`] (the elastic force from the overlap and the effective radius)
//! times a [`Damping`] (the dashpot coefficient γn it puts against the normal velocity), composed
//! as [`Damped`]: fn = f_spring(δ, R*) − γn·vn. A spring is one file of `normal_laws/`, a damping
//! another; a law of them is one line of the `normal_laws!` table.

use super::PairKinematics;

/// A normal force model: signed normal force from a contact's overlap δ > 0, normal relative
/// velocity vn = (v_P − v_I)·n at the contact point (negative while approaching), effective
/// radius R* and effective mass m* ([`PairKinematics`]).
pub trait NormalModel: Send + Sync {
    /// The signed normal force on P along n (force units; positive repulsive) of the contact
    /// `k` (its overlap `k.delta` > 0, normal velocity `k.vn`, R* and m*).
    fn force(&self, k: &PairKinematics) -> f64;

    /// Elastic energy stored at overlap `delta` (length, > 0) for the effective radius
    /// `r_star` (length), in energy units: what the spring can give back; the dashpot stores
    /// none.
    fn stored_energy(&self, delta: f64, r_star: f64) -> f64;

    /// Whether [`NormalModel::dissipated`] is implemented (false by default: the law's
    /// dissipation is then not split).
    const SPLITS_DISSIPATION: bool = false;

    /// The energy (energy units) the non-elastic part of the force `fn_signed` (this model's for
    /// the contact `k`) takes from the pair over a step `dt` (time) at the normal relative
    /// velocity `k.vn`: −(fn − fn_elastic)·vn·dt. Zero by default (not split).
    fn dissipated(&self, _k: &PairKinematics, _fn_signed: f64, _dt: f64) -> f64 {
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
    fn force(&self, k: &PairKinematics) -> f64 {
        self.kn * k.delta - self.gamman * k.vn
    }

    /// ½·kn·δ², the potential of the linear spring.
    fn stored_energy(&self, delta: f64, _r_star: f64) -> f64 {
        0.5 * self.kn * delta * delta
    }

    const SPLITS_DISSIPATION: bool = true;

    /// γn·vn²·dt: the dashpot's force −γn·vn against the velocity vn.
    #[inline(always)]
    fn dissipated(&self, k: &PairKinematics, _fn_signed: f64, dt: f64) -> f64 {
        self.gamman * k.vn * k.vn * dt
    }
}

/// The elastic part of a normal law: a force that depends on the overlap and the effective
/// radius alone, and its potential.
pub trait Spring: Send + Sync + Clone {
    /// The factor c of the restitution damping γn = −2·c·β·√(S·m*) ([`Damping`] of
    /// `normal_laws/restitution.rs`, S the spring's [`Spring::stiffness`]): 1 for the linear
    /// spring, whose e is then exact; √(5/6) for Hertz's (LIGGGHTS `normal_model_hertz.h`).
    const RESTITUTION_FACTOR: f64;

    /// The elastic force (force units, repulsive positive) at overlap `delta` (length, > 0) for
    /// the effective radius `r_star` (length).
    fn force(&self, delta: f64, r_star: f64) -> f64;

    /// Its tangent stiffness dF/dδ (force/length) at `delta` and `r_star`.
    fn stiffness(&self, delta: f64, r_star: f64) -> f64;

    /// Its potential ∫₀^δ F dδ (energy units) at `delta` and `r_star`.
    fn energy(&self, delta: f64, r_star: f64) -> f64;
}

/// The dissipative part of a normal law: the dashpot coefficient γn (mass/time) it puts against
/// the normal relative velocity, fn = f_spring − γn·vn.
pub trait Damping: Send + Sync + Clone {
    /// γn (mass/time, ≥ 0) of the contact `k` whose spring `spring` gives the elastic force
    /// `elastic` (force units) at `k.delta`.
    fn gamma<S: Spring>(&self, spring: &S, elastic: f64, k: &PairKinematics) -> f64;
}

/// A spring and a damping composed into a normal law: fn = f_spring(δ, R*) − γn·vn. Not
/// clipped (wrap it in [`Clipped`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Damped<S, D> {
    pub spring: S,
    pub damping: D,
}

impl<S: Spring, D: Damping> NormalModel for Damped<S, D> {
    #[inline(always)]
    fn force(&self, k: &PairKinematics) -> f64 {
        let elastic = self.spring.force(k.delta, k.r_star());
        elastic - self.damping.gamma(&self.spring, elastic, k) * k.vn
    }

    fn stored_energy(&self, delta: f64, r_star: f64) -> f64 {
        self.spring.energy(delta, r_star)
    }

    const SPLITS_DISSIPATION: bool = true;

    /// γn·vn²·dt: the dashpot's force −γn·vn against the velocity vn.
    #[inline(always)]
    fn dissipated(&self, k: &PairKinematics, _fn_signed: f64, dt: f64) -> f64 {
        let elastic = self.spring.force(k.delta, k.r_star());
        self.damping.gamma(&self.spring, elastic, k) * k.vn * k.vn * dt
    }
}

/// The linear spring F = kn·δ (kn in force/length), as a part for the dampings other than the
/// absolute one (which [`LinearSpringDashpot`] is with it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear {
    pub kn: f64,
}

impl Spring for Linear {
    const RESTITUTION_FACTOR: f64 = 1.0;

    #[inline(always)]
    fn force(&self, delta: f64, _r_star: f64) -> f64 {
        self.kn * delta
    }

    #[inline(always)]
    fn stiffness(&self, _delta: f64, _r_star: f64) -> f64 {
        self.kn
    }

    fn energy(&self, delta: f64, _r_star: f64) -> f64 {
        0.5 * self.kn * delta * delta
    }
}

/// The absolute dashpot: γn (mass/time) given, the same for every contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Absolute {
    pub gamman: f64,
}

impl Damping for Absolute {
    #[inline(always)]
    fn gamma<S: Spring>(&self, _: &S, _: f64, _: &PairKinematics) -> f64 {
        self.gamman
    }
}

/// Wraps a normal model and clips its attractive part: max(fn, 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clipped<N>(pub N);

impl<N: NormalModel> NormalModel for Clipped<N> {
    #[inline(always)]
    fn force(&self, k: &PairKinematics) -> f64 {
        self.0.force(k).max(0.0)
    }

    /// The wrapped model's: clipping acts on the dashpot's pull at the end of a collision,
    /// while the spring itself still holds its energy.
    fn stored_energy(&self, delta: f64, r_star: f64) -> f64 {
        self.0.stored_energy(delta, r_star)
    }

    const SPLITS_DISSIPATION: bool = N::SPLITS_DISSIPATION;

    /// The wrapped model's while the force is not clipped; clipped to zero, the non-elastic part
    /// is minus the elastic force, taken as the wrapped force at vn = 0 (a dashpot gives no
    /// force at rest), so the energy taken is fn_elastic·vn·dt.
    #[inline(always)]
    fn dissipated(&self, k: &PairKinematics, _fn_signed: f64, dt: f64) -> f64 {
        let unclipped = self.0.force(k);
        if unclipped >= 0.0 {
            self.0.dissipated(k, unclipped, dt)
        } else {
            let at_rest = PairKinematics { vn: 0.0, ..*k };
            self.0.force(&at_rest) * k.vn * dt
        }
    }
}

/// The kinematics of a head-on contact of overlap `delta` (length), normal velocity `vn`
/// (length/time), radii `rad_p`, `rad_i` and inverse masses `inv_mass_p`, `inv_mass_i`, along
/// z: for the laws' tests.
#[cfg(test)]
pub(crate) fn head_on(delta: f64, vn: f64, rad: [f64; 2], inv_mass: [f64; 2]) -> PairKinematics {
    let n = crate::Vec3::new(0.0, 0.0, 1.0);
    let mut input = super::PairInput::at_rest((rad[0] + rad[1] - delta) * n, rad[0], rad[1]);
    input.v_p = vn * n;
    input.inv_mass_p = inv_mass[0];
    input.inv_mass_i = inv_mass[1];
    input.kinematics().expect("overlapping")
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
        let k = |delta, vn| head_on(delta, vn, [0.5, 0.5], [1.0, 1.0]);
        let f = m.force(&k(1e-3, -1.0));
        assert!((f - (200.0 + 15.0)).abs() < 1e-9, "{f}");
        assert!(m.force(&k(1e-6, 1.0)) < 0.0);
        assert_eq!(Clipped(m).force(&k(1e-6, 1.0)), 0.0);
    }

    /// The linear spring with the absolute damping, composed, is the linear spring–dashpot to
    /// the bit, its energy and its dissipation included.
    #[test]
    fn the_composed_linear_law_is_the_spring_dashpot() {
        let (kn, gamman) = (2e5, 15.0);
        let one = LinearSpringDashpot { kn, gamman };
        let parts = Damped {
            spring: Linear { kn },
            damping: Absolute { gamman },
        };
        for (delta, vn) in [(1e-3, -1.0), (3e-4, 0.7), (1e-7, 2e-3)] {
            let k = head_on(delta, vn, [0.5, 0.3], [2.0, 0.0]);
            assert_eq!(one.force(&k).to_bits(), parts.force(&k).to_bits());
            let f = one.force(&k);
            assert_eq!(one.dissipated(&k, f, 1e-4), parts.dissipated(&k, f, 1e-4));
            assert_eq!(
                one.stored_energy(delta, 0.2),
                parts.stored_energy(delta, 0.2)
            );
        }
    }
}
