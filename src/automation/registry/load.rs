//! Loading problem files: read, parse against the schema, look up the scene, then expand
//! and check every preset, so that an error in `paper` is found while running `quick`.

use super::expand::Expand;
use super::model::{valid_name, Problem, DEFAULT_PRESET};
use super::schema::{Loc, ProblemFile};
use crate::automation::papers;
use crate::scenes;
use std::path::{Path, PathBuf};

/// Loads and validates every `*.toml` in `dir`, sorted by name, expanded for `preset`.
/// Problems without that preset are an error naming them.
pub fn load_dir(dir: &Path, preset: &str) -> Result<Vec<Problem>, String> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: cannot read the problems folder: {e}", dir.display()))?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        // The Slurm executor's settings live with the problems; they are not a problem.
        .filter(|p| p.file_name().is_none_or(|n| n != crate::automation::slurm::settings::FILE_NAME))
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

/// [`load`] from a string (`path` names it in errors and locates `reference_data/`).
pub fn parse(path: &Path, src: &str, preset: &str) -> Result<Problem, String> {
    let loc = Loc { path, src };
    let file: ProblemFile = toml::from_str(src).map_err(|e| {
        let line = e.span().map(|s| loc.line(s.start)).unwrap_or(1);
        // The parser names the value, not always its key: quote the line, which holds both.
        let text = src.lines().nth(line - 1).map(str::trim).unwrap_or_default();
        let quoted = if text.is_empty() || text.len() > 80 { String::new() } else { format!("`{text}`: ") };
        format!("{}:{line}: {quoted}{}", path.display(), e.message().trim_end().replace('\n', " "))
    })?;
    let scene = scenes::find(file.scene.get_ref()).map_err(|e| loc.err(file.scene.span(), "scene", e))?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    if !valid_name(&name) {
        return Err(format!(
            "{}: the file name must use letters, digits, `.`, `_` and `-` only",
            path.display()
        ));
    }
    papers::find(file.paper.get_ref()).map_err(|e| loc.err(file.paper.span(), "paper", e))?;
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
    let (mut out, mut others, mut claims_at, mut figures_at) = (None, Vec::new(), Vec::new(), Vec::new());
    for (pname, vars) in &file.presets {
        let x = Expand { loc: &loc, file: &file, scene, specs: &specs, preset: pname, vars: vars.get_ref() };
        let p = x.problem(&name)?;
        claims_at.push(p.claims.iter().map(|c| c.at.clone()).collect::<Vec<_>>());
        figures_at.push(p.figures.iter().map(|f| f.select_at.clone()).collect::<Vec<_>>());
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
    // Each claim resolved in every preset, so that a verdict can be drawn from another
    // resolution when the claim's own has no results.
    for at in claims_at {
        for (c, a) in problem.claims.iter_mut().zip(at) {
            c.at.extend(a);
        }
    }
    for at in figures_at {
        for (f, a) in problem.figures.iter_mut().zip(at) {
            f.select_at.extend(a);
        }
    }
    // The paper's section of every numbered item: its own or the problem's.
    let numbered = problem
        .figures
        .iter()
        .map(|f| (&f.id, &f.info))
        .chain(problem.tables.iter().map(|t| (&t.id, &t.info)))
        .find(|(_, i)| i.number.is_some() && i.section.is_none());
    if let (Some((id, _)), None) = (numbered, &problem.section) {
        return Err(format!(
            "{}: `{id}` has the paper's `number` but neither it nor the problem names the paper's `section`",
            path.display()
        ));
    }
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

#[cfg(test)]
mod tests {
    use super::super::testutil::{p, GOOD};

    #[test]
    fn errors_name_file_line_and_key() {
        let e = p(&GOOD.replace("title = \"x\"", "title = \"x\"\ncolour = 3")).unwrap_err();
        assert!(e.contains("x.toml:") && e.contains("colour"), "{e}");
        let e = p(&GOOD.replace("taylor_green", "nope")).unwrap_err();
        assert!(e.contains("x.toml:3:") && e.contains("nope"), "{e}");
    }
}
