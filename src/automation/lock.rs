//! A lock per case folder, so two runners on the same output folder never run one case
//! twice at once: `DIR.lock` beside the case folder, held with an exclusive OS file lock
//! (`flock` on unix) and holding the owner's pid for messages.
//!
//! The OS lock, not the pid, decides who holds it: the kernel releases it when the last
//! process holding the file closes it, so a killed runner leaves nothing to clean up and a
//! recycled pid cannot keep a case locked. The runner hands the open file to the
//! simulation it starts (`inherit_fd`, taken up there with [`Lock::adopt`]), so a
//! simulation that outlives its runner still holds the case and no second one is started
//! in the same folder. A `simulate` run on its own takes the lock of its output folder
//! itself, so two of them never write into one folder.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::Write;
use std::path::{Component, Path, PathBuf};

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

/// A lock on a folder held for this process by the runner that started it: the runner's
/// open lock file, inherited ([`Lock::inherit_fd`]). The runner releases it.
#[derive(Debug)]
pub struct Inherited {
    _file: File,
}

/// `dir` as an absolute path without `.` or `..` components or a trailing slash, so that
/// every way of naming a folder (`out`, `./out/`, `x/../out`) finds the same lock file.
/// Lexical: `..` after a symbolic link is taken as the parent of the link's own path.
pub fn normalize(dir: &Path) -> PathBuf {
    let abs = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

impl Lock {
    /// The lock file of a case folder.
    pub fn path_for(dir: &Path) -> PathBuf {
        let mut s = normalize(dir).into_os_string();
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

    /// Hands the lock down to the simulation `cmd` starts, and ties its life to this
    /// process's: the child inherits the open
    /// lock file, passed as `--lock-fd` (taken up there with [`Lock::adopt`]), so the case
    /// stays locked while either lives and no other runner starts it; and (Linux) it is sent
    /// SIGUSR1, which stops it with a checkpoint as Ctrl-C does, when this process dies, even
    /// by SIGKILL. Not SIGTERM: the kernel sends the signal again each time the child passes
    /// to another of the dying parent's threads, and a second SIGTERM, like a second Ctrl-C,
    /// ends a run at once.
    #[cfg(unix)]
    pub fn hand_down(&self, cmd: &mut std::process::Command) {
        use std::os::unix::process::CommandExt;
        let lock_fd = self.inherit_fd();
        cmd.arg("--lock-fd").arg(lock_fd.to_string());
        #[cfg(target_os = "linux")]
        // SAFETY: getpid is async-signal-safe and called before the fork.
        let pid = unsafe { libc::getpid() };
        // SAFETY: between fork and exec only async-signal-safe calls (fcntl, prctl, getppid)
        // on a descriptor this process owns.
        unsafe {
            cmd.pre_exec(move || {
                let flags = libc::fcntl(lock_fd, libc::F_GETFD);
                if flags < 0 || libc::fcntl(lock_fd, libc::F_SETFD, flags & !libc::FD_CLOEXEC) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                #[cfg(target_os = "linux")]
                {
                    if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGUSR1) < 0 {
                        return Err(std::io::Error::last_os_error());
                    }
                    // The parent may have died before the prctl: no such process (an error
                    // that allocates nothing, as nothing may between fork and exec).
                    if libc::getppid() != pid {
                        return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
                    }
                }
                Ok(())
            });
        }
    }

    /// Takes up the lock of `dir` that the runner which started this process holds and
    /// handed down as the open descriptor `fd`: checked to be that folder's lock file, so
    /// that a wrong number is an error, not a run without a lock.
    #[cfg(unix)]
    pub fn adopt(dir: &Path, fd: std::os::unix::io::RawFd) -> Result<Inherited, String> {
        use std::os::unix::fs::MetadataExt;
        use std::os::unix::io::FromRawFd;
        let path = Self::path_for(dir);
        // SAFETY: fcntl(F_GETFD) only asks whether the descriptor is open.
        if fd < 0 || unsafe { libc::fcntl(fd, libc::F_GETFD) } < 0 {
            return Err(format!("{}: the lock handed down (descriptor {fd}) is not open", path.display()));
        }
        // SAFETY: the descriptor is open and this process owns it from here on (the runner
        // handed it down for this run only; nothing else in this process uses it).
        let file = unsafe { File::from_raw_fd(fd) };
        match (file.metadata(), std::fs::metadata(&path)) {
            (Ok(a), Ok(b)) if a.dev() == b.dev() && a.ino() == b.ino() => Ok(Inherited { _file: file }),
            _ => {
                // Not ours to close: leave the descriptor as it was.
                std::mem::forget(file);
                Err(format!("{}: the lock handed down (descriptor {fd}) is another file", path.display()))
            }
        }
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

    /// Every name of one folder finds one lock file.
    #[test]
    fn every_name_of_a_folder_has_one_lock() {
        let dir = tempfile::tempdir().unwrap();
        let case = dir.path().join("case");
        let lock = Lock::path_for(&case);
        assert_eq!(lock, normalize(&dir.path().join("case.lock")));
        for other in [dir.path().join("./case/"), dir.path().join("x/../case"), dir.path().join("case/.")] {
            assert_eq!(Lock::path_for(&other), lock, "{other:?}");
        }
        let _held = match Lock::try_take(&case).unwrap() {
            Try::Taken(l) => l,
            t => panic!("{t:?}"),
        };
        assert!(matches!(Lock::try_take(&dir.path().join("x/../case/")).unwrap(), Try::Held(_)));
    }
}
