//! The committed results: `results/` next to the problems folder (for `--problems DIR`,
//! `DIR/../results`), laid out as the output folder (`results/<problem>/<case>-<key>/`),
//! and read by the cache as a second, read-only layer ([`Entry`](super::cache::Entry)): a
//! case whose folder there holds a finished summary is done, so a fresh clone runs nothing
//! that was committed, and the paper preset's manuscript is drawn from these results alone
//! (so that it is the same on every clone).
//!
//! [`export`] copies the finished cases of the paper preset from the output folder into it:
//! `case.json`, `summary.json`, `timeseries.csv`, and what the figures of any preset of the
//! problem read from the case ([`reads`](super::reads): the files its profile figures read,
//! e.g. `centerline_u.csv`, and only the snapshots its particle figures draw), gzip-compressed
//! (`vtu/fluid_00012.vtu.gz`, with a `fluid.pvd` / `wall.pvd` listing them under the names they
//! have once uncompressed). Where a claim's paper-preset results are missing, the summaries of
//! its cases at the other presets go too (for the verdict drawn there), and so do those of
//! the stability maps at the other presets (for their first-failure tables): those folders
//! hold a [`SUMMARY_ONLY`] file and are not done cases for the cache. The folder is kept
//! under [`BUDGET`] bytes: past it, the largest snapshots are dropped (named), and the figures
//! that draw them say so. The estimated cost of the cases without a result goes there too
//! (`estimates.json`, [`estimate`](super::estimate)).

use super::cache::{self, root, Entry, SUMMARY_ONLY};
use super::reads::{self, Need};
use super::registry::{Case, FigureKind, Problem};
use super::study::snapshot::{pvd_entries, pvd_text};
use crate::solver::output::summary::{Status, Summary};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The preset whose results are committed (and whose manuscript is).
pub const EXPORT_PRESET: &str = "paper";

/// The size the committed results keep under, in bytes.
pub const BUDGET: u64 = 50_000_000;

const SUMMARY_ONLY_TEXT: &str =
    "Only case.json and summary.json of this case are committed: the paper preset's \
manuscript reads them (a verdict drawn at this case's preset, a stability table). The cache \
does not take the case as done; `sphrepro run` computes it whole.\n";

/// What an export did.
#[derive(Debug, Default)]
pub struct Exported {
    /// Cases exported with their files.
    pub cases: usize,
    /// Cases of other presets exported with their summary only.
    pub summaries: usize,
    /// Snapshots written.
    pub snapshots: usize,
    /// The size of the results folder after it, in bytes.
    pub bytes: u64,
    /// Snapshots dropped to keep under the budget: (file, bytes).
    pub dropped: Vec<(PathBuf, u64)>,
    /// Folders of earlier inputs (matching no case of any preset), per problem: read by
    /// nothing; remove them with `git rm` to keep the folder small.
    pub earlier: Vec<(String, usize)>,
}

fn finished(dir: &Path) -> bool {
    Summary::read(dir).is_ok_and(|s| matches!(s.status, Status::Completed | Status::Diverged))
}

/// Writes `bytes` to `path` unless it holds them already.
fn put(path: &Path, bytes: &[u8]) -> Result<(), String> {
    if std::fs::read(path).is_ok_and(|b| b == bytes) {
        return Ok(());
    }
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    crate::solver::output::write_atomic(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Copies `names` from `from` to `to` (those that exist).
fn copy(from: &Path, to: &Path, names: &[&str]) -> Result<(), String> {
    for n in names {
        let src = from.join(n);
        if src.exists() {
            let bytes = std::fs::read(&src).map_err(|e| format!("{}: {e}", src.display()))?;
            put(&to.join(n), &bytes)?;
        }
    }
    Ok(())
}

/// `bytes` gzip-compressed (no time stamp in the header: the same bytes every time).
fn gzip(bytes: &[u8]) -> Result<Vec<u8>, String> {
    let mut enc = flate2::GzBuilder::new().mtime(0).write(Vec::new(), flate2::Compression::best());
    enc.write_all(bytes).map_err(|e| e.to_string())?;
    enc.finish().map_err(|e| e.to_string())
}

/// Exports the finished cases of the [`EXPORT_PRESET`] of `problems` (loaded for it) from
/// `output` into their committed-results folders (see the module doc).
pub fn export(problems: &[Problem], output: &Path) -> Result<Exported, String> {
    let mut out = Exported::default();
    let mut roots = BTreeSet::new();
    for p in problems.iter().filter(|p| p.preset == EXPORT_PRESET) {
        let Some(root) = root(p) else { continue };
        roots.insert(root.clone());
        let dest = |e: &Entry| root.join(&p.name).join(e.record.folder());
        let entries = cache::entries(output, p);
        // Every finished case, with what the figures of every preset read from it
        // (`reads`): its files, and the snapshots the particle figures draw (of the first
        // case each selects with a result, the one nearest the figure's time, and the
        // walls' and the structures' nearest it). Per case folder: where it is exported,
        // and the files of each series drawn.
        let has_result = |c: &Case| {
            let e = Entry::new(output, p, c);
            finished(&dest(&e)) || finished(&e.dir)
        };
        let mut snaps: BTreeMap<PathBuf, (PathBuf, BTreeMap<String, BTreeSet<String>>)> = BTreeMap::new();
        for e in entries.iter().filter(|e| finished(&e.dir)) {
            let mut names = vec!["case.json".to_string(), "summary.json".into(), "timeseries.csv".into()];
            for r in reads::reads(p, &e.case, &has_result) {
                match r.need {
                    Need::File(f) if !names.contains(&f) => names.push(f),
                    Need::File(_) => {}
                    Need::Snapshot { time } => {
                        let slot = snaps.entry(e.dir.clone()).or_insert_with(|| (dest(e), BTreeMap::new()));
                        for (series, file) in reads::snapshot_files(&e.dir, time)? {
                            slot.1.entry(series).or_default().insert(file);
                        }
                    }
                }
            }
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            copy(&e.dir, &dest(e), &names)?;
            let _ = std::fs::remove_file(dest(e).join(SUMMARY_ONLY));
            out.cases += 1;
        }
        for (from, (to, drawn)) in snaps {
            for (series, files) in &drawn {
                let list: Vec<(f64, String)> =
                    pvd_entries(&from, series)?.into_iter().filter(|(_, f)| files.contains(f)).collect();
                for (_, f) in &list {
                    let src = from.join(f);
                    let bytes = std::fs::read(&src).map_err(|e| format!("{}: {e}", src.display()))?;
                    put(&to.join(format!("{f}.gz")), &gzip(&bytes)?)?;
                    out.snapshots += 1;
                }
                put(&to.join(series), pvd_text(&list).as_bytes())?;
            }
            // Snapshots of an earlier export that no figure draws now.
            let keep: BTreeSet<PathBuf> =
                drawn.values().flatten().map(|f| to.join(format!("{f}.gz"))).collect();
            if let Ok(rd) = std::fs::read_dir(to.join("vtu")) {
                for old in rd.flatten().map(|e| e.path()) {
                    if old.extension().is_some_and(|x| x == "gz") && !keep.contains(&old) {
                        let _ = std::fs::remove_file(&old);
                    }
                }
            }
        }
        // Summaries of the other presets: where a claim's paper-preset results are missing,
        // those of its cases elsewhere; and those of the stability maps.
        let mut lite: BTreeSet<PathBuf> = BTreeSet::new();
        for c in &p.claims {
            let complete = c.at.get(EXPORT_PRESET).is_some_and(|ct| {
                ct.select.pick(&p.cases).iter().all(|case| finished(&dest(&Entry::new(output, p, case))))
            });
            if complete {
                continue;
            }
            for (preset, ct) in c.at.iter().filter(|(k, _)| k.as_str() != EXPORT_PRESET) {
                for case in p.cases_of(preset).map(|cs| ct.select.pick(cs)).unwrap_or_default() {
                    lite.insert(Entry::new(output, p, case).dir);
                }
            }
        }
        for f in p.figures.iter().filter(|f| matches!(f.kind, FigureKind::Stability { .. })) {
            for (preset, cases) in p.presets() {
                if let (true, Some(select)) = (preset != EXPORT_PRESET, f.select_at.get(preset)) {
                    lite.extend(select.pick(cases).into_iter().map(|c| Entry::new(output, p, c).dir));
                }
            }
        }
        for dir in lite.iter().filter(|d| finished(d)) {
            let to = root.join(&p.name).join(dir.file_name().expect("a case folder"));
            if finished(&to) && !to.join(SUMMARY_ONLY).exists() {
                continue; // committed whole already (a case of the paper preset too)
            }
            copy(dir, &to, &["case.json", "summary.json"])?;
            put(&to.join(SUMMARY_ONLY), SUMMARY_ONLY_TEXT.as_bytes())?;
            out.summaries += 1;
        }
        // What the cases still without a result would cost, where a dry run measured it.
        super::estimate::export(output, p)?;
        // Folders of earlier inputs.
        let live: Vec<PathBuf> = p
            .presets()
            .into_iter()
            .flat_map(|(_, cases)| {
                cases.iter().map(|c| root.join(&p.name).join(cache::CaseRecord::new(&p.name, c).folder()))
            })
            .collect();
        let earlier = cache::stale_folders(&root, &p.name, &live).len();
        if earlier > 0 {
            out.earlier.push((p.name.clone(), earlier));
        }
    }
    // The budget: drop the largest snapshots until the folder fits.
    for root in roots {
        let mut files = Vec::new();
        walk(&root, &mut files);
        let mut total: u64 = files.iter().map(|(_, n)| n).sum();
        let mut snaps: Vec<(PathBuf, u64)> =
            files.into_iter().filter(|(f, _)| f.to_string_lossy().ends_with(".vtu.gz")).collect();
        snaps.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        for (f, n) in snaps {
            if total <= BUDGET {
                break;
            }
            std::fs::remove_file(&f).map_err(|e| format!("{}: {e}", f.display()))?;
            total -= n;
            out.dropped.push((f, n));
        }
        out.bytes += total;
    }
    Ok(out)
}

/// Every file under `dir`, with its size.
fn walk(dir: &Path, out: &mut Vec<(PathBuf, u64)>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else if let Ok(m) = e.metadata() {
            out.push((p, m.len()));
        }
    }
}
