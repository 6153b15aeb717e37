//! Host-side tools for trackbelt: the measured-data reader, the params file,
//! running and reporting the bench tests, reproducing the paper's tables,
//! plots.
#![deny(missing_docs)]

pub mod calibrate;
pub mod dataset;
pub mod diagnose;
pub mod diagnose_report;
pub mod diagnose_scroll;
pub mod firmware;
pub mod fit;
pub mod paper;
pub mod params_file;
pub mod plot;
pub mod rig;
pub mod sim;
pub mod synth;
