//! mps2-an386 (Arm MPS2 with an AN386 image: Cortex-M4F, 25 MHz): the f32
//! estimator.
//!
//! `cargo run --release` (from `firmware/`) runs this board on QEMU.
#![no_std]
#![no_main]

use defmt_semihosting as _;
use trackbelt_firmware::{app, cost, executor, exit, monitor_task, params, time_driver, Board};

/// The number type of this board's estimator.
type Num = f32;

/// The AN386 image clocks the core at 25 MHz (40 instructions per SysTick
/// count under `-icount shift=0`).
const BOARD: Board = Board {
    name: "mps2-an386",
    core: "Cortex-M4F",
    core_clock_hz: 25_000_000,
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
    app::estimator_loop::<Num>(&params::TABLE_F32, TOLERANCE).await
}

#[embassy_executor::task]
async fn monitor() {
    monitor_task::monitor_loop::<Num>(&params::TABLE_F32).await
}

#[embassy_executor::task]
async fn telemetry(cost: cost::Cost) {
    app::telemetry(BOARD, cost, "f32", params::TABLE_F32_HASH).await
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::exit(false)
    };
    // Measured first, while SysTick is free and nothing else runs.
    let cost = cost::measure::<Num>(&mut core.SYST, &params::TABLE_F32);
    let monitor_cost = cost::measure_monitor::<Num>(&mut core.SYST, &params::TABLE_F32);
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
