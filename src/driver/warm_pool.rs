//! Keeping rayon's idle workers awake for the length of one run.
//!
//! An engine's right-hand side forks a few short parallel passes (tens of µs each, three per evaluation of the
//! ellipsoid engine) and the integrator runs serially between evaluations. rayon lets a worker that finds no work
//! spin with `sched_yield` for a few tens of µs and then sleep on a futex; the next fork has to wake it, and until
//! it runs, the forking thread does the work alone, and the system calls of spinning and waking take a sizeable
//! share of a run (`analysis/speed/REPORT.md`, "warm workers").
//!
//! [`with_warm_workers`] runs an operation on the current pool while one helper task per other worker polls the
//! pool with [`rayon::yield_now`], which runs any job it can steal (so the helpers do the forked work) and makes no
//! system call. Nothing the operation computes depends on which thread runs what, so the results keep their bits.
//!
//! A helper returns when the operation ends, and also:
//! - at once when the operation's own thread picks it up (it was not stolen before that thread had to wait for a
//!   forked job): it would otherwise sit on top of the operation's stack and stop it from resuming;
//! - at once when another warm operation is running in the process (a campaign running several runs in one pool):
//!   a helper stacked above another run's frame would hold that run up while it found work of its own run;
//! - after [`IDLE_LIMIT`] without finding any work. With three or more workers a helper can be stolen by a worker
//!   that is waiting inside a forked job; if that job is what the operation waits for, nothing else can progress,
//!   the helper finds no work, and the limit ends the wait. A run's serial phases longer than the limit (writing a
//!   checkpoint) end the helpers too; the run then goes on with rayon's own sleeping workers.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// A helper that has found no work for this long returns (see the module docs).
pub const IDLE_LIMIT: Duration = Duration::from_millis(100);

/// Polls between two looks at the clock while idle (reading it costs about as much as a poll).
const POLLS_PER_CLOCK_READ: u32 = 64;

/// Warm operations running in this process.
static ACTIVE: AtomicUsize = AtomicUsize::new(0);

/// Decrements [`ACTIVE`] when the operation ends, also by a panic.
struct Active;

impl Drop for Active {
    fn drop(&mut self) {
        ACTIVE.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Runs `op` on the current thread while the other workers of the current rayon pool poll for its forked jobs
/// instead of sleeping (see the module docs). On a one-thread pool, outside any pool, or while another warm
/// operation runs, it is `op()`.
///
/// ```
/// use rubblepile::driver::warm_pool::with_warm_workers;
/// let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
/// let sum: u64 = pool.install(|| {
///     with_warm_workers(|| {
///         use rayon::prelude::*;
///         (0..1000u64).into_par_iter().sum()
///     })
/// });
/// assert_eq!(sum, 499_500);
/// ```
pub fn with_warm_workers<R: Send>(op: impl FnOnce() -> R + Send) -> R {
    let others = rayon::current_num_threads().saturating_sub(1);
    let owner = rayon::current_thread_index();
    let _active = {
        ACTIVE.fetch_add(1, Ordering::SeqCst);
        Active
    };
    if others == 0 || owner.is_none() || ACTIVE.load(Ordering::SeqCst) > 1 {
        return op();
    }
    let done = AtomicBool::new(false);
    rayon::scope(|s| {
        for _ in 0..others {
            let done = &done;
            s.spawn(move |_| poll_until_done(done, owner));
        }
        // The helpers must learn that the operation ended also when it panics (the scope then waits for them).
        struct Finish<'a>(&'a AtomicBool);
        impl Drop for Finish<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Release);
            }
        }
        let _finish = Finish(&done);
        op()
    })
}

/// One helper: runs stolen jobs until `done`, or returns early (see the module docs).
fn poll_until_done(done: &AtomicBool, owner: Option<usize>) {
    if rayon::current_thread_index() == owner {
        return;
    }
    let mut idle: Option<Instant> = None;
    let mut polls = 0u32;
    while !done.load(Ordering::Acquire) {
        if ACTIVE.load(Ordering::Relaxed) > 1 {
            return;
        }
        match rayon::yield_now() {
            Some(rayon::Yield::Executed) => idle = None,
            _ => {
                let since = *idle.get_or_insert_with(Instant::now);
                polls = polls.wrapping_add(1);
                if polls.is_multiple_of(POLLS_PER_CLOCK_READ) && since.elapsed() > IDLE_LIMIT {
                    return;
                }
                std::hint::spin_loop();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Nested forks two levels deep, with a serial pause between them: the shape of a run's evaluations.
    fn nested_work(rounds: usize) -> u64 {
        let mut total = 0;
        for r in 0..rounds {
            let (a, b) = rayon::join(
                || (0..2000u64).into_par_iter().map(|k| k * k % 7).sum::<u64>(),
                || {
                    (0..64u64)
                        .into_par_iter()
                        .map(|k| (0..100u64).into_par_iter().map(|j| (j + k) % 3).sum::<u64>())
                        .sum::<u64>()
                },
            );
            total += a + b + r as u64;
            std::thread::sleep(Duration::from_micros(20));
        }
        total
    }

    #[test]
    fn warm_workers_give_the_serial_result_on_one_to_four_threads_without_deadlock() {
        let serial = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| nested_work(50));
        for threads in 1..=4 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let warm = pool.install(|| with_warm_workers(|| nested_work(50)));
            assert_eq!(warm, serial, "{threads} threads");
        }
    }

    #[test]
    fn two_warm_runs_sharing_one_pool_both_finish() {
        // Two operations started from two OS threads into one two-worker pool, as a campaign with `--parallel 2`
        // does: the second one must neither wait for the first to end nor be held up by its helper.
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let expected = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| nested_work(30));
        let results: Vec<u64> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..2)
                .map(|_| s.spawn(|| pool.install(|| with_warm_workers(|| nested_work(30)))))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(results, vec![expected, expected]);
    }

    #[test]
    fn a_panicking_operation_releases_its_helpers() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            pool.install(|| with_warm_workers(|| -> u64 { panic!("engine failed") }))
        }));
        assert!(outcome.is_err());
        // The pool is usable again: the helper of the failed operation has returned.
        assert_eq!(pool.install(|| with_warm_workers(|| nested_work(3))), nested_work(3));
    }

    #[test]
    fn outside_a_pool_the_operation_runs_in_place() {
        assert_eq!(with_warm_workers(|| 7), 7);
    }
}
