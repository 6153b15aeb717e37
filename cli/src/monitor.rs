//! `trackbelt monitor`: the onboard belt-health monitor (f32, the embedded
//! build) over a dataset's scroll series.

use std::path::PathBuf;

use serde_json::{json, Value};
use trackbelt::params::Variant;
use trackbelt_host::monitor::{monitor_dataset, MonitorOptions, MonitorRun};

use crate::plot::{write_svg, Figure, HLine, Series, SeriesKind};

/// Arguments of `trackbelt monitor`.
#[derive(clap::Args)]
pub struct MonitorArgs {
    /// Dataset directory (DATA.md) with at least one scroll series.
    dataset_dir: PathBuf,
    /// The belt's joint law (params TOML); default: params/<variant>.toml.
    #[arg(long)]
    params: Option<PathBuf>,
    /// E38, E56 or E76 (the link count of the estimator's belt).
    #[arg(long, default_value = "E56")]
    variant: String,
    /// Feed the series' `belt_temp_c` to the monitor's temperature law
    /// (−0.8 %/K from 20 °C).
    #[arg(long)]
    temperature: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Write an SVG of the estimates over time into this directory.
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn run_json(r: &MonitorRun) -> Value {
    json!({
        "series": r.series,
        "loss_scale": r.loss_scale,
        "loss_scale_sd": r.loss_scale_sd,
        "bearing_nm": r.bearing_nm,
        "bearing_sd": r.bearing_sd,
        "health": r.health,
        "alarm": !r.alarms.is_empty(),
        "alarms": r.alarms,
        "alarm_at_s": r.alarm_at_s,
        "bad_rows": r.bad_rows,
    })
}

/// Run the command.
pub fn cmd_monitor(a: MonitorArgs) -> Result<(), String> {
    let variant = Variant::parse(&a.variant)
        .ok_or_else(|| format!("--variant {:?}: expected E38, E56 or E76", a.variant))?;
    let ds = trackbelt_host::dataset::load(&a.dataset_dir).map_err(|e| e.to_string())?;
    if ds.scrolls.is_empty() {
        return Err(format!(
            "{}: the dataset has no scroll series",
            a.dataset_dir.display()
        ));
    }
    for w in &ds.warnings {
        eprintln!("warning: {w}");
    }
    let options = MonitorOptions {
        use_temperature: a.temperature,
        ..MonitorOptions::default()
    };
    let runs =
        monitor_dataset(&ds, variant, a.params.as_deref(), &options).map_err(|e| e.to_string())?;
    if let Some(dir) = &a.plot {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (i, r) in runs.iter().enumerate() {
            // At most about 2000 points per curve (a small file).
            let every = r.trace.len().div_ceil(2_000).max(1);
            let pick = |f: fn(&trackbelt_host::monitor::MonitorSample) -> f64| {
                r.trace
                    .iter()
                    .step_by(every)
                    .map(|s| (s.t_s, f(s)))
                    .collect::<Vec<_>>()
            };
            let series = [
                Series {
                    label: "loss scale".into(),
                    points: pick(|s| s.loss_scale),
                    kind: SeriesKind::Line,
                },
                Series {
                    label: "bearing friction, N·m".into(),
                    points: pick(|s| s.bearing_nm),
                    kind: SeriesKind::Line,
                },
                Series {
                    label: "health index".into(),
                    points: pick(|s| s.health),
                    kind: SeriesKind::Dashed,
                },
            ];
            let hlines = [
                HLine {
                    label: "drift threshold".into(),
                    y: 1.2,
                },
                HLine {
                    label: String::new(),
                    y: 0.8,
                },
            ];
            let title = format!("Belt-health monitor: {} ({})", r.series, ds.name);
            let path = dir.join(format!("monitor-{}.svg", i + 1));
            write_svg(
                &path,
                &Figure {
                    title: &title,
                    x_label: "time, s",
                    y_label: "estimate",
                    series: &series,
                    hlines: &hlines,
                    equal_aspect: false,
                },
            )
            .map_err(|e| e.to_string())?;
            eprintln!("wrote {}", path.display());
        }
    }
    if a.json {
        let v = if runs.len() == 1 {
            run_json(&runs[0])
        } else {
            json!({ "results": runs.iter().map(run_json).collect::<Vec<_>>() })
        };
        println!("{v}");
        return Ok(());
    }
    println!("belt-health monitor (f32) on {}", ds.name);
    for r in &runs {
        println!(
            "  {}: loss scale {:.3} ± {:.3}, bearing {:.4} ± {:.4} N·m, health {:.2}, {}{}",
            r.series,
            r.loss_scale,
            r.loss_scale_sd,
            r.bearing_nm,
            r.bearing_sd,
            r.health,
            if r.alarms.is_empty() {
                "no alarm".to_string()
            } else {
                format!("alarm {}", r.alarms.join(" | "))
            },
            r.alarm_at_s
                .map_or(String::new(), |t| format!(" (first at {t:.1} s)")),
        );
        if r.bad_rows > 0 {
            println!("    {} rows skipped as bad input", r.bad_rows);
        }
    }
    Ok(())
}
