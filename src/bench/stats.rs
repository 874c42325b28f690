//! Statistics over repeated runs (`bench --repeat`, or the rounds of `--interleave`): the
//! median run of each configuration, and ratios of throughputs taken round by round, with
//! their range and a distribution-free confidence interval of their median.

use super::case::BenchResult;
use super::peer::PeerResult;
use serde::Serialize;

/// A timed run that may be repeated: what makes two runs the same configuration, its
/// throughput, and where the throughputs of all its runs go.
pub(super) trait Repeated: Clone {
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
pub(super) use throughput_and_runs;

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
pub(super) fn median_runs<T: Repeated>(samples: Vec<T>) -> Vec<T> {
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

/// The ratio `a / b` of two throughputs: with as many runs of each (`bench --repeat`, or
/// the rounds of `--interleave`), the median of the rounds' own ratios, since
/// a slow spell of a noisy machine that falls on both runs of a round cancels in their
/// ratio, with their range (how far a target holds in single rounds) and, from six rounds
/// on, the 95 % confidence interval of that median ([`median_interval`]: whether a target
/// holds in the median); otherwise the ratio of the two (median) runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub(super) struct Ratio {
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
    pub(super) fn of(a: &impl Repeated, b: &impl Repeated) -> Self {
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
    pub(super) fn single(v: f64) -> Self {
        Self { median: v, interval: None, range: (v, v), rounds: 1 }
    }

    /// As the table gives it: `digits` decimals and a `suffix`, then the interval in
    /// brackets and the range in parentheses when there were rounds.
    pub(super) fn format(&self, digits: usize, suffix: &str) -> String {
        let median = self.median;
        if self.rounds < 2 {
            return format!("{median:.digits$}{suffix}");
        }
        let interval = self.interval.map_or(String::new(), |(l, h)| format!(" [{l:.digits$}-{h:.digits$}]"));
        let (lo, hi) = self.range;
        format!("{median:.digits$}{suffix}{interval} ({lo:.digits$}-{hi:.digits$})")
    }
}

/// A 95 % confidence interval of the median of the `sorted` samples, free of any assumption
/// on their distribution: the `k`-th smallest and the `k`-th largest, with `k` the largest
/// count for which fewer than `k` of `n` samples fall below the median with a probability
/// of at most 2.5 % (binomial, p = 1/2), so that the interval covers the median with at
/// least 95 %. None below six samples, where even the extremes cover less.
fn median_interval(sorted: &[f64]) -> Option<(f64, f64)> {
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

#[cfg(test)]
mod tests {
    use super::super::report::table;
    use super::super::testutil::sample;
    use super::*;

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
        assert_eq!(Ratio::of(&a, &b).format(1, "x"), "3.0x (2.0-4.0)");
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
        assert_eq!(Ratio::of(&a, &b).format(1, "x"), "4.5x [2.0-7.0] (2.0-7.0)");
    }
}
