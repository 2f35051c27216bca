//! The particle pass: the closing half kick of one step (after gathering its pair forces) fused
//! with the opening half kick and the drift of the next, velocity Verlet in MercuryDPM's order of
//! operations (`BaseParticle::integrateBeforeForceComputation`).

use std::sync::atomic::Ordering;

use super::arrays::Arrays;
use super::walls::WallViews;
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
/// Two loops: the kicks, then the drift of every particle. Without gravity a closing kick only
/// visits the particles that touched something or are not yet quiet (found eight flags at a
/// time); the drift x += v·dt of every particle is one uniform loop over the coordinates. Each
/// particle's arithmetic is the same as in one fused loop, so the bits are too.
///
/// # Safety
/// `arr` is valid (taken after the last rebuild); no other thread touches particles `a..b`
/// during the call; with `kick_end`, every pair chunk holding a pair of these particles is done,
/// so is their wall chunk, and no thread writes those pairs' slots, these particles' wall slots
/// (`walls`) or their `touched` flags.
#[inline(never)]
pub(super) unsafe fn particle_pass<H, const ROT: bool, const GRAV: bool>(
    k: &Kick<'_>,
    (arr, walls): (&Arrays<H>, &WallViews<H>),
    a: usize,
    b: usize,
    kick_end: bool,
    drift: bool,
    gravity_work: &mut i128,
) -> [f64; 2] {
    let dt = k.dt;
    // Plain slices of this chunk: bounds and base pointers stay in registers.
    let x = arr.x.slice_mut(a..b);
    let v = arr.v.slice_mut(a..b);
    let w = arr.w.slice_mut(a..b);
    let f = arr.f.slice_mut(a..b);
    let t = arr.t.slice_mut(a..b);
    // Read eight at a time below as well as one at a time here: a raw pointer, no reference.
    let quiet = arr.quiet.slice_mut(a..b).as_mut_ptr();
    let inv_mass = arr.inv_mass.slice(a..b);
    let inv_inertia = arr.inv_inertia.slice(a..b);
    let touched = arr.touched.slice(a..b);
    // The half kicks of particle `j` if it is free: the closing one (with `kick_end`; its pair forces
    // gathered when it touched something) and the opening one (with `drift`).
    let mut kick = |j: usize, contact: bool| {
        let im = inv_mass[j];
        if im <= 0.0 {
            // a prescribed particle has nothing to kick
            *quiet.add(j) = true;
            return;
        }
        if !GRAV && kick_end && !contact {
            // Free flight: F = T = 0 exactly, so both half kicks add +0; (v + 0) + 0 = v + 0
            // bit for bit, which is v itself once v has absorbed one +0 (quiet).
            if !*quiet.add(j) {
                f[j] = Vec3::zeros();
                t[j] = Vec3::zeros();
                v[j] += Vec3::zeros();
                if ROT {
                    w[j] += Vec3::zeros();
                }
                *quiet.add(j) = true;
            }
            return;
        }
        *quiet.add(j) = false;
        let (fp, tp) = if kick_end {
            let g = if contact {
                touched[j].store(false, Ordering::Relaxed);
                let (mut f, mut t) = gather(a + j, arr);
                if walls.count > 0 {
                    walls.add_to(arr.id.get(a + j), &mut f, &mut t);
                }
                (f, t)
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
    };
    if !GRAV && kick_end {
        // SAFETY: no thread writes these flags during the call (see above), so reading them
        // eight at a time, without atomic loads, races with nothing; `AtomicBool` has the
        // layout of `bool`, one byte that is 0 or 1.
        let (set, clear) = (
            touched.as_ptr().cast::<u8>(),
            quiet.cast::<u8>().cast_const(),
        );
        for_each_set(set, Some(clear), b - a, |j| {
            kick(j, touched[j].load(Ordering::Relaxed))
        });
    } else {
        for j in 0..x.len() {
            kick(j, kick_end && touched[j].load(Ordering::Relaxed));
        }
    }
    if !drift {
        return [0.0; 2];
    }
    let speeds = drift_all(x, v, arr.kind.slice(a..b), dt);
    let near_face = arr.near_face.slice(a..b).as_ptr().cast::<u8>();
    for_each_set(near_face, None, b - a, |j| k.domain.wrap(&mut x[j]));
    speeds
}

/// Calls `visit(j)` for every `j < n` where byte `set[j]` is not 0 or, with `clear`, byte
/// `clear[j]` is 0, in increasing order; the flags (bytes 0 or 1) are read eight at a time
/// before `visit` is called for any of the eight, so `visit` may change them.
///
/// # Safety
/// `set` and `clear` point to `n` readable bytes each that no other thread writes during the
/// call.
#[inline(always)]
unsafe fn for_each_set(
    set: *const u8,
    clear: Option<*const u8>,
    n: usize,
    mut visit: impl FnMut(usize),
) {
    let ones = u64::from_le_bytes([1; 8]);
    let word =
        |flags: *const u8, j: usize| u64::from_le_bytes(flags.add(j).cast::<[u8; 8]>().read());
    let mut j = 0;
    while j + 8 <= n {
        let mut hits = word(set, j);
        if let Some(clear) = clear {
            hits |= word(clear, j) ^ ones;
        }
        while hits != 0 {
            let byte = hits.trailing_zeros() as usize / 8;
            visit(j + byte);
            hits &= !(0xff << (8 * byte));
        }
        j += 8;
    }
    for j in j..n {
        if *set.add(j) != 0 || clear.is_some_and(|c| *c.add(j) == 0) {
            visit(j);
        }
    }
}

/// The drift x += v·dt of every particle of a chunk, in place; returns the largest squared
/// speed |v|² of a particle of kind 0 [0] and of kind 1 [1] (0 for none). Squared speeds sum
/// (vx² + vy²) + vz², as `Vec3::norm_squared`; a NaN one counts for no maximum. Four particles
/// at a time with AVX2 where the CPU has it, then two at a time with SSE2 (the x86-64
/// baseline), then one at a time: the same operations on each particle in every path, and no
/// fused multiply–add, so the same bits.
#[inline(always)]
fn drift_all(x: &mut [Vec3], v: &[Vec3], kind: &[u8], dt: f64) -> [f64; 2] {
    const _: () = assert!(std::mem::size_of::<Vec3>() == 3 * std::mem::size_of::<f64>());
    let n = x.len().min(v.len()).min(kind.len());
    let mut top = [0.0f64; 2];
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut))]
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    {
        let (xs, vs) = (x.as_mut_ptr().cast::<f64>(), v.as_ptr().cast::<f64>());
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2; `Vec3` is three contiguous f64, so `x` and `v` hold
            // 3n of them.
            done = unsafe { simd::drift_fours(xs, vs, kind, n / 4, dt, &mut top) };
        }
        // SAFETY: SSE2 is part of the x86-64 baseline; as above.
        done += unsafe {
            simd::drift_twos(
                xs.add(3 * done),
                vs.add(3 * done),
                &kind[done..],
                (n - done) / 2,
                dt,
                &mut top,
            )
        };
    }
    for j in done..n {
        let vp = v[j];
        x[j] += vp * dt;
        let s2 = vp.norm_squared();
        let m = &mut top[usize::from(kind[j] != 0)];
        if s2 > *m {
            *m = s2;
        }
    }
    top
}

/// The drift several particles at a time: the operations of the scalar loop, lane by lane.
/// `max(a, b)` below is `a > b ? a : b` (MAXPD), so a NaN squared speed leaves a maximum as it
/// was, as in the scalar loop.
#[cfg(target_arch = "x86_64")]
mod simd {
    use std::arch::x86_64::*;

    /// Drifts the first `2 * count` particles of the coordinates `x` by the velocities `v`
    /// (three f64 each) over `dt`; raises `top` to the largest squared speeds by kind. Returns
    /// the number of particles drifted.
    ///
    /// # Safety
    /// `x` and `v` hold `6 * count` f64 each and do not overlap; `kind` has `2 * count`
    /// entries at least.
    #[inline(always)]
    pub(super) unsafe fn drift_twos(
        x: *mut f64,
        v: *const f64,
        kind: &[u8],
        count: usize,
        dt: f64,
        top: &mut [f64; 2],
    ) -> usize {
        let step = _mm_set1_pd(dt);
        let mut slow = _mm_setzero_pd();
        let mut fast = _mm_setzero_pd();
        for q in 0..count {
            let (xq, vq) = (x.add(6 * q), v.add(6 * q));
            // particle 2q is (v0.0, v0.1, v1.0), particle 2q+1 is (v1.1, v2.0, v2.1)
            let v0 = _mm_loadu_pd(vq);
            let v1 = _mm_loadu_pd(vq.add(2));
            let v2 = _mm_loadu_pd(vq.add(4));
            _mm_storeu_pd(xq, _mm_add_pd(_mm_loadu_pd(xq), _mm_mul_pd(v0, step)));
            _mm_storeu_pd(
                xq.add(2),
                _mm_add_pd(_mm_loadu_pd(xq.add(2)), _mm_mul_pd(v1, step)),
            );
            _mm_storeu_pd(
                xq.add(4),
                _mm_add_pd(_mm_loadu_pd(xq.add(4)), _mm_mul_pd(v2, step)),
            );
            let (s0, s1, s2) = (_mm_mul_pd(v0, v0), _mm_mul_pd(v1, v1), _mm_mul_pd(v2, v2));
            let xx = _mm_shuffle_pd::<0b10>(s0, s1);
            let yy = _mm_shuffle_pd::<0b01>(s0, s2);
            let zz = _mm_shuffle_pd::<0b10>(s1, s2);
            let speed2 = _mm_add_pd(_mm_add_pd(xx, yy), zz);
            let is_fast = _mm_castsi128_pd(_mm_set_epi64x(
                -i64::from(kind[2 * q + 1] != 0),
                -i64::from(kind[2 * q] != 0),
            ));
            fast = _mm_max_pd(_mm_and_pd(is_fast, speed2), fast);
            slow = _mm_max_pd(_mm_andnot_pd(is_fast, speed2), slow);
        }
        let mut lanes = [[0.0; 2]; 2];
        _mm_storeu_pd(lanes[0].as_mut_ptr(), slow);
        _mm_storeu_pd(lanes[1].as_mut_ptr(), fast);
        for (t, l) in top.iter_mut().zip(lanes) {
            *t = l.into_iter().fold(*t, f64::max);
        }
        2 * count
    }

    /// As [`drift_twos`], four particles at a time.
    ///
    /// # Safety
    /// As [`drift_twos`] with `12 * count` f64 and `4 * count` kinds; the CPU has AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn drift_fours(
        x: *mut f64,
        v: *const f64,
        kind: &[u8],
        count: usize,
        dt: f64,
        top: &mut [f64; 2],
    ) -> usize {
        let step = _mm256_set1_pd(dt);
        let mut slow = _mm256_setzero_pd();
        let mut fast = _mm256_setzero_pd();
        let kinds = kind.as_ptr();
        for q in 0..count {
            let (xq, vq) = (x.add(12 * q), v.add(12 * q));
            // v0 = (x0 y0 z0 x1), v1 = (y1 z1 x2 y2), v2 = (z2 x3 y3 z3)
            let v0 = _mm256_loadu_pd(vq);
            let v1 = _mm256_loadu_pd(vq.add(4));
            let v2 = _mm256_loadu_pd(vq.add(8));
            for (k, vk) in [v0, v1, v2].into_iter().enumerate() {
                let xk = xq.add(4 * k);
                _mm256_storeu_pd(
                    xk,
                    _mm256_add_pd(_mm256_loadu_pd(xk), _mm256_mul_pd(vk, step)),
                );
            }
            let (s0, s1, s2) = (
                _mm256_mul_pd(v0, v0),
                _mm256_mul_pd(v1, v1),
                _mm256_mul_pd(v2, v2),
            );
            // squares regrouped by component: (x0 y0 | y3 z3), (z0 x1 | z2 x3)
            let ends = _mm256_permute2f128_pd::<0x30>(s0, s2);
            let mid = _mm256_permute2f128_pd::<0x21>(s0, s2);
            let p = _mm256_blend_pd::<0b1100>(ends, s1); // (x0 y0 | x2 y2)
            let q2 = _mm256_blend_pd::<0b1100>(s1, ends); // (y1 z1 | y3 z3)
            let xx = _mm256_shuffle_pd::<0b1010>(p, mid);
            let yy = _mm256_shuffle_pd::<0b0101>(p, q2);
            let zz = _mm256_shuffle_pd::<0b1010>(mid, q2);
            let speed2 = _mm256_add_pd(_mm256_add_pd(xx, yy), zz);
            // kinds 0 or 1 → lanes of all zeros or all ones
            let k4 = _mm_cvtsi32_si128(kinds.add(4 * q).cast::<i32>().read_unaligned());
            let is_fast = _mm256_castsi256_pd(_mm256_sub_epi64(
                _mm256_setzero_si256(),
                _mm256_cvtepu8_epi64(k4),
            ));
            fast = _mm256_max_pd(_mm256_and_pd(is_fast, speed2), fast);
            slow = _mm256_max_pd(_mm256_andnot_pd(is_fast, speed2), slow);
        }
        let mut lanes = [[0.0; 4]; 2];
        _mm256_storeu_pd(lanes[0].as_mut_ptr(), slow);
        _mm256_storeu_pd(lanes[1].as_mut_ptr(), fast);
        for (t, l) in top.iter_mut().zip(lanes) {
            *t = l.into_iter().fold(*t, f64::max);
        }
        4 * count
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The drift as the fused per-particle loop computed it: x + v·dt, then |v|² into the
    /// maximum of the particle's kind when larger.
    fn one_at_a_time(x: &mut [Vec3], v: &[Vec3], kind: &[u8], dt: f64) -> [f64; 2] {
        let mut top = [0.0f64; 2];
        for j in 0..x.len() {
            x[j] += v[j] * dt;
            let s2 = v[j].norm_squared();
            let m = &mut top[kind[j] as usize];
            if s2 > *m {
                *m = s2;
            }
        }
        top
    }

    /// `n` particles with coordinates of many magnitudes and signs (−0, subnormals, large),
    /// one velocity NaN, kinds mixed.
    fn particles(n: usize) -> (Vec<Vec3>, Vec<Vec3>, Vec<u8>) {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let mantissa = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let special = [-0.0, 1e-310, 3.0e7, -2.5];
            match seed >> 60 {
                0 => special[(seed >> 56) as usize & 3],
                s => mantissa * 10f64.powi(s as i32 - 8),
            }
        };
        let mut vec = |_| Vec3::new(next(), next(), next());
        let x: Vec<Vec3> = (0..n).map(&mut vec).collect();
        let mut v: Vec<Vec3> = (0..n).map(&mut vec).collect();
        if n > 5 {
            v[5].y = f64::NAN;
        }
        let kind = (0..n).map(|j| ((j * 7 + j / 3) % 2) as u8).collect();
        (x, v, kind)
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// The drift of every path (AVX2 where the CPU has it, SSE2, the scalar tail) gives the bits
    /// of the fused loop it replaced: positions and largest squared speeds by kind, for counts
    /// that leave every possible tail.
    #[test]
    fn every_drift_path_gives_the_bits_of_one_particle_at_a_time() {
        let dt = 7.192545031528827e-05;
        for n in [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 13, 64, 67] {
            let (x0, v, kind) = particles(n);
            let mut want = x0.clone();
            let top_want = one_at_a_time(&mut want, &v, &kind, dt);
            let mut got = x0.clone();
            let mut tops = vec![drift_all(&mut got, &v, &kind, dt)];
            let mut runs = vec![got];
            #[cfg(target_arch = "x86_64")]
            {
                // SSE2 alone over the even prefix, the rest one at a time
                let mut got = x0.clone();
                let (xs, vs) = (got.as_mut_ptr().cast(), v.as_ptr().cast());
                let mut top = [0.0; 2];
                // SAFETY: SSE2 is baseline; `got` and `v` hold n particles.
                let done = unsafe { simd::drift_twos(xs, vs, &kind, n / 2, dt, &mut top) };
                let rest = one_at_a_time(&mut got[done..], &v[done..], &kind[done..], dt);
                tops.push(std::array::from_fn(|c| top[c].max(rest[c])));
                runs.push(got);
            }
            for (got, top) in runs.iter().zip(&tops) {
                for j in 0..n {
                    for c in 0..3 {
                        assert!(same(got[j][c], want[j][c]), "n {n}, particle {j}, axis {c}");
                    }
                }
                assert!(
                    same(top[0], top_want[0]) && same(top[1], top_want[1]),
                    "n {n}"
                );
            }
        }
    }
}
