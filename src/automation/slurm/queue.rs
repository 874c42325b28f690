//! Which cases sit in a Slurm queue now: the submissions recorded under `OUTPUT/.slurm/`
//! whose jobs Slurm still has pending or running. `status` shows these cases as queued or
//! running, and a new submission leaves them out; whether a case is done is never taken
//! from here, only from its summary.

use super::client::{self, TaskState};
use super::script::{Manifest, FOLDER};
use std::collections::HashMap;
use std::path::Path;

/// A case's task in the queue.
#[derive(Clone, Debug)]
pub struct Queued {
    /// `JOB_TASK`, as Slurm names it.
    pub task: String,
    /// Its state.
    pub state: TaskState,
}

impl Queued {
    /// `queued` or `running`.
    pub fn word(&self) -> &'static str {
        if self.state.running() {
            "running"
        } else {
            "queued"
        }
    }

    /// E.g. `slurm 12_3 on node7` or `slurm 12_3: Priority`.
    pub fn detail(&self) -> String {
        if self.state.running() {
            format!("slurm {} on {}", self.task, self.state.node)
        } else if self.state.reason.is_empty() || self.state.reason == "None" {
            format!("slurm {}", self.task)
        } else {
            format!("slurm {}: {}", self.task, self.state.reason)
        }
    }
}

/// The cases in a Slurm queue, by [`key`]; and what went wrong asking, if something did.
#[derive(Debug, Default)]
pub struct Queue {
    /// Pending or running cases.
    pub cases: HashMap<String, Queued>,
    /// Why the queue could not be read (the cases are then shown by their folders only).
    pub warning: Option<String>,
}

/// A case folder's key: `problem/folder`, the same whatever path led to the output folder.
pub fn key(dir: &Path) -> String {
    let name = |p: Option<&Path>| p.and_then(Path::file_name).map(|n| n.to_string_lossy().into_owned());
    format!("{}/{}", name(dir.parent()).unwrap_or_default(), name(Some(dir)).unwrap_or_default())
}

/// The cases of the submissions under `output` that Slurm still has pending or running.
/// Asks Slurm only when a submission not yet seen to end is recorded; one seen to end is
/// marked (`ended`) and not asked about again.
pub fn read(output: &Path) -> Queue {
    let mut subs = Vec::new();
    if let Ok(rd) = std::fs::read_dir(output.join(FOLDER)) {
        for e in rd.flatten() {
            let dir = e.path();
            if dir.join("ended").exists() {
                continue;
            }
            let Some(job) =
                std::fs::read_to_string(dir.join("job")).ok().and_then(|s| s.trim().parse::<u64>().ok())
            else {
                continue;
            };
            if let Ok(m) = Manifest::read(&dir.join("manifest.json")) {
                subs.push((dir, job, m));
            }
        }
    }
    let mut out = Queue::default();
    if subs.is_empty() {
        return out;
    }
    let q = match client::queue() {
        Ok(q) => q,
        Err(e) => {
            out.warning = Some(format!(
                "cannot read the Slurm queue ({e}): submitted cases are shown by their folders"
            ));
            return out;
        }
    };
    for (dir, job, m) in subs {
        let mut any = false;
        for (i, c) in m.cases.iter().enumerate() {
            if let Some(st) = q.get(&(job, i as u32)).filter(|st| !st.ended()) {
                any = true;
                out.cases.insert(key(&c.dir), Queued { task: format!("{job}_{i}"), state: st.clone() });
            }
        }
        if !any {
            let _ = std::fs::write(dir.join("ended"), b"");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_case_is_known_by_its_problem_and_folder_whatever_the_path_to_it() {
        assert_eq!(key(Path::new("output/tg/a-0123456789")), "tg/a-0123456789");
        assert_eq!(key(Path::new("/home/u/run/./output/tg/a-0123456789")), "tg/a-0123456789");
        let state = |state: &str, reason: &str| TaskState {
            state: state.into(),
            node: "n7".into(),
            reason: reason.into(),
            exit: 0,
            signal: 0,
        };
        let q = Queued { task: "12_3".into(), state: state("RUNNING", "None") };
        assert_eq!((q.word(), q.detail().as_str()), ("running", "slurm 12_3 on n7"));
        let q = Queued { task: "12_4".into(), state: state("PENDING", "Priority") };
        assert_eq!((q.word(), q.detail().as_str()), ("queued", "slurm 12_4: Priority"));
    }
}
