//! A run that does not fit the address space it may use is refused before it starts.

use crate::common::*;

/// A resolution that does not fit in the address space the process may use (`ulimit -v`)
/// is refused before any particle is made, not aborted with no summary.
#[cfg(target_os = "linux")]
#[test]
fn a_run_beyond_the_address_space_limit_is_refused() {
    use std::os::unix::process::CommandExt;
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let mut c = simulate_cmd("taylor_green", &out, &["nx=1000".into(), "tf=0.001".into()]);
    // SAFETY: only setrlimit between fork and exec, async-signal-safe.
    unsafe {
        c.pre_exec(|| {
            let limit = libc::rlimit { rlim_cur: 1 << 30, rlim_max: 1 << 30 };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let ran = run_limited(c, &tmp.path().join("scratch"), CASE_LIMIT).unwrap();
    assert_eq!(ran.code, Some(2), "{}", ran.text());
    assert!(ran.stderr.contains("`nx`") && ran.stderr.contains("GiB"), "{}", ran.text());
}
