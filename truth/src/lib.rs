//! # trackbelt-truth: an independent belt simulator for testing the diagnosis
//!
//! Every dataset the project tested its diagnosis on so far came from
//! `trackbelt synth`, which shares the diagnosis's own model. This crate
//! makes `DATA.md` datasets with a simulator that shares nothing with it
//! (it does not depend on `trackbelt` or `trackbelt-host`):
//!
//! - **Discretisation**: a closed chain of N point masses in maximal
//!   coordinates (N free, 26–36 by default), stiff axial springs with
//!   damping, and at every node the bending moment of a *continuum* law
//!   `M(κ)` at the node's discrete curvature κ = θ/ℓ0 (see [`chain`]), so N
//!   does not enter the law. Explicit kick–drift (symplectic Euler)
//!   integration with a fixed step chosen from the fastest axial, bending
//!   zig-zag and damping rates ([`chain::Chain::stable_step`]).
//! - **Bending law**: smooth, nonlinear and asymmetric ([`law::BendingLaw`]):
//!   a sech² near-straight term, a soft middle range, logistic hardening of a
//!   tight wrap and a stiffer back-bending side. Tuned on the Shredder belt
//!   (2450 × 160 × 8 mm, 6.4 kg, roller 1.3 kg) against Table 1 means
//!   (in brackets); with 26, 30, 36 nodes it gives Hs (read at A, which
//!   sits a few mm below the two humps of the top run) 313, 313, 316 mm
//!   (324), Ws 1059, 1062, 1069 (1062), Hd 227, 227, 228 (225),
//!   Wd 1073, 1076, 1086 (1082), T 0.77, 0.72, 0.75 s (0.74),
//!   Λ 0.76, 0.71, 0.72 (0.73). Other belts scale EI with width·thickness³ and
//!   the law's curvatures with 1/thickness; every parameter is jittered by
//!   ±20 % per dataset, and on the rig the belt is slightly non-uniform
//!   along its length (1–3 %; not in the drop test, where a non-uniform
//!   ring would slowly roll to its softest spot). Nodes sit on the neutral
//!   axis; figures are read at the outer surface.
//! - **Magnitude**: [`Scenario::magnitude`] scales every effect and
//!   disturbance (1: clearly visible, 0.35: moderate; [`draw`] draws it in
//!   0.35–1, [`draw_at`] takes it).
//! - **Rig torque**: a node chain entering a wheel makes a chordal ripple at
//!   the node-passage frequency that a continuous belt has not; the torque is
//!   averaged over one node-passage period before the logger samples it.
//! - **Contacts**: Hunt–Crossley floor with tanh-regularised friction; the
//!   roller is a rigid cylinder on the belt's segments; the rig's wheels are
//!   rigid circles with penalty contact and regularised friction, the
//!   idler on a slider pulled by the tensioner.
//! - **Effects** are written as other laws of the same physics than the
//!   diagnosis's candidates ([`law`], [`scenario::EffectKind`]); several
//!   out-of-catalogue disturbances ([`scenario::DisturbanceKind`]).
//!
//! ```no_run
//! use trackbelt_truth::{draw, generate, EffectKind, Outcome, SeriesKind};
//! let sc = draw(Outcome::Effect(EffectKind::JointFriction), SeriesKind::Dynamic, 7).unwrap();
//! let truth = generate(&sc, std::path::Path::new("/tmp/set-7")).unwrap();
//! println!("{} (noise {:.2} {})", truth.expected, truth.noise_rms, truth.noise_unit);
//! ```
#![deny(missing_docs)]

pub mod ceiling;
pub mod chain;
pub mod drop;
pub mod law;
pub mod rng;
pub mod scenario;
pub mod scroll;
mod write;

pub use scenario::{
    draw, draw_at, Belt, DisturbanceKind, EffectKind, Outcome, Scenario, SeriesKind,
};
pub use write::{drop_figures, drop_test_with_series, generate, generate_beside, generate_runs};

use std::path::PathBuf;

/// Why a dataset could not be made.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The output directory holds files already.
    #[error("{0}: directory is not empty")]
    NotEmpty(PathBuf),
    /// The outcome does not exist in that kind of series.
    #[error("outcome {outcome} does not exist in a {kind} series")]
    KindMismatch {
        /// The outcome asked for.
        outcome: String,
        /// The series kind asked for.
        kind: &'static str,
    },
    /// The simulation left its valid range.
    #[error("simulation unstable ({what}) at t = {t_s:.3} s")]
    Unstable {
        /// Which run.
        what: &'static str,
        /// When.
        t_s: f64,
    },
    /// A scenario value is out of range.
    #[error("invalid scenario: {0}")]
    Invalid(String),
}

/// Figures of the truth run (noise-free), as the simulator found them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Figures {
    /// Settled height of A (material turned by 0), mm.
    pub hs_mm: Option<f64>,
    /// Settled width, mm.
    pub ws_mm: Option<f64>,
    /// Final height of A under the roller, mm.
    pub hd_mm: Option<f64>,
    /// Final width under the roller, mm.
    pub wd_mm: Option<f64>,
    /// Period of A's oscillation, s.
    pub period_s: Option<f64>,
    /// Log decrement of the first two maxima.
    pub log_decrement: Option<f64>,
    /// Mean drive torque of the rig run, N·m.
    pub mean_torque_nm: Option<f64>,
}

/// What was put into a dataset (for scoring a diagnosis; never written
/// into the dataset).
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// The outcome.
    pub outcome: Outcome,
    /// The answer a correct diagnosis gives (`none`, an effect identifier
    /// or `unexplained`).
    pub expected: &'static str,
    /// Series kind.
    pub kind: SeriesKind,
    /// Magnitude knob of the effect or disturbance.
    pub magnitude: f64,
    /// The law or disturbance switched on, with its parameters.
    pub description: String,
    /// RMS of the white noise put into the main channel (A's height or the
    /// torque).
    pub noise_rms: f64,
    /// Its unit ("mm" or "N·m").
    pub noise_unit: &'static str,
    /// Nodes of the simulation.
    pub nodes: usize,
    /// Integration step, s.
    pub step_s: f64,
    /// Figures of the noise-free run.
    pub figures: Figures,
    /// Files written.
    pub files: Vec<PathBuf>,
}
