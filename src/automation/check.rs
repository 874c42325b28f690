//! `check` and `status`: the bounds of the problem files against the cached results, and
//! the state of every case.

use super::cache::{self, State};
use super::registry::Problem;
use crate::outln;
use crate::solver::output::summary::Status;
use std::path::Path;

/// One bound checked against one case.
#[derive(Debug)]
pub struct Breach {
    /// `problem/case`.
    pub case: String,
    /// What went wrong, naming metric, value and bound.
    pub what: String,
}

/// Checks every bound of `problems` against the results under `output`. Returns the
/// number of (bound, case) pairs that hold and every breach; a missing or unfinished
/// result is a breach, and so is a diverged one, named as such with where it blew up (it
/// has no metrics at the end time to compare).
pub fn check(output: &Path, problems: &[Problem]) -> (usize, Vec<Breach>) {
    let mut ok = 0;
    let mut bad = Vec::new();
    for p in problems {
        for b in &p.bounds {
            for c in b.select.pick(&p.cases) {
                let e = cache::Entry::new(output, p, c);
                let case = format!("{}/{}", p.name, c.name);
                let at = format!("{}:{}", p.path.display(), b.line);
                let s = match (e.state(), e.summary()) {
                    (State::Done(_), Some(s)) => s,
                    (state, _) => {
                        bad.push(Breach {
                            case,
                            what: format!(
                                "{}: no result ({}) for the bound on line {at}",
                                b.metric,
                                state_word(&state)
                            ),
                        });
                        continue;
                    }
                };
                if s.status == Status::Diverged {
                    bad.push(Breach {
                        case,
                        what: format!(
                            "{}: the run diverged at t = {:.6e}, step {}: {} (bound on line {at})",
                            b.metric,
                            s.final_time,
                            s.step.map_or_else(|| "?".into(), |n| n.to_string()),
                            s.reason.unwrap_or_default()
                        ),
                    });
                    continue;
                }
                let Some(v) = s.metrics.get(&b.metric).copied() else {
                    bad.push(Breach {
                        case,
                        what: format!(
                            "{} missing: status {:?}, reason {} ({at})",
                            b.metric,
                            s.status,
                            s.reason.unwrap_or_default()
                        ),
                    });
                    continue;
                };
                let mut fail = None;
                if let Some(max) = b.max {
                    if v.is_nan() || v > max {
                        fail = Some(format!("{} = {v:.6e} > max {max:e} ({at})", b.metric));
                    }
                }
                if let Some(min) = b.min {
                    if v.is_nan() || v < min {
                        fail = Some(format!("{} = {v:.6e} < min {min:e} ({at})", b.metric));
                    }
                }
                match fail {
                    Some(what) => bad.push(Breach { case, what }),
                    None => ok += 1,
                }
            }
        }
    }
    (ok, bad)
}

/// A word for a state.
pub fn state_word(s: &State) -> String {
    match s {
        State::Done(st) => serde_json::to_value(st)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_else(|| "done".into()),
        State::Failed(r) => format!("failed: {r}"),
        State::Damaged(r) => r.clone(),
        State::Missing(Some(c)) => format!("stale: {c}"),
        State::Missing(None) => "missing".into(),
        State::Incomplete(r) => format!("incomplete: {r}"),
    }
}

/// Counts of case states.
#[derive(Debug, Default)]
pub struct StatusCounts {
    /// Completed or diverged.
    pub done: usize,
    /// Failed or killed.
    pub failed: usize,
    /// With a summary that cannot be read.
    pub damaged: usize,
    /// Never run, or run with other inputs, or committed without what a figure reads.
    pub missing: usize,
    /// Folders that belong to no current case.
    pub stale_folders: usize,
    /// Not done, and pending or running in a Slurm queue.
    pub queued: usize,
}

/// The simulated and end time a running case last wrote to its `progress` file.
fn progress(dir: &Path) -> Option<(f64, f64)> {
    let s = std::fs::read_to_string(dir.join("progress")).ok()?;
    let mut v = s.split_whitespace().map(|x| x.parse::<f64>().ok());
    Some((v.next()??, v.next()??))
}

/// Prints the state of every case of `problems` (and the stale folders) to stdout.
///
/// Folders that hold the current results of another preset of the problem are counted,
/// not listed; folders of earlier inputs (stale) are listed with `list_stale`, otherwise
/// counted.
pub fn status(output: &Path, problems: &[Problem], list_stale: bool) -> StatusCounts {
    let mut n = StatusCounts::default();
    // Cases submitted to Slurm: queued or running there (never done from there).
    let queue = super::slurm::queue::read(output);
    if let Some(w) = &queue.warning {
        crate::outln!("warning: {w}");
    }
    for p in problems {
        outln!("{} ({}, preset {}):", p.name, p.title, p.preset);
        let entries = cache::entries(output, p);
        for e in &entries {
            let st = e.state();
            let slurm = match st {
                State::Done(_) => None,
                _ => queue.cases.get(&super::slurm::queue::key(&e.dir)),
            };
            if let Some(q) = slurm {
                n.queued += 1;
                crate::outln!(
                    "  {:<10} {}  ({}{})",
                    q.word(),
                    e.case.name,
                    q.detail(),
                    progress(&e.dir).map(|(t, tf)| format!("; t = {t:.3} of {tf} s")).unwrap_or_default()
                );
                continue;
            }
            match st {
                State::Done(_) => n.done += 1,
                State::Failed(_) => n.failed += 1,
                State::Damaged(_) => n.damaged += 1,
                State::Missing(_) | State::Incomplete(_) => n.missing += 1,
            }
            let running = super::lock::Lock::holder(&e.dir).is_some();
            outln!(
                "  {:<10} {}{}",
                match st {
                    State::Done(_) => "done",
                    State::Failed(_) if running => "running",
                    State::Failed(_) => "failed",
                    State::Damaged(_) => "damaged",
                    State::Missing(Some(_)) => "stale",
                    State::Missing(None) => "missing",
                    State::Incomplete(_) => "incomplete",
                },
                e.case.name,
                match &st {
                    State::Done(_) => format!("  ({})", state_word(&st)),
                    State::Failed(_) if running => format!(
                        "  ({}log {})",
                        progress(&e.dir).map(|(t, tf)| format!("t = {t:.3} of {tf} s; ")).unwrap_or_default(),
                        e.dir.join("run.log").display()
                    ),
                    State::Failed(r) => format!("  ({r}; log {})", e.dir.join("run.log").display()),
                    State::Damaged(r) => format!("  ({r})"),
                    State::Missing(Some(c)) => format!("  (inputs changed: {c})"),
                    State::Missing(None) => String::new(),
                    State::Incomplete(r) => format!("  ({r})"),
                }
            );
        }
        // The current cases of every preset: another preset's results are not stale.
        let n_this = entries.len();
        let mut current = entries;
        let mut other_presets = 0;
        for e in p.other_presets.iter().flat_map(|(_, cases)| cases).map(|c| cache::Entry::new(output, p, c))
        {
            if e.dir.is_dir() && !current.iter().any(|c| c.dir == e.dir) {
                other_presets += 1;
            }
            current.push(e);
        }
        let live: Vec<_> = current.iter().map(|e| e.dir.clone()).collect();
        if other_presets > 0 {
            outln!("  {other_presets} folder(s) with the results of the problem's other preset(s)");
        }
        let stale = cache::stale_folders(output, &p.name, &live);
        n.stale_folders += stale.len();
        if !list_stale && !stale.is_empty() {
            outln!(
                "  {} stale folder(s): results of earlier inputs, kept, not deleted (`status --stale` lists them)",
                stale.len()
            );
        }
        for s in if list_stale { &stale[..] } else { &[] } {
            // Against the case of that name in this preset, else in the nearest other one.
            let why = cache::read_record(s)
                .map(|r| {
                    let named = |e: &&cache::Entry| e.record.name == r.name;
                    let this = current[..n_this].iter().find(named);
                    let nearest = this.or_else(|| {
                        current[n_this..].iter().filter(named).min_by_key(|e| e.record.changes(&r).len())
                    });
                    match nearest {
                        Some(e) => format!("case {} now has {}", r.name, e.record.changes_from(&r)),
                        None => format!("case {} is no longer in the problem file", r.name),
                    }
                })
                .unwrap_or_else(|| "no case.json".into());
            outln!("  {:<10} {}  ({why}; kept, not deleted)", "stale", s.display());
        }
    }
    let damaged = if n.damaged > 0 { format!(", {} damaged", n.damaged) } else { String::new() };
    let queued =
        if n.queued > 0 { format!(", {} queued or running in Slurm", n.queued) } else { String::new() };
    outln!(
        "{} done, {} failed{damaged}, {} missing, {} stale folder(s){queued}",
        n.done,
        n.failed,
        n.missing,
        n.stale_folders
    );
    n
}
