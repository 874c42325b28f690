//! Post-processing: the figures and tables a problem declares, drawn from cached results
//! (`summary.json`, `timeseries.csv`, the files a case writes, its `.vtu` snapshots), the
//! verdicts on the paper's claims, and the manuscript assembled from them, paper by paper.
//!
//! - `claims`: the verdict on each claim of a problem file;
//! - `snapshot`: reading a case's snapshots (also gzip-compressed ones);
//! - `words`: parameter values in words, for legends and the text;
//! - `trade` and `stability`: the speed-accuracy trade and stability maps;
//! - `assemble`: the manuscript from every problem's items and verdicts.

mod assemble;
mod claims;
pub(crate) mod snapshot;
mod stability;
mod trade;
pub(crate) mod words;

pub use assemble::{manuscript, Header};
pub(crate) use claims::duration;
pub use claims::{judge, judge_all, judge_at, ClaimVerdict, Judgement, Verdict};

use super::cache::Entry;
use super::papers;
use super::registry::{Case, Figure, FigureKind, ItemInfo, Problem, Select, Table};
use super::report::{self, Block, Series, SeriesStyle};
use crate::solver::output::summary::{Status, Summary};
use std::path::Path;

/// A selected case with its cached summary, if done.
pub(crate) struct Run<'a> {
    case: &'a Case,
    entry: Entry,
    summary: Option<Summary>,
}

impl Run<'_> {
    /// Metric `m` of its summary.
    fn metric(&self, m: &str) -> Option<f64> {
        self.summary.as_ref().and_then(|s| s.metrics.get(m).copied())
    }

    /// The folder its results are read from.
    fn dir(&self) -> &Path {
        self.entry.result_dir()
    }
}

/// The cases of `cases` that `s` selects, with their results.
fn runs_of<'a>(output: &Path, p: &Problem, cases: &'a [Case], s: &Select) -> Vec<Run<'a>> {
    s.pick(cases)
        .into_iter()
        .map(|c| {
            let entry = Entry::new(output, p, c);
            let summary =
                entry.summary().filter(|s| matches!(s.status, Status::Completed | Status::Diverged));
            Run { case: c, entry, summary }
        })
        .collect()
}

fn runs<'a>(output: &Path, p: &'a Problem, s: &Select) -> Vec<Run<'a>> {
    runs_of(output, p, &p.cases, s)
}

/// The `keys` parameters of a case in words (a curve, a row of a map).
pub(crate) fn group(case: &Case, keys: &[String]) -> String {
    words::label(case, keys)
}

pub(crate) fn param_f64(case: &Case, key: &str) -> f64 {
    match case.params.0.get(key) {
        Some(crate::scenes::params::Value::Int(i)) => *i as f64,
        Some(crate::scenes::params::Value::Float(x)) => *x,
        _ => f64::NAN,
    }
}

/// A value for the text and the tables: an integer as one (`3`, not `3.000e0`), anything
/// else with three significant digits, in plain decimals from 0.001 to 100 000 (`0.0724`),
/// in scientific notation outside (`4.80e-5`).
pub(crate) fn fmt_value(x: f64) -> String {
    if x.is_finite() && x.fract() == 0.0 && x.abs() < 1e12 {
        format!("{}", x as i64)
    } else if x.is_finite() && (1e-3..1e5).contains(&x.abs()) {
        let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.2e}")
    }
}

/// A bound or tolerance as written in the problem file (`0.04`, `1e-5`).
pub(crate) fn fmt_bound(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-4 || x.abs() >= 1e6) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Reads columns `t` and `y` of a case's `timeseries.csv`; an unreadable one is a damaged
/// result, which the error says how to compute again.
fn timeseries(p: &Problem, r: &Run, y: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
    columns(&r.dir().join("timeseries.csv"), "t", y).map_err(|e| {
        let command = super::cache::recompute_command(&p.name, &p.preset, &r.case.name);
        format!("{e} (a damaged result: {command} computes it again)")
    })
}

/// Reads columns `x` and `y` of a CSV file (unparsable values are NaN).
fn columns(path: &Path, x: &str, y: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
    let mut rd = csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let headers = rd.headers().map_err(|e| format!("{}: {e}", path.display()))?.clone();
    let col = |name: &str| {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            format!(
                "{}: no column `{name}`; columns: {}",
                path.display(),
                headers.iter().collect::<Vec<_>>().join(", ")
            )
        })
    };
    let (it, iy) = (col(x)?, col(y)?);
    let (mut t, mut v) = (Vec::new(), Vec::new());
    for rec in rd.records() {
        let rec = rec.map_err(|e| format!("{}: {e}", path.display()))?;
        t.push(rec[it].trim().parse().unwrap_or(f64::NAN));
        v.push(rec[iy].trim().parse().unwrap_or(f64::NAN));
    }
    Ok((t, v))
}

/// What one figure or table put in the manuscript.
pub(crate) struct Drawn {
    blocks: Vec<Block>,
}

/// One figure or table of a problem, ready for the manuscript.
#[derive(Clone, Debug)]
pub struct ReportItem {
    /// Its id.
    pub id: String,
    /// Its place and text.
    pub info: ItemInfo,
    /// The item.
    pub item: report::Item,
}

/// What [`regenerate`] made of one problem: its items (figures, then tables, in file order,
/// each with the verdicts on its claims) and every verdict.
#[derive(Clone, Debug)]
pub struct ProblemReport {
    /// The items.
    pub items: Vec<ReportItem>,
    /// Every claim's verdict, in file order.
    pub verdicts: Vec<ClaimVerdict>,
    /// Whether any case had a result (else nothing was drawn).
    pub drawn: bool,
}

fn missing_note(rs: &[Run]) -> String {
    let m: Vec<_> = rs.iter().filter(|r| r.summary.is_none()).map(|r| r.case.name.as_str()).collect();
    if m.is_empty() {
        String::new()
    } else {
        format!(" No result for: {}.", m.join(", "))
    }
}

/// A point array's name in words, with its unit, for a colour bar.
fn with_unit(field: &str) -> String {
    match field {
        "pressure" => "p (Pa)".into(),
        "von_mises" => "von Mises stress sqrt(3 J2) (Pa)".into(),
        "pressure_deviation" => "p - mean p (Pa)".into(),
        "pressure_exact" => "exact p (Pa)".into(),
        "speed" => "|u| (m/s)".into(),
        "density" => "density (kg/m^3)".into(),
        "free_surface" => "1: free surface, 0: not".into(),
        "2*free_surface+near_surface" => "2: surface, 1: near it, 0: inside".into(),
        other => other.to_string(),
    }
}

/// The number of every case's `metric` in words, as a sentence.
fn numbers(f: &Figure, rs: &[Run]) -> String {
    let Some(m) = &f.metric else {
        return format!(
            "{} case(s) drawn.{}",
            rs.iter().filter(|r| r.summary.is_some()).count(),
            missing_note(rs)
        );
    };
    let parts: Vec<String> = rs
        .iter()
        .filter_map(|r| {
            let name = group(r.case, &f.label);
            match (&r.summary, r.metric(m)) {
                (_, Some(v)) => Some(format!("{name}: {}", fmt_value(v))),
                (Some(s), None) if s.status == Status::Diverged => Some(format!(
                    "{name}: diverged at t = {:.3} s ({})",
                    s.final_time,
                    s.reason.clone().unwrap_or_default()
                )),
                (Some(_), None) => Some(format!("{name}: no `{m}`")),
                (None, _) => None,
            }
        })
        .collect();
    if parts.is_empty() {
        return missing_note(rs).trim().to_string();
    }
    format!("`{m}`: {}.{}", parts.join("; "), missing_note(rs))
}

/// A figure prepared for drawing: curves or particles whose axes the panels of one paper
/// figure share, or already drawn.
enum Prepared {
    Lines(report::LineFigure, String),
    Particles(Box<report::ScatterField>, String, Option<String>),
    Drawn(Drawn),
    Missing(String),
}

/// Regenerates the figures and tables of `p` from the results under `output` (and the
/// committed ones) into `manuscript/figures` and `manuscript/tables`, with the verdicts on
/// its claims. A problem none of whose cases has a result draws nothing (its last figures
/// stay as they were): its items say why, its verdicts are `not run`.
pub fn regenerate(p: &Problem, output: &Path, manuscript: &Path) -> Result<ProblemReport, String> {
    let verdicts = judge_all(p, output);
    let drawn = super::cache::entries(output, p).iter().any(|e| e.is_done());
    let figures = manuscript.join("figures");
    let tables = manuscript.join("tables");
    let mut errors = Vec::new();
    let mut prepared = Vec::new();
    for f in &p.figures {
        // A stability map's table of first failures reads every preset's results, so it is
        // written even where this preset has none.
        let out = if drawn || matches!(f.kind, FigureKind::Stability { .. }) {
            prepare(p, f, output, &figures, &tables)
        } else {
            Ok(Prepared::Missing(format!("no case of the `{}` preset has a result", p.preset)))
        };
        match out {
            Ok(x) => prepared.push(x),
            Err(e) => {
                errors.push(format!("{}: figures.{}: {e}", p.path.display(), f.id));
                prepared.push(Prepared::Missing("it could not be drawn".into()));
            }
        }
    }
    share_axes(p, &mut prepared);
    let mut items = Vec::new();
    for (f, prep) in p.figures.iter().zip(prepared) {
        let caption = if f.info.caption.is_empty() { f.title.clone() } else { f.info.caption.clone() };
        let stem = figures.join(&f.id);
        let blocks = match prep {
            Prepared::Lines(fig, ours) => match report::line_figure(&fig, &stem) {
                Ok(()) => vec![Block::Image { path: format!("figures/{}.png", f.id), caption, ours }],
                Err(e) => {
                    errors.push(format!("{}: figures.{}: {e}", p.path.display(), f.id));
                    continue;
                }
            },
            Prepared::Particles(fig, ours, arrows) => {
                let ours = match (&arrows, fig.arrows_drawn()) {
                    (Some(a), (drawn, all)) if all > 0 => format!(
                        "{ours} `{a}` drawn as arrows at {drawn} of the {all} particles that have one{}.",
                        if drawn < all { " (one per arrow length where they stand closer)" } else { "" }
                    ),
                    (Some(a), _) => format!("{ours} No particle has a non-zero `{a}`."),
                    _ => ours,
                };
                match report::particle_figure(&fig, &stem) {
                    Ok(()) => vec![Block::Image { path: format!("figures/{}.png", f.id), caption, ours }],
                    Err(e) => {
                        errors.push(format!("{}: figures.{}: {e}", p.path.display(), f.id));
                        continue;
                    }
                }
            }
            Prepared::Drawn(d) => d.blocks,
            Prepared::Missing(why) => {
                remove_stale(&[figures.join(format!("{}.png", f.id)), figures.join(format!("{}.svg", f.id))]);
                vec![Block::Missing { caption, why }]
            }
        };
        items.push(item(&f.id, &f.title, &f.info, blocks, &verdicts));
    }
    for t in &p.tables {
        let blocks = if drawn {
            match metrics_table(p, t, output, &tables) {
                Ok(b) => vec![b],
                Err(e) => {
                    errors.push(format!("{}: tables.{}: {e}", p.path.display(), t.id));
                    continue;
                }
            }
        } else {
            remove_stale(&[tables.join(format!("{}.md", t.id)), tables.join(format!("{}.csv", t.id))]);
            vec![Block::Missing {
                caption: t.info.caption.clone(),
                why: format!("no case of the `{}` preset has a result", p.preset),
            }]
        };
        items.push(item(&t.id, &t.title, &t.info, blocks, &verdicts));
    }
    if !errors.is_empty() {
        return Err(errors.join("\n"));
    }
    Ok(ProblemReport { items, verdicts, drawn })
}

/// Removes the files of a figure or table the manuscript now says is not drawn: drawn from
/// results that are gone (their inputs changed), they would show what no result holds.
fn remove_stale(files: &[std::path::PathBuf]) {
    for f in files {
        let _ = std::fs::remove_file(f);
    }
}

/// An item of the manuscript: its heading (the paper's number, or our title), the paper's
/// caption, our blocks, the verdicts of the claims on it, its discussion.
fn item(id: &str, title: &str, info: &ItemInfo, blocks: Vec<Block>, verdicts: &[ClaimVerdict]) -> ReportItem {
    let mut verdicts: Vec<String> =
        verdicts.iter().filter(|v| v.claim.figure == id).map(ClaimVerdict::markdown).collect();
    if verdicts.is_empty() && info.number.is_some() {
        verdicts.push("*No claim of the paper on it is tested: none is one a metric decides.*".into());
    }
    ReportItem {
        id: id.to_string(),
        info: info.clone(),
        item: report::Item {
            heading: info.number.clone().unwrap_or_else(|| title.to_string()),
            paper_caption: info.paper_caption.clone(),
            blocks,
            verdicts,
            discussion: info.discussion.clone(),
        },
    }
}

/// Figure `f` read from the results, ready to draw (trade and stability figures are drawn
/// here).
fn prepare(
    p: &Problem,
    f: &Figure,
    output: &Path,
    figures: &Path,
    tables: &Path,
) -> Result<Prepared, String> {
    let rs = runs(output, p, &f.select);
    if let FigureKind::Stability { x, max, above } = &f.kind {
        // Every preset with results, for the table of first failures.
        let mut by_preset = Vec::new();
        for (name, cases) in p.presets() {
            let Some(select) = f.select_at.get(name) else { continue };
            let r = runs_of(output, p, cases, select);
            if r.iter().any(|r| r.summary.is_some()) {
                by_preset.push((name.to_string(), r));
            }
        }
        let metric = f.metric.as_deref().expect("validated");
        let rule = stability::Rule { x, metric, max: *max, above };
        return Ok(Prepared::Drawn(stability::stability(
            f,
            &rule,
            &rs,
            &by_preset,
            (figures, tables),
            &p.preset,
        )?));
    }
    if rs.iter().all(|r| r.summary.is_none()) {
        return Ok(Prepared::Missing(format!("none of its cases has a result at the `{}` preset", p.preset)));
    }
    let lines = |x_label: String, y: &String, series: Vec<Series>| {
        let fig = report::LineFigure {
            title: f.title.clone(),
            x_label,
            y_label: f.y_label.clone().unwrap_or_else(|| y.clone()),
            log_x: false,
            log_y: f.log_y,
            series,
            extent: None,
        };
        Prepared::Lines(fig, numbers(f, &rs))
    };
    Ok(match &f.kind {
        FigureKind::Timeseries { y, exact, exact_label, metric_over } => {
            let mut series = Vec::new();
            for r in rs.iter().filter(|r| r.summary.is_some() && r.dir().join("timeseries.csv").exists()) {
                let (t, v) = timeseries(p, r, y)?;
                if series.is_empty() {
                    if let Some(ex) = exact {
                        let (t, v) = timeseries(p, r, ex)?;
                        series.push(Series {
                            label: exact_label.clone(),
                            x: t,
                            y: v,
                            style: SeriesStyle::Dashed,
                        });
                    }
                }
                let (t0, t1) = (t.first().copied(), t.last().copied());
                series.push(Series { label: group(r.case, &f.label), x: t, y: v, style: SeriesStyle::Line });
                // The value tested, a mean over the run's last part, drawn over that part.
                if let (Some(w), Some(m), Some(t0), Some(t1)) = (metric_over, &f.metric, t0, t1) {
                    if let Some(value) = r.metric(m) {
                        let from = t1 - w * (t1 - t0);
                        series.push(Series {
                            label: format!(
                                "{}: mean over the last {:.0} %",
                                group(r.case, &f.label),
                                w * 100.0
                            ),
                            x: vec![from, t1],
                            y: vec![value, value],
                            style: SeriesStyle::LinePoints,
                        });
                    }
                }
            }
            lines("t (s)".into(), y, series)
        }
        FigureKind::Profile { file, x, y, references, clip_to_reference } => {
            // Over the published points' horizontal range (and a twentieth of it beyond),
            // when asked.
            let clip = clip_to_reference.then(|| {
                let (lo, hi) = references
                    .iter()
                    .flat_map(|r| r.x.iter().copied())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
                (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
            });
            let mut series = Vec::new();
            for r in rs.iter().filter(|r| r.summary.is_some() && r.dir().join(file).exists()) {
                let (mut a, mut b) = columns(&r.dir().join(file), x, y)?;
                if let Some((lo, hi)) = clip {
                    let keep: Vec<bool> = a.iter().map(|v| *v >= lo && *v <= hi).collect();
                    let mut k = keep.iter();
                    a.retain(|_| *k.next().unwrap());
                    let mut k = keep.iter();
                    b.retain(|_| *k.next().unwrap());
                }
                series.push(Series { label: group(r.case, &f.label), x: a, y: b, style: SeriesStyle::Line });
            }
            for rf in references {
                series.push(Series {
                    label: rf.label.clone(),
                    x: rf.x.clone(),
                    y: rf.y.clone(),
                    style: SeriesStyle::Reference,
                });
            }
            lines(f.x_label.clone().unwrap_or_else(|| x.clone()), y, series)
        }
        FigureKind::Particles { field, time, arrows, view } => {
            let Some(r) = rs.iter().find(|r| r.summary.is_some()) else {
                return Ok(Prepared::Missing("no result".into()));
            };
            let Some(s) = snapshot::snapshot(r.dir(), field, *time, arrows.as_deref())? else {
                return Ok(Prepared::Missing(format!(
                    "the snapshot of `{}` it draws is not among the results (the committed results keep only the snapshots their figures draw, within their size budget)",
                    r.case.name
                )));
            };
            let t = s.t;
            let (lo, hi) =
                s.value.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
            let asked = match time {
                Some(want) if (want - t).abs() > 1e-9 => format!(" (the snapshot nearest t = {want} s)"),
                _ => String::new(),
            };
            let who = if f.label.is_empty() { r.case.name.clone() } else { group(r.case, &f.label) };
            // The range of a field of values; a field of flags says it by its colours.
            let range = match field.as_str() {
                "pressure" | "pressure_deviation" => {
                    format!(" p from {} to {} Pa.", fmt_value(lo), fmt_value(hi))
                }
                "speed" => format!(" |u| from {} to {} m/s.", fmt_value(lo), fmt_value(hi)),
                "density" => format!(" Density from {} to {} kg/m^3.", fmt_value(lo), fmt_value(hi)),
                f if f.contains("surface") => String::new(),
                f => format!(" `{f}` from {} to {}.", fmt_value(lo), fmt_value(hi)),
            };
            let outside = match view {
                Some([x0, x1, y0, y1]) => {
                    let out: Vec<usize> = (0..s.x.len().min(s.y.len()))
                        .filter(|&i| !(*x0..=*x1).contains(&s.x[i]) || !(*y0..=*y1).contains(&s.y[i]))
                        .collect();
                    let top = out.iter().map(|&i| s.y[i]).fold(f64::NEG_INFINITY, f64::max);
                    match out.len() {
                        0 => String::new(),
                        n => format!(
                            " {n} of its {} particles lie outside the frame drawn (x from {x0} to {x1} m, y from {y0} to {y1} m), the highest at y = {} m.",
                            s.x.len(),
                            fmt_value(top)
                        ),
                    }
                }
                None => String::new(),
            };
            let ours = format!(
                "Drawn: {who}, at t = {} s{asked}.{range}{outside} {}",
                time_text(t, 3),
                numbers(f, std::slice::from_ref(r))
            );
            let fig = report::ScatterField {
                title: format!("{} (t = {} s)", f.title, time_text(t, 2)),
                x: s.x,
                y: s.y,
                value: s.value,
                value_label: with_unit(field),
                x_label: "x (m)".into(),
                y_label: "y (m)".into(),
                walls: s.walls,
                structures: s.structures,
                extent: *view,
                range: None,
                aspect_equal: true,
                arrows: s.arrows.map(|(u, v)| report::Arrows { u, v, length: None }),
            };
            Prepared::Particles(Box::new(fig), ours.trim().to_string(), arrows.clone())
        }
        FigureKind::Trade { x, spacing } => {
            Prepared::Drawn(trade::trade(f, &rs, x, *spacing, figures, tables)?)
        }
        FigureKind::Stability { .. } => unreachable!("prepared above"),
    })
}

/// The panels of one paper figure (`Fig. 17a`, `17b`, `17c`) that draw the same thing (the
/// same point array; the same columns) share their axes, and particle panels their colour
/// scale, so that they compare at a glance.
fn share_axes(p: &Problem, prepared: &mut [Prepared]) {
    let key = |f: &Figure| -> Option<String> {
        let n = f.info.number.as_ref()?;
        let what = match &f.kind {
            FigureKind::Particles { field, .. } => format!("particles:{field}"),
            FigureKind::Timeseries { y, .. } => format!("t:{y}"),
            FigureKind::Profile { x, y, .. } => format!("{x}:{y}"),
            _ => return None,
        };
        Some(format!("{}|{what}", papers::figure_of(n)))
    };
    let keys: Vec<Option<String>> = p.figures.iter().map(key).collect();
    let extend = |e: &mut [f64; 4], xs: &[f64], ys: &[f64], log_y: bool| {
        for (a, b) in xs.iter().zip(ys) {
            if a.is_finite() && b.is_finite() && !(log_y && *b <= 0.0) {
                e[0] = e[0].min(*a);
                e[1] = e[1].max(*a);
                e[2] = e[2].min(*b);
                e[3] = e[3].max(*b);
            }
        }
    };
    for k in keys.iter().flatten() {
        let members: Vec<usize> = (0..keys.len()).filter(|i| keys[*i].as_ref() == Some(k)).collect();
        if members.len() < 2 || members[0] != keys.iter().position(|x| x.as_ref() == Some(k)).unwrap() {
            continue;
        }
        let mut ext = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
        let mut range = (f64::INFINITY, f64::NEG_INFINITY);
        for &i in &members {
            match &prepared[i] {
                Prepared::Lines(fig, _) => {
                    for s in &fig.series {
                        extend(&mut ext, &s.x, &s.y, fig.log_y);
                    }
                }
                Prepared::Particles(fig, ..) => {
                    // A panel's view (its paper's frame) is its extent; else its particles'.
                    if let Some([x0, x1, y0, y1]) = fig.extent {
                        extend(&mut ext, &[x0, x1], &[y0, y1], false);
                    } else {
                        extend(&mut ext, &fig.x, &fig.y, false);
                        for (wx, wy) in fig.walls.iter().chain(fig.structures.iter()) {
                            extend(&mut ext, wx, wy, false);
                        }
                    }
                    for v in fig.value.iter().filter(|v| v.is_finite()) {
                        range = (range.0.min(*v), range.1.max(*v));
                    }
                }
                _ => {}
            }
        }
        if !(ext[0] <= ext[1] && ext[2] <= ext[3]) {
            continue;
        }
        for &i in &members {
            match &mut prepared[i] {
                Prepared::Lines(fig, _) => fig.extent = Some(ext),
                Prepared::Particles(fig, ..) => {
                    fig.extent = Some(ext);
                    if range.0 <= range.1 {
                        fig.range = Some(range);
                    }
                }
                _ => {}
            }
        }
    }
}

fn metrics_table(p: &Problem, t: &Table, output: &Path, tables: &Path) -> Result<Block, String> {
    let rs = runs(output, p, &t.select);
    let mut headers: Vec<String> = vec!["case".into()];
    headers.extend(t.columns.iter().cloned());
    headers.push("status".into());
    headers.extend(t.metrics.iter().cloned());
    headers.push("wall time (s)".into());
    let rows = rs
        .iter()
        .map(|r| {
            let mut row = vec![r.case.name.clone()];
            row.extend(t.columns.iter().map(|c| words::value(&r.case.params.0[c])));
            row.push(
                r.summary
                    .as_ref()
                    .map(|s| format!("{:?}", s.status).to_lowercase())
                    .unwrap_or_else(|| "missing".into()),
            );
            row.extend(t.metrics.iter().map(|m| r.metric(m).map(fmt_value).unwrap_or_else(|| "-".into())));
            row.push(r.summary.as_ref().map(|s| format!("{:.2}", s.wall_seconds)).unwrap_or_default());
            row
        })
        .collect();
    report::write_table(&report::Table { title: t.title.clone(), headers, rows }, &tables.join(&t.id))?;
    Ok(Block::Table {
        md_path: format!("tables/{}.md", t.id),
        caption: if t.info.caption.is_empty() { t.title.clone() } else { t.info.caption.clone() },
    })
}

/// A snapshot's time in seconds for titles and text: `decimals` decimals, or three
/// significant digits in scientific notation for times below 0.01 s (an impact's
/// microseconds).
fn time_text(t: f64, decimals: usize) -> String {
    if t != 0.0 && t.abs() < 0.01 {
        format!("{t:.2e}")
    } else {
        format!("{t:.decimals$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::registry;
    use crate::automation::report::testutil::check_figure;
    use crate::solver::output::machine::Machine;
    use crate::solver::output::summary::Provenance;
    use std::collections::BTreeMap;

    const SRC: &str = r#"
title = "t"
scene = "taylor_green"
paper = "ctvf"
section = "4.2 Lid driven cavity"
[presets.quick]
nx = [12, 16]
[presets.paper]
nx = [20, 24]
[[cases]]
name = "nx{nx}"
grid = { nx = "$nx" }
[[figures]]
id = "prof_u"
number = "Fig. 14a"
paper_caption = "u against y."
kind = "profile"
title = "u on x = 0.5"
file = "centerline_u.csv"
x = "u"
y = "y"
x_label = "u / U (-)"
y_label = "y / L (-)"
label = ["nx"]
metric = "l1_velocity_final"
reference = { file = "ref.csv", x = "Re100", y = "y", label = "Ghia et al. 1982" }
caption = "u profiles"
[[claims]]
figure = "prof_u"
claim = "It converges."
preset = "quick"
test = { metric = "l1_velocity_final", decreasing = "nx" }
source = "The paper's words."
[[claims]]
figure = "prof_u"
claim = "It is close."
preset = "quick"
test = { metric = "l1_velocity_final", max = 0.15 }
source = "A marker's size."
[[claims]]
figure = "prof_u"
claim = "It is close at the paper's lattices."
test = { metric = "l1_velocity_final", max = 0.15 }
source = "A marker's size."
[[claims]]
figure = "prof_u"
claim = "It is off."
preset = "quick"
test = { metric = "l1_velocity_final", min = 0.05 }
source = "A marker's size."
"#;

    /// The trade figures' note on the kinds of CPU of their wall times: one, several (with
    /// results that predate the record), none.
    #[test]
    fn the_wall_times_name_their_kinds_of_cpu() {
        let here = Machine::detect();
        let other = Machine { cpu_model: here.cpu_model + 1, ..here.clone() };
        assert_eq!(trade::machines_note([&here, &here]), format!(" Wall times on {}.", here.cpu()));
        let mixed = trade::machines_note([&here, &other, &Machine::default()]);
        assert!(
            mixed.starts_with(" Wall times from 3 kinds of CPU (") && mixed.contains("not recorded"),
            "{mixed}"
        );
        assert_eq!(trade::machines_note([]), "");
    }

    /// The summary of a Taylor-Green case of `particles` that completed ten steps to t = 1
    /// with `l1_velocity_final` = `l1`.
    fn completed(params: BTreeMap<String, serde_json::Value>, particles: usize, l1: f64) -> Summary {
        Summary {
            scene: "taylor_green".into(),
            params,
            particles,
            bodies: BTreeMap::from([("fluid".to_string(), particles)]),
            steps: 10,
            final_time: 1.0,
            wall_seconds: 0.1,
            cpu_seconds: None,
            particle_steps_per_second: 1.0,
            threads: 1,
            wavefront_steps: 0,
            status: Status::Completed,
            reason: None,
            step: None,
            metrics: [("l1_velocity_final".to_string(), l1)].into(),
            undefined_metrics: Vec::new(),
            provenance: Provenance::now(chrono::Utc::now()),
        }
    }

    /// The trade figure's cost axis is CPU time when every drawn case recorded it, and wall
    /// time (said on the axis and in the table) while one has not.
    #[test]
    fn the_trade_is_drawn_against_cpu_time_where_recorded() {
        let src = r#"
title = "t"
scene = "taylor_green"
paper = "ctvf"
[presets.quick]
nx = [12, 16]
[[cases]]
name = "nx{nx}"
grid = { nx = "$nx" }
[[figures]]
id = "trade"
kind = "trade"
title = "Trade"
x = "nx"
label = ["scheme"]
metric = "l1_velocity_final"
caption = "Cost."
"#;
        let root = tempfile::tempdir().unwrap();
        let (output, manuscript) = (root.path().join("output"), root.path().join("manuscript"));
        let p = registry::parse(&root.path().join("problems/t.toml"), src, "quick").unwrap();
        let write = |cpu: [Option<f64>; 2]| {
            for (c, cpu) in p.cases.iter().zip(cpu) {
                let e = Entry::new(&output, &p, c);
                std::fs::create_dir_all(&e.dir).unwrap();
                Summary { cpu_seconds: cpu, ..completed(c.params.to_json(), 144, 0.1) }
                    .write(&e.dir)
                    .unwrap();
            }
            regenerate(&p, &output, &manuscript).unwrap();
            std::fs::read_to_string(manuscript.join("tables/trade.md")).unwrap()
        };
        let table = write([Some(0.25), Some(0.5)]);
        assert!(
            table.contains("CPU time (s)") && table.contains("0.25") && !table.contains("wall time"),
            "{table}"
        );
        let table = write([Some(0.25), None]);
        assert!(table.contains("wall time (s)") && table.contains("0.10"), "{table}");
    }

    /// A comparative claim over a study holds at each of its resolutions, not on the mean:
    /// IPST lower than SPST on average but higher at one lattice is not reproduced, and the
    /// verdict names the lattice; with a margin the ratio must clear it at every lattice.
    #[test]
    fn a_comparison_holds_at_each_resolution() {
        let src = |factor: f64| {
            format!(
                r#"
title = "t"
scene = "taylor_green"
paper = "ctvf"
[presets.quick]
nx = [12, 16]
[[cases]]
name = "{{pst}}-nx{{nx}}"
params = {{ scheme = "ctvf" }}
grid = {{ nx = "$nx", pst = ["sun", "ipst"] }}
[[tables]]
id = "l1"
title = "L1"
columns = ["nx", "pst"]
metrics = ["l1_velocity_final"]
caption = "L1."
[[claims]]
figure = "l1"
claim = "IPST is better."
preset = "quick"
test = {{ metric = "l1_velocity_final", lower = {{ where = {{ pst = "ipst" }} }}, higher = {{ where = {{ pst = "sun" }} }}, factor = {factor} }}
source = "The paper's words."
"#
            )
        };
        let root = tempfile::tempdir().unwrap();
        let output = root.path().join("output");
        let judge_with = |factor: f64, l1: [(&str, f64); 4]| {
            let p = registry::parse(&root.path().join("problems/c.toml"), &src(factor), "quick").unwrap();
            for c in &p.cases {
                let e = Entry::new(&output, &p, c);
                std::fs::create_dir_all(&e.dir).unwrap();
                let v = l1.iter().find(|(n, _)| *n == c.name).unwrap().1;
                completed(c.params.to_json(), 144, v).write(&e.dir).unwrap();
            }
            judge(&p, &p.claims[0], &output).own
        };
        // Mean IPST 0.15 against SPST 0.2, but IPST is the higher at 16 x 16.
        let j =
            judge_with(1.0, [("sun-nx12", 0.35), ("ipst-nx12", 0.1), ("sun-nx16", 0.05), ("ipst-nx16", 0.2)]);
        assert_eq!(j.verdict, Verdict::NotReproduced, "{}", j.detail);
        assert!(j.detail.contains("16 x 16: IPST") && j.detail.contains("> "), "{}", j.detail);
        let j =
            judge_with(1.0, [("sun-nx12", 0.35), ("ipst-nx12", 0.1), ("sun-nx16", 0.3), ("ipst-nx16", 0.2)]);
        assert_eq!(j.verdict, Verdict::Reproduced, "{}", j.detail);
        // A margin of 0.5: 0.2 / 0.3 does not clear it.
        let j =
            judge_with(0.5, [("sun-nx12", 0.35), ("ipst-nx12", 0.1), ("sun-nx16", 0.3), ("ipst-nx16", 0.2)]);
        assert_eq!(j.verdict, Verdict::NotReproduced, "{}", j.detail);
        assert!(j.detail.contains("(ratio 0.67)"), "{}", j.detail);
    }

    /// A profile figure: one curve per case that has a result and the file, the reference
    /// drawn as points, the manuscript's numbers and the verdicts on the figure's claims:
    /// met, missed (with the number), and not run (the paper's lattices have no result, with
    /// an estimate scaled from a result, and the quick preset's verdict beside it).
    #[test]
    fn profile_figure_and_the_verdicts_on_its_claims() {
        let root = tempfile::tempdir().unwrap();
        let root = root.path();
        std::fs::create_dir_all(root.join("reference_data")).unwrap();
        std::fs::write(root.join("reference_data/ref.csv"), "y,Re100\n0.0,0.0\n0.5,-0.2\n1.0,1.0\n").unwrap();
        let p = registry::parse(&root.join("problems/cav.toml"), SRC, "quick").unwrap();
        let output = root.join("output");
        for (c, err) in p.cases.iter().zip([0.2, 0.1]) {
            let e = Entry::new(&output, &p, c);
            std::fs::create_dir_all(&e.dir).unwrap();
            let ys: Vec<f64> = (0..=10).map(|i| i as f64 / 10.0).collect();
            let mut csv = String::from("y,u\n");
            for y in &ys {
                csv += &format!("{y},{}\n", y * y - 0.3 * y + err);
            }
            std::fs::write(e.dir.join("centerline_u.csv"), csv).unwrap();
            completed(c.params.to_json(), 144, err).write(&e.dir).unwrap();
        }
        let manuscript = root.join("manuscript");
        let r = regenerate(&p, &output, &manuscript).unwrap();
        check_figure(
            &manuscript.join("figures/prof_u"),
            (900, 600),
            &["u on x = 0.5", "12 x 12", "16 x 16", "Ghia et al. 1982", "u / U (-)", "y / L (-)"],
        );
        let it = &r.items[0];
        assert_eq!((it.item.heading.as_str(), it.item.paper_caption.as_str()), ("Fig. 14a", "u against y."));
        let Block::Image { ours, .. } = &it.item.blocks[0] else { panic!() };
        assert!(ours.contains("12 x 12: 0.200") && ours.contains("16 x 16: 0.100"), "{ours}");
        let v: Vec<&ClaimVerdict> = r.verdicts.iter().collect();
        assert_eq!(v[0].own.verdict, Verdict::Reproduced, "{:?}", v[0]);
        assert!(v[0].own.detail.contains("12 x 12: 0.200 then 16 x 16: 0.100"), "{}", v[0].own.detail);
        assert_eq!(v[1].own.verdict, Verdict::NotReproduced);
        assert!(v[1].own.detail.contains("12 x 12: 0.200 > 0.15; 16 x 16: 0.100."), "{}", v[1].own.detail);
        assert_eq!(v[2].own.verdict, Verdict::NotRun);
        assert!(
            v[2].own.detail.contains("`nx20`") && v[2].own.detail.contains("scaled from `nx16`"),
            "{}",
            v[2].own.detail
        );
        let other = v[2].other.as_ref().expect("the quick preset's verdict");
        assert_eq!((other.preset.as_str(), other.verdict), ("quick", Verdict::NotReproduced));
        let md = v[2].markdown();
        assert!(
            md.contains("**Verdict: not run** at the paper's resolutions")
                && md.contains("At the `quick` preset, not the paper's resolutions: not reproduced"),
            "{md}"
        );
        assert_eq!(r.items[0].item.verdicts.len(), 4);

        // A case without its result is left out of the figure and named as missing; the
        // claims on it are not run.
        let e = Entry::new(&output, &p, &p.cases[1]);
        std::fs::remove_file(e.dir.join("summary.json")).unwrap();
        let r = regenerate(&p, &output, &manuscript).unwrap();
        let svg = std::fs::read_to_string(manuscript.join("figures/prof_u.svg")).unwrap();
        assert!(!svg.contains("16 x 16"));
        let Block::Image { ours, .. } = &r.items[0].item.blocks[0] else { panic!() };
        assert!(ours.contains("No result for: nx16"), "{ours}");
        assert_eq!(r.verdicts[0].own.verdict, Verdict::NotRun);
        // ... unless a case that has run already fails the test: "within 0.15 in every
        // case" is false whatever nx16 gives; "at least 0.05" waits for it.
        let (v1, v3) = (&r.verdicts[1].own, &r.verdicts[3].own);
        assert_eq!((v1.verdict, v3.verdict), (Verdict::NotReproduced, Verdict::NotRun));
        assert!(
            v1.detail.contains("12 x 12: 0.200 > 0.15")
                && v1.detail.contains("no result for 1 of the 2 case(s)"),
            "{}",
            v1.detail
        );

        // A diverged case is a result without metrics: the claim is not reproduced, and says
        // where it blew up.
        Summary {
            steps: 4,
            final_time: 0.19,
            status: Status::Diverged,
            reason: Some("NaN".into()),
            step: Some(4),
            metrics: BTreeMap::new(),
            undefined_metrics: Vec::new(),
            ..completed(p.cases[1].params.to_json(), 256, 0.0)
        }
        .write(&e.dir)
        .unwrap();
        let r = regenerate(&p, &output, &manuscript).unwrap();
        assert_eq!(r.verdicts[0].own.verdict, Verdict::NotReproduced);
        assert!(
            r.verdicts[0].own.detail.contains("16 x 16: diverged at t = 0.190 s (NaN)"),
            "{}",
            r.verdicts[0].own.detail
        );

        // A diverged case that kept the metric as a running record: a lower bound it passed
        // before blowing up holds; an upper bound is not met by a run that blew up.
        Summary {
            steps: 4,
            final_time: 0.19,
            status: Status::Diverged,
            reason: Some("NaN".into()),
            step: Some(4),
            metrics: [("l1_velocity_final".to_string(), 0.1)].into(),
            undefined_metrics: Vec::new(),
            ..completed(p.cases[1].params.to_json(), 256, 0.0)
        }
        .write(&e.dir)
        .unwrap();
        let r = regenerate(&p, &output, &manuscript).unwrap();
        let v: Vec<&Judgement> = r.verdicts.iter().map(|v| &v.own).collect();
        assert_eq!((v[1].verdict, v[3].verdict), (Verdict::NotReproduced, Verdict::Reproduced), "{v:?}");
        assert!(
            v[1].detail.contains("16 x 16: 0.100 before it diverged at t = 0.190 s (NaN)"),
            "{}",
            v[1].detail
        );
    }

    /// A finished case with snapshots at t = 0, 0.5004 and 1.0 (pressure 0, 1, 2 and a
    /// normal at two particles of the middle one), written by the solver's own writers, and
    /// a wall.
    fn case_with_snapshots(output: &Path, p: &Problem) -> Entry {
        use crate::solver::output::vtu::{write_vtu, Field, Series};
        let e = Entry::new(output, p, &p.cases[0]);
        std::fs::create_dir_all(&e.dir).unwrap();
        let pts: Vec<[f64; 3]> = (0..4).map(|i| [i as f64 * 0.1, 0.0, 0.0]).collect();
        let mut series = Series::new(e.dir.join("fluid.pvd"));
        let mut walls = Series::new(e.dir.join("wall.pvd"));
        for (k, t) in [0.0, 0.5004, 1.0].into_iter().enumerate() {
            let file = format!("fluid_{k:05}.vtu");
            let normal: Vec<[f64; 3]> =
                (0..4).map(|i| if k == 1 && i >= 2 { [0.0, 1.0, 0.0] } else { [0.0; 3] }).collect();
            write_vtu(
                &e.dir.join(&file),
                &pts,
                &[
                    Field::Scalar("pressure", vec![k as f64; 4]),
                    Field::Vector("normal", normal),
                    Field::Int("free_surface", vec![1, 0, 1, 0]),
                    Field::Int("near_surface", vec![1, 1, 1, 0]),
                ],
            )
            .unwrap();
            series.push(t, &file).unwrap();
            let wfile = format!("wall_{k:05}.vtu");
            let wpts: Vec<[f64; 3]> = (0..5).map(|i| [i as f64 * 0.1, -0.1, 0.0]).collect();
            write_vtu(&e.dir.join(&wfile), &wpts, &[Field::Scalar("pressure", vec![0.0; 5])]).unwrap();
            walls.push(t, &wfile).unwrap();
        }
        completed(p.cases[0].params.to_json(), 4, 0.1).write(&e.dir).unwrap();
        e
    }

    const PARTICLES: &str = r#"
title = "t"
scene = "taylor_green"
paper = "ctvf"
section = "4.3 2D dam break"
[presets.quick]
tf = 1.0
[[cases]]
name = "one"
params = { tf = "$tf" }
[[figures]]
id = "p_t06"
number = "Fig. 17a"
paper_caption = "At t = 0.6 s."
kind = "particles"
title = "pressure"
field = "pressure"
time = 0.6
arrows = "normal"
[[figures]]
id = "p_last"
number = "Fig. 17b"
paper_caption = "At the end."
kind = "particles"
title = "pressure, last"
field = "pressure"
[[figures]]
id = "p_sum"
kind = "particles"
title = "surface and near it"
field = "2*free_surface+near_surface"
"#;

    /// `time` picks the snapshot nearest it, `arrows` overlays the vector array where it
    /// is non-zero, the walls are drawn; without them the last snapshot is drawn, plain. The
    /// panels of one figure share their axes and colour scale; a field may be a sum.
    #[test]
    fn particles_at_a_time_with_arrows_and_walls() {
        let root = tempfile::tempdir().unwrap();
        let root = root.path();
        let p = registry::parse(&root.join("problems/pp.toml"), PARTICLES, "quick").unwrap();
        assert_eq!(
            p.figures[0].kind,
            FigureKind::Particles {
                field: "pressure".into(),
                time: Some(0.6),
                arrows: Some("normal".into()),
                view: None
            }
        );
        let output = root.join("output");
        case_with_snapshots(&output, &p);
        let manuscript = root.join("manuscript");
        let r = regenerate(&p, &output, &manuscript).unwrap();
        let Block::Image { ours, .. } = &r.items[0].item.blocks[0] else { panic!() };
        assert!(ours.contains("at t = 0.500 s (the snapshot nearest t = 0.6 s)"), "{ours}");
        assert!(ours.contains("p from 1 to 1 Pa"), "{ours}");
        assert!(ours.contains("`normal` drawn as arrows at 2 of the 2 particles"), "{ours}");
        let svg = check_figure(
            &manuscript.join("figures/p_t06"),
            (900, 720),
            &["pressure (t = 0.50 s)", "x (m)", "y (m)"],
        );
        assert_eq!(svg.matches("stroke=\"#D73027\"").count(), 2);
        assert!(svg.contains("#969696"), "walls drawn");
        let Block::Image { ours, .. } = &r.items[1].item.blocks[0] else { panic!() };
        assert!(ours.contains("at t = 1.000 s.") && ours.contains("from 2 to 2"), "{ours}");
        let svg =
            check_figure(&manuscript.join("figures/p_last"), (900, 720), &["pressure, last (t = 1.00 s)"]);
        assert!(!svg.contains("#D73027"));
        // Both panels of Fig. 17 on one colour scale, 1 to 2: alone, the first would span
        // 0.5 to 1.5 (no tick at 1.8) and the second 1.5 to 2.5 (none at 1.2).
        for (id, tick) in [("p_t06", "1.8"), ("p_last", "1.2")] {
            let svg = std::fs::read_to_string(manuscript.join(format!("figures/{id}.svg"))).unwrap();
            assert!(svg.lines().any(|l| l.trim() == tick), "{id}: shared colour range");
        }
        let svg = std::fs::read_to_string(manuscript.join("figures/p_sum.svg")).unwrap();
        assert!(
            svg.contains("2: surface, 1: near it, 0: inside") && svg.lines().any(|l| l.trim() == "3"),
            "a sum with a factor: 0 to 3"
        );

        // Nearest, ties to the first; no time: the last.
        let list: Vec<(f64, String)> = [0.0, 0.5, 1.0].iter().map(|t| (*t, format!("{t}"))).collect();
        assert_eq!(snapshot::pick_snapshot(&list, Some(0.25)).0, 0.0);
        assert_eq!(snapshot::pick_snapshot(&list, Some(0.26)).0, 0.5);
        assert_eq!(snapshot::pick_snapshot(&list, Some(7.0)).0, 1.0);
        assert_eq!(snapshot::pick_snapshot(&list, None).0, 1.0);

        // An arrows array that is not a vector, or missing, names the file and the array.
        let dir = Entry::new(&output, &p, &p.cases[0]).dir;
        let e = snapshot::snapshot(&dir, "pressure", None, Some("pressure"));
        assert!(e.err().unwrap().contains("not 3 per point"));
        let e = snapshot::snapshot(&dir, "pressure", None, Some("nope"));
        assert!(e.err().unwrap().contains("no point array `nope`"));

        // A snapshot kept gzip-compressed is read as well; one that is not there at all
        // leaves the figure undrawn, saying why.
        let raw = std::fs::read(dir.join("fluid_00002.vtu")).unwrap();
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        std::io::Write::write_all(&mut gz, &raw).unwrap();
        std::fs::write(dir.join("fluid_00002.vtu.gz"), gz.finish().unwrap()).unwrap();
        std::fs::remove_file(dir.join("fluid_00002.vtu")).unwrap();
        assert!(snapshot::snapshot(&dir, "pressure", None, None).unwrap().is_some());
        std::fs::remove_file(dir.join("fluid_00002.vtu.gz")).unwrap();
        let r = regenerate(&p, &output, &manuscript).unwrap();
        let Block::Missing { why, .. } = &r.items[1].item.blocks[0] else { panic!() };
        assert!(why.contains("snapshot") && why.contains("not among the results"), "{why}");
    }

    /// `time` after a selected case's end time, a negative time, and `time` or `arrows`
    /// on another kind are errors naming the key.
    #[test]
    fn particles_time_and_arrows_are_checked() {
        let path = Path::new("x.toml");
        let e = registry::parse(path, &PARTICLES.replace("time = 0.6", "time = 1.5"), "quick").unwrap_err();
        assert!(e.contains("figures.p_t06.time") && e.contains("after the end time tf = 1"), "{e}");
        let e = registry::parse(path, &PARTICLES.replace("time = 0.6", "time = -1.0"), "quick").unwrap_err();
        assert!(e.contains("figures.p_t06.time"), "{e}");
        let e = registry::parse(
            path,
            &PARTICLES.replace(
                "kind = \"particles\"\ntitle = \"pressure\"\n",
                "kind = \"timeseries\"\ntitle = \"pressure\"\ny = \"u_max\"\n",
            ),
            "quick",
        )
        .unwrap_err();
        assert!(e.contains("only kind `particles` takes"), "{e}");
        let src = format!("{PARTICLES}x_spacing = true\n");
        let e = registry::parse(path, &src, "quick").unwrap_err();
        assert!(e.contains("only kind `trade` takes `x_spacing`"), "{e}");
    }

    #[test]
    fn values_print_as_they_read() {
        assert_eq!(fmt_value(3.0), "3");
        assert_eq!(fmt_value(0.0724), "0.0724");
        assert_eq!(fmt_value(0.168), "0.168");
        assert_eq!(fmt_value(123.4), "123");
        assert_eq!(fmt_value(4.8e-5), "4.80e-5");
        assert_eq!(fmt_bound(0.04), "0.04");
        assert_eq!(fmt_bound(1e-12), "1e-12");
    }
}
