//! Running the bending-resistance rig for the CLI: the JSON contract of
//! `trackbelt rig`, the torque trace the plots draw, and the onboard
//! estimator's figure beside the reference.

use serde::Serialize;
use std::time::Instant;
use trackbelt::estimator::{BuildOptions, Estimator, EstimatorTable};
use trackbelt::params::{Method, Model};
use trackbelt::rig::{ramp_speed, rig_test, Rig, RigConfig, RigTest};
use trackbelt::Settings;

/// Capacity of the reference rig (links + 5 unknowns): up to 127 links.
pub const RIG_CAPACITY: usize = 132;

/// Figures of one rig run, as `rig --json` prints them (N·m, rad/s, N, s).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct RigOutput {
    /// "E38", "E56", "E76".
    pub variant: String,
    /// "I", "II", "III".
    pub method: String,
    /// Mean drive torque over the constant-speed phase, N·m.
    pub torque_nm_mean: f64,
    /// Its standard deviation (link-passing ripple), N·m.
    pub torque_nm_std: f64,
    /// The bending loss proper (joint damping power over speed), N·m.
    pub bending_torque_nm_mean: f64,
    /// Drive speed of the constant phase, rad/s.
    pub speed_rad_s: f64,
    /// Tensioner force, N.
    pub idler_force_n: f64,
    /// Axle distance at the end of the run, mm.
    pub axle_distance_mm: f64,
    /// The onboard estimator's steady torque at that speed, N·m (with
    /// `--estimator`).
    pub estimator_torque_nm: Option<f64>,
    /// Wall-clock time of the simulation (settle + run), s.
    pub wall_s: f64,
}

/// Torque over time: (t s, speed rad/s, reference torque N·m, estimator
/// torque N·m when built).
pub type RigTrace = Vec<(f64, f64, f64, Option<f64>)>;

/// Run the rig test for `model`; with `estimator`, also build the onboard
/// estimator from the same model and run it on the same speed profile.
pub fn run_rig(
    variant: &str,
    method: Method,
    model: Model<f64>,
    config: RigConfig<f64>,
    test: RigTest,
    estimator: bool,
) -> Result<(RigOutput, RigTrace), trackbelt::Error> {
    let start = Instant::now();
    let mut rig: Box<Rig<f64, RIG_CAPACITY>> =
        Box::new(Rig::new(model.clone(), config, Settings::default())?);
    let mut trace: RigTrace = Vec::new();
    let fig = rig_test(&mut rig, &test, |s| {
        trace.push((s.time_s, s.speed_rad_s, s.torque_nm, None))
    })?;
    let wall_s = start.elapsed().as_secs_f64();
    let mut estimator_torque_nm = None;
    if estimator {
        let table =
            EstimatorTable::from_model::<RIG_CAPACITY>(&model, &config, &BuildOptions::default())?;
        let mut est = Estimator::new(&table);
        let mut t_prev = 0.0;
        for row in trace.iter_mut() {
            let dt = row.0 - t_prev;
            t_prev = row.0;
            row.3 = Some(est.update(ramp_speed(&test, row.0), dt).torque_nm);
        }
        let mut steady = Estimator::new(&table);
        estimator_torque_nm = Some(steady.update(test.speed_rad_s, 1e-3).torque_nm);
    }
    Ok((
        RigOutput {
            variant: variant.to_string(),
            method: method.name().to_string(),
            torque_nm_mean: fig.torque_nm_mean,
            torque_nm_std: fig.torque_nm_std,
            bending_torque_nm_mean: fig.bending_torque_nm_mean,
            speed_rad_s: fig.speed_rad_s,
            idler_force_n: fig.idler_force_n,
            axle_distance_mm: fig.axle_distance_mm,
            estimator_torque_nm,
            wall_s,
        },
        trace,
    ))
}
