//! Synthetic measurements: run the reference model with one effect switched
//! on (or none, or a disturbance outside the effect catalogue), sample it
//! like the camera (25 Hz, about 1 mm of marker noise, a few missing rows)
//! and write a `DATA.md` dataset. The diagnosis gets no hint of what was
//! switched on: the manifest holds only what a real measurement would.
//!
//! Disturbances outside the catalogue (made up to test `unexplained`):
//!
//! | name | what it adds to the measured height |
//! | --- | --- |
//! | `camera_drift` | a slow linear drift of the camera's height reading (e.g. a sagging tripod) |
//! | `second_mode` | a decaying oscillation at another frequency (e.g. the roller rocking on its axle) |
//! | `marker_slip` | a step in the reading half-way through (the marker slipped on the belt) |

pub use crate::forward::{interpolate, knots_at, simulate_height, simulate_scroll};

use crate::catalogue::{scale_stiffness, Baseline, EffectKind};
use crate::dataset::{self, BeltSpec, Dataset, DynamicEntry, DynamicSeries};
use crate::error::Result;
use std::path::{Path, PathBuf};
use trackbelt::joint::JointLaw;

/// Deterministic pseudo-random numbers (xorshift64*, Box–Muller): the
/// generator needs reproducible noise, not cryptographic quality.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed (any value).
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// A disturbance outside the effect catalogue.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Disturbance {
    /// The height reading drifts linearly, mm/s.
    CameraDrift {
        /// Drift rate, mm/s.
        mm_per_s: f64,
    },
    /// An extra decaying oscillation.
    SecondMode {
        /// Initial amplitude, mm.
        amplitude_mm: f64,
        /// Frequency, Hz.
        freq_hz: f64,
        /// Exponential decay rate, 1/s.
        decay_per_s: f64,
    },
    /// The reading steps by `step_mm` at `at_s`.
    MarkerSlip {
        /// Time of the slip, s.
        at_s: f64,
        /// Size of the step, mm.
        step_mm: f64,
    },
}

impl Disturbance {
    /// Names accepted by [`Disturbance::parse`].
    pub const NAMES: [&'static str; 3] = ["camera_drift", "second_mode", "marker_slip"];

    /// The disturbance `name` at `magnitude` times its nominal size.
    pub fn parse(name: &str, magnitude: f64) -> Option<Disturbance> {
        match name {
            "camera_drift" => Some(Disturbance::CameraDrift {
                mm_per_s: 1.5 * magnitude,
            }),
            "second_mode" => Some(Disturbance::SecondMode {
                amplitude_mm: 6.0 * magnitude,
                freq_hz: 3.3,
                decay_per_s: 0.3,
            }),
            "marker_slip" => Some(Disturbance::MarkerSlip {
                at_s: 2.5,
                step_mm: 5.0 * magnitude,
            }),
            _ => None,
        }
    }

    /// What it adds to the reading at time `t`, mm.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Disturbance::CameraDrift { mm_per_s } => mm_per_s * t,
            Disturbance::SecondMode {
                amplitude_mm,
                freq_hz,
                decay_per_s,
            } => {
                amplitude_mm
                    * (-decay_per_s * t).exp()
                    * (std::f64::consts::TAU * freq_hz * t).sin()
            }
            Disturbance::MarkerSlip { at_s, step_mm } => {
                if t >= at_s {
                    step_mm
                } else {
                    0.0
                }
            }
        }
    }
}

/// What a synthetic dynamic measurement holds.
#[derive(Debug, Clone)]
pub struct DynamicSynth {
    /// The joint law of the "true" belt (baseline, perturbed, with or
    /// without an effect).
    pub law: JointLaw<f64>,
    /// The belt simulated (with its number of links).
    pub belt: trackbelt::params::Belt<f64>,
    /// Roller mass, kg.
    pub roller_kg: f64,
    /// Length of the record, s.
    pub duration_s: f64,
    /// Camera sample rate, Hz.
    pub rate_hz: f64,
    /// Standard deviation of the marker noise, mm.
    pub noise_mm: f64,
    /// Rows dropped at random (gaps in `t_s`).
    pub missing_rows: usize,
    /// Constant error of the camera's height zero, mm.
    pub offset_mm: f64,
    /// A disturbance outside the catalogue, if any.
    pub disturbance: Option<Disturbance>,
    /// Seed of the noise.
    pub seed: u64,
}

impl DynamicSynth {
    /// The usual set-up for a baseline: the true belt is 4 % stiffer and
    /// 10 % less damped than the baseline (so the diagnosis has to refit),
    /// 1.3 kg roller, 6 s at 25 Hz, 1 mm noise, 4 missing rows, 1.5 mm
    /// camera offset, no effect.
    pub fn new(baseline: &Baseline, seed: u64) -> Self {
        let mut law = scale_stiffness(&baseline.law, 1.04);
        law.damping *= 0.9;
        DynamicSynth {
            law,
            belt: baseline.belt,
            roller_kg: 1.3,
            duration_s: 6.0,
            rate_hz: 25.0,
            noise_mm: 1.0,
            missing_rows: 4,
            offset_mm: 1.5,
            disturbance: None,
            seed,
        }
    }

    /// Switch on `effect` at `magnitude` times its nominal size.
    pub fn with_effect(mut self, effect: EffectKind, magnitude: f64) -> Self {
        self.law = effect.apply(&self.law, magnitude);
        self
    }

    /// Sample the measurement: `(t_s, a_height_mm)`.
    pub fn sample(&self) -> Result<(Vec<f64>, Vec<f64>)> {
        let mut rng = Rng::new(self.seed);
        let n = (self.duration_s * self.rate_hz).floor() as usize + 1;
        // The camera starts at a random phase within its first frame.
        let phase = rng.uniform() / self.rate_hz;
        let mut times: Vec<f64> = (0..n)
            .map(|i| phase + i as f64 / self.rate_hz)
            .filter(|&t| t <= self.duration_s)
            .collect();
        for _ in 0..self.missing_rows.min(times.len() / 10) {
            // Never the first rows (the release) nor the last.
            let span = times.len().saturating_sub(10).max(1);
            let i = 5 + (rng.uniform() * span as f64) as usize;
            if i < times.len() - 1 {
                times.remove(i);
            }
        }
        let trace = simulate_height(&self.law, &self.belt, self.roller_kg, self.duration_s)?;
        let model = interpolate(&trace, &times);
        let h = times
            .iter()
            .zip(&model)
            .map(|(&t, &m)| {
                let d = self.disturbance.map_or(0.0, |d| d.at(t));
                // Readings are rounded to 0.1 mm like a logger would.
                ((m + self.offset_mm + d + self.noise_mm * rng.normal()) * 10.0).round() / 10.0
            })
            .collect();
        let times = times.iter().map(|t| (t * 1e4).round() / 1e4).collect();
        Ok((times, h))
    }

    /// Write a dataset named `name` with this one dynamic series into the
    /// new directory `dir` (never overwrites).
    pub fn write(&self, dir: &Path, name: &str) -> Result<()> {
        let (t_s, a_height_mm) = self.sample()?;
        let ds = Dataset {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            source: Some("synthetic (trackbelt synth)".into()),
            belt: belt_spec(&self.belt),
            statics: Vec::new(),
            dynamics: vec![DynamicEntry {
                label: Some("run-1".into()),
                roller_kg: self.roller_kg,
                hd_mm: None,
                wd_mm: None,
                period_s: None,
                log_decrement: None,
                settled_hs_mm: None,
                series: Some(DynamicSeries {
                    file: PathBuf::from("dynamic-1.csv"),
                    t_s,
                    a_height_mm,
                    a_x_mm: None,
                }),
            }],
            scrolls: Vec::new(),
            warnings: Vec::new(),
        };
        Ok(dataset::write(&ds, dir)?)
    }
}

/// A disturbance of a scroll (rig) measurement outside the catalogue.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScrollDisturbance {
    /// The torque sensor's zero drifts upwards, N·m/s.
    SensorDrift {
        /// Drift rate, N·m/s.
        nm_per_s: f64,
    },
    /// A periodic load at a fixed frequency (e.g. an out-of-round wheel
    /// rubbing once per revolution of something else).
    PeriodicLoad {
        /// Amplitude, N·m.
        amplitude_nm: f64,
        /// Frequency, Hz.
        freq_hz: f64,
    },
}

impl ScrollDisturbance {
    /// Names accepted by [`ScrollDisturbance::parse`].
    pub const NAMES: [&'static str; 2] = ["sensor_drift", "periodic_load"];

    /// The disturbance `name` at `magnitude` times its nominal size.
    pub fn parse(name: &str, magnitude: f64) -> Option<Self> {
        match name {
            "sensor_drift" => Some(ScrollDisturbance::SensorDrift {
                nm_per_s: 0.03 * magnitude,
            }),
            "periodic_load" => Some(ScrollDisturbance::PeriodicLoad {
                amplitude_nm: 0.15 * magnitude,
                freq_hz: 0.6,
            }),
            _ => None,
        }
    }

    /// What it adds to the torque reading at time `t`, N·m.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            ScrollDisturbance::SensorDrift { nm_per_s } => nm_per_s * t,
            ScrollDisturbance::PeriodicLoad {
                amplitude_nm,
                freq_hz,
            } => amplitude_nm * (std::f64::consts::TAU * freq_hz * t).sin(),
        }
    }
}

/// The drive-speed profile of a synthetic scroll test: steps of speed with
/// linear ramps, rad/s against s (piecewise linear through the knots).
pub fn scroll_profile() -> Vec<(f64, f64)> {
    // Speeds revisited late in the run (1.5 and 3 rad/s), when the belt is
    // warmer: a drift at constant speed shows there.
    vec![
        (0.0, 0.0),
        (0.6, 1.5),
        (2.5, 1.5),
        (3.0, 3.0),
        (5.0, 3.0),
        (5.5, 5.0),
        (7.5, 5.0),
        (8.0, 1.5),
        (10.0, 1.5),
        (10.5, 3.0),
        (12.5, 3.0),
    ]
}

/// Cooling time constant of the synthetic belt's temperature, s.
pub const SYNTH_COOLING_S: f64 = 30.0;

/// What a synthetic scroll measurement holds.
#[derive(Debug, Clone)]
pub struct ScrollSynth {
    /// The "true" joint law (with or without an effect).
    pub law: JointLaw<f64>,
    /// The belt simulated (with its number of links).
    pub belt: trackbelt::params::Belt<f64>,
    /// The rig (its `bearing_friction_nm` is the `bearing_friction` effect).
    pub config: trackbelt::rig::RigConfig<f64>,
    /// Drive speed knots (s, rad/s).
    pub profile: Vec<(f64, f64)>,
    /// Belt temperature at the start and at its warmest, °C (the belt
    /// heated by the drive's dissipation, ∝ ω², and cooling with
    /// [`SYNTH_COOLING_S`]: it warms fast at high speed and little at low
    /// speed; logged in `belt_temp_c`).
    pub temp_c: (f64, f64),
    /// Logger rate, Hz (each sample is the mean over its interval).
    pub rate_hz: f64,
    /// Torque noise, N·m (standard deviation).
    pub noise_nm: f64,
    /// Rows dropped at random.
    pub missing_rows: usize,
    /// A disturbance outside the catalogue.
    pub disturbance: Option<ScrollDisturbance>,
    /// Seed of the noise.
    pub seed: u64,
}

impl ScrollSynth {
    /// The usual set-up: the baseline with 10 % more damping, the rig's
    /// defaults, [`scroll_profile`], a belt warming from 20 to 50 °C, a
    /// 20 Hz logger with 0.01 N·m noise, 4 missing rows, no effect.
    pub fn new(baseline: &Baseline, seed: u64) -> Self {
        let mut law = baseline.law.clone();
        law.damping *= 1.1;
        ScrollSynth {
            law,
            belt: baseline.belt,
            config: trackbelt::rig::RigConfig::default(),
            profile: scroll_profile(),
            temp_c: (20.0, 50.0),
            rate_hz: 20.0,
            noise_nm: 0.01,
            missing_rows: 4,
            disturbance: None,
            seed,
        }
    }

    /// Switch on a scroll effect at `magnitude` times its nominal size.
    pub fn with_effect(mut self, effect: EffectKind, magnitude: f64) -> Self {
        if effect == EffectKind::BearingFriction {
            self.config.bearing_friction_nm = effect.nominal().0 * magnitude;
        } else {
            self.law = effect.apply(&self.law, magnitude);
            if let Some(th) = &mut self.law.effects.thermal_softening {
                th.reference_temp_c = self.temp_c.0;
                th.temp_c = self.temp_c.0;
            }
        }
        self
    }

    /// The belt's warming: heated by the drive's dissipation (∝ ω², the
    /// torque being mostly damping) and cooling towards the start's
    /// temperature with [`SYNTH_COOLING_S`], scaled so that it spans
    /// `temp_c` (start, warmest). Knots every 10 ms over `duration` s.
    fn temperature_knots(&self, duration: f64) -> Vec<(f64, f64)> {
        let (a, b) = self.temp_c;
        let dt = 0.01;
        let steps = (duration / dt).ceil() as usize + 2;
        let mut knots = Vec::with_capacity(steps);
        let mut x = 0.0f64;
        for i in 0..steps {
            let t = i as f64 * dt;
            knots.push((t, x));
            let w = knots_at(&self.profile, t);
            x += dt * (w * w - x / SYNTH_COOLING_S);
        }
        let top = knots.iter().map(|k| k.1).fold(0.0, f64::max);
        let scale = if top > 0.0 { (b - a) / top } else { 0.0 };
        for k in knots.iter_mut() {
            k.1 = a + scale * k.1;
        }
        knots
    }

    /// Sample the measurement: `(t_s, omega_rad_s, torque_nm, belt_temp_c)`.
    #[allow(clippy::type_complexity)]
    pub fn sample(&self) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)> {
        let duration = self.profile.last().map_or(1.0, |k| k.0);
        let temp = self.temperature_knots(duration);
        let temp_at = |t: f64| knots_at(&temp, t);
        let trace = simulate_scroll(
            &self.law,
            &self.belt,
            &self.config,
            &|t| knots_at(&self.profile, t),
            &temp_at,
            duration,
        )?;
        let mut rng = Rng::new(self.seed);
        let dt = 1.0 / self.rate_hz;
        let n = (duration * self.rate_hz).floor() as usize;
        let mut rows = Vec::with_capacity(n);
        let mut j = 0;
        for i in 0..n {
            let (a, b) = (i as f64 * dt, (i + 1) as f64 * dt);
            let (mut sw, mut st, mut k) = (0.0, 0.0, 0);
            while j < trace.len() && trace[j].0 <= b {
                if trace[j].0 > a {
                    sw += trace[j].1;
                    st += trace[j].2;
                    k += 1;
                }
                j += 1;
            }
            if k == 0 {
                continue;
            }
            let t = 0.5 * (a + b);
            let d = self.disturbance.map_or(0.0, |d| d.at(t));
            let tau = st / k as f64 + d + self.noise_nm * rng.normal();
            rows.push((
                (t * 1e4).round() / 1e4,
                ((sw / k as f64) * 1e4).round() / 1e4,
                (tau * 1e4).round() / 1e4,
                (temp_at(t) * 10.0).round() / 10.0,
            ));
        }
        for _ in 0..self.missing_rows.min(rows.len() / 10) {
            let span = rows.len().saturating_sub(10).max(1);
            let i = 5 + (rng.uniform() * span as f64) as usize;
            if i < rows.len() - 1 {
                rows.remove(i);
            }
        }
        Ok((
            rows.iter().map(|r| r.0).collect(),
            rows.iter().map(|r| r.1).collect(),
            rows.iter().map(|r| r.2).collect(),
            rows.iter().map(|r| r.3).collect(),
        ))
    }

    /// Write a dataset named `name` with this one scroll series into the new
    /// directory `dir` (never overwrites).
    pub fn write(&self, dir: &Path, name: &str) -> Result<()> {
        let (t_s, omega_rad_s, torque_nm, temp) = self.sample()?;
        let ds = Dataset {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            source: Some("synthetic (trackbelt synth --kind scroll)".into()),
            belt: belt_spec(&self.belt),
            statics: Vec::new(),
            dynamics: Vec::new(),
            scrolls: vec![dataset::ScrollEntry {
                label: Some("run-1".into()),
                drive_diameter_mm: self.config.drive_diameter_m * 1e3,
                idler_diameter_mm: self.config.idler_diameter_m * 1e3,
                center_distance_mm: (centre_distance_m(&self.belt, &self.config) * 1e4).round()
                    / 10.0,
                idler_force_n: Some(self.config.idler_force_n),
                series: dataset::ScrollSeries {
                    file: PathBuf::from("scroll-1.csv"),
                    t_s,
                    omega_rad_s,
                    torque_nm,
                    belt_temp_c: Some(temp),
                },
            }],
            warnings: Vec::new(),
        };
        Ok(dataset::write(&ds, dir)?)
    }
}

/// The dataset's `[belt]` for the simulated belt: its size and mass, and
/// one grouser per link (the link count the diagnosis reads back).
fn belt_spec(b: &trackbelt::params::Belt<f64>) -> BeltSpec {
    let length_mm = b.length_m * 1e3;
    BeltSpec {
        length_mm,
        width_mm: b.width_m * 1e3,
        thickness_mm: b.thickness_m * 1e3,
        mass_kg: b.mass_kg,
        grousers: u32::try_from(b.links).ok(),
        grouser_pitch_mm: Some((length_mm / b.links as f64 * 10.0).round() / 10.0),
    }
}

/// The nominal centre distance of the two-wheel rig, m: the open-belt
/// length `2·√(C² − (R₁−R₂)²) + π(R₁+R₂) + 2(R₁−R₂)·asin((R₁−R₂)/C)` on the
/// belt's mid-plane (pitch radii `R = D/2 + thickness/2`) equal to the belt
/// length, solved by bisection (the rig's simulation settles the idler
/// itself; this is the figure a bench sheet would give).
fn centre_distance_m(b: &trackbelt::params::Belt<f64>, c: &trackbelt::rig::RigConfig<f64>) -> f64 {
    let r1 = 0.5 * (c.drive_diameter_m + b.thickness_m);
    let r2 = 0.5 * (c.idler_diameter_m + b.thickness_m);
    let dr = r1 - r2;
    let length = |cd: f64| {
        2.0 * (cd * cd - dr * dr).max(0.0).sqrt()
            + std::f64::consts::PI * (r1 + r2)
            + 2.0 * dr * (dr / cd).clamp(-1.0, 1.0).asin()
    };
    let (mut lo, mut hi) = (dr.abs() + 1e-9, b.length_m.max(1e-6));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if length(mid) < b.length_m {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
