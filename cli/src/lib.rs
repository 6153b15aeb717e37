//! Host-side tools for trackbelt.

pub mod dataset;
