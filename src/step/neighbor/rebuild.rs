//! The pair-list rebuild as the time step runs it: the particles are re-ordered in memory by cell,
//! the candidate pairs found again, each contact's history carried over by original ids, and
//! both passes of the step cut into chunks. Pairs are sorted within each chunk by class and gap
//! bin, so that a step visits only the pairs whose gap can have closed since the build.
//!
//! A rebuild runs on a [`Crew`]: its serial phases on the lead thread alone (the others wait at
//! a barrier), its parallel phases (permutation, search, sorting of the pair chunks) in chunks
//! the crew shares out, each thread writing only its chunks' elements through the views the lead
//! took for that phase. The result does not depend on the crew.

use std::sync::atomic::AtomicBool;

use super::{NeighborBuilder, PairList};
use crate::state::{Domain, History, Motion, PairForce, Particles, Tally};
use crate::step::team::{balanced_ranges, Crew, Shared, SharedSlice};
use crate::Vec3;

/// Gap bins of the pair list: one of overlapping pairs, then sixteen of a sixteenth of the skin
/// each, and one more for the round-off at the cut.
pub const GAP_BINS: usize = 18;

/// Classes of pairs, each visited up to its own live end: `3·across + kind_P + kind_I`, where
/// `across` marks a pair that may need a periodic image before the next build and the kinds are
/// the particles' speed classes: a pair's gap closes at most by the sum of its particles' class
/// displacement bounds, so pairs of slow particles are visited later.
pub const CLASSES: usize = 6;

/// Chunks of each pass per thread when the team has more than one: enough that a thread done
/// early takes over a small piece of its partner's work (the wait at a pass's end is at most
/// about one chunk), few enough that starting a chunk (an atomic operation and a fresh loop over
/// each of its arrays) stays cheap. Measurements: `docs/performance.md`.
const CHUNKS_PER_THREAD: usize = 8;

/// Most particles in a chunk: a larger system is cut into more chunks than the team's, so that
/// the pair pass, which sweeps a chunk's positions and radii (32 bytes a particle, 1 MiB at
/// most) once per class and gap bin, finds them in the core's own cache. Measured in
/// `docs/performance.md` ("Chunks of at most 32768 particles").
pub const CHUNK_PARTICLES: usize = 32768;

/// A free particle is fast, at a build, when its speed exceeds this fraction of the fastest
/// free particle's.
const SLOW_FRACTION: f64 = 0.1;

/// How far a slow–slow [0], slow–fast [1] and fast–fast [2] pair can have closed its gap since
/// the last build, from the displacement bounds of a slow [0] and a fast [1] particle (length).
pub fn gap_closed(bound: [f64; 2]) -> [f64; 3] {
    [2.0 * bound[0], bound[0] + bound[1], 2.0 * bound[1]]
}

/// The key of pair (p, i) by original indices, ordered by p then i.
pub fn key(p: u32, i: u32) -> u64 {
    ((p as u64) << 32) | i as u64
}

/// The candidate pairs in memory indices and each pair's slots: its contact history `H`, the
/// force of its last evaluation and the run guard's energy account of the contact.
#[derive(Clone, Debug)]
pub struct Pairs<H> {
    /// Candidate pairs (within r_P + r_I + skin at the last build).
    pub list: PairList,
    /// The contact law's history of each pair; `H::default()` when not in contact.
    pub history: Vec<H>,
    /// Whether each pair was in contact at the last force evaluation.
    pub active: Vec<bool>,
    /// Force and torques of each active pair at the last force evaluation.
    pub out: Vec<PairForce>,
    /// The run guard's energy account of each active pair ([`Tally`]).
    pub tally: Vec<Tally>,
    /// The last build's slots (history, force, account) while a rebuild carries them over.
    carried: Vec<H>,
    carried_out: Vec<PairForce>,
    carried_tally: Vec<Tally>,
    /// The contacts the last rebuild closed because their particles no longer touch: each one's
    /// index in `carried` and whether a free particle is in it.
    dropped: Vec<(u32, bool)>,
}

impl<H> Pairs<H> {
    /// The contacts the last rebuild closed because their particles had separated in the drift
    /// before it (the pair pass of that step would have closed them): each one's history at its
    /// last force evaluation and whether a free particle is in it. Valid until the next rebuild.
    pub fn dropped(&self) -> impl Iterator<Item = (&H, bool)> + '_ {
        self.dropped
            .iter()
            .map(|&(k, free)| (&self.carried[k as usize], free))
    }
}

impl<H> Default for Pairs<H> {
    fn default() -> Self {
        Pairs {
            list: PairList::default(),
            history: Vec::new(),
            active: Vec::new(),
            out: Vec::new(),
            tally: Vec::new(),
            carried: Vec::new(),
            carried_out: Vec::new(),
            carried_tally: Vec::new(),
            dropped: Vec::new(),
        }
    }
}

/// Per-particle flags of the passes (memory order), set or cleared at every build.
#[derive(Debug, Default)]
pub struct Flags {
    /// Set by the pair pass for both particles of every contact, read and cleared by the next
    /// particle pass: a particle without contacts skips the gather (its sum is exactly zero).
    pub touched: Vec<AtomicBool>,
    /// Whether each particle was within a skin of a periodic face at the last build; the others
    /// cannot cross one before the next build and skip the wrap.
    pub near_face: Vec<bool>,
    /// Whether each particle is quiet: its force and torque slots hold zero and its velocities
    /// have absorbed a +0 kick (no −0 component), so that a free flight changes neither and only
    /// drifts it. A prescribed particle is marked quiet at its first particle pass: it has no
    /// kick. Cleared at every build: a restore or a first force evaluation, the only changes to
    /// velocities and forces from outside a run, each rebuild first, so the flags hold across
    /// runs.
    pub quiet: Vec<bool>,
    /// Speed class at the last build: 1 for the fast particles (faster than [`SLOW_FRACTION`]
    /// of the fastest free particle, and all prescribed ones), 0 for the others.
    pub kind: Vec<u8>,
}

/// How the passes of a step are cut into chunks, and the rebuild's scratch.
#[derive(Default)]
pub struct Plan {
    /// Threads of the step.
    pub threads: usize,
    /// The particle pass's chunks: ranges of particles of equal cost.
    pub particle_chunks: Vec<(usize, usize)>,
    /// The pair pass's chunks: ranges of pairs of equal count, in build order.
    pub pair_chunks: Vec<(usize, usize)>,
    /// Bounds of each pair chunk's classes after sorting: class `c` is `ranges[c]..ranges[c +
    /// 1]`, each sorted by gap bin (see [`CLASSES`]).
    pub pair_ranges: Vec<[usize; CLASSES + 1]>,
    /// End of the live prefix of each pair chunk's classes: the pairs a step visits; reset at
    /// every build and grown as the displacement bounds grow.
    pub live: Vec<[usize; CLASSES]>,
    /// Lower edge of the gap bin of each pair at the build (length): the gap |r| − (r_P + r_I)
    /// rounded down to a sixteenth of the skin; one bin below zero for overlapping pairs.
    pub gap: Vec<f64>,
    /// The pair chunks a particle chunk's gather waits for: every chunk with a pair of its
    /// particles is in this range of chunk indices (which may hold others).
    pub needs: Vec<(u32, u32)>,
    scratch: Scratch,
}

/// Buffers a rebuild reuses from one build to the next.
#[derive(Default)]
struct Scratch {
    order: Vec<u32>,
    /// The particles and ids in the new memory order, filled by the crew and then swapped in.
    next: Particles,
    next_id: Vec<u32>,
    /// The pairs each chunk of a build's search found, concatenated into the pair list.
    found: Vec<(Vec<u32>, Vec<u32>)>,
    /// P and I of the pairs in their final order, filled by the crew and then swapped in.
    next_p: Vec<u32>,
    next_i: Vec<u32>,
    old_keys: Vec<(u64, u32)>,
    fill: Vec<u32>,
    /// Class and gap bin of each pair, `class · GAP_BINS + bin`, in build order.
    bin: Vec<u8>,
    /// Build-order index of each pair, in the order of the chunks' bins.
    sorted: Vec<u32>,
    /// Lowest and one past the highest memory index of a particle of each pair chunk's pairs.
    pair_hull: Vec<(u32, u32)>,
    /// The views the crew writes through in the current parallel phase, taken by the lead.
    views: Views,
}

/// What the crew writes in the parallel phases of a rebuild, one element range per chunk.
#[derive(Clone, Copy, Default)]
struct Views {
    next_x: SharedSlice<Vec3>,
    next_v: SharedSlice<Vec3>,
    next_w: SharedSlice<Vec3>,
    next_f: SharedSlice<Vec3>,
    next_t: SharedSlice<Vec3>,
    next_radius: SharedSlice<f64>,
    next_inv_mass: SharedSlice<f64>,
    next_inv_inertia: SharedSlice<f64>,
    next_motion: SharedSlice<Motion>,
    next_id: SharedSlice<u32>,
    found: SharedSlice<(Vec<u32>, Vec<u32>)>,
    bin: SharedSlice<u8>,
    sorted: SharedSlice<u32>,
    gap: SharedSlice<f64>,
    next_p: SharedSlice<u32>,
    next_i: SharedSlice<u32>,
    pair_ranges: SharedSlice<[usize; CLASSES + 1]>,
    pair_hull: SharedSlice<(u32, u32)>,
    active: SharedSlice<bool>,
}

impl Plan {
    /// A plan for a team of `threads` threads (no chunks until the first build).
    pub fn new(threads: usize) -> Self {
        Plan {
            threads,
            ..Plan::default()
        }
    }

    /// Chunks of each pass over `particles` particles: one for a team of one,
    /// [`CHUNKS_PER_THREAD`] a thread for a larger one, and more when a chunk would hold more
    /// than [`CHUNK_PARTICLES`] particles.
    pub fn chunks(&self, particles: usize) -> usize {
        let team = if self.threads == 1 {
            1
        } else {
            self.threads * CHUNKS_PER_THREAD
        };
        team.max(particles.div_ceil(CHUNK_PARTICLES))
    }

    /// Starts every pair chunk's live prefixes empty.
    pub fn reset_live(&mut self) {
        for (live, ranges) in self.live.iter_mut().zip(&self.pair_ranges) {
            live.copy_from_slice(&ranges[..CLASSES]);
        }
    }
}

/// The pair list, the particles it indexes, and everything that changes with them.
pub struct ListState<'a, H> {
    pub particles: &'a mut Particles,
    /// Original index of each particle in memory order.
    pub id: &'a mut Vec<u32>,
    pub pairs: &'a mut Pairs<H>,
    pub builder: &'a mut NeighborBuilder,
    pub plan: &'a mut Plan,
    pub flags: &'a mut Flags,
    /// The views the crew writes the pairs' carried slots through while sorting the pair
    /// chunks.
    pub history: SharedSlice<H>,
    pub out: SharedSlice<PairForce>,
    pub tally: SharedSlice<Tally>,
}

impl<'a, H> ListState<'a, H> {
    /// The list state of these parts (no view taken yet).
    pub fn new(
        particles: &'a mut Particles,
        id: &'a mut Vec<u32>,
        pairs: &'a mut Pairs<H>,
        builder: &'a mut NeighborBuilder,
        plan: &'a mut Plan,
        flags: &'a mut Flags,
    ) -> Self {
        ListState {
            particles,
            id,
            pairs,
            builder,
            plan,
            flags,
            history: SharedSlice::default(),
            out: SharedSlice::default(),
            tally: SharedSlice::default(),
        }
    }
}

/// Part `part` of `0..n` split into `parts` nearly equal contiguous ranges.
fn chunk(n: usize, parts: usize, part: usize) -> std::ops::Range<usize> {
    n * part / parts..n * (part + 1) / parts
}

/// `to[k] = from[order[k]]` for `k` in `range`.
///
/// # Safety
/// As [`SharedSlice::slice_mut`] for `range` of `to`.
unsafe fn permute_range<T: Copy>(
    from: &[T],
    to: SharedSlice<T>,
    order: &[u32],
    range: std::ops::Range<usize>,
) {
    for (t, &o) in to.slice_mut(range.clone()).iter_mut().zip(&order[range]) {
        *t = from[o as usize];
    }
}

/// Re-orders the particles by cell, rebuilds the pair list, carries every contact's history
/// over (matched by original ids), and splits both passes into chunks.
///
/// # Safety
/// Every thread of the crew calls this with the same `list` and `domain`, and holds no
/// reference into `list` across the call. The serial phases take `list` exclusively on the lead
/// while the others wait at the crew's barrier; in a parallel phase every thread reads `list`
/// and writes only the elements of the chunks it takes, through the views the lead took before
/// the phase; no vector is resized or swapped outside the lead's phases.
pub unsafe fn rebuild<H: History>(
    crew: Crew<'_>,
    list: &Shared<ListState<'_, H>>,
    domain: &Domain,
) {
    if crew.leads() {
        // SAFETY: serial phase: the other threads wait at the sync below.
        let l = list.exclusive();
        l.remember_contacts(domain);
    }
    crew.sync();
    let (n, chunks) = {
        let l = list.read();
        let n = l.particles.len();
        (n, l.plan.chunks(n))
    };
    crew.share(chunks, |part| {
        // SAFETY: parallel phase: the particles are only read; each chunk writes its own range
        // of the new order's arrays.
        let l = list.read();
        let (pt, v, o) = (&*l.particles, &l.plan.scratch.views, &l.plan.scratch.order);
        let r = chunk(n, chunks, part);
        permute_range(&pt.x, v.next_x, o, r.clone());
        permute_range(&pt.v, v.next_v, o, r.clone());
        permute_range(&pt.w, v.next_w, o, r.clone());
        permute_range(&pt.f, v.next_f, o, r.clone());
        permute_range(&pt.t, v.next_t, o, r.clone());
        permute_range(&pt.radius, v.next_radius, o, r.clone());
        permute_range(&pt.inv_mass, v.next_inv_mass, o, r.clone());
        permute_range(&pt.inv_inertia, v.next_inv_inertia, o, r.clone());
        permute_range(&pt.motion, v.next_motion, o, r.clone());
        permute_range(l.id, v.next_id, o, r);
    });
    if crew.leads() {
        // SAFETY: serial phase.
        list.exclusive().swap_in_new_order();
    }
    crew.sync();
    crew.share(chunks, |part| {
        // SAFETY: parallel phase: each chunk writes only its own list of found pairs.
        let l = list.read();
        let pt = &*l.particles;
        let motion = &pt.motion;
        let (found_p, found_i) = l.plan.scratch.views.found.at_mut(part);
        found_p.clear();
        found_i.clear();
        // Wall–wall pairs never interact (neighbouring wall spheres overlap by round-off).
        l.builder.search(
            domain,
            &pt.x,
            &pt.radius,
            l.id,
            chunk(n, chunks, part),
            |a, b| motion[a] == Motion::Free || motion[b] == Motion::Free,
            (found_p, found_i),
        );
    });
    if crew.leads() {
        // SAFETY: serial phase.
        list.exclusive().plan_chunks(domain);
    }
    crew.sync();
    // SAFETY: parallel phase: each chunk writes only its own pairs' range.
    crew.share(chunks, |part| list.read().sort_chunk(domain, part));
    if crew.leads() {
        // SAFETY: serial phase; the other threads have returned.
        list.exclusive().finish();
    }
}

impl<H: History> ListState<'_, H> {
    /// Lead phase: the history of the contacts by original ids, and the contacts whose particles
    /// no longer touch ([`Pairs::dropped`]); the new memory order; room for the permutation and
    /// the search, and the views the crew writes them through.
    fn remember_contacts(&mut self, domain: &Domain) {
        let chunks = self.plan.chunks(self.particles.len());
        let s = &mut self.plan.scratch;
        let n = self.particles.len();
        s.old_keys.clear();
        self.pairs.dropped.clear();
        let (list, pt) = (&self.pairs.list, &*self.particles);
        for k in 0..list.p.len() {
            if self.pairs.active[k] {
                let (a, b) = (list.p[k] as usize, list.i[k] as usize);
                s.old_keys.push((key(self.id[a], self.id[b]), k as u32));
                // The touching test of `sort_chunk`, on the same positions: a contact it will
                // not carry over.
                let sum = pt.radius[a] + pt.radius[b];
                let touching = domain.min_image(pt.x[a] - pt.x[b]).norm_squared() < sum * sum;
                if !touching {
                    let free = pt.inv_mass[a] > 0.0 || pt.inv_mass[b] > 0.0;
                    self.pairs.dropped.push((k as u32, free));
                }
            }
        }
        s.old_keys.sort_unstable();
        let pairs = &mut *self.pairs;
        std::mem::swap(&mut pairs.carried, &mut pairs.history);
        std::mem::swap(&mut pairs.carried_out, &mut pairs.out);
        std::mem::swap(&mut pairs.carried_tally, &mut pairs.tally);
        // Memory order by cell; the builder is then ready to search the re-ordered particles.
        self.builder
            .order(domain, &self.particles.x, self.id, &mut s.order);
        if s.next.len() != n {
            // room only: every element is written by the permutation
            s.next = self.particles.clone();
        }
        s.next_id.resize(n, 0);
        s.found.resize_with(chunks, Default::default);
        let next = &mut s.next;
        s.views = Views {
            next_x: SharedSlice::of(&mut next.x),
            next_v: SharedSlice::of(&mut next.v),
            next_w: SharedSlice::of(&mut next.w),
            next_f: SharedSlice::of(&mut next.f),
            next_t: SharedSlice::of(&mut next.t),
            next_radius: SharedSlice::of(&mut next.radius),
            next_inv_mass: SharedSlice::of(&mut next.inv_mass),
            next_inv_inertia: SharedSlice::of(&mut next.inv_inertia),
            next_motion: SharedSlice::of(&mut next.motion),
            next_id: SharedSlice::of(&mut s.next_id),
            found: SharedSlice::of(&mut s.found),
            ..Views::default()
        };
    }

    /// Lead phase: the permuted particles and ids become the current ones.
    fn swap_in_new_order(&mut self) {
        let s = &mut self.plan.scratch;
        std::mem::swap(self.particles, &mut s.next);
        std::mem::swap(self.id, &mut s.next_id);
    }

    /// Lead phase, once the pairs are found: the pair list, the particles' flags and speed
    /// classes, the chunks of both passes, room for the pairs' new order and history, and the
    /// views the crew sorts the pair chunks through.
    fn plan_chunks(&mut self, domain: &Domain) {
        let chunks = self.plan.chunks(self.particles.len());
        let plan = &mut *self.plan;
        let s = &mut plan.scratch;
        let list = &mut self.pairs.list;
        list.p.clear();
        list.i.clear();
        for (found_p, found_i) in &s.found {
            list.p.extend_from_slice(found_p);
            list.i.extend_from_slice(found_i);
        }
        let pt = &*self.particles;
        let n_pairs = list.p.len();
        let flags = &mut *self.flags;
        // All clear between a particle pass and a pair pass; only the length can change.
        flags
            .touched
            .resize_with(pt.len(), || AtomicBool::new(false));
        flags.quiet.clear();
        flags.quiet.resize(pt.len(), false);
        let fastest = (0..pt.len())
            .filter(|&a| pt.inv_mass[a] > 0.0)
            .map(|a| pt.v[a].norm())
            .fold(0.0, f64::max);
        let slow = SLOW_FRACTION * fastest;
        flags.kind.clear();
        flags.kind.extend(
            (0..pt.len()).map(|a| u8::from(pt.inv_mass[a] == 0.0 || pt.v[a].norm() > slow)),
        );
        // Chunks: contiguous particles (a slab of space) of equal cost, and contiguous pairs of
        // equal count; the pair list is in owner (memory, so space) order, so a chunk's pairs
        // lie mostly among one particle chunk and its neighbours.
        let inv_mass = &pt.inv_mass;
        let weight = |a: usize| if inv_mass[a] > 0.0 { 8 } else { 2 };
        balanced_ranges(pt.len(), chunks, weight, &mut plan.particle_chunks);
        balanced_ranges(n_pairs, chunks, |_| 1, &mut plan.pair_chunks);
        let skin = self.builder.skin;
        let interior = |a: usize| {
            (0..3).all(|k| {
                !domain.periodic[k]
                    || (pt.x[a][k] >= domain.lo[k] + skin && pt.x[a][k] < domain.hi[k] - skin)
            })
        };
        flags.near_face.clear();
        flags.near_face.extend((0..pt.len()).map(|a| !interior(a)));
        s.bin.resize(n_pairs, 0);
        s.sorted.resize(n_pairs, 0);
        plan.gap.resize(n_pairs, 0.0);
        s.next_p.resize(n_pairs, 0);
        s.next_i.resize(n_pairs, 0);
        plan.pair_ranges.resize(chunks, [0; CLASSES + 1]);
        s.pair_hull.resize(chunks, (0, 0));
        plan.needs.resize(chunks, (0, 0));
        plan.live.resize(chunks, [0; CLASSES]);
        // Room only: each chunk clears its pairs' history in `sort_chunk`.
        let pairs = &mut *self.pairs;
        pairs.history.resize(n_pairs, H::default());
        pairs.active.resize(n_pairs, false);
        pairs.out.resize(n_pairs, PairForce::default());
        pairs.tally.resize(n_pairs, Tally::default());
        s.views = Views {
            bin: SharedSlice::of(&mut s.bin),
            sorted: SharedSlice::of(&mut s.sorted),
            gap: SharedSlice::of(&mut plan.gap),
            next_p: SharedSlice::of(&mut s.next_p),
            next_i: SharedSlice::of(&mut s.next_i),
            pair_ranges: SharedSlice::of(&mut plan.pair_ranges),
            pair_hull: SharedSlice::of(&mut s.pair_hull),
            active: SharedSlice::of(&mut pairs.active),
            ..Views::default()
        };
        self.history = SharedSlice::of(&mut pairs.history);
        self.out = SharedSlice::of(&mut pairs.out);
        self.tally = SharedSlice::of(&mut pairs.tally);
    }

    /// Parallel phase of a rebuild: chunk `part` of the pairs in its final order and with its
    /// history. Within a chunk, interior pairs (no periodic image needed until the next build)
    /// come first, then the others; each part in bins of gap (GAP_BINS − 1 bins of a sixteenth
    /// of the skin, after one of all overlapping pairs), each bin in build (owner memory) order.
    /// A step visits only the prefix of bins whose gap the particles can have closed (see
    /// [`Plan::live`]), in near-memory order.
    ///
    /// # Safety
    /// Called once per chunk in the sorting phase of [`rebuild`]; writes only the elements of
    /// chunk `part`'s pairs and its own entries of the chunk tables.
    unsafe fn sort_chunk(&self, domain: &Domain, part: usize) {
        let s = &self.plan.scratch;
        let v = &s.views;
        let pt = &*self.particles;
        let flags = &*self.flags;
        let list = &self.pairs.list;
        let (pa, pb) = self.plan.pair_chunks[part];
        let skin = self.builder.skin;
        let bin_width = skin / 16.0;
        let bins = v.bin.slice_mut(pa..pb);
        for (b, k) in bins.iter_mut().zip(pa..pb) {
            let (p, i) = (list.p[k] as usize, list.i[k] as usize);
            let direct = pt.x[p] - pt.x[i];
            let r = domain.min_image(direct);
            let cut = pt.radius[p] + pt.radius[i] + skin;
            let plain = !flags.near_face[p]
                && !flags.near_face[i]
                && r == direct
                && (0..3).all(|k| !domain.periodic[k] || cut + skin < 0.5 * domain.lengths()[k]);
            let gap = r.norm() - (pt.radius[p] + pt.radius[i]);
            // floor(gap / width) + 1, clamped to the bins; the cast floors a non-negative
            // quotient without a call to libm's floor.
            let q = gap / bin_width;
            let bin = if skin > 0.0 && q >= 0.0 {
                (q as usize).min(GAP_BINS - 2) + 1
            } else {
                0
            };
            let class =
                3 * usize::from(!plain) + usize::from(flags.kind[p]) + usize::from(flags.kind[i]);
            *b = (class * GAP_BINS + bin) as u8;
        }
        // A stable counting sort of the chunk by (class, bin).
        let mut next = [0usize; CLASSES * GAP_BINS];
        for &b in bins.iter() {
            next[b as usize] += 1;
        }
        let gaps = v.gap.slice_mut(pa..pb);
        let mut at = pa;
        for (b, n) in next.iter_mut().enumerate() {
            let count = *n;
            *n = at;
            // Lower edge of the bin; overlapping pairs (bin 0) are always visited.
            gaps[at - pa..at - pa + count].fill((b % GAP_BINS) as f64 * bin_width - bin_width);
            at += count;
        }
        let mut ranges = [pb; CLASSES + 1];
        for (c, r) in ranges.iter_mut().take(CLASSES).enumerate() {
            *r = next[c * GAP_BINS];
        }
        *v.pair_ranges.at_mut(part) = ranges;
        let sorted = v.sorted.slice_mut(pa..pb);
        for (k, &b) in (pa..pb).zip(bins.iter()) {
            let slot = &mut next[b as usize];
            sorted[*slot - pa] = k as u32;
            *slot += 1;
        }
        let (next_p, next_i) = (v.next_p.slice_mut(pa..pb), v.next_i.slice_mut(pa..pb));
        let mut hull = (u32::MAX, 0);
        for j in 0..pb - pa {
            let from = sorted[j] as usize;
            let (p, i) = (list.p[from], list.i[from]);
            next_p[j] = p;
            next_i[j] = i;
            hull = (hull.0.min(p).min(i), hull.1.max(p + 1).max(i + 1));
        }
        *v.pair_hull.at_mut(part) = hull;
        let (history, active) = (self.history.slice_mut(pa..pb), v.active.slice_mut(pa..pb));
        let (out, tally) = (self.out.slice_mut(pa..pb), self.tally.slice_mut(pa..pb));
        history.fill(H::default());
        tally.fill(Tally::default());
        active.fill(false);
        if s.old_keys.is_empty() {
            return;
        }
        for j in 0..pb - pa {
            let (pm, im) = (next_p[j] as usize, next_i[j] as usize);
            // A contact the particles have just left would be closed by the coming force
            // pass; close it here, since that pass may skip pairs with a positive gap (the lead
            // phase listed it in `Pairs::dropped`, for the step to book what it held).
            let sum = pt.radius[pm] + pt.radius[im];
            let touching = domain.min_image(pt.x[pm] - pt.x[im]).norm_squared() < sum * sum;
            if !touching {
                continue;
            }
            let (p, i) = (self.id[pm], self.id[im]);
            if let Ok(o) = s.old_keys.binary_search_by_key(&key(p, i), |e| e.0) {
                let from = s.old_keys[o].1 as usize;
                history[j] = self.pairs.carried[from];
                out[j] = self.pairs.carried_out[from];
                tally[j] = self.pairs.carried_tally[from];
                active[j] = true;
            }
        }
    }

    /// Lead phase, last: the pairs in their sorted order, the chunks each gather waits for, the
    /// per-particle slot lists, and empty live prefixes.
    fn finish(&mut self) {
        let plan = &mut *self.plan;
        let s = &mut plan.scratch;
        let list = &mut self.pairs.list;
        std::mem::swap(&mut list.p, &mut s.next_p);
        std::mem::swap(&mut list.i, &mut s.next_i);
        let chunks = plan.pair_ranges.len();
        for (needs, &(a, b)) in plan.needs.iter_mut().zip(&plan.particle_chunks) {
            let hull = &s.pair_hull;
            let touches = |j: &usize| (hull[*j].0 as usize) < b && (hull[*j].1 as usize) > a;
            let first = (0..chunks).find(touches).unwrap_or(0);
            let end = (0..chunks).rev().find(touches).map_or(first, |j| j + 1);
            *needs = (first as u32, end as u32);
        }
        list.index(self.particles.len(), self.id, &mut s.fill);
        s.views = Views::default();
        self.history = SharedSlice::default();
        self.out = SharedSlice::default();
        self.tally = SharedSlice::default();
        plan.reset_live();
        self.make_room_for_next_build();
    }

    /// Room for the next rebuild's carried slots and contact keys, written once now so that
    /// their pages are in memory: the first rebuild of a run then costs what the later ones do,
    /// instead of faulting in tens of megabytes at 10⁵ spheres inside the stepping (a one-time
    /// set-up cost, like a peer's neighbour-list allocation before its time loop). Grows
    /// only, and appends only: the carried slots of the contacts this build dropped stay valid.
    fn make_room_for_next_build(&mut self) {
        let pairs = &mut *self.pairs;
        let n = pairs.history.len();
        if pairs.carried.len() < n {
            pairs.carried.resize(n, H::default());
            pairs.carried_out.resize(n, PairForce::default());
            pairs.carried_tally.resize(n, Tally::default());
        }
        let keys = &mut self.plan.scratch.old_keys;
        if keys.capacity() < n {
            keys.clear();
            keys.resize(n, (0, 0));
            keys.clear();
        }
    }
}
