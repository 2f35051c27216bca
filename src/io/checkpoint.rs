//! Binary checkpoints: everything a step needs to continue bit for bit (positions, velocities,
//! spins, the forces of the current step, and each contact's history and force), written
//! atomically. The pair list itself is rebuilt on resume; results do not depend on when it is.

use std::path::Path;

use anyhow::{bail, Context};

use crate::contact::PairForce;
use crate::state::{Contact, Snapshot};
use crate::step::Engine;
use crate::Vec3;

/// The first 8 bytes of every checkpoint; the format version follows.
const MAGIC: &[u8; 8] = b"VERDEMCK";
/// The first 8 bytes of the checkpoints of format version 1, which had no version field.
const MAGIC_V1: &[u8; 8] = b"VERDEMC1";
/// The layout this verdem writes and reads.
pub const FORMAT_VERSION: u64 = 2;

/// The tag of a run of `case`: what a checkpoint must share with the case it resumes, as
/// `key=value` lines (the case's name and its tangential convention, which fixes what a
/// contact's history words mean). Read compares it field by field, and names the fields that
/// differ; the particle count, the time step and the number of history words are stored and
/// compared apart.
pub fn tag(case: &crate::case::Case) -> String {
    format!(
        "case={:?}\ntangential={}",
        case.name,
        case.contact.tangential.name()
    )
}

/// Writes a checkpoint of a state advanced with time step `dt`; `tag` identifies the case
/// (checked on resume; see [`tag`]). Layout (little-endian): magic, format version, tag, step,
/// time, dt, particle count, history words per contact, then x v w f t of every particle, the
/// contact count and each contact (p, i as u32, its history words, f, torques, fn).
pub fn write(path: &Path, core: &Snapshot, dt: f64, tag: &str) -> anyhow::Result<()> {
    let mut b = Vec::new();
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    b.extend_from_slice(&(tag.len() as u64).to_le_bytes());
    b.extend_from_slice(tag.as_bytes());
    b.extend_from_slice(&core.step.to_le_bytes());
    b.extend_from_slice(&core.time.to_le_bytes());
    b.extend_from_slice(&dt.to_le_bytes());
    let p = &core.particles;
    b.extend_from_slice(&(p.len() as u64).to_le_bytes());
    let words = core.contacts.first().map_or(0, |c| c.history.len());
    b.extend_from_slice(&(words as u64).to_le_bytes());
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
        assert_eq!(
            c.history.len(),
            words,
            "contacts of one law carry as many words"
        );
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
        if n > self.b.len() - self.at {
            bail!(
                "{}: checkpoint truncated at byte {} (of {}; {n} more expected)",
                self.file,
                self.at,
                self.b.len()
            );
        }
        self.at += n;
        Ok(&self.b[self.at - n..self.at])
    }
    fn u64(&mut self) -> anyhow::Result<u64> {
        let mut w = [0; 8];
        w.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(w))
    }
    fn u32(&mut self) -> anyhow::Result<u32> {
        let mut w = [0; 4];
        w.copy_from_slice(self.take(4)?);
        Ok(u32::from_le_bytes(w))
    }
    /// A finite f64, or an error naming `what` and where it is.
    fn f64(&mut self, what: &dyn Fn() -> String) -> anyhow::Result<f64> {
        let at = self.at;
        let v = f64::from_bits(self.u64()?);
        if !v.is_finite() {
            bail!("{}: byte {at}: {} is not finite ({v})", self.file, what());
        }
        Ok(v)
    }
    fn vec(&mut self, what: &dyn Fn() -> String) -> anyhow::Result<Vec3> {
        let mut v = Vec3::zeros();
        for k in 0..3 {
            v[k] = self.f64(&|| format!("{}[{k}]", what()))?;
        }
        Ok(v)
    }
}

/// Restores a checkpoint into `engine` (built from the same case); returns the step it holds.
pub fn read(path: &Path, engine: &mut dyn Engine, tag: &str) -> anyhow::Result<u64> {
    let bytes = std::fs::read(path)
        .with_context(|| format!("{}: cannot read checkpoint", path.display()))?;
    restore(&path.display().to_string(), &bytes, engine, tag)
}

/// Restores the checkpoint `bytes` of `file` into `engine`; returns the step it holds. A
/// checkpoint of another format version, another case (the fields of its tag), another
/// particle count, time step or number of history words is refused, naming every field that
/// differs; so are a truncated file, trailing bytes, a number that is not finite and a contact
/// whose particles are not the case's.
pub fn restore(
    file: &str,
    bytes: &[u8],
    engine: &mut dyn Engine,
    tag: &str,
) -> anyhow::Result<u64> {
    let mut r = Reader {
        b: bytes,
        at: 0,
        file: file.to_string(),
    };
    // A file too short for the magic is not a checkpoint either.
    match r.take(MAGIC.len()).ok() {
        Some(m) if m == MAGIC => {}
        Some(m) if m == MAGIC_V1 => bail!(
            "{file}: checkpoint format version 1 (an earlier verdem), this verdem reads version \
             {FORMAT_VERSION}: resume with the verdem that wrote it, or rerun"
        ),
        _ => bail!("{file}: not a verdem checkpoint"),
    }
    let version = r.u64()?;
    if version != FORMAT_VERSION {
        bail!(
            "{file}: checkpoint format version {version}, this verdem reads version \
             {FORMAT_VERSION}: resume with the verdem that wrote it, or rerun"
        );
    }
    let tag_len = r.u64()?;
    let file_tag = String::from_utf8_lossy(r.take(usize::try_from(tag_len).unwrap_or(usize::MAX))?)
        .to_string();
    let step = r.u64()?;
    let time = r.f64(&|| "time".into())?;
    let dt = r.f64(&|| "dt".into())?;
    let n = r.u64()?;
    let words = r.u64()?;
    let mut differs = tag_differences(&file_tag, tag);
    let particles = engine.state().particles.len();
    if n != particles as u64 {
        differs.push(format!("{n} particles, the case's {particles}"));
    }
    let case_dt = engine.params().dt;
    if dt.to_bits() != case_dt.to_bits() {
        differs.push(format!("dt {dt}, the case's {case_dt} (run.dt)"));
    }
    if !differs.is_empty() {
        bail!(
            "{file}: refused, a checkpoint of another run: {}",
            differs.join("; ")
        );
    }
    let mut snap = engine.snapshot();
    snap.step = step;
    snap.time = time;
    let p = &mut snap.particles;
    for a in 0..particles {
        let id = a + 1;
        p.x[a] = r.vec(&|| format!("particle {id}: position"))?;
        p.v[a] = r.vec(&|| format!("particle {id}: velocity"))?;
        p.w[a] = r.vec(&|| format!("particle {id}: angular velocity"))?;
        p.f[a] = r.vec(&|| format!("particle {id}: force"))?;
        p.t[a] = r.vec(&|| format!("particle {id}: torque"))?;
    }
    let contacts = r.u64()?;
    let case_words = engine.history_words();
    if contacts > 0 && words != case_words as u64 {
        bail!(
            "{file}: refused, a checkpoint of another run: {words} history words per contact, the case's \
             law {case_words} (another contact law)"
        );
    }
    snap.contacts.clear();
    for c in 0..contacts {
        let at = r.at;
        let (cp, ci) = (r.u32()?, r.u32()?);
        if cp as usize >= particles || ci as usize >= particles || cp == ci {
            bail!(
                "{file}: byte {at}: contact {c} between particles {cp} and {ci} (0-based): not \
                 two of the case's {particles}"
            );
        }
        let what = |q: &'static str| move || format!("contact {c}: {q}");
        let history = (0..case_words)
            .map(|_| r.f64(&what("history")))
            .collect::<anyhow::Result<Vec<f64>>>()?;
        let f = r.vec(&what("force"))?;
        let torque_p = r.vec(&what("torque"))?;
        let torque_i = r.vec(&what("torque"))?;
        let fn_signed = r.f64(&what("normal force"))?;
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
            "{file}: {} trailing bytes after the checkpoint",
            bytes.len() - r.at
        );
    }
    engine.restore(&snap);
    Ok(engine.state().step)
}

/// What differs between a checkpoint's tag and the case's: field by field when both are
/// `key=value` lines (as [`tag`] writes them), else the whole tags.
fn tag_differences(file_tag: &str, tag: &str) -> Vec<String> {
    if file_tag == tag {
        return Vec::new();
    }
    let fields = |t: &str| -> Option<Vec<(String, String)>> {
        t.lines()
            .map(|l| {
                l.split_once('=')
                    .map(|(k, v)| (k.to_string(), v.to_string()))
            })
            .collect()
    };
    let (Some(theirs), Some(ours)) = (fields(file_tag), fields(tag)) else {
        return vec![format!("checkpoint of case {file_tag:?}, not {tag:?}")];
    };
    let mut out = Vec::new();
    for (k, v) in &ours {
        match theirs.iter().find(|(kk, _)| kk == k) {
            Some((_, w)) if w == v => {}
            Some((_, w)) if k == "case" => out.push(format!("checkpoint of case {w}, not {v}")),
            Some((_, w)) => out.push(format!("{} {w}, the case's {v}", field_name(k))),
            None => out.push(format!("no {k} (the case's {v})")),
        }
    }
    for (k, w) in &theirs {
        if !ours.iter().any(|(kk, _)| kk == k) {
            out.push(format!("{k} {w}, which the case does not have"));
        }
    }
    out
}

/// How a tag field is named in messages: what it is and where a case sets it.
fn field_name(key: &str) -> String {
    match key {
        "tangential" => "tangential convention (contact.tangential)".into(),
        k => k.into(),
    }
}
