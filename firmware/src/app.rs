//! The motor-control loop: drive speed source, estimator, telemetry.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{Duration, Instant, Ticker};

use crate::cost::Cost;
use crate::estimator::{Estimate, Estimator, EstimatorTable};
use crate::number::FwReal;
use crate::params::{Checkpoint, CHECKPOINTS, TORQUE_SCALE_NM};
use crate::{exit, profile, Board};

/// One speed sample from the drive.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Sample index (0, 1, …; one per millisecond).
    pub k: u32,
    /// Wheel speed, mrad/s.
    pub speed_mrad_s: i32,
}

/// Speed samples, drive → estimator. Every sample is processed exactly
/// once and in order, so the host can replay the run.
static SPEED: Channel<CriticalSectionRawMutex, Sample, 8> = Channel::new();

/// Samples the drive could not queue (the estimator fell behind).
static OVERRUNS: AtomicU32 = AtomicU32::new(0);

/// A telemetry line.
#[derive(Clone, Copy, Debug)]
pub struct Record {
    /// Sample index.
    pub k: u32,
    /// Wheel speed, rad/s.
    pub speed_rad_s: f32,
    /// Estimated bending torque, N·m.
    pub torque_nm: f32,
    /// The torque's raw bits (f32 bits, or the 32.32 fixed-point value).
    pub torque_bits: i64,
}

/// The estimator's verdict after the last sample.
#[derive(Clone, Copy, Debug)]
pub struct Verdict {
    /// Samples processed.
    pub samples: u32,
    /// Samples that arrived out of order or were lost.
    pub lost: u32,
    /// Updates whose status was not OK or whose torque was not finite.
    pub bad_updates: u32,
    /// Checkpoints compared with the host's reference.
    pub checkpoints: u32,
    /// Checkpoints outside the tolerance.
    pub checkpoint_failures: u32,
    /// Largest |torque − reference| over the checkpoints, N·m.
    pub max_abs_err_nm: f32,
    /// Simulated time from the first to the last sample, µs.
    pub elapsed_us: u64,
}

/// Messages to the telemetry task.
#[derive(Clone, Copy, Debug)]
pub enum Telemetry {
    /// A periodic line.
    Record(Record),
    /// The end of the run.
    Done(Verdict),
}

static TELEMETRY: Channel<CriticalSectionRawMutex, Telemetry, 16> = Channel::new();

/// A telemetry line every this many samples (20 Hz).
pub const TELEMETRY_EVERY: u32 = 50;

/// The drive: one speed sample per millisecond on its own 1 kHz ticker,
/// [`profile::SAMPLES`] of them.
pub async fn drive_speed_source() {
    let mut ticker = Ticker::every(Duration::from_hz(profile::TICK_HZ as u64));
    for k in 0..profile::SAMPLES {
        let sample = Sample {
            k,
            speed_mrad_s: profile::speed_mrad_s(k),
        };
        if SPEED.try_send(sample).is_err() {
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
        ticker.next().await;
    }
}

/// The estimator: every millisecond (embassy-time ticker) it updates once
/// per waiting sample, and compares the torque at the build-time
/// checkpoints with the host's reference; `rel_tolerance` is the largest
/// difference accepted, as a fraction of the largest reference torque.
///
/// The table stays where it is (a `static` in flash); the task keeps the
/// estimator's state and a reference to the table.
pub async fn estimator_loop<T: FwReal>(table: &'static EstimatorTable<T>, rel_tolerance: f32) {
    let tolerance_nm = rel_tolerance * TORQUE_SCALE_NM;
    let mut est = Estimator::new(table);
    let dt = T::from_f64(profile::dt_s());
    let mut ticker = Ticker::every(Duration::from_hz(profile::TICK_HZ as u64));
    let mut v = Verdict {
        samples: 0,
        lost: 0,
        bad_updates: 0,
        checkpoints: 0,
        checkpoint_failures: 0,
        max_abs_err_nm: 0.0,
        elapsed_us: 0,
    };
    let mut checkpoints = CHECKPOINTS.iter().peekable();
    let mut first_at = None;
    // Bounded: the drive sends SAMPLES samples over SAMPLES ms; give up
    // (and fail) if they have not all arrived a second later.
    for _ in 0..profile::SAMPLES + profile::TICK_HZ {
        ticker.next().await;
        while let Ok(s) = SPEED.try_receive() {
            let now = Instant::now();
            let first = *first_at.get_or_insert(now);
            if s.k != v.samples {
                v.lost += 1;
            }
            let speed = T::from_f64(profile::rad_s(s.speed_mrad_s));
            let e = est.update(speed, dt);
            let torque = e.torque_nm;
            if !e.status.is_ok() || !torque.is_finite() {
                if v.bad_updates == 0 {
                    defmt::error!(
                        "k={=u32}: first bad update, status {}, torque {=f32} N·m",
                        s.k,
                        e.status,
                        torque.to_f32()
                    );
                }
                v.bad_updates += 1;
            }
            while let Some(c) = checkpoints.next_if(|c: &&Checkpoint| c.k <= s.k) {
                if c.k == s.k {
                    let err = (torque.to_f32() - c.torque_nm as f32).abs();
                    v.checkpoints += 1;
                    v.max_abs_err_nm = v.max_abs_err_nm.max(err);
                    if err.is_nan() || err > tolerance_nm {
                        v.checkpoint_failures += 1;
                        defmt::error!(
                            "k={=u32}: torque {=f32} N·m, host reference {=f32} N·m",
                            s.k,
                            torque.to_f32(),
                            c.torque_nm as f32
                        );
                    }
                }
            }
            if s.k % TELEMETRY_EVERY == 0 || s.k + 1 == profile::SAMPLES {
                let r = Record {
                    k: s.k,
                    speed_rad_s: s.speed_mrad_s as f32 / 1_000.0,
                    torque_nm: torque.to_f32(),
                    torque_bits: torque.bits(),
                };
                TELEMETRY.send(Telemetry::Record(r)).await;
            }
            v.samples = s.k + 1;
            if v.samples == profile::SAMPLES {
                v.elapsed_us = (now - first).as_micros();
                TELEMETRY.send(Telemetry::Done(v)).await;
                return;
            }
        }
    }
    v.lost += profile::SAMPLES - v.samples;
    TELEMETRY.send(Telemetry::Done(v)).await;
}

/// Telemetry: logs the records, then the verdict, and exits QEMU.
pub async fn telemetry(board: Board, cost: Cost, number: &'static str, table_hash: u64) {
    defmt::info!(
        "{=str} ({=str}, {=u32} Hz): estimator in {=str}, params_file={=str} variant={=str} method={=str} table_hash={=u64:#x}",
        board.name,
        board.core,
        board.core_clock_hz,
        number,
        crate::params::PARAMS_FILE,
        crate::params::VARIANT,
        crate::params::METHOD,
        table_hash
    );
    defmt::info!(
        "cost: instructions_per_update={=u32} instructions_per_update_max={=u32} ram_bytes={=u32} (instructions per SysTick count {=u32}/1000, valid={=bool})",
        cost.instructions_per_update,
        cost.instructions_per_update_max,
        cost.ram_bytes,
        cost.instructions_per_count_x1000,
        cost.valid
    );
    loop {
        match TELEMETRY.receive().await {
            Telemetry::Record(r) => defmt::info!(
                "t={=u32} ms speed={=f32} rad/s torque={=f32} N·m bits={=i64:#x}",
                r.k,
                r.speed_rad_s,
                r.torque_nm,
                r.torque_bits
            ),
            Telemetry::Done(v) => {
                let expected_us = (profile::SAMPLES as u64 - 1) * 1_000;
                let timing_ok = v.elapsed_us.abs_diff(expected_us) <= 2_000;
                let overruns = OVERRUNS.load(Ordering::Relaxed);
                let pass = v.samples == profile::SAMPLES
                    && v.lost == 0
                    && overruns == 0
                    && v.bad_updates == 0
                    && v.checkpoints == CHECKPOINTS.len() as u32
                    && v.checkpoint_failures == 0
                    && timing_ok
                    && cost.valid
                    && monitor_ok();
                defmt::info!(
                    "checks: samples={=u32} lost={=u32} overruns={=u32} bad_updates={=u32} checkpoints={=u32}/{=u32} failed={=u32} max_abs_err_nm={=f32} elapsed_us={=u64} (expected {=u64} ± 2000) cost_valid={=bool}",
                    v.samples,
                    v.lost,
                    overruns,
                    v.bad_updates,
                    v.checkpoints,
                    CHECKPOINTS.len() as u32,
                    v.checkpoint_failures,
                    v.max_abs_err_nm,
                    v.elapsed_us,
                    expected_us,
                    cost.valid
                );
                if pass {
                    defmt::info!("PASS");
                } else {
                    defmt::error!("FAIL");
                }
                exit::exit(pass);
            }
        }
    }
}

// The running-gear example's versions of the two tasks' bodies (the first
// example keeps its own, unchanged, so its binary and figures stay as they
// were).

/// The body of an estimator task: every millisecond it calls `update`
/// (sample index, speed) once per waiting sample and compares the torque
/// at `checkpoints` with the host's reference (tolerance
/// `rel_tolerance · torque_scale_nm`).
pub async fn run_estimator<T: FwReal, F: FnMut(u32, T) -> Estimate<T>>(
    mut update: F,
    rel_tolerance: f32,
    checkpoints: &'static [Checkpoint],
    torque_scale_nm: f32,
) {
    let tolerance_nm = rel_tolerance * torque_scale_nm;
    let mut ticker = Ticker::every(Duration::from_hz(profile::TICK_HZ as u64));
    let mut v = Verdict {
        samples: 0,
        lost: 0,
        bad_updates: 0,
        checkpoints: 0,
        checkpoint_failures: 0,
        max_abs_err_nm: 0.0,
        elapsed_us: 0,
    };
    let mut checkpoints = checkpoints.iter().peekable();
    let mut first_at = None;
    // Bounded: the drive sends SAMPLES samples over SAMPLES ms; give up
    // (and fail) if they have not all arrived a second later.
    for _ in 0..profile::SAMPLES + profile::TICK_HZ {
        ticker.next().await;
        while let Ok(s) = SPEED.try_receive() {
            let now = Instant::now();
            let first = *first_at.get_or_insert(now);
            if s.k != v.samples {
                v.lost += 1;
            }
            let speed = T::from_f64(profile::rad_s(s.speed_mrad_s));
            let e = update(s.k, speed);
            let torque = e.torque_nm;
            if !e.status.is_ok() || !torque.is_finite() {
                if v.bad_updates == 0 {
                    defmt::error!(
                        "k={=u32}: first bad update, status {}, torque {=f32} N·m",
                        s.k,
                        e.status,
                        torque.to_f32()
                    );
                }
                v.bad_updates += 1;
            }
            while let Some(c) = checkpoints.next_if(|c: &&Checkpoint| c.k <= s.k) {
                if c.k == s.k {
                    let err = (torque.to_f32() - c.torque_nm as f32).abs();
                    v.checkpoints += 1;
                    v.max_abs_err_nm = v.max_abs_err_nm.max(err);
                    if err.is_nan() || err > tolerance_nm {
                        v.checkpoint_failures += 1;
                        defmt::error!(
                            "k={=u32}: torque {=f32} N·m, host reference {=f32} N·m",
                            s.k,
                            torque.to_f32(),
                            c.torque_nm as f32
                        );
                    }
                }
            }
            if s.k % TELEMETRY_EVERY == 0 || s.k + 1 == profile::SAMPLES {
                let r = Record {
                    k: s.k,
                    speed_rad_s: s.speed_mrad_s as f32 / 1_000.0,
                    torque_nm: torque.to_f32(),
                    torque_bits: torque.bits(),
                };
                TELEMETRY.send(Telemetry::Record(r)).await;
            }
            v.samples = s.k + 1;
            if v.samples == profile::SAMPLES {
                v.elapsed_us = (now - first).as_micros();
                TELEMETRY.send(Telemetry::Done(v)).await;
                return;
            }
        }
    }
    v.lost += profile::SAMPLES - v.samples;
    TELEMETRY.send(Telemetry::Done(v)).await;
}

/// What a run logs about its parameters.
#[derive(Clone, Copy, Debug)]
pub struct RunInfo {
    /// The params file, relative to the repository root.
    pub params_file: &'static str,
    /// Variant (or example) name.
    pub variant: &'static str,
    /// Joint-law method.
    pub method: &'static str,
    /// Checkpoints the estimator task compares.
    pub checkpoints: u32,
}

/// [`telemetry`] for the run `info` describes (the running-gear example).
pub async fn telemetry_run(
    board: Board,
    cost: Cost,
    number: &'static str,
    table_hash: u64,
    info: RunInfo,
) {
    defmt::info!(
        "{=str} ({=str}, {=u32} Hz): estimator in {=str}, params_file={=str} variant={=str} method={=str} table_hash={=u64:#x}",
        board.name,
        board.core,
        board.core_clock_hz,
        number,
        info.params_file,
        info.variant,
        info.method,
        table_hash
    );
    defmt::info!(
        "cost: instructions_per_update={=u32} instructions_per_update_max={=u32} ram_bytes={=u32} (instructions per SysTick count {=u32}/1000, valid={=bool})",
        cost.instructions_per_update,
        cost.instructions_per_update_max,
        cost.ram_bytes,
        cost.instructions_per_count_x1000,
        cost.valid
    );
    loop {
        match TELEMETRY.receive().await {
            Telemetry::Record(r) => defmt::info!(
                "t={=u32} ms speed={=f32} rad/s torque={=f32} N·m bits={=i64:#x}",
                r.k,
                r.speed_rad_s,
                r.torque_nm,
                r.torque_bits
            ),
            Telemetry::Done(v) => {
                let expected_us = (profile::SAMPLES as u64 - 1) * 1_000;
                let timing_ok = v.elapsed_us.abs_diff(expected_us) <= 2_000;
                let overruns = OVERRUNS.load(Ordering::Relaxed);
                let pass = v.samples == profile::SAMPLES
                    && v.lost == 0
                    && overruns == 0
                    && v.bad_updates == 0
                    && v.checkpoints == info.checkpoints
                    && v.checkpoint_failures == 0
                    && timing_ok
                    && cost.valid;
                defmt::info!(
                    "checks: samples={=u32} lost={=u32} overruns={=u32} bad_updates={=u32} checkpoints={=u32}/{=u32} failed={=u32} max_abs_err_nm={=f32} elapsed_us={=u64} (expected {=u64} ± 2000) cost_valid={=bool}",
                    v.samples,
                    v.lost,
                    overruns,
                    v.bad_updates,
                    v.checkpoints,
                    info.checkpoints,
                    v.checkpoint_failures,
                    v.max_abs_err_nm,
                    v.elapsed_us,
                    expected_us,
                    cost.valid
                );
                if pass {
                    defmt::info!("PASS");
                } else {
                    defmt::error!("FAIL");
                }
                exit::exit(pass);
            }
        }
    }
}

/// The monitor task's verdict (logged; it must have finished and passed).
fn monitor_ok() -> bool {
    let v = crate::monitor_task::MONITOR_VERDICT.load(Ordering::Acquire);
    defmt::info!(
        "monitor_check: finished={=bool} passed={=bool}",
        v != 0,
        v == 1
    );
    v == 1
}
