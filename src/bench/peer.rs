//! The peer code measured alongside ours (`bench --peer`, e.g. PySPH through
//! `../shared/peers/pysph-taylor-green.sh`): its runs, what it reports, and the accuracy
//! of ours on the same run.

use serde::{Deserialize, Serialize};
use std::path::Path;

/// What the peer reported for one resolution and thread count.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct PeerResult {
    /// The peer's name, as it reports it (e.g. `pysph-1.0b2`).
    pub peer: String,
    /// Particles per side.
    pub nx: usize,
    /// Threads it ran on.
    pub threads: usize,
    /// Its particle-steps per second.
    pub particle_steps_per_second: f64,
    /// The simulated time it was asked to run to (shorter at large nx, so that it takes
    /// minutes).
    pub tf: f64,
    /// The time it reached, if it says.
    #[serde(default)]
    pub t_final: Option<f64>,
    /// Its L1 velocity error at `t_final` (eq. 66 as PySPH computes it), if it says.
    #[serde(default)]
    pub l1_velocity_final: Option<f64>,
    /// sphrepro `edac`'s L1 velocity error on the same run (size, Re = 100, end time).
    #[serde(default)]
    pub sphrepro_l1_velocity_final: Option<f64>,
    /// Particle-steps per second of every run of the peer at this size and thread count
    /// (`bench --repeat`), in the order they ran; the fields above are the median run's.
    #[serde(default)]
    pub runs: Vec<f64>,
}

impl PeerResult {
    /// The end time both codes are compared at: the peer's, else the one asked for.
    pub(super) fn end_time(&self) -> f64 {
        self.t_final.unwrap_or(self.tf)
    }
}

/// The simulated time a peer runs at resolution `nx`: t = 2 (the paper's Taylor-Green end
/// time) while that is under about 70 million particle-steps (dt = 0.25 h / 11 with h = 1/nx),
/// shorter beyond, so that each peer run takes a minute or two.
pub(super) fn peer_tf(nx: usize) -> f64 {
    let steps_per_unit_time = 44.0 * nx as f64;
    (7.0e7 / ((nx * nx) as f64 * steps_per_unit_time)).min(2.0)
}

/// Reads a peer's one-line JSON report (`particle_steps_per_second`, `peer`, and if there,
/// `t_final` and `l1_velocity_final`).
pub(super) fn parse_peer(stdout: &str, nx: usize, threads: usize, tf: f64) -> Result<PeerResult, String> {
    let line = stdout.lines().rev().find(|l| l.trim_start().starts_with('{')).ok_or("no JSON line")?;
    let v: serde_json::Value = serde_json::from_str(line).map_err(|e| format!("unreadable JSON: {e}"))?;
    let speed = v["particle_steps_per_second"]
        .as_f64()
        .filter(|s| *s > 0.0)
        .ok_or("no positive `particle_steps_per_second`")?;
    Ok(PeerResult {
        peer: v["peer"].as_str().unwrap_or("peer").to_string(),
        nx,
        threads,
        particle_steps_per_second: speed,
        tf,
        t_final: v["t_final"].as_f64(),
        l1_velocity_final: v["l1_velocity_final"].as_f64(),
        sphrepro_l1_velocity_final: None,
        runs: Vec::new(),
    })
}

/// The peer resolution the larger sizes are also compared with: the targets multiply the
/// peer's Taylor-Green throughput at nx = 50.
pub(super) const PEER_BASELINE_NX: usize = 50;

/// One run of a peer's script at `nx` on `threads` threads to time `tf`, read from the
/// JSON line it prints.
pub(super) fn peer_run(script: &Path, nx: usize, threads: usize, tf: f64) -> Result<PeerResult, String> {
    let o = std::process::Command::new(script)
        .args(["--nx", &nx.to_string(), "--tf", &format!("{tf}"), "--threads", &threads.to_string()])
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| e.to_string())?;
    if !o.status.success() {
        return Err(o.status.to_string());
    }
    parse_peer(&String::from_utf8_lossy(&o.stdout), nx, threads, tf)
}

/// sphrepro `edac`'s L1 velocity error on a peer's run (Taylor-Green, `nx`, Re = 100, to
/// `tf`, on `threads` threads, with `kernel`), through `simulate` into a temporary folder.
pub(super) fn edac_l1(exe: &Path, nx: usize, threads: usize, tf: f64, kernel: &str) -> Result<f64, String> {
    let dir = std::env::temp_dir().join(format!("sphrepro-bench-l1-{}-{nx}-{threads}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let set = |kv: String| ["--set".to_string(), kv];
    let mut args =
        vec!["--threads".to_string(), threads.to_string(), "simulate".into(), "taylor_green".into()];
    for kv in [
        format!("nx={nx}"),
        "re=100".into(),
        "scheme=edac".into(),
        format!("kernel={kernel}"),
        format!("tf={tf}"),
        format!("output_dt={tf}"),
    ] {
        args.extend(set(kv));
    }
    args.extend(["--quiet".into(), "--out".into(), dir.display().to_string()]);
    let out = std::process::Command::new(exe).args(&args).output().map_err(|e| e.to_string())?;
    let summary = std::fs::read(dir.join("summary.json"));
    let _ = std::fs::remove_dir_all(&dir);
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).trim().to_string());
    }
    let v: serde_json::Value = serde_json::from_slice(&summary.map_err(|e| e.to_string())?)
        .map_err(|e| format!("summary.json: {e}"))?;
    v["metrics"]["l1_velocity_final"]
        .as_f64()
        .ok_or_else(|| "summary.json: no `l1_velocity_final`".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peers_run_t_2_where_it_is_cheap_and_about_70_million_particle_steps_beyond() {
        assert_eq!(peer_tf(50), 2.0);
        for nx in [200, 400] {
            let steps = peer_tf(nx) * 44.0 * nx as f64;
            let particle_steps = steps * (nx * nx) as f64;
            assert!((particle_steps - 7.0e7).abs() < 1.0, "nx = {nx}: {particle_steps}");
        }
    }

    #[test]
    fn a_peer_report_is_read_from_its_last_json_line() {
        let out = "installing...\n{\"peer\": \"pysph-1.0b2\", \"particle_steps_per_second\": 3.3e5}\n";
        let p = parse_peer(out, 50, 2, 2.0).unwrap();
        assert_eq!(
            (p.peer.as_str(), p.particle_steps_per_second, p.nx, p.threads),
            ("pysph-1.0b2", 3.3e5, 50, 2)
        );
        assert_eq!((p.end_time(), p.l1_velocity_final), (2.0, None));
        let out = "{\"particle_steps_per_second\": 3.3e5, \"l1_velocity_final\": 0.02, \"t_final\": 2.0003}";
        let p = parse_peer(out, 50, 2, 2.0).unwrap();
        assert_eq!((p.end_time(), p.l1_velocity_final), (2.0003, Some(0.02)));
        assert!(parse_peer("no json", 50, 2, 2.0).is_err());
        assert!(parse_peer("{\"particle_steps_per_second\": 0}", 50, 2, 2.0).is_err());
    }
}
