//! Expansion of a problem file into named cases for one preset: preset variables (`$name`)
//! substituted, values checked against the scene's declared parameters, each `[[cases]]`
//! group's grid expanded into one case per combination (like automan's `mdict`/`dprod`),
//! named from the group's template, and the same simulation under two names run once.

use super::model::{valid_name, BaselineRule, Case, Claim, Problem, MAX_CASES};
use super::schema::{Loc, ProblemFile, RawParams, Span};
use crate::scenes::params::{Params, Spec, Value};
use crate::scenes::{self, SceneEntry};
use std::collections::BTreeMap;
use toml::Spanned;

/// A value as written, after substituting preset variables: one value or a list.
pub(super) enum Raw {
    One(Value),
    List(Vec<Value>),
}

/// A scalar TOML value as a parameter value.
fn to_value(v: &toml::Value) -> Result<Value, String> {
    Ok(match v {
        toml::Value::Boolean(b) => Value::Bool(*b),
        toml::Value::Integer(i) => Value::Int(*i),
        toml::Value::Float(x) => Value::Float(*x),
        toml::Value::String(s) => Value::Str(s.clone()),
        other => return Err(format!("expected a number, a boolean or a name, found {other}")),
    })
}

/// The value of `key` as written, with a preset variable (`"$name"`) replaced by its value
/// in `vars`.
pub(super) fn resolve_raw(
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

/// `v` checked as the value of the scene's parameter `key` (its type and bounds), or an error
/// naming the scene's parameters when it has no `key`.
pub(super) fn check_param(
    loc: &Loc,
    span: Span,
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

/// What expanding one problem file has at hand: where its errors point, the file, its scene
/// (and the scene's parameters), the preset and the file's variables.
pub(super) struct Expand<'a> {
    pub(super) loc: &'a Loc<'a>,
    pub(super) file: &'a ProblemFile,
    pub(super) scene: &'static SceneEntry,
    pub(super) specs: &'a [Spec],
    pub(super) preset: &'a str,
    pub(super) vars: &'a RawParams,
}

impl Expand<'_> {
    /// The problem `name` in this preset: its cases, then its figures, tables, bounds and
    /// claims, each checked against the scene and the cases (a claim's `at` holds this preset
    /// when its selection picks a case here).
    pub(super) fn problem(&self, name: &str) -> Result<Problem, String> {
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
        let mut claims = Vec::new();
        for c in &file.claims {
            let at = self.claim(c, &cases, &ids)?;
            let raw = c.get_ref();
            claims.push(Claim {
                figure: raw.figure.clone(),
                claim: raw.claim.clone(),
                preset: raw.preset.clone().unwrap_or_else(|| "paper".into()),
                source: raw.source.clone(),
                line: self.loc.line(c.span().start),
                at: at.map(|t| BTreeMap::from([(self.preset.to_string(), t)])).unwrap_or_default(),
            });
        }
        Ok(Problem {
            name: name.to_string(),
            path: self.loc.path.to_path_buf(),
            title: file.title.clone(),
            paper: file.paper.get_ref().clone(),
            section: file.section.clone(),
            description: file.description.clone(),
            scene: self.scene,
            preset: self.preset.to_string(),
            other_presets: Vec::new(),
            cases,
            figures,
            tables,
            bounds,
            claims,
            baseline: self.baseline()?,
        })
    }

    /// The `[baseline]` rule: tolerances finite and not negative, of metrics the scene
    /// reports, with a reason whenever one is given.
    fn baseline(&self) -> Result<BaselineRule, String> {
        let Some(b) = &self.file.baseline else { return Ok(BaselineRule::default()) };
        let (span, raw) = (b.span(), b.get_ref());
        let bad = |t: f64| !(t.is_finite() && t >= 0.0);
        if let Some(t) = raw.tolerance.filter(|&t| bad(t)) {
            return Err(self.loc.err(
                span,
                "baseline.tolerance",
                format!("{t}: a relative tolerance is finite and not negative"),
            ));
        }
        for (m, &t) in &raw.tolerances {
            if !self.scene.metrics.contains(&m.as_str()) {
                return Err(self.loc.err(
                    span,
                    "baseline.tolerances",
                    format!(
                        "scene `{}` has no metric `{m}`; its metrics: {}",
                        self.scene.name,
                        self.scene.metrics.join(", ")
                    ),
                ));
            }
            if bad(t) {
                return Err(self.loc.err(
                    span,
                    "baseline.tolerances",
                    format!("`{m}` = {t}: a relative tolerance is finite and not negative"),
                ));
            }
        }
        let loose = raw.tolerance.is_some_and(|t| t > 0.0) || raw.tolerances.values().any(|&t| t > 0.0);
        if loose && raw.reason.as_deref().is_none_or(|r| r.trim().is_empty()) {
            return Err(self.loc.err(
                span,
                "baseline.reason",
                "a tolerance needs its reason: why the results are not exact",
            ));
        }
        Ok(BaselineRule {
            tolerance: raw.tolerance.unwrap_or(0.0),
            tolerances: raw.tolerances.clone(),
            reason: raw.reason.clone(),
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
                if let Some(e) = scenes::fluid_scheme::unused_scheme_option(&p, given) {
                    return Err(loc.err(
                        gspan.clone(),
                        e.key,
                        format!("= {} in case `{cname}` {}", p.0[e.key], e.why),
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
    use super::super::parse;
    use super::super::testutil::{p, GOOD};
    use crate::scenes::params::Value;
    use std::path::Path;

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
    fn case_errors_name_file_line_and_key() {
        let e = p(&GOOD.replace("pst = \"sun\"", "pst = \"warp\"")).unwrap_err();
        assert!(e.starts_with("x.toml:15:") && e.contains("pst"), "{e}");
        let e = p(&GOOD.replace("pst = \"sun\" }", "pst = \"sun\", frob = 1 }")).unwrap_err();
        assert!(e.contains("frob") && e.contains(":15:"), "{e}");
        let e = p(&GOOD.replace("nx = 16 }", "nx = 1.5 }")).unwrap_err();
        assert!(e.contains("nx") && e.contains("integer"), "{e}");
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
    }
}
