//! Regression baselines: the quick preset's results of every problem, committed as metrics
//! alone (`baselines/<problem>.json`, beside the problems folder, apart from the literature's
//! reference data and from the paper preset's results), against which `check --baseline`
//! compares a fresh run metric by metric. A paper's tolerance says "still within 5 % of the
//! paper"; a baseline says "this change moved the beam's deflection by 12 %": the two answer
//! different questions, and CI needs both.
//!
//! The arithmetic is deterministic on any number of threads, so by default a metric must not
//! move at all (bit for bit); a problem that cannot promise that states a relative tolerance
//! and its reason (`[baseline]` in its file, [`BaselineRule`]). [`bless`] is the only writer
//! of a baseline: after a deliberate change, it rewrites a problem's and prints what moved, so
//! that the commit that changes results carries its own evidence.

use super::cache::{self, State};
use super::registry::{BaselineRule, Problem};
use crate::solver::output::summary::Status;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The preset whose results are the baselines.
pub const PRESET: &str = "quick";

/// One problem's baseline: its cases' outcomes, by case name.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    /// The problem.
    pub problem: String,
    /// The preset (always [`PRESET`]).
    pub preset: String,
    /// Each case's outcome.
    pub cases: BTreeMap<String, Outcome>,
}

/// A case's outcome as a baseline keeps it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// The key of its inputs (scene, parameters, solver), as in its folder's name.
    pub key: String,
    /// Completed or diverged.
    pub status: Status,
    /// The simulated time it reached.
    pub final_time: f64,
    /// Its metrics.
    pub metrics: BTreeMap<String, f64>,
}

/// One difference between a baseline and a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    /// The case.
    pub case: String,
    /// The metric (or `status`, `final_time`, `inputs`, `case`).
    pub what: String,
    /// The baseline's value, in words.
    pub old: String,
    /// The run's.
    pub new: String,
    /// The relative change, for numbers.
    pub rel: Option<f64>,
}

/// The baselines' folder beside the problems folder `problems`.
pub fn dir_of(problems: &Path) -> PathBuf {
    problems.parent().map_or_else(|| PathBuf::from("baselines"), |p| p.join("baselines"))
}

/// The baseline file of `problem`.
pub fn path(problem: &Problem) -> PathBuf {
    dir_of(problem.path.parent().unwrap_or(Path::new("problems"))).join(format!("{}.json", problem.name))
}

/// The committed baseline of `problem`, if there is one.
pub fn read(problem: &Problem) -> Result<Option<Baseline>, String> {
    let p = path(problem);
    match std::fs::read_to_string(&p) {
        Ok(s) => serde_json::from_str(&s).map(Some).map_err(|e| format!("{}: {e}", p.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("{}: {e}", p.display())),
    }
}

/// The outcomes of the cases of `problem` (loaded for [`PRESET`]) under `output` (over the
/// committed results), and the cases without a finished result, each in words.
pub fn current(output: &Path, problem: &Problem) -> (Baseline, Vec<String>) {
    let mut base = Baseline { problem: problem.name.clone(), preset: PRESET.into(), cases: BTreeMap::new() };
    let mut missing = Vec::new();
    for e in cache::entries(output, problem) {
        match (e.state(), e.summary()) {
            (State::Done(_), Some(s)) => {
                let outcome = Outcome {
                    key: e.record.key.clone(),
                    status: s.status,
                    final_time: s.final_time,
                    metrics: s.metrics,
                };
                base.cases.insert(e.case.name.clone(), outcome);
            }
            (state, _) => missing.push(format!("{}: {}", e.case.name, super::check::state_word(&state))),
        }
    }
    (base, missing)
}

/// Whether `new` is within the relative tolerance `tol` of `old` (exactly equal for 0; two
/// NaNs are equal: the same result).
fn same(old: f64, new: f64, tol: f64) -> bool {
    if old.to_bits() == new.to_bits() || (old.is_nan() && new.is_nan()) {
        return true;
    }
    tol > 0.0 && (new - old).abs() <= tol * old.abs().max(new.abs())
}

/// The relative change from `old` to `new`.
fn relative(old: f64, new: f64) -> f64 {
    (new - old) / old.abs().max(f64::MIN_POSITIVE)
}

/// A number for the tables: every digit that round-trips, so that a change in the last bit
/// shows.
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// What differs between `old` and `new` beyond the tolerances of `rule`, case by case, metric
/// by metric.
pub fn compare(old: &Baseline, new: &Baseline, rule: &BaselineRule) -> Vec<Change> {
    let mut out = Vec::new();
    let change = |case: &str, what: &str, old: String, new: String, rel| Change {
        case: case.to_string(),
        what: what.to_string(),
        old,
        new,
        rel,
    };
    for (name, o) in &old.cases {
        let Some(n) = new.cases.get(name) else {
            out.push(change(name, "case", "in the baseline".into(), "not in the problem".into(), None));
            continue;
        };
        if o.key != n.key {
            out.push(change(
                name,
                "inputs",
                o.key[..10.min(o.key.len())].into(),
                n.key[..10.min(n.key.len())].into(),
                None,
            ));
        }
        if o.status != n.status {
            out.push(change(name, "status", format!("{:?}", o.status), format!("{:?}", n.status), None));
        }
        if !same(o.final_time, n.final_time, rule.tolerance) {
            let rel = Some(relative(o.final_time, n.final_time));
            out.push(change(name, "final_time", num(o.final_time), num(n.final_time), rel));
        }
        let metrics: std::collections::BTreeSet<&String> = o.metrics.keys().chain(n.metrics.keys()).collect();
        for m in metrics {
            match (o.metrics.get(m), n.metrics.get(m)) {
                (Some(&a), Some(&b)) if !same(a, b, rule.of(m)) => {
                    out.push(change(name, m, num(a), num(b), Some(relative(a, b))))
                }
                (Some(&a), None) => out.push(change(name, m, num(a), "absent".into(), None)),
                (None, Some(&b)) => out.push(change(name, m, "absent".into(), num(b), None)),
                _ => {}
            }
        }
    }
    for name in new.cases.keys().filter(|n| !old.cases.contains_key(*n)) {
        out.push(change(name, "case", "not in the baseline".into(), "new".into(), None));
    }
    out
}

/// The changes as a Markdown table: case, metric, old, new and relative change.
pub fn table(problem: &str, changes: &[Change]) -> String {
    let mut s =
        String::from("| problem/case | metric | baseline | now | relative change |\n|---|---|---|---|---|\n");
    for c in changes {
        let rel = c.rel.map_or_else(|| "-".into(), |r| format!("{r:+.3e}"));
        s += &format!("| {problem}/{} | {} | {} | {} | {rel} |\n", c.case, c.what, c.old, c.new);
    }
    s
}

/// Rewrites the baseline of `problem` (loaded for [`PRESET`]) from the results under
/// `output`: every case must have a finished result. Returns the changes from the baseline it
/// replaced (every case, for a first baseline). The only writer of a baseline.
pub fn bless(output: &Path, problem: &Problem) -> Result<Vec<Change>, String> {
    if problem.preset != PRESET {
        return Err(format!("baselines are of the `{PRESET}` preset, not `{}`", problem.preset));
    }
    let (now, missing) = current(output, problem);
    if !missing.is_empty() {
        return Err(format!(
            "{}: no finished result for {} case(s), so no baseline was written (`sphrepro run {}` computes them): {}",
            problem.name,
            missing.len(),
            problem.name,
            missing.join("; ")
        ));
    }
    let old = read(problem)?.unwrap_or_default();
    let changes = compare(&old, &now, &BaselineRule::default());
    let p = path(problem);
    if let Some(d) = p.parent() {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let json = serde_json::to_string_pretty(&now).expect("a baseline serialises") + "\n";
    crate::solver::output::write_atomic(&p, json.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
    Ok(changes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(m: f64) -> Outcome {
        Outcome {
            key: "0123456789abcdef".into(),
            status: Status::Completed,
            final_time: 1.0,
            metrics: BTreeMap::from([("err".to_string(), m), ("nan".to_string(), f64::NAN)]),
        }
    }

    fn base(cases: &[(&str, f64)]) -> Baseline {
        Baseline {
            problem: "p".into(),
            preset: PRESET.into(),
            cases: cases.iter().map(|(n, m)| (n.to_string(), outcome(*m))).collect(),
        }
    }

    /// Exact by default: the last bit of a metric is a change, NaN equals NaN; a tolerance
    /// lets a metric move by that relative amount and no more; added and removed cases, a
    /// changed key and a changed status are changes.
    #[test]
    fn a_baseline_compares_bit_for_bit_unless_a_tolerance_is_given() {
        let old = base(&[("a", 0.1), ("b", 2.0)]);
        assert!(compare(&old, &old, &BaselineRule::default()).is_empty());
        let nudged = base(&[("a", f64::from_bits(0.1f64.to_bits() + 1)), ("b", 2.0)]);
        let c = compare(&old, &nudged, &BaselineRule::default());
        assert_eq!(c.len(), 1, "{c:?}");
        assert_eq!((c[0].case.as_str(), c[0].what.as_str()), ("a", "err"));
        assert!(c[0].old != c[0].new, "the table shows the last digit: {c:?}");
        let loose = BaselineRule { tolerance: 1e-12, ..Default::default() };
        assert!(compare(&old, &nudged, &loose).is_empty());
        let moved = base(&[("a", 0.1 * (1.0 + 1e-9)), ("b", 2.0)]);
        assert_eq!(compare(&old, &moved, &loose).len(), 1);
        let per_metric =
            BaselineRule { tolerances: BTreeMap::from([("err".into(), 1e-8)]), ..Default::default() };
        assert!(compare(&old, &moved, &per_metric).is_empty());
        let mut other = base(&[("b", 2.0), ("c", 1.0)]);
        other.cases.get_mut("b").unwrap().status = Status::Diverged;
        other.cases.get_mut("b").unwrap().key = "fedcba9876543210".into();
        let c = compare(&old, &other, &BaselineRule::default());
        let what: Vec<(&str, &str)> = c.iter().map(|c| (c.case.as_str(), c.what.as_str())).collect();
        assert_eq!(what, [("a", "case"), ("b", "inputs"), ("b", "status"), ("c", "case")]);
    }
}
