//! lm3s6965evb (TI Stellaris LM3S6965 evaluation board: Cortex-M3,
//! no FPU): the 32.32 fixed-point estimator.
//!
//! `cargo lm3s6965evb` (from `firmware/`) runs this board on QEMU.
#![no_std]
#![no_main]

use defmt_semihosting as _;
use trackbelt_firmware::{app, cost, executor, exit, monitor_task, params, time_driver, Board};

/// The number type of this board's estimator.
type Num = trackbelt::Fx;

/// QEMU clocks this board's core at 12.5 MHz (its PLL's 200 MHz divided by
/// 16; the cost calibration confirms 80 instructions per SysTick count
/// under `-icount shift=0`). On a real board use its configured clock.
const BOARD: Board = Board {
    name: "lm3s6965evb",
    core: "Cortex-M3",
    core_clock_hz: 12_500_000,
};

/// Largest |torque − host f64 reference| accepted at a checkpoint, as a
/// fraction of the largest reference torque.
const TOLERANCE: f32 = 1e-4;

#[embassy_executor::task]
async fn drive() {
    app::drive_speed_source().await
}

#[embassy_executor::task]
async fn estimator() {
    app::estimator_loop::<Num>(&params::TABLE_FX, TOLERANCE).await
}

#[embassy_executor::task]
async fn monitor() {
    monitor_task::monitor_loop::<Num>(&params::TABLE_FX).await
}

#[embassy_executor::task]
async fn telemetry(cost: cost::Cost) {
    app::telemetry(BOARD, cost, "I32F32", params::TABLE_FX_HASH).await
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::exit(false)
    };
    // Measured first, while SysTick is free and nothing else runs.
    let cost = cost::measure::<Num>(&mut core.SYST, &params::TABLE_FX);
    let monitor_cost = cost::measure_monitor::<Num>(&mut core.SYST, &params::TABLE_FX);
    defmt::info!(
        "monitor cost: per_tick_mean={=u32} per_tick_max={=u32} state_bytes={=u32} valid={=bool}",
        monitor_cost.per_tick_mean,
        monitor_cost.per_tick_max,
        monitor_cost.state_bytes,
        monitor_cost.valid
    );
    time_driver::init(core.SYST, BOARD.core_clock_hz);
    executor::run(|spawner| {
        spawner.spawn(telemetry(cost).unwrap());
        spawner.spawn(estimator().unwrap());
        spawner.spawn(drive().unwrap());
        spawner.spawn(monitor().unwrap());
    })
}
