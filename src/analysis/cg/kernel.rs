//! Coarse-graining kernels in z (fields are averaged over x and y). Each kernel gives the weight
//! of a point at height z for the field at grid point z_k, and the exact line integral of that
//! weight along a branch from z_a to z_b (Weinhart et al., Granular Matter 14:289, 2012, eq. 12).
//! Weights are per unit length in z; divide by Lx·Ly for a density.

/// The kernel of a coarse-graining.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kernel {
    /// Slices of height h: a point belongs to the slice holding it (MercuryCG `-function
    /// Heaviside`); fields are slice averages.
    Heaviside { h: f64 },
    /// Gaussian of standard deviation w, cut off at 3w and renormalised to unit integral.
    Gauss { w: f64 },
    /// MercuryCG's Gaussian (`-function Gauss -w w`): the point weight of [`Kernel::Gauss`];
    /// a branch's weight is the line integral of the uncut Gaussian, non-zero where the branch
    /// comes within 3w of the grid point and scaled there to unit integral over z.
    MercuryGauss { w: f64 },
    /// Lucy polynomial of cutoff c, (5/4c)(1 + 3q)(1 − q)³ with q = |z|/c (1D normalisation).
    Lucy { c: f64 },
}

impl Kernel {
    /// Half-width of the kernel's support.
    pub fn reach(&self) -> f64 {
        match *self {
            Kernel::Heaviside { h } => 0.5 * h,
            Kernel::Gauss { w } | Kernel::MercuryGauss { w } => 3.0 * w,
            Kernel::Lucy { c } => c,
        }
    }

    /// Cumulative weight ∫_{-∞}^{u} φ(s) ds of the kernel centred at 0 (u = z − z_k); for
    /// [`Kernel::MercuryGauss`] that of its point weight, which its branches do not use.
    fn cumulative(&self, u: f64) -> f64 {
        match *self {
            Kernel::Heaviside { h } => ((u + 0.5 * h) / h).clamp(0.0, 1.0),
            Kernel::Gauss { w } | Kernel::MercuryGauss { w } => {
                let cut = 3.0 * w;
                let u = u.clamp(-cut, cut);
                let norm = libm::erf(3.0 / std::f64::consts::SQRT_2);
                0.5 * (1.0 + libm::erf(u / (w * std::f64::consts::SQRT_2)) / norm)
            }
            Kernel::Lucy { c } => {
                let q = (u / c).clamp(-1.0, 1.0);
                // ∫_0^q (1 + 3s)(1 − s)³ ds = q − 2q³ + 2q⁴ − 3q⁵/5, times 5/4, odd extension.
                let a = q.abs();
                let f = 1.25 * (a - 2.0 * a.powi(3) + 2.0 * a.powi(4) - 0.6 * a.powi(5));
                0.5 + f.copysign(q)
            }
        }
    }

    /// Weight (per unit length) of a point at z for the grid point z_k. For Heaviside slices a
    /// point on a slice boundary belongs to the upper slice.
    pub fn point(&self, z: f64, zk: f64) -> f64 {
        let u = z - zk;
        match *self {
            Kernel::Heaviside { h } => {
                if u >= -0.5 * h && u < 0.5 * h {
                    1.0 / h
                } else {
                    0.0
                }
            }
            Kernel::Gauss { w } | Kernel::MercuryGauss { w } => {
                if u.abs() > 3.0 * w {
                    0.0
                } else {
                    let norm = libm::erf(3.0 / std::f64::consts::SQRT_2);
                    (-0.5 * (u / w).powi(2)).exp()
                        / ((2.0 * std::f64::consts::PI).sqrt() * w * norm)
                }
            }
            Kernel::Lucy { c } => {
                let q = u.abs() / c;
                if q >= 1.0 {
                    0.0
                } else {
                    1.25 / c * (1.0 + 3.0 * q) * (1.0 - q).powi(3)
                }
            }
        }
    }

    /// ∫_0^1 φ(z_b + s(z_a − z_b) − z_k) ds: the weight (per unit length) of a branch from z_b
    /// to z_a for the grid point z_k, exact; for [`Kernel::MercuryGauss`] MercuryCG's weight
    /// instead (see [`mercury_gauss_line`]). A branch with |z_a − z_b| < 1e-14 (length) takes the
    /// point weight of its midpoint.
    pub fn line(&self, za: f64, zb: f64, zk: f64) -> f64 {
        let dz = za - zb;
        if dz.abs() < 1e-14 {
            return self.point(0.5 * (za + zb), zk);
        }
        match *self {
            Kernel::MercuryGauss { w } => {
                mercury_gauss_line(za.min(zb) - zk, za.max(zb) - zk, w, 3.0 * w)
            }
            _ => (self.cumulative(za - zk) - self.cumulative(zb - zk)) / dz,
        }
    }
}

/// MercuryCG's line weight of a branch spanning [lo, hi] about the grid point (lengths, lo < hi)
/// for a Gaussian of standard deviation `w` cut off at `cut`: zero when the branch does not come
/// within `cut` of the grid point, else (erf(hi/(w√2)) − erf(lo/(w√2))) / (2 (F(cut + d) −
/// F(cut))) with d = hi − lo and F(x) = x erf(x/(w√2)) + w√2/√π exp(−x²/(2w²)), the
/// antiderivative of erf, which makes the weights integrate to one over z. MercuryDPM,
/// Kernel/CG/Functions/Gauss.hcc, `Gauss::evaluateCGIntegral1D`, with its prefactor from
/// Kernel/CG/Coordinates/Base_X_Y_Z.cc, `Base_X_Y_Z::getGaussIntegralPrefactor`.
fn mercury_gauss_line(lo: f64, hi: f64, w: f64, cut: f64) -> f64 {
    if lo > cut || hi < -cut {
        return 0.0;
    }
    let s = w * std::f64::consts::SQRT_2;
    let antiderivative =
        |x: f64| x * libm::erf(x / s) + s / std::f64::consts::PI.sqrt() * (-(x / s).powi(2)).exp();
    let norm = 2.0 * (antiderivative(cut + (hi - lo)) - antiderivative(cut));
    (libm::erf(hi / s) - libm::erf(lo / s)) / norm
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kernels() -> [Kernel; 3] {
        [
            Kernel::Heaviside { h: 0.22 },
            Kernel::Gauss { w: 0.3 },
            Kernel::Lucy { c: 0.7 },
        ]
    }

    #[test]
    fn point_weights_integrate_to_one() {
        for k in kernels() {
            let n = 600_000; // step 1e-5: slice edges fall between quadrature points
            let (a, b) = (-3.0, 3.0);
            let h = (b - a) / n as f64;
            let s: f64 = (0..n)
                .map(|i| k.point(a + (i as f64 + 0.5) * h, 0.0) * h)
                .sum();
            assert!((s - 1.0).abs() < 1e-6, "{k:?}: {s}");
        }
    }

    #[test]
    fn mercury_gauss_weighs_particles_as_gauss() {
        let (g, m) = (Kernel::Gauss { w: 0.3 }, Kernel::MercuryGauss { w: 0.3 });
        for u in [-0.95, -0.9, -0.4, 0.0, 0.13, 0.9, 0.91] {
            assert_eq!(g.point(u, 0.0).to_bits(), m.point(u, 0.0).to_bits(), "{u}");
        }
    }

    /// MercuryCG's branch weight against a direct quadrature of the uncut Gaussian along the
    /// branch, scaled by the quadrature over z of that same integral where the branch comes
    /// within 3w of the grid point: an independent check of the closed form.
    #[test]
    fn mercury_gauss_line_is_the_scaled_uncut_line_integral() {
        let w = 0.3;
        let k = Kernel::MercuryGauss { w };
        let gauss =
            |u: f64| (-0.5 * (u / w).powi(2)).exp() / ((2.0 * std::f64::consts::PI).sqrt() * w);
        let uncut = |za: f64, zb: f64, zk: f64| {
            let n = 4000;
            (0..n)
                .map(|i| gauss(zb + (i as f64 + 0.5) / n as f64 * (za - zb) - zk) / n as f64)
                .sum::<f64>()
        };
        for (za, zb) in [(0.4f64, -0.3f64), (-0.05, 0.6), (1.2, 0.1), (0.0, 0.01)] {
            let (lo, hi) = (za.min(zb), za.max(zb));
            let (a, b) = (lo - 3.0 * w, hi + 3.0 * w);
            let n = 4000;
            let dz = (b - a) / n as f64;
            let norm: f64 = (0..n)
                .map(|i| uncut(za, zb, a + (i as f64 + 0.5) * dz) * dz)
                .sum();
            for zk in [-0.75, -0.2, 0.0, 0.35, 0.9, 1.45, 2.2] {
                let expected = if zk < a || zk > b {
                    0.0
                } else {
                    uncut(za, zb, zk) / norm
                };
                let got = k.line(za, zb, zk);
                assert!(
                    (got - expected).abs() < 1e-5 * expected.max(1.0),
                    "{za} {zb} at {zk}: {got} vs {expected}"
                );
            }
        }
    }

    /// Where a branch reaches beyond the cutoff, MercuryCG's weight (the uncut Gaussian) and
    /// `gauss`'s (the cut one, renormalised) differ; for a short branch at the grid point both
    /// tend to the point weight, and agree to first order in its length.
    #[test]
    fn mercury_gauss_differs_from_gauss_by_the_cut() {
        let w = 0.3;
        let (g, m) = (Kernel::Gauss { w }, Kernel::MercuryGauss { w });
        // branch from 0.5 to 1.5 above the grid point: gauss gives only its first 0.4, cut
        let (gz, mz) = (g.line(1.5, 0.5, 0.0), m.line(1.5, 0.5, 0.0));
        assert!(
            gz > 0.0 && mz > 0.0 && (gz - mz).abs() > 1e-3 * gz,
            "{gz} vs {mz}"
        );
        let ratio = m.line(0.01, -0.01, 0.0) / g.line(0.01, -0.01, 0.0);
        assert!((ratio - 1.0).abs() < 1e-2 && ratio != 1.0, "{ratio}");
    }

    #[test]
    fn line_integral_matches_quadrature_of_point_weights() {
        for k in kernels() {
            for (za, zb) in [(0.4, -0.3), (-0.05, 0.6), (0.1, 0.1 + 1e-9)] {
                let n = 100_000;
                let q: f64 = (0..n)
                    .map(|i| {
                        let s = (i as f64 + 0.5) / n as f64;
                        k.point(zb + s * (za - zb), 0.0) / n as f64
                    })
                    .sum();
                let exact = k.line(za, zb, 0.0);
                assert!(
                    (q - exact).abs() < 1e-3 * exact.abs().max(1.0),
                    "{k:?} {za} {zb}: {q} vs {exact}"
                );
            }
        }
    }
}
