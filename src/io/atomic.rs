//! Durable file writes. [`write`] replaces a file atomically; [`append`] adds one whole block to
//! a file. Both report their failures naming the file, so that a full disk or a read-only
//! folder stops a run with a message that says where.

use std::io::Write;
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

/// Writes `bytes` to `path` atomically and durably: the bytes go to a temporary file beside
/// the target (`.NAME.PID.tmp`), which is flushed to the disk (`fsync`), renamed over the
/// target, and then the folder is flushed too. A reader, a run killed at any moment or a power
/// cut sees either the old file or the complete new one, never a mixture. On any failure
/// (a full disk, a read-only folder) the temporary file is removed, the old file is left as it
/// was, and the error names `path` and the system's error.
pub fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = folder(path);
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(named(path, "write", e));
    }
    if let Err(e) = std::fs::rename(&tmp, path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(named(path, "write", e));
    }
    sync_folder(dir).map_err(|e| named(path, "flush the folder of", e))
}

/// Appends one complete line (or block) with a single `write` call and flushes it to the disk
/// (`fsync`; the folder too when the file is new), so that a killed run leaves no partial line
/// behind. When the block cannot be written whole (a full disk), the file is cut back to its
/// old length, and the error names `path` and the system's error.
pub fn append(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let existed = path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| named(path, "open for appending", e))?;
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
}
