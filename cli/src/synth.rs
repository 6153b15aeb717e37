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

use crate::dataset::{self, BeltSpec, Dataset, DynamicEntry, DynamicSeries};
use crate::diagnose::{Baseline, EffectKind};
use std::path::{Path, PathBuf};
use trackbelt::bench::{self, DynamicTest};
use trackbelt::stiffness::JointLaw;
use trackbelt::{ReferenceChain, Settings};

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
    /// Number of links of the simulation.
    pub links: usize,
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
        let mut law = crate::diagnose::scale_stiffness(&baseline.law, 1.04);
        law.damping *= 0.9;
        DynamicSynth {
            law,
            links: baseline.links,
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
    pub fn sample(&self) -> Result<(Vec<f64>, Vec<f64>), String> {
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
        let trace = simulate_height(&self.law, self.links, self.roller_kg, self.duration_s)?;
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
    pub fn write(&self, dir: &Path, name: &str) -> Result<(), String> {
        let (t_s, a_height_mm) = self.sample()?;
        let ds = Dataset {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            source: Some("synthetic (trackbelt synth)".into()),
            belt: BeltSpec {
                length_mm: 2450.0,
                width_mm: 160.0,
                thickness_mm: 8.0,
                mass_kg: 6.4,
                grousers: Some(38),
                grouser_pitch_mm: Some(64.5),
            },
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
        dataset::write(&ds, dir).map_err(|e| e.to_string())
    }
}

/// A's height (mm) against time (s) in the dynamic test of `law`: static
/// settle, roller on, `duration_s` of motion.
pub fn simulate_height(
    law: &JointLaw<f64>,
    links: usize,
    roller_kg: f64,
    duration_s: f64,
) -> Result<Vec<(f64, f64)>, String> {
    let model = crate::sim::model_for(links, law.clone()).map_err(|e| e.to_string())?;
    let mut chain =
        Box::new(ReferenceChain::new(model, Settings::default()).map_err(|e| e.to_string())?);
    bench::static_test(&mut *chain).map_err(|e| e.to_string())?;
    let mut trace = Vec::with_capacity(4096);
    let test = DynamicTest {
        roller_kg,
        duration_s,
    };
    bench::dynamic_test(&mut *chain, &test, |c| {
        trace.push((c.time_s(), c.a_height_m() * 1e3))
    })
    .map_err(|e| e.to_string())?;
    Ok(trace)
}

/// Linear interpolation of a trace (times increasing) at `times`; the ends
/// are held.
pub fn interpolate(trace: &[(f64, f64)], times: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(times.len());
    let mut i = 0;
    for &t in times {
        while i + 1 < trace.len() && trace[i + 1].0 < t {
            i += 1;
        }
        let v = match (trace.get(i), trace.get(i + 1)) {
            (Some(&(t0, y0)), Some(&(t1, y1))) if t1 > t0 => {
                let w = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                y0 + w * (y1 - y0)
            }
            (Some(&(_, y0)), _) => y0,
            _ => f64::NAN,
        };
        out.push(v);
    }
    out
}
