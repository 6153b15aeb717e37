//! The simulated drive: the wheel speed the estimator is fed, one sample
//! per control tick.
//!
//! 0 → 5 rad/s in 1 s, hold, then a few steps down and up. A real speed
//! controller cannot step the wheel speed within one tick, so the steps are
//! slew-limited (25 rad/s²: a 2 rad/s step takes 80 ms).
//!
//! The profile is integer arithmetic in mrad/s, a pure function of the
//! sample index, so the host test (`host-tests/tests/qemu.rs`, which
//! includes this file) and the firmware's build script replay exactly the
//! samples the firmware saw.

/// Control ticks per second (the estimator runs at 1 kHz).
pub const TICK_HZ: u32 = 1_000;

/// Number of samples the firmware runs (4 simulated seconds).
pub const SAMPLES: u32 = 4_000;

/// Ramp from standstill: mrad/s gained per tick (5 rad/s in 1 s).
const RAMP_MRAD_S_PER_TICK: i32 = 5;

/// Slew limit after the ramp: mrad/s per tick (25 rad/s²).
const SLEW_MRAD_S_PER_TICK: i32 = 25;

/// Setpoint changes after the ramp: (sample index, new speed in mrad/s).
const STEPS: [(u32, i32); 4] = [
    (1_600, 3_000),
    (2_200, 4_500),
    (2_800, 2_000),
    (3_400, 5_000),
];

/// Speed after the ramp, mrad/s.
const HOLD_MRAD_S: i32 = 5_000;

/// Drive speed at sample `k`, in mrad/s.
///
/// `speed_mrad_s(0) == 0`, `speed_mrad_s(500) == 2_500`,
/// `speed_mrad_s(1_500) == 5_000` (checked by the host test).
pub fn speed_mrad_s(k: u32) -> i32 {
    let ramp_ticks = (HOLD_MRAD_S / RAMP_MRAD_S_PER_TICK) as u32;
    if k <= ramp_ticks {
        return k as i32 * RAMP_MRAD_S_PER_TICK;
    }
    // Walk the setpoint changes before `k`, slewing from the speed each one
    // started at.
    let mut speed = HOLD_MRAD_S;
    let mut i = 0;
    while i < STEPS.len() {
        let (start, target) = STEPS[i];
        if k < start {
            break;
        }
        let end = if i + 1 < STEPS.len() {
            STEPS[i + 1].0
        } else {
            u32::MAX
        };
        let ticks = (k.min(end) - start) as i32;
        let reach = ticks.saturating_mul(SLEW_MRAD_S_PER_TICK);
        speed = if target >= speed {
            (speed + reach).min(target)
        } else {
            (speed - reach).max(target)
        };
        i += 1;
    }
    speed
}

/// Drive speed at sample `k`, in rad/s (correctly rounded, so identical on
/// every IEEE-754 target).
pub fn speed_rad_s(k: u32) -> f64 {
    rad_s(speed_mrad_s(k))
}

/// mrad/s to rad/s, correctly rounded.
pub fn rad_s(mrad_s: i32) -> f64 {
    mrad_s as f64 / 1_000.0
}

/// Time step between samples, in s.
pub const fn dt_s() -> f64 {
    1.0 / TICK_HZ as f64
}

/// Belt temperature at sample `k` for the running-gear example, in
/// hundredths of a °C: warming linearly from 20 °C to 50 °C over the run
/// (integer arithmetic, like the speed).
pub fn temperature_centi_c(k: u32) -> i32 {
    2_000 + (3_000 * k.min(SAMPLES) as i64 / SAMPLES as i64) as i32
}

/// Belt temperature at sample `k`, °C (correctly rounded).
pub fn temperature_c(k: u32) -> f64 {
    temperature_centi_c(k) as f64 / 100.0
}

/// Belt temperature at sample `k` as the firmware computes it in `f32`, °C
/// (the host's replay computes the same).
pub fn temperature_c_f32(k: u32) -> f32 {
    temperature_centi_c(k) as f32 * 0.01
}
