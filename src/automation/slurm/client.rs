//! The Slurm commands sphrepro calls (`sbatch`, `squeue`, `scancel`, `scontrol`) and what
//! their output means. No accounting (`sacct`) is needed: while a job is remembered,
//! `squeue -t all` gives each task's state and exit status, and the case folders say the
//! rest.

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

/// An array task: (array job id, task index).
pub type TaskId = (u64, u32);

/// A task as `squeue` shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskState {
    /// Slurm's state: PENDING, RUNNING, COMPLETED, FAILED, TIMEOUT, ...
    pub state: String,
    /// The node it runs or ran on (empty while pending).
    pub node: String,
    /// Why it waits or ended (`None` when there is nothing to say).
    pub reason: String,
    /// Exit status of the task's script, once ended.
    pub exit: i32,
    /// The signal that ended it, if one did.
    pub signal: i32,
}

impl TaskState {
    /// Whether the task has ended (Slurm will not run it again unless told to).
    pub fn ended(&self) -> bool {
        matches!(
            self.state.as_str(),
            "COMPLETED"
                | "FAILED"
                | "CANCELLED"
                | "TIMEOUT"
                | "NODE_FAIL"
                | "OUT_OF_MEMORY"
                | "BOOT_FAIL"
                | "DEADLINE"
                | "PREEMPTED"
        )
    }

    /// Whether it runs now.
    pub fn running(&self) -> bool {
        matches!(self.state.as_str(), "RUNNING" | "COMPLETING" | "SIGNALING" | "STAGE_OUT")
    }
}

/// Runs a Slurm command; a command that is not installed is named as such.
fn run(tool: &str, args: &[&str]) -> Result<Output, String> {
    Command::new(tool).args(args).output().map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            format!(
                "`{tool}` not found: --executor slurm needs Slurm's commands on the PATH \
                 (run it on the cluster's login node)"
            )
        } else {
            format!("cannot run `{tool}`: {e}")
        }
    })
}

/// The message of a failed command: its last line, without the tool's prefixes.
fn message(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr);
    let out = String::from_utf8_lossy(&o.stdout);
    let line = err.lines().chain(out.lines()).rev().find(|l| !l.trim().is_empty()).unwrap_or("").trim();
    let mut m = line;
    for prefix in ["sbatch: error: ", "squeue: error: ", "scancel: error: ", "scontrol: error: "] {
        m = m.strip_prefix(prefix).unwrap_or(m);
    }
    for prefix in ["Batch job submission failed: ", "allocation failure: "] {
        m = m.strip_prefix(prefix).unwrap_or(m);
    }
    if m.is_empty() {
        format!("exit status {}", o.status)
    } else {
        m.to_string()
    }
}

/// Asks Slurm whether it would take `script` (`sbatch --test-only`): nothing is submitted.
pub fn test_only(script: &Path) -> Result<(), String> {
    let o = run("sbatch", &["--test-only", &script.display().to_string()])?;
    if o.status.success() {
        Ok(())
    } else {
        Err(message(&o))
    }
}

/// Submits `script`; returns the job id.
pub fn submit(script: &Path) -> Result<u64, String> {
    let o = run("sbatch", &["--parsable", &script.display().to_string()])?;
    if !o.status.success() {
        return Err(message(&o));
    }
    let out = String::from_utf8_lossy(&o.stdout);
    // `ID` or `ID;CLUSTER`.
    out.trim()
        .split(';')
        .next()
        .and_then(|id| id.trim().parse().ok())
        .ok_or_else(|| format!("sbatch printed no job id: {out:?}"))
}

/// Every array task of this user that Slurm remembers (pending, running, or ended less
/// than `MinJobAge` ago), by (array job id, task index).
pub fn queue() -> Result<HashMap<TaskId, TaskState>, String> {
    let o = run(
        "squeue",
        &[
            "--me",
            "--noheader",
            "--array",
            "--states=all",
            "--Format=ArrayJobID:|,ArrayTaskID:|,State:|,NodeList:|,Reason:|,exit_code:|",
        ],
    )?;
    if !o.status.success() {
        return Err(format!("squeue: {}", message(&o)));
    }
    Ok(parse_queue(&String::from_utf8_lossy(&o.stdout)))
}

/// Reads `squeue --Format=ArrayJobID:|,ArrayTaskID:|,State:|,NodeList:|,Reason:|,exit_code:|`.
/// Jobs that are not array tasks (`N/A`) are left out. `exit_code` is a wait status:
/// the exit status times 256, plus the signal.
pub fn parse_queue(text: &str) -> HashMap<TaskId, TaskState> {
    let mut out = HashMap::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split('|').map(str::trim).collect();
        if f.len() < 6 {
            continue;
        }
        let (Ok(job), Ok(task)) = (f[0].parse::<u64>(), f[1].parse::<u32>()) else {
            continue;
        };
        let raw: i32 = f[5].parse().unwrap_or(0);
        out.insert(
            (job, task),
            TaskState {
                state: f[2].to_string(),
                node: f[3].to_string(),
                reason: f[4].to_string(),
                exit: (raw >> 8) & 0xff,
                signal: raw & 0x7f,
            },
        );
    }
    out
}

/// Cancels jobs (every task of each).
pub fn cancel(jobs: &[u64]) -> Result<(), String> {
    let ids: Vec<String> = jobs.iter().map(u64::to_string).collect();
    let args: Vec<&str> = ids.iter().map(String::as_str).collect();
    let o = run("scancel", &args)?;
    if o.status.success() {
        Ok(())
    } else {
        Err(format!("scancel: {}", message(&o)))
    }
}

/// Puts an array task back in the queue (it is stopped if it runs); Slurm runs it again
/// once the requeue delay has passed.
pub fn requeue(task: &str) -> Result<(), String> {
    let o = run("scontrol", &["requeue", task])?;
    if o.status.success() {
        Ok(())
    } else {
        Err(format!("scontrol requeue {task}: {}", message(&o)))
    }
}

/// The settings an sbatch refusal is about, from Slurm's message (none if it does not say).
pub fn refused_settings(message: &str) -> &'static [&'static str] {
    let m = message.to_ascii_lowercase();
    if m.contains("partition") && !m.contains("account") {
        &["partition"]
    } else if m.contains("account") {
        &["account"]
    } else if m.contains("time limit") || m.contains("--time") {
        &["time"]
    } else if m.contains("memory") || m.contains("--mem") {
        &["mem"]
    } else if m.contains("node configuration") || m.contains("cpu count") {
        &["cpus_per_task", "mem"]
    } else if m.contains("qos") {
        &["sbatch"]
    } else {
        &[]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn squeue_lines_read_as_tasks_with_their_exit_status() {
        let q = parse_queue(
            "12|0|COMPLETED|node1|None|0|\n12|1|FAILED|node1|NonZeroExitCode|1792|\n\
             12|2|PENDING||BeginTime|0|\n13|N/A|RUNNING|node2|None|0|\n",
        );
        assert_eq!(q.len(), 3);
        assert_eq!((q[&(12, 1)].exit, q[&(12, 1)].signal, q[&(12, 1)].ended()), (7, 0, true));
        assert!(!q[&(12, 2)].ended() && !q[&(12, 2)].running() && q[&(12, 2)].reason == "BeginTime");
        assert_eq!(q[&(12, 0)].node, "node1");
    }

    #[test]
    fn a_refusal_names_the_setting_it_is_about() {
        for (m, key) in [
            ("Invalid partition name specified", &["partition"][..]),
            ("Invalid account or account/partition combination specified", &["account"]),
            ("Requested time limit is invalid (missing or exceeds some limit)", &["time"]),
            ("Invalid --time specification", &["time"]),
            ("Requested node configuration is not available", &["cpus_per_task", "mem"]),
            ("Invalid qos specification", &["sbatch"]),
            ("Something else", &[]),
        ] {
            assert_eq!(refused_settings(m), key, "{m}");
        }
    }
}
