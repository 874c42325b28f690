//! The regression guard: `check PROBLEM` checks the problems named only, `bless` writes the
//! baselines (and only it does), and `check --baseline` fails on a change to a term's
//! arithmetic for the problems that use the term and no others, naming the problem, the case
//! and the metric. The term is changed here as a test build would change it: the solid
//! momentum equation's pair term scaled by `SPHREPRO_PERTURB_SOLID_MOMENTUM`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_sphrepro");

/// A fluid problem and a solid problem of a few steps each.
const FLUID: &str = r#"title = "a vortex"
scene = "taylor_green"
paper = "ctvf"
[presets.quick]
[[cases]]
name = "edac"
params = { nx = 12, tf = 0.02, scheme = "edac" }
[[bounds]]
metric = "l1_velocity_final"
max = 1.0
"#;

const SOLID: &str = r#"title = "a plate"
scene = "oscillating_plate"
paper = "ctvf"
[presets.quick]
[[cases]]
name = "coarse"
params = { dx = 0.01, tf = 0.004 }
[[bounds]]
metric = "clusters_max"
max = 1.0
"#;

fn setup() -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().to_path_buf();
    std::fs::create_dir_all(root.join("problems")).unwrap();
    std::fs::write(root.join("problems/vortex.toml"), FLUID).unwrap();
    std::fs::write(root.join("problems/plate.toml"), SOLID).unwrap();
    (tmp, root)
}

fn run(root: &Path, args: &[&str], perturb: Option<&str>) -> Output {
    let mut c = Command::new(BIN);
    c.current_dir(root).args(args);
    if let Some(f) = perturb {
        c.env("SPHREPRO_PERTURB_SOLID_MOMENTUM", f);
    }
    c.output().unwrap()
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

#[test]
fn a_changed_term_fails_the_baselines_of_the_problems_that_use_it_and_no_others() {
    let (_tmp, root) = setup();
    // `check` of one problem: the other's missing case is not its business.
    let o = run(&root, &["run", "vortex"], None);
    assert!(o.status.success(), "{}", text(&o));
    let o = run(&root, &["check", "vortex"], None);
    assert!(o.status.success() && text(&o).contains("1 bound(s) hold, 0 breached"), "{}", text(&o));
    assert!(!run(&root, &["check"], None).status.success(), "every problem: the plate has no result");
    // No baseline yet: named.
    let o = run(&root, &["check", "--baseline", "vortex"], None);
    assert!(!o.status.success() && text(&o).contains("FAIL vortex: no baseline"), "{}", text(&o));
    // `bless` needs every case's result, writes nothing without.
    let o = run(&root, &["bless", "--all"], None);
    assert!(!o.status.success() && text(&o).contains("plate: no finished result"), "{}", text(&o));
    assert!(!root.join("baselines/plate.json").exists());
    let o = run(&root, &["run", "plate"], None);
    assert!(o.status.success(), "{}", text(&o));
    let o = run(&root, &["bless", "--all"], None);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("| plate/coarse | case | not in the baseline | new | - |"), "{}", text(&o));
    let blessed = std::fs::read(root.join("baselines/plate.json")).unwrap();
    let o = run(&root, &["check", "--baseline"], None);
    assert!(
        o.status.success() && text(&o).contains("2 case(s) compared with their baselines: no change"),
        "{}",
        text(&o)
    );

    // The solid's momentum term changed in its seventh digit: both problems run again.
    for p in ["vortex", "plate"] {
        let o = run(&root, &["run", p, "--force"], Some("1.000001"));
        assert!(o.status.success(), "{}", text(&o));
    }
    let o = run(&root, &["check", "--baseline"], None);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("FAIL plate/coarse: "), "the plate's metrics moved: {t}");
    assert!(!t.contains("FAIL vortex"), "the vortex has no solid: {t}");
    let named = t.lines().find(|l| l.starts_with("FAIL plate/coarse: ")).unwrap();
    assert!(named.contains(" -> ") && named.contains("e-"), "metric, old, new, relative change: {named}");
    assert!(run(&root, &["check", "--baseline", "vortex"], None).status.success());
    assert_eq!(std::fs::read(root.join("baselines/plate.json")).unwrap(), blessed, "check wrote a baseline");

    // A deliberate change is blessed, with its table; then it holds.
    let o = run(&root, &["bless", "plate"], None);
    assert!(o.status.success() && text(&o).contains("| plate/coarse |"), "{}", text(&o));
    assert!(run(&root, &["check", "--baseline"], None).status.success());
    // Bad input: a baseline of the paper preset, an unknown problem.
    let o = run(&root, &["check", "--baseline", "--preset", "paper"], None);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let o = run(&root, &["bless", "nothing"], None);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("no problem `nothing`"), "{}", text(&o));
}

/// A tolerance needs its reason, and names a metric the scene reports.
#[test]
fn a_baseline_tolerance_is_checked_by_key() {
    let (_tmp, root) = setup();
    for (table, key) in [
        ("[baseline]\ntolerance = 1e-9\n", "baseline.reason"),
        ("[baseline]\ntolerance = -1.0\nreason = \"r\"\n", "baseline.tolerance"),
        ("[baseline]\ntolerances = { no_such_metric = 1e-9 }\nreason = \"r\"\n", "baseline.tolerances"),
    ] {
        std::fs::write(root.join("problems/vortex.toml"), format!("{FLUID}{table}")).unwrap();
        let o = run(&root, &["check", "vortex"], None);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        assert!(text(&o).contains(&format!("`{key}`")), "{key}: {}", text(&o));
    }
}
