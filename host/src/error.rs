//! The host library's error type.
//!
//! Every fallible function of the library returns [`Error`]; its `Display`
//! text is the message the `trackbelt` command prints after `error: `.

use std::path::PathBuf;

/// Why a host operation failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{action} {}: {source}", path.display())]
    Io {
        /// What was being done, e.g. `"cannot read params file"`.
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A params file is not valid TOML or does not describe a joint law.
    #[error("params file {}: {message}", path.display())]
    ParamsFile {
        /// The params file.
        path: PathBuf,
        /// 1-based line of the problem, when the TOML parser names one.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A params document (already parsed) lacks a value or names an
    /// unknown method or variant.
    #[error("{0}")]
    Params(String),
    /// A dataset could not be loaded or written.
    #[cfg(feature = "dataset")]
    #[error(transparent)]
    Dataset(#[from] crate::dataset::DatasetError),
    /// The truth generator could not write a dataset.
    #[cfg(feature = "validate")]
    #[error(transparent)]
    Truth(#[from] trackbelt_truth::Error),
    /// The model refused its parameters or a simulation diverged.
    #[error(transparent)]
    Model(#[from] trackbelt::Error),
    /// The dataset holds no figure to calibrate against.
    #[error(
        "{}: no static or dynamic figures (hs_mm, ws_mm, hd_mm, wd_mm, \
         period_s, log_decrement, or a dynamic series of at least 3 s) to \
         calibrate against",
        manifest.display()
    )]
    NoTargets {
        /// The dataset's manifest.
        manifest: PathBuf,
    },
    /// The fit's start point does not simulate.
    #[error("the start law does not simulate (diverged); pass another --start")]
    StartDiverged,
    /// A start law is not of the calibrated parametrisation.
    #[error("{0}")]
    StartLaw(String),
    /// A series is too short to diagnose.
    #[error("series {series}: {samples} samples; the diagnosis needs at least {needed}")]
    SeriesTooShort {
        /// The series' label.
        series: String,
        /// Samples it has.
        samples: usize,
        /// What the diagnosis needs (with the reason).
        needed: &'static str,
    },
    /// The model does not move along a scroll series' speed.
    #[error("series {series}: the model torque is zero throughout (no motion?)")]
    NoMotion {
        /// The series' label.
        series: String,
    },
    /// A rig run left the model's range of validity: the check that failed
    /// and the value it found (see [`crate::rig::Validity`]).
    #[error("rig run invalid: {check} = {value:.6e} ({limit})")]
    RigInvalid {
        /// The check, e.g. `"belt slip"`.
        check: &'static str,
        /// The value it found.
        value: f64,
        /// The valid range, in words.
        limit: String,
    },
    /// A bench simulation (static or dynamic test) left the model's range
    /// of validity: the check that failed and the value it found (see
    /// [`crate::validity`]).
    #[error("simulation invalid: {check} = {value:.6e} ({limit})")]
    SimInvalid {
        /// The check, e.g. `"energy balance (dynamic test)"`.
        check: &'static str,
        /// The value it found.
        value: f64,
        /// The valid range, in words.
        limit: String,
    },
    /// A params file's running gear is not the two-wheel rig: it needs the
    /// running-gear simulation (`rig` runs the two-wheel rig only).
    #[error(
        "{}: this running gear ({wheels} wheels) needs the running-gear simulation; `rig` \
         runs the two-wheel rig only (drive and idler on one horizontal line, the idler ahead, \
         a force tensioner, no ground)",
        path.display()
    )]
    NeedsGearSimulation {
        /// The params file.
        path: PathBuf,
        /// Its number of wheels.
        wheels: usize,
    },
    /// A simulation loop hit its step budget.
    #[error("{0}: step budget exhausted")]
    StepBudget(&'static str),
    /// An argument is out of its domain (the message names it).
    #[error("{0}")]
    InvalidArgument(String),
    /// A worker thread failed.
    #[error("{0}")]
    Thread(&'static str),
    /// An error with what was being done when it happened.
    #[error("{context}: {source}")]
    Context {
        /// What was being done, e.g. `"rig, method I"`.
        context: String,
        /// The error.
        #[source]
        source: Box<Error>,
    },
}

/// `Result` with the host [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// `self` with `context` in front of its message.
    pub fn context(self, context: impl Into<String>) -> Error {
        Error::Context {
            context: context.into(),
            source: Box::new(self),
        }
    }
}

/// Adds context to the error of a `Result`.
pub trait ResultExt<T> {
    /// On error, put `context()` in front of its message.
    fn context_with<C: Into<String>>(self, context: impl FnOnce() -> C) -> Result<T>;
}

impl<T, E: Into<Error>> ResultExt<T> for std::result::Result<T, E> {
    fn context_with<C: Into<String>>(self, context: impl FnOnce() -> C) -> Result<T> {
        self.map_err(|e| e.into().context(context()))
    }
}

/// 1-based line of a byte offset in `text`.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()
        .iter()
        .take(offset)
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}
