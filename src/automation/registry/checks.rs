//! The checks of figures, tables and bounds against the scene and the expanded cases: every
//! selection picks a case, every metric is one the scene reports, every column one it
//! writes, every label and swept `x` a parameter it has, and each figure kind has the keys
//! it needs and no key of another kind.

use super::expand::{check_param, resolve_raw, Expand, Raw};
use super::model::{
    glob_matches, is_word, valid_name, Bound, Case, ClaimTest, Figure, FigureKind, ItemInfo, Select, Table,
    Test, DEFAULT_PRESET,
};
use super::reference;
use super::schema::{BoundFile, ClaimFile, FigureFile, Loc, RawParams, Span, TableFile};
use crate::automation::papers;
use crate::scenes::params::Value;
use crate::scenes::SceneEntry;
use std::collections::BTreeMap;
use toml::Spanned;

/// Checks that a selection matches at least one case.
fn nonempty(
    loc: &Loc,
    span: Span,
    what: &str,
    s: &Select,
    cases: &[Case],
    preset: &str,
) -> Result<(), String> {
    if s.pick(cases).is_empty() {
        let desc = format!(
            "{}{}",
            if s.cases.is_empty() { String::new() } else { format!("cases {:?} ", s.cases) },
            if s.where_.is_empty() {
                String::new()
            } else {
                format!(
                    "where {}",
                    s.where_.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ")
                )
            }
        );
        for g in &s.cases {
            if !cases.iter().any(|c| glob_matches(g, &c.name).unwrap_or(false)) {
                return Err(loc.err(span, what, format!("no case named `{g}` in preset `{preset}`")));
            }
        }
        return Err(loc.err(span, what, format!("{desc} selects no case in preset `{preset}`")));
    }
    Ok(())
}

/// Checks that `m` is a metric the scene reports.
fn check_metric(loc: &Loc, span: Span, what: &str, scene: &SceneEntry, m: &str) -> Result<(), String> {
    if scene.metrics.contains(&m) {
        Ok(())
    } else {
        Err(loc.err(
            span,
            what,
            format!("scene `{}` has no metric `{m}`; its metrics: {}", scene.name, scene.metrics.join(", ")),
        ))
    }
}

impl Expand<'_> {
    /// The cases a figure, table or bound selects: its globs, checked, and its `where`
    /// table, of known parameters with values of the right type.
    fn select(&self, cases: &[String], where_: &RawParams) -> Result<Select, String> {
        let Expand { loc, scene, specs, preset, vars, .. } = *self;
        let mut w = BTreeMap::new();
        for (k, v) in where_ {
            match resolve_raw(loc, k, v, vars, preset)? {
                Raw::One(x) => {
                    w.insert(k.clone(), check_param(loc, v.span(), scene, specs, k, &x)?);
                }
                Raw::List(_) => return Err(loc.err(v.span(), k, "a `where` value must be one value")),
            }
        }
        for g in cases {
            globset::Glob::new(g).map_err(|e| format!("{}: bad glob `{g}`: {e}", loc.path.display()))?;
        }
        Ok(Select { cases: cases.to_vec(), where_: w })
    }

    /// One figure, checked against the scene and the cases (`ids` holds the ids taken).
    pub(super) fn figure(
        &self,
        f: &Spanned<FigureFile>,
        cases: &[Case],
        ids: &mut BTreeMap<String, usize>,
    ) -> Result<Figure, String> {
        let Expand { loc, scene, preset, .. } = *self;
        let span = f.span();
        let f = f.get_ref();
        let key = format!("figures.{}", f.id);
        claim_id(loc, span.clone(), &key, &f.id, ids)?;
        let select = self.select(&f.cases, &f.where_)?;
        nonempty(loc, span.clone(), &key, &select, cases, preset)?;
        for l in &f.label {
            self.parameter(span.clone(), &key, "label", l)?;
        }
        if let Some(m) = &f.metric {
            check_metric(loc, span.clone(), &key, scene, m)?;
        }
        let kind = self.figure_kind(f, span.clone(), &key, &select, cases)?;
        // Keys that only one kind reads: set on another, they would be silently ignored.
        for (k, set, only) in [
            ("file", f.file.is_some(), "profile"),
            ("reference", f.reference.is_some(), "profile"),
            ("x_label", f.x_label.is_some() && f.kind != "stability", "profile"),
            ("x_range", f.x_range.is_some(), "profile"),
            ("time", f.time.is_some(), "particles"),
            ("arrows", f.arrows.is_some(), "particles"),
            ("view", f.view.is_some(), "particles"),
            ("x_spacing", f.x_spacing, "trade"),
            ("exact", f.exact.is_some(), "timeseries"),
            ("exact_label", f.exact_label.is_some(), "timeseries"),
            ("metric_over", f.metric_over.is_some(), "timeseries"),
            ("above_max", f.above_max.is_some(), "stability"),
        ] {
            if set && f.kind != only {
                return Err(loc.err(span, &format!("{key}.{k}"), format!("only kind `{only}` takes `{k}`")));
            }
        }
        let info = item_info(
            loc,
            span.clone(),
            &key,
            (&f.number, &f.paper_caption, &f.section, &f.caption, &f.discussion),
        )?;
        Ok(Figure {
            id: f.id.clone(),
            kind,
            title: f.title.clone(),
            info,
            select_at: BTreeMap::from([(preset.to_string(), select.clone())]),
            select,
            x_label: f.x_label.clone(),
            y_label: f.y_label.clone(),
            log_y: f.log_y,
            metric: f.metric.clone(),
            label: f.label.clone(),
        })
    }

    /// What figure `f` draws (its `kind` and the keys that kind needs), checked.
    fn figure_kind(
        &self,
        f: &FigureFile,
        span: Span,
        key: &str,
        select: &Select,
        cases: &[Case],
    ) -> Result<FigureKind, String> {
        let need = |what: &str, v: &Option<String>| {
            v.clone()
                .ok_or_else(|| self.loc.err(span.clone(), key, format!("kind `{}` needs `{what}`", f.kind)))
        };
        Ok(match f.kind.as_str() {
            "timeseries" => self.timeseries_kind(f, span.clone(), key, need("y", &f.y)?)?,
            "particles" => {
                self.particles_kind(f, span.clone(), key, select, cases, need("field", &f.field)?)?
            }
            "trade" => {
                need("metric", &f.metric)?;
                FigureKind::Trade {
                    x: self.swept(span.clone(), key, need("x", &f.x)?)?,
                    spacing: f.x_spacing,
                }
            }
            "stability" => {
                need("metric", &f.metric)?;
                let x = self.swept(span.clone(), key, need("x", &f.x)?)?;
                // One case per cell of the map: two that share a row (`label`) and a column
                // (`x`) would hide one another.
                let picked = select.pick(cases);
                for (i, a) in picked.iter().enumerate() {
                    let cell = |c: &Case| -> String {
                        let keys = f.label.iter().map(String::as_str).chain([x.as_str()]);
                        keys.map(|k| format!("{:?}", c.params.0.get(k))).collect::<Vec<_>>().join("|")
                    };
                    if let Some(b) = picked[i + 1..].iter().find(|b| cell(b) == cell(a)) {
                        let differ: Vec<&String> =
                            a.params.0.keys().filter(|k| a.params.0.get(*k) != b.params.0.get(*k)).collect();
                        return Err(self.loc.err(
                            span.clone(),
                            key,
                            format!(
                                "cases `{}` and `{}` fall in one cell of the map in preset `{}` (they differ in {}): narrow `where` or add to `label`",
                                a.name,
                                b.name,
                                self.preset,
                                differ.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ")
                            ),
                        ));
                    }
                }
                let max =
                    f.max.ok_or_else(|| self.loc.err(span.clone(), key, "kind `stability` needs `max`"))?;
                let above = match f.above_max.as_deref() {
                    None => "inaccurate".to_string(),
                    Some(w) if is_word(w) => w.to_string(),
                    Some(w) => {
                        return Err(self.loc.err(
                            span.clone(),
                            &format!("{key}.above_max"),
                            format!(
                            "`{w}` must be a short word or two (letters, spaces, `-`; at most 24 characters)"
                        ),
                        ))
                    }
                };
                FigureKind::Stability { x, max, above }
            }
            "profile" => {
                let file_name = need("file", &f.file)?;
                if !valid_name(&file_name) || file_name.starts_with('.') {
                    return Err(self.loc.err(
                        span.clone(),
                        &format!("{key}.file"),
                        format!("`{file_name}` must be a file name in the case folder (letters, digits, `.`, `_`, `-`)"),
                    ));
                }
                let mut references = Vec::new();
                if let Some(r) = &f.reference {
                    for one in r.get_ref().as_slice() {
                        references.push(reference::read(self.loc, r.span(), key, one)?);
                    }
                }
                let clip_to_reference = match f.x_range.as_deref() {
                    None => false,
                    Some("reference") if !references.is_empty() => true,
                    Some("reference") => {
                        return Err(self.loc.err(
                            span.clone(),
                            &format!("{key}.x_range"),
                            "`x_range = \"reference\"` needs a `reference`",
                        ))
                    }
                    Some(other) => {
                        return Err(self.loc.err(
                            span.clone(),
                            &format!("{key}.x_range"),
                            format!(
                                "`{other}`: the one range is \"reference\" (the published points' x range)"
                            ),
                        ))
                    }
                };
                FigureKind::Profile {
                    file: file_name,
                    x: need("x", &f.x)?,
                    y: need("y", &f.y)?,
                    references,
                    clip_to_reference,
                }
            }
            other => {
                return Err(self.loc.err(
                    span.clone(),
                    key,
                    format!(
                        "unknown kind `{other}`; kinds: timeseries, particles, trade, stability, profile"
                    ),
                ))
            }
        })
    }

    /// A `timeseries` figure of column `y`: it and the exact column are columns the scene
    /// writes.
    fn timeseries_kind(
        &self,
        f: &FigureFile,
        span: Span,
        key: &str,
        y: String,
    ) -> Result<FigureKind, String> {
        let scene = self.scene;
        for (what, c) in [("y", Some(&y)), ("exact", f.exact.as_ref())] {
            if let Some(c) = c.filter(|c| !scene.columns.contains(&c.as_str())) {
                return Err(self.loc.err(
                    span,
                    &format!("{key}.{what}"),
                    format!(
                        "scene `{}` has no time-series column `{c}`; its columns: {}",
                        scene.name,
                        scene.columns.join(", ")
                    ),
                ));
            }
        }
        if f.exact_label.is_some() && f.exact.is_none() {
            return Err(self.loc.err(span, &format!("{key}.exact_label"), "names no `exact` column"));
        }
        let exact_label = f.exact_label.clone().unwrap_or_else(|| "exact".into());
        if let Some(w) = f.metric_over {
            if !(w > 0.0 && w <= 1.0) {
                return Err(self.loc.err(
                    span,
                    &format!("{key}.metric_over"),
                    format!("`{w}` is not a fraction of the run in (0, 1]"),
                ));
            }
            if f.metric.is_none() {
                return Err(self.loc.err(
                    span,
                    &format!("{key}.metric_over"),
                    "the figure names no `metric` to draw",
                ));
            }
        }
        Ok(FigureKind::Timeseries { y, exact: f.exact.clone(), exact_label, metric_over: f.metric_over })
    }

    /// A `particles` figure of point array `field`: its `time` is one every selected case
    /// reaches, and `arrows` a point array name.
    fn particles_kind(
        &self,
        f: &FigureFile,
        span: Span,
        key: &str,
        select: &Select,
        cases: &[Case],
        field: String,
    ) -> Result<FigureKind, String> {
        let (loc, preset) = (self.loc, self.preset);
        if let Some(t) = f.time {
            if !(t.is_finite() && t >= 0.0) {
                return Err(loc.err(span, &format!("{key}.time"), format!("`{t}` is not a time >= 0")));
            }
            // A snapshot after the end time does not exist: the figure would silently show
            // another time. Every preset is checked.
            let picked = select.pick(cases);
            if let Some(c) =
                picked.iter().find(|c| matches!(c.params.0.get("tf"), Some(Value::Float(tf)) if *tf < t))
            {
                return Err(loc.err(
                    span,
                    &format!("{key}.time"),
                    format!(
                        "t = {t} is after the end time tf = {} of case `{}` in preset `{preset}`",
                        c.params.0["tf"], c.name
                    ),
                ));
            }
        }
        if let Some(a) = &f.arrows {
            if a.is_empty() || a.contains(['"', '<', '>']) {
                return Err(loc.err(
                    span,
                    &format!("{key}.arrows"),
                    format!("`{a}` is not a point array name"),
                ));
            }
        }
        let view = match f.view.as_deref() {
            None => None,
            Some(&[x0, x1, y0, y1])
                if [x0, x1, y0, y1].iter().all(|v| v.is_finite()) && x0 < x1 && y0 < y1 =>
            {
                Some([x0, x1, y0, y1])
            }
            Some(v) => {
                return Err(loc.err(
                    span,
                    &format!("{key}.view"),
                    format!("`{v:?}` is not [x0, x1, y0, y1] with x0 < x1 and y0 < y1"),
                ))
            }
        };
        Ok(FigureKind::Particles { field, time: f.time, arrows: f.arrows.clone(), view })
    }

    /// The swept parameter `x` of a `trade` or `stability` figure: one the scene has.
    fn swept(&self, span: Span, key: &str, x: String) -> Result<String, String> {
        self.parameter(span, key, "x", &x)?;
        Ok(x)
    }

    /// Checks that `name`, given as `what` under `key`, is a parameter of the scene (a
    /// figure's labels and swept `x`, a table's columns).
    fn parameter(&self, span: Span, key: &str, what: &str, name: &str) -> Result<(), String> {
        if !self.specs.iter().any(|s| s.name == name) {
            return Err(self.loc.err(span, key, format!("`{what}` names no parameter `{name}`")));
        }
        Ok(())
    }

    /// One table, checked against the scene and the cases (`ids` holds the ids taken).
    pub(super) fn table(
        &self,
        t: &Spanned<TableFile>,
        cases: &[Case],
        ids: &mut BTreeMap<String, usize>,
    ) -> Result<Table, String> {
        let Expand { loc, scene, preset, .. } = *self;
        let span = t.span();
        let t = t.get_ref();
        let key = format!("tables.{}", t.id);
        claim_id(loc, span.clone(), &key, &t.id, ids)?;
        let select = self.select(&t.cases, &t.where_)?;
        nonempty(loc, span.clone(), &key, &select, cases, preset)?;
        for m in &t.metrics {
            check_metric(loc, span.clone(), &key, scene, m)?;
        }
        for c in &t.columns {
            self.parameter(span.clone(), &key, "columns", c)?;
        }
        let info = item_info(
            loc,
            span.clone(),
            &key,
            (&t.number, &t.paper_caption, &t.section, &t.caption, &t.discussion),
        )?;
        Ok(Table {
            id: t.id.clone(),
            title: t.title.clone(),
            info,
            select,
            columns: t.columns.clone(),
            metrics: t.metrics.clone(),
        })
    }

    /// One bound, checked against the scene and the cases; `None` if it does not hold in
    /// this preset.
    pub(super) fn bound(&self, b: &Spanned<BoundFile>, cases: &[Case]) -> Result<Option<Bound>, String> {
        let Expand { loc, file, scene, preset, .. } = *self;
        let span = b.span();
        let b = b.get_ref();
        let key = format!("bounds.{}", b.metric);
        check_metric(loc, span.clone(), "bounds.metric", scene, &b.metric)?;
        if b.max.is_none() && b.min.is_none() {
            return Err(loc.err(span, &key, "a bound needs `max` or `min`"));
        }
        if let (Some(lo), Some(hi)) = (b.min, b.max) {
            if lo > hi {
                return Err(loc.err(
                    span,
                    &key,
                    format!("min = {lo} is above max = {hi}: no value can hold"),
                ));
            }
        }
        let presets = b.presets.clone().unwrap_or_else(|| vec![DEFAULT_PRESET.to_string()]);
        for p in &presets {
            if !file.presets.contains_key(p) {
                return Err(loc.err(span, &key, format!("no preset `{p}`")));
            }
        }
        if !presets.iter().any(|p| p == preset) {
            return Ok(None);
        }
        let select = self.select(&b.cases, &b.where_)?;
        nonempty(loc, span.clone(), &key, &select, cases, preset)?;
        Ok(Some(Bound {
            metric: b.metric.clone(),
            select,
            max: b.max,
            min: b.min,
            presets,
            line: loc.line(span.start),
        }))
    }
}

impl Expand<'_> {
    /// One claim in this preset: its test and selection, checked against the scene, the
    /// cases and the problem's figure and table ids; `None` when its selection picks no case
    /// in this preset and this is not the preset the claim is stated at (whose selection must
    /// pick one).
    pub(super) fn claim(
        &self,
        c: &Spanned<ClaimFile>,
        cases: &[Case],
        ids: &BTreeMap<String, usize>,
    ) -> Result<Option<ClaimTest>, String> {
        let Expand { loc, file, scene, preset, .. } = *self;
        let span = c.span();
        let c = c.get_ref();
        let key = format!("claims.{}", c.figure);
        if !ids.contains_key(&c.figure) {
            let known: Vec<_> = ids.keys().map(String::as_str).collect();
            return Err(loc.err(
                span,
                "claims.figure",
                format!("no figure or table `{}` in this problem; its ids: {}", c.figure, known.join(", ")),
            ));
        }
        for (what, text) in [("claim", &c.claim), ("source", &c.source)] {
            if text.trim().is_empty() {
                return Err(loc.err(span, &format!("{key}.{what}"), "is empty"));
            }
        }
        let own = c.preset.as_deref().unwrap_or("paper");
        if !file.presets.contains_key(own) {
            let known: Vec<_> = file.presets.keys().map(String::as_str).collect();
            return Err(loc.err(
                span,
                &format!("{key}.preset"),
                format!("no preset `{own}`; this problem has: {}", known.join(", ")),
            ));
        }
        let t = c.test.get_ref();
        let tspan = c.test.span();
        check_metric(loc, tspan.clone(), &format!("{key}.test.metric"), scene, &t.metric)?;
        let bound = t.max.is_some() || t.min.is_some();
        let monotone = t.decreasing.is_some() || t.increasing.is_some();
        let compare = t.lower.is_some() || t.higher.is_some();
        if [bound, monotone, compare].iter().filter(|x| **x).count() != 1
            || (t.decreasing.is_some() && t.increasing.is_some())
        {
            return Err(loc.err(
                tspan,
                &format!("{key}.test"),
                "a test is one of: `max` and/or `min`; `decreasing` or `increasing` (a parameter); `lower` with `higher` (and an optional `factor`)",
            ));
        }
        if t.factor.is_some() && !compare {
            return Err(loc.err(
                tspan,
                &format!("{key}.test.factor"),
                "`factor` goes with `lower` and `higher`",
            ));
        }
        if let (Some(lo), Some(hi)) = (t.min, t.max) {
            if lo > hi {
                return Err(loc.err(
                    tspan,
                    &format!("{key}.test"),
                    format!("min = {lo} is above max = {hi}"),
                ));
            }
        }
        let select = self.select(&c.cases, &c.where_)?;
        let picked = select.pick(cases);
        if picked.is_empty() {
            if preset != own {
                return Ok(None);
            }
            nonempty(loc, span, &key, &select, cases, preset)?;
        }
        let test = if bound {
            Test::Bound { metric: t.metric.clone(), max: t.max, min: t.min }
        } else if monotone {
            let (param, decreasing) = match (&t.decreasing, &t.increasing) {
                (Some(p), _) => (p.clone(), true),
                (None, Some(p)) => (p.clone(), false),
                _ => unreachable!("checked above"),
            };
            self.parameter(tspan.clone(), &format!("{key}.test"), "decreasing/increasing", &param)?;
            // Two values of the parameter among cases alike in the others, in the preset the
            // claim is stated at: else there is no trend to judge.
            if preset == own && !has_trend(&picked, &param) {
                return Err(loc.err(
                    tspan,
                    &format!("{key}.test"),
                    format!("no two selected cases differ in `{param}` alone in preset `{own}`: no trend to judge"),
                ));
            }
            Test::Monotone { metric: t.metric.clone(), param, decreasing }
        } else {
            let (Some(lo), Some(hi)) = (&t.lower, &t.higher) else {
                return Err(loc.err(tspan, &format!("{key}.test"), "`lower` and `higher` go together"));
            };
            let lower = self.select(&lo.cases, &lo.where_)?;
            let higher = self.select(&hi.cases, &hi.where_)?;
            if preset == own {
                for (what, s) in [("lower", &lower), ("higher", &higher)] {
                    let within: Vec<Case> =
                        picked.iter().filter(|c| s.matches(c)).map(|c| (*c).clone()).collect();
                    if within.is_empty() {
                        return Err(loc.err(
                            tspan.clone(),
                            &format!("{key}.test.{what}"),
                            format!("selects no case of the claim's selection in preset `{own}`"),
                        ));
                    }
                }
            }
            let factor = t.factor.unwrap_or(1.0);
            if !(factor.is_finite() && factor > 0.0) {
                return Err(loc.err(
                    tspan,
                    &format!("{key}.test.factor"),
                    format!("`{factor}` is not a positive ratio"),
                ));
            }
            Test::LowerThan { metric: t.metric.clone(), lower, higher, factor }
        };
        Ok(Some(ClaimTest { select, test }))
    }
}

/// Whether two of `cases` differ in `param` and in nothing else.
pub(crate) fn has_trend(cases: &[&Case], param: &str) -> bool {
    cases.iter().enumerate().any(|(i, a)| {
        cases[i + 1..].iter().any(|b| {
            a.params.0.get(param) != b.params.0.get(param)
                && a.params.0.iter().all(|(k, v)| k == param || b.params.0.get(k) == Some(v))
        })
    })
}

/// The manuscript keys of a figure or table (`number`, `paper_caption`, `section`, `caption`,
/// `discussion`), checked: a number the manuscript can order, and the paper's caption with it.
fn item_info(
    loc: &Loc,
    span: Span,
    key: &str,
    (number, paper_caption, section, caption, discussion): (
        &Option<String>,
        &Option<String>,
        &Option<String>,
        &String,
        &String,
    ),
) -> Result<ItemInfo, String> {
    if let Some(n) = number {
        if !papers::valid_number(n) {
            return Err(loc.err(
                span,
                &format!("{key}.number"),
                format!("`{n}`: a number is `Fig. N` or `Table N`, with an optional panel (`Fig. 14a`, `Fig. 13 (left)`)"),
            ));
        }
        if paper_caption.as_deref().is_none_or(|c| c.trim().is_empty()) {
            return Err(loc.err(
                span,
                &format!("{key}.paper_caption"),
                "a numbered item needs the paper's caption in our words",
            ));
        }
    } else if paper_caption.is_some() || section.is_some() {
        let k = if paper_caption.is_some() { "paper_caption" } else { "section" };
        return Err(loc.err(span, &format!("{key}.{k}"), "only an item with the paper's `number` takes it"));
    }
    Ok(ItemInfo {
        number: number.clone(),
        paper_caption: paper_caption.clone().unwrap_or_default(),
        section: section.clone(),
        caption: caption.clone(),
        discussion: discussion.clone(),
    })
}

/// Takes `id` for a figure or a table: a name their files can carry (it becomes
/// `figures/ID.png` or `tables/ID.md`, so no path), not taken by another figure or table of
/// the problem (`ids`: each id taken, with its line).
fn claim_id(
    loc: &Loc,
    span: Span,
    key: &str,
    id: &str,
    ids: &mut BTreeMap<String, usize>,
) -> Result<(), String> {
    if !valid_name(id) {
        return Err(loc.err(span, key, "an id may use letters, digits, `.`, `_` and `-` only"));
    }
    if let Some(l) = ids.insert(id.to_string(), loc.line(span.start)) {
        return Err(loc.err(span, key, format!("a figure or table on line {l} has the same id")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{p, GOOD};

    #[test]
    fn selection_metric_and_id_errors_name_file_line_and_key() {
        let e = p(&GOOD.replace("\"sun-*\"", "\"nope\"")).unwrap_err();
        assert!(e.contains("nope") && e.contains("x.toml:1"), "{e}");
        let e =
            p(&GOOD.replace("metric = \"l1_velocity_final\"\nlabel", "metric = \"l2\"\nlabel")).unwrap_err();
        assert!(e.contains("l2"), "{e}");
        // Figure and table ids name files: a path is refused, and so is an id taken twice.
        let table = |id: &str| {
            format!("{GOOD}[[tables]]\nid = \"{id}\"\ntitle = \"t\"\nmetrics = [\"l1_velocity_final\"]\n")
        };
        assert!(p(&table("t1")).is_ok());
        let e = p(&table("../t1")).unwrap_err();
        assert!(
            e.starts_with("x.toml:") && e.contains("`tables.../t1`") && e.contains("an id may use"),
            "{e}"
        );
        let e = p(&table("f1")).unwrap_err();
        assert!(e.contains("`tables.f1`") && e.contains("has the same id"), "{e}");
        let e = p(&GOOD.replace("id = \"f1\"", "id = \"a/f1\"")).unwrap_err();
        assert!(e.contains("`figures.a/f1`") && e.contains("an id may use"), "{e}");
    }

    /// Each figure kind's own keys: what it needs, what it checks, and keys of another kind
    /// refused rather than ignored.
    #[test]
    fn figure_kinds_check_their_keys() {
        let kind = |k: &str, extra: &str| {
            GOOD.replace("kind = \"timeseries\"", &format!("kind = \"{k}\"{extra}"))
                .replace("y = \"u_max\"\n", "")
        };
        for k in ["trade", "stability"] {
            let e = p(&kind(k, "")).unwrap_err();
            assert!(e.starts_with("x.toml:") && e.contains("`figures.f1`") && e.contains("needs `x`"), "{e}");
            let e = p(&kind(k, "\nx = \"nz\"\nmax = 0.1")).unwrap_err();
            assert!(e.contains("`x` names no parameter `nz`"), "{e}");
        }
        assert!(p(&kind("trade", "\nx = \"nx\"")).is_ok());
        let e = p(&kind("stability", "\nx = \"nx\"")).unwrap_err();
        assert!(e.contains("kind `stability` needs `max`"), "{e}");
        assert!(p(&kind("stability", "\nx = \"nx\"\nmax = 0.1")).is_ok());
        // A map's own word for a case beyond `max`: a short word, and on maps only.
        assert!(p(&kind("stability", "\nx = \"nx\"\nmax = 0.1\nabove_max = \"water lost\"")).is_ok());
        let e = p(&kind("stability", "\nx = \"nx\"\nmax = 0.1\nabove_max = \"<b>\"")).unwrap_err();
        assert!(e.contains("`figures.f1.above_max`") && e.contains("`<b>` must be a short word"), "{e}");
        let e = p(&kind("trade", "\nx = \"nx\"\nabove_max = \"lost\"")).unwrap_err();
        assert!(e.contains("only kind `stability` takes `above_max`"), "{e}");
        // The exact curve's legend entry: on a timeseries with an `exact` column only.
        let ts =
            |extra: &str| GOOD.replace("kind = \"timeseries\"", &format!("kind = \"timeseries\"{extra}"));
        assert!(p(&ts("\nexact = \"u_max_exact\"\nexact_label = \"Taylor-Green\"")).is_ok());
        let e = p(&ts("\nexact_label = \"Taylor-Green\"")).unwrap_err();
        assert!(e.contains("`figures.f1.exact_label`") && e.contains("names no `exact` column"), "{e}");
        let e = p(&kind("trade", "\nx = \"nx\"\nexact = \"u_max_exact\"")).unwrap_err();
        assert!(e.contains("only kind `timeseries` takes `exact`"), "{e}");
        // Two cases in one cell of the map (nx = 16: SPST and EDAC, no `label` to part them).
        let e = p(&kind("stability", "\nx = \"nx\"\nmax = 0.1").replace("cases = [\"sun-*\"]\n", ""))
            .unwrap_err();
        assert!(e.contains("fall in one cell of the map") && e.contains("`scheme`"), "{e}");
        let e = p(&kind("particles", "")).unwrap_err();
        assert!(e.contains("needs `field`"), "{e}");
        assert!(p(&kind("particles", "\nfield = \"p\"\ntime = 0.01")).is_ok());
        let e = p(&kind("particles", "\nfield = \"p\"\ntime = 0.5")).unwrap_err();
        assert!(e.contains("`figures.f1.time`") && e.contains("after the end time"), "{e}");
        let e = p(&kind("particles", "\nfield = \"p\"\ntime = -1.0")).unwrap_err();
        assert!(e.contains("not a time >= 0"), "{e}");
        let e = p(&kind("particles", "\nfield = \"p\"\narrows = \"<n>\"")).unwrap_err();
        assert!(e.contains("`figures.f1.arrows`"), "{e}");
        assert!(p(&kind("particles", "\nfield = \"p\"\nview = [0.0, 1.0, 0.0, 2.0]")).is_ok());
        for bad in ["[1.0, 0.0, 0.0, 1.0]", "[0.0, 1.0, 0.0]", "[0.0, 1.0, 2.0, 2.0]"] {
            let e = p(&kind("particles", &format!("\nfield = \"p\"\nview = {bad}"))).unwrap_err();
            assert!(e.contains("`figures.f1.view`") && e.contains("x0 < x1"), "{bad}: {e}");
        }
        let e = p(&GOOD.replace("y = \"u_max\"", "y = \"vorticity\"")).unwrap_err();
        assert!(e.contains("`figures.f1.y`") && e.contains("no time-series column `vorticity`"), "{e}");
        for (extra, only) in [
            ("time = 0.01", "particles"),
            ("arrows = \"n\"", "particles"),
            ("view = [0.0, 1.0, 0.0, 1.0]", "particles"),
            ("x_spacing = true", "trade"),
            ("x_label = \"u\"", "profile"),
        ] {
            let e = p(&GOOD.replace("y = \"u_max\"", &format!("y = \"u_max\"\n{extra}"))).unwrap_err();
            assert!(e.contains(&format!("only kind `{only}` takes")), "{extra}: {e}");
        }
        let e = p(&kind("bars", "")).unwrap_err();
        assert!(e.contains("unknown kind `bars`") && e.contains("timeseries, particles"), "{e}");
    }
}
