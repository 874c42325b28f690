//! The throughput targets, read off one `bench` run: each target the run has the
//! measurements for, the measured ratio with its spread, and whether it holds. On a noisy
//! host a median can fall on either side of a bound from one run to the next; the verdict
//! then says the run cannot tell rather than pick a side.
//!
//! - `edac` at nx = 50: at least 10x the peer (PySPH), at an L1 error no worse;
//! - `edac` at nx = 200 and 400: at least 15x the peer's run at nx = 50; beside it, for
//!   comparison and not as a target, the ratio to the peer at the same size;
//! - the cost of a particle-step flat from nx = 50 to 400 (O(N));
//! - two threads at least 1.7x one at nx >= 100;
//! - `ctvf`+`ipst` within 3x the cost of `edac` a step.

use super::case::BenchResult;
use super::peer::{PeerResult, PEER_BASELINE_NX};
use super::stats::Ratio;
use serde::Serialize;

/// Which side of its bound a target asks a measure to be on.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum Bound {
    /// At least this.
    AtLeast(f64),
    /// At most this.
    AtMost(f64),
}

impl Bound {
    fn holds(self, v: f64) -> bool {
        match self {
            Self::AtLeast(b) => v >= b,
            Self::AtMost(b) => v <= b,
        }
    }
}

impl std::fmt::Display for Bound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::AtLeast(b) => write!(f, ">= {b}"),
            Self::AtMost(b) => write!(f, "<= {b}"),
        }
    }
}

/// Whether a target holds in one run of `bench`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum Verdict {
    /// The whole 95 % interval of the median meets the bound, or, with no interval (fewer
    /// than six rounds, or a single measure), the value does.
    Met,
    /// The whole interval, or the value, misses it.
    Missed,
    /// The interval straddles the bound: this run cannot tell.
    Undecided,
}

/// One target on one measured case.
#[derive(Clone, Debug, Serialize)]
pub(super) struct TargetRow {
    /// The target, in words.
    pub target: &'static str,
    /// Where it was measured (variant, size, threads, and what it is compared with).
    pub case: String,
    /// The measure: a ratio of throughputs (round by round), or a single value.
    pub measured: Ratio,
    /// The bound the target sets on it.
    pub bound: Bound,
    /// Whether the measure meets it.
    pub verdict: Verdict,
}

impl TargetRow {
    fn new(target: &'static str, case: String, measured: Ratio, bound: Bound) -> Self {
        let verdict = match measured.interval {
            Some((lo, hi)) if bound.holds(lo) && bound.holds(hi) => Verdict::Met,
            Some((lo, hi)) if !bound.holds(lo) && !bound.holds(hi) => Verdict::Missed,
            Some(_) => Verdict::Undecided,
            None if bound.holds(measured.median) => Verdict::Met,
            None => Verdict::Missed,
        };
        Self { target, case, measured, bound, verdict }
    }
}

/// The largest exponent `e` of a cost growing as `N^e` that still counts as flat. Over the
/// 64-fold growth of N from nx = 50 to 400 an O(N log N) cost would show `e` of about 0.10
/// (`ln(ln 160000 / ln 2500) / ln 64`); 0.05 lies halfway between that and O(N).
const FLAT_EXPONENT: f64 = 0.05;

/// The least-squares slope of `ln(cost)` against `ln(N)` over the `(particles, particle-steps
/// per second)` points: the exponent `e` of a cost a particle-step growing as `N^e`.
fn cost_exponent(points: &[(usize, f64)]) -> f64 {
    let xy: Vec<(f64, f64)> = points.iter().map(|&(n, speed)| ((n as f64).ln(), -speed.ln())).collect();
    let k = xy.len() as f64;
    let (mx, my) = (xy.iter().map(|p| p.0).sum::<f64>() / k, xy.iter().map(|p| p.1).sum::<f64>() / k);
    let sxy: f64 = xy.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xy.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// Every target that `results` and `peers` have the runs for, in the order of the
/// list above, each on every thread count measured.
pub(super) fn targets(results: &[BenchResult], peers: &[PeerResult]) -> Vec<TargetRow> {
    let ours = |variant: &str, nx: usize, threads: usize, copies: usize| {
        results
            .iter()
            .find(|r| r.variant == variant && r.nx == nx && r.threads == threads && r.copies == copies)
    };
    let peer = |nx: usize, threads: usize| peers.iter().find(|p| p.nx == nx && p.threads == threads);
    let mut threads: Vec<usize> = results.iter().filter(|r| r.copies == 1).map(|r| r.threads).collect();
    threads.sort_unstable();
    threads.dedup();
    let mut sizes: Vec<usize> = results.iter().map(|r| r.nx).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let mut rows = Vec::new();
    for &t in &threads {
        let (Some(e), Some(p)) = (ours("edac", PEER_BASELINE_NX, t, 1), peer(PEER_BASELINE_NX, t)) else {
            continue;
        };
        let case = format!("edac, nx = {PEER_BASELINE_NX}, {t} thread(s), against {}", p.peer);
        rows.push(TargetRow::new(
            "edac at nx = 50: 10x the peer",
            case,
            Ratio::of(e, p),
            Bound::AtLeast(10.0),
        ));
        if let (Some(theirs), Some(mine)) = (p.l1_velocity_final, p.sphrepro_l1_velocity_final) {
            let case = format!(
                "L1 at t = {:.4}: edac {:.2} %, {} {:.2} % (ratio)",
                p.end_time(),
                100.0 * mine,
                p.peer,
                100.0 * theirs
            );
            rows.push(TargetRow::new(
                "edac at nx = 50: L1 error no worse than the peer's",
                case,
                Ratio::single(mine / theirs),
                Bound::AtMost(1.0),
            ));
        }
    }
    for &t in &threads {
        for nx in [200, 400] {
            let Some(e) = ours("edac", nx, t, 1) else { continue };
            if let Some(p) = peer(PEER_BASELINE_NX, t) {
                let case =
                    format!("edac, nx = {nx}, {t} thread(s), against {} at nx = {PEER_BASELINE_NX}", p.peer);
                let target = "edac at nx = 200, 400: 15x the peer at nx = 50";
                rows.push(TargetRow::new(target, case, Ratio::of(e, p), Bound::AtLeast(15.0)));
            }
            if let Some(p) = peer(nx, t) {
                let case = format!("edac, nx = {nx}, {t} thread(s), against {} at nx = {nx}", p.peer);
                let target =
                    "edac at nx = 200, 400: 15x the peer at the same size (for comparison, not a target)";
                rows.push(TargetRow::new(target, case, Ratio::of(e, p), Bound::AtLeast(15.0)));
            }
        }
    }
    for &t in &threads {
        let edac: Vec<&BenchResult> = sizes.iter().filter_map(|&nx| ours("edac", nx, t, 1)).collect();
        if edac.len() >= 2 {
            let list = |f: &dyn Fn(&BenchResult) -> String| edac.iter().map(|r| f(r)).collect::<Vec<_>>();
            let case = format!(
                "edac, {t} thread(s): ns a particle-step {} at nx = {}; exponent of N",
                list(&|r| format!("{:.0}", 1e9 / r.particle_steps_per_second)).join(" / "),
                list(&|r| r.nx.to_string()).join(", ")
            );
            let points: Vec<(usize, f64)> =
                edac.iter().map(|r| (r.particles, r.particle_steps_per_second)).collect();
            let target = "cost a particle-step flat from nx = 50 to 400 (O(N))";
            let exponent = Ratio::single(cost_exponent(&points));
            rows.push(TargetRow::new(target, case, exponent, Bound::AtMost(FLAT_EXPONENT)));
        }
    }
    for &nx in sizes.iter().filter(|&&nx| nx >= 100) {
        let (Some(two), Some(one)) = (ours("edac", nx, 2, 1), ours("edac", nx, 1, 1)) else { continue };
        let ceiling = ours("edac", nx, 1, 2).map_or(String::new(), |c| {
            format!(" (2 independent runs: {})", Ratio::of(c, one).format(2, "x"))
        });
        let case = format!("edac, nx = {nx}{ceiling}");
        let target = "two threads at least 1.7x one at nx >= 100";
        rows.push(TargetRow::new(target, case, Ratio::of(two, one), Bound::AtLeast(1.7)));
    }
    for &t in &threads {
        for &nx in &sizes {
            let (Some(e), Some(i)) = (ours("edac", nx, t, 1), ours("ctvf+ipst", nx, t, 1)) else { continue };
            let case = format!("nx = {nx}, {t} thread(s), cost against edac");
            let target = "ctvf+ipst within 3x the cost of edac a step";
            rows.push(TargetRow::new(target, case, Ratio::of(e, i), Bound::AtMost(3.0)));
        }
    }
    rows
}

/// The rows as a Markdown table.
pub(super) fn table(rows: &[TargetRow]) -> String {
    let mut s = String::from(
        "| target | case | measured: median [95 % interval] (range) | bound | verdict |\n|---|---|---|---|---|\n",
    );
    for r in rows {
        let verdict = match r.verdict {
            Verdict::Met => "met",
            Verdict::Missed => "missed",
            Verdict::Undecided => "undecided (the interval straddles the bound)",
        };
        let how = if r.measured.interval.is_none() && r.measured.rounds > 1 {
            " (no interval: under six rounds)"
        } else {
            ""
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {verdict}{how} |\n",
            r.target,
            r.case,
            r.measured.format(2, ""),
            r.bound
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::super::testutil::sample;
    use super::*;

    /// A configuration with its runs, the median run's throughput as its own.
    fn run(variant: &str, nx: usize, threads: usize, copies: usize, runs: Vec<f64>) -> BenchResult {
        let mut sorted = runs.clone();
        sorted.sort_by(f64::total_cmp);
        BenchResult { copies, runs, ..sample(variant, nx, threads, sorted[(sorted.len() - 1) / 2]) }
    }

    fn peer(nx: usize, speed: f64, runs: Vec<f64>) -> PeerResult {
        PeerResult {
            peer: "pysph".into(),
            nx,
            threads: 2,
            particle_steps_per_second: speed,
            tf: 2.0,
            t_final: Some(2.0),
            l1_velocity_final: Some(0.02),
            sphrepro_l1_velocity_final: Some(0.0125),
            runs,
        }
    }

    fn find<'a>(rows: &'a [TargetRow], target: &str, case: &str) -> &'a TargetRow {
        rows.iter()
            .find(|r| r.target.contains(target) && r.case.contains(case))
            .unwrap_or_else(|| panic!("no row {target} / {case} in {rows:#?}"))
    }

    /// A bound is met only if the whole interval of the median meets it, missed if the
    /// whole interval misses it, and undecided in between; with fewer than six rounds the
    /// median decides.
    #[test]
    fn verdicts_follow_the_interval_of_the_median() {
        let six = |lo: f64, hi: f64| Ratio {
            median: (lo + hi) / 2.0,
            interval: Some((lo, hi)),
            range: (lo, hi),
            rounds: 6,
        };
        let v = |r: Ratio, b: Bound| TargetRow::new("t", String::new(), r, b).verdict;
        assert_eq!(v(six(1.72, 1.9), Bound::AtLeast(1.7)), Verdict::Met);
        assert_eq!(v(six(1.5, 1.69), Bound::AtLeast(1.7)), Verdict::Missed);
        assert_eq!(v(six(1.6, 1.8), Bound::AtLeast(1.7)), Verdict::Undecided);
        assert_eq!(v(six(2.7, 3.1), Bound::AtMost(3.0)), Verdict::Undecided);
        assert_eq!(v(six(2.5, 2.9), Bound::AtMost(3.0)), Verdict::Met);
        let three = Ratio { median: 1.75, interval: None, range: (1.5, 1.9), rounds: 3 };
        assert_eq!(v(three, Bound::AtLeast(1.7)), Verdict::Met);
        assert_eq!(v(Ratio::single(3.2), Bound::AtMost(3.0)), Verdict::Missed);
    }

    /// A cost a particle-step of `a N^e` gives back `e`; flat costs give 0.
    #[test]
    fn the_cost_exponent_is_the_slope_in_logarithms() {
        let speeds = |e: f64| -> Vec<(usize, f64)> {
            [2500usize, 10_000, 40_000, 160_000]
                .iter()
                .map(|&n| (n, 1.0 / (3e-7 * (n as f64).powf(e))))
                .collect()
        };
        assert!(cost_exponent(&speeds(0.0)).abs() < 1e-12);
        assert!((cost_exponent(&speeds(0.1)) - 0.1).abs() < 1e-12);
        assert!((cost_exponent(&speeds(-0.02)) + 0.02).abs() < 1e-12);
    }

    /// A run with the peer at nx = 50 and 400 and ours at both, on two threads: every
    /// peer target, read round by round, and both ratios at nx = 400 on rows of their own.
    #[test]
    fn peer_targets_compare_round_by_round() {
        let results = [
            run("edac", 50, 2, 1, vec![3.0e6, 3.3e6, 2.7e6]),
            run("edac", 400, 2, 1, vec![4.0e6, 4.2e6, 3.6e6]),
        ];
        let peers = [peer(50, 0.2e6, vec![0.2e6, 0.3e6, 0.2e6]), peer(400, 0.5e6, vec![0.5e6, 0.5e6, 0.4e6])];
        let rows = targets(&results, &peers);
        // 3.0/0.2 = 15, 3.3/0.3 = 11, 2.7/0.2 = 13.5: median 13.5.
        let at_50 = find(&rows, "10x the peer", "nx = 50");
        assert_eq!((at_50.measured.median, at_50.measured.range), (13.5, (11.0, 15.0)));
        assert_eq!(at_50.verdict, Verdict::Met);
        let l1 = find(&rows, "L1 error", "");
        assert!((l1.measured.median - 0.625).abs() < 1e-12 && l1.verdict == Verdict::Met);
        // Against the peer at nx = 50: 20, 14, 18; against the peer at nx = 400: 8, 8.4, 9.
        let beat = find(&rows, "15x the peer at nx = 50", "nx = 400");
        assert_eq!((beat.measured.median, beat.verdict), (18.0, Verdict::Met));
        let same = find(&rows, "same size", "nx = 400");
        assert!((same.measured.median - 8.4).abs() < 1e-12 && same.verdict == Verdict::Missed);
        // Without one thread, no speed-up row; ipst was not run, so no cost row.
        assert!(rows.iter().all(|r| !r.target.contains("two threads") && !r.target.contains("ipst")));
    }

    /// Side by side: the speed-up at nx >= 100 with the host's two independent runs beside
    /// it, IPST's cost on every size and thread count, and the flatness of the cost.
    #[test]
    fn side_by_side_targets_read_speed_up_cost_and_flatness() {
        let results = [
            run("edac", 50, 1, 1, vec![2.0e6; 6]),
            run("edac", 50, 2, 1, vec![3.0e6; 6]),
            run("edac", 100, 1, 1, vec![2.0e6; 6]),
            run("edac", 100, 2, 1, vec![3.2e6, 3.4e6, 3.6e6, 3.8e6, 3.5e6, 3.3e6]),
            run("edac", 100, 1, 2, vec![3.6e6; 6]),
            run("ctvf+ipst", 100, 1, 1, vec![0.7e6; 6]),
            run("ctvf+ipst", 100, 2, 1, vec![1.0e6, 1.05e6, 1.1e6, 1.2e6, 1.1e6, 1.05e6]),
        ];
        let rows = targets(&results, &[]);
        // No nx = 50 speed-up (the target is from nx = 100 on).
        assert!(rows
            .iter()
            .filter(|r| r.target.contains("two threads"))
            .all(|r| r.case.contains("nx = 100")));
        let speed_up = find(&rows, "two threads", "nx = 100");
        // Rounds 1.6-1.9, median 1.725, interval the extremes: undecided.
        assert_eq!(speed_up.measured.interval, Some((1.6, 1.9)));
        assert_eq!(speed_up.verdict, Verdict::Undecided);
        assert!(speed_up.case.contains("2 independent runs: 1.80x"), "{}", speed_up.case);
        let one = find(&rows, "ctvf+ipst", "1 thread(s)");
        assert!((one.measured.median - 2.0 / 0.7).abs() < 1e-12 && one.verdict == Verdict::Met);
        // Rounds 3.14-3.27: the whole interval above 3, so missed.
        let two = find(&rows, "ctvf+ipst", "2 thread(s)");
        assert_eq!(two.verdict, Verdict::Missed, "{two:?}");
        // The same cost at nx = 50 and 100 on one thread: flat.
        let flat = find(&rows, "flat", "1 thread(s)");
        assert!(flat.measured.median.abs() < 1e-12 && flat.verdict == Verdict::Met);
        assert!(flat.case.contains("500 / 500 at nx = 50, 100"), "{}", flat.case);
        let t = table(&rows);
        assert!(t.contains("| undecided (the interval straddles the bound) |"), "{t}");
    }
}
