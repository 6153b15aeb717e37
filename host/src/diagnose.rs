//! Closing the loop with measured data (SPEC §5, `trackbelt diagnose`):
//! load a dataset and diagnose each of its series, dynamic
//! ([`crate::diagnose_dynamic`]) and scroll ([`crate::diagnose_scroll`]),
//! or, for datasets that hold only summary figures (like
//! `shredder-table1`), compare the baseline's figures with the measured
//! means against the run-to-run spread: `none` when every figure is inside
//! it, `unexplained` otherwise (summary figures cannot tell the effects
//! apart).
//!
//! The names of the shared modules are re-exported here.

pub use crate::catalogue::{
    baseline, calibrated_baseline, scale_stiffness, Baseline, EffectKind, PLACEHOLDER_E38,
    RECALIBRATION_MAX_ERR_PCT, SCROLL_EFFECTS,
};
pub use crate::diagnose_dynamic::{
    diagnose_dynamic, fit_dynamic, signature, Cycle, SeriesDiagnosis, Signature,
    EVALS_PER_DYNAMIC_SERIES,
};
pub use crate::evidence::{
    decide, lag1, noise_floor, Fitted, ResultRow, BIC_MARGIN, BIC_SEPARATION, FLOOR_FACTOR,
    WHITE_LAG1,
};

use crate::dataset::{self, Dataset};
pub use crate::diagnose_scroll::diagnose_scroll_from;
use crate::diagnose_scroll::{ScrollDiagnosis, CZ_ITERATIONS, EVALS_PER_SCROLL_SERIES};
use crate::error::Result;
use crate::evidence::rms;
use crate::progress::Progress;
use serde::Serialize;
use std::path::Path;
use trackbelt::params::Variant;

/// `diagnose --json` document.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Dataset name.
    pub dataset: String,
    /// One row per series (or per summary).
    pub results: Vec<ResultRow>,
    /// With two series or more: the dataset's answer from theirs
    /// ([`crate::verdict::dataset_verdict`]); left out of the JSON
    /// otherwise (the one row is the answer).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<crate::verdict::Verdict>,
}

/// Summary-figure comparison for datasets without series.
pub fn diagnose_summary(base: &Baseline, ds: &Dataset) -> Result<Option<ResultRow>> {
    let means = ds.dynamic_means();
    let stat = ds.static_mean();
    if stat.is_none() && means.hd_mm.is_none() && means.period_s.is_none() {
        return Ok(None);
    }
    let model = trackbelt::params::Model::new(base.belt, base.law.clone())?;
    let roller = ds.dynamics.first().map_or(1.3, |d| d.roller_kg);
    let mut chain = Box::new(trackbelt::ReferenceChain::new(
        model,
        trackbelt::Settings::default(),
    )?);
    let mut monitor = crate::validity::Monitor::new();
    let st = trackbelt::bench::static_test(&mut *chain)?;
    monitor.after_static(&mut *chain);
    let dy = trackbelt::bench::dynamic_test(
        &mut *chain,
        &trackbelt::bench::DynamicTest {
            roller_kg: roller,
            duration_s: 5.0,
        },
        |c| monitor.observe(c),
    )?;
    monitor.after_dynamic(&mut *chain, &dy);
    let validity_warnings = monitor.validity().check()?;
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
        evidence: if validity_warnings.is_empty() {
            format!("model/measured mean: {}; {why}", parts.join(", "))
        } else {
            format!(
                "model/measured mean: {}; {why}; warnings: {}",
                parts.join(", "),
                validity_warnings.join("; ")
            )
        },
        candidates: Vec::new(),
        gain_samples: None,
    }))
}
/// The whole diagnosis of a dataset directory.
pub struct Diagnosis {
    /// The JSON document.
    pub report: Report,
    /// Per dynamic series details.
    pub series: Vec<SeriesDiagnosis>,
    /// Per scroll series details.
    pub scrolls: Vec<ScrollDiagnosis>,
    /// Where the baseline came from.
    pub baseline_source: String,
    /// Warnings of the dataset reader.
    pub warnings: Vec<String>,
}

/// Load `dir` and diagnose every series in it. `progress` is told the
/// most simulations first, then gets one step per simulation.
pub fn diagnose_dir(
    dir: &Path,
    variant: Variant,
    params: Option<&Path>,
    progress: &dyn Progress,
) -> Result<Diagnosis> {
    let ds = dataset::load(dir)?;
    let mut base = baseline(variant, params)?;
    // The dataset's own belt (length, thickness, mass), simulated with the
    // baseline's number of links.
    base.belt = ds.belt.belt(base.belt.links);
    let with_series: Vec<_> = ds
        .dynamics
        .iter()
        .enumerate()
        .filter_map(|(i, d)| d.series.as_ref().map(|s| (i, d, s)))
        .collect();
    let recalibrate =
        !with_series.is_empty() || (!ds.scrolls.is_empty() && ds.static_mean().is_some());
    // A scroll series may have cz refitted on both tables.
    let second_table = if recalibrate {
        1 + CZ_ITERATIONS as u64
    } else {
        0
    };
    progress.set_total(
        EVALS_PER_DYNAMIC_SERIES * with_series.len() as u64
            + (EVALS_PER_SCROLL_SERIES + second_table) * ds.scrolls.len() as u64,
    );
    // A dataset with dynamic series, or with scroll series and static
    // figures: the baseline is this belt calibrated on this dataset's own
    // figures (the file's table is the start and the fallback). Scroll
    // series refit cz on the rig, from either table (see
    // [`diagnose_scroll_from`]); summary-only datasets are compared with
    // the file's table as it is (a table fitted to the very means it is
    // compared with would say nothing).
    let recalibrated = recalibrate.then(|| crate::catalogue::calibrated_baseline(&base, &ds));
    let bases: Vec<&Baseline> = std::iter::once(&base)
        .chain(recalibrated.as_ref())
        .collect();
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for (i, d, s) in with_series {
        let label = d
            .label
            .clone()
            .unwrap_or_else(|| format!("dynamic {}", i + 1));
        let label = format!("{label} ({})", s.file.display());
        let sd = diagnose_dynamic(
            &bases,
            &label,
            d.roller_kg,
            d.period_s,
            &s.t_s,
            &s.a_height_mm,
            progress,
        )?;
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
        let sd = diagnose_scroll_from(&bases, &label, e, progress)?;
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
            verdict: (rows.len() > 1)
                .then(|| crate::verdict::dataset_verdict(&rows))
                .flatten(),
            results: rows,
        },
        series,
        scrolls,
        baseline_source: base.source,
        warnings: ds.warnings,
    })
}
