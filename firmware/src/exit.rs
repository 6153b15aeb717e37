//! Leaving QEMU: semihosting exit with a pass/fail status, also on panic
//! and HardFault.

use core::fmt::Write as _;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hio};

/// Stop the program: exit status 0 if `pass`, 1 otherwise. On real
/// hardware without a debugger attached semihosting traps instead: put
/// the board's own reset or fault indication here when retargeting.
pub fn exit(pass: bool) -> ! {
    debug::exit(if pass {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

static PANICKING: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // A panic inside the logger must not recurse through the logger.
    if !PANICKING.swap(true, Ordering::Relaxed) {
        if let Some(loc) = info.location() {
            defmt::error!("panic at {=str}:{=u32}", loc.file(), loc.line());
        } else {
            defmt::error!("panic");
        }
    }
    exit(false)
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit(false)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    // Not through defmt: the logger may be what faulted. Semihosting's
    // stderr is separate from the defmt stream on stdout.
    if let Ok(mut err) = hio::hstderr() {
        let _ = writeln!(err, "HardFault at pc={:#010x}", frame.pc());
    }
    exit(false)
}
