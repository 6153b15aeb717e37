//! # trackbelt
//!
//! A rubber track belt modelled as a closed chain of rigid links (after
//! Szpaczyńska, Łopatka & Krogul, *Susceptibility Modeling of a Rubber Track
//! for Lightweight Mobile Robots*), written once, generic over the number
//! type, `#![no_std]`, without heap and without panics:
//!
//! * the **reference build** (`f64`) reproduces the paper's bench tests;
//! * the **embedded build** (`f32`, or 32.32 fixed point) runs the same code
//!   on a Cortex-M.
//!
//! Where things live, lowest layer first (a module uses only those above
//! it):
//!
//! | module | what it holds |
//! | --- | --- |
//! | [`real`] | the number-type trait and its `f64`, `f32`, fixed-point builds |
//! | [`error`] | the typed errors |
//! | [`linalg`] | the one linear solver: dense LU with equilibration, and its banded mode |
//! | [`figures`] | period and logarithmic decrement from a height signal |
//! | `kinematics` | coordinate layout, joint angles, joint positions and velocities (crate-internal) |
//! | [`stiffness`] | torque–angle laws: methods I, II, III |
//! | [`effects`] | the catalogue of optional joint-law terms: joint friction, non-linear damping, amplitude stiffness, thermal softening (bearing friction sits on the rig) |
//! | [`memory`] | the effects' laws with a memory (Dahl friction, Payne softening) and the per-joint state the chain keeps for them |
//! | [`joint`] | the joint law: stiffness + damping + effects |
//! | [`params`] | belt, floor, contacts, the paper's parameters and figures |
//! | `contact` | floor, self-contact and wheel contact laws (crate-internal) |
//! | [`integrator`] | BDF2 time stepping, the static solver, their settings, the scenarios' stepping loop |
//! | [`chain`] | the pin chain: state and equations of motion |
//! | [`bushing`] | the paper's literal bushing joint (reference-build option) |
//! | [`mod@bench`] | the static and dynamic bench tests and their figures |
//! | [`rig`] | the bending-resistance rig: belt round a drive wheel and a tensioned idler |
//! | [`gear`] | a robot's running gear (wheels, tensioner, ground): plain data |
//! | [`estimator`] | the onboard bending-torque estimator (table built from the chain) |
//! | [`monitor`] | the onboard belt-health monitor: loss scale and bearing friction from the measured drive torque (RLS) |
//!
//! ```
//! use trackbelt::{bench, params::{Method, Model, Variant}, ReferenceChain, Settings};
//! let model = Model::paper(Variant::E38, Method::II)?;
//! let mut chain = ReferenceChain::new(model, Settings::default())?;
//! let fig = bench::static_test(&mut chain)?;
//! assert!((fig.hs_mm - 322.0).abs() < 0.06 * 322.0);
//! # Ok::<(), trackbelt::Error>(())
//! ```
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(missing_docs)]
#![forbid(unsafe_code)]
// Numerical kernels index several parallel arrays by the same counter.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod bushing;
pub mod chain;
mod contact;
pub mod effects;
pub mod error;
pub mod estimator;
pub mod figures;
pub mod gear;
pub mod integrator;
pub mod joint;
mod kinematics;
pub mod linalg;
pub mod memory;
pub mod monitor;
pub mod params;
pub mod real;
pub mod rig;
#[cfg(feature = "serde")]
mod serde_impls;
pub mod stiffness;

pub use bushing::{Bushing, BushingChain, ReferenceBushingChain};
pub use chain::{Chain, ReferenceChain};
pub use error::{Error, Result};
pub use integrator::{Settings, Stats};
#[cfg(feature = "fixed")]
pub use real::Fx;
pub use real::Real;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
