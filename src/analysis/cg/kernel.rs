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
    /// Lucy polynomial of cutoff c, (5/4c)(1 + 3q)(1 − q)³ with q = |z|/c (1D normalisation).
    Lucy { c: f64 },
}

impl Kernel {
    /// Half-width of the kernel's support.
    pub fn reach(&self) -> f64 {
        match *self {
            Kernel::Heaviside { h } => 0.5 * h,
            Kernel::Gauss { w } => 3.0 * w,
            Kernel::Lucy { c } => c,
        }
    }

    /// Cumulative weight ∫_{-∞}^{u} φ(s) ds of the kernel centred at 0 (u = z − z_k).
    fn cumulative(&self, u: f64) -> f64 {
        match *self {
            Kernel::Heaviside { h } => ((u + 0.5 * h) / h).clamp(0.0, 1.0),
            Kernel::Gauss { w } => {
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
            Kernel::Gauss { w } => {
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

    /// ∫_0^1 φ(z_b + s(z_a − z_b) − z_k) ds: the weight of a branch from z_b to z_a, exact.
    pub fn line(&self, za: f64, zb: f64, zk: f64) -> f64 {
        let dz = za - zb;
        if dz.abs() < 1e-14 {
            return self.point(0.5 * (za + zb), zk);
        }
        (self.cumulative(za - zk) - self.cumulative(zb - zk)) / dz
    }
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
