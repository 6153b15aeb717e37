//! What both diagnoses (dynamic and scroll series) share: the fitted-model
//! record, the JSON row, the residual statistics (noise floor, lag-1
//! autocorrelation, RMS, BIC) and the decision rule.

use crate::catalogue::{EffectKind, EffectLaw};
use serde::Serialize;

/// Lowest BIC improvement that counts as evidence for a candidate.
pub const BIC_MARGIN: f64 = 10.0;
/// Lowest BIC gap between the best and the second-best candidate for a name.
pub const BIC_SEPARATION: f64 = 4.0;
/// A residual whose RMS is at most this multiple of the noise floor is
/// "at the noise floor".
pub const FLOOR_FACTOR: f64 = 1.25;

/// A named effect whose residual does not reach the noise floor must at
/// least divide the baseline's by this (issue 11's "near the noise").
pub const NEAR_NOISE_REDUCTION: f64 = 3.0;

/// A residual whose lag-1 autocorrelation is below this in magnitude counts
/// as white (dynamic series).
pub const WHITE_LAG1: f64 = 0.3;

/// One fitted model of a series (`Fitted::default()`: an empty record, no
/// model, every figure zero).
#[derive(Debug, Clone, Default, Serialize)]
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
    /// The fitted effect in words: its value, unit, and the law of its
    /// family that was fitted (see [`crate::catalogue::EffectLaw`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub law: Option<String>,
    /// The law of the effect's family that was fitted (`None` for a
    /// baseline or the refitted shape).
    #[serde(skip)]
    pub effect_law: Option<EffectLaw>,
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
    /// The fit's parameter vector (to start other fits from it).
    #[serde(skip)]
    pub params: Vec<f64>,
}

impl Fitted {
    /// Parameters of the effect in the fit's vector (0 for a baseline).
    pub fn effect_params(&self) -> usize {
        self.effect_law.map_or(0, EffectLaw::params)
    }

    /// The fitted effect's value in words: the law's description when the
    /// fit has one, else the value in the effect's unit.
    pub fn value_text(&self) -> String {
        match &self.law {
            Some(l) => l.clone(),
            None => match self.effect_value {
                Some(v) => format!(
                    "{v:.4} {}",
                    EffectKind::parse(&self.model).map_or("", |e| e.nominal().1)
                ),
                // The baseline and the refitted shape carry no effect.
                None => "no effect parameter".into(),
            },
        }
    }

    /// Sum of squared residuals, mm².
    pub fn sum_sq(&self) -> f64 {
        self.residual.iter().map(|x| x * x).sum()
    }
}
/// Robust noise floor of a residual sampled at (nearly) uniform times:
/// RMS of `Δ³r` over runs without gaps (differences beyond 4× the
/// median-based scale dropped), divided by √20.
pub fn noise_floor(t: &[f64], r: &[f64]) -> f64 {
    if t.len() < 8 {
        return f64::NAN;
    }
    let dt = median_step(t);
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

/// Weighted least-squares line through `(x, y, weight)` points:
/// `(intercept, slope, Σw·(x − x̄)²)`, or `None` when the points do not
/// spread in x (the last is what a slope's standard error needs: `1/√` of
/// it with weights `1/σ²`, or the scatter over it).
///
/// ```
/// let (a, b, _) = trackbelt_host::evidence::weighted_line(&[(0.0, 1.0, 1.0), (2.0, 5.0, 3.0)]).unwrap();
/// assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
/// assert!(trackbelt_host::evidence::weighted_line(&[(1.0, 1.0, 1.0), (1.0, 2.0, 1.0)]).is_none());
/// ```
pub fn weighted_line(pts: &[(f64, f64, f64)]) -> Option<(f64, f64, f64)> {
    let sw: f64 = pts.iter().map(|p| p.2).sum();
    let xm = pts.iter().map(|p| p.2 * p.0).sum::<f64>() / sw;
    let ym = pts.iter().map(|p| p.2 * p.1).sum::<f64>() / sw;
    let sxx: f64 = pts.iter().map(|p| p.2 * (p.0 - xm).powi(2)).sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let slope = pts
        .iter()
        .map(|p| p.2 * (p.0 - xm) * (p.1 - ym))
        .sum::<f64>()
        / sxx;
    Some((ym - slope * xm, slope, sxx))
}

/// Root mean square of `r`.
pub fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64).sqrt()
}

/// Bayesian information criterion `n·ln(RSS/n) + k·ln n` of residuals
/// `r` with `k` fitted parameters.
pub fn bic(r: &[f64], k: usize) -> f64 {
    let n = r.len() as f64;
    let rss = r.iter().map(|x| x * x).sum::<f64>().max(1e-300);
    n * (rss / n).ln() + k as f64 * n.ln()
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
    /// Every model fitted beside the baseline (each effect's best law and,
    /// on dynamic series, the refitted table shape), with the BIC gain the
    /// decision ranked it by ([`candidate_rows`]); empty (and left out of
    /// the JSON) for a summary comparison.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub candidates: Vec<CandidateRow>,
    /// Samples the candidates' BIC gains are counted on: the residual's
    /// effective samples on a dynamic series ([`effective_samples`]), the
    /// speed windows on a scroll series; absent without candidates.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gain_samples: Option<f64>,
}

/// One fitted model of a series as the JSON report lists it
/// ([`ResultRow::candidates`]): what a user needs to weigh the candidates
/// against each other without reading the evidence text.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateRow {
    /// An effect identifier, or `table_shape` for the table's shape
    /// refitted on the series.
    pub model: String,
    /// The fitted effect in words (its value, unit and law;
    /// [`Fitted::value_text`]).
    pub fitted: String,
    /// RMS residual, in the row's unit.
    pub rms: f64,
    /// Parameters fitted (the baseline's included).
    pub parameters: usize,
    /// BIC gain over the baseline ([`bic_gain`]) on
    /// [`ResultRow::gain_samples`] samples: above [`BIC_MARGIN`] the
    /// model is supported; a name also needs the rest of the rule.
    pub bic_gain: f64,
}

/// The candidates `cands` of baseline `b` as the report lists them,
/// largest BIC gain first, ranked as the decision ranks them ([`rank`]:
/// on the effective samples when `effective`), and the samples counted
/// (`None` without candidates: [`ResultRow::gain_samples`]).
///
/// ```
/// use trackbelt_host::evidence::{candidate_rows, Fitted};
/// let fit = |model: &str, r: f64, k: usize| Fitted {
///     model: model.into(),
///     rms: r,
///     k,
///     residual: (0..100).map(|i| if i % 2 == 0 { r } else { -r }).collect(),
///     ..Fitted::default()
/// };
/// let b = fit("baseline", 2.0, 3);
/// let (rows, n) = candidate_rows(&b, &[fit("joint_friction", 1.9, 4), fit("quadratic_damping", 1.0, 4)], false);
/// assert_eq!(n, Some(100.0));
/// assert_eq!(candidate_rows(&b, &[], false), (Vec::new(), None));
/// assert_eq!(rows[0].model, "quadratic_damping");
/// // 100·ln 4 − ln 100: the residual sum of squares quartered with one more parameter.
/// assert!((rows[0].bic_gain - (100.0 * 4f64.ln() - 100f64.ln())).abs() < 1e-9);
/// assert!(rows[1].bic_gain < rows[0].bic_gain);
/// ```
pub fn candidate_rows(
    b: &Fitted,
    cands: &[Fitted],
    effective: bool,
) -> (Vec<CandidateRow>, Option<f64>) {
    let ranking = rank(b, cands, effective);
    let rows = ranking
        .order
        .iter()
        .map(|&i| {
            let c = &cands[i];
            CandidateRow {
                model: c.model.clone(),
                fitted: c.value_text(),
                rms: c.rms,
                parameters: c.k,
                bic_gain: ranking.gains[i],
            }
        })
        .collect();
    (rows, (!cands.is_empty()).then_some(ranking.n_eff))
}

/// Effective number of independent samples of a residual of `n` samples
/// whose lag-1 autocorrelation is `rho` (an AR(1) residual):
/// `n·(1 − ρ)/(1 + ρ)`, ρ clamped to [0, 0.95], at least 3. Model
/// mismatch left after a refit is smooth, so the plain BIC (which takes
/// every sample as independent) overstates the evidence for any candidate
/// that absorbs part of it.
pub fn effective_samples(n: usize, rho: f64) -> f64 {
    let r = if rho.is_finite() {
        rho.clamp(0.0, 0.95)
    } else {
        0.95
    };
    (n as f64 * (1.0 - r) / (1.0 + r)).max(3.0)
}

/// BIC improvement of `c` over `b` on `n_eff` effective samples:
/// `n_eff·ln(RSS_b/RSS_c) − (k_c − k_b)·ln n_eff` ([`bic_gain_of`]).
pub fn bic_gain(b: &Fitted, c: &Fitted, n_eff: f64) -> f64 {
    bic_gain_of(b.sum_sq(), b.k, c.sum_sq(), c.k, n_eff)
}

/// BIC improvement of a fit leaving `rss_c` with `k_c` parameters over one
/// leaving `rss_b` with `k_b`, on `n_eff` effective samples (for a model
/// that is no [`Fitted`], such as a step added to a fit's residual).
///
/// ```
/// use trackbelt_host::evidence::bic_gain_of;
/// // Halving the residual sum of squares with one more parameter on 100
/// // samples: 100·ln 2 − ln 100.
/// let g = bic_gain_of(2.0, 3, 1.0, 4, 100.0);
/// assert!((g - (100.0 * 2f64.ln() - 100f64.ln())).abs() < 1e-12);
/// ```
pub fn bic_gain_of(rss_b: f64, k_b: usize, rss_c: f64, k_c: usize, n_eff: f64) -> f64 {
    let (rb, rc) = (rss_b.max(1e-300), rss_c.max(1e-300));
    n_eff * (rb / rc).ln() - (k_c as f64 - k_b as f64) * n_eff.ln()
}

/// Median of the finite values of `v` (the mean of the middle two when
/// their number is even); `None` when there is none.
///
/// ```
/// use trackbelt_host::evidence::median;
/// assert_eq!(median([0.71, 0.70, 3.6, f64::NAN]), Some(0.71));
/// assert_eq!(median([1.0, 2.0]), Some(1.5));
/// assert_eq!(median([f64::INFINITY]), None);
/// ```
pub fn median(v: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Median spacing of sample times (0.05 s when there are fewer than two).
pub fn median_step(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2).copied().unwrap_or(0.05)
}

/// Candidates ranked by their BIC gain over a baseline ([`rank`]).
#[derive(Debug, Clone)]
pub struct Ranking {
    /// Candidate indices, largest gain first.
    pub order: Vec<usize>,
    /// Gain of each candidate (by index).
    pub gains: Vec<f64>,
    /// Samples the gains are counted on.
    pub n_eff: f64,
}

impl Ranking {
    /// The leader: `(index, gain, gap to the runner-up)` (the gap is
    /// infinite without a runner-up); `None` without candidates.
    pub fn best(&self) -> Option<(usize, f64, f64)> {
        let &first = self.order.first()?;
        let gain = self.gains[first];
        let sep = self
            .order
            .get(1)
            .map_or(f64::INFINITY, |&i| gain - self.gains[i]);
        Some((first, gain, sep))
    }
}

/// Rank `cands` by their BIC gain over `b` ([`bic_gain`]), counted on the
/// effective samples of the best fit's residual ([`effective_samples`])
/// when `effective`, else on every sample.
pub fn rank(b: &Fitted, cands: &[Fitted], effective: bool) -> Ranking {
    let mut order: Vec<usize> = (0..cands.len()).collect();
    order.sort_by(|&i, &j| cands[i].sum_sq().total_cmp(&cands[j].sum_sq()));
    let best_fit = order
        .first()
        .map(|&i| &cands[i])
        .filter(|c| c.sum_sq() < b.sum_sq())
        .unwrap_or(b);
    let n_eff = if effective {
        effective_samples(b.residual.len(), lag1(&best_fit.residual))
    } else {
        b.residual.len() as f64
    };
    let gains: Vec<f64> = cands.iter().map(|c| bic_gain(b, c, n_eff)).collect();
    order.sort_by(|&i, &j| gains[j].total_cmp(&gains[i]));
    Ranking {
        order,
        gains,
        n_eff,
    }
}

/// A series' answer while the decision is taken: the effect named (or
/// `none` / `unexplained`), the index of the named candidate, the residual
/// after and the reason. A refusal keeps the baseline's residual as the
/// residual after: no model was accepted.
///
/// ```
/// use trackbelt_host::evidence::Verdict;
/// let mut v = Verdict::refused("none", 1.5, "no candidate is supported".into());
/// assert_eq!((v.effect.as_str(), v.chosen, v.rms_after), ("none", None, 1.5));
/// v.refuse("unexplained", 1.5, format!("{}; a step is left", v.why));
/// assert_eq!(v.why, "no candidate is supported; a step is left");
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The answer: an effect's identifier, `none` or `unexplained`.
    pub effect: String,
    /// Index of the named candidate in the list decided on (`None` unless
    /// an effect is named).
    pub chosen: Option<usize>,
    /// Residual RMS after: the named candidate's, else the baseline's.
    pub rms_after: f64,
    /// Why, in words (the evidence text starts with it).
    pub why: String,
}

impl Verdict {
    /// No name: `effect` (`none` or `unexplained`) with the baseline's
    /// residual `baseline_rms` kept.
    pub fn refused(effect: &str, baseline_rms: f64, why: String) -> Self {
        Self {
            effect: effect.into(),
            chosen: None,
            rms_after: baseline_rms,
            why,
        }
    }

    /// Candidate `i`, fitted as `c`, named.
    pub fn named(i: usize, c: &Fitted, why: String) -> Self {
        Self {
            effect: c.model.clone(),
            chosen: Some(i),
            rms_after: c.rms,
            why,
        }
    }

    /// Withdraw any name: the answer becomes `effect` with the baseline's
    /// residual `baseline_rms`, for the reason `why` (which replaces the
    /// previous one; build it from [`Verdict::why`] to keep that).
    pub fn refuse(&mut self, effect: &str, baseline_rms: f64, why: String) {
        *self = Self::refused(effect, baseline_rms, why);
    }

    /// Name candidate `i`, fitted as `c`, for the reason `why`.
    pub fn name(&mut self, i: usize, c: &Fitted, why: String) {
        *self = Self::named(i, c, why);
    }
}

/// The runner-up of a ranking in words: `runner-up NAME: GAIN`, or that
/// no other candidate was ranked (every other one set aside before the
/// ranking), never a placeholder figure.
fn runner_up_text(second: Option<(&Fitted, f64)>) -> String {
    match second {
        Some((s, g)) => format!("runner-up {}: {g:.1}", s.model),
        None => "no runner-up: no other candidate was ranked".into(),
    }
}

/// The decision rule of the module documentation, as a [`Verdict`].
///
/// The evidence is the BIC on the effective sample size
/// ([`effective_samples`], from the best fit's residual) when `effective`,
/// else on every sample (scroll series, whose `separation` allows for
/// their correlated window means):
///
/// * no candidate lowers it by [`BIC_MARGIN`]: `none` unless `structure`
///   names a disturbance outside the catalogue found in the residual
///   (then `unexplained`, whether or not the residual seems to reach the
///   noise floor: the floor is read from sample-to-sample differences,
///   which a shaking camera inflates until the residual sits at it):
///   shape mismatch left after recalibration is not an effect;
/// * the best candidate lowers it by [`BIC_MARGIN`], brings the residual
///   to the noise floor and beats the runner-up by `separation`: its name;
/// * otherwise `unexplained`. A wrong name is never forced.
///
/// A name without a runner-up (every other candidate set aside) says so
/// in its reason, with no placeholder figure:
///
/// ```
/// use trackbelt_host::evidence::{decide, Fitted};
/// let t: Vec<f64> = (0..40).map(|i| f64::from(i) * 0.1).collect();
/// let wobble = |s: &f64| 0.01 * (7.0 * s).sin();
/// let b = Fitted {
///     model: "baseline".into(),
///     residual: t.iter().map(|s| 0.5 + wobble(s)).collect(),
///     rms: 0.5,
///     k: 1,
///     ..Fitted::default()
/// };
/// let c = Fitted {
///     model: "bearing_friction".into(),
///     residual: t.iter().map(wobble).collect(),
///     rms: 0.007,
///     k: 2,
///     effect_value: Some(0.5),
///     ..Fitted::default()
/// };
/// let v = decide(&b, &[c], 0.02, "N·m", 12.0, None, false);
/// assert_eq!(v.effect, "bearing_friction");
/// assert!(v.why.contains("no runner-up"), "{}", v.why);
/// assert!(!v.why.contains("NaN"), "{}", v.why);
/// ```
pub fn decide(
    b: &Fitted,
    cands: &[Fitted],
    noise: f64,
    unit: &str,
    separation: f64,
    structure: Option<&str>,
    effective: bool,
) -> Verdict {
    let at_floor = |r: f64| r <= FLOOR_FACTOR * noise;
    let ranking = rank(b, cands, effective);
    let Some((first, gain, sep)) = ranking.best() else {
        let (name, why) = match structure {
            Some(s) => ("unexplained", format!("structured residual: {s}")),
            _ => ("none", "no candidate applies".to_string()),
        };
        return Verdict::refused(
            name,
            b.rms,
            format!(
                "{why}; baseline residual {:.3} {unit}, noise floor {:.3} {unit}",
                b.rms, noise
            ),
        );
    };
    let n_eff = ranking.n_eff;
    let best = &cands[first];
    let second = ranking.order.get(1).map(|&i| (&cands[i], ranking.gains[i]));
    let ratio_before = b.rms / noise;
    let n_txt = format!("{n_eff:.0} effective samples of {}", b.residual.len());
    if gain < BIC_MARGIN {
        if let Some(s) = structure {
            return Verdict::refused(
                "unexplained",
                b.rms,
                format!(
                    "structured residual: {s}; baseline {:.3} {unit} (×{:.2} the noise floor {:.3} {unit}); no candidate explains it (best {} lowers BIC by {:.1} on {n_txt})",
                    b.rms, ratio_before, noise, best.model, gain
                ),
            );
        }
        return Verdict::refused(
            "none",
            b.rms,
            format!(
                "no candidate is supported: best {} lowers BIC by only {:.1} on {n_txt}; baseline residual {:.3} {unit} (×{:.2} the noise floor {:.3} {unit}, lag-1 autocorrelation {:.2}){}",
                best.model,
                gain,
                b.rms,
                ratio_before,
                noise,
                lag1(&b.residual),
                if at_floor(b.rms) {
                    ""
                } else {
                    "; what is left is model-shape mismatch, not an effect signature"
                }
            ),
        );
    }
    if at_floor(best.rms) && sep >= separation {
        return Verdict::named(
            first,
            best,
            format!(
                "{} lowers BIC by {:.1} on {n_txt} ({}); residual {:.3} → {:.3} {unit}, noise floor {:.3} {unit}; fitted {} = {}",
                best.model,
                gain,
                runner_up_text(second),
                b.rms,
                best.rms,
                noise,
                best.model,
                best.value_text(),
            ),
        );
    }
    let reason = if at_floor(best.rms) {
        format!(
            "{} and {} explain it about equally well (BIC gap {:.1} on {n_txt})",
            best.model,
            second.map_or("-", |(s, _)| s.model.as_str()),
            sep
        )
    } else {
        format!(
            "best candidate {} (BIC −{:.1} on {n_txt}) leaves {:.3} {unit} (×{:.2} the noise floor {:.3} {unit}, lag-1 autocorrelation {:.2})",
            best.model,
            gain,
            best.rms,
            best.rms / noise,
            noise,
            lag1(&best.residual)
        )
    };
    Verdict::refused(
        "unexplained",
        b.rms,
        format!(
            "structured residual: baseline {:.3} {unit} (×{:.2} the noise floor){}; {reason}",
            b.rms,
            ratio_before,
            structure.map_or(String::new(), |s| format!(", {s}"))
        ),
    )
}
