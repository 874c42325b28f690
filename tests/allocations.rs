//! Once warmed up, a time step allocates nothing, in a fluid, a solid or a fluid-structure
//! scene: every pass, the neighbour search and the sub-steps' binning reuse their buffers
//! (STYLE 6.11). Counted with a global allocator over whole steps, on a pool of
//! two threads as the binary runs them. One test function, because the count is global to
//! the test binary.

use sphrepro::scenes::{self, SceneEntry};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator, only counting.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by steps `warm + 1 ..= warm + steps` of `scene` with `sets`, on `pool`.
fn allocations_per_run(
    pool: &rayon::ThreadPool,
    entry: &SceneEntry,
    sets: &[&str],
    warm: u64,
    steps: u64,
) -> usize {
    let params = entry.params_from_sets(&sets.iter().map(|s| s.to_string()).collect::<Vec<_>>()).unwrap();
    pool.install(|| {
        let mut run = (entry.build)(&params).unwrap();
        let mut start = 0;
        let mut counted = None;
        run.advance(1e9, 1e9, &mut |_, n| {
            if n == warm {
                start = ALLOCATIONS.load(Ordering::SeqCst);
            }
            if n == warm + steps {
                counted = Some(ALLOCATIONS.load(Ordering::SeqCst) - start);
                return false;
            }
            true
        })
        .unwrap();
        counted.expect("the run reached the counted steps")
    })
}

#[test]
fn steps_allocate_nothing_once_warm() {
    let cases: &[(&SceneEntry, &[&str])] = &[
        (scenes::find("taylor_green").unwrap(), &["nx=30", "scheme=edac"]),
        (scenes::find("taylor_green").unwrap(), &["nx=30", "scheme=ctvf", "pst=sun"]),
        (scenes::find("taylor_green").unwrap(), &["nx=30", "scheme=ctvf", "pst=ipst"]),
        // 65 536 particles: sixteen tiles, the step runs as a wavefront.
        (scenes::find("taylor_green").unwrap(), &["nx=256", "scheme=edac"]),
        (scenes::find("cavity").unwrap(), &["nx=20"]),
        (scenes::find("hydrostatic_tank").unwrap(), &["dx=0.1"]),
        (scenes::find("dam_break").unwrap(), &["dx=0.1", "pst=ipst"]),
        // Solids, one body and two summing across, under a load coupling.
        (scenes::find("oscillating_plate").unwrap(), &["dx=0.005"]),
        (scenes::find("colliding_rings").unwrap(), &["dx=0.002", "pst=ipst"]),
        (scenes::find("colliding_rings").unwrap(), &["dx=0.002", "rings=two_bodies"]),
        (scenes::find("clamped_beam_udl").unwrap(), &["dx=0.002", "load=top"]),
        (scenes::find("uniaxial_compression").unwrap(), &["dx=0.002"]),
        // Structures in water: sub-steps in a box around the plate, and one sub-step.
        (scenes::find("hydrostatic_plate").unwrap(), &["dx=0.025"]),
        (scenes::find("dam_break_elastic_plate").unwrap(), &["dx=0.004"]),
    ];
    // One pool, every thread of it started (a thread allocates as it starts, which under load
    // can fall in a counted window; that is rayon's, not the step's).
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.broadcast(|_| ());
    // Warm: past the tuner's trials of the step's orders, whose changes between sweeps and
    // tiles of two widths grow some buffers the first times.
    let warm = sphrepro::solver::simulation::TUNING_STEPS as u64 + 8;
    for (entry, sets) in cases {
        let n = allocations_per_run(&pool, entry, sets, warm, 40);
        assert_eq!(n, 0, "{} {sets:?}: {n} allocations in 40 steps", entry.name);
    }
}
