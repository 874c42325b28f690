//! A lock per case folder, so two runners on the same output folder never run one case
//! twice at once: `DIR.lock` (beside the case folder) created with `create_new`, holding the
//! owner's pid. A lock whose pid is dead is stale and is taken over.

use std::io::Write;
use std::path::{Path, PathBuf};

/// A held lock; released on drop.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
}

/// Result of trying to take a lock.
#[derive(Debug)]
pub enum Try {
    /// Taken.
    Taken(Lock),
    /// Held by this live process.
    Held(u32),
}

fn alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists()
}

impl Lock {
    /// The lock file of a case folder.
    pub fn path_for(dir: &Path) -> PathBuf {
        let mut s = dir.as_os_str().to_owned();
        s.push(".lock");
        PathBuf::from(s)
    }

    /// The live process holding the lock of `dir`, if any (a lock left by a dead process
    /// holds nothing).
    pub fn holder(dir: &Path) -> Option<u32> {
        let pid = std::fs::read_to_string(Self::path_for(dir)).ok()?.trim().parse::<u32>().ok()?;
        alive(pid).then_some(pid)
    }

    /// Tries to lock `dir` once; takes over a lock left by a dead process.
    pub fn try_take(dir: &Path) -> Result<Try, String> {
        let path = Self::path_for(dir);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| format!("{}: cannot create folder: {e}", parent.display()))?;
        }
        for _ in 0..3 {
            match std::fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut f) => {
                    f.write_all(std::process::id().to_string().as_bytes())
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                    return Ok(Try::Taken(Lock { path }));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let pid = std::fs::read_to_string(&path).ok().and_then(|s| s.trim().parse::<u32>().ok());
                    match pid {
                        Some(pid) if alive(pid) => return Ok(Try::Held(pid)),
                        // Empty: its owner may be between create and write; wait.
                        None if age(&path) < 2.0 => return Ok(Try::Held(0)),
                        _ => {
                            // Stale: take it over. If another process removed it first,
                            // the next create_new decides between us.
                            let _ = std::fs::remove_file(&path);
                        }
                    }
                }
                Err(e) => return Err(format!("{}: cannot create lock: {e}", path.display())),
            }
        }
        Ok(Try::Held(0))
    }
}

fn age(path: &Path) -> f64 {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .map(|d| d.as_secs_f64())
        .unwrap_or(f64::INFINITY)
}

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_taker_waits_and_stale_lock_is_taken_over() {
        let dir = std::env::temp_dir().join(format!("sphrepro-lock-{}", std::process::id()));
        let case = dir.join("case");
        let l = match Lock::try_take(&case).unwrap() {
            Try::Taken(l) => l,
            t => panic!("{t:?}"),
        };
        assert!(matches!(Lock::try_take(&case).unwrap(), Try::Held(_)));
        assert_eq!(Lock::holder(&case), Some(std::process::id()));
        drop(l);
        assert_eq!(Lock::holder(&case), None);
        // A lock of a dead pid: held by no one, and taken over.
        std::fs::write(Lock::path_for(&case), "4000000000").unwrap();
        assert_eq!(Lock::holder(&case), None);
        assert!(matches!(Lock::try_take(&case).unwrap(), Try::Taken(_)));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
