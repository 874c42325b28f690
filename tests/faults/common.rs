//! What the fault-injection tests share: a process run within a time limit, `simulate`
//! on one thread, and a tiny problem in a temporary folder.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

pub const BIN: &str = env!("CARGO_BIN_EXE_sphrepro");

/// How long one tiny case may take, on a loaded 2-core machine, before it counts as hung.
pub const CASE_LIMIT: Duration = Duration::from_secs(60);

/// What a finished process did.
#[derive(Debug)]
pub struct Ran {
    /// Exit code, or `None` if a signal ended it.
    pub code: Option<i32>,
    /// The signal that ended it, if one did.
    pub signal: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl Ran {
    pub fn text(&self) -> String {
        format!(
            "exit {:?} signal {:?}\nstdout: {}\nstderr: {}",
            self.code, self.signal, self.stdout, self.stderr
        )
    }
    pub fn panicked(&self) -> bool {
        self.stderr.contains("panicked") || self.code == Some(101)
    }
}

/// Runs `cmd` with its output in files under `scratch` (a pipe could fill up and stall a
/// process that prints much), killing it if it runs longer than `limit`.
pub fn run_limited(mut cmd: Command, scratch: &Path, limit: Duration) -> Result<Ran, String> {
    std::fs::create_dir_all(scratch).unwrap();
    let (out, err) = (scratch.join("stdout.txt"), scratch.join("stderr.txt"));
    cmd.stdout(std::fs::File::create(&out).unwrap()).stderr(std::fs::File::create(&err).unwrap());
    let mut child = cmd.spawn().map_err(|e| format!("cannot start: {e}"))?;
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "still running after {limit:?} (killed); stderr so far: {}",
                std::fs::read_to_string(&err).unwrap_or_default()
            ));
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    #[cfg(unix)]
    let signal = std::os::unix::process::ExitStatusExt::signal(&status);
    #[cfg(not(unix))]
    let signal = None;
    Ok(Ran {
        code: status.code(),
        signal,
        stdout: std::fs::read_to_string(&out).unwrap_or_default(),
        stderr: std::fs::read_to_string(&err).unwrap_or_default(),
    })
}

/// `sphrepro simulate SCENE --quiet --out DIR --set ...` on one thread.
pub fn simulate_cmd(scene: &str, out: &Path, sets: &[String]) -> Command {
    let mut c = Command::new(BIN);
    c.args(["--threads", "1", "simulate", scene, "--quiet", "--out"]).arg(out);
    for s in sets {
        c.arg("--set").arg(s);
    }
    c
}

/// `DIR/summary.json`, if there is a readable one.
pub fn summary(dir: &Path) -> Option<serde_json::Value> {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).ok()?).ok()
}

/// Runs one `simulate` (on one thread) within the case limit.
pub fn simulate(dir: &Path, scene: &str, sets: &[&str]) -> Ran {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let scratch = tempfile::tempdir().unwrap();
    run_limited(simulate_cmd(scene, dir, &sets), scratch.path(), CASE_LIMIT).unwrap()
}

/// A tiny problem of three Taylor-Green cases in a temporary folder.
pub struct Problem {
    _tmp: tempfile::TempDir,
    pub root: PathBuf,
}

pub const THREE_CASES: &str = r#"title = "tiny"
scene = "taylor_green"
paper = "ctvf"
[params]
tf = 0.02
[presets.quick]
[[cases]]
name = "a"
params = { nx = 12 }
[[cases]]
name = "b"
params = { nx = 14 }
[[cases]]
name = "c"
params = { nx = 16 }
[[figures]]
id = "l1"
kind = "timeseries"
title = "L1"
y = "l1_velocity"
[[bounds]]
metric = "l1_velocity_final"
cases = ["b"]
max = 10.0
"#;

/// One case of a few seconds, to be interrupted.
pub const ONE_SLOW_CASE: &str = r#"title = "one slow case"
scene = "taylor_green"
paper = "ctvf"
[presets.quick]
[[cases]]
name = "a"
params = { nx = 16, tf = 20.0 }
"#;

impl Problem {
    pub fn new(toml: &str) -> Self {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path().to_path_buf();
        std::fs::create_dir_all(root.join("problems")).unwrap();
        std::fs::write(root.join("problems/tiny.toml"), toml).unwrap();
        Problem { _tmp: tmp, root }
    }
    /// `sphrepro ARGS` in the problem's folder, with its folders named (results in
    /// `output/` unless ARGS name another).
    pub fn cmd(&self, args: &[&str]) -> Command {
        let mut c = Command::new(BIN);
        c.current_dir(&self.root).args(args).args(["--problems", "problems", "--manuscript", "manuscript"]);
        if !args.contains(&"--output") {
            c.args(["--output", "output"]);
        }
        c
    }
    pub fn run(&self, args: &[&str]) -> Ran {
        let scratch = self.root.join(format!("scratch-{}", args.join("-").replace('/', "_")));
        run_limited(self.cmd(args), &scratch, Duration::from_secs(120)).unwrap()
    }
    pub fn case_dir(&self, name: &str) -> PathBuf {
        std::fs::read_dir(self.root.join("output/tiny"))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .find(|p| {
                p.is_dir() && p.file_name().unwrap().to_string_lossy().rsplit_once('-').unwrap().0 == name
            })
            .unwrap_or_else(|| panic!("no folder for case {name}"))
    }
}
