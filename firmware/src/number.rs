//! The number types the boards run the estimator in.

use trackbelt::{Fx, Real};

/// A [`Real`] the firmware can log: raw bits for bit-exact comparison with
/// the host, and an `f32` for people.
pub trait FwReal: Real + Send + 'static {
    /// The value's bits, sign-extended to 64 (`f32::to_bits` or the 32.32
    /// fixed-point representation).
    fn bits(self) -> i64;
    /// The value as `f32`, for display.
    fn to_f32(self) -> f32;
}

impl FwReal for f32 {
    fn bits(self) -> i64 {
        self.to_bits() as i64
    }
    fn to_f32(self) -> f32 {
        self
    }
}

impl FwReal for Fx {
    fn bits(self) -> i64 {
        self.to_bits()
    }
    fn to_f32(self) -> f32 {
        // Via the fixed-point value's own conversion: no f64 on a core
        // without an FPU.
        self.0.to_num::<f32>()
    }
}
