//! `trackbelt`: simulate the belt, reproduce the paper, benchmark.

use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use trackbelt::bench::DynamicTest;
use trackbelt::params::{paper, Method, Variant};
use trackbelt::Settings;
use trackbelt_cli::paper::{rows, run_all, Row};
use trackbelt_cli::params_file::ParamsFile;
use trackbelt_cli::plot::{write_svg, write_svg_grid, Figure, HLine, Series, SeriesKind};
use trackbelt_cli::sim::{model_for, simulate, SimOutput, SimTrace, Tests};

#[derive(Parser)]
#[command(
    name = "trackbelt",
    version,
    about = "Rubber track belt as a chain of links: simulate, reproduce the paper, benchmark"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq)]
enum TestKind {
    Static,
    Dynamic,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run the static (and dynamic) bench test for one variant and method.
    Simulate(SimArgs),
    /// Reproduce the paper's Tables 2–5 and 8 (methods I and II).
    Paper {
        /// Print one JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Write SVG plots into this directory.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Benchmark one full test (settle + 5 s of oscillation), method I.
    Bench {
        /// Repetitions per variant (the minimum is reported).
        #[arg(long, default_value_t = 5)]
        repeat: usize,
        /// Print one JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Fit the model to a dataset's series, trace the residual to an effect
    /// the model lacks, refit with it and report the error before and after.
    Diagnose(DiagnoseArgs),
    /// Write a synthetic dataset: the model with one effect (or none, or a
    /// disturbance outside the catalogue), sampled like the camera.
    Synth(SynthArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = match cli.cmd {
        Cmd::Simulate(args) => cmd_simulate(args),
        Cmd::Paper { json, plot } => cmd_paper(json, plot.as_deref()),
        Cmd::Bench { repeat, json } => cmd_bench(repeat, json),
        Cmd::Diagnose(args) => cmd_diagnose(args),
        Cmd::Synth(args) => cmd_synth(args),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

#[derive(clap::Args)]
struct SimArgs {
    /// E38, E56 or E76.
    #[arg(long)]
    variant: String,
    /// I, II or III.
    #[arg(long)]
    method: String,
    /// Joint law from a params file (TOML) instead of the paper's.
    #[arg(long)]
    params: Option<PathBuf>,
    /// `static` stops after the static test; `dynamic` runs both.
    #[arg(long, value_enum, default_value = "dynamic")]
    test: TestKind,
    /// Duration of the dynamic test, s.
    #[arg(long, default_value_t = 5.0)]
    duration_s: f64,
    /// Nominal integrator step, ms.
    #[arg(long, default_value_t = 2.0)]
    step_ms: f64,
    /// Floor stiffness per contact point, N/m.
    #[arg(long)]
    floor_stiffness_n_per_m: Option<f64>,
    /// Floor friction coefficient.
    #[arg(long)]
    floor_friction: Option<f64>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Write SVG plots into this directory.
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn cmd_simulate(a: SimArgs) -> Result<(), String> {
    let variant = Variant::parse(&a.variant)
        .ok_or_else(|| format!("--variant {:?}: expected E38, E56 or E76", a.variant))?;
    let method = Method::parse(&a.method)
        .ok_or_else(|| format!("--method {:?}: expected I, II or III", a.method))?;
    let law = match &a.params {
        Some(p) => {
            let (pf, law) = ParamsFile::load(p)?;
            if pf.method()? != method {
                return Err(format!(
                    "{} holds a method {} law but --method {} was given",
                    p.display(),
                    pf.method,
                    method.name()
                ));
            }
            law
        }
        None => paper::joint_law(variant, method).ok_or_else(|| {
            format!(
                "method III needs a torque–angle table: pass --params FILE \
                 (no calibrated table for {} is shipped yet)",
                variant.name()
            )
        })?,
    };
    let mut model = model_for(variant.links(), law).map_err(|e| e.to_string())?;
    if let Some(k) = a.floor_stiffness_n_per_m {
        model.floor.stiffness_n_per_m = k;
    }
    if let Some(mu) = a.floor_friction {
        model.floor.friction = mu;
    }
    model.validate().map_err(|e| e.to_string())?;
    let settings = Settings {
        step_s: a.step_ms * 1e-3,
        ..Settings::default()
    };
    let tests = if a.test == TestKind::Static {
        Tests::Static
    } else {
        Tests::Both
    };
    let dynamic = DynamicTest {
        duration_s: a.duration_s,
        ..DynamicTest::default()
    };
    let (out, trace) =
        simulate(model, method, tests, settings, dynamic).map_err(|e| e.to_string())?;
    if let Some(dir) = &a.plot {
        plot_run(dir, &out, &trace)?;
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&out).map_err(|e| e.to_string())?
        );
    } else {
        let reference = paper::simulated(variant, method);
        print_side_by_side(&out, &reference);
    }
    Ok(())
}

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".into(), |x| format!("{x:.prec$}"))
}

fn fmt_range(v: Option<[f64; 2]>) -> String {
    v.map_or("-".into(), |r| format!("{:.1}…{:.1}", r[0], r[1]))
}

fn print_side_by_side(o: &SimOutput, p: &paper::Figures) {
    let e = &paper::EXPERIMENT_MEAN;
    println!(
        "{} method {}   (simulated in {:.3} s)",
        o.variant, o.method, o.wall_s
    );
    println!(
        "{:<14}{:>12}{:>12}{:>12}",
        "figure", "ours", "paper sim", "Table 1"
    );
    let row = |name: &str, ours: String, ps: f64, ex: f64, prec: usize| {
        println!("{name:<14}{ours:>12}{ps:>12.prec$}{ex:>12.prec$}");
    };
    row("Hs [mm]", format!("{:.1}", o.hs_mm), p.hs_mm, e.hs_mm, 1);
    row("Ws [mm]", format!("{:.1}", o.ws_mm), p.ws_mm, e.ws_mm, 1);
    row("Hd [mm]", fmt_opt(o.hd_mm, 1), p.hd_mm, e.hd_mm, 1);
    row("Wd [mm]", fmt_opt(o.wd_mm, 1), p.wd_mm, e.wd_mm, 1);
    row("T [s]", fmt_opt(o.period_s, 3), p.period_s, e.period_s, 3);
    row(
        "Λ",
        fmt_opt(o.log_decrement, 3),
        p.log_decrement,
        e.log_decrement,
        3,
    );
    println!(
        "{:<14}{:>12}{:>12}",
        "ζ at A [°]",
        fmt_range(o.angle_a_deg),
        format!("{:.1}…{:.1}", p.angle_a_deg[0], p.angle_a_deg[1])
    );
    println!(
        "{:<14}{:>12}{:>12}",
        "ζ at C [°]",
        fmt_range(o.angle_c_deg),
        format!("{:.1}…{:.1}", p.angle_c_deg[0], p.angle_c_deg[1])
    );
}

fn plot_err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

fn height_figure<'a>(title: &'a str, series: &'a [Series], hlines: &'a [HLine]) -> Figure<'a> {
    Figure {
        title,
        x_label: "t [s]",
        y_label: "height of A [mm]",
        series,
        hlines,
        equal_aspect: false,
    }
}

fn plot_run(dir: &Path, o: &SimOutput, t: &SimTrace) -> Result<(), String> {
    let tag = format!("{}_{}", o.variant, o.method);
    if !t.a_height.is_empty() {
        let series = [Series {
            label: format!("{} method {}", o.variant, o.method),
            points: t.a_height.clone(),
            kind: SeriesKind::Line,
        }];
        let hlines = [
            HLine {
                label: "settled Hd (ours)".into(),
                y: o.hd_mm.unwrap_or(f64::NAN),
            },
            HLine {
                label: "Hd measured (Table 1 mean)".into(),
                y: paper::EXPERIMENT_MEAN.hd_mm,
            },
        ];
        let title = format!("Height of A after the roller is put on: {tag}");
        write_svg(
            &dir.join(format!("a_height_{tag}.svg")),
            &height_figure(&title, &series, &hlines),
        )
        .map_err(plot_err)?;
    }
    let mut shapes = vec![Series {
        label: "static".into(),
        points: t.static_shape.clone(),
        kind: SeriesKind::Line,
    }];
    if !t.loaded_shape.is_empty() {
        shapes.push(Series {
            label: "loaded, settled".into(),
            points: t.loaded_shape.clone(),
            kind: SeriesKind::Dashed,
        });
    }
    let title = format!("Settled belt shapes (outer surface): {tag}");
    write_svg(
        &dir.join(format!("shapes_{tag}.svg")),
        &Figure {
            title: &title,
            x_label: "x [mm]",
            y_label: "y [mm]",
            series: &shapes,
            hlines: &[],
            equal_aspect: true,
        },
    )
    .map_err(plot_err)?;
    Ok(())
}

fn progress(len: u64, msg: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed})") {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(msg.to_string());
    pb
}

fn threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}

fn cmd_paper(json: bool, plot: Option<&Path>) -> Result<(), String> {
    let pb = progress(6, "simulating methods I and II, E38/E56/E76");
    let runs = run_all(threads(), || pb.inc(1))?;
    pb.finish_and_clear();
    let rows = rows(&runs);
    if let Some(dir) = plot {
        for r in &runs {
            plot_run(dir, &r.out, &r.trace)?;
        }
        let mut panels_series = Vec::new();
        for v in Variant::ALL {
            let s: Vec<Series> = runs
                .iter()
                .filter(|r| r.variant == v)
                .map(|r| Series {
                    label: format!("method {}", r.method.name()),
                    points: r.trace.a_height.clone(),
                    kind: SeriesKind::Line,
                })
                .collect();
            panels_series.push((v, s));
        }
        let hl = [HLine {
            label: "Hd measured".into(),
            y: paper::EXPERIMENT_MEAN.hd_mm,
        }];
        let titles: Vec<String> = panels_series
            .iter()
            .map(|(v, _)| format!("{}: height of A", v.name()))
            .collect();
        let panels: Vec<Figure> = panels_series
            .iter()
            .zip(&titles)
            .map(|((_, s), t)| height_figure(t, s, &hl))
            .collect();
        write_svg_grid(
            &dir.join("oscillations.svg"),
            "Dynamic test: A's height, methods I and II (cf. Figs. 7, 8)",
            &panels,
            3,
        )
        .map_err(plot_err)?;
    }
    if json {
        let doc = trackbelt_cli::paper::PaperReport { rows };
        println!(
            "{}",
            serde_json::to_string(&doc).map_err(|e| e.to_string())?
        );
    } else {
        print_paper(&rows);
    }
    Ok(())
}

fn print_paper(rows: &[Row]) {
    for table in ["2", "4"] {
        let m = if table == "2" { "I" } else { "II" };
        println!(
            "\nTable {table} (+{}) — method {m}: ours / paper's simulation",
            if table == "2" { "3" } else { "5" }
        );
        println!(
            "{:<5}{:>15}{:>15}{:>15}{:>15}{:>13}{:>13}{:>24}{:>26}  bands",
            "var", "Hs mm", "Ws mm", "Hd mm", "Wd mm", "T s", "Λ", "ζA °", "ζC °"
        );
        for r in rows.iter().filter(|r| r.table == table) {
            let p = &r.paper;
            let o = &r.ours;
            let pair = |a: Option<f64>, b: Option<f64>, prec: usize| {
                format!("{}/{}", fmt_opt(a, prec), fmt_opt(b, prec))
            };
            println!(
                "{:<5}{:>15}{:>15}{:>15}{:>15}{:>13}{:>13}{:>24}{:>26}  {}",
                r.variant,
                pair(Some(o.hs_mm), p.hs_mm, 0),
                pair(Some(o.ws_mm), p.ws_mm, 0),
                pair(o.hd_mm, p.hd_mm, 0),
                pair(o.wd_mm, p.wd_mm, 0),
                pair(o.period_s, p.period_s, 2),
                pair(o.log_decrement, p.log_decrement, 2),
                format!("{}/{}", fmt_range(o.angle_a_deg), fmt_range(p.angle_a_deg)),
                format!("{}/{}", fmt_range(o.angle_c_deg), fmt_range(p.angle_c_deg)),
                if r.within_bands == Some(true) {
                    "inside".to_string()
                } else {
                    r.outside.join("; ")
                }
            );
        }
    }
    println!("\nTable 8 — relative error against the Table 1 mean, % (ours | paper)");
    println!(
        "{:<8}{:<5}{:>14}{:>14}{:>14}{:>14}{:>14}{:>14}",
        "method", "var", "Hs", "Ws", "Hd", "Wd", "T", "Λ"
    );
    for r in rows.iter().filter(|r| r.table == "8") {
        let (Some(v), Some(m)) = (Variant::parse(&r.variant), Method::parse(&r.method)) else {
            continue;
        };
        let theirs = paper::table8(v, m);
        let e = &r.rel_err_pct;
        let ours = [
            e.hs_mm,
            e.ws_mm,
            e.hd_mm,
            e.wd_mm,
            e.period_s,
            e.log_decrement,
        ];
        print!("{:<8}{:<5}", r.method, r.variant);
        for (o, t) in ours.iter().zip(theirs) {
            print!(
                "{:>14}",
                format!("{} | {t:.0}", fmt_opt(o.map(f64::abs), 0))
            );
        }
        println!();
    }
}

fn cmd_bench(repeat: usize, json: bool) -> Result<(), String> {
    let repeat = repeat.clamp(1, 100);
    let mut results = Vec::new();
    for v in Variant::ALL {
        let mut best = f64::INFINITY;
        let mut stats = None;
        for _ in 0..repeat {
            let model = trackbelt::params::Model::paper(v, Method::I).map_err(|e| e.to_string())?;
            let mut chain = Box::new(
                trackbelt::ReferenceChain::new(model, Settings::default())
                    .map_err(|e| e.to_string())?,
            );
            let t0 = std::time::Instant::now();
            trackbelt::bench::run(&mut *chain, &DynamicTest::default(), |_| {})
                .map_err(|e| e.to_string())?;
            let dt = t0.elapsed().as_secs_f64();
            if dt < best {
                best = dt;
                stats = Some(chain.stats());
            }
        }
        let s = stats.unwrap_or_default();
        results.push(serde_json::json!({
            "variant": v.name(),
            "links": v.links(),
            "wall_ms": best * 1e3,
            "steps": s.steps,
            "rejected": s.rejected,
            "residuals": s.residuals,
            "factorizations": s.factorizations,
        }));
        if !json {
            println!(
                "{} (N = {:>2}): {:7.1} ms  ({} steps, {} rejected, {} residuals, {} factorisations; best of {repeat})",
                v.name(),
                v.links(),
                best * 1e3,
                s.steps,
                s.rejected,
                s.residuals,
                s.factorizations
            );
        }
    }
    if json {
        println!(
            "{}",
            serde_json::json!({ "method": "I", "test": "static settle + 5 s dynamic", "results": results })
        );
    }
    Ok(())
}

#[derive(clap::Args)]
struct DiagnoseArgs {
    /// Dataset directory (DATA.md format).
    dataset_dir: PathBuf,
    /// E38, E56 or E76: the link model to fit.
    #[arg(long, default_value = "E38")]
    variant: String,
    /// Baseline joint law (params TOML); default: params/<variant>.toml.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Write SVG plots into this directory.
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn cmd_diagnose(a: DiagnoseArgs) -> Result<(), String> {
    use trackbelt_cli::diagnose::diagnose_dir;
    let variant = Variant::parse(&a.variant)
        .ok_or_else(|| format!("--variant {:?}: expected E38, E56 or E76", a.variant))?;
    let pb = progress(1, "diagnosing (simulations)");
    let t0 = std::time::Instant::now();
    let d = diagnose_dir(
        &a.dataset_dir,
        variant,
        a.params.as_deref(),
        &mut |n| pb.set_length(n),
        &mut || pb.inc(1),
    );
    pb.finish_and_clear();
    let d = d?;
    if let Some(dir) = &a.plot {
        trackbelt_cli::diagnose_report::plots(&d, dir)?;
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&d.report).map_err(|e| e.to_string())?
        );
    } else {
        print!("{}", trackbelt_cli::diagnose_report::text(&d));
        println!("\n(diagnosed in {:.1} s)", t0.elapsed().as_secs_f64());
    }
    Ok(())
}

#[derive(clap::Args)]
struct SynthArgs {
    /// New directory for the dataset (must not exist yet or be empty of its files).
    out_dir: PathBuf,
    /// Effect identifier to switch on (see DATA.md), or `none`, or a
    /// disturbance outside the catalogue: camera_drift, second_mode, marker_slip.
    #[arg(long, default_value = "none")]
    effect: String,
    /// Size of the effect, in multiples of its nominal size.
    #[arg(long, default_value_t = 1.0)]
    magnitude: f64,
    /// E38, E56 or E76.
    #[arg(long, default_value = "E38")]
    variant: String,
    /// Baseline joint law (params TOML); default: params/<variant>.toml.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Marker noise, mm (standard deviation).
    #[arg(long, default_value_t = 1.0)]
    noise_mm: f64,
    /// Record length, s.
    #[arg(long, default_value_t = 6.0)]
    duration_s: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// `dynamic` (camera, roller test) or `scroll` (torque logger, rig).
    #[arg(long, default_value = "dynamic")]
    kind: String,
}

fn cmd_synth(a: SynthArgs) -> Result<(), String> {
    use trackbelt_cli::diagnose::{baseline, EffectKind};
    use trackbelt_cli::synth::{Disturbance, DynamicSynth};
    let variant = Variant::parse(&a.variant)
        .ok_or_else(|| format!("--variant {:?}: expected E38, E56 or E76", a.variant))?;
    let base = baseline(variant, a.params.as_deref())?;
    if !(a.magnitude.is_finite()) {
        return Err("--magnitude must be finite".into());
    }
    let name = a
        .out_dir
        .file_name()
        .map_or("synthetic".into(), |n| n.to_string_lossy().into_owned());
    if a.kind == "scroll" {
        use trackbelt_cli::synth::{ScrollDisturbance, ScrollSynth};
        let mut s = ScrollSynth::new(&base, a.seed);
        if a.effect != "none" {
            if let Some(e) = EffectKind::parse(&a.effect) {
                if EffectKind::DYNAMIC.contains(&e) {
                    return Err(format!(
                        "{} shows in dynamic tests: use --kind dynamic",
                        e.id()
                    ));
                }
                s = s.with_effect(e, a.magnitude);
            } else if let Some(d) = ScrollDisturbance::parse(&a.effect, a.magnitude) {
                s.disturbance = Some(d);
            } else {
                return Err(format!(
                    "--effect {:?}: expected none, bearing_friction, rate_dependent_damping, thermal_softening, {}",
                    a.effect,
                    ScrollDisturbance::NAMES.join(", ")
                ));
            }
        }
        s.write(&a.out_dir, &name)?;
        eprintln!("wrote {}", a.out_dir.display());
        return Ok(());
    } else if a.kind != "dynamic" {
        return Err(format!("--kind {:?}: expected dynamic or scroll", a.kind));
    }
    let mut s = DynamicSynth::new(&base, a.seed);
    s.noise_mm = a.noise_mm;
    s.duration_s = a.duration_s;
    if a.effect != "none" {
        if let Some(e) = EffectKind::parse(&a.effect) {
            if !EffectKind::DYNAMIC.contains(&e) {
                return Err(format!(
                    "{} shows only in scroll tests; this build synthesises dynamic series only",
                    e.id()
                ));
            }
            s = s.with_effect(e, a.magnitude);
        } else if let Some(d) = Disturbance::parse(&a.effect, a.magnitude) {
            s.disturbance = Some(d);
        } else {
            return Err(format!(
                "--effect {:?}: expected none, joint_friction, quadratic_damping, amplitude_stiffness, {}",
                a.effect,
                Disturbance::NAMES.join(", ")
            ));
        }
    }
    s.write(&a.out_dir, &name)?;
    eprintln!("wrote {}", a.out_dir.display());
    Ok(())
}
