//! The TOML schema of a problem file, as written: the serde structs `toml` reads it into,
//! with the spans that errors point at. Unknown keys are refused here (`deny_unknown_fields`)
//! so that a typo is an error, not a silently ignored setting.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

/// A map of parameter values as written in a problem file.
pub(super) type RawParams = BTreeMap<String, Spanned<toml::Value>>;

/// A whole problem file: its scene, problem-wide parameters, presets (named sets of
/// variables, `$name` in values), case groups, and what is drawn, tabulated and bounded.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProblemFile {
    pub(super) title: String,
    pub(super) scene: Spanned<String>,
    pub(super) paper: Spanned<String>,
    #[serde(default)]
    pub(super) section: Option<String>,
    #[serde(default)]
    pub(super) description: String,
    #[serde(default)]
    pub(super) params: RawParams,
    #[serde(default)]
    pub(super) presets: BTreeMap<String, Spanned<RawParams>>,
    #[serde(default)]
    pub(super) cases: Vec<Spanned<GroupFile>>,
    #[serde(default)]
    pub(super) figures: Vec<Spanned<FigureFile>>,
    #[serde(default)]
    pub(super) tables: Vec<Spanned<TableFile>>,
    #[serde(default)]
    pub(super) bounds: Vec<Spanned<BoundFile>>,
    #[serde(default)]
    pub(super) claims: Vec<Spanned<ClaimFile>>,
    #[serde(default)]
    pub(super) baseline: Option<Spanned<BaselineFile>>,
}

/// The `[baseline]` table: how far `check --baseline` lets a metric move from the committed
/// baseline (relative; exact when absent), for every metric or per metric, and why.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BaselineFile {
    #[serde(default)]
    pub(super) tolerance: Option<f64>,
    #[serde(default)]
    pub(super) tolerances: BTreeMap<String, f64>,
    #[serde(default)]
    pub(super) reason: Option<String>,
}

/// A `[[cases]]` group: fixed parameters, a grid of lists expanded into one case per
/// combination, and an optional name template (`sun-nx{nx}`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GroupFile {
    #[serde(default)]
    pub(super) name: Option<String>,
    #[serde(default)]
    pub(super) params: RawParams,
    #[serde(default)]
    pub(super) grid: RawParams,
}

/// The parts of a figure, table or bound that pick cases.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct SelectFile {
    #[serde(default)]
    pub(super) cases: Vec<String>,
    #[serde(default, rename = "where")]
    pub(super) where_: RawParams,
}

/// A `[[figures]]` entry: the keys of every kind, each kind reading its own (checked in
/// `checks.rs`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FigureFile {
    pub(super) id: String,
    pub(super) kind: String,
    pub(super) title: String,
    #[serde(default)]
    pub(super) number: Option<String>,
    #[serde(default)]
    pub(super) paper_caption: Option<String>,
    #[serde(default)]
    pub(super) section: Option<String>,
    #[serde(default)]
    pub(super) caption: String,
    #[serde(default)]
    pub(super) discussion: String,
    #[serde(default)]
    pub(super) cases: Vec<String>,
    #[serde(default, rename = "where")]
    pub(super) where_: RawParams,
    #[serde(default)]
    pub(super) y: Option<String>,
    #[serde(default)]
    pub(super) exact: Option<String>,
    #[serde(default)]
    pub(super) exact_label: Option<String>,
    #[serde(default)]
    pub(super) metric_over: Option<f64>,
    #[serde(default)]
    pub(super) y_label: Option<String>,
    #[serde(default)]
    pub(super) log_y: bool,
    #[serde(default)]
    pub(super) metric: Option<String>,
    #[serde(default)]
    pub(super) label: Vec<String>,
    #[serde(default)]
    pub(super) x: Option<String>,
    #[serde(default)]
    pub(super) field: Option<String>,
    #[serde(default)]
    pub(super) time: Option<f64>,
    #[serde(default)]
    pub(super) arrows: Option<String>,
    #[serde(default)]
    pub(super) view: Option<Vec<f64>>,
    #[serde(default)]
    pub(super) x_spacing: bool,
    #[serde(default)]
    pub(super) above_max: Option<String>,
    #[serde(default)]
    pub(super) file: Option<String>,
    #[serde(default)]
    pub(super) x_label: Option<String>,
    #[serde(default)]
    pub(super) reference: Option<Spanned<OneOrMany<ReferenceFile>>>,
    #[serde(default)]
    pub(super) x_range: Option<String>,
    #[serde(default)]
    pub(super) max: Option<f64>,
}

/// One value or a list of them (`reference = {...}` or `reference = [{...}, {...}]`).
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum OneOrMany<T> {
    One(T),
    Many(Vec<T>),
}

impl<T> OneOrMany<T> {
    /// The values, in order.
    pub(super) fn as_slice(&self) -> &[T] {
        match self {
            OneOrMany::One(t) => std::slice::from_ref(t),
            OneOrMany::Many(v) => v,
        }
    }
}

/// Published points a `profile` figure is drawn against: two columns of a CSV file in
/// `reference_data/`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ReferenceFile {
    pub(super) file: String,
    pub(super) x: String,
    pub(super) y: String,
    #[serde(default)]
    pub(super) label: Option<String>,
    /// Only the rows whose named columns hold these values (a file of several curves).
    #[serde(default)]
    pub(super) rows: std::collections::BTreeMap<String, String>,
    /// A factor on the `y` values as drawn (a file stored in other units).
    #[serde(default)]
    pub(super) y_scale: Option<f64>,
}

/// A `[[tables]]` entry.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TableFile {
    pub(super) id: String,
    pub(super) title: String,
    #[serde(default)]
    pub(super) number: Option<String>,
    #[serde(default)]
    pub(super) paper_caption: Option<String>,
    #[serde(default)]
    pub(super) section: Option<String>,
    #[serde(default)]
    pub(super) caption: String,
    #[serde(default)]
    pub(super) discussion: String,
    #[serde(default)]
    pub(super) cases: Vec<String>,
    #[serde(default, rename = "where")]
    pub(super) where_: RawParams,
    #[serde(default)]
    pub(super) columns: Vec<String>,
    pub(super) metrics: Vec<String>,
}

/// A `[[bounds]]` entry.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BoundFile {
    pub(super) metric: String,
    #[serde(default)]
    pub(super) cases: Vec<String>,
    #[serde(default, rename = "where")]
    pub(super) where_: RawParams,
    #[serde(default)]
    pub(super) max: Option<f64>,
    #[serde(default)]
    pub(super) min: Option<f64>,
    #[serde(default)]
    pub(super) presets: Option<Vec<String>>,
}

/// A `[[claims]]` entry: the paper's claim on one of the problem's figures or tables, as a
/// test on metrics at a preset.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ClaimFile {
    pub(super) figure: String,
    pub(super) claim: String,
    #[serde(default)]
    pub(super) preset: Option<String>,
    #[serde(default)]
    pub(super) cases: Vec<String>,
    #[serde(default, rename = "where")]
    pub(super) where_: RawParams,
    pub(super) test: Spanned<TestFile>,
    pub(super) source: String,
}

/// The test of a claim: a bound on every selected case (`max`, `min`), a monotone trend
/// along a parameter (`decreasing`, `increasing`), or one selection's mean below another's
/// (`lower`, `higher`, `factor`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TestFile {
    pub(super) metric: String,
    #[serde(default)]
    pub(super) max: Option<f64>,
    #[serde(default)]
    pub(super) min: Option<f64>,
    #[serde(default)]
    pub(super) decreasing: Option<String>,
    #[serde(default)]
    pub(super) increasing: Option<String>,
    #[serde(default)]
    pub(super) lower: Option<SelectFile>,
    #[serde(default)]
    pub(super) higher: Option<SelectFile>,
    #[serde(default)]
    pub(super) factor: Option<f64>,
}

/// A byte range of a problem file, where an error points.
pub(super) type Span = std::ops::Range<usize>;

/// Where an error is: file and line.
pub(super) struct Loc<'a> {
    pub(super) path: &'a Path,
    pub(super) src: &'a str,
}

impl Loc<'_> {
    /// The line of byte `offset`, from 1.
    pub(super) fn line(&self, offset: usize) -> usize {
        self.src[..offset.min(self.src.len())].matches('\n').count() + 1
    }
    /// An error at `span`, naming the file, the line and the `key`.
    pub(super) fn err(&self, span: Span, key: &str, msg: impl std::fmt::Display) -> String {
        format!("{}:{}: `{key}`: {msg}", self.path.display(), self.line(span.start))
    }
}
