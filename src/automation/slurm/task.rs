//! `sphrepro slurm-task MANIFEST`: what one array task runs, as the batch shell's own
//! process. It takes the case's lock (so that a local runner and the array never run a
//! case twice), skips a case another runner finished, writes `case.json`, and runs
//! `sphrepro simulate` for the case into its folder, handing the lock down as the local
//! runner does.
//!
//! Slurm's warning before the time limit (`--signal=B:USR1@N`) reaches this process; it
//! passes it on to the simulation, which stops at the next step with a checkpoint, and then
//! puts the task back in the queue (`scontrol requeue`): the task starts again, with the
//! same ids, and the simulation resumes from its checkpoint, bit for bit.

use super::client;
use super::script::Manifest;
use crate::automation::lock::{Lock, Try};
use crate::scenes::harness::INTERRUPTED;
use crate::solver::output::summary::{Status, Summary};
use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Exit status of a task stopped before its case finished, its checkpoint kept (not
/// requeued, or requeued and not yet stopped by Slurm): the case resumes on its next run.
pub const EXIT_INTERRUPTED: u8 = 75;

/// Set when Slurm's warning before the time limit arrives.
static TIME_UP: AtomicBool = AtomicBool::new(false);

/// Runs task `index` (default: `SLURM_ARRAY_TASK_ID`) of the manifest at `path`; returns
/// the exit status: 0 when the case is done (completed or diverged, by this task or
/// another runner), [`EXIT_INTERRUPTED`], or `simulate`'s own (1 failed, 2 bad input).
pub fn run(path: &Path, index: Option<usize>) -> u8 {
    install_warning_handler();
    let manifest = match Manifest::read(path) {
        Ok(m) => m,
        Err(e) => {
            crate::outln!("error: {e}");
            return 2;
        }
    };
    let env = |k: &str| std::env::var(k).ok();
    let Some(index) = index.or_else(|| env("SLURM_ARRAY_TASK_ID")?.parse().ok()) else {
        crate::outln!("error: no task index: SLURM_ARRAY_TASK_ID is not set and --index not given");
        return 2;
    };
    let Some(case) = manifest.cases.get(index) else {
        crate::outln!("error: {}: no case {index} (it lists {})", path.display(), manifest.cases.len());
        return 2;
    };
    let restarts: u32 = env("SLURM_RESTART_COUNT").and_then(|r| r.parse().ok()).unwrap_or(0);
    let task = match (env("SLURM_ARRAY_JOB_ID"), env("SLURM_ARRAY_TASK_ID")) {
        (Some(j), Some(t)) => format!("{j}_{t}"),
        _ => env("SLURM_JOB_ID").unwrap_or_default(),
    };
    crate::outln!("case {}/{} ({})", case.problem, case.case, case.scene);

    // One runner per case, local or Slurm: wait while another holds it.
    let mut waited = false;
    let lock = loop {
        match Lock::try_take(&case.dir) {
            Ok(Try::Taken(l)) => break l,
            Ok(Try::Held(pid)) => {
                if !waited {
                    crate::outln!(
                        "waiting: the case is held by process {pid} (another runner, or its simulation)"
                    );
                    waited = true;
                }
                if TIME_UP.load(Ordering::SeqCst) || INTERRUPTED.load(Ordering::SeqCst) {
                    return stopped(&task, restarts, manifest.max_requeues, None);
                }
                std::thread::sleep(Duration::from_millis(500));
            }
            Err(e) => {
                crate::outln!("error: {e}");
                return 1;
            }
        }
    };
    // A requeued task does not force its case again: the first run of it did.
    let force = case.force && restarts == 0;
    if waited || !force {
        if let Some(s) = done(&case.dir) {
            crate::outln!("done by another runner ({s}): nothing to run");
            return 0;
        }
    }
    let record = serde_json::to_string_pretty(&case.record).expect("record serialises");
    if let Err(e) = crate::solver::output::write_atomic(&case.dir.join("case.json"), record.as_bytes()) {
        crate::outln!("error: {}: {e}", case.dir.join("case.json").display());
        return 1;
    }

    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            crate::outln!("error: cannot find own executable: {e}");
            return 1;
        }
    };
    let threads = env("SLURM_CPUS_PER_TASK").and_then(|c| c.parse().ok()).unwrap_or(manifest.threads).max(1);
    let progress = case.dir.join("progress");
    let _ = std::fs::remove_file(&progress);
    let mut cmd = Command::new(exe);
    cmd.arg("--threads")
        .arg(threads.to_string())
        .arg("simulate")
        .arg(&case.scene)
        .arg("--out")
        .arg(&case.dir)
        // Not quiet: the plan, a resume and the metrics go to the case's log.
        .arg("--progress-file")
        .arg(&progress);
    for s in &case.sets {
        cmd.arg("--set").arg(s);
    }
    if force {
        cmd.arg("--force");
    }
    if let Some(c) = manifest.checkpoint_every {
        cmd.arg("--checkpoint-every").arg(c.to_string());
    }
    // The simulation holds the case's lock this task took, as under the local runner.
    #[cfg(unix)]
    lock.hand_down(&mut cmd);
    crate::outln!("simulating {}/{} with {threads} thread(s)", case.problem, case.case);
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            crate::outln!("error: cannot start the simulation: {e}");
            return 1;
        }
    };
    let mut passed_on = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Some(s),
            Ok(None) => {}
            Err(e) => {
                crate::outln!("error: waiting for the simulation: {e}");
                break None;
            }
        }
        if !passed_on && (TIME_UP.load(Ordering::SeqCst) || INTERRUPTED.load(Ordering::SeqCst)) {
            // SIGUSR1 stops `simulate` with a checkpoint, however often it comes.
            #[cfg(unix)]
            // SAFETY: kill with a pid of our own child, which try_wait has not reaped.
            unsafe {
                libc::kill(child.id() as libc::pid_t, libc::SIGUSR1);
            }
            passed_on = true;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let _ = std::fs::remove_file(&progress);
    if let Some(s) = done(&case.dir) {
        crate::outln!("done: {s}");
        return 0;
    }
    if TIME_UP.load(Ordering::SeqCst) || INTERRUPTED.load(Ordering::SeqCst) {
        return stopped(&task, restarts, manifest.max_requeues, Some(lock));
    }
    let code = status.and_then(|s| s.code()).unwrap_or(1);
    crate::outln!("failed: the simulation exited with {code}");
    if code == 2 {
        2
    } else {
        1
    }
}

/// A task stopped before its case finished. Told its time limit is near, it puts itself
/// back in the queue (at most `max` times), to resume from the checkpoint.
fn stopped(task: &str, restarts: u32, max: u32, lock: Option<Lock>) -> u8 {
    // The requeued task must find the case free.
    drop(lock);
    if !TIME_UP.load(Ordering::SeqCst) {
        crate::outln!("stopped: interrupted; the checkpoint is kept, the next run of the case resumes");
        return EXIT_INTERRUPTED;
    }
    if restarts >= max {
        crate::outln!(
            "error: the time limit came again, and the task was requeued {restarts} time(s) already \
             (max_requeues = {max}); the checkpoint is kept: `--retry-failed` resumes it"
        );
        return 1;
    }
    match client::requeue(task) {
        Ok(()) => {
            crate::outln!("requeued: the time limit is near; the case resumes from its checkpoint when Slurm runs it again");
            // Slurm stops this task now; the status below is for a Slurm that does not.
            std::thread::sleep(Duration::from_secs(120));
            EXIT_INTERRUPTED
        }
        Err(e) => {
            crate::outln!("error: cannot requeue: {e}; the checkpoint is kept: `--retry-failed` resumes it");
            EXIT_INTERRUPTED
        }
    }
}

/// The status of the result in `dir`, if it has one (completed or diverged).
fn done(dir: &Path) -> Option<&'static str> {
    match Summary::read(dir).ok()?.status {
        Status::Completed => Some("completed"),
        Status::Diverged => Some("diverged"),
        Status::Failed => None,
    }
}

/// SIGUSR1, Slurm's warning, sets [`TIME_UP`] (it replaces the handler `main` installs).
fn install_warning_handler() {
    #[cfg(unix)]
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        extern "C" fn on_warning(_: libc::c_int) {
            TIME_UP.store(true, Ordering::SeqCst);
        }
        libc::signal(libc::SIGUSR1, on_warning as extern "C" fn(libc::c_int) as libc::sighandler_t);
    }
}
