//! The trackbelt firmware example: the onboard bending-torque estimator in
//! a small embassy motor-control loop, for QEMU's Cortex-M boards.
//!
//! Four tasks:
//!
//! * the **drive** ([`app::drive_speed_source`]): the wheel speed, one
//!   sample per millisecond, from [`profile`];
//! * the **estimator** ([`app::estimator_loop`], 1 kHz embassy-time
//!   ticker): one update per sample, checked against the host's reference
//!   values computed at build time;
//! * the **belt-health monitor** ([`monitor_task::monitor_loop`], 1 kHz):
//!   fed a simulated measured torque with a wear ramp, logs the health
//!   index and checks its own alarm time;
//! * **telemetry** ([`app::telemetry`]): logs speed and torque with defmt,
//!   and on the last sample the verdict, then exits QEMU through
//!   semihosting with 0 (pass) or 1 (fail).
//!
//! Each board is one binary in `src/bin/` that picks the number type and
//! the core clock. A second example, `gear-mps2-an386` and
//! `gear-lm3s6965evb` (feature `gear`, module `gear`), runs a four-wheel
//! running gear's table with a belt temperature input (estimator and
//! telemetry only). The estimator's table is generated at build time from a
//! params TOML file ([`params`]).
#![no_std]
#![deny(missing_docs)]

pub mod app;
pub mod cost;
pub mod estimator;
pub mod executor;
pub mod exit;
#[cfg(feature = "gear")]
pub mod gear;
pub mod monitor_task;
pub mod number;
pub mod params;
pub mod profile;
pub mod time_driver;

/// What the application needs to know about the board it runs on.
#[derive(Clone, Copy, Debug)]
pub struct Board {
    /// Board (QEMU machine) name.
    pub name: &'static str,
    /// Core name, for the log.
    pub core: &'static str,
    /// Core clock feeding SysTick, Hz.
    pub core_clock_hz: u32,
}
