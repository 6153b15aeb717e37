//! Running a scenario and writing its dataset (`DATA.md`, format 1).

use crate::drop::{Contact, DropConfig};
use crate::rng::Rng;
use crate::scenario::{Disturbance, RigTest, Scenario, Test};
use crate::scroll::{center_distance, Profile, RigConfig};
use crate::{Error, Figures, Truth};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The belt's non-uniformity: a smooth random field of EI factors, one per node.
fn ei_field(sc: &Scenario) -> Vec<f64> {
    let mut rng = Rng::stream(sc.seed, 0x6669_656c);
    let n = sc.nodes;
    let modes: Vec<(f64, f64)> = (1..=3)
        .map(|k| (rng.normal() / k as f64, rng.normal() / k as f64))
        .collect();
    (0..n)
        .map(|i| {
            let phi = std::f64::consts::TAU * i as f64 / n as f64;
            let s: f64 = modes
                .iter()
                .enumerate()
                .map(|(k, (a, b))| {
                    a * ((k + 1) as f64 * phi).cos() + b * ((k + 1) as f64 * phi).sin()
                })
                .sum();
            (1.0 + sc.nonuniformity * s / 1.5).max(0.5)
        })
        .collect()
}

fn interp(t: &[f64], y: &[f64], at: f64) -> f64 {
    if t.is_empty() {
        return 0.0;
    }
    if at <= t[0] {
        return y[0];
    }
    let last = t.len() - 1;
    if at >= t[last] {
        return y[last];
    }
    let i = t.partition_point(|&x| x <= at).min(last).max(1);
    let u = (at - t[i - 1]) / (t[i] - t[i - 1]);
    y[i - 1] + u * (y[i] - y[i - 1])
}

fn round_to(x: f64, q: f64) -> f64 {
    (x / q).round() * q
}

/// Refuse a non-empty directory; create a missing one.
fn prepare_dir(dir: &Path) -> Result<(), Error> {
    let io = |source| Error::Io {
        path: dir.to_path_buf(),
        source,
    };
    if dir.exists() {
        let mut it = std::fs::read_dir(dir).map_err(io)?;
        if it.next().is_some() {
            return Err(Error::NotEmpty(dir.to_path_buf()));
        }
    } else {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    Ok(())
}

/// Write `text` to `dir/name` through a temporary file and a rename.
fn write_atomic(dir: &Path, name: &str, text: &str) -> Result<PathBuf, Error> {
    let path = dir.join(name);
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let io = |p: &Path| {
        let p = p.to_path_buf();
        move |source| Error::Io { path: p, source }
    };
    std::fs::write(&tmp, text).map_err(io(&tmp))?;
    std::fs::rename(&tmp, &path).map_err(io(&path))?;
    Ok(path)
}

fn belt_toml(sc: &Scenario) -> String {
    let b = &sc.belt;
    let mut s = String::new();
    let _ = writeln!(s, "# Measured-data format, version 1 (see DATA.md).");
    let _ = writeln!(s, "format = 1");
    let _ = writeln!(s, "name = \"{}\"", sc.name);
    let _ = writeln!(s, "source = \"bench log export\"");
    let _ = writeln!(s);
    let _ = writeln!(s, "[belt]");
    let _ = writeln!(s, "length_mm = {:.0}", b.length_m * 1e3);
    let _ = writeln!(s, "width_mm = {:.0}", b.width_m * 1e3);
    let _ = writeln!(s, "thickness_mm = {:.1}", b.thickness_m * 1e3);
    let _ = writeln!(s, "mass_kg = {:.2}", b.mass_kg);
    if let Some(g) = b.grousers {
        let _ = writeln!(s, "grousers = {g}");
        let _ = writeln!(s, "grouser_pitch_mm = {:.1}", b.length_m * 1e3 / g as f64);
    }
    s
}

fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Run `sc` and write its dataset (`dataset.toml` and one CSV) into `dir`
/// (created if missing; refused if not empty). Returns what was put in.
pub fn generate(sc: &Scenario, dir: &Path) -> Result<Truth, Error> {
    generate_runs(std::slice::from_ref(sc), dir)
}

/// Run every scenario of `runs` and write them as one dataset of several
/// runs of the same belt (`dataset.toml` with one `[[dynamic]]` or
/// `[[scroll]]` entry per run, the static figures of the first, and one
/// CSV per run) into `dir` (created if missing; refused if not empty).
/// The runs are [`Scenario::repeat`]s of the first: they must share its
/// seed, outcome, belt and kind of test, each with a run number of its
/// own (the same run twice would be one record counted twice), else
/// nothing is written. The truth's noise is the RMS over every run's
/// noise; its figures are the first run's.
///
/// ```no_run
/// use trackbelt_truth::{draw, generate_runs, Outcome, SeriesKind};
/// let first = draw(Outcome::None, SeriesKind::Scroll, 7).unwrap();
/// let runs: Vec<_> = (0..3).map(|r| first.repeat(r)).collect();
/// let truth = generate_runs(&runs, std::path::Path::new("/tmp/set-7x3")).unwrap();
/// assert_eq!(truth.files.len(), 4);
/// ```
pub fn generate_runs(runs: &[Scenario], dir: &Path) -> Result<Truth, Error> {
    write_runs(runs, dir, None)
}

/// [`generate_runs`], with `beside` (when given) appended to the dataset:
/// `dataset.toml` entries after the runs' own, and optionally the text of
/// a `dynamic-1.csv` they name, written last.
fn write_runs(
    runs: &[Scenario],
    dir: &Path,
    beside: Option<(&str, Option<&str>)>,
) -> Result<Truth, Error> {
    let Some(sc) = runs.first() else {
        return Err(Error::Invalid("no run to generate".into()));
    };
    if sc.nodes < 16 || sc.nodes > 200 || !sc.nodes.is_multiple_of(2) {
        return Err(Error::Invalid(format!("nodes {}", sc.nodes)));
    }
    let b = &sc.belt;
    let ok = |x: f64, lo: f64, hi: f64| x.is_finite() && x >= lo && x <= hi;
    if !(ok(b.length_m, 0.5, 5.0)
        && ok(b.width_m, 0.02, 1.0)
        && ok(b.thickness_m, 0.002, 0.05)
        && ok(b.mass_kg, 0.2, 50.0))
    {
        return Err(Error::Invalid(format!("belt {b:?}")));
    }
    if let Some(r) = runs.iter().find(|r| {
        r.seed != sc.seed || r.outcome != sc.outcome || r.belt != sc.belt || r.kind() != sc.kind()
    }) {
        return Err(Error::Invalid(format!(
            "run {} is not a repeat of the first (seed {} against {}): every run must be the same belt on the same kind of test",
            r.run, r.seed, sc.seed
        )));
    }
    // The noise and the repeat's draws come from the run number: the same
    // run twice would be two identical series, one record counted twice.
    let twice = runs.iter().enumerate().find_map(|(i, r)| {
        runs[..i]
            .iter()
            .position(|q| q.run == r.run)
            .map(|first| (r.run, first, i))
    });
    if let Some((run, first, again)) = twice {
        return Err(Error::Invalid(format!(
            "run {run} is listed twice (positions {} and {}): each run of a dataset needs a run number of its own (Scenario::repeat)",
            first + 1,
            again + 1
        )));
    }
    prepare_dir(dir)?;
    let mut outs = Vec::with_capacity(runs.len());
    for (i, r) in runs.iter().enumerate() {
        outs.push(match &r.test {
            Test::Dynamic(_) => dynamic(r, i)?,
            Test::Scroll(_) => scroll(r, i)?,
        });
    }
    let mut toml = belt_toml(sc);
    toml.push_str(&outs[0].statics);
    for o in &outs {
        toml.push_str(&o.entry);
    }
    if let Some((entries, _)) = beside {
        toml.push_str(entries);
    }
    let mut files = Vec::with_capacity(outs.len() + 2);
    for o in &outs {
        files.push(write_atomic(dir, &o.csv_name, &o.csv)?);
    }
    files.insert(0, write_atomic(dir, "dataset.toml", &toml)?);
    if let Some((_, Some(csv))) = beside {
        files.push(write_atomic(dir, "dynamic-1.csv", csv)?);
    }
    let noise: Vec<f64> = outs.iter().flat_map(|o| o.noise.iter().copied()).collect();
    let mut description = describe(sc);
    if runs.len() > 1 {
        let _ = write!(description, "; {} runs", runs.len());
    }
    Ok(Truth {
        outcome: sc.outcome,
        expected: sc.outcome.expected(),
        kind: sc.kind(),
        magnitude: sc.magnitude,
        description,
        noise_rms: rms(&noise),
        noise_unit: outs[0].noise_unit,
        nodes: sc.nodes,
        step_s: outs[0].step_s,
        figures: outs[0].figures,
        files,
    })
}

/// The `dataset.toml` entries of a drop test of `sc`'s belt
/// ([`Scenario::drop_test_beside`]): its `[[static]]` repeats and one
/// `[[dynamic]]` entry with the summary figures as the truth measures
/// them, without a series (DATA.md makes it optional). Appended to a rig
/// dataset they give the diagnosis the belt's own static and drop
/// figures to calibrate its table on.
pub fn drop_figures(sc: &Scenario) -> Result<String, Error> {
    let (entries, _) = drop_test_with_series(sc)?;
    Ok(entries
        .lines()
        .filter(|l| !l.starts_with("series ="))
        .map(|l| format!("{l}\n"))
        .collect())
}

/// [`drop_figures`] with the drop test's series: the entries (the
/// `[[dynamic]]` one naming `dynamic-1.csv`) and that file's text.
pub fn drop_test_with_series(sc: &Scenario) -> Result<(String, String), Error> {
    let out = dynamic(&sc.drop_test_beside(), 0)?;
    Ok((format!("{}{}", out.statics, out.entry), out.csv))
}

/// [`generate`] for a rig test with its belt's drop test beside it: the
/// rig dataset `generate` writes, byte for byte the same series, with the
/// drop test's entries appended to its `dataset.toml` ([`drop_figures`],
/// or with `with_series` the entries of [`drop_test_with_series`] and
/// that series as `dynamic-1.csv`). One dataset then holds both kinds of
/// test of one belt, as a lab that records its drop test beside its rig
/// runs would give it. The drop test is run before anything is written;
/// `sc` must be a rig test and `dir` new or empty, else nothing is
/// written. The truth returned is the rig run's, with the drop series'
/// file added to its files.
///
/// ```no_run
/// use trackbelt_truth::{draw, generate_beside, Outcome, SeriesKind};
/// let sc = draw(Outcome::None, SeriesKind::Scroll, 7).unwrap();
/// let truth = generate_beside(&sc, std::path::Path::new("/tmp/both-7"), true).unwrap();
/// assert_eq!(truth.files.len(), 3);
/// ```
pub fn generate_beside(sc: &Scenario, dir: &Path, with_series: bool) -> Result<Truth, Error> {
    if !matches!(sc.test, Test::Scroll(_)) {
        return Err(Error::Invalid(
            "a drop test is put beside a rig test only".into(),
        ));
    }
    let (entries, csv) = if with_series {
        let (entries, csv) = drop_test_with_series(sc)?;
        (entries, Some(csv))
    } else {
        (drop_figures(sc)?, None)
    };
    write_runs(
        std::slice::from_ref(sc),
        dir,
        Some((&entries, csv.as_deref())),
    )
}

/// One run of a dataset, ready to be written.
struct RunOut {
    /// The `[[static]]` entries (the first run's only).
    statics: String,
    /// Its `[[dynamic]]` or `[[scroll]]` entry.
    entry: String,
    /// Its series file's name and text.
    csv_name: String,
    csv: String,
    /// The noise put into its series.
    noise: Vec<f64>,
    noise_unit: &'static str,
    figures: Figures,
    step_s: f64,
}

/// The noise stream of a run: the first run's is the one a single-run
/// dataset always had.
fn noise_rng(sc: &Scenario) -> Rng {
    Rng::stream(sc.seed, 0x6e6f_6973 ^ (u64::from(sc.run) << 32))
}

fn dynamic(sc: &Scenario, index: usize) -> Result<RunOut, Error> {
    let Test::Dynamic(dt) = &sc.test else {
        return Err(Error::Invalid("not a drop test".into()));
    };
    let cfg = DropConfig {
        length_m: sc.belt.length_m,
        thickness_m: sc.belt.thickness_m,
        mass_kg: sc.belt.mass_kg,
        nodes: sc.nodes,
        ea_n: sc.ea_n,
        material: sc.material,
        ei_scale: ei_field(sc),
        floor: Contact::floor(),
    };
    let mut rng = noise_rng(sc);
    let settled = cfg.settle(0)?;
    let mut statics_mm = vec![(settled.hs_m, settled.ws_m)];
    for k in 1..dt.static_runs {
        if sc.nonuniformity > 0.0 {
            let s = cfg.settle(k * sc.nodes / 4)?;
            statics_mm.push((s.hs_m, s.ws_m));
        } else {
            statics_mm.push((settled.hs_m, settled.ws_m));
        }
    }
    let run = cfg.drop(
        &settled,
        dt.roller_kg,
        dt.roller_radius_m,
        dt.duration_s + 0.05,
        0.001,
    )?;
    let pd = run.period_and_decrement();
    let figures = Figures {
        hs_mm: Some(settled.hs_m * 1e3),
        ws_mm: Some(settled.ws_m * 1e3),
        hd_mm: Some(run.hd_m * 1e3),
        wd_mm: Some(run.wd_m * 1e3),
        period_s: pd.map(|p| p.0),
        log_decrement: pd.map(|p| p.1),
        mean_torque_nm: None,
    };
    // Camera.
    let cam = dt.camera;
    let mut times: Vec<f64> = Vec::new();
    let mut k = 0usize;
    loop {
        let t = cam.phase_s + k as f64 / cam.rate_hz;
        if t > dt.duration_s {
            break;
        }
        times.push(t);
        k += 1;
    }
    for _ in 0..cam.dropped_rows {
        if times.len() > 20 {
            let i = rng.int(5, times.len() - 6);
            times.remove(i);
        }
    }
    let x0 = run.a_x_m.first().copied().unwrap_or(0.0);
    let x_off = rng.range(-3.0, 3.0);
    let mut noise = Vec::with_capacity(times.len());
    let mut csv = String::from(if cam.with_x {
        "t_s,a_height_mm,a_x_mm\n"
    } else {
        "t_s,a_height_mm\n"
    });
    for &t in &times {
        let e = cam.noise_mm * rng.normal();
        noise.push(e);
        let mut hmm = interp(&run.t_s, &run.a_height_m, t) * 1e3 + cam.offset_mm + e;
        hmm += match sc.disturbance {
            Some(Disturbance::CameraDrift {
                mm_per_s,
                mm_per_s2,
            }) => mm_per_s * t + mm_per_s2 * t * t,
            Some(Disturbance::CameraShake {
                amplitude_mm,
                freq_hz,
                decay_per_s,
                start_s,
            }) if t >= start_s => {
                let u = t - start_s;
                amplitude_mm
                    * (-decay_per_s * u).exp()
                    * (std::f64::consts::TAU * freq_hz * u).sin()
            }
            Some(Disturbance::MarkerSlip { at_s, step_mm }) if t >= at_s => step_mm,
            _ => 0.0,
        };
        let _ = write!(csv, "{:.4},{:.1}", t, round_to(hmm, 0.1));
        if cam.with_x {
            let xmm =
                (interp(&run.t_s, &run.a_x_m, t) - x0) * 1e3 + x_off + cam.noise_mm * rng.normal();
            let _ = write!(csv, ",{:.1}", round_to(xmm, 0.1));
        }
        csv.push('\n');
    }
    let mut statics = String::new();
    if index == 0 {
        for (i, (hs, ws)) in statics_mm.iter().enumerate() {
            let sd = dt.static_scatter_mm;
            let _ = writeln!(statics, "\n[[static]]");
            let _ = writeln!(statics, "label = \"run-{}\"", i + 1);
            let _ = writeln!(statics, "hs_mm = {:.0}", hs * 1e3 + sd * rng.normal());
            let _ = writeln!(statics, "ws_mm = {:.0}", ws * 1e3 + 1.5 * sd * rng.normal());
        }
    }
    let mut toml = String::new();
    let _ = writeln!(toml, "\n[[dynamic]]");
    let _ = writeln!(toml, "label = \"run-{}\"", index + 1);
    let _ = writeln!(toml, "roller_kg = {:.2}", dt.roller_kg);
    let _ = writeln!(toml, "settled_hs_mm = {:.0}", settled.hs_m * 1e3);
    let _ = writeln!(toml, "hd_mm = {:.0}", run.hd_m * 1e3);
    let _ = writeln!(toml, "wd_mm = {:.0}", run.wd_m * 1e3);
    if let Some((p, l)) = pd {
        let _ = writeln!(toml, "period_s = {:.3}", p);
        let _ = writeln!(toml, "log_decrement = {:.2}", l);
    }
    let csv_name = format!("dynamic-{}.csv", index + 1);
    let _ = writeln!(toml, "series = \"{csv_name}\"");
    Ok(RunOut {
        statics,
        entry: toml,
        csv_name,
        csv,
        noise,
        noise_unit: "mm",
        figures,
        step_s: run.step_s,
    })
}

/// The rig's speed profile and the belt's warming.
struct RigProfile {
    knots: Vec<(f64, f64)>,
    temp_t: Vec<f64>,
    temp: Vec<f64>,
}

impl RigProfile {
    fn new(r: &RigTest) -> Self {
        let mut p = RigProfile {
            knots: r.profile.clone(),
            temp_t: Vec::new(),
            temp: Vec::new(),
        };
        // dT/dt = ω² − T/τ, scaled so that its largest value is the rise.
        let dt = 0.01;
        let mut t = 0.0;
        let mut x = 0.0f64;
        while t <= r.duration_s + 1.0 {
            p.temp_t.push(t);
            p.temp.push(x);
            let w = p.omega(t);
            x += dt * (w * w - x / r.tau_cool_s);
            t += dt;
        }
        let top = p.temp.iter().cloned().fold(0.0, f64::max);
        if top > 0.0 {
            for v in p.temp.iter_mut() {
                *v *= r.temp_rise_k / top;
            }
        }
        p
    }
}

impl Profile for RigProfile {
    fn omega(&self, t: f64) -> f64 {
        let k = &self.knots;
        if k.is_empty() {
            return 0.0;
        }
        let i = k.partition_point(|&(a, _)| a <= t);
        if i == 0 {
            return k[0].1;
        }
        if i >= k.len() {
            return k[k.len() - 1].1;
        }
        let (t0, w0) = k[i - 1];
        let (t1, w1) = k[i];
        let u = ((t - t0) / (t1 - t0).max(1e-9)).clamp(0.0, 1.0);
        let s = u * u * (3.0 - 2.0 * u);
        w0 + s * (w1 - w0)
    }

    fn temp_rise(&self, t: f64) -> f64 {
        interp(&self.temp_t, &self.temp, t)
    }
}

fn scroll(sc: &Scenario, index: usize) -> Result<RunOut, Error> {
    let Test::Scroll(rt) = &sc.test else {
        return Err(Error::Invalid("not a rig test".into()));
    };
    let (runout, windows, mu_slip) = match &sc.disturbance {
        Some(Disturbance::WheelRunout { eccentricity_m }) => (*eccentricity_m, Vec::new(), 0.8),
        Some(Disturbance::SlipBursts { windows, mu }) => (0.0, windows.clone(), *mu),
        _ => (0.0, Vec::new(), 0.8),
    };
    let cfg = RigConfig {
        length_m: sc.belt.length_m,
        thickness_m: sc.belt.thickness_m,
        mass_kg: sc.belt.mass_kg,
        nodes: sc.nodes,
        ea_n: sc.ea_n,
        material: sc.material,
        ei_scale: ei_field(sc),
        drive_d_m: rt.drive_d_m,
        idler_d_m: rt.idler_d_m,
        idler_force_n: rt.idler_force_n,
        bearing: sc.bearing,
        idler_runout_m: runout,
        mu: 0.8,
        slip_windows: windows,
        mu_slip,
    };
    let profile = RigProfile::new(rt);
    let run = cfg.run(&profile, rt.duration_s + 0.05, 0.001)?;
    let torque = deripple(
        &run.t_s,
        &run.omega_rad_s,
        &run.torque_nm,
        sc.belt.length_m / sc.nodes as f64,
        0.5 * (rt.drive_d_m + sc.belt.thickness_m),
    );
    let run = crate::scroll::RigRun {
        torque_nm: torque,
        ..run
    };
    let mut rng = noise_rng(sc);
    let lg = rt.logger;
    let torque_rms = rms(&run.torque_nm);
    let sd_t = lg.torque_noise_rel * torque_rms + lg.torque_noise_nm;
    let dt_log = 1.0 / lg.rate_hz;
    let phase = rng.unit() * dt_log;
    let mut csv = String::from(if lg.with_temp {
        "t_s,omega_rad_s,torque_nm,belt_temp_c\n"
    } else {
        "t_s,omega_rad_s,torque_nm\n"
    });
    let mut noise = Vec::new();
    let mut k = 1usize;
    let drops: Vec<usize> = (0..rng.int(0, 2)).map(|_| rng.int(10, 200)).collect();
    loop {
        let t = phase + k as f64 * dt_log;
        if t > rt.duration_s {
            break;
        }
        k += 1;
        let (w, q) = if lg.averaging {
            // Mean of the 1 ms records within (t − Δ, t].
            let a = run.t_s.partition_point(|&x| x <= t - dt_log);
            let b = run.t_s.partition_point(|&x| x <= t);
            if b <= a {
                continue;
            }
            let n = (b - a) as f64;
            (
                run.omega_rad_s[a..b].iter().sum::<f64>() / n,
                run.torque_nm[a..b].iter().sum::<f64>() / n,
            )
        } else {
            (
                interp(&run.t_s, &run.omega_rad_s, t),
                interp(&run.t_s, &run.torque_nm, t),
            )
        };
        if drops.contains(&k) {
            continue;
        }
        let e = sd_t * rng.normal();
        noise.push(e);
        let drift = match sc.disturbance {
            Some(Disturbance::TorqueDrift {
                rel_per_s,
                wander_rel,
                wander_period_s,
            }) => {
                torque_rms
                    * (rel_per_s * t
                        + wander_rel * (std::f64::consts::TAU * t / wander_period_s).sin())
            }
            _ => 0.0,
        };
        let wm = w + lg.omega_noise * rng.normal();
        let _ = write!(csv, "{:.4},{:.3},{:.4}", t, wm, q + e + drift);
        if lg.with_temp {
            let temp = rt.ambient_c + profile.temp_rise(t) + lg.temp_noise_k * rng.normal();
            let _ = write!(csv, ",{:.1}", temp);
        }
        csv.push('\n');
    }
    let ht = 0.5 * sc.belt.thickness_m;
    let c = center_distance(
        sc.belt.length_m,
        0.5 * rt.drive_d_m + ht,
        0.5 * rt.idler_d_m + ht,
    )
    .ok_or_else(|| Error::Invalid("belt too short for the wheels".into()))?;
    let mut toml = String::new();
    let _ = writeln!(toml, "\n[[scroll]]");
    let _ = writeln!(toml, "label = \"run-{}\"", index + 1);
    let _ = writeln!(toml, "drive_diameter_mm = {:.0}", rt.drive_d_m * 1e3);
    let _ = writeln!(toml, "idler_diameter_mm = {:.0}", rt.idler_d_m * 1e3);
    let _ = writeln!(toml, "center_distance_mm = {:.0}", c * 1e3);
    let _ = writeln!(toml, "idler_force_n = {:.0}", rt.idler_force_n);
    let csv_name = format!("scroll-{}.csv", index + 1);
    let _ = writeln!(toml, "series = \"{csv_name}\"");
    let mean = run.torque_nm.iter().sum::<f64>() / run.torque_nm.len().max(1) as f64;
    Ok(RunOut {
        statics: String::new(),
        entry: toml,
        csv_name,
        csv,
        noise,
        noise_unit: "N·m",
        figures: Figures {
            mean_torque_nm: Some(mean),
            ..Default::default()
        },
        step_s: run.step_s,
    })
}

/// Average the torque over one node-passage period `ℓ0/v` (centred, at
/// most 1 s): a chain of nodes entering a wheel makes a chordal ripple at
/// that frequency that a continuous belt does not have (its mean converges
/// with N, the ripple does not vanish). Records are 1 ms apart.
fn deripple(t: &[f64], omega: &[f64], torque: &[f64], l0: f64, r_pitch: f64) -> Vec<f64> {
    let n = torque.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for q in torque {
        let last = prefix.last().copied().unwrap_or(0.0);
        prefix.push(last + q);
    }
    let dt = if n > 1 {
        (t[n - 1] - t[0]) / (n - 1) as f64
    } else {
        1e-3
    };
    (0..n)
        .map(|i| {
            let v = omega[i].abs() * r_pitch;
            let w = (l0 / v.max(l0)).min(1.0);
            let half = (0.5 * w / dt).round() as usize;
            let a = i.saturating_sub(half);
            let b = (i + half + 1).min(n);
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect()
}

fn describe(sc: &Scenario) -> String {
    let mut s = format!("{} (magnitude {:.2})", sc.outcome.as_str(), sc.magnitude);
    use crate::law::{DampingLaw, FrictionLaw};
    match sc.material.friction {
        FrictionLaw::None => {}
        f => {
            let _ = write!(s, "; friction {f:?}");
        }
    }
    match sc.material.damping {
        DampingLaw::Linear { .. } => {}
        d => {
            let _ = write!(s, "; damping {d:?}");
        }
    }
    if let Some(p) = sc.material.payne {
        let _ = write!(s, "; {p:?}");
    }
    if let Some(t) = sc.material.thermal {
        let _ = write!(s, "; {t:?}");
    }
    if let Some(b) = sc.bearing {
        let _ = write!(s, "; {b:?}");
    }
    if let Some(d) = &sc.disturbance {
        let _ = write!(s, "; {d:?}");
    }
    s
}
