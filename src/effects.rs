//! Optional terms of the joint law: the effects a measured residual can be
//! traced to (the identifiers of `DATA.md`).
//!
//! The baseline bending law ([`crate::joint`]) is `Mz = −f(ζ) − cz·ζ̇`.
//! Each effect below adds a term to it; all are **off by default**, and when
//! every effect is off [`JointLaw::moment`](crate::joint::JointLaw::moment)
//! returns exactly the baseline (bit for bit, one flag test more). Every
//! term supplies its partial derivatives (`−∂M/∂ζ`, `−∂M/∂ζ̇`) for the
//! integrator's Newton matrix; the kinks (Coulomb friction, power laws at
//! zero speed) are smoothed so the derivatives stay finite.
//!
//! | identifier | term added to `Mz` (N·m) | parameters |
//! | --- | --- | --- |
//! | `joint_friction` | `−μ·ζ̇/√(ζ̇² + ε²)` (smoothed Coulomb) | `torque_nm` μ, `smoothing_rad_s` ε |
//! | `quadratic_damping` | `−c₂·ζ̇·|ζ̇|` | `c2_nms2_per_rad2` |
//! | `amplitude_stiffness` | `−k₃·ζ³` (a cubic, Duffing-type stiffness: the tangent stiffness and so the period change with the bending amplitude) | `k3_nm_per_rad3` |
//! | `rate_dependent_damping` | `−c·|ζ̇|^p·sign ζ̇`, smoothed as `−c·ζ̇·(ζ̇² + ε²)^((p−1)/2)` | `coefficient`, `exponent` p, `smoothing_rad_s` ε |
//! | `thermal_softening` | the whole moment (and its derivatives) scaled by `g = 1 − α·(T − T_ref)`, clamped to [0.05, 2] | `alpha_per_k`, `reference_temp_c`, run-time `temp_c` |
//! | `joint_friction` (Dahl) | a friction moment with pre-sliding, following the joint's travel: see [`crate::memory`] | `torque_nm` Mc, `presliding_rad` ζs |
//! | `amplitude_stiffness` (Payne) | the elastic moment about a slow mean scaled by the recent amplitude's factor: see [`crate::memory`] | `depth`, `amplitude_rad`, `memory_s`, `mean_s` |
//! | `bearing_friction` | not a joint term: a constant resisting torque at the rig's wheel axles | [`RigConfig::bearing_friction_nm`](crate::rig::RigConfig::bearing_friction_nm) |
//!
//! ```
//! use trackbelt::effects::{Effects, JointFriction};
//! use trackbelt::joint::JointLaw;
//! use trackbelt::stiffness::Stiffness;
//! let mut law = JointLaw::<f64>::new(Stiffness::Constant { kz: 8.6 }, 0.45).unwrap();
//! let base = law.moment(-0.2, 0.5);
//! law.effects = Effects { joint_friction: Some(JointFriction { torque_nm: 0.02, smoothing_rad_s: 0.01 }), ..Effects::none() };
//! let with = law.moment(-0.2, 0.5);
//! // Nearly the full friction torque opposes the motion at 0.5 rad/s.
//! assert!((base.moment_nm - with.moment_nm - 0.02).abs() < 1e-5);
//! ```

use crate::error::{invalid as bad, Result};
pub use crate::memory::{DahlFriction, PayneSoftening};
use crate::real::Real;
use crate::stiffness::JointMoment;

/// Smoothed Coulomb friction torque in every joint (`joint_friction`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointFriction<T> {
    /// Friction torque μ at speeds well above `smoothing_rad_s`, N·m.
    pub torque_nm: T,
    /// Joint speed ε below which the torque is proportional to speed, rad/s.
    pub smoothing_rad_s: T,
}

/// Power-law joint damping (`rate_dependent_damping`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RateDamping<T> {
    /// Coefficient c, N·m·(s/rad)^p.
    pub coefficient: T,
    /// Exponent p (1 is linear damping), in (0, 3].
    pub exponent: T,
    /// Joint speed ε that smooths the power law at zero speed, rad/s.
    pub smoothing_rad_s: T,
}

/// Temperature-dependent stiffness and damping (`thermal_softening`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ThermalSoftening<T> {
    /// Relative loss of stiffness and damping per kelvin above the
    /// reference temperature, 1/K.
    pub alpha_per_k: T,
    /// Temperature at which the baseline law holds, °C.
    pub reference_temp_c: T,
    /// Current belt temperature, °C (a run-time input, see
    /// [`Chain::set_belt_temperature_c`](crate::Chain::set_belt_temperature_c)).
    pub temp_c: T,
}

impl<T: Real> ThermalSoftening<T> {
    /// Scale factor `g = 1 − α·(T − T_ref)`, clamped to [0.05, 2].
    pub fn factor(&self) -> T {
        let g = T::ONE - self.alpha_per_k * (self.temp_c - self.reference_temp_c);
        g.clamp(T::from_f64(0.05), T::from_f64(2.0))
    }
}

/// The optional terms of the joint law. `Effects::none()` (the default) is
/// the baseline model.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Effects<T> {
    /// `joint_friction`: Coulomb torque in every joint.
    pub joint_friction: Option<JointFriction<T>>,
    /// `quadratic_damping`: `c₂` of `−c₂·ζ̇·|ζ̇|`, N·m·s²/rad².
    pub quadratic_damping: Option<T>,
    /// `amplitude_stiffness`: `k₃` of `−k₃·ζ³`, N·m/rad³ (positive hardens,
    /// negative softens with amplitude).
    pub amplitude_stiffness: Option<T>,
    /// `rate_dependent_damping`: a power-law damping added to `cz`.
    pub rate_dependent_damping: Option<RateDamping<T>>,
    /// `thermal_softening`: stiffness and damping scaled with temperature.
    pub thermal_softening: Option<ThermalSoftening<T>>,
    /// `joint_friction` with pre-sliding (Dahl): a law with a memory,
    /// carried by the pin chain ([`crate::memory`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub dahl_friction: Option<DahlFriction<T>>,
    /// `amplitude_stiffness` that follows the recent amplitude (Payne): a
    /// law with a memory, carried by the pin chain ([`crate::memory`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub payne_softening: Option<PayneSoftening<T>>,
}

impl<T> Default for Effects<T> {
    fn default() -> Self {
        Effects {
            joint_friction: None,
            quadratic_damping: None,
            amplitude_stiffness: None,
            rate_dependent_damping: None,
            thermal_softening: None,
            dahl_friction: None,
            payne_softening: None,
        }
    }
}

impl<T: Real> Effects<T> {
    /// No effect: the baseline law.
    pub fn none() -> Self {
        Self::default()
    }

    /// Whether any term is on.
    #[inline]
    pub fn any_joint_term(&self) -> bool {
        self.joint_friction.is_some()
            || self.quadratic_damping.is_some()
            || self.amplitude_stiffness.is_some()
            || self.rate_dependent_damping.is_some()
            || self.thermal_softening.is_some()
    }

    /// Whether a law with a memory ([`crate::memory`]) is on.
    #[inline]
    pub fn any_memory_term(&self) -> bool {
        self.dahl_friction.is_some() || self.payne_softening.is_some()
    }

    /// Add the effects to the baseline moment `m` at angle ζ and rate ζ̇.
    #[inline]
    pub fn apply(&self, zeta: T, rate: T, m: JointMoment<T>) -> JointMoment<T> {
        let mut out = m;
        if let Some(f) = &self.joint_friction {
            // μ·v/√(v² + ε²): derivative μ·ε²/(v² + ε²)^(3/2).
            let e2 = f.smoothing_rad_s * f.smoothing_rad_s;
            let s2 = rate * rate + e2;
            let s = s2.sqrt();
            out.moment_nm -= f.torque_nm * rate / s;
            out.damping += f.torque_nm * e2 / (s2 * s);
        }
        if let Some(c2) = self.quadratic_damping {
            let a = rate.abs();
            out.moment_nm -= c2 * rate * a;
            out.damping += T::from_f64(2.0) * c2 * a;
        }
        if let Some(k3) = self.amplitude_stiffness {
            let z2 = zeta * zeta;
            out.moment_nm -= k3 * z2 * zeta;
            out.stiffness += T::from_f64(3.0) * k3 * z2;
        }
        if let Some(r) = &self.rate_dependent_damping {
            // c·v·(v² + ε²)^((p−1)/2); derivative c·(v² + ε²)^((p−3)/2)·(p·v² + ε²).
            // The power is taken in f64 (the number types carry no pow).
            let v = rate.to_f64();
            let e2 = r.smoothing_rad_s.to_f64() * r.smoothing_rad_s.to_f64();
            let p = r.exponent.to_f64();
            let c = r.coefficient.to_f64();
            let s2 = v * v + e2;
            let base = libm::pow(s2, 0.5 * (p - 1.0));
            out.moment_nm -= T::from_f64(c * v * base);
            out.damping += T::from_f64(c * base / s2 * (p * v * v + e2));
        }
        if let Some(th) = &self.thermal_softening {
            let g = th.factor();
            out.moment_nm *= g;
            out.stiffness *= g;
            out.damping *= g;
        }
        out
    }

    /// Check every parameter of the effects that are on.
    pub fn validate(&self) -> Result<()> {
        let pos = |x: T| x.is_finite() && x > T::ZERO;
        let nonneg = |x: T| x.is_finite() && x >= T::ZERO;
        if let Some(f) = &self.joint_friction {
            if !nonneg(f.torque_nm) {
                return Err(bad(
                    "effects.joint_friction.torque_nm",
                    "must be finite and not negative",
                ));
            }
            if !pos(f.smoothing_rad_s) {
                return Err(bad(
                    "effects.joint_friction.smoothing_rad_s",
                    "must be positive and finite",
                ));
            }
        }
        if let Some(c2) = self.quadratic_damping {
            if !nonneg(c2) {
                return Err(bad(
                    "effects.quadratic_damping",
                    "must be finite and not negative",
                ));
            }
        }
        if let Some(k3) = self.amplitude_stiffness {
            if !k3.is_finite() {
                return Err(bad("effects.amplitude_stiffness", "must be finite"));
            }
        }
        if let Some(r) = &self.rate_dependent_damping {
            if !nonneg(r.coefficient) {
                return Err(bad(
                    "effects.rate_dependent_damping.coefficient",
                    "must be finite and not negative",
                ));
            }
            if !(pos(r.exponent) && r.exponent <= T::from_f64(3.0)) {
                return Err(bad(
                    "effects.rate_dependent_damping.exponent",
                    "must be in (0, 3]",
                ));
            }
            if !pos(r.smoothing_rad_s) {
                return Err(bad(
                    "effects.rate_dependent_damping.smoothing_rad_s",
                    "must be positive and finite",
                ));
            }
        }
        if let Some(th) = &self.thermal_softening {
            if !th.alpha_per_k.is_finite()
                || !th.reference_temp_c.is_finite()
                || !th.temp_c.is_finite()
            {
                return Err(bad(
                    "effects.thermal_softening",
                    "alpha_per_k, reference_temp_c and temp_c must be finite",
                ));
            }
        }
        crate::memory::validate(self.dahl_friction.as_ref(), self.payne_softening.as_ref())
    }

    /// Convert to another number type.
    pub fn cast<U: Real>(&self) -> Effects<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        Effects {
            joint_friction: self.joint_friction.map(|f| JointFriction {
                torque_nm: c(f.torque_nm),
                smoothing_rad_s: c(f.smoothing_rad_s),
            }),
            quadratic_damping: self.quadratic_damping.map(c),
            amplitude_stiffness: self.amplitude_stiffness.map(c),
            rate_dependent_damping: self.rate_dependent_damping.map(|r| RateDamping {
                coefficient: c(r.coefficient),
                exponent: c(r.exponent),
                smoothing_rad_s: c(r.smoothing_rad_s),
            }),
            thermal_softening: self.thermal_softening.map(|t| ThermalSoftening {
                alpha_per_k: c(t.alpha_per_k),
                reference_temp_c: c(t.reference_temp_c),
                temp_c: c(t.temp_c),
            }),
            dahl_friction: self.dahl_friction.map(|d| DahlFriction {
                torque_nm: c(d.torque_nm),
                presliding_rad: c(d.presliding_rad),
            }),
            payne_softening: self.payne_softening.map(|p| PayneSoftening {
                depth: c(p.depth),
                amplitude_rad: c(p.amplitude_rad),
                memory_s: c(p.memory_s),
                mean_s: c(p.mean_s),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::JointLaw;
    use crate::stiffness::Stiffness;

    fn law(e: Effects<f64>) -> JointLaw<f64> {
        let mut l = JointLaw::new(Stiffness::Constant { kz: 8.6 }, 0.45).unwrap();
        l.effects = e;
        l.validate().unwrap();
        l
    }

    /// The derivatives each term reports match finite differences.
    #[test]
    fn derivatives_match_finite_differences() {
        let all = [
            Effects {
                joint_friction: Some(JointFriction {
                    torque_nm: 0.03,
                    smoothing_rad_s: 0.02,
                }),
                ..Effects::none()
            },
            Effects {
                quadratic_damping: Some(0.2),
                ..Effects::none()
            },
            Effects {
                amplitude_stiffness: Some(-3.0),
                ..Effects::none()
            },
            Effects {
                rate_dependent_damping: Some(RateDamping {
                    coefficient: 0.1,
                    exponent: 0.5,
                    smoothing_rad_s: 0.01,
                }),
                ..Effects::none()
            },
            Effects {
                thermal_softening: Some(ThermalSoftening {
                    alpha_per_k: 0.01,
                    reference_temp_c: 20.0,
                    temp_c: 45.0,
                }),
                quadratic_damping: Some(0.1),
                ..Effects::none()
            },
        ];
        for e in all {
            let l = law(e);
            for &(z, r) in &[(-0.5, 0.3), (0.1, -0.01), (-0.05, 0.0), (0.2, 2.0)] {
                let m = l.moment(z, r);
                let h = 1e-6;
                let kz = -(l.moment(z + h, r).moment_nm - l.moment(z - h, r).moment_nm) / (2.0 * h);
                let cz = -(l.moment(z, r + h).moment_nm - l.moment(z, r - h).moment_nm) / (2.0 * h);
                assert!(
                    (kz - m.stiffness).abs() < 1e-5 * (1.0 + kz.abs()),
                    "{e:?} k"
                );
                assert!((cz - m.damping).abs() < 1e-4 * (1.0 + cz.abs()), "{e:?} c");
            }
        }
    }

    #[test]
    fn off_is_the_baseline_bit_for_bit() {
        let l = law(Effects::none());
        let m = l.moment(-0.3, 0.7);
        assert_eq!(m.moment_nm, -(8.6 * -0.3) - 0.45 * 0.7);
    }

    #[test]
    fn rejects_bad_parameters() {
        let mut l = law(Effects::none());
        l.effects.quadratic_damping = Some(-1.0);
        assert!(l.validate().is_err());
        l.effects = Effects {
            rate_dependent_damping: Some(RateDamping {
                coefficient: 0.1,
                exponent: 5.0,
                smoothing_rad_s: 0.01,
            }),
            ..Effects::none()
        };
        assert!(l.validate().is_err());
    }

    #[test]
    fn thermal_factor_is_clamped() {
        let t = ThermalSoftening {
            alpha_per_k: 0.1,
            reference_temp_c: 20.0,
            temp_c: 100.0,
        };
        assert_eq!(t.factor(), 0.05);
    }
}
