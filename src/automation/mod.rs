//! The automation framework: everything above the scenes that turns runs into papers.
//!
//! - [`registry`]: problems from `problems/*.toml`, checked and expanded into cases;
//! - [`cache`] and [`lock`]: one folder per case keyed by a sha2 digest, one runner per case;
//! - [`runner`]: a job pool of `simulate` subprocesses;
//! - [`check`]: bounds for CI and case states;
//! - [`study`]: the figures and tables a problem declares, the speed-accuracy trade and
//!   stability maps, and the manuscript;
//! - [`report`]: figures, tables and the manuscript built from run results;
//! - [`commands`]: the commands behind the CLI.
//!
//! It uses the scenes' declared parameters and the `summary.json` / `timeseries.csv` /
//! `.vtu` formats, nothing else from `solver`.

pub mod cache;
pub mod check;
pub mod commands;
pub mod lock;
pub mod registry;
pub mod report;
pub mod runner;
pub mod study;
