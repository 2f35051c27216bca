//! The particle pass: the closing half kick of one step (after gathering its pair forces) fused
//! with the opening half kick and the drift of the next, velocity Verlet in MercuryDPM's order of
//! operations (`BaseParticle::integrateBeforeForceComputation`).

use std::sync::atomic::Ordering;

use super::arrays::Arrays;
use crate::state::Domain;
use crate::Vec3;

/// What the particle pass reads besides the arrays.
pub(super) struct Kick<'a> {
    pub domain: &'a Domain,
    /// Time step (time).
    pub dt: f64,
    /// Gravity (acceleration); used only with `GRAV`.
    pub gravity: Vec3,
    /// Its components along periodic axes, when it has any: the run guard's energy balance
    /// counts their work m·g·Δx at every drift.
    pub periodic_gravity: Option<Vec3>,
}

/// Per-particle pass over `a..b`: with `kick_end`, gather the forces of the step that just
/// ended and apply the closing half kick; with `drift`, apply the opening half kick and the drift
/// of the next step. Returns the largest squared speed after the drift of a slow [0] and of a
/// fast [1] particle (speed classes of the last build). With `GRAV`, adds the work of gravity
/// along periodic axes over the drifts to `gravity_work`, in fixed point
/// ([`super::energy::fixed`]).
///
/// # Safety
/// `arr` is valid (taken after the last rebuild); no other thread touches particles `a..b`
/// during the call; with `kick_end`, every pair chunk holding a pair of these particles is done
/// and no thread writes those pairs' slots.
#[inline(never)]
pub(super) unsafe fn particle_pass<H, const ROT: bool, const GRAV: bool>(
    k: &Kick<'_>,
    arr: &Arrays<H>,
    a: usize,
    b: usize,
    kick_end: bool,
    drift: bool,
    gravity_work: &mut i128,
) -> [f64; 2] {
    let dt = k.dt;
    // Four running maxima of each kind, one per lane j mod 4: a single one would chain every
    // particle's comparison to the previous one's.
    let mut vmax2 = [[0.0f64; 4]; 2];
    let mut see = |class: usize, j: usize, vp: Vec3| {
        let s2 = vp.norm_squared();
        let lane = &mut vmax2[class][j & 3];
        if s2 > *lane {
            *lane = s2;
        }
    };
    // Plain slices of this chunk: bounds and base pointers stay in registers.
    let x = arr.x.slice_mut(a..b);
    let v = arr.v.slice_mut(a..b);
    let w = arr.w.slice_mut(a..b);
    let f = arr.f.slice_mut(a..b);
    let t = arr.t.slice_mut(a..b);
    let quiet = arr.quiet.slice_mut(a..b);
    let inv_mass = arr.inv_mass.slice(a..b);
    let inv_inertia = arr.inv_inertia.slice(a..b);
    let touched = arr.touched.slice(a..b);
    let near_face = arr.near_face.slice(a..b);
    let kind = arr.kind.slice(a..b);
    // Each particle's values are loaded once into locals and stored once: a store followed by
    // an overlapping wider load of the same vector stalls store forwarding.
    for j in 0..x.len() {
        let im = inv_mass[j];
        let drift_to = |vp: Vec3, xj: Vec3| {
            let mut xp = xj + vp * dt;
            if near_face[j] {
                k.domain.wrap(&mut xp);
            }
            xp
        };
        if im > 0.0 {
            // load, then store only if set: a swap would be a locked instruction
            let contact = kick_end && touched[j].load(Ordering::Relaxed);
            if !GRAV && kick_end && !contact {
                // Free flight: F = T = 0 exactly, so both half kicks add +0; (v + 0) + 0 = v + 0
                // bit for bit, which is v itself once v has absorbed one +0 (quiet).
                if !quiet[j] {
                    f[j] = Vec3::zeros();
                    t[j] = Vec3::zeros();
                    v[j] += Vec3::zeros();
                    if ROT {
                        w[j] += Vec3::zeros();
                    }
                    quiet[j] = true;
                }
                if drift {
                    let vp = v[j];
                    x[j] = drift_to(vp, x[j]);
                    see(kind[j] as usize, j, vp);
                }
                continue;
            }
            quiet[j] = false;
            let (fp, tp) = if kick_end {
                let g = if contact {
                    touched[j].store(false, Ordering::Relaxed);
                    gather(a + j, arr)
                } else {
                    (Vec3::zeros(), Vec3::zeros())
                };
                f[j] = g.0;
                t[j] = g.1;
                g
            } else {
                (f[j], t[j])
            };
            // Half kick v += (F/m + g)·dt/2, ω += T/I·dt/2, in MercuryDPM's order of operations
            // (BaseParticle::integrateBeforeForceComputation); the closing kick of one step and
            // the opening kick of the next add the same increment twice.
            let acc = if GRAV { fp * im + k.gravity } else { fp * im };
            let dv = acc * 0.5 * dt;
            let mut vp = v[j];
            if kick_end {
                vp += dv;
            }
            if drift {
                vp += dv;
                x[j] = drift_to(vp, x[j]);
                see(kind[j] as usize, j, vp);
                if let (true, Some(g)) = (GRAV, k.periodic_gravity) {
                    *gravity_work += super::energy::fixed(g.dot(&vp) * dt / im);
                }
            }
            v[j] = vp;
            if ROT {
                let dw = tp * inv_inertia[j] * 0.5 * dt;
                let mut wp = w[j];
                if kick_end {
                    wp += dw;
                }
                if drift {
                    wp += dw;
                }
                w[j] = wp;
            }
        } else if drift {
            let vp = v[j];
            x[j] = drift_to(vp, x[j]);
            see(kind[j] as usize, j, vp);
        }
    }
    vmax2.map(|lanes| lanes.into_iter().fold(0.0, f64::max))
}

/// Sum of the forces and torques of particle `a`'s active pairs, in the order of partner ids.
///
/// # Safety
/// `arr` is valid and no thread writes the slots of `a`'s pairs during the call.
#[inline(always)]
pub(super) unsafe fn gather<H>(a: usize, arr: &Arrays<H>) -> (Vec3, Vec3) {
    let mut f = Vec3::zeros();
    let mut t = Vec3::zeros();
    let (s, e) = (
        arr.adj_start.get(a) as usize,
        arr.adj_start.get(a + 1) as usize,
    );
    for &entry in arr.adj.slice(s..e) {
        let k = (entry >> 1) as usize;
        if arr.active.get(k) {
            let o = arr.out.get(k);
            if entry & 1 == 0 {
                f += o.f;
                t += o.torque_p;
            } else {
                f -= o.f;
                t += o.torque_i;
            }
        }
    }
    (f, t)
}
