//! Progress reporting: the long jobs (calibration, the paper's runs, the
//! diagnosis) tell a [`Progress`] how many simulations they expect and
//! when each one is done. The library draws nothing; the `trackbelt`
//! command drives a progress bar with it.
//!
//! Any `Fn() + Sync` closure is a `Progress` (called once per step):
//!
//! ```
//! use std::sync::atomic::{AtomicUsize, Ordering};
//! use trackbelt_host::progress::Progress;
//! let done = AtomicUsize::new(0);
//! let p = || { done.fetch_add(1, Ordering::Relaxed); };
//! p.set_total(3);
//! p.step();
//! assert_eq!(done.load(Ordering::Relaxed), 1);
//! ```

/// Receiver of progress reports; called from worker threads.
pub trait Progress: Sync {
    /// The most steps the job expects (a job may call it again with a
    /// better bound). The default ignores it.
    fn set_total(&self, total: u64) {
        let _ = total;
    }
    /// One step (usually one simulation) is done.
    fn step(&self);
}

impl<F: Fn() + Sync> Progress for F {
    fn step(&self) {
        self()
    }
}

/// A [`Progress`] that ignores every report.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn step(&self) {}
}
