//! What the cases of a run would cost, before they run: `run --dry-run` and
//! `reproduce --dry-run` print, per case and in total, the CPU-hours and peak memory
//! predicted from a short run of the case itself ([`crate::bench::Estimate`]: built, a few
//! steps untimed, then [`BUDGET`] CPU seconds of timed steps, in a child process on one
//! thread, so that its memory is its own).
//!
//! The estimates are kept by case folder (its name carries the case's key, so a changed
//! case is estimated again) in `OUTPUT/<problem>/estimates.json`, so that a second dry run
//! is instant; the paper preset's export copies those of its cases without a result into
//! the committed results (`results/<problem>/estimates.json`), from which the paper's
//! manuscript states what its missing results would cost.

use super::cache::{self, Entry};
use super::registry::Problem;
use super::runner::Task;
use crate::bench::Estimate;
use crate::scenes::harness::INTERRUPTED;
use crate::solver::output::write_atomic;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The file of a problem's estimates, in its output folder and its committed results.
pub const FILE: &str = "estimates.json";

/// CPU seconds of timed steps per estimate: enough for a few hundred steps of a case of a
/// few thousand particles and a few steps of the largest.
pub const BUDGET: f64 = 3.0;

/// An estimate with the CPU it was measured on.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Measured {
    /// The prediction.
    #[serde(flatten)]
    pub estimate: Estimate,
    /// The CPU's brand string.
    pub cpu: String,
}

/// A problem's estimates by case folder.
type Store = BTreeMap<String, Measured>;

fn read_store(path: &Path) -> Store {
    std::fs::read(path).ok().and_then(|b| serde_json::from_slice(&b).ok()).unwrap_or_default()
}

fn write_store(path: &Path, store: &Store) -> Result<(), String> {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let text = serde_json::to_string_pretty(store).expect("serialises") + "\n";
    if std::fs::read(path).is_ok_and(|b| b == text.as_bytes()) {
        return Ok(());
    }
    write_atomic(path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
}

/// The stored estimate of `entry`: its output folder's store (beside the case's folder),
/// else the committed one.
pub fn stored_for(entry: &Entry) -> Option<Measured> {
    let folder = entry.record.folder();
    let mut places: Vec<PathBuf> = entry.dir.parent().map(|d| d.join(FILE)).into_iter().collect();
    places.extend(entry.committed.as_deref().and_then(Path::parent).map(|d| d.join(FILE)));
    places.into_iter().find_map(|p| read_store(&p).remove(&folder))
}

/// Measures `entry`'s estimate in a child process of this executable on one thread.
fn measure(exe: &Path, entry: &Entry, budget: f64) -> Result<Estimate, String> {
    let mut cmd = std::process::Command::new(exe);
    cmd.args(["--threads", "1", "estimate-case", "--scene", &entry.case.scene, "--budget"])
        .arg(budget.to_string());
    for (k, v) in &entry.case.params.0 {
        cmd.arg("--set").arg(format!("{k}={v}"));
    }
    let o = cmd.output().map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        let last = err.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("failed");
        return Err(last.trim_start_matches("error: ").to_string());
    }
    serde_json::from_slice(&o.stdout).map_err(|e| format!("unreadable estimate: {e}"))
}

/// The estimate of every task, measured where none is stored (in `jobs` child processes at
/// once, each on one thread) and stored as soon as it is; `Err` says why a case has none.
/// Ctrl-C stops measuring: the cases not measured then have none.
pub fn estimates(tasks: &[Task], jobs: usize, budget: f64) -> Vec<Result<Measured, String>> {
    let mut out: Vec<Option<Result<Measured, String>>> =
        tasks.iter().map(|t| stored_for(&t.entry).map(Ok)).collect();
    let todo: Vec<usize> = (0..tasks.len()).filter(|&i| out[i].is_none()).collect();
    if !todo.is_empty() {
        crate::errln!(
            "estimating {} case(s) from a short run of each ({budget} CPU s of steps after building; kept in OUTPUT/<problem>/{FILE})",
            todo.len()
        );
        let exe = std::env::current_exe().map_err(|e| format!("cannot find own executable: {e}"));
        let cpu = crate::solver::output::machine::Machine::detect().cpu_brand;
        let next = AtomicUsize::new(0);
        let results = Mutex::new(Vec::new());
        let stores = Mutex::new(BTreeMap::<PathBuf, Store>::new());
        std::thread::scope(|s| {
            for _ in 0..jobs.max(1).min(todo.len()) {
                s.spawn(|| loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= todo.len() || INTERRUPTED.load(Ordering::Relaxed) {
                        break;
                    }
                    let t = &tasks[todo[k]];
                    let r = match &exe {
                        Ok(exe) => measure(exe, &t.entry, budget),
                        Err(e) => Err(e.clone()),
                    }
                    .map(|estimate| Measured { estimate, cpu: cpu.clone() });
                    if let Ok(m) = &r {
                        let path = t.entry.dir.with_file_name(FILE);
                        let mut stores = stores.lock().expect("not poisoned");
                        let store = stores.entry(path.clone()).or_insert_with(|| read_store(&path));
                        store.insert(t.entry.record.folder(), m.clone());
                        if let Err(e) = write_store(&path, store) {
                            crate::errln!("warning: cannot keep the estimate: {e}");
                        }
                    }
                    results.lock().expect("not poisoned").push((todo[k], r));
                });
            }
        });
        for (i, r) in results.into_inner().expect("not poisoned") {
            out[i] = Some(r);
        }
    }
    out.into_iter().map(|r| r.unwrap_or_else(|| Err("not measured (interrupted)".into()))).collect()
}

/// Bytes in the unit that reads best.
pub fn bytes(b: u64) -> String {
    let b = b as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).max(1.0))
    }
}

/// One case's estimate in words: `14 s of CPU, 9 MB` or `3.8 CPU-h, 350 MB`.
pub fn describe(m: &Measured) -> String {
    let e = &m.estimate;
    let cpu = if e.cpu_seconds < 7200.0 {
        format!("{} of CPU", super::study::duration(e.cpu_seconds))
    } else {
        format!("{} CPU-h", hours(e.cpu_seconds))
    };
    let whole = match (e.diverged_at, e.exact) {
        (Some(t), _) => format!(", diverged at t = {t:.4} s in the short run"),
        (None, true) => ", measured whole".to_string(),
        _ => String::new(),
    };
    format!("{cpu}, {}{whole}", bytes(e.peak_rss_bytes))
}

/// CPU seconds as hours with the digits that matter.
pub fn hours(secs: f64) -> String {
    let h = secs / 3600.0;
    if h >= 10.0 {
        format!("{h:.0}")
    } else if h >= 0.1 {
        format!("{h:.2}")
    } else {
        format!("{h:.4}")
    }
}

/// The total line of a dry run: CPU-hours of the cases estimated, the wall time on `cores`
/// cores, the largest peak memory, and how many cases have no estimate.
pub fn total(estimates: &[Result<Measured, String>], cores: usize) -> String {
    let ok: Vec<&Measured> = estimates.iter().filter_map(|r| r.as_ref().ok()).collect();
    let secs: f64 = ok.iter().map(|m| m.estimate.cpu_seconds).sum();
    let peak = ok.iter().map(|m| m.estimate.peak_rss_bytes).max().unwrap_or(0);
    let missing = estimates.len() - ok.len();
    format!(
        "estimated {} CPU-hours on one thread per case (about {} h on {cores} core(s)), the largest case {}{}",
        hours(secs),
        hours(secs / cores.max(1) as f64),
        bytes(peak),
        if missing > 0 { format!("; {missing} case(s) without an estimate") } else { String::new() }
    )
}

/// The estimates of `problem`'s cases that have no finished result in either layer, from the
/// output folder's store over the committed one: what the paper preset's export commits.
pub fn export(output: &Path, problem: &Problem) -> Result<(), String> {
    let Some(root) = cache::root(problem) else {
        return Ok(());
    };
    let path = root.join(&problem.name).join(FILE);
    let mut store = Store::new();
    for e in cache::entries(output, problem) {
        if e.is_done() {
            continue;
        }
        if let Some(m) = stored_for(&e) {
            store.insert(e.record.folder(), m);
        }
    }
    if store.is_empty() {
        if path.exists() {
            std::fs::remove_file(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        return Ok(());
    }
    write_store(&path, &store)
}

/// What the results of `problems` cover, read from `read` (the committed results for the
/// paper preset): per problem, its cases, those with a result, and those without one with
/// the CPU-hours their estimates add up to (and how many have none), then the totals. The
/// table's headers and rows.
pub fn coverage(read: &Path, problems: &[Problem]) -> (Vec<String>, Vec<Vec<String>>) {
    let headers =
        ["problem", "cases", "with a result", "without", "their estimated CPU-hours", "without an estimate"]
            .map(String::from)
            .to_vec();
    let mut rows = Vec::new();
    let (mut all, mut done, mut secs, mut unknown) = (0, 0, 0.0, 0);
    for p in problems {
        let entries = cache::entries(read, p);
        let have = entries.iter().filter(|e| e.is_done()).count();
        let estimates: Vec<Option<f64>> = entries
            .iter()
            .filter(|e| !e.is_done())
            .map(|e| stored_for(e).map(|m| m.estimate.cpu_seconds))
            .collect();
        let s: f64 = estimates.iter().flatten().sum();
        let none = estimates.iter().filter(|e| e.is_none()).count();
        rows.push(vec![
            format!("`{}`", p.name),
            entries.len().to_string(),
            have.to_string(),
            (entries.len() - have).to_string(),
            if estimates.len() > none { hours(s) } else { "-".into() },
            none.to_string(),
        ]);
        (all, done, secs, unknown) = (all + entries.len(), done + have, secs + s, unknown + none);
    }
    rows.push(vec![
        "all".into(),
        all.to_string(),
        done.to_string(),
        (all - done).to_string(),
        hours(secs),
        unknown.to_string(),
    ]);
    (headers, rows)
}
