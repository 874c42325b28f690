//! Every problem file in `problems/` validates (every preset, figures, tables, bounds and
//! the reference data they draw against), against the registered scenes.
//!
//! Scenes not yet registered but whose contract is fixed (issue 5: `cavity` and
//! `hydrostatic_tank`) are validated against stubs declaring that contract's parameters
//! and metrics; once a scene is registered the stub is no longer used, so the real
//! declaration is what the file is checked against. A problem naming any other unknown
//! scene fails.

use sphrepro::automation::registry;
use sphrepro::scenes::params::{Bound, Params, Spec};
use sphrepro::scenes::{self, common_params, SceneEntry, SceneRun};
use std::path::Path;

fn unbuildable(_: &Params) -> Result<Box<dyn SceneRun>, String> {
    Err("stub scene: the contract of a scene not registered yet".into())
}

const SWITCH: &[&str] = &["auto", "on", "off"];

fn fluid_params() -> Vec<Spec> {
    vec![
        Spec::choice("scheme", &["edac", "tvf", "ctvf"], "ctvf", "fluid scheme"),
        Spec::choice("pst", &["sun", "ipst", "none"], "sun", "particle shifting"),
        Spec::choice("corrections", &["all", "none"], "all", "the CTVF correction terms"),
    ]
}

fn cavity_params() -> Vec<Spec> {
    let mut v = vec![
        Spec::int("nx", 50, 1, "particles per side"),
        Spec::float("re", 100.0, Bound::Positive, "Reynolds number"),
    ];
    v.extend(fluid_params());
    v.extend([
        Spec::choice("corr_continuity", SWITCH, "auto", ""),
        Spec::choice("corr_pressure", SWITCH, "auto", ""),
        Spec::choice("corr_momentum", SWITCH, "auto", ""),
        Spec::choice(
            "kernel",
            &["cubic_spline", "quintic_spline", "wendland_c2", "gaussian"],
            "quintic_spline",
            "",
        ),
        Spec::float("hdx", 1.0, Bound::Positive, "h / dx"),
        Spec::float("ke_window", 1.0, Bound::Positive, "steady-state window (s)"),
    ]);
    v.extend(common_params(10.0));
    v
}

fn tank_params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float("dx", 0.02, Bound::Positive, "particle spacing (m)"),
        Spec::float("height", 1.0, Bound::Positive, "fluid column height (m)"),
        Spec::float("width", 1.0, Bound::Positive, "tank width (m)"),
    ];
    v.extend(fluid_params());
    v.extend(common_params(2.0));
    v
}

/// The contract of issue 5 ("Walls and free surfaces").
static STUBS: &[SceneEntry] = &[
    SceneEntry {
        name: "cavity",
        dim: 2,
        about: "stub: lid-driven cavity (issue 5 contract)",
        params: cavity_params,
        build: unbuildable,
        metrics: &["ghia_u_rms", "ghia_u_max", "ghia_v_rms", "ghia_v_max", "kinetic_energy_change"],
    },
    SceneEntry {
        name: "hydrostatic_tank",
        dim: 2,
        about: "stub: hydrostatic tank (issue 5 contract)",
        params: tank_params,
        build: unbuildable,
        metrics: &["pressure_rel_error", "max_speed"],
    },
];

fn find(name: &str) -> Result<&'static SceneEntry, String> {
    scenes::find(name).or_else(|e| STUBS.iter().find(|s| s.name == name).ok_or(e))
}

#[test]
fn every_problem_file_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 5, "{paths:?}");
    let mut errors = Vec::new();
    for p in &paths {
        let src = std::fs::read_to_string(p).unwrap();
        // `parse_with` expands and checks every preset whichever is asked for.
        match registry::parse_with(p, &src, "quick", find) {
            Ok(pr) => assert!(!pr.cases.is_empty()),
            Err(e) => errors.push(e),
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}

/// The cavity problem: the presets the brief asks for, and Ghia's points for both Re.
#[test]
fn cavity_presets_and_reference_points() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/cavity.toml");
    let src = std::fs::read_to_string(&path).unwrap();
    let quick = registry::parse_with(&path, &src, "quick", find).unwrap();
    let paper = registry::parse_with(&path, &src, "paper", find).unwrap();
    let res = |p: &registry::Problem, re: f64| {
        let mut v: Vec<i64> = p
            .cases
            .iter()
            .filter(|c| c.params.float("re") == re && c.params.str("corrections") == "all")
            .filter(|c| c.params.str("pst") == "sun")
            .map(|c| c.params.int("nx"))
            .collect();
        v.sort();
        v
    };
    assert_eq!(res(&quick, 100.0), [20, 30]);
    assert_eq!(res(&quick, 1000.0), [20, 30]);
    assert_eq!(res(&paper, 100.0), [50, 100, 150]);
    assert_eq!(res(&paper, 1000.0), [50, 100, 200]);
    assert!(paper
        .cases
        .iter()
        .filter(|c| c.params.float("re") == 100.0)
        .all(|c| c.params.float("tf") == 25.0));
    // The u profile is drawn with u horizontal and y vertical; Ghia's 17 points.
    let f = paper.figures.iter().find(|f| f.id == "fig14a_cavity_u_re100").unwrap();
    let registry::FigureKind::Profile { x, y, reference: Some(r), .. } = &f.kind else {
        panic!("{:?}", f.kind)
    };
    assert_eq!((x.as_str(), y.as_str()), ("u", "y"));
    assert_eq!(r.x.len(), 17);
    assert_eq!((r.x[16], r.y[16]), (1.0, 1.0)); // the lid
    let f = paper.figures.iter().find(|f| f.id == "fig15b_cavity_v_re1000").unwrap();
    let registry::FigureKind::Profile { reference: Some(r), .. } = &f.kind else { panic!() };
    assert_eq!(r.y_column, "Re1000");
    // Bounds measured on the quick preset guard the Re = 100 case in CI.
    assert_eq!(quick.bounds.len(), 3, "{:?}", quick.bounds);
}

/// Every figure and table of every problem is drawn with no results at all (as after a
/// fresh checkout with `--plot-only`): empty curves, the published points, "no result".
#[test]
fn every_problem_plots_without_results() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let tmp = tempfile::tempdir().unwrap();
    for name in ["cavity", "cavity_stability", "hydrostatic_tank"] {
        let path = dir.join(format!("{name}.toml"));
        let src = std::fs::read_to_string(&path).unwrap();
        let p = registry::parse_with(&path, &src, "quick", find).unwrap();
        let section =
            sphrepro::automation::study::regenerate(&p, &tmp.path().join("out"), tmp.path()).unwrap();
        let figures = section
            .items
            .iter()
            .filter(|i| matches!(i, sphrepro::automation::report::Item::Figure { .. }))
            .count();
        assert!(figures >= p.figures.len(), "{name}");
        for f in &p.figures {
            assert!(!f.paper.is_empty(), "{name}/{}: no `paper` line", f.id);
        }
    }
    assert!(tmp.path().join("figures/fig14a_cavity_u_re100.svg").exists());
    let svg = std::fs::read_to_string(tmp.path().join("figures/fig15b_cavity_v_re1000.svg")).unwrap();
    assert!(svg.contains("Ghia et al. 1982"));
}
