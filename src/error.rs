//! Typed errors. The library never panics: every failure is one of these.

use core::fmt;

/// Everything that can go wrong in the library, with enough detail for a
/// user to act on it.
///
/// ```
/// use trackbelt::Error;
/// let e = Error::InvalidParameter { field: "belt.mass_kg", reason: "must be positive and finite" };
/// assert_eq!(format!("{e}"), "invalid parameter `belt.mass_kg`: must be positive and finite");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// A parameter is out of its valid range, not finite, or inconsistent.
    InvalidParameter {
        /// Dotted name of the offending field.
        field: &'static str,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A fixed capacity chosen at compile time is too small.
    Capacity {
        /// What overflowed.
        what: &'static str,
        /// How many were requested.
        requested: usize,
        /// How many fit.
        capacity: usize,
    },
    /// A run-time input (speed, tick, state) is NaN or infinite.
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// The simulation diverged: the state became non-finite or the implicit
    /// solver failed even at the smallest allowed step.
    Diverged {
        /// Simulated time at which it happened, in s.
        time_s: f64,
        /// What gave up.
        reason: &'static str,
    },
    /// An iterative solve did not converge within its iteration budget.
    NotConverged {
        /// Which solve.
        what: &'static str,
        /// Iterations spent.
        iterations: usize,
    },
    /// A linear system was singular (a degenerate configuration).
    Singular,
    /// A running gear's fixed idler centre does not suit the belt's length:
    /// the belt cannot reach the wheels, or it would hang slack.
    FixedCentreBelt {
        /// How much longer the path round the wheels is than the belt, mm
        /// (positive: the belt is too short; negative: too long).
        short_by_mm: f64,
        /// The idler's given centre distance from the drive's, mm.
        centre_distance_mm: f64,
        /// The centre distance at which the belt just fits, mm.
        fits_at_mm: f64,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidParameter { field, reason } => {
                write!(f, "invalid parameter `{field}`: {reason}")
            }
            Error::Capacity {
                what,
                requested,
                capacity,
            } => write!(
                f,
                "capacity exceeded for {what}: {requested} requested, {capacity} fit (raise the const-generic capacity)"
            ),
            Error::NonFinite { what } => write!(f, "non-finite value in {what}"),
            Error::Diverged { time_s, reason } => {
                write!(f, "simulation diverged at t = {time_s:.4} s: {reason}")
            }
            Error::NotConverged { what, iterations } => {
                write!(f, "{what} did not converge in {iterations} iterations")
            }
            Error::Singular => write!(f, "singular linear system (degenerate configuration)"),
            Error::FixedCentreBelt {
                short_by_mm,
                centre_distance_mm,
                fits_at_mm,
            } => {
                let moved = (centre_distance_mm - fits_at_mm).abs();
                if *short_by_mm > 0.0 {
                    write!(
                        f,
                        "the belt is {short_by_mm:.1} mm too short for the fixed idler centre \
                         {centre_distance_mm:.1} mm from the drive's: it cannot reach the wheels \
                         (it is tight round them with the idler at {fits_at_mm:.1} mm; beyond \
                         that only the contacts' compression takes up the difference, at most \
                         {:.1} mm of path). Move the idler {moved:.1} mm towards the drive, \
                         lengthen the belt, or give the tensioner a force (`force_n`)",
                        crate::rig::FIXED_CENTRE_SHORT_TOL_MM
                    )
                } else {
                    write!(
                        f,
                        "the belt is {:.1} mm too long for the fixed idler centre \
                         {centre_distance_mm:.1} mm from the drive's: it would hang slack \
                         (pulling on the idler with less than its own weight). Move the idler \
                         away from the drive (it is tight round the wheels at {fits_at_mm:.1} mm, \
                         {moved:.1} mm further out; the belt's bending stiffness and sag give a \
                         pretension a few mm short of that), shorten the belt, or give the \
                         tensioner a force (`force_n`)",
                        -short_by_mm
                    )
                }
            }
        }
    }
}

impl core::error::Error for Error {}

/// Result alias used throughout the crate.
pub type Result<T> = core::result::Result<T, Error>;

/// An [`Error::InvalidParameter`] naming `field`.
pub(crate) fn invalid(field: &'static str, reason: &'static str) -> Error {
    Error::InvalidParameter { field, reason }
}
