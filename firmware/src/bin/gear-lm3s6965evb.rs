//! lm3s6965evb (Cortex-M3), the second example: the I32F32
//! estimator of a four-wheel running gear (drive, idler on a tensioner,
//! two road wheels on the ground under load) with a belt temperature
//! input, its table generated from `params/gear-4wheel.toml`.
//!
//! `cargo gear-lm3s6965evb` (from `firmware/`) runs it on QEMU.
#![no_std]
#![no_main]

use defmt_semihosting as _;
use trackbelt::estimator::{EstimatorState, GearTable};
use trackbelt_firmware::gear::{self, GearNum};
use trackbelt_firmware::{app, cost, executor, exit, time_driver, Board};

/// The number type of this board's estimator.
type Num = trackbelt::Fx;

/// QEMU clocks this board's core at 12.5 MHz (as the first example's).
const BOARD: Board = Board {
    name: "gear-lm3s6965evb",
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
    gear::estimator_loop::<Num>(TOLERANCE).await
}

#[embassy_executor::task]
async fn telemetry(cost: cost::Cost) {
    let info = app::RunInfo {
        params_file: gear::GEAR_PARAMS_FILE,
        variant: gear::GEAR_BELT,
        method: gear::GEAR_METHOD,
        checkpoints: gear::GEAR_CHECKPOINTS.len() as u32,
    };
    let table = Num::table();
    defmt::info!(
        "running gear: links={=u32} wheels={=u32} table_bytes={=u32} temperatures={=u32} tensions={=u32}",
        gear::GEAR_LINKS,
        gear::GEAR_WHEELS,
        core::mem::size_of::<GearTable<Num>>() as u32,
        table.temperatures as u32,
        table.tensions as u32
    );
    app::telemetry_run(BOARD, cost, "I32F32", Num::table_hash(), info).await
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::exit(false)
    };
    // Measured first, while SysTick is free and nothing else runs.
    let cost = cost::measure_update::<Num, _>(
        &mut core.SYST,
        EstimatorState::new,
        gear::update::<Num>,
        gear::ram_bytes::<Num>(),
    );
    time_driver::init(core.SYST, BOARD.core_clock_hz);
    executor::run(|spawner| {
        spawner.spawn(telemetry(cost).unwrap());
        spawner.spawn(estimator().unwrap());
        spawner.spawn(drive().unwrap());
    })
}
