//! The belt-health monitor ([`trackbelt::monitor`]) as a task beside the
//! estimator, fed a simulated measured drive torque with a wear ramp.
//!
//! The demo runs on its own speed sweep ([`demo_speed`]: 5 ± 3 rad/s) at
//! 1 kHz for [`MONITOR_SAMPLES`] ticks. The simulated measured torque is the
//! table's bending loss × a loss scale ramping 1.0 → 1.4 over 4 s (it
//! passes the +20 % threshold at [`CROSSING_MS`]), plus 0.05 N·m of
//! bearing friction, the belt-inertia torque and ±0.02 N·m of
//! deterministic noise. The run is seconds long, so the monitor's time
//! scales are compressed ([`demo_config`]: 0.5 s memory, 0.2 s debounce);
//! the onboard defaults are one minute and ten seconds.
//!
//! The task logs the health index every 250 ms with defmt and checks its
//! own alarm time: LOSS_DRIFT must come after the crossing and within
//! [`ALARM_WINDOW_MS`] of it (the memory, 0.5 s, plus the debounce, 0.2 s,
//! plus margin). The verdict goes to the telemetry task through
//! [`MONITOR_VERDICT`].

use core::sync::atomic::{AtomicU8, Ordering};

use embassy_time::{Duration, Ticker};
use trackbelt::monitor::{MonitorConfig, MonitorInput, MonitorState, MonitorStatus};

use crate::estimator::EstimatorTable;
use crate::number::FwReal;
use crate::profile;

/// Ticks the monitor runs (3.5 simulated seconds, so that it finishes
/// before the estimator's run ends).
pub const MONITOR_SAMPLES: u32 = 3_500;

/// When the simulated loss scale passes 1.2, ms.
pub const CROSSING_MS: u32 = 2_000;

/// Largest delay accepted from the crossing to LOSS_DRIFT, ms.
pub const ALARM_WINDOW_MS: u32 = 1_200;

/// The monitor's verdict: 0 running, 1 pass, 2 fail.
pub static MONITOR_VERDICT: AtomicU8 = AtomicU8::new(0);

/// The monitor's settings for the seconds-long demo (compressed time
/// scales; everything else the library's defaults).
pub fn demo_config<T: FwReal>() -> MonitorConfig<T> {
    MonitorConfig {
        forgetting_per_s: T::from_f64(2.0),
        debounce_s: T::from_f64(0.2),
        block_s: T::from_f64(0.01),
        residual_rate_per_s: T::from_f64(2.0),
        structure_hold_s: T::from_f64(2.0),
        ..MonitorConfig::default()
    }
}

/// The monitor's drive speed at tick `k`: 5 ± 3 rad/s, period 0.8 s
/// (a sweep, so that the loss scale and the bearing friction separate
/// within the demo's short memory), rad/s.
pub fn demo_speed<T: FwReal>(k: u32) -> T {
    let phase = T::from_usize((k % 800) as usize) * T::from_f64(core::f64::consts::TAU / 800.0);
    let (sin, _) = phase.sin_cos();
    T::from_f64(5.0) + T::from_f64(3.0) * sin
}

/// The simulated measured torque at tick `k` (`last` is the previous
/// tick's speed), N·m.
pub fn measured_torque<T: FwReal>(
    table: &EstimatorTable<T>,
    k: u32,
    last: T,
    noise: &mut u32,
) -> T {
    let dt = T::from_f64(profile::dt_s());
    let w = demo_speed::<T>(k);
    let t = T::from_usize(k as usize) * dt;
    let scale = T::ONE + T::from_f64(0.1) * t;
    let (bend, _) = table.loss_at(w.abs());
    // LCG noise, uniform in ±0.02 N·m.
    *noise = noise.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    let u = T::from_usize((*noise >> 16) as usize) * T::from_f64(1.0 / 65_536.0);
    let n = (u - T::from_f64(0.5)) * T::from_f64(0.04);
    scale * bend + T::from_f64(0.05) + table.inertia_kg_m2 * (w - last) / dt + n
}

/// The monitor task: one update per millisecond, the health index logged
/// every 250 ms, the alarm time checked.
pub async fn monitor_loop<T: FwReal>(table: &'static EstimatorTable<T>) {
    let config = demo_config::<T>();
    let ok_config = config.validate().is_ok();
    let mut state = MonitorState::new(&config, table);
    let dt = T::from_f64(profile::dt_s());
    let mut ticker = Ticker::every(Duration::from_hz(profile::TICK_HZ as u64));
    let mut noise = 12_345u32;
    let mut last = demo_speed::<T>(0);
    let mut alarm_ms = None;
    let mut bad = 0u32;
    let mut out = state.output(&config);
    for k in 0..MONITOR_SAMPLES {
        ticker.next().await;
        let torque = measured_torque(table, k, last, &mut noise);
        let w = demo_speed::<T>(k);
        last = w;
        out = config.update(
            table,
            &mut state,
            &MonitorInput {
                speed_rad_s: w,
                torque_nm: torque,
                dt_s: dt,
                temperature_c: None,
                free_running: true,
            },
        );
        if out.status.contains(MonitorStatus::BAD_INPUT) {
            bad += 1;
        }
        if alarm_ms.is_none() && out.status.contains(MonitorStatus::LOSS_DRIFT) {
            alarm_ms = Some(k);
        }
        if k % 250 == 0 {
            defmt::info!(
                "monitor t_ms={=u32} health={=f32} loss_scale={=f32} bearing_nm={=f32} status={}",
                k,
                out.health.to_f32(),
                out.loss_scale.to_f32(),
                out.bearing_nm.to_f32(),
                out.status
            );
        }
    }
    let at = alarm_ms.unwrap_or(u32::MAX);
    let pass = ok_config
        && bad == 0
        && (CROSSING_MS..=CROSSING_MS + ALARM_WINDOW_MS).contains(&at)
        && !out.status.contains(MonitorStatus::STRUCTURED);
    defmt::info!(
        "monitor verdict: alarm_at_ms={=u32} crossing_ms={=u32} window_ms={=u32} final_loss_scale={=f32} final_bearing_nm={=f32} bad_inputs={=u32} ok={=bool}",
        at,
        CROSSING_MS,
        ALARM_WINDOW_MS,
        out.loss_scale.to_f32(),
        out.bearing_nm.to_f32(),
        bad,
        pass
    );
    MONITOR_VERDICT.store(if pass { 1 } else { 2 }, Ordering::Release);
}
