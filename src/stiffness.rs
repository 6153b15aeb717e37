//! The torque–angle laws of a joint: stiffness by methods I, II and III.
//! The complete law of a joint (stiffness, damping and the optional
//! effects) is [`JointLaw`](crate::joint::JointLaw).
//!
//! The joint angle ζ is the rotation of a link against its predecessor, zero
//! when the belt is straight, negative when it bends the way it wraps
//! (around a wheel, the sides of the ring) and positive when it back-bends.
//! The restoring moment is
//!
//! `Mz = −f(ζ) − cz·ζ̇`
//!
//! with `f(ζ) = kz·ζ` (method I), `kz1·ζ` for ζ > 0 and `kz2·ζ` for ζ < 0
//! (method II), or a piecewise-linear torque–angle table (method III).
//!
//! ```
//! use trackbelt::stiffness::{Stiffness, TorqueTable};
//! // Method II, E38, paper parameters (converted to N·m/rad).
//! let k = Stiffness::<f64>::Bivalent { kz_pos: 125.0, kz_neg: 8.6 };
//! let (f, kt) = k.eval(-0.1);
//! assert!((f + 0.86).abs() < 1e-12 && kt == 8.6);
//! // Method III: a table through (0, 0).
//! let t = TorqueTable::<f64>::new(&[-0.6, -0.2, 0.0, 0.1], &[-6.0, -1.0, 0.0, 2.0]).unwrap();
//! assert_eq!(t.eval(-0.1).0, -0.5);
//! ```

use crate::error::{Error, Result};
use crate::real::Real;
use heapless::Vec;

/// Largest number of breakpoints a torque–angle table can hold.
pub const TABLE_CAPACITY: usize = 16;

/// Piecewise-linear torque–angle characteristic `f(ζ)` (method III).
///
/// Breakpoints are strictly increasing in angle, the torque is
/// non-decreasing (a positive stiffness everywhere), and the curve passes
/// through (0, 0): a breakpoint at ζ = 0 is inserted when missing. Outside
/// the table the end segments are extended linearly.
#[derive(Debug, Clone, PartialEq)]
pub struct TorqueTable<T> {
    angle_rad: Vec<T, TABLE_CAPACITY>,
    torque_nm: Vec<T, TABLE_CAPACITY>,
    /// Slope of each segment (to the next breakpoint; the last repeats the
    /// one before), N·m/rad: precomputed so `eval` does not divide.
    slope: Vec<T, TABLE_CAPACITY>,
}

impl<T: Real> TorqueTable<T> {
    /// Build a table from breakpoint angles (rad) and torques (N·m).
    pub fn new(angle_rad: &[T], torque_nm: &[T]) -> Result<Self> {
        if angle_rad.len() != torque_nm.len() {
            return Err(Error::InvalidParameter {
                field: "table",
                reason: "angle and torque lists differ in length",
            });
        }
        if angle_rad.is_empty() {
            return Err(Error::InvalidParameter {
                field: "table",
                reason: "empty table",
            });
        }
        let mut t = TorqueTable {
            angle_rad: Vec::new(),
            torque_nm: Vec::new(),
            slope: Vec::new(),
        };
        let mut has_zero = false;
        for (&a, &m) in angle_rad.iter().zip(torque_nm) {
            if !a.is_finite() || !m.is_finite() {
                return Err(Error::InvalidParameter {
                    field: "table",
                    reason: "non-finite breakpoint",
                });
            }
            if a == T::ZERO {
                if m != T::ZERO {
                    return Err(Error::InvalidParameter {
                        field: "table",
                        reason: "torque at zero angle must be zero",
                    });
                }
                has_zero = true;
            }
        }
        let capacity_error = Error::Capacity {
            what: "torque table breakpoints",
            requested: angle_rad.len() + 1,
            capacity: TABLE_CAPACITY,
        };
        let mut zero_pending = !has_zero;
        for (&a, &m) in angle_rad.iter().zip(torque_nm) {
            if zero_pending && a > T::ZERO {
                t.push(T::ZERO, T::ZERO).map_err(|_| capacity_error)?;
                zero_pending = false;
            }
            t.push(a, m).map_err(|_| capacity_error)?;
        }
        if zero_pending {
            t.push(T::ZERO, T::ZERO).map_err(|_| capacity_error)?;
        }
        t.validate()?;
        t.fill_slopes();
        if t.slope.iter().any(|k| !k.is_finite())
            || t.angle_rad.iter().any(|&a| !t.eval(a).0.is_finite())
        {
            return Err(Error::InvalidParameter {
                field: "table",
                reason: "a segment's slope overflows (breakpoints too close for their torques)",
            });
        }
        Ok(t)
    }

    /// Segment slopes from the breakpoints (after validation: the angles
    /// are strictly increasing, so no division by zero).
    fn fill_slopes(&mut self) {
        let n = self.angle_rad.len();
        self.slope.clear();
        for i in 0..n {
            let (lo, hi) = if i + 1 < n { (i, i + 1) } else { (i - 1, i) };
            let k = (self.torque_nm[hi] - self.torque_nm[lo])
                / (self.angle_rad[hi] - self.angle_rad[lo]);
            // Same length as the breakpoints, which fit: cannot fail.
            let _ = self.slope.push(k);
        }
    }

    fn push(&mut self, a: T, m: T) -> core::result::Result<(), ()> {
        self.angle_rad.push(a).map_err(|_| ())?;
        self.torque_nm.push(m).map_err(|_| ())
    }

    fn validate(&self) -> Result<()> {
        let n = self.angle_rad.len();
        if n < 2 {
            return Err(Error::InvalidParameter {
                field: "table",
                reason: "needs at least one breakpoint besides (0, 0)",
            });
        }
        for i in 1..n {
            if self.angle_rad[i] <= self.angle_rad[i - 1] {
                return Err(Error::InvalidParameter {
                    field: "table",
                    reason: "breakpoint angles must be strictly increasing",
                });
            }
            if self.torque_nm[i] <= self.torque_nm[i - 1] {
                return Err(Error::InvalidParameter {
                    field: "table",
                    reason: "torque must increase with angle (positive stiffness)",
                });
            }
        }
        Ok(())
    }

    /// Number of breakpoints (including (0, 0)).
    pub fn len(&self) -> usize {
        self.angle_rad.len()
    }

    /// Always `false`: a valid table has at least two breakpoints.
    pub fn is_empty(&self) -> bool {
        self.angle_rad.is_empty()
    }

    /// Breakpoint angles, rad.
    pub fn angles_rad(&self) -> &[T] {
        &self.angle_rad
    }

    /// Breakpoint torques, N·m.
    pub fn torques_nm(&self) -> &[T] {
        &self.torque_nm
    }

    /// `(f(ζ), f'(ζ))`: torque and local stiffness at angle ζ.
    #[inline]
    pub fn eval(&self, zeta: T) -> (T, T) {
        let a = &self.angle_rad;
        let m = &self.torque_nm;
        let n = a.len();
        // Segment index i such that a[i] <= zeta < a[i+1], clamped to the ends
        // (binary search: at most log2(16) = 4 comparisons).
        let mut lo = 0usize;
        let mut hi = n - 1;
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if zeta < a[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let slope = self.slope[lo];
        (m[lo] + slope * (zeta - a[lo]), slope)
    }

    /// Energy stored at angle ζ, J: `∫₀^ζ f(s) ds` (exact: the trapezoids
    /// between the breakpoints of a piecewise-linear law).
    pub fn energy_j(&self, zeta: T) -> T {
        let half = T::from_f64(0.5);
        let mut e = T::ZERO;
        let (mut x0, mut f0) = (T::ZERO, T::ZERO);
        // At a breakpoint the law's torque is the breakpoint's own.
        let points = self.angle_rad.iter().zip(self.torque_nm.iter());
        if zeta >= T::ZERO {
            for (&a, &f1) in points.filter(|&(&a, _)| a > T::ZERO && a < zeta) {
                e += half * (f0 + f1) * (a - x0);
                (x0, f0) = (a, f1);
            }
        } else {
            for (&a, &f1) in points.rev().filter(|&(&a, _)| a < T::ZERO && a > zeta) {
                e += half * (f0 + f1) * (a - x0);
                (x0, f0) = (a, f1);
            }
        }
        let f1 = self.eval(zeta).0;
        e + half * (f0 + f1) * (zeta - x0)
    }

    /// Convert to another number type.
    pub fn cast<U: Real>(&self) -> TorqueTable<U> {
        let mut out = TorqueTable {
            angle_rad: Vec::new(),
            torque_nm: Vec::new(),
            slope: Vec::new(),
        };
        for (&a, &m) in self.angle_rad.iter().zip(self.torque_nm.iter()) {
            // Same length as self, which fits: cannot fail.
            let _ = out.push(U::from_f64(a.to_f64()), U::from_f64(m.to_f64()));
        }
        out.fill_slopes();
        out
    }
}

/// Angular stiffness of a joint: the three methods of the paper.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "T: Real + serde::Serialize",
        deserialize = "T: Real + serde::Deserialize<'de>"
    ))
)]
pub enum Stiffness<T> {
    /// Method I: `f = kz·ζ`, N·m/rad.
    Constant {
        /// Stiffness, N·m/rad.
        kz: T,
    },
    /// Method II: `kz_pos` (paper's kz1) for back-bending ζ > 0, `kz_neg`
    /// (kz2) for ζ < 0, N·m/rad.
    Bivalent {
        /// Stiffness for ζ > 0, N·m/rad.
        kz_pos: T,
        /// Stiffness for ζ < 0, N·m/rad.
        kz_neg: T,
    },
    /// Method III: tabulated torque–angle characteristic.
    Table(TorqueTable<T>),
}

impl<T: Real> Stiffness<T> {
    /// `(f(ζ), f'(ζ))`.
    #[inline]
    pub fn eval(&self, zeta: T) -> (T, T) {
        match self {
            Stiffness::Constant { kz } => (*kz * zeta, *kz),
            Stiffness::Bivalent { kz_pos, kz_neg } => {
                if zeta > T::ZERO {
                    (*kz_pos * zeta, *kz_pos)
                } else {
                    (*kz_neg * zeta, *kz_neg)
                }
            }
            Stiffness::Table(t) => t.eval(zeta),
        }
    }

    /// Energy the stiffness stores at angle ζ, J: `∫₀^ζ f(s) ds`.
    pub fn energy_j(&self, zeta: T) -> T {
        let half = T::from_f64(0.5);
        match self {
            Stiffness::Constant { kz } => half * *kz * zeta * zeta,
            Stiffness::Bivalent { kz_pos, kz_neg } => {
                let k = if zeta > T::ZERO { *kz_pos } else { *kz_neg };
                half * k * zeta * zeta
            }
            Stiffness::Table(t) => t.energy_j(zeta),
        }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let ok = |k: T| k.is_finite() && k > T::ZERO;
        match self {
            Stiffness::Constant { kz } if !ok(*kz) => Err(Error::InvalidParameter {
                field: "stiffness.kz",
                reason: "must be positive and finite",
            }),
            Stiffness::Bivalent { kz_pos, kz_neg } if !ok(*kz_pos) || !ok(*kz_neg) => {
                Err(Error::InvalidParameter {
                    field: "stiffness.kz_pos/kz_neg",
                    reason: "must be positive and finite",
                })
            }
            Stiffness::Table(t) => t.validate(),
            _ => Ok(()),
        }
    }

    /// Convert to another number type.
    pub fn cast<U: Real>(&self) -> Stiffness<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        match self {
            Stiffness::Constant { kz } => Stiffness::Constant { kz: c(*kz) },
            Stiffness::Bivalent { kz_pos, kz_neg } => Stiffness::Bivalent {
                kz_pos: c(*kz_pos),
                kz_neg: c(*kz_neg),
            },
            Stiffness::Table(t) => Stiffness::Table(t.cast()),
        }
    }
}

/// Moment in a joint and its derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointMoment<T> {
    /// Restoring moment `Mz`, N·m.
    pub moment_nm: T,
    /// `−∂Mz/∂ζ`, N·m/rad (the tangent stiffness).
    pub stiffness: T,
    /// `−∂Mz/∂ζ̇`, N·m·s/rad (the tangent damping).
    pub damping: T,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₀^ζ f by the midpoint rule with many steps.
    fn integral(k: &Stiffness<f64>, zeta: f64) -> f64 {
        let n = 20_000;
        let h = zeta / n as f64;
        (0..n).map(|i| k.eval((i as f64 + 0.5) * h).0 * h).sum()
    }

    #[test]
    fn energy_is_the_integral_of_the_torque() {
        let t = TorqueTable::new(&[-0.5, -0.1, 0.2], &[-3.0, -0.5, 1.0]).unwrap();
        let laws = [
            Stiffness::Constant { kz: 8.6 },
            Stiffness::Bivalent {
                kz_pos: 125.0,
                kz_neg: 8.6,
            },
            Stiffness::Table(t),
        ];
        for k in &laws {
            for zeta in [-0.9, -0.5, -0.3, -0.1, 0.0, 0.05, 0.2, 0.4] {
                let e = k.energy_j(zeta);
                assert!((e - integral(k, zeta)).abs() < 1e-6, "{k:?} {zeta}: {e}");
                assert!(e >= 0.0);
            }
        }
    }

    #[test]
    fn table_inserts_origin_and_extrapolates() {
        let t = TorqueTable::new(&[-0.5, -0.1, 0.2], &[-3.0, -0.5, 1.0]).unwrap();
        assert_eq!(t.len(), 4);
        assert_eq!(t.eval(0.0).0, 0.0);
        let (f, k) = t.eval(-1.0);
        assert!((k - 6.25).abs() < 1e-12);
        assert!((f - (-3.0 - 6.25 * 0.5)).abs() < 1e-12);
        assert!((t.eval(0.4).0 - 2.0).abs() < 1e-12);
    }

    #[test]
    fn table_rejects_bad_input() {
        assert!(TorqueTable::<f64>::new(&[], &[]).is_err());
        assert!(TorqueTable::new(&[-0.1, -0.2], &[-1.0, -2.0]).is_err());
        assert!(TorqueTable::new(&[-0.2, -0.1], &[-1.0, -2.0]).is_err());
        assert!(TorqueTable::new(&[-0.2, f64::NAN], &[-1.0, -2.0]).is_err());
        assert!(TorqueTable::new(&[0.0], &[1.0]).is_err());
        let many: [f64; 20] = core::array::from_fn(|i| i as f64 + 1.0);
        assert!(matches!(
            TorqueTable::new(&many, &many),
            Err(Error::Capacity { .. })
        ));
    }
}
