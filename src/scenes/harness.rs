//! Runs any scene: progress, time series, snapshots, blow-up handling and the summary.

use super::{params::Params, SceneEntry, SceneRun};

use crate::solver::output::summary::{Provenance, Status, Summary};
use crate::solver::output::vtu::Series;
use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Set by the Ctrl-C handler; a running case stops at the next step and is marked failed.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// How to run.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// No progress bar and no plan on stderr.
    pub quiet: bool,
    /// Overwrite a finished run in the output folder.
    pub force: bool,
    /// Write `time tf steps` here about twice a second (for a parent runner's progress).
    pub progress_file: Option<PathBuf>,
}

/// A run that did not produce a result.
#[derive(Debug)]
pub enum RunError {
    /// Bad input or a refused output folder: nothing was written.
    Input(String),
    /// The run started but an I/O error or an interruption stopped it; a `failed`
    /// summary was written if possible.
    Failed(String),
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunError::Input(s) | RunError::Failed(s) => f.write_str(s),
        }
    }
}

fn io_err(path: &Path, e: std::io::Error) -> String {
    format!("{}: {e}", path.display())
}

/// Runs `entry` with `params`, writing into `out`. Returns the summary (completed or
/// diverged), or an error.
pub fn run(entry: &SceneEntry, params: &Params, out: &Path, opts: &RunOptions) -> Result<Summary, RunError> {
    let started = chrono::Utc::now();
    let t0 = Instant::now();
    // Refuse to overwrite a finished result unless asked.
    if let Ok(old) = Summary::read(out) {
        if old.status != Status::Failed && !opts.force {
            return Err(RunError::Input(format!(
                "{} already holds a {} run; pass --force to overwrite it",
                out.display(),
                serde_json::to_value(old.status).unwrap().as_str().unwrap_or("finished")
            )));
        }
    }
    let mut scene = (entry.build)(params).map_err(RunError::Input)?;
    std::fs::create_dir_all(out).map_err(|e| RunError::Input(io_err(out, e)))?;
    // An old summary must not outlive the run that replaces it.
    let summary_path = out.join("summary.json");
    if summary_path.exists() {
        std::fs::remove_file(&summary_path).map_err(|e| RunError::Input(io_err(&summary_path, e)))?;
    }
    let tf = params.float("tf");
    let output_dt = match params.float("output_dt") {
        x if x > 0.0 => x,
        _ => tf / 10.0,
    };
    let sample_dt = match params.float("sample_dt") {
        x if x > 0.0 => x,
        _ => tf / 100.0,
    };
    let plan = scene.plan();
    if !opts.quiet {
        eprintln!("{} with {} particles\n{plan}", entry.name, scene.particles());
    }
    let _ = std::fs::write(out.join("plan.txt"), &plan);

    let ts_path = out.join("timeseries.csv");
    let mut ts = csv::Writer::from_writer(
        std::fs::File::create(&ts_path).map_err(|e| RunError::Input(io_err(&ts_path, e)))?,
    );
    let vtu_dir = out.join("vtu");
    std::fs::create_dir_all(&vtu_dir).map_err(|e| RunError::Input(io_err(&vtu_dir, e)))?;
    let mut series: BTreeMap<String, Series> = BTreeMap::new();

    let bar = progress_bar(opts.quiet);
    let mut progress_file = ProgressFile::new(opts.progress_file.clone());
    let mut stepping = 0.0f64;
    let mut snapshot_index = 0usize;
    let mut next_output = 0.0f64;
    let mut next_sample = 0.0f64;
    let mut header_written = false;
    let particles = scene.particles() as f64;
    let eps = 1e-12 * tf.max(1.0);
    let outcome = loop {
        let t = scene.time();
        let at_end = t >= tf - eps;
        if t >= next_sample - eps || at_end {
            let row = scene.sample();
            let written = (|| -> csv::Result<()> {
                if !header_written {
                    ts.write_record(row.iter().map(|(k, _)| *k))?;
                }
                ts.write_record(row.iter().map(|(_, v)| format!("{v:e}")))?;
                ts.flush()?;
                Ok(())
            })();
            if let Err(e) = written {
                break Outcome::Failed(format!("{}: {e}", ts_path.display()));
            }
            header_written = true;
            next_sample += sample_dt;
        }
        if t >= next_output - eps || at_end {
            let written = scene.snapshot(&vtu_dir, snapshot_index).and_then(|files| {
                for (body, file) in files {
                    let pvd = out.join(format!("{body}.pvd"));
                    series.entry(body).or_insert_with(|| Series::new(pvd)).push(t, &format!("vtu/{file}"))?;
                }
                Ok(())
            });
            if let Err(e) = written {
                break Outcome::Failed(io_err(&vtu_dir, e));
            }
            snapshot_index += 1;
            next_output += output_dt;
        }
        if at_end {
            break Outcome::Completed;
        }
        let target = next_sample.min(next_output).min(tf);
        let ts0 = Instant::now();
        let mut interrupted = false;
        let res = scene.advance_to(target, &mut |time, steps| {
            if let Some(b) = &bar {
                b.set_position((time / tf * 1000.0) as u64);
                b.set_message(format!("t = {time:.4}/{tf}  step {steps}"));
            }
            progress_file.update(time, tf, steps);
            interrupted |= INTERRUPTED.load(Ordering::Relaxed);
        });
        stepping += ts0.elapsed().as_secs_f64();
        if let Some(b) = &bar {
            let rate = particles * scene.steps() as f64 / stepping.max(1e-9);
            b.set_message(format!("t = {:.4}/{tf}  {rate:.3e} particle-steps/s", scene.time()));
        }
        if let Err(d) = res {
            break Outcome::Diverged(d);
        }
        if interrupted {
            break Outcome::Failed("interrupted".into());
        }
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let (status, reason, metrics) = match &outcome {
        Outcome::Completed => (Status::Completed, None, scene.metrics()),
        Outcome::Diverged(d) => (Status::Diverged, Some(d.reason.clone()), BTreeMap::new()),
        Outcome::Failed(r) => (Status::Failed, Some(r.clone()), BTreeMap::new()),
    };
    let mut s = summary(entry, params, scene.as_ref(), status, reason, metrics, started, t0, stepping);
    if let Outcome::Diverged(d) = &outcome {
        s.step = Some(d.step);
        s.final_time = d.time;
    }
    let written = s.write(out).map_err(|e| io_err(&summary_path, e));
    match (outcome, written) {
        (Outcome::Failed(r), _) => Err(RunError::Failed(r)),
        (_, Err(e)) => Err(RunError::Failed(e)),
        _ => Ok(s),
    }
}

enum Outcome {
    Completed,
    Diverged(crate::solver::simulation::Divergence),
    Failed(String),
}

#[allow(clippy::too_many_arguments)]
fn summary(
    entry: &SceneEntry,
    params: &Params,
    scene: &dyn SceneRun,
    status: Status,
    reason: Option<String>,
    metrics: BTreeMap<String, f64>,
    started: chrono::DateTime<chrono::Utc>,
    t0: Instant,
    stepping: f64,
) -> Summary {
    let particles = scene.particles();
    let steps = scene.steps();
    Summary {
        scene: entry.name.into(),
        params: params.to_json(),
        particles,
        steps,
        final_time: scene.time(),
        wall_seconds: t0.elapsed().as_secs_f64(),
        particle_steps_per_second: if stepping > 0.0 {
            particles as f64 * steps as f64 / stepping
        } else {
            0.0
        },
        threads: rayon::current_num_threads(),
        status,
        reason,
        step: None,
        metrics,
        provenance: Provenance::now(started),
    }
}

fn progress_bar(quiet: bool) -> Option<indicatif::ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::with_draw_target(Some(1000), indicatif::ProgressDrawTarget::stderr());
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {msg}  eta {eta}")
            .expect("valid template"),
    );
    Some(bar)
}

/// `time tf steps`, rewritten at most twice a second for a parent process to read.
struct ProgressFile {
    path: Option<PathBuf>,
    last: Instant,
}

impl ProgressFile {
    fn new(path: Option<PathBuf>) -> Self {
        Self { path, last: Instant::now() }
    }

    fn update(&mut self, time: f64, tf: f64, steps: u64) {
        let Some(p) = &self.path else { return };
        if self.last.elapsed().as_millis() < 500 {
            return;
        }
        self.last = Instant::now();
        if let Ok(mut f) = std::fs::File::create(p) {
            let _ = writeln!(f, "{time} {tf} {steps}");
        }
    }
}
