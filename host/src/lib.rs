//! Host library for trackbelt (`std`): the measured-data format (DATA.md),
//! params files, the method III calibration, the measured-data diagnosis,
//! synthetic datasets, the paper's tables and the estimator tables the
//! firmware is built from. No terminal or plotting code: the `trackbelt`
//! binary (crate `trackbelt-cli`) is a thin layer over this library.
#![deny(missing_docs)]

pub mod calibrate;
pub mod dataset;
pub mod diagnose;
pub mod diagnose_scroll;
pub mod firmware;
pub mod fit;
pub mod paper;
pub mod params_file;
pub mod rig;
pub mod sim;
pub mod synth;
