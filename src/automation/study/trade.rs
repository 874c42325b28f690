//! The speed-accuracy trade: error against wall time and against particle-steps with the
//! Pareto front, and a table with the observed order of convergence of each group along
//! the resolution.

use super::{fmt_value, group, missing_note, param_f64, words, Drawn, Run};
use crate::automation::registry::Figure;
use crate::automation::report::{self, Block};
use crate::solver::output::machine::Machine;
use std::collections::BTreeMap;
use std::path::Path;

/// The kinds of CPU the wall times of a figure were measured on (the cache keeps results
/// from machine to machine): wall times compare only within one.
pub(super) fn machines_note<'a>(machines: impl IntoIterator<Item = &'a Machine>) -> String {
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

/// The fluid and wall particles of a run (`bodies` of its summary; an older summary
/// without it counts every particle as fluid).
pub(super) fn fluid_and_wall(r: &Run) -> (String, String) {
    match &r.summary {
        None => (String::new(), String::new()),
        Some(s) if s.bodies.is_empty() => (s.particles.to_string(), "-".into()),
        Some(s) => {
            let fluid = s.bodies.get("fluid").copied().unwrap_or(0);
            let wall: usize = s.bodies.iter().filter(|(k, _)| *k != "fluid").map(|(_, v)| v).sum();
            (fluid.to_string(), wall.to_string())
        }
    }
}

/// Error against wall time and against particle-steps, the Pareto front, and a table
/// with the observed order of convergence of each group along resolution `res`.
pub(super) fn trade(
    f: &Figure,
    rs: &[Run],
    res: &str,
    spacing: bool,
    figures: &Path,
    tables: &Path,
) -> Result<Drawn, String> {
    let m = f.metric.as_deref().expect("validated");
    let caption = f.info.caption.clone();
    // CPU time where every drawn case recorded it (a loaded machine inflates wall time and
    // reorders the front), wall time otherwise, said on the axis.
    let drawn: Vec<(&Run, f64)> =
        rs.iter().filter(|r| r.summary.is_some()).filter_map(|r| Some((r, r.metric(m)?))).collect();
    let cpu = !drawn.is_empty()
        && drawn.iter().all(|(r, _)| r.summary.as_ref().is_some_and(|s| s.cpu_seconds.is_some()));
    let done: Vec<(&Run, f64, f64, f64)> = drawn
        .into_iter()
        .map(|(r, e)| {
            let s = r.summary.as_ref().expect("drawn");
            let t = if cpu { s.cpu_seconds.expect("recorded") } else { s.wall_seconds };
            (r, e, t, s.particles as f64 * s.steps as f64)
        })
        .collect();
    let time = if cpu { "CPU time (s)" } else { "wall time (s)" };
    let machines =
        machines_note(done.iter().map(|d| &d.0.summary.as_ref().expect("done").provenance.machine));
    let at = |r: &Run| words::phrase(res, &r.case.params.0[res]);
    let mut blocks = Vec::new();
    for (suffix, what, idx) in [("wall", time, 0), ("steps", "particle-steps (-)", 1)] {
        let id = format!("{}_{suffix}", f.id);
        let points = done
            .iter()
            .map(|(r, e, w, ps)| (group(r.case, &f.label), at(r), if idx == 0 { *w } else { *ps }, *e))
            .collect();
        report::pareto_figure(
            &report::ParetoFigure {
                // The axes name the metric and the cost; the title says which cost.
                title: format!("{}: {}", f.title, what.split(" (").next().unwrap_or(what)),
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
            .map(|&i| format!("{}, {}", group(done[i].0.case, &f.label), at(done[i].0)))
            .collect();
        blocks.push(Block::Image {
            path: format!("figures/{id}.png"),
            caption: format!("{caption} (against {what})"),
            ours: format!(
                "Pareto front: {}.{}{}",
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
            let (fluid, wall) = fluid_and_wall(d.0);
            rows.push(vec![
                g.clone(),
                at(d.0),
                fluid,
                wall,
                d.0.summary.as_ref().map(|s| s.steps.to_string()).unwrap_or_default(),
                format!("{:.2}", d.2),
                fmt_value(d.3),
                fmt_value(d.1),
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
                    if sign_change { "change sign" } else { "differ by more than 50 %" }
                ));
            }
        } else if os.len() == 1 {
            notes.push(format!("{g}: one order ({:.2}) only: the asymptotic range cannot be judged.", os[0]));
        }
    }
    report::write_table(
        &report::Table {
            title: format!("{}: {m}, cost and observed order along {res}", f.title),
            headers: [
                "scheme",
                "resolution",
                "fluid particles",
                "wall particles",
                "steps",
                time,
                "particle-steps",
                m,
                "order",
                &format!("Pareto ({})", time.trim_end_matches(" (s)")),
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            rows,
        },
        &tables.join(&f.id),
    )?;
    blocks.push(Block::Table {
        md_path: format!("tables/{}.md", f.id),
        caption: format!(
            "{caption}: error, cost and observed order of convergence (between consecutive resolutions)."
        ),
    });
    if !notes.is_empty() {
        blocks.push(Block::Text(notes.join(" ")));
    }
    Ok(Drawn { blocks })
}
