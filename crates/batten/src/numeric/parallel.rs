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

/// `background()` and `foreground()` side by side, `background` on threads of the lowest
/// scheduling priority (on Linux `SCHED_IDLE`: it runs only on a core nothing else wants),
/// `foreground` on the thread pool. For work a long computation does not need until its end
/// (a fair's measures of its input): while the computation's serial stretches leave a core
/// idle, the background work fills it, and where the computation runs in parallel it is not
/// slowed (beside it at the same priority, the input's measures took the second core from a
/// 10⁶-point `band`'s parallel start and cost it about 0.06 s).
///
/// The background work runs on a pool of its own (as many threads as the global one), handed
/// over from a thread that waits for it without taking other work: within a batch, where
/// every worker is busy, a worker that waits here blocks, which leaves its core to the
/// background work, rather than starting another file (which would hold every file's data in
/// memory until the measures could run). Without that pool (a platform that cannot start
/// threads), the two run one after the other.
pub(crate) fn beside_in_background<A: Send, B: Send>(
    background: impl FnOnce() -> A + Send,
    foreground: impl FnOnce() -> B + Send,
) -> (A, B) {
    let Some(pool) = background_pool() else {
        let a = background();
        return (a, rayon::scope(|_| foreground()));
    };
    // Taken by the thread that hands it over, or back here if that thread cannot start.
    let task = std::sync::Mutex::new(Some(background));
    let take = || task.lock().ok().and_then(|mut t| t.take());
    std::thread::scope(|s| {
        let handle = std::thread::Builder::new()
            .name("batten-beside".into())
            .spawn_scoped(s, || take().map(|f| pool.install(f)));
        // On a worker of the global pool `scope` runs `foreground` in place; from outside it
        // runs it on a worker, so that its own parallel parts stay in the pool.
        let b = rayon::scope(|_| foreground());
        let a = match handle.map(|h| h.join()) {
            Ok(Ok(Some(a))) => Some(a),
            Ok(Err(panic)) => std::panic::resume_unwind(panic),
            Ok(Ok(None)) | Err(_) => None,
        };
        match a.or_else(|| take().map(|f| pool.install(f))) {
            Some(a) => (a, b),
            // The task is taken once: by the thread, which then returned it, or here.
            None => unreachable!("the background task ran nowhere"),
        }
    })
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

    /// Both results come back, the background one from the background pool, the foreground
    /// one from the global pool, whether the caller is outside the pool or one of its
    /// workers (as within a batch).
    #[test]
    fn beside_in_background_runs_both_where_they_belong() {
        let name = || std::thread::current().name().unwrap_or("").to_string();
        let check = || {
            let data: Vec<u64> = (0..100_000).collect();
            let (a, b) = beside_in_background(
                || (data.iter().sum::<u64>(), name()),
                || (data.len(), rayon::current_thread_index().is_some()),
            );
            assert_eq!(a.0, 4_999_950_000);
            assert!(a.1.starts_with("batten-background-"), "{}", a.1);
            assert_eq!(b, (100_000, true));
        };
        check();
        rayon::scope(|_| check());
    }
}
