//! Durable file writes. [`write`] replaces a file atomically; [`append`] adds one whole block to
//! a file. Both report their failures naming the file, so that a full disk or a read-only
//! folder stops a run with a message that says where. Neither writes through a symbolic link
//! planted at the file's name, and neither writes a text that holds a non-finite number
//! ([`non_finite`]): a file verdem writes never holds NaN or an infinity.

use std::io::Write;
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
use std::path::Path;

/// The error of a write into `path`: the file, what was tried and the system's error (its kind
/// is kept, so `ErrorKind::StorageFull` or `PermissionDenied` can still be told apart).
fn named(path: &Path, what: &str, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: cannot {what}: {e}", path.display()))
}

/// The folder holding `path` (`.` for a bare file name).
fn folder(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Makes the folder's entries durable (a rename or a new file survives a power cut).
fn sync_folder(dir: &Path) -> std::io::Result<()> {
    std::fs::File::open(dir)?.sync_all()
}

/// Where a text holds a non-finite number: its line and field (both from 1) and the token.
#[derive(Clone, Debug, PartialEq)]
pub struct NonFinite {
    pub line: usize,
    pub field: usize,
    pub token: String,
}

/// The first token of `bytes` that reads as a non-finite number (`NaN`, `inf`, `-inf`,
/// `infinity`, in any case, as Rust and C print and parse them), when `bytes` are UTF-8 text;
/// tokens are separated by anything but letters, digits, `.`, `+`, `-` and `_`, so a word such
/// as `information` or `nan_count` is not one. Binary files (PNG, checkpoints) are not UTF-8
/// and are not looked into.
pub fn non_finite(bytes: &[u8]) -> Option<NonFinite> {
    let text = std::str::from_utf8(bytes).ok()?;
    for (l, line) in text.lines().enumerate() {
        let tokens = line
            .split(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-' | '_')))
            .filter(|t| !t.is_empty());
        for (f, token) in tokens.enumerate() {
            let unsigned = token.trim_start_matches(['+', '-']);
            if !unsigned.starts_with(['i', 'I', 'n', 'N']) {
                continue;
            }
            if token.parse::<f64>().is_ok_and(|v| !v.is_finite()) {
                return Some(NonFinite {
                    line: l + 1,
                    field: f + 1,
                    token: token.into(),
                });
            }
        }
    }
    None
}

/// Refuses `bytes` for `path` when they hold a non-finite number, naming where.
fn finite(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    match non_finite(bytes) {
        None => Ok(()),
        Some(at) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "{}: not written: line {}, field {} would be the non-finite number {:?} \
                 (verdem never writes NaN or an infinity into a file)",
                path.display(),
                at.line,
                at.field,
                at.token
            ),
        )),
    }
}

/// Writes `bytes` to `path` atomically and durably: the bytes go to a new temporary file beside
/// the target (`.NAME.XXXXXX.tmp`, created exclusively under an unpredictable name, so that
/// no file or link planted in the folder is written through), which is flushed to the disk
/// (`fsync`), renamed over the target (a symbolic link at the target's name is replaced, not
/// followed), and then the folder is flushed too. A reader, a run killed at any moment or a
/// power cut sees either the old file or the complete new one, never a mixture. On any failure
/// (a full disk, a read-only folder, a non-finite number in a text) the temporary file is
/// removed, the old file is left as it was, and the error names `path` and the reason. The new
/// file gets the permissions `File::create` would give it (0666 less the umask).
pub fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    finite(path, bytes)?;
    let dir = folder(path);
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)
        .map_err(|e| named(path, "write", e))?;
    // On an error the temporary file is removed when `tmp` is dropped.
    tmp.write_all(bytes)
        .and_then(|()| tmp.as_file().sync_all())
        .map_err(|e| named(path, "write", e))?;
    tmp.persist(path)
        .map_err(|e| named(path, "write", e.error))?;
    sync_folder(dir).map_err(|e| named(path, "flush the folder of", e))
}

/// Appends one complete line (or block) with a single `write` call and flushes it to the disk
/// (`fsync`; the folder too when the file is new), so that a killed run leaves no partial line
/// behind. When the block cannot be written whole (a full disk), the file is cut back to its
/// old length, and the error names `path` and the system's error. A symbolic link at `path` is
/// refused (`O_NOFOLLOW`), and so is a block that holds a non-finite number.
pub fn append(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    finite(path, bytes)?;
    let existed = path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)
        .map_err(|e| match e.raw_os_error() {
            Some(libc::ELOOP) => std::io::Error::new(
                e.kind(),
                format!(
                    "{}: cannot open for appending: it is a symbolic link, and verdem does not \
                     write through one",
                    path.display()
                ),
            ),
            _ => named(path, "open for appending", e),
        })?;
    let old_len = f.metadata().map_err(|e| named(path, "append to", e))?.len();
    if let Err(e) = f.write_all(bytes).and_then(|()| f.sync_all()) {
        let _ = f.set_len(old_len).and_then(|()| f.sync_all());
        return Err(named(path, "append to", e));
    }
    if !existed {
        sync_folder(folder(path)).map_err(|e| named(path, "flush the folder of", e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn write_replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        super::write(&p, b"one").unwrap();
        super::write(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_failed_write_names_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        // the target is a folder: the rename over it fails
        let p = dir.path().join("busy");
        std::fs::create_dir(p.join("")).unwrap();
        std::fs::write(p.join("inside"), b"x").unwrap();
        let e = super::write(&p, b"new").unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: cannot write: ", p.display())),
            "{e}"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn append_adds_whole_blocks() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        super::append(&p, b"a\n").unwrap();
        super::append(&p, b"b\n").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"a\nb\n");
    }

    #[test]
    fn a_link_at_the_target_is_replaced_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, b"keep").unwrap();
        let p = dir.path().join("out.csv");
        std::os::unix::fs::symlink(&victim, &p).unwrap();
        super::write(&p, b"new").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert!(!std::fs::symlink_metadata(&p).unwrap().is_symlink());
    }

    #[test]
    fn a_link_planted_at_an_appended_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, b"keep").unwrap();
        let p = dir.path().join("t.csv");
        std::os::unix::fs::symlink(&victim, &p).unwrap();
        let e = super::append(&p, b"a\n").unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
    }

    #[test]
    fn the_temporary_file_is_not_a_predictable_name_that_a_link_can_take() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, b"keep").unwrap();
        let p = dir.path().join("a.txt");
        // the name the writer used before it created its temporary files exclusively
        let old = dir
            .path()
            .join(format!(".a.txt.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &old).unwrap();
        super::write(&p, b"new").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
    }

    #[test]
    fn non_finite_numbers_are_found_and_refused_words_are_not() {
        use super::non_finite;
        assert_eq!(
            non_finite(b"1 2 3\n4 inf 6\n").map(|n| (n.line, n.field)),
            Some((2, 2))
        );
        for t in ["NaN", "-inf", "+Infinity", "nan", "x,-INF", "a=NaN"] {
            assert!(non_finite(t.as_bytes()).is_some(), "{t}");
        }
        for t in [
            "information",
            "nan_count",
            "Infinite",
            "1e308",
            "name = \"n\"",
            "in",
            "-",
        ] {
            assert!(non_finite(t.as_bytes()).is_none(), "{t}");
        }
        assert!(non_finite(&[0x89, b'P', b'N', b'G', b' ', b'i', b'n', b'f']).is_none());
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        super::write(&p, b"a,b\n1,2\n").unwrap();
        let e = super::write(&p, b"a,b\n1,NaN\n").unwrap_err().to_string();
        assert!(e.contains("line 2, field 2") && e.contains("NaN"), "{e}");
        let e = super::append(&p, b"3,inf\n").unwrap_err().to_string();
        assert!(e.contains("line 1, field 2"), "{e}");
        assert_eq!(std::fs::read(&p).unwrap(), b"a,b\n1,2\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_new_file_gets_the_permissions_of_file_create() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let created = dir.path().join("created");
        std::fs::File::create(&created).unwrap();
        let p = dir.path().join("written");
        super::write(&p, b"x").unwrap();
        let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode();
        assert_eq!(mode(&p), mode(&created));
    }
}
