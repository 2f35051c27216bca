//! The Mindlin rows' common parts: the closed form of the Mindlin–Deresiewicz loop at constant
//! normal load, the contact they drive (two spheres with Hertz's normal force and a material's
//! G*), and the driver that takes one convention's tangential model through a prescribed
//! motion.
//!
//! Closed form (Mindlin & Deresiewicz, J. Appl. Mech. 20, 327, 1953; Johnson, Contact
//! Mechanics, 1985, §7.4), with T the tangential force resisting a tangential
//! displacement δt at constant normal load N, L = μN and k = 8G*a the no-slip stiffness: a first
//! loading follows δt = (3L/(2k))·[1 − (1 − T/L)^{2/3}], i.e. 3μN/(16G*a)·[…]; unloading from
//! the turning point (δ*, T*) follows δt = δ* − 2·δL((T* − T)/2) and reloading from (−δ*, −T*)
//! δt = −δ* + 2·δL((T + T*)/2) (Masing's doubling), and the energy dissipated per cycle between
//! ±T* is W = (36L²/(5k))·[1 − (1 − x)^{5/3} − (5x/6)·(1 + (1 − x)^{2/3})], x = T*/L (Johnson's
//! 9μ²N²/(10G*a) = 36L²/(5k)); the area of the loop, derived from the branches above.

use crate::contact::{PairInput, Parameters, Tangential, TangentialModel, TangentialVisitor};
use crate::verify::histories::arms;
use crate::Vec3;

/// The first-loading displacement δL(T) (length) of the force `t` (force units, |t| ≤ `limit`)
/// for the Coulomb limit `limit` = μN (force) and the no-slip stiffness `k` = 8G*a
/// (force/length); odd in `t`.
pub fn loading_displacement(t: f64, limit: f64, k: f64) -> f64 {
    let x = (t.abs() / limit).min(1.0);
    t.signum() * 1.5 * limit / k * (1.0 - (1.0 - x).powf(2.0 / 3.0))
}

/// The first-loading force TL(δ) (force units) at the displacement `d` (length), the inverse
/// of [`loading_displacement`]: L·[1 − (1 − d/C)^{3/2}] with C = 3L/(2k), full slip (±L)
/// beyond ±C; odd in `d`.
pub fn loading_force(d: f64, limit: f64, k: f64) -> f64 {
    let c = 1.5 * limit / k;
    let y = (d.abs() / c).min(1.0);
    d.signum() * limit * (1.0 - (1.0 - y).powf(1.5))
}

/// The force (force units) at the displacement `d` (length) unloading from the turning point
/// (`d_star`, `t_star`): T* − 2·TL((δ* − δ)/2).
pub fn unloading_force(d: f64, d_star: f64, t_star: f64, limit: f64, k: f64) -> f64 {
    t_star - 2.0 * loading_force(0.5 * (d_star - d), limit, k)
}

/// The force (force units) at the displacement `d` (length) reloading from the turning point
/// (−`d_star`, −`t_star`): −T* + 2·TL((δ + δ*)/2).
pub fn reloading_force(d: f64, d_star: f64, t_star: f64, limit: f64, k: f64) -> f64 {
    -t_star + 2.0 * loading_force(0.5 * (d + d_star), limit, k)
}

/// The energy (energy units) dissipated by one cycle between ±`t_star` (force units) at the
/// Coulomb limit `limit` and no-slip stiffness `k` (force/length).
pub fn dissipated_per_cycle(t_star: f64, limit: f64, k: f64) -> f64 {
    let x = t_star / limit;
    36.0 * limit * limit / (5.0 * k)
        * (1.0 - (1.0 - x).powf(5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + (1.0 - x).powf(2.0 / 3.0)))
}

/// The contact the Mindlin rows drive: two spheres of radii `radius` (P, I; length) of
/// Young's moduli `youngs` (force/length²) and Poisson's ratios `poisson`, with friction `mu`
/// (dashpots off), at the overlap `delta` (length) to start.
#[derive(Clone, Copy, Debug)]
pub struct Pair {
    pub radius: [f64; 2],
    pub youngs: [f64; 2],
    pub poisson: [f64; 2],
    pub mu: f64,
    pub delta: f64,
}

impl Pair {
    /// Aluminium-alloy spheres (E = 70 GPa, ν = 0.3, Chung & Ooi 2011's test 2 material) of
    /// radius 10 mm and `other` (length) at the overlap 10 µm, μ = 0.3.
    pub fn aluminium(other: f64) -> Pair {
        Pair {
            radius: [0.01, other],
            youngs: [70e9; 2],
            poisson: [0.3; 2],
            mu: 0.3,
            delta: 1e-5,
        }
    }

    /// The materials of Chung & Ooi 2011's test 1, one against the other: a glass sphere
    /// (E = 48 GPa, ν = 0.20) on a limestone one (E = 20 GPa, ν = 0.25), both of radius 10 mm,
    /// at the overlap 10 µm, μ = 0.3.
    pub fn glass_limestone() -> Pair {
        Pair {
            radius: [0.01; 2],
            youngs: [48e9, 20e9],
            poisson: [0.2, 0.25],
            mu: 0.3,
            delta: 1e-5,
        }
    }

    /// E* of the pair: 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ (Johnson 1985, §4.2).
    pub fn e_star(&self) -> f64 {
        let [e1, e2] = self.youngs;
        let [n1, n2] = self.poisson;
        1.0 / ((1.0 - n1 * n1) / e1 + (1.0 - n2 * n2) / e2)
    }

    /// G* of the pair: 1/G* = (2 − ν₁)/G₁ + (2 − ν₂)/G₂ with G = E/(2(1 + ν)) (Mindlin 1949).
    pub fn g_star(&self) -> f64 {
        let g = |e: f64, n: f64| e / (2.0 * (1.0 + n));
        let [e1, e2] = self.youngs;
        let [n1, n2] = self.poisson;
        1.0 / ((2.0 - n1) / g(e1, n1) + (2.0 - n2) / g(e2, n2))
    }

    /// R* = R_P R_I/(R_P + R_I) (length).
    pub fn r_star(&self) -> f64 {
        let [p, i] = self.radius;
        p * i / (p + i)
    }

    /// Hertz's normal force (4/3)E*√R*·δ^{3/2} (force units) at the overlap `delta` (Johnson
    /// 1985, eq. 4.23).
    pub fn normal_force(&self, delta: f64) -> f64 {
        4.0 / 3.0 * self.e_star() * self.r_star().sqrt() * delta.powf(1.5)
    }

    /// Mindlin's no-slip stiffness 8G*a (force/length) at the overlap `delta`, a = √(R*δ).
    pub fn stiffness(&self, delta: f64) -> f64 {
        8.0 * self.g_star() * (self.r_star() * delta).sqrt()
    }

    /// The contact parameters of a case naming the pair's material: G*, E*, μ, no dashpots, no
    /// constant springs.
    pub fn parameters(&self) -> Parameters {
        Parameters {
            kn: 0.0,
            gamman: 0.0,
            kt: 0.0,
            gammat: 0.0,
            mu: self.mu,
            e_star: self.e_star(),
            g_star: self.g_star(),
            restitution: 1.0,
            dissipative_constant: 0.0,
        }
    }

    /// The separation x_P − x_I (length) at the overlap `delta` along `n`.
    pub fn separation(&self, delta: f64, n: Vec3) -> Vec3 {
        (self.radius[0] + self.radius[1] - delta) * n
    }
}

/// The state of the pair at the end of one step of a prescribed motion: the separation
/// x_P − x_I (length; I stays at the origin, P's centre moved along the chord from the last
/// separation) and the spins of P and I (1/time) over the step.
#[derive(Clone, Copy, Debug)]
pub struct Motion {
    pub r: Vec3,
    pub w_p: Vec3,
    pub w_i: Vec3,
}

/// What the driver records at each step: the tangential force on P (force units), the
/// contact's normal and overlap, and the elastic energy the model says its history holds.
#[derive(Clone, Copy, Debug)]
pub struct Recorded {
    pub ft: Vec3,
    pub n: Vec3,
    pub delta: f64,
    pub stored: f64,
}

/// Drives the tangential model of the pair's contact through `motions` from the separation
/// `start`, one step of `dt` (time) each, with the Hertz normal force of the pair.
struct Driven<'a> {
    pair: &'a Pair,
    start: Vec3,
    motions: &'a [Motion],
    dt: f64,
}

impl TangentialVisitor for Driven<'_> {
    type Output = Vec<Recorded>;
    fn visit<T: TangentialModel + Clone + 'static>(self, model: T) -> Vec<Recorded> {
        let mut h = T::History::default();
        let mut last = self.start;
        let mut out = Vec::with_capacity(self.motions.len());
        for m in self.motions {
            let input = PairInput {
                r: m.r,
                rad_p: self.pair.radius[0],
                rad_i: self.pair.radius[1],
                // the tangential laws read no mass
                inv_mass_p: 0.0,
                inv_mass_i: 0.0,
                v_p: (m.r - last) / self.dt,
                v_i: Vec3::zeros(),
                w_p: m.w_p,
                w_i: m.w_i,
            };
            last = m.r;
            let Some(k) = input.kinematics() else {
                h = T::History::default();
                out.push(Recorded {
                    ft: Vec3::zeros(),
                    n: m.r.normalize(),
                    delta: self.pair.radius[0] + self.pair.radius[1] - m.r.norm(),
                    stored: 0.0,
                });
                continue;
            };
            let ft = model.force(&k, self.pair.normal_force(k.delta), &mut h, self.dt);
            out.push(Recorded {
                ft,
                n: k.n,
                delta: k.delta,
                stored: model.stored_energy(&h),
            });
        }
        out
    }
}

/// The forces of `conv`'s tangential model for `pair` through `motions` from `start`, steps of
/// `dt` (time).
pub fn drive(
    conv: Tangential,
    pair: &Pair,
    start: Vec3,
    motions: &[Motion],
    dt: f64,
) -> Vec<Recorded> {
    let driven = Driven {
        pair,
        start,
        motions,
        dt,
    };
    conv.with_model(&pair.parameters(), driven)
}

/// The time step of the Mindlin rows' motions (time): only the rates depend on it, every
/// increment is prescribed as a length.
pub const DT: f64 = 1e-6;

/// A motion of the pair at a fixed normal `n` (unit, from I to P) from the overlap `from`:
/// each entry (overlap, tangential increment) moves P's centre along n to that overlap and
/// slides the contact by the increment (length) along `s` (unit, ⟂ n) by spinning P about
/// s × n, at the slip arm `conv` declares ([`arms`]), so that every convention sees the same
/// slip.
pub fn sliding(
    conv: Tangential,
    pair: &Pair,
    n: Vec3,
    s: Vec3,
    path: &[(f64, f64)],
) -> Vec<Motion> {
    path.iter()
        .map(|&(delta, du)| {
            let (slip_arm, _) = arms(conv, pair.radius[0], delta);
            let arm = slip_arm * (pair.radius[0] - 0.5 * delta);
            Motion {
                r: pair.separation(delta, n),
                w_p: du / (arm * DT) * s.cross(&n),
                w_i: Vec3::zeros(),
            }
        })
        .collect()
}

/// `steps` equal tangential increments adding to `total` (length) at the overlap `delta`.
pub fn slide(delta: f64, total: f64, steps: usize) -> impl Iterator<Item = (f64, f64)> {
    std::iter::repeat_n((delta, total / steps as f64), steps)
}

/// `steps` steps taking the overlap linearly from `from` to `to` (length) with no tangential
/// increment.
pub fn press(from: f64, to: f64, steps: usize) -> impl Iterator<Item = (f64, f64)> {
    (1..=steps).map(move |j| (from + (to - from) * j as f64 / steps as f64, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first loading starts at the no-slip stiffness, reaches full slip at δt = 3L/(2k),
    /// and the force is its inverse; a loop between ±T* closes, and its area by quadrature of
    /// the branches is the closed form's W (which a wrong factor would miss).
    #[test]
    fn the_loop_s_branches_close_and_enclose_the_closed_form_energy() {
        let (limit, k) = (30.0, 1.5e7);
        let small = 1e-6 * limit;
        assert!((loading_displacement(small, limit, k) * k / small - 1.0).abs() < 1e-6);
        assert!((loading_displacement(limit, limit, k) - 1.5 * limit / k).abs() < 1e-20);
        for x in [0.1, 0.5, 0.8, 0.99] {
            let d = loading_displacement(x * limit, limit, k);
            assert!((loading_force(d, limit, k) / (x * limit) - 1.0).abs() < 1e-12);
            assert_eq!(loading_force(-d, limit, k), -loading_force(d, limit, k));
        }
        let t_star = 0.8 * limit;
        let d_star = loading_displacement(t_star, limit, k);
        assert!((unloading_force(d_star, d_star, t_star, limit, k) - t_star).abs() < 1e-9);
        assert!((unloading_force(-d_star, d_star, t_star, limit, k) + t_star).abs() < 1e-9);
        assert!((reloading_force(d_star, d_star, t_star, limit, k) - t_star).abs() < 1e-9);
        let n = 200_000;
        let h = 2.0 * d_star / n as f64;
        let mut area = 0.0;
        for j in 0..n {
            let d = -d_star + (j as f64 + 0.5) * h;
            // the reloading branch lies above the unloading one: ∮T dδt = ∫(T_r − T_u) dδt
            area += (reloading_force(d, d_star, t_star, limit, k)
                - unloading_force(d, d_star, t_star, limit, k))
                * h;
        }
        let w = dissipated_per_cycle(t_star, limit, k);
        assert!((area / w - 1.0).abs() < 1e-6, "{area} against {w}");
        // small loops dissipate as the cube of the amplitude
        let ratio = dissipated_per_cycle(0.02 * limit, limit, k)
            / dissipated_per_cycle(0.01 * limit, limit, k);
        assert!((ratio - 8.0).abs() < 0.1, "{ratio}");
    }

    #[test]
    fn the_pair_s_moduli_follow_the_mixing_rules() {
        let p = Pair::aluminium(0.01);
        let g = 70e9 / 2.6;
        assert!((p.g_star() - 1.0 / (2.0 * (2.0 - 0.3) / g)).abs() < 1e-3);
        assert!((p.e_star() - 1.0 / (2.0 * (1.0 - 0.09) / 70e9)).abs() < 1e-3);
        assert_eq!(p.r_star(), 0.005);
        // glass on limestone: G = 20 GPa and 8 GPa, G* = 1/(1.8/G1 + 1.75/G2)
        let q = Pair::glass_limestone();
        let expected = 1.0 / (1.8 / 20e9 + 1.75 / 8e9);
        assert!(
            (q.g_star() / expected - 1.0).abs() < 1e-14,
            "{}",
            q.g_star()
        );
        assert!((q.e_star() - 1.0 / (0.96 / 48e9 + 0.9375 / 20e9)).abs() < 1e-3);
    }
}
