//! The pair pass: each candidate pair's force into its own slot, at the drifted positions with
//! the half-step velocities; a pair that is not touching forgets its history.

use std::sync::atomic::{AtomicBool, Ordering};

use super::arrays::Arrays;
use super::energy::{fixed, Flows};
use super::guard::Breach;
use crate::contact::{ContactLaw, Dissipated, PairInput};
use crate::state::{Domain, Motion, PairForce, Tally};
use crate::step::neighbor::rebuild::{Pairs, CLASSES};
use crate::step::team::SharedSlice;
use crate::Vec3;

/// What the pair pass reads besides the slots: the law, the box, the time step (time) and the
/// particles.
pub(super) struct PairView<'a, L> {
    pub law: &'a L,
    pub domain: &'a Domain,
    pub dt: f64,
    pub x: SharedSlice<Vec3>,
    pub v: SharedSlice<Vec3>,
    pub w: SharedSlice<Vec3>,
    pub radius: &'a [f64],
    pub inv_mass: &'a [f64],
    /// How each particle moves: the wall group of a prescribed one.
    pub motion: &'a [Motion],
    /// Largest overlap allowed, as a fraction of the smaller radius (the run guard).
    pub overlap: f64,
    /// Largest excess of a contact's energy account allowed, as a fraction of the energy it took
    /// (the run guard; [`Tally::book`]).
    pub excess: f64,
}

/// What the run guard learns from the contacts of a pass: the largest overlap as a fraction of
/// the smaller radius (0 without a contact; infinite when a contact's force or torque is not
/// finite), the largest excess of a contact's energy account as a fraction of the energy it took
/// (0 when none gave out more than it took; infinite when one gave energy it never took), and the
/// work the prescribed particles did on the free ones this step, in fixed point
/// ([`super::energy::fixed`]); and for the ledgers, the contacts' dissipation and the walls'
/// impulses (`flows.wall_work` is left to the caller, who takes `wall_work`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Watch {
    pub worst: f64,
    pub pumped: f64,
    pub wall_work: i128,
    pub flows: Flows,
}

impl Watch {
    fn add(&mut self, other: Watch) {
        self.worst = self.worst.max(other.worst);
        self.pumped = self.pumped.max(other.pumped);
        self.wall_work += other.wall_work;
        self.flows.add(&other.flows);
    }
}

/// A pair in contact after its force evaluation, for the run guard: its overlap `delta`
/// (length) and the power (energy/time) its previous force delivers at the velocities of this
/// evaluation (`None` for a new contact, not in contact at the evaluation before); for the
/// energy ledger, what its dissipative parts took over the step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Touch {
    pub delta: f64,
    pub before: Option<f64>,
    pub dissipated: Dissipated,
}

/// A range of pairs and their slots.
pub(super) struct PairSlots<'a, H> {
    pub p: &'a [u32],
    pub i: &'a [u32],
    pub history: &'a mut [H],
    pub active: &'a mut [bool],
    pub out: &'a mut [PairForce],
    pub tally: &'a mut [Tally],
}

/// Pair pass over pair chunk `c`: first its live ends are grown to every pair whose gap at the
/// build the particles can have `closed` since (length, by class of speed: see
/// [`crate::step::neighbor::rebuild::gap_closed`]), then the live prefix of each class is visited. A
/// pair beyond reach cannot touch yet; its slot stays inactive, exactly as a full pass would
/// leave it. The first `CLASSES / 2` classes hold interior pairs, whose direct separation is
/// their minimum image. One call per chunk rather than per class: fewer loop starts. Returns
/// what the run guard learns from the chunk's contacts.
///
/// # Safety
/// `arr` is valid; chunk `c` is taken by this thread alone; no thread writes the particles of
/// its pairs until it is marked done.
#[inline(never)]
pub(super) unsafe fn pair_chunk<L: ContactLaw>(
    view: &PairView<'_, L>,
    arr: &Arrays<L::History>,
    touched: &[AtomicBool],
    c: usize,
    closed: [f64; 3],
) -> Watch {
    let mut watch = Watch::default();
    let seg = arr.pair_ranges.get(c);
    let ends = arr.live.at_mut(c);
    let gap = arr.gap.slice(0..arr.gap.len());
    for (class, end) in ends.iter_mut().enumerate() {
        let reach = closed[class % 3] + 1e-9;
        while *end < seg[class + 1] && gap[*end] <= reach {
            *end += 1;
        }
    }
    for class in 0..CLASSES {
        let (a, b) = (seg[class], ends[class]);
        if a == b {
            continue;
        }
        let slots = PairSlots {
            p: arr.p.slice(a..b),
            i: arr.i.slice(a..b),
            history: arr.history.slice_mut(a..b),
            active: arr.active.slice_mut(a..b),
            out: arr.out.slice_mut(a..b),
            tally: arr.tally.slice_mut(a..b),
        };
        let seen = if class < CLASSES / 2 {
            pair_range::<L, false>(view, touched, slots)
        } else {
            pair_range::<L, true>(view, touched, slots)
        };
        watch.add(seen);
    }
    watch
}

/// The run guard's report of the first contact among the pairs `slots` whose force or torque is
/// not finite, whose overlap exceeds `view.overlap` times its smaller radius, or whose energy
/// account's excess exceeds `view.excess` times the energy it took, found again from the slots
/// and positions the pair pass left.
///
/// # Safety
/// As [`pair_chunk`] for the chunks holding these pairs, after it, before their particles move.
#[cold]
pub(super) unsafe fn contact_breach<L: ContactLaw>(
    view: &PairView<'_, L>,
    arr: &Arrays<L::History>,
    slots: impl Iterator<Item = usize>,
) -> Option<Breach> {
    slots.filter(|&k| arr.active.get(k)).find_map(|k| {
        let (p, i) = (arr.p.get(k) as usize, arr.i.get(k) as usize);
        if !finite(&arr.out.get(k)) {
            return Some(Breach::Force { p, i });
        }
        let delta = overlap::<L, true>(view, p, i);
        let limit = view.overlap * view.radius[p].min(view.radius[i]);
        if delta > limit {
            return Some(Breach::Overlap { p, i, delta, limit });
        }
        let tally = arr.tally.get(k);
        let excess = tally.excess(view.law.normal_energy(delta, r_star(view, p, i)));
        (tally.open && excess > view.excess * tally.taken).then_some(Breach::Pumped {
            p,
            i,
            excess,
            taken: tally.taken,
            limit: view.excess * tally.taken,
        })
    })
}

/// Forces of a range of pairs into their slots; sets the `touched` flag of the free particles
/// of every contact. `PERIODIC` false for interior pairs. Returns what the run guard learns
/// from its contacts.
///
/// # Safety
/// As [`pair_force`] for every pair of the range.
#[inline(always)]
pub(super) unsafe fn pair_range<L: ContactLaw, const PERIODIC: bool>(
    view: &PairView<'_, L>,
    touched: &[AtomicBool],
    mut s: PairSlots<'_, L::History>,
) -> Watch {
    let mut watch = Watch::default();
    let mut visit = |k: usize, s: &mut PairSlots<'_, L::History>| {
        let (p, i) = (s.p[k] as usize, s.i[k] as usize);
        let Some(r) = touching::<L, PERIODIC>(view, p, i) else {
            if s.active[k] {
                opened(view, k, s, &mut watch.flows);
            }
            return;
        };
        contact(view, touched, r, k, s, &mut watch);
    };
    let n = s.p.len().min(s.i.len()).min(s.active.len());
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut))]
    let mut k = 0;
    #[cfg(target_arch = "x86_64")]
    {
        // Four pairs at a time: those of which none touches and none was active, the great
        // majority, have nothing to do.
        let (x, radius) = (view.x.slice(0..view.radius.len()), view.radius);
        let period = view.domain.period();
        while k + 4 <= n {
            // SAFETY: `k + 4 <= n`; the pair's indices are particles of the views.
            if simd::any_of_four::<PERIODIC>(x, radius, period, s.p, s.i, s.active, k) {
                for k in k..k + 4 {
                    visit(k, &mut s);
                }
            }
            k += 4;
        }
    }
    for k in k..n {
        visit(k, &mut s);
    }
    watch
}

/// The distance test of interior pairs, several at a time.
#[cfg(target_arch = "x86_64")]
mod simd {
    use std::arch::x86_64::*;

    use crate::Vec3;

    /// Whether any of the pairs `k..k + 4` (particles `p`, `i`) touches,
    /// |x_P − x_I|² < (r_P + r_I)² as [`super::touching`] computes it (squares summed
    /// (x² + y²) + z²; with `PERIODIC`, the minimum image of [`crate::state::Domain::min_image`]
    /// for the periods `period`), or was active.
    ///
    /// # Safety
    /// `k + 4` is at most the length of `p`, `i` and `active`; their particles index `x` and
    /// `radius`.
    #[inline(always)]
    pub(super) unsafe fn any_of_four<const PERIODIC: bool>(
        x: &[Vec3],
        radius: &[f64],
        period: Vec3,
        p: &[u32],
        i: &[u32],
        active: &[bool],
        k: usize,
    ) -> bool {
        let (x, radius) = (x.as_ptr().cast::<f64>(), radius.as_ptr());
        // d − L·([d > L/2] − [d < −L/2]) lane by lane, as `Domain::min_image`
        let image = |d: __m128d, l: __m128d| {
            let one = _mm_set1_pd(1.0);
            let up = _mm_and_pd(_mm_cmpgt_pd(d, _mm_mul_pd(_mm_set1_pd(0.5), l)), one);
            let down = _mm_and_pd(_mm_cmplt_pd(d, _mm_mul_pd(_mm_set1_pd(-0.5), l)), one);
            _mm_sub_pd(d, _mm_mul_pd(l, _mm_sub_pd(up, down)))
        };
        let (l_xy, l_z) = (_mm_set_pd(period.y, period.x), _mm_set1_pd(period.z));
        // (x, y) and z of x_P − x_I, and r_P + r_I, of pair m
        let pair = |m: usize| {
            let (a, b) = (
                *p.get_unchecked(k + m) as usize,
                *i.get_unchecked(k + m) as usize,
            );
            let (xa, xb) = (x.add(3 * a), x.add(3 * b));
            let xy = _mm_sub_pd(_mm_loadu_pd(xa), _mm_loadu_pd(xb));
            let z = _mm_sub_sd(_mm_load_sd(xa.add(2)), _mm_load_sd(xb.add(2)));
            let sum = _mm_add_sd(_mm_load_sd(radius.add(a)), _mm_load_sd(radius.add(b)));
            if PERIODIC {
                (image(xy, l_xy), z, sum)
            } else {
                (xy, z, sum)
            }
        };
        // bit m set when pair m of the two touches
        let two = |m: usize| {
            let ((xy0, z0, r0), (xy1, z1, r1)) = (pair(m), pair(m + 1));
            let (s0, s1) = (_mm_mul_pd(xy0, xy0), _mm_mul_pd(xy1, xy1));
            let z = _mm_unpacklo_pd(z0, z1);
            let z = if PERIODIC { image(z, l_z) } else { z };
            let d2 = _mm_add_pd(
                _mm_add_pd(_mm_unpacklo_pd(s0, s1), _mm_unpackhi_pd(s0, s1)),
                _mm_mul_pd(z, z),
            );
            let reach = _mm_unpacklo_pd(r0, r1);
            _mm_movemask_pd(_mm_cmplt_pd(d2, _mm_mul_pd(reach, reach)))
        };
        let was = active.as_ptr().add(k).cast::<u32>().read_unaligned();
        (two(0) | two(2)) != 0 || was != 0
    }
}

/// Force of pair (p, i) into its slot (history, active flag, force); a pair that is not
/// touching forgets its history. The run guard is not consulted (the forces before the first
/// step).
///
/// # Safety
/// `p` and `i` index the views, and no thread writes their positions or velocities during the
/// call.
#[inline(always)]
pub(super) unsafe fn pair_force<L: ContactLaw, const PERIODIC: bool>(
    view: &PairView<'_, L>,
    p: usize,
    i: usize,
    slot: (&mut L::History, &mut bool, &mut PairForce),
) {
    match touching::<L, PERIODIC>(view, p, i) {
        Some(r) => {
            evaluate(view, p, i, r, slot);
        }
        None => forget(slot.0, slot.1),
    }
}

/// The separation x_P − x_I of pair (p, i) (minimum image with `PERIODIC`), if the spheres
/// overlap.
///
/// # Safety
/// As [`pair_force`].
#[inline(always)]
unsafe fn touching<L, const PERIODIC: bool>(
    view: &PairView<'_, L>,
    p: usize,
    i: usize,
) -> Option<Vec3> {
    let direct = view.x.get(p) - view.x.get(i);
    let r = if PERIODIC {
        view.domain.min_image(direct)
    } else {
        direct
    };
    let sum = view.radius[p] + view.radius[i];
    (r.norm_squared() < sum * sum).then_some(r)
}

/// A pair that is not touching: an active one forgets its history.
#[inline(always)]
fn forget<H: Default>(history: &mut H, active: &mut bool) {
    if *active {
        *active = false;
        *history = H::default();
    }
}

/// A contact in slot `k` of `s` that has just opened: forgets its history, and books what its
/// springs still held at zero overlap as released by the slider (the Coulomb cap μ·|fn| closes
/// as the contact opens; when the law splits its dissipation and a free particle is in it). Out
/// of line and cold: a contact ends once in many pair visits.
///
/// # Safety
/// As [`pair_force`] for the pair in slot `k`.
#[cold]
#[inline(never)]
unsafe fn opened<L: ContactLaw>(
    view: &PairView<'_, L>,
    k: usize,
    s: &mut PairSlots<'_, L::History>,
    flows: &mut Flows,
) {
    let (p, i) = (s.p[k] as usize, s.i[k] as usize);
    let free = view.inv_mass[p] > 0.0 || view.inv_mass[i] > 0.0;
    book_release(view.law, &s.history[k], free, flows);
    forget(&mut s.history[k], &mut s.active[k]);
}

/// Books what the springs of a contact that has just opened (history `history`, its last) still
/// held at zero overlap, stored_energy(0, h) − normal_energy(0), as released by the slider, when
/// the law splits its dissipation and a free particle is in it (`free`).
#[inline(always)]
fn book_release<L: ContactLaw>(law: &L, history: &L::History, free: bool, flows: &mut Flows) {
    if L::SPLITS_DISSIPATION && free {
        let held = law.stored_energy(0.0, 0.0, history) - law.normal_energy(0.0, 0.0);
        flows.dissipated[2] += fixed(held);
    }
}

/// Books, as [`opened`] does, the contacts the last pair-list rebuild closed because their
/// particles had separated in the drift before it ([`Pairs::dropped`]): the pair pass of the
/// same step, which would have booked them, no longer sees them active. Call right after the
/// rebuild, in the step it ran in.
#[cold]
pub(super) fn book_dropped<L: ContactLaw>(law: &L, pairs: &Pairs<L::History>, flows: &mut Flows) {
    for (history, free) in pairs.dropped() {
        book_release(law, history, free, flows);
    }
}

/// The force of the contact in slot `k` of `s` (separation `r`, overlapping), its run guard
/// and its particles' `touched` flags, out of line: the loop over all pairs then keeps its
/// registers for the pairs that do not touch, the great majority.
///
/// # Safety
/// As [`pair_force`] for the pair in slot `k`.
#[inline(never)]
unsafe fn contact<L: ContactLaw>(
    view: &PairView<'_, L>,
    touched: &[AtomicBool],
    r: Vec3,
    k: usize,
    s: &mut PairSlots<'_, L::History>,
    watch: &mut Watch,
) {
    let (p, i) = (s.p[k] as usize, s.i[k] as usize);
    let (history, active, out) = (&mut s.history[k], &mut s.active[k], &mut s.out[k]);
    let Some(touch) = evaluate(view, p, i, r, (history, active, out)) else {
        return;
    };
    guard_contact(view, p, i, touch, (history, out, &mut s.tally[k]), watch);
    book_flows(view, p, i, &touch.dissipated, out, &mut watch.flows);
    // only free particles gather (and clear their flag)
    for q in [p, i] {
        if view.inv_mass[q] > 0.0 {
            touched[q].store(true, Ordering::Relaxed);
        }
    }
}

/// The force of pair (p, i) at separation `r` (overlapping) into its slot, its history updated
/// over the step; returns what the run guard needs of it.
///
/// # Safety
/// As [`pair_force`].
#[inline(always)]
unsafe fn evaluate<L: ContactLaw>(
    view: &PairView<'_, L>,
    p: usize,
    i: usize,
    r: Vec3,
    (history, active, out): (&mut L::History, &mut bool, &mut PairForce),
) -> Option<Touch> {
    let input = PairInput {
        r,
        rad_p: view.radius[p],
        rad_i: view.radius[i],
        inv_mass_p: view.inv_mass[p],
        inv_mass_i: view.inv_mass[i],
        v_p: view.v.get(p),
        v_i: view.v.get(i),
        w_p: view.w.get(p),
        w_i: view.w.get(i),
    };
    let kin = input.kinematics()?;
    let before = active.then(|| power(out, [input.v_p, input.v_i, input.w_p, input.w_i]));
    let (force, dissipated) = view.law.evaluate_dissipating(&kin, history, view.dt);
    *out = force;
    *active = true;
    Some(Touch {
        delta: kin.delta,
        before,
        dissipated,
    })
}

/// The ledgers' share of a contact just evaluated (force `out` on P, its dissipation over the
/// step `lost`): with a free particle in it, its dissipation (when the law splits it) and, with
/// a wall particle, the impulse out.f·dt the wall group receives (I receives −out.f). Part of
/// [`contact`], off the loop over all pairs.
#[inline(always)]
fn book_flows<L: ContactLaw>(
    view: &PairView<'_, L>,
    p: usize,
    i: usize,
    lost: &Dissipated,
    out: &PairForce,
    flows: &mut Flows,
) {
    let (wall_p, wall_i) = (view.motion[p], view.motion[i]);
    let wall = match (wall_p, wall_i) {
        (Motion::Prescribed(_), Motion::Prescribed(_)) => return,
        (Motion::Prescribed(g), Motion::Free) => Some((g, out.f)),
        (Motion::Free, Motion::Prescribed(g)) => Some((g, -out.f)),
        (Motion::Free, Motion::Free) => None,
    };
    if L::SPLITS_DISSIPATION {
        let d = &mut flows.dissipated;
        d[0] += fixed(lost.normal);
        d[1] += fixed(lost.tangential);
        d[2] += fixed(lost.slide);
    }
    if let Some((g, f)) = wall {
        let j = &mut flows.impulse[usize::from(g.min(1))];
        for (c, jc) in j.iter_mut().enumerate() {
            *jc += fixed(f[c] * view.dt);
        }
    }
}

/// The power (energy/time) force `o` delivers to the pair at velocities [v_P, v_I, ω_P, ω_I]:
/// F·(v_P − v_I) + T_P·ω_P + T_I·ω_I.
#[inline(always)]
fn power(o: &PairForce, [v_p, v_i, w_p, w_i]: [Vec3; 4]) -> f64 {
    o.f.dot(&(v_p - v_i)) + o.torque_p.dot(&w_p) + o.torque_i.dot(&w_i)
}

/// Whether a contact's force and torques are finite: a NaN or ±∞ component makes their sum
/// non-finite (a force that is not finite is how a velocity would become so).
#[inline(always)]
fn finite(o: &PairForce) -> bool {
    let sum = |v: Vec3| v.x + v.y + v.z;
    (sum(o.f) + sum(o.torque_p) + sum(o.torque_i)).is_finite()
}

/// The run guard, for a contact just evaluated (`touch`, and its slot: history, force and energy
/// account): raises `watch.worst` to the overlap as a fraction of the smaller radius, or to
/// infinity when the force or torques are not finite; books the step's work in the account and
/// raises `watch.pumped` to its excess as a fraction of what it took; and adds a wall's work on
/// its free partner over this step, F·U·dt with F the force on the free particle and U the
/// wall's velocity. Part of [`contact`], off the loop over all pairs.
///
/// # Safety
/// As [`pair_force`].
#[inline(always)]
unsafe fn guard_contact<L: ContactLaw>(
    view: &PairView<'_, L>,
    p: usize,
    i: usize,
    touch: Touch,
    (history, out, tally): (&L::History, &PairForce, &mut Tally),
    watch: &mut Watch,
) {
    let depth = touch.delta / view.radius[p].min(view.radius[i]);
    watch.worst = if finite(out) {
        watch.worst.max(depth)
    } else {
        f64::INFINITY
    };
    let (free_p, free_i) = (view.inv_mass[p] > 0.0, view.inv_mass[i] > 0.0);
    if !free_p && !free_i {
        // two prescribed particles: no energy reaches a free one
        return;
    }
    let at = [view.v.get(p), view.v.get(i), view.w.get(p), view.w.get(i)];
    // F_n·(v_(n−½) + v_(n+½))·dt/2: half of each of the two forces at these velocities.
    let work = 0.5 * view.dt * (touch.before.unwrap_or(0.0) + power(out, at));
    let r_star = r_star(view, p, i);
    let normal = view.law.normal_energy(touch.delta, r_star);
    let held_now = || view.law.stored_energy(touch.delta, r_star, history);
    let excess = tally.book(work, normal, touch.before.is_none(), held_now);
    if excess > 0.0 {
        watch.pumped = watch.pumped.max(excess / tally.taken);
    }
    // out.f is the force on P; the force on I is −out.f.
    let power = if !free_p {
        -out.f.dot(&at[0])
    } else if !free_i {
        out.f.dot(&at[1])
    } else {
        return;
    };
    watch.wall_work += super::energy::fixed(power * view.dt);
}

/// The effective radius R* = r_P·r_I/(r_P + r_I) (length) of pair (p, i).
#[inline(always)]
fn r_star<L>(view: &PairView<'_, L>, p: usize, i: usize) -> f64 {
    let (rp, ri) = (view.radius[p], view.radius[i]);
    rp * ri / (rp + ri)
}

/// The overlap r_P + r_I − |x_P − x_I| (length) of pair (p, i); `PERIODIC` false for interior
/// pairs, whose direct separation is their minimum image.
///
/// # Safety
/// As [`pair_force`].
#[inline(always)]
unsafe fn overlap<L, const PERIODIC: bool>(view: &PairView<'_, L>, p: usize, i: usize) -> f64 {
    let direct = view.x.get(p) - view.x.get(i);
    let r = if PERIODIC {
        view.domain.min_image(direct)
    } else {
        direct
    };
    view.radius[p] + view.radius[i] - r.norm()
}

#[cfg(test)]
mod tests {
    use crate::state::Domain;
    use crate::Vec3;

    /// The four-pair test finds a block to visit exactly when the per-pair test would: some pair
    /// touches (|x_P − x_I|² < (r_P + r_I)², with the minimum image for periodic pairs) or was
    /// active; pairs at exactly touching distance, across the periodic faces and far apart.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn four_pairs_at_a_time_find_the_blocks_one_pair_at_a_time_finds() {
        let domain = Domain::new(
            Vec3::zeros(),
            Vec3::new(20.0, 10.3923048454133, 22.0),
            [true, true, false],
        );
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |scale: f64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            scale * ((seed >> 11) as f64 / (1u64 << 53) as f64)
        };
        let n = 400;
        let mut x: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(next(20.0), next(10.3923048454133), next(22.0)))
            .collect();
        let radius: Vec<f64> = (0..n).map(|_| 0.5 + next(0.1)).collect();
        // particle 2k+1 sits near particle 2k: closer, at, or just beyond touching, or across a face
        for k in 0..n / 2 {
            let (a, b) = (2 * k, 2 * k + 1);
            let sum = radius[a] + radius[b];
            let d = [0.9 * sum, sum, 1.0000001 * sum, 3.0 * sum][k % 4];
            x[b] = x[a] + Vec3::new(d, 0.0, 0.0);
            if k % 3 == 0 {
                x[b].x -= 20.0;
            }
        }
        let p: Vec<u32> = (0..n as u32)
            .step_by(2)
            .chain((0..n as u32).step_by(3))
            .collect();
        let i: Vec<u32> = (1..n as u32)
            .step_by(2)
            .chain((1..n as u32).step_by(3))
            .collect();
        let m = p.len().min(i.len()) / 4 * 4;
        let active: Vec<bool> = (0..m).map(|k| k % 37 == 5).collect();
        let touches = |k: usize, periodic: bool| {
            let (a, b) = (p[k] as usize, i[k] as usize);
            let direct = x[a] - x[b];
            let r = if periodic {
                domain.min_image(direct)
            } else {
                direct
            };
            let sum = radius[a] + radius[b];
            r.norm_squared() < sum * sum
        };
        let mut visited = [0, 0];
        for k in (0..m).step_by(4) {
            let want = |periodic| (k..k + 4).any(|k| touches(k, periodic) || active[k]);
            let period = domain.period();
            // SAFETY: k + 4 <= m; every index is below n.
            let got = unsafe {
                [
                    super::simd::any_of_four::<false>(&x, &radius, period, &p, &i, &active, k),
                    super::simd::any_of_four::<true>(&x, &radius, period, &p, &i, &active, k),
                ]
            };
            assert_eq!(got, [want(false), want(true)], "block at {k}");
            for (v, g) in visited.iter_mut().zip(got) {
                *v += usize::from(g);
            }
        }
        // both kinds of block occur, and the image makes a difference
        assert!(visited[0] > 0 && visited[1] > visited[0] && visited[1] < m / 4);
    }
}
