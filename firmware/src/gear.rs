//! The second example (feature `gear`): a four-wheel running gear with a
//! belt temperature input. Its table (speed × belt temperature, the
//! gear's own tension) is generated at build time from a version 2 params
//! file (`params/gear-4wheel.toml`: belt, joint law with thermal
//! softening, drive, idler on a tensioner, two road wheels on the ground
//! under load), in `f32` (mps2-an386) and 32.32 fixed point
//! (lm3s6965evb); the drive speed follows [`profile::speed_mrad_s`] and the
//! belt warms along [`profile::temperature_centi_c`].

use trackbelt::estimator::{Estimate, EstimatorState, EstimatorTable, GearTable};
use trackbelt::real::FxRepr;
use trackbelt::Fx;

use crate::number::FwReal;
use crate::params::Checkpoint;
use crate::{app, profile};

include!(concat!(env!("OUT_DIR"), "/gear_params.rs"));

/// A number type with a running-gear table.
pub trait GearNum: FwReal {
    /// The table in this type (a `static` in flash).
    fn table() -> &'static GearTable<Self>;
    /// Its fingerprint.
    fn table_hash() -> u64;
    /// The belt temperature at sample `k`, °C.
    fn temperature_c(k: u32) -> Self;
}

impl GearNum for f32 {
    fn table() -> &'static GearTable<f32> {
        &GEAR_TABLE_F32
    }
    fn table_hash() -> u64 {
        GEAR_TABLE_F32_HASH
    }
    fn temperature_c(k: u32) -> f32 {
        profile::temperature_c_f32(k)
    }
}

impl GearNum for Fx {
    fn table() -> &'static GearTable<Fx> {
        &GEAR_TABLE_FX
    }
    fn table_hash() -> u64 {
        GEAR_TABLE_FX_HASH
    }
    fn temperature_c(k: u32) -> Fx {
        <Fx as trackbelt::Real>::from_f64(profile::temperature_c(k))
    }
}

/// One update of the running-gear estimator with the belt temperature at
/// sample `k`: one out-of-line call, as an application makes it.
#[inline(never)]
pub fn update<T: GearNum>(
    state: &mut EstimatorState<T>,
    k: u32,
    speed_rad_s: T,
    dt_s: T,
) -> Estimate<T> {
    T::table().update(state, speed_rad_s, dt_s, Some(T::temperature_c(k)), None)
}

/// The estimator task's body for the running gear.
pub async fn estimator_loop<T: GearNum>(rel_tolerance: f32) {
    let mut state = EstimatorState::new();
    let dt = T::from_f64(profile::dt_s());
    app::run_estimator(
        move |k, speed| update(&mut state, k, speed, dt),
        rel_tolerance,
        GEAR_CHECKPOINTS,
        GEAR_TORQUE_SCALE_NM,
    )
    .await
}

/// RAM the estimator keeps: its state and the reference to the table
/// (which is in flash), bytes.
pub fn ram_bytes<T: GearNum>() -> u32 {
    (core::mem::size_of::<EstimatorState<T>>() + core::mem::size_of::<&GearTable<T>>()) as u32
}
