//! Raw coarse-grained fields of one save (MercuryCG definitions; Weinhart, Thornton, Luding &
//! Bokhove, Granular Matter 14:289, 2012): volume fraction Σ V_i φ, density Σ m_i φ, momentum
//! Σ m_i v_i φ, momentum flux Σ m_i v_i⊗v_i φ, contact stress Σ f_ij⊗l_ij ψ_ij. Fields are
//! averaged over x and y: every weight is divided by Lx·Ly.

use nalgebra::Matrix3;

use super::kernel::Kernel;
use crate::io::mercury::{DataFile, FstatFile};
use crate::state::Domain;
use crate::Vec3;

/// A 3×3 tensor.
pub type Mat3 = Matrix3<f64>;

/// Raw fields at each grid point (per unit volume).
#[derive(Clone, Debug, PartialEq)]
pub struct Raw {
    pub nu: Vec<f64>,
    pub rho: Vec<f64>,
    pub momentum: Vec<Vec3>,
    pub flux: Vec<Mat3>,
    pub contact: Vec<Mat3>,
}

impl Raw {
    /// All fields zero on `n` grid points.
    pub fn zeros(n: usize) -> Self {
        Raw {
            nu: vec![0.0; n],
            rho: vec![0.0; n],
            momentum: vec![Vec3::zeros(); n],
            flux: vec![Mat3::zeros(); n],
            contact: vec![Mat3::zeros(); n],
        }
    }

    /// Adds a free particle at height `z` with velocity `v` and radius `radius` (particle
    /// density `density`) to the volume fraction, density, momentum and momentum flux; `area` is
    /// Lx·Ly, which every weight is divided by.
    #[allow(clippy::too_many_arguments)]
    pub fn add_particle(
        &mut self,
        z: f64,
        v: Vec3,
        radius: f64,
        density: f64,
        grid: &Grid,
        kernel: Kernel,
        area: f64,
    ) {
        let vol = sphere_volume(radius);
        let m = vol * density;
        for k in grid.near(z, z, kernel.reach()) {
            let w = kernel.point(z, grid.z(k)) / area;
            if w != 0.0 {
                self.nu[k] += vol * w;
                self.rho[k] += m * w;
                self.momentum[k] += m * w * v;
                self.flux[k] += m * w * v * v.transpose();
            }
        }
    }

    /// Adds the contact stress f⊗l of one contact: `f` is the force on particle i, whose centre
    /// is at height `z_i`, and `branch` the vector from the branch's start (the partner's centre
    /// for a free–free contact, the contact point for a free–wall one) to that centre, spread
    /// along the branch by the kernel's exact line integral.
    pub fn add_contact(
        &mut self,
        z_i: f64,
        branch: Vec3,
        f: Vec3,
        grid: &Grid,
        kernel: Kernel,
        area: f64,
    ) {
        let z_start = z_i - branch.z;
        let tensor = f * branch.transpose();
        for k in grid.near(z_i, z_start, kernel.reach()) {
            let w = kernel.line(z_i, z_start, grid.z(k)) / area;
            if w != 0.0 {
                self.contact[k] += w * tensor;
            }
        }
    }

    /// self += s·other.
    pub fn add_scaled(&mut self, other: &Raw, s: f64) {
        for k in 0..self.nu.len() {
            self.nu[k] += s * other.nu[k];
            self.rho[k] += s * other.rho[k];
            self.momentum[k] += s * other.momentum[k];
            self.flux[k] += s * other.flux[k];
            self.contact[k] += s * other.contact[k];
        }
    }
}

/// Where the fields are evaluated: the mid-points of `n` equal slices of [z0, z1].
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub z0: f64,
    pub z1: f64,
    pub n: usize,
}

impl Grid {
    /// Height of one slice.
    pub fn h(&self) -> f64 {
        (self.z1 - self.z0) / self.n as f64
    }
    /// Grid point k.
    pub fn z(&self, k: usize) -> f64 {
        self.z0 + (k as f64 + 0.5) * self.h()
    }
    /// Grid points whose kernel can reach the interval [a, b].
    fn near(&self, a: f64, b: f64, reach: f64) -> std::ops::Range<usize> {
        let h = self.h();
        let lo = (((a.min(b) - reach - self.z0) / h).floor() - 1.0).max(0.0) as usize;
        let hi = (((a.max(b) + reach - self.z0) / h).ceil() + 1.0).max(0.0) as usize;
        lo.min(self.n)..hi.min(self.n)
    }
}

/// The volume 4/3 π r³ of a sphere of radius `r` (length³), which the fields weigh a particle
/// by (times the density for its mass).
pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r.powi(3)
}

/// Raw fields of one save. `is_wall(i)` tells wall particles (no volume, mass or momentum);
/// `density` is the particle density.
pub fn raw_fields(
    data: &DataFile,
    fstat: &FstatFile,
    is_wall: &dyn Fn(usize) -> bool,
    domain: &Domain,
    grid: &Grid,
    kernel: Kernel,
    density: f64,
) -> Raw {
    let l = domain.lengths();
    let area = l.x * l.y;
    let mut raw = Raw::zeros(grid.n);
    for (i, p) in data.rows.iter().enumerate() {
        if is_wall(i) {
            continue;
        }
        raw.add_particle(p.x.z, p.v, p.radius, density, grid, kernel, area);
    }
    for r in &fstat.rows {
        let (i, j) = (r.i, r.j);
        let (wi, wj) = (is_wall(i), is_wall(j));
        // A free–free contact is written twice: keep the line with i < j. A free–wall contact is
        // written once, free particle first.
        if wi || (!wj && i > j) {
            continue;
        }
        let xi = data.rows[i].x;
        let f = r.fn_signed * r.n + r.ft * r.t;
        // Branch from the partner's centre (free–free) or from the contact point (free–wall) to
        // the centre of i, as a minimum-image vector.
        let start = if wj { r.c } else { data.rows[j].x };
        let branch = domain.min_image(xi - start);
        raw.add_contact(xi.z, branch, f, grid, kernel, area);
    }
    raw
}

/// Fields derived from (time-averaged) raw fields at one grid point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derived {
    pub nu: f64,
    pub rho: f64,
    pub velocity: Vec3,
    /// Kinetic stress: momentum flux − ρ V⊗V.
    pub kinetic: Mat3,
    /// Contact stress Σ f⊗l ψ (positive in compression).
    pub contact: Mat3,
    /// Granular temperature trace(kinetic)/(3ρ).
    pub temperature: f64,
    /// trace(kinetic + contact)/3.
    pub pressure: f64,
    /// (kinetic + contact)_xz.
    pub shear: f64,
}

/// Derives velocity, kinetic stress, temperature, pressure and shear stress from raw fields.
pub fn derive(raw: &Raw) -> Vec<Derived> {
    (0..raw.nu.len())
        .map(|k| {
            let rho = raw.rho[k];
            let velocity = if rho > 0.0 {
                raw.momentum[k] / rho
            } else {
                Vec3::zeros()
            };
            let kinetic = raw.flux[k] - rho * velocity * velocity.transpose();
            let total = kinetic + raw.contact[k];
            Derived {
                nu: raw.nu[k],
                rho,
                velocity,
                kinetic,
                contact: raw.contact[k],
                temperature: if rho > 0.0 {
                    kinetic.trace() / (3.0 * rho)
                } else {
                    0.0
                },
                pressure: total.trace() / 3.0,
                shear: total[(0, 2)],
            }
        })
        .collect()
}
