//! Validity checks of the bench simulations (static and dynamic tests):
//! every run whose figures are printed (`simulate`, `paper`, `bench`,
//! `calibrate`'s final model, `synth`, the forward runs of `diagnose`)
//! passes them first. A failed check is an [`Error::SimInvalid`] naming the
//! check and the value; where the run is still useful, a warning
//! `"<check>: <value>"` instead (SPEC section 7).
//!
//! The checks (thresholds below, with the margins measured on the paper's
//! nine runs in the README):
//!
//! * **static equilibrium** (error): after each settle (the static test,
//!   and the loaded state the dynamic test decays to) the largest
//!   generalised force of the static equations over the weight must be
//!   ≤ [`MAX_STATIC_IMBALANCE`]: Hs/Ws and Hd/Wd are read from a state that
//!   is really at rest.
//! * **energy balance** (error): in the dynamic test, the mechanical energy
//!   (kinetic, gravity, joint springs, contact springs) plus the work the
//!   joint damping has done may never exceed its value when the roller is
//!   put on by more than [`MAX_ENERGY_GAIN`] of the energy the drop
//!   releases; and the joint damping's work may not be negative.
//! * **constraint drift** (error): the loop's closure residual stays below
//!   [`MAX_CLOSURE_M`] on positions; on velocities (which the index-3
//!   integrator does not enforce) below [`MAX_CLOSURE_RATE`] of the fastest
//!   joint speed, else a warning (the figures read positions).
//! * **settled** (warning): over the last period of the dynamic test A
//!   must stay within [`MAX_SETTLE_RATIO`] of the drop's amplitude of the
//!   settled height it is reported with (otherwise Hd/Wd are an
//!   equilibrium the run had not reached).
//! * **time resolution** (warning): at least [`MIN_STEPS_PER_PERIOD`] time
//!   steps per period of A's oscillation (T and Λ are read from it).
//! * **step rejections** (warning): at most [`MAX_REJECTED_PER_STEP`]
//!   rejected (quartered) steps per accepted step.
//!
//! Newton failures at the smallest step and an exhausted step budget are
//! already typed errors of the core (`Diverged`, `NotConverged`).

use crate::error::{Error, Result};
use trackbelt::bench::{BenchChain, DynamicFigures};
use trackbelt::Stats;

/// Largest generalised force of the static equations over the weight after
/// a settle (the solver stops at 1e-7 when it reaches equilibrium by
/// Newton; the paper runs: ≤ 5.2e-12 static, ≤ 3.6e-11 loaded).
pub const MAX_STATIC_IMBALANCE: f64 = 1e-4;
/// Largest gain of mechanical energy plus joint damping work over its start
/// value in the dynamic test, as a fraction of the energy the drop releases
/// (the paper runs lose energy from the first step on: the largest "gain"
/// is −1.5e-4; a Newton tolerance of 0.1 mm gives +3.2).
pub const MAX_ENERGY_GAIN: f64 = 0.01;
/// Smallest energy scale of the energy balance, J (a drop that releases
/// less, e.g. no roller, is judged against this).
pub const MIN_RELEASED_J: f64 = 1e-6;
/// Largest closure residual on positions over the dynamic test, m (Newton
/// holds it to ~1e-9 m; the paper runs: ≤ 2.8e-10 m; a Newton tolerance
/// of 10 µm gives 2.5e-6 m).
pub const MAX_CLOSURE_M: f64 = 1e-6;
/// Largest closure residual on velocities over the fastest joint speed
/// (the paper runs at 2 ms: ≤ 6.4e-4; nominal steps up to 0.5 s: ≤ 5e-3).
pub const MAX_CLOSURE_RATE: f64 = 0.05;
/// Largest distance of A from the settled height over the last period of
/// the dynamic test, over the drop (the settled height minus A's start
/// height). The paper runs (5 s) swing ≤ 0.128 (method I, the least
/// damped, still rings); a run that ends within the first two periods
/// swings 0.35–0.6.
pub const MAX_SETTLE_RATIO: f64 = 0.3;
/// Fewest time steps per period of A's oscillation (the largest accepted
/// step): BDF2's phase error makes T about 1.4 % long at 31 steps per
/// period (50 ms steps), 0.2 % at 78 (20 ms); the paper runs at 2 ms:
/// ≥ 250.
pub const MIN_STEPS_PER_PERIOD: f64 = 50.0;
/// Most rejected steps per accepted step before a run is flagged: the
/// nominal step is too large for Newton and the controller hunts (a
/// rejection quarters the step, an accepted one doubles it, so the ratio
/// stays near or below 0.5; nominal steps of 0.1–0.5 s give 0.14–0.28,
/// the paper runs at 2 ms ≤ 0.0022).
pub const MAX_REJECTED_PER_STEP: f64 = 0.1;

/// What the checks measured on one bench run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BenchValidity {
    /// Static test: generalised-force imbalance over the weight (`None`:
    /// the model cannot tell).
    pub static_imbalance: Option<f64>,
    /// Dynamic test, loaded settled state: the same.
    pub loaded_imbalance: Option<f64>,
    /// Largest `E(t) + W_damp(t) − E(0)` over the energy the drop releases
    /// (`E(0) − E(settled)`).
    pub energy_gain: Option<f64>,
    /// Energy the drop releases, J.
    pub energy_released_j: Option<f64>,
    /// Work the joint damping did over the dynamic test, J.
    pub damping_work_j: Option<f64>,
    /// Largest closure residual on positions, m.
    pub closure_m: Option<f64>,
    /// Largest closure residual on velocities over the largest joint speed.
    pub closure_rate: Option<f64>,
    /// A's largest distance from the settled height over the last period
    /// of the run (the last half when there is no period), over the
    /// drop |settled − start height|.
    pub settle_ratio: Option<f64>,
    /// Period of A's oscillation over the largest accepted time step.
    pub steps_per_period: Option<f64>,
    /// Rejected steps per accepted step.
    pub rejected_per_step: Option<f64>,
}

/// Collects what the checks need while a bench run goes: call
/// [`Monitor::after_static`] after the static test, [`Monitor::observe`] in
/// the dynamic test's observer, [`Monitor::after_dynamic`] after it.
#[derive(Debug, Clone)]
pub struct Monitor {
    v: BenchValidity,
    e0: Option<f64>,
    h0_m: f64,
    heights: Vec<(f64, f64)>,
    max_step_s: f64,
    gain_j: f64,
    damping_work_j: f64,
    last: Option<(f64, f64)>,
    closure_m: f64,
    closure_rate_m_s: f64,
    max_speed_m_s: f64,
    nonfinite: bool,
    stats0: Option<Stats>,
    stride: usize,
    observed: usize,
}

impl Default for Monitor {
    fn default() -> Self {
        Monitor::new()
    }
}

/// `a` and `b`'s larger, NaN counting as infinite.
fn worse(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::INFINITY
    } else {
        a.max(b)
    }
}

impl Monitor {
    /// A monitor for a new run.
    pub fn new() -> Monitor {
        Monitor {
            v: BenchValidity::default(),
            e0: None,
            h0_m: 0.0,
            heights: Vec::new(),
            max_step_s: 0.0,
            gain_j: f64::NEG_INFINITY,
            damping_work_j: 0.0,
            last: None,
            closure_m: 0.0,
            closure_rate_m_s: 0.0,
            max_speed_m_s: 0.0,
            nonfinite: false,
            stats0: None,
            stride: 1,
            observed: 0,
        }
    }

    /// A monitor that takes the energy balance, the closure and the
    /// joint speeds at the start and then after every `stride`-th step
    /// only (`stride` 0 counts as 1); the damping work, the heights, the
    /// step sizes and the finiteness are still taken after every step.
    /// These checks guard against a run that fails numerically, which
    /// shows for many steps: a fit that simulates a thousand times takes
    /// them every few steps (`crate::forward`, where they cost a quarter
    /// of the run when taken every step).
    ///
    /// ```
    /// use trackbelt_host::validity::Monitor;
    /// let m = Monitor::sampling_every(4);
    /// assert_eq!(m.validity(), Monitor::new().validity());
    /// ```
    pub fn sampling_every(stride: usize) -> Monitor {
        Monitor {
            stride: stride.max(1),
            ..Monitor::new()
        }
    }

    /// After the static test: its equilibrium.
    pub fn after_static<const D: usize, C: BenchChain<f64, D>>(&mut self, chain: &mut C) {
        self.v.static_imbalance = chain.static_imbalance().map(|(f, _)| f);
    }

    /// In the dynamic test's observer (called at the start, then after
    /// every step).
    pub fn observe<const D: usize, C: BenchChain<f64, D>>(&mut self, chain: &C) {
        let t = chain.time_s();
        let h = chain.a_height_m();
        let full = self.observed.is_multiple_of(self.stride);
        self.observed += 1;
        if full {
            if let Some((cpos, cvel)) = chain.closure_residuals() {
                self.closure_m = worse(self.closure_m, cpos);
                self.closure_rate_m_s = worse(self.closure_rate_m_s, cvel);
            }
            if let Some(speed) = chain.max_joint_speed_m_s() {
                self.max_speed_m_s = worse(self.max_speed_m_s, speed);
            }
        }
        if let Some(p) = chain.joint_damping_power_w() {
            if let Some((t0, p0)) = self.last {
                self.damping_work_j += 0.5 * (p + p0) * (t - t0);
            }
            self.last = Some((t, p));
        }
        if let Some(e) = full.then(|| chain.mechanical_energy_j()).flatten() {
            match self.e0 {
                None => {
                    self.e0 = Some(e);
                    self.h0_m = h;
                    self.stats0 = chain.solver_stats();
                }
                Some(e0) => {
                    let w = if self.last.is_some() {
                        self.damping_work_j
                    } else {
                        0.0
                    };
                    self.gain_j = worse(self.gain_j, e + w - e0);
                }
            }
        } else if self.stats0.is_none() {
            self.h0_m = h;
            self.stats0 = chain.solver_stats();
        }
        if !(h.is_finite() && t.is_finite()) {
            self.nonfinite = true;
        }
        if let Some(&(t_prev, _)) = self.heights.last() {
            self.max_step_s = worse(self.max_step_s, t - t_prev);
        }
        self.heights.push((t, h));
    }

    /// After the dynamic test (the chain at its loaded settled state).
    pub fn after_dynamic<const D: usize, C: BenchChain<f64, D>>(
        &mut self,
        chain: &mut C,
        figures: &DynamicFigures,
    ) {
        let v = &mut self.v;
        v.loaded_imbalance = chain.static_imbalance().map(|(f, _)| f);
        if let (Some(e0), Some(e_settled)) = (self.e0, chain.mechanical_energy_j()) {
            let released = e0 - e_settled;
            v.energy_released_j = Some(released);
            v.energy_gain = Some(if self.nonfinite {
                f64::INFINITY
            } else {
                self.gain_j / released.abs().max(MIN_RELEASED_J)
            });
        }
        if chain.joint_damping_power_w().is_some() {
            v.damping_work_j = Some(self.damping_work_j);
        }
        if chain.closure_residuals().is_some() {
            v.closure_m = Some(self.closure_m);
            v.closure_rate = Some(self.closure_rate_m_s / self.max_speed_m_s.max(1e-9));
        }
        let hd = figures.hd_mm * 1e-3;
        let drop = (hd - self.h0_m).abs().max(1e-9);
        let t_end = self.heights.last().map_or(0.0, |p| p.0);
        let window = figures.period_s.unwrap_or(0.5 * t_end).min(t_end);
        let swing = self
            .heights
            .iter()
            .filter(|p| p.0 >= t_end - window)
            .fold(0.0f64, |m, p| worse(m, (p.1 - hd).abs()));
        v.settle_ratio = Some(if self.nonfinite {
            f64::INFINITY
        } else {
            swing / drop
        });
        if let Some(period) = figures.period_s {
            v.steps_per_period = Some(period / self.max_step_s.max(1e-12));
        }
        if let (Some(s0), Some(s1)) = (self.stats0, chain.solver_stats()) {
            let steps = s1.steps.saturating_sub(s0.steps);
            let rejected = s1.rejected.saturating_sub(s0.rejected);
            v.rejected_per_step = Some(rejected as f64 / steps.max(1) as f64);
        }
    }

    /// What was measured.
    pub fn validity(&self) -> BenchValidity {
        self.v
    }
}

impl BenchValidity {
    /// Errors for the checks a figure cannot fail (equilibrium, energy
    /// balance, position drift); warnings `"<check>: <value>"` for those it
    /// may (settling, velocity drift, step rejections).
    pub fn check(&self) -> Result<Vec<String>> {
        let fail = |check: &'static str, value: f64, limit: String| Error::SimInvalid {
            check,
            value,
            limit,
        };
        let bad = |x: Option<f64>, max: f64| x.is_some_and(|x| x.is_nan() || x > max);
        if bad(self.static_imbalance, MAX_STATIC_IMBALANCE) {
            return Err(fail(
                "static equilibrium (static test)",
                self.static_imbalance.unwrap_or(f64::NAN),
                format!(
                    "largest generalised force over the weight, valid up to {MAX_STATIC_IMBALANCE:e}: \
                     the settled state is not at rest"
                ),
            ));
        }
        if bad(self.loaded_imbalance, MAX_STATIC_IMBALANCE) {
            return Err(fail(
                "static equilibrium (loaded, dynamic test)",
                self.loaded_imbalance.unwrap_or(f64::NAN),
                format!(
                    "largest generalised force over the weight, valid up to {MAX_STATIC_IMBALANCE:e}: \
                     the settled state is not at rest"
                ),
            ));
        }
        if let Some(w) = self.damping_work_j {
            if w.is_nan() || w < -1e-9 {
                return Err(fail(
                    "energy balance (joint damping work)",
                    w,
                    "J, valid when not negative: the joint damping fed energy in".into(),
                ));
            }
        }
        if bad(self.energy_gain, MAX_ENERGY_GAIN) {
            return Err(fail(
                "energy balance (dynamic test)",
                self.energy_gain.unwrap_or(f64::NAN),
                format!(
                    "largest gain of mechanical energy plus joint damping work over its start \
                     value, as a fraction of the energy the drop releases ({:.4e} J), valid up \
                     to {MAX_ENERGY_GAIN}: the run created energy",
                    self.energy_released_j.unwrap_or(f64::NAN)
                ),
            ));
        }
        if bad(self.closure_m, MAX_CLOSURE_M) {
            return Err(fail(
                "constraint drift (closure, positions)",
                self.closure_m.unwrap_or(f64::NAN),
                format!("m, valid up to {MAX_CLOSURE_M:e} m: the loop does not close"),
            ));
        }
        let mut warnings = Vec::new();
        if bad(self.closure_rate, MAX_CLOSURE_RATE) {
            warnings.push(format!(
                "constraint drift (closure, velocities, over the fastest joint speed; valid up to {MAX_CLOSURE_RATE}): {:.4e}",
                self.closure_rate.unwrap_or(f64::NAN)
            ));
        }
        if bad(self.settle_ratio, MAX_SETTLE_RATIO) {
            warnings.push(format!(
                "not settled (A's largest distance from the settled height over the last period of the dynamic test, over the drop; valid up to {MAX_SETTLE_RATIO}): {:.4}",
                self.settle_ratio.unwrap_or(f64::NAN)
            ));
        }
        if self
            .steps_per_period
            .is_some_and(|x| x.is_nan() || x < MIN_STEPS_PER_PERIOD)
        {
            warnings.push(format!(
                "time resolution (period of A over the largest time step; valid from {MIN_STEPS_PER_PERIOD}): {:.1}",
                self.steps_per_period.unwrap_or(f64::NAN)
            ));
        }
        if bad(self.rejected_per_step, MAX_REJECTED_PER_STEP) {
            warnings.push(format!(
                "step rejections (rejected steps per accepted step; valid up to {MAX_REJECTED_PER_STEP}): {:.3}",
                self.rejected_per_step.unwrap_or(f64::NAN)
            ));
        }
        Ok(warnings)
    }
}
