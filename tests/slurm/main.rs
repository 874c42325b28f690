//! `run --executor slurm` against a real Slurm: each test starts a private slurmctld,
//! slurmd and munged on localhost (`cluster.rs`) and runs tiny Taylor-Green problems written
//! into a temporary folder. Where Slurm cannot be started the test says it was skipped and
//! why, except under CI (`CI=true`), where it fails.

mod cluster;

use cluster::Slurm;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_sphrepro");

/// The summary fields that are results: equal bit for bit whoever computes them (not the
/// wall time, the threads or the provenance).
const RESULTS: [&str; 7] = ["status", "metrics", "steps", "final_time", "particles", "params", "bodies"];

/// A folder with `problems/tiny.toml` and `problems/slurm.toml`, and the Slurm its commands
/// talk to (none for a local run).
struct Env<'a> {
    _tmp: tempfile::TempDir,
    root: PathBuf,
    slurm: Option<&'a Slurm>,
}

impl<'a> Env<'a> {
    fn new(problem: &str, settings: &str, slurm: Option<&'a Slurm>) -> Self {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path().to_path_buf();
        std::fs::create_dir_all(root.join("problems")).unwrap();
        std::fs::write(root.join("problems/tiny.toml"), problem).unwrap();
        std::fs::write(root.join("problems/slurm.toml"), settings).unwrap();
        Env { _tmp: tmp, root, slurm }
    }

    fn cmd(&self, args: &[&str]) -> Command {
        let mut c = Command::new(BIN);
        c.current_dir(&self.root).args(args).args(["--problems", "problems", "--output", "output"]);
        if let Some(s) = self.slurm {
            c.env("SLURM_CONF", &s.conf);
        }
        c.stdin(Stdio::null());
        c
    }

    fn run(&self, args: &[&str]) -> Output {
        self.cmd(args).output().unwrap()
    }

    /// The folder of case `name`.
    fn case_dir(&self, name: &str) -> PathBuf {
        let dir = self.root.join("output/tiny");
        std::fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .find(|p| {
                p.is_dir() && p.file_name().unwrap().to_string_lossy().rsplit_once('-').unwrap().0 == name
            })
            .unwrap_or_else(|| panic!("no folder for case {name}"))
    }

    fn summary(&self, name: &str) -> serde_json::Value {
        let s = std::fs::read_to_string(self.case_dir(name).join("summary.json")).unwrap();
        serde_json::from_str(&s).unwrap()
    }

    fn log(&self, name: &str) -> String {
        std::fs::read_to_string(self.case_dir(name).join("run.log")).unwrap_or_default()
    }

    /// Waits for case `name`'s simulation to report progress past t = 0.
    fn wait_for_progress(&self, name: &str, limit: Duration) {
        let t0 = Instant::now();
        loop {
            let dir = self.root.join("output/tiny");
            let progress = std::fs::read_dir(&dir).ok().and_then(|rd| {
                rd.flatten()
                    .map(|e| e.path())
                    .find(|p| {
                        p.file_name().unwrap().to_string_lossy().starts_with(&format!("{name}-"))
                            && p.is_dir()
                    })
                    .and_then(|p| std::fs::read_to_string(p.join("progress")).ok())
            });
            let t: f64 = progress.and_then(|s| s.split_whitespace().next()?.parse().ok()).unwrap_or(0.0);
            if t > 0.0 {
                return;
            }
            assert!(t0.elapsed() < limit, "case {name} made no progress in {limit:?}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Cases `a`, `b`, `c`, ... at nx = 12, 14, 16, ..., to `tf`.
fn cases(names: &[&str], tf: f64) -> String {
    let mut s = format!("title = \"tiny\"\nscene = \"taylor_green\"\npaper = \"ctvf\"\n[params]\ntf = {tf}\n[presets.quick]\n");
    for (i, n) in names.iter().enumerate() {
        s += &format!("[[cases]]\nname = \"{n}\"\nparams = {{ nx = {} }}\n", 12 + 2 * i);
    }
    s
}

/// Settings for a fast test: a look at the queue every 0.2 s.
const FAST: &str = "poll = 0.2\n";

/// The result fields of two summaries are equal, bit for bit.
fn assert_same_results(a: &serde_json::Value, b: &serde_json::Value, what: &str) {
    for k in RESULTS {
        assert_eq!(a[k], b[k], "{what}: `{k}` differs");
    }
}

/// A small problem run as a Slurm job array gives, case by case, the summaries a local run
/// gives (every result field, bit for bit); the cache then calls the cases done for either
/// executor, and each summary names its job, task and node.
#[test]
fn a_slurm_run_gives_the_local_results_bit_for_bit() {
    let Some(slurm) = cluster::start_or_skip("a_slurm_run_gives_the_local_results_bit_for_bit") else {
        return;
    };
    let problem = cases(&["a", "b", "c"], 0.02);
    let (on_slurm, local) = (Env::new(&problem, FAST, Some(&slurm)), Env::new(&problem, FAST, None));
    let t0 = Instant::now();
    let o = on_slurm.run(&["run", "tiny", "--executor", "slurm"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}\n{}", slurm.logs());
    assert!(t.contains("submitted Slurm job") && t.contains("0 queued, 0 running, 3 done, 0 failed"), "{t}");
    eprintln!("3 cases on Slurm: {:.1} s", t0.elapsed().as_secs_f64());
    let o = local.run(&["run", "tiny"]);
    assert!(o.status.success(), "{}", text(&o));
    for n in ["a", "b", "c"] {
        let (s, l) = (on_slurm.summary(n), local.summary(n));
        assert_eq!(s["status"], "completed");
        assert_same_results(&s, &l, n);
        let job = &s["provenance"]["slurm"];
        assert!(job["array_job_id"].is_string() && job["array_task_id"].is_string(), "{job}");
        assert_eq!(job["node"], "localhost");
        assert!(l["provenance"].get("slurm").is_none());
        assert!(on_slurm.log(n).contains("--- slurm task "), "{}", on_slurm.log(n));
    }
    // Done for both executors: nothing to run, nothing submitted.
    let t = text(&on_slurm.run(&["run", "tiny"]));
    assert!(t.contains("0 case(s) to run, 3 done"), "{t}");
    let t = text(&on_slurm.run(&["run", "tiny", "--executor", "slurm"]));
    assert!(t.contains("0 case(s) to run, 3 done") && !t.contains("submitted"), "{t}");
    let o = on_slurm.run(&["status"]);
    assert!(o.status.success() && text(&o).contains("3 done, 0 failed, 0 missing"), "{}", text(&o));
}

/// A task told its time limit is near (Slurm's `--signal=B:USR1@N`, sent here at once with
/// `scancel --batch --signal=USR1`, the same delivery to the same process: a real limit of
/// Slurm's least, one minute, takes 30-90 s) checkpoints, requeues itself and resumes from
/// its checkpoint, and ends with the result of an uninterrupted run, bit for bit.
#[test]
fn a_task_at_its_time_limit_is_requeued_and_resumes_from_its_checkpoint() {
    let Some(slurm) =
        cluster::start_or_skip("a_task_at_its_time_limit_is_requeued_and_resumes_from_its_checkpoint")
    else {
        return;
    };
    let problem = "title = \"slow\"\nscene = \"taylor_green\"\npaper = \"ctvf\"\n[presets.quick]\n\
                   [[cases]]\nname = \"a\"\nparams = { nx = 16, tf = 24.0 }\n";
    let (on_slurm, local) = (Env::new(problem, FAST, Some(&slurm)), Env::new(problem, FAST, None));
    let t0 = Instant::now();
    let reference =
        local.cmd(&["run", "tiny"]).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let runner = on_slurm
        .cmd(&["run", "tiny", "--executor", "slurm"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    on_slurm.wait_for_progress("a", Duration::from_secs(60));
    let running = slurm.tasks("running");
    assert_eq!(running.len(), 1, "{running:?}");
    let o = slurm.cmd("scancel").args(["--batch", "--signal=USR1", &running[0]]).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let o = runner.wait_with_output().unwrap();
    let t = text(&o);
    let log = on_slurm.log("a");
    assert!(o.status.success(), "{t}\n{log}");
    eprintln!("stopped, requeued and resumed on Slurm: {:.1} s", t0.elapsed().as_secs_f64());
    assert!(t.contains("requeue tiny/a") && t.contains("done    tiny/a (completed"), "{t}");
    assert!(log.contains("failed: interrupted (checkpoint written"), "{log}");
    assert!(log.contains("requeued: the time limit is near"), "{log}");
    assert!(log.contains("restart 1") && log.contains("resuming from"), "{log}");
    let s = on_slurm.summary("a");
    assert_eq!(s["status"], "completed");
    assert_eq!(s["provenance"]["slurm"]["restarts"], 1);
    let o = reference.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    assert_same_results(&s, &local.summary("a"), "resumed on Slurm against uninterrupted");
}

/// Where Slurm refuses the requeue (a site's policy; here a `scontrol` that refuses it,
/// first on the tasks' PATH), the task ends with its checkpoint kept and the waiting command
/// submits the case again, in a new array: it resumes from the checkpoint.
#[test]
fn a_case_whose_requeue_is_refused_is_submitted_again_and_resumes() {
    let Some(slurm) =
        cluster::start_or_skip("a_case_whose_requeue_is_refused_is_submitted_again_and_resumes")
    else {
        return;
    };
    let problem = "title = \"slow\"\nscene = \"taylor_green\"\npaper = \"ctvf\"\n[presets.quick]\n\
                   [[cases]]\nname = \"a\"\nparams = { nx = 16, tf = 24.0 }\n";
    let env = Env::new(problem, FAST, Some(&slurm));
    let fake = tempfile::tempdir().unwrap();
    let scontrol = fake.path().join("scontrol");
    std::fs::write(
        &scontrol,
        format!(
            "#!/bin/sh\nif [ \"$1\" = requeue ]; then echo 'Requeue refused by site policy' >&2; exit 1; fi\nexec {} \"$@\"\n",
            cluster::find("scontrol").unwrap().display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&scontrol, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", fake.path().display(), std::env::var("PATH").unwrap_or_default());
    let runner = env
        .cmd(&["run", "tiny", "--executor", "slurm"])
        .env("PATH", path)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    env.wait_for_progress("a", Duration::from_secs(60));
    let first = slurm.tasks("running");
    assert_eq!(first.len(), 1, "{first:?}");
    let o = slurm.cmd("scancel").args(["--batch", "--signal=USR1", &first[0]]).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let o = runner.wait_with_output().unwrap();
    let (t, log) = (text(&o), env.log("a"));
    assert!(o.status.success(), "{t}\n{log}");
    assert!(t.contains("resubmit tiny/a") && t.contains("done    tiny/a (completed"), "{t}");
    assert!(
        log.contains("error: cannot requeue: ") && log.contains("Requeue refused by site policy"),
        "{log}"
    );
    assert!(log.contains("resuming from"), "{log}");
    let s = env.summary("a");
    assert_eq!(s["status"], "completed");
    let job = &s["provenance"]["slurm"];
    assert_ne!(job["array_job_id"].as_str().unwrap(), first[0].split('_').next().unwrap(), "{job}");
    let local = Env::new(problem, FAST, None);
    assert!(local.run(&["run", "tiny"]).status.success());
    assert_same_results(&s, &local.summary("a"), "resubmitted on Slurm against uninterrupted");
}

/// A case whose task fails is reported with its Slurm state, exit code and log, and the
/// command exits non-zero; `--retry-failed` then submits that case alone.
#[test]
fn a_failed_case_is_reported_with_its_log_and_retry_failed_reruns_only_it() {
    let Some(slurm) =
        cluster::start_or_skip("a_failed_case_is_reported_with_its_log_and_retry_failed_reruns_only_it")
    else {
        return;
    };
    // The tasks' setup fails for case b alone.
    let failing = format!(
        "{FAST}setup = ['case \"$SPHREPRO_CASE_DIR\" in */b-*) echo \"no licence here\"; sh -c \"exit 7\";; esac']\n"
    );
    let env = Env::new(&cases(&["a", "b", "c"], 0.02), &failing, Some(&slurm));
    let o = env.run(&["run", "tiny", "--executor", "slurm"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    let b_log = env.case_dir("b").join("run.log");
    assert!(t.contains("1 case(s) failed:") && t.contains("tiny/b: slurm "), "{t}");
    assert!(t.contains("ended FAILED, exit code 7: setup command failed (exit 7)"), "{t}");
    assert!(t.contains(&format!("log: {}", std::path::absolute(&b_log).unwrap().display())), "{t}");
    assert!(env.log("b").contains("no licence here"), "{}", env.log("b"));
    for n in ["a", "c"] {
        assert_eq!(env.summary(n)["status"], "completed");
    }
    let t = text(&env.run(&["status"]));
    assert!(t.contains("failed     b") && t.contains("2 done, 1 failed"), "{t}");
    let finished = |n: &str| env.summary(n)["provenance"]["finished"].clone();
    let (a, c) = (finished("a"), finished("c"));
    // Fixed: only b is submitted again.
    std::fs::write(env.root.join("problems/slurm.toml"), FAST).unwrap();
    let t = text(&env.run(&["run", "tiny", "--executor", "slurm", "--retry-failed", "--dry-run"]));
    assert!(t.contains("task 0: tiny/b") && !t.contains("task 1:") && t.contains("1 to run"), "{t}");
    let o = env.run(&["run", "tiny", "--executor", "slurm", "--retry-failed"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("(1 case(s): tiny/b)") && t.contains("done    tiny/b (completed"), "{t}");
    assert_eq!(env.summary("b")["status"], "completed");
    assert_eq!((finished("a"), finished("c")), (a, c), "a and c ran again");
}

/// With `--no-wait` the command returns once submitted; `status` then shows each case
/// queued or running until its summary says it is done, never done before, and a second
/// submission leaves the queued cases out.
#[test]
fn no_wait_then_status_shows_queued_and_running_cases_never_a_false_done() {
    let Some(slurm) =
        cluster::start_or_skip("no_wait_then_status_shows_queued_and_running_cases_never_a_false_done")
    else {
        return;
    };
    let env = Env::new(&cases(&["a", "b", "c"], 4.0), FAST, Some(&slurm));
    // One task at a time (--jobs caps the array), so that some wait in the queue.
    let o = env.run(&["run", "tiny", "--executor", "slurm", "--no-wait", "--jobs", "1"]);
    let t = text(&o);
    assert!(o.status.success() && t.contains("submitted Slurm job") && t.contains("--no-wait"), "{t}");
    let o = env.run(&["status"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("queued") && t.contains("queued or running in Slurm"), "{t}");
    let t = text(&env.run(&["run", "tiny", "--executor", "slurm", "--dry-run"]));
    assert!(t.contains("not submitted again") && t.contains("0 to run"), "{t}");
    let (mut saw_queued, mut saw_running) = (false, false);
    let t0 = Instant::now();
    loop {
        let o = env.run(&["status"]);
        let t = text(&o);
        for n in ["a", "b", "c"] {
            let line = t.lines().find(|l| l.split_whitespace().nth(1) == Some(n)).unwrap_or_default();
            saw_queued |= line.trim_start().starts_with("queued");
            saw_running |= line.trim_start().starts_with("running");
            if line.trim_start().starts_with("done") {
                assert_eq!(env.summary(n)["status"], "completed", "a false done: {line}");
            }
        }
        if o.status.success() {
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(90), "not done:\n{t}\n{}", slurm.logs());
        std::thread::sleep(Duration::from_millis(100));
    }
    assert!(saw_queued && saw_running, "queued {saw_queued}, running {saw_running}");
    assert!(text(&env.run(&["status"])).contains("3 done, 0 failed, 0 missing"));
    let o = env.run(&["run", "tiny", "--plot-only"]);
    assert!(o.status.success(), "{}", text(&o));
}

/// A local runner and a Slurm array started at once on one output folder: every case is
/// simulated once, by one of them (the other waits for its lock, then finds it done).
#[test]
fn a_local_runner_and_a_slurm_array_on_one_folder_never_run_a_case_twice() {
    let Some(slurm) =
        cluster::start_or_skip("a_local_runner_and_a_slurm_array_on_one_folder_never_run_a_case_twice")
    else {
        return;
    };
    let names = ["a", "b", "c", "d"];
    let env = Env::new(&cases(&names, 1.0), FAST, Some(&slurm));
    let o = env.run(&["run", "tiny", "--executor", "slurm", "--no-wait"]);
    assert!(o.status.success(), "{}", text(&o));
    let o = env.run(&["run", "tiny", "--jobs", "1"]);
    let local = text(&o);
    assert!(o.status.success(), "{local}");
    slurm.wait_idle(Duration::from_secs(60));
    let (mut by_slurm, mut by_local) = (0, 0);
    for n in names {
        let log = env.log(n);
        let on_slurm = log.matches(&format!("simulating tiny/{n} ")).count();
        let here = local.matches(&format!("done    tiny/{n} ")).count();
        assert_eq!(on_slurm + here, 1, "case {n}: {on_slurm} on Slurm, {here} locally\n{local}\n{log}");
        assert_eq!(env.summary(n)["status"], "completed");
        assert!(!log.lines().any(|l| l.starts_with("error") || l.starts_with("failed")), "{log}");
        (by_slurm, by_local) = (by_slurm + on_slurm, by_local + here);
    }
    eprintln!("{by_slurm} case(s) simulated on Slurm, {by_local} locally");
    let t = text(&env.run(&["status"]));
    assert!(t.contains("4 done, 0 failed, 0 missing"), "{t}");
}

/// Ctrl-C while waiting asks what to do with the jobs: `n` leaves them running (and
/// `status` shows the case running), `y` cancels them (and the case is not done).
#[test]
fn ctrl_c_while_waiting_asks_whether_to_cancel_the_jobs() {
    let Some(slurm) = cluster::start_or_skip("ctrl_c_while_waiting_asks_whether_to_cancel_the_jobs") else {
        return;
    };
    let env = Env::new(&cases(&["a", "b"], 200.0), FAST, Some(&slurm));
    let interrupt = |case: &str, answer: &str| {
        let mut child = env
            .cmd(&["run", "tiny", "--executor", "slurm", "--match", case])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        env.wait_for_progress(case, Duration::from_secs(60));
        // SAFETY: kill with the pid of our own child.
        unsafe {
            libc::kill(child.id() as libc::pid_t, libc::SIGINT);
        }
        use std::io::Write;
        child.stdin.take().unwrap().write_all(answer.as_bytes()).unwrap();
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(130), "{}", text(&o));
        text(&o)
    };
    let t = interrupt("a", "n\n");
    assert!(t.contains("cancel the submitted Slurm job(s)") && t.contains("left running"), "{t}");
    assert_eq!(slurm.tasks("running").len(), 1);
    let t = text(&env.run(&["status"]));
    assert!(t.contains("running    a  (slurm ") && t.contains("queued or running in Slurm"), "{t}");
    let t = interrupt("b", "y\n");
    assert!(t.contains("cancelled Slurm job(s)"), "{t}");
    let running = slurm.tasks("running");
    assert_eq!(running.len(), 1, "b's task was not cancelled, or a's was: {running:?}");
    let t = text(&env.run(&["status"]));
    assert!(t.contains("running    a") && t.contains("failed     b"), "{t}");
}

/// A partition or account that sbatch refuses: one line naming the setting, where it was
/// set and its value, exit status 2, nothing submitted.
#[test]
fn a_partition_or_account_slurm_refuses_submits_nothing() {
    let Some(slurm) = cluster::start_or_skip("a_partition_or_account_slurm_refuses_submits_nothing") else {
        return;
    };
    let env = Env::new(&cases(&["a", "b"], 0.02), FAST, Some(&slurm));
    for (args, want) in [
        (
            &["--partition", "nosuch"][..],
            "error: sbatch refused --partition = \"nosuch\": Invalid partition name specified\n",
        ),
        (
            &["--partition", "restricted", "--account", "nosuch"][..],
            "error: sbatch refused --account = \"nosuch\": Invalid account or account/partition combination specified\n",
        ),
    ] {
        let o = env.cmd(&["run", "tiny", "--executor", "slurm"]).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        assert_eq!(err, want);
        assert!(!slurm.busy() && slurm.tasks("all").is_empty(), "a job was submitted");
        assert_no_submission(&env.root);
    }
    // The same from the settings file names the file and the key.
    std::fs::write(env.root.join("problems/slurm.toml"), format!("{FAST}partition = \"nosuch\"\n")).unwrap();
    let o = env.run(&["run", "tiny", "--executor", "slurm"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: sbatch refused problems/slurm.toml: `partition` = \"nosuch\": Invalid partition name specified\n"
    );
    assert_no_submission(&env.root);
}

/// A malformed settings file, a Slurm flag without `--executor slurm`, or no `sbatch` on
/// the PATH: one line naming the file, key and value (or the command), exit status 2,
/// nothing submitted. (Needs no Slurm.)
#[test]
fn bad_settings_or_no_sbatch_submit_nothing() {
    let env = Env::new(&cases(&["a"], 0.02), FAST, None);
    for (settings, want) in [
        (
            "time = 60\n",
            "error: problems/slurm.toml:1: `time = 60`: invalid type: integer `60`, expected a string\n",
        ),
        (
            "poll = 0.2\nparition = \"x\"\n",
            "error: problems/slurm.toml:2: `parition = \"x\"`: unknown field `parition`",
        ),
        ("mem = \"lots\"\n", "error: problems/slurm.toml: `mem` = \"lots\": not a Slurm memory size"),
        (
            "[problems.tinny]\ntime = \"10\"\n",
            "error: problems/slurm.toml: `problems.tinny`: no problem `tinny`",
        ),
    ] {
        std::fs::write(env.root.join("problems/slurm.toml"), settings).unwrap();
        let o = env.run(&["run", "tiny", "--executor", "slurm"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{settings}: {}", text(&o));
        assert!(err.starts_with(want) && err.lines().count() == 1, "{settings}: {err}");
        assert_no_submission(&env.root);
    }
    std::fs::write(env.root.join("problems/slurm.toml"), FAST).unwrap();
    let o = env.run(&["run", "tiny", "--time", "10"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: --time is a Slurm setting: add --executor slurm\n"
    );
    let o = env.run(&["run", "tiny", "--executor", "slurm", "--time", "1-2-3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).starts_with("error: --time = \"1-2-3\": not a Slurm time limit")
    );
    let empty = tempfile::tempdir().unwrap();
    let o = env.cmd(&["run", "tiny", "--executor", "slurm"]).env("PATH", empty.path()).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: `sbatch` not found: --executor slurm needs Slurm's commands on the PATH \
         (run it on the cluster's login node)\n"
    );
    assert_no_submission(&env.root);
    assert!(!env.root.join("output/tiny").exists(), "a case ran");
}

/// No submission folder is left under `output/.slurm`.
fn assert_no_submission(root: &Path) {
    let left: Vec<_> = std::fs::read_dir(root.join("output/.slurm"))
        .map(|rd| rd.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "submission folders left: {left:?}");
}

/// The real thing, slow (one to two minutes, so not in the default run): a task with
/// Slurm's least time limit, one minute, asking for the warning 50 s before it, gets it
/// from Slurm's own clock (checked every 30 s), requeues itself and completes.
#[test]
#[ignore = "waits for a real Slurm time limit: one to two minutes"]
fn a_real_time_limit_is_survived() {
    let Some(slurm) = cluster::start_or_skip("a_real_time_limit_is_survived") else {
        return;
    };
    let problem = "title = \"slow\"\nscene = \"taylor_green\"\npaper = \"ctvf\"\n[presets.quick]\n\
                   [[cases]]\nname = \"a\"\nparams = { nx = 32, tf = 40.0 }\n";
    let env = Env::new(problem, &format!("{FAST}time = \"1\"\nsignal_before = 50\n"), Some(&slurm));
    let t0 = Instant::now();
    let o = env.run(&["run", "tiny", "--executor", "slurm"]);
    let (t, log) = (text(&o), env.log("a"));
    eprintln!("{:.1} s\n{t}\n{log}", t0.elapsed().as_secs_f64());
    assert!(o.status.success(), "{t}\n{log}");
    assert!(log.contains("requeued: the time limit is near") && log.contains("resuming from"), "{log}");
    assert_eq!(env.summary("a")["status"], "completed");
}
