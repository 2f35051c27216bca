//! One run per output folder: an advisory lock (`flock(2)`) on the file `.verdem.lock` in the
//! folder, taken before anything is written there and held until the run ends. The lock file
//! names the process that holds it (its PID and command line), so that a second run into the
//! same folder is refused naming the first, and a lock file left by a run that was killed is
//! recognised (the kernel drops a dead process's lock; its file stays) and said.

use std::fs::File;
use std::io::{Read, Seek, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// The lock file's name in a folder.
pub const LOCK_FILE: &str = ".verdem.lock";

/// Why a folder could not be locked.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another live process holds the folder.
    #[error(
        "{folder}: another verdem run is writing into this folder ({holder}); nothing was \
         written. Wait for it to end, or choose another output folder with --out"
    )]
    Held { folder: String, holder: String },
    /// The lock file could not be opened, read or locked.
    #[error("{file}: cannot {what}: {source}")]
    Io {
        file: String,
        what: &'static str,
        source: std::io::Error,
    },
}

/// The lock of an output folder, held while this value lives; dropping it removes the lock
/// file (while still holding the lock, so that no other process can take the removed one).
#[derive(Debug)]
pub struct FolderLock {
    file: Option<File>,
    path: PathBuf,
    /// The holder a lock file left by a run that did not end named, when there was one.
    stale: Option<String>,
}

impl FolderLock {
    /// Takes the lock of `dir` (which must exist) for this process, whose command line is
    /// `command`. A folder that cannot be written (a read-only file system, no permission) is
    /// not locked: nothing can be written there to mix, and the run's first write reports the
    /// reason naming its file.
    pub fn take(dir: &Path, command: &str) -> Result<FolderLock, LockError> {
        let path = dir.join(LOCK_FILE);
        let io = |what, source| LockError::Io {
            file: path.display().to_string(),
            what,
            source,
        };
        loop {
            let mut f = match std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC)
                .open(&path)
            {
                Ok(f) => f,
                Err(e) if matches!(e.raw_os_error(), Some(libc::EROFS | libc::EACCES)) => {
                    return Ok(FolderLock {
                        file: None,
                        path,
                        stale: None,
                    })
                }
                Err(e) => return Err(io("open the lock file", e)),
            };
            let fd = std::os::fd::AsRawFd::as_raw_fd(&f);
            // SAFETY: `fd` is the open descriptor of `f`, which outlives the call; flock only
            // reads the descriptor.
            if unsafe { libc::flock(fd, libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                let e = std::io::Error::last_os_error();
                if e.raw_os_error() != Some(libc::EWOULDBLOCK) {
                    return Err(io("lock", e));
                }
                let mut holder = String::new();
                let _ = f.read_to_string(&mut holder);
                return Err(LockError::Held {
                    folder: dir.display().to_string(),
                    holder: describe(&holder),
                });
            }
            // The holder before us may have removed the file between our open and our lock:
            // then we hold the lock of a file that is no longer the folder's, and try again.
            let ours = f.metadata().map_err(|e| io("read", e))?;
            match std::fs::symlink_metadata(&path) {
                Ok(now) if now.ino() == ours.ino() && now.dev() == ours.dev() => {}
                _ => continue,
            }
            let mut left = String::new();
            f.read_to_string(&mut left).map_err(|e| io("read", e))?;
            let stale = (!left.trim().is_empty()).then(|| describe(&left));
            let me = format!("PID {}: {command}\n", std::process::id());
            f.set_len(0)
                .and_then(|()| f.rewind())
                .and_then(|()| f.write_all(me.as_bytes()))
                .and_then(|()| f.sync_all())
                .map_err(|e| io("write", e))?;
            return Ok(FolderLock {
                file: Some(f),
                path,
                stale,
            });
        }
    }

    /// The holder named by a lock file that a run which did not end (killed, or its machine
    /// stopped) left in the folder, if this lock took one over.
    pub fn stale(&self) -> Option<&str> {
        self.stale.as_deref()
    }

    /// Whether the folder is locked (false for a folder that cannot be written).
    pub fn held(&self) -> bool {
        self.file.is_some()
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        if self.file.is_some() {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Creates the output folder `dir` (and its parents) where it does not exist, then takes its
/// lock for this process ([`FolderLock::take`], with [`this_command`] as the holder's name).
pub fn lock_folder(dir: &Path) -> Result<FolderLock, LockError> {
    std::fs::create_dir_all(dir).map_err(|source| LockError::Io {
        file: dir.display().to_string(),
        what: "create the output folder",
        source,
    })?;
    FolderLock::take(dir, &this_command())
}

/// The holder a lock file's text names, for a message.
fn describe(text: &str) -> String {
    match text.lines().next().map(str::trim) {
        Some(line) if !line.is_empty() => line.chars().take(400).collect(),
        _ => "a process that has not yet named itself".into(),
    }
}

/// This process's command line, its arguments separated by spaces, for a lock file.
pub fn this_command() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_naming_the_first_and_the_first_s_end_frees_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let first = FolderLock::take(dir.path(), "verdem run a.toml").unwrap();
        assert!(first.held() && first.stale().is_none());
        let e = FolderLock::take(dir.path(), "verdem run b.toml").unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains(&format!("PID {}: verdem run a.toml", std::process::id())),
            "{text}"
        );
        assert!(matches!(e, LockError::Held { .. }));
        drop(first);
        assert!(!dir.path().join(LOCK_FILE).exists());
        let again = FolderLock::take(dir.path(), "verdem run b.toml").unwrap();
        assert!(again.stale().is_none());
    }

    #[test]
    fn a_lock_file_left_by_a_killed_run_is_said_and_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join(LOCK_FILE),
            "PID 4242: verdem run old.toml\n",
        )
        .unwrap();
        let lock = FolderLock::take(dir.path(), "verdem run new.toml").unwrap();
        assert_eq!(lock.stale(), Some("PID 4242: verdem run old.toml"));
        let text = std::fs::read_to_string(dir.path().join(LOCK_FILE)).unwrap();
        assert!(text.ends_with(": verdem run new.toml\n"), "{text}");
    }

    #[test]
    fn a_link_at_the_lock_file_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "keep").unwrap();
        std::os::unix::fs::symlink(&victim, dir.path().join(LOCK_FILE)).unwrap();
        let e = FolderLock::take(dir.path(), "verdem run").unwrap_err();
        assert!(e.to_string().contains("cannot open the lock file"), "{e}");
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
    }
}
