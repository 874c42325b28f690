//! Two writers on one folder: the second is refused, naming the folder and the first.

use crate::common::*;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A second `simulate` into a folder another one is writing is refused, naming the folder
/// and the other process; the first run's files are its own.
#[cfg(unix)]
#[test]
fn a_second_simulation_into_a_busy_folder_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let progress = tmp.path().join("progress");
    let mut first = Command::new(BIN)
        .args(["--threads", "1", "simulate", "taylor_green", "--quiet", "--set", "nx=16", "--set", "tf=20"])
        .arg("--out")
        .arg(&out)
        .arg("--progress-file")
        .arg(&progress)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !progress.exists() {
        assert!(t0.elapsed() < CASE_LIMIT, "the first run does not step");
        std::thread::sleep(Duration::from_millis(20));
    }
    // The same folder, named three ways.
    let other_names = [out.clone(), tmp.path().join("./run/"), tmp.path().join("x/../run")];
    for (i, name) in other_names.iter().enumerate() {
        let ran = run_limited(
            simulate_cmd("taylor_green", name, &["nx=12".into(), "tf=0.02".into()]),
            &tmp.path().join(format!("second{i}")),
            CASE_LIMIT,
        )
        .unwrap();
        assert_eq!(ran.code, Some(2), "{name:?}: {}", ran.text());
        assert!(
            ran.stderr.contains(&out.display().to_string()) && ran.stderr.contains(&first.id().to_string()),
            "{name:?}: the folder and the other process are named: {}",
            ran.text()
        );
    }
    Command::new("kill").args(["-INT", &first.id().to_string()]).status().unwrap();
    assert_eq!(first.wait().unwrap().code(), Some(1));
    let s = summary(&out).unwrap();
    assert_eq!((s["status"].as_str(), s["params"]["nx"].as_i64()), (Some("failed"), Some(16)));
    // One run's rows only: times strictly increasing under one header.
    let series = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let t: Vec<f64> = series.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    assert!(t.len() > 1 && t.windows(2).all(|w| w[0] < w[1]), "{series}");
    assert!(!series.lines().skip(1).any(|l| l.starts_with('t')), "{series}");
    // Once it has stopped, the folder is free again.
    let mut c = simulate_cmd("taylor_green", &out, &["nx=12".into(), "tf=0.02".into()]);
    assert!(c.arg("--force").stderr(Stdio::null()).status().unwrap().success());
    assert_eq!(summary(&out).unwrap()["status"], "completed");
}
