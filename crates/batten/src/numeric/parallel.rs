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
