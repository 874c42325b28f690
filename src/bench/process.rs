//! Each bench case in a process of its own: the parent starts the hidden subcommands
//! `bench-case` and `bench-interleaved` of its own executable and reads the one JSON line
//! each prints; the child times the case and prints it. A process per case starts every
//! configuration from the same memory state, and makes its peak memory its own.

use super::case::{BenchResult, WARMUP};
use super::timing::{run_case, run_interleaved};
use std::path::Path;

/// Runs the hidden bench subcommand `args` in a child process and reads its JSON result.
pub(super) fn bench_child<T: serde::de::DeserializeOwned>(exe: &Path, args: &[&str]) -> Result<T, String> {
    let o = std::process::Command::new(exe)
        .args(args)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if !o.status.success() {
        return Err(format!("failed: {}", String::from_utf8_lossy(&o.stderr)));
    }
    serde_json::from_slice(&o.stdout).map_err(|e| format!("unreadable result: {e}"))
}

/// One benchmark configuration, timed in a process of its own (`bench-case`) so that each
/// starts from the same memory state and its peak memory is its own.
pub(super) fn bench_case(
    exe: &Path,
    variant: &str,
    nx: usize,
    threads: usize,
    steps: u64,
    kernel: &str,
) -> Result<BenchResult, String> {
    let (nx, threads, steps) = (nx.to_string(), threads.to_string(), steps.to_string());
    bench_child(
        exe,
        &[
            "--threads",
            &threads,
            "bench-case",
            "--variant",
            variant,
            "--nx",
            &nx,
            "--steps",
            &steps,
            "--kernel",
            kernel,
        ],
    )
}

/// The cases of resolution `nx` timed side by side in a process of their own
/// (`bench-interleaved`; see `timing::run_interleaved`).
pub(super) fn bench_interleaved(
    exe: &Path,
    variants: &[String],
    nx: usize,
    threads: &[usize],
    steps: u64,
    rounds: u32,
    kernel: &str,
) -> Result<Vec<BenchResult>, String> {
    let variants = variants.join(",");
    let threads = threads.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(",");
    let (nx, steps, rounds) = (nx.to_string(), steps.to_string(), rounds.to_string());
    bench_child(
        exe,
        &[
            "bench-interleaved",
            "--variants",
            &variants,
            "--nx",
            &nx,
            "--bench-threads",
            &threads,
            "--steps",
            &steps,
            "--rounds",
            &rounds,
            "--kernel",
            kernel,
        ],
    )
}

/// `bench-case`: one configuration timed in this process (see `timing::run_case`), its
/// result printed as one JSON line; the exit code, 0 or 1.
pub fn case_child(variant: &str, nx: usize, steps: u64, kernel: &str) -> u8 {
    print_json(run_case(variant, nx, steps, WARMUP, kernel))
}

/// `bench-interleaved`: the configurations of resolution `nx` timed side by side in this
/// process (see `timing::run_interleaved`), their results printed as one JSON line; the
/// exit code, 0 or 1.
pub fn interleaved_child(
    variants: &[String],
    nx: usize,
    threads: &[usize],
    steps: u64,
    rounds: u32,
    kernel: &str,
) -> u8 {
    print_json(run_interleaved(variants, nx, threads, steps, rounds, WARMUP, kernel))
}

/// A child's result as one JSON line on stdout (exit code 0), or its error on stderr (1).
pub(super) fn print_json(r: Result<impl serde::Serialize, String>) -> u8 {
    match r {
        Ok(r) => {
            crate::outln!("{}", serde_json::to_string(&r).expect("serialises"));
            0
        }
        Err(e) => {
            crate::errln!("error: {e}");
            1
        }
    }
}
