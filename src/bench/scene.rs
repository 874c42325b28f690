//! `bench --scene NAME [--set key=value ...]`: the throughput and memory of any registered
//! scene at the parameters given (its defaults otherwise), at each thread count, in a process
//! of its own per run (`bench-scene`). The Taylor-Green variants measure the fluid's passes
//! on a periodic box; a scene measures everything its run does per step: walls, free
//! surface, a structure's sub-steps, the scene's own probes.
//!
//! A step is a step of the scene's time loop (the fluid's, where there is one), and the
//! particle-steps count every particle of every body once per such step, as `simulate`'s
//! summary does: a structure's sub-steps are inside the step's cost, not counted as steps.

use super::case::{default_steps, WARMUP};
use super::process::{bench_child, print_json};
use super::stats::{median_runs, throughput_and_runs, Repeated};
use super::timing::status_kb;
use crate::scenes::{self, SceneRun};
use crate::solver::output::summary::Provenance;
use crate::solver::output::write_atomic;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// One timed run of a scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct SceneResult {
    /// The scene's name.
    pub scene: String,
    /// The parameters given (`key=value`), the rest at the scene's defaults.
    pub sets: Vec<String>,
    /// Rayon threads.
    pub threads: usize,
    /// Particles of every body.
    pub particles: usize,
    /// Particles per body, by name.
    pub bodies: Vec<(String, usize)>,
    /// Timed steps (after the warm-up).
    pub steps: u64,
    /// Simulated time at the start and at the end of the timed steps (s).
    pub time: (f64, f64),
    /// Seconds of the timed steps.
    pub seconds: f64,
    /// particles x steps / seconds.
    pub particle_steps_per_second: f64,
    /// Peak resident memory of the process (bytes).
    pub peak_rss_bytes: u64,
    /// (peak resident memory - resident memory before the scene was built) / particles.
    pub bytes_per_particle: f64,
    /// Particle-steps per second of every run of its thread count, in a table's median run
    /// ([`median_runs`]); empty in the JSON's list of every run.
    #[serde(default)]
    pub runs: Vec<f64>,
}

impl Repeated for SceneResult {
    /// One scene at one set of parameters per bench: its runs differ in threads alone.
    type Key = usize;
    fn key(&self) -> Self::Key {
        self.threads
    }
    throughput_and_runs!();
}

/// Steps `run` `n` more steps (fewer if it reaches the scene's end time `tf` first);
/// returns how many it took. A divergence is an error naming its time.
fn steps(run: &mut dyn SceneRun, n: u64, tf: f64) -> Result<u64, String> {
    let start = run.steps();
    run.advance(tf, tf, &mut |_, s| s - start < n)
        .map_err(|d| format!("diverged at t = {:.6} (step {}): {}", d.time, d.step, d.reason))?;
    Ok(run.steps() - start)
}

/// Builds `scene` from `sets`, steps it [`WARMUP`] steps untimed, then times `steps` steps
/// (default: about 4 million particle-steps) in this process.
pub(super) fn time_scene(
    scene: &str,
    sets: &[String],
    steps_wanted: Option<u64>,
) -> Result<SceneResult, String> {
    let entry = scenes::find(scene)?;
    let params = entry.params_from_sets(sets)?;
    let tf = params.float("tf");
    let before = status_kb("VmRSS:");
    let mut run = (entry.build)(&params)?;
    let particles = run.particles();
    let wanted = steps_wanted.unwrap_or_else(|| default_steps(particles));
    let warm = steps(run.as_mut(), WARMUP, tf)?;
    let t0 = run.time();
    let clock = Instant::now();
    let taken = steps(run.as_mut(), wanted, tf)?;
    let seconds = clock.elapsed().as_secs_f64();
    if taken < wanted {
        return Err(format!(
            "scene `{scene}` reached tf = {tf} s after {} of the {} steps (warm-up and timed): set a larger `tf`",
            warm + taken,
            WARMUP + wanted
        ));
    }
    let peak = status_kb("VmHWM:");
    Ok(SceneResult {
        scene: scene.into(),
        sets: sets.to_vec(),
        threads: rayon::current_num_threads(),
        particles,
        bodies: run.body_particles(),
        steps: taken,
        time: (t0, run.time()),
        seconds,
        particle_steps_per_second: particles as f64 * taken as f64 / seconds,
        peak_rss_bytes: peak * 1024,
        bytes_per_particle: peak.saturating_sub(before) as f64 * 1024.0 / particles as f64,
        runs: Vec::new(),
    })
}

/// `bench-scene`: one run timed in this process, printed as one JSON line; the exit code.
pub fn scene_child(scene: &str, sets: &[String], steps: Option<u64>) -> u8 {
    print_json(time_scene(scene, sets, steps))
}

/// What `bench --scene` measures.
pub struct SceneOptions<'a> {
    /// The scene's name.
    pub scene: &'a str,
    /// Its parameters (`key=value`).
    pub sets: &'a [String],
    /// Thread counts.
    pub threads: &'a [usize],
    /// Timed steps per run; `None`: about 4 million particle-steps.
    pub steps: Option<u64>,
    /// Runs per thread count, in as many rounds over the thread counts.
    pub repeat: u32,
    /// Where the results go as JSON.
    pub json: &'a Path,
}

/// `bench --scene`: every thread count `repeat` times in rounds, each run in a process of
/// its own; prints the median run per thread count with the range and the speed-up over
/// the fewest threads, and writes every run to the JSON. The exit code: 0, 1 when a run
/// failed (what ran before it is still reported and written) or the JSON cannot be
/// written, 2 on bad options.
pub fn run_scene(o: &SceneOptions) -> u8 {
    let started = chrono::Utc::now();
    // The scene and its parameters are checked before the first run, as `build` would.
    let checked = scenes::find(o.scene).and_then(|e| (e.check)(&e.params_from_sets(o.sets)?));
    if let Err(e) = checked {
        crate::errln!("error: bench: {e}");
        return 2;
    }
    let exe = std::env::current_exe().expect("own executable");
    let mut runs: Vec<SceneResult> = Vec::new();
    let mut failure = None;
    'rounds: for _ in 0..o.repeat {
        for &t in o.threads {
            let t_arg = t.to_string();
            let mut args = vec!["--threads", &t_arg, "bench-scene", "--scene", o.scene];
            for s in o.sets {
                args.extend(["--set", s.as_str()]);
            }
            let steps_arg = o.steps.map(|s| s.to_string());
            if let Some(s) = &steps_arg {
                args.extend(["--steps", s.as_str()]);
            }
            match bench_child::<SceneResult>(&exe, &args) {
                Ok(r) => runs.push(r),
                Err(e) => {
                    failure = Some(format!("{} on {t} thread(s): {e}", o.scene));
                    break 'rounds;
                }
            }
        }
    }
    if runs.is_empty() {
        // Nothing measured: an earlier results file is left as it was.
        crate::errln!("error: bench: {}", failure.unwrap_or_default());
        return 1;
    }
    crate::outln!("{}", table(&runs));
    let provenance = Provenance::now(started);
    let doc = serde_json::json!({ "provenance": provenance, "scene": o.scene, "runs": runs });
    let text = serde_json::to_string_pretty(&doc).expect("serialises");
    let written = o
        .json
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .and_then(|_| write_atomic(o.json, text.as_bytes()));
    if let Err(e) = written {
        crate::errln!("error: bench: cannot write {}: {e}", o.json.display());
        return 1;
    }
    crate::outln!("wrote {}", o.json.display());
    match failure {
        Some(e) => {
            crate::errln!("error: bench: {e}");
            1
        }
        None => 0,
    }
}

/// The Markdown table of `runs`: per thread count, the median run (as `bench` takes it for
/// every case: [`median_runs`]) with its throughput, the range over the runs, its memory,
/// and the speed-up of its throughput over the fewest threads'.
fn table(runs: &[SceneResult]) -> String {
    let mut medians = median_runs(runs.to_vec());
    medians.sort_by_key(|r| r.threads);
    let mut s = String::from(
        "| scene | particles | threads | steps | particle-steps/s (median) | range | speed-up | peak MB | bytes/particle |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let base = medians.first().map_or(1.0, |r| r.particle_steps_per_second);
    for r in &medians {
        let m = r.particle_steps_per_second;
        let lo = r.runs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = r.runs.iter().copied().fold(0.0, f64::max);
        s += &format!(
            "| {} | {} | {} | {} | {m:.3e} | {lo:.3e} - {hi:.3e} | {:.2} | {:.0} | {:.0} |\n",
            r.scene,
            r.particles,
            r.threads,
            r.steps,
            m / base,
            r.peak_rss_bytes as f64 / 1e6,
            r.bytes_per_particle
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene timed in this process: its particles and steps as asked, a throughput that is
    /// particles x steps / seconds; a run that reaches its end time first is refused.
    #[test]
    fn a_scene_is_timed_for_the_steps_asked() {
        let sets = ["nx=12".to_string(), "tf=1".to_string()];
        let r = time_scene("taylor_green", &sets, Some(5)).unwrap();
        assert_eq!((r.steps, r.particles), (5, 144));
        let expect = r.particles as f64 * r.steps as f64 / r.seconds;
        assert!((r.particle_steps_per_second - expect).abs() <= 1e-9 * expect);
        assert!(r.time.1 > r.time.0);
        let short = ["nx=12".to_string(), "tf=0.001".to_string()];
        let e = time_scene("taylor_green", &short, Some(500)).unwrap_err();
        assert!(e.contains("reached tf = 0.001") && e.contains("set a larger `tf`"), "{e}");
        assert!(time_scene("no_such_scene", &[], Some(1)).unwrap_err().contains("unknown scene"));
    }

    /// The table gives the median per thread count and the speed-up over the fewest threads.
    #[test]
    fn the_table_gives_medians_and_speed_up() {
        let run = |threads, pss| SceneResult {
            scene: "s".into(),
            sets: vec![],
            threads,
            particles: 100,
            bodies: vec![],
            steps: 10,
            time: (0.0, 1.0),
            seconds: 1.0,
            particle_steps_per_second: pss,
            peak_rss_bytes: 50_000_000,
            bytes_per_particle: 1000.0,
            runs: vec![],
        };
        let t = table(&[
            run(1, 1.0e6),
            run(2, 1.6e6),
            run(1, 3.0e6),
            run(2, 4.0e6),
            run(1, 2.0e6),
            run(2, 3.0e6),
        ]);
        assert!(t.contains("| s | 100 | 1 | 10 | 2.000e6 | 1.000e6 - 3.000e6 | 1.00 | 50 | 1000 |"), "{t}");
        assert!(t.contains("| s | 100 | 2 | 10 | 3.000e6 | 1.600e6 - 4.000e6 | 1.50 |"), "{t}");
    }
}
