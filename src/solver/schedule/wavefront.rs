//! The gather passes of a step as a wavefront over tiles of the sorted particles, so that
//! a large body's neighbour list is still in cache when the passes read it.
//!
//! It is the fast path of a scene of one fluid body and nothing else. A step lists the
//! neighbours (with the summation density), then evaluates the pressure rates (pass A),
//! updates the pressure, and evaluates the accelerations (pass B): three sweeps over a list
//! of about 0.8 kB a particle in 2D. Once the list outgrows the cache (160 000 particles
//! make 130 MB), each sweep streams it from memory, and a particle-step cost 1.7 times as
//! much at nx = 400 as at nx = 200 on a host whose cache held the smaller list. Here the
//! particles, in cell order, are cut into
//! tiles of whole list chunks, each wider than two cell layers, so that a particle's
//! neighbours lie in its own tile or the next one on either side (cyclically). Each stage
//! of a tile then needs only the previous stage done on the tile and its two neighbours,
//! and the stages run one tile behind each other: listing tile t, pass A on tile t - 1,
//! the pressure update on tile t - 2, pass B on tile t - 3. Only about four tiles of the
//! list are alive at a time. The tiles are the narrowest the reach allows: the less of the
//! list is alive, the more of it stays in cache beside what else the step keeps there
//! (IPST's work space: in `ctvf`+`ipst` at nx = 200, passes A and B ran 1.6x faster in
//! such tiles than in sweeps on one thread). Once a tile's pass B has run its
//! payloads (the kernel values, 24 of a pair's 28 bytes) are dead, and their storage goes
//! to the next tile listed, so that the listing writes into memory still in cache rather
//! than into memory last touched a step ago: without that hand-over the wavefront took
//! 12 % off a step at nx = 400, with it 32 % (one thread; the same as at nx = 200). The
//! pairs themselves stay, for IPST's sweeps after the step.
//!
//! Every particle's sums are the same sums, over the same neighbours in the same order, as
//! in the sweeps one after the other; only the order in which particles are visited
//! changes. The results are bit for bit those of the sweeps, on any number of threads
//! (tested).
//!
//! On several threads each thread runs a wave of its own over a region of the tiles, a
//! stage of a tile at a time, and waits for another only where a stage needs one of its
//! tiles ([`Board`]). A stage forks no parallel loop: when each stage of each tile was one,
//! their forks and joins (some eighty a step at nx = 200) made the narrow tiles 13 % slower
//! than the sweeps on two threads. Which is faster, the sweeps or the
//! wavefront, depends on the host's cache, the scheme and the threads, so by default a run
//! times both on its first steps and keeps the faster ([`Schedule`], [`Tuner`]).

use crate::solver::equations::Point;
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::fluid_fluid::{FluidFluid, RateTerms};
use crate::solver::interactions::lists::{KernelAndDensity, KernelList};
use crate::solver::kernel::Kernel;
use crate::solver::nnps::{CellList, CHUNK};
use crate::solver::passes::accelerations::{shifting_dt, write_accelerations, writes_homogenisation};
use crate::solver::passes::rates::pressure_rates;
use crate::solver::passes::{set_and_regather, FluidPasses, FluidViews, Sources};
use crate::solver::scheme::{DensityModel, FluidScheme, PressureModel, PressureReference};
use crate::solver::stages::{run_stages, Grid, Tiled, WHOLE_TILE};
use crate::solver::systems::{Fluid, FluidRates};
use std::collections::VecDeque;
use std::ops::Range;
use std::time::Instant;

/// The fewest tiles a wavefront step is run with (from nx = 130 or so in 2D). On one host,
/// `ctvf`+`ipst` at nx = 150 (ten tiles) ran 6-8 % faster in tiles than in
/// sweeps on one thread; at nx = 100 (six tiles), whose list the cache mostly holds, the
/// two took the same time in three rounds, so offering the tiles there only gave the tuner
/// a choice to get wrong.
const MIN_TILES: usize = 8;

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
    /// The fewest tiles a wavefront step is run with.
    min_tiles: usize,
    /// Tile `k` holds the particles `bounds[k]..bounds[k + 1]`.
    bounds: Vec<usize>,
    /// The start of every non-empty cell layer, then the number of particles.
    layers: Vec<usize>,
    /// The workers' shared state during a step.
    board: Board,
}

/// Whether a step of a fluid of `scheme` can run as a wavefront, `alone` in its scene (no
/// other body): its passes are the listing with the summation density, pass A with the
/// EDAC pressure only, and pass B, and nothing between them reads the whole body (another
/// body, a free surface, a global mean pressure).
pub fn applies(scheme: &FluidScheme, alone: bool) -> bool {
    alone
        && scheme.free_surface.is_none()
        && scheme.density == DensityModel::Summation
        && matches!(scheme.pressure, PressureModel::Edac { .. })
        && scheme.pressure_reference != PressureReference::GlobalMean
}

impl Default for Wavefront {
    fn default() -> Self {
        Self::with_min_tiles(MIN_TILES)
    }
}

impl Wavefront {
    /// No tiles.
    pub fn new() -> Self {
        Self::default()
    }

    /// No tiles; at least `min_tiles` of them to come for a wavefront step (tests cut
    /// small bodies into few tiles).
    pub(crate) fn with_min_tiles(min_tiles: usize) -> Self {
        Self { min_tiles, bounds: Vec::new(), layers: Vec::new(), board: Board::default() }
    }

    /// Cuts the `n` particles binned by `cells` (in cell order) into tiles of whole list
    /// chunks, each at least two cell layers and a chunk wide, and checks that every
    /// particle's neighbours lie in its tile or the next ones (cyclically). Returns whether
    /// the body makes at least `MIN_TILES` (8) such tiles.
    pub fn plan<const D: usize>(&mut self, cells: &CellList<D>, n: usize) -> bool {
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
        let width = (widest_pair.div_ceil(CHUNK) + 1) * CHUNK;
        let tiles = n / width;
        if tiles < self.min_tiles.max(1) {
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
}

/// What a wavefront step reads and writes.
pub struct StepBodies<'a, const D: usize> {
    /// The fluid, sorted by cell and binned in `cells` (its scheme [`applies`]).
    pub fluid: &'a mut Fluid<D>,
    /// Its binning.
    pub cells: &'a CellList<D>,
    /// The smoothing kernel.
    pub kernel: &'a Kernel,
    /// Its neighbour list, rebuilt tile by tile, with its share of the summation density.
    pub own: &'a mut FluidFluid<D>,
    /// The passes' gathered views.
    pub passes: &'a mut FluidPasses<D>,
    /// The rates the passes write.
    pub rates: &'a mut FluidRates<D>,
}

/// Seconds spent listing, in pass A and the update, and in pass B: the threads' time in
/// each, scaled to add up to the step's.
#[derive(Clone, Copy, Debug, Default)]
pub struct StageTimes {
    /// Listing and summation density.
    pub list: f64,
    /// Pass A and the pressure update.
    pub pressure: f64,
    /// Pass B.
    pub accelerations: f64,
}

impl StageTimes {
    fn add(&mut self, stage: Stage, seconds: f64) {
        match stage {
            Stage::List => self.list += seconds,
            Stage::Rates | Stage::Update => self.pressure += seconds,
            Stage::Accelerations => self.accelerations += seconds,
        }
    }

    fn scaled(self, to: f64) -> Self {
        let f = to / (self.list + self.pressure + self.accelerations).max(f64::MIN_POSITIVE);
        Self { list: self.list * f, pressure: self.pressure * f, accelerations: self.accelerations * f }
    }
}

/// A stage of a tile taken by a worker, and for a listing the tile whose list storage it
/// takes over.
#[derive(Clone, Copy, Debug)]
struct Task {
    stage: Stage,
    tile: usize,
    dead: Option<usize>,
}

/// What the workers of a wavefront step share, under a mutex: the stages done and taken
/// on each tile, and the tiles whose lists are dead. Kept in the [`Wavefront`] from step to
/// step, so that a step allocates nothing.
///
/// Each worker owns a region, a run of tiles with about as many particles as the others',
/// and runs its stages as one thread runs them all: the deepest stage that is ready first,
/// else the listing of the next tile, the region's last tile first (the next region's
/// first passes read it) and then from its first on. A stage on the tile next to it then
/// finds the tile's list and views still in its own core's cache. A worker takes stages of
/// other regions only once its own are all taken, or while some region's worker has not
/// started ([`Grid::take`]).
#[derive(Clone, Debug, Default)]
struct Board {
    grid: Grid,
    /// Stages done in all.
    finished: usize,
    /// For each region, its tiles whose lists are no longer read, in the order their pass B
    /// ended (their storage, last touched by the region's core, goes to its next listing).
    dead: Vec<VecDeque<usize>>,
    /// The threads' seconds in each kind of stage.
    times: StageTimes,
}

impl Board {
    /// Readies the board for a step over `bounds` (the tiles' first particles, then the
    /// number of particles) on `workers` threads.
    fn reset(&mut self, bounds: &[usize], workers: usize) {
        self.grid.reset(bounds, workers);
        self.dead.resize_with(workers, VecDeque::new);
        self.dead.iter_mut().for_each(VecDeque::clear);
        self.finished = 0;
        self.times = StageTimes::default();
    }

    /// Stages in all.
    fn stages(&self) -> usize {
        STAGES.len() * self.grid.tiles()
    }
}

/// The tile whose stage one thread would run next among `tiles`: the deepest stage that is
/// ready, on the first tile it is ready on; else the listing of the last tile, or of the
/// first one not listed.
fn pick(g: &Grid, tiles: Range<usize>) -> Option<usize> {
    let deepest = (1..STAGES.len() as u32).rev().find_map(|s| tiles.clone().find(|&k| g.ready(s, k)));
    deepest.or_else(|| {
        let last = tiles.end.checked_sub(1).filter(|_| !tiles.is_empty())?;
        std::iter::once(last).chain(tiles.start..last).find(|&k| g.ready(0, k))
    })
}

impl crate::solver::stages::Board for Board {
    type Task = Task;
    type Out = ();

    fn grid(&mut self) -> &mut Grid {
        &mut self.grid
    }

    fn take(&mut self, w: usize) -> Option<Task> {
        let (tile, s) = self.grid.take(w, STAGES.len() as u32, pick)?;
        let stage = STAGES[s as usize];
        let dead = if stage == Stage::List { self.dead[self.grid.region_of(tile)].pop_front() } else { None };
        Some(Task { stage, tile, dead })
    }

    fn finish(&mut self, task: Task, (): (), seconds: f64) {
        self.grid.done[task.tile] += 1;
        self.finished += 1;
        self.times.add(task.stage, seconds);
        if task.stage == Stage::Accelerations {
            let region = self.grid.region_of(task.tile);
            self.dead[region].push_back(task.tile);
        }
    }

    fn over(&self) -> bool {
        self.finished == self.stages()
    }
}

impl Wavefront {
    /// The listing, summation density, pass A with the pressure update over `dt`, and pass B
    /// (whose shifting is scaled for `dt_accel`) of a step, tile by tile as `wave` plans
    /// them ([`Wavefront::plan`] must have returned true for these particles). The threads
    /// of the pool each take whole stages of tiles whose inputs are done, so that a stage
    /// forks nothing and threads wait for each other only where the dependencies make them.
    pub fn step<const D: usize>(&mut self, b: StepBodies<'_, D>, dt: f64, dt_accel: f64) -> StageTimes {
        let clock = Instant::now();
        let StepBodies { fluid, cells, kernel, own, passes, rates } = b;
        let FluidFluid { list, density: fluid_density, .. } = own;
        let n = fluid.len();
        list.begin(cells, n);
        fluid_density.resize(n, 0.0);
        passes
            .points
            .resize(n, Point::new(fluid.u[0], fluid.u_hat()[0], fluid.m[0], fluid.rho[0], fluid.p[0]));
        let scheme = fluid.physics;
        rates.a_c_dt = shifting_dt(&scheme, dt_accel);
        let terms = RateTerms::new(&scheme);
        let writes_ac = writes_homogenisation(&scheme);
        let wave = self;
        let mut board = std::mem::take(&mut wave.board);
        board.reset(&wave.bounds, rayon::current_num_threads());

        // Each stage of a tile writes only that tile's elements, and reads its neighbours'
        // only once their writers are done and before their next writer starts (the
        // dependencies of `Grid::ready`; see the match below). So the slices written are
        // handed out by tile (`Tiled`, `ChunkWriter`), and read element by element (the
        // views through `Tiled::gather`, the list chunk by chunk), never through a reference
        // to a whole array, whose making would read the elements other threads write.
        let (rho, p) = (Tiled::new(&mut fluid.rho), Tiled::new(&mut fluid.p));
        let points = Tiled::new(&mut passes.points);
        let density = Tiled::new(fluid_density);
        let (dp, du) = (Tiled::new(&mut rates.dp), Tiled::new(&mut rates.du));
        let a_c = Tiled::new(if writes_ac { &mut rates.a_c[..] } else { &mut [] });
        let writer = list.chunk_writer();
        let (fluid, list, tiles): (&Fluid<D>, &KernelList<D>, &Wavefront) = (fluid, list, wave);
        let views = FluidViews::of(fluid);
        let listing = KernelAndDensity::new(&fluid.m, fluid.h, kernel);
        let chunks_of = |k: usize| tiles.range(k).start / CHUNK..tiles.range(k).end.div_ceil(CHUNK);
        let run = |task: Task| {
            let (k, r) = (task.tile, tiles.range(task.tile));
            // SAFETY (of each `run`, `build_chunks` and `recycle` below): only this stage
            // touches tile k's elements now. Every stage of a tile waits for the one before
            // it on the tile. The list of tile k is read by passes A and B of tile k only,
            // and a dead tile's by none: its pass B is done. The views of tile k's particles
            // (`points`), written by its listing and its update, are read by the passes of
            // tiles k - 1..=k + 1 (whose neighbours lie there, `Wavefront::plan`), which wait
            // for those writes, and the update waits for the three passes A that read what
            // it overwrites. Density, pressure and rates are read by tile k's stages only.
            match task.stage {
                Stage::List => unsafe {
                    if let Some(dead) = task.dead {
                        for (d, c) in chunks_of(dead).zip(chunks_of(k)) {
                            writer.recycle(d, c);
                        }
                    }
                    let rho_k = density.run(r.clone());
                    let payload = |r2: &[f64], out: &mut [_]| listing.payload(r2, out);
                    writer.build_chunks(list, cells, &fluid.x, payload, chunks_of(k), rho_k, |p| {
                        listing.density(p)
                    });
                    // Without walls the summation density is the fluid's share.
                    let rho_k = &*rho_k;
                    let own = (points.run(r.clone()), rho.run(r.clone()), p.run(r.clone()));
                    set_and_regather(views, r.start, own, |i, rho, _| *rho = rho_k[i - r.start], WHOLE_TILE);
                },
                Stage::Rates => unsafe {
                    let src = Sources::new(fluid, list, points.gather(), Boundaries::none());
                    pressure_rates(&terms, &src, r.start, dp.run(r.clone()), WHOLE_TILE);
                },
                Stage::Update => unsafe {
                    // eq. (57)
                    let dp_k = &*dp.run(r.clone());
                    let own = (points.run(r.clone()), rho.run(r.clone()), p.run(r.clone()));
                    set_and_regather(views, r.start, own, |i, _, p| *p += dt * dp_k[i - r.start], WHOLE_TILE);
                },
                Stage::Accelerations => unsafe {
                    let src = Sources::new(fluid, list, points.gather(), Boundaries::none());
                    let a_c = if writes_ac { a_c.run(r.clone()) } else { &mut [] };
                    write_accelerations(
                        &src,
                        fluid,
                        None,
                        dt_accel,
                        r.start,
                        du.run(r.clone()),
                        a_c,
                        WHOLE_TILE,
                    );
                },
            }
        };
        let board = run_stages(board, &run);
        debug_assert!(!board.grid.failed && board.finished == board.stages(), "every stage ran");
        let times = board.times.scaled(clock.elapsed().as_secs_f64());
        wave.board = board;
        times
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::math::Vector;
    use crate::solver::nnps::{Domain, NeighbourList};
    use crate::solver::stages::take_turns;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every stage of every tile runs once, after the stage before it on the tile and on
    /// both tiles next to it (cyclically), as the board hands the stages to workers that
    /// take turns (one, two or three, starting at once or one late, each stage taking one
    /// turn). One worker keeps the list local: at most seven tiles are listed and not yet
    /// through pass B at any time (four in the wave, three held back at the periodic edge),
    /// whatever the number of tiles. Several workers each run a wave over their region, and
    /// wait for each other no longer on many tiles than on few.
    #[test]
    fn the_board_runs_each_stage_once_after_its_inputs() {
        let mut idle_turns = Vec::new();
        for workers in 1..=3 {
            for late in [false, true] {
                for n in 1..60 {
                    let what =
                        format!("{n} tiles, {workers} workers{}", if late { ", one late" } else { "" });
                    let bounds: Vec<usize> = (0..=n).map(|k| k * 100).collect();
                    let mut b = Board::default();
                    b.reset(&bounds, workers);
                    let mut most_open = 0;
                    let idle = take_turns(
                        &what,
                        &mut b,
                        workers,
                        late,
                        |_| (),
                        |_, _| {},
                        |b| {
                            let open = b.grid.done.iter().filter(|&&l| (1..4).contains(&l)).count();
                            most_open = most_open.max(open);
                        },
                    );
                    assert!(
                        b.grid.done.iter().all(|&l| l == 4) && b.grid.taken.iter().all(|&l| l == 4),
                        "{what}: every stage once"
                    );
                    if workers == 1 {
                        assert!(most_open <= 7, "{what}: {most_open} tiles open at once");
                    }
                    let covered: usize = b.grid.regions.iter().map(|r| r.len()).sum();
                    assert_eq!(covered, n, "{what}: the regions cover the tiles");
                    idle_turns.push((workers, late, n, idle));
                }
            }
        }
        // The waves never stall on each other: the turns a worker waits (for a region one
        // tile longer than another, or a late start) do not grow with the number of tiles.
        for workers in 1..=3 {
            for late in [false, true] {
                let most = |tiles: Range<usize>| {
                    let of =
                        idle_turns.iter().filter(|t| t.0 == workers && t.1 == late && tiles.contains(&t.2));
                    of.map(|t| t.3).max().unwrap()
                };
                let (few, many) = (most(16..22), most(22..60));
                assert!(
                    many <= few,
                    "{workers} workers, late {late}: waits {many} turns on many tiles, {few} on 16-21"
                );
            }
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
                let mut w = Wavefront::with_min_tiles(4);
                if !w.plan(&cells, n) {
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
}
