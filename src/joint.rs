//! The complete law of one joint: stiffness ([`crate::stiffness`]) plus
//! linear damping plus the optional effects ([`crate::effects`]),
//!
//! `Mz = −f(ζ) − cz·ζ̇ + (effect terms)`,
//!
//! the moment every joint of the pin chain and the bushing chain applies.
//!
//! ```
//! use trackbelt::joint::JointLaw;
//! use trackbelt::stiffness::Stiffness;
//! // Method II, E38, paper parameters (converted to N·m/rad).
//! let law = JointLaw::<f64>::new(Stiffness::Bivalent { kz_pos: 125.0, kz_neg: 8.6 }, 0.2).unwrap();
//! let m = law.moment(-0.1, 0.0);
//! assert!((m.moment_nm - 0.86).abs() < 1e-12);
//! ```

use crate::effects::Effects;
use crate::error::{Error, Result};
use crate::real::Real;
pub use crate::stiffness::JointMoment;
use crate::stiffness::Stiffness;

/// The complete constraint law of a joint: stiffness plus linear damping,
/// plus the optional terms of [`crate::effects`] (all off by default).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "T: Real + serde::Serialize",
        deserialize = "T: Real + serde::Deserialize<'de>"
    ))
)]
pub struct JointLaw<T> {
    /// Angular stiffness.
    pub stiffness: Stiffness<T>,
    /// Linear angular damping `cz`, N·m·s/rad.
    pub damping: T,
    /// Optional effects (joint friction, non-linear damping, …); none by
    /// default, which is the paper's law.
    pub effects: Effects<T>,
}

impl<T: Real> JointLaw<T> {
    /// Validated joint law.
    pub fn new(stiffness: Stiffness<T>, damping_nms_per_rad: T) -> Result<Self> {
        let law = JointLaw {
            stiffness,
            damping: damping_nms_per_rad,
            effects: Effects::none(),
        };
        law.validate()?;
        Ok(law)
    }

    /// Check all parameters.
    pub fn validate(&self) -> Result<()> {
        self.stiffness.validate()?;
        if !self.damping.is_finite() || self.damping < T::ZERO {
            return Err(Error::InvalidParameter {
                field: "damping.cz",
                reason: "must be finite and not negative",
            });
        }
        self.effects.validate()
    }

    /// Moment at angle ζ (rad) and rate ζ̇ (rad/s).
    #[inline]
    pub fn moment(&self, zeta: T, zeta_rate: T) -> JointMoment<T> {
        let (f, k) = self.stiffness.eval(zeta);
        let m = JointMoment {
            moment_nm: -f - self.damping * zeta_rate,
            stiffness: k,
            damping: self.damping,
        };
        if self.effects.any_joint_term() {
            self.effects.apply(zeta, zeta_rate, m)
        } else {
            m
        }
    }

    /// Power the law's rate-dependent part dissipates at angle ζ and rate
    /// ζ̇, W: `−(M(ζ, ζ̇) − M(ζ, 0))·ζ̇` (the elastic part stores energy and
    /// gives it back; this is what bending the belt costs).
    ///
    /// ```
    /// use trackbelt::joint::JointLaw;
    /// use trackbelt::stiffness::Stiffness;
    /// let law = JointLaw::<f64>::new(Stiffness::Constant { kz: 8.6 }, 0.45).unwrap();
    /// assert!((law.damping_power_w(-0.3, 2.0) - 0.45 * 4.0).abs() < 1e-12);
    /// ```
    #[inline]
    pub fn damping_power_w(&self, zeta: T, zeta_rate: T) -> T {
        let d = self.moment(zeta, zeta_rate).moment_nm - self.moment(zeta, T::ZERO).moment_nm;
        -(d * zeta_rate)
    }

    /// Energy the law's elastic part stores at angle ζ, J: `−∫₀^ζ M(s, 0) ds`
    /// (the stiffness, the `amplitude_stiffness` term, both scaled by
    /// `thermal_softening`; friction and damping store nothing).
    ///
    /// ```
    /// use trackbelt::joint::JointLaw;
    /// use trackbelt::stiffness::Stiffness;
    /// let law = JointLaw::<f64>::new(Stiffness::Constant { kz: 8.6 }, 0.45).unwrap();
    /// assert!((law.elastic_energy_j(-0.2) - 0.5 * 8.6 * 0.04).abs() < 1e-12);
    /// ```
    pub fn elastic_energy_j(&self, zeta: T) -> T {
        let mut e = self.stiffness.energy_j(zeta);
        if let Some(k3) = self.effects.amplitude_stiffness {
            let z2 = zeta * zeta;
            e += T::from_f64(0.25) * k3 * z2 * z2;
        }
        if let Some(th) = &self.effects.thermal_softening {
            e *= th.factor();
        }
        e
    }

    /// Convert to another number type.
    pub fn cast<U: Real>(&self) -> JointLaw<U> {
        JointLaw {
            stiffness: self.stiffness.cast(),
            damping: U::from_f64(self.damping.to_f64()),
            effects: self.effects.cast(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn law_rejects_negative_damping() {
        assert!(JointLaw::new(Stiffness::Constant { kz: 1.0 }, -1.0).is_err());
        assert!(JointLaw::new(Stiffness::Constant { kz: f64::NAN }, 1.0).is_err());
    }
}
