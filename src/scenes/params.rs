//! Self-describing scene parameters: each scene declares its parameters with a kind, a
//! default and a help line; values from the command line (`--set key=value`) or a problem
//! file are checked against them, and every error names the scene, the key and the value.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// A parameter value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    /// Boolean.
    Bool(bool),
    /// Integer.
    Int(i64),
    /// Floating-point number.
    Float(f64),
    /// A name from a fixed list.
    Str(String),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{b}"),
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x}"),
            Value::Str(s) => write!(f, "{s}"),
        }
    }
}

/// What values a parameter takes.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// An integer `>= min`.
    Int {
        /// Smallest accepted value.
        min: i64,
    },
    /// A finite number, optionally required `> 0` or `>= 0`.
    Float {
        /// Lower bound.
        bound: Bound,
    },
    /// `true` or `false`.
    Bool,
    /// One of the listed names.
    Choice(&'static [&'static str]),
    /// `auto` or an integer `>= min` (a count the scene may work out itself).
    AutoOrInt {
        /// Smallest accepted value.
        min: i64,
    },
}

/// A lower bound on a float parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// Any finite value.
    None,
    /// `> 0`.
    Positive,
    /// `>= 0`.
    NonNegative,
}

/// One declared parameter.
#[derive(Clone, Debug)]
pub struct Spec {
    /// Key.
    pub name: &'static str,
    /// Accepted values.
    pub kind: Kind,
    /// Default.
    pub default: Value,
    /// One line of help (with units).
    pub help: &'static str,
    /// Added after results were computed without it, with a default that reproduces them:
    /// at its default it stays out of the cache key, so those results stay current.
    pub added_later: bool,
    /// The largest value that makes sense, if there is one (a number or an integer): a
    /// perturbation beyond the spacing, or a loop bound so large that a step would never
    /// end, is refused up front with the key named.
    pub max: Option<f64>,
}

impl Spec {
    /// An integer parameter.
    pub fn int(name: &'static str, default: i64, min: i64, help: &'static str) -> Self {
        Self {
            name,
            kind: Kind::Int { min },
            default: Value::Int(default),
            help,
            added_later: false,
            max: None,
        }
    }
    /// A float parameter.
    pub fn float(name: &'static str, default: f64, bound: Bound, help: &'static str) -> Self {
        Self {
            name,
            kind: Kind::Float { bound },
            default: Value::Float(default),
            help,
            added_later: false,
            max: None,
        }
    }
    /// A boolean parameter.
    pub fn bool(name: &'static str, default: bool, help: &'static str) -> Self {
        Self { name, kind: Kind::Bool, default: Value::Bool(default), help, added_later: false, max: None }
    }
    /// A choice parameter.
    pub fn choice(
        name: &'static str,
        choices: &'static [&'static str],
        default: &str,
        help: &'static str,
    ) -> Self {
        Self {
            name,
            kind: Kind::Choice(choices),
            default: Value::Str(default.into()),
            help,
            added_later: false,
            max: None,
        }
    }

    /// A parameter that is `auto` (its default) or an integer `>= min`.
    pub fn auto_or_int(name: &'static str, min: i64, help: &'static str) -> Self {
        Self {
            name,
            kind: Kind::AutoOrInt { min },
            default: Value::Str("auto".into()),
            help,
            added_later: false,
            max: None,
        }
    }

    /// The parameter marked [`added_later`](Self::added_later).
    pub fn added_later(self) -> Self {
        Self { added_later: true, ..self }
    }

    /// The parameter with its largest sensible value, [`max`](Self::max).
    pub fn at_most(self, max: f64) -> Self {
        Self { max: Some(max), ..self }
    }

    /// The kind in words, for help and errors.
    pub fn kind_name(&self) -> String {
        let kind = self.lower_bound_name();
        match self.max {
            Some(max) => format!("{kind}, <= {max}"),
            None => kind,
        }
    }

    fn lower_bound_name(&self) -> String {
        match self.kind {
            Kind::Int { min } => format!("integer >= {min}"),
            Kind::Float { bound: Bound::Positive } => "number > 0".into(),
            Kind::Float { bound: Bound::NonNegative } => "number >= 0".into(),
            Kind::Float { bound: Bound::None } => "number".into(),
            Kind::Bool => "true|false".into(),
            Kind::Choice(c) => c.join("|"),
            Kind::AutoOrInt { min } => format!("auto|integer >= {min}"),
        }
    }

    /// Checks a typed value (from a problem file), converting an integer given for a float.
    pub fn check(&self, scene: &str, v: &Value) -> Result<Value, String> {
        // A number as Rust reads it back: 1e300 in three digits, not in 301.
        let shown = match v {
            Value::Float(x) => format!("{x:?}"),
            v => v.to_string(),
        };
        let bad = |why: &str| format!("scene `{scene}`: parameter `{}` = {shown}: {why}", self.name);
        match (self.kind, v) {
            (Kind::Int { min }, Value::Int(i)) => {
                if *i < min {
                    return Err(bad(&format!("must be >= {min}")));
                }
                if let Some(max) = self.max.filter(|&m| *i as f64 > m) {
                    return Err(bad(&format!("must be <= {max}")));
                }
                Ok(v.clone())
            }
            (Kind::Int { .. }, _) => Err(bad("expected an integer")),
            (Kind::Float { bound }, Value::Int(_) | Value::Float(_)) => {
                let x = match v {
                    Value::Int(i) => *i as f64,
                    Value::Float(x) => *x,
                    _ => unreachable!(),
                };
                if !x.is_finite() {
                    return Err(bad("must be finite"));
                }
                match bound {
                    Bound::Positive if x <= 0.0 => Err(bad("must be > 0")),
                    Bound::NonNegative if x < 0.0 => Err(bad("must be >= 0")),
                    _ if self.max.is_some_and(|m| x > m) => {
                        Err(bad(&format!("must be <= {}", self.max.unwrap_or_default())))
                    }
                    _ => Ok(Value::Float(x)),
                }
            }
            (Kind::Float { .. }, _) => Err(bad("expected a number")),
            (Kind::Bool, Value::Bool(_)) => Ok(v.clone()),
            (Kind::Bool, _) => Err(bad("expected true or false")),
            (Kind::Choice(c), Value::Str(s)) if c.contains(&s.as_str()) => Ok(v.clone()),
            (Kind::Choice(c), _) => Err(bad(&format!("expected one of {}", c.join(", ")))),
            (Kind::AutoOrInt { .. }, Value::Str(s)) if s == "auto" => Ok(v.clone()),
            (Kind::AutoOrInt { min }, Value::Int(i)) if *i >= min => {
                match self.max.filter(|&m| *i as f64 > m) {
                    Some(max) => Err(bad(&format!("must be auto or <= {max}"))),
                    None => Ok(v.clone()),
                }
            }
            (Kind::AutoOrInt { min }, _) => Err(bad(&format!("expected auto or an integer >= {min}"))),
        }
    }

    /// Parses a command-line string against this parameter's kind.
    pub fn parse(&self, scene: &str, s: &str) -> Result<Value, String> {
        let s = s.trim();
        let v = match self.kind {
            Kind::Int { .. } | Kind::AutoOrInt { .. } => {
                s.parse::<i64>().map(Value::Int).unwrap_or_else(|_| Value::Str(s.into()))
            }
            Kind::Float { .. } => s.parse::<f64>().map(Value::Float).unwrap_or_else(|_| Value::Str(s.into())),
            Kind::Bool => match s {
                "true" => Value::Bool(true),
                "false" => Value::Bool(false),
                _ => Value::Str(s.into()),
            },
            Kind::Choice(_) => Value::Str(s.into()),
        };
        self.check(scene, &v)
    }
}

/// Resolved parameters: every declared key with its value.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Params(pub BTreeMap<String, Value>);

impl Params {
    /// All defaults of `specs`.
    pub fn defaults(specs: &[Spec]) -> Self {
        Self(specs.iter().map(|s| (s.name.to_string(), s.default.clone())).collect())
    }

    /// Without the parameters [added later](Spec::added_later) that hold their default:
    /// the inputs as a run from before those parameters existed recorded them, so that
    /// its results (cache keys, checkpoints) stay its own.
    pub fn without_later_defaults(&self, specs: &[Spec]) -> Self {
        let mut p = self.clone();
        for s in specs.iter().filter(|s| s.added_later) {
            if p.0.get(s.name) == Some(&s.default) {
                p.0.remove(s.name);
            }
        }
        p
    }

    /// Sets `key` from a string, checked against `specs`.
    pub fn set_str(&mut self, scene: &str, specs: &[Spec], key: &str, value: &str) -> Result<(), String> {
        let spec = find_spec(scene, specs, key, value)?;
        self.0.insert(key.into(), spec.parse(scene, value)?);
        Ok(())
    }

    /// Sets `key` from a typed value, checked against `specs`.
    pub fn set_value(&mut self, scene: &str, specs: &[Spec], key: &str, value: &Value) -> Result<(), String> {
        let spec = find_spec(scene, specs, key, &value.to_string())?;
        self.0.insert(key.into(), spec.check(scene, value)?);
        Ok(())
    }

    fn get(&self, key: &str) -> &Value {
        self.0.get(key).unwrap_or_else(|| panic!("parameter `{key}` is not declared by this scene"))
    }

    /// An integer parameter.
    pub fn int(&self, key: &str) -> i64 {
        match self.get(key) {
            Value::Int(i) => *i,
            v => panic!("parameter `{key}` = {v} is not an integer"),
        }
    }

    /// A float parameter.
    pub fn float(&self, key: &str) -> f64 {
        match self.get(key) {
            Value::Float(x) => *x,
            Value::Int(i) => *i as f64,
            v => panic!("parameter `{key}` = {v} is not a number"),
        }
    }

    /// A boolean parameter.
    pub fn bool(&self, key: &str) -> bool {
        match self.get(key) {
            Value::Bool(b) => *b,
            v => panic!("parameter `{key}` = {v} is not a boolean"),
        }
    }

    /// An `auto`-or-integer parameter: `None` for `auto`.
    pub fn auto_or_int(&self, key: &str) -> Option<i64> {
        match self.get(key) {
            Value::Int(i) => Some(*i),
            Value::Str(s) if s == "auto" => None,
            v => panic!("parameter `{key}` = {v} is neither auto nor an integer"),
        }
    }

    /// A choice parameter.
    pub fn str(&self, key: &str) -> &str {
        match self.get(key) {
            Value::Str(s) => s,
            v => panic!("parameter `{key}` = {v} is not a name"),
        }
    }

    /// As a JSON object (for `summary.json`).
    pub fn to_json(&self) -> BTreeMap<String, serde_json::Value> {
        self.0.iter().map(|(k, v)| (k.clone(), serde_json::to_value(v).expect("value serialises"))).collect()
    }
}

fn find_spec<'a>(scene: &str, specs: &'a [Spec], key: &str, value: &str) -> Result<&'a Spec, String> {
    specs.iter().find(|s| s.name == key).ok_or_else(|| {
        let known: Vec<_> = specs.iter().map(|s| s.name).collect();
        format!(
            "scene `{scene}`: unknown parameter `{key}` (= {value}); known parameters: {}",
            known.join(", ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn specs() -> Vec<Spec> {
        vec![
            Spec::int("nx", 50, 1, "particles per side"),
            Spec::float("tf", 2.0, Bound::Positive, "end time"),
            Spec::bool("flag", true, "a switch"),
            Spec::choice("scheme", &["edac", "ctvf"], "ctvf", "scheme"),
            Spec::float("perturb", 0.0, Bound::NonNegative, "a displacement").at_most(1.0),
            Spec::int("sweeps", 10, 1, "a loop bound").at_most(1000.0),
        ]
    }

    #[test]
    fn errors_name_key_and_value() {
        let s = specs();
        let mut p = Params::defaults(&s);
        let e = p.set_str("tg", &s, "nx", "-5").unwrap_err();
        assert!(e.contains("`nx`") && e.contains("-5"), "{e}");
        let e = p.set_str("tg", &s, "nx", "fifty").unwrap_err();
        assert!(e.contains("`nx`") && e.contains("fifty") && e.contains("integer"), "{e}");
        let e = p.set_str("tg", &s, "tf", "0").unwrap_err();
        assert!(e.contains("`tf`") && e.contains("> 0"), "{e}");
        let e = p.set_str("tg", &s, "frobnicate", "3").unwrap_err();
        assert!(e.contains("`frobnicate`") && e.contains("unknown"), "{e}");
        let e = p.set_str("tg", &s, "scheme", "warp9").unwrap_err();
        assert!(e.contains("warp9") && e.contains("edac, ctvf"), "{e}");
        let e = p.set_str("tg", &s, "tf", "nan").unwrap_err();
        assert!(e.contains("finite"), "{e}");
        let e = p.set_str("tg", &s, "perturb", "1e20").unwrap_err();
        assert!(e.contains("`perturb` = 1e20: must be <= 1"), "{e}");
        let e = p.set_str("tg", &s, "sweeps", "1001").unwrap_err();
        assert!(e.contains("`sweeps` = 1001: must be <= 1000"), "{e}");
        p.set_str("tg", &s, "perturb", "1").unwrap();
        p.set_str("tg", &s, "sweeps", "1000").unwrap();
        assert_eq!(s[4].kind_name(), "number >= 0, <= 1");
    }

    #[test]
    fn values_parse_and_integers_widen_to_floats() {
        let s = specs();
        let mut p = Params::defaults(&s);
        p.set_str("tg", &s, "nx", "32").unwrap();
        p.set_value("tg", &s, "tf", &Value::Int(3)).unwrap();
        p.set_str("tg", &s, "flag", "false").unwrap();
        assert_eq!(p.int("nx"), 32);
        assert_eq!(p.0["tf"], Value::Float(3.0));
        assert!(!p.bool("flag"));
        assert_eq!(p.str("scheme"), "ctvf");
    }
}
