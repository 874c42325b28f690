//! Times a run cannot resolve are refused; no interval makes a loop spin.

use crate::common::*;
use std::time::{Duration, Instant};

/// An output or sample interval the run cannot tell apart from zero, or an end time it
/// cannot resolve, is refused with the key named, at once; a tiny `tf` whose default
/// sample interval follows it runs to its end without spinning.
#[test]
fn tiny_intervals_and_end_times_are_refused_or_run_without_spinning() {
    let tmp = tempfile::tempdir().unwrap();
    let refused: &[(&[&str], &str)] = &[
        (&["tf=0.05", "output_dt=1e-15"], "output_dt"),
        (&["tf=0.05", "sample_dt=1e-300"], "sample_dt"),
        (&["tf=1e-300"], "tf"),
        (&["tf=1e-13"], "tf"),
    ];
    for (i, (sets, key)) in refused.iter().enumerate() {
        let out = tmp.path().join(format!("r{i}"));
        let t0 = Instant::now();
        let ran = simulate(&out, "taylor_green", &[&["nx=16"], *sets].concat());
        assert!(t0.elapsed() < Duration::from_secs(20), "{sets:?}: {:?}", t0.elapsed());
        assert_eq!(ran.code, Some(2), "{sets:?}: {}", ran.text());
        assert!(ran.stderr.contains(&format!("`{key}`")), "{sets:?}: {}", ran.text());
    }
    // tf = 1e-10: its default sample interval, 1e-12, is below the time resolution, so a
    // row per step; one shortened step reaches tf.
    let out = tmp.path().join("short");
    let ran = simulate(&out, "taylor_green", &["nx=16", "tf=1e-10"]);
    assert_eq!(ran.code, Some(0), "{}", ran.text());
    let s = summary(&out).unwrap();
    assert_eq!((s["status"].as_str(), s["steps"].as_u64()), (Some("completed"), Some(1)));
    let rows = std::fs::read_to_string(out.join("timeseries.csv")).unwrap().lines().count();
    assert_eq!(rows, 3, "a header, t = 0 and t = tf");
}
