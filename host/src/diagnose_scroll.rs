//! Diagnosis of scroll series (belt turned between two wheels; drive torque
//! against time at changing speeds, maybe belt temperature).
//!
//! The model is the reference rig simulation (`trackbelt::rig`) driven
//! along the measured speed (the logged ω, linearly interpolated, from rest
//! at t = 0), with the logged belt temperature as its run-time input; its
//! drive torque is averaged over each logger interval like the logger does,
//! and residuals are compared on means over windows of [`WINDOW_S`].
//! The baseline refits `cz` (one parameter: the torque is almost all
//! bending damping); each scroll candidate adds one parameter:
//!
//! * `bearing_friction`: the rig's constant bearing torque
//!   ([`trackbelt::rig::RigConfig::bearing_friction_nm`]);
//! * `rate_dependent_damping`: a power-law joint damping `c·|ζ̇|^p`,
//!   whose drive torque goes as `|ω|^p` (joint speeds are ∝ ω), the
//!   exponent fitted on [`POWER_EXPONENTS`] (0.3…0.9; two parameters);
//! * `thermal_softening`: stiffness and damping scaled by
//!   `1 − α·(T − T₀)`, `T₀` the first logged temperature (needs
//!   `belt_temp_c`; without it the candidate is left out).
//!
//! The choice follows [`crate::evidence::decide`] (BIC, noise floor), with
//! the larger separation [`SCROLL_BIC_SEPARATION`], and each name needs its
//! signature on the steady plateaus ([`speed_curve_veto`],
//! [`sublinear_veto`], [`thermal_veto`]).

pub use crate::catalogue::SCROLL_EFFECTS;

use crate::catalogue::{Baseline, EffectKind, EffectLaw};
use crate::dataset::ScrollEntry;
use crate::error::{Error, Result};
use crate::evidence::{decide, lag1, median_step, noise_floor, weighted_line, Fitted, ResultRow};
use crate::forward::{interpolate, simulate_scroll};
use crate::progress::Progress;
use trackbelt::rig::RigConfig;

/// BIC gap a scroll candidate needs over the runner-up. Larger than for
/// dynamic series because (a) the window residuals stay correlated (lag-1
/// autocorrelation 0.5–0.7 from the rig's chaotic part), so the BIC
/// overstates the evidence, and (b) over 1.5–5 rad/s the shapes of bearing
/// friction (constant) and power-law damping (|ω|^p, p < 1) next to cz (∝ ω) are
/// nearly collinear: on the synthetic data a bearing friction of 0.2 N·m was
/// preferred as power-law damping by up to 7 BIC units.
pub const SCROLL_BIC_SEPARATION: f64 = 12.0;

/// Exponents the power-law damping candidate is fitted over (its drive
/// torque ∝ |ω|^p beside the linear damping). Not below 0.3: over the
/// factor of 3 in speed a scroll test spans, |ω|^0.2 changes by only 25 %
/// and is a constant torque, bearing friction's shape, in all but name (with
/// p down to 0.1 the synthetic strong bearing friction of
/// `host-tests/tests/diagnose.rs` was no longer told from a power law).
pub const POWER_EXPONENTS: [f64; 7] = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9];

/// Re-simulations of the baseline with cz refitted, at most.
pub const CZ_ITERATIONS: usize = 3;
/// Relative change of cz below which the re-simulation stops.
pub const CZ_TOLERANCE: f64 = 0.03;

/// Simulations a scroll diagnosis may spend (for a progress bar): the
/// baseline run, its re-simulations with cz refitted and the twin.
pub const EVALS_PER_SCROLL_SERIES: u64 = 2 + CZ_ITERATIONS as u64;

/// Everything found for one scroll series.
#[derive(Debug, Clone)]
pub struct ScrollDiagnosis {
    /// The JSON row.
    pub row: ResultRow,
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// Drive speed, rad/s.
    pub omega_rad_s: Vec<f64>,
    /// Measured torque, N·m.
    pub torque_nm: Vec<f64>,
    /// Belt temperature, °C, if logged.
    pub temp_c: Option<Vec<f64>>,
    /// Baseline fit.
    pub baseline: Fitted,
    /// Candidate fits.
    pub candidates: Vec<Fitted>,
    /// Index of the chosen candidate.
    pub chosen: Option<usize>,
    /// Noise floor of the window means, N·m.
    pub noise_nm: f64,
    /// Centre times of the residual windows, s.
    pub t_windows_s: Vec<f64>,
}

/// The rig of a scroll entry: the rig's defaults with the entry's wheel
/// diameters and tensioner force.
pub fn rig_config(e: &ScrollEntry) -> RigConfig<f64> {
    let mut c = RigConfig {
        drive_diameter_m: e.drive_diameter_mm * 1e-3,
        idler_diameter_m: e.idler_diameter_mm * 1e-3,
        ..RigConfig::default()
    };
    if let Some(f) = e.idler_force_n {
        c.idler_force_n = f;
    }
    c
}

/// Length of the residual windows: the link-passing ripple of the rig
/// torque (5–15 Hz at the usual speeds) depends on where each link sits on
/// the wheels, which no fit reproduces sample by sample; residuals are
/// therefore taken on the means of consecutive windows of about
/// [`WINDOW_S`] (the ripple averages out, the effects do not).
pub fn window_len(t: &[f64]) -> usize {
    ((WINDOW_S / median_step(t)).round() as usize).max(1)
}

/// Residual window, s.
pub const WINDOW_S: f64 = 0.5;

/// Means of consecutive windows of `k` values (a shorter last window is
/// dropped when it has fewer than `k/2` values).
pub fn window_means(x: &[f64], k: usize) -> Vec<f64> {
    x.chunks(k.max(1))
        .filter(|c| 2 * c.len() >= k)
        .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        .collect()
}

/// Torque of the rig driven along the logged speed, averaged over each
/// logger interval.
pub fn model_torque(
    law: &trackbelt::joint::JointLaw<f64>,
    belt: &trackbelt::params::Belt<f64>,
    config: &RigConfig<f64>,
    t: &[f64],
    omega: &[f64],
    temp: Option<&[f64]>,
) -> Result<Vec<f64>> {
    let mut knots: Vec<(f64, f64)> = Vec::with_capacity(t.len() + 1);
    if t.first().is_some_and(|&t0| t0 > 0.0) {
        knots.push((0.0, 0.0));
    }
    knots.extend(t.iter().copied().zip(omega.iter().copied()));
    let tk: Vec<(f64, f64)> = match temp {
        Some(tc) => t.iter().copied().zip(tc.iter().copied()).collect(),
        None => vec![(0.0, 20.0)],
    };
    let dt = median_step(t);
    let end = t.last().copied().unwrap_or(0.0) + 0.5 * dt;
    let trace = simulate_scroll(
        law,
        belt,
        config,
        &|x| interpolate(&knots, &[x])[0],
        &|x| interpolate(&tk, &[x])[0],
        end,
    )?;
    // Mean over (t − dt/2, t + dt/2].
    let mut out = Vec::with_capacity(t.len());
    let mut j = 0;
    for &ti in t {
        let (a, b) = (ti - 0.5 * dt, ti + 0.5 * dt);
        while j < trace.len() && trace[j].0 <= a {
            j += 1;
        }
        let (mut s, mut k) = (0.0, 0);
        let mut i = j;
        while i < trace.len() && trace[i].0 <= b {
            s += trace[i].2;
            k += 1;
            i += 1;
        }
        out.push(if k > 0 {
            s / k as f64
        } else {
            interpolate(&trace.iter().map(|x| (x.0, x.2)).collect::<Vec<_>>(), &[ti])[0]
        });
    }
    Ok(out)
}

/// Maps `(θ_j, θ_0)` of a linear fit to an effect's value.
type EffectValue = fn(f64, f64) -> f64;

/// Linear least squares on window means: `y ≈ Σ θ_j·regs_j`; the model at
/// the samples is `Σ θ_j·sample_regs_j`. `effect = (j, map)` names the
/// coefficient that is the effect's value and maps `(θ_j, θ_0)` to it.
fn linear_fit(
    model: &str,
    y: &[f64],
    regs: &[Vec<f64>],
    sample_regs: &[Vec<f64>],
    effect: Option<(usize, EffectValue)>,
) -> Option<Fitted> {
    let k = regs.len();
    let mut m = vec![vec![0.0; k]; k];
    let mut v = vec![0.0; k];
    for a in 0..k {
        for c in 0..k {
            m[a][c] = regs[a].iter().zip(&regs[c]).map(|(x, z)| x * z).sum();
        }
        v[a] = regs[a].iter().zip(y).map(|(x, z)| x * z).sum();
    }
    let theta = crate::fit::solve(m, v)?;
    let fit_w: Vec<f64> = (0..y.len())
        .map(|i| (0..k).map(|j| theta[j] * regs[j][i]).sum())
        .collect();
    let residual: Vec<f64> = y.iter().zip(&fit_w).map(|(a, b)| a - b).collect();
    let n = residual.len() as f64;
    let rss = residual.iter().map(|x| x * x).sum::<f64>().max(1e-300);
    let len = sample_regs.first().map_or(0, |x| x.len());
    let model_values = (0..len)
        .map(|i| (0..k).map(|j| theta[j] * sample_regs[j][i]).sum())
        .collect();
    Some(Fitted {
        model: model.to_string(),
        stiffness_scale: 1.0,
        cz_nms_per_rad: theta[0],
        offset_mm: 0.0,
        effect_value: effect.map(|(j, f)| f(theta[j], theta[0])),
        law: None,
        effect_law: effect.map(|_| EffectLaw::Plain),
        rms: (rss / n).sqrt(),
        bic: n * (rss / n).ln() + k as f64 * n.ln(),
        k,
        evaluations: 0,
        model_values,
        residual,
        params: theta,
    })
}

/// Diagnose one scroll series.
pub fn diagnose_scroll(
    base: &Baseline,
    label: &str,
    entry: &ScrollEntry,
    progress: &dyn Progress,
) -> Result<ScrollDiagnosis> {
    let s = &entry.series;
    let (t, w, tq) = (&s.t_s, &s.omega_rad_s, &s.torque_nm);
    if t.len() < 20 {
        return Err(Error::SeriesTooShort {
            series: label.to_string(),
            samples: t.len(),
            needed: "20",
        });
    }
    let temp = s.belt_temp_c.as_deref();
    let config = rig_config(entry);
    let k_win = window_len(t);
    // One run of the rig with the baseline law along the measured speed
    // (and temperature): its torque τ₀(t) is almost all bending damping, so
    // refitting cz scales it, and every scroll effect adds a known shape:
    //   bearing_friction        b·sign ω
    //   rate_dependent_damping  c·|ω|^p·sign ω (joint speeds ∝ ω)
    //   thermal_softening       −α·(T − T₀)·τ₀ (all joint moments × g(T))
    // so each candidate is a linear least-squares refit on window means.
    progress.step();
    let y = window_means(tq, k_win);
    // cz refitted by re-simulation: the rig's torque is not proportional to
    // cz (a stiffer damping smooths the belt's entry into the wraps, so the
    // torque–speed curve bends more), and scaling one run's torque would
    // carry the start's curve into the fit.
    let win = |x: &Vec<f64>| window_means(x, k_win);
    let fit_baseline = |tau0: &Vec<f64>| {
        linear_fit(
            "baseline",
            &y,
            &[win(tau0)],
            std::slice::from_ref(tau0),
            None,
        )
    };
    let mut law = base.law.clone();
    let mut tau0 = model_torque(&law, &base.belt, &config, t, w, temp)?;
    let mut fit = fit_baseline(&tau0);
    for _ in 0..CZ_ITERATIONS {
        let Some(a) = fit.as_ref().map(|f| f.params[0]) else {
            break;
        };
        if !(a > 0.0 && a.is_finite()) || (a - 1.0).abs() < CZ_TOLERANCE {
            break;
        }
        law.damping *= a;
        progress.step();
        tau0 = model_torque(&law, &base.belt, &config, t, w, temp)?;
        fit = fit_baseline(&tau0);
    }
    // The rig's own chaotic part (link impacts on the wheels make the torque
    // spiky, and where the spikes fall depends on the whole speed history):
    // a twin run at 0.1 % more speed, a difference no logger resolves.
    progress.step();
    let w_twin: Vec<f64> = w.iter().map(|x| x * 1.001).collect();
    let twin = model_torque(&law, &base.belt, &config, t, &w_twin, temp)?;
    let sgn: Vec<f64> = w.iter().map(|x| x / (x * x + 1e-4).sqrt()).collect();
    let t0 = temp.and_then(|x| x.first().copied()).unwrap_or(20.0);
    let th: Option<Vec<f64>> =
        temp.map(|tc| tc.iter().zip(&tau0).map(|(c, q)| -(c - t0) * q).collect());
    let cz0 = law.damping;
    let bad = || Error::NoMotion {
        series: label.to_string(),
    };
    // The baseline is the last fit: cz scales the run made at the refitted cz.
    let mut b = fit.ok_or_else(bad)?;
    b.cz_nms_per_rad *= cz0;
    let t_win = window_means(t, k_win);
    let sim_floor = (win(&twin)
        .iter()
        .zip(win(&tau0))
        .map(|(a, c)| (a - c).powi(2))
        .sum::<f64>()
        / (2.0 * y.len().max(1) as f64))
        .sqrt();
    // Two floors add: the logger's (third differences of the per-sample
    // residual, averaged over a window) and the simulation's.
    // The baseline's torque per sample (the run at the refitted cz).
    let base_tq: Vec<f64> = tau0.iter().map(|q| b.cz_nms_per_rad / cz0 * q).collect();
    let per_sample: Vec<f64> = tq.iter().zip(&base_tq).map(|(m, q)| m - q).collect();
    let noise = (noise_floor(t, &per_sample) / (k_win as f64).sqrt()).hypot(sim_floor);
    let _ = &t_win;
    let mut cands = Vec::new();
    let fit_one = |e: EffectKind, reg: &Vec<f64>, f: EffectValue| -> Option<Fitted> {
        let mut c = linear_fit(
            e.id(),
            &y,
            &[win(&tau0), win(reg)],
            &[tau0.clone(), reg.clone()],
            Some((1, f)),
        )?;
        c.cz_nms_per_rad *= cz0;
        // A negative friction, damping or softening is not that effect.
        (c.effect_value.is_some_and(|v| v >= 0.0) && c.cz_nms_per_rad > 0.0).then_some(c)
    };
    let mut add = |c: Option<Fitted>| cands.extend(c);
    add(fit_one(EffectKind::BearingFriction, &sgn, |b, _| b));
    // Power-law damping covers its family: the exponent is fitted too (on
    // [`POWER_EXPONENTS`], one more parameter in the BIC), as a belt's
    // rubber may follow any power below linear.
    let power = POWER_EXPONENTS
        .iter()
        .filter_map(|&p| {
            let reg: Vec<f64> = w.iter().map(|x| x.abs().powf(p) * x.signum()).collect();
            fit_one(EffectKind::RateDependentDamping, &reg, |c, _| c).map(|mut c| {
                c.params.push(p);
                c
            })
        })
        .min_by(|a, b| a.rms.total_cmp(&b.rms))
        .map(|mut c| {
            let n = c.residual.len() as f64;
            c.k += 1;
            c.bic += n.ln();
            c
        });
    add(power);
    if let Some(th) = &th {
        add(fit_one(EffectKind::ThermalSoftening, th, |a, s| a / s));
    }
    // Scroll series: a residual above the floor is structure (the window
    // means average the rig's ripple out, so what is left is not shape).
    let (mut effect, mut chosen, mut rms_after, mut why) = decide(
        &b,
        &cands,
        noise,
        "N·m",
        SCROLL_BIC_SEPARATION,
        Some("the window-mean residual is above the noise floor"),
        false,
    );
    // Bearing friction and a power law are told apart by the curvature of
    // the torque–speed curve over the plateaus: a name needs it.
    if let Some(i) = chosen {
        let e = EffectKind::parse(&cands[i].model);
        let pairs = plateau_pairs(t, w, tq, &base_tq);
        let meas: Vec<(f64, f64)> = pairs.iter().map(|p| (p.0, p.1)).collect();
        let veto = e.and_then(|e| {
            speed_curve_veto(e, &meas)
                .or_else(|| sublinear_veto(e, &pairs, noise))
                .or_else(|| {
                    // The constant-speed drift is read for thermal softening only.
                    let drift = (e == EffectKind::ThermalSoftening)
                        .then(|| temp.and_then(|tc| constant_speed_drift(t, w, tc, tq, k_win)))
                        .flatten();
                    thermal_veto(e, drift.as_ref())
                })
        });
        if let Some(veto) = veto {
            why = format!("{} fits better ({why}) but {veto}", cands[i].model);
            effect = "unexplained".into();
            chosen = None;
            rms_after = b.rms;
        }
    }
    let temp_win = temp.map(|x| window_means(x, k_win));
    let evidence = format!(
        "{why}; {}",
        signatures(&t_win, w, tq, temp_win.as_deref(), &b.residual)
    );
    Ok(ScrollDiagnosis {
        row: ResultRow {
            series: label.to_string(),
            kind: "scroll".into(),
            effect,
            rms_before: b.rms,
            rms_after,
            unit: "N·m".into(),
            evidence,
        },
        t_s: t.clone(),
        omega_rad_s: w.clone(),
        torque_nm: tq.clone(),
        temp_c: s.belt_temp_c.clone(),
        baseline: b,
        candidates: cands,
        chosen,
        noise_nm: noise,
        t_windows_s: t_win,
    })
}

/// Mean torque per speed plateau (samples binned to 0.25 rad/s, bins with at
/// least 5 samples): `(ω, mean of each of the given signals)`.
pub fn torque_vs_speed(omega: &[f64], signals: &[&[f64]]) -> Vec<(f64, Vec<f64>)> {
    let mut bins: std::collections::BTreeMap<i64, (usize, Vec<f64>, f64)> = Default::default();
    for (i, &w) in omega.iter().enumerate() {
        let e = bins
            .entry((w / 0.25).round() as i64)
            .or_insert((0, vec![0.0; signals.len()], 0.0));
        e.0 += 1;
        e.2 += w;
        for (k, s) in signals.iter().enumerate() {
            e.1[k] += s[i];
        }
    }
    bins.into_values()
        .filter(|b| b.0 >= 5)
        .map(|(n, s, w)| (w / n as f64, s.iter().map(|x| x / n as f64).collect()))
        .collect()
}

/// Signatures in words: torque against speed (is it proportional?), the
/// residual's drift against time and temperature (`t`, `temp` and `r` per
/// window; `w`, `tq` per sample).
fn signatures(t: &[f64], w: &[f64], tq: &[f64], temp: Option<&[f64]>, r: &[f64]) -> String {
    let tv = torque_vs_speed(w, &[tq]);
    let curve: Vec<String> = tv
        .iter()
        .filter(|(w, _)| w.abs() > 0.1)
        .map(|(w, m)| format!("{:.2} N·m/(rad/s) at {w:.1} rad/s", m[0] / w))
        .collect();
    let slope = |x: &[f64]| -> f64 {
        let n = x.len() as f64;
        let (mx, my) = (x.iter().sum::<f64>() / n, r.iter().sum::<f64>() / n);
        let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
        let sxy: f64 = x.iter().zip(r).map(|(a, b)| (a - mx) * (b - my)).sum();
        if sxx > 0.0 {
            sxy / sxx
        } else {
            0.0
        }
    };
    let mut s = format!(
        "torque/speed {}; baseline residual drifts {:+.4} N·m/s",
        if curve.is_empty() {
            "-".into()
        } else {
            curve.join(", ")
        },
        slope(t)
    );
    if let Some(tc) = temp {
        s.push_str(&format!(", {:+.4} N·m/K", slope(tc)));
    }
    s.push_str(&format!(", lag-1 autocorrelation {:.2}", lag1(r)));
    s
}

/// Shortest steady stretch of the drive speed that counts as a plateau, s.
pub const PLATEAU_MIN_S: f64 = 1.0;
/// Relative speed band of a plateau.
pub const PLATEAU_BAND: f64 = 0.03;

/// Steady-speed plateaus of a scroll series: `(mean |ω| rad/s, mean |τ|
/// N·m)` over each stretch of at least [`PLATEAU_MIN_S`] whose speed stays
/// within [`PLATEAU_BAND`] of its start (the first 30 % of each stretch,
/// the ramp's transient, left out), stretches at speeds within 10 % of
/// each other merged, sorted by speed.
pub fn plateaus(t: &[f64], w: &[f64], tq: &[f64]) -> Vec<(f64, f64)> {
    plateau_stats(t, w, tq)
        .into_iter()
        .map(|(a, b, _)| (a, b))
        .collect()
}

/// Steady stretches of the drive speed: index ranges `from..=to` of each
/// stretch of at least [`PLATEAU_MIN_S`] whose speed stays within
/// [`PLATEAU_BAND`] of its start, above 0.2 rad/s, with the first 30 % (the
/// ramp's transient) left out. In time order, not merged.
fn steady_stretches(t: &[f64], w: &[f64]) -> Vec<(usize, usize)> {
    let n = t.len().min(w.len());
    let mut out = Vec::new();
    let mut i = 0;
    while i < n {
        let w0 = w[i].abs();
        let mut j = i;
        while j + 1 < n && (w[j + 1].abs() - w0).abs() <= PLATEAU_BAND * w0.max(0.3) {
            j += 1;
        }
        if t[j] - t[i] >= PLATEAU_MIN_S && w0 > 0.2 {
            out.push((i + (j - i) * 3 / 10, j));
        }
        i = j + 1;
    }
    out
}

/// [`plateaus`] with the seconds averaged in each: `(ω, τ, s)`.
fn plateau_stats(t: &[f64], w: &[f64], tq: &[f64]) -> Vec<(f64, f64, f64)> {
    let n = t.len().min(w.len()).min(tq.len());
    let mut raw: Vec<(f64, f64, usize, f64)> = Vec::new();
    for (from, j) in steady_stretches(&t[..n], &w[..n]) {
        let k = (j + 1 - from) as f64;
        let mw = w[from..=j].iter().map(|x| x.abs()).sum::<f64>() / k;
        let mt = tq[from..=j].iter().map(|x| x.abs()).sum::<f64>() / k;
        raw.push((mw, mt, j + 1 - from, t[j] - t[from]));
    }
    raw.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64, usize, f64)> = Vec::new();
    for p in raw {
        match out.last_mut() {
            Some(q) if p.0 <= 1.1 * q.0 => {
                let k = (q.2 + p.2) as f64;
                q.0 = (q.0 * q.2 as f64 + p.0 * p.2 as f64) / k;
                q.1 = (q.1 * q.2 as f64 + p.1 * p.2 as f64) / k;
                q.2 += p.2;
                q.3 += p.3;
            }
            _ => out.push(p),
        }
    }
    out.into_iter().map(|(a, b, _, d)| (a, b, d)).collect()
}

/// Why `effect` (bearing friction or power-law damping) cannot be named
/// from the torque–speed curve of the plateaus, or `None` when it can. On
/// log–log axes a constant torque added to a linear damping makes the
/// curve *steepen* with speed (its slope rises towards 1); a power law
/// that replaces linear damping (smoothed to linear at small speeds)
/// makes it *flatten*. Both need at least three plateaus at distinct
/// speeds: with two, both fit exactly. Other effects: `None`.
pub fn speed_curve_veto(effect: EffectKind, plateaus: &[(f64, f64)]) -> Option<String> {
    if !matches!(
        effect,
        EffectKind::BearingFriction | EffectKind::RateDependentDamping
    ) {
        return None;
    }
    let pts: Vec<(f64, f64)> = plateaus
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    if pts.len() < 3 {
        return Some(format!(
            "{} steady plateau(s) at distinct speeds: bearing friction and a power law fit alike",
            pts.len()
        ));
    }
    let slope = |a: (f64, f64), b: (f64, f64)| (b.1 - a.1) / (b.0 - a.0);
    let first = slope(pts[0], pts[1]);
    let last = slope(pts[pts.len() - 2], pts[pts.len() - 1]);
    let steepens = last > first;
    let wrong = match effect {
        EffectKind::BearingFriction => !steepens,
        _ => steepens,
    };
    wrong.then(|| {
        format!(
            "the plateaus' log–log torque–speed slope goes {first:.2} → {last:.2} ({}), the other family's shape",
            if steepens { "steepens" } else { "flattens" }
        )
    })
}

/// The plateaus of the measured torque `tq` and of the baseline's `base`
/// along the same speed: `(mean |ω|, mean |τ| measured, mean |τ|
/// baseline, seconds averaged)`, as [`plateaus`].
pub fn plateau_pairs(t: &[f64], w: &[f64], tq: &[f64], base: &[f64]) -> Vec<(f64, f64, f64, f64)> {
    // The stretches depend on the speed only, so both lists hold the same
    // plateaus in the same order.
    let n = t.len().min(w.len()).min(tq.len()).min(base.len());
    let m = plateau_stats(&t[..n], &w[..n], &tq[..n]);
    let b = plateau_stats(&t[..n], &w[..n], &base[..n]);
    m.iter()
        .zip(&b)
        .map(|(m, b)| (m.0, m.1, b.1, m.2))
        .collect()
}

/// Standard errors by which the measured torque must grow slower with the
/// speed than the baseline's for bearing friction or a power law to be
/// named.
pub const SUBLINEAR_Z: f64 = 2.0;

/// Why `effect` (bearing friction or power-law damping) cannot be named,
/// or `None`: both make the drive torque grow *slower* with the speed
/// than the baseline's damping (a constant torque, or |ω|^α with α < 1,
/// beside or instead of cz·ω), so on the plateaus (`pairs` from
/// [`plateau_pairs`]) the weighted slope of `ln(τ measured / τ baseline)`
/// against `ln ω` must be negative by [`SUBLINEAR_Z`] standard errors
/// (each plateau's mean uncertain by the window-mean floor `noise_nm`
/// over the square root of its 0.5 s windows). Held-out seed 8104: a
/// rig whose measured τ/ω stayed at 0.79, 0.78, 0.77 N·m/(rad/s) over
/// 3.4–7.8 rad/s got power-law damping named on four series of other
/// truths. Fewer than two plateaus, or other effects: `None` (the
/// curvature rule, [`speed_curve_veto`], speaks there).
///
/// ```
/// use trackbelt_host::catalogue::EffectKind;
/// use trackbelt_host::diagnose_scroll::sublinear_veto;
/// // τ = 0.5·ω + 1 measured against a baseline 0.6·ω, 4 s plateaus.
/// let p = |w: f64, b: f64| (w, 0.5 * w + b, 0.6 * w, 4.0);
/// let friction = [p(1.0, 1.0), p(3.0, 1.0), p(6.0, 1.0)];
/// assert!(sublinear_veto(EffectKind::BearingFriction, &friction, 0.01).is_none());
/// // A torque proportional to the baseline's has no such signature.
/// let plain = [p(1.0, 0.0), p(3.0, 0.0), p(6.0, 0.0)];
/// assert!(sublinear_veto(EffectKind::BearingFriction, &plain, 0.01).is_some());
/// ```
pub fn sublinear_veto(
    effect: EffectKind,
    pairs: &[(f64, f64, f64, f64)],
    noise_nm: f64,
) -> Option<String> {
    if !matches!(
        effect,
        EffectKind::BearingFriction | EffectKind::RateDependentDamping
    ) {
        return None;
    }
    // (ln ω, ln(τ/τ₀), weight = 1/variance)
    let pts: Vec<(f64, f64, f64)> = pairs
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.2 > 0.0)
        .map(|p| {
            let windows = (p.3 / WINDOW_S).max(1.0);
            let se = noise_nm / windows.sqrt() / p.1;
            (p.0.ln(), (p.1 / p.2).ln(), se.powi(-2))
        })
        .filter(|p| p.2.is_finite() && p.2 > 0.0)
        .collect();
    let (_, slope, sxx) = weighted_line(&pts)?;
    let se = sxx.powf(-0.5);
    (slope > -SUBLINEAR_Z * se).then(|| {
        format!(
            "the measured torque does not grow slower with the speed than the baseline's on the plateaus (log–log slope of their ratio {slope:+.3} ± {se:.3}): no sign of a torque beside or instead of the damping"
        )
    })
}

/// The drift of the measured torque at constant speed, against the belt
/// temperature and against time (see [`constant_speed_drift`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantSpeedDrift {
    /// Softening per kelvin fitted inside the speed groups (the slope of
    /// `|τ| − τ̄` against `−(T − T̄)·τ̄`, means per group), 1/K.
    pub per_k: f64,
    /// Its standard error, 1/K.
    pub per_k_se: f64,
    /// Relative torque loss per second fitted the same way against time,
    /// 1/s.
    pub per_s: f64,
    /// Residual sum of squares of the time line minus that of the
    /// temperature line, over the window mean's variance (both lines have
    /// one parameter): positive when the temperature explains the drift
    /// better than the time.
    pub temp_over_time: f64,
    /// Windows used.
    pub windows: usize,
    /// Speed groups used (steady stretches at the same speed, within
    /// [`PLATEAU_BAND`], with at least two windows).
    pub groups: usize,
    /// Kelvin between the coolest and the warmest window of each group,
    /// summed over the groups.
    pub rise_k: f64,
}

/// The measured torque's drift at constant drive speed. A baseline without
/// thermal softening holds a steady torque at a steady speed, so a drift
/// there is the effect's signature, and reading it off the measured torque
/// alone keeps the model's own chaotic ripple out of it. Window means of
/// `k` samples of `|τ|`, `|ω|`, the temperature `temp` and the time `t` are
/// taken inside the steady stretches (the speed within [`PLATEAU_BAND`],
/// the first 30 % of each left out); stretches at the same speed (within
/// the band) form one group, so a speed revisited later, on a warmer belt,
/// compares like with like. Relative to its group's means (so what
/// differs between speeds, the shape of the torque–speed curve, drops
/// out), one slope is fitted across all groups against `−(T − T̄)·τ̄`
/// (softening) and one against `−(t − t̄)·τ̄` (a drift in time, as of a
/// logger), each beside the relative speed deviation (a nuisance, left
/// out when the speed does not vary inside the groups). The window mean's
/// variance is the better line's residual variance. `None` with fewer
/// than 3 degrees of freedom or no temperature change inside the groups.
///
/// ```
/// use trackbelt_host::diagnose_scroll::constant_speed_drift;
/// // Two 5 s plateaus at 100 Hz, the belt warming 3 K/s on the first and
/// // 1 K/s on the second, the torque softening by 1 %/K (of itself), a
/// // little noise.
/// let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
/// let w: Vec<f64> = t.iter().map(|&x| if x < 5.0 { 6.0 } else { 3.0 }).collect();
/// let temp: Vec<f64> = t.iter().map(|&x| if x < 5.0 { 20.0 + 3.0 * x } else { 30.0 + x }).collect();
/// let tq: Vec<f64> = (0..1000)
///     .map(|i| 0.5 * w[i] * (-0.01 * (temp[i] - 20.0)).exp() + 0.01 * ((i * 7919) % 13) as f64 / 13.0)
///     .collect();
/// let d = constant_speed_drift(&t, &w, &temp, &tq, 50).unwrap();
/// assert!((d.per_k - 0.01).abs() < 1e-3);
/// assert!(d.per_k > 10.0 * d.per_k_se);
/// assert!(d.temp_over_time > 4.0);
/// ```
pub fn constant_speed_drift(
    t: &[f64],
    w: &[f64],
    temp: &[f64],
    tq: &[f64],
    k: usize,
) -> Option<ConstantSpeedDrift> {
    let n = t.len().min(w.len()).min(temp.len()).min(tq.len());
    let abs: Vec<f64> = tq[..n].iter().map(|x| x.abs()).collect();
    let wabs: Vec<f64> = w[..n].iter().map(|x| x.abs()).collect();
    // Rows: (t, T, |ω|, |τ|) per window, grouped by speed.
    type Row = (f64, f64, f64, f64);
    let mut groups: Vec<(f64, Vec<Row>)> = Vec::new();
    for (from, to) in steady_stretches(&t[..n], &w[..n]) {
        let win = |x: &[f64]| window_means(&x[from..=to], k);
        let (wt, wc, ww, wq) = (win(t), win(temp), win(&wabs), win(&abs));
        if wt.is_empty() {
            continue;
        }
        let speed = ww.iter().sum::<f64>() / ww.len() as f64;
        let rows = (0..wt.len()).map(|i| (wt[i], wc[i], ww[i], wq[i]));
        match groups
            .iter_mut()
            .find(|g| (speed - g.0).abs() <= PLATEAU_BAND * g.0.max(speed))
        {
            Some(g) => g.1.extend(rows),
            None => groups.push((speed, rows.collect())),
        }
    }
    // Per window, relative to its group's means: (x_T, x_t, x_ω, y), the
    // regressors scaled by the group's torque (x_ω: the relative speed
    // deviation, whose pooled coefficient is the log–log slope of the
    // torque–speed curve, a nuisance).
    let mut pts: Vec<[f64; 4]> = Vec::new();
    let (mut rise_k, mut used) = (0.0, 0);
    for (_, g) in &groups {
        if g.len() < 2 {
            continue;
        }
        used += 1;
        let m = g.len() as f64;
        let mean = |f: fn(&Row) -> f64| g.iter().map(f).sum::<f64>() / m;
        let (mt, mc, mw, mq) = (mean(|x| x.0), mean(|x| x.1), mean(|x| x.2), mean(|x| x.3));
        let lo = g.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
        let hi = g.iter().map(|x| x.1).fold(f64::NEG_INFINITY, f64::max);
        rise_k += hi - lo;
        for x in g {
            pts.push([
                -(x.1 - mc) * mq,
                -(x.0 - mt) * mq,
                (x.2 - mw) / mw * mq,
                x.3 - mq,
            ]);
        }
    }
    let dof = pts.len() as f64 - used as f64 - 2.0;
    if dof < 3.0 {
        return None;
    }
    // Least squares y ≈ a·x_j + b·x_ω: (a, variance factor of a, rss). A
    // speed that does not vary inside the groups (a logger that rounds it,
    // or synthetic plateaus) leaves b out.
    let fit = |j: usize| -> Option<(f64, f64, f64)> {
        let s = |a: usize, b: usize| pts.iter().map(|p| p[a] * p[b]).sum::<f64>();
        let (sjj, sjw, sww, sjy, swy) = (s(j, j), s(j, 2), s(2, 2), s(j, 3), s(2, 3));
        if sjj.is_nan() || sjj <= 0.0 {
            return None;
        }
        let det = sjj * sww - sjw * sjw;
        let (a, b, var_a) = if det > 1e-9 * sjj * sww {
            (
                (sjy * sww - swy * sjw) / det,
                (swy * sjj - sjy * sjw) / det,
                sww / det,
            )
        } else {
            (sjy / sjj, 0.0, 1.0 / sjj)
        };
        let rss = pts
            .iter()
            .map(|p| (p[3] - a * p[j] - b * p[2]).powi(2))
            .sum();
        Some((a, var_a, rss))
    };
    let (per_k, var_k, rss_k) = fit(0)?;
    let (per_s, _, rss_s) = fit(1)?;
    let var = rss_k.min(rss_s).max(1e-300) / dof;
    let d = ConstantSpeedDrift {
        per_k,
        per_k_se: (var * var_k).sqrt(),
        per_s,
        temp_over_time: (rss_s - rss_k) / var,
        windows: pts.len(),
        groups: used,
        rise_k,
    };
    (d.per_k.is_finite() && d.per_k_se > 0.0 && d.temp_over_time.is_finite()).then_some(d)
}

/// Standard errors by which the torque must fall with the temperature at
/// constant speed for thermal softening to be named.
pub const THERMAL_Z: f64 = 3.0;
/// By how much (in units of the window mean's variance) the temperature
/// must explain the constant-speed drift better than the time.
pub const THERMAL_OVER_TIME: f64 = 2.0;

/// Why thermal softening cannot be named, or `None`: its signature is the
/// torque falling as the belt warms *at constant speed*
/// ([`constant_speed_drift`]), by [`THERMAL_Z`] standard errors, and
/// following the temperature better than the time by
/// [`THERMAL_OVER_TIME`] (a logger that drifts, or anything else that
/// changes in time, warms nothing). Across plateaus the temperature rises
/// with the time and with the speed, so a torque–speed curve the baseline
/// does not share reads as softening there (held-out seeds 8102/8103:
/// thermal softening named on a clean series, on bearing friction and on
/// power-law damping, whose torque stayed flat on every plateau while the
/// belt warmed by 12 K). Without steady speed groups, or without a logged
/// temperature, the signature cannot be read and the name is refused.
/// Other effects: `None`.
///
/// ```
/// use trackbelt_host::catalogue::EffectKind;
/// use trackbelt_host::diagnose_scroll::{thermal_veto, ConstantSpeedDrift};
/// let d = ConstantSpeedDrift {
///     per_k: 0.0065, per_k_se: 0.0006, per_s: 0.02, temp_over_time: 8.1,
///     windows: 17, groups: 2, rise_k: 18.5,
/// };
/// assert!(thermal_veto(EffectKind::ThermalSoftening, Some(&d)).is_none());
/// let flat = ConstantSpeedDrift { per_k: 0.0, temp_over_time: -0.2, ..d };
/// assert!(thermal_veto(EffectKind::ThermalSoftening, Some(&flat)).is_some());
/// assert!(thermal_veto(EffectKind::ThermalSoftening, None).is_some());
/// assert!(thermal_veto(EffectKind::BearingFriction, None).is_none());
/// ```
pub fn thermal_veto(effect: EffectKind, drift: Option<&ConstantSpeedDrift>) -> Option<String> {
    if effect != EffectKind::ThermalSoftening {
        return None;
    }
    let Some(d) = drift else {
        return Some(
            "its signature, the torque falling as the belt warms at constant speed, cannot be read (no steady stretch with a temperature change)".into(),
        );
    };
    let z = d.per_k / d.per_k_se;
    if z < THERMAL_Z {
        return Some(format!(
            "at constant speed the torque does not fall with the temperature ({:+.4} ± {:.4} 1/K over {} windows in {} speed groups, {:.1} K): the baseline's torque–speed curve differs, no softening",
            d.per_k, d.per_k_se, d.windows, d.groups, d.rise_k
        ));
    }
    (d.temp_over_time < THERMAL_OVER_TIME).then(|| {
        format!(
            "the torque falls at constant speed ({:+.4} ± {:.4} 1/K) but follows the time as well as the temperature (Δχ² {:.1}): a drift, not softening",
            d.per_k, d.per_k_se, d.temp_over_time
        )
    })
}
