//! The executor's idle loop: embassy's raw executor, sleeping with `WFI`.
//!
//! embassy's Cortex-M thread executor sleeps with `WFE`, which QEMU treats
//! as a no-op: the core would spin through every idle millisecond. `WFI`
//! halts until an interrupt, which lets QEMU (with `-icount ...,sleep=off`)
//! skip idle time, and is the usual low-power idle on real silicon too.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_executor::{raw, Spawner};
use static_cell::StaticCell;

/// Set when a task has been woken and the executor must poll again.
static PENDED: AtomicBool = AtomicBool::new(false);

#[unsafe(export_name = "__pender")]
fn pender(_context: *mut ()) {
    PENDED.store(true, Ordering::SeqCst);
}

static EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();

/// Run the executor forever; `init` spawns the tasks.
pub fn run(init: impl FnOnce(Spawner)) -> ! {
    let executor: &'static raw::Executor = EXECUTOR.init(raw::Executor::new(core::ptr::null_mut()));
    init(executor.spawner());
    loop {
        // SAFETY: `poll` is only ever called from this one loop.
        unsafe { executor.poll() };
        // With interrupts masked, a wake-up cannot slip in between the
        // check and the WFI; a pending interrupt still ends the WFI.
        cortex_m::interrupt::free(|_| {
            if !PENDED.swap(false, Ordering::SeqCst) {
                cortex_m::asm::wfi();
            }
        });
    }
}
