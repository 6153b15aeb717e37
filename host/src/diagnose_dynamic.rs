//! Diagnosis of dynamic series (SPEC §5, `trackbelt diagnose`).
//!
//! For every dynamic series of a dataset:
//!
//! 1. **Baseline fit.** The baseline law (the calibrated method III table of
//!    the variant, see [`crate::catalogue::baseline`]) is refitted to the series with three
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
//!    [`crate::evidence::BIC_MARGIN`] and the baseline residual is at the noise floor
//!    (RMS ≤ [`FLOOR_FACTOR`] × floor); the best candidate's identifier when
//!    it lowers the BIC by at least [`crate::evidence::BIC_MARGIN`], brings the residual to
//!    the noise floor, and beats the runner-up by at least [`BIC_SEPARATION`];
//!    otherwise `unexplained` (structured, but no single candidate explains
//!    it, or two explain it equally well). A wrong name is never forced.
//!
//! Datasets that hold only summary figures (like `shredder-table1`) get one
//! row comparing the baseline's figures with the measured means against the
//! run-to-run spread: `none` when every figure is inside it, `unexplained`
//! otherwise (summary figures cannot tell the effects apart).

use crate::catalogue::{scale_stiffness, Baseline, EffectKind};
use crate::error::{Error, Result};
use crate::evidence::{
    bic, decide, lag1, noise_floor, rms, Fitted, ResultRow, BIC_SEPARATION, FLOOR_FACTOR,
    WHITE_LAG1,
};
use crate::fit::{self, Problem};
use crate::forward::{interpolate, simulate_height};
use crate::progress::Progress;
use serde::Serialize;
use trackbelt::joint::JointLaw;

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
    // As many times as heights: a longer column is cut to the shorter one.
    let n = t.len().min(h.len());
    let (t, h) = (&t[..n], &h[..n]);
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

/// The extremum at sample `i` about `settled`, refined by a parabola.
fn refine(t: &[f64], h: &[f64], i: usize, settled: f64) -> (f64, f64) {
    let (tv, hv) = crate::peaks::parabola_vertex(t, h, i);
    (tv, hv - settled)
}
/// A series fit as a [`Problem`] of the shared fitter: parameters
/// `[ln s, ln(cz/cz₀), magnitude?]`, the camera offset solved in closed
/// form; an evaluation is the model's height at the sample times and the
/// offset.
struct SeriesFit<'a> {
    base: &'a Baseline,
    roller_kg: f64,
    t: &'a [f64],
    h: &'a [f64],
    effect: Option<EffectKind>,
    duration: f64,
    bounds: Vec<(f64, f64)>,
}

impl SeriesFit<'_> {
    fn law(&self, p: &[f64]) -> JointLaw<f64> {
        let cz0 = self.base.law.damping.max(1e-6);
        let mut law = scale_stiffness(&self.base.law, p[0].exp());
        law.damping = cz0 * p[1].exp();
        if let (Some(e), Some(&m)) = (self.effect, p.get(2)) {
            law = e.apply(&law, m);
        }
        law
    }

    fn model(&self, p: &[f64]) -> Result<(Vec<f64>, f64)> {
        let trace = simulate_height(&self.law(p), &self.base.belt, self.roller_kg, self.duration)?;
        let m = interpolate(&trace, self.t);
        let h = self.h;
        let off = h.iter().zip(&m).map(|(a, b)| a - b).sum::<f64>() / h.len() as f64;
        Ok((m, off))
    }
}

impl Problem for SeriesFit<'_> {
    type Output = (Vec<f64>, f64);
    fn evaluate(&self, p: &[f64]) -> Option<(Vec<f64>, f64)> {
        // A diverging trial is a bad point, not a failure of the fit.
        self.model(p).ok()
    }
    fn residuals(&self, (m, off): &(Vec<f64>, f64)) -> Vec<f64> {
        self.h.iter().zip(m).map(|(a, b)| a - b - off).collect()
    }
    fn clamp(&self, p: &mut [f64]) {
        for (x, &(lo, hi)) in p.iter_mut().zip(&self.bounds) {
            *x = x.clamp(lo, hi);
        }
    }
}

/// The fitter's settings for a series fit.
fn series_options(params: usize) -> fit::Options {
    fit::Options {
        max_iterations: 10,
        max_evaluations: 45,
        rel_tol: 1e-3,
        ..fit::Options::new(vec![2e-3; params])
    }
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
    progress: &dyn Progress,
) -> Result<Fitted> {
    let mut bounds = vec![(0.5f64.ln(), 2.0f64.ln()), (0.05f64.ln(), 20f64.ln())];
    if let Some(e) = effect {
        bounds.push(e.bounds());
    }
    let problem = SeriesFit {
        base,
        roller_kg,
        t,
        h,
        effect,
        duration: t.last().copied().unwrap_or(1.0).max(0.5) + 0.02,
        bounds,
    };
    let res = match fit::fit(&problem, start, &series_options(start.len()), progress) {
        Err(Error::StartDiverged) => {
            // Name why the start does not simulate.
            let mut p = start.to_vec();
            problem.clamp(&mut p);
            problem.model(&p)?;
            return Err(Error::StartDiverged);
        }
        r => r?,
    };
    let (m, off) = &res.output;
    let residual = res.residuals;
    let k = 3 + usize::from(effect.is_some());
    let law = problem.law(&res.params);
    Ok(Fitted {
        model: effect.map_or("baseline".into(), |e| e.id().into()),
        stiffness_scale: res.params[0].exp(),
        cz_nms_per_rad: law.damping,
        offset_mm: *off,
        effect_value: effect.map(|e| e.nominal().0 * res.params[2]),
        rms: rms(&residual),
        bic: bic(&residual, k),
        k,
        evaluations: res.evaluations,
        model_values: m.iter().map(|x| x + off).collect(),
        residual,
    })
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
    progress: &dyn Progress,
) -> Result<SeriesDiagnosis> {
    if t.len() < 25 {
        return Err(Error::SeriesTooShort {
            series: label.to_string(),
            samples: t.len(),
            needed: "25 (1 s at 25 Hz)",
        });
    }
    let mut b = fit_dynamic(base, roller_kg, t, h, None, &[0.0, 0.0], progress)?;
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
            let f = fit_dynamic(base, roller_kg, t, h, Some(e), &s0, progress)?;
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
            let b2 = fit_dynamic(base, roller_kg, t, h, None, &s0, progress)?;
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
/// Number of simulations [`diagnose_dynamic`] may spend per series (an
/// upper bound for a progress bar).
pub const EVALS_PER_DYNAMIC_SERIES: u64 = 9 * 46;
