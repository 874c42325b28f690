//! Submitting cases: one job array per group of cases that ask for the same resources
//! (one, unless `[problems.NAME]` tables differ), checked by Slurm (`sbatch --test-only`)
//! before any is submitted, so that a refused setting submits nothing.

use super::client;
use super::script::{self, Manifest, ManifestCase};
use super::settings::{Job, Settings};
use crate::automation::runner::Task;
use std::path::{Path, PathBuf};

/// Tasks in one array at most (Slurm's default `MaxArraySize` is 1001).
pub const MAX_ARRAY: usize = 1000;

/// A job array submitted (or, for `--dry-run`, written out but not submitted).
#[derive(Clone, Debug)]
pub struct Submission {
    /// Its folder: `OUTPUT/.slurm/<id>/`.
    pub dir: PathBuf,
    /// Slurm's job id (0 before submission).
    pub job_id: u64,
    /// What it asks for.
    pub job: Job,
    /// Task `i` runs `cases[i]`.
    pub cases: Vec<ManifestCase>,
    /// The batch script.
    pub script: String,
}

/// Why nothing was submitted.
#[derive(Debug)]
pub enum Refused {
    /// A setting Slurm refused, or no Slurm: bad input.
    Input(String),
    /// An I/O error.
    Failed(String),
}

/// The manifest entries of `tasks`.
pub fn cases_of(tasks: &[Task], force: bool) -> Vec<ManifestCase> {
    tasks
        .iter()
        .map(|t| ManifestCase {
            problem: t.problem.clone(),
            case: t.entry.case.name.clone(),
            dir: std::path::absolute(&t.entry.dir).unwrap_or_else(|_| t.entry.dir.clone()),
            scene: t.entry.case.scene.clone(),
            sets: t.entry.case.params.0.iter().map(|(k, v)| format!("{k}={v}")).collect(),
            force,
            record: t.entry.record.clone(),
            estimate_seconds: crate::automation::estimate::stored_for(&t.entry)
                .map(|m| m.estimate.cpu_seconds),
        })
        .collect()
}

/// What is submitted, before it is: the cases grouped by the job they ask for, each group in
/// arrays of at most [`MAX_ARRAY`], with their folders and scripts (nothing written yet).
pub fn plan(
    output: &Path,
    cases: Vec<ManifestCase>,
    settings: &Settings,
    throttle: Option<usize>,
) -> Result<Vec<Submission>, Refused> {
    let exe =
        std::env::current_exe().map_err(|e| Refused::Failed(format!("cannot find own executable: {e}")))?;
    let root = std::path::absolute(output.join(script::FOLDER))
        .map_err(|e| Refused::Failed(format!("{}: {e}", output.display())))?;
    let mut groups: Vec<(Job, Vec<ManifestCase>)> = Vec::new();
    for c in cases {
        if c.dir.to_string_lossy().contains(['\n', '\r']) {
            return Err(Refused::Input(format!("{}: a case folder with a line break", c.dir.display())));
        }
        let job = settings.job(&c.problem).clone();
        match groups.iter_mut().find(|(j, _)| *j == job) {
            Some((_, list)) => list.push(c),
            None => groups.push((job, vec![c])),
        }
    }
    let stamp = chrono::Utc::now().format("%Y%m%d-%H%M%S");
    let mut out = Vec::new();
    for (job, list) in groups {
        for chunk in list.chunks(MAX_ARRAY) {
            let job = with_estimated_time(&job, chunk);
            let dir = root.join(format!("{stamp}-{}-{}", std::process::id(), out.len()));
            let mut problems: Vec<&str> = chunk.iter().map(|c| c.problem.as_str()).collect();
            problems.sort_unstable();
            problems.dedup();
            let name = match problems[..] {
                [one] => format!("sphrepro-{one}"),
                _ => "sphrepro".to_string(),
            };
            let script = script::render(&job, &name, &dir, chunk.len(), throttle, &exe);
            out.push(Submission { dir, job_id: 0, job: job.clone(), cases: chunk.to_vec(), script });
        }
    }
    Ok(out)
}

/// Margin of a time limit taken from estimates: the estimates run low where a step grows
/// dearer during a run (IPST in a developed flow), and a task past its limit is requeued
/// from its checkpoint, not lost.
const ESTIMATE_MARGIN: f64 = 1.5;

/// `job` with a time limit from the estimates of `cases` where the settings set none: the
/// largest case's CPU time over the task's CPUs, times [`ESTIMATE_MARGIN`], plus the
/// checkpoint signal's lead and ten minutes for start-up and output, in whole minutes.
/// Without an estimate for every case the limit stays the partition's default.
fn with_estimated_time(job: &Job, cases: &[ManifestCase]) -> Job {
    let longest = cases.iter().map(|c| c.estimate_seconds).try_fold(0.0_f64, |m, e| e.map(|e| m.max(e)));
    match (&job.time, longest) {
        (None, Some(secs)) => {
            let limit =
                secs / job.cpus_per_task.max(1) as f64 * ESTIMATE_MARGIN + job.signal_before as f64 + 600.0;
            let minutes = (limit / 60.0).ceil() as u64;
            let time = format!("{}-{:02}:{:02}:00", minutes / 1440, minutes / 60 % 24, minutes % 60);
            Job { time: Some(time), ..job.clone() }
        }
        _ => job.clone(),
    }
}

/// Writes every submission's folder, asks Slurm whether it takes each, then submits them
/// all. A refusal submits nothing and leaves no folder; it names the setting Slurm
/// refused, where it was set and its value.
pub fn submit(
    subs: &mut [Submission],
    settings: &Settings,
    checkpoint_every: Option<f64>,
) -> Result<(), Refused> {
    let clean = |subs: &[Submission]| {
        for s in subs {
            let _ = std::fs::remove_dir_all(&s.dir);
        }
    };
    for s in subs.iter() {
        if let Err(e) = write(s, settings, checkpoint_every) {
            clean(subs);
            return Err(Refused::Failed(e));
        }
    }
    for s in subs.iter() {
        if let Err(m) = client::test_only(&s.dir.join("job.sh")) {
            clean(subs);
            return Err(Refused::Input(refusal(&m, s, settings)));
        }
    }
    for i in 0..subs.len() {
        match client::submit(&subs[i].dir.join("job.sh")) {
            Ok(id) => {
                subs[i].job_id = id;
                let path = subs[i].dir.join("job");
                if let Err(e) = crate::solver::output::write_atomic(&path, id.to_string().as_bytes()) {
                    // The job runs; only `status` will not see it.
                    crate::errln!("warning: {}: {e}", path.display());
                }
            }
            Err(m) => {
                // Taken by --test-only, refused now: take back what went in.
                let ids: Vec<u64> = subs[..i].iter().map(|s| s.job_id).collect();
                if !ids.is_empty() {
                    let _ = client::cancel(&ids);
                }
                let e = refusal(&m, &subs[i], settings);
                clean(subs);
                return Err(Refused::Input(e));
            }
        }
    }
    Ok(())
}

/// Writes `job.sh`, `manifest.json` and `dirs.txt` of a submission.
fn write(s: &Submission, settings: &Settings, checkpoint_every: Option<f64>) -> Result<(), String> {
    std::fs::create_dir_all(&s.dir).map_err(|e| format!("{}: cannot create: {e}", s.dir.display()))?;
    let manifest = Manifest {
        checkpoint_every,
        max_requeues: settings.max_requeues,
        threads: s.job.cpus_per_task,
        cases: s.cases.clone(),
    };
    let dirs: String = s.cases.iter().map(|c| format!("{}\n", c.dir.display())).collect();
    for (name, bytes) in [
        ("manifest.json", serde_json::to_vec_pretty(&manifest).expect("manifest serialises")),
        ("dirs.txt", dirs.into_bytes()),
        ("job.sh", s.script.clone().into_bytes()),
    ] {
        let path = s.dir.join(name);
        crate::solver::output::write_atomic(&path, &bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// One line for a submission Slurm refused: its message, and the setting it is about with
/// its value and where it was set.
fn refusal(message: &str, s: &Submission, settings: &Settings) -> String {
    if message.starts_with('`') {
        // No Slurm here (`sbatch` not found): nothing to do with a setting.
        return message.to_string();
    }
    let problem = s.cases.first().map(|c| c.problem.as_str()).unwrap_or_default();
    let named: Vec<String> = client::refused_settings(message)
        .iter()
        .map(|&key| {
            let value = match key {
                "partition" => s.job.partition.clone(),
                "account" => s.job.account.clone(),
                "time" => s.job.time.clone(),
                "mem" => s.job.mem.clone(),
                "cpus_per_task" => Some(s.job.cpus_per_task.to_string()),
                "sbatch" => Some(s.job.sbatch.join(" ")),
                _ => None,
            };
            let value =
                value.map_or_else(|| "(not set: the cluster's default)".to_string(), |v| format!("{v:?}"));
            format!("{} = {value}", settings.origin(key, problem))
        })
        .collect();
    if named.is_empty() {
        format!("sbatch refused the job: {message} (script: {})", s.dir.join("job.sh").display())
    } else {
        format!("sbatch refused {}: {message}", named.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::cache::CaseRecord;

    fn case(estimate: Option<f64>) -> ManifestCase {
        let record = CaseRecord {
            problem: "p".into(),
            name: "c".into(),
            scene: "taylor_green".into(),
            params: Default::default(),
            solver: String::new(),
            key: "0".repeat(64),
        };
        ManifestCase {
            problem: "p".into(),
            case: "c".into(),
            dir: PathBuf::from("/o/p/c"),
            scene: "taylor_green".into(),
            sets: Vec::new(),
            force: false,
            record,
            estimate_seconds: estimate,
        }
    }

    /// The longest case's CPU time over the task's CPUs, times 1.5, plus the signal's lead
    /// and ten minutes, in whole minutes; only where every case has an estimate and the
    /// settings set no limit.
    #[test]
    fn a_time_limit_comes_from_the_estimates_where_the_settings_set_none() {
        let job = Job { cpus_per_task: 2, signal_before: 180, ..Job::default() };
        // 7200 / 2 * 1.5 + 180 + 600 = 6180 s: 103 minutes.
        let cases = [case(Some(600.0)), case(Some(7200.0))];
        assert_eq!(with_estimated_time(&job, &cases).time.as_deref(), Some("0-01:43:00"));
        // Two days and more.
        let long = [case(Some(2.0 * 86_400.0 * 2.0 / 1.5))];
        assert_eq!(with_estimated_time(&job, &long).time.as_deref(), Some("2-00:13:00"));
        assert_eq!(with_estimated_time(&job, &[case(Some(1.0)), case(None)]).time, None);
        let fixed = Job { time: Some("01:00:00".into()), ..job.clone() };
        assert_eq!(with_estimated_time(&fixed, &cases).time.as_deref(), Some("01:00:00"));
    }
}
