//! A problem file the registry's tests vary, and its parser.

use super::{parse, Problem};
use std::path::Path;

/// A valid problem of Taylor-Green: two presets, a named group with a preset grid, an
/// unnamed grid whose `ctvf` case repeats one of the first group's, a figure and a bound.
pub(super) const GOOD: &str = r#"
title = "t"
scene = "taylor_green"
paper = "ctvf"
[params]
tf = "$tf"
[presets.quick]
tf = 0.05
nx = [12, 16]
[presets.paper]
tf = 2.0
nx = [50, 100]
[[cases]]
name = "sun-nx{nx}"
params = { pst = "sun" }
grid = { nx = "$nx" }
[[cases]]
grid = { scheme = ["edac", "ctvf"], nx = 16 }
[[figures]]
id = "f1"
kind = "timeseries"
title = "x"
y = "u_max"
cases = ["sun-*"]
metric = "l1_velocity_final"
label = ["nx"]
[[bounds]]
metric = "l1_velocity_final"
where = { nx = 16, pst = "sun", scheme = "ctvf" }
max = 1.0
"#;

/// [`GOOD`] or a variant of it, parsed as `x.toml` for the `quick` preset.
pub(super) fn p(src: &str) -> Result<Problem, String> {
    parse(Path::new("x.toml"), src, "quick")
}
