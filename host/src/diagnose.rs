//! Closing the loop with measured data (SPEC §5, `trackbelt diagnose`).
//!
//! For every dynamic series of a dataset:
//!
//! 1. **Baseline fit.** The baseline law (the calibrated method III table of
//!    the variant, see [`baseline`]) is refitted to the series with three
//!    parameters: a stiffness scale `s` (the whole torque–angle curve times
//!    `s`), the linear damping `cz`, and the camera's height offset (solved in
//!    closed form). Levenberg–Marquardt, one simulation per evaluation.
//!    Residual = measured − model.
//! 2. **Trace.** The residual's structure is described with the signatures
//!    engineers use: the per-cycle log decrement and period against the
//!    amplitude (peak-based, from the measured extrema about the settled
//!    height), the noise floor (robust estimate from third differences of
//!    the residual: white noise of σ gives differences of σ·√20, an
//!    oscillation at 1–2 Hz sampled at 25 Hz is attenuated 30-fold) and the
//!    lag-1 autocorrelation of the residual.
//! 3. **Candidates.** Each dynamic effect of the catalogue
//!    ([`EffectKind::DYNAMIC`]) is added to the model and refitted (`s`, `cz`,
//!    offset and the effect's magnitude). Candidates are compared with the
//!    Bayesian information criterion `BIC = n·ln(RSS/n) + k·ln n`, which
//!    charges every added parameter.
//!    When a candidate fits much better than the baseline, the baseline is
//!    refitted from that candidate's stiffness scale and cz (its first fit
//!    may have stopped in a local minimum), and the noise floor is taken from
//!    the best-fitting model's residual: the difference estimate, or that
//!    residual's RMS when it is larger and the residual is white
//!    ([`WHITE_LAG1`]; the difference estimate scatters by 10–20 % on 6 s).
//! 4. **Decision.** `none` when no candidate lowers the BIC by at least
//!    [`BIC_MARGIN`] and the baseline residual is at the noise floor
//!    (RMS ≤ [`FLOOR_FACTOR`] × floor); the best candidate's identifier when
//!    it lowers the BIC by at least [`BIC_MARGIN`], brings the residual to
//!    the noise floor, and beats the runner-up by at least [`BIC_SEPARATION`];
//!    otherwise `unexplained` (structured, but no single candidate explains
//!    it, or two explain it equally well). A wrong name is never forced.
//!
//! Datasets that hold only summary figures (like `shredder-table1`) get one
//! row comparing the baseline's figures with the measured means against the
//! run-to-run spread: `none` when every figure is inside it, `unexplained`
//! otherwise (summary figures cannot tell the effects apart).

use crate::dataset::{self, Dataset};
use crate::fit::{levenberg_marquardt, Options};
use crate::params_file::ParamsFile;
use crate::synth::{interpolate, simulate_height};
use serde::Serialize;
use std::path::{Path, PathBuf};
use trackbelt::effects::JointFriction;
use trackbelt::joint::JointLaw;
use trackbelt::params::Variant;
use trackbelt::stiffness::{Stiffness, TorqueTable};

/// Lowest BIC improvement that counts as evidence for a candidate.
pub const BIC_MARGIN: f64 = 10.0;
/// Lowest BIC gap between the best and the second-best candidate for a name.
pub const BIC_SEPARATION: f64 = 4.0;
/// A residual whose RMS is at most this multiple of the noise floor is
/// "at the noise floor".
pub const FLOOR_FACTOR: f64 = 1.25;

/// A residual whose lag-1 autocorrelation is below this in magnitude counts
/// as white (dynamic series).
pub const WHITE_LAG1: f64 = 0.3;

/// The effects of `DATA.md`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EffectKind {
    /// Coulomb friction in the joints.
    JointFriction,
    /// Damping growing with the square of the joint speed.
    QuadraticDamping,
    /// Stiffness changing with the bending amplitude.
    AmplitudeStiffness,
    /// Power-law joint damping.
    RateDependentDamping,
    /// Stiffness and damping falling as the belt warms.
    ThermalSoftening,
    /// Constant resisting torque at the rig's wheel axles.
    BearingFriction,
}

impl EffectKind {
    /// All effects, in the order of `DATA.md`.
    pub const ALL: [EffectKind; 6] = [
        EffectKind::JointFriction,
        EffectKind::QuadraticDamping,
        EffectKind::AmplitudeStiffness,
        EffectKind::BearingFriction,
        EffectKind::RateDependentDamping,
        EffectKind::ThermalSoftening,
    ];

    /// The effects that show in a dynamic (roller) test.
    pub const DYNAMIC: [EffectKind; 3] = [
        EffectKind::JointFriction,
        EffectKind::QuadraticDamping,
        EffectKind::AmplitudeStiffness,
    ];

    /// Identifier as in `DATA.md` and the JSON output.
    pub const fn id(self) -> &'static str {
        match self {
            EffectKind::JointFriction => "joint_friction",
            EffectKind::QuadraticDamping => "quadratic_damping",
            EffectKind::AmplitudeStiffness => "amplitude_stiffness",
            EffectKind::RateDependentDamping => "rate_dependent_damping",
            EffectKind::ThermalSoftening => "thermal_softening",
            EffectKind::BearingFriction => "bearing_friction",
        }
    }

    /// Parse an identifier.
    pub fn parse(s: &str) -> Option<EffectKind> {
        EffectKind::ALL.into_iter().find(|e| e.id() == s)
    }

    /// The parameter the fit adjusts, at magnitude 1 (for E38; joint terms
    /// scale with the link count like the stiffness does), with its unit.
    pub fn nominal(self) -> (f64, &'static str) {
        match self {
            EffectKind::JointFriction => (0.02, "N·m per joint"),
            EffectKind::QuadraticDamping => (0.3, "N·m·s²/rad²"),
            EffectKind::AmplitudeStiffness => (3.0, "N·m/rad³"),
            EffectKind::RateDependentDamping => (0.1, "N·m·(s/rad)^0.5"),
            EffectKind::ThermalSoftening => (0.005, "1/K"),
            EffectKind::BearingFriction => (0.5, "N·m"),
        }
    }

    /// `law` with this effect switched on at `magnitude` times its nominal
    /// size (replacing any earlier setting of the same effect).
    pub fn apply(self, law: &JointLaw<f64>, magnitude: f64) -> JointLaw<f64> {
        let mut out = law.clone();
        let x = self.nominal().0 * magnitude;
        let e = &mut out.effects;
        match self {
            EffectKind::JointFriction => {
                e.joint_friction = Some(JointFriction {
                    torque_nm: x.max(0.0),
                    smoothing_rad_s: 0.01,
                })
            }
            EffectKind::QuadraticDamping => e.quadratic_damping = Some(x.max(0.0)),
            EffectKind::AmplitudeStiffness => e.amplitude_stiffness = Some(x),
            EffectKind::RateDependentDamping => {
                e.rate_dependent_damping = Some(trackbelt::effects::RateDamping {
                    coefficient: x.max(0.0),
                    exponent: 0.5,
                    smoothing_rad_s: 0.01,
                })
            }
            EffectKind::ThermalSoftening => {
                e.thermal_softening = Some(trackbelt::effects::ThermalSoftening {
                    alpha_per_k: x,
                    reference_temp_c: 20.0,
                    temp_c: 20.0,
                })
            }
            // Not a joint term: the rig's configuration carries it.
            EffectKind::BearingFriction => {}
        }
        out
    }

    /// Bounds of the magnitude in the fit.
    fn bounds(self) -> (f64, f64) {
        match self {
            EffectKind::AmplitudeStiffness => (-10.0, 10.0),
            _ => (0.0, 20.0),
        }
    }
}

/// The baseline model of a dataset.
#[derive(Debug, Clone)]
pub struct Baseline {
    /// Joint law (no effects).
    pub law: JointLaw<f64>,
    /// Number of links.
    pub links: usize,
    /// Where the law came from.
    pub source: String,
}

/// Placeholder method III table for E38 used until calibrated files ship
/// (angles in degrees, torques in N·mm; Z1/Z2/Z3 shape of the paper's
/// Figs. 9–10), with cz = 360 N·mm·s/rad.
pub const PLACEHOLDER_E38: ([f64; 6], [f64; 6], f64) = (
    [-45.0, -30.0, -6.0, 0.0, 3.0, 13.0],
    [-14000.0, -4300.0, -1000.0, 0.0, 1600.0, 12000.0],
    360.0,
);

/// The baseline law for `variant`: the params file given, else the shipped
/// `params/<variant>.toml` (looked up in the current directory and in the
/// source tree), else the built-in placeholder table scaled from E38 (angles
/// by 38/N, cz by N/38).
pub fn baseline(variant: Variant, params: Option<&Path>) -> Result<Baseline, String> {
    let candidates: Vec<PathBuf> = match params {
        Some(p) => vec![p.to_path_buf()],
        None => {
            let file = format!("{}.toml", variant.name());
            vec![
                Path::new("params").join(&file),
                Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("..")
                    .join("params")
                    .join(&file),
            ]
        }
    };
    for p in &candidates {
        if params.is_some() || p.is_file() {
            let (_, law) = ParamsFile::load(p)?;
            return Ok(Baseline {
                law,
                links: variant.links(),
                source: p.display().to_string(),
            });
        }
    }
    let n = variant.links() as f64;
    let (a, t, cz) = PLACEHOLDER_E38;
    let angles: Vec<f64> = a.iter().map(|d| d.to_radians() * 38.0 / n).collect();
    let torques: Vec<f64> = t.iter().map(|x| x * 1e-3).collect();
    let table = TorqueTable::new(&angles, &torques).map_err(|e| e.to_string())?;
    let law =
        JointLaw::new(Stiffness::Table(table), cz * 1e-3 * n / 38.0).map_err(|e| e.to_string())?;
    Ok(Baseline {
        law,
        links: variant.links(),
        source: "built-in placeholder method III table (no params file found)".into(),
    })
}

/// `law` with its whole stiffness curve multiplied by `s`.
pub fn scale_stiffness(law: &JointLaw<f64>, s: f64) -> JointLaw<f64> {
    let mut out = law.clone();
    out.stiffness = match &law.stiffness {
        Stiffness::Constant { kz } => Stiffness::Constant { kz: kz * s },
        Stiffness::Bivalent { kz_pos, kz_neg } => Stiffness::Bivalent {
            kz_pos: kz_pos * s,
            kz_neg: kz_neg * s,
        },
        Stiffness::Table(t) => {
            let torques: Vec<f64> = t.torques_nm().iter().map(|x| x * s).collect();
            match TorqueTable::new(t.angles_rad(), &torques) {
                Ok(t) => Stiffness::Table(t),
                Err(_) => law.stiffness.clone(),
            }
        }
    };
    out
}

/// One fitted model of a series.
#[derive(Debug, Clone, Serialize)]
pub struct Fitted {
    /// `baseline` or an effect identifier.
    pub model: String,
    /// Stiffness scale against the baseline table.
    pub stiffness_scale: f64,
    /// Linear damping, N·m·s/rad.
    pub cz_nms_per_rad: f64,
    /// Camera height offset, mm.
    pub offset_mm: f64,
    /// Effect magnitude in its unit (see [`EffectKind::nominal`]), if any.
    pub effect_value: Option<f64>,
    /// RMS residual, mm.
    pub rms: f64,
    /// Bayesian information criterion.
    pub bic: f64,
    /// Fitted parameters.
    pub k: usize,
    /// Simulations spent.
    pub evaluations: usize,
    /// Model height at the sample times, mm.
    #[serde(skip)]
    pub model_values: Vec<f64>,
    /// Residual (measured − model), mm.
    #[serde(skip)]
    pub residual: Vec<f64>,
}

/// One cycle of the oscillation about the settled height.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Cycle {
    /// Time of the cycle's first extremum, s.
    pub time_s: f64,
    /// Mean amplitude over the cycle, mm.
    pub amplitude_mm: f64,
    /// Time between the extrema one cycle apart, s.
    pub period_s: f64,
    /// `ln(A_i / A_{i+2})` over one cycle.
    pub log_decrement: f64,
}

impl Fitted {
    /// Sum of squared residuals, mm².
    pub fn sum_sq(&self) -> f64 {
        self.residual.iter().map(|x| x * x).sum()
    }
}

/// The signatures of a signal's decay.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Signature {
    /// Per-cycle figures.
    pub cycles: Vec<Cycle>,
}

impl Signature {
    fn describe(&self) -> String {
        let c = &self.cycles;
        match (c.first(), c.last()) {
            (Some(a), Some(b)) if c.len() >= 2 => format!(
                "per cycle, as the amplitude falls {:.0}→{:.0} mm: log decrement {:.2}→{:.2}, period {:.3}→{:.3} s",
                a.amplitude_mm, b.amplitude_mm, a.log_decrement, b.log_decrement, a.period_s, b.period_s
            ),
            _ => "fewer than two cycles above the noise".into(),
        }
    }
}

/// Per-cycle signatures of `h` (mm) at `t` (s) about `settled` (mm), using
/// only extrema at least `min_amp` (mm) from it. Extrema are the samples
/// furthest from `settled` between its crossings, refined by a parabola.
pub fn signature(t: &[f64], h: &[f64], settled: f64, min_amp: f64) -> Signature {
    // Half-cycles: runs of samples on one side of the settled height
    // (with hysteresis min_amp/2 to ignore noise-level crossings).
    let mut ext: Vec<(f64, f64)> = Vec::new(); // (time, signed amplitude)
    let mut side = 0i32;
    let mut best: Option<usize> = None;
    for i in 0..h.len() {
        let d = h[i] - settled;
        let s = if d > 0.5 * min_amp {
            1
        } else if d < -0.5 * min_amp {
            -1
        } else {
            0
        };
        if s != 0 && s != side {
            if let Some(b) = best {
                ext.push(refine(t, h, b, settled));
            }
            side = s;
            best = Some(i);
        } else if s == side && s != 0 {
            if let Some(b) = best {
                if (h[i] - settled).abs() > (h[b] - settled).abs() {
                    best = Some(i);
                }
            }
        }
    }
    if let Some(b) = best {
        // The last run counts only if the signal turned back within it.
        if b + 1 < h.len() {
            ext.push(refine(t, h, b, settled));
        }
    }
    // Skip the start: the roller is released at rest at a maximum.
    let ext: Vec<(f64, f64)> = ext
        .into_iter()
        .skip_while(|&(tt, _)| tt < 0.05)
        .filter(|&(_, a)| a.abs() >= min_amp)
        .collect();
    let mut cycles = Vec::new();
    for w in ext.windows(3) {
        let (a0, a2) = (w[0].1.abs(), w[2].1.abs());
        if w[0].1.signum() != w[2].1.signum() || a2 <= 0.0 {
            continue;
        }
        cycles.push(Cycle {
            time_s: w[0].0,
            amplitude_mm: (a0 * a2).sqrt(),
            period_s: w[2].0 - w[0].0,
            log_decrement: (a0 / a2).ln(),
        });
    }
    Signature { cycles }
}

fn refine(t: &[f64], h: &[f64], i: usize, settled: f64) -> (f64, f64) {
    if i == 0 || i + 1 >= h.len() {
        return (t[i], h[i] - settled);
    }
    let (t0, t1, t2) = (t[i - 1], t[i], t[i + 1]);
    let (y0, y1, y2) = (h[i - 1], h[i], h[i + 1]);
    let d0 = t0 - t1;
    let d2 = t2 - t1;
    let s0 = (y0 - y1) / d0;
    let s2 = (y2 - y1) / d2;
    let a = (s0 - s2) / (d0 - d2);
    let b = s0 - a * d0;
    if a == 0.0 || !a.is_finite() {
        return (t1, y1 - settled);
    }
    let tau = (-b / (2.0 * a)).clamp(d0, d2);
    (t1 + tau, y1 + b * tau + a * tau * tau - settled)
}

/// Robust noise floor of a residual sampled at (nearly) uniform times:
/// RMS of `Δ³r` over runs without gaps (differences beyond 4× the
/// median-based scale dropped), divided by √20.
pub fn noise_floor(t: &[f64], r: &[f64]) -> f64 {
    if t.len() < 8 {
        return f64::NAN;
    }
    let mut dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dts.sort_by(f64::total_cmp);
    let dt = dts[dts.len() / 2];
    let mut d3 = Vec::new();
    for i in 0..r.len().saturating_sub(3) {
        let uniform = (1..=3).all(|k| (t[i + k] - t[i + k - 1] - dt).abs() < 0.25 * dt);
        if uniform {
            d3.push((r[i + 3] - 3.0 * r[i + 2] + 3.0 * r[i + 1] - r[i]).abs());
        }
    }
    if d3.len() < 5 {
        return f64::NAN;
    }
    // Robust start (median), then the efficient estimate (RMS) over the
    // differences within 4 σ of it: the median alone scatters by ~10 % on a
    // 6 s record; the clipping keeps steps and spikes out.
    let mut sorted = d3.clone();
    sorted.sort_by(f64::total_cmp);
    let s0 = 1.4826 * sorted[sorted.len() / 2];
    let kept: Vec<f64> = d3.into_iter().filter(|x| *x <= 4.0 * s0).collect();
    if kept.len() < 5 {
        return s0 / 20f64.sqrt();
    }
    (kept.iter().map(|x| x * x).sum::<f64>() / kept.len() as f64).sqrt() / 20f64.sqrt()
}

/// Lag-1 autocorrelation of `r`.
pub fn lag1(r: &[f64]) -> f64 {
    let n = r.len() as f64;
    let m = r.iter().sum::<f64>() / n;
    let v: f64 = r.iter().map(|x| (x - m).powi(2)).sum();
    let c: f64 = r.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum();
    if v > 0.0 {
        c / v
    } else {
        0.0
    }
}

fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64).sqrt()
}

fn bic(r: &[f64], k: usize) -> f64 {
    let n = r.len() as f64;
    let rss = r.iter().map(|x| x * x).sum::<f64>().max(1e-300);
    n * (rss / n).ln() + k as f64 * n.ln()
}

/// Fit the baseline (`effect = None`) or baseline + one effect to a series.
/// `start` is `[ln s, ln(cz/cz₀)]` (and the effect magnitude, if any).
pub fn fit_dynamic(
    base: &Baseline,
    roller_kg: f64,
    t: &[f64],
    h: &[f64],
    effect: Option<EffectKind>,
    start: &[f64],
    on_eval: &mut dyn FnMut(),
) -> Result<Fitted, String> {
    let duration = t.last().copied().unwrap_or(1.0).max(0.5) + 0.02;
    let cz0 = base.law.damping.max(1e-6);
    let law_of = |p: &[f64]| {
        let mut law = scale_stiffness(&base.law, p[0].exp());
        law.damping = cz0 * p[1].exp();
        if let (Some(e), Some(&m)) = (effect, p.get(2)) {
            law = e.apply(&law, m);
        }
        law
    };
    let model_of = |p: &[f64]| -> Result<(Vec<f64>, f64), String> {
        let trace = simulate_height(&law_of(p), base.links, roller_kg, duration)?;
        let m = interpolate(&trace, t);
        let off = h.iter().zip(&m).map(|(a, b)| a - b).sum::<f64>() / h.len() as f64;
        Ok((m, off))
    };
    let mut bounds = vec![(0.5f64.ln(), 2.0f64.ln()), (0.05f64.ln(), 20f64.ln())];
    if let Some(e) = effect {
        bounds.push(e.bounds());
    }
    let res = levenberg_marquardt(
        |p: &[f64]| {
            on_eval();
            // A diverging trial is a bad point, not a failure of the fit.
            match model_of(p) {
                Ok((m, off)) => Ok(h.iter().zip(&m).map(|(a, b)| a - b - off).collect()),
                Err(_) => Ok::<_, String>(vec![1e3; h.len()]),
            }
        },
        start,
        &bounds,
        &Options {
            max_iterations: 10,
            rel_tol: 1e-3,
            fd_step: 2e-3,
            max_evaluations: 45,
        },
    )?;
    let (m, off) = model_of(&res.params)?;
    let residual: Vec<f64> = h.iter().zip(&m).map(|(a, b)| a - b - off).collect();
    let k = 3 + usize::from(effect.is_some());
    let law = law_of(&res.params);
    Ok(Fitted {
        model: effect.map_or("baseline".into(), |e| e.id().into()),
        stiffness_scale: res.params[0].exp(),
        cz_nms_per_rad: law.damping,
        offset_mm: off,
        effect_value: effect.map(|e| e.nominal().0 * res.params[2]),
        rms: rms(&residual),
        bic: bic(&residual, k),
        k,
        evaluations: res.evaluations,
        model_values: m.iter().map(|x| x + off).collect(),
        residual,
    })
}

/// One row of the JSON report (SPEC §6).
#[derive(Debug, Clone, Serialize)]
pub struct ResultRow {
    /// The series' label or file.
    pub series: String,
    /// "dynamic" or "scroll".
    pub kind: String,
    /// Effect identifier, `none` or `unexplained`.
    pub effect: String,
    /// RMS residual of the refitted baseline.
    pub rms_before: f64,
    /// RMS residual of the refitted extended model (the baseline's for
    /// `none`/`unexplained`).
    pub rms_after: f64,
    /// Unit of the residuals.
    pub unit: String,
    /// Short reason.
    pub evidence: String,
}

/// `diagnose --json` document.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Dataset name.
    pub dataset: String,
    /// One row per series (or per summary).
    pub results: Vec<ResultRow>,
}

/// Everything found for one dynamic series (for the report and plots).
#[derive(Debug, Clone)]
pub struct SeriesDiagnosis {
    /// The JSON row.
    pub row: ResultRow,
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// Measured height, mm.
    pub measured_mm: Vec<f64>,
    /// Baseline fit.
    pub baseline: Fitted,
    /// Candidate fits.
    pub candidates: Vec<Fitted>,
    /// Index of the chosen candidate, if an effect was named.
    pub chosen: Option<usize>,
    /// Noise floor, mm.
    pub noise_mm: f64,
    /// Signatures of the measurement, the baseline and the chosen (or best)
    /// model.
    pub signatures: [Signature; 3],
}

/// Diagnose one dynamic series.
pub fn diagnose_dynamic(
    base: &Baseline,
    label: &str,
    roller_kg: f64,
    t: &[f64],
    h: &[f64],
    on_eval: &mut dyn FnMut(),
) -> Result<SeriesDiagnosis, String> {
    if t.len() < 25 {
        return Err(format!(
            "series {label}: {} samples; the diagnosis needs at least 25 (1 s at 25 Hz)",
            t.len()
        ));
    }
    let mut b = fit_dynamic(base, roller_kg, t, h, None, &[0.0, 0.0], on_eval)?;
    let mut noise = noise_floor(t, &b.residual);
    let start = [
        b.stiffness_scale.ln(),
        (b.cz_nms_per_rad / base.law.damping).ln(),
    ];
    let mut cands = Vec::new();
    for e in EffectKind::DYNAMIC {
        // Start from the baseline fit with a small effect; when that does
        // not reach the noise floor, also from the table as shipped with a
        // clear effect of either sign (the cubic stiffness trades off
        // against the stiffness scale, which leaves local minima).
        let starts: Vec<[f64; 3]> = match e {
            EffectKind::AmplitudeStiffness => vec![
                [start[0], start[1], 0.0],
                [0.0, start[1], 3.0],
                [0.0, start[1], -3.0],
            ],
            _ => vec![[start[0], start[1], 0.1], [0.0, start[1], 2.0]],
        };
        let mut best: Option<Fitted> = None;
        for s0 in starts {
            let f = fit_dynamic(base, roller_kg, t, h, Some(e), &s0, on_eval)?;
            let done = f.rms <= FLOOR_FACTOR * noise;
            if best.as_ref().is_none_or(|b| f.sum_sq() < b.sum_sq()) {
                best = Some(f);
            }
            if done {
                break;
            }
        }
        if let Some(b) = best {
            cands.push(b);
        }
    }
    // The baseline fit can stop in a local minimum (a candidate whose effect
    // went to zero then fits better than the baseline): refit the baseline
    // from the best candidate's stiffness scale and cz, and take the noise
    // floor from the best fit found (least structure left in it).
    if let Some(c) = cands
        .iter()
        .min_by(|x, y| x.sum_sq().total_cmp(&y.sum_sq()))
    {
        if c.sum_sq() < 0.8 * b.sum_sq() {
            let s0 = [
                c.stiffness_scale.ln(),
                (c.cz_nms_per_rad / base.law.damping.max(1e-6)).ln(),
            ];
            let b2 = fit_dynamic(base, roller_kg, t, h, None, &s0, on_eval)?;
            if b2.sum_sq() < b.sum_sq() {
                b = b2;
            }
        }
        noise = noise_floor(t, &c.residual).min(noise_floor(t, &b.residual));
        // On a 6 s record the difference estimate scatters by ±10–20 %; when
        // the best fit's residual is white (|lag-1 autocorrelation| < 0.3,
        // about 3.5/√n), its RMS is the better estimate of the floor.
        let best = if c.sum_sq() < b.sum_sq() { c } else { &b };
        if lag1(&best.residual).abs() < WHITE_LAG1 {
            noise = noise.max(best.rms);
        }
    }
    let settled = b.model_values.last().copied().unwrap_or(f64::NAN);
    let min_amp = (4.0 * noise).max(1.0);
    let shown = cands
        .iter()
        .min_by(|x, y| x.bic.total_cmp(&y.bic))
        .map_or(&b.model_values, |f| &f.model_values);
    let sig_meas = signature(t, h, settled, min_amp);
    let sig_base = signature(t, &b.model_values, settled, min_amp);
    let sig_best = signature(t, shown, settled, min_amp);
    let (effect, chosen, rms_after, why) = decide(&b, &cands, noise, "mm", BIC_SEPARATION);
    let evidence = format!("{why}; measured {}", sig_meas.describe());
    Ok(SeriesDiagnosis {
        row: ResultRow {
            series: label.to_string(),
            kind: "dynamic".into(),
            effect,
            rms_before: b.rms,
            rms_after,
            unit: "mm".into(),
            evidence,
        },
        t_s: t.to_vec(),
        measured_mm: h.to_vec(),
        baseline: b,
        candidates: cands,
        chosen,
        noise_mm: noise,
        signatures: [sig_meas, sig_base, sig_best],
    })
}

/// The decision rule of the module documentation: `(effect, index of the
/// chosen candidate, rms_after, reason)`.
/// `separation` is the BIC gap the best candidate needs over the runner-up
/// ([`BIC_SEPARATION`] for dynamic series).
pub fn decide(
    b: &Fitted,
    cands: &[Fitted],
    noise: f64,
    unit: &str,
    separation: f64,
) -> (String, Option<usize>, f64, String) {
    let mut order: Vec<usize> = (0..cands.len()).collect();
    order.sort_by(|&i, &j| cands[i].bic.total_cmp(&cands[j].bic));
    let Some(&first) = order.first() else {
        return (
            if b.rms <= FLOOR_FACTOR * noise {
                "none"
            } else {
                "unexplained"
            }
            .into(),
            None,
            b.rms,
            format!(
                "no candidate applies; baseline residual {:.3} {unit}, noise floor {:.3} {unit}",
                b.rms, noise
            ),
        );
    };
    let best = &cands[first];
    let second = order.get(1).map(|&i| &cands[i]);
    let gain = b.bic - best.bic;
    let sep = second.map_or(f64::INFINITY, |s| s.bic - best.bic);
    let at_floor = |r: f64| r <= FLOOR_FACTOR * noise;
    let ratio_before = b.rms / noise;
    if gain < BIC_MARGIN && at_floor(b.rms) {
        (
            "none".to_string(),
            None,
            b.rms,
            format!(
                "baseline residual {:.3} {unit} is at the noise floor {:.3} {unit} (×{:.2}, lag-1 autocorrelation {:.2}); best candidate {} lowers BIC by only {:.1}",
                b.rms, noise, ratio_before, lag1(&b.residual), best.model, gain
            ),
        )
    } else if gain >= BIC_MARGIN && at_floor(best.rms) && sep >= separation {
        (
            best.model.clone(),
            Some(first),
            best.rms,
            format!(
                "{} lowers BIC by {:.1} (runner-up {}: {:.1}); residual {:.3} → {:.3} {unit}, noise floor {:.3} {unit}; fitted {} = {:.4} {}",
                best.model,
                gain,
                second.map_or("-", |s| s.model.as_str()),
                second.map_or(f64::NAN, |s| b.bic - s.bic),
                b.rms,
                best.rms,
                noise,
                best.model,
                best.effect_value.unwrap_or(f64::NAN),
                EffectKind::parse(&best.model).map_or("", |e| e.nominal().1)
            ),
        )
    } else {
        let reason = if gain >= BIC_MARGIN && at_floor(best.rms) {
            format!(
                "{} and {} explain it about equally well (BIC gap {:.1})",
                best.model,
                second.map_or("-", |s| s.model.as_str()),
                sep
            )
        } else {
            format!(
                "best candidate {} leaves {:.3} {unit} (×{:.2} the noise floor {:.3} {unit}, lag-1 autocorrelation {:.2})",
                best.model,
                best.rms,
                best.rms / noise,
                noise,
                lag1(&best.residual)
            )
        };
        (
            "unexplained".to_string(),
            None,
            b.rms,
            format!(
                "structured residual: baseline {:.3} {unit} (×{:.2} the noise floor); {reason}",
                b.rms, ratio_before
            ),
        )
    }
}

/// Number of simulations [`diagnose_dynamic`] may spend per series (an
/// upper bound for a progress bar).
pub const EVALS_PER_DYNAMIC_SERIES: u64 = 9 * 46;

/// Summary-figure comparison for datasets without series.
pub fn diagnose_summary(base: &Baseline, ds: &Dataset) -> Result<Option<ResultRow>, String> {
    let means = ds.dynamic_means();
    let stat = ds.static_mean();
    if stat.is_none() && means.hd_mm.is_none() && means.period_s.is_none() {
        return Ok(None);
    }
    let model = crate::sim::model_for(base.links, base.law.clone()).map_err(|e| e.to_string())?;
    let roller = ds.dynamics.first().map_or(1.3, |d| d.roller_kg);
    let mut chain = Box::new(
        trackbelt::ReferenceChain::new(model, trackbelt::Settings::default())
            .map_err(|e| e.to_string())?,
    );
    let st = trackbelt::bench::static_test(&mut *chain).map_err(|e| e.to_string())?;
    let dy = trackbelt::bench::dynamic_test(
        &mut *chain,
        &trackbelt::bench::DynamicTest {
            roller_kg: roller,
            duration_s: 5.0,
        },
        |_| {},
    )
    .map_err(|e| e.to_string())?;
    // (name, measured values, model value)
    let spread = |vals: Vec<f64>| -> (f64, f64) {
        let n = vals.len() as f64;
        let m = vals.iter().sum::<f64>() / n;
        let sd = if vals.len() > 1 {
            (vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            0.0
        };
        (m, sd)
    };
    let mut figs: Vec<(&str, Vec<f64>, Option<f64>)> = vec![
        (
            "Hs",
            ds.statics.iter().map(|s| s.hs_mm).collect(),
            Some(st.hs_mm),
        ),
        (
            "Ws",
            ds.statics.iter().map(|s| s.ws_mm).collect(),
            Some(st.ws_mm),
        ),
    ];
    figs.push((
        "Hd",
        ds.dynamics.iter().filter_map(|d| d.hd_mm).collect(),
        Some(dy.hd_mm),
    ));
    figs.push((
        "Wd",
        ds.dynamics.iter().filter_map(|d| d.wd_mm).collect(),
        Some(dy.wd_mm),
    ));
    figs.push((
        "T",
        ds.dynamics.iter().filter_map(|d| d.period_s).collect(),
        dy.period_s,
    ));
    figs.push((
        "Λ",
        ds.dynamics.iter().filter_map(|d| d.log_decrement).collect(),
        dy.log_decrement,
    ));
    let mut errs = Vec::new();
    let mut outside = Vec::new();
    let mut parts = Vec::new();
    for (name, vals, model) in figs {
        if vals.is_empty() {
            continue;
        }
        let (m, sd) = spread(vals);
        let Some(model) = model else {
            outside.push(format!("{name}: model has no value"));
            continue;
        };
        let rel = 100.0 * (model - m) / m;
        errs.push(rel);
        // Inside when within 2 standard deviations of the runs (at least 2 %).
        let tol = (2.0 * sd).max(0.02 * m.abs());
        parts.push(format!("{name} {model:.3}/{m:.3} ({rel:+.1} %)"));
        if (model - m).abs() > tol {
            outside.push(format!(
                "{name} off by {rel:+.1} % (run spread ±{:.1} %)",
                100.0 * tol / m
            ));
        }
    }
    let r = rms(&errs);
    let (effect, why) = if outside.is_empty() {
        (
            "none",
            "every summary figure of the baseline is inside the run-to-run spread".to_string(),
        )
    } else {
        (
            "unexplained",
            format!(
                "{}; summary figures alone cannot tell the candidate effects apart (no time series to refit)",
                outside.join(", ")
            ),
        )
    };
    Ok(Some(ResultRow {
        series: format!(
            "summary ({} static, {} dynamic entries)",
            ds.statics.len(),
            ds.dynamics.len()
        ),
        kind: "dynamic".into(),
        effect: effect.into(),
        rms_before: r,
        rms_after: r,
        unit: "%".into(),
        evidence: format!("model/measured mean: {}; {why}", parts.join(", ")),
    }))
}

/// The whole diagnosis of a dataset directory.
pub struct Diagnosis {
    /// The JSON document.
    pub report: Report,
    /// Per dynamic series details.
    pub series: Vec<SeriesDiagnosis>,
    /// Per scroll series details.
    pub scrolls: Vec<crate::diagnose_scroll::ScrollDiagnosis>,
    /// Where the baseline came from.
    pub baseline_source: String,
    /// Warnings of the dataset reader.
    pub warnings: Vec<String>,
}

/// Load `dir` and diagnose every series in it. `on_start(most simulations)`
/// is called first, then `on_eval` once per simulation (for a progress bar).
pub fn diagnose_dir(
    dir: &Path,
    variant: Variant,
    params: Option<&Path>,
    on_start: &mut dyn FnMut(u64),
    on_eval: &mut dyn FnMut(),
) -> Result<Diagnosis, String> {
    let ds = dataset::load(dir).map_err(|e| e.to_string())?;
    let base = baseline(variant, params)?;
    let with_series: Vec<_> = ds
        .dynamics
        .iter()
        .enumerate()
        .filter_map(|(i, d)| d.series.as_ref().map(|s| (i, d, s)))
        .collect();
    on_start(
        EVALS_PER_DYNAMIC_SERIES * with_series.len() as u64
            + crate::diagnose_scroll::EVALS_PER_SCROLL_SERIES * ds.scrolls.len() as u64,
    );
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for (i, d, s) in with_series {
        let label = d
            .label
            .clone()
            .unwrap_or_else(|| format!("dynamic {}", i + 1));
        let label = format!("{label} ({})", s.file.display());
        let sd = diagnose_dynamic(&base, &label, d.roller_kg, &s.t_s, &s.a_height_mm, on_eval)?;
        rows.push(sd.row.clone());
        series.push(sd);
    }
    let mut scrolls = Vec::new();
    for (i, e) in ds.scrolls.iter().enumerate() {
        let label = e
            .label
            .clone()
            .unwrap_or_else(|| format!("scroll {}", i + 1));
        let label = format!("{label} ({})", e.series.file.display());
        let sd = crate::diagnose_scroll::diagnose_scroll(&base, &label, e, on_eval)?;
        rows.push(sd.row.clone());
        scrolls.push(sd);
    }
    if series.is_empty() && scrolls.is_empty() {
        if let Some(r) = diagnose_summary(&base, &ds)? {
            rows.push(r);
        }
    }
    Ok(Diagnosis {
        report: Report {
            dataset: ds.name.clone(),
            results: rows,
        },
        series,
        scrolls,
        baseline_source: base.source,
        warnings: ds.warnings,
    })
}
