//! A run over an older one leaves a series and a folder that agree.

use crate::common::*;

/// `simulate --force` over a run with more snapshots leaves only the new run's: the `.pvd`
/// series and the `vtu/` folder agree.
#[test]
fn force_over_an_older_run_leaves_only_the_new_snapshots() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    assert_eq!(simulate(&out, "taylor_green", &["nx=12", "tf=0.05", "output_dt=0.005"]).code, Some(0));
    let mut c =
        simulate_cmd("taylor_green", &out, &["nx=12".into(), "tf=0.05".into(), "output_dt=0.025".into()]);
    assert!(c.arg("--force").status().unwrap().success());
    let pvd = std::fs::read_to_string(out.join("fluid.pvd")).unwrap();
    let mut listed: Vec<String> = pvd
        .lines()
        .filter_map(|l| {
            Some(l.split("file=\"").nth(1)?.split('"').next()?.trim_start_matches("vtu/").to_string())
        })
        .collect();
    let mut present: Vec<String> = std::fs::read_dir(out.join("vtu"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    listed.sort();
    present.sort();
    assert_eq!(listed.len(), 3, "{pvd}");
    assert_eq!(present, listed);
}
