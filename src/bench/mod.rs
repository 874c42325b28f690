//! `sphrepro bench`: throughput (particle-steps per second) and peak memory per particle
//! of the Taylor-Green vortex for `edac`, `ctvf`+`sun` and `ctvf`+`ipst`, over resolutions
//! and thread counts. Each configuration runs in its own process (`bench-case`), so its
//! peak resident memory is its own; or, with `--interleave`, the configurations of a size
//! run side by side in one process (`bench-interleaved`), stepped in turn, so that the
//! machine's slow spells fall on all of them alike.

pub mod targets;

use crate::scenes::taylor_green;
use crate::solver::schedule::warm;
use crate::solver::simulation::{PhaseTimes, Schedule, Simulation};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// What a peer code (e.g. `../shared/peers/pysph-taylor-green.sh`) reported for one
/// resolution and thread count, run in the same sitting.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PeerResult {
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
    pub fn end_time(&self) -> f64 {
        self.t_final.unwrap_or(self.tf)
    }
}

/// The simulated time a peer runs at resolution `nx`: t = 2 (the Taylor-Green run)
/// while that is under about 70 million particle-steps (dt = 0.25 h / 11 with h = 1/nx),
/// shorter beyond, so that each peer run takes a minute or two.
pub fn peer_tf(nx: usize) -> f64 {
    let steps_per_unit_time = 44.0 * nx as f64;
    (7.0e7 / ((nx * nx) as f64 * steps_per_unit_time)).min(2.0)
}

/// Reads a peer's one-line JSON report (`particle_steps_per_second`, `peer`, and if there,
/// `t_final` and `l1_velocity_final`).
pub fn parse_peer(stdout: &str, nx: usize, threads: usize, tf: f64) -> Result<PeerResult, String> {
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

/// One measured configuration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchResult {
    /// `edac`, `ctvf+sun`, `ctvf+ipst`.
    pub variant: String,
    /// The kernel (h/dx = 1).
    pub kernel: String,
    /// Particles per side.
    pub nx: usize,
    /// Rayon threads.
    pub threads: usize,
    /// Simulations stepped at once, each on its own pool of `threads` threads, with their
    /// throughputs summed (`bench --interleave`): k copies on one thread each give what the
    /// host lets k independent runs do together, the ceiling of a k-thread speed-up on a
    /// machine whose cores slow each other down (shared caches, memory, a hypervisor).
    #[serde(default = "one_copy")]
    pub copies: usize,
    /// Particle count (of one copy).
    pub particles: usize,
    /// Timed steps (after warm-up).
    pub steps: u64,
    /// Seconds of the timed steps.
    pub seconds: f64,
    /// particles x steps / seconds.
    pub particle_steps_per_second: f64,
    /// Peak resident memory of the process (bytes).
    pub peak_rss_bytes: u64,
    /// (peak resident memory - resident memory before the scene was built) / particles.
    pub bytes_per_particle: f64,
    /// Mean IPST iterations per step (0 without IPST).
    pub ipst_iterations_mean: f64,
    /// Share of the timed steps spent in each phase.
    pub phase_shares: crate::solver::simulation::PhaseTimes,
    /// How the last timed step's passes ran ([`schedule_name`]): for a variant without a
    /// suffix of [`SCHEDULES`], the order the tuner kept.
    #[serde(default)]
    pub schedule: String,
    /// Particle-steps per second of every run of this configuration (`bench --repeat`), in
    /// the order they ran; the fields above are those of the median run (see
    /// [`median_runs`]).
    #[serde(default)]
    pub runs: Vec<f64>,
}

fn one_copy() -> usize {
    1
}

impl BenchResult {
    /// The thread count as the table gives it: `k x 1` for k copies on one thread each.
    pub fn threads_label(&self) -> String {
        if self.copies > 1 {
            format!("{} x {}", self.copies, self.threads)
        } else {
            self.threads.to_string()
        }
    }
}

/// A timed run that may be repeated: what makes two runs the same configuration, its
/// throughput, and where the throughputs of all its runs go.
pub trait Repeated: Clone {
    /// The configuration.
    type Key: PartialEq;
    /// The configuration of this run.
    fn key(&self) -> Self::Key;
    /// Its particle-steps per second.
    fn speed(&self) -> f64;
    /// The throughputs of every run of its configuration (after [`median_runs`]).
    fn runs(&self) -> &[f64];
    /// The same, to be set.
    fn runs_mut(&mut self) -> &mut Vec<f64>;
}

/// The [`Repeated`] methods of a result that holds its `particle_steps_per_second` and the
/// `runs` of its configuration (ours and the peer's alike).
macro_rules! throughput_and_runs {
    () => {
        fn speed(&self) -> f64 {
            self.particle_steps_per_second
        }
        fn runs(&self) -> &[f64] {
            &self.runs
        }
        fn runs_mut(&mut self) -> &mut Vec<f64> {
            &mut self.runs
        }
    };
}

impl Repeated for BenchResult {
    type Key = (String, String, usize, usize, usize);
    fn key(&self) -> Self::Key {
        (self.variant.clone(), self.kernel.clone(), self.nx, self.threads, self.copies)
    }
    throughput_and_runs!();
}

impl Repeated for PeerResult {
    type Key = (usize, usize);
    fn key(&self) -> Self::Key {
        (self.nx, self.threads)
    }
    throughput_and_runs!();
}

/// One result per configuration from repeated runs of each, in the order the
/// configurations first appear: the run of median throughput (of an even count, the slower
/// of the two middle ones), so that its phase shares and memory belong to the throughput
/// reported, with every run's throughput in `runs`. A slow spell of the machine then moves
/// the reported figure only if it lasts through half the runs.
pub fn median_runs<T: Repeated>(samples: Vec<T>) -> Vec<T> {
    let mut groups: Vec<Vec<T>> = Vec::new();
    for r in samples {
        match groups.iter_mut().find(|g| g[0].key() == r.key()) {
            Some(g) => g.push(r),
            None => groups.push(vec![r]),
        }
    }
    groups
        .into_iter()
        .map(|g| {
            let runs: Vec<f64> = g.iter().map(T::speed).collect();
            let mut order: Vec<usize> = (0..g.len()).collect();
            order.sort_by(|&a, &b| runs[a].total_cmp(&runs[b]));
            let mut median = g[order[(g.len() - 1) / 2]].clone();
            *median.runs_mut() = runs;
            median
        })
        .collect()
}

/// The kernel of the cases unless `--kernel` names another: the paper's and PySPH's.
pub const DEFAULT_KERNEL: &str = "quintic_spline";

/// The variants benchmarked: (name, scheme, pst).
pub const VARIANTS: &[(&str, &str, &str)] =
    &[("edac", "edac", "none"), ("ctvf+sun", "ctvf", "sun"), ("ctvf+ipst", "ctvf", "ipst")];

/// The suffixes of a variant that fix the order of its step's passes (`edac/sweeps`,
/// `edac/wavefront`: the same results, for timing them side by side); without one, the
/// step takes the faster on this host ([`Schedule::Tuned`]).
pub const SCHEDULES: &[(&str, Schedule)] =
    &[("/sweeps", Schedule::Sweeps), ("/wavefront", Schedule::Wavefront)];

/// A schedule's name in bench results: its suffix in [`SCHEDULES`] without the slash.
pub fn schedule_name(schedule: Schedule) -> &'static str {
    SCHEDULES.iter().find(|s| s.1 == schedule).map_or("tuned", |s| &s.0[1..])
}

/// A variant's entry of [`VARIANTS`] (name, scheme, pst) and its schedule, if it is one of
/// them, optionally with a suffix of [`SCHEDULES`].
fn lookup_variant(variant: &str) -> Option<(&'static (&'static str, &'static str, &'static str), Schedule)> {
    let (base, schedule) = SCHEDULES
        .iter()
        .find_map(|&(suffix, s)| variant.strip_suffix(suffix).map(|base| (base, s)))
        .unwrap_or((variant, Schedule::Tuned));
    VARIANTS.iter().find(|v| v.0 == base).map(|v| (v, schedule))
}

/// Whether `variant` is one of [`VARIANTS`], optionally with a suffix of [`SCHEDULES`].
pub fn known_variant(variant: &str) -> bool {
    lookup_variant(variant).is_some()
}

fn status_kb(field: &str) -> u64 {
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

/// The simulation a bench case times: Taylor-Green of `variant` at `nx` with `kernel`
/// (Re = 100, h/dx = 1), from a lattice perturbed by 5 % of dx. IPST is timed at its
/// iteration cap (10 moves a step, with a tolerance it never meets): a developed
/// Taylor-Green flow sits there (measured at nx = 50 and 100: from t = 0.09 on, every step
/// makes the 10 moves), while the first steps of a run barely iterate, so timing those would
/// understate its cost.
/// A variant may end in a suffix of [`SCHEDULES`]. It is returned after `warmup` untimed
/// steps, in which a tuned schedule has made its choice.
fn case_simulation(variant: &str, nx: usize, kernel: &str, warmup: u64) -> Result<Simulation<2>, String> {
    let ((_, scheme, pst), schedule) =
        lookup_variant(variant).ok_or_else(|| format!("unknown bench variant `{variant}`"))?;
    let (nx, scheme, kernel) = (format!("nx={nx}"), format!("scheme={scheme}"), format!("kernel={kernel}"));
    let pst_set = format!("pst={pst}");
    let mut sets =
        vec![nx.as_str(), scheme.as_str(), pst_set.as_str(), kernel.as_str(), "re=100", "perturb=0.05"];
    if *pst == "ipst" {
        sets.push("ipst_tol=1e-12");
    }
    let p = taylor_green::params_from(&sets)?;
    let mut sim = taylor_green::simulation::<2>(&p)?;
    sim.set_schedule(schedule);
    warm_up(&mut sim, warmup)?;
    Ok(sim)
}

/// `warmup` untimed steps of `sim` on the current pool.
fn warm_up(sim: &mut Simulation<2>, warmup: u64) -> Result<(), String> {
    for _ in 0..warmup {
        sim.step(f64::INFINITY).map_err(|d| d.reason)?;
    }
    Ok(())
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
pub fn run_case(
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
pub fn run_interleaved(
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

/// Steps to time for `n` particles: about 4 million particle-steps, at least 20 steps.
pub fn default_steps(n: usize) -> u64 {
    ((4.0e6 / n as f64) as u64).max(20)
}

/// The peer resolution of the figure to beat: PySPH's Taylor-Green at nx = 50.
pub const FIGURE_TO_BEAT_NX: usize = 50;

/// A throughput in millions, with the range over `runs` when there were several.
fn millions(speed: f64, runs: &[f64]) -> String {
    let lo = runs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = runs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if runs.len() > 1 {
        format!("{:.3} ({:.3}-{:.3})", speed / 1e6, lo / 1e6, hi / 1e6)
    } else {
        format!("{:.3}", speed / 1e6)
    }
}

/// The ratio `a / b` of two throughputs over a sitting: with as many runs of each (`bench
/// --repeat`, or the rounds of `--interleave`), the median of the rounds' own ratios, since
/// a slow spell of a noisy machine that falls on both runs of a round cancels in their
/// ratio, with their range (how far a target holds in single rounds) and, from six rounds
/// on, the 95 % confidence interval of that median ([`median_interval`]: whether a target
/// holds in the median); otherwise the ratio of the two (median) runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Ratio {
    /// The median of the rounds' ratios (of an even count, the mean of the two middle
    /// ones), or the ratio of the median runs.
    pub median: f64,
    /// The 95 % confidence interval of the median, from six rounds on.
    pub interval: Option<(f64, f64)>,
    /// The smallest and largest ratio of a round.
    pub range: (f64, f64),
    /// Rounds compared (1: the median runs only).
    pub rounds: usize,
}

impl Ratio {
    /// `a / b`, round by round where both ran as many rounds.
    pub fn of(a: &impl Repeated, b: &impl Repeated) -> Self {
        let (a_runs, b_runs) = (a.runs(), b.runs());
        if a_runs.len() < 2 || a_runs.len() != b_runs.len() {
            return Self::single(a.speed() / b.speed());
        }
        let mut rounds: Vec<f64> = a_runs.iter().zip(b_runs).map(|(a, b)| a / b).collect();
        rounds.sort_by(f64::total_cmp);
        let n = rounds.len();
        Self {
            // Of an even count, the mean of the two middle ratios (neither favoured).
            median: (rounds[(n - 1) / 2] + rounds[n / 2]) / 2.0,
            interval: median_interval(&rounds),
            range: (rounds[0], rounds[n - 1]),
            rounds: n,
        }
    }

    /// One value, not a ratio of rounds: the ratio of two median runs, an L1 error ratio, a
    /// fitted exponent.
    pub fn single(v: f64) -> Self {
        Self { median: v, interval: None, range: (v, v), rounds: 1 }
    }

    /// As the table gives it: `digits` decimals and a `suffix`, then the interval in
    /// brackets and the range in parentheses when there were rounds.
    pub fn format(&self, digits: usize, suffix: &str) -> String {
        let median = self.median;
        if self.rounds < 2 {
            return format!("{median:.digits$}{suffix}");
        }
        let interval = self.interval.map_or(String::new(), |(l, h)| format!(" [{l:.digits$}-{h:.digits$}]"));
        let (lo, hi) = self.range;
        format!("{median:.digits$}{suffix}{interval} ({lo:.digits$}-{hi:.digits$})")
    }
}

/// [`Ratio::of`] `a / b`, formatted ([`Ratio::format`]).
fn ratio(a: &impl Repeated, b: &impl Repeated, digits: usize, suffix: &str) -> String {
    Ratio::of(a, b).format(digits, suffix)
}

/// A 95 % confidence interval of the median of the `sorted` samples, free of any assumption
/// on their distribution: the `k`-th smallest and the `k`-th largest, with `k` the largest
/// count for which fewer than `k` of `n` samples fall below the median with a probability
/// of at most 2.5 % (binomial, p = 1/2), so that the interval covers the median with at
/// least 95 %. None below six samples, where even the extremes cover less.
pub fn median_interval(sorted: &[f64]) -> Option<(f64, f64)> {
    let n = sorted.len();
    // ln P(X = k) for X ~ B(n, 1/2), from k = 0 up (in logarithms: n may be large).
    let mut ln_p = -(n as f64) * std::f64::consts::LN_2;
    let (mut k, mut below) = (0, 0.0);
    while k < n / 2 && below + ln_p.exp() <= 0.025 {
        below += ln_p.exp();
        ln_p += ((n - k) as f64).ln() - ((k + 1) as f64).ln();
        k += 1;
    }
    (k > 0).then(|| (sorted[k - 1], sorted[n - k]))
}

/// The benchmark table as Markdown (throughput of the median run, with the range over the
/// runs when there were several), with the throughput of each variant relative to
/// `edac` on the same size and threads, and the two-thread speed-up; with peer results, the
/// peer's throughput and our ratio to it on the same size and threads, our ratio to the
/// peer's run at [`FIGURE_TO_BEAT_NX`] on the same threads (the issue states one figure to
/// beat, PySPH at nx = 50, and targets multiples of it at every size; this column reads the targets that
/// way, the one before it against the peer at each size), and both L1 velocity errors at
/// the peer's end time. Ratios of repeated runs are those of each round (see `ratio`).
pub fn table(results: &[BenchResult], peers: &[PeerResult]) -> String {
    let mut s = String::from(
        "| variant | nx | particles | threads | steps | Mparticle-steps/s | ns/particle-step | bytes/particle | cost vs edac | speed-up vs 1 thread | IPST iters | step order | time: neighbours/density/pressure/accel/ipst/integrate (%) |",
    );
    if !peers.is_empty() {
        s.push_str(&format!(
            " peer Mparticle-steps/s | ratio to peer | ratio to peer at nx = {FIGURE_TO_BEAT_NX} | L1 at the peer's end time: peer / edac (%) |"
        ));
    }
    s.push_str("\n|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    if !peers.is_empty() {
        s.push_str("---|---|---|---|");
    }
    s.push('\n');
    for r in results {
        let edac = results
            .iter()
            .find(|e| e.variant == "edac" && e.nx == r.nx && e.threads == r.threads && e.copies == r.copies);
        let one = results
            .iter()
            .find(|e| e.variant == r.variant && e.nx == r.nx && e.threads == 1 && e.copies == 1);
        let cost = match edac {
            Some(e) if std::ptr::eq(e, r) => "1.00".to_string(),
            Some(e) => ratio(e, r, 2, ""),
            None => String::new(),
        };
        // Of k copies on one thread each, the speed-up the host allows k independent runs.
        let speedup = if r.threads * r.copies > 1 {
            one.map(|o| ratio(r, o, 2, "")).unwrap_or_default()
        } else {
            String::new()
        };
        let p = &r.phase_shares;
        let shares = format!(
            "{:.0}/{:.0}/{:.0}/{:.0}/{:.0}/{:.0}",
            100.0 * p.neighbours,
            100.0 * p.density,
            100.0 * p.pressure,
            100.0 * p.accelerations,
            100.0 * p.ipst,
            100.0 * p.integrate
        );
        let speed = millions(r.particle_steps_per_second, &r.runs);
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {} | {} | {:.2} | {} | {} |\n",
            r.variant,
            r.nx,
            r.particles,
            r.threads_label(),
            r.steps,
            speed,
            1e9 / r.particle_steps_per_second,
            r.bytes_per_particle,
            cost,
            speedup,
            r.ipst_iterations_mean,
            r.schedule,
            shares
        ));
        if !peers.is_empty() {
            match peers.iter().find(|p| p.nx == r.nx && p.threads == r.threads && r.copies == 1) {
                Some(p) => {
                    let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.2}", 100.0 * v));
                    let l1 = if r.variant == "edac" {
                        format!(
                            "{} / {} (t = {:.4})",
                            pct(p.l1_velocity_final),
                            pct(p.sphrepro_l1_velocity_final),
                            p.end_time()
                        )
                    } else {
                        String::new()
                    };
                    let at_50 = peers
                        .iter()
                        .find(|q| q.nx == FIGURE_TO_BEAT_NX && q.threads == r.threads)
                        .map_or(String::new(), |q| ratio(r, q, 1, "x"));
                    let to_peer = ratio(r, p, 1, "x");
                    s.insert_str(
                        s.len() - 1,
                        &format!(
                            " {} | {to_peer} | {at_50} | {l1} |",
                            millions(p.particle_steps_per_second, &p.runs)
                        ),
                    )
                }
                None => s.insert_str(s.len() - 1, "  |  |  |  |"),
            }
        }
    }
    for k in results.iter().map(|r| r.copies).filter(|&k| k > 1).collect::<std::collections::BTreeSet<_>>() {
        s.push_str(&format!(
            "\n`{k} x 1`: {k} copies of the case stepped at once, on one thread each, their throughputs \
             summed: their speed-up is what this host gives {k} independent runs, the ceiling of \
             the {k}-thread one.\n"
        ));
    }
    s
}

#[cfg(test)]
mod peer_tests {
    use super::*;

    /// A measured configuration with nothing but its name and throughput.
    pub(super) fn sample(variant: &str, nx: usize, threads: usize, speed: f64) -> BenchResult {
        BenchResult {
            variant: variant.into(),
            kernel: DEFAULT_KERNEL.into(),
            nx,
            threads,
            copies: 1,
            particles: nx * nx,
            steps: 100,
            seconds: 1.0,
            particle_steps_per_second: speed,
            peak_rss_bytes: 0,
            bytes_per_particle: 0.0,
            ipst_iterations_mean: 0.0,
            phase_shares: Default::default(),
            runs: Vec::new(),
            schedule: "sweeps".into(),
        }
    }

    #[test]
    fn peers_run_t_2_where_it_is_cheap_and_about_70_million_particle_steps_beyond() {
        assert_eq!(peer_tf(50), 2.0);
        for nx in [200, 400] {
            let steps = peer_tf(nx) * 44.0 * nx as f64;
            let particle_steps = steps * (nx * nx) as f64;
            assert!((particle_steps - 7.0e7).abs() < 1.0, "nx = {nx}: {particle_steps}");
        }
    }

    /// The peer columns: its throughput, our ratio to it, and both L1 errors on edac's row.
    #[test]
    fn the_table_compares_throughput_and_accuracy_with_the_peer() {
        let ours = |variant: &str, speed: f64| sample(variant, 50, 2, speed);
        let out = "{\"particle_steps_per_second\": 3.0e5, \"l1_velocity_final\": 0.02, \"t_final\": 2.0}";
        let mut peer = parse_peer(out, 50, 2, 2.0).unwrap();
        peer.sphrepro_l1_velocity_final = Some(0.0115);
        let t = table(&[ours("edac", 4.5e6), ours("ctvf+sun", 3.0e6)], &[peer.clone()]);
        let rows: Vec<&str> = t.lines().collect();
        assert!(rows[2].ends_with("| 0.300 | 15.0x | 15.0x | 2.00 / 1.15 (t = 2.0000) |"), "{}", rows[2]);
        assert!(rows[3].ends_with("| 0.300 | 10.0x | 10.0x |  |"), "{}", rows[3]);
        // At a larger size the peer is faster (its overhead amortised): the ratio to it
        // there and to its nx = 50 run differ.
        let big = BenchResult { nx: 400, particles: 160_000, ..ours("edac", 5.4e6) };
        let peer_400 = PeerResult { nx: 400, particle_steps_per_second: 9.0e5, ..peer.clone() };
        let t = table(&[ours("edac", 4.5e6), big], &[peer, peer_400]);
        let rows: Vec<&str> = t.lines().collect();
        assert!(rows[3].contains("| 0.900 | 6.0x | 18.0x |"), "{}", rows[3]);
        // Without a peer run at nx = 50 the column is empty.
        let t = table(
            &[BenchResult { nx: 400, ..ours("edac", 5.4e6) }],
            &[PeerResult { nx: 400, ..parse_peer(out, 400, 2, 0.02).unwrap() }],
        );
        assert!(t.lines().nth(2).unwrap().contains("| 0.300 | 18.0x |  |"), "{t}");
    }

    /// Repeated runs: the median one is kept whole (its phase shares with its throughput),
    /// every run's throughput beside it, and the table gives the range.
    #[test]
    fn repeated_runs_report_the_median_run_and_the_range() {
        // `seconds` tells the runs apart.
        let run = |variant: &str, threads: usize, speed: f64, seconds: f64| BenchResult {
            seconds,
            ..sample(variant, 100, threads, speed)
        };
        // Three rounds over edac on one and two threads, then ctvf+ipst on one.
        let samples = vec![
            run("edac", 1, 3.0e6, 1.0),
            run("edac", 2, 5.0e6, 2.0),
            run("edac", 1, 1.0e6, 3.0),
            run("edac", 2, 6.0e6, 4.0),
            run("edac", 1, 2.0e6, 5.0),
            run("edac", 2, 4.0e6, 6.0),
            run("ctvf+ipst", 1, 1.0e6, 7.0),
        ];
        let r = median_runs(samples);
        let got: Vec<_> =
            r.iter().map(|r| (r.variant.as_str(), r.threads, r.seconds, r.runs.clone())).collect();
        assert_eq!(
            got,
            [
                ("edac", 1, 5.0, vec![3.0e6, 1.0e6, 2.0e6]),
                ("edac", 2, 2.0, vec![5.0e6, 6.0e6, 4.0e6]),
                ("ctvf+ipst", 1, 7.0, vec![1.0e6]),
            ]
        );
        // Of an even count, the slower of the two middle runs.
        let two = median_runs(vec![run("edac", 1, 2.0e6, 1.0), run("edac", 1, 1.0e6, 2.0)]);
        assert_eq!(two[0].seconds, 2.0);
        let t = table(&r, &[]);
        let rows: Vec<&str> = t.lines().collect();
        assert!(rows[2].contains("| 2.000 (1.000-3.000) | 500 |"), "{}", rows[2]);
        // The speed-up compares the runs of each round: 5/3, 6/1 and 4/2, median 2 (the
        // ratio of the median runs would be 2.5).
        assert!(
            rows[3].contains("| 5.000 (4.000-6.000) | 200 |")
                && rows[3].contains("| 1.00 | 2.00 (1.67-6.00) |"),
            "{}",
            rows[3]
        );
        // With one run against three, the cost compares the median runs.
        assert!(rows[4].contains("| 1.000 | 1000 |") && rows[4].contains("| 2.00 |"), "{}", rows[4]);
        // Two configurations of three rounds each: the median of the rounds' costs.
        let ipst = BenchResult { runs: vec![1.0e6, 0.25e6, 1.0e6], ..sample("ctvf+ipst", 100, 1, 1.0e6) };
        let t = table(&[r[0].clone(), ipst], &[]);
        // 3/1, 1/0.25, 2/1
        assert!(t.lines().nth(3).unwrap().contains("| 3.00 (2.00-4.00) |"), "{t}");
        // Of an even count of rounds, the mean of the two middle ratios.
        let (a, b) = (sample("edac", 100, 2, 2.0), sample("edac", 100, 1, 1.0));
        let a = BenchResult { runs: vec![2.0, 4.0], ..a };
        let b = BenchResult { runs: vec![1.0, 1.0], ..b };
        assert_eq!(ratio(&a, &b, 1, "x"), "3.0x (2.0-4.0)");
    }

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

    /// A variant with `/sweeps` is the same case with its passes one after the other: known,
    /// timed, and named as given; any other suffix is refused.
    #[test]
    fn sweeps_variants_are_the_same_cases() {
        assert!(
            known_variant("edac") && known_variant("edac/sweeps") && known_variant("ctvf+ipst/wavefront")
        );
        assert!(!known_variant("edac/sweep") && !known_variant("sph/sweeps") && !known_variant("/sweeps"));
        let variants = ["edac".to_string(), "edac/sweeps".to_string(), "edac/wavefront".to_string()];
        let r = run_interleaved(&variants, 12, &[1], 3, 2, 1, DEFAULT_KERNEL).unwrap();
        let names: Vec<_> = r.iter().map(|r| r.variant.as_str()).collect();
        assert_eq!(names, ["edac", "edac/sweeps", "edac/wavefront"]);
        assert!(run_interleaved(&["edac/tiles".to_string()], 12, &[1], 2, 2, 0, DEFAULT_KERNEL).is_err());
    }

    /// A result written before copies were timed reads back as one copy.
    #[test]
    fn results_without_copies_read_as_one() {
        let mut v = serde_json::to_value(sample("edac", 50, 2, 1.0e6)).unwrap();
        v.as_object_mut().unwrap().remove("copies");
        let r: BenchResult = serde_json::from_value(v).unwrap();
        assert_eq!((r.copies, r.threads_label()), (1, "2".to_string()));
    }

    /// The interval of the median from order statistics: the extremes at six samples
    /// (coverage 1 - 2/64), the 14th from each end at forty (96 %), none below six.
    #[test]
    fn the_median_interval_is_the_binomial_order_statistics() {
        let v = |n: usize| (1..=n).map(|i| i as f64).collect::<Vec<_>>();
        assert_eq!(median_interval(&v(5)), None);
        assert_eq!(median_interval(&v(6)), Some((1.0, 6.0)));
        assert_eq!(median_interval(&v(9)), Some((2.0, 8.0)));
        assert_eq!(median_interval(&v(15)), Some((4.0, 12.0)));
        assert_eq!(median_interval(&v(40)), Some((14.0, 27.0)));
        // Large counts do not overflow: the interval narrows to about sqrt(n) around n/2.
        let (lo, hi) = median_interval(&v(2000)).unwrap();
        assert!((955.0..=960.0).contains(&lo) && hi == 2001.0 - lo, "{lo} {hi}");
        // In the table, from six rounds on.
        let run = |speed: f64, runs: Vec<f64>| BenchResult { runs, ..sample("edac", 100, 1, speed) };
        let a = run(6.0, vec![2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        let b = run(1.0, vec![1.0; 6]);
        assert_eq!(ratio(&a, &b, 1, "x"), "4.5x [2.0-7.0] (2.0-7.0)");
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
