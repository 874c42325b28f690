//! The resolved model of a problem, as the rest of the crate uses it: a [`Problem`] with its
//! [`Case`]s (every parameter resolved) for one preset, the [`Figure`]s and [`Table`]s it
//! regenerates and the [`Bound`]s `check` enforces, each picking its cases with a
//! [`Select`].

use crate::scenes::params::{Params, Value};
use crate::scenes::SceneEntry;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// The preset used when none is named.
pub const DEFAULT_PRESET: &str = "quick";

/// The most cases a problem may have in a preset: far more than any problem here runs,
/// few enough to expand and check at once.
pub const MAX_CASES: usize = 10_000;

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
#[derive(Clone, Debug, Default, PartialEq)]
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

/// Whether two parameter values are equal, an integer equal to a float of the same value.
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
        /// Its legend entry: what the solution is ("exact" unless the problem names it, as
        /// where the reference is exact only for another set-up).
        exact_label: String,
        /// Where the figure's `metric` is a mean of the curve over the last part of each
        /// run, that part as a fraction of the run (`metric_over = 0.5`: its second half):
        /// the metric is drawn as a segment over it, so that the value tested is seen beside
        /// an oscillating curve.
        metric_over: Option<f64>,
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
        /// The region drawn, `[x0, x1, y0, y1]` (the paper's frame, e.g. the tank); `None`:
        /// every particle. The particles outside it are counted in the figure's text.
        view: Option<[f64; 4]>,
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
        /// The word for such a case in this map (`above_max`, default "inaccurate"): what
        /// exceeding `max` means, e.g. "fractured" for a count of clusters.
        above: String,
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
        /// Published points drawn as markers (one set per entry).
        references: Vec<Reference>,
        /// Curves drawn only over the horizontal range of the published points (`x_range =
        /// "reference"`), e.g. a toe position over the time range of the experiment.
        clip_to_reference: bool,
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

/// Where a figure or a table sits in the manuscript and what it says beside it.
#[derive(Clone, Debug, Default)]
pub struct ItemInfo {
    /// The paper's number for it (`Fig. 14a`, `Table 1`); `None`: beyond the paper.
    pub number: Option<String>,
    /// The paper's caption, in our words (numbered items).
    pub paper_caption: String,
    /// The paper's section it belongs to when not the problem's (`3.4 Free-surface ...`).
    pub section: Option<String>,
    /// Our caption: what our figure or table shows.
    pub caption: String,
    /// What is learnt from it (Markdown, present tense), after the verdicts.
    pub discussion: String,
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
    /// Its place and text in the manuscript.
    pub info: ItemInfo,
    /// Cases drawn.
    pub select: Select,
    /// Its selection resolved in every preset of the file (by name), e.g. for a stability
    /// map's table of every preset.
    pub select_at: BTreeMap<String, Select>,
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
}

/// A table of summary values.
#[derive(Clone, Debug)]
pub struct Table {
    /// File stem.
    pub id: String,
    /// Title.
    pub title: String,
    /// Its place and text in the manuscript.
    pub info: ItemInfo,
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

/// A claim of the paper on one of a problem's figures or tables, checked as a test on the
/// summaries' metrics at a preset.
#[derive(Clone, Debug)]
pub struct Claim {
    /// The id of the figure or table it is judged on.
    pub figure: String,
    /// The paper's claim, in our words.
    pub claim: String,
    /// The preset whose results judge it (the resolution it is stated at).
    pub preset: String,
    /// Where the tolerance (or the qualitative test) comes from.
    pub source: String,
    /// Line in the problem file.
    pub line: usize,
    /// Its selection and test resolved in every preset where the selection picks a case
    /// (by preset name; always holds `preset`).
    pub at: BTreeMap<String, ClaimTest>,
}

/// A claim's selection and test, resolved in one preset.
#[derive(Clone, Debug)]
pub struct ClaimTest {
    /// The cases it is judged on.
    pub select: Select,
    /// The test.
    pub test: Test,
}

/// What a claim tests.
#[derive(Clone, Debug, PartialEq)]
pub enum Test {
    /// `metric` within `[min, max]` in every selected case.
    Bound {
        /// Metric.
        metric: String,
        /// Largest value that meets the claim.
        max: Option<f64>,
        /// Smallest value that meets the claim.
        min: Option<f64>,
    },
    /// `metric` falls (or grows) strictly as `param` grows, in every group of selected
    /// cases alike in their other parameters.
    Monotone {
        /// Metric.
        metric: String,
        /// The parameter along which it is monotone.
        param: String,
        /// Falls (`true`) or grows.
        decreasing: bool,
    },
    /// In every group of the claim's cases alike but in the parameters `lower` and `higher`
    /// select by (each resolution of a study on its own), the mean of `metric` over the
    /// group's `lower` cases is at most `factor` times its mean over its `higher` ones.
    LowerThan {
        /// Metric.
        metric: String,
        /// The cases the paper finds better.
        lower: Select,
        /// The cases they are compared with.
        higher: Select,
        /// The ratio the claim allows (1: lower or equal).
        factor: f64,
    },
}

impl Test {
    /// The metric tested.
    pub fn metric(&self) -> &str {
        match self {
            Test::Bound { metric, .. } | Test::Monotone { metric, .. } | Test::LowerThan { metric, .. } => {
                metric
            }
        }
    }
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
    /// The paper it belongs to (a key of [`papers::PAPERS`](crate::automation::papers::PAPERS)).
    pub paper: String,
    /// The paper's section its numbered figures and tables belong to (`4.1 Taylor-Green
    /// vortex`), unless an item names its own.
    pub section: Option<String>,
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
    /// The paper's claims, each resolved in every preset.
    pub claims: Vec<Claim>,
    /// How far `check --baseline` lets the quick preset's metrics move.
    pub baseline: BaselineRule,
}

/// How far `check --baseline` lets a metric of the quick preset move from its committed
/// baseline: exactly not at all unless the problem file says otherwise (`[baseline]`), with
/// the reason. The arithmetic is deterministic on any number of threads, so a result that
/// moves has changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BaselineRule {
    /// The relative tolerance of every metric not named below (0: exact).
    pub tolerance: f64,
    /// Relative tolerances per metric.
    pub tolerances: BTreeMap<String, f64>,
    /// Why the results are not exact, where a tolerance is given.
    pub reason: Option<String>,
}

impl BaselineRule {
    /// The relative tolerance of `metric`.
    pub fn of(&self, metric: &str) -> f64 {
        self.tolerances.get(metric).copied().unwrap_or(self.tolerance)
    }
}

impl Problem {
    /// The cases of every preset, this one first: `(preset, cases)`.
    pub fn presets(&self) -> Vec<(&str, &[Case])> {
        let mut v = vec![(self.preset.as_str(), self.cases.as_slice())];
        v.extend(self.other_presets.iter().map(|(n, c)| (n.as_str(), c.as_slice())));
        v
    }

    /// The cases of preset `name`, if the problem has it.
    pub fn cases_of(&self, name: &str) -> Option<&[Case]> {
        self.presets().into_iter().find(|(n, _)| *n == name).map(|(_, c)| c)
    }
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

/// Whether `s` may name a problem file, a case, a figure or table id, or a file in a case
/// folder: letters, digits, `.`, `_` and `-` only (no path).
pub(super) fn valid_name(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'))
}

/// Whether `s` may stand in a map's key and its tables for an outcome: a short word or two
/// (letters, spaces and `-`, at most 24 characters, starting with a letter).
pub(super) fn is_word(s: &str) -> bool {
    s.len() <= 24
        && s.starts_with(|c: char| c.is_ascii_alphabetic())
        && s.chars().all(|c| c.is_ascii_alphabetic() || matches!(c, ' ' | '-'))
}
