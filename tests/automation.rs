//! Reliability of the automation half: the runner, the cache, the registry's errors and
//! `check`, on tiny Taylor-Green problems written by each test into a temporary folder.

use std::path::PathBuf;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_sphrepro");

struct Env {
    _tmp: tempfile::TempDir,
    root: PathBuf,
}

impl Env {
    /// A folder with `problems/tiny.toml` holding `toml`.
    fn new(toml: &str) -> Self {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path().to_path_buf();
        std::fs::create_dir_all(root.join("problems")).unwrap();
        std::fs::write(root.join("problems/tiny.toml"), toml).unwrap();
        Env { _tmp: tmp, root }
    }
    fn cmd(&self, args: &[&str]) -> Command {
        let mut c = Command::new(BIN);
        c.current_dir(&self.root).args(args).args([
            "--problems",
            "problems",
            "--output",
            "output",
            "--manuscript",
            "manuscript",
        ]);
        c
    }
    fn run(&self, args: &[&str]) -> Output {
        self.cmd(args).output().unwrap()
    }
    /// The folder of case `name`; after an edit there are two (the stale one is kept), so
    /// the one written last.
    fn case_dir(&self, name: &str) -> PathBuf {
        let dir = self.root.join("output/tiny");
        std::fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.is_dir()
                    && p.file_name()
                        .unwrap()
                        .to_string_lossy()
                        .rsplit_once('-')
                        .is_some_and(|(n, _)| n == name)
            })
            .max_by_key(|p| std::fs::metadata(p.join("case.json")).and_then(|m| m.modified()).ok())
            .unwrap_or_else(|| panic!("no folder for case {name}"))
    }

    /// The `progress` file of the first case that writes one (its simulation is stepping).
    fn progress_file(&self) -> PathBuf {
        let t0 = std::time::Instant::now();
        loop {
            let p = std::fs::read_dir(self.root.join("output/tiny")).ok().and_then(|mut d| {
                d.find_map(|e| e.ok().map(|e| e.path().join("progress")).filter(|p| p.exists()))
            });
            if let Some(p) = p {
                return p;
            }
            assert!(t0.elapsed().as_secs() < 60, "no progress file");
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
    }

    fn summary(&self, name: &str) -> serde_json::Value {
        let s = std::fs::read_to_string(self.case_dir(name).join("summary.json")).unwrap();
        serde_json::from_str(&s).unwrap()
    }
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// One case that runs for seconds, to be interrupted.
const ONE_SLOW_CASE: &str = r#"title = "one slow case"
scene = "taylor_green"
paper = "ctvf"
[presets.quick]
[[cases]]
name = "a"
params = { nx = 16, tf = 20.0 }
"#;

/// Three named cases at nx = 12/14/16, tf as given.
fn three_cases(tf: f64) -> String {
    format!(
        r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
[params]
tf = {tf}
[presets.quick]
[[cases]]
name = "a"
params = {{ nx = 12 }}
[[cases]]
name = "b"
params = {{ nx = 14 }}
[[cases]]
name = "c"
params = {{ nx = 16 }}
[[bounds]]
metric = "l1_velocity_final"
cases = ["a", "b", "c"]
max = BOUND
"#
    )
}

#[test]
fn edit_reruns_exactly_the_edited_case_and_check_enforces_bounds() {
    let src = three_cases(0.03).replace("BOUND", "1.0");
    let env = Env::new(&src);
    let o = env.run(&["run", "tiny"]);
    assert!(o.status.success(), "{}", text(&o));
    let started = |n: &str| env.summary(n)["provenance"]["started"].clone();
    let before: Vec<_> = ["a", "b", "c"].iter().map(|n| started(n)).collect();
    // A second run does nothing.
    let o = env.run(&["run", "tiny"]);
    assert!(text(&o).contains("0 case(s) to run, 3 done"), "{}", text(&o));
    // Edit b's parameter: only b runs, and the dry run names the change.
    std::fs::write(env.root.join("problems/tiny.toml"), src.replace("nx = 14", "nx = 15")).unwrap();
    let o = env.run(&["run", "tiny", "--dry-run"]);
    let t = text(&o);
    assert!(t.contains("tiny/b (stale: nx 14 -> 15)") && t.contains("1 to run"), "{t}");
    let o = env.run(&["run", "tiny"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("run     tiny/b") && !t.contains("run     tiny/a") && !t.contains("run     tiny/c"),
        "{t}"
    );
    assert_eq!(started("a"), before[0]);
    assert_eq!(started("c"), before[2]);
    assert_eq!(env.summary("b")["params"]["nx"], 15);
    // The old folder of b is reported as stale, not deleted; `--stale` lists it with what
    // changed.
    let o = env.run(&["status"]);
    assert!(text(&o).contains("1 stale folder(s)"), "{}", text(&o));
    let o = env.run(&["status", "--stale"]);
    assert!(text(&o).contains("case b now has nx 14 -> 15; kept, not deleted"), "{}", text(&o));

    // check: within bounds passes; a breached bound names problem, case, metric, value, bound.
    let o = env.run(&["check"]);
    assert!(o.status.success(), "{}", text(&o));
    std::fs::write(
        env.root.join("problems/tiny.toml"),
        src.replace("nx = 14", "nx = 15").replace("max = 1.0", "max = 1e-9"),
    )
    .unwrap();
    let o = env.run(&["check"]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("tiny/a") && t.contains("l1_velocity_final") && t.contains("> max 1e-9"), "{t}");
}

/// A diverged case is done (a result, not rerun) but breaches every bound on it, even one
/// no value could breach, and the breach says where it blew up.
#[test]
fn a_diverged_case_is_done_but_breaches_its_bounds() {
    let env = Env::new(
        r#"title = "blows up"
scene = "taylor_green"
paper = "ctvf"
[presets.quick]
[[cases]]
name = "a"
params = { nx = 8, scheme = "edac", cfl = 5.0, tf = 1.0 }
[[bounds]]
metric = "l1_velocity_final"
max = 1e300
"#,
    );
    let o = env.run(&["run", "tiny"]);
    assert!(text(&o).contains("diverged"), "{}", text(&o));
    assert_eq!(env.summary("a")["status"], "diverged");
    let o = env.run(&["run", "tiny"]);
    assert!(text(&o).contains("0 case(s) to run, 1 done"), "{}", text(&o));
    let o = env.run(&["check"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("tiny/a") && t.contains("the run diverged at t = ") && t.contains("tiny.toml:"),
        "{t}"
    );
}

#[test]
fn a_killed_run_is_not_done_and_is_repeated() {
    use std::os::unix::process::CommandExt;
    let env = Env::new(ONE_SLOW_CASE);
    let mut child = env.cmd(&["run", "tiny", "--jobs", "1"]).process_group(0).spawn().unwrap();
    // Wait until the simulation reports progress, then kill runner and case at once.
    let progress = env.progress_file();
    let pgid = child.id();
    Command::new("kill").args(["-KILL", "--", &format!("-{pgid}")]).status().unwrap();
    let _ = child.wait();
    let dir = progress.parent().unwrap();
    assert!(!dir.join("summary.json").exists(), "killed run left a summary");
    // `wait` reaps the runner only: the case, killed with it, holds the runner's lock until
    // the kernel has torn it down, and until then `status` rightly calls it running (seen
    // on a loaded machine). Give it a few seconds to go.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    let (o, t) = loop {
        let o = env.run(&["status"]);
        let t = text(&o);
        if !t.contains("running") || std::time::Instant::now() > deadline {
            break (o, t);
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("failed") && t.contains("a  (no summary"), "{t}");
    // The next run repeats it, taking over the dead runner's lock.
    let o = env.run(&["run", "tiny"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("run     tiny/a"), "{t}");
    assert_eq!(env.summary("a")["status"], "completed");
}

/// A runner killed outright (SIGKILL, its simulation spared) does not leave the
/// simulation running on its own: it stops with a checkpoint (Linux: it gets SIGUSR1), and
/// the next run resumes it.
#[cfg(target_os = "linux")]
#[test]
fn a_killed_runner_takes_its_simulation_with_it() {
    let env = Env::new(ONE_SLOW_CASE);
    let mut runner = env.cmd(&["run", "tiny", "--jobs", "1"]).spawn().unwrap();
    let progress = env.progress_file();
    runner.kill().unwrap();
    let _ = runner.wait();
    let dir = progress.parent().unwrap();
    let t0 = std::time::Instant::now();
    while !dir.join("summary.json").exists() {
        assert!(
            t0.elapsed().as_secs() < 30,
            "the orphaned simulation did not stop; its log:\n{}",
            std::fs::read_to_string(dir.join("run.log")).unwrap_or_default()
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    // Let it finish writing, then check it stopped short of tf, checkpointed.
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert_eq!(env.summary("a")["status"], "failed");
    assert!(dir.join("checkpoint.json").exists());
    let o = env.run(&["run", "tiny"]);
    let t = text(&o);
    assert!(o.status.success() && t.contains("resuming"), "{t}");
    assert_eq!(env.summary("a")["status"], "completed");
}

/// A case whose time step would need more steps than any machine takes is refused when the
/// problem file is loaded, before anything runs, naming file, case and the binding limit.
#[test]
fn a_case_that_would_step_forever_is_refused_before_anything_runs() {
    let env =
        Env::new(&three_cases(0.02).replace("BOUND", "1.0").replace("nx = 14 }", "nx = 14, re = 1e-30 }"));
    let o = env.run(&["run", "tiny"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("tiny.toml") && t.contains("viscous limit") && t.contains("check the viscosity (re)"),
        "{t}"
    );
    assert!(!env.root.join("output").exists(), "{t}");
}

/// Another preset's current result of a case of the same name is not an earlier input of
/// it: the paper preset's first run calls the case missing, not stale.
#[test]
fn another_presets_result_does_not_make_a_case_stale() {
    let env = Env::new(
        r#"title = "two presets"
scene = "taylor_green"
paper = "ctvf"
[params]
nx = 12
tf = "$tf"
[presets.quick]
tf = 0.02
[presets.paper]
tf = 0.03
[[cases]]
name = "a"
"#,
    );
    assert!(env.run(&["run", "tiny"]).status.success());
    let o = env.run(&["run", "tiny", "--preset", "paper", "--dry-run"]);
    let t = text(&o);
    assert!(t.contains("would run tiny/a (missing)"), "{t}");
    let t = text(&env.run(&["status", "--preset", "paper"]));
    assert!(
        t.contains("missing    a\n") && !t.contains("inputs changed") && t.contains("other preset"),
        "{t}"
    );
    // An edit of the quick preset's own input still makes its case stale.
    let src = std::fs::read_to_string(env.root.join("problems/tiny.toml")).unwrap();
    std::fs::write(env.root.join("problems/tiny.toml"), src.replace("tf = 0.02", "tf = 0.025")).unwrap();
    let t = text(&env.run(&["run", "tiny", "--dry-run"]));
    assert!(t.contains("would run tiny/a (stale: tf 0.02 -> 0.025)"), "{t}");
}

/// `--plot-only` never draws over the figures of a problem with nothing (a mistyped
/// --output, a fresh checkout): it names the problem, writes nothing and exits 1.
#[test]
fn plot_only_without_results_overwrites_nothing() {
    let env = Env::new(&three_cases(0.02).replace("BOUND", "1.0"));
    let o = env.run(&["reproduce", "--plot-only"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("tiny: no case has a result under output"), "{t}");
    assert!(!env.root.join("manuscript/manuscript.md").exists());
    assert!(env.run(&["run", "tiny"]).status.success());
    let o = env.run(&["reproduce", "--plot-only"]);
    assert!(o.status.success(), "{}", text(&o));
    let md = env.root.join("manuscript/manuscript.md");
    let before = std::fs::read_to_string(&md).unwrap();
    std::fs::rename(env.root.join("output"), env.root.join("elsewhere")).unwrap();
    let o = env.run(&["reproduce", "--plot-only"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&md).unwrap(), before);
}

#[test]
fn two_runs_at_once_simulate_each_case_once() {
    let env = Env::new(&three_cases(0.3).replace("BOUND", "1.0"));
    let spawn = || {
        env.cmd(&["run", "tiny"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn(), spawn());
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    assert!(a.status.success() && b.status.success(), "{}\n{}", text(&a), text(&b));
    let all = text(&a) + &text(&b);
    for n in ["a", "b", "c"] {
        let done = all.matches(&format!("done    tiny/{n} ")).count();
        assert_eq!(done, 1, "case {n} simulated {done} times:\n{all}");
        assert_eq!(env.summary(n)["status"], "completed");
    }
    assert!(env.run(&["status"]).status.success());
}

const VALID: &str = r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
[params]
tf = 0.02
[presets.quick]
nx = [12]
[[cases]]
name = "a-nx{nx}"
grid = { nx = "$nx" }
[[cases]]
name = "b"
params = { nx = 14 }
[[figures]]
id = "f"
kind = "timeseries"
title = "t"
y = "u_max"
cases = ["a-*"]
metric = "l1_velocity_final"
"#;

#[test]
fn invalid_problem_files_are_refused_with_file_and_line() {
    let bad: &[(&str, &str, &str, &str)] = &[
        // (what, from, to, expected word; the expected line is where `to` lands)
        ("malformed", "tf = 0.02", "tf = = 0.02", "tiny.toml:5"),
        ("unknown key", "kind = \"timeseries\"", "kind = \"timeseries\"\ncolour = 1", "colour"),
        ("unknown scene", "\"taylor_green\"", "\"no_such_scene\"", "no_such_scene"),
        ("unknown parameter", "params = { nx = 14 }", "params = { nx = 14, frob = 2 }", "frob"),
        ("wrong type", "params = { nx = 14 }", "params = { nx = \"fourteen\" }", "nx"),
        ("duplicate case", "name = \"b\"", "name = \"a-nx12\"", "two cases"),
        ("missing case", "cases = [\"a-*\"]", "cases = [\"zz\"]", "zz"),
        ("missing metric", "metric = \"l1_velocity_final\"", "metric = \"l7\"", "l7"),
        ("missing column", "y = \"u_max\"", "y = \"u_maxx\"", "no time-series column `u_maxx`"),
        (
            "bound that no value can hold",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[bounds]]\nmetric = \"l1_velocity_final\"\ncases = [\"b\"]\nmin = 0.5\nmax = 0.1\n",
            "min = 0.5 is above max = 0.1",
        ),
        // Claims: on a figure that does not exist, of a metric the scene does not write,
        // selecting nothing, with a key a test does not take, with no trend to judge.
        (
            "claim on no figure",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[claims]]\nfigure = \"g\"\nclaim = \"c\"\npreset = \"quick\"\ntest = { metric = \"l1_velocity_final\", max = 1 }\nsource = \"s\"\n",
            "no figure or table `g`",
        ),
        (
            "claim of a missing metric",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[claims]]\nfigure = \"f\"\nclaim = \"c\"\npreset = \"quick\"\ntest = { metric = \"l9\", max = 1 }\nsource = \"s\"\n",
            "no metric `l9`",
        ),
        (
            "claim selecting nothing",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[claims]]\nfigure = \"f\"\nclaim = \"c\"\npreset = \"quick\"\nwhere = { nx = 99 }\ntest = { metric = \"l1_velocity_final\", max = 1 }\nsource = \"s\"\n",
            "selects no case in preset `quick`",
        ),
        (
            "claim test with an unknown key",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[claims]]\nfigure = \"f\"\nclaim = \"c\"\npreset = \"quick\"\ntest = { metric = \"l1_velocity_final\", maximum = 1 }\nsource = \"s\"\n",
            "maximum",
        ),
        (
            "claim with no trend to judge",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[claims]]\nfigure = \"f\"\nclaim = \"c\"\npreset = \"quick\"\ncases = [\"a-*\"]\ntest = { metric = \"l1_velocity_final\", decreasing = \"nx\" }\nsource = \"s\"\n",
            "no trend to judge",
        ),
        (
            "claim at a preset the problem has not",
            "metric = \"l1_velocity_final\"\n",
            "metric = \"l1_velocity_final\"\n[[claims]]\nfigure = \"f\"\nclaim = \"c\"\ntest = { metric = \"l1_velocity_final\", max = 1 }\nsource = \"s\"\n",
            "no preset `paper`",
        ),
        // Valid alone, refused by the scene before anything runs (named by case, not line).
        (
            "support reaching no neighbour",
            "params = { nx = 14 }",
            "params = { nx = 14, hdx = 0.3 }",
            "`hdx` = 0.3",
        ),
    ];
    let ok = Env::new(VALID);
    assert!(ok.run(&["run", "tiny", "--dry-run"]).status.success());
    for (what, from, to, word) in bad {
        assert!(VALID.contains(from), "{what}");
        let src = VALID.replacen(from, to, 1);
        let end = src.find(to).unwrap() + to.len();
        let line = src[..end].matches('\n').count() + 1;
        let env = Env::new(&src);
        let o = env.run(&["run", "tiny"]);
        let t = text(&o);
        assert!(!o.status.success(), "{what}: accepted\n{t}");
        assert!(t.contains(word), "{what}: no `{word}` in: {t}");
        assert!(
            t.contains(&format!("tiny.toml:{line}"))
                || *what == "missing case"
                || *what == "missing metric"
                || *what == "missing column"
                || *what == "duplicate case"
                || *what == "bound that no value can hold"
                || what.starts_with("claim")
                || *what == "support reaching no neighbour",
            "{what}: no line {line} in: {t}"
        );
        assert!(t.contains("tiny.toml:"), "{what}: no file in {t}");
        assert!(!env.root.join("output").exists(), "{what}: wrote output");
        assert!(!t.contains("panicked"), "{what}: {t}");
    }
}

/// Options that select nothing or make no sense are refused before anything runs.
#[test]
fn a_match_that_selects_nothing_and_zero_counts_are_refused() {
    let env = Env::new(VALID);
    for (args, word) in [
        (&["run", "tiny", "--match", "zzz*"][..], "zzz*"),
        (&["run", "tiny", "--jobs", "0"][..], "--jobs"),
        (&["--threads", "0", "run", "tiny"][..], "--threads"),
    ] {
        let o = env.run(args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
        assert!(t.contains(word), "{args:?}: no `{word}` in {t}");
        assert!(!env.root.join("output").exists(), "{args:?}: wrote output");
    }
}

/// A problems folder named on the command line that does not exist is a typo: `list`
/// refuses it (without --problems, outside a checkout, it still lists the scenes).
#[test]
fn list_refuses_a_problems_folder_that_does_not_exist() {
    let env = Env::new(VALID);
    let o = Command::new(BIN).current_dir(&env.root).args(["list", "--problems", "nope"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("nope"), "{}", text(&o));
    let bare = env.root.join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    let o = Command::new(BIN).current_dir(&bare).arg("list").output().unwrap();
    assert!(o.status.success() && text(&o).contains("taylor_green"), "{}", text(&o));
}

#[test]
fn an_unwritable_output_folder_is_reported_with_its_path() {
    let env = Env::new(VALID);
    std::fs::write(env.root.join("afile"), "x").unwrap();
    let o = Command::new(BIN)
        .current_dir(&env.root)
        .args(["run", "tiny", "--problems", "problems", "--output", "afile/out"])
        .output()
        .unwrap();
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("afile/out") && !t.contains("panicked"), "{t}");
}

/// `status` for one preset does not call the other preset's current results stale; a
/// preset edited afterwards leaves a stale folder, counted and, with `--stale`, listed.
#[test]
fn status_keeps_other_presets_apart_from_stale_folders() {
    let toml = |quick_tf: f64| {
        format!(
            r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
[params]
tf = "$tf"
[presets.quick]
tf = {quick_tf}
[presets.paper]
tf = 0.03
[[cases]]
name = "a"
params = {{ nx = 12 }}
"#
        )
    };
    let env = Env::new(&toml(0.02));
    assert!(env.run(&["run", "tiny"]).status.success());
    let o = env.run(&["status", "--preset", "paper"]);
    let t = text(&o);
    assert!(!o.status.success(), "paper is not done: {t}");
    assert!(t.contains("1 folder(s) with the results of the problem's other preset(s)"), "{t}");
    assert!(t.contains("0 done, 0 failed, 1 missing, 0 stale folder(s)"), "{t}");
    std::fs::write(env.root.join("problems/tiny.toml"), toml(0.025)).unwrap();
    // Described against the case of the preset asked about.
    for (preset, now) in [("paper", "0.03"), ("quick", "0.025")] {
        let o = env.run(&["status", "--preset", preset, "--stale"]);
        let t = text(&o);
        assert!(
            t.contains("1 stale folder(s)") && t.contains(&format!("case a now has tf 0.02 -> {now}")),
            "{t}"
        );
    }
}

/// A done case whose `timeseries.csv` was damaged by hand: the figure's error names the
/// file and the command that computes the case again, and that command does.
#[test]
fn a_damaged_time_series_names_the_command_that_repairs_it() {
    let src = three_cases(0.01).replace("BOUND", "1.0")
        + "[[figures]]\nid = \"l1\"\nkind = \"timeseries\"\ntitle = \"L1\"\ny = \"l1_velocity\"\n";
    let env = Env::new(&src);
    let o = env.run(&["run", "tiny"]);
    assert!(o.status.success(), "{}", text(&o));
    let series = env.case_dir("b").join("timeseries.csv");
    let mut damaged = std::fs::read_to_string(&series).unwrap();
    damaged.push_str("1,2\n");
    std::fs::write(&series, damaged).unwrap();
    let o = env.run(&["run", "tiny"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("b-") && t.contains("`sphrepro run tiny --match b --force`"), "{t}");
    let o = env.run(&["run", "tiny", "--match", "b", "--force"]);
    let t = text(&o);
    assert!(o.status.success() && t.contains("1 case(s) to run"), "{t}");
}

/// A command of the binary in `root` with only the problems folder named (the output and
/// manuscript folders at their defaults), as a user types it.
fn bare(root: &std::path::Path, args: &[&str]) -> Output {
    Command::new(BIN).current_dir(root).args(args).output().unwrap()
}

/// A fresh clone of the folders `dirs` of `root`: a new folder holding their files.
fn clone_of(root: &std::path::Path, dirs: &[&str]) -> tempfile::TempDir {
    let clone = tempfile::tempdir().unwrap();
    for d in dirs {
        for (rel, bytes) in files(&root.join(d)) {
            let p = clone.path().join(d).join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, bytes).unwrap();
        }
    }
    clone
}

/// Every file under `dir` with its bytes, by path relative to it.
fn files(dir: &std::path::Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    fn walk(
        base: &std::path::Path,
        d: &std::path::Path,
        out: &mut std::collections::BTreeMap<String, Vec<u8>>,
    ) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.insert(p.strip_prefix(base).unwrap().display().to_string(), std::fs::read(&p).unwrap());
            }
        }
    }
    let mut out = std::collections::BTreeMap::new();
    if dir.exists() {
        walk(dir, dir, &mut out);
    }
    out
}

/// Two tiny presets of Taylor-Green with a figure of each kind the export serves (a time
/// series, a particle plot at a time), a table and claims.
const TWO_PRESETS: &str = r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
section = "4.1 Taylor-Green vortex"
description = "A tiny vortex."
[params]
tf = "$tf"
[presets.quick]
tf = 0.02
nx = [12]
[presets.paper]
tf = 0.03
nx = [12, 14]
[[cases]]
name = "nx{nx}"
grid = { nx = "$nx" }
[[figures]]
id = "fig06a_decay"
number = "Fig. 6a"
paper_caption = "The decay of max |u|."
kind = "timeseries"
title = "decay"
y = "u_max"
exact = "u_max_exact"
label = ["nx"]
metric = "l1_velocity_final"
caption = "Our decay."
[[figures]]
id = "fig12_pressure"
number = "Fig. 12"
paper_caption = "The pressure."
kind = "particles"
title = "pressure"
field = "pressure"
time = 0.02
cases = ["nx12"]
caption = "Our pressure."
[[figures]]
id = "stability_nx"
kind = "stability"
title = "stability"
x = "nx"
metric = "l1_velocity_final"
max = 1.0
[[tables]]
id = "table_errors"
title = "errors"
columns = ["nx"]
metrics = ["l1_velocity_final"]
[[claims]]
figure = "fig06a_decay"
claim = "Close to the exact decay."
test = { metric = "l1_velocity_final", max = 1.0 }
source = "A generous tolerance."
[[claims]]
figure = "fig06a_decay"
claim = "Exactly the exact decay."
test = { metric = "l1_velocity_final", max = 1e-12 }
source = "An impossible tolerance."
"#;

/// The paper preset's results are exported into `results/` (summaries, time series, only the
/// snapshots figures draw, gzip-compressed; the other preset's summaries that a stability
/// table reads, marked as such); on a fresh clone (no output folder) the cache takes the
/// paper preset's as done, and `reproduce --plot-only --preset paper` simulates nothing and
/// writes the committed manuscript, figures and tables byte for byte. The quick preset's
/// manuscript goes under the output folder, titled as a smoke check, and never touches
/// `manuscript/`.
#[test]
fn the_paper_presets_results_are_committed_and_redrawn_byte_for_byte() {
    let env = Env::new(TWO_PRESETS);
    let root = &env.root;
    // The quick preset: its manuscript under output/, a smoke check; manuscript/ untouched.
    let o = bare(root, &["reproduce"]);
    assert!(o.status.success(), "{}", text(&o));
    let quick = std::fs::read_to_string(root.join("output/manuscript/manuscript.md")).unwrap();
    assert!(quick.starts_with("# Smoke check (quick preset): not the paper's resolutions"), "{quick}");
    assert!(!root.join("manuscript").exists() && !root.join("results").exists());
    // The paper preset.
    let o = bare(root, &["reproduce", "--preset", "paper"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("exported 2 case(s), 1 summary(ies) of other presets"), "{t}");
    let results = root.join("results/tiny");
    let dirs: Vec<_> = std::fs::read_dir(&results).unwrap().flatten().map(|e| e.path()).collect();
    assert_eq!(dirs.len(), 3, "{dirs:?}");
    let key = |d: &std::path::PathBuf| {
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("case.json")).unwrap()).unwrap();
        (r["params"]["nx"].as_i64().unwrap(), r["params"]["tf"].as_f64().unwrap())
    };
    let nx12 = dirs.iter().find(|d| key(d) == (12, 0.03)).unwrap();
    // The quick preset's case, for the stability table: its summary only, marked.
    let quick12 = dirs.iter().find(|d| key(d) == (12, 0.02)).unwrap();
    assert!(quick12.join("SUMMARY_ONLY").exists() && !quick12.join("timeseries.csv").exists());
    for f in ["case.json", "summary.json", "timeseries.csv", "fluid.pvd"] {
        assert!(nx12.join(f).exists(), "{f}");
    }
    // One snapshot, the one fig. 12 draws, compressed; the series lists it by its plain name.
    let snaps: Vec<_> =
        std::fs::read_dir(nx12.join("vtu")).unwrap().flatten().map(|e| e.file_name()).collect();
    assert_eq!(snaps.len(), 1, "{snaps:?}");
    assert!(snaps[0].to_string_lossy().ends_with(".vtu.gz"));
    let pvd = std::fs::read_to_string(nx12.join("fluid.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 1);
    assert!(pvd.contains(".vtu\"") && !pvd.contains(".gz"), "{pvd}");
    let nx14 = dirs.iter().find(|d| key(d).0 == 14).unwrap();
    assert!(!nx14.join("vtu").exists(), "no figure draws nx14's snapshots");
    assert!(!nx12.join("SUMMARY_ONLY").exists());
    // The manuscript: the paper's, with computed verdicts and nothing that changes by run.
    let md = std::fs::read_to_string(root.join("manuscript/manuscript.md")).unwrap();
    assert!(md.contains("#### Fig. 6a") && md.contains("#### Fig. 12"), "{md}");
    assert!(md.contains("**Verdict: reproduced** at the paper's resolutions"), "{md}");
    assert!(
        md.contains("**Verdict: not reproduced** at the paper's resolutions") && md.contains("> 1e-12"),
        "{md}"
    );
    let date = md.as_bytes().windows(10).any(|w| {
        w.iter().enumerate().all(|(i, c)| if i == 4 || i == 7 { *c == b'-' } else { c.is_ascii_digit() })
    });
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(nx12.join("summary.json")).unwrap()).unwrap();
    let commit = summary["provenance"]["git_commit"].as_str().unwrap_or_default().to_string();
    let host = summary["provenance"]["host"].as_str().unwrap_or_default().to_string();
    assert!(!date && !md.contains("git_"), "{md}");
    assert!(commit.len() < 7 || !md.contains(&commit[..7]), "{md}");
    assert!(host.is_empty() || !md.contains(&format!("{host} ")), "{md}");
    // The stability table has a row at each preset.
    let first =
        std::fs::read_to_string(root.join("manuscript/tables/stability_nx_first_failure.md")).unwrap();
    assert!(first.contains("| paper | nx12 |") || first.contains("| paper |"), "{first}");
    assert!(first.contains("| quick |"), "{first}");
    let committed = files(&root.join("manuscript"));
    let committed_results = files(&root.join("results"));

    // A fresh clone: the problems, the committed results and manuscript, no output folder.
    let clone = clone_of(root, &["problems", "results", "manuscript"]);
    let t = text(&bare(clone.path(), &["status", "--preset", "paper"]));
    assert!(t.contains("2 done, 0 failed, 0 missing"), "{t}");
    // A case of which only the summary is committed is not done: the quick preset runs it.
    let t = text(&bare(clone.path(), &["status"]));
    assert!(t.contains("0 done, 0 failed, 1 missing"), "{t}");
    let t = text(&bare(clone.path(), &["run", "tiny", "--preset", "paper", "--dry-run"]));
    assert!(t.contains("0 to run, 2 done"), "{t}");
    let o = bare(clone.path(), &["reproduce", "--plot-only", "--preset", "paper"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(!t.contains("run ") && !clone.path().join("output").exists(), "simulated or wrote output: {t}");
    assert_eq!(files(&clone.path().join("manuscript")), committed, "the manuscript differs");
    assert_eq!(files(&clone.path().join("results")), committed_results, "the results changed");
    // And so does a full `reproduce --preset paper`: nothing to run.
    let t = text(&bare(clone.path(), &["reproduce", "--preset", "paper"]));
    assert!(t.contains("0 case(s) to run, 2 done"), "{t}");
    assert_eq!(files(&clone.path().join("manuscript")), committed);

    // The quick preset again: manuscript/ untouched, and the paper's claims judged from the
    // committed results.
    let o = bare(root, &["reproduce", "--plot-only"]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(files(&root.join("manuscript")), committed, "the quick preset wrote over manuscript/");
    let quick = std::fs::read_to_string(root.join("output/manuscript/manuscript.md")).unwrap();
    assert!(quick.contains("**Verdict: reproduced** at the paper's resolutions"), "{quick}");
    // And on the clone, the quick preset runs its one case and draws its figures.
    let o = bare(clone.path(), &["reproduce"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("1 case(s) to run"), "{}", text(&o));
}

/// A case both presets run, which a particle figure of the quick preset draws and none of
/// the paper preset's: the export keeps its snapshot for the quick figure, so a fresh
/// clone's `reproduce` runs nothing committed; a committed case without what a figure reads
/// (an export from before this rule) is not done, and the cache says what it lacks.
const SHARED_CASE: &str = r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
section = "4.1 Taylor-Green vortex"
description = "A tiny vortex."
[params]
tf = 0.02
[presets.quick]
nx = [12]
drawn = 12
[presets.paper]
nx = [12, 14]
drawn = 14
[[cases]]
name = "nx{nx}"
grid = { nx = "$nx" }
[[figures]]
id = "fig12_pressure"
number = "Fig. 12"
paper_caption = "The pressure."
kind = "particles"
title = "pressure"
field = "pressure"
time = 0.02
where = { nx = "$drawn" }
caption = "Our pressure."
"#;

#[test]
fn a_committed_case_holds_what_the_other_presets_figures_read() {
    let env = Env::new(SHARED_CASE);
    let root = &env.root;
    let o = bare(root, &["reproduce", "--preset", "paper"]);
    assert!(o.status.success(), "{}", text(&o));
    let dir = |nx: i64| {
        std::fs::read_dir(root.join("results/tiny"))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .find(|d| d.file_name().unwrap().to_string_lossy().starts_with(&format!("nx{nx}-")))
            .unwrap()
    };
    // Each case keeps the one snapshot a figure draws: nx14 the paper's, nx12 the quick one's.
    for nx in [12, 14] {
        let snaps = std::fs::read_dir(dir(nx).join("vtu")).unwrap().count();
        assert_eq!(snaps, 1, "nx{nx}");
    }
    // A fresh clone: the quick preset runs nothing, and draws its figure.
    let clone = clone_of(root, &["problems", "results"]);
    let o = bare(clone.path(), &["reproduce"]);
    let t = text(&o);
    assert!(o.status.success() && t.contains("0 case(s) to run, 1 done"), "{t}");
    assert!(clone.path().join("output/manuscript/figures/fig12_pressure.png").exists(), "{t}");
    // Without the snapshot (an older export), the committed case is not done: it runs.
    let nx12 = clone.path().join("results/tiny").join(dir(12).file_name().unwrap());
    std::fs::remove_file(nx12.join("fluid.pvd")).unwrap();
    std::fs::remove_dir_all(clone.path().join("output")).unwrap();
    let t = text(&bare(clone.path(), &["status"]));
    assert!(t.contains("incomplete") && t.contains("0 done, 0 failed, 1 missing"), "{t}");
    let t = text(&bare(clone.path(), &["run", "tiny", "--dry-run"]));
    assert!(
        t.contains("the committed result lacks its snapshot series (*.pvd), which fig12_pressure of the `quick` preset draws"),
        "{t}"
    );
    let o = bare(clone.path(), &["reproduce"]);
    assert!(o.status.success() && text(&o).contains("1 case(s) to run"), "{}", text(&o));
}

/// A manuscript from a small synthetic results folder (no simulation): a claim met is
/// `reproduced`, a claim missed `not reproduced` with the number, and a claim whose
/// resolution has no result `not run`, naming the missing case with an estimate of its cost.
#[test]
fn verdicts_from_a_synthetic_results_folder() {
    use sphrepro::automation::{cache::CaseRecord, registry};
    use sphrepro::solver::output::summary::{Provenance, Status, Summary};
    let src = r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
section = "4.1 Taylor-Green vortex"
[params]
tf = 2.0
[presets.quick]
nx = [12]
[presets.paper]
nx = [20, 30, 40]
[[cases]]
name = "nx{nx}"
grid = { nx = "$nx" }
[[tables]]
id = "table_l1"
number = "Table 1"
paper_caption = "The errors."
title = "errors"
columns = ["nx"]
metrics = ["l1_velocity_mean"]
[[claims]]
figure = "table_l1"
claim = "Small at 20 x 20."
where = { nx = 20 }
test = { metric = "l1_velocity_mean", max = 0.1 }
source = "The paper's words."
[[claims]]
figure = "table_l1"
claim = "Smaller still at 30 x 30."
where = { nx = 30 }
test = { metric = "l1_velocity_mean", max = 0.01 }
source = "The paper's words."
[[claims]]
figure = "table_l1"
claim = "Falls with the resolution."
test = { metric = "l1_velocity_mean", decreasing = "nx" }
source = "The paper's words."
"#;
    let env = Env::new(src);
    let path = env.root.join("problems/tiny.toml");
    let p = registry::parse(&path, src, "paper").unwrap();
    for (case, l1) in p.cases.iter().zip([0.05, 0.03]) {
        let record = CaseRecord::new("tiny", case);
        let dir = env.root.join("results/tiny").join(record.folder());
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("case.json"), serde_json::to_string_pretty(&record).unwrap()).unwrap();
        Summary {
            scene: "taylor_green".into(),
            params: record.params.clone(),
            particles: 400,
            bodies: [("fluid".to_string(), 400)].into(),
            steps: 1000,
            final_time: 2.0,
            wall_seconds: 10.0,
            cpu_seconds: None,
            particle_steps_per_second: 4e4,
            threads: 1,
            wavefront_steps: 0,
            status: Status::Completed,
            reason: None,
            step: None,
            metrics: [("l1_velocity_mean".to_string(), l1)].into(),
            undefined_metrics: Vec::new(),
            provenance: Provenance::now(chrono::Utc::now()),
        }
        .write(&dir)
        .unwrap();
    }
    let o = env.run(&["reproduce", "--plot-only", "--preset", "paper"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(!env.root.join("output").exists(), "{t}");
    let md = std::fs::read_to_string(env.root.join("manuscript/manuscript.md")).unwrap();
    let verdict = |claim: &str| {
        let at = md.find(&format!("**Claim:** {claim}")).unwrap_or_else(|| panic!("{claim}: {md}"));
        let v = md[at..].find("**Verdict: ").unwrap() + at;
        md[v..].lines().next().unwrap().to_string()
    };
    assert!(verdict("Small at 20 x 20.").starts_with("**Verdict: reproduced**"), "{md}");
    let missed = verdict("Smaller still at 30 x 30.");
    assert!(
        missed.starts_with("**Verdict: not reproduced**") && missed.contains("0.0300 > 0.01"),
        "{missed}"
    );
    let not_run = verdict("Falls with the resolution.");
    assert!(not_run.starts_with("**Verdict: not run**") && not_run.contains("`nx40`"), "{not_run}");
    // 40 x 40 from 30 x 30's 10 s: (4/3)^3 as many particle-steps.
    assert!(not_run.contains("estimated 24 s on 1 thread, scaled from `nx30`"), "{not_run}");
    // The summary table lists each claim with its verdict, under the paper's number.
    assert!(md.contains("| CTVF Table 1 | Small at 20 x 20. | reproduced |"), "{md}");
    assert!(md.contains("| CTVF Table 1 | Smaller still at 30 x 30. | **not reproduced** |"), "{md}");
}
