//! Worker threads through `rayon`: a local pool of a given size, and an
//! order-preserving parallel map (results do not depend on the number of
//! threads).

use crate::error::{Error, Result};
use rayon::prelude::*;

/// Run `f` on a local pool of `threads` workers (at least 1): every
/// [`par_map`] inside it uses that pool.
pub fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> Result<R> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|_| Error::Thread("cannot start the worker threads"))?;
    Ok(pool.install(f))
}

/// Map `f` over `items` in parallel on the current pool; results in input
/// order.
pub fn par_map<T: Sync, R: Send, F: Fn(&T) -> R + Sync + Send>(items: &[T], f: F) -> Vec<R> {
    items.par_iter().map(f).collect()
}

/// [`par_map`] on a local pool of `threads` workers (sequential when the
/// pool cannot be started).
pub fn par_map_on<T: Sync, R: Send, F: Fn(&T) -> R + Sync + Send>(
    items: &[T],
    threads: usize,
    f: F,
) -> Vec<R> {
    match rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
    {
        Ok(pool) => pool.install(|| par_map(items, &f)),
        Err(_) => items.iter().map(f).collect(),
    }
}
