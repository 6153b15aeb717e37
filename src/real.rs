//! The number type the model is written against.
//!
//! The link-chain model, the integrator and the estimator are written once,
//! generic over [`Real`]. Three implementations ship:
//!
//! * `f64` — the **reference build**: full precision, `libm` functions.
//! * `f32` — the **embedded build** for cores with an FPU (Cortex-M4F),
//!   `libm`; with the `micromath` feature, micromath's fast approximations
//!   of `sqrt` and `sin_cos` instead.
//! * `Fx` (feature `fixed`) — signed 32.32 fixed point from the `fixed`
//!   crate, saturating, with CORDIC trigonometry (the `cordic` crate), for
//!   cores without an FPU.
//!
//! ```
//! use trackbelt::real::Real;
//! let (s, c) = 0.5f32.sin_cos();
//! assert!((s * s + c * c - 1.0).abs() < 1e-3);
//! # #[cfg(feature = "fixed")]
//! # {
//! use trackbelt::real::Fx;
//! let x = Fx::from_f64(2.25);
//! assert!((x.sqrt().to_f64() - 1.5).abs() < 1e-8);
//! # }
//! ```

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// Arithmetic the model needs from its number type.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
{
    /// Zero.
    const ZERO: Self;
    /// One.
    const ONE: Self;
    /// Short name used in reports ("f64", "f32", "I32F32").
    const NAME: &'static str;
    /// Relative precision of a value of order one (machine epsilon, or the
    /// resolution for fixed point).
    fn epsilon() -> Self;
    /// Conversion from `f64` (rounding; saturating for fixed point).
    fn from_f64(x: f64) -> Self;
    /// Conversion to `f64`.
    fn to_f64(self) -> f64;
    /// Square root; zero for negative input.
    fn sqrt(self) -> Self;
    /// Sine and cosine.
    fn sin_cos(self) -> (Self, Self);
    /// Absolute value.
    fn abs(self) -> Self;
    /// `false` for NaN, infinities and saturated fixed-point values.
    fn is_finite(self) -> bool;

    /// Conversion from a small integer count.
    #[inline]
    fn from_usize(n: usize) -> Self {
        Self::from_f64(n as f64)
    }
    /// The larger of two values.
    #[inline]
    fn max(self, other: Self) -> Self {
        if self >= other {
            self
        } else {
            other
        }
    }
    /// The smaller of two values.
    #[inline]
    fn min(self, other: Self) -> Self {
        if self <= other {
            self
        } else {
            other
        }
    }
    /// Clamp into `[lo, hi]`.
    #[inline]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        self.max(lo).min(hi)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const NAME: &'static str = "f64";
    #[inline]
    fn epsilon() -> Self {
        f64::EPSILON
    }
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn sqrt(self) -> Self {
        if self > 0.0 {
            libm::sqrt(self)
        } else {
            0.0
        }
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        libm::sincos(self)
    }
    #[inline]
    fn abs(self) -> Self {
        libm::fabs(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

// Calls micromath's functions by path: `use micromath::F32Ext` method
// syntax would silently resolve to std's exact methods where std is linked
// (host tests), measuring the wrong thing.
impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const NAME: &'static str = "f32";
    #[inline]
    fn epsilon() -> Self {
        f32::EPSILON
    }
    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline]
    fn sqrt(self) -> Self {
        if self > 0.0 {
            #[cfg(not(feature = "micromath"))]
            return libm::sqrtf(self);
            #[cfg(feature = "micromath")]
            return micromath::F32(self).sqrt().0;
        } else {
            0.0
        }
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        #[cfg(not(feature = "micromath"))]
        return libm::sincosf(self);
        #[cfg(feature = "micromath")]
        {
            let (s, c) = micromath::F32(self).sin_cos();
            (s.0, c.0)
        }
    }
    #[inline]
    fn abs(self) -> Self {
        #[cfg(not(feature = "micromath"))]
        return libm::fabsf(self);
        #[cfg(feature = "micromath")]
        return micromath::F32(self).abs().0;
    }
    #[inline]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

#[cfg(feature = "fixed")]
pub use self::fx::{Fx, FxRepr};

#[cfg(feature = "fixed")]
mod fx {
    use super::*;

    /// The fixed-point representation behind [`Fx`]: 32 integer and 32
    /// fractional bits (range ±2.1e9, resolution 2.3e-10).
    pub type FxRepr = fixed::types::I32F32;

    /// Saturating signed 32.32 fixed-point number.
    ///
    /// Every operation saturates instead of wrapping or panicking; a saturated
    /// value reports `is_finite() == false`, which the model turns into a typed
    /// error. Division by zero saturates towards the sign of the numerator.
    #[derive(Clone, Copy, Default, PartialEq, PartialOrd)]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(transparent))]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    pub struct Fx(pub FxRepr);

    impl Debug for Fx {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            write!(f, "{}", self.0)
        }
    }

    impl Fx {
        /// Raw bits (for bit-exact comparisons between builds).
        #[inline]
        pub fn to_bits(self) -> i64 {
            self.0.to_bits()
        }
    }

    impl Add for Fx {
        type Output = Fx;
        #[inline]
        fn add(self, o: Fx) -> Fx {
            Fx(self.0.saturating_add(o.0))
        }
    }
    impl Sub for Fx {
        type Output = Fx;
        #[inline]
        fn sub(self, o: Fx) -> Fx {
            Fx(self.0.saturating_sub(o.0))
        }
    }
    impl Mul for Fx {
        type Output = Fx;
        #[inline]
        fn mul(self, o: Fx) -> Fx {
            Fx(self.0.saturating_mul(o.0))
        }
    }
    impl Div for Fx {
        type Output = Fx;
        #[inline]
        fn div(self, o: Fx) -> Fx {
            match self.0.checked_div(o.0) {
                Some(q) => Fx(q),
                None => {
                    let neg = (self.0 < 0) != (o.0 < 0);
                    Fx(if neg { FxRepr::MIN } else { FxRepr::MAX })
                }
            }
        }
    }
    impl Neg for Fx {
        type Output = Fx;
        #[inline]
        fn neg(self) -> Fx {
            Fx(self.0.saturating_neg())
        }
    }
    impl AddAssign for Fx {
        #[inline]
        fn add_assign(&mut self, o: Fx) {
            *self = *self + o;
        }
    }
    impl SubAssign for Fx {
        #[inline]
        fn sub_assign(&mut self, o: Fx) {
            *self = *self - o;
        }
    }
    impl MulAssign for Fx {
        #[inline]
        fn mul_assign(&mut self, o: Fx) {
            *self = *self * o;
        }
    }
    impl DivAssign for Fx {
        #[inline]
        fn div_assign(&mut self, o: Fx) {
            *self = *self / o;
        }
    }

    impl Real for Fx {
        const ZERO: Self = Fx(FxRepr::ZERO);
        const ONE: Self = Fx(FxRepr::ONE);
        const NAME: &'static str = "I32F32";
        #[inline]
        fn epsilon() -> Self {
            Fx(FxRepr::DELTA)
        }
        #[inline]
        fn from_f64(x: f64) -> Self {
            if x.is_nan() {
                return Fx(FxRepr::MAX);
            }
            Fx(FxRepr::saturating_from_num(x))
        }
        #[inline]
        fn to_f64(self) -> f64 {
            self.0.to_num::<f64>()
        }
        #[inline]
        fn sqrt(self) -> Self {
            if self.0 <= 0 {
                return Self::ZERO;
            }
            Fx(self.0.checked_sqrt().unwrap_or(FxRepr::ZERO))
        }
        fn sin_cos(self) -> (Self, Self) {
            // Reduce into [-pi, pi] with one multiplication so CORDIC's own
            // reduction loop runs at most once.
            let two_pi = FxRepr::TAU;
            let turns = self
                .0
                .saturating_mul(FxRepr::FRAC_1_PI / 2)
                .saturating_add(FxRepr::from_bits(1 << 31))
                .floor();
            let r = self.0.saturating_sub(turns.saturating_mul(two_pi));
            let r = r.clamp(-FxRepr::PI, FxRepr::PI);
            let (s, c) = cordic::sin_cos(r);
            (Fx(s), Fx(c))
        }
        #[inline]
        fn abs(self) -> Self {
            Fx(self.0.saturating_abs())
        }
        #[inline]
        fn is_finite(self) -> bool {
            self.0 != FxRepr::MAX && self.0 != FxRepr::MIN
        }
    }
}

#[cfg(all(test, feature = "fixed"))]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_trig_matches_libm() {
        for i in -200..200 {
            let x = i as f64 * 0.1;
            let (s, c) = Fx::from_f64(x).sin_cos();
            assert!((s.to_f64() - libm::sin(x)).abs() < 1e-7, "sin({x})");
            assert!((c.to_f64() - libm::cos(x)).abs() < 1e-7, "cos({x})");
        }
    }

    #[test]
    fn fixed_point_saturates_instead_of_panicking() {
        let big = Fx::from_f64(1e9);
        assert!(!(big * big).is_finite());
        assert!(!(Fx::ONE / Fx::ZERO).is_finite());
        assert!(!Fx::from_f64(f64::NAN).is_finite());
        assert_eq!(Fx::from_f64(-4.0).sqrt(), Fx::ZERO);
    }
}
