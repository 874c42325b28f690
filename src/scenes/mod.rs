//! Scenes: one module per benchmark geometry and initial condition. A scene declares its
//! parameters ([`params::Spec`]), builds a simulation from them and computes its metrics;
//! the [`harness`] runs any scene and writes its output. The automation half sees only
//! [`SCENES`].

pub mod cavity;
pub mod clamped_beam_udl;
pub mod colliding_rings;
pub mod dam_break;
pub mod dam_break_elastic_plate;
pub mod elastic_gate;
pub mod fluid_scheme;
pub mod free_surface_demo;
pub mod fsi_common;
pub mod geometry;
pub mod harness;
pub mod high_velocity_impact;
pub mod hydrostatic_plate;
pub mod hydrostatic_tank;
pub mod measure;
pub mod memory;
pub mod oscillating_plate;
pub mod params;
pub mod progress;
pub mod snapshots;
pub mod solid_common;
pub mod stepping;
pub mod tank;
pub mod taylor_green;
pub mod turek_csm3;
pub mod uniaxial_compression;
pub mod walls;

use crate::solver::simulation::Divergence;
use params::{Params, Spec};
use std::collections::BTreeMap;
use std::path::Path;

/// A scene built from parameters and ready to run: the dimension-free face of a
/// `Simulation<D>` plus the scene's own bookkeeping.
pub trait SceneRun {
    /// Particles in all bodies.
    fn particles(&self) -> usize;
    /// Particles of each body, by name.
    fn body_particles(&self) -> Vec<(String, usize)>;
    /// Simulated time.
    fn time(&self) -> f64;
    /// Steps taken.
    fn steps(&self) -> u64;
    /// Steps of this process whose listing and passes ran as a wavefront over tiles (the
    /// others as sweeps; the results are the same).
    fn wavefront_steps(&self) -> u64;
    /// The plan (bodies, scheme and terms), written at the top of the run log.
    fn plan(&self) -> String;
    /// Steps until the time reaches `t_stop` (steps are not shortened for it) without
    /// passing `t_end` (the step that would is shortened), calling `on_step(time, steps)`
    /// after every step; stops early (returning `Ok(false)`) when `on_step` returns false.
    fn advance(
        &mut self,
        t_stop: f64,
        t_end: f64,
        on_step: &mut dyn FnMut(f64, u64) -> bool,
    ) -> Result<bool, Divergence>;
    /// One time-series row: named values at the current time (the first is `t`).
    fn sample(&mut self) -> Vec<(&'static str, f64)>;
    /// Writes the bodies' snapshots for output number `index` into `dir`; returns the file
    /// names written (relative to `dir`), one per body, with the body name.
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>>;
    /// The metrics of `summary.json` at the end of a completed run.
    fn metrics(&self) -> BTreeMap<String, f64>;
    /// The metrics a run defines before its end (running records: the worst fracture seen
    /// and when it began), which the summary of a run that blew up keeps.
    fn running_metrics(&self) -> BTreeMap<String, f64> {
        BTreeMap::new()
    }
    /// Everything that evolves (bodies, rates, time, the scene's running extrema), for a
    /// checkpoint from which the run resumes bit for bit.
    fn save_state(&self) -> serde_json::Value;
    /// Restores a state written by [`save_state`](Self::save_state) of the same scene
    /// built from the same parameters.
    fn load_state(&mut self, state: serde_json::Value) -> Result<(), String>;
}

/// A registered scene.
pub struct SceneEntry {
    /// Name used on the command line and in problem files.
    pub name: &'static str,
    /// Spatial dimension.
    pub dim: usize,
    /// One line on what it is.
    pub about: &'static str,
    /// Declared parameters (every scene has `tf`, `output_dt` and `sample_dt`).
    pub params: fn() -> Vec<Spec>,
    /// Builds the scene; errors name the parameter.
    pub build: fn(&Params) -> Result<Box<dyn SceneRun>, String>,
    /// The parameter errors `build` would report, found without making a particle (problem
    /// files are checked with it before anything runs).
    pub check: fn(&Params) -> Result<(), String>,
    /// Names of the metrics written to `summary.json`.
    pub metrics: &'static [&'static str],
    /// The columns of `timeseries.csv`, in order (problem files' figures are checked
    /// against them before anything runs).
    pub columns: &'static [&'static str],
    /// Version of what the scene reports (metrics, time-series columns) and of how it builds
    /// its bodies: raised when a metric is added or the scene's geometry is fixed, so that
    /// cached results of the earlier version are stale and rerun (it joins the cache key; 0
    /// adds nothing to it).
    pub outputs: u32,
}

/// Every scene.
pub const SCENES: &[SceneEntry] = &[
    taylor_green::ENTRY,
    taylor_green::ENTRY_3D,
    cavity::ENTRY,
    dam_break::ENTRY,
    hydrostatic_tank::ENTRY,
    free_surface_demo::ENTRY,
    oscillating_plate::ENTRY,
    uniaxial_compression::ENTRY,
    colliding_rings::ENTRY,
    high_velocity_impact::ENTRY,
    turek_csm3::ENTRY,
    clamped_beam_udl::ENTRY,
    hydrostatic_plate::ENTRY,
    dam_break_elastic_plate::ENTRY,
    elastic_gate::ENTRY,
];

/// Looks a scene up by name.
pub fn find(name: &str) -> Result<&'static SceneEntry, String> {
    SCENES.iter().find(|s| s.name == name).ok_or_else(|| {
        let known: Vec<_> = SCENES.iter().map(|s| s.name).collect();
        format!("unknown scene `{name}`; known scenes: {}", known.join(", "))
    })
}

impl SceneEntry {
    /// Parameters from `key=value` strings over the defaults.
    pub fn params_from_sets(&self, sets: &[String]) -> Result<Params, String> {
        let specs = (self.params)();
        let mut p = Params::defaults(&specs);
        let mut given = std::collections::BTreeMap::new();
        for s in sets {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| format!("scene `{}`: `--set {s}` is not of the form key=value", self.name))?;
            let k = k.trim();
            // A key given twice is a typo in one of them: which value was meant is unknown.
            if let Some(first) = given.insert(k, v) {
                return Err(format!("scene `{}`: `{k}` is set twice (`{k}={first}` and `{s}`)", self.name));
            }
            p.set_str(self.name, &specs, k, v)?;
        }
        // A default value counts as not given: the runner passes every resolved parameter of
        // a case, defaults included, and its problem file was checked with the keys it gives.
        let defaults = Params::defaults(&specs);
        let given = |k: &str| given.contains_key(k) && p.0.get(k) != defaults.0.get(k);
        if let Some(e) = fluid_scheme::unused_scheme_option(&p, given) {
            return Err(format!("scene `{}`: parameter `{}` = {} {}", self.name, e.key, p.0[e.key], e.why));
        }
        Ok(p)
    }
}

/// The parameters every scene shares, appended to its own.
pub fn common_params(tf: f64) -> Vec<Spec> {
    use params::Bound;
    vec![
        Spec::float("tf", tf, Bound::Positive, "end time (s)"),
        Spec::float(
            "output_dt",
            0.0,
            Bound::NonNegative,
            "interval between ParaView snapshots (s); 0: tf/10",
        ),
        Spec::float("sample_dt", 0.0, Bound::NonNegative, "interval between time-series rows (s); 0: tf/100"),
        Spec::float("cfl", 0.25, Bound::Positive, "factor of the time-step limits, CTVF eq. (61)"),
        Spec::choice(
            "rate_positions",
            crate::solver::integrator::RatePositions::NAMES,
            "end",
            "where the density and pressure rates (eqs. 56-57) are evaluated: end (after the drift, at the new positions) or start (sec. 3.7: before it, at the step's start positions)",
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `check` refuses what `build` refuses, with the same message, and passes what it builds.
    #[test]
    fn check_refuses_what_build_refuses() {
        let cases: &[(&str, &[&str])] = &[
            ("taylor_green", &["hdx=0.3"]),
            ("taylor_green", &["nx=4"]),
            ("taylor_green", &["nx=100000"]),
            ("taylor_green_3d", &["nz=4"]),
            ("cavity", &["kernel=cubic_spline", "hdx=0.4"]),
            ("dam_break", &["tank_width=0.5"]),
            ("dam_break", &["scheme=edac"]),
            ("hydrostatic_tank", &["height=0.01"]),
            ("free_surface_demo", &["dx=0.2"]),
            ("oscillating_plate", &["poisson_ratio=0.5"]),
            ("oscillating_plate", &["dx=0.05"]),
            ("colliding_rings", &["separation=0.05"]),
            ("colliding_rings", &["dx=0.02"]),
            ("turek_csm3", &["dx=0.02"]),
            ("clamped_beam_udl", &["dx=0.005"]),
        ];
        for (scene, sets) in cases {
            let e = find(scene).unwrap();
            let p = e.params_from_sets(&sets.iter().map(|s| s.to_string()).collect::<Vec<_>>()).unwrap();
            let checked = (e.check)(&p).expect_err(&format!("{scene} {sets:?} passes check"));
            let built = (e.build)(&p).err().expect("build refuses it");
            assert_eq!(checked, built, "{scene} {sets:?}");
        }
        for e in SCENES {
            let p = Params::defaults(&(e.params)());
            assert!((e.check)(&p).is_ok(), "{}: defaults refused", e.name);
        }
    }

    /// Every scene's time series has the columns it declares, in order, with and without
    /// shifting.
    #[test]
    fn each_scene_samples_the_columns_it_declares() {
        for e in SCENES {
            let coarse = match e.name {
                "taylor_green" | "taylor_green_3d" | "cavity" => vec!["nx=16"],
                "dam_break" => vec!["dx=0.1"],
                "oscillating_plate" => vec!["dx=0.01"],
                "colliding_rings" => vec!["dx=0.004"],
                "turek_csm3" => vec!["dx=0.005"],
                "clamped_beam_udl" => vec!["dx=0.003"],
                _ => vec![],
            };
            for pst in ["sun", "none"] {
                let mut sets: Vec<String> = coarse.iter().map(|s| s.to_string()).collect();
                if (e.params)().iter().any(|s| s.name == "pst") {
                    sets.push(format!("pst={pst}"));
                }
                let p = e.params_from_sets(&sets).unwrap();
                let mut run = (e.build)(&p).unwrap();
                let keys: Vec<&str> = run.sample().iter().map(|(k, _)| *k).collect();
                assert_eq!(keys, e.columns, "{} {sets:?}", e.name);
            }
        }
    }
}
