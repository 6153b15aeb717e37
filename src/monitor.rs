//! The onboard belt-health monitor: the belt's loss scale and the bearing
//! friction, tracked from the measured drive torque.
//!
//! The [estimator](crate::estimator) says what bending the calibrated belt
//! should cost at the present speed. The motor controller knows what
//! driving the belt does cost (motor current × torque constant, less the
//! motor's own losses). While the track is free-running (or on a known
//! surface, so that terrain load is not mistaken for belt loss), the
//! measured torque is modelled as
//!
//! ```text
//! τ_meas − J·dω/dt = s · f(T) · τ_bend(|ω|) · sign(ω) + b · sign(ω) + noise
//! ```
//!
//! with `τ_bend` the table's bending loss ([`EstimatorTable::loss_at`]),
//! `J` the table's belt inertia, `f(T)` the documented temperature law
//! ([`MonitorConfig::temperature_coeff_per_k`]; 1 without a temperature
//! input), and two unknowns: the **loss scale** `s` (1.0 = as calibrated)
//! and the **bearing friction** `b`, N·m (the table's
//! `bearing_friction_nm` is the prior).
//!
//! # Algorithm
//!
//! * Ticks are averaged over short blocks ([`MonitorConfig::block_s`]):
//!   the model is linear, so it holds for block means, and the filter runs
//!   once per block (cheaper per tick, and better conditioned in fixed
//!   point).
//! * A 2-parameter recursive least squares with exponential forgetting
//!   (`λ = 1 − rate·Δt` per block, applied as the multiply `P·(1 + rate·Δt)`:
//!   one division per block). The covariance is kept symmetric, bounded
//!   (trace ≤ [`MonitorConfig::p_max`]) and regularised (diagonal ≥
//!   [`MonitorConfig::p_min`], correlation ≤ 0.99), so a long run at one
//!   speed (no excitation to separate `s` from `b`) cannot wind it up in
//!   f32 or overflow 32.32 fixed point.
//! * Uncertainties are `sqrt(P_ii · v)` with `v` the exponentially
//!   averaged squared block residual (floored at the configured noise over
//!   the block).
//! * **LOSS_DRIFT**: `|s − 1|` past [`MonitorConfig::threshold`] (default
//!   20 %) with `sd(s)` below half the threshold, held for
//!   [`MonitorConfig::debounce_s`].
//! * **STRUCTURED**: a whiteness test on the block residual after the fit:
//!   the exponentially averaged lag-1 correlation `E[e_k e_{k−1}]/E[e²]` or
//!   the squared mean `E[e]²/E[e²]` past
//!   [`MonitorConfig::structure_threshold`], while the residual's power
//!   exceeds the noise over the block plus
//!   ([`MonitorConfig::structure_rel`] × the modelled bending torque)²,
//!   held for [`MonitorConfig::structure_hold_s`] (longer than the
//!   forgetting memory: a step the estimates absorb is not structure). A
//!   residual that the two estimates absorb is white; one they cannot (a
//!   ripple, a loss with the wrong speed shape, terrain load flagged as
//!   free-running) stays correlated.
//! * **BAD_INPUT**: a non-finite or out-of-range input; the tick is skipped
//!   and the state is left unchanged.
//! * The health index is `clamp(1 − |s − 1| / (2·threshold), 0, 1)`, halved
//!   while the residual is structured: 1 as calibrated, 0.5 at the drift
//!   threshold.
//!
//! Per tick: input checks, one table lookup, a few multiply-adds. Per
//! block: one division, one square root per uncertainty. No loops, no
//! heap, no panics.
//!
//! # Config and state
//!
//! As the estimator, in parts: [`MonitorConfig`] is `Copy` plain data (it
//! can live in flash), [`MonitorState`] a few scalars in RAM, and
//! [`Monitor`] borrows a config and an [`EstimatorTable`] and owns a state.
//!
//! ```
//! use trackbelt::estimator::EstimatorTable;
//! use trackbelt::monitor::{Monitor, MonitorConfig, MonitorInput, MonitorStatus};
//!
//! // A table with a bending loss rising linearly with speed (a real one
//! // comes from `EstimatorTable::from_model`).
//! let loss = core::array::from_fn(|k| 0.02 * k as f32);
//! let slope = [0.02f32; 16];
//! let table = EstimatorTable::from_coefficients(1.0f32, 1.0, loss, slope, 0.0, 0.0);
//! let config = MonitorConfig::<f32>::default();
//! config.validate()?;
//! let mut monitor = Monitor::new(&config, &table);
//! // A belt losing 30 % more than calibrated, plus 0.05 N·m of bearing
//! // friction, at speeds sweeping 2…8 rad/s, 100 Hz.
//! let mut out = None;
//! for i in 0..60_000 {
//!     let t = i as f32 * 0.01;
//!     let w = 5.0 + 3.0 * libm::sinf(0.2 * t);
//!     let (bend, _) = table.loss_at(w);
//!     let input = MonitorInput::free_running(w, 1.3 * bend + 0.05, 0.01);
//!     out = Some(monitor.update(&input));
//! }
//! let out = out.unwrap();
//! assert!((out.loss_scale - 1.3).abs() < 0.02);
//! assert!((out.bearing_nm - 0.05).abs() < 0.01);
//! assert!(out.status.contains(MonitorStatus::LOSS_DRIFT));
//! # Ok::<(), trackbelt::Error>(())
//! ```

use crate::error::Result;
use crate::estimator::EstimatorTable;
use crate::params::invalid;
use crate::real::Real;

bitflags::bitflags! {
    /// The monitor's alarms and input flags, empty when the belt is
    /// healthy and the tick was good.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub struct MonitorStatus: u8 {
        /// The loss scale has stayed past the threshold (default ±20 %)
        /// for the debounce time.
        const LOSS_DRIFT = 1;
        /// The residual stays structured (correlated or biased) although
        /// both estimates are fitted: something the loss scale and bearing
        /// friction do not explain.
        const STRUCTURED = 1 << 1;
        /// This tick's input was not finite or out of range: it was
        /// skipped and the state left unchanged.
        const BAD_INPUT = 1 << 2;
        /// This tick was not used for estimation (not free-running, or the
        /// speed too low or beyond the table).
        const SKIPPED = 1 << 3;
    }
}

impl MonitorStatus {
    /// No flag set.
    pub const OK: MonitorStatus = MonitorStatus::empty();

    /// An alarm is raised (LOSS_DRIFT or STRUCTURED).
    #[inline]
    pub fn alarm(self) -> bool {
        self.intersects(MonitorStatus::LOSS_DRIFT | MonitorStatus::STRUCTURED)
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for MonitorStatus {
    /// `OK`, or the flags' names joined by ` | `.
    fn format(&self, f: defmt::Formatter<'_>) {
        if self.is_empty() {
            defmt::write!(f, "OK");
        }
        for (i, (name, _)) in self.iter_names().enumerate() {
            if i > 0 {
                defmt::write!(f, " | ");
            }
            defmt::write!(f, "{=str}", name);
        }
    }
}

/// The monitor's settings: plain `Copy` data in the target's number type
/// (a `static` in flash is fine). Check with [`validate`](Self::validate);
/// convert with [`cast`](Self::cast).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MonitorConfig<T> {
    /// Forgetting rate, 1/s: the RLS forgets with `λ = 1 − rate·Δt` per
    /// block (memory `1/rate`, default 1/60 s⁻¹: one minute).
    pub forgetting_per_s: T,
    /// Relative drift of the loss scale that raises LOSS_DRIFT (default
    /// 0.2: ±20 %).
    pub threshold: T,
    /// How long a condition must hold before its alarm is raised, s
    /// (default 10 s).
    pub debounce_s: T,
    /// Standard deviation of the measured torque's noise per tick, N·m
    /// (the floor of the residual variance, default 0.02 N·m).
    pub noise_nm: T,
    /// Length of the averaging block, s (default 0.02 s).
    pub block_s: T,
    /// Lowest |speed| used for estimation, rad/s (default 0.5): near
    /// standstill the bearing friction's sign is unknown.
    pub min_speed_rad_s: T,
    /// Largest |measured torque| accepted, N·m (default 1000; larger is
    /// BAD_INPUT: keeps fixed point far from overflow).
    pub max_torque_nm: T,
    /// Relative change of the bending loss per kelvin (the temperature
    /// law `f(T) = 1 + c·(T − T_ref)`, clamped to `[0.1, 10]`; default
    /// −0.008/K: rubber's damping falls as it warms). Used only when the
    /// tick gives a temperature.
    pub temperature_coeff_per_k: T,
    /// Temperature at which the table was calibrated, °C (default 20).
    pub reference_temperature_c: T,
    /// Exponential averaging rate of the residual statistics, 1/s
    /// (default 0.1: ten seconds).
    pub residual_rate_per_s: T,
    /// Threshold of the whiteness statistics for STRUCTURED (default 0.5).
    pub structure_threshold: T,
    /// Residual RMS, relative to the modelled bending torque, that the
    /// whiteness test tolerates before STRUCTURED (default 0.03: a lagging
    /// loss-scale estimate leaves a small correlated residual that fits
    /// the estimate and is not "structured").
    pub structure_rel: T,
    /// How long the residual must stay structured before STRUCTURED, s
    /// (default 130 s: the debounce time plus two forgetting memories, so
    /// that a step the estimates absorb, such as a bearing going, is not
    /// taken for structure).
    pub structure_hold_s: T,
    /// Initial covariance diagonal (default 100; the estimates' covariance
    /// is this times the residual variance, so the prior is weak).
    pub p_initial: T,
    /// Bound on the covariance trace (default 1000).
    pub p_max: T,
    /// Floor of the covariance diagonal (default 1e-6): keeps the filter
    /// adapting and the fixed-point covariance many LSBs above zero.
    pub p_min: T,
}

impl<T: Real> Default for MonitorConfig<T> {
    fn default() -> Self {
        MonitorConfig {
            forgetting_per_s: T::from_f64(1.0 / 60.0),
            threshold: T::from_f64(0.2),
            debounce_s: T::from_f64(10.0),
            noise_nm: T::from_f64(0.02),
            block_s: T::from_f64(0.02),
            min_speed_rad_s: T::from_f64(0.5),
            max_torque_nm: T::from_f64(1000.0),
            temperature_coeff_per_k: T::from_f64(-0.008),
            reference_temperature_c: T::from_f64(20.0),
            residual_rate_per_s: T::from_f64(0.1),
            structure_threshold: T::from_f64(0.5),
            structure_rel: T::from_f64(0.03),
            structure_hold_s: T::from_f64(130.0),
            p_initial: T::from_f64(100.0),
            p_max: T::from_f64(1000.0),
            p_min: T::from_f64(1.0e-6),
        }
    }
}

impl<T: Real> MonitorConfig<T> {
    /// Check every field: an [`Error::InvalidParameter`](crate::Error)
    /// naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        let checks: [(&'static str, bool, &'static str); 16] = [
            (
                "monitor.forgetting_per_s",
                pos(self.forgetting_per_s) && self.forgetting_per_s <= T::from_f64(10.0),
                "must be positive and at most 10 per second",
            ),
            (
                "monitor.threshold",
                pos(self.threshold) && self.threshold < T::ONE,
                "must be between 0 and 1",
            ),
            (
                "monitor.debounce_s",
                self.debounce_s.is_finite()
                    && self.debounce_s >= T::ZERO
                    && self.debounce_s <= T::from_f64(1.0e5),
                "must be between 0 and 1e5 s",
            ),
            (
                "monitor.noise_nm",
                pos(self.noise_nm) && self.noise_nm <= T::from_f64(100.0),
                "must be positive and at most 100 N·m",
            ),
            (
                "monitor.block_s",
                pos(self.block_s) && self.block_s <= T::from_f64(10.0),
                "must be positive and at most 10 s",
            ),
            (
                "monitor.min_speed_rad_s",
                self.min_speed_rad_s.is_finite() && self.min_speed_rad_s >= T::ZERO,
                "must be finite and not negative",
            ),
            (
                "monitor.max_torque_nm",
                pos(self.max_torque_nm) && self.max_torque_nm <= T::from_f64(1.0e4),
                "must be positive and at most 1e4 N·m",
            ),
            (
                "monitor.temperature_coeff_per_k",
                self.temperature_coeff_per_k.is_finite()
                    && self.temperature_coeff_per_k.abs() <= T::from_f64(0.1),
                "must be finite and at most 0.1 per kelvin in size",
            ),
            (
                "monitor.reference_temperature_c",
                self.reference_temperature_c.is_finite()
                    && self.reference_temperature_c.abs() <= T::from_f64(500.0),
                "must be between −500 and 500 °C",
            ),
            (
                "monitor.residual_rate_per_s",
                pos(self.residual_rate_per_s) && self.residual_rate_per_s <= T::from_f64(10.0),
                "must be positive and at most 10 per second",
            ),
            (
                "monitor.structure_threshold",
                pos(self.structure_threshold) && self.structure_threshold <= T::ONE,
                "must be between 0 and 1",
            ),
            (
                "monitor.structure_rel",
                self.structure_rel.is_finite()
                    && self.structure_rel >= T::ZERO
                    && self.structure_rel <= T::ONE,
                "must be between 0 and 1",
            ),
            (
                "monitor.structure_hold_s",
                self.structure_hold_s.is_finite()
                    && self.structure_hold_s >= T::ZERO
                    && self.structure_hold_s <= T::from_f64(1.0e5),
                "must be between 0 and 1e5 s",
            ),
            (
                "monitor.p_initial",
                pos(self.p_initial) && self.p_initial <= self.p_max,
                "must be positive and at most p_max",
            ),
            (
                "monitor.p_max",
                pos(self.p_max) && self.p_max <= T::from_f64(1.0e4),
                "must be positive and at most 1e4",
            ),
            (
                "monitor.p_min",
                pos(self.p_min) && self.p_min < self.p_initial,
                "must be positive and below p_initial",
            ),
        ];
        for (field, ok, reason) in checks {
            if !ok {
                return Err(invalid(field, reason));
            }
        }
        Ok(())
    }

    /// The same settings in another number type.
    pub fn cast<U: Real>(&self) -> MonitorConfig<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        MonitorConfig {
            forgetting_per_s: c(self.forgetting_per_s),
            threshold: c(self.threshold),
            debounce_s: c(self.debounce_s),
            noise_nm: c(self.noise_nm),
            block_s: c(self.block_s),
            min_speed_rad_s: c(self.min_speed_rad_s),
            max_torque_nm: c(self.max_torque_nm),
            temperature_coeff_per_k: c(self.temperature_coeff_per_k),
            reference_temperature_c: c(self.reference_temperature_c),
            residual_rate_per_s: c(self.residual_rate_per_s),
            structure_threshold: c(self.structure_threshold),
            structure_rel: c(self.structure_rel),
            structure_hold_s: c(self.structure_hold_s),
            p_initial: c(self.p_initial),
            p_max: c(self.p_max),
            p_min: c(self.p_min),
        }
    }
}

/// One control tick's input.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MonitorInput<T> {
    /// Drive-wheel speed, rad/s.
    pub speed_rad_s: T,
    /// Measured drive torque (motor current × torque constant, less the
    /// motor's own losses), N·m, positive driving forwards.
    pub torque_nm: T,
    /// Tick length, s.
    pub dt_s: T,
    /// Belt temperature, °C, if the controller has it.
    pub temperature_c: Option<T>,
    /// The controller says the track is free-running (or on a known
    /// surface): only such ticks are used for estimation.
    pub free_running: bool,
}

impl<T: Real> MonitorInput<T> {
    /// A free-running tick without a temperature.
    pub fn free_running(speed_rad_s: T, torque_nm: T, dt_s: T) -> Self {
        MonitorInput {
            speed_rad_s,
            torque_nm,
            dt_s,
            temperature_c: None,
            free_running: true,
        }
    }
}

/// Largest loss scale the monitor reports (an estimate beyond it is held
/// there: a belt losing 100 times its calibrated bending torque is a fault
/// the alarms already report).
pub const MAX_LOSS_SCALE: f64 = 100.0;

/// What the monitor reports after a tick.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MonitorOutput<T> {
    /// Belt loss scale (1.0 = as calibrated).
    pub loss_scale: T,
    /// Its standard deviation.
    pub loss_scale_sd: T,
    /// Bearing friction at the drive axle, N·m.
    pub bearing_nm: T,
    /// Its standard deviation, N·m.
    pub bearing_sd: T,
    /// Health index in `[0, 1]`: 1 as calibrated, 0.5 at the drift
    /// threshold, halved while the residual is structured.
    pub health: T,
    /// Alarms and input flags.
    pub status: MonitorStatus,
}

/// The monitor's state: a few scalars in RAM.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MonitorState<T> {
    /// Estimates: loss scale and bearing friction, N·m.
    theta: [T; 2],
    /// Covariance (symmetric: p11, p12, p22), normalised.
    p: [T; 3],
    /// Block sums: time, y, φ1, φ2, ticks.
    block_t: T,
    sum_y: T,
    sum_f1: T,
    sum_f2: T,
    ticks: T,
    /// Previous speed (for the inertia term).
    last_speed: T,
    /// Last tick length and its reciprocal.
    last_dt: T,
    inv_dt: T,
    primed: bool,
    /// Residual statistics: mean, mean square, lag-1 product, last.
    e_mean: T,
    e_sq: T,
    e_lag: T,
    e_last: T,
    /// How long each condition has held, s.
    drift_held_s: T,
    structure_held_s: T,
    status: MonitorStatus,
}

impl<T: Real> MonitorState<T> {
    /// The state before the first tick: loss scale 1, the table's bearing
    /// friction, covariance `p_initial`.
    pub fn new(config: &MonitorConfig<T>, table: &EstimatorTable<T>) -> Self {
        MonitorState {
            theta: [T::ONE, table.bearing_friction_nm],
            p: [config.p_initial, T::ZERO, config.p_initial],
            block_t: T::ZERO,
            sum_y: T::ZERO,
            sum_f1: T::ZERO,
            sum_f2: T::ZERO,
            ticks: T::ZERO,
            last_speed: T::ZERO,
            last_dt: T::ZERO,
            inv_dt: T::ZERO,
            primed: false,
            e_mean: T::ZERO,
            e_sq: config.noise_nm * config.noise_nm,
            e_lag: T::ZERO,
            e_last: T::ZERO,
            drift_held_s: T::ZERO,
            structure_held_s: T::ZERO,
            status: MonitorStatus::OK,
        }
    }

    /// The present estimates and alarms (without a new tick).
    pub fn output(&self, config: &MonitorConfig<T>) -> MonitorOutput<T> {
        let v = self.e_sq.max(T::epsilon());
        let s = self.theta[0];
        let dev = (s - T::ONE).abs();
        let mut health =
            (T::ONE - dev / (config.threshold + config.threshold)).clamp(T::ZERO, T::ONE);
        if self.status.contains(MonitorStatus::STRUCTURED) {
            health *= T::from_f64(0.5);
        }
        MonitorOutput {
            loss_scale: s,
            loss_scale_sd: (self.p[0] * v).max(T::ZERO).sqrt(),
            bearing_nm: self.theta[1],
            bearing_sd: (self.p[2] * v).max(T::ZERO).sqrt(),
            health,
            status: self.status,
        }
    }
}

impl<T: Real> MonitorConfig<T> {
    /// One tick: update `state` from `input` with the `table`'s bending
    /// loss as the regressor. A bad input (non-finite, tick not positive,
    /// |torque| beyond [`max_torque_nm`](Self::max_torque_nm)) leaves the
    /// state unchanged and sets BAD_INPUT in the output.
    pub fn update(
        &self,
        table: &EstimatorTable<T>,
        state: &mut MonitorState<T>,
        input: &MonitorInput<T>,
    ) -> MonitorOutput<T> {
        let w = input.speed_rad_s;
        let y = input.torque_nm;
        let dt = input.dt_s;
        let temp_ok = match input.temperature_c {
            Some(t) => t.is_finite() && t.abs() <= T::from_f64(1000.0),
            None => true,
        };
        if !(w.is_finite()
            && y.is_finite()
            && dt.is_finite()
            && dt > T::ZERO
            && dt <= T::from_f64(10.0)
            && w.abs() <= T::from_f64(1.0e4)
            && y.abs() <= self.max_torque_nm
            && temp_ok)
        {
            let mut out = state.output(self);
            out.status |= MonitorStatus::BAD_INPUT;
            return out;
        }
        // Inertia torque from the speed change since the last tick.
        if dt != state.last_dt {
            // One division per change of tick length, not per tick.
            state.last_dt = dt;
            state.inv_dt = T::ONE / dt;
        }
        let accel_torque = if state.primed {
            table.inertia_kg_m2 * (w - state.last_speed) * state.inv_dt
        } else {
            T::ZERO
        };
        state.last_speed = w;
        state.primed = true;
        let speed = w.abs();
        let (bend, in_range) = table.loss_at(speed);
        let usable = input.free_running && speed >= self.min_speed_rad_s && in_range;
        if !usable {
            let mut out = state.output(self);
            out.status |= MonitorStatus::SKIPPED;
            return out;
        }
        let sign = if w > T::ZERO { T::ONE } else { -T::ONE };
        let factor = match input.temperature_c {
            Some(t) => (T::ONE + self.temperature_coeff_per_k * (t - self.reference_temperature_c))
                .clamp(T::from_f64(0.1), T::from_f64(10.0)),
            None => T::ONE,
        };
        state.sum_y += (y - accel_torque) * sign;
        state.sum_f1 += bend * factor;
        state.sum_f2 += T::ONE;
        state.ticks += T::ONE;
        state.block_t += dt;
        if state.block_t >= self.block_s {
            self.block(state);
        }
        state.output(self)
    }

    /// The RLS step, the residual statistics and the alarms, on one block.
    fn block(&self, s: &mut MonitorState<T>) {
        let n = s.ticks;
        let bt = s.block_t;
        let inv_n = T::ONE / n;
        let y = s.sum_y * inv_n;
        let f1 = s.sum_f1 * inv_n;
        let f2 = s.sum_f2 * inv_n;
        s.block_t = T::ZERO;
        s.sum_y = T::ZERO;
        s.sum_f1 = T::ZERO;
        s.sum_f2 = T::ZERO;
        s.ticks = T::ZERO;
        let [p11, p12, p22] = s.p;
        // Forgetting: P / λ ≈ P (1 + rate·Δt).
        let g = T::ONE + self.forgetting_per_s * bt;
        let (p11, p12, p22) = (p11 * g, p12 * g, p22 * g);
        // a-priori residual and gain.
        // Clipped to the input range: a block mean dominated by an
        // implausible inertia torque (a speed jump between two ticks)
        // cannot wind the estimates up to overflow.
        let e = (y - (s.theta[0] * f1 + s.theta[1] * f2))
            .clamp(-self.max_torque_nm, self.max_torque_nm);
        let pf1 = p11 * f1 + p12 * f2;
        let pf2 = p12 * f1 + p22 * f2;
        let den = T::ONE + f1 * pf1 + f2 * pf2;
        let inv_den = T::ONE / den;
        let k1 = pf1 * inv_den;
        let k2 = pf2 * inv_den;
        // Estimates held to a physical range (loss scale within ±MAX_LOSS_SCALE,
        // bearing friction within the torque range): never a non-finite figure.
        let max_scale = T::from_f64(MAX_LOSS_SCALE);
        s.theta[0] = (s.theta[0] + k1 * e).clamp(-max_scale, max_scale);
        s.theta[1] = (s.theta[1] + k2 * e).clamp(-self.max_torque_nm, self.max_torque_nm);
        let mut p11 = p11 - k1 * pf1;
        let mut p12 = p12 - k1 * pf2;
        let mut p22 = p22 - k2 * pf2;
        // Bounds: trace ≤ p_max, diagonal ≥ p_min, correlation ≤ 0.99.
        let tr = p11 + p22;
        if tr > self.p_max {
            let f = self.p_max / tr;
            p11 *= f;
            p12 *= f;
            p22 *= f;
        }
        p11 = p11.max(self.p_min);
        p22 = p22.max(self.p_min);
        let lim = T::from_f64(0.99) * (p11 * p22).sqrt();
        p12 = p12.clamp(-lim, lim);
        s.p = [p11, p12, p22];
        // Residual after the fit, and its statistics.
        let e_post = e * inv_den;
        let a = (self.residual_rate_per_s * bt).min(T::ONE);
        let floor = self.noise_nm * self.noise_nm * inv_n;
        s.e_mean += a * (e_post - s.e_mean);
        s.e_sq += a * (e_post * e_post - s.e_sq);
        s.e_sq = s.e_sq.max(floor);
        s.e_lag += a * (e_post * s.e_last - s.e_lag);
        s.e_last = e_post;
        // Alarms, debounced.
        let dev = (s.theta[0] - T::ONE).abs();
        let sd = (s.p[0] * s.e_sq).sqrt();
        let drift = dev > self.threshold && sd + sd < self.threshold;
        s.drift_held_s = if drift {
            (s.drift_held_s + bt).min(self.debounce_s + bt)
        } else {
            T::ZERO
        };
        let v = s.e_sq;
        let k = self.structure_threshold;
        // Significant: the residual power above the noise over the block
        // plus the relative allowance on the modelled bending torque
        // (a tracking lag of the loss scale is not "structured").
        let model = s.theta[0] * f1 * self.structure_rel;
        let significant = v > floor + model * model;
        let structured = significant && (s.e_lag > k * v || s.e_mean * s.e_mean > k * v);
        s.structure_held_s = if structured {
            (s.structure_held_s + bt).min(self.structure_hold_s + bt)
        } else {
            T::ZERO
        };
        s.status.set(
            MonitorStatus::LOSS_DRIFT,
            drift && s.drift_held_s >= self.debounce_s,
        );
        s.status.set(
            MonitorStatus::STRUCTURED,
            structured && s.structure_held_s >= self.structure_hold_s,
        );
    }
}

/// A monitor that borrows its config and the estimator's table and owns
/// its state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Monitor<'a, T> {
    config: &'a MonitorConfig<T>,
    table: &'a EstimatorTable<T>,
    state: MonitorState<T>,
}

impl<'a, T: Real> Monitor<'a, T> {
    /// A fresh monitor (loss scale 1, the table's bearing friction).
    pub fn new(config: &'a MonitorConfig<T>, table: &'a EstimatorTable<T>) -> Self {
        Monitor {
            config,
            table,
            state: MonitorState::new(config, table),
        }
    }

    /// One tick (see [`MonitorConfig::update`]).
    #[inline]
    pub fn update(&mut self, input: &MonitorInput<T>) -> MonitorOutput<T> {
        self.config.update(self.table, &mut self.state, input)
    }

    /// The present estimates and alarms.
    pub fn output(&self) -> MonitorOutput<T> {
        self.state.output(self.config)
    }

    /// The state.
    pub fn state(&self) -> &MonitorState<T> {
        &self.state
    }
}
