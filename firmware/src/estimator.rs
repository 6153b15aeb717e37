//! The estimator the firmware runs: the library's, unchanged.
pub use trackbelt::estimator::{Estimate, Estimator, EstimatorState, EstimatorTable, Status};
