//! Kill and resume: bit for bit, and a log that ends with how the case ended.

use crate::common::*;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A simulation killed outright (SIGKILL) after a checkpoint resumes from it on the next
/// run into the folder and ends bit for bit as an uninterrupted run; a case the runner
/// resumes has a log that ends with its completion.
#[cfg(unix)]
#[test]
fn a_killed_simulation_resumes_bit_for_bit_and_its_log_ends_with_its_end() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["nx=16", "tf=10", "output_dt=2"];
    let whole = tmp.path().join("whole");
    assert_eq!(simulate(&whole, "taylor_green", &sets).code, Some(0));
    let killed = tmp.path().join("killed");
    let mut c = simulate_cmd("taylor_green", &killed, &sets.map(String::from));
    let mut child = c.arg("--checkpoint-every").arg("0.05").stderr(Stdio::null()).spawn().unwrap();
    let t0 = Instant::now();
    while !killed.join("checkpoint.json").exists() {
        assert!(t0.elapsed() < CASE_LIMIT, "no checkpoint");
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(summary(&killed).is_none(), "a killed run left a summary");
    let ran = run_limited(
        {
            let mut c = Command::new(BIN);
            c.args(["--threads", "1", "simulate", "taylor_green", "--out"]).arg(&killed);
            for s in sets {
                c.args(["--set", s]);
            }
            c
        },
        &tmp.path().join("resume"),
        CASE_LIMIT,
    )
    .unwrap();
    assert_eq!(ran.code, Some(0), "{}", ran.text());
    assert!(ran.stderr.contains("resuming"), "{}", ran.text());
    let (a, b) = (summary(&whole).unwrap(), summary(&killed).unwrap());
    assert_eq!((&a["metrics"], &a["steps"]), (&b["metrics"], &b["steps"]));
    for f in ["timeseries.csv", "fluid.pvd"] {
        assert_eq!(std::fs::read(whole.join(f)).unwrap(), std::fs::read(killed.join(f)).unwrap(), "{f}");
    }

    // Through the runner: interrupted (Ctrl-C to runner and case), then resumed.
    use std::os::unix::process::CommandExt;
    let p = Problem::new(ONE_SLOW_CASE);
    let mut c = p.cmd(&["run", "tiny"]);
    let mut runner = c.stdout(Stdio::null()).stderr(Stdio::null()).process_group(0).spawn().unwrap();
    let t0 = Instant::now();
    while !std::fs::read_dir(p.root.join("output/tiny"))
        .is_ok_and(|mut d| d.any(|e| e.is_ok_and(|e| e.path().join("progress").exists())))
    {
        assert!(t0.elapsed() < CASE_LIMIT, "the case does not step");
        std::thread::sleep(Duration::from_millis(20));
    }
    Command::new("kill").args(["-INT", "--", &format!("-{}", runner.id())]).status().unwrap();
    runner.wait().unwrap();
    let log = p.case_dir("a").join("run.log");
    let before = std::fs::read_to_string(&log).unwrap();
    assert!(before.trim_end().lines().last().unwrap().contains("interrupted"), "{before}");
    let o = p.run(&["run", "tiny"]);
    assert_eq!(o.code, Some(0), "{}", o.text());
    let after = std::fs::read_to_string(&log).unwrap();
    assert!(after.starts_with(&before), "the log keeps the first attempt:\n{after}");
    let last = after.trim_end().lines().last().unwrap();
    assert!(last.contains("completed"), "the log ends with {last:?}:\n{after}");
}
