//! The joint law's terms with a memory of the past motion, and the state
//! the pin chain keeps for them at every joint.
//!
//! The terms of [`crate::effects`] that are functions of the joint's angle
//! and rate alone live in [`JointLaw::moment`](crate::joint::JointLaw::moment).
//! Two families of the catalogue's effects also come in laws with a
//! memory; they are written here, because they need a state per joint
//! that only the chain can hold:
//!
//! | identifier | law | state per joint |
//! | --- | --- | --- |
//! | `joint_friction` | [`DahlFriction`]: the friction moment follows the joint's travel, `dF/dζ = (Mc·sgn Δζ − F)/ζs`, integrated exactly over each step (pre-sliding: a stiffness `Mc/ζs` at small travel, the full `Mc` after a few `ζs`) | the friction moment F |
//! | `amplitude_stiffness` | [`PayneSoftening`]: a standard-linear-solid arm whose stiffness depends on the recent amplitude `a` (a low-passed `√2·|ζ − ζ̄|` in the RMS sense, not the instantaneous angle): the static law holds the slowly moving mean angle ζ̄, the deviation from it sees `h(a)` times the static stiffness, `h = 1 + s·a_c/(a + a_c)` (softening: stiffer at small amplitude, Payne) or `h = 1 + s·a/(a + a_c)` (hardening), never below 1 | ζ̄ and a |
//!
//! Both act only in dynamics (a static solve or the estimator's march sees
//! the baseline law), are not scaled by `thermal_softening`, and start
//! from rest (F = 0, ζ̄ = the present angle, a = 0) whenever the chain's
//! motion is reset. The friction moment enters the Newton matrix through
//! its exact derivative with respect to the step's travel; the Payne
//! state moves on once per accepted step (its times are ≫ a step).
//!
//! Both laws take energy out of the motion and never put it in over a
//! cycle: Dahl's moment lags the travel; the Payne arm `(h − 1)·k`
//! relaxes through the mean (a spring in series with a dashpot of time
//! `mean_s`), and it is never negative, because a dynamic stiffness below
//! the static one would make that arm a source of energy (a negative
//! spring behind a dashpot: the swing grows).
//!
//! ```
//! use trackbelt::memory::DahlFriction;
//! let d = DahlFriction { torque_nm: 0.03, presliding_rad: 0.01 };
//! // From rest, a travel of one pre-sliding angle builds 63 % of Mc.
//! let (f, _) = d.advance(0.0, 0.01);
//! assert!((f - 0.03 * (1.0 - (-1.0f64).exp())).abs() < 1e-12);
//! // Far past it the full sliding moment opposes the motion.
//! assert!((d.advance(0.0, 0.2).0 - 0.03).abs() < 1e-9);
//! ```

use crate::effects::Effects;
use crate::error::{invalid as bad, Result};
use crate::real::Real;
use crate::stiffness::JointMoment;

/// Dahl friction in every joint (a `joint_friction` law with pre-sliding).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DahlFriction<T> {
    /// Sliding friction moment Mc, N·m.
    pub torque_nm: T,
    /// Pre-sliding angle ζs: the travel over which the moment builds up
    /// (by 1 − 1/e), rad.
    pub presliding_rad: T,
}

impl<T: Real> DahlFriction<T> {
    /// The friction moment (N·m, acting against the travel) after the joint
    /// travels `d_zeta` rad from a state `moment_nm`, and its derivative
    /// with respect to `d_zeta` (N·m/rad, never negative).
    pub fn advance(&self, moment_nm: T, d_zeta: T) -> (T, T) {
        if d_zeta == T::ZERO {
            return (moment_nm, T::ZERO);
        }
        let target = if d_zeta > T::ZERO {
            self.torque_nm
        } else {
            -self.torque_nm
        };
        let e = T::from_f64(libm::exp(
            -d_zeta.abs().to_f64() / self.presliding_rad.to_f64(),
        ));
        let gap = moment_nm - target;
        let m = target + gap * e;
        // d/dΔζ of target + gap·e^(−|Δζ|/ζs) = −sgn(Δζ)·gap·e/ζs.
        let slope = (-gap * e / self.presliding_rad).abs();
        (m, slope)
    }
}

/// Payne-type amplitude dependence with memory (an `amplitude_stiffness`
/// law): the elastic moment about a slowly moving mean angle ζ̄ is the
/// static law's times the factor [`Self::factor`] of the recent amplitude,
/// while ζ̄ itself is held by the static law:
/// `M = −[f(ζ̄) + h(a)·(f(ζ) − f(ζ̄))]`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PayneSoftening<T> {
    /// Relative change of the dynamic stiffness from small to large
    /// amplitude, in (−1, 1): positive softens (at large amplitude the
    /// dynamic stiffness is `1 − depth` times the one at small amplitude),
    /// negative hardens (it is `1 − depth` times, i.e. more).
    pub depth: T,
    /// Amplitude at which half the change is reached, rad.
    pub amplitude_rad: T,
    /// Time over which the amplitude is remembered, s.
    pub memory_s: T,
    /// Time over which the mean angle follows the motion (the arm's
    /// relaxation time), s.
    pub mean_s: T,
}

impl<T: Real> PayneSoftening<T> {
    /// The dynamic stiffness about the mean, relative to the static law's,
    /// at amplitude `a` rad: `h = 1 + s·a_c/(a + a_c)` with
    /// `s = depth/(1 − depth)` when softening (from `1/(1 − depth)` at rest
    /// down to 1), `h = 1 − depth·a/(a + a_c)` when hardening (from 1 up
    /// to `1 − depth`). Never below 1: the arm is a spring, not a source.
    ///
    /// ```
    /// use trackbelt::memory::PayneSoftening;
    /// let p = PayneSoftening::<f64> { depth: 0.4, amplitude_rad: 0.02, memory_s: 0.5, mean_s: 1.5 };
    /// // Stiffer at small amplitude, by 1/(1 − depth).
    /// assert!((p.factor(0.0) - 1.0 / 0.6).abs() < 1e-12);
    /// // Half the excess gone at a_c, all of it at large amplitude.
    /// assert!((p.factor(0.02) - (1.0 + 0.5 * 0.4 / 0.6)).abs() < 1e-12);
    /// assert!((p.factor(1e9) - 1.0).abs() < 1e-6);
    /// // Hardening: 1 at rest, 1 − depth at large amplitude.
    /// let hard = PayneSoftening { depth: -0.3, ..p };
    /// assert_eq!(hard.factor(0.0), 1.0);
    /// assert!((hard.factor(1e9) - 1.3).abs() < 1e-6);
    /// ```
    pub fn factor(&self, amplitude_rad: T) -> T {
        let a = amplitude_rad.abs();
        let w = a / (a + self.amplitude_rad);
        if self.depth > T::ZERO {
            T::ONE + self.depth / (T::ONE - self.depth) * (T::ONE - w)
        } else {
            T::ONE - self.depth * w
        }
    }
}

/// Check the memory laws' parameters (called by
/// [`Effects::validate`](crate::effects::Effects::validate)).
pub(crate) fn validate<T: Real>(
    dahl: Option<&DahlFriction<T>>,
    payne: Option<&PayneSoftening<T>>,
) -> Result<()> {
    let pos = |x: T| x.is_finite() && x > T::ZERO;
    if let Some(d) = dahl {
        if !(d.torque_nm.is_finite() && d.torque_nm >= T::ZERO) {
            return Err(bad(
                "effects.dahl_friction.torque_nm",
                "must be finite and not negative",
            ));
        }
        if !pos(d.presliding_rad) {
            return Err(bad(
                "effects.dahl_friction.presliding_rad",
                "must be positive and finite",
            ));
        }
        // The pre-sliding stiffness, up to 2·Mc/ζs (a state at −Mc moving
        // on), enters the Newton matrix: it must not overflow (a
        // subnormal ζs made it infinite).
        if !(T::from_f64(2.0) * d.torque_nm / d.presliding_rad).is_finite() {
            return Err(bad(
                "effects.dahl_friction.presliding_rad",
                "is too small for torque_nm: the pre-sliding stiffness 2·Mc/ζs overflows",
            ));
        }
    }
    if let Some(p) = payne {
        if !(p.depth.is_finite() && p.depth.abs() < T::ONE) {
            return Err(bad("effects.payne_softening.depth", "must be in (−1, 1)"));
        }
        for (v, f) in [
            (p.amplitude_rad, "effects.payne_softening.amplitude_rad"),
            (p.memory_s, "effects.payne_softening.memory_s"),
            (p.mean_s, "effects.payne_softening.mean_s"),
        ] {
            if !pos(v) {
                return Err(bad(f, "must be positive and finite"));
            }
        }
    }
    Ok(())
}

/// The memory state of every joint of a chain with up to `D` joints.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Memory<T, const D: usize> {
    /// Dahl friction moment, N·m.
    friction_nm: [T; D],
    /// Payne mean angle ζ̄, rad.
    mean_rad: [T; D],
    /// Payne remembered squared amplitude a², rad².
    amp2: [T; D],
}

impl<T: Real, const D: usize> Memory<T, D> {
    /// At rest at angle zero everywhere.
    pub(crate) fn new() -> Self {
        Memory {
            friction_nm: [T::ZERO; D],
            mean_rad: [T::ZERO; D],
            amp2: [T::ZERO; D],
        }
    }

    /// Start from rest at the angles `angle(j)` of joints `0..n`.
    pub(crate) fn reset(&mut self, n: usize, angle: impl Fn(usize) -> T) {
        for j in 0..n.min(D) {
            self.friction_nm[j] = T::ZERO;
            self.mean_rad[j] = angle(j);
            self.amp2[j] = T::ZERO;
        }
    }

    /// Joint `j`'s moment `m` (at angle `zeta`, after travelling `d_zeta`
    /// over the step being solved) with the memory terms added. `elastic`
    /// evaluates the baseline's elastic law `(f(ζ), ∂f/∂ζ)`.
    pub(crate) fn apply(
        &self,
        j: usize,
        zeta: T,
        d_zeta: T,
        effects: &Effects<T>,
        elastic: impl Fn(T) -> (T, T),
        m: JointMoment<T>,
    ) -> JointMoment<T> {
        let mut out = m;
        if let Some(d) = &effects.dahl_friction {
            let (f, slope) = d.advance(self.friction_nm[j], d_zeta);
            out.moment_nm -= f;
            out.stiffness += slope;
        }
        if let Some(p) = &effects.payne_softening {
            // M = −[f(ζ̄) + h·(f(ζ) − f(ζ̄))] replaces −f(ζ): the arm
            // (h − 1)·(f(ζ) − f(ζ̄)) is added.
            let arm = p.factor(self.amp2[j].sqrt()) - T::ONE;
            let (f, k) = elastic(zeta);
            let (f_mean, _) = elastic(self.mean_rad[j]);
            out.moment_nm -= arm * (f - f_mean);
            out.stiffness += arm * k;
        }
        out
    }

    /// Power joint `j`'s memory terms take out of the motion at angle
    /// `zeta` and rate `rate` in the present state, W (their moment, with
    /// no travel in the step, against the rate). The energy balance counts
    /// it with the damping's: the Payne term is not a potential.
    pub(crate) fn power_w(
        &self,
        j: usize,
        zeta: T,
        rate: T,
        effects: &Effects<T>,
        elastic: impl Fn(T) -> (T, T),
    ) -> T {
        let zero = JointMoment {
            moment_nm: T::ZERO,
            stiffness: T::ZERO,
            damping: T::ZERO,
        };
        -(self
            .apply(j, zeta, T::ZERO, effects, elastic, zero)
            .moment_nm
            * rate)
    }

    /// Move the states of joints `0..n` on over an accepted step of `h` s
    /// from the angles `before(j)` to `after(j)`.
    pub(crate) fn accept(
        &mut self,
        n: usize,
        h: T,
        effects: &Effects<T>,
        before: impl Fn(usize) -> T,
        after: impl Fn(usize) -> T,
    ) {
        // The low-pass gains of the step, the same at every joint.
        let gains = effects.payne_softening.as_ref().map(|p| {
            (
                T::from_f64(1.0 - libm::exp(-(h / p.mean_s).to_f64())),
                T::from_f64(1.0 - libm::exp(-(h / p.memory_s).to_f64())),
            )
        });
        for j in 0..n.min(D) {
            let z = after(j);
            if let Some(d) = &effects.dahl_friction {
                self.friction_nm[j] = d.advance(self.friction_nm[j], z - before(j)).0;
            }
            if let Some((am, aa)) = gains {
                self.mean_rad[j] += (z - self.mean_rad[j]) * am;
                let dev = z - self.mean_rad[j];
                let target = T::from_f64(2.0) * dev * dev;
                self.amp2[j] += (target - self.amp2[j]) * aa;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact step composes: two half travels give the one whole.
    #[test]
    fn dahl_steps_compose() {
        let d = DahlFriction {
            torque_nm: 0.05,
            presliding_rad: 0.004,
        };
        for &(m0, dz) in &[(0.0, 0.003), (-0.04, 0.01), (0.03, -0.002), (0.05, 0.0)] {
            let whole = d.advance(m0, dz).0;
            let half = d.advance(d.advance(m0, dz / 2.0).0, dz / 2.0).0;
            assert!((whole - half).abs() < 1e-14, "{m0} {dz}");
        }
    }

    /// The derivative matches a finite difference on either side.
    #[test]
    fn dahl_slope_matches_finite_difference() {
        let d = DahlFriction {
            torque_nm: 0.05,
            presliding_rad: 0.004,
        };
        for &(m0, dz) in &[(0.0, 0.003), (-0.04, 0.01), (0.03, -0.002)] {
            let h = 1e-8;
            let fd = (d.advance(m0, dz + h).0 - d.advance(m0, dz - h).0) / (2.0 * h);
            let (_, s) = d.advance(m0, dz);
            assert!((fd - s).abs() < 1e-5 * (1.0 + s), "{fd} {s}");
        }
    }

    /// A steady oscillation of amplitude A about a fixed mean is
    /// remembered as A.
    #[test]
    fn payne_remembers_the_amplitude() {
        let p = PayneSoftening {
            depth: 0.3,
            amplitude_rad: 0.02,
            memory_s: 0.3,
            mean_s: 1.0,
        };
        let e = Effects {
            payne_softening: Some(p),
            ..Effects::none()
        };
        let mut m = Memory::<f64, 4>::new();
        m.reset(1, |_| -0.1);
        let (amp, w, h) = (0.01, 8.0, 1e-3);
        let at = |t: f64| -0.1 + amp * libm::sin(w * t);
        let mut t = 0.0;
        for _ in 0..8000 {
            m.accept(1, h, &e, |_| at(t), |_| at(t + h));
            t += h;
        }
        let a = m.amp2[0].sqrt();
        assert!((a - amp).abs() < 0.1 * amp, "{a}");
        assert!((m.mean_rad[0] + 0.1).abs() < 0.2 * amp);
    }

    /// Driven through a steady cycle (a prescribed sinusoid about a bent
    /// angle, with a few seconds to settle the memory), the Payne arm
    /// takes energy out of the motion, softening or hardening, at every
    /// amplitude and period tried: the work its moment does on the motion
    /// over the last cycles is negative. The law as first written (the
    /// deviation softened below the static stiffness) fails this: it put
    /// energy in.
    #[test]
    fn payne_arm_takes_energy_out_of_a_steady_cycle() {
        let elastic = |x: f64| (0.4 * x + 3.0 * x * x * x, 0.4 + 9.0 * x * x);
        for depth in [0.6, 0.3, -0.4] {
            for (amp, w) in [(0.005, 3.0), (0.03, 8.0), (0.1, 20.0)] {
                let e = Effects {
                    payne_softening: Some(PayneSoftening {
                        depth,
                        amplitude_rad: 0.02,
                        memory_s: 0.4,
                        mean_s: 1.0,
                    }),
                    ..Effects::none()
                };
                let mut m = Memory::<f64, 4>::new();
                m.reset(1, |_| -0.2);
                let h = 1e-4;
                let at = |t: f64| -0.2 + amp * libm::sin(w * t);
                let rate = |t: f64| amp * w * libm::cos(w * t);
                let (mut t, mut dissipated) = (0.0, 0.0);
                let settle = 6.0;
                let cycles = 4.0 * 2.0 * core::f64::consts::PI / w;
                while t < settle + cycles {
                    if t >= settle {
                        let mid = t + h / 2.0;
                        dissipated += h * m.power_w(0, at(mid), rate(mid), &e, elastic);
                    }
                    m.accept(1, h, &e, |_| at(t), |_| at(t + h));
                    t += h;
                }
                assert!(
                    dissipated > 0.0,
                    "depth {depth} amp {amp} w {w}: {dissipated}"
                );
            }
        }
    }
}
