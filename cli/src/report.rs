//! Readable report and SVG plots of a [`Diagnosis`].

use crate::plot::{write_svg, Figure, HLine, Series, SeriesKind};
use std::fmt::Write as _;
use std::path::Path;
use trackbelt_host::diagnose::{Diagnosis, SeriesDiagnosis, Signature};

/// The report printed by `trackbelt diagnose` without `--json`.
pub fn text(d: &Diagnosis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "dataset {}", d.report.dataset);
    let _ = writeln!(s, "baseline: {}", d.baseline_source);
    for w in &d.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    for r in &d.report.results {
        let _ = writeln!(s, "\n{} [{}]", r.series, r.kind);
        let _ = writeln!(s, "  effect:     {}", r.effect);
        let _ = writeln!(
            s,
            "  RMS error:  {:.3} {} before, {:.3} {} after",
            r.rms_before, r.unit, r.rms_after, r.unit
        );
        let _ = writeln!(s, "  evidence:   {}", r.evidence);
    }
    if let Some(v) = &d.report.verdict {
        let _ = writeln!(s, "\ndataset verdict ({} series)", d.report.results.len());
        let _ = writeln!(s, "  effect:     {}", v.effect);
        let _ = writeln!(s, "  evidence:   {}", v.evidence);
    }
    for sd in &d.scrolls {
        let _ = writeln!(
            s,
            "\n{}: fits on {:.1} s window means (noise floor {:.4} N·m)",
            sd.row.series,
            trackbelt_host::diagnose_scroll::WINDOW_S,
            sd.noise_nm
        );
        let _ = writeln!(
            s,
            "  {:<24}{:>10}{:>10}{:>12}{:>16}{:>8}",
            "model", "RMS N·m", "BIC", "cz N·m·s", "effect value", "sims"
        );
        for f in std::iter::once(&sd.baseline).chain(&sd.candidates) {
            let _ = writeln!(
                s,
                "  {:<24}{:>10.4}{:>10.1}{:>12.4}{:>16}{:>8}",
                f.model,
                f.rms,
                f.bic,
                f.cz_nms_per_rad,
                f.effect_value.map_or("-".into(), |v| format!("{v:.4}")),
                f.evaluations
            );
        }
    }
    for sd in &d.series {
        let _ = writeln!(
            s,
            "\n{}: fits (noise floor {:.2} mm)",
            sd.row.series, sd.noise_mm
        );
        let _ = writeln!(
            s,
            "  {:<22}{:>9}{:>10}{:>12}{:>10}{:>16}{:>8}",
            "model", "RMS mm", "BIC", "stiff×", "cz N·m·s", "effect value", "sims"
        );
        for f in std::iter::once(&sd.baseline).chain(&sd.candidates) {
            let _ = writeln!(
                s,
                "  {:<22}{:>9.3}{:>10.1}{:>12.4}{:>10.4}{:>16}{:>8}",
                f.model,
                f.rms,
                f.bic,
                f.stiffness_scale,
                f.cz_nms_per_rad,
                f.effect_value.map_or("-".into(), |v| format!("{v:.4}")),
                f.evaluations
            );
        }
        let _ = writeln!(
            s,
            "  per-cycle signatures (amplitude mm: log decrement, period s)"
        );
        for (name, sig) in ["measured", "baseline", "best candidate"]
            .iter()
            .zip(&sd.signatures)
        {
            let cells: Vec<String> = sig
                .cycles
                .iter()
                .map(|c| {
                    format!(
                        "{:.0}: {:.2}, {:.3}",
                        c.amplitude_mm, c.log_decrement, c.period_s
                    )
                })
                .collect();
            let _ = writeln!(s, "    {name:<15} {}", cells.join(" | "));
        }
    }
    s
}

fn sig_series(
    label: &str,
    sig: &Signature,
    y: fn(&trackbelt_host::diagnose::Cycle) -> f64,
    kind: SeriesKind,
) -> Series {
    Series {
        label: label.to_string(),
        points: sig.cycles.iter().map(|c| (c.amplitude_mm, y(c))).collect(),
        kind,
    }
}

/// Write the plots of every dynamic series into `dir`: measured and fitted
/// heights, residual before/after, log decrement and period against
/// amplitude.
pub fn plots(d: &Diagnosis, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for (i, sd) in d.series.iter().enumerate() {
        plot_series(sd, dir, i + 1)?;
    }
    for (i, sd) in d.scrolls.iter().enumerate() {
        plot_scroll(sd, dir, i + 1)?;
    }
    Ok(())
}

fn plot_scroll(
    sd: &trackbelt_host::diagnose_scroll::ScrollDiagnosis,
    dir: &Path,
    n: usize,
) -> Result<(), String> {
    let shown = sd
        .chosen
        .map(|i| &sd.candidates[i])
        .or_else(|| sd.candidates.iter().min_by(|a, b| a.bic.total_cmp(&b.bic)));
    let pts = |x: &[f64], y: &[f64]| -> Vec<(f64, f64)> {
        x.iter().copied().zip(y.iter().copied()).collect()
    };
    let mut ts = vec![
        Series {
            label: "measured".into(),
            points: pts(&sd.t_s, &sd.torque_nm),
            kind: SeriesKind::Markers,
        },
        Series {
            label: "baseline (refitted)".into(),
            points: pts(&sd.t_s, &sd.baseline.model_values),
            kind: SeriesKind::Line,
        },
    ];
    if let Some(f) = shown {
        ts.push(Series {
            label: format!("baseline + {}", f.model),
            points: pts(&sd.t_s, &f.model_values),
            kind: SeriesKind::Dashed,
        });
    }
    let title = format!("{}: drive torque", sd.row.series);
    write(
        &dir.join(format!("diagnose_scroll_{n}_torque_time.svg")),
        &Figure {
            title: &title,
            x_label: "t [s]",
            y_label: "drive torque [N·m]",
            series: &ts,
            hlines: &[],
            equal_aspect: false,
        },
    )?;
    let mut rs = vec![Series {
        label: format!("before: baseline, RMS {:.3} N·m", sd.baseline.rms),
        points: pts(&sd.t_windows_s, &sd.baseline.residual),
        kind: SeriesKind::Line,
    }];
    if let Some(f) = shown {
        rs.push(Series {
            label: format!("after: + {}, RMS {:.3} N·m", f.model, f.rms),
            points: pts(&sd.t_windows_s, &f.residual),
            kind: SeriesKind::Line,
        });
    }
    let hl = [
        HLine {
            label: format!("noise floor +{:.3} N·m", sd.noise_nm),
            y: sd.noise_nm,
        },
        HLine {
            label: format!("noise floor −{:.3} N·m", sd.noise_nm),
            y: -sd.noise_nm,
        },
    ];
    let title = format!(
        "{}: residual of {:.1} s window means, effect {}",
        sd.row.series,
        trackbelt_host::diagnose_scroll::WINDOW_S,
        sd.row.effect
    );
    write(
        &dir.join(format!("diagnose_scroll_{n}_residual.svg")),
        &Figure {
            title: &title,
            x_label: "t [s]",
            y_label: "residual [N·m]",
            series: &rs,
            hlines: &hl,
            equal_aspect: false,
        },
    )?;
    let empty: Vec<f64> = vec![0.0; sd.t_s.len()];
    let after = shown.map_or(&empty, |f| &f.model_values);
    let tv = trackbelt_host::diagnose_scroll::torque_vs_speed(
        &sd.omega_rad_s,
        &[&sd.torque_nm, &sd.baseline.model_values, after],
    );
    let col = |k: usize| -> Vec<(f64, f64)> { tv.iter().map(|(w, m)| (*w, m[k])).collect() };
    let mut vs = vec![
        Series {
            label: "measured (plateau means)".into(),
            points: col(0),
            kind: SeriesKind::Markers,
        },
        Series {
            label: "baseline".into(),
            points: col(1),
            kind: SeriesKind::Line,
        },
    ];
    if let Some(f) = shown {
        vs.push(Series {
            label: format!("baseline + {}", f.model),
            points: col(2),
            kind: SeriesKind::Dashed,
        });
    }
    let title = format!("{}: torque against speed", sd.row.series);
    write(
        &dir.join(format!("diagnose_scroll_{n}_torque_speed.svg")),
        &Figure {
            title: &title,
            x_label: "drive speed [rad/s]",
            y_label: "drive torque [N·m]",
            series: &vs,
            hlines: &[],
            equal_aspect: false,
        },
    )
}

fn plot_series(sd: &SeriesDiagnosis, dir: &Path, n: usize) -> Result<(), String> {
    let after = sd.chosen.map(|i| &sd.candidates[i]);
    let best = sd.candidates.iter().min_by(|a, b| a.bic.total_cmp(&b.bic));
    let shown = after.or(best);
    let pts =
        |y: &[f64]| -> Vec<(f64, f64)> { sd.t_s.iter().copied().zip(y.iter().copied()).collect() };
    let mut hs = vec![
        Series {
            label: "measured".into(),
            points: pts(&sd.measured_mm),
            kind: SeriesKind::Markers,
        },
        Series {
            label: "baseline (refitted)".into(),
            points: pts(&sd.baseline.model_values),
            kind: SeriesKind::Line,
        },
    ];
    if let Some(f) = shown {
        hs.push(Series {
            label: format!("baseline + {}", f.model),
            points: pts(&f.model_values),
            kind: SeriesKind::Dashed,
        });
    }
    let title = format!("{}: height of A", sd.row.series);
    write(
        &dir.join(format!("diagnose_{n}_height.svg")),
        &Figure {
            title: &title,
            x_label: "t [s]",
            y_label: "height of A [mm]",
            series: &hs,
            hlines: &[],
            equal_aspect: false,
        },
    )?;
    let mut rs = vec![Series {
        label: format!("before: baseline, RMS {:.2} mm", sd.baseline.rms),
        points: pts(&sd.baseline.residual),
        kind: SeriesKind::Line,
    }];
    if let Some(f) = shown {
        rs.push(Series {
            label: format!("after: + {}, RMS {:.2} mm", f.model, f.rms),
            points: pts(&f.residual),
            kind: SeriesKind::Line,
        });
    }
    let hl = [
        HLine {
            label: format!("noise floor +{:.2} mm", sd.noise_mm),
            y: sd.noise_mm,
        },
        HLine {
            label: format!("noise floor −{:.2} mm", sd.noise_mm),
            y: -sd.noise_mm,
        },
    ];
    let title = format!(
        "{}: residual (measured − model), effect {}",
        sd.row.series, sd.row.effect
    );
    write(
        &dir.join(format!("diagnose_{n}_residual.svg")),
        &Figure {
            title: &title,
            x_label: "t [s]",
            y_label: "residual [mm]",
            series: &rs,
            hlines: &hl,
            equal_aspect: false,
        },
    )?;
    let names = [
        "measured",
        "baseline",
        shown.map_or("best", |f| f.model.as_str()),
    ];
    let kinds = [SeriesKind::Markers, SeriesKind::Line, SeriesKind::Dashed];
    let dec: Vec<Series> = (0..3)
        .map(|k| sig_series(names[k], &sd.signatures[k], |c| c.log_decrement, kinds[k]))
        .collect();
    let title = format!("{}: log decrement per cycle vs amplitude", sd.row.series);
    write(
        &dir.join(format!("diagnose_{n}_decrement.svg")),
        &Figure {
            title: &title,
            x_label: "amplitude [mm]",
            y_label: "log decrement per cycle",
            series: &dec,
            hlines: &[],
            equal_aspect: false,
        },
    )?;
    let per: Vec<Series> = (0..3)
        .map(|k| sig_series(names[k], &sd.signatures[k], |c| c.period_s, kinds[k]))
        .collect();
    let title = format!("{}: period per cycle vs amplitude", sd.row.series);
    write(
        &dir.join(format!("diagnose_{n}_period.svg")),
        &Figure {
            title: &title,
            x_label: "amplitude [mm]",
            y_label: "period [s]",
            series: &per,
            hlines: &[],
            equal_aspect: false,
        },
    )
}

fn write(path: &Path, fig: &Figure) -> Result<(), String> {
    write_svg(path, fig).map_err(|e| e.to_string())
}

/// Short column heading of an answer: the initials of an effect
/// identifier (`joint_friction` → `JF`), the word otherwise.
fn short(answer: &str) -> String {
    match answer {
        "none" | "error" => answer.to_string(),
        "unexplained" => "unexpl".to_string(),
        a => a
            .split('_')
            .filter_map(|w| w.chars().next())
            .flat_map(char::to_uppercase)
            .collect(),
    }
}

/// The comparison part of `validate-diagnosis --again DIR`: the kept
/// run's right answers and wrong names against this build's, and every
/// answer that changed.
pub fn again(r: &trackbelt_host::validate::Again, dir: &Path) -> String {
    let s = &r.report.summary;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\nagain, on the datasets kept in {}: right {}/{} before, {}/{} now; wrong names {} before, {} now; {} answer(s) changed",
        dir.display(),
        r.right_before,
        s.datasets,
        s.right,
        s.datasets,
        r.wrong_names_before,
        s.wrong_names,
        r.changed.len()
    );
    for c in &r.changed {
        let _ = writeln!(
            out,
            "  {}: {} -> {} (right: {})",
            c.dataset, c.before, c.after, c.expected
        );
    }
    out
}

/// `validate-diagnosis`: the confusion matrix, the summary line against the
/// issue's targets, residuals and times.
pub fn validation(r: &trackbelt_host::validate::Report) -> String {
    use trackbelt_host::validate::{
        Stats, NEAR_NOISE_FACTOR, NEAR_NOISE_REDUCTION, TARGET_MIN_PER_OUTCOME,
        TARGET_RIGHT_FRACTION,
    };
    let m = &r.matrix;
    let s = &r.summary;
    let mut o = String::new();
    let last = r.seed.wrapping_add(r.count_per_outcome as u64 - 1);
    let _ = writeln!(
        o,
        "diagnosis ({}) on {} datasets of the truth generator, seeds {}–{} per outcome, {}, {} threads, {:.1} s\n",
        r.variant,
        s.datasets,
        r.seed,
        last,
        r.magnitude.map_or("magnitudes 0.35–1".to_string(), |m| format!(
            "every effect and disturbance at magnitude {m}"
        )),
        r.threads,
        r.wall_s
    );
    let label = |row: &trackbelt_host::validate::MatrixRow| {
        if row.outcome == "none" {
            format!("none ({})", row.kind)
        } else {
            row.outcome.clone()
        }
    };
    let w = m
        .rows
        .iter()
        .map(|x| label(x).len())
        .max()
        .unwrap_or(5)
        .max(14);
    let heads: Vec<String> = m.columns.iter().map(|c| short(c)).collect();
    let _ = write!(o, "{:<w$}", "truth \\ answer");
    for h in &heads {
        let _ = write!(o, " {:>6}", h);
    }
    let _ = writeln!(o, "  | right");
    for row in &m.rows {
        let _ = write!(o, "{:<w$}", label(row));
        for (c, n) in m.columns.iter().zip(&row.counts) {
            let cell = if *n == 0 {
                ".".to_string()
            } else if *c == row.expected {
                format!("[{n}]")
            } else {
                n.to_string()
            };
            let _ = write!(o, " {cell:>6}");
        }
        let _ = writeln!(o, "  | {}/{}", row.right, row.total);
    }
    let legend: Vec<String> = m
        .columns
        .iter()
        .zip(&heads)
        .filter(|(c, h)| c != h)
        .map(|(c, h)| format!("{h} {c}"))
        .collect();
    let _ = writeln!(o, "[n]: right answers; {}\n", legend.join(", "));
    let mark = |ok: bool| if ok { "met" } else { "NOT met" };
    let _ = writeln!(
        o,
        "right {}/{} ({:.0} %, target ≥ {:.0} %: {}); wrong names {} (target 0: {}); \
         near the noise {}/{} named effects (rms_after ≤ {NEAR_NOISE_FACTOR} × noise or ≤ before/{NEAR_NOISE_REDUCTION}: {}); \
         datasets per outcome ≥ {} (target {TARGET_MIN_PER_OUTCOME}: {})",
        s.right,
        s.datasets,
        100.0 * s.right_fraction,
        100.0 * TARGET_RIGHT_FRACTION,
        mark(s.right_fraction >= TARGET_RIGHT_FRACTION),
        s.wrong_names,
        mark(s.wrong_names == 0),
        s.near_noise_met,
        s.named,
        mark(s.near_noise_met == s.named),
        s.min_per_outcome,
        mark(s.min_per_outcome >= TARGET_MIN_PER_OUTCOME),
    );
    let _ = writeln!(
        o,
        "issue 11 target: {}\n",
        if s.target_met { "met" } else { "not met" }
    );
    if !r.by_runs.is_empty() {
        let _ = writeln!(
            o,
            "{} runs of each belt per dataset; on the first runs alone (the series' own answers combined as the verdict combines them):",
            r.runs_per_dataset
        );
        for b in &r.by_runs {
            let _ = writeln!(
                o,
                "  {} run{}: right {}/{} ({:.0} %), wrong names {}",
                b.runs,
                if b.runs == 1 { "" } else { "s" },
                b.right,
                b.datasets,
                100.0 * b.right as f64 / b.datasets.max(1) as f64,
                b.wrong_names
            );
        }
        let _ = writeln!(o);
    }
    let st = |x: &Option<Stats>| match x {
        Some(x) => format!("{:.3} / {:.3}", x.median, x.max),
        None => "-".to_string(),
    };
    let _ = writeln!(
        o,
        "{:<w$} {:>5}  {:>17}  {:>17}  {:>17}  {:>15}",
        "median / max", "unit", "rms before", "rms after", "noise put in", "diagnosis, s"
    );
    for row in &m.rows {
        let e = &row.errors;
        let _ = writeln!(
            o,
            "{:<w$} {:>5}  {:>17}  {:>17}  {:>17}  {:>15}",
            label(row),
            e.unit,
            st(&e.rms_before),
            st(&e.rms_after),
            st(&e.noise),
            match e.diagnose_s {
                Some(x) => format!("{:.1} / {:.1}", x.median, x.max),
                None => "-".to_string(),
            }
        );
    }
    let t = |x: &Option<Stats>| match x {
        Some(x) => format!("median {:.1} s, max {:.1} s", x.median, x.max),
        None => "-".to_string(),
    };
    let _ = writeln!(
        o,
        "\ntime per dataset ({} threads shared): generation {}; diagnosis {} (dynamic {}; scroll {})",
        r.threads,
        t(&s.generate_s),
        t(&s.diagnose_s),
        t(&s.diagnose_dynamic_s),
        t(&s.diagnose_scroll_s)
    );
    if r.threads > 1 && !r.datasets.is_empty() {
        // A worker waiting for its own simulations runs other datasets'
        // (work stealing), so a dataset's time above includes others'
        // work; the run's core time per dataset is the fair figure.
        let _ = writeln!(
            o,
            "core time per dataset (wall × threads / datasets, generation included): {:.1} s; `--threads 1` gives each dataset's own time",
            r.wall_s * r.threads as f64 / r.datasets.len() as f64
        );
    }
    use trackbelt_host::validate::CEILING_BINS;
    let [lo, hi] = CEILING_BINS;
    for (rows, what) in [
        (&r.by_ceiling, format!("evidence ceiling (Δχ² the data hold against the clean twin fitted with the truth's own law; under {lo:.0} no method can name the effect)")),
        (&r.by_separation, format!("separation (the smaller of the evidence ceiling and the rival ceilings, Δχ² against a twin with each other effect of the kind, its law fitted too; under {lo:.0} no method can tell the effect from the nearest)")),
    ] {
        if rows.is_empty() {
            continue;
        }
        let _ = writeln!(o, "\nright answers by {what}:");
        let heads = [
            format!("Δχ² < {lo:.0}"),
            format!("{lo:.0}–{hi:.0}"),
            format!("≥ {hi:.0}"),
        ];
        let _ = writeln!(
            o,
            "{:<w$} {:>10} {:>10} {:>10}",
            "effect", heads[0], heads[1], heads[2]
        );
        for row in rows.iter() {
            let cell = |(a, b): (usize, usize)| {
                if b == 0 {
                    ".".to_string()
                } else {
                    format!("{a}/{b}")
                }
            };
            let _ = writeln!(
                o,
                "{:<w$} {:>10} {:>10} {:>10}",
                row.effect,
                cell(row.bins[0]),
                cell(row.bins[1]),
                cell(row.bins[2])
            );
        }
    }
    let misses: Vec<_> = r.datasets.iter().filter(|d| !d.right).collect();
    if !misses.is_empty() {
        let _ = writeln!(o, "\nnot right:");
        for d in misses {
            let mut ev = d.evidence.clone();
            if ev.chars().count() > 160 {
                ev = ev.chars().take(160).collect::<String>() + "…";
            }
            let _ = writeln!(
                o,
                "  {} {} seed {} (magnitude {:.2}{}): {}{}, expected {}: {ev}",
                d.outcome,
                d.kind,
                d.seed,
                d.magnitude,
                d.evidence_ceiling
                    .map_or(String::new(), |c| format!(", ceiling Δχ² {c:.0}"))
                    + &d.separation()
                        .filter(|s| s.1 != "clean")
                        .map_or(String::new(), |(c, r)| format!(", {c:.0} against {r}")),
                d.answer,
                if d.wrong_name { " (WRONG NAME)" } else { "" },
                d.expected,
            );
        }
    }
    for d in &r.datasets {
        for c in d.rival_ceilings.iter().filter(|c| c.error.is_some()) {
            let _ = writeln!(
                o,
                "rival ceiling not measured: {} {} seed {} against {}: {}",
                d.outcome,
                d.kind,
                d.seed,
                c.rival,
                c.error.as_deref().unwrap_or_default()
            );
        }
    }
    for d in r.datasets.iter().filter(|d| d.ceiling_error.is_some()) {
        let _ = writeln!(
            o,
            "evidence ceiling not measured: {} {} seed {}: {}",
            d.outcome,
            d.kind,
            d.seed,
            d.ceiling_error.as_deref().unwrap_or_default()
        );
    }
    for k in &r.skipped {
        let _ = writeln!(
            o,
            "skipped: {} {} seed {}: {}",
            k.outcome, k.kind, k.seed, k.reason
        );
    }
    o
}
