//! A full disk and a read-only folder (small tmpfs mounts, where the tests run as root).

use crate::common::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A small tmpfs mounted for a test, unmounted when dropped. Mounting needs root: `None`
/// (with a message saying the test is skipped) elsewhere.
#[cfg(target_os = "linux")]
struct Tmpfs {
    dir: PathBuf,
}

#[cfg(target_os = "linux")]
impl Tmpfs {
    fn mount(dir: &Path, options: &str, test: &str) -> Option<Self> {
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } != 0 {
            eprintln!("{test}: skipped: mounting a tmpfs needs root");
            return None;
        }
        std::fs::create_dir_all(dir).unwrap();
        let ok = Command::new("mount").args(["-t", "tmpfs", "-o", options, "tmpfs"]).arg(dir).status();
        if !ok.is_ok_and(|s| s.success()) {
            eprintln!("{test}: skipped: cannot mount a tmpfs here");
            return None;
        }
        Some(Tmpfs { dir: dir.to_path_buf() })
    }
}

#[cfg(target_os = "linux")]
impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.dir).status();
    }
}

/// A case under `run` on a full disk: the runner reports the case's own error, naming the
/// path and the cause, not "killed or crashed"; `simulate` on it exits 1 naming both; no
/// panic, and nothing reads as done.
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_is_reported_with_the_path_and_the_cause() {
    let p = Problem::new(THREE_CASES);
    let disk = p.root.join("disk");
    let Some(_mount) = Tmpfs::mount(&disk, "size=64k", "a_full_disk_is_reported_with_the_path_and_the_cause")
    else {
        return;
    };
    let o = p.run(&["run", "tiny", "--match", "c", "--output", "disk/output"]);
    let t = o.text();
    assert_eq!(o.code, Some(1), "{t}");
    assert!(!o.panicked(), "{t}");
    assert!(t.contains("No space left on device") && t.contains("disk/output/tiny/c-"), "{t}");
    assert!(!t.contains("killed or crashed"), "{t}");
    let s = p.run(&["status", "--output", "disk/output"]);
    assert!(s.stdout.contains("0 done"), "{}", s.text());
    let out = disk.join("sim");
    let ran = simulate(&out, "taylor_green", &["nx=16", "tf=0.02"]);
    assert_eq!(ran.code, Some(1), "{}", ran.text());
    assert!(
        ran.stderr.contains("No space left on device") && ran.stderr.contains(&disk.display().to_string())
    );
    assert!(!ran.panicked(), "{}", ran.text());
    assert!(summary(&out).is_none_or(|s| s["status"] == "failed"));
}

/// A read-only output folder: `run` and `simulate` end with an error naming the path and
/// the cause, without a panic, and write nothing.
#[cfg(target_os = "linux")]
#[test]
fn a_read_only_output_folder_is_reported_with_the_path_and_the_cause() {
    let p = Problem::new(THREE_CASES);
    let ro = p.root.join("ro");
    let Some(_mount) =
        Tmpfs::mount(&ro, "size=64k,ro", "a_read_only_output_folder_is_reported_with_the_path_and_the_cause")
    else {
        return;
    };
    let o = p.run(&["run", "tiny", "--output", "ro/output"]);
    let t = o.text();
    assert_eq!(o.code, Some(1), "{t}");
    assert!(t.contains("ro/output") && t.contains("Read-only file system") && !o.panicked(), "{t}");
    let ran = simulate(&ro.join("sim"), "taylor_green", &["nx=16", "tf=0.02"]);
    assert!(matches!(ran.code, Some(1) | Some(2)), "{}", ran.text());
    assert!(ran.stderr.contains("Read-only file system") && ran.stderr.contains(&ro.display().to_string()));
    assert!(!ran.panicked(), "{}", ran.text());
}
