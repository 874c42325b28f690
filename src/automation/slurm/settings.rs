//! What `--executor slurm` asks Slurm for: a settings file kept with the problems
//! (`problems/slurm.toml`, or the file `--slurm-config` names), per-problem overrides in it,
//! and the command line over both. Every key is typed and checked before anything is
//! submitted; an error names the file (or the flag), the key and the value.
//!
//! ```toml
//! partition = "compute"
//! account = "proj42"
//! time = "02:00:00"            # per case: MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS
//! cpus_per_task = 4
//! mem = "4G"
//! sbatch = ["--qos=normal"]    # extra #SBATCH lines
//! setup = ["module load gcc"]  # run in the task before the simulation
//! signal_before = 180          # seconds before the limit: checkpoint, then requeue
//! max_requeues = 10            # requeues of one case after its time limit
//! poll = 5                     # seconds between two looks at the queue while waiting
//!
//! [problems.cavity]            # replaces the keys it sets, for that problem's cases
//! time = "12:00:00"
//! ```

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The settings file's name in the problems folder.
pub const FILE_NAME: &str = "slurm.toml";

/// Seconds before the time limit at which a task is told to checkpoint, by default: enough
/// for the last step and the checkpoint of a paper-size case, with the 30 s by which
/// Slurm's own clock may be late.
pub const DEFAULT_SIGNAL_BEFORE: u32 = 180;
/// Requeues of one case after its time limit, by default.
pub const DEFAULT_MAX_REQUEUES: u32 = 10;
/// Seconds between two looks at the queue while waiting, by default.
pub const DEFAULT_POLL: f64 = 5.0;

/// The settings file as written.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    partition: Option<String>,
    account: Option<String>,
    time: Option<String>,
    cpus_per_task: Option<u32>,
    mem: Option<String>,
    sbatch: Option<Vec<String>>,
    setup: Option<Vec<String>>,
    signal_before: Option<u32>,
    max_requeues: Option<u32>,
    poll: Option<f64>,
    #[serde(default)]
    problems: BTreeMap<String, ProblemFile>,
}

/// A `[problems.NAME]` table: the keys that may differ between problems.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProblemFile {
    partition: Option<String>,
    account: Option<String>,
    time: Option<String>,
    cpus_per_task: Option<u32>,
    mem: Option<String>,
    sbatch: Option<Vec<String>>,
    setup: Option<Vec<String>>,
}

/// Settings given on the command line: they win over the file (`sbatch` and `setup` lines
/// are added to the file's).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// `--partition`.
    pub partition: Option<String>,
    /// `--account`.
    pub account: Option<String>,
    /// `--time`.
    pub time: Option<String>,
    /// `--cpus-per-task`.
    pub cpus_per_task: Option<u32>,
    /// `--mem`.
    pub mem: Option<String>,
    /// `--sbatch` (repeatable).
    pub sbatch: Vec<String>,
    /// `--setup` (repeatable).
    pub setup: Vec<String>,
}

/// What one job array asks for: the cases of the problems that resolve to equal `Job`s go
/// into one array.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Job {
    /// `--partition` (none: the cluster's default).
    pub partition: Option<String>,
    /// `--account` (none: the user's default).
    pub account: Option<String>,
    /// `--time`, per case (none: the partition's default).
    pub time: Option<String>,
    /// `--cpus-per-task`: also the threads of each simulation.
    pub cpus_per_task: u32,
    /// `--mem` (none: the partition's default).
    pub mem: Option<String>,
    /// Extra `#SBATCH` lines, as written after `#SBATCH `.
    pub sbatch: Vec<String>,
    /// Shell lines run in the task before the simulation.
    pub setup: Vec<String>,
    /// Seconds before the limit at which the task is told to checkpoint (`--signal`).
    pub signal_before: u32,
}

/// The resolved settings.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Where they came from (`defaults` when no file was read), for messages.
    pub source: String,
    base: Job,
    problems: BTreeMap<String, Job>,
    /// Requeues of one case after its time limit.
    pub max_requeues: u32,
    /// Seconds between two looks at the queue while waiting.
    pub poll: f64,
    /// Which keys the command line set (to name the flag when sbatch refuses a value).
    pub from_cli: Vec<&'static str>,
}

impl Settings {
    /// Reads `path` (or, with none, `problems/slurm.toml` when it exists) and applies `cli`.
    /// `problems` lists the problems there are, so that an override of a problem that does
    /// not exist (a typo) is an error.
    pub fn load(
        explicit: Option<&Path>,
        problems_dir: &Path,
        problems: &[String],
        cli: &Overrides,
    ) -> Result<Self, String> {
        let default_path = problems_dir.join(FILE_NAME);
        let (file, source) = match explicit {
            Some(p) => (read(p)?, p.display().to_string()),
            None if default_path.exists() => (read(&default_path)?, default_path.display().to_string()),
            None => (File::default(), "defaults".to_string()),
        };
        Self::resolve(file, source, problems, cli)
    }

    /// Parses `text` as the file `path` (for tests and `load`).
    pub fn parse(path: &Path, text: &str, problems: &[String], cli: &Overrides) -> Result<Self, String> {
        Self::resolve(parse_file(path, text)?, path.display().to_string(), problems, cli)
    }

    fn resolve(file: File, source: String, problems: &[String], cli: &Overrides) -> Result<Self, String> {
        let at = |key: &str| format!("{source}: `{key}`");
        let base = Job {
            partition: file.partition,
            account: file.account,
            time: file.time,
            cpus_per_task: file.cpus_per_task.unwrap_or(1),
            mem: file.mem,
            sbatch: file.sbatch.unwrap_or_default(),
            setup: file.setup.unwrap_or_default(),
            signal_before: file.signal_before.unwrap_or(DEFAULT_SIGNAL_BEFORE),
        };
        check_job(&base, &|k| at(k))?;
        let poll = file.poll.unwrap_or(DEFAULT_POLL);
        if !(poll.is_finite() && poll > 0.0) {
            return Err(format!("{} = {poll}: not a positive number of seconds", at("poll")));
        }
        let mut per_problem = BTreeMap::new();
        for (name, o) in file.problems {
            if !problems.contains(&name) {
                return Err(format!(
                    "{}: no problem `{name}` (problems: {})",
                    at(&format!("problems.{name}")),
                    problems.join(", ")
                ));
            }
            let job = Job {
                partition: o.partition.or_else(|| base.partition.clone()),
                account: o.account.or_else(|| base.account.clone()),
                time: o.time.or_else(|| base.time.clone()),
                cpus_per_task: o.cpus_per_task.unwrap_or(base.cpus_per_task),
                mem: o.mem.or_else(|| base.mem.clone()),
                sbatch: o.sbatch.unwrap_or_else(|| base.sbatch.clone()),
                setup: o.setup.unwrap_or_else(|| base.setup.clone()),
                signal_before: base.signal_before,
            };
            check_job(&job, &|k| at(&format!("problems.{name}.{k}")))?;
            per_problem.insert(name, job);
        }
        let mut s = Settings {
            source,
            base,
            problems: per_problem,
            max_requeues: file.max_requeues.unwrap_or(DEFAULT_MAX_REQUEUES),
            poll,
            from_cli: Vec::new(),
        };
        s.apply(cli)?;
        Ok(s)
    }

    /// The command line over every job of the file.
    fn apply(&mut self, cli: &Overrides) -> Result<(), String> {
        let mut set = Vec::new();
        for job in std::iter::once(&mut self.base).chain(self.problems.values_mut()) {
            set.clear();
            if let Some(v) = &cli.partition {
                job.partition = Some(v.clone());
                set.push("partition");
            }
            if let Some(v) = &cli.account {
                job.account = Some(v.clone());
                set.push("account");
            }
            if let Some(v) = &cli.time {
                job.time = Some(v.clone());
                set.push("time");
            }
            if let Some(v) = cli.cpus_per_task {
                job.cpus_per_task = v;
                set.push("cpus_per_task");
            }
            if let Some(v) = &cli.mem {
                job.mem = Some(v.clone());
                set.push("mem");
            }
            if !cli.sbatch.is_empty() {
                job.sbatch.extend(cli.sbatch.iter().cloned());
                set.push("sbatch");
            }
            if !cli.setup.is_empty() {
                job.setup.extend(cli.setup.iter().cloned());
                set.push("setup");
            }
            let source = &self.source;
            check_job(job, &|k| {
                if set.contains(&k) {
                    format!("--{}", k.replace('_', "-"))
                } else {
                    format!("{source}: `{k}`")
                }
            })?;
        }
        self.from_cli = set;
        Ok(())
    }

    /// Where the settings came from, in words: the file (or `defaults`) and the flags.
    pub fn describe(&self) -> String {
        if self.from_cli.is_empty() {
            self.source.clone()
        } else {
            let flags: Vec<String> =
                self.from_cli.iter().map(|k| format!("--{}", k.replace('_', "-"))).collect();
            format!("{}, with {}", self.source, flags.join(" "))
        }
    }

    /// The job the cases of `problem` are submitted with.
    pub fn job(&self, problem: &str) -> &Job {
        self.problems.get(problem).unwrap_or(&self.base)
    }

    /// Where a key's value came from, for an error: the flag, the file's problem table or the
    /// file's top level.
    pub fn origin(&self, key: &str, problem: &str) -> String {
        if self.from_cli.contains(&key) {
            format!("--{}", key.replace('_', "-"))
        } else if self.problems.contains_key(problem) {
            format!("{}: `problems.{problem}.{key}` (or the top-level `{key}`)", self.source)
        } else {
            format!("{}: `{key}`", self.source)
        }
    }
}

/// Reads and parses the settings file `path`.
fn read(path: &Path) -> Result<File, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_file(path, &text)
}

/// Parses a settings file; a syntax error, an unknown key or a value of the wrong type
/// names the file, the line and what is written there.
fn parse_file(path: &Path, text: &str) -> Result<File, String> {
    toml::from_str(text).map_err(|e| {
        let start = e.span().map_or(0, |s| s.start.min(text.len()));
        let mut line = text[..start].lines().count().max(1);
        if text[..start].ends_with('\n') {
            line += 1;
        }
        // An unknown key is reported at its table: find the key's own line.
        let unknown = e.message().strip_prefix("unknown field `").and_then(|m| m.split('`').next());
        if let Some(key) = unknown {
            let found = text.lines().enumerate().skip(line - 1).find(|(_, l)| {
                l.trim_start().strip_prefix(key).is_some_and(|rest| rest.trim_start().starts_with('='))
            });
            if let Some((n, _)) = found {
                line = n + 1;
            }
        }
        let written = text.lines().nth(line - 1).map(str::trim).unwrap_or_default();
        let quoted =
            if written.is_empty() || written.len() > 80 { String::new() } else { format!("`{written}`: ") };
        let message = e.message().replace('\n', " ");
        format!("{}:{line}: {quoted}{message}", path.display())
    })
}

/// Checks every value of `job`; `at(key)` names where the key was set.
fn check_job(job: &Job, at: &dyn Fn(&'static str) -> String) -> Result<(), String> {
    for (key, value) in [("partition", &job.partition), ("account", &job.account)] {
        if let Some(v) = value {
            if v.is_empty() || v.chars().any(|c| c.is_whitespace() || c.is_control()) {
                return Err(format!("{} = {v:?}: not a Slurm {key} name (empty, or with spaces)", at(key)));
            }
        }
    }
    let limit = match &job.time {
        Some(t) => Some(time_seconds(t).ok_or_else(|| {
            format!(
                "{} = {t:?}: not a Slurm time limit (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS)",
                at("time")
            )
        })?),
        None => None,
    };
    if job.cpus_per_task == 0 {
        return Err(format!("{} = 0: at least 1", at("cpus_per_task")));
    }
    if let Some(m) = &job.mem {
        if !is_memory(m) {
            return Err(format!(
                "{} = {m:?}: not a Slurm memory size (a whole number, optionally with K, M, G or T)",
                at("mem")
            ));
        }
    }
    for line in &job.sbatch {
        if !line.starts_with('-') || line.contains(['\n', '\r']) {
            return Err(format!(
                "{} = {line:?}: an #SBATCH line is one option, such as \"--qos=normal\"",
                at("sbatch")
            ));
        }
    }
    for line in &job.setup {
        if line.contains(['\n', '\r']) {
            return Err(format!("{} = {line:?}: one command a line (no line breaks)", at("setup")));
        }
    }
    if let Some(limit) = limit {
        if u64::from(job.signal_before) >= limit {
            return Err(format!(
                "{} = {}: the checkpoint signal must come before the time limit ({} = {:?}, {limit} s)",
                at("signal_before"),
                job.signal_before,
                at("time"),
                job.time.as_deref().unwrap_or_default()
            ));
        }
    }
    Ok(())
}

/// Seconds in a Slurm time limit: `M`, `M:S`, `H:M:S`, `D-H`, `D-H:M`, `D-H:M:S`.
pub fn time_seconds(t: &str) -> Option<u64> {
    let num = |s: &str| -> Option<u64> {
        if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        s.parse().ok()
    };
    let (days, rest) = match t.split_once('-') {
        Some((d, rest)) => (Some(num(d)?), rest),
        None => (None, t),
    };
    let parts: Vec<u64> = rest.split(':').map(num).collect::<Option<_>>()?;
    let secs = match (days, parts.as_slice()) {
        (None, [m]) => m * 60,
        (None, [m, s]) => m * 60 + s,
        (None, [h, m, s]) => h * 3600 + m * 60 + s,
        (Some(d), [h]) => d * 86400 + h * 3600,
        (Some(d), [h, m]) => d * 86400 + h * 3600 + m * 60,
        (Some(d), [h, m, s]) => d * 86400 + h * 3600 + m * 60 + s,
        _ => return None,
    };
    (secs > 0).then_some(secs)
}

/// Whether `m` is a Slurm memory size: digits, then optionally K, M, G or T.
fn is_memory(m: &str) -> bool {
    let digits = m.trim_end_matches(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't']);
    m.len() - digits.len() <= 1 && !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Settings, String> {
        Settings::parse(
            Path::new("problems/slurm.toml"),
            text,
            &["cavity".into(), "tg".into()],
            &Overrides::default(),
        )
    }

    #[test]
    fn slurm_time_limits_read_as_seconds() {
        for (t, s) in [
            ("30", 1800),
            ("5:30", 330),
            ("02:00:00", 7200),
            ("1-0", 86400),
            ("1-2:30", 95400),
            ("1-00:00:10", 86410),
        ] {
            assert_eq!(time_seconds(t), Some(s), "{t}");
        }
        for t in ["", "12h", "1:2:3:4", "-1", "0", "1-", "a:00"] {
            assert_eq!(time_seconds(t), None, "{t}");
        }
        assert!(is_memory("4G") && is_memory("4000") && !is_memory("4GB") && !is_memory("G"));
    }

    #[test]
    fn a_problem_table_replaces_the_keys_it_sets_and_the_command_line_wins() {
        let text = "partition = \"cpu\"\ntime = \"01:00:00\"\nsetup = [\"module load a\"]\n\
                    [problems.cavity]\ntime = \"12:00:00\"\ncpus_per_task = 8\n";
        let s = parse(text).unwrap();
        assert_eq!(s.job("tg").time.as_deref(), Some("01:00:00"));
        let cavity = s.job("cavity");
        assert_eq!((cavity.time.as_deref(), cavity.cpus_per_task), (Some("12:00:00"), 8));
        assert_eq!(
            (cavity.partition.as_deref(), &cavity.setup[..]),
            (Some("cpu"), &["module load a".to_string()][..])
        );
        let cli =
            Overrides { time: Some("30".into()), setup: vec!["module load b".into()], ..Default::default() };
        let s = Settings::parse(Path::new("s.toml"), text, &["cavity".into()], &cli).unwrap();
        assert_eq!(s.job("cavity").time.as_deref(), Some("30"));
        assert_eq!(s.job("x").setup, ["module load a", "module load b"]);
        assert_eq!(s.origin("time", "cavity"), "--time");
        assert_eq!(s.origin("partition", "x"), "s.toml: `partition`");
    }

    #[test]
    fn a_bad_settings_file_names_the_file_the_key_and_the_value() {
        let cases = [
            ("partiton = \"cpu\"", "problems/slurm.toml:1: `partiton = \"cpu\"`: unknown field `partiton`"),
            (
                "time = 60",
                "problems/slurm.toml:1: `time = 60`: invalid type: integer `60`, expected a string",
            ),
            ("time = \"12h\"", "problems/slurm.toml: `time` = \"12h\": not a Slurm time limit"),
            ("mem = \"4GB\"", "problems/slurm.toml: `mem` = \"4GB\": not a Slurm memory size"),
            ("cpus_per_task = 0", "problems/slurm.toml: `cpus_per_task` = 0"),
            ("sbatch = [\"qos=x\"]", "problems/slurm.toml: `sbatch` = \"qos=x\""),
            ("[problems.cavty]\ntime = \"1\"", "problems/slurm.toml: `problems.cavty`: no problem `cavty`"),
            ("[problems.cavity]\ntme = \"1\"", "problems/slurm.toml:2: `tme = \"1\"`: unknown field `tme`"),
            ("[problems.cavity]\nmem = \"x\"", "problems/slurm.toml: `problems.cavity.mem` = \"x\""),
            (
                "time = \"2\"\nsignal_before = 180",
                "`signal_before` = 180: the checkpoint signal must come before",
            ),
            ("poll = 0.0", "problems/slurm.toml: `poll` = 0"),
            ("partition = \"a b\"", "problems/slurm.toml: `partition` = \"a b\""),
        ];
        for (text, want) in cases {
            let e = parse(text).unwrap_err();
            assert!(e.starts_with(want) || e.contains(want), "{text}: {e}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
        let cli = Overrides { time: Some("forever".into()), ..Default::default() };
        let e = Settings::parse(Path::new("s.toml"), "", &[], &cli).unwrap_err();
        assert!(e.starts_with("--time = \"forever\": not a Slurm time limit"), "{e}");
    }
}
