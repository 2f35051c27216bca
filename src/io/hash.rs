//! SHA-256 of the full dynamic state, serialised canonically: little-endian f64 of positions,
//! velocities and angular velocities of every particle in id order, then for every contact with
//! a tangential history, sorted by index pair, `P I` as little-endian u32 and the words of its
//! history as f64 (ξ for every law today); then, only when the scene has flat walls, each
//! wall's point (f64) and each wall contact, sorted by (sphere, wall), sphere and wall as u32
//! and its history words (a scene without walls hashes as before they existed).

use sha2::{Digest, Sha256};

use crate::state::Snapshot;

/// Hex SHA-256 of the state.
pub fn state_hash(core: &Snapshot) -> String {
    let mut h = Sha256::new();
    let p = &core.particles;
    for a in 0..p.len() {
        for v in [&p.x[a], &p.v[a], &p.w[a]] {
            for k in 0..3 {
                h.update(v[k].to_le_bytes());
            }
        }
    }
    for c in &core.contacts {
        h.update(c.p.to_le_bytes());
        h.update(c.i.to_le_bytes());
        for w in &c.history {
            h.update(w.to_le_bytes());
        }
    }
    for w in &core.walls {
        for k in 0..3 {
            h.update(w.point[k].to_le_bytes());
        }
    }
    for c in &core.wall_contacts {
        h.update(c.particle.to_le_bytes());
        h.update(c.wall.to_le_bytes());
        for w in &c.history {
            h.update(w.to_le_bytes());
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}
