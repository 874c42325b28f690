//! Workers kept awake between the parallel loops of a run.
//!
//! A step forks some twenty parallel loops (the list build, the passes, IPST's sweeps, the
//! kicks) with short serial stretches between them. A rayon worker that finds no work
//! yields a few times and then sleeps, so that loops begin by waking it: a futex call and,
//! on a virtual machine, an interrupt to a halted vCPU that the host may have given to
//! someone else meanwhile. `perf` put 8 % of a two-thread `edac` step's samples at 10 000
//! particles (11 % of a `ctvf`+`ipst` one's) in the wake-up alone, and blocks of a few
//! steps on two threads ran anywhere from one to two single-thread speeds. OpenMP runtimes
//! avoid this by letting their threads spin between parallel regions; [`keep_warm`] does
//! the same for the pool that steps a simulation. Measured on a 2-vCPU KVM host (Zen 4):
//! two threads ran 6-12 % more particle-steps a second at 10 000 particles, the same
//! within the noise at 40 000 and more.
//!
//! It changes which thread runs which task, never a result: the passes fix every order of
//! addition themselves.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Runs `f` on the current rayon pool with the pool's other workers polling for its tasks
/// instead of sleeping, until `f` returns or unwinds. Outside a pool, or in a pool of one
/// thread, it only runs `f`.
///
/// Call it with no other parallel work of the pool in flight (a run's stepping loop, a
/// benchmark's block): the pollers must start on idle workers, before `f` queues anything.
/// A poller started inside a task of `f` would hold that task's thread until `f` ends,
/// while `f` waits for the task: so `f` starts only once every poller is running, and if
/// they do not all start within [`START_WAIT`] (a worker busy elsewhere), `f` runs with the
/// pollers told to stop as they start.
///
/// Between tasks the pollers spin, giving the CPU back to the operating system every
/// `SPINS_PER_YIELD` polls, so that a machine running more threads than cores still
/// gives its time to the work. They cost a core each while `f` runs serial code.
pub fn keep_warm<R>(f: impl FnOnce() -> R) -> R {
    let Some(me) = rayon::current_thread_index() else {
        return f();
    };
    let others = rayon::current_num_threads() - 1;
    if others == 0 {
        return f();
    }
    let started = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    rayon::in_place_scope(|s| {
        s.spawn_broadcast(|_, ctx| {
            if ctx.index() != me && !stop.load(Ordering::Acquire) {
                started.fetch_add(1, Ordering::AcqRel);
                poll(&stop);
            }
        });
        // Stops the pollers even if `f` unwinds, so the scope's end never waits on them.
        let _stop = StopOnDrop(&stop);
        let deadline = Instant::now() + START_WAIT;
        while started.load(Ordering::Acquire) < others {
            if Instant::now() > deadline {
                stop.store(true, Ordering::Release);
                break;
            }
            std::thread::yield_now();
        }
        f()
    })
}

/// How long `keep_warm` waits for its pollers to start (a sleeping worker wakes in tens of
/// microseconds).
pub const START_WAIT: Duration = Duration::from_millis(20);

/// Polls between yields to the operating system: a poll that finds nothing takes some
/// tens of nanoseconds, so a poller gives up the CPU every few microseconds.
const SPINS_PER_YIELD: u32 = 64;

/// Runs the pool's queued tasks until `stop` is set.
fn poll(stop: &AtomicBool) {
    let mut idle = 0u32;
    while !stop.load(Ordering::Acquire) {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            idle = 0;
            continue;
        }
        idle += 1;
        if idle.is_multiple_of(SPINS_PER_YIELD) {
            std::thread::yield_now();
        } else {
            std::hint::spin_loop();
        }
    }
}

/// Sets its flag when dropped.
struct StopOnDrop<'a>(&'a AtomicBool);

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Nested parallel loops under `keep_warm` give what they give without it, on pools of
    /// two and three threads, many times over (a poller run inside a task would hang
    /// here), and the pollers end with it (the scope would not return otherwise).
    #[test]
    fn nested_loops_under_keep_warm_give_the_same_result_and_end() {
        let work = || {
            (0..20_000u32)
                .into_par_iter()
                .with_max_len(64)
                .map(|i| (0..8u32).into_par_iter().map(|j| u64::from(i * j % 7)).sum::<u64>())
                .collect::<Vec<_>>()
        };
        for threads in [2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let plain = pool.install(work);
            for _ in 0..300 {
                assert_eq!(pool.install(|| keep_warm(work)), plain);
            }
        }
        // Outside any pool, and on one thread, it only runs the closure.
        assert_eq!(keep_warm(|| 3), 3);
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        assert_eq!(one.install(|| keep_warm(|| 4)), 4);
    }

    /// A worker busy elsewhere cannot start its poller: `keep_warm` runs its closure all
    /// the same after `START_WAIT`, and returns.
    #[test]
    fn a_busy_worker_does_not_hold_keep_warm() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let release = AtomicBool::new(false);
        let got = pool.install(|| {
            rayon::join(
                || {
                    // Wait until the other half is taken by the second worker.
                    let t0 = Instant::now();
                    while !release.load(Ordering::Acquire) && t0.elapsed() < Duration::from_secs(5) {
                        std::hint::spin_loop();
                    }
                    keep_warm(|| 5)
                },
                || {
                    release.store(true, Ordering::Release);
                    std::thread::sleep(START_WAIT * 3);
                },
            )
            .0
        });
        assert_eq!(got, 5);
    }

    /// A panic inside stops the pollers and reaches the caller (no hang).
    #[test]
    fn a_panic_under_keep_warm_stops_the_pollers() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let caught = pool.install(|| std::panic::catch_unwind(|| keep_warm(|| panic!("blown up"))));
        assert!(caught.is_err(), "the panic reached the caller, so the scope ended");
        let sum: u64 = pool.install(|| (0..1000u64).into_par_iter().sum());
        assert_eq!(sum, 499_500);
    }
}
