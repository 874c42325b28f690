//! The automation commands behind `sphrepro list | run | reproduce | status | check`; each
//! returns the process exit status.

use super::registry::{self, Problem};
use super::runner::{self, Options};
use super::{baseline, cache, check, estimate, results, slurm, study};
use crate::{errln, outln};
use std::path::{Path, PathBuf};

/// The problems folder when none is named: `problems/` of the checkout.
pub const DEFAULT_PROBLEMS: &str = "problems";

/// Folders every automation command reads or writes.
#[derive(Clone, Debug)]
pub struct Dirs {
    /// Problem files.
    pub problems: PathBuf,
    /// Results.
    pub output: PathBuf,
    /// Figures, tables and manuscript.md.
    pub manuscript: PathBuf,
}

/// The manuscript folder of `preset` when none is named: `manuscript/` for the preset whose
/// results are committed (the paper's resolutions), `OUTPUT/manuscript/` for any other (a
/// smoke check never writes over the committed manuscript).
pub fn default_manuscript(preset: &str, output: &Path) -> PathBuf {
    if preset == results::EXPORT_PRESET {
        PathBuf::from(DEFAULT_MANUSCRIPT)
    } else {
        output.join("manuscript")
    }
}

/// The committed manuscript's folder.
pub const DEFAULT_MANUSCRIPT: &str = "manuscript";

/// Exit status: success.
pub const OK: u8 = 0;
/// Exit status: a case failed, a bound was breached, an I/O error.
pub const FAILED: u8 = 1;
/// Exit status: invalid problem files or arguments; nothing ran.
pub const BAD_INPUT: u8 = 2;
/// Exit status: interrupted by Ctrl-C.
pub const INTERRUPTED: u8 = 130;

/// Loads every problem of `dirs.problems` (all are validated), keeping those named in
/// `only` (all if empty).
fn load(dirs: &Dirs, preset: &str, only: &[String]) -> Result<Vec<Problem>, String> {
    let all = registry::load_dir(&dirs.problems, preset)?;
    for name in only {
        if !all.iter().any(|p| &p.name == name) {
            let known: Vec<_> = all.iter().map(|p| p.name.as_str()).collect();
            return Err(format!(
                "no problem `{name}` in {}; problems: {}",
                dirs.problems.display(),
                known.join(", ")
            ));
        }
    }
    Ok(all.into_iter().filter(|p| only.is_empty() || only.contains(&p.name)).collect())
}

/// `list`: problems and their cases.
pub fn list(dirs: &Dirs, preset: &str) -> u8 {
    match load(dirs, preset, &[]) {
        Ok(ps) => {
            for p in &ps {
                outln!(
                    "{} ({}): {} case(s) in preset {}, scene {}",
                    p.name,
                    p.title,
                    p.cases.len(),
                    p.preset,
                    p.scene.name
                );
                for c in &p.cases {
                    outln!("    {}", c.name);
                }
            }
            OK
        }
        // Outside a checkout (no `problems/` here) `list` still shows the scenes; a folder
        // named with --problems that does not exist is a typo.
        Err(e) if !dirs.problems.exists() && dirs.problems == Path::new(DEFAULT_PROBLEMS) => {
            outln!("(no problems: {e})");
            OK
        }
        Err(e) => {
            errln!("error: {e}");
            BAD_INPUT
        }
    }
}

/// Creates the output folder, or says why it cannot.
fn ensure_dir(dir: &Path, what: &str) -> Result<(), String> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("cannot create the {what} folder {}: {e}", dir.display()))?;
    let probe = dir.join(format!(".write-probe-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| format!("cannot write in the {what} folder {}: {e}", dir.display()))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// What `run` and `reproduce` do besides simulating.
#[derive(Clone, Debug, Default)]
pub struct RunFlags {
    /// Regenerate figures from cached results only.
    pub plot_only: bool,
    /// Also write manuscript.md.
    pub manuscript: bool,
    /// Where the cases run.
    pub executor: Executor,
    /// Only the cases that failed before (a failed summary, or a folder without one).
    pub retry_failed: bool,
}

/// Where the cases run.
#[derive(Clone, Debug, Default)]
pub enum Executor {
    /// Subprocesses of this process, in a job pool (`runner`).
    #[default]
    Local,
    /// Job arrays on a Slurm cluster (`slurm`).
    Slurm(slurm::Request),
}

/// `run` (and `reproduce` with every problem): simulate what is missing or stale, then
/// regenerate the figures and tables of the problems.
pub fn run(dirs: &Dirs, preset: &str, only: &[String], opts: &Options, flags: &RunFlags) -> u8 {
    let problems = match load(dirs, preset, only) {
        Ok(p) => p,
        Err(e) => {
            errln!("error: {e}");
            return BAD_INPUT;
        }
    };
    let mut status = OK;
    // Slurm's settings are checked first: a bad file or flag submits nothing.
    let slurm = match &flags.executor {
        Executor::Slurm(request) if !flags.plot_only => match slurm::settings(&dirs.problems, request) {
            Ok(s) => Some((request, s)),
            Err(e) => {
                errln!("error: {e}");
                return BAD_INPUT;
            }
        },
        _ => None,
    };
    if !flags.plot_only {
        let runner::Plan { mut tasks, done, damaged } = match runner::plan(&dirs.output, &problems, opts) {
            Ok(t) => t,
            Err(e) => {
                errln!("error: {e}");
                return BAD_INPUT;
            }
        };
        // A damaged result is not a crash to rerun over: named, with the command that does.
        for d in &damaged {
            errln!("error: {d}");
        }
        if !damaged.is_empty() {
            status = FAILED;
        }
        if flags.retry_failed {
            // Not a case that is running now: its folder has no summary yet either.
            tasks.retain(|t| {
                matches!(t.entry.state(), cache::State::Failed(_))
                    && super::lock::Lock::holder(&t.entry.dir).is_none()
            });
        }
        if slurm.is_some() {
            slurm::leave_out_queued(&dirs.output, &mut tasks);
        }
        if let (true, Some((_, settings))) = (opts.dry_run, &slurm) {
            if let Err(slurm::Error::Input(e) | slurm::Error::Failed(e)) =
                slurm::dry_run(&dirs.output, &tasks, settings, opts.jobs, opts.force)
            {
                errln!("error: {e}");
                return BAD_INPUT;
            }
            outln!("{} to run, {done} done (skipped)", tasks.len());
            return OK;
        }
        if opts.dry_run {
            let cores = rayon::current_num_threads();
            let costs = match opts.estimate {
                Some(budget) if !tasks.is_empty() => {
                    estimate::estimates(&tasks, opts.jobs.unwrap_or(cores), budget)
                }
                _ => Vec::new(),
            };
            for (i, t) in tasks.iter().enumerate() {
                let cost = match costs.get(i) {
                    Some(Ok(m)) => format!("  [{}]", estimate::describe(m)),
                    Some(Err(e)) => format!("  [no estimate: {e}]"),
                    None => String::new(),
                };
                outln!(
                    "would run {}/{} ({})  -> {}{cost}",
                    t.problem,
                    t.entry.case.name,
                    t.reason,
                    t.entry.dir.display()
                );
            }
            if costs.is_empty() {
                outln!("{} to run, {done} done (skipped)", tasks.len());
            } else {
                outln!("{} to run, {done} done (skipped); {}", tasks.len(), estimate::total(&costs, cores));
            }
            return OK;
        }
        if let Err(e) = ensure_dir(&dirs.output, "output") {
            errln!("error: {e}");
            return FAILED;
        }
        outln!("{} case(s) to run, {done} done (skipped)", tasks.len());
        let report = match &slurm {
            None => runner::execute(tasks, opts),
            Some((request, settings)) => {
                match slurm::execute(
                    &dirs.output,
                    &tasks,
                    settings,
                    request,
                    opts.jobs,
                    opts.force,
                    opts.checkpoint_every,
                ) {
                    Ok(slurm::Outcome::Submitted) => return OK,
                    Ok(slurm::Outcome::Waited(r)) => Ok(r),
                    Err(slurm::Error::Input(e)) => {
                        errln!("error: {e}");
                        return BAD_INPUT;
                    }
                    Err(slurm::Error::Failed(e)) => Err(e),
                }
            }
        };
        let report = match report {
            Ok(r) => r,
            Err(e) => {
                errln!("error: {e}");
                return FAILED;
            }
        };
        if report.interrupted {
            // (The Slurm executor has said what became of its jobs.)
            if slurm.is_none() {
                errln!("interrupted: running cases were stopped and are not done");
            }
            status = INTERRUPTED;
        }
        if !report.failures.is_empty() {
            errln!("{} case(s) failed:", report.failures.len());
            for (case, log, why) in &report.failures {
                errln!("  {case}: {why}\n    log: {}", log.display());
            }
            if status == OK {
                status = FAILED;
            }
        }
        if report.interrupted {
            return status;
        }
    } else if opts.dry_run {
        outln!("(--plot-only: nothing would be simulated)");
        return OK;
    }
    if preset == results::EXPORT_PRESET {
        match results::export(&problems, &dirs.output) {
            Ok(x) => {
                if x.cases + x.summaries > 0 {
                    outln!(
                        "exported {} case(s), {} summary(ies) of other presets and {} snapshot(s) to the committed results ({:.1} MB)",
                        x.cases,
                        x.summaries,
                        x.snapshots,
                        x.bytes as f64 / 1e6
                    );
                }
                for (f, n) in &x.dropped {
                    outln!(
                        "dropped {} ({:.1} MB) to keep the committed results under {:.0} MB: the figure that draws it says so",
                        f.display(),
                        *n as f64 / 1e6,
                        results::BUDGET as f64 / 1e6
                    );
                }
                for (p, n) in &x.earlier {
                    outln!("{p}: {n} committed folder(s) of earlier inputs, read by nothing (`git rm` them to keep the results small)");
                }
            }
            Err(e) => {
                errln!("error: exporting the results: {e}");
                return FAILED;
            }
        }
    }
    if let Err(e) = post_process(dirs, &problems, flags) {
        errln!("error: {e}");
        return FAILED;
    }
    status
}

/// Where the figures of `problems` read results: for the preset whose results are
/// committed, the committed results alone (so that its manuscript is the same on every
/// clone; the export above brings the output folder's new results there first); for any
/// other, the output folder over the committed results.
fn read_from(dirs: &Dirs, problems: &[Problem]) -> PathBuf {
    match (problems.first().map(|p| p.preset.as_str()), cache::root_of(&dirs.problems)) {
        (Some(results::EXPORT_PRESET), Some(root)) => root,
        _ => dirs.output.clone(),
    }
}

/// Figures, tables and (with `flags.manuscript`) manuscript.md from cached results. A
/// problem none of whose cases has a result draws nothing (its last figures stay); if no
/// problem has one (a mistyped --output), nothing is written and it is an error.
fn post_process(dirs: &Dirs, problems: &[Problem], flags: &RunFlags) -> Result<(), String> {
    if problems.iter().all(|p| p.figures.is_empty() && p.tables.is_empty()) && !flags.manuscript {
        return Ok(());
    }
    let read = read_from(dirs, problems);
    let empty: Vec<&Problem> = problems
        .iter()
        .filter(|p| {
            let entries = cache::entries(&read, p);
            !entries.is_empty() && !entries.iter().any(|e| e.is_done())
        })
        .collect();
    let note = |p: &Problem| {
        format!(
            "{}: no case has a result under {}; its figures and tables are left as they were",
            p.name,
            read.display()
        )
    };
    if empty.len() == problems.len() {
        return Err(problems.iter().map(&note).collect::<Vec<_>>().join("\nerror: "));
    }
    for p in &empty {
        outln!("{}", note(p));
    }
    ensure_dir(&dirs.manuscript, "manuscript")?;
    let mut reports = Vec::new();
    let mut errors = Vec::new();
    for p in problems {
        // Nor are figures drawn without a case whose result is damaged (it would be left
        // out): named, with the command that computes it again.
        let damaged: Vec<String> = cache::entries(&read, p)
            .iter()
            .filter_map(|e| match e.state() {
                cache::State::Damaged(r) => Some(format!("{}/{}: {r}", p.name, e.case.name)),
                _ => None,
            })
            .collect();
        if !damaged.is_empty() {
            // Without --plot-only the runner has named them already.
            let named =
                if flags.plot_only { format!("{}\n", damaged.join("\nerror: ")) } else { String::new() };
            errors.push(format!(
                "{named}{}: a case's result is damaged; its figures and tables are left as they were",
                p.name
            ));
            continue;
        }
        match study::regenerate(p, &read, &dirs.manuscript) {
            Ok(r) => {
                if r.drawn {
                    outln!(
                        "{}: {} figure(s), {} table(s) in {}",
                        p.name,
                        p.figures.len(),
                        p.tables.len(),
                        dirs.manuscript.display()
                    );
                }
                reports.push((p, r));
            }
            Err(e) => errors.push(e),
        }
    }
    // Every problem's figures were attempted; a manuscript missing a section is not written
    // over the last whole one.
    if !errors.is_empty() {
        return Err(errors.join("\nerror: "));
    }
    if flags.manuscript {
        let preset = problems.first().map(|p| p.preset.as_str()).unwrap_or(registry::DEFAULT_PRESET);
        let path = dirs.manuscript.join("manuscript.md");
        let refs: Vec<(&Problem, &study::ProblemReport)> = reports.iter().map(|(p, r)| (*p, r)).collect();
        let mut header = header(preset);
        header.cases = Some(estimate::coverage(&read, problems));
        super::report::write_manuscript(&study::manuscript(header, &refs), &path)?;
        outln!("wrote {}", path.display());
        let removed = sweep(&dirs.manuscript, &refs);
        if !removed.is_empty() {
            outln!(
                "removed {} figure and table file(s) the manuscript no longer shows: {}",
                removed.len(),
                removed.join(", ")
            );
        }
    }
    Ok(())
}

/// Removes the files under `manuscript`'s `figures/` and `tables/` that no item of `reports`
/// shows (every problem's, as `reproduce` draws them all): drawn from results that are gone,
/// they would show what no result holds. Returns their names.
fn sweep(manuscript: &Path, reports: &[(&Problem, &study::ProblemReport)]) -> Vec<String> {
    let mut shown = std::collections::BTreeSet::new();
    for (_, r) in reports {
        for block in r.items.iter().flat_map(|it| &it.item.blocks) {
            let (stem, kinds): (&str, [&str; 2]) = match block {
                super::report::Block::Image { path, .. } => (path.trim_end_matches(".png"), ["png", "svg"]),
                super::report::Block::Table { md_path, .. } => {
                    (md_path.trim_end_matches(".md"), ["md", "csv"])
                }
                _ => continue,
            };
            shown.extend(kinds.map(|k| manuscript.join(format!("{stem}.{k}"))));
        }
    }
    let mut removed = Vec::new();
    for sub in ["figures", "tables"] {
        let Ok(rd) = std::fs::read_dir(manuscript.join(sub)) else { continue };
        for f in rd.flatten().map(|e| e.path()) {
            let ours = f
                .extension()
                .is_some_and(|x| ["png", "svg", "md", "csv"].contains(&x.to_str().unwrap_or("")));
            if ours && !shown.contains(&f) && std::fs::remove_file(&f).is_ok() {
                removed.push(format!("{sub}/{}", f.file_name().unwrap_or_default().to_string_lossy()));
            }
        }
    }
    removed.sort();
    removed
}

/// The manuscript's title and opening paragraphs for `preset`.
fn header(preset: &str) -> study::Header {
    let how = format!(
        "Every figure, table and verdict below is regenerated by `sphrepro reproduce --preset {preset}` \
         from the problem files (`problems/`) and the results of their cases; nothing in it is written by hand \
         but the problem files' text. Each figure or table of a paper appears under the paper's own number, with \
         the paper's caption in our words, our figure, and the paper's claims on it. A claim is a test on the \
         results' metrics at a stated resolution, with the source of its tolerance; its verdict is computed: \
         *reproduced*, *not reproduced* (with the numbers), or *not run* (the results at that resolution are \
         missing, with an estimate of what they would cost). A verdict drawn from another resolution than the \
         paper's says so."
    );
    if preset == results::EXPORT_PRESET {
        study::Header {
            title: "sphrepro: the seed papers' figures at the papers' resolutions".into(),
            intro: format!(
                "{how}\n\nThe results are committed in `results/`, so `sphrepro reproduce --plot-only --preset {preset}` \
                 on a fresh clone redraws this manuscript, byte for byte, without simulating."
            ),
            cases: None,
        }
    } else {
        study::Header {
            title: format!("Smoke check ({preset} preset): not the paper's resolutions"),
            intro: format!(
                "{how}\n\nThis is the `{preset}` preset: coarser resolutions and shorter runs than the papers', to check \
                 in minutes that every problem runs and every figure is drawn. Its verdicts at the paper's \
                 resolutions come from the committed results where they exist; the manuscript of the papers' \
                 resolutions is `manuscript/manuscript.md`."
            ),
            cases: None,
        }
    }
}

/// `status`: every case's state and the stale folders. Exits 1 if any case is not done.
pub fn status(dirs: &Dirs, preset: &str, list_stale: bool) -> u8 {
    match load(dirs, preset, &[]) {
        Ok(ps) => {
            let n = check::status(&dirs.output, &ps, list_stale);
            if n.failed + n.damaged + n.missing + n.queued == 0 {
                OK
            } else {
                FAILED
            }
        }
        Err(e) => {
            errln!("error: {e}");
            BAD_INPUT
        }
    }
}

/// `check`: every bound of the preset against the cached results.
pub fn check(
    dirs: &Dirs,
    preset: &str,
    only: &[String],
    matching: Option<&str>,
    against_baseline: bool,
) -> u8 {
    if against_baseline && preset != baseline::PRESET {
        errln!(
            "error: `--baseline` compares the `{}` preset's results; `--preset {preset}` has no baseline",
            baseline::PRESET
        );
        return BAD_INPUT;
    }
    let mut ps = match load(dirs, preset, only) {
        Ok(p) => p,
        Err(e) => {
            errln!("error: {e}");
            return BAD_INPUT;
        }
    };
    if let Some(g) = matching {
        let m = match globset::Glob::new(g) {
            Ok(m) => m.compile_matcher(),
            Err(e) => {
                errln!("error: --match `{g}`: {e}");
                return BAD_INPUT;
            }
        };
        for p in &mut ps {
            let name = p.name.clone();
            p.cases.retain(|c| m.is_match(&c.name) || m.is_match(format!("{name}/{}", c.name)));
        }
        ps.retain(|p| !p.cases.is_empty());
        if ps.is_empty() {
            errln!("error: --match `{g}` selects no case");
            return BAD_INPUT;
        }
    }
    if against_baseline {
        return check_baselines(dirs, &ps, matching.is_some());
    }
    let (ok, bad) = check::check(&dirs.output, &ps);
    for b in &bad {
        outln!("FAIL {}: {}", b.case, b.what);
    }
    outln!("{ok} bound(s) hold, {} breached (preset {preset})", bad.len());
    if bad.is_empty() {
        OK
    } else {
        FAILED
    }
}

/// `check --baseline`: every problem's results against its committed baseline, metric by
/// metric, within the tolerances its file states (exact by default); a case `--match` left
/// out (`partial`) is not a change.
fn check_baselines(dirs: &Dirs, ps: &[Problem], partial: bool) -> u8 {
    let (mut status, mut compared) = (OK, 0);
    for p in ps {
        let old = match baseline::read(p) {
            Ok(Some(b)) => b,
            Ok(None) => {
                outln!(
                    "FAIL {}: no baseline ({}); `sphrepro bless {}` writes it",
                    p.name,
                    baseline::path(p).display(),
                    p.name
                );
                status = FAILED;
                continue;
            }
            Err(e) => {
                errln!("error: {e}");
                status = FAILED;
                continue;
            }
        };
        let (now, missing) = baseline::current(&dirs.output, p);
        for m in &missing {
            outln!("FAIL {}/{m}: no result to compare (`sphrepro run {}` computes it)", p.name, p.name);
            status = FAILED;
        }
        let mut changes = baseline::compare(&old, &now, &p.baseline);
        // Cases not selected or not run are named above, not as changes.
        changes.retain(|c| {
            !(c.what == "case"
                && c.old == "in the baseline"
                && (partial || missing.iter().any(|m| m.starts_with(&format!("{}:", c.case)))))
        });
        compared += now.cases.len();
        if !changes.is_empty() {
            status = FAILED;
            for c in &changes {
                let rel = c.rel.map(|r| format!(" ({r:+.3e})")).unwrap_or_default();
                outln!("FAIL {}/{}: {}: {} -> {}{rel}", p.name, c.case, c.what, c.old, c.new);
            }
            if let Some(reason) = &p.baseline.reason {
                outln!("  ({}'s tolerances: {reason})", p.name);
            }
        }
    }
    outln!(
        "{compared} case(s) compared with their baselines: {}",
        if status == OK {
            "no change"
        } else {
            "changed or missing (a deliberate change is blessed with `sphrepro bless PROBLEM`)"
        }
    );
    status
}

/// `bless`: rewrites the baselines of `only` (every problem with `all`) from the quick
/// preset's results, and prints what moved.
pub fn bless(dirs: &Dirs, only: &[String], all: bool) -> u8 {
    if only.is_empty() && !all {
        errln!("error: name the problems whose baselines to rewrite, or give `--all`");
        return BAD_INPUT;
    }
    let ps = match load(dirs, baseline::PRESET, only) {
        Ok(p) => p,
        Err(e) => {
            errln!("error: {e}");
            return BAD_INPUT;
        }
    };
    let mut status = OK;
    for p in &ps {
        match baseline::bless(&dirs.output, p) {
            Ok(changes) if changes.is_empty() => {
                outln!("{}: unchanged ({})", p.name, baseline::path(p).display())
            }
            Ok(changes) => {
                outln!("{}: {} change(s), written to {}", p.name, changes.len(), baseline::path(p).display());
                outln!("{}", baseline::table(&p.name, &changes));
            }
            Err(e) => {
                errln!("error: {e}");
                status = FAILED;
            }
        }
    }
    status
}

/// The cache folder of every case (for tests and tools).
pub fn case_dirs(dirs: &Dirs, preset: &str) -> Result<Vec<PathBuf>, String> {
    let ps = load(dirs, preset, &[])?;
    Ok(ps.iter().flat_map(|p| cache::entries(&dirs.output, p).into_iter().map(|e| e.dir)).collect())
}
