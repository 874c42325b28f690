//! File helpers shared by the report writers.

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};

/// `<stem><suffix>`, keeping any dots already in the stem (`a/nx=0.5` -> `a/nx=0.5.png`).
pub(crate) fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut s = OsString::from(stem.as_os_str());
    s.push(suffix);
    PathBuf::from(s)
}

/// Creates the directory that will hold `path`.
pub(crate) fn create_parent(path: &Path) -> Result<(), String> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create directory: {e}", dir.display()))
        }
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a
/// rename, so readers never see a half-written file.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    create_parent(path)?;
    let tmp = with_suffix(path, &format!(".{}.tmp", std::process::id()));
    fs::write(&tmp, bytes).map_err(|e| format!("{}: {e}", tmp.display()))?;
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}
