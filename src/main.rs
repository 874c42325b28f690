//! The `sphrepro` command line. Thin: every command calls into the library.

use clap::{Args, Parser, Subcommand};
use sphrepro::automation::commands::{self, Dirs, Executor, RunFlags};
use sphrepro::automation::{runner, slurm};
use sphrepro::bench;
use sphrepro::scenes::{self, harness};
use sphrepro::{errln, outln};
use std::path::PathBuf;
use std::process::ExitCode;

/// A count that must be at least 1 (threads, jobs, resolutions, steps).
fn at_least_one<T: std::str::FromStr + PartialOrd + From<u8>>(s: &str) -> Result<T, String> {
    match s.parse::<T>() {
        Ok(n) if n >= T::from(1) => Ok(n),
        _ => Err(format!("`{s}` is not a whole number of at least 1")),
    }
}

/// A finite, positive number of seconds.
fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        Ok(_) => Err(format!("`{s}` is not a positive number of seconds")),
        Err(e) => Err(format!("`{s}`: {e}")),
    }
}

/// Reproduce SPH papers with one command.
#[derive(Parser)]
#[command(name = "sphrepro", version, about)]
struct Cli {
    /// Rayon threads (default: all cores, or RAYON_NUM_THREADS).
    #[arg(long, global = true, value_parser = at_least_one::<usize>)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

/// Where problems, results and the manuscript live.
#[derive(Args, Clone)]
struct DirArgs {
    /// Folder of problem files (*.toml).
    #[arg(long, default_value = commands::DEFAULT_PROBLEMS)]
    problems: PathBuf,
    /// Folder of results (one sub-folder per problem and case).
    #[arg(long, default_value = "output")]
    output: PathBuf,
    /// Folder of figures/, tables/ and manuscript.md [default: `manuscript` for the paper
    /// preset, whose results are committed; OUTPUT/manuscript for any other].
    #[arg(long)]
    manuscript: Option<PathBuf>,
}

impl DirArgs {
    /// The folders for `preset` (which decides the manuscript's when none is named).
    fn dirs(&self, preset: &str) -> Dirs {
        Dirs {
            problems: self.problems.clone(),
            output: self.output.clone(),
            manuscript: self
                .manuscript
                .clone()
                .unwrap_or_else(|| commands::default_manuscript(preset, &self.output)),
        }
    }
}

/// Options of `run` and `reproduce`.
#[derive(Args, Clone)]
struct RunArgs {
    /// Preset: quick (minutes, the default) or paper (the published resolutions).
    #[arg(long, default_value = "quick")]
    preset: String,
    /// Only cases whose name (or problem/name) matches this glob.
    #[arg(long = "match", value_name = "GLOB")]
    matching: Option<String>,
    /// Re-run cases that are done.
    #[arg(long)]
    force: bool,
    /// Concurrent cases (default: the core count; cores are split between cases and threads).
    #[arg(long, value_parser = at_least_one::<usize>)]
    jobs: Option<usize>,
    /// Print what would run and why, with each case's estimated CPU-hours and peak memory
    /// (from a short run of it, kept for the next dry run); run nothing.
    #[arg(long)]
    dry_run: bool,
    /// With --dry-run: list the cases without estimating what they cost.
    #[arg(long, requires = "dry_run")]
    no_estimate: bool,
    /// With --dry-run: CPU seconds of timed steps in each case's short run (longer: closer
    /// estimates); estimates kept from an earlier dry run are reused whatever their budget.
    #[arg(long, value_name = "SECONDS", requires = "dry_run", default_value_t = sphrepro::automation::estimate::BUDGET, value_parser = positive_seconds)]
    estimate_budget: f64,
    /// Regenerate figures and tables from cached and committed results without simulating.
    #[arg(long)]
    plot_only: bool,
    /// Only the cases that failed before (a failed summary, or a folder without one).
    #[arg(long)]
    retry_failed: bool,
    #[command(flatten)]
    slurm: SlurmArgs,
    #[command(flatten)]
    dirs: DirArgs,
}

/// Where the cases of `run` and `reproduce` run.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum ExecutorName {
    /// Subprocesses on this machine.
    Local,
    /// One Slurm job array, a task per case (README: "On a cluster").
    Slurm,
}

/// `--executor slurm` and its settings; each setting wins over the settings file.
#[derive(Args, Clone)]
#[command(next_help_heading = "Cluster (--executor slurm)")]
struct SlurmArgs {
    /// Where the cases run: local, or as a Slurm job array (a task per case; --jobs then
    /// caps the tasks running at once).
    #[arg(long, value_enum, default_value = "local")]
    executor: ExecutorName,
    /// Slurm settings file (default: slurm.toml in the problems folder, if there is one).
    #[arg(long, value_name = "FILE")]
    slurm_config: Option<PathBuf>,
    /// Slurm partition.
    #[arg(long)]
    partition: Option<String>,
    /// Slurm account.
    #[arg(long)]
    account: Option<String>,
    /// Time limit of each case's task (MM, HH:MM:SS, D-HH:MM:SS); a task near it
    /// checkpoints and is requeued.
    #[arg(long)]
    time: Option<String>,
    /// CPUs of each case's task (the simulation's threads).
    #[arg(long, value_parser = at_least_one::<u32>)]
    cpus_per_task: Option<u32>,
    /// Memory of each case's task (e.g. 4G).
    #[arg(long)]
    mem: Option<String>,
    /// An extra #SBATCH option, e.g. --sbatch=--qos=long (repeatable; added to the file's).
    #[arg(long, value_name = "OPTION", allow_hyphen_values = true)]
    sbatch: Vec<String>,
    /// A command each task runs before its simulation, e.g. 'module load gcc'
    /// (repeatable; added to the file's).
    #[arg(long, value_name = "COMMAND")]
    setup: Vec<String>,
    /// Return once submitted; `status` shows the queued and running cases.
    #[arg(long)]
    no_wait: bool,
}

impl SlurmArgs {
    /// The executor, or the Slurm flag given without `--executor slurm`.
    fn executor(&self) -> Result<Executor, String> {
        if self.executor == ExecutorName::Local {
            let given = [
                ("--slurm-config", self.slurm_config.is_some()),
                ("--partition", self.partition.is_some()),
                ("--account", self.account.is_some()),
                ("--time", self.time.is_some()),
                ("--cpus-per-task", self.cpus_per_task.is_some()),
                ("--mem", self.mem.is_some()),
                ("--sbatch", !self.sbatch.is_empty()),
                ("--setup", !self.setup.is_empty()),
                ("--no-wait", self.no_wait),
            ];
            if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
                return Err(format!("{flag} is a Slurm setting: add --executor slurm"));
            }
            return Ok(Executor::Local);
        }
        Ok(Executor::Slurm(slurm::Request {
            config: self.slurm_config.clone(),
            overrides: slurm::settings::Overrides {
                partition: self.partition.clone(),
                account: self.account.clone(),
                time: self.time.clone(),
                cpus_per_task: self.cpus_per_task,
                mem: self.mem.clone(),
                sbatch: self.sbatch.clone(),
                setup: self.setup.clone(),
            },
            wait: !self.no_wait,
        }))
    }
}

impl RunArgs {
    fn options(&self) -> runner::Options {
        runner::Options {
            jobs: self.jobs,
            force: self.force,
            matching: self.matching.clone(),
            dry_run: self.dry_run,
            estimate: (self.dry_run && !self.no_estimate).then_some(self.estimate_budget),
            checkpoint_every: Some(30.0),
        }
    }

    /// What `run` and `reproduce` do besides simulating.
    fn flags(&self, manuscript: bool) -> Result<RunFlags, String> {
        Ok(RunFlags {
            plot_only: self.plot_only,
            manuscript,
            executor: self.slurm.executor()?,
            retry_failed: self.retry_failed,
        })
    }
}

/// `sphrepro bench`.
#[derive(Args)]
struct BenchArgs {
    /// Resolutions (particles per side).
    #[arg(long, value_delimiter = ',', default_values_t = vec![50usize, 100, 200, 400], value_parser = at_least_one::<usize>)]
    nx: Vec<usize>,
    /// Thread counts.
    #[arg(long = "bench-threads", value_delimiter = ',', default_values_t = vec![1usize, 2], value_parser = at_least_one::<usize>)]
    bench_threads: Vec<usize>,
    /// Variants (edac, ctvf+sun, ctvf+ipst); each may end in `/sweeps` or `/wavefront`
    /// (e.g. `edac/sweeps`): the same case with the step's passes one after the other, or
    /// tile by tile (the same results), to time them side by side; without, the step takes
    /// the faster on this host.
    #[arg(long, value_delimiter = ',')]
    variants: Option<Vec<String>>,
    /// Timed steps per case (default: about 4 million particle-steps).
    #[arg(long, value_parser = at_least_one::<u64>)]
    steps: Option<u64>,
    /// Runs of every case and of the peer, in as many rounds over all of them (so that a
    /// slow spell of the machine falls on every variant and on the peer alike); the
    /// table gives the median run and the range, and every ratio (cost, speed-up, to the
    /// peer) as the median of the rounds' own ratios and their range; the JSON every run's
    /// throughput.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    repeat: u32,
    /// Where to write the results as JSON.
    #[arg(long, default_value = "output/bench.json")]
    json: PathBuf,
    /// A peer code's runner to measure in the same rounds as ours, e.g.
    /// `../shared/peers/pysph-taylor-green.sh`: called with `--nx N --tf T --threads K`
    /// for every resolution and thread count, it must print one JSON line with
    /// `particle_steps_per_second`; the table then gives our ratio to it at each size
    /// and, when nx = 50 is among the resolutions, to its nx = 50 run.
    #[arg(long)]
    peer: Option<PathBuf>,
    /// The kernel of every case (with h/dx = 1); the default is the paper's and PySPH's.
    #[arg(long, default_value = bench::DEFAULT_KERNEL)]
    kernel: String,
    /// Time the cases of each resolution side by side in one process, stepped in turn in
    /// ROUNDS rounds of a block of steps each (the first step of a block untimed), so that
    /// a slow spell of the machine, even one of seconds, falls on every variant and thread
    /// count alike: every ratio is then the median of the rounds' own ratios. Memory is
    /// the resident growth while each simulation was built.
    #[arg(long, value_name = "ROUNDS", conflicts_with_all = ["repeat", "peer"], value_parser = clap::value_parser!(u32).range(2..))]
    interleave: Option<u32>,
    /// Time a registered scene (`list`) instead of the Taylor-Green variants: its
    /// particle-steps per second and memory at each of --bench-threads, with its parameters
    /// from --set (its defaults otherwise), e.g. `--scene dam_break_elastic_plate --set
    /// dx=0.0005`. A step is a step of the scene's time loop, a structure's sub-steps inside it.
    #[arg(long, conflicts_with_all = ["nx", "variants", "peer", "kernel", "interleave"])]
    scene: Option<String>,
    /// A parameter of --scene, as key=value (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE", requires = "scene")]
    sets: Vec<String>,
}

impl BenchArgs {
    fn options(self) -> bench::Options {
        let BenchArgs { nx, bench_threads, variants, steps, repeat, json, peer, kernel, interleave, .. } =
            self;
        bench::Options { nx, threads: bench_threads, variants, steps, repeat, json, peer, kernel, interleave }
    }
}

#[derive(Subcommand)]
enum Command {
    /// List the problems and their cases, then the scenes and their parameters.
    List {
        /// Preset whose cases are listed.
        #[arg(long, default_value = "quick")]
        preset: String,
        #[command(flatten)]
        dirs: DirArgs,
    },
    /// Run problems (cases that are missing, failed or stale), then their figures and tables.
    Run {
        /// Problem names (file stems under --problems).
        #[arg(required = true)]
        problem: Vec<String>,
        #[command(flatten)]
        args: RunArgs,
    },
    /// Every problem, figure, table and manuscript.md: the paper preset's in manuscript/ (its
    /// results exported to results/), another preset's smoke check in OUTPUT/manuscript/.
    Reproduce {
        #[command(flatten)]
        args: RunArgs,
    },
    /// Done, missing, stale and failed cases.
    Status {
        /// Preset.
        #[arg(long, default_value = "quick")]
        preset: String,
        /// List every stale folder (results of earlier inputs) with what changed, not only
        /// their count.
        #[arg(long)]
        stale: bool,
        #[command(flatten)]
        dirs: DirArgs,
    },
    /// Compare the bounds of the problem files with the cached results, or (--baseline) the
    /// quick preset's results with the committed baselines, metric by metric (for CI).
    Check {
        /// Problem names (file stems under --problems); every problem without.
        problem: Vec<String>,
        /// Preset.
        #[arg(long, default_value = "quick")]
        preset: String,
        /// Only cases whose name (or problem/name) matches this glob.
        #[arg(long = "match", value_name = "GLOB")]
        matching: Option<String>,
        /// Compare with the committed baselines (baselines/PROBLEM.json) instead of the bounds:
        /// every metric as it was (exactly, or within the tolerance the problem file states).
        #[arg(long)]
        baseline: bool,
        #[command(flatten)]
        dirs: DirArgs,
    },
    /// Rewrite the baselines of the named problems from the quick preset's results after a
    /// deliberate change, printing what moved (the only writer of baselines).
    Bless {
        /// Problem names (file stems under --problems).
        problem: Vec<String>,
        /// Every problem.
        #[arg(long)]
        all: bool,
        #[command(flatten)]
        dirs: DirArgs,
    },
    /// Run one simulation, no cache: writes DIR/summary.json, timeseries.csv and snapshots.
    Simulate {
        /// Scene name (see `list`).
        scene: String,
        /// Parameter, as key=value (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// No progress bar or plan on stderr.
        #[arg(long)]
        quiet: bool,
        /// Overwrite a finished run in the output folder, or discard an interrupted run of other
        /// parameters there.
        #[arg(long)]
        force: bool,
        /// Write `time tf steps t0 seconds` to this file about twice a second.
        #[arg(long, hide = true)]
        progress_file: Option<PathBuf>,
        /// Write DIR/checkpoint.json every SECONDS of stepping (and on Ctrl-C); a run of
        /// the same case into the same folder resumes from it.
        #[arg(long, value_name = "SECONDS", value_parser = positive_seconds)]
        checkpoint_every: Option<f64>,
        /// Stop after N steps as if interrupted, checkpointing first (tests the resume path).
        #[arg(long, hide = true)]
        stop_after_steps: Option<u64>,
        /// The lock of the output folder, held by the runner that started this run and
        /// handed down as this open file descriptor (otherwise the run takes the lock).
        #[arg(long, hide = true)]
        lock_fd: Option<i32>,
    },
    /// One task of a Slurm job array: its case from the manifest (used by --executor slurm).
    #[command(hide = true)]
    SlurmTask {
        /// The submission's manifest.json.
        manifest: PathBuf,
        /// The case's index in it (default: SLURM_ARRAY_TASK_ID).
        #[arg(long)]
        index: Option<usize>,
    },
    /// Throughput and memory of Taylor-Green for edac, ctvf+sun, ctvf+ipst, or of any scene
    /// (--scene).
    Bench(BenchArgs),
    /// One benchmark configuration in this process (used by `bench`).
    #[command(hide = true)]
    BenchCase {
        #[arg(long)]
        variant: String,
        #[arg(long)]
        nx: usize,
        #[arg(long)]
        steps: u64,
        #[arg(long, default_value = bench::DEFAULT_KERNEL)]
        kernel: String,
    },
    /// The cases of one resolution timed side by side in this process (used by
    /// `bench --interleave`).
    #[command(hide = true)]
    BenchInterleaved {
        #[arg(long, value_delimiter = ',')]
        variants: Vec<String>,
        #[arg(long)]
        nx: usize,
        #[arg(long = "bench-threads", value_delimiter = ',')]
        bench_threads: Vec<usize>,
        #[arg(long)]
        steps: u64,
        #[arg(long)]
        rounds: u32,
        #[arg(long, default_value = bench::DEFAULT_KERNEL)]
        kernel: String,
    },
    /// One run of a scene timed in this process (used by `bench --scene`).
    #[command(hide = true)]
    BenchScene {
        #[arg(long)]
        scene: String,
        #[arg(long = "set")]
        sets: Vec<String>,
        #[arg(long)]
        steps: Option<u64>,
    },
    /// One case's cost predicted from a short run of it in this process (used by
    /// `run --dry-run`).
    #[command(hide = true)]
    EstimateCase {
        #[arg(long)]
        scene: String,
        #[arg(long = "set")]
        sets: Vec<String>,
        /// CPU seconds of timed stepping.
        #[arg(long)]
        budget: f64,
    },
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`sphrepro list | head`) panics;
    // the default action ends the process quietly, as other command-line tools do.
    #[cfg(unix)]
    // SAFETY: called first in main, before any thread exists; SIG_DFL is a valid handler.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
            errln!("error: cannot start {n} threads: {e}");
            return ExitCode::from(2);
        }
    }
    install_signal_handlers();
    // Run the command on a worker of the pool: the solver's parallel loops are then forked
    // from inside it, without handing each one over from a thread outside the pool, which
    // costs a sleep and a wake-up per loop (measured: 15 % more particle-steps per second on
    // one thread at 2 500 particles).
    let code = rayon::scope(|_| run(cli));
    // Output that could not be written is an error, whatever the command did otherwise.
    match sphrepro::console::failure() {
        Some(e) => {
            errln!("error: {e}");
            ExitCode::from(if code == 0 { 1 } else { code })
        }
        None => ExitCode::from(code),
    }
}

/// Ctrl-C, SIGTERM and SIGHUP stop a run with a checkpoint (a second one exits at once).
/// SIGUSR1 is what a case's runner, dying, sends its simulation (runner.rs): stop as on a
/// first Ctrl-C, however often it comes. A SIGHUP ignored by whoever started us (`nohup`)
/// stays ignored, so a run under `nohup` outlives the terminal as it did.
fn install_signal_handlers() {
    #[cfg(unix)]
    // SAFETY: sigaction only reads the current disposition into a zeroed struct.
    let hup_ignored = unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        libc::sigaction(libc::SIGHUP, std::ptr::null(), &mut old) == 0 && old.sa_sigaction == libc::SIG_IGN
    };
    let _ = ctrlc::set_handler(|| {
        if harness::INTERRUPTED.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    #[cfg(unix)]
    // SAFETY: SIG_IGN is a valid disposition; the SIGUSR1 handler only stores to an
    // atomic, which is async-signal-safe.
    unsafe {
        if hup_ignored {
            libc::signal(libc::SIGHUP, libc::SIG_IGN);
        }
        extern "C" fn on_runner_death(_: libc::c_int) {
            harness::INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst);
        }
        libc::signal(libc::SIGUSR1, on_runner_death as extern "C" fn(libc::c_int) as libc::sighandler_t);
    }
}

/// Runs the command; returns its exit status.
fn run(cli: Cli) -> u8 {
    match cli.command {
        Command::List { preset, dirs } => {
            let code = commands::list(&dirs.dirs(&preset), &preset);
            if code != 0 {
                return code;
            }
            print_scenes();
            0
        }
        Command::Run { problem, args } => match args.flags(false) {
            Ok(flags) => {
                commands::run(&args.dirs.dirs(&args.preset), &args.preset, &problem, &args.options(), &flags)
            }
            Err(e) => {
                errln!("error: {e}");
                commands::BAD_INPUT
            }
        },
        Command::Reproduce { args } => match args.flags(true) {
            Ok(flags) => {
                commands::run(&args.dirs.dirs(&args.preset), &args.preset, &[], &args.options(), &flags)
            }
            Err(e) => {
                errln!("error: {e}");
                commands::BAD_INPUT
            }
        },
        Command::SlurmTask { manifest, index } => slurm::task::run(&manifest, index),
        Command::Status { preset, stale, dirs } => commands::status(&dirs.dirs(&preset), &preset, stale),
        Command::Check { problem, preset, matching, baseline, dirs } => {
            commands::check(&dirs.dirs(&preset), &preset, &problem, matching.as_deref(), baseline)
        }
        Command::Bless { problem, all, dirs } => commands::bless(&dirs.dirs("quick"), &problem, all),
        Command::Simulate {
            scene,
            sets,
            out,
            quiet,
            force,
            progress_file,
            checkpoint_every,
            stop_after_steps,
            lock_fd,
        } => simulate(
            &scene,
            &sets,
            &out,
            lock_fd,
            harness::RunOptions { quiet, force, progress_file, checkpoint_every, stop_after_steps },
        ),
        Command::Bench(args) => match &args.scene {
            Some(scene) => bench::run_scene(&bench::SceneOptions {
                scene,
                sets: &args.sets,
                threads: &args.bench_threads,
                steps: args.steps,
                repeat: args.repeat,
                json: &args.json,
            }),
            None => bench::run(&args.options()),
        },
        Command::BenchScene { scene, sets, steps } => bench::scene_child(&scene, &sets, steps),
        Command::EstimateCase { scene, sets, budget } => bench::estimate_child(&scene, &sets, budget),
        Command::BenchCase { variant, nx, steps, kernel } => bench::case_child(&variant, nx, steps, &kernel),
        Command::BenchInterleaved { variants, nx, bench_threads, steps, rounds, kernel } => {
            bench::interleaved_child(&variants, nx, &bench_threads, steps, rounds, &kernel)
        }
    }
}

/// `simulate`: one run of `scene` into `out`; exit 0 when it completes, 3 when it diverges
/// (a result, reported as such), 2 on bad input (or an output folder another run is
/// writing) and 1 when the run fails. The run holds the lock of `out` while it lives: its
/// own, or the runner's, handed down as the open descriptor `lock_fd`.
fn simulate(
    scene: &str,
    sets: &[String],
    out: &std::path::Path,
    lock_fd: Option<i32>,
    opts: harness::RunOptions,
) -> u8 {
    let found = scenes::find(scene).and_then(|e| {
        let params = e.params_from_sets(sets)?;
        // Every check that needs no particle, before the lock file is made.
        harness::check_times(e.name, &params)?;
        (e.check)(&params)?;
        Ok((e, params))
    });
    let (entry, params) = match found {
        Ok(found) => found,
        Err(e) => {
            errln!("error: {e}");
            return 2;
        }
    };
    let _lock = match lock_output(out, lock_fd) {
        Ok(lock) => lock,
        Err(e) => {
            errln!("error: {e}");
            return 2;
        }
    };
    match harness::run(entry, &params, out, &opts) {
        Ok(s) => match s.status {
            sphrepro::solver::output::summary::Status::Completed => {
                if !opts.quiet {
                    errln!(
                        "completed: {} steps, {:.2} s, {:.3e} particle-steps/s",
                        s.steps,
                        s.wall_seconds,
                        s.particle_steps_per_second
                    );
                    for (k, v) in &s.metrics {
                        errln!("  {k} = {v:.6e}");
                    }
                }
                0
            }
            _ => {
                errln!(
                    "diverged at step {} (t = {}): {}",
                    s.step.unwrap_or(s.steps),
                    s.final_time,
                    s.reason.as_deref().unwrap_or("")
                );
                3
            }
        },
        Err(harness::RunError::Input(e)) => {
            errln!("error: {e}");
            2
        }
        Err(harness::RunError::Failed(e)) => {
            errln!("failed: {e}");
            1
        }
    }
}

/// The lock `simulate` holds on its output folder while it runs.
enum OutputLock {
    #[allow(dead_code)] // held for its drop
    Own(sphrepro::automation::lock::Lock),
    #[cfg(unix)]
    #[allow(dead_code)] // held for its drop
    Inherited(sphrepro::automation::lock::Inherited),
}

/// Takes the lock of `out` (or takes up the runner's, handed down as `fd`): a folder
/// another run is writing into is refused, naming the folder and that run's process.
fn lock_output(out: &std::path::Path, fd: Option<i32>) -> Result<OutputLock, String> {
    use sphrepro::automation::lock::{normalize, Lock, Try};
    match fd {
        #[cfg(unix)]
        Some(fd) => Lock::adopt(out, fd).map(OutputLock::Inherited),
        #[cfg(not(unix))]
        Some(_) => Err("--lock-fd: only on unix".into()),
        None => match Lock::try_take(out)? {
            Try::Taken(lock) => Ok(OutputLock::Own(lock)),
            Try::Held(pid) => Err(format!(
                "{}: another run ({}) is writing into this folder; wait for it to end, or choose another --out",
                normalize(out).display(),
                if pid == 0 { "just starting".to_string() } else { format!("process {pid}") }
            )),
        },
    }
}

/// The scenes, each with its parameters (name, kind, default, help) and metrics.
fn print_scenes() {
    outln!("scenes:");
    for s in scenes::SCENES {
        outln!("{} ({}D): {}", s.name, s.dim, s.about);
        let params = (s.params)();
        // Columns as wide as the scene's widest entry, so that long names and
        // choice lists keep the help text aligned.
        let rows: Vec<[String; 4]> = params
            .iter()
            .map(|p| [p.name.to_string(), p.kind_name(), p.default.to_string(), p.help.to_string()])
            .collect();
        let width = |c: usize| rows.iter().map(|r| r[c].len()).max().unwrap_or(0);
        let (w0, w1, w2) = (width(0), width(1), width(2));
        for [name, kind, default, help] in &rows {
            outln!("    {name:<w0$} {kind:<w1$} default {default:<w2$} {help}");
        }
        outln!("    metrics: {}", s.metrics.join(", "));
    }
}
