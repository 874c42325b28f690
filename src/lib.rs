//! sphrepro reproduces SPH research papers with one command.
//!
//! Two halves, three layers (`automation -> scenes -> solver`, never the reverse):
//! - [`solver`]: the SPH library (bodies as systems, who acts on whom, one function per
//!   physics term, schemes, the parallel passes, kick-drift-kick integration, output);
//! - [`scenes`]: one module per benchmark geometry, declaring its parameters and metrics;
//! - the command line (`src/main.rs`) and the automation framework that runs problems
//!   from `problems/*.toml` and regenerates the manuscript.
//!
//! To add a scene: write `src/scenes/NAME.rs` with a `SceneEntry` (parameters, build,
//! metric names) and list it in `scenes::SCENES`.

#![deny(missing_docs)]

pub mod automation;
pub mod bench;
pub mod console;
pub mod scenes;
pub mod solver;

/// The README's Rust example, compiled and run as a doc test.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
