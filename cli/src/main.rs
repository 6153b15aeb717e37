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
use trackbelt_cli::sim::{model_for, simulate_joint, Joint, SimOutput, SimTrace, Tests};

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

/// How consecutive links are joined.
#[derive(Clone, Copy, ValueEnum, PartialEq, Eq)]
enum JointKind {
    /// Exact pins (inextensible chain).
    Pin,
    /// The paper's literal bushing, 1e8 N/m and 1e6 N·s/m (slower).
    Bushing,
}

impl From<JointKind> for Joint {
    fn from(j: JointKind) -> Joint {
        match j {
            JointKind::Pin => Joint::Pin,
            JointKind::Bushing => Joint::Bushing,
        }
    }
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
    /// Bending-resistance rig: the belt round a drive wheel and a tensioned
    /// idler; drive torque at a constant speed.
    Rig(RigArgs),
    /// Benchmark one full test (settle + 5 s of oscillation), method I.
    Bench {
        /// Repetitions per variant (the minimum is reported).
        #[arg(long, default_value_t = 5)]
        repeat: usize,
        /// Print one JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Joint model to benchmark.
        #[arg(long, value_enum, default_value = "pin")]
        joint: JointKind,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = match cli.cmd {
        Cmd::Simulate(args) => cmd_simulate(args),
        Cmd::Paper { json, plot } => cmd_paper(json, plot.as_deref()),
        Cmd::Bench {
            repeat,
            json,
            joint,
        } => cmd_bench(repeat, json, joint.into()),
        Cmd::Rig(args) => cmd_rig(args),
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
    /// Joints as exact pins, or the paper's literal bushing (eqs. 1–3).
    #[arg(long, value_enum, default_value = "pin")]
    joint: JointKind,
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

/// The joint law for `--variant/--method [--params]`.
fn law_for(
    variant_arg: &str,
    method_arg: &str,
    params: Option<&Path>,
) -> Result<(Variant, Method, trackbelt::stiffness::JointLaw<f64>), String> {
    let variant = Variant::parse(variant_arg)
        .ok_or_else(|| format!("--variant {variant_arg:?}: expected E38, E56 or E76"))?;
    let method = Method::parse(method_arg)
        .ok_or_else(|| format!("--method {method_arg:?}: expected I, II or III"))?;
    let law = match params {
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
    Ok((variant, method, law))
}

fn cmd_simulate(a: SimArgs) -> Result<(), String> {
    let (variant, method, law) = law_for(&a.variant, &a.method, a.params.as_deref())?;
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
    let (out, trace) = simulate_joint(model, method, a.joint.into(), tests, settings, dynamic)
        .map_err(|e| e.to_string())?;
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
        "{} method {}, {} joints   (simulated in {:.3} s)",
        o.variant, o.method, o.joint, o.wall_s
    );
    if let Some(s) = o.max_stretch_um {
        println!("largest bushing stretch over the run: {s:.3} µm");
    }
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

fn cmd_bench(repeat: usize, json: bool, joint: Joint) -> Result<(), String> {
    let repeat = repeat.clamp(1, 100);
    let mut results = Vec::new();
    for v in Variant::ALL {
        let mut best = f64::INFINITY;
        let mut stats = None;
        for _ in 0..repeat {
            let (dt, s) = bench_once(v, joint)?;
            if dt < best {
                best = dt;
                stats = Some(s);
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
                "{} (N = {:>2}, {} joints): {:7.1} ms  ({} steps, {} rejected, {} residuals, {} factorisations; best of {repeat})",
                v.name(),
                v.links(),
                joint.name(),
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
            serde_json::json!({ "method": "I", "joint": joint.name(), "test": "static settle + 5 s dynamic", "results": results })
        );
    }
    Ok(())
}

/// One full bench test (method I): wall time of the simulation work, s,
/// and the solver counters.
fn bench_once(v: Variant, joint: Joint) -> Result<(f64, trackbelt::Stats), String> {
    let model = trackbelt::params::Model::paper(v, Method::I).map_err(|e| e.to_string())?;
    match joint {
        Joint::Pin => {
            let mut chain = Box::new(
                trackbelt::ReferenceChain::new(model, Settings::default())
                    .map_err(|e| e.to_string())?,
            );
            let t0 = std::time::Instant::now();
            trackbelt::bench::run(&mut *chain, &DynamicTest::default(), |_| {})
                .map_err(|e| e.to_string())?;
            Ok((t0.elapsed().as_secs_f64(), chain.stats()))
        }
        // The bushing chain is about 1.3 MB: its own thread, a big stack.
        Joint::Bushing => std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn(move || {
                let mut chain = Box::new(
                    trackbelt::ReferenceBushingChain::new(
                        model,
                        trackbelt::Bushing::paper(),
                        Settings::default(),
                    )
                    .map_err(|e| e.to_string())?,
                );
                let t0 = std::time::Instant::now();
                trackbelt::bench::run(&mut *chain, &DynamicTest::default(), |_| {})
                    .map_err(|e| e.to_string())?;
                Ok((t0.elapsed().as_secs_f64(), chain.stats()))
            })
            .map_err(|e| format!("cannot start the benchmark thread: {e}"))?
            .join()
            .map_err(|_| "the benchmark thread failed".to_string())?,
    }
}

#[derive(clap::Args)]
struct RigArgs {
    /// E38, E56 or E76.
    #[arg(long, default_value = "E56")]
    variant: String,
    /// I, II or III.
    #[arg(long)]
    method: String,
    /// Joint law from a params file (TOML) instead of the paper's.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Tensioner force pulling the idler away from the drive, N.
    #[arg(long, default_value_t = 500.0)]
    idler_force_n: f64,
    /// Drive speed of the constant phase, rad/s.
    #[arg(long, default_value_t = 5.0)]
    speed_rad_s: f64,
    /// Duration of the ramp from rest, s.
    #[arg(long, default_value_t = 1.0)]
    ramp_s: f64,
    /// Time held at the speed, s (the mean starts 0.5 s after the ramp).
    #[arg(long, default_value_t = 2.0)]
    hold_s: f64,
    /// Also build the onboard estimator from the same model and report it.
    #[arg(long)]
    estimator: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Write an SVG of the drive torque over time (methods I, II and, when
    /// available, III) into this directory.
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn rig_model(
    variant: &str,
    method: &str,
    params: Option<&Path>,
) -> Result<(Method, trackbelt::params::Model<f64>), String> {
    let (v, m, law) = law_for(variant, method, params)?;
    let model = model_for(v.links(), law).map_err(|e| e.to_string())?;
    Ok((m, model))
}

fn cmd_rig(a: RigArgs) -> Result<(), String> {
    use trackbelt::rig::{RigConfig, RigTest};
    use trackbelt_cli::rig::run_rig;
    let (method, model) = rig_model(&a.variant, &a.method, a.params.as_deref())?;
    let config = RigConfig {
        idler_force_n: a.idler_force_n,
        ..RigConfig::default()
    };
    config.validate().map_err(|e| e.to_string())?;
    let test = RigTest {
        speed_rad_s: a.speed_rad_s,
        ramp_s: a.ramp_s,
        hold_s: a.hold_s,
        settle_s: 0.5_f64.min(a.hold_s / 2.0),
    };
    let pb = progress(1, "rig");
    let (out, trace) =
        run_rig(&a.variant, method, model, config, test, a.estimator).map_err(|e| e.to_string())?;
    pb.finish_and_clear();
    if let Some(dir) = &a.plot {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let mut series = Vec::new();
        for m in ["I", "II", "III"] {
            let tr = if m == out.method {
                trace.clone()
            } else {
                match rig_model(&a.variant, m, None) {
                    Ok((mm, model)) => {
                        run_rig(&a.variant, mm, model, config, test, false)
                            .map_err(|e| e.to_string())?
                            .1
                    }
                    Err(_) => continue,
                }
            };
            series.push(Series {
                label: format!("method {m}"),
                points: tr.iter().map(|r| (r.0, r.2)).collect(),
                kind: SeriesKind::Line,
            });
            if m == out.method && a.estimator {
                series.push(Series {
                    label: format!("method {m}: onboard estimator"),
                    points: tr.iter().filter_map(|r| r.3.map(|e| (r.0, e))).collect(),
                    kind: SeriesKind::Dashed,
                });
            }
        }
        let title = format!(
            "Drive torque, {} on the rig ({} N tensioner, {} rad/s)",
            a.variant, a.idler_force_n, a.speed_rad_s
        );
        write_svg(
            &dir.join(format!("rig_torque_{}.svg", a.variant)),
            &Figure {
                title: &title,
                x_label: "t [s]",
                y_label: "drive torque [N·m]",
                series: &series,
                hlines: &[],
                equal_aspect: false,
            },
        )
        .map_err(plot_err)?;
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&out).map_err(|e| e.to_string())?
        );
    } else {
        println!(
            "{} method {} on the rig: {:.3} ± {:.3} N·m at {} rad/s, tensioner {} N, axle distance {:.1} mm (simulated in {:.2} s)",
            out.variant,
            out.method,
            out.torque_nm_mean,
            out.torque_nm_std,
            out.speed_rad_s,
            out.idler_force_n,
            out.axle_distance_mm,
            out.wall_s
        );
        if let Some(e) = out.estimator_torque_nm {
            println!(
                "onboard estimator: {:.3} N·m ({:+.2} % against the simulation)",
                e,
                100.0 * (e / out.torque_nm_mean - 1.0)
            );
        }
    }
    Ok(())
}
