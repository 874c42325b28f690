//! What the figures and tables of a problem read from a case's folder, over every preset of
//! its file: one rule for the cache (a committed case lacking any of it is not done, see
//! [`Entry`](super::cache::Entry)), for the export of the committed results (which keeps all
//! of it, see [`results::export`](super::results::export)) and for the static check that the
//! committed results hold it.
//!
//! Every figure and table reads a case's `summary.json`; besides it:
//! - a `timeseries` figure reads `timeseries.csv`;
//! - a `profile` figure reads its `file` (`centerline_u.csv`, or `timeseries.csv`);
//! - a `particles` figure reads, of the first case it selects that has a result, the
//!   snapshot of its drawn series nearest the figure's time, and the snapshots nearest that
//!   of the series drawn beside it ([`snapshot::beside`]);
//! - trade and stability figures, tables and claims read the summary only.

use super::registry::{Case, FigureKind, Problem};
use super::study::snapshot::{beside, drawn_series, pick_snapshot, pvd_entries};
use std::path::Path;

/// One thing a figure reads from a case folder besides its summary.
#[derive(Clone, Debug, PartialEq)]
pub enum Need {
    /// A file of the case (`timeseries.csv`, a profile's CSV).
    File(String),
    /// The snapshot of the drawn series nearest `time` (the last one for `None`), with the
    /// series drawn beside it at that time.
    Snapshot {
        /// The figure's time.
        time: Option<f64>,
    },
}

/// A figure's id with what it reads, for the words of a report.
#[derive(Clone, Debug, PartialEq)]
pub struct Read {
    /// The figure.
    pub figure: String,
    /// The preset whose figure it is.
    pub preset: String,
    /// What it reads.
    pub need: Need,
}

/// Whether `a` and `b` are the same case (the same folder): the same name and parameters.
fn same(a: &Case, b: &Case) -> bool {
    a.name == b.name && a.scene == b.scene && a.params == b.params
}

/// What the figures of every preset of `p` read from the folder of `case` besides its
/// summary (see the module doc). `has_result` says whether a case has a finished result in
/// either layer: a particle figure draws the first case it selects that has one.
pub fn reads(p: &Problem, case: &Case, has_result: &dyn Fn(&Case) -> bool) -> Vec<Read> {
    let mut out: Vec<Read> = Vec::new();
    for (preset, cases) in p.presets() {
        for f in &p.figures {
            let Some(select) = f.select_at.get(preset) else { continue };
            let picked = select.pick(cases);
            if !picked.iter().any(|c| same(c, case)) {
                continue;
            }
            let need = match &f.kind {
                FigureKind::Timeseries { .. } => Need::File("timeseries.csv".into()),
                FigureKind::Profile { file, .. } => Need::File(file.clone()),
                FigureKind::Particles { time, .. } => {
                    match picked.iter().find(|c| same(c, case) || has_result(c)) {
                        Some(first) if same(first, case) => Need::Snapshot { time: *time },
                        _ => continue,
                    }
                }
                FigureKind::Trade { .. } | FigureKind::Stability { .. } => continue,
            };
            let read = Read { figure: f.id.clone(), preset: preset.to_string(), need };
            if !out.iter().any(|r| r.need == read.need) {
                out.push(read);
            }
        }
    }
    out
}

/// The files of case folder `dir` that a snapshot figure at `time` draws: `(series, file)`
/// for the drawn series and each series beside it (the file as the series lists it, which
/// the folder may hold gzip-compressed).
pub fn snapshot_files(dir: &Path, time: Option<f64>) -> Result<Vec<(String, String)>, String> {
    let series = drawn_series(dir)?;
    let list = pvd_entries(dir, &series)?;
    let (t, file) = pick_snapshot(&list, time).clone();
    let mut out = vec![(series.clone(), file)];
    for other in beside(dir, &series)? {
        let entries = pvd_entries(dir, &other)?;
        out.push((other, pick_snapshot(&entries, Some(t)).1.clone()));
    }
    Ok(out)
}

/// Whether case folder `dir` holds file `file` as written or gzip-compressed.
fn holds(dir: &Path, file: &str) -> bool {
    dir.join(file).is_file() || dir.join(format!("{file}.gz")).is_file()
}

/// What case folder `dir` lacks of `reads`, in words (empty: it holds all of it).
pub fn lacking(dir: &Path, reads: &[Read]) -> Vec<String> {
    let mut out = Vec::new();
    for r in reads {
        let what = match &r.need {
            Need::File(f) if holds(dir, f) => continue,
            Need::File(f) => format!("`{f}`"),
            Need::Snapshot { time } => match snapshot_files(dir, *time) {
                Ok(files) => {
                    let absent: Vec<String> = files
                        .into_iter()
                        .filter(|(_, f)| !holds(dir, f))
                        .map(|(_, f)| format!("`{f}`"))
                        .collect();
                    if absent.is_empty() {
                        continue;
                    }
                    format!("the snapshot(s) {}", absent.join(", "))
                }
                Err(_) => "its snapshot series (*.pvd)".to_string(),
            },
        };
        out.push(format!("{what}, which {} of the `{}` preset draws", r.figure, r.preset));
    }
    out
}
