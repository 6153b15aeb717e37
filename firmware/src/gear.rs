//! The second example (feature `gear`): a four-wheel running gear with a
//! belt temperature input. Its table (speed × belt temperature, the
//! gear's own tension) is generated at build time from a version 2 params
//! file (`params/gear-4wheel.toml`: belt, joint law with thermal
//! softening, drive, idler on a tensioner, two road wheels on the ground
//! under load); the drive speed follows [`profile::speed_mrad_s`] and the
//! belt warms along [`profile::temperature_centi_c`].

use trackbelt::estimator::{Estimate, EstimatorState, EstimatorTable, GearTable};

use crate::params::Checkpoint;
use crate::{app, profile};

include!(concat!(env!("OUT_DIR"), "/gear_params.rs"));

/// One update of the running-gear estimator with the belt temperature at
/// sample `k`: one out-of-line call, as an application makes it.
#[inline(never)]
pub fn update(
    state: &mut EstimatorState<f32>,
    k: u32,
    speed_rad_s: f32,
    dt_s: f32,
) -> Estimate<f32> {
    let temp = profile::temperature_c_f32(k);
    GEAR_TABLE_F32.update(state, speed_rad_s, dt_s, Some(temp), None)
}

/// The estimator task's body for the running gear.
pub async fn estimator_loop(rel_tolerance: f32) {
    let mut state = EstimatorState::new();
    let dt = profile::dt_s() as f32;
    app::run_estimator(
        move |k, speed| update(&mut state, k, speed, dt),
        rel_tolerance,
        GEAR_CHECKPOINTS,
        GEAR_TORQUE_SCALE_NM,
    )
    .await
}
