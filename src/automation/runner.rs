//! The task runner: decides which cases must run (missing, failed, stale or forced), runs
//! them as subprocesses of this binary (`sphrepro simulate ... --out DIR`, as automan's
//! `CommandTask`) in a job pool that splits the cores between concurrent cases and their
//! rayon threads, shows one progress bar per running case plus an overall one, keeps one
//! log per case, and collects failures instead of stopping at the first.

use super::cache::{Entry, State};
use super::lock::{Lock, Try};
use super::registry::Problem;
use crate::outln;
use crate::scenes::harness::INTERRUPTED;
use crate::scenes::progress::{duration, read_file};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::VecDeque;
use std::io::{BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How to run.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Concurrent cases (default: from the core count).
    pub jobs: Option<usize>,
    /// Re-run done cases too.
    pub force: bool,
    /// Only cases whose name matches this glob.
    pub matching: Option<String>,
    /// Print the plan, run nothing.
    pub dry_run: bool,
    /// With `dry_run`: each case's cost, measured from a short run of it with this budget of
    /// CPU seconds of timed steps ([`estimate`](super::estimate)).
    pub estimate: Option<f64>,
    /// Checkpoint interval passed to `simulate` (seconds), when it supports it.
    pub checkpoint_every: Option<f64>,
}

/// A case to run and why.
#[derive(Clone, Debug)]
pub struct Task {
    /// Problem name.
    pub problem: String,
    /// The case and its folder.
    pub entry: Entry,
    /// Why it runs.
    pub reason: String,
}

/// What a run did.
#[derive(Debug, Default)]
pub struct Report {
    /// Cases simulated to a result (completed or diverged).
    pub ran: Vec<String>,
    /// Cases skipped because they were done.
    pub skipped: usize,
    /// Cases that did not produce a result: (case, log file, reason).
    pub failures: Vec<(String, PathBuf, String)>,
    /// Whether Ctrl-C stopped the run.
    pub interrupted: bool,
}

/// What a run of some problems has to do.
#[derive(Debug, Default)]
pub struct Plan {
    /// The cases that must run, each with the reason.
    pub tasks: Vec<Task>,
    /// How many are done.
    pub done: usize,
    /// The cases whose result is damaged, each as `problem/case: what is wrong and the
    /// command that computes it again`: not run unless forced.
    pub damaged: Vec<String>,
}

/// The cases of `problems` that must run, with the reason, how many are done, and which
/// are damaged.
pub fn plan(output: &Path, problems: &[Problem], opts: &Options) -> Result<Plan, String> {
    let matcher = match &opts.matching {
        Some(g) => Some(globset::Glob::new(g).map_err(|e| format!("--match `{g}`: {e}"))?.compile_matcher()),
        None => None,
    };
    let mut plan = Plan::default();
    let mut matched = 0;
    for p in problems {
        for e in super::cache::entries(output, p) {
            if let Some(m) = &matcher {
                if !m.is_match(&e.case.name) && !m.is_match(format!("{}/{}", p.name, e.case.name)) {
                    continue;
                }
            }
            matched += 1;
            let reason = match e.state() {
                State::Done(_) if opts.force => "forced".to_string(),
                State::Done(_) => {
                    plan.done += 1;
                    continue;
                }
                State::Damaged(_) if opts.force => "forced over a damaged result".to_string(),
                State::Damaged(r) => {
                    plan.damaged.push(format!("{}/{}: {r}", p.name, e.case.name));
                    continue;
                }
                State::Failed(r) => match Lock::holder(&e.dir) {
                    Some(pid) => format!("running under runner pid {pid}: wait for it"),
                    None => format!("failed before ({r}): re-run, resuming if it can"),
                },
                State::Missing(Some(change)) => format!("stale: {change}"),
                State::Missing(None) => "missing".to_string(),
                State::Incomplete(why) => why,
            };
            plan.tasks.push(Task { problem: p.name.clone(), entry: e, reason });
        }
    }
    // A pattern that selects nothing is a typo, not a request to run nothing.
    if let (Some(g), 0) = (&opts.matching, matched) {
        return Err(format!("--match `{g}`: no case of the selected problems matches it"));
    }
    Ok(plan)
}

/// Concurrent cases and rayon threads per case for `tasks` cases within a budget of
/// `threads` (the `--threads` of the command, else every core): jobs x threads <= budget.
pub fn split_cores(jobs: Option<usize>, tasks: usize, threads: usize) -> (usize, usize) {
    let jobs = jobs.unwrap_or_else(|| threads.min(tasks)).max(1);
    (jobs, (threads / jobs).max(1))
}

/// Prints a line above the progress bars.
fn say(mp: &MultiProgress, line: String) {
    mp.suspend(|| outln!("{line}"));
}

/// Runs `tasks` in a job pool. Failures are collected, not fatal; Ctrl-C stops starting
/// new cases and lets the running ones write their `failed` summary.
pub fn execute(tasks: Vec<Task>, opts: &Options) -> Result<Report, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find own executable: {e}"))?;
    let (jobs, threads) = split_cores(opts.jobs, tasks.len(), rayon::current_num_threads());
    let checkpoint = opts.checkpoint_every;
    let mp = MultiProgress::with_draw_target(if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    });
    let total = mp.add(ProgressBar::new(tasks.len() as u64));
    total.set_style(
        ProgressStyle::with_template("{prefix:>12} [{elapsed_precise}] {bar:30} {pos}/{len} cases")
            .expect("template"),
    );
    total.set_prefix("all");
    if !tasks.is_empty() {
        say(&mp, format!("running {} case(s): {jobs} at a time, {threads} thread(s) each", tasks.len()));
    }
    let queue = Arc::new(Mutex::new(VecDeque::from(tasks)));
    let report = Arc::new(Mutex::new(Report::default()));
    std::thread::scope(|s| {
        for _ in 0..jobs {
            let (queue, report, mp, total, exe) = (&queue, &report, &mp, &total, &exe);
            s.spawn(move || loop {
                if INTERRUPTED.load(Ordering::SeqCst) {
                    report.lock().unwrap().interrupted = true;
                    break;
                }
                let Some(task) = queue.lock().unwrap().pop_front() else {
                    break;
                };
                let name = format!("{}/{}", task.problem, task.entry.case.name);
                let outcome = run_one(exe, &task, threads, checkpoint, opts.force, mp);
                let mut r = report.lock().unwrap();
                match outcome {
                    Outcome::Done(secs, how) => {
                        say(mp, format!("done    {name} ({how}, {secs:.1} s)"));
                        r.ran.push(name);
                    }
                    Outcome::Skipped(why) => {
                        say(mp, format!("skip    {name} ({why})"));
                        r.skipped += 1;
                    }
                    Outcome::Failed(why) => {
                        let log = task.entry.dir.join("run.log");
                        say(mp, format!("FAILED  {name}: {why} (log: {})", log.display()));
                        r.failures.push((name, log, why));
                    }
                }
                total.inc(1);
            });
        }
    });
    total.finish_and_clear();
    let _ = mp.clear();
    let mut r = std::mem::take(&mut *report.lock().unwrap());
    r.interrupted |= INTERRUPTED.load(Ordering::SeqCst);
    if r.interrupted {
        for t in queue.lock().unwrap().iter() {
            r.failures.push((
                format!("{}/{}", t.problem, t.entry.case.name),
                t.entry.dir.join("run.log"),
                "not started: interrupted".into(),
            ));
        }
    }
    Ok(r)
}

enum Outcome {
    Done(f64, String),
    Skipped(String),
    Failed(String),
}

fn run_one(
    exe: &Path,
    task: &Task,
    threads: usize,
    checkpoint: Option<f64>,
    force: bool,
    mp: &MultiProgress,
) -> Outcome {
    let e = &task.entry;
    let name = format!("{}/{}", task.problem, e.case.name);
    // One runner per case: wait while another holds it.
    let mut waited = false;
    let lock = loop {
        match Lock::try_take(&e.dir) {
            Ok(Try::Taken(l)) => break l,
            Ok(Try::Held(pid)) => {
                if !waited {
                    say(
                        mp,
                        format!("wait    {name} (held by runner pid {pid} or the simulation it started)"),
                    );
                    waited = true;
                }
                if INTERRUPTED.load(Ordering::SeqCst) {
                    return Outcome::Failed("interrupted while waiting for its lock".into());
                }
                std::thread::sleep(Duration::from_millis(300));
            }
            Err(err) => return Outcome::Failed(err),
        }
    };
    // Another runner may have finished it while we waited.
    if (waited || !force) && e.is_done() {
        return Outcome::Skipped("done by another runner".into());
    }
    // Said before the folder is made: a runner that dies writing it (its stdout a closed
    // pipe) leaves no folder that looks like a crashed case.
    say(mp, format!("run     {name} ({})", task.reason));
    if let Err(err) = e.write_record() {
        return Outcome::Failed(err);
    }
    let log_path = e.dir.join("run.log");
    let mut log = match std::fs::OpenOptions::new().create(true).append(true).open(&log_path) {
        Ok(f) => f,
        Err(err) => return Outcome::Failed(format!("{}: {err}", log_path.display())),
    };
    let started = chrono::Utc::now().to_rfc3339_opts(chrono::SecondsFormat::Secs, true);
    // The log of a case run more than once (interrupted, resumed) tells its attempts apart.
    let mut log_error = writeln!(log, "== {started} run ({})", task.reason).err();
    let progress = e.dir.join("progress");
    let _ = std::fs::remove_file(&progress);
    let mut cmd = Command::new(exe);
    cmd.arg("--threads")
        .arg(threads.to_string())
        .arg("simulate")
        .arg(&e.case.scene)
        .arg("--out")
        .arg(&e.dir)
        .arg("--quiet")
        .arg("--progress-file")
        .arg(&progress);
    for (k, v) in &e.case.params.0 {
        cmd.arg("--set").arg(format!("{k}={v}"));
    }
    if force {
        cmd.arg("--force");
    }
    if let Some(c) = checkpoint {
        cmd.arg("--checkpoint-every").arg(c.to_string());
    }
    let stdout = match log.try_clone() {
        Ok(l) => l,
        Err(err) => return Outcome::Failed(format!("{}: {err}", log_path.display())),
    };
    // The case's messages come through this runner on their way to the log, so that one it
    // cannot write there (a full disk) still reaches the report.
    cmd.stdout(Stdio::from(stdout)).stderr(Stdio::piped());
    #[cfg(unix)]
    lock.hand_down(&mut cmd);
    let t0 = Instant::now();
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(err) => return Outcome::Failed(format!("cannot start {}: {err}", exe.display())),
    };
    let stderr = child.stderr.take().expect("piped");
    let copier = std::thread::spawn({
        let mut log = log.try_clone();
        move || {
            // (last line, first error writing the log)
            let (mut last, mut error) = (String::new(), None);
            for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
                let written = match log.as_mut() {
                    Ok(l) => writeln!(l, "{line}"),
                    Err(e) => Err(std::io::Error::new(e.kind(), e.to_string())),
                };
                if let Err(e) = written {
                    error.get_or_insert(e);
                }
                if !line.trim().is_empty() {
                    last = line;
                }
            }
            (last, error)
        }
    });
    let bar = mp.add(ProgressBar::new(1000));
    bar.set_style(
        ProgressStyle::with_template("{prefix:>12} [{elapsed_precise}] {bar:30} {msg}").expect("template"),
    );
    bar.set_prefix(short(&e.case.name, 12));
    let mut signalled = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Ok(s),
            Ok(None) => {}
            Err(err) => break Err(err),
        }
        if INTERRUPTED.load(Ordering::SeqCst) && !signalled {
            // Make sure the child stops with a checkpoint. Not SIGINT: the terminal may
            // have sent it one already, and a second ends a run without its checkpoint;
            // SIGUSR1 stops `simulate` with a checkpoint however often it comes.
            #[cfg(unix)]
            // SAFETY: kill has no memory-safety preconditions; the pid is our live child's.
            unsafe {
                libc::kill(child.id() as libc::pid_t, libc::SIGUSR1);
            }
            #[cfg(not(unix))]
            let _ = child.kill();
            signalled = true;
        }
        if let Some((t, tf, left)) = std::fs::read_to_string(&progress).ok().as_deref().and_then(read_file) {
            let left = left.map_or("?".into(), duration);
            bar.set_position((t / tf * 1000.0) as u64);
            bar.set_message(format!("{}  t = {t:.3}/{tf}  left {left}", e.case.name));
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    bar.finish_and_clear();
    mp.remove(&bar);
    let _ = std::fs::remove_file(&progress);
    let secs = t0.elapsed().as_secs_f64();
    let (last, copy_error) = copier.join().unwrap_or_default();
    log_error = log_error.or(copy_error);
    let code = match status {
        Ok(s) => s,
        Err(err) => return Outcome::Failed(format!("waiting for the case: {err}")),
    };
    let outcome = match e.state() {
        State::Done(s) => Outcome::Done(
            secs,
            serde_json::to_value(s).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default(),
        ),
        // `simulate` exits 2 on bad input, having written its one-line error and nothing else.
        State::Failed(_) | State::Missing(_) | State::Incomplete(_) if code.code() == Some(2) => {
            Outcome::Failed(format!("bad input: {}", last.strip_prefix("error: ").unwrap_or(&last)))
        }
        // It said why it failed, but could not write a summary (a full disk, say).
        State::Failed(_) | State::Missing(_) | State::Damaged(_) | State::Incomplete(_)
            if code.code() == Some(1) && last.starts_with("failed: ") =>
        {
            Outcome::Failed(format!("{} ({code})", &last["failed: ".len()..]))
        }
        State::Failed(r) => Outcome::Failed(format!("{r} ({code})")),
        State::Damaged(r) => Outcome::Failed(format!("{r} ({code})")),
        State::Missing(_) | State::Incomplete(_) => Outcome::Failed(format!("no result ({code})")),
    };
    // The log ends with how this attempt ended (a resumed case's with its completion).
    let end = match &outcome {
        Outcome::Done(secs, how) => format!("== {how} ({secs:.1} s)"),
        Outcome::Failed(why) => format!("== failed: {why}"),
        Outcome::Skipped(why) => format!("== skipped: {why}"),
    };
    if let Err(err) = writeln!(log, "{end}").and_then(|()| log.flush()) {
        log_error.get_or_insert(err);
    }
    match (outcome, log_error) {
        (Outcome::Failed(why), Some(err)) => {
            Outcome::Failed(format!("{why}; its log could not be written: {}: {err}", log_path.display()))
        }
        (outcome, _) => outcome,
    }
}

fn short(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        let tail: String = s.chars().rev().take(n - 1).collect::<Vec<_>>().into_iter().rev().collect();
        format!("…{tail}")
    }
}

#[cfg(test)]
mod tests {
    use super::split_cores;

    #[test]
    fn cases_share_the_thread_budget() {
        assert_eq!(split_cores(None, 10, 2), (2, 1), "one thread a case, two at a time");
        assert_eq!(split_cores(None, 1, 2), (1, 2), "a lone case takes both");
        assert_eq!(split_cores(Some(1), 5, 1), (1, 1), "--threads 1 --jobs 1");
        assert_eq!(split_cores(Some(4), 5, 2), (4, 1), "more jobs than threads: one each");
    }
}
