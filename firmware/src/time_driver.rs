//! An `embassy-time` driver on the Cortex-M SysTick timer.
//!
//! No HAL ships a time driver for the QEMU boards, and SysTick is the one
//! timer every Cortex-M core has, so this driver works on any of them: give
//! [`init`] the frequency of the core clock that feeds SysTick.
//!
//! SysTick interrupts once per millisecond; the interrupt counts
//! milliseconds and wakes the timers that are due. [`Driver::now`] is in
//! microseconds (embassy-time's default tick rate): whole milliseconds from
//! the interrupt count plus the fraction read from the SysTick counter. An
//! alarm therefore fires on the first millisecond boundary at or after its
//! deadline — the resolution a 1 kHz control loop needs, at one short
//! interrupt per millisecond.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicU32, Ordering};
use core::task::Waker;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use critical_section::{CriticalSection, Mutex};
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

/// Microseconds per SysTick period.
const PERIOD_US: u64 = 1_000;

struct SystickDriver {
    /// Whole periods (milliseconds) elapsed since [`init`].
    periods: Mutex<Cell<u64>>,
    /// SysTick counts per period (the reload value plus one); zero before
    /// [`init`].
    counts_per_period: AtomicU32,
    /// Earliest deadline in the queue, in µs (`u64::MAX`: none).
    next_alarm: Mutex<Cell<u64>>,
    queue: Mutex<RefCell<Queue>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SystickDriver = SystickDriver {
    periods: Mutex::new(Cell::new(0)),
    counts_per_period: AtomicU32::new(0),
    next_alarm: Mutex::new(Cell::new(u64::MAX)),
    queue: Mutex::new(RefCell::new(Queue::new())),
});

/// Start the time base: SysTick on the core clock, one interrupt per
/// millisecond.
///
/// `core_clock_hz` must be a multiple of 1 kHz and at most 16.7 GHz (the
/// 24-bit reload register holds one millisecond's count).
pub fn init(mut syst: SYST, core_clock_hz: u32) {
    let counts = core_clock_hz / 1_000;
    syst.disable_counter();
    syst.set_reload(counts.saturating_sub(1).min(0x00FF_FFFF));
    syst.clear_current();
    syst.set_clock_source(SystClkSource::Core);
    DRIVER.counts_per_period.store(counts, Ordering::Relaxed);
    syst.enable_interrupt();
    syst.enable_counter();
}

impl SystickDriver {
    fn now_cs(&self, cs: CriticalSection<'_>) -> u64 {
        let counts = self.counts_per_period.load(Ordering::Relaxed) as u64;
        if counts == 0 {
            return 0;
        }
        let periods = self.periods.borrow(cs).get();
        // The counter counts down from `counts - 1`. If the period has
        // wrapped but its interrupt is still pending (we are in a critical
        // section), the wrap is not yet counted: read the counter after
        // looking at the pending bit so both agree.
        let before = SYST::get_current() as u64;
        let wrapped = SCB::is_pendst_pending();
        let after = SYST::get_current() as u64;
        let (periods, current) = if wrapped {
            (periods + 1, after)
        } else {
            (periods, before)
        };
        let elapsed = counts.saturating_sub(1).saturating_sub(current);
        periods * PERIOD_US + elapsed * PERIOD_US / counts
    }

    /// Wake what is due and remember the next deadline.
    fn service_queue(&self, cs: CriticalSection<'_>) {
        let mut queue = self.queue.borrow(cs).borrow_mut();
        let next = queue.next_expiration(self.now_cs(cs));
        self.next_alarm.borrow(cs).set(next);
    }
}

impl Driver for SystickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now_cs(cs))
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let changed = self.queue.borrow(cs).borrow_mut().schedule_wake(at, waker);
            if changed {
                // Wakes immediately what is already due; the rest waits for
                // the millisecond interrupt.
                self.service_queue(cs);
            }
        });
    }
}

#[exception]
fn SysTick() {
    critical_section::with(|cs| {
        let periods = DRIVER.periods.borrow(cs);
        periods.set(periods.get() + 1);
        // Taking this exception cleared its pending bit, so `now_cs` sees
        // the period just counted.
        if DRIVER.now_cs(cs) >= DRIVER.next_alarm.borrow(cs).get() {
            DRIVER.service_queue(cs);
        }
    });
}
