//! `summary.json`: the record of one run, in the shape of DESIGN.md's contract.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Reached `tf`.
    Completed,
    /// The physics blew up: a reproducible result.
    Diverged,
    /// Anything else stopped it (I/O error, interruption): never a done case.
    Failed,
}

/// Where and from what a result was computed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Provenance {
    /// Crate version.
    pub version: String,
    /// Scheme version: bumped whenever results change for the same parameters.
    pub scheme_version: String,
    /// Git commit the binary was built from.
    pub git_commit: String,
    /// Whether the tree had uncommitted changes at build time.
    pub git_dirty: bool,
    /// rustc that built it.
    pub rustc: String,
    /// Host name.
    pub host: String,
    /// Its CPU, and the vector paths the binary takes on it (absent from results written
    /// before it was recorded).
    #[serde(default)]
    pub machine: super::machine::Machine,
    /// Start, RFC 3339.
    pub started: String,
    /// End, RFC 3339.
    pub finished: String,
    /// The Slurm job that wrote it, when one did (absent otherwise, and from results written
    /// before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slurm: Option<SlurmJob>,
}

/// The Slurm job a run was part of, from the environment Slurm gives its jobs.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SlurmJob {
    /// `SLURM_JOB_ID` (for an array task, the task's own job id).
    pub job_id: String,
    /// `SLURM_ARRAY_JOB_ID`, for an array task.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array_job_id: Option<String>,
    /// `SLURM_ARRAY_TASK_ID`, for an array task.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array_task_id: Option<String>,
    /// `SLURMD_NODENAME`: the node it ran on.
    pub node: String,
    /// `SLURM_CLUSTER_NAME`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cluster: Option<String>,
    /// `SLURM_RESTART_COUNT`: how often the job was requeued before this run (a run resumed
    /// after its time limit has 1 or more).
    #[serde(default)]
    pub restarts: u32,
}

impl SlurmJob {
    /// The job this process runs in, if it runs in one (`SLURM_JOB_ID` is set).
    pub fn from_env() -> Option<Self> {
        let var = |k: &str| std::env::var(k).ok().filter(|v| !v.is_empty());
        Some(Self {
            job_id: var("SLURM_JOB_ID")?,
            array_job_id: var("SLURM_ARRAY_JOB_ID"),
            array_task_id: var("SLURM_ARRAY_TASK_ID"),
            node: var("SLURMD_NODENAME").unwrap_or_else(hostname),
            cluster: var("SLURM_CLUSTER_NAME"),
            restarts: var("SLURM_RESTART_COUNT").and_then(|r| r.parse().ok()).unwrap_or(0),
        })
    }
}

/// The version of the solver's results: raised whenever they change for unchanged
/// parameters (rounding included), so that results of an older solver read as stale. Every
/// summary records it, and the cache keys every case by it.
pub const SCHEME_VERSION: &str = "6";

impl Provenance {
    /// Provenance of this binary, for a run that started at `started`.
    pub fn now(started: chrono::DateTime<chrono::Utc>) -> Self {
        Self {
            version: env!("CARGO_PKG_VERSION").into(),
            scheme_version: SCHEME_VERSION.into(),
            git_commit: env!("SPHREPRO_GIT_COMMIT").into(),
            git_dirty: env!("SPHREPRO_GIT_DIRTY") == "true",
            rustc: env!("SPHREPRO_RUSTC").into(),
            host: hostname(),
            machine: super::machine::Machine::detect(),
            started: started.to_rfc3339(),
            finished: chrono::Utc::now().to_rfc3339(),
            slurm: SlurmJob::from_env(),
        }
    }
}

/// The user plus system CPU time this process has spent so far, in seconds (all its
/// threads), from `getrusage`; `None` where the OS does not tell.
pub fn process_cpu_seconds() -> Option<f64> {
    let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a whole `rusage` into the pointer it is given.
    let ok = unsafe { libc::getrusage(libc::RUSAGE_SELF, u.as_mut_ptr()) } == 0;
    ok.then(|| {
        // SAFETY: initialised by the successful call above.
        let u = unsafe { u.assume_init() };
        let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
        secs(u.ru_utime) + secs(u.ru_stime)
    })
}

fn hostname() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|_| std::env::var("HOSTNAME").unwrap_or_else(|_| "unknown".into()))
}

/// The contents of `summary.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Resolved parameters (defaults filled in).
    pub params: BTreeMap<String, serde_json::Value>,
    /// Particle count (all bodies).
    pub particles: usize,
    /// Particles of each body, by name (empty in summaries written before bodies were
    /// counted apart).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub bodies: BTreeMap<String, usize>,
    /// Time steps taken.
    pub steps: u64,
    /// Simulated time reached.
    pub final_time: f64,
    /// Wall-clock seconds of the whole run.
    pub wall_seconds: f64,
    /// CPU seconds (user + system, all threads) the run's process spent, from the OS
    /// ([`process_cpu_seconds`]): the cost a loaded machine does not inflate as it does the
    /// wall time. Absent in summaries written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_seconds: Option<f64>,
    /// particles x steps / seconds spent stepping.
    pub particle_steps_per_second: f64,
    /// Rayon threads.
    pub threads: usize,
    /// Steps of this run's last process whose listing and passes ran as a wavefront over
    /// tiles rather than as sweeps (the same results; the faster on the host, see
    /// `solver::scheme::Schedule`).
    #[serde(default)]
    pub wavefront_steps: u64,
    /// How it ended.
    pub status: Status,
    /// Why it diverged or failed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub reason: Option<String>,
    /// The step at which it diverged.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub step: Option<u64>,
    /// Named error norms and validation figures: finite, but for the NaN that stands for each
    /// name of [`undefined_metrics`](Self::undefined_metrics) until written (as `null`; read
    /// back, it is left out).
    #[serde(serialize_with = "with_undefined", deserialize_with = "defined_only")]
    pub metrics: BTreeMap<String, f64>,
    /// The scene's metrics this run cannot define (the period of a run shorter than half a
    /// period): named in `metrics` as `null` so that every declared name is in the file, and
    /// listed here so that a `null` is never mistaken for a value that blew up.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub undefined_metrics: Vec<String>,
    /// Provenance.
    pub provenance: Provenance,
}

impl Summary {
    /// Names every metric of `declared` the run left undefined: listed in
    /// [`undefined_metrics`](Self::undefined_metrics) and written as `null` in `metrics`.
    pub fn with_undefined(mut self, declared: &[&str]) -> Self {
        for &m in declared {
            if !self.metrics.contains_key(m) {
                self.metrics.insert(m.to_string(), f64::NAN);
                self.undefined_metrics.push(m.to_string());
            }
        }
        self
    }

    /// Writes `DIR/summary.json` atomically.
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        let json = serde_json::to_string_pretty(self).expect("summary serialises");
        super::write_atomic(&dir.join("summary.json"), json.as_bytes())
    }

    /// Reads `DIR/summary.json`.
    pub fn read(dir: &Path) -> Result<Self, String> {
        let path = dir.join("summary.json");
        let s = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&s).map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// Writes [`Summary::metrics`] with the NaN of an undefined metric
/// ([`Summary::with_undefined`]) as `null`.
fn with_undefined<S: serde::Serializer>(m: &BTreeMap<String, f64>, s: S) -> Result<S::Ok, S::Error> {
    let out: BTreeMap<&str, Option<f64>> =
        m.iter().map(|(k, v)| (k.as_str(), v.is_finite().then_some(*v))).collect();
    out.serialize(s)
}

/// Reads [`Summary::metrics`], leaving out the `null`s of undefined metrics.
fn defined_only<'de, D: serde::Deserializer<'de>>(d: D) -> Result<BTreeMap<String, f64>, D::Error> {
    let m = BTreeMap::<String, Option<f64>>::deserialize(d)?;
    Ok(m.into_iter().filter_map(|(k, v)| Some((k, v?))).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Results written before the machine was recorded still read (the cache keeps them).
    #[test]
    fn a_provenance_without_the_machine_reads_back() {
        let mut p = serde_json::to_value(Provenance::now(chrono::Utc::now())).unwrap();
        assert!(p["machine"]["logical_cpus"].as_u64().unwrap() >= 1);
        p.as_object_mut().unwrap().remove("machine");
        let old: Provenance = serde_json::from_value(p).unwrap();
        assert_eq!(old.machine, super::super::machine::Machine::default());
    }

    /// A run outside Slurm writes no `slurm` entry, and summaries without one read back.
    #[test]
    fn the_slurm_job_is_recorded_only_inside_one() {
        let mut p = Provenance::now(chrono::Utc::now());
        p.slurm = None;
        let v = serde_json::to_value(&p).unwrap();
        assert!(v.get("slurm").is_none());
        p.slurm = Some(SlurmJob {
            job_id: "13".into(),
            array_job_id: Some("12".into()),
            array_task_id: Some("1".into()),
            node: "node7".into(),
            cluster: None,
            restarts: 1,
        });
        let v = serde_json::to_value(&p).unwrap();
        assert_eq!(v["slurm"]["array_task_id"], "1");
        let back: Provenance = serde_json::from_value(v).unwrap();
        assert_eq!(back.slurm, p.slurm);
    }
}
