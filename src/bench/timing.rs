//! Timing bench cases in this process: one configuration alone (`bench-case`), or the
//! configurations of one size side by side (`bench-interleaved`), with the phase times,
//! IPST iterations and resident memory of each.

use super::case::{case_simulation, schedule_name, warm_up, BenchResult};
use crate::solver::schedule::warm;
use crate::solver::simulation::{PhaseTimes, Schedule, Simulation};
use std::time::Instant;

/// A `/proc/self/status` field in kB (`VmRSS:` now, `VmHWM:` the peak), 0 where there is
/// none.
pub(super) fn status_kb(field: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse().ok())
        })
        .unwrap_or(0)
}

/// What a configuration's timed steps added up to.
#[derive(Default)]
struct Timed {
    seconds: f64,
    steps: u64,
    ipst: usize,
    times: PhaseTimes,
    /// Particle-steps per second of each block of steps.
    runs: Vec<f64>,
    /// How the last step's passes ran.
    schedule: Schedule,
}

impl Timed {
    /// Times `steps` steps of `sim`, adding them up.
    fn steps(&mut self, sim: &mut Simulation<2>, steps: u64) -> Result<(), String> {
        sim.times = Default::default();
        // As a run steps: the pool's other workers polling between the loops (timed once
        // they run).
        let (ipst, seconds) = warm::keep_warm(|| -> Result<(usize, f64), String> {
            let (t0, mut ipst) = (Instant::now(), 0);
            for _ in 0..steps {
                sim.step(f64::INFINITY).map_err(|d| d.reason)?;
                ipst += sim.last_ipst_iterations();
            }
            Ok((ipst, t0.elapsed().as_secs_f64()))
        })?;
        self.ipst += ipst;
        self.seconds += seconds;
        self.steps += steps;
        self.times += sim.times;
        self.runs.push(sim.fluid().len() as f64 * steps as f64 / seconds);
        self.schedule = sim.last_schedule();
        Ok(())
    }

    /// Times `steps` steps of every simulation of `sims` at once, each on its own pool of
    /// `pools` (after one untimed step each, and a barrier, so that they start together),
    /// adding them up as one block of their summed steps over the slowest one's seconds.
    /// The phase times are the first simulation's.
    fn concurrent_steps(
        &mut self,
        sims: &mut [&mut Simulation<2>],
        pools: &[rayon::ThreadPool],
        steps: u64,
    ) -> Result<(), String> {
        let barrier = std::sync::Barrier::new(sims.len());
        let each: Vec<Result<Timed, String>> = std::thread::scope(|s| {
            let handles: Vec<_> = sims
                .iter_mut()
                .zip(pools)
                .map(|(sim, pool)| {
                    let barrier = &barrier;
                    s.spawn(move || {
                        pool.install(|| {
                            let first = sim.step(f64::INFINITY).map_err(|d| d.reason);
                            // Every copy reaches the barrier, even one whose step failed.
                            barrier.wait();
                            first?;
                            let mut timed = Timed::default();
                            timed.steps(sim, steps)?;
                            Ok(timed)
                        })
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap_or_else(|_| Err("a copy panicked".into()))).collect()
        });
        let each = each.into_iter().collect::<Result<Vec<_>, _>>()?;
        let seconds = each.iter().map(|t| t.seconds).fold(0.0, f64::max);
        let all_steps = steps * each.len() as u64;
        self.seconds += seconds;
        self.steps += all_steps;
        self.ipst += each.iter().map(|t| t.ipst).sum::<usize>();
        self.times += each[0].times.scaled(seconds / each[0].seconds);
        self.runs.push(sims[0].fluid().len() as f64 * all_steps as f64 / seconds);
        self.schedule = each[0].schedule;
        Ok(())
    }

    fn result(self, variant: &str, kernel: &str, nx: usize, threads: usize, particles: usize) -> BenchResult {
        BenchResult {
            variant: variant.into(),
            kernel: kernel.into(),
            nx,
            threads,
            copies: 1,
            particles,
            steps: self.steps,
            seconds: self.seconds,
            particle_steps_per_second: particles as f64 * self.steps as f64 / self.seconds,
            peak_rss_bytes: 0,
            bytes_per_particle: 0.0,
            ipst_iterations_mean: self.ipst as f64 / self.steps as f64,
            phase_shares: self.times.scaled(1.0 / self.seconds),
            runs: self.runs,
            schedule: schedule_name(self.schedule).into(),
        }
    }
}

/// Runs one configuration in this process: `warmup` untimed steps of
/// `case_simulation`, then `steps` timed ones.
pub(super) fn run_case(
    variant: &str,
    nx: usize,
    steps: u64,
    warmup: u64,
    kernel: &str,
) -> Result<BenchResult, String> {
    let rss0 = status_kb("VmRSS:") * 1024;
    let mut sim = case_simulation(variant, nx, kernel, warmup)?;
    let mut timed = Timed::default();
    timed.steps(&mut sim, steps)?;
    let n = sim.fluid().len();
    let hwm = status_kb("VmHWM:") * 1024;
    Ok(BenchResult {
        peak_rss_bytes: hwm,
        bytes_per_particle: hwm.saturating_sub(rss0) as f64 / n as f64,
        ..timed.result(variant, kernel, nx, rayon::current_num_threads(), n)
    })
}

/// Times every variant of `variants` on every thread count of `threads` at `nx` side by
/// side in this process (`bench --interleave`): their simulations are built and warmed up
/// (`warmup` steps) together, on every pool each steps on, so that each thread count tunes
/// its own schedule, then stepped in turn, `rounds` times, a block of
/// `steps / rounds` timed steps each (after one untimed step, since the caches then hold
/// the configuration before), each thread count on its own pool; the order of a round is
/// reversed every other round. A slow spell of a noisy machine, even one of seconds, then
/// falls on every configuration alike, and each block's throughput is a run (`runs`), so
/// that every ratio is the median of the rounds' own ratios. A variant's thread counts step
/// the same simulation, whose results do not depend on the thread count. When one thread is
/// among `threads`, every larger count k also gets a configuration of k copies of the
/// simulation stepped at once on one thread each (`copies`): the speed-up the host allows
/// independent runs, against which the k-thread speed-up is read. Memory: the
/// resident growth while a simulation was built and warmed (`bytes_per_particle`), and the
/// process's peak with all of them (`peak_rss_bytes`).
pub(super) fn run_interleaved(
    variants: &[String],
    nx: usize,
    threads: &[usize],
    steps: u64,
    rounds: u32,
    warmup: u64,
    kernel: &str,
) -> Result<Vec<BenchResult>, String> {
    let pool = |t: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| format!("cannot start a thread pool: {e}"))
    };
    let pools = threads.iter().map(|&t| pool(t)).collect::<Result<Vec<_>, _>>()?;
    let widest = pools.iter().max_by_key(|p| p.current_num_threads()).ok_or("no thread count")?;
    let copy_counts: Vec<usize> =
        if threads.contains(&1) { threads.iter().copied().filter(|&t| t > 1).collect() } else { Vec::new() };
    let most_copies = copy_counts.iter().copied().max().unwrap_or(1);
    let solo = (0..most_copies).map(|_| pool(1)).collect::<Result<Vec<_>, _>>()?;
    // Each variant's simulation and the further copies of it, with the resident growth of
    // building the first.
    let mut sims = Vec::new();
    for v in variants {
        let rss0 = status_kb("VmRSS:") * 1024;
        let mut sim = widest.install(|| case_simulation(v, nx, kernel, warmup))?;
        let grown = (status_kb("VmRSS:") * 1024).saturating_sub(rss0);
        // Warmed up, and tuned, on every pool it steps on: the faster schedule depends on
        // the number of threads.
        for pool in pools.iter().filter(|p| p.current_num_threads() != widest.current_num_threads()) {
            pool.install(|| warm_up(&mut sim, warmup))?;
        }
        let copies = (1..most_copies)
            .map(|_| {
                let mut copy = widest.install(|| case_simulation(v, nx, kernel, warmup))?;
                solo[0].install(|| warm_up(&mut copy, warmup))?;
                Ok(copy)
            })
            .collect::<Result<Vec<_>, String>>()?;
        sims.push((sim, copies, grown));
    }
    let block = steps.div_ceil(rounds as u64).max(1);
    // Each variant on the pool of every thread count, then as its copies.
    let configs: Vec<(usize, On)> = (0..sims.len())
        .flat_map(|v| {
            let on_pools = (0..pools.len()).map(move |t| (v, On::Pool(t)));
            on_pools.chain(copy_counts.iter().map(move |&k| (v, On::Copies(k))))
        })
        .collect();
    let mut timed: Vec<Timed> = configs.iter().map(|_| Timed::default()).collect();
    for round in 0..rounds {
        let mut order: Vec<usize> = (0..configs.len()).collect();
        if round % 2 == 1 {
            order.reverse();
        }
        for c in order {
            let (v, on) = configs[c];
            let (sim, more, _) = &mut sims[v];
            match on {
                On::Pool(t) => pools[t].install(|| -> Result<(), String> {
                    sim.step(f64::INFINITY).map_err(|d| d.reason)?;
                    timed[c].steps(sim, block)
                })?,
                On::Copies(k) => {
                    let mut all: Vec<&mut Simulation<2>> =
                        std::iter::once(sim).chain(more.iter_mut()).collect();
                    timed[c].concurrent_steps(&mut all[..k], &solo[..k], block)?;
                }
            }
        }
    }
    let hwm = status_kb("VmHWM:") * 1024;
    Ok(configs
        .iter()
        .zip(timed)
        .map(|(&(v, on), timed)| {
            let (sim, _, grown) = &sims[v];
            let n = sim.fluid().len();
            let (threads, copies) = match on {
                On::Pool(t) => (threads[t], 1),
                On::Copies(k) => (1, k),
            };
            BenchResult {
                peak_rss_bytes: hwm,
                bytes_per_particle: *grown as f64 / n as f64,
                copies,
                ..timed.result(&variants[v], kernel, nx, threads, n)
            }
        })
        .collect())
}

/// Where an interleaved configuration runs: on the pool of `threads[t]`, or as k copies
/// stepped at once on one-thread pools.
#[derive(Clone, Copy)]
enum On {
    Pool(usize),
    Copies(usize),
}

#[cfg(test)]
mod tests {
    use super::super::case::DEFAULT_KERNEL;
    use super::*;

    /// Side by side: one result per variant and thread count, then the variant's two
    /// copies on one thread each (twice the steps in the same blocks), in the order of the
    /// table, with one run per round and the block's steps added up; IPST at its cap.
    #[test]
    fn interleaved_cases_report_one_run_a_round() {
        let variants = ["edac".to_string(), "ctvf+ipst".to_string()];
        let r = run_interleaved(&variants, 12, &[1, 2], 5, 2, 1, DEFAULT_KERNEL).unwrap();
        let got: Vec<_> =
            r.iter().map(|r| (r.variant.as_str(), r.threads_label(), r.steps, r.runs.len())).collect();
        let row = |v, t: &str, steps| (v, t.to_string(), steps, 2);
        assert_eq!(
            got,
            [
                row("edac", "1", 6),
                row("edac", "2", 6),
                row("edac", "2 x 1", 12),
                row("ctvf+ipst", "1", 6),
                row("ctvf+ipst", "2", 6),
                row("ctvf+ipst", "2 x 1", 12)
            ]
        );
        for r in &r {
            assert_eq!(r.particles, 144);
            assert!(r.particle_steps_per_second > 0.0 && r.runs.iter().all(|&s| s > 0.0));
            // Every block's particle-steps over its seconds: the runs' harmonic mean.
            let hm = r.runs.len() as f64 / r.runs.iter().map(|s| 1.0 / s).sum::<f64>();
            assert!((hm / r.particle_steps_per_second - 1.0).abs() < 1e-9, "{r:?}");
        }
        assert_eq!(
            (r[0].ipst_iterations_mean, r[3].ipst_iterations_mean, r[5].ipst_iterations_mean),
            (0.0, 10.0, 10.0)
        );
        // Without one thread among the counts there is no speed-up to bound: no copies.
        let two = run_interleaved(&variants[..1], 12, &[2], 2, 2, 0, DEFAULT_KERNEL).unwrap();
        assert_eq!(two.iter().map(|r| r.copies).collect::<Vec<_>>(), [1]);
        assert!(run_interleaved(&["sph".to_string()], 12, &[1], 2, 2, 0, DEFAULT_KERNEL).is_err());
    }
}
