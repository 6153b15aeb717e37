//! Host-side tools for trackbelt.
