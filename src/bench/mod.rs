//! `sphrepro bench`: throughput (particle-steps per second) and peak memory per particle
//! of the Taylor-Green vortex for `edac`, `ctvf`+`sun` and `ctvf`+`ipst`, over resolutions
//! and thread counts. Each configuration runs in its own process (`bench-case`), so its
//! peak resident memory is its own; or, with `--interleave`, the configurations of a size
//! run side by side in one process (`bench-interleaved`), stepped in turn, so that the
//! machine's slow spells fall on all of them alike.
//!
//! - `run`: the command from start to end ([`run`], [`Options`]);
//! - `process`: a case in a child process, both sides ([`case_child`], [`interleaved_child`]);
//! - `case`: the variants, the simulation a case times, and a measured configuration;
//! - `timing`: timing cases in this process, alone or side by side;
//! - `stats`: median runs and round-by-round ratios with their confidence interval;
//! - `peer`: the peer code's runs and our accuracy on them;
//! - `report`: the Markdown table and what is printed;
//! - `targets`: the throughput targets and whether the runs meet them;
//! - `scene`: `bench --scene`, any registered scene at its parameters, per thread count;
//! - `estimate`: a whole run's cost predicted from a short run of it (`run --dry-run`).

mod case;
mod estimate;
mod peer;
mod process;
mod report;
mod run;
mod scene;
mod stats;
mod targets;
mod timing;

pub use case::DEFAULT_KERNEL;
pub use estimate::{estimate_child, Estimate};
pub use process::{case_child, interleaved_child};
pub use run::{run, Options};
pub use scene::{run_scene, scene_child, SceneOptions};

#[cfg(test)]
mod testutil;
