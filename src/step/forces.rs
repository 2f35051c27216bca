//! The pair pass: each candidate pair's force into its own slot, at the drifted positions with
//! the half-step velocities; a pair that is not touching forgets its history.

use std::sync::atomic::{AtomicBool, Ordering};

use super::arrays::Arrays;
use super::guard::Breach;
use crate::contact::{ContactLaw, PairInput};
use crate::neighbor::rebuild::CLASSES;
use crate::state::{Domain, PairForce};
use crate::team::SharedSlice;
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
    /// Largest overlap allowed, as a fraction of the smaller radius (the run guard).
    pub overlap: f64,
}

/// A range of pairs and their slots.
pub(super) struct PairSlots<'a, H> {
    pub p: &'a [u32],
    pub i: &'a [u32],
    pub history: &'a mut [H],
    pub active: &'a mut [bool],
    pub out: &'a mut [PairForce],
}

/// Pair pass over pair chunk `c`: first its live ends are grown to every pair whose gap at the
/// build the particles can have `closed` since (length, by class of speed: see
/// [`crate::neighbor::rebuild::gap_closed`]), then the live prefix of each class is visited. A
/// pair beyond reach cannot touch yet; its slot stays inactive, exactly as a full pass would
/// leave it. The first `CLASSES / 2` classes hold interior pairs, whose direct separation is
/// their minimum image. One call per chunk rather than per class: fewer loop starts. Returns
/// the first overlap beyond the guard's limit, if any.
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
) -> Option<Breach> {
    let mut breach = None;
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
        };
        let found = if class < CLASSES / 2 {
            pair_range::<L, false>(view, touched, slots)
        } else {
            pair_range::<L, true>(view, touched, slots)
        };
        breach = breach.or(found);
    }
    breach
}

/// Forces of a range of pairs into their slots; sets the `touched` flag of the free particles
/// of every contact. `PERIODIC` false for interior pairs. Returns the first overlap beyond the
/// guard's limit, if any.
///
/// # Safety
/// As [`pair_force`] for every pair of the range.
#[inline(always)]
pub(super) unsafe fn pair_range<L: ContactLaw, const PERIODIC: bool>(
    view: &PairView<'_, L>,
    touched: &[AtomicBool],
    s: PairSlots<'_, L::History>,
) -> Option<Breach> {
    let mut breach = None;
    for k in 0..s.p.len() {
        let (p, i) = (s.p[k] as usize, s.i[k] as usize);
        let (history, active, out) = (&mut s.history[k], &mut s.active[k], &mut s.out[k]);
        if let Some((delta, limit)) = pair_force::<L, PERIODIC>(view, p, i, history, active, out) {
            breach.get_or_insert(Breach::Overlap { p, i, delta, limit });
        }
        if s.active[k] {
            // only free particles gather (and clear their flag)
            for q in [p, i] {
                if view.inv_mass[q] > 0.0 {
                    touched[q].store(true, Ordering::Relaxed);
                }
            }
        }
    }
    breach
}

/// Force of pair (p, i) into its slot; a pair that is not touching forgets its history. Returns
/// the overlap and its limit (length) when the overlap exceeds the guard's limit.
///
/// # Safety
/// `p` and `i` index the views, and no thread writes their positions or velocities during the
/// call.
#[inline(always)]
pub(super) unsafe fn pair_force<L: ContactLaw, const PERIODIC: bool>(
    view: &PairView<'_, L>,
    p: usize,
    i: usize,
    history: &mut L::History,
    active: &mut bool,
    out: &mut PairForce,
) -> Option<(f64, f64)> {
    let direct = view.x.get(p) - view.x.get(i);
    let r = if PERIODIC {
        view.domain.min_image(direct)
    } else {
        direct
    };
    let sum = view.radius[p] + view.radius[i];
    if r.norm_squared() >= sum * sum {
        if *active {
            *active = false;
            *history = L::History::default();
        }
        return None;
    }
    let input = PairInput {
        r,
        rad_p: view.radius[p],
        rad_i: view.radius[i],
        v_p: view.v.get(p),
        v_i: view.v.get(i),
        w_p: view.w.get(p),
        w_i: view.w.get(i),
    };
    let kin = input.kinematics()?;
    *out = view.law.evaluate(&kin, history, view.dt);
    *active = true;
    let limit = view.overlap * input.rad_p.min(input.rad_i);
    (kin.delta > limit).then_some((kin.delta, limit))
}
