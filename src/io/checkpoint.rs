//! Binary checkpoints: everything a step needs to continue bit for bit (positions, velocities,
//! spins, the forces of the current step, and each contact's history and force), written
//! atomically. The pair list itself is rebuilt on resume; results do not depend on when it is.

use std::path::Path;

use anyhow::{bail, Context};

use crate::contact::PairForce;
use crate::state::{Contact, Snapshot};
use crate::step::Engine;
use crate::Vec3;

const MAGIC: &[u8; 8] = b"VERDEMC1";

/// Writes a checkpoint of a state advanced with time step `dt`; `tag` identifies the case
/// (checked on resume).
pub fn write(path: &Path, core: &Snapshot, dt: f64, tag: &str) -> anyhow::Result<()> {
    let mut b = Vec::new();
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&(tag.len() as u64).to_le_bytes());
    b.extend_from_slice(tag.as_bytes());
    b.extend_from_slice(&core.step.to_le_bytes());
    b.extend_from_slice(&core.time.to_le_bytes());
    b.extend_from_slice(&dt.to_le_bytes());
    let p = &core.particles;
    b.extend_from_slice(&(p.len() as u64).to_le_bytes());
    let put = |b: &mut Vec<u8>, v: &Vec3| {
        for k in 0..3 {
            b.extend_from_slice(&v[k].to_le_bytes());
        }
    };
    for a in 0..p.len() {
        for v in [&p.x[a], &p.v[a], &p.w[a], &p.f[a], &p.t[a]] {
            put(&mut b, v);
        }
    }
    b.extend_from_slice(&(core.contacts.len() as u64).to_le_bytes());
    for c in &core.contacts {
        b.extend_from_slice(&c.p.to_le_bytes());
        b.extend_from_slice(&c.i.to_le_bytes());
        for w in &c.history {
            b.extend_from_slice(&w.to_le_bytes());
        }
        let o = &c.force;
        for v in [&o.f, &o.torque_p, &o.torque_i] {
            put(&mut b, v);
        }
        b.extend_from_slice(&o.fn_signed.to_le_bytes());
    }
    Ok(crate::io::atomic::write(path, &b)?)
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
    file: String,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> anyhow::Result<&[u8]> {
        if self.at + n > self.b.len() {
            bail!("{}: checkpoint truncated at byte {}", self.file, self.at);
        }
        self.at += n;
        Ok(&self.b[self.at - n..self.at])
    }
    fn u64(&mut self) -> anyhow::Result<u64> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn u32(&mut self) -> anyhow::Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn f64(&mut self) -> anyhow::Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn vec(&mut self) -> anyhow::Result<Vec3> {
        Ok(Vec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
}

/// Restores a checkpoint into `core` (built from the same case); returns the step it holds.
pub fn read(path: &Path, engine: &mut dyn Engine, tag: &str) -> anyhow::Result<u64> {
    let words = engine.history_words();
    let bytes = std::fs::read(path)
        .with_context(|| format!("{}: cannot read checkpoint", path.display()))?;
    let mut r = Reader {
        b: &bytes,
        at: 0,
        file: path.display().to_string(),
    };
    // A file too short for the magic is not a checkpoint either.
    if r.take(MAGIC.len()).ok() != Some(MAGIC.as_slice()) {
        bail!("{}: not a verdem checkpoint", path.display());
    }
    let tag_len = r.u64()? as usize;
    let file_tag = String::from_utf8_lossy(r.take(tag_len)?).to_string();
    if file_tag != tag {
        bail!(
            "{}: checkpoint of case {file_tag:?}, not {tag:?}",
            path.display()
        );
    }
    let mut snap = engine.snapshot();
    snap.step = r.u64()?;
    snap.time = r.f64()?;
    let dt = r.f64()?;
    if dt.to_bits() != engine.params().dt.to_bits() {
        bail!(
            "{}: checkpoint dt {dt} differs from the case's {}",
            path.display(),
            engine.params().dt
        );
    }
    let n = r.u64()? as usize;
    if n != engine.state().particles.len() {
        bail!(
            "{}: checkpoint has {n} particles, the case {}",
            path.display(),
            engine.state().particles.len()
        );
    }
    let p = &mut snap.particles;
    for a in 0..n {
        p.x[a] = r.vec()?;
        p.v[a] = r.vec()?;
        p.w[a] = r.vec()?;
        p.f[a] = r.vec()?;
        p.t[a] = r.vec()?;
    }
    let contacts = r.u64()? as usize;
    snap.contacts.clear();
    for _ in 0..contacts {
        let (cp, ci) = (r.u32()?, r.u32()?);
        let history = (0..words)
            .map(|_| r.f64())
            .collect::<anyhow::Result<Vec<f64>>>()?;
        let f = r.vec()?;
        let torque_p = r.vec()?;
        let torque_i = r.vec()?;
        let fn_signed = r.f64()?;
        snap.contacts.push(Contact {
            p: cp,
            i: ci,
            history,
            spring: Vec3::zeros(),
            force: PairForce {
                f,
                fn_signed,
                torque_p,
                torque_i,
            },
        });
    }
    if r.at != bytes.len() {
        bail!(
            "{}: {} trailing bytes after the checkpoint",
            path.display(),
            bytes.len() - r.at
        );
    }
    engine.restore(&snap);
    Ok(engine.state().step)
}
