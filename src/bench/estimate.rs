//! The cost of a whole run predicted from a short run of it (`estimate-case`, the child
//! process of `run --dry-run`'s estimates, [`crate::automation::estimate`]).
//!
//! The case is built as `simulate` builds it, stepped a few untimed steps (a run's first
//! steps fault its memory in and its step schedule is still being tuned), then stepped
//! until `budget` seconds of CPU have gone or it ends. The whole run's CPU time is the
//! measured building and stepping plus the steps still to come times the CPU time a timed
//! step took; the steps still to come are the simulated time left over the mean time step
//! of the timed steps, which is what the scene's time-step rule gives there. Where the short
//! run reaches the scene's end time or diverges (as a stability map's case past its limit
//! does), the estimate is that run's own cost (`exact`).
//!
//! What it cannot see: a cost that grows during a run (IPST's iterations, few in a flow's
//! first steps and at their cap in a developed one; a time step that shrinks as the flow
//! speeds up) and the time series and snapshots the run writes; the estimate is then low.

use super::timing::status_kb;
use crate::scenes::{self, SceneRun};
use crate::solver::output::summary::process_cpu_seconds;
use serde::{Deserialize, Serialize};

/// Untimed steps before the timed ones.
const WARMUP: u64 = 3;

/// Timed steps at least, whatever the budget.
const MIN_TIMED: u64 = 3;

/// A case's predicted cost on one thread.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Estimate {
    /// CPU seconds of the whole run (user + system), predicted.
    pub cpu_seconds: f64,
    /// Peak resident memory of the short run (bytes): the particles and their lists are
    /// all there from the first step.
    pub peak_rss_bytes: u64,
    /// Steps of the whole run, predicted.
    pub steps: u64,
    /// Particles of every body.
    pub particles: usize,
    /// CPU seconds of building the case.
    pub setup_seconds: f64,
    /// CPU seconds per timed step.
    pub seconds_per_step: f64,
    /// Mean time step of the timed steps (s of simulated time).
    pub dt: f64,
    /// Steps timed.
    pub timed_steps: u64,
    /// Whether the short run reached the end time or diverged (the estimate is its measured
    /// cost).
    pub exact: bool,
    /// The simulated time at which the short run diverged, if it did: the whole run stops
    /// there too (a stability map's case past its limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diverged_at: Option<f64>,
}

/// Seconds of CPU this process has used (0 where the OS does not tell).
fn cpu() -> f64 {
    process_cpu_seconds().unwrap_or(0.0)
}

/// Steps `run` until `more` says stop or it reaches `tf`; returns the time of a divergence.
fn step_while(run: &mut dyn SceneRun, tf: f64, more: &mut dyn FnMut(u64) -> bool) -> Option<f64> {
    run.advance(tf, tf, &mut |_, s| more(s)).err().map(|d| d.time)
}

/// Builds `scene` with `sets` and predicts its whole run from a short one of about `budget`
/// CPU seconds of stepping (see the module's text).
pub fn estimate_scene(scene: &str, sets: &[String], budget: f64) -> Result<Estimate, String> {
    let entry = scenes::find(scene)?;
    let params = entry.params_from_sets(sets)?;
    let tf = params.float("tf");
    let c0 = cpu();
    let mut run = (entry.build)(&params)?;
    let setup_seconds = cpu() - c0;
    let particles = run.particles();
    let warm_end = run.steps() + WARMUP;
    let mut diverged_at = step_while(run.as_mut(), tf, &mut |s| s < warm_end);
    let (n0, t0, c1) = (run.steps(), run.time(), cpu());
    if diverged_at.is_none() {
        // (getrusage after each step costs about a microsecond: nothing beside a step.)
        diverged_at = step_while(run.as_mut(), tf, &mut |s| s - n0 < MIN_TIMED || cpu() - c1 < budget);
    }
    let (timed, t1, c2) = (run.steps() - n0, run.time(), cpu());
    let peak_rss_bytes = status_kb("VmHWM:") * 1024;
    let exact = t1 >= tf * (1.0 - 1e-12) || timed == 0 || diverged_at.is_some();
    let seconds_per_step = if timed > 0 { (c2 - c1) / timed as f64 } else { 0.0 };
    let dt = if timed > 0 { (t1 - t0) / timed as f64 } else { 0.0 };
    let (steps, cpu_seconds) = if exact || dt <= 0.0 {
        (run.steps(), c2 - c0)
    } else {
        let left = ((tf - t1) / dt).ceil().max(0.0);
        (run.steps() + left as u64, c2 - c0 + left * seconds_per_step)
    };
    Ok(Estimate {
        cpu_seconds,
        peak_rss_bytes,
        steps,
        particles,
        setup_seconds,
        seconds_per_step,
        dt,
        timed_steps: timed,
        exact,
        diverged_at,
    })
}

/// `estimate-case`: the estimate of one case, printed as one JSON line; the exit code.
pub fn estimate_child(scene: &str, sets: &[String], budget: f64) -> u8 {
    super::process::print_json(estimate_scene(scene, sets, budget))
}
