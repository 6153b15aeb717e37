//! Host library for trackbelt (`std`): the measured-data format (DATA.md),
//! params files, the method III calibration, the measured-data diagnosis,
//! synthetic datasets, the paper's tables and the estimator tables the
//! firmware is built from. No terminal or plotting code: the `trackbelt`
//! binary (crate `trackbelt-cli`) is a thin layer over this library.
//!
//! Errors are typed ([`Error`]); long jobs report progress through
//! [`progress::Progress`].
//!
//! Cargo features (all on by default): `calibrate`, `diagnose`, `paper`,
//! `validate` (the diagnosis scored on the independent truth generator's
//! datasets, [`validate`]),
//! and the parts they pull in: `dataset` (the data format, `csv`),
//! `parallel` (`rayon` worker threads), `atomic` (atomic file output,
//! `tempfile`). With `default-features = false` the library holds only what
//! a firmware build script needs: params files, the model set-up and the
//! estimator table generation ([`firmware`]).
//!
//! Host code that loads a params file and builds the onboard estimator's
//! table for it, without the CLI crate (the README shows the same lines):
//!
//! ```
//! use trackbelt::estimator::Estimator;
//! use trackbelt_host::firmware::estimator_table;
//! use trackbelt_host::params_file::ParamsFile;
//!
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/E56.toml");
//! let (file, law) = ParamsFile::load(&path)?; // a typed error names the file and line
//! assert_eq!(file.method()?.name(), "III");
//! assert!(law.damping > 0.0);
//! let ft = estimator_table(&path)?; // built from the link chain on the paper's rig, ~1–2 s
//! let mut est = Estimator::new(&ft.table); // the table is a value (flash on a MCU); the state is 24–48 B
//! let out = est.update(5.0, 1e-3); // drive speed rad/s, tick s
//! assert!(out.status.is_ok() && out.torque_nm > 0.0);
//! # Ok::<(), trackbelt_host::Error>(())
//! ```
#![deny(missing_docs)]

pub mod error;
pub mod figures;
pub mod firmware;
pub mod gear;
pub mod params_file;
pub mod progress;
pub mod rig;
pub mod select;
pub mod sim;
pub mod validity;

#[cfg(feature = "atomic")]
pub mod atomic;
#[cfg(feature = "calibrate")]
pub mod calibrate;
#[cfg(feature = "diagnose")]
pub mod catalogue;
#[cfg(feature = "dataset")]
pub mod dataset;
#[cfg(feature = "diagnose")]
pub mod diagnose;
#[cfg(feature = "diagnose")]
pub mod diagnose_dynamic;
#[cfg(feature = "diagnose")]
pub mod diagnose_scroll;
#[cfg(feature = "diagnose")]
pub mod evidence;
#[cfg(any(feature = "calibrate", feature = "diagnose"))]
pub mod fit;
#[cfg(feature = "diagnose")]
pub mod forward;
#[cfg(feature = "diagnose")]
pub mod monitor;
#[cfg(feature = "paper")]
pub mod paper;
#[cfg(feature = "parallel")]
pub mod parallel;
#[cfg(any(feature = "calibrate", feature = "diagnose"))]
pub mod peaks;
#[cfg(feature = "diagnose")]
pub mod synth;
#[cfg(feature = "validate")]
pub mod validate;
#[cfg(feature = "diagnose")]
pub mod verdict;

pub use error::{Error, Result};
pub use progress::{NoProgress, Progress};
