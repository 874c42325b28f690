//! A measured configuration the bench tests build on.

use super::case::{BenchResult, DEFAULT_KERNEL};

/// A measured configuration with nothing but its name and throughput.
pub(super) fn sample(variant: &str, nx: usize, threads: usize, speed: f64) -> BenchResult {
    BenchResult {
        variant: variant.into(),
        kernel: DEFAULT_KERNEL.into(),
        nx,
        threads,
        copies: 1,
        particles: nx * nx,
        steps: 100,
        seconds: 1.0,
        particle_steps_per_second: speed,
        peak_rss_bytes: 0,
        bytes_per_particle: 0.0,
        ipst_iterations_mean: 0.0,
        phase_shares: Default::default(),
        runs: Vec::new(),
        schedule: "sweeps".into(),
    }
}
