//! Bad data files: every reader refuses them with a message naming the file, the line and the
//! field, through the command line as a user meets them (exit status 1, no panic, nothing
//! non-finite written) and in-process; and every reader is fuzzed with random mutations of the
//! valid files in `tests/corpus/` (see its README) and of the tables and checkpoints verdem
//! writes, and with arbitrary text or bytes, returning Ok or an Err that names the file (and a
//! line the file has), never panicking.

use std::path::{Path, PathBuf};
use std::process::Command;

use proptest::prelude::*;
use verdem::case::Case;
use verdem::io::{self, checkpoint, mercury, official, Lines};
use verdem::peers::lammps_family::dump;
use verdem::step::engine::{self, Overrides};
use verdem::step::Engine;

/// A file of the corpus.
fn corpus(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(name)
}

fn corpus_bytes(name: &str) -> Vec<u8> {
    std::fs::read(corpus(name)).unwrap()
}

fn corpus_lines(name: &str) -> Vec<String> {
    String::from_utf8(corpus_bytes(name))
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// `lines` with line `no` (from 1) replaced by `f` of it.
fn edit(lines: &[String], no: usize, f: impl Fn(&str) -> String) -> Vec<u8> {
    let mut l = lines.to_vec();
    l[no - 1] = f(&l[no - 1]);
    (l.join("\n") + "\n").into_bytes()
}

/// `line` with its whitespace-separated field `k` (from 0) replaced by `v`.
fn field(line: &str, k: usize, v: &str) -> String {
    let mut t: Vec<&str> = line.split_whitespace().collect();
    t[k] = v;
    t.join(" ")
}

/// Runs `verdem ARGS` and checks it refused: exit status 1 (an error, not a panic's 101 or
/// an abort), every word of `expect` in its stderr, no panic or backtrace, and no file of
/// `out` (when given) holding a NaN or an infinity.
fn refused(args: &[&str], out: Option<&Path>, expect: &[&str]) {
    refused_beside(args, out, &[], expect)
}

/// As [`refused`], when `out` also holds the bad inputs, whose names start with `inputs`.
fn refused_beside(args: &[&str], out: Option<&Path>, inputs: &[&str], expect: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .args(args)
        .output()
        .expect("verdem runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    for e in expect {
        assert!(err.contains(e), "{args:?}: {e:?} missing from: {err}");
    }
    for bad in ["panicked", "RUST_BACKTRACE", "stack backtrace"] {
        assert!(!err.contains(bad), "{args:?}: {err}");
    }
    if let Some(out) = out {
        assert_no_non_finite(out, inputs);
    }
}

/// No text file in `dir` but the `inputs` holds `NaN` or `inf` as a number.
fn assert_no_non_finite(dir: &Path, inputs: &[&str]) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy();
        if inputs.iter().any(|i| name.starts_with(i)) {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&p) else {
            continue;
        };
        for tok in text.split(|c: char| c.is_whitespace() || c == ',') {
            let t = tok.trim_start_matches(['-', '+']).to_ascii_lowercase();
            assert!(
                !(t == "nan" || t == "inf" || t == "infinity"),
                "{} holds {tok}",
                p.display()
            );
        }
    }
}

/// `verdem run small.toml --init FILE` into a fresh folder, refused with `expect`.
fn init_refused(name: &str, bytes: &[u8], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let init = dir.path().join(name);
    std::fs::write(&init, bytes).unwrap();
    let out = dir.path().join("out");
    let case = corpus("small.toml");
    refused(
        &[
            "run",
            case.to_str().unwrap(),
            "--init",
            init.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--steps",
            "10",
            "--quiet",
        ],
        Some(&out),
        expect,
    );
}

#[test]
fn the_corpus_seeds_are_valid() {
    let dir = tempfile::tempdir().unwrap();
    let case = corpus("small.toml");
    for init in ["small.data", "small.official.data"] {
        let out = dir.path().join(init);
        let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
            .args(["run", case.to_str().unwrap(), "--init"])
            .arg(corpus(init))
            .args(["--steps", "10", "--quiet", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (data, fstat) = mercury::read_save(&corpus("small.data"), &corpus("small.fstat")).unwrap();
    assert_eq!(data.rows.len(), 20);
    assert_eq!(fstat.rows.len(), 4);
    assert_eq!(
        mercury::read_fstat(&corpus("mercury.fstat"))
            .unwrap()
            .rows
            .len(),
        2
    );
    assert_eq!(
        official::read(&corpus("small.official.data"))
            .unwrap()
            .x
            .len(),
        20
    );
    for d in ["lammps_dump.100.txt", "liggghts_dump.100.txt"] {
        let f = dump::read(&corpus(d)).unwrap();
        assert_eq!((f.step, f.x.len()), (100, 20));
    }
    assert_eq!(
        dump::read_entries(&corpus("lammps_contacts.0.txt"), 6)
            .unwrap()
            .len(),
        3
    );
    assert_eq!(
        dump::read_entries(&corpus("liggghts_contacts.0.txt"), 5)
            .unwrap()
            .len(),
        3
    );
    let (file, text) = io::read_text(&corpus("motion.csv")).unwrap();
    assert_eq!(
        verdem::verify::kinematics::parse_motion(&file, &text)
            .unwrap()
            .len(),
        20
    );
    let mut e = small_engine();
    let tag = checkpoint::tag(&small_case());
    assert_eq!(
        checkpoint::read(&corpus("small.checkpoint"), e.as_mut(), &tag).unwrap(),
        10
    );
}

#[test]
fn a_data_file_with_wrong_columns_a_wrong_count_or_a_truncation_is_refused_by_line() {
    let l = corpus_lines("small.data");
    init_refused(
        "cols.data",
        &edit(&l, 6, |s| {
            s.split(' ').take(11).collect::<Vec<_>>().join(" ")
        }),
        &["cols.data:6:", "expected 14 columns", "got 11"],
    );
    init_refused(
        "more.data",
        &edit(&l, 1, |s| field(s, 0, "21")),
        &[
            "more.data:21:",
            "header announces 21 particles but the file has 20",
        ],
    );
    init_refused(
        "fewer.data",
        &edit(&l, 1, |s| field(s, 0, "19")),
        &[
            "fewer.data:21:",
            "more particle lines than the 19 announced",
        ],
    );
    init_refused(
        "half.data",
        &edit(&l, 1, |s| field(s, 0, "2.5")),
        &[
            "half.data:1:",
            "N (particles): expected a whole number",
            "2.5",
        ],
    );
    let whole = corpus_bytes("small.data");
    init_refused(
        "cut.data",
        &whole[..whole.len() - 30],
        &["cut.data:21:", "expected 14 columns"],
    );
    let mut official = corpus_lines("small.official.data");
    official.truncate(official.len() - 3);
    init_refused(
        "cut.official.data",
        &(official.join("\n") + "\n").into_bytes(),
        &[
            "cut.official.data:20:",
            "header announces 20 particles but the file has 17",
        ],
    );
    let o = corpus_lines("small.official.data");
    init_refused(
        "count.official.data",
        &edit(&o, 2, |_| "Particles 21".into()),
        &["count.official.data:23:", "header announces 21 particles"],
    );
}

#[test]
fn an_absurd_count_is_refused_before_anything_is_reserved_for_it() {
    // Both once made verdem panic (capacity overflow) or abort (allocation failure).
    init_refused(
        "hugecount.data",
        &std::fs::read(corpus("malformed/hugecount.data")).unwrap(),
        &[
            "hugecount.data:1:",
            "N (particles): expected a whole number >= 0, got 1e300",
        ],
    );
    init_refused(
        "count_2_64.data",
        &std::fs::read(corpus("malformed/count_2_64.data")).unwrap(),
        &[
            "count_2_64.data:1:",
            "N (particles): expected a whole number >= 0, got 1.8446744073709552e19",
        ],
    );
    init_refused(
        "hugecount.official.data",
        &std::fs::read(corpus("malformed/hugecount.official.data")).unwrap(),
        &[
            "hugecount.official.data:2:",
            "Particles: expected a whole number >= 0",
        ],
    );
}

#[test]
fn nan_infinity_and_non_numbers_are_refused_by_line_and_column() {
    let l = corpus_lines("small.data");
    init_refused(
        "nan.data",
        &edit(&l, 20, |s| field(s, 2, "NaN")),
        &["nan.data:20:", "column 3 (rz)", "not finite", "\"NaN\""],
    );
    init_refused(
        "inf.data",
        &edit(&l, 19, |s| field(s, 6, "inf")),
        &["inf.data:19:", "column 7 (radius)", "not finite"],
    );
    init_refused(
        "word.data",
        &edit(&l, 1, |s| field(s, 5, "twenty")),
        &["word.data:1:", "column 6 (xmax)", "not a number"],
    );
    init_refused(
        "radius.data",
        &edit(&l, 19, |s| field(s, 6, "-0.5")),
        &["radius.data:19:", "column 7 (radius)", "must be > 0"],
    );
    let o = corpus_lines("small.official.data");
    init_refused(
        "nanbox.official.data",
        &edit(&o, 1, |s| field(s, 3, "nan")),
        &["nanbox.official.data:1:", "xMax", "not a finite number"],
    );
    init_refused(
        "inf.official.data",
        &edit(&o, 10, |s| field(s, 3, "-inf")),
        &["inf.official.data:10:", "column 4 (z)", "not finite"],
    );
}

#[test]
fn bytes_that_are_not_utf8_are_refused_by_line() {
    let mut bytes = corpus_bytes("small.data");
    let line_11 = nth_line_start(&bytes, 11);
    bytes.insert(line_11 + 3, 0xff);
    init_refused(
        "latin.data",
        &bytes,
        &["latin.data:11:", "not UTF-8", "0xff"],
    );
    let mut bytes = corpus_bytes("small.official.data");
    let line_5 = nth_line_start(&bytes, 5);
    bytes.insert(line_5, 0xe9);
    init_refused(
        "latin.official.data",
        &bytes,
        &["latin.official.data:5:", "not UTF-8"],
    );
}

/// The byte where line `no` (from 1) starts.
fn nth_line_start(bytes: &[u8], no: usize) -> usize {
    let mut at = 0;
    for _ in 1..no {
        at += bytes[at..].iter().position(|&b| b == b'\n').unwrap() + 1;
    }
    at
}

#[test]
fn repeated_ids_and_repeated_particles_are_refused_naming_both_lines() {
    let o = corpus_lines("small.official.data");
    init_refused(
        "dup.official.data",
        &edit(&o, 11, |s| field(s, 0, "7")),
        &[
            "dup.official.data:11:",
            "id: 7 repeats the id of line 10",
            "expected 8",
        ],
    );
    // A .data file has no ids: a repeated line is two particles at one place.
    let mut l = corpus_lines("small.data");
    l[19] = l[18].clone();
    init_refused(
        "dup.data",
        &(l.join("\n") + "\n").into_bytes(),
        &[
            "dup.data:20:",
            "particles 18 (free, line 19) and 19 (free, line 20)",
            "same place",
        ],
    );
}

#[test]
fn particles_outside_the_box_are_refused_along_every_axis() {
    let l = corpus_lines("small.data");
    init_refused(
        "above.data",
        &edit(&l, 20, |s| field(s, 2, "7.5")),
        &[
            "above.data:20:",
            "particle 19: z = 7.5 is outside the case's box [0, 5]",
        ],
    );
    // x is periodic in the case: a file's positions lie in its box all the same.
    init_refused(
        "left.data",
        &edit(&l, 20, |s| field(s, 0, "-9")),
        &[
            "left.data:20:",
            "particle 19: x = -9 is outside the case's box [0, 4]",
        ],
    );
    let o = corpus_lines("small.official.data");
    init_refused(
        "below.official.data",
        &edit(&o, 23, |s| field(s, 3, "-3")),
        &["below.official.data:23:", "particle 20: z = -3 is outside"],
    );
}

#[test]
fn overlaps_beyond_the_guard_limit_are_refused_naming_the_particles() {
    let l = corpus_lines("small.data");
    // particle 19 at z = 2.7 overlaps particle 18 at z = 2.5 by 0.8 (limit 0.1 * 0.5)
    init_refused(
        "free.data",
        &edit(&l, 20, |s| field(s, 2, "2.7")),
        &[
            "free.data:20:",
            "particles 18 (free, line 19) and 19 (free, line 20) overlap by 7.99",
            "[guard] overlap = 0.1",
        ],
    );
    // particle 17 at z = 1.2 overlaps wall sphere 1 at z = 0.5 by 0.3
    init_refused(
        "wall.data",
        &edit(&l, 18, |s| field(s, 2, "1.2")),
        &[
            "wall.data:18:",
            "particles 1 (wall, line 2) and 17 (free, line 18) overlap by 3",
        ],
    );
    // an overlap within the limit (0.01 < 0.05, as in the seed) is accepted: the seed runs
    // (the_corpus_seeds_are_valid); so is a larger one under a looser case limit
    let dir = tempfile::tempdir().unwrap();
    let init = dir.path().join("loose.data");
    std::fs::write(&init, edit(&l, 18, |s| field(s, 2, "1.45"))).unwrap();
    let case = dir.path().join("loose.toml");
    let text = std::fs::read_to_string(corpus("small.toml")).unwrap();
    std::fs::write(&case, format!("{text}\n[guard]\noverlap = 0.2\n")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_verdem"))
        .arg("run")
        .arg(&case)
        .arg("--init")
        .arg(&init)
        .args(["--steps", "0", "--quiet", "--out"])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `verdem run CASE --init small.data --resume CHECKPOINT`, refused with `expect`.
fn resume_refused(case_text: &str, init: &Path, ck: &Path, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("case.toml");
    std::fs::write(&case, case_text).unwrap();
    let out = dir.path().join("out");
    refused(
        &[
            "run",
            case.to_str().unwrap(),
            "--init",
            init.to_str().unwrap(),
            "--resume",
            ck.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--steps",
            "20",
            "--quiet",
        ],
        Some(&out),
        expect,
    );
}

#[test]
fn a_checkpoint_of_another_case_law_step_count_or_version_is_refused_saying_what_differs() {
    let text = std::fs::read_to_string(corpus("small.toml")).unwrap();
    let init = corpus("small.data");
    let ck = corpus("small.checkpoint");
    let ck_name = ck.to_str().unwrap();
    resume_refused(
        &text.replace("name = \"small\"", "name = \"other\""),
        &init,
        &ck,
        &[ck_name, "checkpoint of case \"small\", not \"other\""],
    );
    resume_refused(
        &text.replace("dt = 7.192545031528827e-05", "dt = 7e-05"),
        &init,
        &ck,
        &[
            ck_name,
            "dt 0.00007192545031528827, the case's 0.00007 (run.dt)",
        ],
    );
    resume_refused(
        &text.replace("\"mercury\"", "\"yade\""),
        &init,
        &ck,
        &[
            ck_name,
            "tangential convention (contact.tangential) mercury, the case's yade",
        ],
    );
    // one free sphere fewer, from the seed without its last line
    let dir = tempfile::tempdir().unwrap();
    let fewer = dir.path().join("19.data");
    let mut l = corpus_lines("small.data");
    l.pop();
    l[0] = field(&l[0], 0, "19");
    std::fs::write(&fewer, l.join("\n") + "\n").unwrap();
    resume_refused(
        &text.replace("free = 4", "free = 3"),
        &fewer,
        &ck,
        &[ck_name, "20 particles, the case's 19"],
    );
    resume_refused(
        &text,
        &init,
        &corpus("small_v1.checkpoint"),
        &[
            "small_v1.checkpoint",
            "checkpoint format version 1",
            "reads versions 2 to 4",
        ],
    );
    let cut = dir.path().join("cut.checkpoint");
    std::fs::write(&cut, &corpus_bytes("small.checkpoint")[..1500]).unwrap();
    resume_refused(
        &text,
        &init,
        &cut,
        &[
            "cut.checkpoint",
            "checkpoint truncated at byte 1495 (of 1500",
        ],
    );
    let other = dir.path().join("data.checkpoint");
    std::fs::write(&other, corpus_bytes("small.data")).unwrap();
    resume_refused(
        &text,
        &init,
        &other,
        &["data.checkpoint", "not a verdem checkpoint"],
    );
}

#[test]
fn a_checkpoint_with_other_history_words_or_a_non_finite_number_is_refused_naming_it() {
    let bytes = corpus_bytes("small.checkpoint");
    let tag = checkpoint::tag(&small_case());
    // magic, version, tag length, tag, step, time, dt, particle count, then the words
    let words_at = 8 + 8 + 8 + tag.len() + 8 + 8 + 8 + 8;
    let words = u64::from_le_bytes(bytes[words_at..words_at + 8].try_into().unwrap());
    let mut e = small_engine();
    assert_eq!(words, e.history_words() as u64);
    let mut other = bytes.clone();
    other[words_at..words_at + 8].copy_from_slice(&(words + 1).to_le_bytes());
    let err = checkpoint::restore("c.ck", &other, e.as_mut(), &tag)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(&format!(
            "c.ck: refused, a checkpoint of another run: {} history words per contact, the case's law {words}",
            words + 1
        )),
        "{err}"
    );
    // the first particle's x follows the words
    let x_at = words_at + 8;
    let mut nan = bytes.clone();
    nan[x_at..x_at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let err = checkpoint::restore("c.ck", &nan, e.as_mut(), &tag)
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        format!("c.ck: byte {x_at}: particle 1: position[0] is not finite (NaN)")
    );
    let mut longer = bytes.clone();
    longer.push(0);
    let err = checkpoint::restore("c.ck", &longer, e.as_mut(), &tag)
        .unwrap_err()
        .to_string();
    assert_eq!(err, "c.ck: 1 trailing bytes after the checkpoint");
    assert_eq!(
        checkpoint::restore("c.ck", &bytes, e.as_mut(), &tag).unwrap(),
        10
    );
}

/// The checkpoint this verdem writes of the seed's run at step 10, with a run record (the
/// ledgers with their last save's reading, and an observer's state), and the engine it holds.
fn written_checkpoint(dir: &Path) -> (PathBuf, Vec<u8>, checkpoint::RunRecord, Box<dyn Engine>) {
    let mut e = small_engine();
    e.advance(10).unwrap();
    let record = checkpoint::RunRecord {
        ledgers: Some(checkpoint::Ledgers {
            flows: e.flows(),
            last_save: Some(e.ledger()),
        }),
        observer: Some(b"the observer's sums".to_vec()),
    };
    let p = dir.join("c.checkpoint");
    let tag = checkpoint::tag(&small_case());
    checkpoint::write_run(&p, &e.snapshot(), e.params().dt, &tag, &record).unwrap();
    (p.clone(), std::fs::read(&p).unwrap(), record, e)
}

/// The bits of everything a checkpoint holds of `s`: step, time, and every number of its
/// particles and contacts.
fn state_bits(s: &verdem::state::Snapshot) -> Vec<u64> {
    let p = &s.particles;
    let mut out = vec![s.step, s.time.to_bits()];
    let put = |out: &mut Vec<u64>, v: &verdem::Vec3| out.extend(v.iter().map(|x| x.to_bits()));
    for a in 0..p.len() {
        for v in [&p.x[a], &p.v[a], &p.w[a], &p.f[a], &p.t[a]] {
            put(&mut out, v);
        }
    }
    for c in &s.contacts {
        let f = &c.force;
        for v in [&f.f, &f.torque_p, &f.torque_i] {
            put(&mut out, v);
        }
        out.extend([u64::from(c.p), u64::from(c.i), f.fn_signed.to_bits()]);
        out.extend(c.history.iter().map(|w| w.to_bits()));
    }
    out
}

/// The SHA-256 digest of `bytes`.
fn sha256(bytes: &[u8]) -> Vec<u8> {
    use sha2::Digest;
    sha2::Sha256::digest(bytes).to_vec()
}

/// The first 8 bytes of `digest` in hex.
fn short_hex(digest: &[u8]) -> String {
    digest[..8].iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn a_checkpoint_is_not_text_and_resumes_bit_for_bit_with_its_run_record() {
    let dir = tempfile::tempdir().unwrap();
    let (p, bytes, record, mut e) = written_checkpoint(dir.path());
    assert_eq!(bytes[0], 0x89);
    assert!(std::str::from_utf8(&bytes).is_err());
    let before = e.snapshot();
    assert!(
        !before.contacts.is_empty() && !before.contacts[0].history.is_empty(),
        "the checkpoint holds contacts with their histories"
    );
    let tag = checkpoint::tag(&small_case());
    let mut resumed = small_engine();
    let r = checkpoint::read_run(&p, resumed.as_mut(), &tag).unwrap();
    assert_eq!((r.step, r.version), (10, checkpoint::FORMAT_VERSION));
    assert_eq!(r.record, record);
    assert!(r.lacks().is_empty(), "{:?}", r.lacks());
    assert_eq!(state_bits(&resumed.snapshot()), state_bits(&before));
    assert_eq!(
        io::hash::state_hash(&resumed.snapshot()),
        io::hash::state_hash(&before)
    );
    assert_eq!(resumed.flows(), e.flows());
    e.advance(20).unwrap();
    resumed.advance(20).unwrap();
    assert_eq!(
        io::hash::state_hash(&resumed.snapshot()),
        io::hash::state_hash(&e.snapshot())
    );
}

/// Every single bit of the file flipped in turn, in its header (magic, version, tag, step,
/// time, dt, counts), its particles, its contacts' histories and forces, its ledgers, its
/// observer's state and its checksum, and the file cut at every byte: each is refused naming
/// the file, before anything is restored, in-process and by `verdem run --resume`.
#[test]
fn a_checkpoint_with_any_bit_flipped_or_cut_anywhere_is_refused_before_it_is_restored() {
    let dir = tempfile::tempdir().unwrap();
    let (p, bytes, _, _) = written_checkpoint(dir.path());
    let name = p.display().to_string();
    let tag = checkpoint::tag(&small_case());
    let mut e = small_engine();
    let untouched = (state_bits(&e.snapshot()), e.flows());
    let (body, sum) = bytes.split_at(bytes.len() - 32);
    assert_eq!(sum, sha256(body));
    for k in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[k] ^= 1 << bit;
            let err = checkpoint::restore(&name, &b, e.as_mut(), &tag)
                .unwrap_err()
                .to_string();
            let expect = if k < 8 {
                format!("{name}: not a verdem checkpoint")
            } else {
                format!("{name}: refused, a corrupted checkpoint")
            };
            assert!(err.starts_with(&expect), "byte {k} bit {bit}: {err}");
        }
    }
    // the first particle's x: magic, version, tag length, tag, step, time, dt and two counts
    let x_at = 8 + 8 + 8 + tag.len() + 8 * 5;
    let mut b = bytes.clone();
    b[x_at + 3] ^= 0x10;
    std::fs::write(&p, &b).unwrap();
    let err = checkpoint::read(&p, e.as_mut(), &tag)
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        format!(
            "{name}: refused, a corrupted checkpoint (changed or truncated since it was \
             written): its checksum says SHA-256 {}…, its {} bytes before it have {}…",
            short_hex(sum),
            body.len(),
            short_hex(&sha256(&b[..body.len()]))
        )
    );
    for len in 0..bytes.len() {
        let err = checkpoint::restore(&name, &bytes[..len], e.as_mut(), &tag)
            .unwrap_err()
            .to_string();
        let expect = match len {
            0..8 => "not a verdem checkpoint",
            8..32 => "checkpoint truncated",
            _ => "refused, a corrupted checkpoint",
        };
        assert!(
            err.starts_with(&format!("{name}: {expect}")),
            "cut at {len}: {err}"
        );
    }
    assert!(untouched == (state_bits(&e.snapshot()), e.flows()));
    // as `verdem run --resume` meets it
    let text = std::fs::read_to_string(corpus("small.toml")).unwrap();
    resume_refused(
        &text,
        &corpus("small.data"),
        &p,
        &[&name, "refused, a corrupted checkpoint", &short_hex(sum)],
    );
}

/// A checkpoint of format version 3 (no checksum) still resumes bit for bit, and says that it
/// carries no checksum; one of format version 2 says it too, beside its lack of ledgers.
#[test]
fn a_checkpoint_of_an_older_format_resumes_saying_it_carries_no_checksum() {
    let dir = tempfile::tempdir().unwrap();
    let (_, bytes, record, e) = written_checkpoint(dir.path());
    // version 3: the magic of versions 2 and 3, and no checksum
    let mut v3 = b"VERDEMCK".to_vec();
    v3.extend_from_slice(&3u64.to_le_bytes());
    v3.extend_from_slice(&bytes[16..bytes.len() - 32]);
    let tag = checkpoint::tag(&small_case());
    let mut resumed = small_engine();
    let r = checkpoint::restore_run("c3.ck", &v3, resumed.as_mut(), &tag).unwrap();
    assert_eq!((r.version, &r.record), (3, &record));
    assert_eq!(state_bits(&resumed.snapshot()), state_bits(&e.snapshot()));
    assert_eq!(
        r.lacks(),
        [
            "a checkpoint of format version 3 carries no checksum: a change to it since it was \
          written (a flipped bit) cannot be detected"
        ]
    );
    let r = checkpoint::read_run(&corpus("small.checkpoint"), resumed.as_mut(), &tag).unwrap();
    let lacks = r.lacks();
    assert_eq!(lacks.len(), 2, "{lacks:?}");
    assert!(lacks[0].starts_with("a checkpoint of format version 2 carries no checksum"));
    assert!(lacks[1].starts_with("a checkpoint of format version 2 holds no ledgers"));
}

/// `bytes` with its checksum made again for its changed body.
fn resealed(bytes: &[u8]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    b.extend_from_slice(&sha256(bytes));
    b
}

#[test]
fn an_absurd_count_in_a_checkpoint_is_refused_before_anything_is_reserved_for_it() {
    let dir = tempfile::tempdir().unwrap();
    let (_, bytes, record, _) = written_checkpoint(dir.path());
    let body = &bytes[..bytes.len() - 32];
    let tag = checkpoint::tag(&small_case());
    let huge = (1u64 << 60).to_le_bytes();
    let contacts_at = 8 + 8 + 8 + tag.len() + 8 * 5 + 20 * 15 * 8;
    let observer_at = body.len() - record.observer.as_ref().unwrap().len() - 8;
    let len = body.len();
    for (at, expect) in [
        (
            16,
            format!("c.ck: checkpoint truncated at byte 24 (of {len}; 1152921504606846976 more"),
        ),
        (
            contacts_at,
            format!(
                "c.ck: byte {contacts_at}: the contact count is 1152921504606846976, more than"
            ),
        ),
        (
            observer_at,
            format!(
                "c.ck: byte {observer_at}: the observer's state length is 1152921504606846976, \
                 more than {len}"
            ),
        ),
    ] {
        let mut b = body.to_vec();
        b[at..at + 8].copy_from_slice(&huge);
        let mut e = small_engine();
        let err = checkpoint::restore("c.ck", &resealed(&b), e.as_mut(), &tag)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(&expect),
            "{expect:?} is not the start of {err:?}"
        );
    }
    let mut r = checkpoint::Reader::new("c.ck", &huge, 100, "checkpoint");
    let err = r.count(usize::MAX >> 8, &|| "a count".into()).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "c.ck: byte 100: a count is 1152921504606846976, more than {}",
            usize::MAX >> 8
        )
    );
}

/// `verdem cg DIR/s` over the seed save with its `.fstat` replaced, refused with `expect`.
fn cg_refused(fstat: &[u8], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(corpus("small.data"), dir.path().join("s.data.0000")).unwrap();
    std::fs::write(dir.path().join("s.fstat.0000"), fstat).unwrap();
    let base = dir.path().join("s");
    let case = corpus("small.toml");
    refused_beside(
        &[
            "cg",
            base.to_str().unwrap(),
            "--case",
            case.to_str().unwrap(),
        ],
        Some(dir.path()),
        &["s.data.", "s.fstat."],
        expect,
    );
}

#[test]
fn fstat_files_with_bad_contacts_are_refused_by_cg_naming_line_and_column() {
    let l = corpus_lines("small.fstat");
    cg_refused(
        &edit(&l, 5, |s| field(s, 2, "25")),
        &[
            "s.fstat.0000:5:",
            "column 3: particle index 25 is not among the save's 20",
        ],
    );
    cg_refused(
        &edit(&l, 6, |s| field(s, 1, "17.5")),
        &["s.fstat.0000:6:", "column 2 (i): expected a whole number"],
    );
    cg_refused(
        &edit(&l, 6, |s| s.rsplit_once(' ').unwrap().0.to_string()),
        &["s.fstat.0000:6:", "expected 16 columns", "got 15"],
    );
    cg_refused(
        &edit(&l, 6, |s| field(s, 8, "nan")),
        &["s.fstat.0000:6:", "column 9 (fn)", "not finite"],
    );
    cg_refused(
        &edit(&l, 6, |s| field(s, 0, "0.5")),
        &[
            "s.fstat.0000:6:",
            "column 1 (time)",
            "differs from the header's 0",
        ],
    );
    cg_refused(
        &edit(&l, 1, |s| s.replace('#', "")),
        &["s.fstat.0000:1:", "header line 1 must be `# time ...`"],
    );
    let mut bytes = corpus_bytes("small.fstat");
    bytes.truncate(bytes.len() - 20);
    bytes.extend_from_slice(b"\xc3(\n");
    cg_refused(&bytes, &["s.fstat.0000:7:", "not UTF-8"]);
}

/// `verdem kinematics binary_collision.toml MOTION --out FORCES`, refused with `expect`; the
/// forces file is not written.
fn motion_refused(motion: &[u8], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("m.csv");
    std::fs::write(&m, motion).unwrap();
    let forces = dir.path().join("forces.csv");
    let case = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cases/verify/binary_collision.toml");
    refused_beside(
        &[
            "kinematics",
            case.to_str().unwrap(),
            m.to_str().unwrap(),
            "--out",
            forces.to_str().unwrap(),
        ],
        Some(dir.path()),
        &["m.csv"],
        expect,
    );
    assert!(!forces.exists());
}

#[test]
fn motion_files_with_bad_rows_are_refused_naming_line_and_column() {
    let l = corpus_lines("motion.csv");
    let csv_field = |s: &str, k: usize, v: &str| {
        let mut t: Vec<&str> = s.split(',').collect();
        t[k] = v;
        t.join(",")
    };
    motion_refused(
        &edit(&l, 6, |s| csv_field(s, 1, "nan")),
        &["m.csv:6:", "x1: not a finite number: \"nan\""],
    );
    motion_refused(
        &edit(&l, 6, |s| s.rsplitn(3, ',').nth(2).unwrap().to_string()),
        &["m.csv:6:", "expected 27 columns, got 25"],
    );
    // finite numbers too large for the law: its forces would not be finite
    motion_refused(
        &edit(&l, 6, |s| csv_field(s, 1, "-1e308")),
        &["m.csv:6:", "forces or overlap", "not finite"],
    );
    let whole = corpus_bytes("motion.csv");
    motion_refused(
        &whole[..whole.len() - 40],
        &["m.csv:22:", "expected 27 columns"],
    );
    let mut bytes = whole.clone();
    bytes.insert(nth_line_start(&whole, 6), 0xfe);
    motion_refused(&bytes, &["m.csv:6:", "not UTF-8"]);
}

#[test]
fn a_profiles_table_with_nan_is_refused_by_compare() {
    let dir = tempfile::tempdir().unwrap();
    let l = corpus_lines("small.profiles.csv");
    let bad = dir.path().join("nan.profiles.csv");
    std::fs::write(
        &bad,
        edit(&l, 3, |s| {
            let mut t: Vec<&str> = s.split(',').collect();
            t[5] = "NaN";
            t.join(",")
        }),
    )
    .unwrap();
    let good = corpus("small.profiles.csv");
    refused(
        &["compare", good.to_str().unwrap(), bad.to_str().unwrap()],
        None,
        &["nan.profiles.csv:3:", "field vx: not finite"],
    );
}

/// Parses `bytes` as a dump of atoms.
fn parse_dump(bytes: &[u8]) -> Result<verdem::peers::Frame, io::FormatError> {
    dump::parse(&mut Lines::new("d.txt", bytes))
}

#[test]
fn dumps_with_bad_rows_or_headers_are_refused_naming_line_and_item() {
    let l = corpus_lines("lammps_dump.100.txt");
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (
            edit(&l, 12, |s| field(s, 0, "4")),
            "d.txt:12: id: expected 3 (sorted ids 1..N), got 4",
        ),
        (
            edit(&l, 12, |s| field(s, 2, "0")),
            "d.txt:12: radius: must be > 0, got 0",
        ),
        (
            edit(&l, 12, |s| field(s, 6, "nan")),
            "d.txt:12: column 7 (vx): not finite",
        ),
        (
            edit(&l, 4, |_| "21".into()),
            "d.txt:30: 21 rows announced (ITEM: NUMBER OF ATOMS), 20 found",
        ),
        (
            edit(&l, 4, |_| "19".into()),
            "d.txt:29: more lines than the 19 rows announced",
        ),
        (
            edit(&l, 4, |_| "1e30".into()),
            "d.txt:4: ITEM: NUMBER OF ATOMS: expected a whole number",
        ),
        (
            edit(&l, 6, |_| "0 nan".into()),
            "d.txt:6: column 2: not finite",
        ),
        (
            edit(&l, 7, |_| "4".into()),
            "d.txt:7: ITEM: BOX BOUNDS: expected `ylo yhi`",
        ),
        (
            edit(&l, 9, |s| s.replace("omegaz", "fz")),
            "d.txt:9: columns must be",
        ),
        (
            edit(&l, 15, |s| field(s, 11, "1 2")),
            "d.txt:15: expected 12 columns, got 13",
        ),
    ];
    for (bytes, expect) in cases {
        let e = parse_dump(&bytes).unwrap_err().to_string();
        assert!(e.contains(expect), "{expect:?} missing from {e:?}");
    }
    // cut inside a row: the error is on the row it cut
    let cut = &corpus_bytes("lammps_dump.100.txt")[..700];
    let line = 1 + cut.iter().filter(|&&b| b == b'\n').count();
    let e = parse_dump(cut).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("d.txt:{line}: expected 12 columns")),
        "{e}"
    );
    let mut bytes = corpus_bytes("liggghts_dump.100.txt");
    bytes.insert(nth_line_start(&bytes, 13), 0xff);
    let e = parse_dump(&bytes).unwrap_err().to_string();
    assert!(e.starts_with("d.txt:13: not UTF-8"), "{e}");
    let e = dump::parse_entries(
        &mut Lines::new("c.txt", &corpus_bytes("lammps_contacts.0.txt")[..]),
        5,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("c.txt:10: expected 5 columns, got 6"), "{e}");
}

/// A wall means file whose steps reach the end of the step numbers is refused naming the line
/// after which no step can follow (the next step was once computed with an overflow: a panic in
/// a debug build, a wrapped step in a release one).
#[test]
fn wall_means_at_the_end_of_the_step_numbers_are_refused_without_an_overflow() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("walls.txt");
    let last = u64::MAX - 4095;
    std::fs::write(&p, format!("{last} 0 0 0 0 0 0\n{last} 0 0 0 0 0 0\n")).unwrap();
    let err = verdem::peers::inrun::read_wall_means(&p, 4096)
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        format!(
            "{}:2: column 1 (step): step {last}, expected none: the step numbers end (a mean \
             every 4096 steps)",
            p.display()
        )
    );
}

// ---- fuzzing ----------------------------------------------------------------------------

/// One random change to a file's bytes.
#[derive(Clone, Debug)]
enum Mutation {
    /// Flip one bit of one byte.
    Flip(prop::sample::Index, u8),
    /// Cut the file at a byte.
    Truncate(prop::sample::Index),
    /// Delete a line.
    DeleteLine(prop::sample::Index),
    /// Repeat a line.
    DuplicateLine(prop::sample::Index),
    /// Replace a word or CSV field by a troublesome token, on any line or (`head`) on one of
    /// the first ten, where the headers and their counts are.
    Token {
        line: prop::sample::Index,
        head: bool,
        word: prop::sample::Index,
        token: &'static str,
    },
    /// Insert bytes that are not UTF-8.
    NotUtf8(prop::sample::Index, &'static [u8]),
    /// Overwrite 8 bytes with a troublesome little-endian word (a count, NaN, an infinity).
    Word(prop::sample::Index, u64),
}

const TOKENS: [&str; 20] = [
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e999",
    "1e-320",
    "0",
    "-0",
    "-1",
    "0.5",
    "18446744073709551616",
    "4294967296",
    "99999999999999999999",
    "",
    "#",
    "x",
    "1 2",
    "\"",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    use prop::sample::Index;
    prop_oneof![
        1 => (any::<Index>(), 0u8..8).prop_map(|(i, b)| Mutation::Flip(i, b)),
        1 => any::<Index>().prop_map(Mutation::Truncate),
        1 => any::<Index>().prop_map(Mutation::DeleteLine),
        1 => any::<Index>().prop_map(Mutation::DuplicateLine),
        3 => (
            any::<Index>(),
            any::<bool>(),
            any::<Index>(),
            prop::sample::select(TOKENS.to_vec())
        )
            .prop_map(|(line, head, word, token)| Mutation::Token {
                line,
                head,
                word,
                token
            }),
        1 => (
            any::<Index>(),
            prop::sample::select(vec![
                &b"\xff"[..],
                b"\xc3",
                b"\xe2\x82",
                b"\x00",
                b"\xed\xa0\x80"
            ])
        )
            .prop_map(|(i, b)| Mutation::NotUtf8(i, b)),
        1 => (
            any::<Index>(),
            prop::sample::select(vec![
                u64::MAX,
                1 << 40,
                0xffff_ffff,
                0,
                19,
                21,
                f64::NAN.to_bits(),
                f64::INFINITY.to_bits(),
                1e308f64.to_bits(),
            ])
        )
            .prop_map(|(i, w)| Mutation::Word(i, w)),
    ]
}

/// `bytes` after `m`.
fn apply(bytes: &[u8], m: &Mutation) -> Vec<u8> {
    let mut out = bytes.to_vec();
    if out.is_empty() {
        return out;
    }
    let lines =
        |b: &[u8]| -> Vec<Vec<u8>> { b.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect() };
    match m {
        Mutation::Flip(i, bit) => {
            let k = i.index(out.len());
            out[k] ^= 1 << bit;
        }
        Mutation::Truncate(i) => out.truncate(i.index(out.len())),
        Mutation::DeleteLine(i) => {
            let mut l = lines(&out);
            l.remove(i.index(l.len()));
            out = l.join(&b'\n');
        }
        Mutation::DuplicateLine(i) => {
            let mut l = lines(&out);
            let k = i.index(l.len());
            l.insert(k, l[k].clone());
            out = l.join(&b'\n');
        }
        Mutation::Token {
            line,
            head,
            word,
            token,
        } => {
            let mut l = lines(&out);
            let k = line.index(if *head { l.len().min(10) } else { l.len() });
            let text = String::from_utf8_lossy(&l[k]).to_string();
            let sep = if text.contains(',') { "," } else { " " };
            let mut words: Vec<&str> = text.split(sep).collect();
            let w = word.index(words.len());
            words[w] = token;
            l[k] = words.join(sep).into_bytes();
            out = l.join(&b'\n');
        }
        Mutation::NotUtf8(i, b) => {
            let k = i.index(out.len() + 1);
            out.splice(k..k, b.iter().copied());
        }
        Mutation::Word(i, w) => {
            let k = i.index(out.len());
            let end = (k + 8).min(out.len());
            out[k..end].copy_from_slice(&w.to_le_bytes()[..end - k]);
        }
    }
    out
}

/// A valid corpus file after one to four random mutations.
fn mutated(seed: &'static str) -> impl Strategy<Value = Vec<u8>> {
    mutations_of(corpus_bytes(seed))
}

/// `bytes` after one to four random mutations.
fn mutations_of(bytes: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(mutation(), 1..5)
        .prop_map(move |ms| ms.iter().fold(bytes.clone(), |b, m| apply(&b, m)))
}

/// Words of the tables verdem reads: numbers, the troublesome tokens, and words of their
/// headers and items.
const WORDS: [&str; 16] = [
    "1",
    "2",
    "3",
    "20",
    "100",
    "0.25",
    "-2.5",
    "1e-3",
    "ITEM: TIMESTEP",
    "ITEM: NUMBER OF ATOMS",
    "ITEM: BOX BOUNDS pp pp ff",
    "ITEM: ATOMS id type radius x y z vx vy vz omegax omegay omegaz",
    "ITEM: ENTRIES",
    "# time",
    "Particles",
    "xMin 0 xMax 4 yMin 0 yMax 2 zMin 0 zMax 5",
];

/// Arbitrary text: any characters, or (mostly) lines of the words of [`WORDS`] and
/// [`TOKENS`] separated by commas or spaces, after one of the `headers` or none.
fn arbitrary_text(headers: Vec<String>) -> impl Strategy<Value = Vec<u8>> {
    let word = prop::sample::select([&WORDS[..], &TOKENS[..]].concat());
    let line = (prop::collection::vec(word, 0..30), any::<bool>())
        .prop_map(|(w, comma)| w.join(if comma { "," } else { " " }));
    let head = prop::option::of(prop::sample::select(
        [headers, vec![String::new()]].concat(),
    ));
    prop_oneof![
        1 => any::<String>().prop_map(String::into_bytes),
        4 => (head, prop::collection::vec(line, 0..40), any::<bool>()).prop_map(
            |(head, lines, crlf)| {
                let lines: Vec<String> = head.into_iter().chain(lines).collect();
                lines.join(if crlf { "\r\n" } else { "\n" }).into_bytes()
            }
        ),
    ]
}

/// What a reader of `text`, the file `file`, returned: a value, or an error that starts with
/// the file's name and, when it names a line next, one the text has (or the one after).
fn named<T, E: std::fmt::Display>(
    r: Result<T, E>,
    file: &str,
    text: &[u8],
) -> Result<(), TestCaseError> {
    let Err(e) = r else { return Ok(()) };
    let msg = e.to_string();
    let rest = msg.strip_prefix(file).and_then(|m| m.strip_prefix(':'));
    prop_assert!(rest.is_some(), "{msg:?} does not start with {file:?}:");
    let digits: String = rest
        .unwrap()
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    if !digits.is_empty() {
        let line: usize = digits.parse().unwrap();
        let lines = 1 + text.iter().filter(|&&b| b == b'\n').count();
        prop_assert!((1..=lines + 1).contains(&line), "{msg:?}: {lines} lines");
    }
    Ok(())
}

thread_local! {
    /// The folder of a test's files, one per test thread (a folder per case would spend the
    /// fuzzing's time making and removing folders).
    static FILES: tempfile::TempDir = tempfile::tempdir().unwrap();
    /// The seed's initial state, as [`small_engine`] builds it.
    static SMALL_SNAPSHOT: verdem::state::Snapshot = small_engine().snapshot();
}

/// [`named`] for a reader of the file `name`, whose text `text` is written to the folder of
/// the test's files. The file is removed after it is read: a file written over by truncation
/// is flushed to the disk when closed on some file systems (ext4), which would spend the
/// fuzzing's time waiting for the disk.
fn named_file<T, E: std::fmt::Display>(
    name: &str,
    text: &[u8],
    read: impl FnOnce(&Path) -> Result<T, E>,
) -> Result<(), TestCaseError> {
    let p = FILES.with(|d| d.path().join(name));
    std::fs::write(&p, text).unwrap();
    let r = read(&p);
    std::fs::remove_file(&p).unwrap();
    named(r, &p.display().to_string(), text)
}

/// The seed of the table `name` that verdem's own commands read back, with its header: the
/// diagnostics table of a run of the seed (its ledgers), an in-run error table, a wall means
/// file of the peers' in-run averaging, a sweep's `bench.csv` or a trade-off table.
fn table_seed(name: &str) -> Vec<u8> {
    match name {
        "diagnostics" => {
            let dir = tempfile::tempdir().unwrap();
            let mut e = small_engine();
            let opts = verdem::run::RunOptions {
                end_step: 20,
                save_every: 5,
                checkpoint_every: 0,
                out_dir: dir.path().to_path_buf(),
                name: "s".into(),
                tag: checkpoint::tag(&small_case()),
                progress: false,
                write_saves: true,
                vtk: false,
                stop: None,
            };
            verdem::run::run(e.as_mut(), &opts, false).unwrap();
            std::fs::read(verdem::run::diagnostics_path(dir.path(), "s")).unwrap()
        }
        "errors" => {
            let mut t = String::from(
                "column,tau_measured,tau_reference,tau_used,blocks,degrees_of_freedom,method,\
                 core_mean,core_se,core_degrees_of_freedom,core_trusted\n",
            );
            for c in verdem::analysis::cg::COLUMNS {
                t.push_str(&format!("{c},1.5,2,2,10,9,blocks,0.25,1e-3,9,true\n"));
            }
            t.into_bytes()
        }
        "walls" => {
            let rows: String = (1..6)
                .map(|k| format!("{} 0 0 -1.5 0 0 1.5\n", 10 * k))
                .collect();
            ("# step fx fy fz fx fy fz\n".to_string() + &rows).into_bytes()
        }
        "bench" => (verdem::bench::csv(&[])
            + "verdem,1,100,1e6,100 101,3480,1000,287.3,1,1,\n\
               lammps,2,90,9e5,90 91,3480,1000,319.2,1.1,,\n")
            .into_bytes(),
        "tradeoff" => verdem::tradeoff::csv(&[]).into_bytes(),
        _ => unreachable!("no seed table {name}"),
    }
}

/// The seed table `name` ([`table_seed`]) after random mutations, or arbitrary text after its
/// header.
fn table(name: &'static str) -> impl Strategy<Value = Vec<u8>> {
    let seed = table_seed(name);
    let header = String::from_utf8_lossy(&seed)
        .lines()
        .next()
        .unwrap_or_default()
        .to_string();
    prop_oneof![mutations_of(seed), arbitrary_text(vec![header])]
}

/// Yade's files of step 0 of the seed as its script writes them: `save.0.txt` (radius x y z
/// vx vy vz wx wy wz per body) and `contacts.0.txt` (the two bodies, from 0, the force on the
/// first and its elastic spring).
fn yade_seed(what: &str) -> Vec<u8> {
    let s = small_engine().snapshot();
    let p = &s.particles;
    let mut t = String::from("# written by the seed\n");
    match what {
        "save" => {
            for a in 0..p.len() {
                let n = |v: &verdem::Vec3| format!("{} {} {}", v.x, v.y, v.z);
                t.push_str(&format!(
                    "{} {} {} {}\n",
                    p.radius[a],
                    n(&p.x[a]),
                    n(&p.v[a]),
                    n(&p.w[a])
                ));
            }
        }
        _ => t.push_str("16 0 0 0 -2.5 0 0 -1e-3\n17 18 0.25 0 0 1e-3 0 0\n"),
    }
    t.into_bytes()
}

/// The first line of the corpus file `name`.
fn first_line(name: &str) -> String {
    corpus_lines(name)[0].clone()
}

/// A checkpoint this verdem writes, as [`written_checkpoint`] writes it.
fn checkpoint_bytes() -> Vec<u8> {
    written_checkpoint(tempfile::tempdir().unwrap().path()).1
}

/// Arbitrary bytes, alone or after the magic and version of a checkpoint of format 4 (with a
/// checksum) or 3 (without).
fn arbitrary_checkpoint() -> impl Strategy<Value = Vec<u8>> {
    let tail = prop::collection::vec(any::<u8>(), 0..4096);
    prop_oneof![
        tail.clone(),
        tail.clone()
            .prop_map(|t| [&b"\x89VERDEMK"[..], &4u64.to_le_bytes(), &t].concat()),
        tail.prop_map(|t| [&b"VERDEMCK"[..], &3u64.to_le_bytes(), &t].concat()),
    ]
}

/// Cases per reader: the whole fuzz set runs in a few seconds in release.
fn fuzz_config() -> ProptestConfig {
    ProptestConfig {
        cases: 4000,
        ..ProptestConfig::default()
    }
}

fn small_case() -> Case {
    Case::load(&corpus("small.toml")).unwrap()
}

fn small_engine() -> Box<dyn Engine> {
    let case = small_case();
    let scene = verdem::scene::build(&case, Some(&corpus("small.data"))).unwrap();
    engine::build(&case, scene, &Overrides::default()).unwrap()
}

proptest! {
    #![proptest_config(fuzz_config())]

    #[test]
    fn fuzz_data(b in prop_oneof![
        mutated("small.data"),
        arbitrary_text(vec![first_line("small.data")])
    ]) {
        named(mercury::parse_data(&mut Lines::new("f", &b[..])), "f", &b)?;
    }

    #[test]
    fn fuzz_fstat(b in prop_oneof![
        mutated("small.fstat"),
        mutated("mercury.fstat"),
        arbitrary_text(vec![first_line("small.fstat")])
    ]) {
        named(mercury::parse_fstat(&mut Lines::new("f", &b[..]), None), "f", &b)?;
        named(mercury::parse_fstat(&mut Lines::new("f", &b[..]), Some(20)), "f", &b)?;
    }

    #[test]
    fn fuzz_official(b in prop_oneof![
        mutated("small.official.data"),
        arbitrary_text(vec![first_line("small.official.data")])
    ]) {
        named(official::parse(&mut Lines::new("f", &b[..])), "f", &b)?;
    }

    #[test]
    fn fuzz_dumps(b in prop_oneof![
        mutated("lammps_dump.100.txt"),
        mutated("liggghts_dump.100.txt"),
        arbitrary_text(vec![first_line("lammps_dump.100.txt")])
    ]) {
        named(dump::parse(&mut Lines::new("f", &b[..])), "f", &b)?;
    }

    #[test]
    fn fuzz_dump_entries(b in prop_oneof![
        mutated("lammps_contacts.0.txt"),
        mutated("liggghts_contacts.0.txt"),
        arbitrary_text(vec![first_line("lammps_contacts.0.txt")])
    ]) {
        named(dump::parse_entries(&mut Lines::new("f", &b[..]), 6), "f", &b)?;
        named(dump::parse_entries(&mut Lines::new("f", &b[..]), 5), "f", &b)?;
    }

    #[test]
    fn fuzz_motion(b in prop_oneof![
        mutated("motion.csv"),
        arbitrary_text(vec![first_line("motion.csv")])
    ]) {
        match io::utf8("f", b.clone()) {
            Ok(text) => named(verdem::verify::kinematics::parse_motion("f", &text), "f", &b)?,
            Err(e) => named(Err::<(), _>(e), "f", &b)?,
        }
    }

    #[test]
    fn fuzz_forces(b in arbitrary_text(vec![verdem::verify::kinematics::forces_csv(&[])])) {
        if let Ok(text) = String::from_utf8(b.clone()) {
            named(verdem::verify::kinematics::parse_forces_lines("f", &text), "f", &b)?;
        }
    }

    #[test]
    fn fuzz_csv_records(b in arbitrary_text(Vec::new())) {
        if let Ok(text) = String::from_utf8(b.clone()) {
            for comments in [false, true] {
                for r in io::csv_table::records("f", &text, comments) {
                    named(r, "f", &b)?;
                }
            }
        }
    }

    #[test]
    fn fuzz_profiles_table(b in prop_oneof![
        mutated("small.profiles.csv"),
        arbitrary_text(vec![first_line("small.profiles.csv")])
    ]) {
        named_file("t.csv", &b, verdem::analysis::cg::table::Table::read)?;
    }

    #[test]
    fn fuzz_diagnostics_table(b in table("diagnostics")) {
        named_file("s.diagnostics.csv", &b, io::diagnostics::read_ledgers)?;
    }

    #[test]
    fn fuzz_inrun_errors_table(b in table("errors")) {
        named_file("e.csv", &b, verdem::analysis::inrun::read_core_means)?;
    }

    #[test]
    fn fuzz_wall_means(b in table("walls")) {
        named_file("walls.txt", &b, |p| verdem::peers::inrun::read_wall_means(p, 10))?;
    }

    #[test]
    fn fuzz_bench_table(b in table("bench")) {
        named_file("bench.csv", &b, verdem::bench::cost_lines)?;
    }

    /// A peer's files, read through the peer as `verdem cross` reads them.
    #[test]
    fn fuzz_yade_frames(b in prop_oneof![
        mutations_of(yade_seed("save")),
        arbitrary_text(Vec::new())
    ]) {
        let yade = verdem::peers::by_name("yade").unwrap();
        named_file("save.0.txt", &b, |p| {
            let run = verdem::peers::Run { dir: p.parent().unwrap(), np: 1 };
            yade.read_frame(&run, verdem::peers::Save { index: 0, step: 0 })
        })?;
    }

    #[test]
    fn fuzz_peer_contacts(b in prop_oneof![
        mutations_of(yade_seed("contacts")),
        mutated("lammps_contacts.0.txt"),
        arbitrary_text(vec![first_line("lammps_contacts.0.txt")])
    ]) {
        let s = SMALL_SNAPSHOT.with(Clone::clone);
        for peer in ["yade", "lammps", "liggghts"] {
            let peer = verdem::peers::by_name(peer).unwrap();
            named_file("contacts.0.txt", &b, |p| {
                let run = verdem::peers::Run { dir: p.parent().unwrap(), np: 1 };
                peer.read_contacts(&run, verdem::peers::Save { index: 0, step: 0 }, &s)
            })?;
        }
    }

    #[test]
    fn fuzz_tradeoff_table(b in table("tradeoff")) {
        if let Ok(text) = String::from_utf8(b.clone()) {
            let p = Path::new("tradeoff.csv");
            named(verdem::tradeoff::read_csv(&text, p), "tradeoff.csv", &b)?;
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..fuzz_config() })]

    /// Loading into a scene adds the checks that need the case (box, overlaps, counts).
    #[test]
    fn fuzz_initial_state(b in prop_oneof![mutated("small.data"), mutated("small.official.data")]) {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("init.data");
        std::fs::write(&p, &b).unwrap();
        let _ = verdem::scene::build(&small_case(), Some(&p));
    }

    /// A checkpoint of format 2 has no checksum: its mutations reach every field.
    #[test]
    fn fuzz_checkpoint(b in mutated("small.checkpoint")) {
        let mut e = small_engine();
        let tag = checkpoint::tag(&small_case());
        named(checkpoint::restore("f", &b, e.as_mut(), &tag), "f", &[])?;
    }

    /// Any change to a checkpoint with a checksum is refused.
    #[test]
    fn fuzz_checkpoint_with_its_checksum((b, intact) in {
        let intact = checkpoint_bytes();
        mutations_of(intact.clone()).prop_map(move |b| (b, intact.clone()))
    }) {
        prop_assume!(b != intact);
        let mut e = small_engine();
        let tag = checkpoint::tag(&small_case());
        let r = checkpoint::restore("f", &b, e.as_mut(), &tag);
        prop_assert!(r.is_err());
        named(r, "f", &[])?;
    }

    /// Changes made behind the checksum's back (the checksum made again) reach every field.
    #[test]
    fn fuzz_checkpoint_resealed(b in {
        let b = checkpoint_bytes();
        mutations_of(b[..b.len() - 32].to_vec()).prop_map(|b| resealed(&b))
    }) {
        let mut e = small_engine();
        let tag = checkpoint::tag(&small_case());
        named(checkpoint::restore("f", &b, e.as_mut(), &tag), "f", &[])?;
    }

    /// Arbitrary bytes are no checkpoint.
    #[test]
    fn fuzz_checkpoint_arbitrary(b in arbitrary_checkpoint()) {
        let mut e = small_engine();
        let tag = checkpoint::tag(&small_case());
        let r = checkpoint::restore("f", &b, e.as_mut(), &tag);
        prop_assert!(r.is_err());
        named(r, "f", &[])?;
    }
}
