//! What one estimator update costs, in instructions, measured with SysTick.
//!
//! Under QEMU with `-icount shift=0` every guest instruction advances the
//! virtual clock by exactly 1 ns, and SysTick counts that clock (one count
//! per 40 instructions on mps2-an386's 25 MHz core clock). A count is too
//! coarse for one update, so the measurement repeats the update
//! [`REPEATS`] times and subtracts the same loop without the update. The
//! instructions per SysTick count are not assumed: they are calibrated
//! against a loop of a known number of instructions, so the same code
//! works on any board's clock. (On real silicon the figure is cycles, not
//! instructions, and only as exact as the calibration loop's timing.)
//!
//! Runs before the time driver takes over SysTick, with interrupts off.

use core::hint::black_box;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

use crate::estimator::{Estimate, Estimator, EstimatorTable};
use crate::number::FwReal;
use crate::profile;

/// Updates per measurement: with 40 instructions per SysTick count, 2 000
/// repeats resolve 0.04 instructions per update.
pub const REPEATS: u32 = 2_000;

/// Instructions of the calibration loop: `ITERATIONS` times two
/// instructions (`subs`, `bne`).
const CAL_ITERATIONS: u32 = 1_000_000;

/// The measured cost of the estimator.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct Cost {
    /// Mean instructions per update over [`REPEATS`] updates along the
    /// drive profile (rounded).
    pub instructions_per_update: u32,
    /// Largest single update seen, in instructions; resolution one SysTick
    /// count (see `instructions_per_count_x1000`).
    pub instructions_per_update_max: u32,
    /// Instructions per SysTick count, times 1000 (calibration result).
    pub instructions_per_count_x1000: u32,
    /// RAM of the estimator (`size_of::<Estimator<T>>()`: its state and a
    /// reference to the table, which is read-only data in flash), bytes.
    pub ram_bytes: u32,
    /// `false` if the 24-bit counter wrapped during a measurement (the
    /// figures are then meaningless).
    pub valid: bool,
}

/// A spin loop of exactly `2 * n + c` instructions, `n ≥ 1`.
#[inline(never)]
pub(crate) fn spin(n: u32) {
    let n = n.max(1);
    // SAFETY: a register-only countdown loop; touches no memory or stack.
    unsafe {
        core::arch::asm!(
            "1:",
            "subs {0}, {0}, #1",
            "bne 1b",
            inout(reg) n => _,
            options(nomem, nostack),
        );
    }
}

/// SysTick counts spent in `f` (counter runs down from 2^24 − 1).
pub(crate) fn counts<F: FnMut()>(syst: &mut SYST, mut f: F, wrapped: &mut bool) -> u32 {
    syst.clear_current();
    let _ = syst.has_wrapped(); // clear COUNTFLAG
    let start = SYST::get_current();
    f();
    let end = SYST::get_current();
    if syst.has_wrapped() {
        *wrapped = true;
    }
    start.wrapping_sub(end) & 0x00FF_FFFF
}

/// One update, as an application calls it: one out-of-line call. (Left to
/// itself the compiler inlines the update into the measuring loops, keeps
/// the state in registers and folds the constant tick length into it,
/// which measures something no application runs.)
#[inline(never)]
fn update<T: FwReal>(est: &mut Estimator<'_, T>, speed_rad_s: T, dt_s: T) -> Estimate<T> {
    est.update(speed_rad_s, dt_s)
}

/// Measure the estimator built from `table`. Leaves SysTick stopped.
pub fn measure<T: FwReal>(syst: &mut SYST, table: &EstimatorTable<T>) -> Cost {
    syst.set_clock_source(SystClkSource::Core);
    syst.disable_interrupt();
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();

    let mut wrapped = false;
    let cal = cortex_m::interrupt::free(|_| {
        let long = counts(syst, || spin(CAL_ITERATIONS + 1), &mut wrapped);
        let short = counts(syst, || spin(1), &mut wrapped);
        long.saturating_sub(short).max(1)
    });
    // Instructions per count = 2 * CAL_ITERATIONS / cal.
    let to_instructions = |c: u64| c * 2 * CAL_ITERATIONS as u64 / cal as u64;

    // The inputs: the first REPEATS samples of the drive profile (ramp,
    // hold and the first step). Converting a sample is in both loops and
    // cancels out.
    // Opaque, so that the compiler cannot fold the constant tick length
    // into the update (an application's tick comes from a timer).
    let dt = black_box(T::from_f64(profile::dt_s()));
    let speed = |i: u32| T::from_f64(profile::speed_rad_s(i % profile::SAMPLES));
    let mut max_counts = 0u32;

    let (work, base) = cortex_m::interrupt::free(|_| {
        let mut est = Estimator::new(table);
        let work = counts(
            syst,
            || {
                for i in 0..REPEATS {
                    black_box(update(&mut est, black_box(speed(i)), dt));
                }
            },
            &mut wrapped,
        );
        let base = counts(
            syst,
            || {
                for i in 0..REPEATS {
                    black_box((black_box(speed(i)), dt));
                }
            },
            &mut wrapped,
        );
        // Single updates, for the largest one (resolution: one count).
        let mut est = Estimator::new(table);
        let empty = counts(syst, || {}, &mut wrapped);
        for i in 0..REPEATS {
            let s = speed(i);
            let c = counts(
                syst,
                || {
                    black_box(update(&mut est, black_box(s), dt));
                },
                &mut wrapped,
            );
            max_counts = max_counts.max(c.saturating_sub(empty));
        }
        (work, base)
    });
    syst.disable_counter();

    let net = work.saturating_sub(base) as u64;
    let num = net * 2 * CAL_ITERATIONS as u64;
    let den = cal as u64 * REPEATS as u64;
    Cost {
        instructions_per_update: ((num + den / 2) / den) as u32,
        instructions_per_update_max: to_instructions(max_counts as u64) as u32,
        instructions_per_count_x1000: (2_000 * CAL_ITERATIONS as u64 / cal as u64) as u32,
        ram_bytes: core::mem::size_of::<Estimator<'_, T>>() as u32,
        valid: !wrapped,
    }
}

/// [`measure`] for any update: `init` makes a fresh state, `update` is one
/// out-of-line update (sample index, speed, tick), `ram_bytes` what the
/// estimator keeps in RAM. Leaves SysTick stopped.
pub fn measure_update<T: FwReal, S>(
    syst: &mut SYST,
    mut init: impl FnMut() -> S,
    update: fn(&mut S, u32, T, T) -> Estimate<T>,
    ram_bytes: u32,
) -> Cost {
    syst.set_clock_source(SystClkSource::Core);
    syst.disable_interrupt();
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();

    let mut wrapped = false;
    let cal = cortex_m::interrupt::free(|_| {
        let long = counts(syst, || spin(CAL_ITERATIONS + 1), &mut wrapped);
        let short = counts(syst, || spin(1), &mut wrapped);
        long.saturating_sub(short).max(1)
    });
    let to_instructions = |c: u64| c * 2 * CAL_ITERATIONS as u64 / cal as u64;
    let dt = black_box(T::from_f64(profile::dt_s()));
    let speed = |i: u32| T::from_f64(profile::speed_rad_s(i % profile::SAMPLES));
    let mut max_counts = 0u32;
    let (work, base) = cortex_m::interrupt::free(|_| {
        let mut st = init();
        let work = counts(
            syst,
            || {
                for i in 0..REPEATS {
                    black_box(update(&mut st, black_box(i), black_box(speed(i)), dt));
                }
            },
            &mut wrapped,
        );
        let base = counts(
            syst,
            || {
                for i in 0..REPEATS {
                    black_box((black_box(i), black_box(speed(i)), dt));
                }
            },
            &mut wrapped,
        );
        let mut st = init();
        let empty = counts(syst, || {}, &mut wrapped);
        for i in 0..REPEATS {
            let s = speed(i);
            let c = counts(
                syst,
                || {
                    black_box(update(&mut st, black_box(i), black_box(s), dt));
                },
                &mut wrapped,
            );
            max_counts = max_counts.max(c.saturating_sub(empty));
        }
        (work, base)
    });
    syst.disable_counter();
    let net = work.saturating_sub(base) as u64;
    let num = net * 2 * CAL_ITERATIONS as u64;
    let den = cal as u64 * REPEATS as u64;
    Cost {
        instructions_per_update: ((num + den / 2) / den) as u32,
        instructions_per_update_max: to_instructions(max_counts as u64) as u32,
        instructions_per_count_x1000: (2_000 * CAL_ITERATIONS as u64 / cal as u64) as u32,
        ram_bytes,
        valid: !wrapped,
    }
}

/// The measured cost of the belt-health monitor (the library's default
/// settings: one filter step per 20 ticks at 1 kHz).
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct MonitorCost {
    /// Mean instructions per tick over [`REPEATS`] ticks (rounded).
    pub per_tick_mean: u32,
    /// Largest single tick (a tick that closes a block and runs the filter
    /// step), resolution one SysTick count.
    pub per_tick_max: u32,
    /// `size_of::<MonitorState<T>>()`, bytes (the config and the table are
    /// read-only).
    pub state_bytes: u32,
    /// `false` if the counter wrapped.
    pub valid: bool,
}

/// One monitor tick, out of line (as [`update`]).
#[inline(never)]
fn monitor_tick<T: FwReal>(
    config: &trackbelt::monitor::MonitorConfig<T>,
    table: &EstimatorTable<T>,
    state: &mut trackbelt::monitor::MonitorState<T>,
    input: &trackbelt::monitor::MonitorInput<T>,
) -> trackbelt::monitor::MonitorOutput<T> {
    config.update(table, state, input)
}

/// Measure the monitor over `table` along the drive profile (after the
/// ramp, so every tick is used). Leaves SysTick stopped.
pub fn measure_monitor<T: FwReal>(syst: &mut SYST, table: &EstimatorTable<T>) -> MonitorCost {
    use trackbelt::monitor::{MonitorConfig, MonitorInput, MonitorState};
    syst.set_clock_source(SystClkSource::Core);
    syst.disable_interrupt();
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    let mut wrapped = false;
    let config = MonitorConfig::<T>::default();
    let dt = black_box(T::from_f64(profile::dt_s()));
    let input = |i: u32| {
        let w = T::from_f64(profile::speed_rad_s(1_000 + i % 2_500));
        MonitorInput::free_running(w, w * T::from_f64(0.3), dt)
    };
    let mut max_counts = 0u32;
    let (cal, work, base) = cortex_m::interrupt::free(|_| {
        let long = counts(syst, || spin(CAL_ITERATIONS + 1), &mut wrapped);
        let short = counts(syst, || spin(1), &mut wrapped);
        let cal = long.saturating_sub(short).max(1);
        let mut state = MonitorState::new(&config, table);
        let work = counts(
            syst,
            || {
                for i in 0..REPEATS {
                    black_box(monitor_tick(
                        &config,
                        table,
                        &mut state,
                        &black_box(input(i)),
                    ));
                }
            },
            &mut wrapped,
        );
        let base = counts(
            syst,
            || {
                for i in 0..REPEATS {
                    black_box(black_box(input(i)));
                }
            },
            &mut wrapped,
        );
        let mut state = MonitorState::new(&config, table);
        let empty = counts(syst, || {}, &mut wrapped);
        for i in 0..REPEATS {
            let x = input(i);
            let c = counts(
                syst,
                || {
                    black_box(monitor_tick(&config, table, &mut state, &black_box(x)));
                },
                &mut wrapped,
            );
            max_counts = max_counts.max(c.saturating_sub(empty));
        }
        (cal, work, base)
    });
    syst.disable_counter();
    let num = work.saturating_sub(base) as u64 * 2 * CAL_ITERATIONS as u64;
    let den = cal as u64 * REPEATS as u64;
    MonitorCost {
        per_tick_mean: ((num + den / 2) / den) as u32,
        per_tick_max: (max_counts as u64 * 2 * CAL_ITERATIONS as u64 / cal as u64) as u32,
        state_bytes: core::mem::size_of::<MonitorState<T>>() as u32,
        valid: !wrapped,
    }
}
