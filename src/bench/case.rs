//! What a bench case measures: the variants (scheme, shifting, step schedule), the
//! Taylor-Green simulation each one times, and the result of one measured configuration.

use crate::scenes::taylor_green;
use crate::solver::simulation::{PhaseTimes, Schedule, Simulation, TUNING_STEPS};
use serde::{Deserialize, Serialize};

/// The kernel of the cases unless `--kernel` names another: the paper's and PySPH's.
pub const DEFAULT_KERNEL: &str = "quintic_spline";

/// The variants benchmarked: (name, scheme, pst).
pub(super) const VARIANTS: &[(&str, &str, &str)] =
    &[("edac", "edac", "none"), ("ctvf+sun", "ctvf", "sun"), ("ctvf+ipst", "ctvf", "ipst")];

/// The suffixes of a variant that fix the order of its step's passes (`edac/sweeps`,
/// `edac/wavefront`: the same results, for timing them side by side); without one, the
/// step takes the faster on this host ([`Schedule::Tuned`]).
pub(super) const SCHEDULES: &[(&str, Schedule)] =
    &[("/sweeps", Schedule::Sweeps), ("/wavefront", Schedule::Wavefront)];

/// A schedule's name in bench results: its suffix in [`SCHEDULES`] without the slash.
pub(super) fn schedule_name(schedule: Schedule) -> &'static str {
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
pub(super) fn known_variant(variant: &str) -> bool {
    lookup_variant(variant).is_some()
}

/// Steps to time for `n` particles: about 4 million particle-steps, at least 20 steps.
pub(super) fn default_steps(n: usize) -> u64 {
    ((4.0e6 / n as f64) as u64).max(20)
}

/// Untimed steps before a bench case is timed: enough for a tuned step schedule to have
/// timed its choices and kept one.
pub(super) const WARMUP: u64 = TUNING_STEPS as u64 + 2;

/// The simulation a bench case times: Taylor-Green of `variant` at `nx` with `kernel`
/// (Re = 100, h/dx = 1), from a lattice perturbed by 5 % of dx. IPST is timed at its
/// iteration cap (10 moves a step, with a tolerance it never meets): a developed
/// Taylor-Green flow sits there (measured at nx = 50 and 100: from t = 0.09 on, every step
/// makes the 10 moves), while the first steps of a run barely iterate, so timing those would
/// understate its cost.
/// A variant may end in a suffix of [`SCHEDULES`]. It is returned after `warmup` untimed
/// steps, in which a tuned schedule has made its choice.
pub(super) fn case_simulation(
    variant: &str,
    nx: usize,
    kernel: &str,
    warmup: u64,
) -> Result<Simulation<2>, String> {
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
pub(super) fn warm_up(sim: &mut Simulation<2>, warmup: u64) -> Result<(), String> {
    for _ in 0..warmup {
        sim.step(f64::INFINITY).map_err(|d| d.reason)?;
    }
    Ok(())
}

/// One measured configuration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct BenchResult {
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
    pub phase_shares: PhaseTimes,
    /// How the last timed step's passes ran ([`schedule_name`]): for a variant without a
    /// suffix of [`SCHEDULES`], the order the tuner kept.
    #[serde(default)]
    pub schedule: String,
    /// Particle-steps per second of every run of this configuration (`bench --repeat`), in
    /// the order they ran; the fields above are those of the median run (see
    /// `stats::median_runs`).
    #[serde(default)]
    pub runs: Vec<f64>,
}

/// `copies` of a result that does not give it: one.
fn one_copy() -> usize {
    1
}

impl BenchResult {
    /// The thread count as the table gives it: `k x 1` for k copies on one thread each.
    pub(super) fn threads_label(&self) -> String {
        if self.copies > 1 {
            format!("{} x {}", self.copies, self.threads)
        } else {
            self.threads.to_string()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::sample;
    use super::super::timing::run_interleaved;
    use super::*;

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
}
