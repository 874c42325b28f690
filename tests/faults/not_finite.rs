//! A run whose values are not finite ends `diverged`, never `completed`, and a
//! perturbation that cannot make sense is refused up front.

use crate::common::*;
use sphrepro::scenes::harness::{self, RunOptions};
use sphrepro::scenes::params::{Params, Spec};
use sphrepro::scenes::{common_params, SceneEntry, SceneRun};
use sphrepro::solver::simulation::Divergence;
use std::collections::BTreeMap;
use std::path::Path;

/// A scene that steps time by 0.1 s and reports `bad` as its metric `m` (and, from
/// `sample_bad_after` on, as the time-series column `x`).
struct Fake {
    t: f64,
    steps: u64,
    bad: f64,
    sample_bad_after: f64,
}

impl SceneRun for Fake {
    fn particles(&self) -> usize {
        1
    }
    fn body_particles(&self) -> Vec<(String, usize)> {
        vec![("fake".into(), 1)]
    }
    fn time(&self) -> f64 {
        self.t
    }
    fn steps(&self) -> u64 {
        self.steps
    }
    fn wavefront_steps(&self) -> u64 {
        0
    }
    fn plan(&self) -> String {
        "a fake scene".into()
    }
    fn advance(
        &mut self,
        t_stop: f64,
        t_end: f64,
        on_step: &mut dyn FnMut(f64, u64) -> bool,
    ) -> Result<bool, Divergence> {
        while self.t < t_stop - 1e-12 && self.t < t_end - 1e-12 {
            self.t = (self.t + 0.1).min(t_end);
            self.steps += 1;
            if !on_step(self.t, self.steps) {
                return Ok(false);
            }
        }
        Ok(true)
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let x = if self.t >= self.sample_bad_after { self.bad } else { 1.0 };
        vec![("t", self.t), ("x", x)]
    }
    fn snapshot(&self, _: &Path, _: usize) -> std::io::Result<Vec<(String, String)>> {
        Ok(Vec::new())
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        BTreeMap::from([("m".to_string(), self.bad)])
    }
    fn save_state(&self) -> serde_json::Value {
        serde_json::json!({})
    }
    fn load_state(&mut self, _: serde_json::Value) -> Result<(), String> {
        Ok(())
    }
}

fn params() -> Vec<Spec> {
    common_params(1.0)
}

fn entry(build: fn(&Params) -> Result<Box<dyn SceneRun>, String>) -> SceneEntry {
    SceneEntry {
        name: "fake",
        dim: 2,
        about: "a scene whose values turn non-finite",
        params,
        build,
        check: |_| Ok(()),
        metrics: &["m"],
        columns: &["t", "x"],
        outputs: 0,
    }
}

fn run(build: fn(&Params) -> Result<Box<dyn SceneRun>, String>) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let p = Params::defaults(&params());
    let quiet = RunOptions { quiet: true, ..Default::default() };
    let s = harness::run(&entry(build), &p, dir.path(), &quiet).expect("a result");
    let written: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(written["status"], serde_json::to_value(s.status).unwrap());
    written
}

#[test]
fn a_metric_that_is_not_finite_ends_diverged() {
    for bad in [f64::NAN, f64::INFINITY] {
        let s = run(match bad.is_nan() {
            true => |_| Ok(Box::new(Fake { t: 0.0, steps: 0, bad: f64::NAN, sample_bad_after: f64::MAX })),
            false => {
                |_| Ok(Box::new(Fake { t: 0.0, steps: 0, bad: f64::INFINITY, sample_bad_after: f64::MAX }))
            }
        });
        assert_eq!(s["status"], "diverged", "{s}");
        let reason = s["reason"].as_str().unwrap();
        assert!(reason.contains("`m`") && reason.contains("not finite"), "{reason}");
        assert!((s["final_time"].as_f64().unwrap() - 1.0).abs() < 1e-12, "{s}");
        assert_eq!(s["step"], 10);
    }
}

#[test]
fn a_time_series_value_that_is_not_finite_ends_diverged_where_it_turned() {
    let s = run(|_| Ok(Box::new(Fake { t: 0.0, steps: 0, bad: f64::NAN, sample_bad_after: 0.45 })));
    assert_eq!(s["status"], "diverged", "{s}");
    let reason = s["reason"].as_str().unwrap();
    assert!(reason.contains("`x`") && reason.contains("not finite"), "{reason}");
    // Samples fall every tf/100 = 0.01 s, so at each step: the first at or after 0.45.
    assert_eq!(s["step"], 5);
    assert!((s["final_time"].as_f64().unwrap() - 0.5).abs() < 1e-12, "{s}");
    assert!(s["metrics"].as_object().unwrap().is_empty());
}

/// A perturbation of the lattice larger than the spacing (every particle wrapped to one
/// point, every metric NaN) is refused with the key named, not reported `completed`.
#[test]
fn a_perturbation_beyond_the_spacing_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    for (i, perturb) in ["1e20", "1.5"].iter().enumerate() {
        let out = tmp.path().join(format!("p{i}"));
        let ran = simulate(&out, "taylor_green", &["nx=16", "tf=0.05", &format!("perturb={perturb}")]);
        assert_eq!(ran.code, Some(2), "{}", ran.text());
        assert!(ran.stderr.contains(&format!("`perturb` = {perturb}: must be <= 1")), "{}", ran.text());
        assert!(!out.join("summary.json").exists());
    }
    // Up to the spacing itself, it runs.
    let out = tmp.path().join("ok");
    let ran = simulate(&out, "taylor_green", &["nx=16", "tf=0.01", "perturb=1"]);
    assert!(matches!(ran.code, Some(0) | Some(3)), "{}", ran.text());
}
