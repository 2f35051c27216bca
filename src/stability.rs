//! Stability of verdem's time step for one linear spring–dashpot contact, and the restitution
//! error a coarse time step makes (the derivation is in `docs/stability.md`).
//!
//! The scheme (`step`): kick v_{n+1/2} = v_n + a_n·dt/2, drift x_{n+1} = x_n + v_{n+1/2}·dt,
//! force at x_{n+1} with the half-step velocity v_{n+1/2}, kick v_{n+1} = v_{n+1/2} +
//! a_{n+1}·dt/2. For the relative coordinate x of one contact (overlap, or tangential spring)
//! of effective mass meff, stiffness k and absolute damping γ, a = −(k x + γ v_{n+1/2})/meff, so
//! the step is a linear map of the state (x_n, v_{n−1/2}) (the force of step n depends on
//! v_{n−1/2}, not on v_n): the leapfrog form
//!   v_{n+1/2} = (1 − c·dt) v_{n−1/2} − ω²·dt x_n,   x_{n+1} = x_n + dt·v_{n+1/2},
//! with ω² = k/meff and c = γ/meff. The full-step velocity v_n is an invertible linear function
//! of (x_n, v_{n−1/2}) for c·dt ≠ 2, so the map on (x_n, v_n) has the same eigenvalues.

/// A linear spring–dashpot: stiffness `k` (force/length) and absolute damping `gamma`
/// (mass/time, not scaled by the effective mass).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    pub k: f64,
    pub gamma: f64,
}

/// Which two bodies a contact joins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pair {
    /// Two free spheres (meff = m_P m_I/(m_P + m_I), m/2 for equal spheres).
    FreeFree,
    /// A free sphere and a wall sphere of infinite mass (meff = m).
    FreeWall,
}

impl Pair {
    /// "free–free" or "free–wall".
    pub const fn name(self) -> &'static str {
        match self {
            Pair::FreeFree => "free–free",
            Pair::FreeWall => "free–wall",
        }
    }
}

/// Which spring of a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// The normal spring (kn, γn) on the overlap.
    Normal,
    /// The tangential spring (kt, γt) on the sticking contact point, which moves with the
    /// spheres' translation and rotation.
    Tangential,
}

impl Direction {
    /// "normal" or "tangential".
    pub const fn name(self) -> &'static str {
        match self {
            Direction::Normal => "normal",
            Direction::Tangential => "tangential",
        }
    }

    /// The effective mass (mass) of this direction's relative motion, from the pair's normal
    /// effective mass `meff_normal` (mass). Tangentially each free solid sphere (I = 2/5 m R²)
    /// answers a force F at its contact point with F/m + R²F/I = 7F/(2m), so meff_t =
    /// 2/7·meff_n (lever arm R; the contact point's R − δ/2 gives a slightly heavier, more
    /// stable contact, so this is the conservative side).
    pub fn meff(self, meff_normal: f64) -> f64 {
        match self {
            Direction::Normal => meff_normal,
            // rigid-body kinematics of the contact point, 1/m + R²/I = 7/(2m) per solid sphere
            // (as in Chung & Ooi, Granular Matter 13:643, 2011, for kt = 2/7 kn)
            Direction::Tangential => 2.0 / 7.0 * meff_normal,
        }
    }
}

/// The one-step amplification matrix of one contact's relative motion, acting on the column
/// (x_n, v_{n−1/2}) (length, length/time): effective mass `meff` (mass), spring `s`, time step
/// `dt` (time). Rows and columns in that order.
pub fn amplification(meff: f64, s: Spring, dt: f64) -> [[f64; 2]; 2] {
    let (w2, c) = (s.k / meff, s.gamma / meff);
    // v' = (1 − c dt) v − ω² dt x;  x' = x + dt v'
    [
        [1.0 - w2 * dt * dt, dt * (1.0 - c * dt)],
        [-w2 * dt, 1.0 - c * dt],
    ]
}

/// Spectral radius (largest eigenvalue modulus, dimensionless) of a real 2×2 matrix, from its
/// exact eigenvalues λ = (T ± √(T² − 4D))/2 (T trace, D determinant).
pub fn spectral_radius(a: [[f64; 2]; 2]) -> f64 {
    let t = a[0][0] + a[1][1];
    let d = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let disc = t * t - 4.0 * d;
    if disc < 0.0 {
        // complex pair: |λ|² = D
        return d.sqrt();
    }
    // the larger root without cancellation, the other from λ1·λ2 = D
    let l1 = 0.5 * (t + t.signum() * disc.sqrt());
    let l2 = if l1 == 0.0 { 0.0 } else { d / l1 };
    l1.abs().max(l2.abs())
}

/// The largest stable time step (time) of one linear spring–dashpot contact of effective mass
/// `meff` (mass) under verdem's scheme: the spectral radius of [`amplification`] is ≤ 1 exactly
/// for dt ≤ 2/ω·(√(1 + ζ²) − ζ), with ω = √(k/meff) and ζ = γ/(2√(k·meff)) (Jury's conditions
/// on λ² − Tλ + D: |D| ≤ 1 and |T| ≤ 1 + D; the binding one is ω²dt² + 2c·dt ≤ 4). Undamped it
/// is 2/ω, Störmer–Verlet's limit; damping lowers it. Infinite when k = γ = 0.
pub fn critical_dt(meff: f64, s: Spring) -> f64 {
    let (w2, c) = (s.k / meff, s.gamma / meff);
    // the positive root of ω² dt² + 2 c dt − 4 = 0, written without cancellation
    // (Belytschko, Liu & Moran 2000, ch. 6: central differences with a lagged dashpot)
    4.0 / (c + (c * c + 4.0 * w2).sqrt())
}

/// One contact's stability limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limit {
    pub pair: Pair,
    pub direction: Direction,
    /// Effective mass of the direction's relative motion (mass).
    pub meff: f64,
    /// Largest stable time step (time).
    pub dt: f64,
}

impl Limit {
    /// The limit of `direction` of a `pair` contact whose normal effective mass is
    /// `meff_normal` (mass), with that direction's `spring`.
    pub fn of(pair: Pair, direction: Direction, meff_normal: f64, spring: Spring) -> Limit {
        let meff = direction.meff(meff_normal);
        Limit {
            pair,
            direction,
            meff,
            dt: critical_dt(meff, spring),
        }
    }

    /// "free–wall normal", etc.
    pub fn contact(&self) -> String {
        format!("{} {}", self.pair.name(), self.direction.name())
    }
}

/// Onset phases of [`restitution_error`]: where within a step the spheres first touch (the
/// mid-points of equal parts of a step).
const ONSET_PHASES: usize = 16;

/// What one head-on collision of verdem's scheme gives (see [`discrete_collision`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteCollision {
    /// Restitution coefficient −u_after/u_before (dimensionless).
    pub e: f64,
    /// Steps that end with the spheres overlapping (the contact's duration in steps).
    pub steps_in_contact: u64,
    /// Largest overlap at the end of a step, per unit impact speed (time).
    pub delta_max_per_speed: f64,
}

/// One head-on collision of effective mass `meff` (mass) under the linear spring–dashpot `s`
/// at step `dt` (time), with the force clipped at 0 when `clip` (else the attractive tail is
/// kept, as verdem's default law), the spheres touching 1 − `phase` (0 < phase ≤ 1) of a step
/// after the start of a step, so that they overlap by `phase`·u·dt at its end: the scheme of
/// this module's head, run on the overlap δ (rate u = dδ/dt, force k·δ + γ·u_{n+1/2} while
/// δ > 0) until the spheres part. The collision is linear in the impact speed, so the overlap
/// is returned per unit speed; `None` when the step is unstable (no parting within 10⁶ steps).
pub fn discrete_collision(
    meff: f64,
    s: Spring,
    dt: f64,
    phase: f64,
    clip: bool,
) -> Option<DiscreteCollision> {
    let u0 = 1.0;
    // the gap closes at the step's fraction `phase`: δ_0 = −(1 − phase)·u0·dt
    let (mut delta, mut u, mut a) = (-(1.0 - phase) * u0 * dt, u0, 0.0);
    let (mut steps_in_contact, mut delta_max) = (0u64, 0.0f64);
    for _ in 0..1_000_000 {
        let half = u + 0.5 * dt * a;
        delta += half * dt;
        a = if delta > 0.0 {
            let f = s.k * delta + s.gamma * half;
            -(if clip { f.max(0.0) } else { f }) / meff
        } else {
            0.0
        };
        u = half + 0.5 * dt * a;
        if delta > 0.0 {
            steps_in_contact += 1;
            delta_max = delta_max.max(delta);
        }
        if steps_in_contact > 0 && delta <= 0.0 && u < 0.0 {
            return Some(DiscreteCollision {
                e: -u / u0,
                steps_in_contact,
                delta_max_per_speed: delta_max / u0,
            });
        }
        if !u.is_finite() {
            return None;
        }
    }
    None
}

/// The restitution coefficient of [`discrete_collision`] with the attractive tail kept
/// (verdem's default law).
pub fn discrete_restitution(meff: f64, s: Spring, dt: f64, phase: f64) -> Option<f64> {
    discrete_collision(meff, s, dt, phase, false).map(|c| c.e)
}

/// The largest relative error |e_dt − e|/e (dimensionless) of the restitution coefficient of one
/// head-on collision of effective mass `meff` (mass) under `s` at step `dt` (time), over
/// [`ONSET_PHASES`] onsets within a step ([`discrete_restitution`] against the closed form
/// e = exp(−η·tc), η = γ/(2·meff), tc = π/√(ω² − η²)); infinite when the step is unstable or the
/// contact over-damped. Computed, not extrapolated: the scheme is first order for restitution at
/// fine steps (the dashpot lags by dt/2), and much worse near its stability limit.
pub fn restitution_error(meff: f64, s: Spring, dt: f64) -> f64 {
    let eta = s.gamma / (2.0 * meff);
    let wd2 = s.k / meff - eta * eta;
    if wd2 <= 0.0 {
        return f64::INFINITY;
    }
    let e = (-eta * std::f64::consts::PI / wd2.sqrt()).exp();
    (0..ONSET_PHASES)
        .map(|j| {
            // mid-points: an onset exactly at a step's start is a measure-zero edge case
            discrete_restitution(meff, s, dt, (j as f64 + 0.5) / ONSET_PHASES as f64)
                .map_or(f64::INFINITY, |ed| (ed / e - 1.0).abs())
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The benchmark's sphere (d = 1, ρ = 1) and springs.
    const M: f64 = std::f64::consts::PI / 6.0;
    const NORMAL: Spring = Spring {
        k: 2e5,
        gamma: 15.0,
    };
    const TANGENTIAL: Spring = Spring {
        k: 2e5 * 2.0 / 7.0,
        gamma: 15.0 * 2.0 / 7.0,
    };

    /// The largest dt with spectral radius ≤ 1 + 1e-12, by bisection on the exact eigenvalues:
    /// independent of the closed form.
    fn bisected_limit(meff: f64, s: Spring) -> f64 {
        let stable = |dt: f64| spectral_radius(amplification(meff, s, dt)) <= 1.0 + 1e-12;
        let (mut lo, mut hi) = (0.0, 1.0);
        while stable(hi) {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if stable(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    #[test]
    fn undamped_limit_is_two_over_omega() {
        for (meff, k) in [(0.5 * M, 2e5), (M, 2e5), (1e-3, 1e9), (7.0, 1e2)] {
            let s = Spring { k, gamma: 0.0 };
            let two_over_w = 2.0 / (k / meff).sqrt();
            let closed = critical_dt(meff, s);
            assert!(
                (closed - two_over_w).abs() <= 1e-12 * two_over_w,
                "{closed}"
            );
            let bisected = bisected_limit(meff, s);
            assert!(
                (bisected - two_over_w).abs() <= 1e-12 * two_over_w,
                "{bisected}"
            );
        }
    }

    #[test]
    fn closed_form_agrees_with_the_eigenvalues() {
        for meff in [0.5 * M, M, 2.0 / 7.0 * M] {
            for gamma in [0.0, 1.0, 15.0, 100.0, 1e3, 1e4] {
                let s = Spring { k: 2e5, gamma };
                let (closed, bisected) = (critical_dt(meff, s), bisected_limit(meff, s));
                assert!(
                    (closed - bisected).abs() <= 1e-9 * closed,
                    "meff {meff} γ {gamma}: {closed} vs {bisected}"
                );
            }
        }
    }

    #[test]
    fn damping_lowers_the_limit() {
        let mut last = f64::INFINITY;
        for gamma in [0.0, 1.0, 15.0, 100.0, 1e3, 1e4, 1e5] {
            let dt = critical_dt(0.5 * M, Spring { k: 2e5, gamma });
            assert!(dt < last, "γ {gamma}: {dt} !< {last}");
            last = dt;
        }
        // very heavy damping: c·dt → 2 (the dashpot's own explicit limit)
        let c = 1e7 / (0.5 * M);
        let dt = critical_dt(0.5 * M, Spring { k: 2e5, gamma: 1e7 });
        assert!((c * dt - 2.0).abs() < 1e-3, "{}", c * dt);
    }

    #[test]
    fn benchmark_limits_in_steps_per_collision() {
        // tc = π/ω_d (free–free) against the limit ≈ 2/ω: tc/dt_crit ≈ π/2 lightly damped.
        let meff = 0.5 * M;
        let wd = (NORMAL.k / meff - (NORMAL.gamma / (2.0 * meff)).powi(2)).sqrt();
        let tc = std::f64::consts::PI / wd;
        let ff = Limit::of(Pair::FreeFree, Direction::Normal, meff, NORMAL);
        let per_tc = tc / ff.dt;
        assert!(
            per_tc > std::f64::consts::FRAC_PI_2 && per_tc < 1.7,
            "{per_tc}"
        );
        // a wall sphere doubles meff: a longer limit
        let fw = Limit::of(Pair::FreeWall, Direction::Normal, M, NORMAL);
        assert!(fw.dt > ff.dt * 2f64.sqrt() * 0.99 && fw.dt > ff.dt);
        // kt = 2/7 kn and γt = 2/7 γn: the tangential oscillator is the normal one
        let t = Limit::of(Pair::FreeFree, Direction::Tangential, meff, TANGENTIAL);
        assert!((t.dt - ff.dt).abs() < 1e-15 * ff.dt);
        assert_eq!(ff.contact(), "free–free normal");
    }

    /// Two bodies joined by the linear law, advanced as `step` does (kick, drift, force at the
    /// new positions with the half-step velocities, kick) for `steps` steps; body 2 is a wall
    /// (never moves) when `wall`. Returns the largest |stretch| of the last 100 steps over the
    /// initial stretch (NaN once it overflowed).
    fn normal_pair_growth(m: f64, wall: bool, s: Spring, dt: f64, steps: usize) -> f64 {
        let inv_m = [1.0 / m, if wall { 0.0 } else { 1.0 / m }];
        let (mut x, mut v) = ([0.0, 1.0 - 1e-3], [0.0; 2]);
        let force = |x: [f64; 2], v: [f64; 2]| {
            // overlap δ = 1 − (x2 − x1); n from body 2 to body 1 is −x̂, so the normal velocity
            // is vn = v2 − v1 and the repulsive fn = kδ − γ·vn pushes body 1 along −x
            let delta = 1.0 - (x[1] - x[0]);
            let fn_ = s.k * delta - s.gamma * (v[1] - v[0]);
            [-fn_, fn_]
        };
        let mut f = force(x, v);
        let mut worst: f64 = 0.0;
        for n in 0..steps {
            for b in 0..2 {
                v[b] += f[b] * inv_m[b] * 0.5 * dt;
                x[b] += v[b] * dt;
            }
            f = force(x, v);
            for b in 0..2 {
                v[b] += f[b] * inv_m[b] * 0.5 * dt;
            }
            let stretch = (1.0 - (x[1] - x[0])).abs();
            // a NaN (overflow) counts as growth
            if n + 100 >= steps && (stretch.is_nan() || stretch > worst) {
                worst = stretch;
            }
        }
        worst / 1e-3
    }

    /// Two spheres of radius `r` and mass `m` (or sphere 1 against a fixed wall sphere) in a
    /// sticking tangential contact along y, normal along x, with spins about z, advanced as
    /// `step` does; the spring ξ += slip·dt before the force, slip from the half-step velocities
    /// and spins with lever arms r. Returns the largest |ξ| of the last 100 steps over the
    /// initial ξ (NaN once it overflowed).
    fn tangential_pair_growth(m: f64, wall: bool, s: Spring, dt: f64, steps: usize) -> f64 {
        let r = 0.5;
        let inertia = 0.4 * m * r * r;
        let inv_m = [1.0 / m, if wall { 0.0 } else { 1.0 / m }];
        let inv_i = [1.0 / inertia, if wall { 0.0 } else { 1.0 / inertia }];
        // v: y velocities, w: z spins; n = x̂ from sphere 2 to sphere 1
        let (mut v, mut w, mut xi) = ([0.0f64; 2], [0.0f64; 2], 1e-3);
        // slip of 1's contact point relative to 2's: v1 − v2 − r(ω1 + ω2)(ẑ × x̂)·ŷ
        let slip = |v: [f64; 2], w: [f64; 2]| v[0] - v[1] - r * (w[0] + w[1]);
        // force on 1 along y is F; torques on both (∓r n) × (±F ŷ) = −r F ẑ
        let loads = |f: f64| ([f, -f], [-r * f, -r * f]);
        let mut ft = -s.k * xi;
        let mut worst: f64 = 0.0;
        for n in 0..steps {
            let (f, t) = loads(ft);
            for b in 0..2 {
                v[b] += f[b] * inv_m[b] * 0.5 * dt;
                w[b] += t[b] * inv_i[b] * 0.5 * dt;
            }
            let u = slip(v, w);
            xi += u * dt;
            ft = -s.k * xi - s.gamma * u;
            let (f, t) = loads(ft);
            for b in 0..2 {
                v[b] += f[b] * inv_m[b] * 0.5 * dt;
                w[b] += t[b] * inv_i[b] * 0.5 * dt;
            }
            if n + 100 >= steps && (xi.is_nan() || xi.abs() > worst) {
                worst = xi.abs();
            }
        }
        worst / 1e-3
    }

    #[test]
    fn the_two_body_recurrence_grows_just_above_the_limit_only() {
        let steps = 10_000;
        for (pair, wall, meff) in [(Pair::FreeFree, false, 0.5 * M), (Pair::FreeWall, true, M)] {
            for (direction, spring) in [
                (Direction::Normal, NORMAL),
                (Direction::Normal, Spring { k: 2e5, gamma: 0.0 }),
                (
                    Direction::Normal,
                    Spring {
                        k: 2e5,
                        gamma: 200.0,
                    },
                ),
                (Direction::Tangential, TANGENTIAL),
                (
                    Direction::Tangential,
                    Spring {
                        k: 1e5,
                        gamma: 50.0,
                    },
                ),
            ] {
                let limit = Limit::of(pair, direction, meff, spring);
                let growth = |dt| match direction {
                    Direction::Normal => normal_pair_growth(M, wall, spring, dt, steps),
                    Direction::Tangential => tangential_pair_growth(M, wall, spring, dt, steps),
                };
                let (below, above) = (growth(0.999 * limit.dt), growth(1.001 * limit.dt));
                let what = format!("{} {spring:?}", limit.contact());
                assert!(below < 10.0, "{what}: grew {below}× below the limit");
                assert!(
                    above.is_nan() || above >= 1e6,
                    "{what}: only {above}× above the limit"
                );
            }
        }
    }

    #[test]
    fn restitution_error_is_first_order_at_fine_steps_and_grows_near_the_limit() {
        let (m, meff) = (M, 0.5 * M);
        let eta = NORMAL.gamma / m;
        let tc = std::f64::consts::PI / (NORMAL.k / meff - eta * eta).sqrt();
        let e = (-eta * tc).exp();
        // the relative restitution errors `verdem run` gives two spheres closing at 1 at
        // dt = tc/50, touching half a step, 0.97 and 0.03 of a step in (docs/stability.md)
        for (phase, engine) in [(0.5, -3.434e-4), (0.97, 3.800e-3), (0.03, -2.321e-4)] {
            let got = discrete_restitution(meff, NORMAL, tc / 50.0, phase).unwrap() / e - 1.0;
            assert!(
                (got - engine).abs() < 2e-6,
                "phase {phase}: {got} against {engine}"
            );
        }
        let err = |per_tc: f64| restitution_error(meff, NORMAL, tc / per_tc);
        // first order: halving dt about halves the worst error
        let ratio = err(50.0) / err(100.0);
        assert!(ratio > 1.5 && ratio < 2.6, "{ratio}");
        // near the stability limit (tc/dt = 1.624) collisions gain energy on average
        // (`verdem extremes`, docs/extremes.md)
        assert!(err(2.0) > 0.1, "{}", err(2.0));
        assert!(err(1.5) > err(2.0), "beyond the limit it is worse still");
    }
}
