//! The progress of a run: a bar on the terminal (simulated time, steps per second and the
//! time left) and a file a parent runner reads. The time left is estimated from the
//! simulated time this run has covered so far (not from the bar's position, which cannot
//! move while a run crawls through its first thousandth of `tf`).

use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Positions of the bar from `t = 0` to `tf`: fine enough that a long run moves it.
const LENGTH: u64 = 1_000_000;

/// The progress of one run, started at simulated time `t0` after `steps0` steps (a resumed
/// run starts where its checkpoint left off): its bar (none when quiet or not on a
/// terminal) and its progress file (if asked for), rewritten at most twice a second.
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    file: Option<PathBuf>,
    last_write: Instant,
    tf: f64,
    start: Instant,
    t0: f64,
    steps0: u64,
}

impl Progress {
    /// A bar on stderr, unless `quiet` or stderr is not a terminal, and the progress file
    /// `file`.
    pub fn new(quiet: bool, file: Option<PathBuf>, tf: f64, t0: f64, steps0: u64) -> Self {
        use std::io::IsTerminal;
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::with_draw_target(
                Some(LENGTH),
                indicatif::ProgressDrawTarget::stderr(),
            );
            bar.set_style(
                indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {msg}")
                    .expect("valid template"),
            );
            bar
        });
        let now = Instant::now();
        Self { bar, file, last_write: now, tf, start: now, t0, steps0 }
    }

    /// Shows the run at simulated time `t` after `steps` steps in all; `extra` is appended
    /// to the bar (e.g. the particle-steps per second of the stepping so far).
    pub fn update(&mut self, t: f64, steps: u64, extra: &str) {
        if self.bar.is_none() && self.file.is_none() {
            return;
        }
        let elapsed = self.start.elapsed().as_secs_f64();
        if let Some(bar) = &self.bar {
            bar.set_position(((t / self.tf).clamp(0.0, 1.0) * LENGTH as f64) as u64);
            let rate = (elapsed > 0.0).then(|| steps.saturating_sub(self.steps0) as f64 / elapsed);
            bar.set_message(line(t, self.tf, steps, rate, time_left(elapsed, self.t0, t, self.tf), extra));
        }
        if let Some(path) = &self.file {
            if self.last_write.elapsed().as_millis() >= 500 {
                self.last_write = Instant::now();
                if let Ok(mut f) = std::fs::File::create(path) {
                    let _ = writeln!(f, "{t} {} {steps} {} {elapsed}", self.tf, self.t0);
                }
            }
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// A progress file's `time tf steps t0 seconds` (the simulated time this run started from
/// and the wall seconds it has taken since): `(time, tf, seconds left)`; `None` if the
/// file is not (yet) whole.
pub fn read_file(text: &str) -> Option<(f64, f64, Option<f64>)> {
    let v: Vec<f64> = text.split_whitespace().map(|x| x.parse().ok()).collect::<Option<_>>()?;
    match v[..] {
        [t, tf, _, t0, seconds] if tf > 0.0 => Some((t, tf, time_left(seconds, t0, t, tf))),
        _ => None,
    }
}

/// Seconds left at the pace of this run so far: `elapsed` wall seconds took the run from
/// simulated time `t0` to `t`; `None` before it has covered any (the pace is unknown, and
/// "0 s" would be a lie).
pub fn time_left(elapsed: f64, t0: f64, t: f64, tf: f64) -> Option<f64> {
    let covered = t - t0;
    (covered > 0.0 && elapsed > 0.0).then(|| elapsed / covered * (tf - t).max(0.0))
}

/// The bar's message.
fn line(
    t: f64,
    tf: f64,
    steps: u64,
    steps_per_second: Option<f64>,
    left: Option<f64>,
    extra: &str,
) -> String {
    let rate = steps_per_second.map_or_else(|| "-".to_string(), |r| format!("{r:.0}"));
    let left = left.map_or_else(|| "?".to_string(), duration);
    let extra = if extra.is_empty() { String::new() } else { format!("  {extra}") };
    // Four decimals, or three significant digits while t is below a thousandth.
    let t = if t == 0.0 || t.abs() >= 1e-3 { format!("{t:.4}") } else { format!("{t:.3e}") };
    format!("t = {t}/{tf}  step {steps}  {rate} steps/s  left {left}{extra}")
}

/// `1h 02m`, `3m 05s`, `12s` (to the nearest second), `<1s`; past a hundred days, `> 100 d`.
pub fn duration(seconds: f64) -> String {
    if !seconds.is_finite() || seconds > 100.0 * 86_400.0 {
        return "> 100 d".into();
    }
    if seconds < 0.5 {
        return "<1s".into();
    }
    let s = Duration::from_secs_f64(seconds.round()).as_secs();
    match (s / 3600, s / 60 % 60, s % 60) {
        (h, _, _) if h >= 24 => format!("{}d {:02}h", h / 24, h % 24),
        (h, m, _) if h > 0 => format!("{h}h {m:02}m"),
        (_, m, s) if m > 0 => format!("{m}m {s:02}s"),
        (_, _, s) => format!("{s}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_left_is_unknown_until_the_run_has_moved() {
        assert_eq!(time_left(3.0, 0.0, 0.0, 2.0), None);
        assert_eq!(time_left(0.0, 0.0, 0.0, 2.0), None);
        // A quarter of tf in 10 s: three quarters left, 30 s.
        assert_eq!(time_left(10.0, 0.0, 0.5, 2.0), Some(30.0));
        // A resumed run is paced by what it covered itself, from t0.
        assert_eq!(time_left(10.0, 1.0, 1.5, 2.0), Some(10.0));
        assert_eq!(time_left(10.0, 0.0, 2.0, 2.0), Some(0.0));
    }

    #[test]
    fn a_progress_file_reads_back_with_its_pace() {
        assert_eq!(read_file("0.5 2 40 0 10\n"), Some((0.5, 2.0, Some(30.0))));
        assert_eq!(read_file("1.5 2 40 1 10"), Some((1.5, 2.0, Some(10.0))));
        assert_eq!(read_file("0 2 0 0 0.1"), Some((0.0, 2.0, None)));
        for partial in ["", "0.5 2 40", "0.5 2 40 0 1x", "0.5 0 40 0 10"] {
            assert_eq!(read_file(partial), None, "{partial:?}");
        }
    }

    #[test]
    fn a_crawling_run_shows_its_true_time_left() {
        // 1.36e-5 s of tf = 0.05 in 3 s (the viscous step limit at Re = 1e-6, nx = 20):
        // 3 s / 1.36e-5 s * (0.05 - 1.36e-5) s = 11 027 s left, where the bar's position
        // (a thousandth of tf at best) had not moved and indicatif's estimate said 0 s.
        let left = time_left(3.0, 0.0, 1.36e-5, 0.05).unwrap();
        assert!((left - 11_026.5).abs() < 1.0, "{left}");
        assert_eq!(duration(left), "3h 03m");
        assert_eq!(duration(1e9), "> 100 d");
        assert_eq!(duration(40.0 * 86_400.0 + 5.0 * 3600.0), "40d 05h");
        assert_eq!(duration(3725.0), "1h 02m");
        assert_eq!(duration(185.4), "3m 05s");
        assert_eq!(duration(12.0), "12s");
        assert_eq!(duration(0.9), "1s");
        assert_eq!(duration(0.2), "<1s");
        assert_eq!(duration(f64::INFINITY), "> 100 d");
        let msg = line(1.36e-5, 0.05, 21803, Some(7267.7), Some(left), "");
        assert_eq!(msg, "t = 1.360e-5/0.05  step 21803  7268 steps/s  left 3h 03m");
        assert_eq!(line(0.0, 2.0, 0, None, None, "x"), "t = 0.0000/2  step 0  - steps/s  left ?  x");
        assert_eq!(line(0.25, 2.0, 9, Some(3.0), Some(7.0), ""), "t = 0.2500/2  step 9  3 steps/s  left 7s");
    }
}
