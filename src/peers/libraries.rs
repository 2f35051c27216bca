//! The contact-law libraries of the LAMMPS family that verdem drives in process through a
//! prescribed motion ([`super::motion`] drives them; each dialect declares its own in
//! `Dialect::MOTION`): who they are, apart from how they are driven, so that a dialect can name
//! its libraries without importing the driver that uses the dialect.

/// A peer whose contact law can be driven through a prescribed motion in process.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionPeer {
    Lammps,
    /// LAMMPS with the classic `pair_style gran/hooke/history` (not a peer of the cross-runs).
    LammpsHookeHistory,
    Liggghts,
}

impl MotionPeer {
    /// Every such peer.
    pub const ALL: [MotionPeer; 3] = [
        MotionPeer::Lammps,
        MotionPeer::LammpsHookeHistory,
        MotionPeer::Liggghts,
    ];
}
