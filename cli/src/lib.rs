//! Host-side tools for trackbelt: the measured-data reader, the params file,
//! running and reporting the bench tests, reproducing the paper's tables,
//! plots.
#![deny(missing_docs)]

pub mod calibrate;
pub mod dataset;
pub mod firmware;
pub mod paper;
pub mod params_file;
pub mod plot;
pub mod rig;
pub mod sim;
