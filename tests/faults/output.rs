//! Output that cannot be written: an error naming the stream and the cause, never a panic;
//! a reader that goes away ends the runner quietly.

use crate::common::*;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Standard output on a full device: `list`, `status`, `check` and `run` end with an error
/// naming stdout and the cause, exit 1, no panic; `run`'s results are still true results.
#[cfg(target_os = "linux")]
#[test]
fn output_on_a_full_device_is_an_error_not_a_panic() {
    let p = Problem::new(THREE_CASES);
    for args in [&["list"][..], &["status"], &["check"], &["run", "tiny"]] {
        let mut c = p.cmd(args);
        c.stdout(std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap());
        c.stderr(Stdio::piped());
        let o = c.output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.contains("stdout") && err.contains("No space left on device"), "{args:?}: {err}");
    }
    // The cases `run` simulated are done and true.
    let o = p.run(&["status"]);
    assert_eq!(o.code, Some(0), "{}", o.text());
    assert!(o.stdout.contains("3 done, 0 failed"), "{}", o.text());
}

/// Standard error on a full device: `simulate` stops before stepping, with a `failed`
/// summary naming stderr and the cause, and exit 1, not a panic.
#[cfg(target_os = "linux")]
#[test]
fn simulate_with_stderr_on_a_full_device_fails_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let status = Command::new(BIN)
        .args(["--threads", "1", "simulate", "taylor_green", "--set", "nx=16", "--set", "tf=0.02", "--out"])
        .arg(&out)
        .stderr(std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap())
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(1));
    let s = summary(&out).expect("a summary");
    assert_eq!(s["status"], "failed");
    let reason = s["reason"].as_str().unwrap();
    assert!(reason.contains("stderr") && reason.contains("No space left on device"), "{reason}");
}

/// `run | head -2`: the runner ends quietly when its reader goes, and leaves no case
/// `failed` with a log that does not exist; the next run does every case.
#[cfg(unix)]
#[test]
fn a_closed_pipe_ends_the_runner_quietly() {
    use std::io::BufRead;
    let p = Problem::new(THREE_CASES);
    for lines in [1, 2, 3, 4] {
        let _ = std::fs::remove_dir_all(p.root.join("output"));
        let mut c = p.cmd(&["run", "tiny", "--jobs", "1"]);
        let mut child = c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
        let mut reader = std::io::BufReader::new(child.stdout.take().unwrap());
        for _ in 0..lines {
            let mut l = String::new();
            reader.read_line(&mut l).unwrap();
        }
        drop(reader);
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("panicked") && !err.contains("error"), "after {lines} line(s): {err}");
        // Any case left behind is resumable or missing, never failed with a missing log.
        std::thread::sleep(Duration::from_millis(300));
        let s = p.run(&["status"]);
        for l in s.stdout.lines().filter(|l| l.contains("failed") && l.contains("log ")) {
            let log = l.rsplit("log ").next().unwrap().trim_end_matches(')');
            assert!(p.root.join(log).exists(), "after {lines} line(s): {l}\n{}", s.text());
        }
    }
    let o = p.run(&["run", "tiny"]);
    assert_eq!(o.code, Some(0), "{}", o.text());
    assert!(p.run(&["status"]).stdout.contains("3 done, 0 failed, 0 missing"));
}
