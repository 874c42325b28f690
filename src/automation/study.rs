//! Post-processing: the figures and tables a problem declares, drawn from cached results
//! (`summary.json`, `timeseries.csv`, the last `.vtu` snapshot), with the manuscript's
//! comparison line per figure: what the paper shows, what we got (numbers from the
//! summaries) and whether the paper's claim holds here. Also the two reusable studies:
//! the speed-accuracy trade (error against wall time and particle-steps, Pareto front,
//! observed orders of convergence) and stability maps (stable / inaccurate / diverged).

use super::cache::Entry;
use super::registry::{Case, Figure, FigureKind, Problem, Select, Table};
use super::report::{self, Item, Outcome, Section, Series, SeriesStyle};
use crate::solver::output::machine::Machine;
use crate::solver::output::summary::{Status, Summary};
use std::collections::BTreeMap;
use std::path::Path;

/// A selected case with its cached summary, if done.
struct Run<'a> {
    case: &'a Case,
    entry: Entry,
    summary: Option<Summary>,
}

fn runs<'a>(output: &Path, p: &'a Problem, s: &Select) -> Vec<Run<'a>> {
    s.pick(&p.cases)
        .into_iter()
        .map(|c| {
            let entry = Entry::new(output, p, c);
            let summary =
                entry.summary().filter(|s| matches!(s.status, Status::Completed | Status::Diverged));
            Run { case: c, entry, summary }
        })
        .collect()
}

/// `key = value, ...` of the `keys` parameters of `case` (its name if none).
fn label(case: &Case, keys: &[String]) -> String {
    if keys.is_empty() {
        return case.name.clone();
    }
    keys.iter()
        .map(|k| format!("{k} = {}", case.params.0.get(k).map(|v| v.to_string()).unwrap_or_default()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Values of the `keys` parameters joined by `/` (a curve group).
fn group(case: &Case, keys: &[String]) -> String {
    keys.iter()
        .map(|k| case.params.0.get(k).map(|v| v.to_string()).unwrap_or_default())
        .collect::<Vec<_>>()
        .join("/")
}

fn param_f64(case: &Case, key: &str) -> f64 {
    match case.params.0.get(key) {
        Some(crate::scenes::params::Value::Int(i)) => *i as f64,
        Some(crate::scenes::params::Value::Float(x)) => *x,
        _ => f64::NAN,
    }
}

fn metric(r: &Run, m: &str) -> Option<f64> {
    r.summary.as_ref().and_then(|s| s.metrics.get(m).copied())
}

fn fmt(x: f64) -> String {
    format!("{x:.3e}")
}

/// Reads columns `t` and `y` of a case's `timeseries.csv`; an unreadable one is a damaged
/// result, which the error says how to compute again.
fn timeseries(p: &Problem, r: &Run, y: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
    columns(&r.entry.dir.join("timeseries.csv"), "t", y).map_err(|e| {
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
        let a: f64 = rec[it].trim().parse().unwrap_or(f64::NAN);
        let b: f64 = rec[iy].trim().parse().unwrap_or(f64::NAN);
        t.push(a);
        v.push(b);
    }
    Ok((t, v))
}

/// The text of the first `<DataArray ...>` after `from` whose tag contains `tag_has`.
fn data_array<'a>(xml: &'a str, from: usize, tag_has: &str) -> Option<&'a str> {
    let mut at = from;
    loop {
        let i = at + xml[at..].find("<DataArray")?;
        let close = i + xml[i..].find('>')?;
        if xml[i..close].contains(tag_has) {
            let end = close + xml[close..].find("</DataArray>")?;
            return Some(&xml[close + 1..end]);
        }
        at = close;
    }
}

/// One snapshot of a case read for a particle figure.
struct Snapshot {
    x: Vec<f64>,
    y: Vec<f64>,
    value: Vec<f64>,
    /// x and y components of the `arrows` array, if asked for.
    arrows: Option<(Vec<f64>, Vec<f64>)>,
    /// Its time.
    t: f64,
}

/// The snapshots listed in `fluid.pvd`: (time, file), in file order.
fn pvd_entries(dir: &Path) -> Result<Vec<(f64, String)>, String> {
    let pvd = dir.join("fluid.pvd");
    let s = std::fs::read_to_string(&pvd).map_err(|e| format!("{}: {e}", pvd.display()))?;
    let list: Vec<(f64, String)> = s
        .lines()
        .filter_map(|l| {
            let f = l.split("file=\"").nth(1)?.split('"').next()?;
            let t: f64 = l.split("timestep=\"").nth(1)?.split('"').next()?.parse().ok()?;
            Some((t, f.to_string()))
        })
        .collect();
    if list.is_empty() {
        return Err(format!("{}: no snapshot listed", pvd.display()));
    }
    Ok(list)
}

/// The entry nearest `time` (the first of equally near ones), or the last one.
fn pick_snapshot(list: &[(f64, String)], time: Option<f64>) -> &(f64, String) {
    match time {
        None => list.last().expect("non-empty"),
        Some(t) => {
            list.iter().fold(&list[0], |best, e| if (e.0 - t).abs() < (best.0 - t).abs() { e } else { best })
        }
    }
}

/// Points (x, y), the scalar point array `field` and the x, y components of the vector
/// point array `arrows` of the snapshot listed in `fluid.pvd` nearest `time` (the last one
/// without a time).
fn snapshot(dir: &Path, field: &str, time: Option<f64>, arrows: Option<&str>) -> Result<Snapshot, String> {
    let list = pvd_entries(dir)?;
    let (t, file) = pick_snapshot(&list, time).clone();
    let path = dir.join(&file);
    let xml = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let nums = |s: &str| -> Vec<f64> { s.split_whitespace().filter_map(|x| x.parse().ok()).collect() };
    let array = |name: &str| {
        data_array(&xml, 0, &format!("Name=\"{name}\""))
            .map(nums)
            .ok_or_else(|| format!("{}: no point array `{name}`", path.display()))
    };
    let value = array(field)?;
    let pts_at = xml.find("<Points>").ok_or_else(|| format!("{}: no <Points>", path.display()))?;
    let pts = data_array(&xml, pts_at, "DataArray")
        .map(nums)
        .ok_or_else(|| format!("{}: unreadable <Points>", path.display()))?;
    let x: Vec<f64> = pts.iter().step_by(3).copied().collect();
    let y = pts.iter().skip(1).step_by(3).copied().collect();
    let arrows = match arrows {
        None => None,
        Some(a) => {
            let v = array(a)?;
            if v.len() != 3 * x.len() {
                return Err(format!(
                    "{}: point array `{a}` has {} values, not 3 per point ({} points)",
                    path.display(),
                    v.len(),
                    x.len()
                ));
            }
            Some((v.iter().step_by(3).copied().collect(), v.iter().skip(1).step_by(3).copied().collect()))
        }
    };
    Ok(Snapshot { x, y, value, arrows, t })
}

/// Regenerates the figures and tables of `p` from the results under `output` into
/// `manuscript/figures` and `manuscript/tables`; returns the manuscript section.
pub fn regenerate(p: &Problem, output: &Path, manuscript: &Path) -> Result<Section, String> {
    let figures = manuscript.join("figures");
    let tables = manuscript.join("tables");
    // A figure that cannot be drawn does not keep the others (or the tables) from being
    // drawn; every failure is reported, named by the problem file and the figure or table.
    let mut items = Vec::new();
    let mut errors = Vec::new();
    for f in &p.figures {
        match figure(p, f, output, &figures, &tables) {
            Ok(drawn) => items.extend(drawn),
            Err(e) => errors.push(format!("{}: figures.{}: {e}", p.path.display(), f.id)),
        }
    }
    for t in &p.tables {
        match metrics_table(p, t, output, &tables) {
            Ok(table) => items.push(table),
            Err(e) => errors.push(format!("{}: tables.{}: {e}", p.path.display(), t.id)),
        }
    }
    if !errors.is_empty() {
        return Err(errors.join("\n"));
    }
    Ok(Section {
        title: p.title.clone(),
        text: format!(
            "{}\n\nProblem file `problems/{}.toml`, preset `{}`, {} case(s).",
            p.description.trim(),
            p.name,
            p.preset,
            p.cases.len()
        ),
        items,
    })
}

fn missing_note(rs: &[Run]) -> String {
    let m: Vec<_> = rs.iter().filter(|r| r.summary.is_none()).map(|r| r.case.name.as_str()).collect();
    if m.is_empty() {
        String::new()
    } else {
        format!(" No result for: {}.", m.join(", "))
    }
}

/// The kinds of CPU the wall times of a figure were measured on (the cache keeps results
/// from machine to machine): wall times compare only within one.
fn machines_note<'a>(machines: impl IntoIterator<Item = &'a Machine>) -> String {
    let mut kinds: Vec<String> = machines.into_iter().map(Machine::cpu).collect();
    kinds.sort();
    kinds.dedup();
    match kinds.as_slice() {
        [] => String::new(),
        [one] => format!(" Wall times on {one}."),
        many => format!(
            " Wall times from {} kinds of CPU ({}): compare them only within one.",
            many.len(),
            many.join("; ")
        ),
    }
}

/// Why a claim over `rs` cannot be judged: the cases that diverged (a result, but no
/// metric at the end time), else missing results.
fn unjudged(f: &Figure, rs: &[Run]) -> String {
    let diverged: Vec<String> = rs
        .iter()
        .filter(|r| r.summary.as_ref().is_some_and(|s| s.status == Status::Diverged))
        .map(|r| label(r.case, &f.label))
        .collect();
    if diverged.is_empty() {
        "results are missing".into()
    } else {
        format!("diverged before the end time: {}", diverged.join(", "))
    }
}

/// Numbers per case and the verdict on the figure's claim.
fn ours(f: &Figure, rs: &[Run]) -> String {
    let Some(m) = &f.metric else {
        return format!("{} case(s) drawn.{}", rs.len(), missing_note(rs));
    };
    let mut parts: Vec<String> = rs
        .iter()
        .map(|r| match (&r.summary, metric(r, m)) {
            (_, Some(v)) => format!("{}: {}", label(r.case, &f.label), fmt(v)),
            (Some(s), None) => format!(
                "{}: {:?} at t = {:.3} ({})",
                label(r.case, &f.label),
                s.status,
                s.final_time,
                s.reason.clone().unwrap_or_default()
            ),
            (None, None) => format!("{}: no result", label(r.case, &f.label)),
        })
        .collect();
    let mut text = format!("`{m}`: {}.", std::mem::take(&mut parts).join("; "));
    if f.converges {
        let key = f.label.last().expect("validated");
        let mut pts: Vec<(f64, Option<f64>)> =
            rs.iter().map(|r| (param_f64(r.case, key), metric(r, m))).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let vals: Vec<f64> = pts.iter().filter_map(|x| x.1).collect();
        if vals.len() < pts.len() || vals.len() < 2 {
            text += &format!(" The convergence claim cannot be judged: {}.", unjudged(f, rs));
        } else if vals.windows(2).all(|w| w[1] < w[0]) {
            text += &format!(" Reproduced: `{m}` decreases as `{key}` grows.");
        } else {
            text += &format!(
                " **Not reproduced:** `{m}` does not decrease monotonically as `{key}` grows ({}).",
                vals.iter().map(|v| fmt(*v)).collect::<Vec<_>>().join(", ")
            );
        }
    }
    if let Some((lo, hi)) = &f.lower_than {
        // Within the figure's cases.
        let mean = |s: &Select| {
            let v: Vec<f64> = rs.iter().filter(|r| s.matches(r.case)).filter_map(|r| metric(r, m)).collect();
            (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        };
        match (mean(lo), mean(hi)) {
            (Some(a), Some(b)) if a < b => {
                text += &format!(" Reproduced: {} < {} (ratio {:.2}).", fmt(a), fmt(b), b / a)
            }
            (Some(a), Some(b)) => {
                text += &format!(
                    " **Not reproduced:** the case the paper finds better has {} against {}.",
                    fmt(a),
                    fmt(b)
                )
            }
            _ => text += &format!(" The claim cannot be judged: {}.", unjudged(f, rs)),
        }
    }
    text + &missing_note(rs)
}

fn figure(
    p: &Problem,
    f: &Figure,
    output: &Path,
    figures: &Path,
    tables: &Path,
) -> Result<Vec<Item>, String> {
    let rs = runs(output, p, &f.select);
    let stem = figures.join(&f.id);
    let rel = |id: &str| format!("figures/{id}.png");
    let fig_item = |id: &str, caption: &str, ours: String| Item::Figure {
        path: rel(id),
        caption: caption.to_string(),
        paper: f.paper.clone(),
        ours,
    };
    let caption = if f.caption.is_empty() { f.title.clone() } else { f.caption.clone() };
    // The figure as curves of `series` against `x_label` (its y label, if not given, the
    // column `y`), and its item.
    let lines = |x_label: String, y: &String, series: Vec<Series>| -> Result<Vec<Item>, String> {
        let y_label = f.y_label.clone().unwrap_or_else(|| y.clone());
        let fig = report::LineFigure {
            title: f.title.clone(),
            x_label,
            y_label,
            log_x: false,
            log_y: f.log_y,
            series,
        };
        report::line_figure(&fig, &stem)?;
        Ok(vec![fig_item(&f.id, &caption, ours(f, &rs))])
    };
    match &f.kind {
        FigureKind::Timeseries { y, exact } => {
            let mut series = Vec::new();
            for r in rs.iter().filter(|r| r.entry.dir.join("timeseries.csv").exists()) {
                let (t, v) = timeseries(p, r, y)?;
                if series.is_empty() {
                    if let Some(ex) = exact {
                        let (t, v) = timeseries(p, r, ex)?;
                        series.push(Series { label: "exact".into(), x: t, y: v, style: SeriesStyle::Dashed });
                    }
                }
                series.push(Series { label: label(r.case, &f.label), x: t, y: v, style: SeriesStyle::Line });
            }
            lines("t (s)".into(), y, series)
        }
        FigureKind::Particles { field, time, arrows } => {
            let at = time.map(|t| format!(" at t = {t} s")).unwrap_or_default();
            let Some(r) = rs.iter().find(|r| r.summary.is_some()) else {
                report::particle_figure(
                    &report::ScatterField {
                        title: format!("{}{at} (no result)", f.title),
                        x: vec![],
                        y: vec![],
                        value: vec![],
                        value_label: field.clone(),
                        range: None,
                        aspect_equal: true,
                        arrows: None,
                    },
                    &stem,
                )?;
                return Ok(vec![fig_item(&f.id, &caption, missing_note(&rs))]);
            };
            let s = snapshot(&r.entry.dir, field, *time, arrows.as_deref())?;
            let t = s.t;
            let (lo, hi) =
                s.value.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
            let n_arrows = s.arrows.as_ref().map(|(u, v)| {
                u.iter().zip(v).filter(|(a, b)| a.hypot(**b) > 0.0 && a.is_finite() && b.is_finite()).count()
            });
            report::particle_figure(
                &report::ScatterField {
                    title: format!("{} (t = {t:.2} s)", f.title),
                    x: s.x,
                    y: s.y,
                    value: s.value,
                    value_label: with_unit(field),
                    range: None,
                    aspect_equal: true,
                    arrows: s.arrows.map(|(u, v)| report::Arrows { u, v, length: None }),
                },
                &stem,
            )?;
            let asked = match time {
                Some(want) if (want - t).abs() > 1e-9 => format!(" (nearest snapshot to t = {want} s)"),
                _ => String::new(),
            };
            let arrows_note = match (arrows, n_arrows) {
                (Some(a), Some(n)) => format!(" `{a}` drawn at {n} particle(s)."),
                _ => String::new(),
            };
            Ok(vec![fig_item(
                &f.id,
                &caption,
                format!(
                    "case {} at t = {t:.3} s{asked}: {field} from {} to {}.{arrows_note} {}",
                    r.case.name,
                    fmt(lo),
                    fmt(hi),
                    ours(f, std::slice::from_ref(r))
                ),
            )])
        }
        FigureKind::Profile { file, x, y, reference } => {
            let mut series = Vec::new();
            for r in rs.iter().filter(|r| r.summary.is_some() && r.entry.dir.join(file).exists()) {
                let (a, b) = columns(&r.entry.dir.join(file), x, y)?;
                series.push(Series { label: label(r.case, &f.label), x: a, y: b, style: SeriesStyle::Line });
            }
            if let Some(rf) = reference {
                series.push(Series {
                    label: rf.label.clone(),
                    x: rf.x.clone(),
                    y: rf.y.clone(),
                    style: SeriesStyle::Reference,
                });
            }
            lines(f.x_label.clone().unwrap_or_else(|| x.clone()), y, series)
        }
        FigureKind::Trade { x, spacing } => trade(f, &rs, x, *spacing, figures, tables, &caption),
        FigureKind::Stability { x, max } => stability(f, &rs, x, *max, figures, tables, &caption),
    }
}

/// A point array's name with its unit, for a colour bar.
fn with_unit(field: &str) -> String {
    let unit = match field {
        "pressure" | "pressure_deviation" | "pressure_exact" => " (Pa)",
        "speed" | "velocity" => " (m/s)",
        "density" => " (kg/m^3)",
        _ => "",
    };
    format!("{field}{unit}")
}

/// Error against wall time and against particle-steps, the Pareto front, and a table
/// with the observed order of convergence of each group along resolution `res`.
fn trade(
    f: &Figure,
    rs: &[Run],
    res: &str,
    spacing: bool,
    figures: &Path,
    tables: &Path,
    caption: &str,
) -> Result<Vec<Item>, String> {
    let m = f.metric.as_deref().expect("validated");
    let done: Vec<(&Run, f64, f64, f64)> = rs
        .iter()
        .filter_map(|r| {
            let s = r.summary.as_ref()?;
            let e = metric(r, m)?;
            Some((r, e, s.wall_seconds, s.particles as f64 * s.steps as f64))
        })
        .collect();
    let machines =
        machines_note(done.iter().map(|d| &d.0.summary.as_ref().expect("done").provenance.machine));
    let mut items = Vec::new();
    for (suffix, what, idx) in [("wall", "wall time (s)", 0), ("steps", "particle-steps (-)", 1)] {
        let id = format!("{}_{suffix}", f.id);
        let points = done
            .iter()
            .map(|(r, e, w, ps)| {
                (
                    group(r.case, &f.label),
                    format!("{res}={}", r.case.params.0[res]),
                    if idx == 0 { *w } else { *ps },
                    *e,
                )
            })
            .collect();
        report::pareto_figure(
            &report::ParetoFigure {
                title: format!("{}: {m} against {what}", f.title),
                x_label: what.into(),
                y_label: f.y_label.clone().unwrap_or_else(|| format!("{m} (-)")),
                points,
                log_x: true,
                log_y: true,
            },
            &figures.join(&id),
        )?;
        let front = report::pareto_front(
            &done.iter().map(|d| (if idx == 0 { d.2 } else { d.3 }, d.1)).collect::<Vec<_>>(),
        );
        let names: Vec<String> = front
            .iter()
            .map(|&i| format!("{} {res}={}", group(done[i].0.case, &f.label), done[i].0.case.params.0[res]))
            .collect();
        items.push(Item::Figure {
            path: format!("figures/{id}.png"),
            caption: format!("{caption} ({what})"),
            paper: f.paper.clone(),
            ours: format!(
                "Pareto front ({what}): {}.{}{}",
                if names.is_empty() { "none".into() } else { names.join("; ") },
                missing_note(rs),
                if idx == 0 { machines.as_str() } else { "" }
            ),
        });
    }
    // The table, with orders of convergence per group along `res`.
    let mut groups: BTreeMap<String, Vec<&(&Run, f64, f64, f64)>> = BTreeMap::new();
    for d in &done {
        groups.entry(group(d.0.case, &f.label)).or_default().push(d);
    }
    let front_w = report::pareto_front(&done.iter().map(|d| (d.2, d.1)).collect::<Vec<_>>());
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for (g, mut ds) in groups {
        ds.sort_by(|a, b| param_f64(a.0.case, res).total_cmp(&param_f64(b.0.case, res)));
        let h: Vec<f64> = ds
            .iter()
            .map(|d| if spacing { param_f64(d.0.case, res) } else { 1.0 / param_f64(d.0.case, res) })
            .collect();
        let e: Vec<f64> = ds.iter().map(|d| d.1).collect();
        let orders = report::observed_order(&h, &e);
        for (i, d) in ds.iter().enumerate() {
            let k = done.iter().position(|x| std::ptr::eq(x.0, d.0)).unwrap_or(usize::MAX);
            rows.push(vec![
                g.clone(),
                d.0.case.params.0[res].to_string(),
                d.0.summary.as_ref().map(|s| s.particles.to_string()).unwrap_or_default(),
                format!("{:.2}", d.2),
                fmt(d.3),
                fmt(d.1),
                if i == 0 {
                    "-".into()
                } else {
                    orders[i - 1].map(|o| format!("{o:.2}")).unwrap_or_else(|| "n/a".into())
                },
                if front_w.contains(&k) { "yes".into() } else { String::new() },
            ]);
        }
        let os: Vec<f64> = orders.iter().flatten().copied().collect();
        if os.len() >= 2 {
            let sign_change = os.windows(2).any(|w| w[0].signum() != w[1].signum());
            let spread = os.windows(2).any(|w| (w[0] - w[1]).abs() > 0.5 * w[0].abs().max(w[1].abs()));
            if sign_change || spread {
                notes.push(format!(
                    "{g}: orders {} {}: not in the asymptotic range.",
                    os.iter().map(|o| format!("{o:.2}")).collect::<Vec<_>>().join(", "),
                    if sign_change { "change sign" } else { "differ by more than 50%" }
                ));
            }
        } else if os.len() == 1 {
            notes.push(format!("{g}: one order ({:.2}) only: the asymptotic range cannot be judged.", os[0]));
        }
    }
    report::write_table(
        &report::Table {
            title: format!("{}: {m}, cost and observed order along {res}", f.title),
            headers: ["scheme", res, "particles", "wall (s)", "particle-steps", m, "order", "Pareto (wall)"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            rows,
        },
        &tables.join(&f.id),
    )?;
    items.push(Item::Table {
        md_path: format!("tables/{}.md", f.id),
        caption: format!(
            "{caption}: error, cost and observed order of convergence (order between consecutive {res})."
        ),
    });
    if !notes.is_empty() {
        items.push(Item::Text(notes.join(" ")));
    }
    Ok(items)
}

/// Outcome of one case for a stability map.
fn outcome(r: &Run, m: &str, max: f64) -> (Outcome, String) {
    match &r.summary {
        None => (Outcome::Missing, "no result".into()),
        Some(s) if s.status == Status::Diverged => (
            Outcome::Diverged,
            format!("diverged at t = {:.3}: {}", s.final_time, s.reason.clone().unwrap_or_default()),
        ),
        Some(s) => match s.metrics.get(m) {
            Some(v) if v.is_finite() && *v <= max => (Outcome::Stable, format!("{m} = {}", fmt(*v))),
            Some(v) => (Outcome::Inaccurate, format!("{m} = {} > {max}", fmt(*v))),
            None => (Outcome::Missing, format!("no `{m}`")),
        },
    }
}

fn stability(
    f: &Figure,
    rs: &[Run],
    x: &str,
    max: f64,
    figures: &Path,
    tables: &Path,
    caption: &str,
) -> Result<Vec<Item>, String> {
    let m = f.metric.as_deref().expect("validated");
    let mut xs: Vec<(f64, String)> = Vec::new();
    let mut ys: Vec<String> = Vec::new();
    for r in rs {
        let v = (param_f64(r.case, x), r.case.params.0[x].to_string());
        if !xs.iter().any(|a| a.1 == v.1) {
            xs.push(v);
        }
        let g = group(r.case, &f.label);
        if !ys.contains(&g) {
            ys.push(g);
        }
    }
    xs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut cells = Vec::new();
    let mut rows = Vec::new();
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for r in rs {
        let ix = xs.iter().position(|a| a.1 == r.case.params.0[x].to_string()).expect("listed");
        let g = group(r.case, &f.label);
        let iy = ys.iter().position(|a| *a == g).expect("listed");
        let (o, why) = outcome(r, m, max);
        *counts
            .entry(match o {
                Outcome::Stable => "stable",
                Outcome::Inaccurate => "inaccurate",
                Outcome::Diverged => "diverged",
                Outcome::Missing => "missing",
            })
            .or_default() += 1;
        cells.push((ix, iy, o, None));
        rows.push(vec![g, xs[ix].1.clone(), format!("{o:?}").to_lowercase(), why]);
    }
    report::outcome_map(
        &report::OutcomeMap {
            title: f.title.clone(),
            x_label: x.into(),
            y_label: f.label.join("/"),
            x_ticks: xs.iter().map(|a| a.1.clone()).collect(),
            y_ticks: ys,
            cells,
        },
        &figures.join(&f.id),
    )?;
    report::write_table(
        &report::Table {
            title: format!("{}: outcome per case (inaccurate: {m} > {max})", f.title),
            headers: vec![f.label.join("/"), x.into(), "outcome".into(), "detail".into()],
            rows,
        },
        &tables.join(&f.id),
    )?;
    Ok(vec![
        Item::Figure {
            path: format!("figures/{}.png", f.id),
            caption: caption.to_string(),
            paper: f.paper.clone(),
            ours: counts.iter().map(|(k, v)| format!("{v} {k}")).collect::<Vec<_>>().join(", ") + ".",
        },
        Item::Table {
            md_path: format!("tables/{}.md", f.id),
            caption: format!("{caption}: outcome per case."),
        },
    ])
}

fn metrics_table(p: &Problem, t: &Table, output: &Path, tables: &Path) -> Result<Item, String> {
    let rs = runs(output, p, &t.select);
    let mut headers: Vec<String> = vec!["case".into()];
    headers.extend(t.columns.iter().cloned());
    headers.push("status".into());
    headers.extend(t.metrics.iter().cloned());
    headers.push("wall (s)".into());
    let rows = rs
        .iter()
        .map(|r| {
            let mut row = vec![r.case.name.clone()];
            row.extend(t.columns.iter().map(|c| r.case.params.0[c].to_string()));
            row.push(
                r.summary
                    .as_ref()
                    .map(|s| format!("{:?}", s.status).to_lowercase())
                    .unwrap_or_else(|| "missing".into()),
            );
            row.extend(t.metrics.iter().map(|m| metric(r, m).map(fmt).unwrap_or_else(|| "-".into())));
            row.push(r.summary.as_ref().map(|s| format!("{:.2}", s.wall_seconds)).unwrap_or_default());
            row
        })
        .collect();
    report::write_table(&report::Table { title: t.title.clone(), headers, rows }, &tables.join(&t.id))?;
    Ok(Item::Table {
        md_path: format!("tables/{}.md", t.id),
        caption: if t.caption.is_empty() { t.title.clone() } else { t.caption.clone() },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::registry;
    use crate::automation::report::testutil::check_figure;
    use crate::solver::output::summary::Provenance;

    const SRC: &str = r#"
title = "t"
scene = "taylor_green"
[presets.quick]
nx = [12, 16]
[[cases]]
name = "nx{nx}"
grid = { nx = "$nx" }
[[figures]]
id = "prof_u"
kind = "profile"
title = "u on x = 0.5"
file = "centerline_u.csv"
x = "u"
y = "y"
x_label = "u / U (-)"
y_label = "y / L (-)"
label = ["nx"]
metric = "l1_velocity_final"
converges = true
reference = { file = "ref.csv", x = "Re100", y = "y", label = "Ghia et al. 1982" }
caption = "u profiles"
paper = "Fig. 14a"
"#;

    /// The trade figures' note on the kinds of CPU of their wall times: one, several (with
    /// results that predate the record), none.
    #[test]
    fn the_wall_times_name_their_kinds_of_cpu() {
        let here = Machine::detect();
        let other = Machine { cpu_model: here.cpu_model + 1, ..here.clone() };
        assert_eq!(machines_note([&here, &here]), format!(" Wall times on {}.", here.cpu()));
        let mixed = machines_note([&here, &other, &Machine::default()]);
        assert!(
            mixed.starts_with(" Wall times from 3 kinds of CPU (") && mixed.contains("not recorded"),
            "{mixed}"
        );
        assert_eq!(machines_note([]), "");
    }

    /// A profile figure: one curve per case that has a result and the file, the
    /// reference drawn as points, the manuscript line with the metric and the claim.
    #[test]
    fn profile_figure_from_case_files_and_reference() {
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
        let section = regenerate(&p, &output, &manuscript).unwrap();
        check_figure(
            &manuscript.join("figures/prof_u"),
            (900, 600),
            &["u on x = 0.5", "nx = 12", "nx = 16", "Ghia et al. 1982", "u / U (-)", "y / L (-)"],
        );
        let Item::Figure { ours, paper, .. } = &section.items[0] else { panic!() };
        assert_eq!(paper, "Fig. 14a");
        assert!(ours.contains("nx = 12: 2.000e-1") && ours.contains("Reproduced"), "{ours}");

        // A case without its file is left out of the figure and reported as missing.
        let e = Entry::new(&output, &p, &p.cases[1]);
        std::fs::remove_file(e.dir.join("summary.json")).unwrap();
        let section = regenerate(&p, &output, &manuscript).unwrap();
        let svg = std::fs::read_to_string(manuscript.join("figures/prof_u.svg")).unwrap();
        assert!(!svg.contains("nx = 16"));
        let Item::Figure { ours, .. } = &section.items[0] else { panic!() };
        assert!(ours.contains("No result for: nx16"), "{ours}");
        assert!(ours.contains("cannot be judged: results are missing"), "{ours}");

        // A diverged case is a result without metrics: the claim names it.
        Summary {
            steps: 4,
            final_time: 0.19,
            status: Status::Diverged,
            reason: Some("NaN".into()),
            step: Some(4),
            metrics: BTreeMap::new(),
            ..completed(p.cases[1].params.to_json(), 256, 0.0)
        }
        .write(&e.dir)
        .unwrap();
        let section = regenerate(&p, &output, &manuscript).unwrap();
        let Item::Figure { ours, .. } = &section.items[0] else { panic!() };
        assert!(ours.contains("cannot be judged: diverged before the end time: nx = 16"), "{ours}");
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
            particle_steps_per_second: 1.0,
            threads: 1,
            wavefront_steps: 0,
            status: Status::Completed,
            reason: None,
            step: None,
            metrics: [("l1_velocity_final".to_string(), l1)].into(),
            provenance: Provenance::now(chrono::Utc::now()),
        }
    }

    /// A finished case with snapshots at t = 0, 0.5004 and 1.0 (pressure 0, 1, 2 and a
    /// normal at two particles of the middle one), written by the solver's own writers.
    fn case_with_snapshots(output: &Path, p: &Problem) -> Entry {
        use crate::solver::output::vtu::{write_vtu, Field, Series};
        let e = Entry::new(output, p, &p.cases[0]);
        std::fs::create_dir_all(&e.dir).unwrap();
        let pts: Vec<[f64; 3]> = (0..4).map(|i| [i as f64 * 0.1, 0.0, 0.0]).collect();
        let mut series = Series::new(e.dir.join("fluid.pvd"));
        for (k, t) in [0.0, 0.5004, 1.0].into_iter().enumerate() {
            let file = format!("fluid_{k:05}.vtu");
            let normal: Vec<[f64; 3]> =
                (0..4).map(|i| if k == 1 && i >= 2 { [0.0, 1.0, 0.0] } else { [0.0; 3] }).collect();
            write_vtu(
                &e.dir.join(&file),
                &pts,
                &[Field::Scalar("pressure", vec![k as f64; 4]), Field::Vector("normal", normal)],
            )
            .unwrap();
            series.push(t, &file).unwrap();
        }
        completed(p.cases[0].params.to_json(), 4, 0.1).write(&e.dir).unwrap();
        e
    }

    const PARTICLES: &str = r#"
title = "t"
scene = "taylor_green"
[presets.quick]
tf = 1.0
[[cases]]
name = "one"
params = { tf = "$tf" }
[[figures]]
id = "p_t06"
kind = "particles"
title = "pressure"
field = "pressure"
time = 0.6
arrows = "normal"
paper = "Fig. 3"
[[figures]]
id = "p_last"
kind = "particles"
title = "pressure, last"
field = "pressure"
"#;

    /// `time` picks the snapshot nearest it, `arrows` overlays the vector array where it
    /// is non-zero; without them the last snapshot is drawn, plain.
    #[test]
    fn particles_at_a_time_with_arrows() {
        let root = tempfile::tempdir().unwrap();
        let root = root.path();
        let p = registry::parse(&root.join("problems/pp.toml"), PARTICLES, "quick").unwrap();
        assert_eq!(
            p.figures[0].kind,
            FigureKind::Particles {
                field: "pressure".into(),
                time: Some(0.6),
                arrows: Some("normal".into())
            }
        );
        let output = root.join("output");
        case_with_snapshots(&output, &p);
        let manuscript = root.join("manuscript");
        let section = regenerate(&p, &output, &manuscript).unwrap();
        let Item::Figure { ours, .. } = &section.items[0] else { panic!() };
        assert!(ours.contains("at t = 0.500 s (nearest snapshot to t = 0.6 s)"), "{ours}");
        assert!(ours.contains("pressure from 1.000e0 to 1.000e0"), "{ours}");
        assert!(ours.contains("`normal` drawn at 2 particle(s)"), "{ours}");
        let svg = check_figure(&manuscript.join("figures/p_t06"), (900, 720), &["pressure (t = 0.50 s)"]);
        assert_eq!(svg.matches("stroke=\"#D73027\"").count(), 2);
        let Item::Figure { ours, .. } = &section.items[1] else { panic!() };
        assert!(ours.contains("at t = 1.000 s:") && ours.contains("from 2.000e0"), "{ours}");
        let svg =
            check_figure(&manuscript.join("figures/p_last"), (900, 720), &["pressure, last (t = 1.00 s)"]);
        assert!(!svg.contains("#D73027"));

        // Nearest, ties to the first; no time: the last.
        let list: Vec<(f64, String)> = [0.0, 0.5, 1.0].iter().map(|t| (*t, format!("{t}"))).collect();
        assert_eq!(pick_snapshot(&list, Some(0.25)).0, 0.0);
        assert_eq!(pick_snapshot(&list, Some(0.26)).0, 0.5);
        assert_eq!(pick_snapshot(&list, Some(7.0)).0, 1.0);
        assert_eq!(pick_snapshot(&list, None).0, 1.0);

        // An arrows array that is not a vector, or missing, names the file and the array.
        let e = snapshot(&Entry::new(&output, &p, &p.cases[0]).dir, "pressure", None, Some("pressure"));
        assert!(e.err().unwrap().contains("not 3 per point"));
        let e = snapshot(&Entry::new(&output, &p, &p.cases[0]).dir, "pressure", None, Some("nope"));
        assert!(e.err().unwrap().contains("no point array `nope`"));
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
}
