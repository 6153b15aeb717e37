//! The onboard estimator: the torque the drive spends bending and unbending
//! the belt, per control tick, from the link chain.
//!
//! # Where the numbers come from
//!
//! [`EstimatorTable::from_model`] solves the **travelling belt** of the link
//! chain on the rig ([`crate::rig`]), with the method's joint law (a method
//! III table included):
//!
//! 1. The belt is laid round the wheels with one joint held on the drive
//!    wheel's rim (a sprocket tooth) and settled (the chain's statics).
//! 2. At each speed of the grid it is **marched** round through a sequence
//!    of static equilibria of the chain, `phases` per link pitch, each
//!    solved with the chain's own static solver while the held joint turns
//!    with the drive. Between two equilibria each joint's rate is its change
//!    of angle over the travel time, so the joint law's damping acts as the
//!    joints pass on and off the wheels (implicit Euler without inertia).
//! 3. The march is continued with the links' inertia — the chain's own BDF2
//!    dynamics, the held joint carried round by the drive, the wheels
//!    frictionless — and the energy the joints' damping dissipates over the
//!    last pitches gives the loss torque at that speed. (Inertia adds 0–3 %:
//!    the stiff back-bending side of method II rings as joints snap on.)
//!
//! The energy the joints store as they bend onto a wheel is returned as they
//! straighten, so in steady running only the dissipated part costs torque;
//! while the speed changes, the belt's kinetic energy (from the same run)
//! adds an inertia term. Nothing is fitted to simulator output.
//!
//! [`EstimatorTable::update`] then costs a table lookup on a uniform grid
//! (four comparisons against the table's grid speeds, one multiply-add),
//! the acceleration term (a division only when the tick length changes) and
//! no loops over links: 131 instructions per update on a Cortex-M4F (f32)
//! and 591 on a Cortex-M3 (32.32 fixed point), measured under QEMU by the
//! firmware.
//!
//! # Table and state
//!
//! As in quartiq's `idsp` (coefficients apart from state), the estimator
//! comes in two parts:
//!
//! * the **table** ([`EstimatorTable`]): the coefficients, read-only, `Copy`
//!   plain data that can be a `static` or `const` in flash (the firmware's
//!   build script writes it out as Rust source with exact bit patterns);
//! * the **state** ([`EstimatorState`]): the previous speed and tick and the
//!   last output, a few scalars in RAM
//!   (`core::mem::size_of::<EstimatorState<f32>>()` bytes).
//!
//! An update takes the table by reference: `table.update(&mut state, …)`.
//! [`Estimator`] bundles a reference to a table with a state for the common
//! case of one estimator per table.
//!
//! ```
//! use trackbelt::estimator::{BuildOptions, Estimator, EstimatorState, EstimatorTable};
//! use trackbelt::params::{Method, Model, Variant};
//! use trackbelt::rig::RigConfig;
//!
//! // Host (or build script): the table from the link chain (about a second).
//! let model = Model::<f64>::paper(Variant::E38, Method::II)?;
//! let options = BuildOptions { phases: 4, ..BuildOptions::default() };
//! let table = EstimatorTable::from_model::<48>(&model, &RigConfig::default(), &options)?;
//! // Target: f32, one update per control tick. The table would be a
//! // `static` in flash; the state lives in RAM.
//! let table32 = table.cast::<f32>();
//! let mut state = EstimatorState::new();
//! let out = table32.update(&mut state, 5.0, 1.0e-3);
//! assert!(out.status.is_ok() && out.torque_nm > 0.0);
//! // The same with the table borrowed by a bundled estimator.
//! let mut est = Estimator::new(&table32);
//! assert_eq!(est.update(5.0, 1.0e-3), out);
//! # Ok::<(), trackbelt::Error>(())
//! ```

use crate::chain::{joint_angle_in, Chain, TH, X, Y};
use crate::error::{Error, Result};
use crate::gear::RunningGear;
use crate::params::{invalid, Model};
use crate::real::Real;
use crate::rig::{rig_settings, Rig, RigConfig};

/// Points of the speed grid (0, Δω, 2Δω, …).
pub const SPEED_POINTS: usize = 16;

/// Largest number of phase positions the builder can use.
pub const MAX_PHASES: usize = 32;

/// How to build the table.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BuildOptions {
    /// Highest speed of the grid, rad/s; faster speeds are flagged.
    pub max_speed_rad_s: f64,
    /// Equilibria per link pitch in the march (resolution of the joint
    /// rates along the path; the loss converges like 1/phases).
    pub phases: usize,
    /// Link pitches the belt is marched through quasi-statically at each
    /// speed; the last one (by then periodic) is measured.
    pub march_links: usize,
    /// Refine with the links' inertia: continue the march with the chain's
    /// own dynamics (joint A carried round by the drive) and measure there.
    pub inertia: bool,
    /// Pitches of dynamics before measuring.
    pub settle_links: usize,
    /// Pitches of dynamics measured.
    pub measure_links: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            max_speed_rad_s: 15.0,
            phases: 32,
            march_links: 3,
            inertia: true,
            settle_links: 4,
            measure_links: 2,
        }
    }
}

/// 1/ε of the bearing friction's regularisation `tanh`-like ramp
/// `clamp(ω/ε, −1, 1)`, s/rad (ε = 0.01 rad/s).
const BEARING_INV_EPS_S_PER_RAD: f64 = 100.0;

/// The estimator's coefficients: built once (on the host or at start-up),
/// then read-only — plain `Copy` data that can be a `static` or `const` in
/// flash. `T` is the number type of the target (`f32`, or `Fx` with the
/// `fixed` feature).
///
/// The grid speeds [`knots_rad_s`](Self::knots_rad_s) and
/// [`bearing_inv_eps_s_per_rad`](Self::bearing_inv_eps_s_per_rad) are
/// derived from the other fields, in `T`, so that an update converts
/// nothing: build tables with [`EstimatorTable::from_model`],
/// [`EstimatorTable::from_coefficients`] or [`EstimatorTable::cast`], which
/// fill them in.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EstimatorTable<T> {
    /// Spacing of the speed grid, rad/s.
    pub speed_step_rad_s: T,
    /// Its reciprocal, s/rad (so the lookup multiplies).
    pub inv_speed_step: T,
    /// Bending loss torque at the grid speeds, N·m.
    pub loss_nm: [T; SPEED_POINTS],
    /// Slope of the loss from each grid point to the next, N·m·s/rad.
    pub loss_slope_nm_s: [T; SPEED_POINTS],
    /// Inertia of the moving belt seen at the drive axle, kg·m².
    pub inertia_kg_m2: T,
    /// Constant bearing friction at the drive axle, N·m.
    pub bearing_friction_nm: T,
    /// The grid speeds `k·Δω` in `T` (derived), rad/s.
    pub knots_rad_s: [T; SPEED_POINTS],
    /// 1/ε of the bearing friction's regularisation (derived), s/rad.
    pub bearing_inv_eps_s_per_rad: T,
}

bitflags::bitflags! {
    /// What an update reports besides the torque: a set of flags, empty
    /// when everything is in range.
    ///
    /// A [`bitflags`] set in one byte, as the flag byte it replaces: the
    /// update sets bits exactly as before (same code, same cost), and a
    /// user gets the set operations (`contains`, `|`, `iter_names`), serde
    /// (flag names in human-readable formats, feature `serde`) and defmt
    /// (flag names, feature `defmt`) without a hand-rolled API.
    ///
    /// ```
    /// use trackbelt::estimator::Status;
    /// let s = Status::BAD_TICK | Status::SPEED_OUT_OF_RANGE;
    /// assert!(!s.is_ok() && s.contains(Status::BAD_TICK));
    /// assert!(Status::OK.is_ok());
    /// ```
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub struct Status: u8 {
        /// The speed was NaN or infinite: the last good output is held.
        const SPEED_NOT_FINITE = 1;
        /// The tick length was not positive and finite: no acceleration
        /// term.
        const BAD_TICK = 1 << 1;
        /// The speed is beyond the table: the loss is extrapolated linearly
        /// from the last two grid points.
        const SPEED_OUT_OF_RANGE = 1 << 2;
        /// A [`GearTable`] input (belt temperature, tension) was outside
        /// its axis or not finite: held at the nearest edge (not finite: the
        /// axis's first point).
        const INPUT_OUT_OF_RANGE = 1 << 3;
    }
}

impl Status {
    /// Everything in range (no flag set).
    pub const OK: Status = Status::empty();

    /// No flag set.
    #[inline]
    pub fn is_ok(self) -> bool {
        self.is_empty()
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Status {
    /// `OK`, or the flags' names joined by ` | `.
    fn format(&self, f: defmt::Formatter<'_>) {
        if self.is_empty() {
            defmt::write!(f, "OK");
        }
        for (i, (name, _)) in self.iter_names().enumerate() {
            if i > 0 {
                defmt::write!(f, " | ");
            }
            defmt::write!(f, "{=str}", name);
        }
    }
}

/// The result of one update.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate<T> {
    /// Torque the drive spends on the belt (bending loss, inertia while the
    /// speed changes, bearing friction), N·m, in the sense of the speed.
    pub torque_nm: T,
    /// The bending loss alone, N·m.
    pub bending_nm: T,
    /// Flags.
    pub status: Status,
}

/// The estimator's state: what it remembers between updates (a few
/// scalars, in RAM). The coefficients are in an [`EstimatorTable`] that
/// each update takes by reference.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EstimatorState<T> {
    last_speed: T,
    /// The last tick length and its reciprocal (one division per change of
    /// tick length, not per update).
    last_dt: T,
    inv_dt: T,
    /// The last good output's torque and bending loss, N·m (held when the
    /// speed is not finite).
    last_torque_nm: T,
    last_bending_nm: T,
    primed: bool,
}

/// An estimator that borrows its table: a reference to an
/// [`EstimatorTable`] (e.g. a `static` in flash) and an [`EstimatorState`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimator<'a, T> {
    table: &'a EstimatorTable<T>,
    state: EstimatorState<T>,
}

impl<T: Real> EstimatorTable<T> {
    /// Build the table from the link chain's travelling-belt statics on the
    /// rig (`D ≥ N + 5`). Costs a few hundred static solves: run it on the
    /// host (build script, calibration tool) or once at start-up.
    pub fn from_model<const D: usize>(
        model: &Model<T>,
        rig: &RigConfig<T>,
        options: &BuildOptions,
    ) -> Result<Self> {
        check_options(options)?;
        let rig: Rig<T, D> = Rig::new(model.clone(), *rig, rig_settings())?;
        Self::from_rig(rig, options)
    }

    /// Build the table for a running gear (`D ≥ N + 5`, one more with
    /// ground) at the belt temperature `temperature_c` (°C; `None`: the
    /// joint law's own, see [`Rig::set_belt_temperature_c`]). The paper's
    /// two-wheel rig gives exactly [`EstimatorTable::from_model`]'s table.
    ///
    /// ```
    /// use trackbelt::estimator::{BuildOptions, EstimatorTable};
    /// use trackbelt::gear::RunningGear;
    /// use trackbelt::params::{Method, Model, Variant};
    /// use trackbelt::rig::RigConfig;
    ///
    /// let model = Model::<f64>::paper(Variant::E38, Method::II)?;
    /// let options = BuildOptions { phases: 4, ..BuildOptions::default() };
    /// let gear = RunningGear::paper_rig(&RigConfig::default(), 0.74)?;
    /// let a = EstimatorTable::from_gear::<48>(&model, &gear, &options, None)?;
    /// let b = EstimatorTable::from_model::<48>(&model, &RigConfig::default(), &options)?;
    /// assert_eq!(a, b);
    /// # Ok::<(), trackbelt::Error>(())
    /// ```
    pub fn from_gear<const D: usize>(
        model: &Model<T>,
        gear: &RunningGear<T>,
        options: &BuildOptions,
        temperature_c: Option<T>,
    ) -> Result<Self> {
        check_options(options)?;
        let mut rig: Rig<T, D> = Rig::from_gear(model.clone(), gear, rig_settings())?;
        if let Some(t) = temperature_c {
            rig.set_belt_temperature_c(t)?;
        }
        Self::from_rig(rig, options)
    }

    /// The table from a settled rig (the belt's temperature already set).
    fn from_rig<const D: usize>(mut rig: Rig<T, D>, options: &BuildOptions) -> Result<Self> {
        let mp = options.phases;
        // A load resting on the drive wheel (the ground pressing the belt
        // onto it) is held by the drive's friction: keep it in the
        // dynamics (frictionless, those links slide on the rim and bend
        // 6–12 % more than the reference simulation's).
        let drive_friction = rig.ground_presses_drive();
        let nd = rig.chain().ndof();
        let path_per_rad = rig.path_speed_per_rad_m().to_f64();
        let l = rig.chain().l.to_f64();
        let ds = l / mp as f64;
        // Joint A is held on the drive wheel's rim (a sprocket tooth) and
        // carried round with it: the drive's pull enters the belt in its
        // wrap. It starts just past where the bottom run meets the drive and
        // must stay on the wrap for the whole march.
        let (rim_r, beta) = rig.drive_polygon();
        let dphi = beta / mp as f64;
        let phi0 = rig.drive_entry_rad() - beta;
        // Fit the pitches into the wrap (E38's long links leave room for
        // about six): shorten the quasi-static march, then the settling,
        // then the measurement.
        let room = libm::floor(rig.drive_wrap_rad() / beta) as usize;
        let room = room.saturating_sub(2);
        let mut opt = *options;
        if !opt.inertia {
            opt.settle_links = 0;
            opt.measure_links = 0;
        }
        while opt.march_links + opt.settle_links + opt.measure_links > room {
            if opt.march_links > 2 {
                opt.march_links -= 1;
            } else if opt.settle_links > 0 {
                opt.settle_links -= 1;
            } else if opt.measure_links > 1 {
                opt.measure_links -= 1;
            } else {
                return Err(invalid(
                    "rig wheels",
                    "the drive wheel's wrap holds too few links for the estimator's march \
                     (it needs about 5 links in the wrap): give the belt more, shorter links \
                     or the drive a larger diameter",
                ));
            }
        }
        let options = &opt;
        rig.chain_mut().pin_y = true;
        let mut rest = [[T::ZERO; D]; 2];
        let mut rest_lam = [[T::ZERO; 2]; 2];
        for (i, phi) in [phi0, phi0 - dphi].into_iter().enumerate() {
            rig.lay_out_on_drive(phi)?;
            // Settle with joint A held there (dynamic relaxation, then the
            // static polish).
            let c = rig.chain_mut();
            c.track = Some(crate::chain::Track {
                radius_m: T::from_f64(rim_r),
                phi0_rad: T::from_f64(phi),
                omega_rad_s: T::ZERO,
                t0_s: c.time,
            });
            let settled = c.solve_static();
            c.track = None;
            settled?;
            rest[i] = rig.chain().q;
            rest_lam[i] = rig.chain().lam;
        }
        let law = rig.chain().model.joint.clone();
        let dw = options.max_speed_rad_s / (SPEED_POINTS - 1) as f64;
        let mut loss = [0.0f64; SPEED_POINTS];
        let mut inertia = 0.0;
        let mut kinetic;
        for (k, loss_k) in loss.iter_mut().enumerate().skip(1) {
            let omega = dw * k as f64;
            let v = omega * path_per_rad;
            rig.set_drive_speed(T::from_f64(omega))?;
            let c = rig.chain_mut();
            c.q = rest[1];
            c.lam = rest_lam[1];
            c.reset_motion();
            let mut march = March {
                phi: phi0 - dphi,
                rim_r,
                omega,
                prev: rest[0],
                prev_dt: ds / v,
                nd,
                law: &law,
                energy: 0.0,
                kinetic: 0.0,
                measuring: false,
            };
            let steps = options.march_links * mp;
            for step in 0..steps {
                march.measuring = step + mp >= steps;
                march.step(c, ds / v, 0)?;
            }
            // Averages over the last link pitch (duration l/v).
            let period = l / v;
            let power = march.energy / period;
            kinetic = march.kinetic / period;
            if !power.is_finite() || power < 0.0 {
                return Err(Error::Diverged {
                    time_s: 0.0,
                    reason: "estimator statics gave a non-finite or negative loss",
                });
            }
            *loss_k = power / omega;
            inertia = kinetic;
            if options.inertia {
                // Carry on with the links' inertia: the chain's own dynamics
                // (BDF2), joint A carried round by the drive, wheels
                // frictionless, starting from the quasi-static march.
                let (e, ke) = dynamic_pitches(c, &march, options, l / v, drive_friction)?;
                *loss_k = e / omega;
                inertia = ke;
            }
        }
        let mut loss_nm = [T::ZERO; SPEED_POINTS];
        let mut loss_slope_nm_s = [T::ZERO; SPEED_POINTS];
        for k in 0..SPEED_POINTS {
            loss_nm[k] = T::from_f64(loss[k]);
            let next = if k + 1 < SPEED_POINTS {
                loss[k + 1]
            } else {
                2.0 * loss[k] - loss[k - 1]
            };
            loss_slope_nm_s[k] = T::from_f64((next - loss[k]) / dw);
        }
        Ok(EstimatorTable::from_coefficients(
            T::from_f64(dw),
            T::from_f64(1.0 / dw),
            loss_nm,
            loss_slope_nm_s,
            T::from_f64(inertia),
            rig.config().bearing_friction_nm,
        ))
    }
}

/// Check the build options.
fn check_options(options: &BuildOptions) -> Result<()> {
    if !(options.max_speed_rad_s.is_finite() && options.max_speed_rad_s > 0.0) {
        return Err(invalid(
            "estimator.max_speed_rad_s",
            "must be positive and finite",
        ));
    }
    if options.phases < 2 || options.phases > MAX_PHASES {
        return Err(invalid("estimator.phases", "must be between 2 and 32"));
    }
    if options.march_links < 2 || options.march_links > 6 {
        return Err(invalid("estimator.march_links", "must be between 2 and 6"));
    }
    if options.inertia
        && (options.settle_links > 6 || options.measure_links == 0 || options.measure_links > 4)
    {
        return Err(invalid(
            "estimator.settle_links/measure_links",
            "settle at most 6 pitches, measure 1 to 4",
        ));
    }
    Ok(())
}

/// Continue a converged quasi-static march with the chain's dynamics for
/// `settle_links + measure_links` pitches of `pitch_s` seconds; returns the
/// joints' mean dissipated power over the measured pitches (W) and the
/// belt's mean kinetic energy per ½ω² (kg·m²). The wheels are
/// frictionless (joint A carries the belt round) unless `drive_friction`:
/// then the drive keeps its friction (the ground presses the belt onto
/// it).
fn dynamic_pitches<T: Real, const D: usize>(
    c: &mut Chain<T, D>,
    march: &March<'_, T, D>,
    options: &BuildOptions,
    pitch_s: f64,
    drive_friction: bool,
) -> Result<(f64, f64)> {
    let nd = march.nd;
    // Velocities from the last march step.
    let inv = T::from_f64(1.0 / march.prev_dt);
    c.reset_motion();
    for i in 0..nd {
        c.v[i] = (c.q[i] - march.prev[i]) * inv;
    }
    c.kinematics_positions();
    c.static_mode = false;
    if !drive_friction {
        if let Some(w) = c.contacts.wheels.as_mut() {
            w.friction = T::ZERO;
        }
    }
    let t0 = c.time;
    c.track = Some(crate::chain::Track {
        radius_m: T::from_f64(march.rim_r),
        phi0_rad: T::from_f64(march.phi),
        omega_rad_s: T::from_f64(march.omega),
        t0_s: t0,
    });
    let start = options.settle_links as f64 * pitch_s;
    let end = start + options.measure_links as f64 * pitch_s;
    let (mut energy, mut kinetic, mut span) = (0.0, 0.0, 0.0);
    let min_step = c.settings.min_step_s.to_f64();
    let result = crate::integrator::step_until(
        c,
        end,
        min_step,
        "estimator dynamics (too many steps)",
        |c| (c.time - t0).to_f64(),
        |c, t| {
            let h_max = c.settings.step_s.to_f64().min(end - t);
            c.step_max(T::from_f64(h_max))?;
            let t_now = (c.time - t0).to_f64();
            if t_now > start {
                let h = t_now - t.max(start);
                energy += c.joint_damping_power_w().to_f64() * h;
                kinetic += c.kinetic_energy_j().to_f64() * h;
                span += h;
            }
            Ok(())
        },
    );
    c.track = None;
    c.time = t0;
    result?;
    if span <= 0.0 {
        return Err(Error::NotConverged {
            what: "estimator dynamics (nothing measured)",
            iterations: 0,
        });
    }
    let omega = march.omega;
    Ok((energy / span, 2.0 * kinetic / span / (omega * omega)))
}

/// A quasi-static march of the belt round the rig: consecutive equilibria
/// with implicit-Euler velocities, accumulating what the last pitch
/// dissipates.
struct March<'a, T, const D: usize> {
    /// Polar angle of joint A on the drive rim, rad, and the rim radius, m.
    phi: f64,
    rim_r: f64,
    /// Drive speed, rad/s.
    omega: f64,
    prev: [T; D],
    prev_dt: f64,
    nd: usize,
    law: &'a crate::joint::JointLaw<T>,
    /// Energy dissipated in the joints while measuring, J.
    energy: f64,
    /// ∫ (kinetic energy per ω²) dt while measuring, kg·m²·s.
    kinetic: f64,
    measuring: bool,
}

impl<T: Real, const D: usize> March<'_, T, D> {
    /// Advance by `dt` seconds of travel; a step Newton cannot solve is
    /// split in two (at most four levels deep).
    fn step(&mut self, c: &mut Chain<T, D>, dt: f64, depth: u32) -> Result<()> {
        let nd = self.nd;
        let n = c.n;
        let before = c.q;
        let before_lam = c.lam;
        for j in 0..n {
            c.march_ref[j] = c.joint_angle(j);
        }
        // Predictor: extrapolate the march (exact for a belt that moves
        // along a fixed path).
        let ratio = T::from_f64(dt / self.prev_dt);
        for i in 0..nd {
            c.q[i] = c.q[i] + (c.q[i] - self.prev[i]) * ratio;
        }
        // Joint A turns with the drive (clockwise: the angle decreases).
        let phi = self.phi - self.omega * dt;
        let (sn, cs) = libm::sincos(phi);
        c.q[X] = T::from_f64(self.rim_r * cs);
        c.q[Y] = T::from_f64(self.rim_r * sn);
        c.march_inv_dt = T::from_f64(1.0 / dt);
        c.reset_motion();
        let solved = c.polish_static();
        c.march_inv_dt = T::ZERO;
        if solved.is_err() {
            if depth >= 4 {
                return solved.map(|_| ());
            }
            c.q = before;
            c.lam = before_lam;
            c.reset_motion();
            self.step(c, dt / 2.0, depth + 1)?;
            return self.step(c, dt / 2.0, depth + 1);
        }
        if self.measuring {
            let inv = T::from_f64(1.0 / dt);
            for j in 0..n {
                let z = c.joint_angle(j);
                let rate = (z - joint_angle_in(&before, j, n, c.two_pi)) * inv;
                self.energy += self.law.damping_power_w(z, rate).to_f64() * dt;
            }
            let omega = c.contacts.wheels.map_or(0.0, |w| w.drive_omega.to_f64());
            if omega > 0.0 {
                self.kinetic += kinetic_per_omega2(c, &before, nd, 1.0 / (dt * omega)) * dt;
            }
        }
        self.prev = before;
        self.prev_dt = dt;
        self.phi = phi;
        Ok(())
    }
}

/// Kinetic energy per ω² of the belt between two consecutive equilibria of
/// a march (`scale` = 1/(dt·ω)), kg·m².
fn kinetic_per_omega2<T: Real, const D: usize>(
    c: &Chain<T, D>,
    before: &[T; D],
    nd: usize,
    scale: f64,
) -> f64 {
    let n = c.n.min(nd);
    let l = c.l.to_f64();
    let (m, i) = (c.m.to_f64(), c.inertia.to_f64());
    let (mut xa, mut ya) = (before[X].to_f64(), before[Y].to_f64());
    let (mut xb, mut yb) = (c.q[X].to_f64(), c.q[Y].to_f64());
    let mut e = 0.0;
    for k in 0..n {
        let (ta, tb) = (before[TH + k].to_f64(), c.q[TH + k].to_f64());
        let (sa, ca) = libm::sincos(ta);
        let (sb, cb) = libm::sincos(tb);
        let dx = (xb + 0.5 * l * cb) - (xa + 0.5 * l * ca);
        let dy = (yb + 0.5 * l * sb) - (ya + 0.5 * l * sa);
        let dth = tb - ta;
        e += (m * (dx * dx + dy * dy) + i * dth * dth) * scale * scale;
        xa += l * ca;
        ya += l * sa;
        xb += l * cb;
        yb += l * sb;
    }
    e
}

impl<T: Real> EstimatorTable<T> {
    /// A table from its coefficients; fills in the derived grid speeds and
    /// the bearing friction's regularisation in `T`.
    pub fn from_coefficients(
        speed_step_rad_s: T,
        inv_speed_step: T,
        loss_nm: [T; SPEED_POINTS],
        loss_slope_nm_s: [T; SPEED_POINTS],
        inertia_kg_m2: T,
        bearing_friction_nm: T,
    ) -> Self {
        let mut knots_rad_s = [T::ZERO; SPEED_POINTS];
        for (i, x) in knots_rad_s.iter_mut().enumerate() {
            *x = speed_step_rad_s * T::from_usize(i);
        }
        EstimatorTable {
            speed_step_rad_s,
            inv_speed_step,
            loss_nm,
            loss_slope_nm_s,
            inertia_kg_m2,
            bearing_friction_nm,
            knots_rad_s,
            bearing_inv_eps_s_per_rad: T::from_f64(BEARING_INV_EPS_S_PER_RAD),
        }
    }

    /// The same table in another number type (e.g. built in `f64` on the
    /// host, run in `f32` or fixed point on the target). The coefficients
    /// are rounded to `U`; the derived fields are computed again in `U`.
    pub fn cast<U: Real>(&self) -> EstimatorTable<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        EstimatorTable::from_coefficients(
            c(self.speed_step_rad_s),
            c(self.inv_speed_step),
            self.loss_nm.map(c),
            self.loss_slope_nm_s.map(c),
            c(self.inertia_kg_m2),
            c(self.bearing_friction_nm),
        )
    }

    /// Highest speed of the grid, rad/s.
    pub fn max_speed_rad_s(&self) -> T {
        self.speed_step_rad_s * T::from_usize(SPEED_POINTS - 1)
    }

    /// Bending loss at speed `omega ≥ 0` (linear between grid points,
    /// linear extrapolation beyond), and whether it was in range.
    pub fn loss_at(&self, omega: T) -> (T, bool) {
        self.lookup(omega)
    }

    /// The grid speeds `k·Δω`, rad/s.
    pub fn knots(&self) -> [T; SPEED_POINTS] {
        self.knots_rad_s
    }

    /// The loss at `omega ≥ 0`: the interval by bisection over the knots
    /// (four comparisons, no conversion or division), then one multiply-add.
    #[inline]
    fn lookup(&self, omega: T) -> (T, bool) {
        let knots = &self.knots_rad_s;
        let last = SPEED_POINTS - 1;
        if omega >= knots[last] {
            let v = self.loss_nm[last] + self.loss_slope_nm_s[last - 1] * (omega - knots[last]);
            return (v, omega <= knots[last]);
        }
        // Here knots[0] = 0 ≤ omega < knots[15]: the last knot not above
        // omega, by halving steps of 8, 4, 2, 1 (unrolled: four comparisons,
        // indices the compiler sees in bounds).
        const _: () = assert!(
            SPEED_POINTS == 16,
            "the search below is unrolled for 16 knots"
        );
        let mut lo = 0usize;
        for step in [8, 4, 2, 1] {
            if omega >= knots[lo + step] {
                lo += step;
            }
        }
        (
            self.loss_nm[lo] + self.loss_slope_nm_s[lo] * (omega - knots[lo]),
            true,
        )
    }

    /// One control tick of the estimator with this table and `state`: the
    /// drive speed now (rad/s, clockwise positive as on the rig) and the
    /// time since the last tick (s). Never panics; bad input is flagged in
    /// the status and gives a defined output.
    #[inline]
    pub fn update(&self, state: &mut EstimatorState<T>, speed_rad_s: T, dt_s: T) -> Estimate<T> {
        self.step(state, speed_rad_s, dt_s)
    }

    /// The body of both `update`s, inlined into each so that each is one
    /// call with its own argument layout.
    #[inline(always)]
    fn step(&self, state: &mut EstimatorState<T>, speed_rad_s: T, dt_s: T) -> Estimate<T> {
        self.step_with(state, speed_rad_s, dt_s, |w| self.lookup(w))
    }

    /// The update with the bending loss at `|ω|` from `loss` (the 1-D
    /// table, or a [`GearTable`]'s interpolation).
    #[inline(always)]
    fn step_with<F: FnOnce(T) -> (T, bool)>(
        &self,
        state: &mut EstimatorState<T>,
        speed_rad_s: T,
        dt_s: T,
        loss: F,
    ) -> Estimate<T> {
        if !speed_rad_s.is_finite() {
            return Estimate {
                torque_nm: state.last_torque_nm,
                bending_nm: state.last_bending_nm,
                status: Status::SPEED_NOT_FINITE,
            };
        }
        let mut status = Status::OK;
        let w = speed_rad_s;
        let neg = w < T::ZERO;
        let (loss, in_range) = loss(w.abs());
        if !in_range {
            status |= Status::SPEED_OUT_OF_RANGE;
        }
        let bending = if neg { -loss } else { loss };
        let mut accel = T::ZERO;
        if dt_s.is_finite() && dt_s > T::ZERO {
            if dt_s != state.last_dt {
                state.last_dt = dt_s;
                state.inv_dt = T::ONE / dt_s;
            }
            if state.primed {
                accel = (w - state.last_speed) * state.inv_dt;
                if !accel.is_finite() {
                    accel = T::ZERO;
                }
            }
        } else {
            status |= Status::BAD_TICK;
        }
        let bearing =
            self.bearing_friction_nm * (w * self.bearing_inv_eps_s_per_rad).clamp(-T::ONE, T::ONE);
        let torque = bending + self.inertia_kg_m2 * accel + bearing;
        state.last_speed = w;
        state.primed = true;
        state.last_torque_nm = torque;
        state.last_bending_nm = bending;
        Estimate {
            torque_nm: torque,
            bending_nm: bending,
            status,
        }
    }
}

impl<T: Real> EstimatorState<T> {
    /// A state at rest (no previous speed).
    pub fn new() -> Self {
        EstimatorState {
            last_speed: T::ZERO,
            last_dt: T::ZERO,
            inv_dt: T::ZERO,
            last_torque_nm: T::ZERO,
            last_bending_nm: T::ZERO,
            primed: false,
        }
    }

    /// Forget the previous speed (e.g. after a gap in the speed signal).
    pub fn reset(&mut self) {
        self.primed = false;
        self.last_speed = T::ZERO;
    }
}

impl<T: Real> Default for EstimatorState<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<'a, T: Real> Estimator<'a, T> {
    /// An estimator at rest with the table `table`.
    pub fn new(table: &'a EstimatorTable<T>) -> Self {
        Estimator {
            table,
            state: EstimatorState::new(),
        }
    }

    /// The coefficients.
    pub fn table(&self) -> &'a EstimatorTable<T> {
        self.table
    }

    /// The state.
    pub fn state(&self) -> &EstimatorState<T> {
        &self.state
    }

    /// One control tick: [`EstimatorTable::update`] with this estimator's
    /// table and state.
    #[inline]
    pub fn update(&mut self, speed_rad_s: T, dt_s: T) -> Estimate<T> {
        self.table.step(&mut self.state, speed_rad_s, dt_s)
    }

    /// Forget the previous speed (e.g. after a gap in the speed signal).
    pub fn reset(&mut self) {
        self.state.reset();
    }
}

/// Most belt temperatures on a [`GearTable`]'s temperature axis.
pub const MAX_TEMPERATURES: usize = 4;
/// Most tensioner forces on a [`GearTable`]'s tension axis.
pub const MAX_TENSIONS: usize = 4;

/// Bending loss over speed × belt temperature × tension: the estimator for
/// a running gear whose controller may know the belt's temperature and the
/// tensioner's force. Plain `Copy` data for flash, like [`EstimatorTable`]
/// (f32: about 2.3 KiB; 32.32 fixed point: about 4.5 KiB).
///
/// * `base` is the 1-D table at the nominal temperature and tension: an
///   update without the optional inputs is exactly `base`'s update (same
///   code, same numbers).
/// * With an input, the loss is interpolated linearly along each axis
///   (bilinear in temperature and tension, linear in speed as the 1-D
///   table) with the reciprocals of the axes' spacings stored: no
///   division in the update. An input outside its axis is held at the
///   nearest edge and flagged [`Status::INPUT_OUT_OF_RANGE`].
/// * The speed grid, the belt's inertia and the bearing friction are
///   `base`'s.
///
/// ```
/// use trackbelt::estimator::{EstimatorState, EstimatorTable, GearTable, SPEED_POINTS};
/// let col = |k: f64| EstimatorTable::from_coefficients(
///     1.0, 1.0, [k; SPEED_POINTS], [0.0; SPEED_POINTS], 0.0, 0.0);
/// // Loss 1 N·m at 20 °C and 2 N·m at 40 °C, one tension.
/// let t = GearTable::from_columns(col(1.0), &[20.0, 40.0], &[500.0], &[col(1.0), col(2.0)], 20.0, 500.0)?;
/// let mut s = EstimatorState::new();
/// let e = t.update(&mut s, 3.0, 1e-3, Some(30.0), None);
/// assert!((e.bending_nm - 1.5).abs() < 1e-12);
/// # Ok::<(), trackbelt::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GearTable<T> {
    /// The table at the nominal temperature and tension.
    pub base: EstimatorTable<T>,
    /// Points on the temperature axis (1..=[`MAX_TEMPERATURES`]).
    pub temperatures: usize,
    /// Points on the tension axis (1..=[`MAX_TENSIONS`]).
    pub tensions: usize,
    /// Belt temperatures, ascending, °C.
    pub temperature_c: [T; MAX_TEMPERATURES],
    /// Reciprocal spacing from each temperature to the next, 1/K (0 past
    /// the last).
    pub inv_temperature_step: [T; MAX_TEMPERATURES],
    /// Tensioner forces, ascending, N.
    pub tension_n: [T; MAX_TENSIONS],
    /// Reciprocal spacing from each force to the next, 1/N (0 past the
    /// last).
    pub inv_tension_step: [T; MAX_TENSIONS],
    /// Nominal temperature (used when only the tension is given), °C.
    pub nominal_temperature_c: T,
    /// Nominal tension (used when only the temperature is given), N.
    pub nominal_tension_n: T,
    /// Loss at the speed grid, per temperature and tension, N·m.
    pub loss_nm: [[[T; SPEED_POINTS]; MAX_TENSIONS]; MAX_TEMPERATURES],
    /// Its slope to the next speed, N·m·s/rad.
    pub loss_slope_nm_s: [[[T; SPEED_POINTS]; MAX_TENSIONS]; MAX_TEMPERATURES],
}

/// Where `x` sits on an axis of `n` ascending points: the interval and the
/// fraction in it (clamped to the axis), and whether it was on the axis.
#[inline(always)]
fn axis_position<T: Real, const M: usize>(
    x: T,
    knots: &[T; M],
    inv: &[T; M],
    n: usize,
) -> (usize, T, bool) {
    if !x.is_finite() {
        return (0, T::ZERO, false);
    }
    let mut i = 0usize;
    for j in 1..M {
        if j + 1 < n && x >= knots[j] {
            i = j;
        }
    }
    let f = (x - knots[i]) * inv[i];
    let inside = x >= knots[0] && (n < 2 || x <= knots[n.saturating_sub(1).min(M - 1)]);
    (i, f.clamp(T::ZERO, T::ONE), inside)
}

impl<T: Real> GearTable<T> {
    /// A table from its columns: `columns[i·tensions + j]` is the 1-D
    /// table at `temperature_c[i]` and `tension_n[j]` (built like `base`,
    /// on the same speed grid). The axes must ascend strictly.
    pub fn from_columns(
        base: EstimatorTable<T>,
        temperature_c: &[T],
        tension_n: &[T],
        columns: &[EstimatorTable<T>],
        nominal_temperature_c: T,
        nominal_tension_n: T,
    ) -> Result<Self> {
        let (nt, nf) = (temperature_c.len(), tension_n.len());
        if nt == 0 || nt > MAX_TEMPERATURES || nf == 0 || nf > MAX_TENSIONS {
            return Err(invalid(
                "estimator axes",
                "1 to 4 temperatures and 1 to 4 tensions",
            ));
        }
        if columns.len() != nt * nf {
            return Err(invalid(
                "estimator columns",
                "one table per temperature and tension",
            ));
        }
        let ascending =
            |xs: &[T]| xs.windows(2).all(|w| w[1] > w[0]) && xs.iter().all(|x| x.is_finite());
        if !ascending(temperature_c) || !ascending(tension_n) {
            return Err(invalid(
                "estimator axes",
                "temperatures and tensions must be finite and strictly ascending",
            ));
        }
        if columns
            .iter()
            .any(|c| c.speed_step_rad_s != base.speed_step_rad_s)
        {
            return Err(invalid(
                "estimator columns",
                "every column needs the base table's speed grid",
            ));
        }
        let mut t = GearTable {
            base,
            temperatures: nt,
            tensions: nf,
            temperature_c: [T::ZERO; MAX_TEMPERATURES],
            inv_temperature_step: [T::ZERO; MAX_TEMPERATURES],
            tension_n: [T::ZERO; MAX_TENSIONS],
            inv_tension_step: [T::ZERO; MAX_TENSIONS],
            nominal_temperature_c,
            nominal_tension_n,
            loss_nm: [[[T::ZERO; SPEED_POINTS]; MAX_TENSIONS]; MAX_TEMPERATURES],
            loss_slope_nm_s: [[[T::ZERO; SPEED_POINTS]; MAX_TENSIONS]; MAX_TEMPERATURES],
        };
        for (i, &x) in temperature_c.iter().enumerate() {
            t.temperature_c[i] = x;
            if i + 1 < nt {
                t.inv_temperature_step[i] = T::ONE / (temperature_c[i + 1] - x);
            }
        }
        for (j, &x) in tension_n.iter().enumerate() {
            t.tension_n[j] = x;
            if j + 1 < nf {
                t.inv_tension_step[j] = T::ONE / (tension_n[j + 1] - x);
            }
        }
        for i in 0..nt {
            for j in 0..nf {
                let c = &columns[i * nf + j];
                t.loss_nm[i][j] = c.loss_nm;
                t.loss_slope_nm_s[i][j] = c.loss_slope_nm_s;
            }
        }
        Ok(t)
    }

    /// The same table in another number type (coefficients rounded to `U`,
    /// reciprocals computed again in `U`).
    pub fn cast<U: Real>(&self) -> GearTable<U> {
        let c = |x: T| U::from_f64(x.to_f64());
        let mut t = GearTable {
            base: self.base.cast(),
            temperatures: self.temperatures,
            tensions: self.tensions,
            temperature_c: self.temperature_c.map(c),
            inv_temperature_step: [U::ZERO; MAX_TEMPERATURES],
            tension_n: self.tension_n.map(c),
            inv_tension_step: [U::ZERO; MAX_TENSIONS],
            nominal_temperature_c: c(self.nominal_temperature_c),
            nominal_tension_n: c(self.nominal_tension_n),
            loss_nm: self.loss_nm.map(|a| a.map(|b| b.map(c))),
            loss_slope_nm_s: self.loss_slope_nm_s.map(|a| a.map(|b| b.map(c))),
        };
        for i in 0..self.temperatures.min(MAX_TEMPERATURES).saturating_sub(1) {
            t.inv_temperature_step[i] = U::ONE / (t.temperature_c[i + 1] - t.temperature_c[i]);
        }
        for j in 0..self.tensions.min(MAX_TENSIONS).saturating_sub(1) {
            t.inv_tension_step[j] = U::ONE / (t.tension_n[j + 1] - t.tension_n[j]);
        }
        t
    }

    /// Bending loss at `omega ≥ 0`, belt temperature and tension
    /// (interpolated; held at the axes' edges), and whether all three were
    /// in range.
    pub fn loss_at(&self, omega: T, temperature_c: T, tension_n: T) -> (T, bool) {
        let (loss, speed_ok, inputs_ok) = self.lookup(omega, temperature_c, tension_n);
        (loss, speed_ok && inputs_ok)
    }

    /// The loss, whether the speed was on the grid, whether the inputs
    /// were on their axes.
    #[inline(always)]
    fn lookup(&self, omega: T, temperature_c: T, tension_n: T) -> (T, bool, bool) {
        let b = &self.base;
        let knots = &b.knots_rad_s;
        let last = SPEED_POINTS - 1;
        // The speed interval once for all columns (as the 1-D lookup).
        let (il, is, dw, speed_ok) = if omega >= knots[last] {
            (last, last - 1, omega - knots[last], omega <= knots[last])
        } else {
            let mut lo = 0usize;
            for step in [8, 4, 2, 1] {
                if omega >= knots[lo + step] {
                    lo += step;
                }
            }
            (lo, lo, omega - knots[lo], true)
        };
        let (ti, ft, t_ok) = axis_position(
            temperature_c,
            &self.temperature_c,
            &self.inv_temperature_step,
            self.temperatures,
        );
        let (fi, ff, f_ok) = axis_position(
            tension_n,
            &self.tension_n,
            &self.inv_tension_step,
            self.tensions,
        );
        let ti1 = (ti + 1)
            .min(self.temperatures.max(1) - 1)
            .min(MAX_TEMPERATURES - 1);
        let fi1 = (fi + 1).min(self.tensions.max(1) - 1).min(MAX_TENSIONS - 1);
        let ti = ti.min(MAX_TEMPERATURES - 1);
        let fi = fi.min(MAX_TENSIONS - 1);
        let il = il.min(last);
        let is = is.min(last);
        let v = |i: usize, j: usize| self.loss_nm[i][j][il] + self.loss_slope_nm_s[i][j][is] * dw;
        let a = v(ti, fi);
        let a = a + (v(ti, fi1) - a) * ff;
        let c = v(ti1, fi);
        let c = c + (v(ti1, fi1) - c) * ff;
        (a + (c - a) * ft, speed_ok, t_ok && f_ok)
    }

    /// One control tick: the drive speed (rad/s), the time since the last
    /// tick (s), and, when the controller has them, the belt temperature
    /// (°C) and the tensioner force (N). Without both it is exactly
    /// `self.base.update(state, speed_rad_s, dt_s)`.
    #[inline]
    pub fn update(
        &self,
        state: &mut EstimatorState<T>,
        speed_rad_s: T,
        dt_s: T,
        temperature_c: Option<T>,
        tension_n: Option<T>,
    ) -> Estimate<T> {
        if temperature_c.is_none() && tension_n.is_none() {
            return self.base.step(state, speed_rad_s, dt_s);
        }
        let temp = temperature_c.unwrap_or(self.nominal_temperature_c);
        let tension = tension_n.unwrap_or(self.nominal_tension_n);
        let mut inputs_ok = true;
        let mut e = self.base.step_with(state, speed_rad_s, dt_s, |w| {
            let (loss, speed_ok, ok) = self.lookup(w, temp, tension);
            inputs_ok = ok;
            (loss, speed_ok)
        });
        if !inputs_ok {
            e.status |= Status::INPUT_OUT_OF_RANGE;
        }
        e
    }
}

#[cfg(test)]
mod gear_table_tests {
    use super::*;

    fn col(k: f64) -> EstimatorTable<f64> {
        let mut loss = [0.0; SPEED_POINTS];
        for (i, x) in loss.iter_mut().enumerate() {
            *x = k * i as f64;
        }
        EstimatorTable::from_coefficients(1.0, 1.0, loss, [k; SPEED_POINTS], 0.0, 0.0)
    }

    fn table() -> GearTable<f64> {
        GearTable::from_columns(
            col(1.0),
            &[20.0, 40.0],
            &[300.0, 500.0],
            &[col(1.0), col(2.0), col(3.0), col(4.0)],
            20.0,
            300.0,
        )
        .unwrap()
    }

    #[test]
    fn bilinear_between_columns_and_flagged_off_the_axes() {
        let t = table();
        let mut s = EstimatorState::new();
        // At 30 °C, 400 N: the mean of the four columns' slopes (2.5) × ω.
        let e = t.update(&mut s, 2.0, 1e-3, Some(30.0), Some(400.0));
        assert!(e.status.is_ok());
        assert!((e.bending_nm - 5.0).abs() < 1e-12, "{e:?}");
        // Only the temperature: the nominal tension (300 N).
        let e = t.update(&mut s, 2.0, 1e-3, Some(40.0), None);
        assert!((e.bending_nm - 6.0).abs() < 1e-12, "{e:?}");
        // Off the axis: held at the edge, flagged.
        let e = t.update(&mut s, 2.0, 1e-3, Some(90.0), Some(500.0));
        assert!(e.status.contains(Status::INPUT_OUT_OF_RANGE));
        assert!((e.bending_nm - 8.0).abs() < 1e-12, "{e:?}");
        // Beyond the speed grid: extrapolated and flagged as before.
        let e = t.update(&mut s, 20.0, 1e-3, Some(20.0), Some(300.0));
        assert!(e.status.contains(Status::SPEED_OUT_OF_RANGE));
        assert!(!e.status.contains(Status::INPUT_OUT_OF_RANGE));
        // Without inputs: exactly the base table.
        let (mut a, mut b) = (EstimatorState::new(), EstimatorState::new());
        for w in [0.0, 0.5, 3.3, -7.0, 15.0, 99.0, f64::NAN] {
            assert_eq!(
                t.update(&mut a, w, 1e-3, None, None),
                t.base.update(&mut b, w, 1e-3)
            );
        }
    }

    #[test]
    fn bad_tables_and_inputs_never_panic() {
        let mut t = table();
        let mut s = EstimatorState::new();
        for (nt, nf) in [(0, 0), (99, 99), (1, 4), (4, 1)] {
            t.temperatures = nt;
            t.tensions = nf;
            for x in [f64::NAN, f64::INFINITY, -1e300, 0.0, 35.0, 1e300] {
                let e = t.update(&mut s, 3.0, 1e-3, Some(x), Some(x));
                assert!(e.torque_nm.is_finite() || x.abs() > 1e299, "{e:?}");
                let _ = t.cast::<f32>();
            }
        }
        assert!(GearTable::from_columns(col(1.0), &[], &[1.0], &[], 0.0, 0.0).is_err());
        assert!(GearTable::from_columns(
            col(1.0),
            &[2.0, 1.0],
            &[1.0],
            &[col(1.0), col(1.0)],
            0.0,
            0.0
        )
        .is_err());
        assert!(
            GearTable::from_columns(col(1.0), &[1.0], &[1.0], &[col(1.0), col(1.0)], 0.0, 0.0)
                .is_err()
        );
    }
}
