//! The automation framework: everything above the scenes that turns runs into papers.
//!
//! - [`report`]: figures, tables and the manuscript built from run results.

pub mod report;
