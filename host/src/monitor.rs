//! The onboard belt-health monitor ([`trackbelt::monitor`]) run over a
//! dataset's scroll series, in the embedded build (f32), with the
//! estimator table built as `trackbelt rig --estimator` builds it: the
//! variant's joint law (or a params file) on the rig of the scroll entry
//! (wheel diameters, tensioner force), default build options.
//!
//! A scroll test turns the belt between two wheels with no ground: every
//! row is free-running. The first row only primes the tick; rows whose
//! tick is not positive (a duplicated time) are reported by the monitor as
//! bad input and skipped.

use std::path::Path;

use trackbelt::estimator::{BuildOptions, EstimatorTable};
use trackbelt::monitor::{MonitorConfig, MonitorInput, MonitorState, MonitorStatus};
use trackbelt::params::Variant;
use trackbelt::rig::RigConfig;

use crate::catalogue::baseline;
use crate::dataset::{Dataset, ScrollEntry};
use crate::error::Result;
use crate::rig::RIG_CAPACITY;
use crate::sim::model_for;

/// Options of a monitor run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MonitorOptions {
    /// The monitor's settings (validated before the run).
    pub config: MonitorConfig<f64>,
    /// Feed the series' belt temperature (`belt_temp_c`), if it has one, to
    /// the monitor's temperature law. Off by default: the law is an
    /// assumption about the belt, not part of the calibrated table.
    pub use_temperature: bool,
}

/// One row of a monitor run (the output after that row).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonitorSample {
    /// Time, s.
    pub t_s: f64,
    /// Loss scale and its standard deviation.
    pub loss_scale: f64,
    /// Standard deviation of the loss scale.
    pub loss_scale_sd: f64,
    /// Bearing friction, N·m.
    pub bearing_nm: f64,
    /// Health index.
    pub health: f64,
    /// Flags.
    pub status: MonitorStatus,
}

/// The monitor over one scroll series.
#[derive(Debug, Clone, PartialEq)]
pub struct MonitorRun {
    /// The series' label, or its file name.
    pub series: String,
    /// Final loss scale (1.0 = as calibrated).
    pub loss_scale: f64,
    /// Its standard deviation.
    pub loss_scale_sd: f64,
    /// Final bearing friction, N·m.
    pub bearing_nm: f64,
    /// Its standard deviation, N·m.
    pub bearing_sd: f64,
    /// Final health index.
    pub health: f64,
    /// Names of the alarms raised at any time in the run (LOSS_DRIFT,
    /// STRUCTURED).
    pub alarms: Vec<String>,
    /// Time of the first alarm, s.
    pub alarm_at_s: Option<f64>,
    /// Rows the monitor skipped as bad input.
    pub bad_rows: usize,
    /// The output after every row.
    pub trace: Vec<MonitorSample>,
}

/// The rig of a scroll entry (its wheels and tensioner, the rest default).
pub fn rig_of(entry: &ScrollEntry) -> RigConfig<f64> {
    let mut rig = RigConfig {
        drive_diameter_m: entry.drive_diameter_mm * 1e-3,
        idler_diameter_m: entry.idler_diameter_mm * 1e-3,
        ..RigConfig::default()
    };
    if let Some(f) = entry.idler_force_n {
        rig.idler_force_n = f;
    }
    rig
}

/// Run the f32 monitor over every scroll series of `dataset`, with the
/// variant's baseline law (`params`, or `params/<variant>.toml`).
pub fn monitor_dataset(
    dataset: &Dataset,
    variant: Variant,
    params: Option<&Path>,
    options: &MonitorOptions,
) -> Result<Vec<MonitorRun>> {
    options.config.validate()?;
    let base = baseline(variant, params)?;
    let model = model_for(variant.links(), base.law)?;
    let mut runs = Vec::new();
    for entry in &dataset.scrolls {
        let rig = rig_of(entry);
        rig.validate()?;
        let table =
            EstimatorTable::from_model::<RIG_CAPACITY>(&model, &rig, &BuildOptions::default())?;
        runs.push(monitor_series(entry, &table.cast::<f32>(), options));
    }
    Ok(runs)
}

/// Run the f32 monitor over one scroll series with a given table.
pub fn monitor_series(
    entry: &ScrollEntry,
    table: &EstimatorTable<f32>,
    options: &MonitorOptions,
) -> MonitorRun {
    let config = options.config.cast::<f32>();
    let mut state = MonitorState::new(&config, table);
    let s = &entry.series;
    let mut trace = Vec::with_capacity(s.t_s.len());
    let (mut alarms, mut alarm_at_s, mut bad_rows) = (MonitorStatus::empty(), None, 0);
    for i in 1..s.t_s.len() {
        let temperature_c = match (&s.belt_temp_c, options.use_temperature) {
            (Some(temp), true) => Some(temp[i] as f32),
            _ => None,
        };
        let input = MonitorInput {
            speed_rad_s: s.omega_rad_s[i] as f32,
            torque_nm: s.torque_nm[i] as f32,
            dt_s: (s.t_s[i] - s.t_s[i - 1]) as f32,
            temperature_c,
            free_running: true,
        };
        let out = config.update(table, &mut state, &input);
        if out.status.contains(MonitorStatus::BAD_INPUT) {
            bad_rows += 1;
        }
        let raised = out.status & (MonitorStatus::LOSS_DRIFT | MonitorStatus::STRUCTURED);
        if !raised.is_empty() && alarm_at_s.is_none() {
            alarm_at_s = Some(s.t_s[i]);
        }
        alarms |= raised;
        trace.push(MonitorSample {
            t_s: s.t_s[i],
            loss_scale: out.loss_scale as f64,
            loss_scale_sd: out.loss_scale_sd as f64,
            bearing_nm: out.bearing_nm as f64,
            health: out.health as f64,
            status: out.status,
        });
    }
    let last = state.output(&config);
    MonitorRun {
        series: entry
            .label
            .clone()
            .unwrap_or_else(|| s.file.display().to_string()),
        loss_scale: last.loss_scale as f64,
        loss_scale_sd: last.loss_scale_sd as f64,
        bearing_nm: last.bearing_nm as f64,
        bearing_sd: last.bearing_sd as f64,
        health: last.health as f64,
        alarms: alarms.iter_names().map(|(n, _)| n.to_string()).collect(),
        alarm_at_s,
        bad_rows,
        trace,
    }
}
