//! The automation commands behind `sphrepro list | run | reproduce | status | check`; each
//! returns the process exit status.

use super::registry::{self, Problem};
use super::runner::{self, Options};
use super::{cache, check, slurm};
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
            for t in &tasks {
                outln!(
                    "would run {}/{} ({})  -> {}",
                    t.problem,
                    t.entry.case.name,
                    t.reason,
                    t.entry.dir.display()
                );
            }
            outln!("{} to run, {done} done (skipped)", tasks.len());
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
    if let Err(e) = post_process(dirs, &problems, flags) {
        errln!("error: {e}");
        return FAILED;
    }
    status
}

/// Figures, tables and (with `flags.manuscript`) manuscript.md from cached results.
fn post_process(dirs: &Dirs, problems: &[Problem], flags: &RunFlags) -> Result<(), String> {
    if problems.iter().all(|p| p.figures.is_empty() && p.tables.is_empty()) && !flags.manuscript {
        return Ok(());
    }
    ensure_dir(&dirs.manuscript, "manuscript")?;
    let mut sections = Vec::new();
    let mut errors = Vec::new();
    for p in problems {
        // Figures of nothing would overwrite the last ones drawn from results (a mistyped
        // --output, every case failed): leave them, and say so.
        let entries = super::cache::entries(&dirs.output, p);
        // Nor are they drawn without a case whose result is damaged (it would be left out).
        let damaged: Vec<String> = entries
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
        if !entries.is_empty() && !entries.iter().any(|e| e.is_done()) {
            errors.push(format!(
                "{}: no case has a result under {}; its figures and tables are left as they were",
                p.name,
                dirs.output.display()
            ));
            continue;
        }
        match super::study::regenerate(p, &dirs.output, &dirs.manuscript) {
            Ok(section) => sections.push(section),
            Err(e) => {
                errors.push(e);
                continue;
            }
        }
        outln!(
            "{}: {} figure(s), {} table(s) in {}",
            p.name,
            p.figures.len(),
            p.tables.len(),
            dirs.manuscript.display()
        );
    }
    // Every problem's figures were attempted; a manuscript missing a section is not written
    // over the last whole one.
    if !errors.is_empty() {
        return Err(errors.join("\nerror: "));
    }
    if flags.manuscript {
        let path = dirs.manuscript.join("manuscript.md");
        super::report::write_manuscript(
            &super::report::Manuscript {
                title: "sphrepro: regenerated results".into(),
                intro: format!(
                    "Every figure and table below was regenerated by `sphrepro reproduce --preset {}` \
                     from the problem files in `problems/` and the cached results; each figure says what \
                     the paper shows and what this run got. Solver fingerprint {}.",
                    problems.first().map(|p| p.preset.as_str()).unwrap_or("quick"),
                    super::cache::fingerprint()
                ),
                sections,
            },
            &path,
        )?;
        outln!("wrote {}", path.display());
    }
    Ok(())
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
pub fn check(dirs: &Dirs, preset: &str) -> u8 {
    let ps = match load(dirs, preset, &[]) {
        Ok(p) => p,
        Err(e) => {
            errln!("error: {e}");
            return BAD_INPUT;
        }
    };
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

/// The cache folder of every case (for tests and tools).
pub fn case_dirs(dirs: &Dirs, preset: &str) -> Result<Vec<PathBuf>, String> {
    let ps = load(dirs, preset, &[])?;
    Ok(ps.iter().flat_map(|p| cache::entries(&dirs.output, p).into_iter().map(|e| e.dir)).collect())
}
