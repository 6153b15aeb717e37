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

/// Map `f` over `items` on `threads` plain worker threads (at least 1),
/// each item alone on its worker with a one-thread pool of its own: the
/// parallel loops inside `f` run there, so no worker takes up another
/// item while it waits for them, and the wall time of one call is that
/// item's own. Results in input order. (In one shared pool a worker that
/// waits for an inner loop steals other items, and timing an item counts
/// theirs too.)
///
/// ```
/// let squares = trackbelt_host::parallel::map_isolated(&[1, 2, 3, 4], 2, |x| x * x);
/// assert_eq!(squares, vec![1, 4, 9, 16]);
/// ```
pub fn map_isolated<T: Sync, R: Send, F: Fn(&T) -> R + Sync>(
    items: &[T],
    threads: usize,
    f: F,
) -> Vec<R> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let work = || {
        // One pool per worker, for all its items (sequential without one).
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().ok();
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= items.len() {
                return done;
            }
            let r = match &pool {
                Some(p) => p.install(|| f(&items[i])),
                None => f(&items[i]),
            };
            done.push((i, r));
        }
    };
    let mut all: Vec<(usize, R)> = std::thread::scope(|s| {
        let workers: Vec<_> = (1..threads.max(1)).map(|_| s.spawn(work)).collect();
        let mut all = work();
        for w in workers {
            match w.join() {
                Ok(d) => all.extend(d),
                Err(p) => std::panic::resume_unwind(p),
            }
        }
        all
    });
    all.sort_by_key(|p| p.0);
    all.into_iter().map(|p| p.1).collect()
}
