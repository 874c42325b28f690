//! Runs any scene: progress, time series, snapshots, blow-up handling and the summary.

use super::progress::Progress;
use super::{params::Params, SceneEntry, SceneRun};

use crate::errln;
use crate::solver::output::summary::{Provenance, Status, Summary};
use crate::solver::output::vtu::Series;
use crate::solver::simulation::Divergence;
use std::collections::BTreeMap;
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
    /// Overwrite a finished run in the output folder, or discard the checkpoint of an
    /// interrupted run of other parameters.
    pub force: bool,
    /// Write `time tf steps t0 seconds` here about twice a second (for a parent runner's
    /// progress; see [`progress::read_file`](super::progress::read_file)).
    pub progress_file: Option<PathBuf>,
    /// Write `checkpoint.json` after at most this many wall-clock seconds of stepping
    /// (and always on Ctrl-C); a later run of the same case in the same folder resumes
    /// from it, bit for bit.
    pub checkpoint_every: Option<f64>,
    /// Stop (as if interrupted) after this many steps, checkpointing first: for tests of
    /// the resume path.
    pub stop_after_steps: Option<u64>,
}

/// What `checkpoint.json` holds: the scene's evolving state and the run's bookkeeping.
#[derive(serde::Serialize, serde::Deserialize)]
struct Checkpoint {
    params: Params,
    next_output: f64,
    next_sample: f64,
    snapshot_index: usize,
    stepping: f64,
    ts_rows: usize,
    series: BTreeMap<String, Vec<(f64, String)>>,
    scene: serde_json::Value,
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

/// The time resolution of a run to `tf`: times closer than this count as equal (the
/// solver's step loop takes the same), 1e-12 of `tf` or of 1 s, whichever is larger.
pub fn time_resolution(tf: f64) -> f64 {
    1e-12 * tf.max(1.0)
}

/// Refuses times a run cannot resolve in double precision: an end time `tf` no longer than
/// the time resolution (no step would be taken), and an `output_dt` or `sample_dt` given
/// shorter than it (outputs that close cannot be told apart). Each error names the key.
pub fn check_times(scene: &str, p: &Params) -> Result<(), String> {
    let tf = p.float("tf");
    let resolution = time_resolution(tf);
    if tf <= resolution {
        return Err(format!(
            "scene `{scene}`: `tf` = {tf:e}: not longer than the time resolution of a run, {resolution:e} s (no step would be taken)"
        ));
    }
    for key in ["output_dt", "sample_dt"] {
        let dt = p.float(key);
        if dt > 0.0 && dt <= resolution {
            return Err(format!(
                "scene `{scene}`: `{key}` = {dt:e}: not longer than the time resolution of this run, {resolution:e} s (1e-12 of `tf` or of 1 s); 0 takes a tenth (output) or a hundredth (samples) of `tf`"
            ));
        }
    }
    Ok(())
}

/// The first multiple of `interval` later than `t` by more than `eps`: the next output or
/// sample time after a step that ended at `t`, computed at once (adding `interval` until
/// it passes would spin for as many intervals as `eps` holds). Always later than `t + eps`,
/// so that the run steps before it comes: an interval too fine to pass it (the default
/// tf/100 of a tiny `tf`) gives one output a step.
fn next_after(t: f64, eps: f64, interval: f64) -> f64 {
    let k = ((t + eps) / interval).floor() + 1.0;
    let mut next = k * interval;
    // The product may round down onto `t + eps`.
    if next - eps <= t {
        next = (k + 1.0) * interval;
    }
    if next - eps <= t {
        next = t + 2.0 * eps;
    }
    next
}

/// The first value of `row` (a time-series row or the metrics) that is not finite, as
/// `(name, value)`.
fn not_finite<'a>(row: impl IntoIterator<Item = (&'a str, f64)>) -> Option<(&'a str, f64)> {
    row.into_iter().find(|(_, v)| !v.is_finite())
}

/// Removes the snapshots an earlier run left in `out` (its `.pvd` series and their `vtu/`
/// files), so that a run started afresh there lists what the folder holds.
fn remove_old_snapshots(out: &Path, vtu_dir: &Path) -> std::io::Result<()> {
    for e in std::fs::read_dir(vtu_dir)? {
        let path = e?.path();
        if path.extension().is_some_and(|x| x == "vtu") {
            std::fs::remove_file(&path)?;
        }
    }
    for e in std::fs::read_dir(out)? {
        let path = e?.path();
        // A series of ours: a `.pvd` whose snapshots are under `vtu/`.
        if path.extension().is_some_and(|x| x == "pvd")
            && std::fs::read_to_string(&path).is_ok_and(|s| s.contains("file=\"vtu/"))
        {
            std::fs::remove_file(&path)?;
        }
    }
    Ok(())
}

/// Runs `entry` with `params`, writing into `out`. Returns the summary (completed or
/// diverged), or an error.
pub fn run(entry: &SceneEntry, params: &Params, out: &Path, opts: &RunOptions) -> Result<Summary, RunError> {
    let started = chrono::Utc::now();
    let t0 = Instant::now();
    check_times(entry.name, params).map_err(RunError::Input)?;
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
    // A checkpoint of other parameters is another case's interrupted work: keep it unless
    // asked.
    let ckpt_path = out.join("checkpoint.json");
    let specs = (entry.params)();
    let checkpoint = match read_checkpoint(&ckpt_path) {
        Some(c) if c.params.without_later_defaults(&specs) == params.without_later_defaults(&specs) => {
            Some(c)
        }
        Some(_) if !opts.force => {
            return Err(RunError::Input(format!(
                "{} holds an interrupted run of other parameters; pass --force to discard it",
                ckpt_path.display()
            )))
        }
        _ => None,
    };
    let mut scene = (entry.build)(params).map_err(RunError::Input)?;
    let tf = params.float("tf");
    std::fs::create_dir_all(out).map_err(|e| RunError::Input(io_err(out, e)))?;
    // An old summary must not outlive the run that replaces it.
    let summary_path = out.join("summary.json");
    if summary_path.exists() {
        std::fs::remove_file(&summary_path).map_err(|e| RunError::Input(io_err(&summary_path, e)))?;
    }
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
        errln!("{} with {} particles\n{plan}", entry.name, scene.particles());
    }
    let _ = std::fs::write(out.join("plan.txt"), &plan);

    let ts_path = out.join("timeseries.csv");
    let vtu_dir = out.join("vtu");
    std::fs::create_dir_all(&vtu_dir).map_err(|e| RunError::Input(io_err(&vtu_dir, e)))?;
    let mut series: BTreeMap<String, Series> = BTreeMap::new();
    let mut stepping = 0.0f64;
    let mut snapshot_index = 0usize;
    let mut next_output = 0.0f64;
    let mut next_sample = 0.0f64;
    let mut ts_rows = 0usize;
    // Resume from a checkpoint of this very case, if one is there.
    match checkpoint {
        Some(c) => {
            scene
                .load_state(c.scene)
                .map_err(|e| RunError::Input(format!("{}: {e}", ckpt_path.display())))?;
            truncate_rows(&ts_path, c.ts_rows).map_err(|e| RunError::Input(io_err(&ts_path, e)))?;
            (stepping, snapshot_index, next_output, next_sample, ts_rows) =
                (c.stepping, c.snapshot_index, c.next_output, c.next_sample, c.ts_rows);
            for (body, entries) in c.series {
                let pvd = out.join(format!("{body}.pvd"));
                series.insert(body, Series::with_entries(pvd, entries));
            }
            if !opts.quiet {
                errln!("resuming from {} at t = {}", ckpt_path.display(), scene.time());
            }
        }
        None => {
            let _ = std::fs::remove_file(&ckpt_path);
            remove_old_snapshots(out, &vtu_dir).map_err(|e| RunError::Input(io_err(out, e)))?;
            std::fs::File::create(&ts_path).map_err(|e| RunError::Input(io_err(&ts_path, e)))?;
        }
    }
    let append =
        |path: &Path| std::fs::OpenOptions::new().append(true).open(path).map(csv::Writer::from_writer);
    let mut ts = append(&ts_path).map_err(|e| RunError::Input(io_err(&ts_path, e)))?;
    // The columns of the rows written before a resume: a later build may sample others.
    let mut resumed_columns = (ts_rows > 0).then(|| header(&ts_path)).flatten();

    let mut progress = Progress::new(opts.quiet, opts.progress_file.clone(), tf, scene.time(), scene.steps());
    let mut last_checkpoint = Instant::now();
    let particles = scene.particles() as f64;
    // The particle-steps per second of the stepping so far, shown after each output.
    let mut rate = String::new();
    let eps = time_resolution(tf);
    // The state the run stopped in, as the last snapshot of the series: what blew up and
    // where, for ParaView. Best effort: the divergence is the result.
    let last_snapshot = |scene: &dyn SceneRun, index: usize, series: &mut BTreeMap<String, Series>| {
        if let Err(e) = snapshot(scene, out, &vtu_dir, index, series) {
            errln!("warning: no snapshot of the diverged state: {}", io_err(&vtu_dir, e));
        }
    };
    let outcome = loop {
        let t = scene.time();
        let at_end = t >= tf - eps;
        if t >= next_sample - eps || at_end {
            let row = scene.sample();
            let keys: Vec<&str> = row.iter().map(|(k, _)| *k).collect();
            if resumed_columns.take().is_some_and(|old| old != keys) {
                let realigned =
                    ts.flush().and_then(|_| realign_columns(&ts_path, &keys)).and_then(|_| append(&ts_path));
                match realigned {
                    Ok(w) => ts = w,
                    Err(e) => break Outcome::Failed(io_err(&ts_path, e)),
                }
            }
            let written = (|| -> csv::Result<()> {
                if ts_rows == 0 {
                    ts.write_record(row.iter().map(|(k, _)| *k))?;
                }
                ts.write_record(row.iter().map(|(_, v)| format!("{v:e}")))?;
                ts.flush()?;
                Ok(())
            })();
            if let Err(e) = written {
                break Outcome::Failed(format!("{}: {e}", ts_path.display()));
            }
            ts_rows += 1;
            // A value that is not finite is a blow-up the solver's checks of the fields did
            // not see (a norm over particles that all sit at one point, say).
            if let Some((k, v)) = not_finite(row.iter().copied()) {
                last_snapshot(scene.as_ref(), snapshot_index, &mut series);
                let reason = format!("time-series value `{k}` = {v} is not finite");
                break Outcome::Diverged(Divergence { reason, step: scene.steps(), time: t });
            }
            next_sample = next_after(t, eps, sample_dt);
        }
        if t >= next_output - eps || at_end {
            if let Err(e) = snapshot(scene.as_ref(), out, &vtu_dir, snapshot_index, &mut series) {
                break Outcome::Failed(io_err(&vtu_dir, e));
            }
            snapshot_index += 1;
            next_output = next_after(t, eps, output_dt);
        }
        if at_end {
            let metrics = scene.metrics();
            if let Some((k, v)) = not_finite(metrics.iter().map(|(k, v)| (k.as_str(), *v))) {
                let reason = format!("metric `{k}` = {v} is not finite at the end of the run");
                break Outcome::Diverged(Divergence { reason, step: scene.steps(), time: t });
            }
            break Outcome::Completed(metrics);
        }
        // Output happens at the first step boundary at or after each output time: steps
        // are never shortened for output, so the cadence does not change the solution.
        let target = next_sample.min(next_output).min(tf);
        let ts0 = Instant::now();
        let res = scene.advance(target, tf, &mut |time, steps| {
            progress.update(time, steps, &rate);
            !INTERRUPTED.load(Ordering::Relaxed)
                && crate::console::failure().is_none()
                && opts.stop_after_steps.is_none_or(|n| steps < n)
        });
        stepping += ts0.elapsed().as_secs_f64();
        rate = format!("{:.3e} particle-steps/s", particles * scene.steps() as f64 / stepping.max(1e-9));
        progress.update(scene.time(), scene.steps(), &rate);
        let reached = match res {
            Ok(reached) => reached,
            Err(d) => {
                last_snapshot(scene.as_ref(), snapshot_index, &mut series);
                break Outcome::Diverged(d);
            }
        };
        // At a step boundary: checkpoint when stopped early or when it is time to.
        let due = opts.checkpoint_every.is_some_and(|s| last_checkpoint.elapsed().as_secs_f64() >= s);
        if !reached || due {
            let c = Checkpoint {
                params: params.clone(),
                next_output,
                next_sample,
                snapshot_index,
                stepping,
                ts_rows,
                series: series.iter().map(|(b, s)| (b.clone(), s.entries().to_vec())).collect(),
                scene: scene.save_state(),
            };
            let json = serde_json::to_vec(&c).expect("checkpoint serialises");
            if let Err(e) = crate::solver::output::write_atomic(&ckpt_path, &json) {
                break Outcome::Failed(io_err(&ckpt_path, e));
            }
            last_checkpoint = Instant::now();
        }
        if !reached {
            // Stopped by a signal, or by a message that could not be written.
            let why = crate::console::failure().unwrap_or_else(|| "interrupted".into());
            break Outcome::Failed(format!("{why} (checkpoint written: the next run of this case resumes)"));
        }
    };
    progress.finish();
    let (status, reason, metrics) = match &outcome {
        Outcome::Completed(m) => (Status::Completed, None, m.clone()),
        Outcome::Diverged(d) => (Status::Diverged, Some(d.reason.clone()), scene.running_metrics()),
        Outcome::Failed(r) => (Status::Failed, Some(r.clone()), BTreeMap::new()),
    };
    let mut s = summary(entry, params, scene.as_ref(), status, reason, metrics, started, t0, stepping);
    match &outcome {
        Outcome::Diverged(d) => {
            s.step = Some(d.step);
            s.final_time = d.time;
        }
        // Every declared metric is named: one the run cannot define as `null`.
        Outcome::Completed(_) => s = s.with_undefined(entry.metrics),
        Outcome::Failed(_) => {}
    }
    let written = s.write(out).map_err(|e| io_err(&summary_path, e));
    if written.is_ok() && status != Status::Failed {
        // A finished result needs no checkpoint (and must not be resumed into).
        let _ = std::fs::remove_file(&ckpt_path);
    }
    match (outcome, written) {
        (Outcome::Failed(r), _) => Err(RunError::Failed(r)),
        (_, Err(e)) => Err(RunError::Failed(e)),
        _ => Ok(s),
    }
}

/// Writes snapshot `index` of every body of `scene` and adds it to the bodies' `.pvd`
/// series at the scene's time.
fn snapshot(
    scene: &dyn SceneRun,
    out: &Path,
    vtu_dir: &Path,
    index: usize,
    series: &mut BTreeMap<String, Series>,
) -> std::io::Result<()> {
    let t = scene.time();
    for (body, file) in scene.snapshot(vtu_dir, index)? {
        let pvd = out.join(format!("{body}.pvd"));
        series.entry(body).or_insert_with(|| Series::new(pvd)).push(t, &format!("vtu/{file}"))?;
    }
    Ok(())
}

enum Outcome {
    /// Reached `tf`, with these metrics, every one finite.
    Completed(BTreeMap<String, f64>),
    Diverged(Divergence),
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
        bodies: scene.body_particles().into_iter().collect(),
        steps,
        final_time: scene.time(),
        wall_seconds: t0.elapsed().as_secs_f64(),
        cpu_seconds: crate::solver::output::summary::process_cpu_seconds(),
        particle_steps_per_second: if stepping > 0.0 {
            particles as f64 * steps as f64 / stepping
        } else {
            0.0
        },
        threads: rayon::current_num_threads(),
        wavefront_steps: scene.wavefront_steps(),
        status,
        reason,
        step: None,
        metrics,
        undefined_metrics: Vec::new(),
        provenance: Provenance::now(started),
    }
}

/// The checkpoint in `path`, if there is a readable one.
fn read_checkpoint(path: &Path) -> Option<Checkpoint> {
    let bytes = std::fs::read(path).ok()?;
    serde_json::from_slice(&bytes).ok()
}

/// The column names of a CSV file's header, if it has one.
fn header(path: &Path) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(path).ok()?;
    Some(text.lines().next()?.split(',').map(str::to_string).collect())
}

/// Rewrites a time series under the header `keys`, for a run resumed by a build that samples
/// other columns: each row keeps its values under their names, `NaN` where a column is new
/// (a column no longer sampled is dropped), so that every row has the header's width.
fn realign_columns(path: &Path, keys: &[&str]) -> std::io::Result<()> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let old: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let mut out = keys.join(",") + "\n";
    for line in lines {
        let values: Vec<&str> = line.split(',').collect();
        let value = |k: &&str| old.iter().position(|o| o == k).and_then(|i| values.get(i)).copied();
        out += &keys.iter().map(|k| value(k).unwrap_or("NaN")).collect::<Vec<_>>().join(",");
        out.push('\n');
    }
    crate::solver::output::write_atomic(path, out.as_bytes())
}

/// Keeps the header and the first `rows` rows of a CSV file.
fn truncate_rows(path: &Path, rows: usize) -> std::io::Result<()> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let kept: Vec<&str> = text.lines().take(if rows == 0 { 0 } else { rows + 1 }).collect();
    let mut out = kept.join("\n");
    if !out.is_empty() {
        out.push('\n');
    }
    crate::solver::output::write_atomic(path, out.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The next output time comes at once however small the interval is against the time
    /// resolution, and is the first multiple of the interval past it.
    #[test]
    fn the_next_output_time_is_computed_not_counted_up_to() {
        assert_eq!(next_after(0.0, 1e-12, 0.1), 0.1);
        assert_eq!(next_after(0.1, 1e-12, 0.1), 0.2);
        assert_eq!(next_after(0.25, 1e-12, 0.1), 0.30000000000000004);
        // 1e290 intervals within the resolution: one multiplication, not 1e290 additions.
        let t = std::time::Instant::now();
        let next = next_after(0.0, 1e-12, 1e-302);
        assert!(next > 1e-12 && next <= 2e-12, "{next:e}");
        assert!(t.elapsed().as_secs_f64() < 0.1);
        // Always past the resolution, so that a step comes before it.
        for (t, interval) in [(0.0, 1e-12), (1.0, 1e-13), (0.3, 3e-13), (1e3, 1e-20)] {
            let eps = time_resolution(t);
            assert!(next_after(t, eps, interval) - eps > t, "{t} {interval}");
        }
        // An interval longer than the run: its end.
        assert_eq!(next_after(0.5, 1e-12, 1e300), 1e300);
    }

    #[test]
    fn times_a_run_cannot_resolve_are_refused_naming_the_key() {
        let specs = crate::scenes::common_params(2.0);
        let with = |k: &str, v: f64| {
            let mut p = Params::defaults(&specs);
            p.0.insert(k.into(), super::super::params::Value::Float(v));
            check_times("s", &p)
        };
        assert!(with("tf", 2.0).is_ok() && with("output_dt", 2e-12 * 1.5).is_ok());
        for (k, v) in [("tf", 1e-300), ("tf", 1e-12), ("output_dt", 1e-15), ("sample_dt", 2e-12)] {
            let e = with(k, v).unwrap_err();
            assert!(e.contains(&format!("`{k}` = {v:e}")), "{e}");
        }
    }

    /// Rows written by an older build keep their values under their column names; a column
    /// new to this build reads NaN, one it no longer samples is dropped.
    #[test]
    fn a_resumed_time_series_takes_the_new_columns() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("timeseries.csv");
        std::fs::write(&path, "t,u_max,old\n0e0,1e0,7e0\n1e-1,2e0,8e0\n").unwrap();
        assert_eq!(header(&path).unwrap(), ["t", "u_max", "old"]);
        realign_columns(&path, &["t", "u_max", "shift_max"]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, "t,u_max,shift_max\n0e0,1e0,NaN\n1e-1,2e0,NaN\n");
        assert!(text.lines().nth(1).unwrap().split(',').all(|v| v.parse::<f64>().is_ok()));
    }
}
