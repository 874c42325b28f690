//! Verdicts on the paper's claims: each claim of a problem file is a test on the summaries'
//! metrics at a preset ([`Test`]); its verdict is `reproduced`, `not reproduced` (with each
//! case's number against the test) or `not run` (results missing at that preset, with an
//! estimate of what they would cost). A case that ran and fails the test on its own (it
//! diverged, or breaks the bound) makes the claim `not reproduced` even while others are
//! missing: a failure at the claim's resolution is never hidden as `not run`. When the
//! claim's own preset has no results and another preset does, the verdict there is given
//! too, labelled as drawn at that resolution.

use super::words;
use super::{fmt_bound, fmt_value, param_f64};
use crate::automation::cache::Entry;
use crate::automation::registry::{Case, Claim, Problem, Select, Test};
use crate::solver::output::summary::{Status, Summary};
use std::collections::BTreeMap;
use std::path::Path;

/// What became of a claim at one preset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The test holds.
    Reproduced,
    /// The test fails (the numbers say by how much).
    NotReproduced,
    /// Results are missing at that preset.
    NotRun,
}

impl Verdict {
    /// The verdict in words.
    pub fn word(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::NotReproduced => "not reproduced",
            Verdict::NotRun => "not run",
        }
    }
}

/// A claim judged at one preset.
#[derive(Clone, Debug)]
pub struct Judgement {
    /// The verdict.
    pub verdict: Verdict,
    /// The preset whose results judged it.
    pub preset: String,
    /// The numbers (or the missing cases and their estimated cost), as a sentence.
    pub detail: String,
}

/// A claim with its verdict at its own preset and, when that is `not run`, at another.
#[derive(Clone, Debug)]
pub struct ClaimVerdict {
    /// The claim.
    pub claim: Claim,
    /// At the claim's preset.
    pub own: Judgement,
    /// At another preset with results, when the claim's own has none.
    pub other: Option<Judgement>,
}

impl ClaimVerdict {
    /// The verdict as a Markdown paragraph: the claim, the source of its tolerance, the
    /// verdict and its numbers.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "**Claim:** {} *Test, {}:* {}. *Source:* {}\n\n**Verdict: {}** {}: {}",
            end_sentence(&self.claim.claim),
            at_words(&self.own.preset),
            describe(&self.claim, &self.own.preset),
            end_sentence(&self.claim.source),
            self.own.verdict.word(),
            at_words(&self.own.preset),
            self.own.detail
        );
        if let Some(o) = &self.other {
            s += &format!(" {}: {}, {}", capitalise(&at_words(&o.preset)), o.verdict.word(), o.detail);
        }
        s
    }

    /// The verdict in a few words, for the summary table.
    pub fn short(&self) -> String {
        let mut s = match self.own.verdict {
            Verdict::NotReproduced => format!("**{}**", self.own.verdict.word()),
            v => v.word().to_string(),
        };
        if self.own.preset != "paper" {
            s += &format!(" (`{}` preset)", self.own.preset);
        }
        if let Some(o) = &self.other {
            s += &format!("; `{}` preset: {}", o.preset, o.verdict.word());
        }
        s
    }
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

fn end_sentence(s: &str) -> String {
    let t = s.trim();
    if t.ends_with(['.', '!', '?']) {
        t.to_string()
    } else {
        format!("{t}.")
    }
}

/// "at the paper's resolutions (`paper` preset)" or "at the `quick` preset, not the paper's
/// resolutions".
fn at_words(preset: &str) -> String {
    if preset == "paper" {
        "at the paper's resolutions (`paper` preset)".into()
    } else {
        format!("at the `{preset}` preset, not the paper's resolutions")
    }
}

/// The test of `claim` at `preset` in words.
fn describe(claim: &Claim, preset: &str) -> String {
    let Some(ct) = claim.at.get(preset).or_else(|| claim.at.get(&claim.preset)) else {
        return "none".into();
    };
    match &ct.test {
        Test::Bound { metric, max, min } => match (min, max) {
            (Some(lo), Some(hi)) => {
                format!("{} <= `{metric}` <= {} in every case", fmt_bound(*lo), fmt_bound(*hi))
            }
            (None, Some(hi)) => format!("`{metric}` <= {} in every case", fmt_bound(*hi)),
            (Some(lo), None) => format!("`{metric}` >= {} in every case", fmt_bound(*lo)),
            (None, None) => format!("`{metric}`"),
        },
        Test::Monotone { metric, param, decreasing } => {
            format!("`{metric}` {} strictly as `{param}` grows", if *decreasing { "falls" } else { "grows" })
        }
        Test::LowerThan { metric, lower, higher, factor } => {
            let side = |s: &Select| {
                let w: Vec<String> =
                    s.where_.iter().map(|(k, v)| words::phrase(k, v)).filter(|p| !p.is_empty()).collect();
                if w.is_empty() {
                    format!("cases {}", s.cases.join(", "))
                } else {
                    w.join(", ")
                }
            };
            let times = if *factor == 1.0 { String::new() } else { format!("{factor} x ") };
            format!(
                "`{metric}` ({}) <= {times}`{metric}` ({}) in every group of cases alike in the other parameters (each resolution on its own), a side's cases averaged within a group",
                side(lower),
                side(higher)
            )
        }
    }
}

/// One case's outcome for a metric.
enum Outcome {
    Value(f64),
    /// A run that blew up at a time, why, and the metric if the run kept it: a diverged
    /// summary keeps only running records (the worst seen so far, the time of a first
    /// event), which can only grow or stay, so a lower bound they pass before the blow-up
    /// holds whatever came after.
    Diverged(f64, String, Option<f64>),
    NoMetric,
    Missing,
}

fn outcome(entry: &Entry, metric: &str) -> Outcome {
    match entry.summary() {
        Some(s) if s.status == Status::Diverged => {
            let kept = s.metrics.get(metric).copied();
            Outcome::Diverged(s.final_time, s.reason.unwrap_or_default(), kept)
        }
        Some(s) if s.status == Status::Completed => {
            s.metrics.get(metric).copied().map(Outcome::Value).unwrap_or(Outcome::NoMetric)
        }
        _ => Outcome::Missing,
    }
}

/// How a value breaks the bound `[min, max]`: " > max", " < min", or nothing.
fn mark(max: Option<f64>, min: Option<f64>, x: f64) -> String {
    // NaN is over and under: a non-finite value passes no bound.
    match (max, min) {
        (Some(m), _) if x.is_nan() || x > m => format!(" > {}", fmt_bound(m)),
        (_, Some(m)) if x.is_nan() || x < m => format!(" < {}", fmt_bound(m)),
        _ => String::new(),
    }
}

/// Whether a case's outcome fails `test` on its own, whatever the other cases give: a run
/// that blew up (unless the running record it kept passes a lower bound, which it cannot
/// fall back from) or has not the metric fails any test; a value fails a bound it breaks.
fn fails_alone(test: &Test, v: &Outcome) -> bool {
    match (test, v) {
        (_, Outcome::Missing) => false,
        (_, Outcome::NoMetric) => true,
        (Test::Bound { max, min, .. }, Outcome::Value(x)) => !mark(*max, *min, *x).is_empty(),
        (_, Outcome::Value(_)) => false,
        (Test::Bound { max: None, min: Some(m), .. }, Outcome::Diverged(_, _, Some(x))) => *x < *m,
        (_, Outcome::Diverged(..)) => true,
    }
}

/// The key of `case`'s group: its parameters but those `apart` names (the ones a test
/// compares along), so that cases alike in all else share a key.
fn group_key(case: &Case, apart: impl Fn(&str) -> bool) -> String {
    let key: Vec<String> =
        case.params.0.iter().filter(|(k, _)| !apart(k)).map(|(k, v)| format!("{k}={v}")).collect();
    key.join(",")
}

/// The parameters that tell `cases` apart, in the order the first case lists them (its
/// resolution when they are alike).
fn distinguishing(cases: &[&Case]) -> Vec<String> {
    let Some(first) = cases.first() else { return Vec::new() };
    let keys: Vec<String> = first
        .params
        .0
        .keys()
        .filter(|k| cases.iter().any(|c| c.params.0.get(*k) != first.params.0.get(*k)))
        .cloned()
        .collect();
    if !keys.is_empty() {
        return keys;
    }
    ["nx", "dx"].iter().filter(|k| first.params.0.contains_key(**k)).map(|k| k.to_string()).take(1).collect()
}

/// Judges every claim of `p` from the results under `output` (and the committed ones).
pub fn judge_all(p: &Problem, output: &Path) -> Vec<ClaimVerdict> {
    p.claims.iter().map(|c| judge(p, c, output)).collect()
}

/// Judges `claim` at its preset and, if `not run` there, at the first other preset (this
/// run's first) whose selection has every result.
pub fn judge(p: &Problem, claim: &Claim, output: &Path) -> ClaimVerdict {
    let own = judge_at(p, claim, &claim.preset, output);
    let other = (own.verdict == Verdict::NotRun)
        .then(|| {
            p.presets()
                .into_iter()
                .map(|(name, _)| name)
                .filter(|name| *name != claim.preset && claim.at.contains_key(*name))
                .map(|name| judge_at(p, claim, name, output))
                .find(|j| j.verdict != Verdict::NotRun)
        })
        .flatten();
    ClaimVerdict { claim: claim.clone(), own, other }
}

/// Judges `claim` at `preset`.
pub fn judge_at(p: &Problem, claim: &Claim, preset: &str, output: &Path) -> Judgement {
    let j = |verdict, detail: String| Judgement { verdict, preset: preset.to_string(), detail };
    let (Some(ct), Some(cases)) = (claim.at.get(preset), p.cases_of(preset)) else {
        return j(Verdict::NotRun, format!("the claim selects no case of the `{preset}` preset."));
    };
    let picked = ct.select.pick(cases);
    let keys = distinguishing(&picked);
    let name = |c: &Case| words::label(c, &keys);
    let metric = ct.test.metric();
    let results: Vec<(&Case, Outcome)> =
        picked.iter().map(|c| (*c, outcome(&Entry::new(output, p, c), metric))).collect();
    let missing: Vec<&Case> =
        results.iter().filter(|(_, v)| matches!(v, Outcome::Missing)).map(|(c, _)| *c).collect();
    let show = |c: &Case, v: &Outcome| match v {
        Outcome::Value(x) => format!("{}: {}", name(c), fmt_value(*x)),
        Outcome::Diverged(t, why, None) => format!("{}: diverged at t = {t:.3} s ({why})", name(c)),
        Outcome::Diverged(t, why, Some(x)) => {
            format!("{}: {} before it diverged at t = {t:.3} s ({why})", name(c), fmt_value(*x))
        }
        Outcome::NoMetric => format!("{}: no `{metric}`", name(c)),
        Outcome::Missing => format!("{}: no result", name(c)),
    };
    // A case as the test reads it: a value with the bound it breaks.
    let show_tested = |c: &Case, v: &Outcome| match (&ct.test, v) {
        (Test::Bound { max, min, .. }, Outcome::Value(x)) => {
            format!("{}{}", show(c, v), mark(*max, *min, *x))
        }
        _ => show(c, v),
    };
    if !missing.is_empty() {
        let list: Vec<String> = missing
            .iter()
            .map(|c| {
                let est = estimate(p, c, output).map(|e| format!(" ({e})")).unwrap_or_default();
                format!("`{}`{est}", c.name)
            })
            .collect();
        let not_run =
            format!("no result for {} of the {} case(s): {}.", missing.len(), picked.len(), list.join("; "));
        // A case that has run and fails the test decides the claim whatever the missing
        // ones would give: every test needs each of its cases to hold.
        let failed: Vec<String> = results
            .iter()
            .filter(|(_, v)| fails_alone(&ct.test, v))
            .map(|(c, v)| show_tested(c, v))
            .collect();
        if failed.is_empty() {
            return j(Verdict::NotRun, not_run);
        }
        return j(Verdict::NotReproduced, format!("`{metric}` {}; and {not_run}", failed.join("; ")));
    }
    match &ct.test {
        Test::Bound { max, min, .. } => {
            let mut ok = true;
            let parts: Vec<String> = results
                .iter()
                .map(|(c, v)| match v {
                    Outcome::Value(_) => {
                        ok &= !fails_alone(&ct.test, v);
                        show_tested(c, v)
                    }
                    // A running record over a lower bound only: it passed before the blow-up
                    // and cannot fall back.
                    Outcome::Diverged(_, _, Some(x)) if max.is_none() && min.is_some_and(|m| *x >= m) => {
                        show(c, v)
                    }
                    other => {
                        ok = false;
                        show(c, other)
                    }
                })
                .collect();
            j(
                if ok { Verdict::Reproduced } else { Verdict::NotReproduced },
                format!("`{metric}` {}.", parts.join("; ")),
            )
        }
        Test::Monotone { param, decreasing, .. } => {
            // Groups of cases alike but in `param`, each sorted along it.
            let mut groups: BTreeMap<String, Vec<(&Case, &Outcome)>> = BTreeMap::new();
            for (c, v) in &results {
                groups.entry(group_key(c, |k| k == param)).or_default().push((c, v));
            }
            let group_keys: Vec<String> = keys.iter().filter(|k| *k != param).cloned().collect();
            let mut ok = true;
            let mut judged = 0;
            let mut parts = Vec::new();
            for g in groups.values_mut().filter(|g| g.len() >= 2) {
                judged += 1;
                g.sort_by(|a, b| param_f64(a.0, param).total_cmp(&param_f64(b.0, param)));
                let mut text = String::new();
                let mut prev: Option<f64> = None;
                for (c, v) in g.iter() {
                    let at = words::phrase(param, &c.params.0[param]);
                    match v {
                        Outcome::Value(x) => {
                            if let Some(p0) = prev {
                                let holds = if *decreasing { *x < p0 } else { *x > p0 };
                                ok &= holds;
                                text += if holds { " then " } else { " then (not monotone) " };
                            }
                            text += &format!("{at}: {}", fmt_value(*x));
                            prev = Some(*x);
                        }
                        other => {
                            ok = false;
                            if !text.is_empty() {
                                text += " then ";
                            }
                            text += &show(c, other);
                            prev = None;
                        }
                    }
                }
                let head = if group_keys.is_empty() {
                    String::new()
                } else {
                    format!("{}: ", words::label(g[0].0, &group_keys))
                };
                parts.push(format!("{head}{text}"));
            }
            if judged == 0 {
                return j(
                    Verdict::NotRun,
                    format!("no two cases differ in `{param}` alone at this preset: no trend to judge."),
                );
            }
            j(
                if ok { Verdict::Reproduced } else { Verdict::NotReproduced },
                format!("`{metric}` {}.", parts.join("; ")),
            )
        }
        Test::LowerThan { lower, higher, factor, .. } => {
            // The comparison holds in every group of cases alike but in the sides' parameters
            // (each resolution of a study on its own), not on a mean that one group can carry.
            // The sides' parameters: those the two sides hold no value of in common (the
            // `where` keys, or what tells cases picked by name apart).
            let values = |s: &Select, k: &String| -> Vec<String> {
                results
                    .iter()
                    .filter(|(c, _)| s.matches(c))
                    .map(|(c, _)| format!("{:?}", c.params.0.get(k)))
                    .collect()
            };
            let all_keys: std::collections::BTreeSet<&String> =
                results.iter().flat_map(|(c, _)| c.params.0.keys()).collect();
            let sides: Vec<&String> = all_keys
                .into_iter()
                .filter(|k| {
                    let (a, b) = (values(lower, k), values(higher, k));
                    lower.where_.contains_key(*k)
                        || higher.where_.contains_key(*k)
                        || (!a.is_empty() && !b.is_empty() && a.iter().all(|v| !b.contains(v)))
                })
                .collect();
            let mut groups: BTreeMap<String, Vec<&(&Case, Outcome)>> = BTreeMap::new();
            for r in &results {
                groups.entry(group_key(r.0, |k| sides.iter().any(|s| s.as_str() == k))).or_default().push(r);
            }
            let group_keys: Vec<String> = keys.iter().filter(|k| !sides.contains(k)).cloned().collect();
            let describe_side = |s: &Select| -> String {
                let cs: Vec<&Case> = results.iter().map(|(c, _)| *c).filter(|c| s.matches(c)).collect();
                let k: Vec<String> = s.where_.keys().cloned().collect();
                match cs.first() {
                    Some(c) if !k.is_empty() => words::label(c, &k),
                    _ => cs.iter().map(|c| c.name.clone()).collect::<Vec<_>>().join(", "),
                }
            };
            let (la, lb) = (describe_side(lower), describe_side(higher));
            let bound = if *factor == 1.0 { String::new() } else { format!(" x {factor}") };
            let mut ok = true;
            let mut parts = Vec::new();
            for g in groups.values() {
                let side = |s: &Select| -> Result<f64, Vec<String>> {
                    let mut vals = Vec::new();
                    let mut notes = Vec::new();
                    for (c, v) in g.iter().map(|r| (&r.0, &r.1)).filter(|(c, _)| s.matches(c)) {
                        match v {
                            Outcome::Value(x) => vals.push(*x),
                            other => notes.push(show(c, other)),
                        }
                    }
                    match (notes.is_empty(), vals.is_empty()) {
                        (true, false) => Ok(vals.iter().sum::<f64>() / vals.len() as f64),
                        _ => Err(notes),
                    }
                };
                let head = if group_keys.is_empty() || groups.len() == 1 {
                    String::new()
                } else {
                    format!("{}: ", words::label(g[0].0, &group_keys))
                };
                match (side(lower), side(higher)) {
                    (Ok(a), Ok(b)) => {
                        let holds = a <= factor * b;
                        ok &= holds;
                        let ratio = if b != 0.0 { format!(" (ratio {:.2})", a / b) } else { String::new() };
                        parts.push(format!(
                            "{head}{la}: {} {} {lb}: {}{bound}{ratio}",
                            fmt_value(a),
                            if holds { "<=" } else { ">" },
                            fmt_value(b)
                        ));
                    }
                    (a, b) => {
                        ok = false;
                        let notes: Vec<String> = a.err().into_iter().chain(b.err()).flatten().collect();
                        let notes = if notes.is_empty() {
                            "one side has no case".to_string()
                        } else {
                            notes.join("; ")
                        };
                        parts.push(format!("{head}{notes}"));
                    }
                }
            }
            j(
                if ok { Verdict::Reproduced } else { Verdict::NotReproduced },
                format!("`{metric}` {}.", parts.join("; ")),
            )
        }
    }
}

/// The parameters that set a case's size and length, and how its cost grows with each.
const SIZE_KEYS: [&str; 4] = ["nx", "dx", "tf", "nz"];

/// An estimate of what `case` would take: the one a dry run measured from a short run of
/// the case ([`estimate`](crate::automation::estimate)), else one scaled from the most
/// similar finished case of the problem (any preset, either layer): the fewest other
/// differing parameters, then the nearest in size. Wall time grows as particles times
/// steps: (nx ratio)^(dim + 1) or (dx ratio)^-(dim + 1), tf and nz linearly.
pub fn estimate(p: &Problem, case: &Case, output: &Path) -> Option<String> {
    if let Some(m) = crate::automation::estimate::stored_for(&Entry::new(output, p, case)) {
        return Some(format!(
            "estimated {} of CPU on 1 thread, {}, from a short run of it",
            duration(m.estimate.cpu_seconds),
            crate::automation::estimate::bytes(m.estimate.peak_rss_bytes)
        ));
    }
    let dim = p.scene.dim as i32;
    let mut best: Option<(usize, f64, &Case, Summary)> = None;
    for (_, cases) in p.presets() {
        for c in cases {
            if c.params == case.params {
                continue;
            }
            let Some(s) = Entry::new(output, p, c).summary().filter(|s| s.status == Status::Completed) else {
                continue;
            };
            let diffs = case
                .params
                .0
                .iter()
                .filter(|(k, v)| !SIZE_KEYS.contains(&k.as_str()) && c.params.0.get(*k) != Some(*v))
                .count();
            let scale = scale(case, c, dim);
            let far = scale.ln().abs();
            if best.as_ref().is_none_or(|b| (diffs, far) < (b.0, b.1)) {
                best = Some((diffs, far, c, s));
            }
        }
    }
    let (_, _, c, s) = best?;
    let secs = s.wall_seconds * scale(case, c, dim);
    Some(format!(
        "estimated {} on {} thread{}, scaled from `{}`, which took {}",
        duration(secs),
        s.threads,
        if s.threads == 1 { "" } else { "s" },
        c.name,
        duration(s.wall_seconds)
    ))
}

/// How much longer `a` runs than `b`, from their sizes.
fn scale(a: &Case, b: &Case, dim: i32) -> f64 {
    let ratio = |k: &str| -> Option<f64> {
        let (x, y) = (param_f64(a, k), param_f64(b, k));
        (x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0).then(|| x / y)
    };
    let mut f = 1.0;
    if let Some(r) = ratio("nx") {
        f *= r.powi(dim + 1);
    }
    if let Some(r) = ratio("dx") {
        f *= r.powi(-(dim + 1));
    }
    for k in ["tf", "nz"] {
        if let Some(r) = ratio(k) {
            f *= r;
        }
    }
    f
}

/// A duration in the unit that reads best.
pub(crate) fn duration(secs: f64) -> String {
    if secs < 120.0 {
        format!("{secs:.0} s")
    } else if secs < 7200.0 {
        format!("{:.0} min", secs / 60.0)
    } else {
        format!("{:.1} h", secs / 3600.0)
    }
}
