//! Element-wise work over long sequences, in parallel only where it pays.

/// From this many elements on, [`map_indices`] runs in parallel: below it, the hand-off to the
/// thread pool costs more than the work (chord lengths and the noise estimate's values of a
/// 10⁶-point curve each took tens of milliseconds on one thread).
pub(crate) const PARALLEL_FROM: usize = 1 << 16;

/// `f(0), …, f(count − 1)` in order, in parallel from [`PARALLEL_FROM`] elements on (in pieces
/// of at least 4096): the same values with any number of threads.
pub(crate) fn map_indices<T: Send>(count: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    use rayon::prelude::*;
    if count >= PARALLEL_FROM {
        (0..count)
            .into_par_iter()
            .with_min_len(4096)
            .map(f)
            .collect()
    } else {
        (0..count).map(f).collect()
    }
}

/// `f` of the pieces `0..piece`, `piece..2·piece`, … of `0..count` (the last one shorter), in
/// order, in parallel from [`PARALLEL_FROM`] elements on: for sweeps whose pieces each
/// gather a few results, joined afterwards in order.
pub(crate) fn map_pieces<T: Send>(
    count: usize,
    piece: usize,
    f: impl Fn(std::ops::Range<usize>) -> T + Sync + Send,
) -> Vec<T> {
    use rayon::prelude::*;
    let at = |c: usize| f(c * piece..((c + 1) * piece).min(count));
    let pieces = count.div_ceil(piece);
    if count >= PARALLEL_FROM {
        (0..pieces).into_par_iter().map(at).collect()
    } else {
        (0..pieces).map(at).collect()
    }
}

/// The largest of `f(0), …, f(count − 1)` and 0 (NaNs ignored), in parallel from
/// [`PARALLEL_FROM`] elements on (in pieces of at least `piece`): the largest is the same in
/// any order, so the same with any number of threads.
pub(crate) fn max_indices(
    count: usize,
    piece: usize,
    f: impl Fn(usize) -> f64 + Sync + Send,
) -> f64 {
    use rayon::prelude::*;
    if count >= PARALLEL_FROM {
        (0..count)
            .into_par_iter()
            .with_min_len(piece)
            .map(f)
            .reduce(|| 0.0, f64::max)
    } else {
        (0..count).map(f).fold(0.0, f64::max)
    }
}

/// `background(&data)` and `foreground()` side by side, `background` on threads of the
/// lowest scheduling priority (on Linux `SCHED_IDLE`: it runs only on a core nothing else
/// wants), `foreground` on the thread pool. For work a long computation does not need until
/// its end (a fair's measures of its input): while the computation's serial stretches leave a
/// core idle, the background work fills it, and where the computation runs in parallel it is
/// not slowed (beside it at the same priority, the input's measures took the second core from
/// a 10⁶-point `band`'s parallel start and cost it about 0.06 s).
///
/// The background never holds the caller up: when `foreground` is done and the background is
/// not (a loaded machine gives an idle-priority thread almost nothing: a 10⁶-point fair waited
/// 5.6 s for it beside a build), the caller computes `background(&data)` itself, at its own
/// priority, and the background's copy, if it has begun, finishes unheeded; one not begun
/// never starts, and keeps none of the data. The result is the same either way (the same
/// function of the same data).
pub(crate) fn beside_in_background<T, A, B>(
    data: T,
    background: fn(&T) -> A,
    foreground: impl FnOnce() -> B + Send,
) -> (A, B)
where
    T: Send + Sync + 'static,
    A: Send + 'static,
    B: Send,
{
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{Arc, Mutex};
    // Nothing here waits on the background: an idle-priority thread stopped inside a
    // critical section would hold the caller up as long as the machine stays busy. The task
    // begins only if it claims the work before the caller does, reaches the data only through
    // a weak reference (a task that never began keeps none of it), and the caller takes its
    // result only if the result's lock is free.
    struct Shared<A> {
        claimed: AtomicBool,
        result: Mutex<Option<A>>,
    }
    let data = Arc::new(data);
    let shared = Arc::new(Shared {
        claimed: AtomicBool::new(false),
        result: Mutex::new(None),
    });
    if let Some(pool) = background_pool() {
        let (weak, shared) = (Arc::downgrade(&data), Arc::clone(&shared));
        pool.spawn(move || {
            if shared.claimed.swap(true, Ordering::AcqRel) {
                return;
            }
            let Some(d) = weak.upgrade() else { return };
            let a = background(&d);
            if let Ok(mut r) = shared.result.lock() {
                *r = Some(a);
            }
        });
    }
    // On a worker of the global pool `scope` runs `foreground` in place; from outside it runs
    // it on a worker, so that its own parallel parts stay in the pool.
    let b = rayon::scope(|_| foreground());
    let begun = shared.claimed.swap(true, Ordering::AcqRel);
    let done = if begun {
        shared.result.try_lock().ok().and_then(|mut r| r.take())
    } else {
        None
    };
    let a = done.unwrap_or_else(|| background(&data));
    (a, b)
}

/// The pool of [`beside_in_background`]: as many threads as the global pool, each at the
/// lowest scheduling priority its platform grants (a preference: where it is refused, the
/// thread keeps the normal one).
fn background_pool() -> Option<&'static rayon::ThreadPool> {
    static POOL: std::sync::OnceLock<Option<rayon::ThreadPool>> = std::sync::OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(rayon::current_num_threads())
            .thread_name(|i| format!("batten-background-{i}"))
            .start_handler(|_| lowest_priority())
            .build()
            .ok()
    })
    .as_ref()
}

/// Put the calling thread at the lowest scheduling priority: `SCHED_IDLE` on Linux, the
/// lowest priority of the normal policy elsewhere. Errors are ignored (see [`background_pool`]).
fn lowest_priority() {
    #[cfg(target_os = "linux")]
    {
        use thread_priority::unix::{
            NormalThreadSchedulePolicy, ThreadSchedulePolicy, set_thread_priority_and_policy,
            thread_native_id,
        };
        let _ = set_thread_priority_and_policy(
            thread_native_id(),
            thread_priority::ThreadPriority::Min,
            ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Idle),
        );
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = thread_priority::set_current_thread_priority(thread_priority::ThreadPriority::Min);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // `beside_in_background` takes `fn(&T)`, and `T` here is the vector.
    #[allow(clippy::ptr_arg)]
    fn total(v: &Vec<u64>) -> u64 {
        v.iter().sum()
    }

    /// Both results come back, whether the background finished first or the caller computed
    /// its part itself (a foreground that ends at once), called from outside the pool or from
    /// one of its workers (as within a batch).
    #[test]
    fn beside_in_background_gives_both_results() {
        let check = |wait: bool| {
            let data: Vec<u64> = (0..100_000).collect();
            let (a, b) = beside_in_background(data, total, || {
                if wait {
                    std::thread::sleep(std::time::Duration::from_millis(50));
                }
                rayon::current_thread_index().is_some()
            });
            assert_eq!(a, 4_999_950_000);
            assert!(b, "the foreground runs on the pool");
        };
        for wait in [true, false] {
            check(wait);
            rayon::scope(|_| check(wait));
        }
    }
}
