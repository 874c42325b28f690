//! A lock per case folder, so two runners on the same output folder never run one case
//! twice at once: `DIR.lock` beside the case folder, held with an exclusive OS file lock
//! (`flock` on unix) and holding the owner's pid for messages.
//!
//! The OS lock, not the pid, decides who holds it: the kernel releases it when the last
//! process holding the file closes it, so a killed runner leaves nothing to clean up and a
//! recycled pid cannot keep a case locked. The runner hands the open file to the
//! simulation it starts (`inherit_fd`), so a simulation that outlives its runner still
//! holds the case and no second one is started in the same folder.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::Write;
use std::path::{Path, PathBuf};

/// A held lock; released (and its file removed) on drop.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
    file: File,
}

/// Result of trying to take a lock.
#[derive(Debug)]
pub enum Try {
    /// Taken.
    Taken(Lock),
    /// Held by another open file: the pid it names (0 if not yet written).
    Held(u32),
}

impl Lock {
    /// The lock file of a case folder.
    pub fn path_for(dir: &Path) -> PathBuf {
        let mut s = dir.as_os_str().to_owned();
        s.push(".lock");
        PathBuf::from(s)
    }

    /// The pid named by the lock of `dir` while a live process holds it.
    pub fn holder(dir: &Path) -> Option<u32> {
        let path = Self::path_for(dir);
        let file = File::open(&path).ok()?;
        match file.try_lock_shared() {
            Ok(()) => None,
            Err(TryLockError::WouldBlock) => Some(pid_in(&path)),
            Err(TryLockError::Error(_)) => None,
        }
    }

    /// Tries to lock `dir` once. A lock file that no process holds (its owner died) is
    /// taken over.
    pub fn try_take(dir: &Path) -> Result<Try, String> {
        let path = Self::path_for(dir);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| format!("{}: cannot create folder: {e}", parent.display()))?;
        }
        let io = |e: std::io::Error| format!("{}: cannot lock: {e}", path.display());
        // The holder removes the file on release: a file locked after that removal is no
        // longer the one at `path`, so check it still is, and retry if not.
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => return Ok(Try::Held(pid_in(&path))),
                Err(TryLockError::Error(e)) => return Err(io(e)),
            }
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0).map_err(io)?;
            file.write_all(std::process::id().to_string().as_bytes()).map_err(io)?;
            return Ok(Try::Taken(Lock { path, file }));
        }
    }

    /// Lets a child process inherit the locked file, so that the lock holds while either
    /// lives. Call in the child between fork and exec (`CommandExt::pre_exec`): it only
    /// clears the descriptor's close-on-exec flag.
    #[cfg(unix)]
    pub fn inherit_fd(&self) -> std::os::unix::io::RawFd {
        std::os::unix::io::AsRawFd::as_raw_fd(&self.file)
    }
}

/// Whether `file` is the file now at `path` (same device and inode).
fn same_file(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        path.exists()
    }
}

fn pid_in(path: &Path) -> u32 {
    std::fs::read_to_string(path).ok().and_then(|s| s.trim().parse().ok()).unwrap_or(0)
}

impl Drop for Lock {
    fn drop(&mut self) {
        // Remove while still holding it; closing the file then releases the lock.
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_taker_waits_and_an_unheld_lock_file_is_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        let case = dir.path().join("case");
        let l = match Lock::try_take(&case).unwrap() {
            Try::Taken(l) => l,
            t => panic!("{t:?}"),
        };
        assert!(matches!(Lock::try_take(&case).unwrap(), Try::Held(p) if p == std::process::id()));
        assert_eq!(Lock::holder(&case), Some(std::process::id()));
        drop(l);
        assert_eq!(Lock::holder(&case), None);
        assert!(!Lock::path_for(&case).exists());
        // A file left by a dead owner, or naming a live pid that is not its owner (a
        // recycled pid): held by no one, and taken over.
        for pid in ["4000000000", "1"] {
            std::fs::write(Lock::path_for(&case), pid).unwrap();
            assert_eq!(Lock::holder(&case), None);
            assert!(matches!(Lock::try_take(&case).unwrap(), Try::Taken(_)));
        }
    }
}
