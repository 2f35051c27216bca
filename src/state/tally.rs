//! A contact's energy account, kept by the run guard: what the contact force has given its two
//! particles and taken from them since the account opened, so that a contact that gives back
//! more than it took and than its springs held is found where it happens, however large the
//! system.

/// The energy account of one contact (energy units).
///
/// The work of a step is the contact's share of the particles' kinetic energy change under
/// kick–drift–kick: the force of step n acts over two half kicks, with the velocities before and
/// after it, so its work is F_n·(v_(n−½) + v_(n+½))·dt/2 summed over both particles, forces and
/// torques alike. For two spheres alone the sum over a collision is exactly their kinetic
/// energy's change.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tally {
    /// Whether the account is open; a contact found active without an open account (the first
    /// step of a run, or after a restore) opens it from its state at that step.
    pub open: bool,
    /// Net work the contact force did on its particles since the account opened.
    pub given: f64,
    /// Work the particles did on the contact (the steps' negative work, summed), plus the
    /// energy the contact held when the account opened: the scale the excess is judged on.
    pub taken: f64,
    /// Energy the contact's springs held when the account opened (0 for a new contact).
    pub held: f64,
}

impl Tally {
    /// Books the work `w` of one step (energy units; positive when given to the particles) and
    /// returns the excess: the energy given out plus what the normal spring holds now
    /// (`normal`), beyond what the contact held when the account opened. A passive contact keeps
    /// it at or below zero up to the scheme's truncation error, whatever its tangential spring
    /// does: what that spring holds and has yet to give back only lowers the excess. `new` says
    /// the contact was not in contact at the step before: its account opens afresh, holding
    /// nothing; an account still closed otherwise opens here, holding what the contact's springs
    /// hold now, normal and tangential (`held_now`, asked for only then), plus this step's work.
    #[inline(always)]
    pub fn book(&mut self, w: f64, normal: f64, new: bool, held_now: impl FnOnce() -> f64) -> f64 {
        if new || !self.open {
            let held = if new { 0.0 } else { w + held_now() };
            *self = Tally {
                open: true,
                given: 0.0,
                taken: held,
                held,
            };
        }
        self.given += w;
        if w < 0.0 {
            self.taken -= w;
        }
        self.excess(normal)
    }

    /// The excess with the normal spring holding `normal` (energy units); see [`Tally::book`].
    pub fn excess(&self, normal: f64) -> f64 {
        self.given + normal - self.held
    }
}
