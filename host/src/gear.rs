//! A robot's running gear on the host (issue 12): simulate it at a drive
//! speed (the rig test on any [`RunningGear`]), and build the onboard
//! estimator's table over speed × belt temperature × tension for it.
//!
//! ```no_run
//! use trackbelt::estimator::BuildOptions;
//! use trackbelt::gear::RunningGear;
//! use trackbelt::rig::{RigConfig, RigTest};
//! use trackbelt_host::gear::{gear_table, run_gear, TableAxes};
//!
//! let law = trackbelt_host::paper::law_for(
//!     trackbelt::params::Variant::E56, trackbelt::params::Method::II)?;
//! let model = trackbelt_host::sim::model_for(56, law)?;
//! let gear = RunningGear::paper_rig(&RigConfig::default(), 0.74)?;
//! let (out, _trace) = run_gear(&model, &gear, RigTest::default(), None)?;
//! let axes = TableAxes { temperatures_c: vec![20.0, 60.0], tensions_n: vec![300.0, 500.0] };
//! let table = gear_table(&model, &gear, &axes, &BuildOptions::default())?;
//! # let _ = (out, table);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use serde::Serialize;
use std::time::Instant;
use trackbelt::estimator::{
    BuildOptions, EstimatorTable, GearTable, MAX_TEMPERATURES, MAX_TENSIONS,
};
use trackbelt::gear::{RunningGear, Tensioner};
use trackbelt::params::Model;
use trackbelt::rig::{rig_test, Rig, RigConfig, RigTest};

use crate::error::{Error, Result};
use crate::rig::{RigTrace, Validity, RIG_CAPACITY};

/// Figures of one running-gear run (N·m, rad/s, N, mm, °C, s).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct GearOutput {
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
    /// Distance from the drive's centre to the idler's at the end, mm.
    pub axle_distance_mm: f64,
    /// Force the ground carries at the end, N (with ground: the robot's
    /// weight on this track plus the ripple of the moment).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_force_n: Option<f64>,
    /// Force the ground carries averaged over the constant-speed phase, N
    /// (with ground: the robot's weight on this track; `ground_force_n` is
    /// a snapshot, the drive's polygon action on the ground included).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_force_n_mean: Option<f64>,
    /// Belt temperature of the run, °C (when given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Wall-clock time (settle + run), s.
    pub wall_s: f64,
    /// Validity checks passed only in part (as `trackbelt rig`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// The rig configuration the speed check sees for `gear` (its drive
/// wheel; the other fields as the gear's contact law).
fn drive_config(gear: &RunningGear<f64>) -> Result<RigConfig<f64>> {
    let drive = gear.drive().ok_or_else(|| {
        Error::from(trackbelt::Error::InvalidParameter {
            field: "running_gear.wheels",
            reason: "needs exactly one wheel with role \"drive\"",
        })
    })?;
    Ok(RigConfig {
        drive_diameter_m: drive.diameter_m,
        ..RigConfig::default()
    })
}

/// Simulate `model`'s belt on `gear` through the rig test `test` (ramp,
/// hold, average) at the belt temperature `temperature_c` (°C; `None`: the
/// joint law's own). The same validity checks as `trackbelt rig`: a drive
/// speed beyond the valid range, a slipping belt or a bending loss above
/// the drive torque are errors; settling and step rejections are warnings.
pub fn run_gear(
    model: &Model<f64>,
    gear: &RunningGear<f64>,
    test: RigTest,
    temperature_c: Option<f64>,
) -> Result<(GearOutput, RigTrace)> {
    let start = Instant::now();
    gear.validate()?;
    let config = drive_config(gear)?;
    let max = crate::rig::max_speed_rad_s(model, &config);
    if test.speed_rad_s.is_nan() || test.speed_rad_s.abs() > max {
        return Err(Error::RigInvalid {
            check: "drive speed",
            value: test.speed_rad_s,
            limit: format!("valid up to ±{max:.1} rad/s on this drive wheel"),
        });
    }
    let mut rig: Box<Rig<f64, RIG_CAPACITY>> = Box::new(Rig::from_gear(
        model.clone(),
        gear,
        crate::rig::rig_settings(),
    )?);
    if let Some(t) = temperature_c {
        rig.set_belt_temperature_c(t)?;
    }
    let mut trace: RigTrace = Vec::new();
    let mut kinetic_j: Vec<f64> = Vec::new();
    let fig = rig_test(&mut rig, &test, |s| {
        trace.push((s.time_s, s.speed_rad_s, s.torque_nm, None));
        kinetic_j.push(s.kinetic_energy_j);
    })?;
    let validity = Validity::of_run(&rig, model, &test, &fig, &trace, &kinetic_j);
    let warnings = validity.check()?;
    Ok((
        GearOutput {
            torque_nm_mean: fig.torque_nm_mean,
            torque_nm_std: fig.torque_nm_std,
            bending_torque_nm_mean: fig.bending_torque_nm_mean,
            speed_rad_s: fig.speed_rad_s,
            idler_force_n: fig.idler_force_n,
            axle_distance_mm: fig.axle_distance_mm,
            ground_force_n: gear.ground.map(|_| rig.ground_force_n()),
            ground_force_n_mean: gear.ground.map(|_| fig.ground_force_n_mean),
            temperature_c,
            wall_s: start.elapsed().as_secs_f64(),
            warnings,
        },
        trace,
    ))
}

/// The axes of a running gear's estimator table besides speed: belt
/// temperatures (°C) and tensioner forces (N), each 1 to 4 points,
/// ascending. One point: that axis is not an input (the table holds the
/// loss there).
///
/// A fixed idler centre ([`Tensioner::FixedCentre`]) has no tensioner
/// force to vary: its belt tension is set by the centre distance and the
/// belt's length. Its tension axis must be one point, a label only (0 N
/// from [`TableAxes::nominal`]): every column is built at the fixed centre,
/// so a tension input changes nothing (a tension below the label is still
/// flagged `INPUT_OUT_OF_RANGE`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableAxes {
    /// Belt temperatures, °C.
    pub temperatures_c: Vec<f64>,
    /// Tensioner forces, N.
    pub tensions_n: Vec<f64>,
}

impl TableAxes {
    /// No temperature or tension input: the gear's own tension (0 N, a
    /// label, for a fixed idler centre), the joint law's temperature
    /// (`reference_c`, the law's reference when it has thermal softening).
    pub fn nominal(gear: &RunningGear<f64>, reference_c: f64) -> Self {
        TableAxes {
            temperatures_c: vec![reference_c],
            tensions_n: vec![nominal_tension(gear)],
        }
    }
}

fn nominal_tension(gear: &RunningGear<f64>) -> f64 {
    match gear.tensioner {
        Tensioner::Force { force_n } => force_n,
        Tensioner::FixedCentre => 0.0,
    }
}

/// The estimator table for `model`'s belt on `gear` over `axes` (columns
/// built in parallel with the `parallel` feature): the base table at the
/// joint law's own temperature and the gear's tension (exactly
/// [`EstimatorTable::from_gear`], and for the paper's rig exactly
/// [`EstimatorTable::from_model`]), and one column per temperature ×
/// tension. A fixed idler centre takes one tension point (see
/// [`TableAxes`]); more is an error.
pub fn gear_table(
    model: &Model<f64>,
    gear: &RunningGear<f64>,
    axes: &TableAxes,
    options: &BuildOptions,
) -> Result<GearTable<f64>> {
    let (nt, nf) = (axes.temperatures_c.len(), axes.tensions_n.len());
    if nt == 0 || nt > MAX_TEMPERATURES || nf == 0 || nf > MAX_TENSIONS {
        return Err(Error::from(trackbelt::Error::InvalidParameter {
            field: "estimator axes",
            reason: "1 to 4 temperatures and 1 to 4 tensions",
        }));
    }
    if gear.tensioner == Tensioner::FixedCentre && nf != 1 {
        return Err(Error::from(trackbelt::Error::InvalidParameter {
            field: "estimator axes",
            reason: "a fixed idler centre has no tensioner force to vary: give one tension \
                     point (a label; TableAxes::nominal gives 0 N)",
        }));
    }
    let has_thermal = model.joint.effects.thermal_softening.is_some();
    let nominal_c = model
        .joint
        .effects
        .thermal_softening
        .map_or(axes.temperatures_c[0], |t| t.temp_c);
    // Job 0: the base; then temperature-major columns.
    let mut jobs: Vec<(Option<f64>, Option<f64>)> = vec![(None, None)];
    for &t in &axes.temperatures_c {
        for &f in &axes.tensions_n {
            jobs.push((has_thermal.then_some(t), Some(f)));
        }
    }
    let build = |job: &(Option<f64>, Option<f64>)| -> Result<EstimatorTable<f64>> {
        let mut g = gear.clone();
        if let (Some(f), Tensioner::Force { .. }) = (job.1, g.tensioner) {
            g.tensioner = Tensioner::Force { force_n: f };
        }
        Ok(EstimatorTable::from_gear::<RIG_CAPACITY>(
            model, &g, options, job.0,
        )?)
    };
    let built: Vec<Result<EstimatorTable<f64>>> = run_jobs(&jobs, build);
    let mut tables = Vec::with_capacity(built.len());
    for t in built {
        tables.push(t?);
    }
    Ok(GearTable::from_columns(
        tables[0],
        &axes.temperatures_c,
        &axes.tensions_n,
        &tables[1..],
        nominal_c,
        nominal_tension(gear),
    )?)
}

#[cfg(feature = "parallel")]
fn run_jobs<J: Sync, R: Send>(jobs: &[J], f: impl Fn(&J) -> R + Sync + Send) -> Vec<R> {
    crate::parallel::par_map(jobs, f)
}

#[cfg(not(feature = "parallel"))]
fn run_jobs<J: Sync, R: Send>(jobs: &[J], f: impl Fn(&J) -> R + Sync + Send) -> Vec<R> {
    jobs.iter().map(f).collect()
}
