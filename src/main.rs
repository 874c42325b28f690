//! The `sphrepro` command line. Thin: every command calls into the library.

use clap::{Args, Parser, Subcommand};
use sphrepro::automation::commands::{self, Dirs, RunFlags};
use sphrepro::automation::runner;
use sphrepro::bench;
use sphrepro::scenes::{self, harness};
use sphrepro::solver::simulation::TUNING_STEPS;
use sphrepro::{err, errln, outln};
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
    /// Folder of figures/, tables/ and manuscript.md.
    #[arg(long, default_value = "manuscript")]
    manuscript: PathBuf,
}

impl DirArgs {
    fn dirs(&self) -> Dirs {
        Dirs {
            problems: self.problems.clone(),
            output: self.output.clone(),
            manuscript: self.manuscript.clone(),
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
    /// Print what would run and why; run nothing.
    #[arg(long)]
    dry_run: bool,
    /// Regenerate figures and tables from cached results without simulating.
    #[arg(long)]
    plot_only: bool,
    #[command(flatten)]
    dirs: DirArgs,
}

impl RunArgs {
    fn options(&self) -> runner::Options {
        runner::Options {
            jobs: self.jobs,
            force: self.force,
            matching: self.matching.clone(),
            dry_run: self.dry_run,
            checkpoint_every: Some(30.0),
        }
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
    /// A peer code's runner to measure in the same sitting, e.g.
    /// `../shared/peers/pysph-taylor-green.sh`: called with `--nx N --tf T --threads K`
    /// for every resolution and thread count, it must print one JSON line with
    /// `particle_steps_per_second`; the table then gives our ratio to it at each size
    /// and, when nx = 50 is among the resolutions, to its nx = 50 run (the issue's
    /// figure to beat).
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
    /// Every problem, every figure and table, and manuscript.md.
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
    /// Compare every bound of the problem files with the cached results (for CI).
    Check {
        /// Preset.
        #[arg(long, default_value = "quick")]
        preset: String,
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
    /// Throughput and memory of Taylor-Green for edac, ctvf+sun, ctvf+ipst.
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
            let code = commands::list(&dirs.dirs(), &preset);
            if code != 0 {
                return code;
            }
            print_scenes();
            0
        }
        Command::Run { problem, args } => commands::run(
            &args.dirs.dirs(),
            &args.preset,
            &problem,
            &args.options(),
            &RunFlags { plot_only: args.plot_only, manuscript: false },
        ),
        Command::Reproduce { args } => commands::run(
            &args.dirs.dirs(),
            &args.preset,
            &[],
            &args.options(),
            &RunFlags { plot_only: args.plot_only, manuscript: true },
        ),
        Command::Status { preset, stale, dirs } => commands::status(&dirs.dirs(), &preset, stale),
        Command::Check { preset, dirs } => commands::check(&dirs.dirs(), &preset),
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
        Command::Bench(args) => run_bench(args),
        Command::BenchCase { variant, nx, steps, kernel } => {
            print_json(bench::run_case(&variant, nx, steps, BENCH_WARMUP, &kernel))
        }
        Command::BenchInterleaved { variants, nx, bench_threads, steps, rounds, kernel } => print_json(
            bench::run_interleaved(&variants, nx, &bench_threads, steps, rounds, BENCH_WARMUP, &kernel),
        ),
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

/// sphrepro `edac`'s L1 velocity error on a peer's run (Taylor-Green, `nx`, Re = 100, to
/// `tf`, on `threads` threads, with `kernel`), through `simulate` into a temporary folder.
fn edac_l1(exe: &std::path::Path, nx: usize, threads: usize, tf: f64, kernel: &str) -> Result<f64, String> {
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

/// Untimed steps before a bench case is timed: enough for a tuned step schedule to have
/// timed its choices and kept one.
const BENCH_WARMUP: u64 = TUNING_STEPS as u64 + 2;

/// A bench child's result as one JSON line on stdout, or its error on stderr (exit 1).
fn print_json(r: Result<impl serde::Serialize, String>) -> u8 {
    match r {
        Ok(r) => {
            outln!("{}", serde_json::to_string(&r).expect("serialises"));
            0
        }
        Err(e) => {
            errln!("error: {e}");
            1
        }
    }
}

/// Runs the hidden bench subcommand `args` in a child process and reads its JSON result.
fn bench_child<T: serde::de::DeserializeOwned>(exe: &std::path::Path, args: &[&str]) -> Result<T, String> {
    let o = std::process::Command::new(exe)
        .args(args)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if !o.status.success() {
        return Err(format!("failed: {}", String::from_utf8_lossy(&o.stderr)));
    }
    serde_json::from_slice(&o.stdout).map_err(|e| format!("unreadable result: {e}"))
}

/// One benchmark configuration, timed in a process of its own (`bench-case`) so that each
/// starts from the same memory state and its peak memory is its own.
fn bench_case(
    exe: &std::path::Path,
    variant: &str,
    nx: usize,
    threads: usize,
    steps: u64,
    kernel: &str,
) -> Result<bench::BenchResult, String> {
    let (nx, threads, steps) = (nx.to_string(), threads.to_string(), steps.to_string());
    bench_child(
        exe,
        &[
            "--threads",
            &threads,
            "bench-case",
            "--variant",
            variant,
            "--nx",
            &nx,
            "--steps",
            &steps,
            "--kernel",
            kernel,
        ],
    )
}

/// The cases of resolution `nx` timed side by side in a process of their own
/// (`bench-interleaved`; see `bench::run_interleaved`).
fn bench_interleaved(
    exe: &std::path::Path,
    variants: &[String],
    nx: usize,
    threads: &[usize],
    steps: u64,
    rounds: u32,
    kernel: &str,
) -> Result<Vec<bench::BenchResult>, String> {
    let variants = variants.join(",");
    let threads = threads.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(",");
    let (nx, steps, rounds) = (nx.to_string(), steps.to_string(), rounds.to_string());
    bench_child(
        exe,
        &[
            "bench-interleaved",
            "--variants",
            &variants,
            "--nx",
            &nx,
            "--bench-threads",
            &threads,
            "--steps",
            &steps,
            "--rounds",
            &rounds,
            "--kernel",
            kernel,
        ],
    )
}

/// One run of a peer's script at `nx` on `threads` threads to time `tf`, read from the
/// JSON line it prints.
fn peer_run(
    script: &std::path::Path,
    nx: usize,
    threads: usize,
    tf: f64,
) -> Result<bench::PeerResult, String> {
    let o = std::process::Command::new(script)
        .args(["--nx", &nx.to_string(), "--tf", &format!("{tf}"), "--threads", &threads.to_string()])
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| e.to_string())?;
    if !o.status.success() {
        return Err(format!("exit status {}", o.status));
    }
    bench::parse_peer(&String::from_utf8_lossy(&o.stdout), nx, threads, tf)
}

fn run_bench(args: BenchArgs) -> u8 {
    let BenchArgs { nx, bench_threads: threads, variants, steps, repeat, json, peer, kernel, interleave } =
        args;
    let started = chrono::Utc::now();
    let kernel = kernel.as_str();
    if !sphrepro::solver::kernel::KernelKind::NAMES.contains(&kernel) {
        errln!(
            "error: bench: --kernel {kernel}: expected one of {}",
            sphrepro::solver::kernel::KernelKind::NAMES.join(", ")
        );
        return 2;
    }
    let variants: Vec<String> =
        variants.unwrap_or_else(|| bench::VARIANTS.iter().map(|v| v.0.to_string()).collect());
    // Every argument is checked before the first case runs, so that a typo costs no sitting.
    if let Some(v) = variants.iter().find(|v| !bench::known_variant(v)) {
        let known: Vec<&str> = bench::VARIANTS.iter().map(|k| k.0).collect();
        let suffixes: Vec<&str> = bench::SCHEDULES.iter().map(|s| s.0).collect();
        errln!(
            "error: bench: --variants {v}: expected one of {}, each optionally ending in {}",
            known.join(", "),
            suffixes.join(" or ")
        );
        return 2;
    }
    if let Some(script) = peer.as_ref().filter(|p| !p.is_file()) {
        errln!("error: bench: --peer {}: no such file", script.display());
        return 2;
    }
    let exe = std::env::current_exe().expect("own executable");
    let (mut results, mut peers) = (Vec::new(), Vec::new());
    // A case or a peer run that fails ends the sitting, but what was measured before it is
    // still reported and written.
    let mut failure: Option<String> = None;
    if let Some(rounds) = interleave {
        for &n in &nx {
            let k = steps.unwrap_or_else(|| bench::default_steps(n * n));
            err!(
                "bench nx={n}, {} on {threads:?} threads side by side, {rounds} rounds of {} steps each ... ",
                variants.join(", "),
                k.div_ceil(rounds as u64)
            );
            match bench_interleaved(&exe, &variants, n, &threads, k, rounds, kernel) {
                Ok(r) => {
                    let speeds: Vec<String> = r
                        .iter()
                        .map(|r| {
                            format!(
                                "{} on {}: {:.3} M",
                                r.variant,
                                r.threads_label(),
                                r.particle_steps_per_second / 1e6
                            )
                        })
                        .collect();
                    errln!("{}", speeds.join(", "));
                    results.extend(r);
                }
                Err(e) => {
                    errln!("{e}");
                    failure = Some(format!("bench nx={n}, side by side: {e}"));
                    break;
                }
            }
        }
    }
    // Side by side, our cases ran above: no rounds of processes.
    let repeat = if interleave.is_some() { 0 } else { repeat };
    'rounds: for round in 1..=repeat {
        let of = if repeat > 1 { format!(" (run {round} of {repeat})") } else { String::new() };
        for &n in &nx {
            for v in &variants {
                for &t in &threads {
                    let k = steps.unwrap_or_else(|| bench::default_steps(n * n));
                    err!("bench {v} nx={n} threads={t} steps={k}{of} ... ");
                    match bench_case(&exe, v, n, t, k, kernel) {
                        Ok(r) => {
                            errln!("{:.3} M particle-steps/s", r.particle_steps_per_second / 1e6);
                            results.push(r);
                        }
                        Err(e) => {
                            errln!("{e}");
                            failure = Some(format!("bench {v} nx={n} threads={t}: {e}"));
                            break 'rounds;
                        }
                    }
                }
            }
        }
        // The peer in the same round, so that a slow spell falls on both codes alike.
        if let Some(script) = &peer {
            for &n in &nx {
                for &t in &threads {
                    let tf = bench::peer_tf(n);
                    err!("peer {} nx={n} threads={t} tf={tf:.4}{of} ... ", script.display());
                    match peer_run(script, n, t, tf) {
                        Ok(p) => {
                            errln!("{:.3} M particle-steps/s", p.particle_steps_per_second / 1e6);
                            peers.push(p);
                        }
                        Err(e) => {
                            errln!("error: peer {}: {e}", script.display());
                            failure = Some(format!("peer {} nx={n} threads={t}: {e}", script.display()));
                            break 'rounds;
                        }
                    }
                }
            }
        }
    }
    // Side by side, each configuration is one result already, its blocks its runs.
    let results = if interleave.is_some() { results } else { bench::median_runs(results) };
    let mut peers = bench::median_runs(peers);
    for p in &mut peers {
        let (n, t) = (p.nx, p.threads);
        err!("edac nx={n} threads={t} to the peer's t = {:.4} ... ", p.end_time());
        match edac_l1(&exe, n, t, p.end_time(), kernel) {
            Ok(l1) => {
                p.sphrepro_l1_velocity_final = Some(l1);
                let peer = p.l1_velocity_final.map_or("-".into(), |v| format!("{:.2} %", 100.0 * v));
                errln!("L1: peer {peer}, edac {:.2} %", 100.0 * l1);
            }
            Err(e) => {
                errln!("\nerror: edac on the peer's run: {e}");
                failure.get_or_insert(format!("edac on the peer's run nx={n} threads={t}: {e}"));
            }
        }
    }
    // The host and build: figures compare only within one kind of host, and without a
    // vector path for the distance test the neighbour list costs a host more.
    let provenance = sphrepro::solver::output::summary::Provenance::now(started);
    outln!("Taylor-Green, Re = 100, kernel {kernel}, h/dx = 1, on {}:\n", provenance.machine.describe());
    outln!("{}", bench::table(&results, &peers));
    let targets = bench::targets::targets(&results, &peers);
    if !targets.is_empty() {
        // The figures are PySPH's own run, with its quintic spline.
        let caveat = if kernel == bench::DEFAULT_KERNEL {
            String::new()
        } else {
            format!(" (they are set for the {} kernel; this sitting ran {kernel})", bench::DEFAULT_KERNEL)
        };
        outln!(
            "Against the targets of issue 3, in this sitting{caveat}:\n\n{}",
            bench::targets::table(&targets)
        );
    }
    if let Some(dir) = json.parent().filter(|d| !d.as_os_str().is_empty()) {
        if let Err(e) = std::fs::create_dir_all(dir) {
            errln!("error: {}: {e}", dir.display());
            return 1;
        }
    }
    let text = serde_json::to_string_pretty(
        &serde_json::json!({ "provenance": provenance, "results": results, "peers": peers, "targets": targets }),
    )
    .expect("serialises");
    if let Err(e) = sphrepro::solver::output::write_atomic(&json, text.as_bytes()) {
        errln!("error: {}: {e}", json.display());
        return 1;
    }
    errln!("wrote {}", json.display());
    match failure {
        Some(e) => {
            errln!("error: the sitting stopped early (the table and the JSON hold what ran before): {e}");
            1
        }
        None => 0,
    }
}
