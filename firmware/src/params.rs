//! The estimator's parameters, generated at build time by `build.rs` from a
//! params TOML file (`TRACKBELT_PARAMS`, default `params/E56.toml`), with
//! the host's full-precision reference torques at checkpoints of the drive
//! profile.

use crate::estimator::EstimatorTable;
use trackbelt::real::FxRepr;
use trackbelt::Fx;

/// The host's reference torque (f64 estimator) at one sample.
#[derive(Clone, Copy, Debug)]
pub struct Checkpoint {
    /// Sample index.
    pub k: u32,
    /// Reference torque, N·m.
    pub torque_nm: f64,
}

include!(concat!(env!("OUT_DIR"), "/params.rs"));
