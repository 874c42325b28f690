//! Which order a step's gather passes run in, the sweeps or the wavefront, timed on a
//! run's first steps: which is faster depends on the host's cache, the scheme and the
//! threads, and either gives the same results.

/// How a step's gather passes are ordered; the results are the same bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Schedule {
    /// The fastest of the others on this host, timed over the first steps ([`Tuner`]).
    #[default]
    Tuned,
    /// Each pass over the whole body, one after the other.
    Sweeps,
    /// Tile by tile where the scheme and the body allow ([`Wavefront`]), else sweeps.
    Wavefront,
}

/// Steps a [`Tuner`] runs a schedule for in a row (`BLOCK`), and how many of the first of
/// them it does not time (`SETTLE`): a schedule pays for its predecessor's state for two
/// or three steps after a change. At nx = 200 on two threads, on one host,
/// `edac`'s first steps in tiles after sweeps ran 10-20 % faster than the ones after them,
/// and the sweeps' first steps after tiles 10-20 % slower: timed step by step in
/// alternation, the tiles looked faster than the sweeps, and ran 13 % slower when kept.
const BLOCK: usize = 6;
const SETTLE: usize = 3;
/// Blocks of each schedule before the tuner keeps one, in turn, so that a slow spell of the
/// host does not fall on one schedule alone.
const ROUNDS: usize = 3;

/// How much faster than the wavefront the sweeps must have run for the tuner to keep them.
/// The tiles keep a step's lists in cache, so they lose less than the sweeps to whatever
/// runs between and around the passes: after a pause as long as IPST's sweeps, the listing
/// and passes took 4-6 % longer in tiles and 6-17 % in sweeps (nx = 200, one thread), and where
/// `edac` at nx = 200 on two threads ran within 3 % in either order alone, the sweeps ran
/// 338 ns a particle-step against 297 for the tiles when stepped side by side with other
/// runs (`bench --interleave`).
const SWEEPS_MARGIN: f64 = 0.03;

/// Steps the tuner takes at most before it keeps a schedule: a block of sweeps untimed (a
/// run's first steps, which fault its memory in, took up to three times as long as the
/// later ones), then `ROUNDS` blocks of the sweeps and of the wavefront.
pub const TUNING_STEPS: usize = (1 + 2 * ROUNDS) * BLOCK;

/// Picks the faster of the sweeps and the wavefront for a body. Which one
/// is faster is a property of the host and the scheme: on one host the wavefront was 1.45x faster at nx = 400 but 10 % slower on two threads at nx = 256, where
/// the list still fitted its cache; on hosts whose memory kept up with the sweeps, only
/// its cost would show. The first steps go round the candidates in blocks of `BLOCK`
/// steps, `ROUNDS` times, then the one with the shortest median timed step (of the last
/// `BLOCK - SETTLE` steps of each block) is kept, the wavefront unless the sweeps beat it by
/// more than `SWEEPS_MARGIN`.
/// Each gives the same results, so the choice changes only the speed.
#[derive(Clone, Debug, Default)]
pub struct Tuner {
    /// The schedules timed, sweeps first: empty until the body first makes tiles.
    candidates: Vec<Schedule>,
    /// Seconds of each candidate's timed steps.
    seconds: Vec<Vec<f64>>,
    /// Steps recorded so far.
    steps: usize,
    chosen: Option<Schedule>,
}

impl Tuner {
    /// Whether the candidates are still to be offered.
    pub fn needs_candidates(&self) -> bool {
        self.candidates.is_empty()
    }

    /// The schedules to time, once (later offers are ignored).
    pub fn offer(&mut self, candidates: Vec<Schedule>) {
        if self.candidates.is_empty() {
            self.seconds = vec![Vec::with_capacity(ROUNDS * (BLOCK - SETTLE)); candidates.len()];
            self.candidates = candidates;
        }
    }

    /// The schedule of the next step: the one kept, else the one whose block it is (the
    /// sweeps in the first, untimed block); sweeps without candidates.
    pub fn next(&self) -> Schedule {
        match (self.chosen, self.turn()) {
            (Some(kept), _) => kept,
            (None, Some(k)) => self.candidates[k],
            (None, None) => Schedule::Sweeps,
        }
    }

    /// The candidate whose block the next step is in, if it is not the first block.
    fn turn(&self) -> Option<usize> {
        (self.steps / BLOCK).checked_sub(1).and_then(|b| b.checked_rem(self.candidates.len()))
    }

    /// The schedule kept, once the trials are done.
    pub fn chosen(&self) -> Option<Schedule> {
        self.chosen
    }

    /// Records a step that took `seconds` under `schedule` (ignored unless it is
    /// [`next`](Self::next)'s, while the trials last).
    pub fn record(&mut self, schedule: Schedule, seconds: f64) {
        if self.chosen.is_some() || self.candidates.is_empty() || schedule != self.next() {
            return;
        }
        if let Some(k) = self.turn() {
            if self.steps % BLOCK >= SETTLE {
                self.seconds[k].push(seconds);
            }
        }
        self.steps += 1;
        if self.steps == (1 + ROUNDS * self.candidates.len()) * BLOCK {
            // In place: the step allocates nothing.
            let median = |t: &mut [f64]| {
                t.sort_by(f64::total_cmp);
                (t[(t.len() - 1) / 2] + t[t.len() / 2]) / 2.0
            };
            let (mut best, mut tiles) = (None::<(Schedule, f64)>, None);
            for (k, &schedule) in self.candidates.iter().enumerate() {
                let m = median(&mut self.seconds[k]);
                if best.is_none_or(|b| m < b.1) {
                    best = Some((schedule, m));
                }
                if schedule == Schedule::Wavefront {
                    tiles = Some(m);
                }
            }
            self.chosen = match (best, tiles) {
                (Some((_, b)), Some(t)) if t <= b * (1.0 + SWEEPS_MARGIN) => Some(Schedule::Wavefront),
                (b, _) => b.map(|b| b.0),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tuner runs a block of sweeps untimed, then goes round its candidates in blocks,
    /// sweeps first, leaving each block's first steps untimed, and keeps the one with the
    /// shortest median timed step (the tiles, unless the sweeps beat them by more than
    /// `SWEEPS_MARGIN`): neither a change's transient nor one slow step decides.
    /// Without candidates it runs the sweeps and keeps nothing.
    #[test]
    fn the_tuner_keeps_the_schedule_with_the_shortest_median_settled_step() {
        let tiles = Schedule::Wavefront;
        let tune = |tiles_settled: f64| {
            let mut t = Tuner::default();
            assert!(t.needs_candidates());
            assert_eq!(t.next(), Schedule::Sweeps);
            t.record(Schedule::Sweeps, 1.0);
            assert_eq!(t.chosen(), None, "nothing timed without candidates");
            t.offer(vec![Schedule::Sweeps, tiles]);
            assert!(!t.needs_candidates());
            let (mut order, mut at) = (Vec::new(), 0);
            while t.chosen().is_none() {
                let s = t.next();
                // The step's place in its block: the transient of a change lasts SETTLE steps.
                let settled =
                    order.last() == Some(&s) && order.iter().rev().take_while(|&&o| o == s).count() >= SETTLE;
                let seconds = match s {
                    _ if at < BLOCK => 5.0, // the run's first steps
                    Schedule::Sweeps if settled => 1.0,
                    Schedule::Sweeps => 3.0,
                    _ if !settled => 0.1,
                    // one slow step, the tiles' first settled one
                    _ if order.iter().filter(|&&o| o == tiles).count() == SETTLE => 9.0,
                    _ => tiles_settled,
                };
                t.record(s, seconds);
                order.push(s);
                at += 1;
            }
            let mut expected = vec![Schedule::Sweeps; BLOCK];
            for _ in 0..ROUNDS {
                for s in [Schedule::Sweeps, tiles] {
                    expected.extend([s; BLOCK]);
                }
            }
            assert_eq!(order, expected);
            assert_eq!(order.len(), TUNING_STEPS);
            t
        };
        let mut t = tune(1.1);
        assert_eq!(t.chosen(), Some(Schedule::Sweeps), "the tiles' fast first steps do not decide");
        // Sweeps faster by less than the margin: the tiles, which lose less to the host.
        assert_eq!(tune(1.0 + SWEEPS_MARGIN / 2.0).chosen(), Some(tiles), "within the margin");
        let t2 = tune(0.9);
        assert_eq!(t2.chosen(), Some(tiles), "one slow step does not decide");
        assert_eq!(t2.next(), tiles);
        t.record(tiles, 0.01);
        t.offer(vec![tiles]);
        assert_eq!(t.chosen(), Some(Schedule::Sweeps), "kept once chosen");
        let mut slow = Tuner::default();
        slow.offer(vec![Schedule::Sweeps, tiles]);
        while slow.chosen().is_none() {
            slow.record(Schedule::Tuned, 0.1);
            let s = slow.next();
            slow.record(s, if s == tiles { 1.2 } else { 1.0 });
        }
        assert_eq!(slow.chosen(), Some(Schedule::Sweeps), "only the schedule run counts");
    }
}
