//! Waiting for submitted arrays: the cases queued, running, done and failed, from `squeue`
//! and the case folders; a case whose task ended at its time limit without requeueing
//! itself is submitted again, to resume from its checkpoint; Ctrl-C asks whether to cancel
//! the jobs or leave them running.

use super::client::{self, TaskState};
use super::script::ManifestCase;
use super::settings::Settings;
use super::submit::{self, Submission};
use super::task::EXIT_INTERRUPTED;
use crate::automation::runner::Report;
use crate::scenes::harness::INTERRUPTED;
use crate::solver::output::summary::{Status, Summary};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// A task Slurm has not shown yet is taken as gone after this long.
const UNSEEN: Duration = Duration::from_secs(60);

/// One case's task, as last seen.
struct Tracked {
    /// Index into the submissions.
    sub: usize,
    /// Task index in its array.
    index: u32,
    case: ManifestCase,
    /// Last state seen (none yet).
    seen: Option<TaskState>,
    /// Running when last seen.
    running: bool,
    /// How it ended: `Some(None)` when Slurm no longer knew it.
    ended: Option<Option<TaskState>>,
    /// Submissions of this case before this one (after time limits).
    resubmits: u32,
    /// Submitted again: a later entry tracks it.
    replaced: bool,
}

impl Tracked {
    fn name(&self) -> String {
        format!("{}/{}", self.case.problem, self.case.case)
    }
}

/// Waits for the tasks of `subs`, shows their progress, submits again the cases whose task
/// ended at the time limit with a checkpoint (at most `max_requeues` times each), and
/// reports what each case came to.
pub fn wait(
    output: &Path,
    mut subs: Vec<Submission>,
    settings: &Settings,
    throttle: Option<usize>,
    checkpoint_every: Option<f64>,
) -> Report {
    let mut all: Vec<Tracked> = Vec::new();
    for (s, sub) in subs.iter().enumerate() {
        for (i, c) in sub.cases.iter().enumerate() {
            all.push(Tracked {
                sub: s,
                index: i as u32,
                case: c.clone(),
                seen: None,
                running: false,
                ended: None,
                resubmits: 0,
                replaced: false,
            });
        }
    }
    let mut submitted_at = vec![Instant::now(); subs.len()];
    let terminal = std::io::stderr().is_terminal();
    let bar = ProgressBar::with_draw_target(
        Some(all.len() as u64),
        if terminal { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() },
    );
    bar.set_style(
        ProgressStyle::with_template("{prefix:>6} [{elapsed_precise}] {bar:30} {pos}/{len} cases  {msg}")
            .expect("template"),
    );
    bar.set_prefix("slurm");
    let say = |line: String| bar.suspend(|| crate::outln!("{line}"));
    let mut last_counts = String::new();
    let mut last_warning = String::new();
    let mut interrupted = false;
    loop {
        // Sleep in short steps, to answer Ctrl-C at once.
        let until = Instant::now() + Duration::from_secs_f64(settings.poll);
        while Instant::now() < until && !INTERRUPTED.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(100));
        }
        if INTERRUPTED.load(Ordering::SeqCst) {
            interrupted = true;
            bar.suspend(|| ask_to_cancel(&subs, &all));
            break;
        }
        let q = match client::queue() {
            Ok(q) => q,
            Err(e) => {
                if e != last_warning {
                    say(format!("warning: {e}; trying again"));
                    last_warning = e;
                }
                continue;
            }
        };
        let mut again = Vec::new();
        for (n, t) in all.iter_mut().enumerate().filter(|(_, t)| t.ended.is_none()) {
            let sub = &subs[t.sub];
            let task = format!("{}_{}", sub.job_id, t.index);
            let Some(st) = q.get(&(sub.job_id, t.index)) else {
                if t.seen.is_some() || submitted_at[t.sub].elapsed() > UNSEEN {
                    t.ended = Some(None);
                    report_end(&say, t, &task);
                }
                continue;
            };
            if st.running() && !t.running {
                say(format!("run     {} (slurm {task} on {})", t.name(), st.node));
            } else if t.running && !st.running() && !st.ended() {
                say(format!(
                    "requeue {} (slurm {task}: stopped at its time limit, resumes from its checkpoint)",
                    t.name()
                ));
            }
            t.running = st.running();
            t.seen = Some(st.clone());
            if st.ended() {
                t.ended = Some(Some(st.clone()));
                if resumable(st) && done(&t.case.dir).is_none() && t.resubmits < settings.max_requeues {
                    again.push(n);
                } else {
                    report_end(&say, t, &task);
                }
            }
        }
        if !again.is_empty() {
            let cases: Vec<ManifestCase> = again.iter().map(|&n| all[n].case.clone()).collect();
            let planned = submit::plan(output, cases, settings, throttle);
            let result =
                planned.and_then(|mut new| submit::submit(&mut new, settings, checkpoint_every).map(|_| new));
            match result {
                Ok(new) => {
                    for sub in new {
                        let s = subs.len();
                        for (i, c) in sub.cases.iter().enumerate() {
                            let old = again.iter().map(|&n| &all[n]).find(|t| t.case.dir == c.dir);
                            let resubmits = old.map_or(0, |t| t.resubmits) + 1;
                            say(format!(
                                "resubmit {}/{} (slurm {}_{i}: its last task stopped at the time limit; it resumes from its checkpoint)",
                                c.problem, c.case, sub.job_id
                            ));
                            all.push(Tracked {
                                sub: s,
                                index: i as u32,
                                case: c.clone(),
                                seen: None,
                                running: false,
                                ended: None,
                                resubmits,
                                replaced: false,
                            });
                        }
                        subs.push(sub);
                        submitted_at.push(Instant::now());
                    }
                    for &n in &again {
                        all[n].replaced = true;
                    }
                }
                Err(e) => {
                    let e = match e {
                        submit::Refused::Input(e) | submit::Refused::Failed(e) => e,
                    };
                    say(format!("warning: cannot submit again: {e}"));
                    for &n in &again {
                        let task = format!("{}_{}", subs[all[n].sub].job_id, all[n].index);
                        report_end(&say, &all[n], &task);
                    }
                }
            }
        }
        let live = all.iter().filter(|t| !t.replaced);
        let (mut queued, mut running, mut finished, mut failed) = (0, 0, 0, 0);
        for t in live {
            match &t.ended {
                None if t.running => running += 1,
                None => queued += 1,
                Some(_) if done(&t.case.dir).is_some() => finished += 1,
                Some(_) => failed += 1,
            }
        }
        let counts = format!("{queued} queued, {running} running, {finished} done, {failed} failed");
        bar.set_position((finished + failed) as u64);
        bar.set_message(counts.clone());
        if !terminal && counts != last_counts {
            crate::outln!("slurm: {counts}");
        }
        last_counts = counts;
        if queued + running == 0 {
            break;
        }
    }
    bar.finish_and_clear();
    if !interrupted {
        // Every task has ended: `status` need not ask Slurm about these again.
        for sub in &subs {
            let _ = std::fs::write(sub.dir.join("ended"), b"");
        }
    }
    let mut report = Report { interrupted, ..Default::default() };
    for t in all.iter().filter(|t| !t.replaced) {
        if done(&t.case.dir).is_some() {
            report.ran.push(t.name());
        } else if t.ended.is_some() || !interrupted {
            let task = format!("{}_{}", subs[t.sub].job_id, t.index);
            report.failures.push((t.name(), log_of(&subs[t.sub], t), why(t, &task)));
        }
    }
    report
}

/// Prints how a case's task ended.
fn report_end(say: &dyn Fn(String), t: &Tracked, task: &str) {
    match done(&t.case.dir) {
        Some(status) => say(format!("done    {} ({status}, slurm {task})", t.name())),
        None => say(format!(
            "FAILED  {}: {} (log: {})",
            t.name(),
            why(t, task),
            t.case.dir.join("run.log").display()
        )),
    }
}

/// Whether a task ended stopped with a checkpoint, to be resumed: at its time limit
/// without requeueing itself (Slurm's warning came too late, or the requeue was refused),
/// preempted, or its node lost. Never a cancelled one.
fn resumable(st: &TaskState) -> bool {
    matches!(st.state.as_str(), "TIMEOUT" | "PREEMPTED" | "NODE_FAIL")
        || (st.state == "FAILED" && st.exit == i32::from(EXIT_INTERRUPTED))
}

/// The status of a case's result, if it has one.
fn done(dir: &Path) -> Option<&'static str> {
    match Summary::read(dir).ok()?.status {
        Status::Completed => Some("completed"),
        Status::Diverged => Some("diverged"),
        Status::Failed => None,
    }
}

/// Why a case has no result, in one line.
fn why(t: &Tracked, task: &str) -> String {
    let Some(Some(st)) = &t.ended else {
        return match &t.ended {
            Some(None) => format!("slurm {task}: Slurm no longer knows the task and the case has no result"),
            _ => format!("slurm {task}: not ended"),
        };
    };
    let mut s = format!("slurm {task} ended {}", st.state);
    if st.exit != 0 {
        s += &format!(", exit code {}", st.exit);
    }
    if st.signal != 0 {
        s += &format!(", signal {}", st.signal);
    }
    if st.state == "TIMEOUT" || st.exit == i32::from(EXIT_INTERRUPTED) {
        s += ": stopped with its checkpoint kept (`--retry-failed` resumes it)";
    } else if let Some(e) = last_error(&t.case.dir.join("run.log")) {
        s += &format!(": {e}");
    }
    s
}

/// The log to read for a case: its `run.log`, or Slurm's own output of the task when the
/// task never got as far as opening the log.
fn log_of(sub: &Submission, t: &Tracked) -> PathBuf {
    let log = t.case.dir.join("run.log");
    if log.exists() {
        log
    } else {
        sub.dir.join(format!("slurm-{}_{}.out", sub.job_id, t.index))
    }
}

/// The last `error: ...` line of a log, without the prefix.
fn last_error(log: &Path) -> Option<String> {
    let text = std::fs::read_to_string(log).ok()?;
    text.lines().rev().find_map(|l| l.strip_prefix("error: ")).map(str::to_string)
}

/// Asks, after Ctrl-C, whether to cancel the jobs with tasks still queued or running;
/// leaves them running unless told `y` (end of input, or a second Ctrl-C, leaves them).
fn ask_to_cancel(subs: &[Submission], all: &[Tracked]) {
    let mut jobs: Vec<u64> =
        all.iter().filter(|t| t.ended.is_none() && !t.replaced).map(|t| subs[t.sub].job_id).collect();
    jobs.sort_unstable();
    jobs.dedup();
    if jobs.is_empty() {
        return;
    }
    let ids = jobs.iter().map(u64::to_string).collect::<Vec<_>>().join(" ");
    crate::err!(
        "\ninterrupted: cancel the submitted Slurm job(s) {ids}? [y/N] (another Ctrl-C leaves them running) "
    );
    let mut answer = String::new();
    let _ = std::io::stdin().read_line(&mut answer);
    if matches!(answer.trim().to_ascii_lowercase().as_str(), "y" | "yes") {
        match client::cancel(&jobs) {
            Ok(()) => {
                // Until the tasks are gone, so that what follows sees them stopped.
                let t0 = Instant::now();
                while t0.elapsed() < Duration::from_secs(60) {
                    let Ok(q) = client::queue() else { break };
                    if !q.iter().any(|((j, _), st)| jobs.contains(j) && !st.ended()) {
                        break;
                    }
                    std::thread::sleep(Duration::from_millis(200));
                }
                crate::errln!("cancelled Slurm job(s) {ids}: their unfinished cases are not done");
            }
            Err(e) => crate::errln!("error: {e}"),
        }
    } else {
        crate::errln!(
            "left running: Slurm job(s) {ids}; `sphrepro status` shows their cases, `scancel {ids}` cancels them"
        );
    }
}
