//! `run --dry-run`'s cost estimates against the runs they predict: quick cases of a fluid, a
//! fluid with IPST, two solids and a fluid-structure scene, each estimated from a short run
//! (one CPU second of steps, so that most of each run is predicted, not measured), then run
//! on one thread; the estimate must be within a factor of 1.5 of the run's CPU time.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_sphrepro");

/// (problem, case) of the quick preset, each running for seconds.
const CASES: &[(&str, &str)] = &[
    ("dam_break", "ctvf-sun-corr_all-dx0.05"),
    ("taylor_green", "ctvf-ipst-corr_all-re100-nx40-eq27"),
    ("colliding_rings", "ctvf-sun-corr_all-nu0.3975"),
    ("oscillating_plate", "ctvf-sun-corr_all-vf0.05"),
    ("elastic_gate", "ctvf-sun-gate_ipst-substeps_auto-dx0.0025"),
];

fn sphrepro(output: &Path, args: &[&str]) -> (String, String) {
    let problems = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let o = Command::new(BIN)
        .args(["--threads", "1"])
        .args(args)
        .arg("--problems")
        .arg(&problems)
        .arg("--output")
        .arg(output)
        .output()
        .expect("binary runs");
    let (out, err) =
        (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned());
    assert!(o.status.success(), "sphrepro {args:?} failed:\n{out}{err}");
    (out, err)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .unwrap()
}

/// The one case folder under `output/problem`.
fn case_dir(output: &Path, problem: &str) -> PathBuf {
    let dirs: Vec<PathBuf> = std::fs::read_dir(output.join(problem))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    assert_eq!(dirs.len(), 1, "{dirs:?}");
    dirs[0].clone()
}

#[test]
fn a_dry_runs_estimate_is_within_a_factor_of_one_and_a_half_of_the_run() {
    let tmp = tempfile::tempdir().unwrap();
    let mut report = Vec::new();
    for (problem, case) in CASES {
        let out = tmp.path().join(problem);
        let dry = ["run", problem, "--match", case, "--dry-run", "--estimate-budget", "1", "--jobs", "1"];
        let (listed, said) = sphrepro(&out, &dry);
        assert!(said.contains("estimating 1 case(s)"), "{said}");
        assert!(listed.lines().any(|l| l.starts_with("would run") && l.contains("CPU")), "{listed}");
        assert!(listed.contains("1 to run") && listed.contains("CPU-hours"), "{listed}");
        // Kept: a second dry run measures nothing.
        let (again, said) = sphrepro(&out, &dry);
        assert!(!said.contains("estimating"), "{said}");
        assert_eq!(again, listed);
        let store = json(&out.join(problem).join("estimates.json"));
        let store = store.as_object().unwrap();
        assert_eq!(store.len(), 1);
        let (folder, estimate) = store.iter().next().unwrap();
        assert_eq!(estimate["exact"], false, "{case}: the short run reached the end; nothing was predicted");
        sphrepro(&out, &["run", problem, "--match", case, "--jobs", "1"]);
        let dir = case_dir(&out, problem);
        assert!(dir.ends_with(folder), "{} is not {folder}", dir.display());
        let summary = json(&dir.join("summary.json"));
        assert_eq!(summary["status"], "completed", "{case}");
        let real = summary["cpu_seconds"].as_f64().expect("cpu_seconds recorded");
        let predicted = estimate["cpu_seconds"].as_f64().unwrap();
        let (steps_real, steps_predicted) =
            (summary["steps"].as_f64().unwrap(), estimate["steps"].as_f64().unwrap());
        report.push(format!(
            "{problem}/{case}: estimated {predicted:.1} s, ran {real:.1} s (ratio {:.2}); steps {steps_predicted} against {steps_real}",
            predicted / real
        ));
        // The number of steps follows from the time-step rule: within a few per cent.
        assert!((steps_predicted / steps_real - 1.0).abs() < 0.05, "{}", report.join("\n"));
    }
    let off: Vec<&String> = report
        .iter()
        .filter(|r| {
            let ratio: f64 = r.split("(ratio ").nth(1).unwrap().split(')').next().unwrap().parse().unwrap();
            !(1.0 / 1.5..=1.5).contains(&ratio)
        })
        .collect();
    assert!(off.is_empty(), "estimates off by more than 1.5x:\n{}", report.join("\n"));
    println!("{}", report.join("\n"));
}
