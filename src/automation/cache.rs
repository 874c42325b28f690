//! The result cache: one folder per case, `OUTPUT/<problem>/<case>-<first 10 hex of key>/`,
//! keyed by a sha2 digest of the scene, the resolved parameters (canonical JSON) and the
//! solver fingerprint. A case is done when its `summary.json` (written atomically by
//! `simulate`) says `completed` or `diverged`; `case.json` beside it keeps the inputs, so
//! a stale folder can say which input changed.
//!
//! A second, read-only layer holds the committed results (`results/`, next to the problems
//! folder, [`root`]; the paper preset's export writes it): a case whose folder there holds a
//! finished summary and everything the figures of every preset read from it
//! ([`reads`](super::reads)) is done too, so that a fresh clone runs nothing that was
//! committed. A result in the output folder comes first (a forced rerun replaces the
//! committed one).

use super::registry::{Case, Problem};
use crate::solver::output::summary::{Status, Summary, SCHEME_VERSION};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The file that marks a committed case folder holding only its summary (a case of another
/// preset, exported for a verdict or a stability table): it is read by the paper preset's
/// manuscript, and is not a done case for the cache (the case's figures need more).
pub const SUMMARY_ONLY: &str = "SUMMARY_ONLY";

/// The committed results' folder of `problem`: `results/` beside its problems folder (`None`
/// for a file given without a folder).
pub fn root(problem: &Problem) -> Option<PathBuf> {
    root_of(problem.path.parent()?)
}

/// The committed results' folder beside the problems folder `problems`.
pub fn root_of(problems: &Path) -> Option<PathBuf> {
    let parent = problems.parent()?;
    Some(parent.join("results"))
}

/// Versions of parts of the solver that only some cases use, each raised whenever that
/// part's results change for unchanged parameters: `(parameter, value, version)`. A case
/// whose parameter has that value has the version in its cache key; every other case keeps
/// its results.
pub const PART_VERSIONS: &[(&str, &str, u32)] = &[
    ("pst", "sun", 1),
    ("pst", "ipst", 3),
    ("surface_pressure", "zero", 1),
    ("surface_pressure", "zero_isolated", 1),
    ("surface_pressure", "non_negative", 1),
];

/// The solver fingerprint: crate version and scheme version.
pub fn fingerprint() -> String {
    format!("{}+scheme{}", env!("CARGO_PKG_VERSION"), SCHEME_VERSION)
}

/// The fingerprint in the keys of `scene`'s cases: the solver's, and the version of what the
/// scene reports when above 0 (so that the keys of scenes still at 0 stay as they were).
pub fn fingerprint_of(scene: &str) -> String {
    match crate::scenes::find(scene) {
        Ok(e) if e.outputs > 0 => format!("{}+{}-outputs{}", fingerprint(), e.name, e.outputs),
        _ => fingerprint(),
    }
}

/// The fingerprint in the key of a case of `scene` with `params`: [`fingerprint_of`] and the
/// versions of the parts of the solver the case uses ([`PART_VERSIONS`]).
pub fn fingerprint_of_case(scene: &str, params: &BTreeMap<String, serde_json::Value>) -> String {
    let mut f = fingerprint_of(scene);
    for (key, value, version) in PART_VERSIONS {
        if params.get(*key).and_then(|v| v.as_str()) == Some(value) {
            f.push_str(&format!("+{value}{version}"));
        }
    }
    f
}

/// The parameters in a case's key: all of them but those [added later](crate::scenes::params::Spec::added_later)
/// at their default, which reproduces the results computed before they existed.
fn keyed_params(case: &Case) -> BTreeMap<String, serde_json::Value> {
    match crate::scenes::find(&case.scene) {
        Ok(entry) => case.params.without_later_defaults(&(entry.params)()).to_json(),
        Err(_) => case.params.to_json(),
    }
}

/// The inputs of a case, written to `case.json` in its folder.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CaseRecord {
    /// Problem name.
    pub problem: String,
    /// Case name.
    pub name: String,
    /// Scene.
    pub scene: String,
    /// Resolved parameters.
    pub params: BTreeMap<String, serde_json::Value>,
    /// Solver fingerprint.
    pub solver: String,
    /// The full key (hex sha256).
    pub key: String,
}

impl CaseRecord {
    /// The record of `case` of `problem` for this binary.
    pub fn new(problem: &str, case: &Case) -> Self {
        let params = keyed_params(case);
        let solver = fingerprint_of_case(&case.scene, &params);
        let canonical = serde_json::json!({
            "scene": case.scene,
            "params": params,
            "solver": solver,
        });
        let digest = Sha256::digest(canonical.to_string().as_bytes());
        let key = digest.iter().map(|b| format!("{b:02x}")).collect();
        Self {
            problem: problem.into(),
            name: case.name.clone(),
            scene: case.scene.clone(),
            params,
            solver,
            key,
        }
    }

    /// Folder name: `<case>-<first 10 hex of key>`.
    pub fn folder(&self) -> String {
        format!("{}-{}", self.name, &self.key[..10])
    }

    /// What differs between `old` (a record found on disk) and this one, in words.
    pub fn changes_from(&self, old: &CaseRecord) -> String {
        Self::describe(self.changes(old))
    }

    /// A list of [`changes`](Self::changes) as one line.
    fn describe(changes: Vec<String>) -> String {
        if changes.is_empty() {
            "unchanged inputs".into()
        } else {
            changes.join(", ")
        }
    }

    /// The inputs that differ from `old`, one entry each.
    pub fn changes(&self, old: &CaseRecord) -> Vec<String> {
        let mut out = Vec::new();
        if old.scene != self.scene {
            out.push(format!("scene {} -> {}", old.scene, self.scene));
        }
        if old.solver != self.solver {
            out.push(format!("solver {} -> {}", old.solver, self.solver));
        }
        let keys: std::collections::BTreeSet<&String> = old.params.keys().chain(self.params.keys()).collect();
        for k in keys {
            let (a, b) = (old.params.get(k), self.params.get(k));
            if a != b {
                let show = |v: Option<&serde_json::Value>| {
                    v.map(|v| v.to_string()).unwrap_or_else(|| "(none)".into())
                };
                out.push(format!("{k} {} -> {}", show(a), show(b)));
            }
        }
        out
    }
}

/// State of a case in the cache.
#[derive(Clone, Debug, PartialEq)]
pub enum State {
    /// A `completed` or `diverged` summary.
    Done(Status),
    /// A folder with a `failed` summary, or none (killed, crashed).
    Failed(String),
    /// A `summary.json` that cannot be read (edited or damaged after it was written, which
    /// `simulate` does atomically): what is wrong, and the command that computes the case
    /// again. Not rerun unless asked (`--force`): the folder holds a run that finished.
    Damaged(String),
    /// No folder. If a folder of the same case name with other inputs exists (not the
    /// current result of another preset), the change: the case is stale.
    Missing(Option<String>),
    /// No result in the output folder, and the committed one lacks what a figure reads
    /// (see [`reads`](super::reads)), in words: the case runs again.
    Incomplete(String),
}

/// A case with its place in the cache.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The case.
    pub case: Case,
    /// Its inputs and key.
    pub record: CaseRecord,
    /// Its folder, where it runs.
    pub dir: PathBuf,
    /// Its folder in the committed results, if the problem has such a layer (it may not
    /// exist).
    pub committed: Option<PathBuf>,
    /// What the committed folder, where it holds a whole finished run, lacks of what the
    /// problem's figures read from it (see [`reads`](super::reads)), in words: a committed
    /// result that lacks anything is not one the cache takes as done.
    committed_lacks: Vec<String>,
    /// The folders of the current cases of the problem's other presets (filled by
    /// [`entries`]): their results are not earlier inputs of this case.
    others: Arc<HashSet<PathBuf>>,
    /// The preset the case was expanded for (for the command that computes it again).
    preset: String,
}

/// The command that computes case `case` of `problem` (in `preset`) again, over what its
/// folder holds.
pub fn recompute_command(problem: &str, preset: &str, case: &str) -> String {
    let preset = if preset == "quick" { String::new() } else { format!(" --preset {preset}") };
    format!("`sphrepro run {problem}{preset} --match {case} --force`")
}

impl Entry {
    /// The cache entry of `case` of `problem` under `output`.
    pub fn new(output: &Path, problem: &Problem, case: &Case) -> Self {
        let (record, dir, committed) = Self::locate(output, problem, case);
        let committed_lacks = match &committed {
            Some(c) if Self::whole(c) => {
                let has_result = |other: &Case| {
                    let (_, d, c) = Self::locate(output, problem, other);
                    Self::finished(&d) || c.as_deref().is_some_and(Self::finished)
                };
                super::reads::lacking(c, &super::reads::reads(problem, case, &has_result))
            }
            _ => Vec::new(),
        };
        Self {
            case: case.clone(),
            record,
            dir,
            committed,
            committed_lacks,
            others: Arc::default(),
            preset: problem.preset.clone(),
        }
    }

    /// The record of `case` of `problem`, its folder under `output` and its committed folder.
    fn locate(output: &Path, problem: &Problem, case: &Case) -> (CaseRecord, PathBuf, Option<PathBuf>) {
        let record = CaseRecord::new(&problem.name, case);
        let dir = output.join(&problem.name).join(record.folder());
        let committed = root(problem).map(|r| r.join(&problem.name).join(record.folder()));
        (record, dir, committed)
    }

    /// Whether `dir` holds a finished (`completed` or `diverged`) summary.
    fn finished(dir: &Path) -> bool {
        Summary::read(dir).is_ok_and(|s| matches!(s.status, Status::Completed | Status::Diverged))
    }

    /// Whether committed folder `dir` holds a whole finished run (not only its summary, see
    /// [`SUMMARY_ONLY`]).
    fn whole(dir: &Path) -> bool {
        Self::finished(dir) && !dir.join(SUMMARY_ONLY).exists()
    }

    /// Where its results are read from: the output folder when it holds a finished run,
    /// else the committed folder when that holds a whole one with everything the figures
    /// read from it, else the output folder.
    pub fn result_dir(&self) -> &Path {
        if Self::finished(&self.dir) {
            return &self.dir;
        }
        match &self.committed {
            Some(c) if self.committed_lacks.is_empty() && Self::whole(c) => c,
            _ => &self.dir,
        }
    }

    /// What the committed result lacks of what the figures read, in words (empty where it
    /// lacks nothing or there is none).
    pub fn committed_lacks(&self) -> &[String] {
        &self.committed_lacks
    }

    /// Whether its result is the committed one (none in the output folder).
    pub fn is_committed(&self) -> bool {
        self.committed.as_deref().is_some_and(|c| c == self.result_dir())
    }

    /// The summary, if there is a readable one (see [`result_dir`](Self::result_dir)).
    pub fn summary(&self) -> Option<Summary> {
        Summary::read(self.result_dir()).ok()
    }

    /// The state of this case on disk: done if either layer holds a finished run.
    pub fn state(&self) -> State {
        if self.is_committed() {
            if let Ok(s) = Summary::read(self.result_dir()) {
                return State::Done(s.status);
            }
        }
        match Summary::read(&self.dir) {
            Ok(s) if matches!(s.status, Status::Completed | Status::Diverged) => State::Done(s.status),
            Ok(s) => State::Failed(s.reason.unwrap_or_else(|| "failed".into())),
            Err(e) if self.dir.join("summary.json").exists() => State::Damaged(format!(
                "damaged result: {e}; {} computes it again",
                recompute_command(&self.record.problem, &self.preset, &self.case.name)
            )),
            // A folder where no simulation started (its runner died writing `case.json`):
            // no log and nothing to resume.
            Err(_) if self.dir.exists() && self.started() => {
                State::Failed("no summary: the run was killed or crashed".into())
            }
            Err(_) if !self.committed_lacks.is_empty() => {
                State::Incomplete(format!("the committed result lacks {}", self.committed_lacks.join("; ")))
            }
            Err(_) => State::Missing(self.previous_change()),
        }
    }

    /// Whether a simulation of the case started in its folder (a log or a checkpoint).
    fn started(&self) -> bool {
        self.dir.join("run.log").exists() || self.dir.join("checkpoint.json").exists()
    }

    /// Whether the case is done.
    pub fn is_done(&self) -> bool {
        matches!(self.state(), State::Done(_))
    }

    /// If other folders hold this case name with other keys (other than the other presets'
    /// current results), what changed from the nearest of them (the fewest changes, then
    /// the first by name, so that the answer does not depend on the order the system lists
    /// the folder in).
    fn previous_change(&self) -> Option<String> {
        let parent = self.dir.parent()?;
        let mut found: Vec<(Vec<String>, String)> = Vec::new();
        for e in std::fs::read_dir(parent).ok()?.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let Some((case, _)) = name.rsplit_once('-') else {
                continue;
            };
            if case != self.record.name || e.path() == self.dir || self.others.contains(&e.path()) {
                continue;
            }
            if let Some(old) = read_record(&e.path()) {
                found.push((self.record.changes(&old), name));
            }
        }
        let nearest = found.into_iter().min_by(|a, b| (a.0.len(), &a.1).cmp(&(b.0.len(), &b.1)))?;
        Some(CaseRecord::describe(nearest.0))
    }

    /// Writes `case.json` (creating the folder).
    pub fn write_record(&self) -> Result<(), String> {
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| format!("{}: cannot create the case folder: {e}", self.dir.display()))?;
        let path = self.dir.join("case.json");
        let json = serde_json::to_string_pretty(&self.record).expect("record serialises");
        crate::solver::output::write_atomic(&path, json.as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// Reads `DIR/case.json`.
pub fn read_record(dir: &Path) -> Option<CaseRecord> {
    let s = std::fs::read_to_string(dir.join("case.json")).ok()?;
    serde_json::from_str(&s).ok()
}

/// Every case of `problem` with its cache entry.
pub fn entries(output: &Path, problem: &Problem) -> Vec<Entry> {
    let others: Arc<HashSet<PathBuf>> = Arc::new(
        problem
            .other_presets
            .iter()
            .flat_map(|(_, cases)| cases)
            .map(|c| Entry::new(output, problem, c).dir)
            .collect(),
    );
    problem.cases.iter().map(|c| Entry { others: others.clone(), ..Entry::new(output, problem, c) }).collect()
}

/// Folders under `OUTPUT/<problem>/` that belong to no case of `problems` (in any of the
/// given presets' expansions): results of changed inputs. Reported, never deleted.
pub fn stale_folders(output: &Path, problem: &str, live: &[PathBuf]) -> Vec<PathBuf> {
    let dir = output.join(problem);
    let Ok(rd) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    let mut out: Vec<PathBuf> =
        rd.flatten().map(|e| e.path()).filter(|p| p.is_dir() && !live.contains(p)).collect();
    out.sort();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::params::{Params, Value};

    fn case(nx: i64) -> Case {
        let entry = crate::scenes::find("taylor_green").unwrap();
        let mut p = Params::defaults(&(entry.params)());
        p.0.insert("nx".into(), Value::Int(nx));
        Case { name: "a".into(), scene: "taylor_green".into(), params: p }
    }

    #[test]
    fn key_depends_on_parameters_only() {
        let (a, b, c) = (
            CaseRecord::new("p", &case(16)),
            CaseRecord::new("p", &case(16)),
            CaseRecord::new("p", &case(20)),
        );
        assert_eq!(a.key, b.key);
        assert_ne!(a.key, c.key);
        assert_eq!(c.changes_from(&a), "nx 16 -> 20");
        assert!(a.folder().starts_with("a-") && a.folder().len() == 12);
    }

    #[test]
    fn a_scene_that_reports_more_has_new_keys_the_others_keep_theirs() {
        assert_eq!(fingerprint_of("dam_break"), fingerprint());
        let tg = crate::scenes::find("taylor_green").unwrap();
        assert!(tg.outputs > 0 && fingerprint_of("taylor_green") != fingerprint());
        // (and the default `pst = sun` adds its part's version)
        assert_eq!(
            CaseRecord::new("p", &case(16)).solver,
            format!("{}+sun1", fingerprint_of("taylor_green"))
        );
    }

    /// A parameter added later leaves the keys of the cases at its default as they were
    /// before it existed, and renews those that set it.
    #[test]
    fn a_parameter_added_later_keeps_the_earlier_keys() {
        let entry = crate::scenes::find("dam_break").unwrap();
        let specs = (entry.params)();
        assert!(specs.iter().any(|s| s.name == "wall_pressure" && s.added_later));
        let with = |value: Option<&str>| {
            let mut p = Params::defaults(&specs);
            match value {
                Some(v) => p.0.insert("wall_pressure".into(), Value::Str(v.into())),
                None => p.0.remove("wall_pressure"),
            };
            CaseRecord::new("p", &Case { name: "a".into(), scene: "dam_break".into(), params: p })
        };
        let (before, default, clamped) = (with(None), with(Some("extrapolated")), with(Some("non_negative")));
        assert_eq!(default.key, before.key);
        assert!(!default.params.contains_key("wall_pressure"));
        assert_ne!(clamped.key, before.key);
        assert_eq!(clamped.changes_from(&before), "wall_pressure (none) -> \"non_negative\"");
    }

    /// A change to a shifting technique renews the keys of the cases that use it only.
    #[test]
    fn a_part_of_the_solver_renews_only_the_keys_of_cases_that_use_it() {
        let with = |pst: &str| {
            let mut c = case(16);
            c.params.0.insert("pst".into(), Value::Str(pst.into()));
            CaseRecord::new("p", &c).solver
        };
        assert_eq!(with("none"), fingerprint_of("taylor_green"));
        for (pst, version) in [("sun", "+sun1"), ("ipst", "+ipst3")] {
            assert!(with(pst).starts_with(&fingerprint_of("taylor_green")) && with(pst).ends_with(version));
        }
    }
}
