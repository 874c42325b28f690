//! The gather passes of a step as a wavefront over tiles of the sorted particles, so that
//! a large body's neighbour list is still in cache when the passes read it.
//!
//! A step lists the neighbours (with the summation density), then evaluates the pressure
//! rates (pass A), updates the pressure, and evaluates the accelerations (pass B): three
//! sweeps over a list of about 0.8 kB a particle in 2D. Once the list outgrows the cache
//! (160 000 particles make 130 MB), each sweep streams it from memory, and a particle-step
//! cost 1.7 times as much at nx = 400 as at nx = 200 on a host whose cache held the smaller
//! list (docs/throughput.md, session 35). Here the particles, in cell order, are cut into
//! tiles of whole list chunks, each wider than two cell layers, so that a particle's
//! neighbours lie in its own tile or the next one on either side (cyclically). Each stage
//! of a tile then needs only the previous stage done on the tile and its two neighbours,
//! and the stages run one tile behind each other: listing tile t, pass A on tile t - 1,
//! the pressure update on tile t - 2, pass B on tile t - 3. Only about four tiles of the
//! list are alive at a time. Once a tile's pass B has run its payloads (the kernel values,
//! 24 of a pair's 28 bytes) are dead, and their storage goes to the next tile listed, so
//! that the listing writes into memory still in cache rather than into memory last
//! touched a step ago: without that hand-over the wavefront took 12 % off a step at
//! nx = 400, with it 32 % (one thread; the same as at nx = 200). The pairs themselves stay,
//! for IPST's sweeps after the step.
//!
//! Every particle's sums are the same sums, over the same neighbours in the same order, as
//! in the sweeps one after the other; only the order in which particles are visited
//! changes. The results are bit for bit those of the sweeps, on any number of threads
//! (tested). Which is faster, the sweeps or the wavefront in wide or narrow tiles
//! ([`Tiles`]), depends on the host's cache, the scheme and the threads, so by default a
//! run times each on its first steps and keeps the fastest ([`Schedule`], [`Tuner`]).

use super::passes::{
    build_kernel_chunks_summing_density, pressure_rates, shifting_dt, writes_homogenisation, RateTerms,
};
use super::{DensityModel, FluidPasses, FluidScheme, KernelList, PressureModel, PressureReference};
use crate::solver::kernel::Kernel;
use crate::solver::nnps::{CellList, CHUNK};
use crate::solver::particles::{Fluid, FluidRates};
use std::ops::Range;

/// The smallest wide tile ([`Tiles::Wide`]), in list chunks (4096 particles). About five
/// tiles of the list are alive at a time, some 17 MB in 2D: tiles twice as wide lost most
/// of the gain at nx = 400 on the host that needed it (session 35); the narrowest the
/// reach allows (six chunks there) were within the noise of these, and fork more parallel
/// loops.
const MIN_TILE_CHUNKS: usize = 8;
/// The fewest tiles a wavefront step is run with (65 536 particles in 2D in wide tiles, a
/// list three times the live window). Each stage of a tile is a parallel loop; on two
/// threads their forks and joins made a step at nx = 200 (ten tiles, a list the host's
/// cache held) 5-7 % slower than the sweeps, while at nx = 400 (39 tiles) the wavefront ran
/// 1.4x faster.
const MIN_TILES: usize = 16;

/// A stage of a tile, in the order they run on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// The neighbour list of the tile's particles, their summation density and their
    /// views for pass A.
    List,
    /// Pass A: the pressure rates (eq. 26).
    Rates,
    /// The pressure update (eq. 57) and the views for pass B.
    Update,
    /// Pass B: the accelerations (eq. 27).
    Accelerations,
}

const STAGES: [Stage; 4] = [Stage::List, Stage::Rates, Stage::Update, Stage::Accelerations];

/// The tiles of a body and the order their stages run in.
#[derive(Clone, Debug)]
pub struct Wavefront {
    /// The smallest wide tile in chunks, and the fewest tiles.
    limits: (usize, usize),
    /// Tile `k` holds the particles `bounds[k]..bounds[k + 1]`.
    bounds: Vec<usize>,
    /// The start of every non-empty cell layer, then the number of particles.
    layers: Vec<usize>,
    /// The stages in the order they run, for `schedule_tiles` tiles.
    schedule: Vec<(Stage, usize)>,
    schedule_tiles: usize,
    /// Scratch: the stages done on each tile,
    level: Vec<u8>,
    /// and the tiles whose lists are no longer read, in the order their pass B ran.
    dead: std::collections::VecDeque<usize>,
}

/// Whether a step of `scheme` (on a fluid with or without `walls`) can run as a wavefront:
/// its passes are the listing with the summation density, pass A with the EDAC pressure
/// only, and pass B, and nothing between them reads the whole body (walls, a free surface,
/// a global mean pressure).
pub fn applies(scheme: &FluidScheme, walls: bool) -> bool {
    !walls
        && scheme.free_surface.is_none()
        && scheme.density == DensityModel::Summation
        && matches!(scheme.pressure, PressureModel::Edac { .. })
        && scheme.pressure_reference != PressureReference::GlobalMean
}

impl Default for Wavefront {
    fn default() -> Self {
        Self::with_limits(MIN_TILE_CHUNKS, MIN_TILES)
    }
}

impl Wavefront {
    /// No tiles.
    pub fn new() -> Self {
        Self::default()
    }

    /// No tiles; wide tiles to come at least `wide_chunks` chunks wide, and at least
    /// `min_tiles` of them for a wavefront step (tests run small bodies in many tiles).
    pub(crate) fn with_limits(wide_chunks: usize, min_tiles: usize) -> Self {
        Self {
            limits: (wide_chunks, min_tiles),
            bounds: Vec::new(),
            layers: Vec::new(),
            schedule: Vec::new(),
            schedule_tiles: 0,
            level: Vec::new(),
            dead: Default::default(),
        }
    }

    /// Cuts the `n` particles binned by `cells` (in cell order) into tiles of whole list
    /// chunks, each at least two cell layers and a chunk wide (and, for [`Tiles::Wide`],
    /// `MIN_TILE_CHUNKS`), and checks that every particle's neighbours lie in its tile or
    /// the next ones (cyclically). Returns whether the body makes at least `MIN_TILES` (16)
    /// such tiles.
    pub fn plan<const D: usize>(&mut self, cells: &CellList<D>, n: usize, tiles: Tiles) -> bool {
        let (wide_chunks, min_tiles) = self.limits;
        let min_tile_chunks = match tiles {
            Tiles::Wide => wide_chunks,
            Tiles::Narrow => 1,
        };
        self.layers.clear();
        for l in 0..cells.layers() {
            let r = cells.layer_points(l..l + 1);
            if !r.is_empty() {
                self.layers.push(r.start);
            }
        }
        self.layers.push(n);
        let layer_count = self.layers.len() - 1;
        if layer_count < 3 {
            return false;
        }
        let widest_pair = self.layers.windows(3).map(|w| w[2] - w[0]).max().unwrap_or(n);
        let width = (widest_pair.div_ceil(CHUNK) + 1).max(min_tile_chunks) * CHUNK;
        let tiles = n / width;
        if tiles < min_tiles.max(1) {
            return false;
        }
        self.bounds.clear();
        self.bounds.extend((0..tiles).map(|k| k * width));
        // The last tile takes the remainder, so that it is at least as wide as the others.
        self.bounds.push(n);
        self.reach_holds()
    }

    /// Whether each tile's neighbours, which lie in the cell layers from the one before its
    /// first particle's to the one after its last particle's (a cell is at least a search
    /// radius wide; across a periodic last axis the first and last layers are neighbours),
    /// lie in the tile and the tiles next to it.
    fn reach_holds(&self) -> bool {
        let (layers, tiles) = (self.layers.len() - 1, self.tiles());
        let layer_of = |i: usize| self.layers.partition_point(|&s| s <= i) - 1;
        let tile_of = |i: usize| self.bounds.partition_point(|&s| s <= i) - 1;
        // A layer's particles lie in tiles k - 1..=k + 1 (cyclically).
        let within = |k: usize, l: usize| {
            let (first, last) = (tile_of(self.layers[l]), tile_of(self.layers[l + 1] - 1));
            let near = |t: usize| t == k || t == (k + 1) % tiles || t == (k + tiles - 1) % tiles;
            near(first) && near(last) && last - first <= 2
        };
        (0..tiles).all(|k| {
            let (lo, hi) = (layer_of(self.bounds[k]), layer_of(self.bounds[k + 1] - 1));
            let around = [(lo + layers - 1) % layers, lo, hi, (hi + 1) % layers];
            around.iter().all(|&l| within(k, l))
        })
    }

    /// Number of tiles.
    pub(crate) fn tiles(&self) -> usize {
        self.bounds.len() - 1
    }

    /// The particles of tile `k`.
    fn range(&self, k: usize) -> Range<usize> {
        self.bounds[k]..self.bounds[k + 1]
    }

    /// Orders the stages: the deepest stage that is ready, else the next tile's listing
    /// (the last tile first, which the first tile's passes read across a periodic edge). A
    /// stage is ready on a tile when the stage before it is done on the tile and on both
    /// tiles next to it. Kept while the number of tiles does not change.
    fn order_stages(&mut self) {
        let n = self.tiles();
        if self.schedule_tiles != n {
            self.schedule.clear();
            self.level.clear();
            self.level.resize(n, 0);
            let level = &mut self.level;
            let ready = |level: &[u8], k: usize, s: usize| {
                level[k] as usize == s
                    && level[(k + 1) % n] as usize >= s
                    && level[(k + n - 1) % n] as usize >= s
            };
            let mut listed = 0;
            while self.schedule.len() < STAGES.len() * n {
                debug_assert!(listed <= n, "some stage is ready while tiles are left");
                let next = (1..STAGES.len())
                    .rev()
                    .find_map(|s| (0..n).find(|&k| ready(level, k, s)).map(|k| (s, k)));
                let (s, k) = next.unwrap_or_else(|| {
                    listed += 1;
                    (0, (listed + n - 2) % n)
                });
                level[k] += 1;
                self.schedule.push((STAGES[s], k));
            }
            self.schedule_tiles = n;
        }
    }
}

/// How a step's gather passes are ordered; the results are the same bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Schedule {
    /// The fastest of the others on this host, timed over the first steps ([`Tuner`]).
    #[default]
    Tuned,
    /// Each pass over the whole body, one after the other.
    Sweeps,
    /// Tile by tile where the scheme and the body allow ([`Wavefront`]), else sweeps.
    Wavefront(Tiles),
}

/// How wide a wavefront's tiles are cut. Neither is faster everywhere, so the tuner times
/// both (docs/throughput.md, session 38).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tiles {
    /// At least `MIN_TILE_CHUNKS` list chunks: fewer parallel loops a step, which two
    /// threads need (at nx = 300 on the host of session 38 the narrow tiles' listing took
    /// 1.4x as long as the wide ones' on two threads).
    Wide,
    /// The narrowest the reach allows (two cell layers and a chunk): the least of the list
    /// alive at a time. Where IPST's sweeps share the cache with the list (`ctvf`+`ipst`
    /// at nx = 200, whose 40 000 particles make too few wide tiles), passes A and B ran
    /// 1.6x faster in them than in sweeps on one thread, and the step 12 % faster.
    Narrow,
}

/// Steps a [`Tuner`] runs a schedule for in a row (`BLOCK`), and how many of the first of
/// them it does not time (`SETTLE`): a schedule pays for its predecessor's state for two
/// or three steps after a change. On
/// the host of session 38, at nx = 200 on two threads, `edac`'s first steps in narrow tiles
/// after sweeps ran 10-20 % faster than the ones after them, and the sweeps' first steps
/// after tiles 10-20 % slower: timed step by step in alternation, the narrow tiles looked
/// faster than the sweeps, and ran 13 % slower when kept.
const BLOCK: usize = 6;
const SETTLE: usize = 3;
/// Blocks of each schedule before the tuner keeps one, in turn, so that a slow spell of the
/// host does not fall on one schedule alone.
const ROUNDS: usize = 2;

/// Steps the tuner takes at most before it keeps a schedule: a block of sweeps untimed (a
/// run's first steps, which fault its memory in, took up to three times as long as the
/// later ones), then `ROUNDS` blocks of the sweeps and of both widths of tiles.
pub const TUNING_STEPS: usize = (1 + 3 * ROUNDS) * BLOCK;

/// Picks the fastest of the sweeps and the wavefront's tile widths for a body. Which one
/// is faster is a property of the host and the scheme: on the host of session 35 the
/// wavefront was 1.45x faster at nx = 400 but 10 % slower on two threads at nx = 256, where
/// the list still fitted its cache; on hosts whose memory kept up with the sweeps, only
/// its cost would show. The first steps go round the candidates in blocks of `BLOCK`
/// steps, `ROUNDS` times, then the one with the shortest median timed step (of the last
/// `BLOCK - SETTLE` steps of each block) is kept.
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
            let best = (0..self.candidates.len())
                .map(|k| (k, median(&mut self.seconds[k])))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(k, _)| k);
            self.chosen = best.map(|k| self.candidates[k]);
        }
    }
}

/// What a wavefront step reads and writes.
pub struct StepBodies<'a, const D: usize> {
    /// The fluid, sorted by cell and binned in `cells`.
    pub fluid: &'a mut Fluid<D>,
    /// Its binning.
    pub cells: &'a CellList<D>,
    /// The smoothing kernel.
    pub kernel: &'a Kernel,
    /// Its neighbour list, rebuilt tile by tile.
    pub list: &'a mut KernelList<D>,
    /// The fluid's share of the summation density.
    pub fluid_density: &'a mut Vec<f64>,
    /// The scheme ([`applies`] to it).
    pub scheme: &'a FluidScheme,
    /// The rates the passes write.
    pub rates: &'a mut FluidRates<D>,
}

/// Seconds spent listing, in pass A and the update, and in pass B.
#[derive(Clone, Copy, Debug, Default)]
pub struct StageTimes {
    /// Listing and summation density.
    pub list: f64,
    /// Pass A and the pressure update.
    pub pressure: f64,
    /// Pass B.
    pub accelerations: f64,
}

impl<const D: usize> FluidPasses<D> {
    /// The listing, summation density, pass A with the pressure update over `dt`, and pass B
    /// (whose shifting is scaled for `dt_accel`) of a step, tile by tile as `wave` plans
    /// them ([`Wavefront::plan`] must have returned true for these particles).
    pub fn wavefront_step(
        &mut self,
        wave: &mut Wavefront,
        b: StepBodies<'_, D>,
        dt: f64,
        dt_accel: f64,
    ) -> StageTimes {
        let StepBodies { fluid, cells, kernel, list, fluid_density, scheme, rates } = b;
        let n = fluid.len();
        list.begin(cells, n);
        fluid_density.resize(n, 0.0);
        rates.a_c_dt = shifting_dt(scheme, dt_accel);
        let terms = RateTerms::new(scheme);
        let writes_ac = writes_homogenisation(scheme);
        // A tile's payloads are dead once its pass B ran; their storage goes to the next tile
        // listed. (IPST, after the step, reads only the pairs.)
        let mut times = StageTimes::default();
        wave.order_stages();
        wave.dead.clear();
        for &(stage, k) in &wave.schedule {
            let clock = std::time::Instant::now();
            let r = wave.range(k);
            match stage {
                Stage::List => {
                    let chunks = r.start / CHUNK..r.end.div_ceil(CHUNK);
                    if let Some(dead) = wave.dead.pop_front() {
                        let from = wave.range(dead).start / CHUNK..wave.range(dead).end.div_ceil(CHUNK);
                        for (d, c) in from.zip(chunks.clone()) {
                            list.recycle(d, c);
                        }
                    }
                    let rho = &mut fluid_density[r.clone()];
                    build_kernel_chunks_summing_density(list, cells, fluid, kernel, chunks, rho);
                    // Without walls the summation density is the fluid's share.
                    let fd = &fluid_density[..];
                    self.set_and_regather(fluid, r, |i, rho, _| *rho = fd[i]);
                }
                Stage::Rates => {
                    let src = self.sources(fluid, list, None);
                    pressure_rates(&terms, &src, r.start, &mut rates.dp[r]);
                }
                Stage::Update => {
                    // eq. (57)
                    let dp = &rates.dp[..];
                    self.set_and_regather(fluid, r, |i, _, p| *p += dt * dp[i]);
                }
                Stage::Accelerations => {
                    let a_c = if writes_ac { &mut rates.a_c[r.clone()] } else { &mut [] };
                    let du = &mut rates.du[r.clone()];
                    self.write_accelerations(fluid, list, None, None, scheme, dt_accel, r.start, du, a_c);
                    wave.dead.push_back(k);
                }
            }
            let t = clock.elapsed().as_secs_f64();
            match stage {
                Stage::List => times.list += t,
                Stage::Rates | Stage::Update => times.pressure += t,
                Stage::Accelerations => times.accelerations += t,
            }
        }
        times
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::math::Vector;
    use crate::solver::nnps::{Domain, NeighbourList};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every stage of every tile runs once, after the stage before it on the tile and on
    /// both tiles next to it (cyclically); and the list stays local: at most seven tiles
    /// are listed and not yet through pass B at any time (four in the wave, three held
    /// back at the periodic edge), whatever the number of tiles.
    #[test]
    fn the_schedule_runs_each_stage_once_after_its_inputs() {
        for n in 1..60 {
            let mut w = Wavefront::with_limits(1, 1);
            w.bounds = (0..=n).collect();
            w.order_stages();
            let mut level = vec![0; n];
            let mut most_open = 0;
            for &(stage, k) in &w.schedule {
                let s = STAGES.iter().position(|&t| t == stage).unwrap();
                assert_eq!(level[k], s, "{n} tiles: {stage:?} on tile {k}");
                if s > 0 {
                    for b in [(k + 1) % n, (k + n - 1) % n] {
                        assert!(level[b] >= s, "{n} tiles: {stage:?} on tile {k} before its inputs on {b}");
                    }
                }
                level[k] += 1;
                most_open = most_open.max(level.iter().filter(|&&l| (1..4).contains(&l)).count());
            }
            assert!(level.iter().all(|&l| l == 4), "{n} tiles: every stage once");
            assert!(most_open <= 7, "{n} tiles: {most_open} tiles open at once");
        }
    }

    /// The tiles hold what the wavefront needs: on random points in periodic and bounded
    /// boxes, every listed neighbour of a tile's particle lies in that tile or a tile next
    /// to it (cyclically), and each tile is whole chunks.
    #[test]
    fn every_neighbour_lies_in_the_tile_or_the_next_ones() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut planned, mut refused) = (0, 0);
        for periodic in [[true, true], [false, false], [false, true]] {
            for (n, radius) in [(20_000, 0.03), (30_000, 0.02), (6_000, 0.05), (20_000, 0.12)] {
                let domain = Domain { min: [0.0, 0.0], max: [1.0, 1.3], periodic };
                let mut x: Vec<Vector<2>> =
                    (0..n).map(|_| Vector::<2>::new(rng.gen::<f64>(), 1.3 * rng.gen::<f64>())).collect();
                let mut cells = CellList::new(domain, radius);
                cells.update(&x);
                x = cells.order().iter().map(|&i| x[i as usize]).collect();
                cells.mark_reordered();
                let mut list = NeighbourList::<2>::new();
                list.build(&cells, &x, |_, _| {});
                let mut w = Wavefront::with_limits(1, 4);
                if !w.plan(&cells, n, Tiles::Narrow) {
                    continue;
                }
                planned += 1;
                let tiles = w.tiles();
                // Tiles of one chunk, where a layer is wider than three chunks: a tile inside
                // it cannot have its neighbours within three chunks, and is refused.
                if w.layers.windows(2).any(|l| l[1] - l[0] > 3 * CHUNK) {
                    let mut narrow = w.clone();
                    narrow.bounds = (0..n).step_by(CHUNK).chain([n]).collect();
                    assert!(!narrow.reach_holds(), "{periodic:?}, {n} points: one-chunk tiles");
                    refused += 1;
                }
                let tile_of = |i: usize| w.bounds.partition_point(|&s| s <= i) - 1;
                for k in 0..tiles {
                    assert!(k + 1 == tiles || w.range(k).end.is_multiple_of(CHUNK), "tile {k} ends a chunk");
                    for i in w.range(k) {
                        list.for_each(i, &x, |j, _, _, _| {
                            let t = tile_of(j);
                            assert!(
                                t == k || t == (k + 1) % tiles || t == (k + tiles - 1) % tiles,
                                "{periodic:?}, {n} points: {i} in tile {k}, its neighbour {j} in tile {t}"
                            );
                        });
                    }
                }
            }
        }
        assert!(planned >= 9 && refused >= 3, "the test needs bodies that make tiles ({planned}, {refused})");
    }

    /// The tuner runs a block of sweeps untimed, then goes round its candidates in blocks,
    /// sweeps first, leaving each block's first steps untimed, and keeps the one with the
    /// shortest median timed step: neither a change's transient nor one slow step decides.
    /// Without candidates it runs the sweeps and keeps nothing.
    #[test]
    fn the_tuner_keeps_the_schedule_with_the_shortest_median_settled_step() {
        let (wide, narrow) = (Schedule::Wavefront(Tiles::Wide), Schedule::Wavefront(Tiles::Narrow));
        let tune = |narrow_settled: f64| {
            let mut t = Tuner::default();
            assert!(t.needs_candidates());
            assert_eq!(t.next(), Schedule::Sweeps);
            t.record(Schedule::Sweeps, 1.0);
            assert_eq!(t.chosen(), None, "nothing timed without candidates");
            t.offer(vec![Schedule::Sweeps, wide, narrow]);
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
                    _ if s == wide => 1.2,
                    _ if !settled => 0.1,
                    // one slow step among the narrow tiles' settled ones
                    _ if order.iter().filter(|&&o| o == narrow).count() == BLOCK - 1 => 9.0,
                    _ => narrow_settled,
                };
                t.record(s, seconds);
                order.push(s);
                at += 1;
            }
            let mut expected = vec![Schedule::Sweeps; BLOCK];
            for _ in 0..ROUNDS {
                for s in [Schedule::Sweeps, wide, narrow] {
                    expected.extend([s; BLOCK]);
                }
            }
            assert_eq!(order, expected);
            assert_eq!(order.len(), TUNING_STEPS);
            t
        };
        let mut t = tune(1.4);
        assert_eq!(t.chosen(), Some(Schedule::Sweeps), "the narrow tiles' fast first steps do not decide");
        let t2 = tune(0.9);
        assert_eq!(t2.chosen(), Some(narrow), "one slow step does not decide");
        assert_eq!(t2.next(), narrow);
        t.record(narrow, 0.01);
        t.offer(vec![narrow]);
        assert_eq!(t.chosen(), Some(Schedule::Sweeps), "kept once chosen");
        let mut slow = Tuner::default();
        slow.offer(vec![Schedule::Sweeps, wide]);
        while slow.chosen().is_none() {
            slow.record(narrow, 0.1);
            let s = slow.next();
            slow.record(s, if s == wide { 1.2 } else { 1.0 });
        }
        assert_eq!(slow.chosen(), Some(Schedule::Sweeps), "only candidates count");
    }
}
