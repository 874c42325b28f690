//! Work in stages over tiles, runs of a body's particles in cell order, on the threads of
//! the pool: the wavefront step's passes ([`wavefront`](crate::solver::schedule::wavefront)) and IPST's
//! sweeps ([`ipst`](crate::solver::passes::ipst)). A stage of a tile needs the stage before it done on the
//! tile and on both tiles next to it (cyclically), since a particle's neighbours lie in
//! those. Each thread owns a region of tiles and takes their stages one at a time as their
//! inputs are done ([`Grid`]), waiting for another thread only where a stage needs one of
//! its tiles. A stage is one task on one thread and forks nothing: a parallel loop per
//! stage, or per sweep, ends in a join where one thread waits for the other, and on a
//! virtual machine a waiting thread that has gone to sleep takes tens of microseconds to
//! wake.
//!
//! Which thread runs a stage never changes what it computes: every sum is over the same
//! terms in the same order.

use crate::solver::nnps::Gather;
use std::ops::Range;
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

/// The stages done and taken on each tile, and each worker's region.
#[derive(Clone, Debug, Default)]
pub(crate) struct Grid {
    /// Stages done on each tile,
    pub(crate) done: Vec<u32>,
    /// and taken by a worker (done or running).
    pub(crate) taken: Vec<u32>,
    /// The tiles of each worker's region.
    pub(crate) regions: Vec<Range<usize>>,
    /// Workers started.
    pub(crate) started: usize,
    /// Whether a stage unwound: the other workers then stop rather than wait for it.
    pub(crate) failed: bool,
}

impl Grid {
    /// Readies the grid for the tiles `bounds` (their first particles, then the number of
    /// particles) on `workers` threads, no stage done. A tile belongs to the region its
    /// middle particle falls in, so that the regions hold about as many particles each.
    pub(crate) fn reset(&mut self, bounds: &[usize], workers: usize) {
        let tiles = bounds.len() - 1;
        for v in [&mut self.done, &mut self.taken] {
            v.clear();
            v.resize(tiles, 0);
        }
        let n = bounds[tiles];
        let region_of = |k: usize| ((bounds[k] + bounds[k + 1]) / 2 * workers / n.max(1)).min(workers - 1);
        self.regions.clear();
        self.regions.extend((0..workers).map(|w| {
            let first = (0..tiles).find(|&k| region_of(k) >= w).unwrap_or(tiles);
            let end = (first..tiles).find(|&k| region_of(k) > w).unwrap_or(tiles);
            first..end
        }));
        (self.started, self.failed) = (0, false);
    }

    /// Number of tiles.
    pub(crate) fn tiles(&self) -> usize {
        self.done.len()
    }

    /// Whether stage `s` of tile `k` can start: it is not taken, and the stage before it
    /// is done on the tile and on both tiles next to it (cyclically).
    pub(crate) fn ready(&self, s: u32, k: usize) -> bool {
        let n = self.done.len();
        self.taken[k] == s
            && self.done[k] == s
            && self.done[(k + 1) % n] >= s
            && self.done[(k + n - 1) % n] >= s
    }

    /// The tile worker `w` takes a stage of next, and the stage, now taken: the tile `pick`
    /// chooses among its region's, else among all the tiles if the worker may take stages
    /// of other regions ([`roams`](Self::roams)); `None` if it is to wait.
    pub(crate) fn take(
        &mut self,
        w: usize,
        stages: u32,
        pick: impl Fn(&Self, Range<usize>) -> Option<usize>,
    ) -> Option<(usize, u32)> {
        let own = pick(self, self.regions[w].clone());
        let k = own.or_else(|| self.roams(w, stages).then(|| pick(self, 0..self.tiles())).flatten())?;
        self.taken[k] += 1;
        Some((k, self.taken[k] - 1))
    }

    /// Whether worker `w` may take stages of other regions: its own `stages` stages are
    /// all taken on every tile of its region, or some worker has not started (on a pool
    /// whose other threads are busy, one worker then runs everything, and nothing waits
    /// for a worker that never comes).
    fn roams(&self, w: usize, stages: u32) -> bool {
        self.started < self.regions.len() || self.regions[w].clone().all(|k| self.taken[k] == stages)
    }

    /// The region tile `k` belongs to.
    pub(crate) fn region_of(&self, k: usize) -> usize {
        self.regions.iter().position(|r| r.contains(&k)).unwrap_or(0)
    }
}

/// What the workers of [`run_stages`] share, under a mutex: which stage each takes next,
/// and what a stage done changes.
pub(crate) trait Board: Send {
    /// A stage of a tile.
    type Task: Copy + Send;
    /// What a stage returns to the board.
    type Out: Send;
    /// The grid of stages.
    fn grid(&mut self) -> &mut Grid;
    /// The stage worker `w` runs next, now taken; `None` if it is to wait.
    fn take(&mut self, w: usize) -> Option<Self::Task>;
    /// Records `task` done in `seconds`, with what it returned.
    fn finish(&mut self, task: Self::Task, out: Self::Out, seconds: f64);
    /// Whether the workers are to stop: every stage is done, or the work ended early.
    fn over(&self) -> bool;
}

/// Runs the stages `board` hands out on the threads of the current rayon pool, a worker a
/// thread and as many workers as the grid has regions (on one thread, the calling thread
/// runs them all in the order the board gives), until the board is over. Returns the board.
pub(crate) fn run_stages<B: Board>(mut board: B, run: &(impl Fn(B::Task) -> B::Out + Sync)) -> B {
    let workers = board.grid().regions.len();
    let board = Mutex::new(board);
    let lock = || board.lock().unwrap_or_else(PoisonError::into_inner);
    let worker = |w: usize| {
        lock().grid().started += 1;
        let mut finished = None;
        loop {
            let task = {
                let mut b = lock();
                if let Some((task, out, seconds)) = finished.take() {
                    b.finish(task, out, seconds);
                }
                if b.grid().failed || b.over() {
                    return;
                }
                b.take(w)
            };
            let Some(task) = task else {
                // A stage on another thread is under way (stages take tens of microseconds
                // or more): wait for it without giving up the core.
                for _ in 0..64 {
                    std::hint::spin_loop();
                }
                continue;
            };
            let clock = Instant::now();
            let failing = FailOnUnwind(&board);
            let out = run(task);
            std::mem::forget(failing);
            finished = Some((task, out, clock.elapsed().as_secs_f64()));
        }
    };
    on_each_thread(0, workers.max(1), &worker);
    board.into_inner().unwrap_or_else(PoisonError::into_inner)
}

/// Runs `f(w)` for `w` in `first..threads` on threads of the current rayon pool (as many
/// as take them up: with none free, the calling thread runs each in turn). Nothing `f`
/// runs may wait for another call of `f` to start, and `f` must not fork rayon tasks
/// itself: a thread waiting for a forked task may run another call of `f` on top of its own.
fn on_each_thread(first: usize, threads: usize, f: &(impl Fn(usize) + Sync)) {
    if first + 1 >= threads {
        f(first);
    } else {
        rayon::join(|| f(first), || on_each_thread(first + 1, threads, f));
    }
}

/// Marks the board failed if a stage unwinds, so that the other workers stop rather than
/// wait for it.
struct FailOnUnwind<'a, B: Board>(&'a Mutex<B>);

impl<B: Board> Drop for FailOnUnwind<'_, B> {
    fn drop(&mut self) {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).grid().failed = true;
    }
}

/// A slice that several threads write disjoint runs of at once, while other threads may
/// read other elements.
pub(crate) struct Tiled<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: elements are reached only through `run` and `view`, whose callers keep the
// threads' runs apart.
unsafe impl<T: Send> Send for Tiled<T> {}
unsafe impl<T: Send + Sync> Sync for Tiled<T> {}

impl<T> Tiled<T> {
    pub(crate) fn new(v: &mut [T]) -> Self {
        Self { ptr: v.as_mut_ptr(), len: v.len() }
    }

    /// The elements `r`, for this thread alone.
    ///
    /// # Safety
    /// No other thread reads or writes them while the borrow lives, and the slice is alive
    /// and not moved.
    #[allow(clippy::mut_from_ref)]
    pub(crate) unsafe fn run(&self, r: Range<usize>) -> &mut [T] {
        assert!(r.start <= r.end && r.end <= self.len, "{r:?} of {}", self.len);
        // SAFETY: in bounds (checked) and exclusive (the caller's contract).
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(r.start), r.len()) }
    }

    /// All the elements, to read one at a time those no thread writes meanwhile (a `&[T]`
    /// of all would read every element as it is made, while other threads write some).
    ///
    /// # Safety
    /// No element read through the result is written while it lives, and the slice is
    /// alive and not moved.
    pub(crate) unsafe fn gather(&self) -> Gather<'_, T> {
        // SAFETY: the whole slice, alive (the caller's contract).
        unsafe { Gather::from_raw(self.ptr, self.len) }
    }

    /// The elements `r`, to read.
    ///
    /// # Safety
    /// No thread writes them while the borrow lives, and the slice is alive and not moved.
    pub(crate) unsafe fn read(&self, r: Range<usize>) -> &[T] {
        assert!(r.start <= r.end && r.end <= self.len, "{r:?} of {}", self.len);
        // SAFETY: in bounds (checked), not written (the caller's contract).
        unsafe { std::slice::from_raw_parts(self.ptr.add(r.start), r.len()) }
    }
}

/// Rayon tasks of a stage: one, the whole tile (the workers of [`run_stages`] are the
/// parallelism, and must not fork).
pub(crate) const WHOLE_TILE: usize = usize::MAX;

/// Drives `board` (the case `what`) as `workers` workers taking turns would, a stage a
/// turn, the last one starting at turn 4 if `late` (a test of a [`Board`]): each turn each
/// worker finishes the stage it ran, with `out(task)`, and takes the next, which must be
/// ready by the grid's rule (asserted here) and which `taken(board, task)` may check
/// further; `turn(board)` sees the board after each turn. Returns the turns workers found
/// nothing to take.
#[cfg(test)]
pub(crate) fn take_turns<B: Board>(
    what: &str,
    b: &mut B,
    workers: usize,
    late: bool,
    out: impl Fn(&B::Task) -> B::Out,
    mut taken: impl FnMut(&B, B::Task),
    mut turn: impl FnMut(&B),
) -> usize
where
    B::Task: std::fmt::Debug,
{
    const LATE_START: usize = 4;
    let mut running: Vec<Option<B::Task>> = vec![None; workers];
    b.grid().started = if late { workers - 1 } else { workers };
    let (mut turns, mut idle) = (0, 0);
    while !b.over() {
        turns += 1;
        assert!(turns < 100_000, "{what}: stuck");
        for (w, running) in running.iter_mut().enumerate() {
            if late && w == workers - 1 {
                match turns.cmp(&LATE_START) {
                    std::cmp::Ordering::Less => continue,
                    std::cmp::Ordering::Equal => b.grid().started += 1,
                    std::cmp::Ordering::Greater => {}
                }
            }
            if let Some(t) = running.take() {
                let o = out(&t);
                b.finish(t, o, 1.0);
            }
            if b.over() {
                break;
            }
            let before = b.grid().taken.clone();
            let Some(t) = b.take(w) else {
                idle += 1;
                continue;
            };
            let g = b.grid();
            let k = (0..g.tiles()).find(|&k| g.taken[k] != before[k]).expect("a stage taken");
            let (s, n) = (before[k], g.tiles());
            assert_eq!(g.taken[k], s + 1, "{what}: {t:?}");
            assert_eq!(g.done[k], s, "{what}: {t:?} before the stage before it");
            for j in [(k + 1) % n, (k + n - 1) % n] {
                assert!(g.done[j] >= s, "{what}: {t:?} before its inputs on {j}");
            }
            taken(b, t);
            *running = Some(t);
        }
        turn(b);
    }
    idle
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A board of `stages` stages on each tile, the shallowest ready one first.
    #[derive(Debug)]
    struct Ring {
        grid: Grid,
        stages: u32,
    }

    impl Board for Ring {
        type Task = (usize, u32);
        type Out = ();
        fn grid(&mut self) -> &mut Grid {
            &mut self.grid
        }
        fn take(&mut self, w: usize) -> Option<(usize, u32)> {
            let stages = self.stages;
            let pick = |g: &Grid, tiles: Range<usize>| {
                tiles.filter(|&k| g.taken[k] < stages && g.ready(g.taken[k], k)).min_by_key(|&k| g.taken[k])
            };
            self.grid.take(w, stages, pick)
        }
        fn finish(&mut self, (k, _): (usize, u32), _: (), _: f64) {
            self.grid.done[k] += 1;
        }
        fn over(&self) -> bool {
            self.grid.done.iter().all(|&s| s == self.stages)
        }
    }

    /// `(x[i - 1] + 2 x[i] + x[i + 1]) / 4` on a ring.
    fn smooth(x: Gather<'_, f64>, i: usize) -> f64 {
        let n = x.len();
        (x.get((i + n - 1) % n) + 2.0 * x.get(i) + x.get((i + 1) % n)) * 0.25
    }

    /// Stages on the threads compute what a loop computes, bit for bit, with the access
    /// pattern of IPST's moves: stage `s` of a tile reads buffer `s % 2` on the tile and both
    /// next to it (through [`Tiled::gather`], while other threads write other tiles) and writes
    /// its tile of the other buffer (through [`Tiled::run`]). Under Miri
    /// (`MIRIFLAGS=-Zmiri-tree-borrows cargo +nightly miri test --lib stages`; Stacked Borrows
    /// stops in rayon's deque first) this also checks the shared access to the buffers.
    #[test]
    fn stages_on_threads_compute_what_a_loop_computes() {
        let (sizes, stages): (&[usize], u32) =
            if cfg!(miri) { (&[2, 3, 1, 2, 4], 4) } else { (&[5, 40, 1, 17, 9, 33, 2], 25) };
        let mut bounds = vec![0];
        bounds.extend(sizes.iter().scan(0, |end, &s| {
            *end += s;
            Some(*end)
        }));
        let n = bounds[sizes.len()];
        let start: Vec<f64> = (0..n).map(|i| ((i * i) % 7) as f64 + 0.1 * i as f64).collect();
        let mut want = start.clone();
        for _ in 0..stages {
            want = (0..n).map(|i| smooth(want[..].into(), i)).collect();
        }
        for threads in 1..=3 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (mut a, mut b) = (start.clone(), vec![0.0; n]);
            let buffers = [Tiled::new(&mut a), Tiled::new(&mut b)];
            let mut grid = Grid::default();
            grid.reset(&bounds, threads.min(sizes.len()));
            let run = |(k, s): (usize, u32)| {
                let tile = bounds[k]..bounds[k + 1];
                // SAFETY: the grid runs stage s of tile k after stage s - 1 of it and both
                // its neighbours (which wrote what this reads) and before stage s + 1 of them
                // (which overwrite it), and no other stage writes tile k of this buffer.
                let (from, to) = unsafe {
                    (buffers[s as usize % 2].gather(), buffers[(s as usize + 1) % 2].run(tile.clone()))
                };
                for (i, y) in tile.zip(to) {
                    *y = smooth(from, i);
                }
            };
            let board = pool.install(|| run_stages(Ring { grid, stages }, &run));
            assert!(board.over() && !board.grid.failed);
            let got = if stages % 2 == 0 { &a } else { &b };
            assert!(got.iter().zip(&want).all(|(g, w)| g.to_bits() == w.to_bits()), "{threads} threads");
        }
    }

    /// A stage that panics ends the run with its panic on every thread count, rather than
    /// leaving the other workers waiting for it.
    #[test]
    fn a_stage_that_panics_stops_the_other_workers() {
        let bounds = [0, 2, 4, 6, 8];
        for threads in 1..=3 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut grid = Grid::default();
            grid.reset(&bounds, threads);
            let run = |(k, s): (usize, u32)| {
                assert!(!(k == 2 && s == 1), "stage 1 of tile 2 fails");
            };
            let result = pool.install(|| {
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    run_stages(Ring { grid, stages: 3 }, &run)
                }))
            });
            let message = result.expect_err("the panic reaches the caller");
            let text = message.downcast_ref::<&str>().copied();
            assert_eq!(text, Some("stage 1 of tile 2 fails"), "{threads} threads");
        }
    }

    /// Regions split the tiles by particles, in order, covering every tile once, for
    /// tiles of equal and unequal sizes, and more workers than tiles.
    #[test]
    #[allow(clippy::single_range_in_vec_init)]
    fn regions_share_out_the_particles_in_order() {
        let mut g = Grid::default();
        for (bounds, workers, want) in [
            (vec![0, 100, 200, 300, 400], 2, vec![0..2, 2..4]),
            (vec![0, 100, 200, 300, 433], 2, vec![0..2, 2..4]),
            (vec![0, 10, 20, 400], 2, vec![0..2, 2..3]),
            (vec![0, 100], 3, vec![0..0, 0..1, 1..1]),
            (vec![0, 100, 200, 300], 1, vec![0..3]),
        ] {
            g.reset(&bounds, workers);
            assert_eq!(g.regions, want, "{bounds:?} on {workers}");
            assert!(g.done.iter().chain(&g.taken).all(|&s| s == 0));
        }
    }
}
