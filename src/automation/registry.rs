//! The problem registry: reads `problems/*.toml`, checks every entry against the scene's
//! declared parameters and metrics, and expands parameter grids into named cases for a
//! preset. Every error names the file, the line and the key; nothing runs unless every
//! problem file is valid. The schema is documented in `docs/problems.md`.

use crate::scenes::params::{Params, Spec, Value};
use crate::scenes::{self, SceneEntry};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The preset used when none is named.
pub const DEFAULT_PRESET: &str = "quick";

/// The most cases a problem may have in a preset: far more than any problem here runs,
/// few enough to expand and check at once.
pub const MAX_CASES: usize = 10_000;

/// A map of parameter values as written in a problem file.
type RawParams = BTreeMap<String, Spanned<toml::Value>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProblemFile {
    title: String,
    scene: Spanned<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    params: RawParams,
    #[serde(default)]
    presets: BTreeMap<String, Spanned<RawParams>>,
    #[serde(default)]
    cases: Vec<Spanned<GroupFile>>,
    #[serde(default)]
    figures: Vec<Spanned<FigureFile>>,
    #[serde(default)]
    tables: Vec<Spanned<TableFile>>,
    #[serde(default)]
    bounds: Vec<Spanned<BoundFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GroupFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    params: RawParams,
    #[serde(default)]
    grid: RawParams,
}

/// The parts of a figure, table or bound that pick cases.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SelectFile {
    #[serde(default)]
    cases: Vec<String>,
    #[serde(default, rename = "where")]
    where_: RawParams,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FigureFile {
    id: String,
    kind: String,
    title: String,
    #[serde(default)]
    caption: String,
    #[serde(default)]
    paper: String,
    #[serde(default)]
    cases: Vec<String>,
    #[serde(default, rename = "where")]
    where_: RawParams,
    #[serde(default)]
    y: Option<String>,
    #[serde(default)]
    exact: Option<String>,
    #[serde(default)]
    y_label: Option<String>,
    #[serde(default)]
    log_y: bool,
    #[serde(default)]
    metric: Option<String>,
    #[serde(default)]
    label: Vec<String>,
    #[serde(default)]
    x: Option<String>,
    #[serde(default)]
    field: Option<String>,
    #[serde(default)]
    time: Option<f64>,
    #[serde(default)]
    arrows: Option<String>,
    #[serde(default)]
    x_spacing: bool,
    #[serde(default)]
    file: Option<String>,
    #[serde(default)]
    x_label: Option<String>,
    #[serde(default)]
    reference: Option<Spanned<ReferenceFile>>,
    #[serde(default)]
    max: Option<f64>,
    #[serde(default)]
    converges: bool,
    #[serde(default)]
    lower: Option<SelectFile>,
    #[serde(default)]
    higher: Option<SelectFile>,
}

/// Published points a `profile` figure is drawn against: two columns of a CSV file in
/// `reference_data/`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ReferenceFile {
    file: String,
    x: String,
    y: String,
    #[serde(default)]
    label: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TableFile {
    id: String,
    title: String,
    #[serde(default)]
    caption: String,
    #[serde(default)]
    cases: Vec<String>,
    #[serde(default, rename = "where")]
    where_: RawParams,
    #[serde(default)]
    columns: Vec<String>,
    metrics: Vec<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoundFile {
    metric: String,
    #[serde(default)]
    cases: Vec<String>,
    #[serde(default, rename = "where")]
    where_: RawParams,
    #[serde(default)]
    max: Option<f64>,
    #[serde(default)]
    min: Option<f64>,
    #[serde(default)]
    presets: Option<Vec<String>>,
}

/// One simulation: a scene with every parameter resolved.
#[derive(Clone, Debug)]
pub struct Case {
    /// Name, unique within its problem (letters, digits, `.`, `_`, `-`).
    pub name: String,
    /// Scene name.
    pub scene: String,
    /// Every declared parameter, defaults filled in.
    pub params: Params,
}

/// Which cases a figure, table or bound is about: names (globs) and parameter values; a
/// case is selected when it matches one of the globs (or there are none) and every value.
#[derive(Clone, Debug, Default)]
pub struct Select {
    /// Globs over case names (empty: every case).
    pub cases: Vec<String>,
    /// Parameter values the case must have.
    pub where_: BTreeMap<String, Value>,
}

impl Select {
    /// Whether `case` is selected.
    pub fn matches(&self, case: &Case) -> bool {
        let by_name =
            self.cases.is_empty() || self.cases.iter().any(|g| glob_matches(g, &case.name).unwrap_or(false));
        by_name && self.where_.iter().all(|(k, v)| case.params.0.get(k).is_some_and(|c| values_equal(c, v)))
    }

    /// The selected cases, in problem order.
    pub fn pick<'a>(&self, cases: &'a [Case]) -> Vec<&'a Case> {
        cases.iter().filter(|c| self.matches(c)).collect()
    }
}

/// Whether `name` matches the glob `pattern`.
pub fn glob_matches(pattern: &str, name: &str) -> Result<bool, String> {
    globset::Glob::new(pattern)
        .map(|g| g.compile_matcher().is_match(name))
        .map_err(|e| format!("bad glob `{pattern}`: {e}"))
}

fn values_equal(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Int(i)) | (Value::Int(i), Value::Float(x)) => *x == *i as f64,
        _ => a == b,
    }
}

/// What a figure draws.
#[derive(Clone, Debug, PartialEq)]
pub enum FigureKind {
    /// A `timeseries.csv` column against `t`, one curve per case, with an optional exact
    /// curve (dashed) from the first case.
    Timeseries {
        /// Column drawn.
        y: String,
        /// Column holding the exact solution.
        exact: Option<String>,
    },
    /// The particles of one case's snapshot (the last one, or the one nearest `time`),
    /// coloured by a point array, with an optional vector array drawn as short segments.
    Particles {
        /// Point array (e.g. `pressure`).
        field: String,
        /// Simulated time of the snapshot drawn (the nearest listed in `fluid.pvd`);
        /// `None`: the last snapshot.
        time: Option<f64>,
        /// A 3-component point array (e.g. `normal`) drawn as segments about one particle
        /// spacing long at the particles where it is non-zero.
        arrows: Option<String>,
    },
    /// Error against cost (wall time and particle-steps) with the Pareto front, and the
    /// same as a table with the observed orders of convergence along `x`.
    Trade {
        /// The resolution parameter (e.g. `nx`); h is taken as `1 / x`, or as `x` when
        /// `spacing` (e.g. `dx`).
        x: String,
        /// `x` is a spacing (h = x) rather than a count (h = 1 / x).
        spacing: bool,
    },
    /// Outcome map (stable / inaccurate / diverged) of the curve groups against parameter
    /// `x`, and the same as a table.
    Stability {
        /// Swept parameter.
        x: String,
        /// Above this value of the metric a case that completed is inaccurate.
        max: f64,
    },
    /// Column `y` against column `x` of a CSV file in each case folder (e.g. a velocity
    /// profile written at the end of the run), one curve per case, with optional
    /// published points.
    Profile {
        /// File name in the case folder (e.g. `centerline_u.csv`).
        file: String,
        /// Column on the horizontal axis.
        x: String,
        /// Column on the vertical axis.
        y: String,
        /// Published points drawn as markers.
        reference: Option<Reference>,
    },
}

/// Published points of a [`FigureKind::Profile`], read and checked when the problem file
/// is loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// The CSV file (under `reference_data/`).
    pub path: PathBuf,
    /// Legend entry.
    pub label: String,
    /// Column on the horizontal axis.
    pub x_column: String,
    /// Column on the vertical axis.
    pub y_column: String,
    /// Its values, one per row.
    pub x: Vec<f64>,
    /// Its values, one per row.
    pub y: Vec<f64>,
}

/// A figure a problem regenerates.
#[derive(Clone, Debug)]
pub struct Figure {
    /// File stem, named after the paper (e.g. `fig06a_tg_decay_sun_re100`).
    pub id: String,
    /// What it draws.
    pub kind: FigureKind,
    /// Title.
    pub title: String,
    /// Caption in the manuscript.
    pub caption: String,
    /// What the paper shows, for the manuscript's comparison line.
    pub paper: String,
    /// Cases drawn.
    pub select: Select,
    /// X-axis label (with units; `profile` only).
    pub x_label: Option<String>,
    /// Y-axis label (with units).
    pub y_label: Option<String>,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The summary metric reported in the manuscript (and drawn by trade and stability).
    pub metric: Option<String>,
    /// Parameters naming each curve (or each row of a stability map).
    pub label: Vec<String>,
    /// The paper's claim: the metric decreases as the last `label` parameter grows.
    pub converges: bool,
    /// The paper's claim: the `lower` cases have a smaller metric than the `higher` ones.
    pub lower_than: Option<(Select, Select)>,
}

/// A table of summary values.
#[derive(Clone, Debug)]
pub struct Table {
    /// File stem.
    pub id: String,
    /// Title.
    pub title: String,
    /// Caption.
    pub caption: String,
    /// Rows.
    pub select: Select,
    /// Parameter columns.
    pub columns: Vec<String>,
    /// Metric columns.
    pub metrics: Vec<String>,
}

/// A bound `check` enforces.
#[derive(Clone, Debug)]
pub struct Bound {
    /// Metric.
    pub metric: String,
    /// Cases it applies to.
    pub select: Select,
    /// Largest accepted value.
    pub max: Option<f64>,
    /// Smallest accepted value.
    pub min: Option<f64>,
    /// Presets it applies to (bounds are measured on one).
    pub presets: Vec<String>,
    /// Line in the problem file.
    pub line: usize,
}

/// A problem: one paper benchmark, with its cases expanded for one preset.
#[derive(Clone)]
pub struct Problem {
    /// File stem, used as the output folder name.
    pub name: String,
    /// Problem file.
    pub path: PathBuf,
    /// Title.
    pub title: String,
    /// Description (Markdown), for the manuscript.
    pub description: String,
    /// Scene.
    pub scene: &'static SceneEntry,
    /// Preset the cases were expanded for.
    pub preset: String,
    /// The cases each other preset of the file expands to (by preset name), so that their
    /// results are known for what they are.
    pub other_presets: Vec<(String, Vec<Case>)>,
    /// Cases of this preset.
    pub cases: Vec<Case>,
    /// Figures.
    pub figures: Vec<Figure>,
    /// Tables.
    pub tables: Vec<Table>,
    /// Bounds that apply to this preset.
    pub bounds: Vec<Bound>,
}

impl std::fmt::Debug for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Problem")
            .field("name", &self.name)
            .field("scene", &self.scene.name)
            .field("preset", &self.preset)
            .field("cases", &self.cases)
            .finish_non_exhaustive()
    }
}

/// A byte range of a problem file, where an error points.
type Span = std::ops::Range<usize>;

/// Where an error is: file and line.
struct Loc<'a> {
    path: &'a Path,
    src: &'a str,
}

impl Loc<'_> {
    fn line(&self, offset: usize) -> usize {
        self.src[..offset.min(self.src.len())].matches('\n').count() + 1
    }
    fn err(&self, span: std::ops::Range<usize>, key: &str, msg: impl std::fmt::Display) -> String {
        format!("{}:{}: `{key}`: {msg}", self.path.display(), self.line(span.start))
    }
}

/// Loads and validates every `*.toml` in `dir`, sorted by name, expanded for `preset`.
/// Problems without that preset are an error naming them.
pub fn load_dir(dir: &Path, preset: &str) -> Result<Vec<Problem>, String> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: cannot read the problems folder: {e}", dir.display()))?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(format!("{}: no problem files (*.toml)", dir.display()));
    }
    let mut errors = Vec::new();
    let mut problems = Vec::new();
    for p in &paths {
        match load(p, preset) {
            Ok(pr) => problems.push(pr),
            Err(e) => errors.push(e),
        }
    }
    if errors.is_empty() {
        Ok(problems)
    } else {
        Err(errors.join("\n"))
    }
}

/// Loads, validates and expands one problem file for `preset`. Every preset of the file is
/// expanded and checked, so an error in `paper` is found while running `quick`.
pub fn load(path: &Path, preset: &str) -> Result<Problem, String> {
    let src = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(path, &src, preset)
}

/// The folder of published curves for the problem file at `path`: `reference_data/` next
/// to the problems folder (`problems/x.toml` -> `reference_data/`).
pub fn reference_dir(path: &Path) -> PathBuf {
    let problems = path.parent().unwrap_or(Path::new(""));
    match problems.parent() {
        Some(root) => root.join("reference_data"),
        None => problems.join("..").join("reference_data"),
    }
}

/// [`load`] from a string (`path` names it in errors and locates `reference_data/`).
pub fn parse(path: &Path, src: &str, preset: &str) -> Result<Problem, String> {
    parse_with(path, src, preset, scenes::find)
}

/// [`parse`] with the scenes looked up by `find` (tests validate problem files against
/// declared scene contracts with it).
pub fn parse_with(
    path: &Path,
    src: &str,
    preset: &str,
    find: fn(&str) -> Result<&'static SceneEntry, String>,
) -> Result<Problem, String> {
    let loc = Loc { path, src };
    let file: ProblemFile = toml::from_str(src).map_err(|e| {
        let line = e.span().map(|s| loc.line(s.start)).unwrap_or(1);
        // The parser names the value, not always its key: quote the line, which holds both.
        let text = src.lines().nth(line - 1).map(str::trim).unwrap_or_default();
        let quoted = if text.is_empty() || text.len() > 80 { String::new() } else { format!("`{text}`: ") };
        format!("{}:{line}: {quoted}{}", path.display(), e.message().trim_end().replace('\n', " "))
    })?;
    let scene = find(file.scene.get_ref()).map_err(|e| loc.err(file.scene.span(), "scene", e))?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    if !valid_name(&name) {
        return Err(format!(
            "{}: the file name must use letters, digits, `.`, `_` and `-` only",
            path.display()
        ));
    }
    let specs = (scene.params)();
    if !file.presets.contains_key(DEFAULT_PRESET) {
        return Err(format!("{}: no [presets.{DEFAULT_PRESET}] (the default preset)", path.display()));
    }
    if file.cases.is_empty() {
        return Err(format!("{}: no [[cases]]: a problem needs at least one", path.display()));
    }
    // Preset variables: every preset defines the same names; the one that lacks a name
    // another defines is the one named.
    for (pname, vars) in &file.presets {
        for (other, other_vars) in &file.presets {
            if let Some(v) = other_vars.get_ref().keys().find(|v| !vars.get_ref().contains_key(*v)) {
                return Err(loc.err(
                    vars.span(),
                    &format!("presets.{pname}"),
                    format!("does not define `{v}`, which [presets.{other}] does: every preset defines the same variables"),
                ));
            }
        }
    }
    let (mut out, mut others) = (None, Vec::new());
    for (pname, vars) in &file.presets {
        let x = Expand { loc: &loc, file: &file, scene, specs: &specs, preset: pname, vars: vars.get_ref() };
        let p = x.problem(&name)?;
        if pname == preset {
            out = Some(p);
        } else {
            others.push((pname.clone(), p.cases));
        }
    }
    let mut problem = out.ok_or_else(|| {
        let known: Vec<_> = file.presets.keys().cloned().collect();
        format!("{}: no preset `{preset}`; this problem has: {}", path.display(), known.join(", "))
    })?;
    problem.other_presets = others;
    // What the scene would refuse at build time (a support that reaches no neighbour, a
    // resolution this machine cannot hold, ...), found before anything runs; for the preset
    // asked for only, since the others may be meant for a larger machine.
    for c in &problem.cases {
        crate::scenes::harness::check_times(scene.name, &c.params)
            .and_then(|()| (scene.check)(&c.params))
            .map_err(|e| format!("{}: case `{}` (preset {preset}): {e}", path.display(), c.name))?;
    }
    Ok(problem)
}

fn valid_name(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'))
}

/// A value as written, after substituting preset variables: one value or a list.
enum Raw {
    One(Value),
    List(Vec<Value>),
}

fn to_value(v: &toml::Value) -> Result<Value, String> {
    Ok(match v {
        toml::Value::Boolean(b) => Value::Bool(*b),
        toml::Value::Integer(i) => Value::Int(*i),
        toml::Value::Float(x) => Value::Float(*x),
        toml::Value::String(s) => Value::Str(s.clone()),
        other => return Err(format!("expected a number, a boolean or a name, found {other}")),
    })
}

fn resolve_raw(
    loc: &Loc,
    key: &str,
    v: &Spanned<toml::Value>,
    vars: &RawParams,
    preset: &str,
) -> Result<Raw, String> {
    let err = |m: String| loc.err(v.span(), key, m);
    let mut val = v.get_ref();
    if let toml::Value::String(s) = val {
        if let Some(var) = s.strip_prefix('$') {
            val = vars
                .get(var)
                .map(|x| x.get_ref())
                .ok_or_else(|| err(format!("preset `{preset}` does not define the variable `{var}`")))?;
        }
    }
    match val {
        toml::Value::Array(a) => {
            a.iter().map(to_value).collect::<Result<Vec<_>, _>>().map(Raw::List).map_err(err)
        }
        other => to_value(other).map(Raw::One).map_err(err),
    }
}

fn check_param(
    loc: &Loc,
    span: std::ops::Range<usize>,
    scene: &SceneEntry,
    specs: &[Spec],
    key: &str,
    v: &Value,
) -> Result<Value, String> {
    let spec = specs.iter().find(|s| s.name == key).ok_or_else(|| {
        let known: Vec<_> = specs.iter().map(|s| s.name).collect();
        loc.err(
            span.clone(),
            key,
            format!(
                "scene `{}` has no parameter `{key}`; known parameters: {}",
                scene.name,
                known.join(", ")
            ),
        )
    })?;
    spec.check(scene.name, v).map_err(|e| loc.err(span, key, e))
}

/// Checks a `where` table: known parameters, values of the right type.
fn select(
    loc: &Loc,
    scene: &SceneEntry,
    specs: &[Spec],
    cases: &[String],
    where_: &RawParams,
    vars: &RawParams,
    preset: &str,
) -> Result<Select, String> {
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

/// Checks that a selection matches at least one case.
fn nonempty(
    loc: &Loc,
    span: std::ops::Range<usize>,
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

fn check_metric(
    loc: &Loc,
    span: std::ops::Range<usize>,
    what: &str,
    scene: &SceneEntry,
    m: &str,
) -> Result<(), String> {
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

/// What expanding one problem file has at hand: where its errors point, the file, its scene
/// (and the scene's parameters), the preset and the file's variables.
struct Expand<'a> {
    loc: &'a Loc<'a>,
    file: &'a ProblemFile,
    scene: &'static SceneEntry,
    specs: &'a [Spec],
    preset: &'a str,
    vars: &'a RawParams,
}

impl Expand<'_> {
    /// The problem `name` in this preset: its cases, then its figures, tables and bounds,
    /// each checked against the scene and the cases.
    fn problem(&self, name: &str) -> Result<Problem, String> {
        let file = self.file;
        let cases = self.cases()?;
        // Figures and tables share one space of ids.
        let mut ids: BTreeMap<String, usize> = BTreeMap::new();
        let figures =
            file.figures.iter().map(|f| self.figure(f, &cases, &mut ids)).collect::<Result<Vec<_>, _>>()?;
        let tables =
            file.tables.iter().map(|t| self.table(t, &cases, &mut ids)).collect::<Result<Vec<_>, _>>()?;
        let bounds = file
            .bounds
            .iter()
            .filter_map(|b| self.bound(b, &cases).transpose())
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Problem {
            name: name.to_string(),
            path: self.loc.path.to_path_buf(),
            title: file.title.clone(),
            description: file.description.clone(),
            scene: self.scene,
            preset: self.preset.to_string(),
            other_presets: Vec::new(),
            cases,
            figures,
            tables,
            bounds,
        })
    }

    /// The cases of the preset: the problem-wide parameters over the scene's defaults, then
    /// each group's, its grid expanded (a simulation named twice, or named alike with
    /// other parameters, is caught here).
    fn cases(&self) -> Result<Vec<Case>, String> {
        let Expand { loc, file, scene, specs, preset, vars } = *self;
        // Problem-wide parameters over the defaults.
        let mut base = Params::defaults(specs);
        for (k, v) in &file.params {
            match resolve_raw(loc, k, v, vars, preset)? {
                Raw::One(x) => {
                    let x = check_param(loc, v.span(), scene, specs, k, &x)?;
                    base.0.insert(k.clone(), x);
                }
                Raw::List(_) => {
                    return Err(loc.err(v.span(), k, "a list is a grid: put it under [cases.grid]"))
                }
            }
        }
        let mut cases: Vec<Case> = Vec::new();
        let mut case_lines: BTreeMap<String, usize> = BTreeMap::new();
        for g in &file.cases {
            let gspan = g.span();
            let g = g.get_ref();
            let mut fixed = base.clone();
            let mut set_keys: Vec<(String, Vec<Value>)> = Vec::new();
            for (k, v) in &g.params {
                match resolve_raw(loc, k, v, vars, preset)? {
                    Raw::One(x) => {
                        let x = check_param(loc, v.span(), scene, specs, k, &x)?;
                        fixed.0.insert(k.clone(), x.clone());
                        set_keys.push((k.clone(), vec![x]));
                    }
                    Raw::List(_) => return Err(loc.err(v.span(), k, "a list belongs under [cases.grid]")),
                }
            }
            for (k, v) in &g.grid {
                let vals = match resolve_raw(loc, k, v, vars, preset)? {
                    Raw::One(x) => vec![x],
                    Raw::List(l) => l,
                };
                if vals.is_empty() {
                    return Err(loc.err(v.span(), k, "an empty list makes no case"));
                }
                let vals = vals
                    .iter()
                    .map(|x| check_param(loc, v.span(), scene, specs, k, x))
                    .collect::<Result<Vec<_>, _>>()?;
                set_keys.retain(|(s, _)| s != k);
                set_keys.push((k.clone(), vals));
            }
            // Product of the grid (like automan's mdict/dprod), counted before it is made:
            // seven lists of ten values would make ten million cases.
            let count = set_keys.iter().fold(1f64, |n, (_, vals)| n * vals.len() as f64);
            if cases.len() as f64 + count > MAX_CASES as f64 {
                return Err(loc.err(
                    gspan.clone(),
                    "cases.grid",
                    format!(
                        "this group makes {count:.0} case(s), which brings the problem past {MAX_CASES}: more than one problem can run"
                    ),
                ));
            }
            let mut combos: Vec<Params> = vec![fixed];
            for (k, vals) in &set_keys {
                combos = combos
                    .into_iter()
                    .flat_map(|p| {
                        vals.iter().map(move |v| {
                            let mut q = p.clone();
                            q.0.insert(k.clone(), v.clone());
                            q
                        })
                    })
                    .collect();
            }
            let given = |k: &str| file.params.contains_key(k) || set_keys.iter().any(|(s, _)| s == k);
            for p in combos {
                let cname = case_name(g.name.as_deref(), &set_keys, &p)
                    .map_err(|e| loc.err(gspan.clone(), "cases.name", e))?;
                if let Some((key, why)) = scenes::common::unused_scheme_option(&p, given) {
                    return Err(loc.err(
                        gspan.clone(),
                        key,
                        format!("= {} in case `{cname}` {why}", p.0[key]),
                    ));
                }
                if !valid_name(&cname) {
                    return Err(loc.err(
                        gspan.clone(),
                        "cases.name",
                        format!("case name `{cname}` may use letters, digits, `.`, `_` and `-` only"),
                    ));
                }
                if let Some(other) = cases.iter().find(|c| c.name == cname) {
                    if other.params == p {
                        continue;
                    }
                    return Err(loc.err(
                        gspan.clone(),
                        "cases.name",
                        format!(
                            "two cases are named `{cname}` (the first on line {}) with different parameters",
                            case_lines[&cname]
                        ),
                    ));
                }
                if cases.iter().any(|c| c.params == p) {
                    continue; // the same simulation under another name: run it once
                }
                case_lines.insert(cname.clone(), loc.line(gspan.start));
                cases.push(Case { name: cname, scene: scene.name.to_string(), params: p });
            }
        }
        Ok(cases)
    }

    /// The cases a figure, table or bound selects.
    fn select(&self, cases: &[String], where_: &RawParams) -> Result<Select, String> {
        select(self.loc, self.scene, self.specs, cases, where_, self.vars, self.preset)
    }

    /// One figure, checked against the scene and the cases (`ids` holds the ids taken).
    fn figure(
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
            ("x_label", f.x_label.is_some(), "profile"),
            ("time", f.time.is_some(), "particles"),
            ("arrows", f.arrows.is_some(), "particles"),
            ("x_spacing", f.x_spacing, "trade"),
        ] {
            if set && f.kind != only {
                return Err(loc.err(span, &format!("{key}.{k}"), format!("only kind `{only}` takes `{k}`")));
            }
        }
        if (f.converges || f.lower.is_some()) && f.metric.is_none() {
            return Err(loc.err(span, &key, "a claim (`converges`, `lower`) needs `metric`"));
        }
        if f.converges && f.label.is_empty() {
            return Err(loc.err(span, &key, "`converges` needs `label` (the resolution last)"));
        }
        let lower_than = match (&f.lower, &f.higher) {
            (Some(a), Some(b)) => {
                let a = self.select(&a.cases, &a.where_)?;
                let b = self.select(&b.cases, &b.where_)?;
                nonempty(loc, span.clone(), &format!("{key}.lower"), &a, cases, preset)?;
                nonempty(loc, span.clone(), &format!("{key}.higher"), &b, cases, preset)?;
                Some((a, b))
            }
            (None, None) => None,
            _ => return Err(loc.err(span, &key, "`lower` and `higher` go together")),
        };
        Ok(Figure {
            id: f.id.clone(),
            kind,
            title: f.title.clone(),
            caption: f.caption.clone(),
            paper: f.paper.clone(),
            select,
            x_label: f.x_label.clone(),
            y_label: f.y_label.clone(),
            log_y: f.log_y,
            metric: f.metric.clone(),
            label: f.label.clone(),
            converges: f.converges,
            lower_than,
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
                let max =
                    f.max.ok_or_else(|| self.loc.err(span.clone(), key, "kind `stability` needs `max`"))?;
                FigureKind::Stability { x, max }
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
                let reference = match &f.reference {
                    Some(r) => Some(reference(self.loc, r.span(), key, r.get_ref())?),
                    None => None,
                };
                FigureKind::Profile { file: file_name, x: need("x", &f.x)?, y: need("y", &f.y)?, reference }
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
        Ok(FigureKind::Timeseries { y, exact: f.exact.clone() })
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
        Ok(FigureKind::Particles { field, time: f.time, arrows: f.arrows.clone() })
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
    fn table(
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
        Ok(Table {
            id: t.id.clone(),
            title: t.title.clone(),
            caption: t.caption.clone(),
            select,
            columns: t.columns.clone(),
            metrics: t.metrics.clone(),
        })
    }

    /// One bound, checked against the scene and the cases; `None` if it does not hold in
    /// this preset.
    fn bound(&self, b: &Spanned<BoundFile>, cases: &[Case]) -> Result<Option<Bound>, String> {
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

/// Takes `id` for a figure or a table: a name their files can carry (it becomes
/// `figures/ID.png` or `tables/ID.md`, so no path), not taken by another figure or table of
/// the problem (`ids`: each id taken, with its line).
fn claim_id(
    loc: &Loc,
    span: std::ops::Range<usize>,
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

/// Reads and checks the published points of a `profile` figure: the file exists under
/// `reference_data/`, has both columns, and every value is a number.
fn reference(
    loc: &Loc,
    span: std::ops::Range<usize>,
    key: &str,
    r: &ReferenceFile,
) -> Result<Reference, String> {
    let key = format!("{key}.reference");
    if !valid_name(&r.file) || r.file.starts_with('.') {
        return Err(loc.err(
            span,
            &format!("{key}.file"),
            format!("`{}` must be a file name in reference_data/ (letters, digits, `.`, `_`, `-`)", r.file),
        ));
    }
    let path = reference_dir(loc.path).join(&r.file);
    let mut rd = csv::Reader::from_path(&path)
        .map_err(|e| loc.err(span.clone(), &format!("{key}.file"), format!("{}: {e}", path.display())))?;
    let headers = rd
        .headers()
        .map_err(|e| loc.err(span.clone(), &format!("{key}.file"), format!("{}: {e}", path.display())))?
        .clone();
    let col = |which: &str, name: &str| {
        headers.iter().position(|h| h.trim() == name).ok_or_else(|| {
            loc.err(
                span.clone(),
                &format!("{key}.{which}"),
                format!(
                    "{} has no column `{name}`; its columns: {}",
                    path.display(),
                    headers.iter().collect::<Vec<_>>().join(", ")
                ),
            )
        })
    };
    let (ix, iy) = (col("x", &r.x)?, col("y", &r.y)?);
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (i, rec) in rd.records().enumerate() {
        let row = i + 2; // the header is line 1
        let rec = rec
            .map_err(|e| loc.err(span.clone(), &format!("{key}.file"), format!("{}: {e}", path.display())))?;
        let num = |j: usize, name: &str| -> Result<f64, String> {
            let s = rec.get(j).unwrap_or("").trim();
            s.parse::<f64>().map_err(|_| {
                loc.err(
                    span.clone(),
                    &format!("{key}.file"),
                    format!("{}:{row}: column `{name}`: `{s}` is not a number", path.display()),
                )
            })
        };
        x.push(num(ix, &r.x)?);
        y.push(num(iy, &r.y)?);
    }
    if x.is_empty() {
        return Err(loc.err(span, &format!("{key}.file"), format!("{}: no rows", path.display())));
    }
    Ok(Reference {
        label: r.label.clone().unwrap_or_else(|| r.file.trim_end_matches(".csv").to_string()),
        path,
        x_column: r.x.clone(),
        y_column: r.y.clone(),
        x,
        y,
    })
}

/// A case name: the group's template with `{key}` replaced by the parameter's value, or,
/// without a template, `key-value` for every key the group sets, joined by `_`.
fn case_name(
    template: Option<&str>,
    set_keys: &[(String, Vec<Value>)],
    p: &Params,
) -> Result<String, String> {
    let show = |v: &Value| match v {
        Value::Float(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{}", *x as i64),
        v => v.to_string(),
    };
    match template {
        Some(t) => {
            let mut out = String::new();
            let mut rest = t;
            while let Some(i) = rest.find('{') {
                out.push_str(&rest[..i]);
                let j = rest[i..].find('}').ok_or_else(|| format!("unclosed `{{` in name template `{t}`"))?;
                let key = &rest[i + 1..i + j];
                let v =
                    p.0.get(key).ok_or_else(|| format!("name template `{t}` names no parameter `{key}`"))?;
                out.push_str(&show(v));
                rest = &rest[i + j + 1..];
            }
            out.push_str(rest);
            Ok(out)
        }
        None => {
            Ok(set_keys.iter().map(|(k, _)| format!("{k}-{}", show(&p.0[k]))).collect::<Vec<_>>().join("_"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
title = "t"
scene = "taylor_green"
[params]
tf = "$tf"
[presets.quick]
tf = 0.05
nx = [12, 16]
[presets.paper]
tf = 2.0
nx = [50, 100]
[[cases]]
name = "sun-nx{nx}"
params = { pst = "sun" }
grid = { nx = "$nx" }
[[cases]]
grid = { scheme = ["edac", "ctvf"], nx = 16 }
[[figures]]
id = "f1"
kind = "timeseries"
title = "x"
y = "u_max"
cases = ["sun-*"]
metric = "l1_velocity_final"
label = ["nx"]
[[bounds]]
metric = "l1_velocity_final"
where = { nx = 16, pst = "sun", scheme = "ctvf" }
max = 1.0
"#;

    fn p(src: &str) -> Result<Problem, String> {
        parse(Path::new("x.toml"), src, "quick")
    }

    #[test]
    fn expands_grids_and_merges_identical_cases() {
        let pr = p(GOOD).unwrap();
        let names: Vec<_> = pr.cases.iter().map(|c| c.name.as_str()).collect();
        // sun-nx16 and the ctvf case of the second group are the same simulation.
        assert_eq!(names, ["sun-nx12", "sun-nx16", "nx-16_scheme-edac"]);
        assert_eq!(pr.cases[0].params.0["tf"], Value::Float(0.05));
        assert_eq!(pr.bounds.len(), 1);
        let paper = parse(Path::new("x.toml"), GOOD, "paper").unwrap();
        assert_eq!(paper.cases[1].name, "sun-nx100");
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let e = p(&GOOD.replace("title = \"x\"", "title = \"x\"\ncolour = 3")).unwrap_err();
        assert!(e.contains("x.toml:") && e.contains("colour"), "{e}");
        let e = p(&GOOD.replace("pst = \"sun\"", "pst = \"warp\"")).unwrap_err();
        assert!(e.starts_with("x.toml:14:") && e.contains("pst"), "{e}");
        let e = p(&GOOD.replace("pst = \"sun\" }", "pst = \"sun\", frob = 1 }")).unwrap_err();
        assert!(e.contains("frob") && e.contains(":14:"), "{e}");
        let e = p(&GOOD.replace("nx = 16 }", "nx = 1.5 }")).unwrap_err();
        assert!(e.contains("nx") && e.contains("integer"), "{e}");
        let e = p(&GOOD.replace("\"sun-*\"", "\"nope\"")).unwrap_err();
        assert!(e.contains("nope") && e.contains("x.toml:1"), "{e}");
        let e =
            p(&GOOD.replace("metric = \"l1_velocity_final\"\nlabel", "metric = \"l2\"\nlabel")).unwrap_err();
        assert!(e.contains("l2"), "{e}");
        let e = p(&GOOD.replace("taylor_green", "nope")).unwrap_err();
        assert!(e.contains("x.toml:3:") && e.contains("nope"), "{e}");
        let dup =
            GOOD.replace("[[figures]]", "[[cases]]\nname = \"sun-nx12\"\nparams = { re = 5 }\n[[figures]]");
        let e = p(&dup).unwrap_err();
        assert!(e.contains("sun-nx12") && e.contains("two cases"), "{e}");
        // A scheme option in a case whose scheme does not read it: the `edac` case of the
        // grid, named, with the key and value.
        let ignored = GOOD.replace("grid = { scheme", "params = { pst = \"ipst\" }\ngrid = { scheme");
        let e = p(&ignored).unwrap_err();
        assert!(e.starts_with("x.toml:") && e.contains("`pst`") && e.contains("ipst"), "{e}");
        assert!(e.contains("`scheme` = edac") && e.contains("case `"), "{e}");
        // Switched off, it passes.
        assert!(p(&GOOD.replace("grid = { scheme", "params = { pst = \"none\" }\ngrid = { scheme")).is_ok());
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
        let e = p(&kind("particles", "")).unwrap_err();
        assert!(e.contains("needs `field`"), "{e}");
        assert!(p(&kind("particles", "\nfield = \"p\"\ntime = 0.01")).is_ok());
        let e = p(&kind("particles", "\nfield = \"p\"\ntime = 0.5")).unwrap_err();
        assert!(e.contains("`figures.f1.time`") && e.contains("after the end time"), "{e}");
        let e = p(&kind("particles", "\nfield = \"p\"\ntime = -1.0")).unwrap_err();
        assert!(e.contains("not a time >= 0"), "{e}");
        let e = p(&kind("particles", "\nfield = \"p\"\narrows = \"<n>\"")).unwrap_err();
        assert!(e.contains("`figures.f1.arrows`"), "{e}");
        let e = p(&GOOD.replace("y = \"u_max\"", "y = \"vorticity\"")).unwrap_err();
        assert!(e.contains("`figures.f1.y`") && e.contains("no time-series column `vorticity`"), "{e}");
        for (extra, only) in [
            ("time = 0.01", "particles"),
            ("arrows = \"n\"", "particles"),
            ("x_spacing = true", "trade"),
            ("x_label = \"u\"", "profile"),
        ] {
            let e = p(&GOOD.replace("y = \"u_max\"", &format!("y = \"u_max\"\n{extra}"))).unwrap_err();
            assert!(e.contains(&format!("only kind `{only}` takes")), "{extra}: {e}");
        }
        let e = p(&kind("bars", "")).unwrap_err();
        assert!(e.contains("unknown kind `bars`") && e.contains("timeseries, particles"), "{e}");
    }

    /// A profile figure appended to [`GOOD`], with a reference file in
    /// `ROOT/reference_data/ref.csv` (the problem is `ROOT/problems/x.toml`).
    const PROFILE: &str = r#"
[[figures]]
id = "prof"
kind = "profile"
title = "u on x = 0.5"
where = { pst = "sun" }
file = "centerline_u.csv"
x = "u"
y = "y"
x_label = "u / U (-)"
label = ["nx"]
reference = { file = "ref.csv", x = "Re100", y = "y", label = "Ghia et al. 1982" }
"#;

    fn with_reference(csv: &str) -> tempfile::TempDir {
        let root = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(root.path().join("reference_data")).unwrap();
        std::fs::write(root.path().join("reference_data/ref.csv"), csv).unwrap();
        root
    }

    fn p_in(root: &Path, src: &str) -> Result<Problem, String> {
        parse(&root.join("problems/x.toml"), src, "quick")
    }

    #[test]
    fn profile_reads_its_reference_points() {
        let root = with_reference("y,Re100,Re400\n0.0,0.0,0.0\n0.5,-0.2,-0.1\n1.0,1.0,1.0\n");
        let pr = p_in(root.path(), &format!("{GOOD}{PROFILE}")).unwrap();
        let f = pr.figures.iter().find(|f| f.id == "prof").unwrap();
        let FigureKind::Profile { file, x, y, reference: Some(r) } = &f.kind else { panic!("{:?}", f.kind) };
        assert_eq!((file.as_str(), x.as_str(), y.as_str()), ("centerline_u.csv", "u", "y"));
        assert_eq!(r.x, [0.0, -0.2, 1.0]);
        assert_eq!(r.y, [0.0, 0.5, 1.0]);
        assert_eq!(r.label, "Ghia et al. 1982");
        assert_eq!(r.path, root.path().join("reference_data/ref.csv"));
        assert_eq!(f.x_label.as_deref(), Some("u / U (-)"));
        // Without a reference, and with the default label (the file stem).
        let bare = PROFILE.replace(", label = \"Ghia et al. 1982\"", "");
        let pr = p_in(root.path(), &format!("{GOOD}{bare}")).unwrap();
        let FigureKind::Profile { reference: Some(r), .. } = &pr.figures[1].kind else { panic!() };
        assert_eq!(r.label, "ref");
        let none = bare.lines().filter(|l| !l.starts_with("reference")).collect::<Vec<_>>().join("\n");
        let pr = p_in(root.path(), &format!("{GOOD}{none}")).unwrap();
        assert!(matches!(pr.figures[1].kind, FigureKind::Profile { reference: None, .. }));
        // reference_data/ sits next to the problems folder.
        assert_eq!(reference_dir(Path::new("problems/a.toml")), Path::new("reference_data"));
        assert_eq!(reference_dir(Path::new("/r/problems/a.toml")), Path::new("/r/reference_data"));
    }

    #[test]
    fn profile_errors_name_file_line_and_key() {
        let root = with_reference("y,Re100\n0.0,0.0\n1.0,1.0\n");
        let src = format!("{GOOD}{PROFILE}");
        let line = src.lines().position(|l| l.starts_with("reference =")).unwrap() + 1;
        let at = format!("x.toml:{line}: ");
        let e = p_in(root.path(), &src.replace("\"Re100\"", "\"Re1000\"")).unwrap_err();
        assert!(
            e.contains(&at) && e.contains("`figures.prof.reference.x`") && e.contains("no column `Re1000`"),
            "{e}"
        );
        let e = p_in(root.path(), &src.replace("y = \"y\", label", "y = \"z\", label")).unwrap_err();
        assert!(e.contains(&at) && e.contains("`figures.prof.reference.y`") && e.contains("`z`"), "{e}");
        let e = p_in(root.path(), &src.replace("\"ref.csv\"", "\"nope.csv\"")).unwrap_err();
        assert!(
            e.contains(&at) && e.contains("`figures.prof.reference.file`") && e.contains("nope.csv"),
            "{e}"
        );
        let e = p_in(root.path(), &src.replace("\"ref.csv\"", "\"../ref.csv\"")).unwrap_err();
        assert!(e.contains("reference.file") && e.contains("file name"), "{e}");
        let e = p_in(root.path(), &src.replace("Ghia et al. 1982\" }", "G\", colour = 1 }")).unwrap_err();
        assert!(e.contains("colour"), "{e}");
        let bad = with_reference("y,Re100\n0.0,0.0\n0.5,oops\n");
        let e = p_in(bad.path(), &src).unwrap_err();
        assert!(e.contains(&at) && e.contains("ref.csv:3") && e.contains("`oops`"), "{e}");
        let e = p_in(root.path(), &src.replace("file = \"centerline_u.csv\"\n", "")).unwrap_err();
        assert!(e.contains("`figures.prof`") && e.contains("needs `file`"), "{e}");
        let e = p_in(root.path(), &src.replace("y = \"y\"\nx_label", "x_label")).unwrap_err();
        assert!(e.contains("needs `y`"), "{e}");
        let timeseries = src
            .replace("kind = \"profile\"", "kind = \"timeseries\"")
            .replace("y = \"y\"\nx_label", "y = \"u_max\"\nx_label");
        let e = p_in(root.path(), &timeseries).unwrap_err();
        assert!(e.contains("only kind `profile`"), "{e}");
    }
}
