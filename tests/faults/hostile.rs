//! Every parameter of every scene at values no one should give, generated from the scenes'
//! declarations.

use crate::common::*;
use sphrepro::scenes::params::{Kind, Spec, Value};
use sphrepro::scenes::{self, SceneEntry};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// Whether `text` names the parameter `key`: as a word of its own, not inside another name
/// (`re` in "(re)" or "`re`", not in "pressure").
fn names(text: &str, key: &str) -> bool {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.match_indices(key).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + key.len()..].chars().next();
        !before.is_some_and(ident) && !after.is_some_and(ident)
    })
}

/// Whether `ran`, a `simulate` into `out`, ended as the contract allows: refused with exit 2,
/// a one-line error naming `key` and no summary; `completed` (exit 0) with metrics the scene
/// declares, every one a finite number (a scene may leave one out where it is undefined,
/// as the cavity does Ghia's deviations at a Re Ghia did not tabulate); or `diverged`
/// (exit 3) with its reason.
fn judge(entry: &SceneEntry, key: &str, ran: &Ran, out: &Path) -> Result<&'static str, String> {
    if ran.panicked() {
        return Err("panicked".into());
    }
    match ran.code {
        Some(2) => {
            let err = ran.stderr.trim();
            if err.lines().count() != 1 {
                return Err(format!("refused, but not in one line: {err}"));
            }
            if !names(err, key) {
                return Err(format!("refused without naming `{key}`: {err}"));
            }
            if out.join("summary.json").exists() {
                return Err("refused, but wrote a summary".into());
            }
            Ok("refused")
        }
        Some(0) => {
            let s = summary(out).ok_or("exit 0 without a readable summary")?;
            if s["status"] != "completed" {
                return Err(format!("exit 0 with status {}", s["status"]));
            }
            let metrics = s["metrics"].as_object().ok_or("completed without metrics")?;
            if metrics.is_empty() {
                return Err("completed without metrics".into());
            }
            // A `null` stands only for a metric the summary lists as undefined by the run.
            let undefined =
                |m: &str| s["undefined_metrics"].as_array().is_some_and(|u| u.iter().any(|n| n == m));
            for (m, v) in metrics {
                let defined = v.as_f64().is_some_and(f64::is_finite) || (v.is_null() && undefined(m));
                if !entry.metrics.contains(&m.as_str()) || !defined {
                    return Err(format!("completed with metric `{m}` = {v}"));
                }
            }
            Ok("completed")
        }
        Some(3) => {
            let s = summary(out).ok_or("exit 3 without a readable summary")?;
            if s["status"] != "diverged" || s["reason"].as_str().is_none_or(str::is_empty) {
                return Err(format!("exit 3 with status {} and reason {}", s["status"], s["reason"]));
            }
            Ok("diverged")
        }
        _ => Err("neither refused, completed nor diverged".into()),
    }
}

/// Values of a parameter that no one should give: for a number 0, negative, NaN, infinite,
/// 1e-300 and 1e300; for an integer 0, negative, the largest and one beyond it; for a
/// choice or a switch a name it does not know, and nothing.
fn hostile_values(spec: &Spec) -> Vec<&'static str> {
    match spec.kind {
        Kind::Float { .. } => vec!["0", "-1", "NaN", "inf", "-inf", "1e-300", "1e300"],
        Kind::Int { .. } => vec!["0", "-1", "9223372036854775807", "99999999999999999999"],
        Kind::Bool => vec!["maybe", ""],
        Kind::Choice(_) => vec!["no_such_name", ""],
        Kind::AutoOrInt { .. } => {
            vec!["0", "-1", "9223372036854775807", "99999999999999999999", "no_such_name", ""]
        }
    }
}

/// A valid value of `spec` other than its default (to find where a key is read).
fn other_valid_value(spec: &Spec) -> String {
    match (&spec.kind, &spec.default) {
        (Kind::Float { .. }, Value::Float(x)) if *x > 0.0 => format!("{}", x * 0.75),
        (Kind::Float { .. }, _) => "0.5".into(),
        (Kind::Int { .. }, Value::Int(i)) => format!("{}", i + 1),
        (Kind::Bool, Value::Bool(b)) => format!("{}", !b),
        (Kind::AutoOrInt { .. }, _) => "2".into(),
        (Kind::Choice(names), d) => {
            names.iter().find(|n| d.to_string() != **n).unwrap_or(&names[0]).to_string()
        }
        _ => spec.default.to_string(),
    }
}

fn accepts(entry: &SceneEntry, sets: &[String]) -> bool {
    entry.params_from_sets(sets).is_ok_and(|p| (entry.check)(&p).is_ok())
}

/// A tiny run of `entry`: the resolution (`nx` particles per side, or a spacing `dx`) as
/// coarse as the scene accepts, and a few steps (`tf` at most 0.01 s). A scene with other
/// resolution parameters runs at its defaults for those few steps.
fn tiny(entry: &SceneEntry) -> Vec<String> {
    let specs = (entry.params)();
    let mut sets = Vec::new();
    for s in &specs {
        match (s.name, &s.default) {
            ("tf", Value::Float(tf)) => sets.push(format!("tf={}", tf.min(0.01))),
            ("nx", Value::Int(_)) => {
                if let Some(nx) = [12, 16, 20].iter().find(|nx| accepts(entry, &[format!("nx={nx}")])) {
                    sets.push(format!("nx={nx}"));
                }
            }
            ("dx", Value::Float(dx)) => {
                if let Some(f) =
                    [5.0, 4.0, 2.5, 2.0].iter().find(|f| accepts(entry, &[format!("dx={}", dx * *f)]))
                {
                    sets.push(format!("dx={}", dx * f));
                }
            }
            _ => {}
        }
    }
    assert!(accepts(entry, &sets), "{}: the tiny run {sets:?} is refused", entry.name);
    sets
}

/// The settings under which `key` is read: the tiny run, or the tiny run with one choice
/// parameter changed (IPST's settings act with `pst = ipst` only, and a key given where it
/// has no effect is refused as such).
fn base_for(entry: &SceneEntry, tiny: &[String], key: &str) -> Vec<String> {
    let specs = (entry.params)();
    let spec = specs.iter().find(|s| s.name == key).unwrap();
    let probe = format!("{key}={}", other_valid_value(spec));
    let with = |extra: Option<String>| -> Vec<String> {
        let mut v: Vec<String> =
            tiny.iter().filter(|s| !s.starts_with(&format!("{key}="))).cloned().collect();
        v.extend(extra);
        v
    };
    let mut candidates = vec![with(None)];
    for s in &specs {
        if let Kind::Choice(names) = s.kind {
            if s.name != key {
                candidates.extend(names.iter().map(|n| with(Some(format!("{}={n}", s.name)))));
            }
        }
    }
    candidates
        .into_iter()
        .find(|base| accepts(entry, &[base.clone(), vec![probe.clone()]].concat()))
        .unwrap_or_else(|| with(None))
}

/// Runs `cases` (name, command, output folder) on a few threads, each within
/// [`CASE_LIMIT`]; `judge` says whether each ended as it must. Returns the tally of
/// outcomes, or panics listing every case that did not.
fn run_all(
    cases: Vec<(String, Command, PathBuf)>,
    judge: impl Fn(&str, &Ran, &Path) -> Result<&'static str, String> + Sync,
) -> std::collections::BTreeMap<&'static str, usize> {
    let queue = Mutex::new(cases);
    let failures = Mutex::new(Vec::new());
    let tally = Mutex::new(std::collections::BTreeMap::new());
    std::thread::scope(|s| {
        for _ in 0..3 {
            s.spawn(|| loop {
                let Some((name, cmd, out)) = queue.lock().unwrap().pop() else { break };
                let scratch = out.with_extension("scratch");
                let verdict = run_limited(cmd, &scratch, CASE_LIMIT)
                    .and_then(|ran| judge(&name, &ran, &out).map_err(|e| format!("{e}\n{}", ran.text())));
                match verdict {
                    Ok(outcome) => *tally.lock().unwrap().entry(outcome).or_insert(0) += 1,
                    Err(e) => failures.lock().unwrap().push(format!("{name}: {e}")),
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(failures.is_empty(), "{} case(s) misbehaved:\n{}", failures.len(), failures.join("\n\n"));
    tally.into_inner().unwrap()
}

/// Every parameter of every scene at every hostile value, over a tiny run: refused with
/// the key named, or `diverged`, or `completed` with finite metrics, within the time
/// limit. The cases come from the scenes' declarations (`scenes::SCENES`), so a new scene,
/// or a new parameter, is covered without a change here.
#[test]
fn every_parameter_of_every_scene_at_hostile_values() {
    let tmp = tempfile::tempdir().unwrap();
    let mut cases = Vec::new();
    for entry in scenes::SCENES {
        let tiny = tiny(entry);
        for spec in (entry.params)() {
            let base = base_for(entry, &tiny, spec.name);
            for (i, value) in hostile_values(&spec).into_iter().enumerate() {
                let name = format!("{} {}={value} over {base:?}", entry.name, spec.name);
                let out = tmp.path().join(format!("{}-{}-{i}", entry.name, spec.name));
                let mut sets = base.clone();
                sets.push(format!("{}={value}", spec.name));
                cases.push((name, simulate_cmd(entry.name, &out, &sets), out));
            }
        }
    }
    let n = cases.len();
    let tally = run_all(cases, |name, ran, out| {
        let scene = name.split(' ').next().unwrap();
        let key = name.split(' ').nth(1).unwrap().split('=').next().unwrap();
        judge(scenes::find(scene).unwrap(), key, ran, out)
    });
    eprintln!("{n} hostile cases: {tally:?}");
    assert_eq!(tally.values().sum::<usize>(), n);
}

/// Every scene's tiny run itself completes with finite metrics (the base the hostile
/// values are set over is a run that works).
#[test]
fn every_scene_completes_its_tiny_run_with_finite_metrics() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = scenes::SCENES
        .iter()
        .map(|e| {
            let out = tmp.path().join(e.name);
            (e.name.to_string(), simulate_cmd(e.name, &out, &tiny(e)), out)
        })
        .collect();
    let tally = run_all(cases, |name, ran, out| match judge(scenes::find(name).unwrap(), "tf", ran, out)? {
        "completed" => Ok("completed"),
        other => Err(format!("the tiny run of {name} {other}")),
    });
    assert_eq!(tally.get("completed"), Some(&scenes::SCENES.len()));
}
