//! The arrays the team's threads share during a run, as raw views ([`SharedSlice`]): taken by
//! thread 0 while it holds the state exclusively (at the start of a run and at the end of every
//! rebuild), read by every thread after the barrier that follows.
//!
//! Who touches what between two barriers of a step:
//! - the particle pass writes the particle arrays (`x`, `v`, `w`, `f`, `t`, `quiet`) of the
//!   chunks it takes only; it reads the slots (`active`, `out`) of its particles' pairs once the
//!   pair chunks that hold them are marked done;
//! - the pair pass writes the slots (`history`, `active`, `out`, `tally`) of its chunk's pairs and
//!   its chunk's `live` ends only, and reads the positions and velocities of its pairs' particles, whose
//!   particle chunk cannot start until this pair chunk is marked done;
//! - `touched` flags are atomics, set by the pair pass, cleared by the particle pass;
//! - everything else (radii, masses, flags of the build, the pair list, the plan) is written only
//!   by a rebuild and read-only in between.

use std::sync::atomic::AtomicBool;

use crate::state::{Motion, PairForce, Tally};
use crate::step::neighbor::rebuild::{ListState, CLASSES};
use crate::step::team::SharedSlice;
use crate::Vec3;

/// Views of every array a step's threads share.
#[derive(Default)]
pub(super) struct Arrays<H> {
    pub x: SharedSlice<Vec3>,
    pub v: SharedSlice<Vec3>,
    pub w: SharedSlice<Vec3>,
    pub f: SharedSlice<Vec3>,
    pub t: SharedSlice<Vec3>,
    pub radius: SharedSlice<f64>,
    pub inv_mass: SharedSlice<f64>,
    pub inv_inertia: SharedSlice<f64>,
    pub motion: SharedSlice<Motion>,
    pub touched: SharedSlice<AtomicBool>,
    pub near_face: SharedSlice<bool>,
    pub quiet: SharedSlice<bool>,
    pub kind: SharedSlice<u8>,
    /// Original index of each particle (the wall contacts' slots are by it).
    pub id: SharedSlice<u32>,
    pub p: SharedSlice<u32>,
    pub i: SharedSlice<u32>,
    pub adj_start: SharedSlice<u32>,
    pub adj: SharedSlice<u32>,
    pub history: SharedSlice<H>,
    pub active: SharedSlice<bool>,
    pub out: SharedSlice<PairForce>,
    pub tally: SharedSlice<Tally>,
    pub particle_chunks: SharedSlice<(usize, usize)>,
    pub pair_ranges: SharedSlice<[usize; CLASSES + 1]>,
    pub live: SharedSlice<[usize; CLASSES]>,
    pub gap: SharedSlice<f64>,
    pub needs: SharedSlice<(u32, u32)>,
}

impl<H> Clone for Arrays<H> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<H> Copy for Arrays<H> {}

impl<H> Arrays<H> {
    /// Views of the arrays of `l`, valid until its next rebuild.
    pub fn of(l: &mut ListState<'_, H>) -> Self {
        let (pt, pairs, plan, flags) = (
            &mut *l.particles,
            &mut *l.pairs,
            &mut *l.plan,
            &mut *l.flags,
        );
        Arrays {
            x: SharedSlice::of(&mut pt.x),
            v: SharedSlice::of(&mut pt.v),
            w: SharedSlice::of(&mut pt.w),
            f: SharedSlice::of(&mut pt.f),
            t: SharedSlice::of(&mut pt.t),
            radius: SharedSlice::of(&mut pt.radius),
            inv_mass: SharedSlice::of(&mut pt.inv_mass),
            inv_inertia: SharedSlice::of(&mut pt.inv_inertia),
            motion: SharedSlice::of(&mut pt.motion),
            touched: SharedSlice::of(&mut flags.touched),
            near_face: SharedSlice::of(&mut flags.near_face),
            quiet: SharedSlice::of(&mut flags.quiet),
            kind: SharedSlice::of(&mut flags.kind),
            id: SharedSlice::of(l.id),
            p: SharedSlice::of(&mut pairs.list.p),
            i: SharedSlice::of(&mut pairs.list.i),
            adj_start: SharedSlice::of(&mut pairs.list.adj_start),
            adj: SharedSlice::of(&mut pairs.list.adj),
            history: SharedSlice::of(&mut pairs.history),
            active: SharedSlice::of(&mut pairs.active),
            out: SharedSlice::of(&mut pairs.out),
            tally: SharedSlice::of(&mut pairs.tally),
            particle_chunks: SharedSlice::of(&mut plan.particle_chunks),
            pair_ranges: SharedSlice::of(&mut plan.pair_ranges),
            live: SharedSlice::of(&mut plan.live),
            gap: SharedSlice::of(&mut plan.gap),
            needs: SharedSlice::of(&mut plan.needs),
        }
    }
}
