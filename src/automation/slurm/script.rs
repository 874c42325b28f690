//! A submission on disk: the batch script of one job array and the manifest its tasks read
//! their case from, in `OUTPUT/.slurm/<id>/` beside the cases they run.
//!
//! Task `i` of the array runs the case on line `i + 1` of `dirs.txt` (for the shell, which
//! sends everything the task prints to that case's `run.log`) and entry `i` of
//! `manifest.json` (for `sphrepro slurm-task`, which takes the case's lock and runs
//! `sphrepro simulate` for it).

use super::settings::Job;
use crate::automation::cache::CaseRecord;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The folder of every submission under an output folder.
pub const FOLDER: &str = ".slurm";

/// The signal Slurm sends `signal_before` seconds before a task's time limit, to the
/// task's own process (`B:`): `simulate` stops at the next step with a checkpoint on it.
pub const WARNING_SIGNAL: &str = "USR1";

/// One case of a submission.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ManifestCase {
    /// Problem name.
    pub problem: String,
    /// Case name.
    pub case: String,
    /// The case's folder (absolute).
    pub dir: PathBuf,
    /// Scene.
    pub scene: String,
    /// `--set key=value` arguments of `simulate`.
    pub sets: Vec<String>,
    /// Re-run even if done (`--force`); a requeued task does not force again.
    pub force: bool,
    /// The case's inputs, written to `case.json` when the task starts.
    pub record: CaseRecord,
    /// Its estimated CPU seconds on one thread, where a dry run measured them (they set the
    /// array's time limit when the settings set none).
    #[serde(skip)]
    pub estimate_seconds: Option<f64>,
}

/// What the tasks of one array read.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    /// `simulate --checkpoint-every` (seconds).
    pub checkpoint_every: Option<f64>,
    /// Requeues of a case after its time limit, at most.
    pub max_requeues: u32,
    /// Threads of each simulation when Slurm does not say (`SLURM_CPUS_PER_TASK`).
    pub threads: u32,
    /// Task `i` runs `cases[i]`.
    pub cases: Vec<ManifestCase>,
}

impl Manifest {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// The batch script of a submission in folder `dir` (absolute) of `n` tasks, at most
/// `throttle` running at once, running `exe`.
pub fn render(job: &Job, name: &str, dir: &Path, n: usize, throttle: Option<usize>, exe: &Path) -> String {
    let mut s = String::from("#!/bin/bash\n");
    s += "# Written by sphrepro (--executor slurm): one array task per case. Task i runs the case\n";
    s += "# on line i+1 of dirs.txt and entry i of manifest.json, in this folder.\n";
    let mut directive = |line: String| {
        s += "#SBATCH ";
        s += &line;
        s.push('\n');
    };
    directive(format!("--job-name={name}"));
    directive(format!(
        "--array=0-{}{}",
        n.saturating_sub(1),
        throttle.map(|t| format!("%{t}")).unwrap_or_default()
    ));
    // Slurm's own notes (a time limit, a requeue) and anything the task prints before
    // its case's log is open.
    directive(format!("--output={}", dir.join("slurm-%A_%a.out").display()));
    directive("--open-mode=append".into());
    // A task told its time limit is near checkpoints and requeues itself.
    directive("--requeue".into());
    directive(format!("--signal=B:{WARNING_SIGNAL}@{}", job.signal_before));
    directive(format!("--cpus-per-task={}", job.cpus_per_task));
    for (flag, value) in
        [("partition", &job.partition), ("account", &job.account), ("time", &job.time), ("mem", &job.mem)]
    {
        if let Some(v) = value {
            directive(format!("--{flag}={v}"));
        }
    }
    for line in &job.sbatch {
        directive(line.clone());
    }
    // -e: a failing setup line ends the task (not -u: module systems read unset variables).
    s += "set -e\n";
    s += &format!("SUBMISSION={}\n", quote(&dir.display().to_string()));
    s += "SPHREPRO_CASE_DIR=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" \"$SUBMISSION/dirs.txt\")\n";
    s += "export SPHREPRO_CASE_DIR\n";
    s += "mkdir -p \"$SPHREPRO_CASE_DIR\"\n";
    s += "# From here on, everything the task prints goes to its case's log, beside its results.\n";
    s += "exec >>\"$SPHREPRO_CASE_DIR/run.log\" 2>&1\n";
    s += "echo \"--- slurm task ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID} on $(hostname), \
          $(date -u +%Y-%m-%dT%H:%M:%SZ), restart ${SLURM_RESTART_COUNT:-0}\"\n";
    if !job.setup.is_empty() {
        s += "trap 'echo \"error: setup command failed (exit $?): $BASH_COMMAND\"' ERR\n";
        for line in &job.setup {
            s += line;
            s.push('\n');
        }
        s += "trap - ERR\n";
    }
    // `exec`: the task's process is the batch shell's, so the warning signal reaches it.
    s += &format!("exec {} slurm-task \"$SUBMISSION/manifest.json\"\n", quote(&exe.display().to_string()));
    s
}

/// `s` quoted for the shell.
pub fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_asks_for_the_warning_and_runs_the_task_as_the_batch_shell() {
        let job = Job {
            partition: Some("cpu".into()),
            time: Some("01:00:00".into()),
            cpus_per_task: 4,
            sbatch: vec!["--qos=long".into()],
            setup: vec!["module load gcc".into()],
            signal_before: 120,
            ..Default::default()
        };
        let s = render(&job, "sphrepro-tg", Path::new("/o/.slurm/x"), 3, Some(2), Path::new("/bin/it's"));
        for want in [
            "#SBATCH --array=0-2%2\n",
            "#SBATCH --signal=B:USR1@120\n",
            "#SBATCH --requeue\n",
            "#SBATCH --cpus-per-task=4\n#SBATCH --partition=cpu\n#SBATCH --time=01:00:00\n#SBATCH --qos=long\n",
            "#SBATCH --output=/o/.slurm/x/slurm-%A_%a.out\n",
            "SUBMISSION='/o/.slurm/x'\n",
            "\nmodule load gcc\n",
            "exec '/bin/it'\\''s' slurm-task \"$SUBMISSION/manifest.json\"\n",
        ] {
            assert!(s.contains(want), "{want:?} not in\n{s}");
        }
        assert!(!s.contains("--account") && !s.contains("--mem"));
        // Every directive before the first command, or sbatch ignores it.
        let first_command = s.lines().position(|l| !l.starts_with('#')).unwrap();
        assert!(s.lines().skip(first_command).all(|l| !l.starts_with("#SBATCH")));
    }
}
