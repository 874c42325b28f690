//! Parameter values in words, for legends, map rows and the manuscript: declared once here
//! so that every figure says "SPST, with corrections" or "surface pressure held at zero"
//! rather than `pst = sun, corrections = all` or `surface_pressure=zero`.

use crate::automation::registry::Case;
use crate::scenes::params::Value;
use crate::solver::scheme::SolidSchemeName;

/// The words for parameter `key` at value `v`; empty when the value needs no mention (a
/// switch left to the scheme's default).
pub(crate) fn phrase(key: &str, v: &Value) -> String {
    let s = match v {
        Value::Str(s) => s.as_str(),
        _ => "",
    };
    let num = || number(v);
    match (key, s) {
        ("scheme", "edac") => "EDAC".into(),
        ("scheme", "tvf") => "TVF".into(),
        ("scheme", "ctvf") => "CTVF".into(),
        ("scheme", "gtvf") => "GTVF (its background pressure)".into(),
        ("scheme", "gtvf_pst") => "GTVF's equations".into(),
        ("scheme", "gray") => "Gray et al. (artificial stress)".into(),
        ("pst", "sun") => "SPST".into(),
        ("pst", "ipst") => "IPST".into(),
        ("pst", "none") => "no shifting".into(),
        ("corrections", "all") => "with corrections".into(),
        ("corrections", "none") => "without corrections".into(),
        ("corr_pressure" | "corr_momentum" | "corr_continuity", "auto") => String::new(),
        ("corr_pressure", "on") => "pressure corrections on".into(),
        ("corr_pressure", "off") => "pressure corrections off".into(),
        ("corr_momentum", "on") => "momentum correction on".into(),
        ("corr_momentum", "off") => "momentum correction off".into(),
        ("corr_continuity", "on") => "continuity correction on".into(),
        ("corr_continuity", "off") => "continuity correction off".into(),
        ("surface_pressure", "evolve") => "surface pressure evolved".into(),
        ("surface_pressure", "zero") => "surface pressure held at zero".into(),
        ("surface_pressure", "zero_isolated") => "isolated particles at zero pressure".into(),
        ("surface_pressure", "non_negative") => "surface pressure clamped at zero".into(),
        ("wall_pressure", "extrapolated") => "wall pressure extrapolated".into(),
        ("wall_pressure", "non_negative") => "wall pressure clamped at zero".into(),
        ("wall_density", "state_equation") => "wall density from the state equation".into(),
        ("wall_density", "reference") => "walls at the reference density".into(),
        ("pressure_reference", "auto") => String::new(),
        ("pressure_reference", "local_mean") => "neighbours' mean pressure as reference".into(),
        ("pressure_reference", "global_mean") => "fluid's mean pressure as reference".into(),
        ("pressure_reference", "none") => "no reference pressure (eq. 27)".into(),
        ("rate_positions", "start") => "rates at the step's start".into(),
        ("rate_positions", "end") => "rates after the drift".into(),
        ("kernel", k) if !k.is_empty() => k.replace('_', " ").replace("wendland c2", "Wendland C2"),
        ("shape", sh) if !sh.is_empty() => sh.to_string(),
        ("nx", _) => format!("{0} x {0}", num()),
        ("dx", _) => format!("dx = {} m", num()),
        ("re", _) => format!("Re = {}", num()),
        ("hdx", _) => format!("h/dx = {}", num()),
        ("cfl", _) => format!("CFL {}", num()),
        ("perturb", _) if number_value(v) == Some(0.0) => "exact lattice".into(),
        ("perturb", _) => format!("perturbed by {} dx", num()),
        ("alpha", _) => format!("alpha = {}", num()),
        ("ipst_interval", _) if number_value(v) == Some(1.0) => "IPST every step".into(),
        ("ipst_interval", _) => format!("IPST every {} steps", num()),
        ("ipst_tol", _) => format!("tolerance {}", num()),
        ("tf", _) => format!("to t = {} s", num()),
        ("piston_speed", _) => format!("piston at {} m/s", num()),
        ("vf", _) => format!("V_f = {}", num()),
        ("poisson_ratio", _) => format!("nu = {}", num()),
        ("nz", _) => format!("{} layers deep", num()),
        ("gradient", "paper") => "the paper's kernel gradient".into(),
        ("gradient", "corrected") => "corrected kernel gradient".into(),
        ("surface_shift", "normal") => "shift's normal part removed near the surface".into(),
        ("surface_shift", "outward") => "shift's outward part removed near the surface".into(),
        ("platens", "bonded") => "bonded to the platens".into(),
        ("platens", "frictionless") => "frictionless platens".into(),
        ("rings", "two_bodies") => "rings as two bodies".into(),
        ("rings", "one_body") => "rings as one body".into(),
        ("shift_speed", _) if number_value(v) == Some(0.0) => "shifting speed v0".into(),
        ("shift_speed", _) => format!("shifting speed {} m/s", num()),
        ("ipst_test", "two_sided") => "IPST's test two-sided".into(),
        ("ipst_test", "one_sided") => "IPST's test one-sided".into(),
        ("wall_viscosity", "wall") => "viscosity with the wall's velocity".into(),
        ("wall_viscosity", "no_slip") => "viscosity with the no-slip velocity".into(),
        ("surface_cone", "support") => "60-degree test over the support".into(),
        ("surface_cone", "fluid_2h") => "60-degree test over the fluid within 2h".into(),
        ("substeps", "auto") => "sub-steps as its own time step needs".into(),
        ("substeps", _) if number_value(v) == Some(1.0) => "no sub-steps".into(),
        ("substeps", _) => format!("{} sub-steps", num()),
        // A structure's switches (`solid_pst`, `solid_gradient`, ...) read as the solid's.
        (k, _) if k.starts_with("solid_") => {
            let inner = phrase(&k["solid_".len()..], v);
            if inner.is_empty() {
                inner
            } else {
                format!("structure: {inner}")
            }
        }
        _ => format!("{key} = {v}"),
    }
}

/// A parameter value as it reads in text: integers without a decimal point.
pub(crate) fn value(v: &Value) -> String {
    number(v)
}

/// A number as it reads in text: integers without a decimal point.
fn number(v: &Value) -> String {
    match v {
        // From 1e5 on in powers of ten, so that a row of 1e5, 1e6, 1e7 reads alike.
        Value::Float(x) if x.abs() >= 1e5 && x.is_finite() => format!("{x:e}"),
        Value::Int(i) if i.abs() >= 100_000 => format!("{:e}", *i as f64),
        Value::Float(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{}", *x as i64),
        other => other.to_string(),
    }
}

fn number_value(v: &Value) -> Option<f64> {
    match v {
        Value::Int(i) => Some(*i as f64),
        Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// The `keys` parameters of `case` in words, joined by commas (its name if none, or if every
/// phrase is empty). A key its solid scheme fixes ([`SolidSchemeName::fixed_keys`]; a
/// structure's `solid_` keys by its `solid_scheme`) goes unsaid.
pub(crate) fn label(case: &Case, keys: &[String]) -> String {
    let fixed = |k: &str| {
        let (scheme_key, bare) = match k.strip_prefix("solid_") {
            Some(bare) => ("solid_scheme", bare),
            None => ("scheme", k),
        };
        match case.params.0.get(scheme_key) {
            Some(Value::Str(s)) => {
                SolidSchemeName::from_name(s).is_some_and(|n| n.fixed_keys().contains(&bare))
            }
            _ => false,
        }
    };
    let words: Vec<String> = keys
        .iter()
        .filter(|k| !fixed(k))
        .filter_map(|k| case.params.0.get(k).map(|v| phrase(k, v)))
        .filter(|p| !p.is_empty())
        .collect();
    if words.is_empty() {
        case.name.clone()
    } else {
        words.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_read_as_words() {
        assert_eq!(phrase("surface_pressure", &Value::Str("zero".into())), "surface pressure held at zero");
        assert_eq!(phrase("nx", &Value::Int(50)), "50 x 50");
        assert_eq!(phrase("re", &Value::Float(1000.0)), "Re = 1000");
        assert_eq!(phrase("dx", &Value::Float(0.01)), "dx = 0.01 m");
        assert_eq!(phrase("perturb", &Value::Float(0.0)), "exact lattice");
        assert_eq!(phrase("corr_momentum", &Value::Str("auto".into())), "");
        assert_eq!(phrase("kernel", &Value::Str("wendland_c2".into())), "Wendland C2");
        assert_eq!(phrase("frobs", &Value::Int(3)), "frobs = 3");
        assert_eq!(value(&Value::Float(1e9)), "1e9");
        assert_eq!(value(&Value::Int(1_000_000)), "1e6");
        assert_eq!(value(&Value::Float(100_000.0)), "1e5");
        assert_eq!(phrase("solid_pst", &Value::Str("ipst".into())), "structure: IPST");
        assert_eq!(
            phrase("solid_substeps", &Value::Str("auto".into())),
            "structure: sub-steps as its own time step needs"
        );
        assert_eq!(phrase("solid_substeps", &Value::Int(1)), "structure: no sub-steps");
        assert_eq!(phrase("solid_scheme", &Value::Str("ctvf".into())), "structure: CTVF");
    }

    /// GTVF's legend names its own homogenisation, not "no shifting"; Gray's keeps it.
    #[test]
    fn gtvf_is_not_said_to_shift_nothing() {
        let case = |scheme: &str| Case {
            name: "c".into(),
            scene: "oscillating_plate".into(),
            params: crate::scenes::params::Params(
                [("scheme", scheme), ("pst", "none"), ("corrections", "none")]
                    .into_iter()
                    .map(|(k, v)| (k.to_string(), Value::Str(v.into())))
                    .collect(),
            ),
        };
        let keys: Vec<String> = ["scheme", "pst", "corrections"].map(String::from).to_vec();
        assert_eq!(label(&case("gtvf"), &keys), "GTVF (its background pressure)");
        assert_eq!(
            label(&case("gray"), &keys),
            "Gray et al. (artificial stress), no shifting, without corrections"
        );
    }
}
