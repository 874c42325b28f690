//! Stability maps: the outcome of every case (stable, inaccurate, diverged) against a swept
//! parameter, per scheme, as a map and a table; and, per scheme and preset, where along the
//! swept parameter it stops being stable (the first failing value).

use super::{fmt_bound, fmt_value, group, param_f64, words, Drawn, Run};
use crate::automation::registry::Figure;
use crate::automation::report::{self, Block, Outcome};
use crate::solver::output::summary::Status;
use std::collections::BTreeMap;
use std::path::Path;

/// Outcome of one case for a stability map, and why.
pub(super) fn outcome(r: &Run, m: &str, max: f64) -> (Outcome, String) {
    match &r.summary {
        None => (Outcome::Missing, "no result".into()),
        Some(s) if s.status == Status::Diverged => (
            Outcome::Diverged,
            format!("diverged at t = {:.3}: {}", s.final_time, s.reason.clone().unwrap_or_default()),
        ),
        Some(s) => match s.metrics.get(m) {
            Some(v) if v.is_finite() && *v <= max => (Outcome::Stable, format!("{m} = {}", fmt_value(*v))),
            Some(v) => (Outcome::Inaccurate, format!("{m} = {} > {}", fmt_value(*v), fmt_bound(max))),
            // Completed, with nothing to judge its accuracy by (e.g. no published points at
            // that Reynolds number): it ran, which is what the map is about.
            None => (Outcome::Stable, format!("completed; no `{m}` to judge its accuracy by")),
        },
    }
}

/// Outcome `o` in words, `above` naming a completed case whose metric exceeds the map's `max`.
fn word(o: Outcome, above: &str) -> &str {
    match o {
        Outcome::Stable => "stable",
        Outcome::Inaccurate => above,
        Outcome::Diverged => "diverged",
        Outcome::Missing => "no result",
    }
}

/// The outcomes of one scheme along the swept parameter (ascending), in words: runs of one
/// outcome, the first `up to` its last value, the last `from` its first.
pub(crate) fn along(cells: &[(String, Outcome)], above: &str) -> String {
    let mut runs: Vec<(Outcome, Vec<&str>)> = Vec::new();
    for (x, o) in cells {
        match runs.last_mut() {
            Some((last, xs)) if *last == *o => xs.push(x),
            _ => runs.push((*o, vec![x])),
        }
    }
    let n = runs.len();
    runs.iter()
        .enumerate()
        .map(|(i, (o, xs))| {
            let (first, last) = (xs[0], xs[xs.len() - 1]);
            let span = if xs.len() == 1 { first.to_string() } else { format!("{first} to {last}") };
            match (i, n) {
                (_, 1) => format!("{} at every value ({span})", word(*o, above)),
                (0, _) => format!("{} up to {last}", word(*o, above)),
                (i, n) if i == n - 1 => format!("{} from {first}", word(*o, above)),
                _ => format!("{} at {span}", word(*o, above)),
            }
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The first value along the swept parameter (ascending) where a scheme is not stable, in
/// words (`diverged at 1`, or `none up to 2`).
pub(crate) fn first_failure(cells: &[(String, Outcome)], above: &str) -> String {
    match cells.iter().find(|(_, o)| matches!(o, Outcome::Diverged | Outcome::Inaccurate)) {
        Some((x, o)) => format!("{} at {x}", word(*o, above)),
        None => match cells.last() {
            Some((x, _)) if cells.iter().all(|(_, o)| *o == Outcome::Stable) => format!("none up to {x}"),
            _ => "-".into(),
        },
    }
}

/// What a stability map judges: its swept parameter `x`, and a completed case whose
/// `metric` is above `max` is named `above` ("inaccurate", "fractured", ...).
pub(super) struct Rule<'a> {
    pub x: &'a str,
    pub metric: &'a str,
    pub max: f64,
    pub above: &'a str,
}

/// The map, the per-case table and the first-failure table of figure `f` by `rule`, for the
/// runs of this preset (`rs`, drawn) and of every preset that has results (`by_preset`). If
/// this preset (`preset`) has no result, the map and its table are not drawn, and the
/// first-failure table says what the other presets found.
pub(super) fn stability(
    f: &Figure,
    rule: &Rule,
    rs: &[Run],
    by_preset: &[(String, Vec<Run>)],
    (figures, tables): (&Path, &Path),
    preset: &str,
) -> Result<Drawn, String> {
    let Rule { x, metric: m, max, above } = *rule;
    let caption = f.info.caption.clone();
    let first = first_failures(f, rule, by_preset, tables)?;
    if rs.iter().all(|r| r.summary.is_none()) {
        let mut blocks = vec![Block::Missing {
            caption,
            why: format!("none of its cases has a result at the `{preset}` preset"),
        }];
        blocks.extend(first);
        return Ok(Drawn { blocks });
    }
    let name_x = |r: &Run| words::value(&r.case.params.0[x]);
    let mut xs: Vec<(f64, String)> = Vec::new();
    let mut ys: Vec<String> = Vec::new();
    for r in rs {
        let v = (param_f64(r.case, x), name_x(r));
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
        let ix = xs.iter().position(|a| a.1 == name_x(r)).expect("listed");
        let g = group(r.case, &f.label);
        let iy = ys.iter().position(|a| *a == g).expect("listed");
        let (o, why) = outcome(r, m, max);
        *counts.entry(word(o, above)).or_default() += 1;
        cells.push((ix, iy, o, None));
        rows.push(vec![g, xs[ix].1.clone(), word(o, above).to_string(), why]);
    }
    report::outcome_map(
        &report::OutcomeMap {
            title: f.title.clone(),
            x_label: f.x_label.clone().unwrap_or_else(|| x.into()),
            y_label: String::new(),
            x_ticks: xs.iter().map(|a| a.1.clone()).collect(),
            y_ticks: ys,
            cells,
            above: above.to_string(),
        },
        &figures.join(&f.id),
    )?;
    report::write_table(
        &report::Table {
            title: format!("{}: outcome per case ({above}: {m} > {max})", f.title),
            headers: vec!["scheme".into(), x.into(), "outcome".into(), "detail".into()],
            rows,
        },
        &tables.join(&f.id),
    )?;
    let mut blocks = vec![Block::Image {
        path: format!("figures/{}.png", f.id),
        caption: caption.clone(),
        ours: format!(
            "{} ({above}: `{m}` > {}).",
            counts.iter().map(|(k, v)| format!("{v} {k}")).collect::<Vec<_>>().join(", "),
            fmt_bound(max)
        ),
    }];
    blocks.extend(first);
    blocks.push(Block::Table {
        md_path: format!("tables/{}.md", f.id),
        caption: "The outcome of every case.".into(),
    });
    Ok(Drawn { blocks })
}

/// The table of where each scheme stops being stable along `x`, at every preset with results
/// (none if no preset has one).
fn first_failures(
    f: &Figure,
    rule: &Rule,
    by_preset: &[(String, Vec<Run>)],
    tables: &Path,
) -> Result<Option<Block>, String> {
    let Rule { x, metric: m, max, above } = *rule;
    if by_preset.is_empty() {
        return Ok(None);
    }
    let name_x = |r: &Run| words::value(&r.case.params.0[x]);
    // Where each scheme stops being stable, at every preset with results.
    let mut first = Vec::new();
    for (preset, runs) in by_preset {
        // per scheme group: (x, x as named, outcome)
        type Cell = (f64, String, Outcome);
        let mut per: Vec<(String, Vec<Cell>)> = Vec::new();
        for r in runs {
            let g = group(r.case, &f.label);
            let (o, _) = outcome(r, m, max);
            let cell = (param_f64(r.case, x), name_x(r), o);
            match per.iter_mut().find(|(k, _)| *k == g) {
                Some((_, v)) => v.push(cell),
                None => per.push((g, vec![cell])),
            }
        }
        for (g, mut v) in per {
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            let cells: Vec<(String, Outcome)> = v.into_iter().map(|(_, n, o)| (n, o)).collect();
            if cells.iter().all(|(_, o)| *o == Outcome::Missing) {
                continue;
            }
            first.push(vec![preset.clone(), g, first_failure(&cells, above), along(&cells, above)]);
        }
    }
    let first_id = format!("{}_first_failure", f.id);
    report::write_table(
        &report::Table {
            title: format!("{}: the first failing value per scheme", f.title),
            headers: vec!["preset".into(), "scheme".into(), "first failure".into(), format!("along {x}")],
            rows: first,
        },
        &tables.join(&first_id),
    )?;
    Ok(Some(Block::Table {
        md_path: format!("tables/{first_id}.md"),
        caption: format!("Where each scheme stops being stable along {x}, at every preset with results (values ascending)."),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcomes_along_the_sweep_in_words() {
        let c = |v: &[(&str, Outcome)]| v.iter().map(|(x, o)| (x.to_string(), *o)).collect::<Vec<_>>();
        use Outcome::*;
        let s =
            c(&[("0.1", Stable), ("0.25", Stable), ("0.5", Inaccurate), ("1", Diverged), ("2", Diverged)]);
        assert_eq!(along(&s, "inaccurate"), "stable up to 0.25; inaccurate at 0.5; diverged from 1");
        assert_eq!(first_failure(&s, "inaccurate"), "inaccurate at 0.5");
        // A map's own word for exceeding its bound.
        assert_eq!(along(&s, "fractured"), "stable up to 0.25; fractured at 0.5; diverged from 1");
        assert_eq!(first_failure(&s, "fractured"), "fractured at 0.5");
        let all = c(&[("1", Stable), ("2", Stable)]);
        assert_eq!(along(&all, "inaccurate"), "stable at every value (1 to 2)");
        assert_eq!(first_failure(&all, "inaccurate"), "none up to 2");
        let low = c(&[("0.5", Diverged), ("1", Stable)]);
        assert_eq!(first_failure(&low, "inaccurate"), "diverged at 0.5");
        assert_eq!(along(&low, "inaccurate"), "diverged up to 0.5; stable from 1");
    }
}
