//! The automation half: problems from `problems/*.toml` ([`registry`]), a result cache
//! keyed by sha2 digests ([`cache`], [`lock`]), a job-pool runner of `simulate`
//! subprocesses ([`runner`]), bounds for CI and case states ([`check`]). It uses the scenes'
//! declared parameters and the `summary.json` / `timeseries.csv` formats, nothing in
//! `solver` but the summary format.

pub mod cache;
pub mod check;
pub mod commands;
pub mod lock;
pub mod registry;
pub mod runner;
