//! The Slurm executor: `run` and `reproduce` with `--executor slurm` submit the cases that
//! are missing, failed or stale as job arrays, one task per case, each task running
//! `sphrepro simulate` for its case into the same folder, under the same lock, as the local
//! runner does; so a case either finished is done for the other.
//!
//! - [`settings`]: `problems/slurm.toml` (or `--slurm-config`), per-problem overrides, the
//!   command line;
//! - [`script`]: the batch script and the manifest its tasks read their case from;
//! - [`submit`]: every array checked by Slurm, then submitted, or none;
//! - [`task`]: what a task runs (`sphrepro slurm-task`): the lock, the simulation, the
//!   checkpoint and requeue before the time limit;
//! - [`queue`]: the cases pending or running in Slurm, for `status` and for a later
//!   submission, which leaves them out;
//! - [`client`]: `sbatch`, `squeue`, `scancel`, `scontrol` and their output;
//! - `watch`: waiting, with progress, resubmission after a time limit, and Ctrl-C.

pub mod client;
pub mod queue;
pub mod script;
pub mod settings;
pub mod submit;
pub mod task;
mod watch;

use super::runner::{Report, Task};
use settings::{Overrides, Settings};
use std::path::{Path, PathBuf};

/// What `--executor slurm` was asked for on the command line.
#[derive(Clone, Debug, Default)]
pub struct Request {
    /// `--slurm-config`: the settings file (default: `slurm.toml` in the problems folder).
    pub config: Option<PathBuf>,
    /// Settings given as flags.
    pub overrides: Overrides,
    /// Wait for the jobs (not `--no-wait`).
    pub wait: bool,
}

/// How a Slurm run ended.
#[derive(Debug)]
pub enum Outcome {
    /// Submitted, not waited for (`--no-wait`).
    Submitted,
    /// Waited for: what each case came to.
    Waited(Report),
}

/// Why it stopped before waiting.
#[derive(Debug)]
pub enum Error {
    /// Bad settings, a refused submission, no Slurm: nothing was submitted.
    Input(String),
    /// An I/O error.
    Failed(String),
}

impl From<submit::Refused> for Error {
    fn from(r: submit::Refused) -> Self {
        match r {
            submit::Refused::Input(e) => Error::Input(e),
            submit::Refused::Failed(e) => Error::Failed(e),
        }
    }
}

/// The settings for a run over the problems in `problems_dir`.
pub fn settings(problems_dir: &Path, request: &Request) -> Result<Settings, String> {
    let mut names: Vec<String> = std::fs::read_dir(problems_dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .filter(|p| p.file_name().is_some_and(|n| n != settings::FILE_NAME))
                .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    Settings::load(request.config.as_deref(), problems_dir, &names, &request.overrides)
}

/// Leaves out of `tasks` the cases a Slurm queue holds already (pending or running, from an
/// earlier submission), saying so.
pub fn leave_out_queued(output: &Path, tasks: &mut Vec<Task>) {
    let queue = queue::read(output);
    if let Some(w) = &queue.warning {
        crate::errln!("warning: {w}");
    }
    tasks.retain(|t| match queue.cases.get(&queue::key(&t.entry.dir)) {
        Some(q) => {
            crate::outln!(
                "{:<7} {}/{} ({}): not submitted again",
                q.word(),
                t.problem,
                t.entry.case.name,
                q.detail()
            );
            false
        }
        None => true,
    });
}

/// `--dry-run`: the scripts that would be submitted and the cases each covers.
pub fn dry_run(
    output: &Path,
    tasks: &[Task],
    settings: &Settings,
    throttle: Option<usize>,
    force: bool,
) -> Result<(), Error> {
    let subs = submit::plan(output, submit::cases_of(tasks, force), settings, throttle)?;
    let reasons: std::collections::HashMap<String, &str> =
        tasks.iter().map(|t| (queue::key(&t.entry.dir), t.reason.as_str())).collect();
    for s in &subs {
        crate::outln!(
            "would submit a job array of {} task(s) (settings: {}):",
            s.cases.len(),
            settings.describe()
        );
        for (i, c) in s.cases.iter().enumerate() {
            let reason = reasons.get(&queue::key(&c.dir)).copied().unwrap_or_default();
            crate::outln!("  task {i}: {}/{} ({reason})  -> {}", c.problem, c.case, c.dir.display());
        }
        crate::outln!("--- {} (not written)", s.dir.join("job.sh").display());
        print!("{}", s.script);
        crate::outln!("---");
    }
    Ok(())
}

/// Submits `tasks` and, with `request.wait`, waits for them.
pub fn execute(
    output: &Path,
    tasks: &[Task],
    settings: &Settings,
    request: &Request,
    throttle: Option<usize>,
    force: bool,
    checkpoint_every: Option<f64>,
) -> Result<Outcome, Error> {
    if tasks.is_empty() {
        return Ok(Outcome::Waited(Report::default()));
    }
    let mut subs = submit::plan(output, submit::cases_of(tasks, force), settings, throttle)?;
    submit::submit(&mut subs, settings, checkpoint_every)?;
    for s in &subs {
        let names: Vec<String> = s.cases.iter().map(|c| format!("{}/{}", c.problem, c.case)).collect();
        crate::outln!(
            "submitted Slurm job {} ({} case(s): {}); script {}",
            s.job_id,
            s.cases.len(),
            names.join(", "),
            s.dir.join("job.sh").display()
        );
    }
    if !request.wait {
        let ids: Vec<String> = subs.iter().map(|s| s.job_id.to_string()).collect();
        crate::outln!(
            "not waiting (--no-wait): `sphrepro status` shows the cases queued, running and done; \
             `--plot-only` draws what has finished; `scancel {}` cancels them",
            ids.join(" ")
        );
        return Ok(Outcome::Submitted);
    }
    Ok(Outcome::Waited(watch::wait(output, subs, settings, throttle, checkpoint_every)))
}
