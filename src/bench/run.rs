//! `sphrepro bench` from start to end: check the options, measure every case (one process
//! each, in as many rounds as `--repeat` asks, the peer in each round after ours; or the
//! cases of a size side by side with `--interleave`), measure ours against the peer's
//! accuracy, then print the report and write the JSON.

use super::case::{default_steps, known_variant, BenchResult, SCHEDULES, VARIANTS};
use super::peer::{edac_l1, peer_run, peer_tf, PeerResult};
use super::process::{bench_case, bench_interleaved};
use super::stats::median_runs;
use super::{report, targets};
use crate::solver::kernel::KernelKind;
use crate::solver::output::summary::Provenance;
use crate::solver::output::write_atomic;
use std::path::{Path, PathBuf};

/// What `sphrepro bench` measures, and where it writes the results.
pub struct Options {
    /// Resolutions (particles per side).
    pub nx: Vec<usize>,
    /// Thread counts.
    pub threads: Vec<usize>,
    /// Variants, each optionally with a schedule suffix (`edac/sweeps`); `None`: every
    /// variant.
    pub variants: Option<Vec<String>>,
    /// Timed steps per case; `None`: about 4 million particle-steps.
    pub steps: Option<u64>,
    /// Runs of every case and of the peer, in as many rounds.
    pub repeat: u32,
    /// Where the results go as JSON.
    pub json: PathBuf,
    /// The peer's runner script.
    pub peer: Option<PathBuf>,
    /// The kernel of every case.
    pub kernel: String,
    /// Time the cases of each size side by side in this many rounds (instead of `repeat`
    /// runs of separate processes; no peer).
    pub interleave: Option<u32>,
}

/// What the runs measured, and the first failure that ended them early.
#[derive(Default)]
struct Measured {
    results: Vec<BenchResult>,
    peers: Vec<PeerResult>,
    failure: Option<String>,
}

/// Runs `sphrepro bench`; the exit code: 0, 1 when a case or a peer run failed (what was
/// measured before it is still reported and written) or the JSON cannot be written, 2 on
/// bad options.
pub fn run(o: &Options) -> u8 {
    let started = chrono::Utc::now();
    // Every option is checked before the first case runs, so that a typo costs no runs.
    let variants = match check(o) {
        Ok(v) => v,
        Err(e) => {
            crate::errln!("error: bench: {e}");
            return 2;
        }
    };
    let exe = std::env::current_exe().expect("own executable");
    let kernel = o.kernel.as_str();
    let mut m = Measured::default();
    match o.interleave {
        Some(rounds) => side_by_side(&exe, o, &variants, rounds, &mut m),
        None => in_rounds(&exe, o, &variants, &mut m),
    }
    // Side by side, each configuration is one result already, its blocks its runs.
    let results = if o.interleave.is_some() { m.results } else { median_runs(m.results) };
    let mut peers = median_runs(m.peers);
    let mut failure = m.failure;
    for p in &mut peers {
        if let Err(e) = peer_accuracy(&exe, p, kernel) {
            failure.get_or_insert(e);
        }
    }
    let provenance = Provenance::now(started);
    let targets = targets::targets(&results, &peers);
    report::print(kernel, &provenance.machine, &results, &peers, &targets);
    let text = serde_json::to_string_pretty(
        &serde_json::json!({ "provenance": provenance, "results": results, "peers": peers, "targets": targets }),
    )
    .expect("serialises");
    if let Err(e) = write_json(&o.json, &text) {
        crate::errln!("error: {e}");
        return 1;
    }
    crate::errln!("wrote {}", o.json.display());
    match failure {
        Some(e) => {
            crate::errln!(
                "error: the bench stopped early (the table and the JSON hold what ran before): {e}"
            );
            1
        }
        None => 0,
    }
}

/// The variants to run, once the kernel, the variants and the peer's script are checked.
fn check(o: &Options) -> Result<Vec<String>, String> {
    if !KernelKind::NAMES.contains(&o.kernel.as_str()) {
        return Err(format!("--kernel {}: expected one of {}", o.kernel, KernelKind::NAMES.join(", ")));
    }
    let variants: Vec<String> =
        o.variants.clone().unwrap_or_else(|| VARIANTS.iter().map(|v| v.0.to_string()).collect());
    if let Some(v) = variants.iter().find(|v| !known_variant(v)) {
        let known: Vec<&str> = VARIANTS.iter().map(|k| k.0).collect();
        let suffixes: Vec<&str> = SCHEDULES.iter().map(|s| s.0).collect();
        return Err(format!(
            "--variants {v}: expected one of {}, each optionally ending in {}",
            known.join(", "),
            suffixes.join(" or ")
        ));
    }
    if let Some(script) = o.peer.as_ref().filter(|p| !p.is_file()) {
        return Err(format!("--peer {}: no such file", script.display()));
    }
    Ok(variants)
}

/// The cases of each size side by side in one process (`--interleave`), in `rounds` rounds.
fn side_by_side(exe: &Path, o: &Options, variants: &[String], rounds: u32, m: &mut Measured) {
    let threads = &o.threads;
    for &n in &o.nx {
        let k = o.steps.unwrap_or_else(|| default_steps(n * n));
        crate::err!(
            "bench nx={n}, {} on {threads:?} threads side by side, {rounds} rounds of {} steps each ... ",
            variants.join(", "),
            k.div_ceil(rounds as u64)
        );
        match bench_interleaved(exe, variants, n, threads, k, rounds, &o.kernel) {
            Ok(r) => {
                let speeds: Vec<String> = r
                    .iter()
                    .map(|r| {
                        format!(
                            "{} on {}: {:.3} M",
                            r.variant,
                            r.threads_label(),
                            r.particle_steps_per_second / 1e6
                        )
                    })
                    .collect();
                crate::errln!("{}", speeds.join(", "));
                m.results.extend(r);
            }
            Err(e) => {
                crate::errln!("{e}");
                m.failure = Some(format!("bench nx={n}, side by side: {e}"));
                return;
            }
        }
    }
}

/// `--repeat` rounds over every case, each in a process of its own, then the peer in the
/// same round, so that a slow spell of the machine falls on both codes alike. The first
/// failure ends the rounds.
fn in_rounds(exe: &Path, o: &Options, variants: &[String], m: &mut Measured) {
    let repeat = o.repeat;
    for round in 1..=repeat {
        let of = if repeat > 1 { format!(" (run {round} of {repeat})") } else { String::new() };
        for &n in &o.nx {
            for v in variants {
                for &t in &o.threads {
                    let k = o.steps.unwrap_or_else(|| default_steps(n * n));
                    crate::err!("bench {v} nx={n} threads={t} steps={k}{of} ... ");
                    match bench_case(exe, v, n, t, k, &o.kernel) {
                        Ok(r) => {
                            crate::errln!("{:.3} M particle-steps/s", r.particle_steps_per_second / 1e6);
                            m.results.push(r);
                        }
                        Err(e) => {
                            crate::errln!("{e}");
                            m.failure = Some(format!("bench {v} nx={n} threads={t}: {e}"));
                            return;
                        }
                    }
                }
            }
        }
        if let Some(script) = &o.peer {
            for &n in &o.nx {
                for &t in &o.threads {
                    let tf = peer_tf(n);
                    crate::err!("peer {} nx={n} threads={t} tf={tf:.4}{of} ... ", script.display());
                    match peer_run(script, n, t, tf) {
                        Ok(p) => {
                            crate::errln!("{:.3} M particle-steps/s", p.particle_steps_per_second / 1e6);
                            m.peers.push(p);
                        }
                        Err(e) => {
                            crate::errln!("error: peer {}: {e}", script.display());
                            m.failure = Some(format!("peer {} nx={n} threads={t}: {e}", script.display()));
                            return;
                        }
                    }
                }
            }
        }
    }
}

/// Our `edac`'s L1 velocity error on the peer's run `p` (same size, threads and end time),
/// set in `p`; an error names the run.
fn peer_accuracy(exe: &Path, p: &mut PeerResult, kernel: &str) -> Result<(), String> {
    let (n, t) = (p.nx, p.threads);
    crate::err!("edac nx={n} threads={t} to the peer's t = {:.4} ... ", p.end_time());
    match edac_l1(exe, n, t, p.end_time(), kernel) {
        Ok(l1) => {
            p.sphrepro_l1_velocity_final = Some(l1);
            let peer = p.l1_velocity_final.map_or("-".into(), |v| format!("{:.2} %", 100.0 * v));
            crate::errln!("L1: peer {peer}, edac {:.2} %", 100.0 * l1);
            Ok(())
        }
        Err(e) => {
            crate::errln!("\nerror: edac on the peer's run: {e}");
            Err(format!("edac on the peer's run nx={n} threads={t}: {e}"))
        }
    }
}

/// Writes the JSON `text` to `path` atomically, creating its folder.
fn write_json(path: &Path, text: &str) -> Result<(), String> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    write_atomic(path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
}
