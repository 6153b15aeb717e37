//! Running the bending-resistance rig for the CLI: the JSON contract of
//! `trackbelt rig`, the torque trace the plots draw, and the onboard
//! estimator's figure beside the reference.

use serde::Serialize;
use std::time::Instant;
use trackbelt::estimator::{BuildOptions, Estimator, EstimatorTable};
use trackbelt::params::{Method, Model};
use trackbelt::rig::{ramp_speed, rig_test, Rig, RigConfig, RigTest};
use trackbelt::Settings;

use crate::error::{Error, Result};

/// Capacity of the reference rig (links + 5 unknowns): up to 127 links.
pub const RIG_CAPACITY: usize = 132;

/// The rig's static-solve budget and settings live with the rig in the
/// core (the estimator's table builders use them too); re-exported here.
pub use trackbelt::rig::{rig_settings, RIG_STATIC_ITERATIONS};

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
    /// Validity checks the run passed only in part, `"<check>: <value>"`
    /// (see [`Validity`]); absent from the JSON when there is none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
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
) -> Result<(RigOutput, RigTrace)> {
    let start = Instant::now();
    check_speed(&model, &config, test.speed_rad_s)?;
    let mut rig: Box<Rig<f64, RIG_CAPACITY>> =
        Box::new(Rig::new(model.clone(), config, rig_settings())?);
    let mut trace: RigTrace = Vec::new();
    let mut kinetic_j: Vec<f64> = Vec::new();
    let fig = rig_test(&mut rig, &test, |s| {
        trace.push((s.time_s, s.speed_rad_s, s.torque_nm, None));
        kinetic_j.push(s.kinetic_energy_j);
    })?;
    let wall_s = start.elapsed().as_secs_f64();
    let validity = Validity::of_run(&rig, &model, &test, &fig, &trace, &kinetic_j);
    let warnings = validity.check()?;
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
            warnings,
        },
        trace,
    ))
}

/// Time steps a link must take at least to pass the drive: the highest
/// valid drive speed is the one at which a link passes in this many steps.
pub const MIN_STEPS_PER_LINK: f64 = 5.0;
/// Largest belt slip on the drive, `|1 − belt/drive speed|` (the model's
/// runs slip 0.2–0.8 %).
pub const MAX_SLIP: f64 = 0.05;
/// Largest bending loss over drive torque (the bending loss is part of
/// what the drive supplies; the model's runs give 0.94–0.99).
pub const MAX_BENDING_SHARE: f64 = 1.0;
/// Largest change of the mean torque between the halves of the measured
/// phase, relative to the mean, before the run is flagged as not settled
/// (the model's runs: ≤ 3 %).
pub const MAX_SETTLE_DRIFT: f64 = 0.1;
/// Most rejected (halved) steps per accepted step before the run is
/// flagged (the model's runs: ≤ 0.5).
pub const MAX_REJECTED_PER_STEP: f64 = 1.0;

/// Highest valid drive speed of `model` on the rig `config`, rad/s: a link
/// passes the drive in [`MIN_STEPS_PER_LINK`] time steps of the default
/// settings (E38 ≈ 41, E56 ≈ 28, E76 ≈ 21 rad/s on 300 mm wheels).
pub fn max_speed_rad_s(model: &Model<f64>, config: &RigConfig<f64>) -> f64 {
    let l = model.belt.link_length_m();
    let rho = 0.5 * config.drive_diameter_m + 0.5 * model.belt.thickness_m;
    // Belt path per drive radian: one link per angle a wrapped link
    // subtends (as `Rig::path_speed_per_rad_m`).
    let beta = 2.0 * (l / (2.0 * rho)).atan();
    let path_per_rad_m = l / beta;
    let h = Settings::<f64>::default().step_s;
    l / (MIN_STEPS_PER_LINK * h * path_per_rad_m)
}

/// The speed check, before anything is simulated.
fn check_speed(model: &Model<f64>, config: &RigConfig<f64>, speed_rad_s: f64) -> Result<()> {
    let max = max_speed_rad_s(model, config);
    if speed_rad_s.is_nan() || speed_rad_s.abs() > max {
        return Err(Error::RigInvalid {
            check: "drive speed",
            value: speed_rad_s,
            limit: format!(
                "valid up to ±{max:.1} rad/s: faster, a link passes the drive in fewer than \
                 {MIN_STEPS_PER_LINK} time steps"
            ),
        });
    }
    Ok(())
}

/// The figures a rig run is checked against before its result is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Validity {
    /// Belt path speed the drive imposes over the measured phase, m/s.
    pub drive_path_speed_m_s: f64,
    /// Belt speed from its kinetic energy, `√(2·E/m)`, averaged over the
    /// measured phase, m/s.
    pub belt_speed_m_s: f64,
    /// Slip `1 − belt/drive path speed` (0 when the belt follows the drive;
    /// slightly negative from the links' rotation on the wheels).
    pub slip: f64,
    /// Mean torque of the measured phase's first half minus its second
    /// half, relative to the mean magnitude.
    pub settle_drift: f64,
    /// Rejected (halved) steps per accepted step over the whole run.
    pub rejected_per_step: f64,
    /// Bending torque over drive torque (the bending loss is part of what
    /// the drive supplies: at most 1, not negative).
    pub bending_share: f64,
    /// Link passages over the measured phase (belt path over link length).
    pub link_passages: f64,
}

impl Validity {
    /// Errors for the checks a useful figure cannot fail (slip, energy
    /// balance); warnings `"<check>: <value>"` for those it may (settling,
    /// step rejections).
    pub fn check(&self) -> Result<Vec<String>> {
        if self.slip.is_nan() || self.slip.abs() > MAX_SLIP {
            return Err(Error::RigInvalid {
                check: "belt slip",
                value: self.slip,
                limit: format!(
                    "valid within ±{MAX_SLIP}: the belt ({:.4} m/s) does not follow the drive ({:.4} m/s)",
                    self.belt_speed_m_s, self.drive_path_speed_m_s
                ),
            });
        }
        if !(-0.01..=MAX_BENDING_SHARE).contains(&self.bending_share) {
            return Err(Error::RigInvalid {
                check: "energy balance (bending loss / drive torque)",
                value: self.bending_share,
                limit: format!(
                    "valid in [0, {MAX_BENDING_SHARE}]: the joints cannot dissipate more than the drive supplies"
                ),
            });
        }
        let mut warnings = Vec::new();
        if self.link_passages < 1.0 && self.drive_path_speed_m_s > 0.0 {
            warnings.push(format!(
                "measured phase shorter than one link passage (link-passing ripple not averaged out): {:.3} passages",
                self.link_passages
            ));
        } else if self.settle_drift.is_nan() || self.settle_drift > MAX_SETTLE_DRIFT {
            warnings.push(format!(
                "not settled (mean torque of the measured phase's halves differs by more than {MAX_SETTLE_DRIFT} relative): {:.4}",
                self.settle_drift
            ));
        }
        if self.rejected_per_step > MAX_REJECTED_PER_STEP {
            warnings.push(format!(
                "step rejections (halved steps per accepted step above {MAX_REJECTED_PER_STEP}): {:.3}",
                self.rejected_per_step
            ));
        }
        Ok(warnings)
    }

    /// The figures of a finished run of `rig` (the trace and kinetic
    /// energies as `rig_test` reported them).
    pub fn of_run(
        rig: &Rig<f64, RIG_CAPACITY>,
        model: &Model<f64>,
        test: &RigTest,
        fig: &trackbelt::rig::RigFigures,
        trace: &RigTrace,
        kinetic_j: &[f64],
    ) -> Validity {
        let from = test.ramp_s + test.settle_s;
        let drive_path_speed_m_s = test.speed_rad_s.abs() * rig.path_speed_per_rad_m();
        let measured: Vec<usize> = (0..trace.len()).filter(|&i| trace[i].0 > from).collect();
        let mass = model.belt.mass_kg;
        let belt_speed_m_s = if measured.is_empty() {
            0.0
        } else {
            measured
                .iter()
                .map(|&i| (2.0 * kinetic_j[i].max(0.0) / mass).sqrt())
                .sum::<f64>()
                / measured.len() as f64
        };
        let slip = if drive_path_speed_m_s > 0.0 {
            1.0 - belt_speed_m_s / drive_path_speed_m_s
        } else {
            0.0
        };
        let half = measured.len() / 2;
        let mean =
            |ix: &[usize]| ix.iter().map(|&i| trace[i].2).sum::<f64>() / ix.len().max(1) as f64;
        let (m1, m2) = (mean(&measured[..half]), mean(&measured[half..]));
        let settle_drift = (m1 - m2).abs() / fig.torque_nm_mean.abs().max(1e-9);
        let stats = rig.chain().stats();
        let rejected_per_step = stats.rejected as f64 / stats.steps.max(1) as f64;
        let bending_share = if fig.torque_nm_mean.abs() > 1e-12 {
            fig.bending_torque_nm_mean / fig.torque_nm_mean
        } else {
            0.0
        };
        let window_s = test.hold_s - test.settle_s;
        let link_passages = drive_path_speed_m_s * window_s / model.belt.link_length_m();
        Validity {
            link_passages,
            drive_path_speed_m_s,
            belt_speed_m_s,
            slip,
            settle_drift,
            rejected_per_step,
            bending_share,
        }
    }
}
