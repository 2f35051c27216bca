//! Binary checkpoints: everything a step needs to continue bit for bit (positions, velocities,
//! spins, the forces of the current step, and each contact's history and force), and what the
//! run loop needs to write the same files as a run never stopped (the ledgers' flows and their
//! reading at the last save, and the state of its observer, the in-run averaging), written
//! atomically in one file. The pair list itself is rebuilt on resume; results do not depend on
//! when it is. A SHA-256 checksum of the file closes it, so that a checkpoint changed since it
//! was written (a flipped bit, a cut) is refused before anything is restored.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::contact::PairForce;
use crate::state::{Contact, Snapshot, WallContact};
use crate::step::{Engine, Flows, Reading};
use crate::Vec3;

/// The first 8 bytes of every checkpoint from format version 4 on; the format version follows.
/// Its first byte, 0x89, cannot start a UTF-8 character, so that a checkpoint is never valid
/// UTF-8 text by accident, which [`crate::io::atomic::write`] would check for non-finite number
/// tokens.
const MAGIC: &[u8; 8] = b"\x89VERDEMK";
/// The first 8 bytes of the checkpoints of format versions 2 and 3, which had no checksum.
const MAGIC_UNSUMMED: &[u8; 8] = b"VERDEMCK";
/// The first 8 bytes of the checkpoints of format version 1, which had no version field.
const MAGIC_V1: &[u8; 8] = b"VERDEMC1";
/// The layout this verdem writes; it also reads versions 2, which had no run record
/// ([`RunRecord`]), and 3, which had no checksum (both with a warning: [`Resumed::lacks`]).
pub const FORMAT_VERSION: u64 = 4;

/// The last format version without a run record.
const WITHOUT_RECORD: u64 = 2;
/// The last format version without a checksum.
const WITHOUT_CHECKSUM: u64 = 3;
/// The length of the checksum that closes a checkpoint (a SHA-256 digest, bytes).
const CHECKSUM_LEN: usize = 32;

/// What a run keeps beside the state, written with it from format version 3 on, so that a
/// resumed run writes the same diagnostics and in-run profiles as a run never stopped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunRecord {
    /// The ledgers; `None` in a checkpoint written without them (not by a run).
    pub ledgers: Option<Ledgers>,
    /// The state of the run loop's observer ([`crate::run::Observer::state`]: the in-run
    /// averaging), opaque here; `None` for a run without one.
    pub observer: Option<Vec<u8>>,
}

/// The ledgers of a run at its checkpoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ledgers {
    /// The flows accumulated from the simulation's start to the checkpoint's step
    /// ([`Engine::flows`]).
    pub flows: Flows,
    /// The ledgers' reading at the run's last save at or before the checkpoint's step, from
    /// which its next save's ledger row is taken (`None` before the run's first save).
    pub last_save: Option<Reading>,
}

/// A checkpoint restored into an engine: its step, its format version and its run record.
#[derive(Clone, Debug, PartialEq)]
pub struct Resumed {
    pub step: u64,
    pub version: u64,
    pub record: RunRecord,
    /// Where the run record's observer state starts in the file (byte), for its messages.
    pub observer_at: usize,
}

impl Resumed {
    /// What the checkpoint lacks, one sentence each (for the user): a checksum (format versions
    /// 2 and 3), and of its run record the ledgers (the observer's state is its owner's to
    /// judge).
    pub fn lacks(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.version <= WITHOUT_CHECKSUM {
            out.push(format!(
                "a checkpoint of format version {} carries no checksum: a change to it since it \
                 was written (a flipped bit) cannot be detected",
                self.version
            ));
        }
        if self.record.ledgers.is_none() {
            let why = if self.version <= WITHOUT_RECORD {
                format!(
                    "a checkpoint of format version {} holds no ledgers",
                    self.version
                )
            } else {
                "the checkpoint was written without the ledgers (not by a run)".into()
            };
            out.push(format!(
                "{why}: the ledgers' flows start again at zero, and when the resume is \
                 between saves the first save after it has an empty ledger row (its \
                 diagnostics columns are whole)"
            ));
        }
        out
    }
}

/// Why a checkpoint was not written, or was refused when read. Every message names the file
/// (as the caller gave it), and the byte where one applies.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file cannot be read (the system's error is the source).
    #[error("{}: cannot read checkpoint", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file cannot be written ([`crate::io::atomic::write`]'s error, which names it).
    #[error(transparent)]
    Write(std::io::Error),
    /// Not a verdem checkpoint (its first bytes are no checkpoint's magic).
    #[error("{file}: not a verdem checkpoint")]
    NotCheckpoint { file: String },
    /// A format version this verdem does not read (1, an earlier verdem's, had no version
    /// field).
    #[error(
        "{file}: checkpoint format version {version}{}, this verdem reads versions \
         {WITHOUT_RECORD} to {FORMAT_VERSION}: resume with the verdem that wrote it, or rerun",
        if *version == 1 { " (an earlier verdem)" } else { "" }
    )]
    Version { file: String, version: u64 },
    /// The checksum is not the SHA-256 of the bytes before it: changed since it was written.
    #[error(
        "{file}: refused, a corrupted checkpoint (changed or truncated since it was written): \
         its checksum says SHA-256 {stored}…, its {len} bytes before it have {found}…"
    )]
    Corrupt {
        file: String,
        /// The first 8 bytes of the stored and of the computed digest, in hex.
        stored: String,
        found: String,
        /// The bytes before the checksum.
        len: usize,
    },
    /// The file ends before a field: `what` truncated at byte `at` of `len`, `more` bytes
    /// short.
    #[error("{file}: {what} truncated at byte {at} (of {len}; {more} more expected)")]
    Truncated {
        file: String,
        what: &'static str,
        at: usize,
        len: usize,
        more: usize,
    },
    /// A malformed field: a count the file cannot hold, a flag neither 0 nor 1, a number that
    /// is not finite, a contact between particles the case does not have, trailing bytes, a
    /// file too short for its checksum.
    #[error("{file}: {}{msg}", at.map_or(String::new(), |at| format!("byte {at}: ")))]
    Format {
        file: String,
        /// The byte the field starts at, when the message is about one.
        at: Option<usize>,
        msg: String,
    },
    /// A checkpoint of another run: every field that differs from the case's (its name, its
    /// tangential convention, the particle count, dt, the history words per contact).
    #[error("{file}: refused, a checkpoint of another run: {}", differs.join("; "))]
    OtherRun { file: String, differs: Vec<String> },
    /// Ledgers of a contact law that splits its dissipation otherwise than the case's.
    #[error(
        "{file}: byte {at}: ledgers: refused, a checkpoint of another contact law: its law {} \
         its dissipation, the case's {}",
        splits_text(*theirs),
        splits_text(*ours)
    )]
    OtherLaw {
        file: String,
        at: usize,
        /// Whether the checkpoint's law and the case's split their dissipation.
        theirs: bool,
        ours: bool,
    },
}

/// How [`CheckpointError::OtherLaw`] says whether a law splits its dissipation.
fn splits_text(splits: bool) -> &'static str {
    if splits {
        "splits"
    } else {
        "does not split"
    }
}

impl CheckpointError {
    /// A malformed field of `file` at byte `at` (if any).
    fn format(file: &str, at: Option<usize>, msg: String) -> CheckpointError {
        CheckpointError::Format {
            file: file.to_string(),
            at,
            msg,
        }
    }
}

/// The tag of a run of `case`: what a checkpoint must share with the case it resumes, as
/// `key=value` lines (the case's name and its tangential convention, which fixes what a
/// contact's history words mean). Read compares it field by field, and names the fields that
/// differ; the particle count, the time step and the number of history words are stored and
/// compared apart.
pub fn tag(case: &crate::case::Case) -> String {
    let mut tag = format!(
        "case={:?}\ntangential={}",
        case.name,
        case.contact.tangential.name()
    );
    // the flat walls' count, only when there are walls (checkpoints without stay as they were)
    if !case.wall.is_empty() {
        tag.push_str(&format!("\nwalls={}", case.wall.len()));
    }
    tag
}

/// Writes a checkpoint of a state advanced with time step `dt` without a run record (its
/// resume starts the ledgers again: [`Resumed::lacks`]); `tag` identifies the case (checked on
/// resume; see [`tag`]).
pub fn write(path: &Path, core: &Snapshot, dt: f64, tag: &str) -> Result<(), CheckpointError> {
    write_run(path, core, dt, tag, &RunRecord::default())
}

/// Writes a checkpoint of a state advanced with time step `dt` and the run record `record`;
/// `tag` identifies the case (checked on resume; see [`tag`]). Layout (little-endian): magic,
/// format version, tag, step, time, dt, particle count, history words per contact, then x v w
/// f t of every particle, the contact count and each contact (p, i as u32, its history words,
/// f, torques, fn); when the scene has flat walls, their section ([`put_walls`]); then the run
/// record: a flag (0 or 1) and the ledgers (the flows, a flag and
/// the reading at the last save: [`put_flows`], [`put_reading`]), a flag and the observer's
/// state (its length and bytes); last the SHA-256 digest of all the bytes before it (32 bytes).
pub fn write_run(
    path: &Path,
    core: &Snapshot,
    dt: f64,
    tag: &str,
    record: &RunRecord,
) -> Result<(), CheckpointError> {
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
    let words = (core.contacts.first().map(|c| c.history.len()))
        .or(core.wall_contacts.first().map(|c| c.history.len()))
        .unwrap_or(0);
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
    if !core.walls.is_empty() {
        put_walls(&mut b, core, words);
    }
    let flag = |b: &mut Vec<u8>, set: bool| b.extend_from_slice(&u64::from(set).to_le_bytes());
    flag(&mut b, record.ledgers.is_some());
    if let Some(l) = &record.ledgers {
        put_flows(&mut b, &l.flows);
        flag(&mut b, l.last_save.is_some());
        if let Some(r) = &l.last_save {
            put_reading(&mut b, r);
        }
    }
    flag(&mut b, record.observer.is_some());
    if let Some(o) = &record.observer {
        b.extend_from_slice(&(o.len() as u64).to_le_bytes());
        b.extend_from_slice(o);
    }
    let sum = Sha256::digest(&b);
    b.extend_from_slice(&sum);
    crate::io::atomic::write(path, &b).map_err(CheckpointError::Write)
}

/// Appends the flat walls' section: each wall's point (3 f64), the wall contacts' count and each
/// wall contact (sphere and wall as u32, its `words` history words, force, torque on the sphere
/// and fn).
fn put_walls(b: &mut Vec<u8>, core: &Snapshot, words: usize) {
    let put = |b: &mut Vec<u8>, v: &Vec3| {
        for k in 0..3 {
            b.extend_from_slice(&v[k].to_le_bytes());
        }
    };
    for w in &core.walls {
        put(b, &w.point);
    }
    b.extend_from_slice(&(core.wall_contacts.len() as u64).to_le_bytes());
    for c in &core.wall_contacts {
        b.extend_from_slice(&c.particle.to_le_bytes());
        b.extend_from_slice(&c.wall.to_le_bytes());
        for k in 0..words {
            let w = c.history.get(k).copied().unwrap_or(0.0);
            b.extend_from_slice(&w.to_le_bytes());
        }
        put(b, &c.force.f);
        put(b, &c.force.torque_p);
        b.extend_from_slice(&c.force.fn_signed.to_le_bytes());
    }
}

/// Reads the flat walls' section ([`put_walls`]) into `snap`, whose walls are the case's
/// (their count), for a law of `words` history words and `particles` spheres.
fn read_walls(
    r: &mut Reader<'_>,
    snap: &mut Snapshot,
    words: usize,
    particles: usize,
) -> Result<(), CheckpointError> {
    for (w, wall) in snap.walls.iter_mut().enumerate() {
        wall.point = r.vec(&|| format!("wall[{w}]: point"))?;
    }
    let at = r.at();
    // sphere and wall, the history words, f, the torque and fn (bytes)
    let len = 8 + 8 * words + 8 * 7;
    let contacts = r.count((r.b.len() - r.at) / len, &|| {
        format!("byte {at}: the wall contact count")
    })?;
    snap.wall_contacts.clear();
    for c in 0..contacts {
        let at = r.at();
        let (particle, wall) = (r.u32()?, r.u32()?);
        if particle as usize >= particles || wall as usize >= snap.walls.len() {
            return Err(r.error(
                at,
                format!(
                    "wall contact {c} of particle {particle} with wall {wall} (0-based): not \
                     one of the case's {particles} spheres and {} walls",
                    snap.walls.len()
                ),
            ));
        }
        let what = |q: &'static str| move || format!("wall contact {c}: {q}");
        let history = (0..words)
            .map(|_| r.f64(&what("history")))
            .collect::<Result<Vec<f64>, CheckpointError>>()?;
        let f = r.vec(&what("force"))?;
        let torque_p = r.vec(&what("torque"))?;
        let fn_signed = r.f64(&what("normal force"))?;
        snap.wall_contacts.push(WallContact {
            particle,
            wall,
            history,
            spring: Vec3::zeros(),
            force: PairForce {
                f,
                fn_signed,
                torque_p,
                torque_i: Vec3::zeros(),
            },
        });
    }
    Ok(())
}

/// The first 8 bytes of `digest` in hex, as messages show a checksum.
fn short_hex(digest: &[u8]) -> String {
    digest[..8].iter().map(|b| format!("{b:02x}")).collect()
}

/// The bytes of the checkpoint `bytes` of `file` before its checksum, once the checksum is
/// theirs; else an error naming the file and both digests.
fn checked_body<'a>(file: &str, bytes: &'a [u8]) -> Result<&'a [u8], CheckpointError> {
    let Some(split) = bytes.len().checked_sub(CHECKSUM_LEN) else {
        return Err(CheckpointError::format(
            file,
            None,
            format!(
                "checkpoint truncated: {} bytes, too few for its checksum",
                bytes.len()
            ),
        ));
    };
    let (body, stored) = bytes.split_at(split);
    let found = Sha256::digest(body);
    if found.as_slice() != stored {
        return Err(CheckpointError::Corrupt {
            file: file.to_string(),
            stored: short_hex(stored),
            found: short_hex(&found),
            len: body.len(),
        });
    }
    Ok(body)
}

/// Appends `flows`: the walls' and gravity's work, the three dissipations, the impulses of the
/// two wall groups (i128 fixed point, [`Flows`]).
fn put_flows(b: &mut Vec<u8>, f: &Flows) {
    let words = [f.wall_work, f.gravity_work]
        .into_iter()
        .chain(f.dissipated)
        .chain(f.impulse.into_iter().flatten());
    for w in words {
        b.extend_from_slice(&w.to_le_bytes());
    }
}

/// Appends the reading `r`: step, dt, whether the law splits its dissipation (0 or 1), its
/// flows, the translational, rotational, elastic and potential energies, the momentum, the
/// force on the two wall groups (i128 fixed point) and the weight (f64).
fn put_reading(b: &mut Vec<u8>, r: &Reading) {
    b.extend_from_slice(&r.step.to_le_bytes());
    b.extend_from_slice(&r.dt.to_le_bytes());
    b.extend_from_slice(&u64::from(r.splits).to_le_bytes());
    put_flows(b, &r.flows);
    let words = [r.trans, r.rot, r.elastic, r.potential]
        .into_iter()
        .chain(r.momentum)
        .chain(r.wall_force.into_iter().flatten());
    for w in words {
        b.extend_from_slice(&w.to_le_bytes());
    }
    for k in 0..3 {
        b.extend_from_slice(&r.weight[k].to_le_bytes());
    }
}

/// A little-endian reader of a binary file (a checkpoint, or a section of one) whose errors
/// name the file and the byte.
pub struct Reader<'a> {
    b: &'a [u8],
    at: usize,
    /// Where `b` starts in the file (byte).
    base: usize,
    file: String,
    /// What `b` is, for the messages ("checkpoint").
    what: &'static str,
}

impl<'a> Reader<'a> {
    /// A reader of `bytes`, which start at byte `base` of `file` and are a `what`.
    pub fn new(file: &str, bytes: &'a [u8], base: usize, what: &'static str) -> Reader<'a> {
        Reader {
            b: bytes,
            at: 0,
            base,
            file: file.to_string(),
            what,
        }
    }

    /// Where the reader is in the file (byte).
    pub fn at(&self) -> usize {
        self.base + self.at
    }

    /// An error at byte `at` of the file: `msg` about the field there.
    pub fn error(&self, at: usize, msg: String) -> CheckpointError {
        CheckpointError::format(&self.file, Some(at), msg)
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: usize) -> Result<&'a [u8], CheckpointError> {
        if n > self.b.len() - self.at {
            return Err(CheckpointError::Truncated {
                file: self.file.clone(),
                what: self.what,
                at: self.at(),
                len: self.base + self.b.len(),
                more: n,
            });
        }
        self.at += n;
        Ok(&self.b[self.at - n..self.at])
    }
    pub fn u64(&mut self) -> Result<u64, CheckpointError> {
        let mut w = [0; 8];
        w.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(w))
    }
    fn u32(&mut self) -> Result<u32, CheckpointError> {
        let mut w = [0; 4];
        w.copy_from_slice(self.take(4)?);
        Ok(u32::from_le_bytes(w))
    }
    fn i128(&mut self) -> Result<i128, CheckpointError> {
        let mut w = [0; 16];
        w.copy_from_slice(self.take(16)?);
        Ok(i128::from_le_bytes(w))
    }
    /// A count of at most `most`, or an error naming `what` and where it is.
    pub fn count(
        &mut self,
        most: usize,
        what: &dyn Fn() -> String,
    ) -> Result<usize, CheckpointError> {
        let at = self.at();
        let n = self.u64()?;
        match usize::try_from(n) {
            Ok(n) if n <= most => Ok(n),
            _ => Err(self.error(at, format!("{} is {n}, more than {most}", what()))),
        }
    }
    /// A flag, 0 or 1, or an error naming `what` and where it is.
    pub fn flag(&mut self, what: &dyn Fn() -> String) -> Result<bool, CheckpointError> {
        let at = self.at();
        match self.u64()? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(self.error(at, format!("{} is {v}, neither 0 nor 1", what()))),
        }
    }
    /// A finite f64, or an error naming `what` and where it is.
    pub fn f64(&mut self, what: &dyn Fn() -> String) -> Result<f64, CheckpointError> {
        let at = self.at();
        let v = f64::from_bits(self.u64()?);
        if !v.is_finite() {
            return Err(self.error(at, format!("{} is not finite ({v})", what())));
        }
        Ok(v)
    }
    pub fn vec(&mut self, what: &dyn Fn() -> String) -> Result<Vec3, CheckpointError> {
        let mut v = Vec3::zeros();
        for k in 0..3 {
            v[k] = self.f64(&|| format!("{}[{k}]", what()))?;
        }
        Ok(v)
    }
    /// An error unless every byte has been read.
    pub fn end(&self) -> Result<(), CheckpointError> {
        if self.at != self.b.len() {
            return Err(CheckpointError::format(
                &self.file,
                None,
                format!(
                    "{} trailing bytes after the {}",
                    self.b.len() - self.at,
                    self.what
                ),
            ));
        }
        Ok(())
    }
    fn flows(&mut self) -> Result<Flows, CheckpointError> {
        let mut f = Flows {
            wall_work: self.i128()?,
            gravity_work: self.i128()?,
            ..Flows::default()
        };
        for d in &mut f.dissipated {
            *d = self.i128()?;
        }
        for j in f.impulse.iter_mut().flatten() {
            *j = self.i128()?;
        }
        Ok(f)
    }
    fn reading(&mut self) -> Result<Reading, CheckpointError> {
        let step = self.u64()?;
        let dt = self.f64(&|| "ledgers: dt of the last save's reading".into())?;
        let splits = self.flag(&|| "ledgers: the last save's dissipation flag".into())?;
        let flows = self.flows()?;
        let mut r = Reading {
            step,
            dt,
            splits,
            flows,
            trans: self.i128()?,
            rot: self.i128()?,
            elastic: self.i128()?,
            potential: self.i128()?,
            momentum: [0; 3],
            wall_force: [[0; 3]; 2],
            weight: Vec3::zeros(),
        };
        for m in &mut r.momentum {
            *m = self.i128()?;
        }
        for f in r.wall_force.iter_mut().flatten() {
            *f = self.i128()?;
        }
        r.weight = self.vec(&|| "ledgers: weight of the last save's reading".into())?;
        Ok(r)
    }
}

/// Restores a checkpoint into `engine` (built from the same case); returns the step it holds.
pub fn read(path: &Path, engine: &mut dyn Engine, tag: &str) -> Result<u64, CheckpointError> {
    Ok(read_run(path, engine, tag)?.step)
}

/// Restores a checkpoint into `engine` (built from the same case), the ledgers' flows among
/// it when the checkpoint holds them; returns what it holds besides ([`Resumed`]).
pub fn read_run(
    path: &Path,
    engine: &mut dyn Engine,
    tag: &str,
) -> Result<Resumed, CheckpointError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    restore_run(&path.display().to_string(), &bytes, engine, tag)
}

/// Restores the checkpoint `bytes` of `file` into `engine`; returns the step it holds.
pub fn restore(
    file: &str,
    bytes: &[u8],
    engine: &mut dyn Engine,
    tag: &str,
) -> Result<u64, CheckpointError> {
    Ok(restore_run(file, bytes, engine, tag)?.step)
}

/// Restores the checkpoint `bytes` of `file` into `engine`, and the ledgers' flows when it
/// holds them; returns its step and run record. A checkpoint whose checksum is not the SHA-256
/// of its bytes is refused before anything else is read from it, naming both digests. A
/// checkpoint of another format version than 2, 3 or 4 (2 and 3 carry no checksum:
/// [`Resumed::lacks`]), another case (the fields of its tag), another particle count, time step
/// or number of history words is refused, naming every field that differs; so are a truncated
/// file, trailing bytes, a count that the rest of the file cannot hold, a number that is not
/// finite, a contact whose particles are not the case's, and ledgers of another time step, of a
/// law that splits its dissipation otherwise, or read after the checkpoint's step.
pub fn restore_run(
    file: &str,
    bytes: &[u8],
    engine: &mut dyn Engine,
    tag: &str,
) -> Result<Resumed, CheckpointError> {
    // A file too short for the magic is not a checkpoint either.
    let body = match bytes.get(..MAGIC.len()) {
        Some(m) if m == MAGIC => checked_body(file, bytes)?,
        Some(m) if m == MAGIC_UNSUMMED => bytes,
        Some(m) if m == MAGIC_V1 => {
            return Err(CheckpointError::Version {
                file: file.to_string(),
                version: 1,
            })
        }
        _ => {
            return Err(CheckpointError::NotCheckpoint {
                file: file.to_string(),
            })
        }
    };
    let mut r = Reader::new(file, body, 0, "checkpoint");
    let unsummed = r.take(MAGIC.len())? == MAGIC_UNSUMMED;
    let version = r.u64()?;
    let known = if unsummed {
        (WITHOUT_RECORD..=WITHOUT_CHECKSUM).contains(&version)
    } else {
        version == FORMAT_VERSION
    };
    if !known {
        return Err(CheckpointError::Version {
            file: file.to_string(),
            version,
        });
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
        return Err(CheckpointError::OtherRun {
            file: file.to_string(),
            differs,
        });
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
    let contacts_at = r.at();
    let contacts = r.u64()?;
    let case_words = engine.history_words();
    if contacts > 0 && words != case_words as u64 {
        return Err(CheckpointError::OtherRun {
            file: file.to_string(),
            differs: vec![format!(
                "{words} history words per contact, the case's law {case_words} (another \
                 contact law)"
            )],
        });
    }
    // p and i, the history words, f, the two torques and fn (bytes)
    let contact_len = 8 + 8 * case_words + 8 * 10;
    let room = (r.b.len() - r.at) / contact_len;
    if contacts > room as u64 {
        return Err(r.error(
            contacts_at,
            format!(
                "the contact count is {contacts}, more than the {room} the rest of the \
                 checkpoint can hold"
            ),
        ));
    }
    snap.contacts.clear();
    for c in 0..contacts {
        let at = r.at;
        let (cp, ci) = (r.u32()?, r.u32()?);
        if cp as usize >= particles || ci as usize >= particles || cp == ci {
            return Err(r.error(
                at,
                format!(
                    "contact {c} between particles {cp} and {ci} (0-based): not two of the \
                     case's {particles}"
                ),
            ));
        }
        let what = |q: &'static str| move || format!("contact {c}: {q}");
        let history = (0..case_words)
            .map(|_| r.f64(&what("history")))
            .collect::<Result<Vec<f64>, _>>()?;
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
    if !snap.walls.is_empty() {
        read_walls(&mut r, &mut snap, case_words, particles)?;
    }
    let mut record = RunRecord::default();
    let mut observer_at = body.len();
    if version > WITHOUT_RECORD {
        if r.flag(&|| "the ledgers' flag".into())? {
            let flows = r.flows()?;
            let last_save = if r.flag(&|| "the last save's ledgers flag".into())? {
                let at = r.at();
                let reading = r.reading()?;
                if reading.step > step || reading.dt.to_bits() != dt.to_bits() {
                    return Err(r.error(
                        at,
                        format!(
                            "ledgers: the last save's reading is at step {} with dt {}, not at \
                             or before the checkpoint's step {step} with dt {dt}",
                            reading.step, reading.dt
                        ),
                    ));
                }
                Some((at, reading))
            } else {
                None
            };
            record.ledgers = Some(Ledgers {
                flows,
                last_save: last_save.map(|l| l.1),
            });
            if let Some((at, reading)) = last_save {
                check_splits(file, at, &reading, engine)?;
            }
        }
        if r.flag(&|| "the observer's flag".into())? {
            let len = r.count(body.len(), &|| "the observer's state length".into())?;
            observer_at = r.at();
            record.observer = Some(r.take(len)?.to_vec());
        }
    }
    r.end()?;
    engine.restore(&snap);
    if let Some(l) = &record.ledgers {
        engine.set_flows(l.flows);
    }
    Ok(Resumed {
        step: engine.state().step,
        version,
        record,
        observer_at,
    })
}

/// Refuses a last save's reading (at byte `at` of `file`) of a law that splits its dissipation
/// otherwise than `engine`'s.
fn check_splits(
    file: &str,
    at: usize,
    reading: &Reading,
    engine: &dyn Engine,
) -> Result<(), CheckpointError> {
    let ours = engine.ledger().splits;
    if reading.splits != ours {
        return Err(CheckpointError::OtherLaw {
            file: file.to_string(),
            at,
            theirs: reading.splits,
            ours,
        });
    }
    Ok(())
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
