//! Identifying the method III joint law (a torque–angle table plus the
//! damping cz) from measured bench-test figures.
//!
//! **Parametrisation.** A 6-breakpoint table through (0, 0), written for
//! E38 and carried over to other link counts by scaling the angles by 38/N
//! (the torques stay; so every slope and cz scale by N/38, the SPEC's
//! constant-EI rule). In E38 angles the breakpoints are
//!
//! `[z1 − 15°, z1, −6°, 0, +3°, +13°]`
//!
//! giving five slopes: Z1 (below `z1`, extended linearly: caps the largest
//! bend, sets Hd), Z2 (`z1`…−6°, the softest, sets Hs), Z3 (−6°…0, sets T),
//! P1 (0…3°) and P2 (above 3°, extended). The fitted unknowns are the
//! logarithms of the five slopes and of cz (so the table is monotone, with
//! zero torque at zero angle, by construction) and the Z1 onset `z1`.
//!
//! **Fit.** Levenberg–Marquardt on the relative errors of Hs, Ws, Hd, Wd, T
//! and Λ (the figures the dataset gives), with finite-difference Jacobians
//! (columns simulated in parallel threads) and a mild Tikhonov regulariser
//! that pulls the log-slopes and log-cz towards the start: an e-fold change
//! of one slope costs as much as a 0.2 % error in one figure. Every step is
//! a fixed sequence of simulations, so the result does not depend on the
//! number of threads. A fit that misses a figure by more than 2 % is
//! restarted from other Z1 onsets ([`Z1_RESTARTS_DEG`]): while no joint
//! bends past the onset, no figure moves with it, and the fit cannot find
//! it from there. The onsets nearest the first fit's are tried first.
//!
//! **Uncertainty.** Each of the dataset's repeat runs (static and dynamic
//! entries paired by position) is fitted again, warm-started from the mean
//! fit and its Jacobian (updated by Broyden's rule; at most ten
//! simulations per run); the spread of those fits is reported for every
//! parameter and every simulated figure, with each run's fit quality.

pub use crate::figures::{PerFigure, Six, FIGURE_NAMES};
pub use crate::params_file::{shipped_law, shipped_text};

use crate::dataset::Dataset;
use crate::error::{Error, Result, ResultExt};
use crate::fit::{self as lm, Problem};
use crate::parallel::{self, with_threads};
use crate::progress::Progress;
use crate::sim::{simulate, Tests};
use serde::Serialize;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use trackbelt::bench::DynamicTest;
use trackbelt::gear::RunningGear;
use trackbelt::joint::JointLaw;
use trackbelt::params::{Belt, Method, Model, Variant};
use trackbelt::rig::RigConfig;
use trackbelt::stiffness::{Stiffness, TorqueTable};
use trackbelt::Settings;

/// Number of breakpoints of the fitted table (including (0, 0)).
pub const BREAKPOINTS: usize = 6;

/// Z2/Z3 boundary, E38 degrees.
const Z3_START_DEG: f64 = -6.0;
/// P1/P2 boundary, E38 degrees.
const P2_START_DEG: f64 = 3.0;
/// Span used to place the outer breakpoints (the end segments extend
/// linearly beyond them), E38 degrees.
const END_SPAN_DEG: f64 = 15.0;
const POS_END_SPAN_DEG: f64 = 10.0;
/// Bounds of the Z1 onset, E38 degrees.
const Z1_MIN_DEG: f64 = -60.0;
const Z1_MAX_DEG: f64 = Z3_START_DEG - 4.0;
/// Bounds of the log-slopes (N·m/rad) and log-cz (N·m·s/rad).
const LN_SLOPE_BOUNDS: (f64, f64) = (-3.0, 7.0);
const LN_CZ_BOUNDS: (f64, f64) = (-6.0, 1.0);
/// Number of unknowns.
const P: usize = 7;
/// Default regulariser weight per unit of log-parameter.
pub const DEFAULT_REGULARISATION: f64 = 0.002;

/// The unknowns of the fit, E38-equivalent (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableParams {
    /// ln of the slopes Z1, Z2, Z3, P1, P2 in N·m/rad (E38 angles).
    pub ln_slopes: [f64; 5],
    /// ln of cz in N·m·s/rad (E38).
    pub ln_cz: f64,
    /// Z1 onset, E38 degrees.
    pub z1_deg: f64,
}

/// The built-in start: round numbers after the SPEC's description of the
/// table (Z1 steep, Z2 the softest, Z3 steeper again, the positive side
/// steeper than Z2/Z3 but far softer than method II's kz1): slopes 40, 6,
/// 15, 30, 60 N·m/rad, cz 0.36 N·m·s/rad (the paper's E38 value), Z1 from
/// −30°, all in E38 terms.
pub const DEFAULT_START: TableParams = TableParams {
    ln_slopes: [3.689, 1.792, 2.708, 3.401, 4.094],
    ln_cz: -1.022,
    z1_deg: -30.0,
};

impl TableParams {
    fn to_vec(self) -> [f64; P] {
        let s = self.ln_slopes;
        [s[0], s[1], s[2], s[3], s[4], self.ln_cz, self.z1_deg / 10.0]
    }

    fn from_vec(x: &[f64]) -> TableParams {
        TableParams {
            ln_slopes: [x[0], x[1], x[2], x[3], x[4]],
            ln_cz: x[5],
            z1_deg: x[6] * 10.0,
        }
    }

    fn clamp(x: &mut [f64]) {
        for v in x.iter_mut().take(5) {
            *v = v.clamp(LN_SLOPE_BOUNDS.0, LN_SLOPE_BOUNDS.1);
        }
        x[5] = x[5].clamp(LN_CZ_BOUNDS.0, LN_CZ_BOUNDS.1);
        x[6] = x[6].clamp(Z1_MIN_DEG / 10.0, Z1_MAX_DEG / 10.0);
    }

    /// Breakpoints for `links` links: angles in degrees, torques in N·m.
    pub fn breakpoints(&self, links: usize) -> ([f64; BREAKPOINTS], [f64; BREAKPOINTS]) {
        let s: Vec<f64> = self.ln_slopes.iter().map(|l| l.exp()).collect();
        let z1 = self.z1_deg.clamp(Z1_MIN_DEG, Z1_MAX_DEG);
        let a38 = [
            z1 - END_SPAN_DEG,
            z1,
            Z3_START_DEG,
            0.0,
            P2_START_DEG,
            P2_START_DEG + POS_END_SPAN_DEG,
        ];
        let r = |d: f64| d.to_radians();
        let t3 = s[2] * r(a38[2]);
        let t2 = t3 + s[1] * r(a38[1] - a38[2]);
        let t1 = t2 + s[0] * r(a38[0] - a38[1]);
        let t4 = s[3] * r(a38[4]);
        let t5 = t4 + s[4] * r(a38[5] - a38[4]);
        let k = 38.0 / links as f64;
        (a38.map(|a| a * k), [t1, t2, t3, 0.0, t4, t5])
    }

    /// cz for `links` links, N·m·s/rad.
    pub fn cz(&self, links: usize) -> f64 {
        self.ln_cz.exp() * links as f64 / 38.0
    }

    /// The joint law for `links` links.
    pub fn joint_law(&self, links: usize) -> Result<JointLaw<f64>> {
        let (a, t) = self.breakpoints(links);
        let a: Vec<f64> = a.iter().map(|d| d.to_radians()).collect();
        let table = TorqueTable::new(&a, &t)?;
        Ok(JointLaw::new(Stiffness::Table(table), self.cz(links))?)
    }

    /// Recover the unknowns from a 6-breakpoint table of this
    /// parametrisation (e.g. a shipped params file), for `links` links.
    pub fn from_law(law: &JointLaw<f64>, links: usize) -> Result<TableParams> {
        let Stiffness::Table(t) = &law.stiffness else {
            return Err(Error::StartLaw(
                "the start law is not a method III table".into(),
            ));
        };
        let (a, m) = (t.angles_rad(), t.torques_nm());
        if a.len() != BREAKPOINTS || a[3] != 0.0 {
            return Err(Error::StartLaw(format!(
                "the start table must have {BREAKPOINTS} breakpoints with (0, 0) the fourth"
            )));
        }
        let k = links as f64 / 38.0; // E38 angle = angle * N/38
        let slope = |i: usize, j: usize| (m[j] - m[i]) / ((a[j] - a[i]) * k);
        Ok(TableParams {
            ln_slopes: [
                slope(0, 1).ln(),
                slope(1, 2).ln(),
                slope(2, 3).ln(),
                slope(3, 4).ln(),
                slope(4, 5).ln(),
            ],
            ln_cz: (law.damping / k).ln(),
            z1_deg: a[1].to_degrees() * k,
        })
    }
}

/// What is simulated: the belt of the dataset, `links` links, the
/// dataset's roller.
#[derive(Debug, Clone, Copy)]
pub struct Setup {
    /// Belt (with the link count of the variant).
    pub belt: Belt<f64>,
    /// Roller mass, kg.
    pub roller_kg: f64,
}

impl Setup {
    /// The setup of a dataset for a variant.
    pub fn of(dataset: &Dataset, variant: Variant) -> Setup {
        Setup::of_links(dataset, variant.links())
    }

    /// The setup of a dataset for `links` links.
    pub fn of_links(dataset: &Dataset, links: usize) -> Setup {
        let b = &dataset.belt;
        let rollers: Vec<f64> = dataset.dynamics.iter().map(|d| d.roller_kg).collect();
        let roller_kg = if rollers.is_empty() {
            1.3
        } else {
            rollers.iter().sum::<f64>() / rollers.len() as f64
        };
        Setup {
            belt: b.belt(links),
            roller_kg,
        }
    }

    /// The paper's belt and roller.
    pub fn paper(variant: Variant) -> Setup {
        Setup {
            belt: Belt::shredder(variant.links()),
            roller_kg: 1.3,
        }
    }

    /// Simulate the static and dynamic tests with `law`.
    pub fn simulate(&self, law: JointLaw<f64>) -> Result<crate::sim::SimOutput> {
        let model = Model::new(self.belt, law)?;
        let dynamic = DynamicTest {
            roller_kg: self.roller_kg,
            ..DynamicTest::default()
        };
        simulate(
            model,
            Method::III,
            Tests::Both,
            Settings::default(),
            dynamic,
        )
        .map(|(o, _)| o)
    }

    fn figures(&self, x: &[f64]) -> Option<Six> {
        let law = TableParams::from_vec(x).joint_law(self.belt.links).ok()?;
        self.simulate(law).ok().map(|o| Six::of(&o))
    }
}

/// Relative difference below which a dataset's belt counts as the paper's
/// Shredder belt (length, mass, thickness), so the built-in start is used
/// as it is.
const SHREDDER_MATCH: f64 = 0.005;

/// Whether `belt` is the paper's Shredder belt (length, mass and thickness
/// within 0.5 %).
pub fn is_shredder(belt: &Belt<f64>) -> bool {
    let s = Belt::<f64>::shredder(belt.links);
    [
        (belt.length_m, s.length_m),
        (belt.mass_kg, s.mass_kg),
        (belt.thickness_m, s.thickness_m),
    ]
    .iter()
    .all(|(a, b)| ((a - b) / b).abs() <= SHREDDER_MATCH)
}

/// Static simulations at most in the start's stiffness search.
const START_STATIC_SIMS: usize = 6;
/// The stiffness search stops once Hs is within this relative error.
const START_HS_TOL: f64 = 0.002;

/// The start of a fit for the dataset's belt: [`DEFAULT_START`] (the
/// Shredder's) for the paper's belt, else the Shredder start carried to the
/// belt and its figures:
///
/// 1. **Similar shape.** A ring of length L and mass m settles into the
///    same shape when its gravity number m·g·L²/EI is the same, so the
///    bending stiffness scales as EI ∝ m·L². The fit's slopes are torques
///    per E38-equivalent angle (κ·L/38 at curvature κ), i.e. 38·EI/L, and
///    scale as m·L; cz, as critical damping √(k·I) with I ∝ m·L², scales
///    as √(m·L · m·L²).
/// 2. **The measured static height.** All slopes are scaled once more by
///    a secant search in log space on Hs (static test only, at most six
///    simulations, until Hs is within 0.2 %): the belt's stiffness relative
///    to its weight, which the similar-shape rule cannot know.
/// 3. **The measured period and decrement.** One full simulation; the Z3
///    slope (the one that sets T) is scaled by (T_model/T_target)²
///    (within ×½…×2) and cz by Λ_target/Λ_model (within ×¼…×4).
///
/// The fit then starts there and its regulariser pulls towards it (not
/// towards the Shredder table). Returns the start and a note describing
/// it (`None` for the paper's belt).
pub fn start_for(setup: &Setup, target: &Six) -> Result<(TableParams, Option<String>)> {
    let b = setup.belt;
    if is_shredder(&b) {
        return Ok((DEFAULT_START, None));
    }
    let s = Belt::<f64>::shredder(38);
    let k0 = (b.mass_kg * b.length_m) / (s.mass_kg * s.length_m);
    let inertia = (b.mass_kg * b.length_m * b.length_m) / (s.mass_kg * s.length_m * s.length_m);
    let mut p = DEFAULT_START;
    let shift = |p: &TableParams, ln_k: f64| TableParams {
        ln_slopes: p.ln_slopes.map(|l| l + ln_k),
        ..*p
    };
    p = shift(&p, k0.ln());
    p.ln_cz += 0.5 * (k0 * inertia).ln();
    let mut steps = Vec::new();
    // 2. Hs: secant on ln(Hs/target) against ln(scale).
    if let Some(hs_t) = target.hs_mm.filter(|h| h.is_finite() && *h > 0.0) {
        let hs_of = |q: &TableParams| -> Option<f64> {
            let law = q.joint_law(b.links).ok()?;
            let model = Model::new(b, law).ok()?;
            simulate(
                model,
                Method::III,
                Tests::Static,
                Settings::default(),
                DynamicTest::default(),
            )
            .ok()
            .map(|(o, _)| o.hs_mm)
            .filter(|h| h.is_finite() && *h > 0.0)
        };
        // (ln scale, ln(Hs/target)) pairs.
        let mut pts: Vec<(f64, f64)> = Vec::new();
        let mut x = 0.0;
        for _ in 0..START_STATIC_SIMS {
            let q = shift(&p, x);
            let Some(hs) = hs_of(&q) else { break };
            let f = (hs / hs_t).ln();
            pts.push((x, f));
            if f.abs() <= START_HS_TOL {
                break;
            }
            // Slope d ln Hs / d ln k: from the last two points, else a
            // typical 0.15 (the Shredder ring's).
            let slope = match pts.as_slice() {
                [.., (x0, f0), (x1, f1)] if (x1 - x0).abs() > 1e-9 => {
                    ((f1 - f0) / (x1 - x0)).clamp(0.02, 2.0)
                }
                _ => 0.15,
            };
            x = (x - f / slope).clamp(x - 1.5, x + 1.5).clamp(-4.0, 4.0);
        }
        // The best point found.
        if let Some(&(xb, fb)) = pts.iter().min_by(|a, b| a.1.abs().total_cmp(&b.1.abs())) {
            p = shift(&p, xb);
            steps.push(format!(
                "stiffness × {:.3} for Hs ({} static runs, Hs {:+.2} %)",
                xb.exp(),
                pts.len(),
                100.0 * (fb.exp() - 1.0)
            ));
        }
    }
    // 3. T and Λ: one full run.
    let run = p
        .joint_law(b.links)
        .ok()
        .and_then(|law| setup.simulate(law).ok());
    let good = |x: Option<f64>| x.filter(|v| v.is_finite() && *v > 0.0);
    let before = p;
    if let Some(o) = &run {
        if let (Some(t_t), Some(t)) = (good(target.period_s), good(o.period_s)) {
            // Z3 sets T (k ∝ 1/T²).
            let r = (t / t_t).powi(2).clamp(0.5, 2.0);
            p.ln_slopes[2] += r.ln();
            steps.push(format!("Z3 × {r:.3} for T"));
        }
        if let (Some(l_t), Some(l)) = (good(target.log_decrement), good(o.log_decrement)) {
            let r = (l_t / l).clamp(0.25, 4.0);
            p.ln_cz += r.ln();
            steps.push(format!("cz × {r:.3} for Λ"));
        }
    }
    let mut v = p.to_vec();
    TableParams::clamp(&mut v);
    let mut p = TableParams::from_vec(&v);
    // The start must simulate: else keep only the cz step, else neither.
    let simulates = |q: &TableParams| {
        q.joint_law(b.links)
            .ok()
            .is_some_and(|law| setup.simulate(law).is_ok())
    };
    if run.is_some() && !simulates(&p) {
        let cz_only = TableParams {
            ln_slopes: before.ln_slopes,
            ..p
        };
        p = if simulates(&cz_only) { cz_only } else { before };
        steps.push("(the T/Λ steps undone: the start did not simulate)".into());
    }
    Ok((
        p,
        Some(format!(
            "start carried from the Shredder table to this belt ({:.0} mm, {:.2} kg): slopes × \
             {:.3} (m·L), cz × {:.3}; {}",
            b.length_m * 1e3,
            b.mass_kg,
            k0,
            (k0 * inertia).sqrt(),
            if steps.is_empty() {
                "no Hs or Λ to refine on".to_string()
            } else {
                steps.join(", ")
            }
        )),
    ))
}

/// The targets of a dataset: the means, and one set per repeat run.
#[derive(Debug, Clone, Serialize)]
pub struct Targets {
    /// Means over all entries.
    pub mean: Six,
    /// One per run: (label, figures); static and dynamic entries paired by
    /// position.
    pub runs: Vec<(String, Six)>,
    /// Figures read from series because an entry lacked them.
    pub notes: Vec<String>,
    /// The dynamic figures of each roller mass the drop tests used
    /// (entries whose masses agree within [`SAME_ROLLER_REL`] share one),
    /// in the order they first appear; empty without dynamic figures.
    pub rollers: Vec<RollerFigures>,
}

/// The drop tests of one roller mass ([`Targets::rollers`]).
#[derive(Debug, Clone, Serialize)]
pub struct RollerFigures {
    /// Roller mass, kg (the first entry's of the group).
    pub roller_kg: f64,
    /// How many `[[dynamic]]` entries used it.
    pub runs: usize,
    /// The mean of their dynamic figures (`hd_mm`, `wd_mm`, `period_s`,
    /// `log_decrement`; the static figures are `None`).
    pub figures: Six,
}

/// One roller's figures in a calibration on several rollers
/// ([`Calibration::rollers`]).
#[derive(Debug, Clone, Serialize)]
pub struct RollerReport {
    /// Roller mass, kg.
    pub roller_kg: f64,
    /// Drop tests with it.
    pub runs: usize,
    /// Their mean dynamic figures.
    pub target: Six,
    /// The fitted table's figures at this mass.
    pub fitted: Six,
    /// Relative errors of its dynamic figures, percent.
    pub rel_err_pct: Six,
}

/// Relative difference below which two drop tests' roller masses count as
/// the same roller ([`Targets::rollers`]).
pub const SAME_ROLLER_REL: f64 = 0.01;

/// The mean of dynamic figure `k` (`hd_mm`, `wd_mm`, `period_s`,
/// `log_decrement`) over the entries that have it; `None` if none has.
fn dynamic_mean(figs: &[[Option<f64>; 4]], k: usize) -> Option<f64> {
    let v: Vec<f64> = figs.iter().filter_map(|f| f[k]).collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

impl Targets {
    /// Targets of a dataset; an error if it holds no figure to fit.
    pub fn of(dataset: &Dataset) -> Result<Targets> {
        // Each dynamic entry's figures: as given, else read from its series.
        let mut notes = Vec::new();
        let dyn_figs: Vec<[Option<f64>; 4]> = dataset
            .dynamics
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let mut f = [e.hd_mm, e.wd_mm, e.period_s, e.log_decrement];
                if let Some(s) = &e.series {
                    if f[0].is_none() || f[2].is_none() || f[3].is_none() {
                        let (hd, t, l) = series_figures(&s.t_s, &s.a_height_mm);
                        let mut used = Vec::new();
                        for (slot, v, name) in [
                            (0, hd, "hd_mm"),
                            (2, t, "period_s"),
                            (3, l, "log_decrement"),
                        ] {
                            if f[slot].is_none() && v.is_some() {
                                f[slot] = v;
                                used.push(name);
                            }
                        }
                        if !used.is_empty() {
                            notes.push(format!(
                                "[[dynamic]] entry {}: {} read from {}",
                                i + 1,
                                used.join(", "),
                                s.file.display()
                            ));
                        }
                    }
                }
                f
            })
            .collect();
        let mean_of = |k: usize| dynamic_mean(&dyn_figs, k);
        let (hs, ws) = dataset.static_mean().unzip();
        let mean = Six {
            hs_mm: hs,
            ws_mm: ws,
            hd_mm: mean_of(0),
            wd_mm: mean_of(1),
            period_s: mean_of(2),
            log_decrement: mean_of(3),
        };
        if mean.to_array().iter().all(Option::is_none) {
            return Err(Error::NoTargets {
                manifest: dataset.dir.join(crate::dataset::MANIFEST_FILE),
            });
        }
        let n = dataset.statics.len().max(dataset.dynamics.len());
        let mut runs = Vec::new();
        for i in 0..n {
            let s = dataset.statics.get(i);
            let dy = dataset.dynamics.get(i);
            let f = dyn_figs.get(i).copied().unwrap_or([None; 4]);
            let label = s
                .and_then(|s| s.label.clone())
                .or_else(|| dy.and_then(|d| d.label.clone()))
                .unwrap_or_else(|| format!("run {}", i + 1));
            let six = Six {
                hs_mm: s.map(|s| s.hs_mm),
                ws_mm: s.map(|s| s.ws_mm),
                hd_mm: f[0],
                wd_mm: f[1],
                period_s: f[2],
                log_decrement: f[3],
            };
            if six.to_array().iter().any(Option::is_some) {
                runs.push((label, six));
            }
        }
        let mut rollers: Vec<(f64, Vec<[Option<f64>; 4]>)> = Vec::new();
        for (e, f) in dataset.dynamics.iter().zip(&dyn_figs) {
            if f.iter().all(Option::is_none) {
                continue;
            }
            let m = e.roller_kg;
            match rollers
                .iter_mut()
                .find(|(r, _)| (m - r).abs() <= SAME_ROLLER_REL * r.abs())
            {
                Some((_, figs)) => figs.push(*f),
                None => rollers.push((m, vec![*f])),
            }
        }
        let rollers = rollers
            .into_iter()
            .map(|(roller_kg, figs)| {
                let mean_of = |k: usize| dynamic_mean(&figs, k);
                RollerFigures {
                    roller_kg,
                    runs: figs.len(),
                    figures: Six {
                        hs_mm: None,
                        ws_mm: None,
                        hd_mm: mean_of(0),
                        wd_mm: mean_of(1),
                        period_s: mean_of(2),
                        log_decrement: mean_of(3),
                    },
                }
            })
            .collect();
        Ok(Targets {
            mean,
            runs,
            notes,
            rollers,
        })
    }
}

/// Shortest dynamic series (s) from which the settled height is read.
const SERIES_MIN_DURATION_S: f64 = 3.0;
/// The settled height is the mean over this last stretch of the series, s.
const SERIES_SETTLE_WINDOW_S: f64 = 1.0;

/// Figures read from a measured dynamic series (A's height over time) the
/// way the model's are read: the settled height is the mean of the last
/// second, T and Λ come from the first two maxima about it after the first
/// dip. The series is smoothed over three samples first (camera noise of
/// about a millimetre); lobes smaller than 2 mm or 5 % of the largest
/// excursion are noise and skipped. `None` where the series does not allow
/// a figure (shorter than 3 s, or fewer than two maxima).
pub fn series_figures(t_s: &[f64], h_mm: &[f64]) -> (Option<f64>, Option<f64>, Option<f64>) {
    let n = t_s.len().min(h_mm.len());
    if n < 10 {
        return (None, None, None);
    }
    let (t, h) = (&t_s[..n], &h_mm[..n]);
    let smooth: Vec<f64> = (0..n)
        .map(|i| {
            let lo = i.saturating_sub(1);
            let hi = (i + 1).min(n - 1);
            h[lo..=hi].iter().sum::<f64>() / (hi - lo + 1) as f64
        })
        .collect();
    let (t0, t_end) = (t[0], t[n - 1]);
    if t_end - t0 < SERIES_MIN_DURATION_S {
        return (None, None, None);
    }
    let tail: Vec<f64> = t
        .iter()
        .zip(&smooth)
        .filter(|(ti, _)| **ti >= t_end - SERIES_SETTLE_WINDOW_S)
        .map(|(_, v)| *v)
        .collect();
    let settled = tail.iter().sum::<f64>() / tail.len().max(1) as f64;
    if !settled.is_finite() {
        // A non-finite value in the last second: no figure (not NaN).
        return (None, None, None);
    }
    let d: Vec<f64> = smooth.iter().map(|v| v - settled).collect();
    let biggest = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let thr = (0.05 * biggest).max(2.0);
    let Some(first_dip) = d.iter().position(|v| *v < -thr) else {
        return (Some(settled), None, None);
    };
    let mut maxima: Vec<(f64, f64)> = Vec::new();
    let mut lobe: Option<usize> = None;
    for i in first_dip..n {
        if d[i] > 0.0 {
            lobe = match lobe {
                Some(k) if d[k] >= d[i] => Some(k),
                _ => Some(i),
            };
        } else if let Some(k) = lobe.take() {
            if d[k] > thr {
                maxima.push(crate::peaks::parabola_vertex(t, &d, k));
                if maxima.len() == 2 {
                    break;
                }
            }
        }
    }
    match maxima.as_slice() {
        [(ta, ha), (tb, hb), ..]
            if *ha > 0.0
                && *hb > 0.0
                && tb > ta
                && (tb - ta).is_finite()
                && (ha / hb).is_finite() =>
        {
            (Some(settled), Some(tb - ta), Some((ha / hb).ln()))
        }
        _ => (Some(settled), None, None),
    }
}

/// Options of a fit.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Worker threads for the Jacobian columns and the per-run fits.
    pub threads: usize,
    /// Largest number of Levenberg–Marquardt iterations.
    pub max_iterations: usize,
    /// Stop once every figure is within this many percent.
    pub tolerance_pct: f64,
    /// Stop as soon as progress stalls (an iteration gains less than 1 % of
    /// the cost) once every figure is within this many percent.
    pub stall_pct: f64,
    /// Regulariser weight: an e-fold change of one slope or of cz from the
    /// start costs as much as this relative error in one figure.
    pub regularisation: f64,
    /// Fit every repeat run too (the spread).
    pub per_run: bool,
    /// Restart a poor mean fit from other Z1 onsets (see [`fit`]).
    pub z1_restarts: bool,
    /// With drop tests of several roller masses, fit each roller's
    /// figures at its own mass ([`fit_rollers`]); `false`: their mean
    /// figures at their mean mass.
    pub per_roller: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            threads: 1,
            max_iterations: 12,
            tolerance_pct: 0.5,
            stall_pct: 2.0,
            regularisation: DEFAULT_REGULARISATION,
            per_run: true,
            z1_restarts: true,
            per_roller: true,
        }
    }
}

/// Mean, standard deviation, min and max of one quantity over the runs.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Spread {
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub std: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

impl Spread {
    fn of(v: &[f64]) -> Option<Spread> {
        if v.is_empty() {
            return None;
        }
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = if v.len() > 1 {
            v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        Some(Spread {
            mean,
            std: var.sqrt(),
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// The fit of one repeat run.
#[derive(Debug, Clone, Serialize)]
pub struct RunFit {
    /// Label of the run.
    pub label: String,
    /// The run's measured figures.
    pub target: Six,
    /// Simulated figures with the run's fitted law.
    pub fitted: Six,
    /// Breakpoint torques, N·mm.
    pub torques_nmm: Vec<f64>,
    /// Breakpoint angles, degrees.
    pub angles_deg: Vec<f64>,
    /// cz, N·mm·s/rad.
    pub cz_nmms_per_rad: f64,
    /// Largest |relative error| of the run's fit, percent.
    pub max_abs_rel_err_pct: f64,
}

/// Spread over the repeat runs.
#[derive(Debug, Clone, Serialize)]
pub struct RunSpread {
    /// Each run's fit.
    pub runs: Vec<RunFit>,
    /// Spread of cz, N·mm·s/rad.
    pub cz_nmms_per_rad: Option<Spread>,
    /// Spread of each breakpoint angle, degrees.
    pub angles_deg: Vec<Option<Spread>>,
    /// Spread of each breakpoint torque, N·mm.
    pub torques_nmm: Vec<Option<Spread>>,
    /// Spread of each simulated figure over the runs' fits.
    pub fitted: SixSpread,
    /// Spread of each measured figure over the runs.
    pub measured: SixSpread,
}

/// A [`Spread`] per figure.
pub type SixSpread = PerFigure<Option<Spread>>;

/// The spread of each figure over `sets`.
fn six_spread<'a>(sets: impl Iterator<Item = &'a Six> + Clone) -> SixSpread {
    PerFigure::from_fn(|i| {
        let v: Vec<f64> = sets.clone().filter_map(|s| s.to_array()[i]).collect();
        Spread::of(&v)
    })
}

/// Result of `calibrate`.
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    /// Dataset name.
    pub dataset: String,
    /// Variant.
    pub variant: String,
    /// Number of links.
    pub links: usize,
    /// Fitted table: breakpoint angles, degrees.
    pub angles_deg: Vec<f64>,
    /// Fitted table: breakpoint torques, N·mm.
    pub torques_nmm: Vec<f64>,
    /// Segment slopes Z1, Z2, Z3, P1, P2 for this variant, N·mm/rad.
    pub slopes_nmm_per_rad: Vec<f64>,
    /// Fitted cz, N·mm·s/rad.
    pub cz_nmms_per_rad: f64,
    /// Simulated figures with the fitted law.
    pub fitted: Six,
    /// The dataset's mean figures.
    pub target: Six,
    /// Relative errors, percent.
    pub rel_err_pct: Six,
    /// Largest |relative error|, percent.
    pub max_abs_rel_err_pct: f64,
    /// Every figure within 2 %.
    pub within_2pct: bool,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Simulations run (mean fit).
    pub simulations: usize,
    /// Restarts of the mean fit from other Z1 onsets (see [`fit`]).
    pub z1_restarts: usize,
    /// Simulations run for the per-run spread.
    pub spread_simulations: usize,
    /// Threads used.
    pub threads: usize,
    /// Wall-clock time of the mean fit, s.
    pub fit_wall_s: f64,
    /// Wall-clock time of the whole calibration (fit and spread), s.
    pub wall_s: f64,
    /// Spread over the repeat runs.
    pub spread: Option<RunSpread>,
    /// Where the params file was written.
    pub out: Option<String>,
    /// Figures read from dynamic series (entries that lacked them).
    pub notes: Vec<String>,
    /// The fitted law's parameters (not serialised).
    #[serde(skip)]
    pub params: Option<TableParams>,
    /// Validity checks the calibrated model's run passed only in part,
    /// `"<check>: <value>"` (see [`crate::validity`]); absent from the JSON
    /// when there is none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// With drop tests of several roller masses ([`Targets::rollers`]):
    /// each roller's figures against the fitted table run at its own mass
    /// ([`fit_rollers`]); then `fitted` is the table run at the mean mass
    /// against the mean figures (`target`), which no one drop test is, and
    /// `max_abs_rel_err_pct` is the largest over the static figures and
    /// these. Empty (absent from the JSON) with one roller.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rollers: Vec<RollerReport>,
    /// The belt fitted on (the dataset's, with `links` links; not
    /// serialised): written into the params file.
    #[serde(skip)]
    pub belt: Option<Belt<f64>>,
    /// The running gear written into the params file (the dataset's
    /// scroll rig, or one given by the caller; not serialised).
    #[serde(skip)]
    pub gear: Option<RunningGear<f64>>,
}

/// Map `f` over `items` on `threads` workers; results in input order
/// (see [`crate::parallel::par_map`]).
pub fn par_map<T: Sync, R: Send, F: Fn(&T) -> R + Sync + Send>(
    items: &[T],
    threads: usize,
    f: F,
) -> Vec<R> {
    parallel::par_map_on(items, threads, f)
}

/// Residual of one figure: relative error; a missing model figure counts
/// as a 100 % error so the fit moves away from it.
fn residuals(f: Option<&Six>, target: &Six) -> Vec<f64> {
    let t = target.to_array();
    let o = f.map(Six::to_array);
    let mut r = Vec::new();
    for i in 0..6 {
        if let Some(ti) = t[i] {
            let oi = o.and_then(|o| o[i]);
            r.push(match oi {
                Some(oi) if ti != 0.0 => (oi - ti) / ti,
                _ => 1.0,
            });
        }
    }
    r
}

/// Largest number of simulations per repeat run in the spread.
const SPREAD_STEPS: usize = 10;
/// A repeat run's fit stops once every figure is within this many percent.
const SPREAD_TOLERANCE_PCT: f64 = 1.0;

/// Finite-difference steps per unknown.
const FD_STEP: [f64; P] = [0.03, 0.03, 0.03, 0.03, 0.03, 0.03, 0.05];

/// Outcome of [`fit`].
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Fitted unknowns.
    pub params: TableParams,
    /// Simulated figures at the fit.
    pub figures: Six,
    /// Iterations.
    pub iterations: usize,
    /// Simulations.
    pub simulations: usize,
    /// Restarts from other Z1 onsets (see [`Z1_RESTARTS_DEG`]).
    pub restarts: usize,
    /// Last Jacobian (rows: the target's figures).
    jacobian: Vec<Vec<f64>>,
}

/// The mean fit as a [`Problem`] of the shared fitter.
struct FigureFit<'a> {
    setup: &'a Setup,
    target: &'a Six,
}

impl Problem for FigureFit<'_> {
    type Output = Six;
    fn evaluate(&self, x: &[f64]) -> Option<Six> {
        self.setup.figures(x)
    }
    fn residuals(&self, f: &Six) -> Vec<f64> {
        residuals(Some(f), self.target)
    }
    fn clamp(&self, x: &mut [f64]) {
        TableParams::clamp(x)
    }
    fn quality(&self, f: &Six) -> f64 {
        f.max_abs_rel_err_pct(self.target)
    }
}

/// The fitter's settings for a calibration: the regulariser pulls the
/// log-slopes and log-cz (not the Z1 onset) towards `prior`; steps are
/// limited to 0.5 per unknown.
fn lm_options(opts: &Options, prior: &[f64; P]) -> lm::Options {
    lm::Options {
        max_iterations: opts.max_iterations,
        tolerance: opts.tolerance_pct,
        rel_tol: 1e-4,
        stall_quality: opts.stall_pct,
        stall_gain: 1e-2,
        max_step: 0.5,
        regularisation: opts.regularisation,
        prior: prior[..REGULARISED].to_vec(),
        ..lm::Options::new(FD_STEP.to_vec())
    }
}

/// Number of leading unknowns the regulariser pulls (the log-slopes and
/// log-cz).
const REGULARISED: usize = 6;

/// A fit that misses a figure by more than this (%) is tried again from
/// other Z1 onsets ([`Z1_RESTARTS_DEG`]).
pub const Z1_RESTART_ABOVE_PCT: f64 = 2.0;

/// The Z1 onsets (E38 degrees) a poor fit is restarted from, nearest the
/// first fit's onset first (see [`restart_order`]).
///
/// The onset is the one unknown with a flat direction: while no joint
/// bends past it, no figure moves with it, so a fit started at −30° on a
/// belt whose side joints stop at −20° never learns that an onset there
/// would set the period. On such a belt (a truth belt stiff for its
/// weight) the fit from −30° missed T by 22 % and Hs by 5.5 %; from −18°
/// it met all six figures within 1.1 %.
pub const Z1_RESTARTS_DEG: [f64; 7] = [-14.0, -18.0, -22.0, -26.0, -34.0, -42.0, -50.0];

/// A restart is skipped when its onset is within this many degrees of the
/// first fit's.
const Z1_RESTART_MIN_SHIFT_DEG: f64 = 3.0;

/// A restart replaces the fit so far only if it lowers the largest figure
/// error by more than this (percentage points).
const Z1_RESTART_GAIN_PCT: f64 = 0.1;

/// The order in which the restarts of a fit whose Z1 onset came out at
/// `first_z1_deg` are tried: [`Z1_RESTARTS_DEG`] by distance from it,
/// nearest first (ties in the constant's order).
///
/// Each restart is a whole fit (up to 12 iterations, about 100
/// simulations) whose result does not depend on the order, and the first
/// to meet the figures ends the search: the order sets the cost, and
/// which onset is kept only where more than one would meet them. Tried
/// from −14° on, a belt of session 61's fresh run (first fit at −30.4°,
/// met at −34°) spent five restarts and 599 simulations on onsets far
/// from its own, and its series took up to 69 s on one core against the
/// 60 s aimed at; nearest first it spends one restart (170 simulations
/// in all). Over that run's 35 dynamic datasets the recalibrations took
/// 676 fewer simulations, and all but one (which met the figures at
/// another onset, 1.13 % instead of 1.46 %) ended at the same onset.
///
/// ```
/// use trackbelt_host::calibrate::restart_order;
/// assert_eq!(restart_order(-30.4), [-34.0, -26.0, -22.0, -42.0, -18.0, -14.0, -50.0]);
/// assert_eq!(restart_order(-30.0), [-26.0, -34.0, -22.0, -18.0, -42.0, -14.0, -50.0]);
/// ```
pub fn restart_order(first_z1_deg: f64) -> [f64; Z1_RESTARTS_DEG.len()] {
    let mut order = Z1_RESTARTS_DEG;
    order.sort_by(|a, b| {
        (a - first_z1_deg)
            .abs()
            .total_cmp(&(b - first_z1_deg).abs())
    });
    order
}

/// Fit the unknowns to `target` from `start` (on `opts.threads` workers).
///
/// The regulariser pulls towards `start` throughout. When the fit misses a
/// figure by more than [`Z1_RESTART_ABOVE_PCT`] (and `opts.z1_restarts`
/// allows it), it is run again from its own result with the Z1 onset
/// moved to each of [`Z1_RESTARTS_DEG`] in turn, nearest the first fit's
/// onset first ([`restart_order`]; the slopes kept), until one meets that
/// bar; the fit with the smallest largest figure error is kept. The
/// iterations and simulations count every run.
pub fn fit(
    setup: &Setup,
    target: &Six,
    start: TableParams,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<FitResult> {
    let r = fit_restarting(&FigureFit { setup, target }, start, opts, progress)?;
    Ok(FitResult {
        params: r.params,
        figures: r.output,
        iterations: r.iterations,
        simulations: r.simulations,
        restarts: r.restarts,
        jacobian: r.jacobian,
    })
}

/// What [`fit_restarting`] found.
struct Restarted<O> {
    params: TableParams,
    output: O,
    iterations: usize,
    simulations: usize,
    restarts: usize,
    jacobian: Vec<Vec<f64>>,
}

/// The fit of [`fit`] (its regulariser, its restarts from other Z1
/// onsets) on any problem over the table's unknowns; a restart is judged
/// by the problem's [`Problem::quality`] (the largest figure error, %).
fn fit_restarting<Pr: Problem>(
    problem: &Pr,
    start: TableParams,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<Restarted<Pr::Output>> {
    let mut prior = start.to_vec();
    TableParams::clamp(&mut prior);
    let lm_opts = lm_options(opts, &prior);
    let run =
        |from: &[f64]| with_threads(opts.threads, || lm::fit(problem, from, &lm_opts, progress));
    let r = run(&prior)??;
    let mut best_quality = problem.quality(&r.output);
    let mut out = Restarted {
        params: TableParams::from_vec(&r.params),
        output: r.output,
        iterations: r.iterations,
        simulations: r.evaluations,
        jacobian: r.jacobian,
        restarts: 0,
    };
    if !opts.z1_restarts || best_quality <= Z1_RESTART_ABOVE_PCT {
        return Ok(out);
    }
    let first = out.params;
    for z1 in restart_order(first.z1_deg) {
        if (z1 - first.z1_deg).abs() < Z1_RESTART_MIN_SHIFT_DEG {
            continue;
        }
        let from = TableParams {
            z1_deg: z1,
            ..first
        }
        .to_vec();
        out.restarts += 1;
        // A restart whose start does not simulate is only a restart lost.
        let Ok(Ok(r)) = run(&from) else { continue };
        out.iterations += r.iterations;
        out.simulations += r.evaluations;
        let q = problem.quality(&r.output);
        if q < best_quality - Z1_RESTART_GAIN_PCT {
            best_quality = q;
            out.params = TableParams::from_vec(&r.params);
            out.output = r.output;
            out.jacobian = r.jacobian;
        }
        if best_quality <= Z1_RESTART_ABOVE_PCT {
            break;
        }
    }
    Ok(out)
}

/// The fit of a belt whose drop tests used several roller masses, each
/// simulated at its own mass ([`fit_rollers`]): the static figures
/// against the first roller's run, each roller's dynamic figures against
/// its own.
struct RollerFit<'a> {
    belt: Belt<f64>,
    statics: Six,
    rollers: &'a [RollerFigures],
}

impl RollerFit<'_> {
    /// The figures of `law`, one per roller, or `None` when a run fails.
    fn figures_of(&self, law: JointLaw<f64>) -> Option<Vec<Six>> {
        self.rollers
            .iter()
            .map(|r| {
                let s = Setup {
                    belt: self.belt,
                    roller_kg: r.roller_kg,
                };
                s.simulate(law.clone()).ok().map(|o| Six::of(&o))
            })
            .collect()
    }
}

impl Problem for RollerFit<'_> {
    type Output = Vec<Six>;
    fn evaluate(&self, x: &[f64]) -> Option<Vec<Six>> {
        let law = TableParams::from_vec(x).joint_law(self.belt.links).ok()?;
        self.figures_of(law)
    }
    fn residuals(&self, f: &Vec<Six>) -> Vec<f64> {
        let mut r = residuals(f.first(), &self.statics);
        for (i, g) in self.rollers.iter().enumerate() {
            r.extend(residuals(f.get(i), &g.figures));
        }
        r
    }
    fn clamp(&self, x: &mut [f64]) {
        TableParams::clamp(x)
    }
    fn quality(&self, f: &Vec<Six>) -> f64 {
        let stat = f
            .first()
            .map_or(f64::INFINITY, |o| o.max_abs_rel_err_pct(&self.statics));
        self.rollers
            .iter()
            .enumerate()
            .map(|(i, g)| {
                f.get(i)
                    .map_or(f64::INFINITY, |o| o.max_abs_rel_err_pct(&g.figures))
            })
            .fold(stat, f64::max)
    }
}

/// Outcome of [`fit_rollers`].
#[derive(Debug, Clone)]
pub struct RollerFitResult {
    /// Fitted unknowns.
    pub params: TableParams,
    /// Simulated figures at the fit, one per roller of
    /// [`Targets::rollers`] (the first carries the static figures).
    pub figures: Vec<Six>,
    /// Largest |relative error| over the static figures and every
    /// roller's dynamic figures, percent.
    pub max_abs_rel_err_pct: f64,
    /// Iterations.
    pub iterations: usize,
    /// Simulations (one per roller per evaluation).
    pub simulations: usize,
    /// Restarts from other Z1 onsets (see [`fit`]).
    pub restarts: usize,
}

/// Fit the table to a dataset whose drop tests used several roller
/// masses ([`Targets::rollers`]), each roller's figures against a run at
/// its own mass, the static figures (`targets.mean`'s `hs_mm`, `ws_mm`)
/// beside them. A mean over rollers of different masses, fitted at their
/// mean mass, is not any one drop test: the settled height, the period
/// and the decrement move with the roller's mass, and not linearly, so
/// each roller is a point of its own on the belt's bending curve. The
/// regulariser and the Z1 restarts are [`fit`]'s. An evaluation costs one
/// simulation per roller.
///
/// ```no_run
/// # fn main() -> trackbelt_host::Result<()> {
/// use trackbelt_host::calibrate::{fit_rollers, start_for, Options, Setup, Targets};
/// let ds = trackbelt_host::dataset::load(std::path::Path::new("my-drop-tests"))?;
/// let targets = Targets::of(&ds)?;
/// let setup = Setup::of_links(&ds, 38);
/// let (start, _) = start_for(&setup, &targets.mean)?;
/// let fit = fit_rollers(&setup, &targets, start, &Options::default(),
///                       &trackbelt_host::progress::NoProgress)?;
/// println!("largest figure error {:.2} %", fit.max_abs_rel_err_pct);
/// # Ok(()) }
/// ```
pub fn fit_rollers(
    setup: &Setup,
    targets: &Targets,
    start: TableParams,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<RollerFitResult> {
    if targets.rollers.is_empty() {
        return Err(Error::InvalidArgument(
            "fit_rollers: the dataset has no drop test with dynamic figures".into(),
        ));
    }
    let problem = RollerFit {
        belt: setup.belt,
        statics: Six {
            hs_mm: targets.mean.hs_mm,
            ws_mm: targets.mean.ws_mm,
            ..Six::default()
        },
        rollers: &targets.rollers,
    };
    let r = fit_restarting(&problem, start, opts, progress)?;
    Ok(RollerFitResult {
        params: r.params,
        max_abs_rel_err_pct: problem.quality(&r.output),
        figures: r.output,
        iterations: r.iterations,
        simulations: r.simulations * targets.rollers.len(),
        restarts: r.restarts,
    })
}

/// Re-fit each repeat run from the mean fit: Levenberg–Marquardt steps
/// starting from the mean fit's Jacobian, updated by Broyden's rank-one
/// rule after every step (one simulation per step, at most
/// `SPREAD_STEPS`, stopping once every figure is within 1 %). Returns
/// the spread and the simulations used.
pub fn run_spread(
    setup: &Setup,
    targets: &Targets,
    mean_fit: &FitResult,
    start: &TableParams,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<(RunSpread, usize)> {
    let reg = opts.regularisation;
    let prior_all = start.to_vec();
    let prior = &prior_all[..REGULARISED];
    let x0 = mean_fit.params.to_vec().to_vec();
    let sims = AtomicUsize::new(0);
    let fits = with_threads(opts.threads, || {
        parallel::par_map(&targets.runs, |(label, t)| {
            // The Jacobian rows of the figures this run has (the mean fit's
            // rows are the mean target's figures).
            let mean_has = targets.mean.to_array();
            let run_has = t.to_array();
            let mut rows = Vec::new();
            let mut k = 0;
            for i in 0..6 {
                if mean_has[i].is_some() {
                    if run_has[i].is_some() {
                        if let Some(row) = mean_fit.jacobian.get(k) {
                            rows.push(row.clone());
                        }
                    }
                    k += 1;
                }
            }
            let mut x = x0.clone();
            let mut f = mean_fit.figures;
            let mut lambda = 1e-3;
            for _ in 0..SPREAD_STEPS {
                if f.max_abs_rel_err_pct(t) <= SPREAD_TOLERANCE_PCT {
                    break;
                }
                let r = residuals(Some(&f), t);
                if rows.len() != r.len() {
                    break;
                }
                let Some(d) = lm::lm_step(&rows, &r, &x, prior, reg, lambda) else {
                    break;
                };
                let mut xn: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + b).collect();
                TableParams::clamp(&mut xn);
                sims.fetch_add(1, Ordering::SeqCst);
                let fe = setup.figures(&xn);
                progress.step();
                let Some(fe) = fe else {
                    lambda *= 10.0;
                    continue;
                };
                // Broyden update of the Jacobian with the step just taken.
                let rn = residuals(Some(&fe), t);
                let dx: Vec<f64> = xn.iter().zip(&x).map(|(a, b)| a - b).collect();
                let dx2: f64 = dx.iter().map(|v| v * v).sum();
                if dx2 > 0.0 {
                    for (row, (a, b)) in rows.iter_mut().zip(rn.iter().zip(&r)) {
                        let pred: f64 = row.iter().zip(&dx).map(|(j, d)| j * d).sum();
                        let k = (a - b - pred) / dx2;
                        for (j, d) in row.iter_mut().zip(&dx) {
                            *j += k * d;
                        }
                    }
                }
                if lm::cost(&rn, &xn, prior, reg) < lm::cost(&r, &x, prior, reg) {
                    x = xn;
                    f = fe;
                    lambda = (lambda / 3.0).max(1e-6);
                } else {
                    lambda *= 10.0;
                }
            }
            let p = TableParams::from_vec(&x);
            let (a, m) = p.breakpoints(setup.belt.links);
            RunFit {
                label: label.clone(),
                target: *t,
                fitted: f,
                torques_nmm: m.iter().map(|v| v * 1e3).collect(),
                angles_deg: a.to_vec(),
                cz_nmms_per_rad: p.cz(setup.belt.links) * 1e3,
                max_abs_rel_err_pct: f.max_abs_rel_err_pct(t),
            }
        })
    })?;
    let per = |get: &dyn Fn(&RunFit) -> f64| Spread::of(&fits.iter().map(get).collect::<Vec<_>>());
    let spread = RunSpread {
        cz_nmms_per_rad: per(&|r| r.cz_nmms_per_rad),
        angles_deg: (0..BREAKPOINTS)
            .map(|i| per(&|r| r.angles_deg.get(i).copied().unwrap_or(f64::NAN)))
            .collect(),
        torques_nmm: (0..BREAKPOINTS)
            .map(|i| per(&|r| r.torques_nmm.get(i).copied().unwrap_or(f64::NAN)))
            .collect(),
        fitted: six_spread(fits.iter().map(|r| &r.fitted)),
        measured: six_spread(targets.runs.iter().map(|(_, s)| s)),
        runs: fits,
    };
    Ok((spread, sims.load(Ordering::SeqCst)))
}

/// Calibrate `variant` against `dataset`: the mean fit and, if asked, the
/// per-run spread. `progress` gets one step per simulation.
pub fn calibrate(
    dataset: &Dataset,
    variant: Variant,
    start: TableParams,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<Calibration> {
    calibrate_links(dataset, variant.links(), start, opts, progress)
}

/// [`calibrate`] for any number of links (3 to
/// [`crate::params_file::MAX_LINKS`]); the result names a preset's variant
/// for 38, 56 and 76 links, `N<links>` otherwise.
pub fn calibrate_links(
    dataset: &Dataset,
    links: usize,
    start: TableParams,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<Calibration> {
    let t0 = Instant::now();
    let targets = Targets::of(dataset)?;
    let setup = Setup::of_links(dataset, links);
    progress.set_total(((opts.max_iterations + 1) * (P + 2) + 48) as u64);
    let mut notes = targets.notes.clone();
    // Drop tests with rollers of different masses: each roller's figures
    // at its own mass (a mean over them at the mean mass is no drop test).
    let by_roller = if opts.per_roller && targets.rollers.len() >= 2 {
        Some(fit_rollers(&setup, &targets, start, opts, progress)?)
    } else {
        None
    };
    // With several rollers the table's run at the mean mass gives the
    // mean report's figures; it is the validity run below too.
    let mut at_mean = None;
    let mean = match &by_roller {
        Some(r) => {
            let o = setup
                .simulate(r.params.joint_law(links)?)
                .context_with(|| "the calibrated model at the mean roller mass")?;
            let figures = Six::of(&o);
            at_mean = Some(o);
            FitResult {
                params: r.params,
                figures,
                iterations: r.iterations,
                simulations: r.simulations + 1,
                restarts: r.restarts,
                jacobian: Vec::new(),
            }
        }
        None => fit(&setup, &targets.mean, start, opts, progress)?,
    };
    let fit_wall_s = t0.elapsed().as_secs_f64();
    if by_roller.is_some() && opts.per_run {
        notes.push(format!(
            "no per-run spread: the drop tests used {} roller masses, and each is one point of the fit, not a repeat",
            targets.rollers.len()
        ));
    }
    let (spread, spread_sims) = if opts.per_run && targets.runs.len() > 1 && by_roller.is_none() {
        let (s, n) = run_spread(&setup, &targets, &mean, &start, opts, progress)?;
        (Some(s), n)
    } else {
        (None, 0)
    };
    let p = mean.params;
    // The calibrated model, simulated once more through the validity checks
    // (crate::validity): an invalid run is an error, a doubtful one a
    // warning in the report.
    let mut warnings = match at_mean {
        Some(o) => o.warnings,
        None => {
            setup
                .simulate(p.joint_law(links)?)
                .context_with(|| "the calibrated model")?
                .warnings
        }
    };
    // With several rollers, each roller's run passes the same checks.
    if by_roller.is_some() {
        for r in &targets.rollers {
            let at = Setup {
                roller_kg: r.roller_kg,
                ..setup
            };
            let o = at.simulate(p.joint_law(links)?).context_with(|| {
                format!("the calibrated model with the {:.3} kg roller", r.roller_kg)
            })?;
            warnings.extend(
                o.warnings
                    .into_iter()
                    .map(|w| format!("{:.3} kg roller: {w}", r.roller_kg)),
            );
        }
    }
    let (a, m) = p.breakpoints(links);
    let k = links as f64 / 38.0;
    let max_err = by_roller.as_ref().map_or_else(
        || mean.figures.max_abs_rel_err_pct(&targets.mean),
        |r| r.max_abs_rel_err_pct,
    );
    let rollers: Vec<RollerReport> = by_roller
        .as_ref()
        .map(|r| {
            targets
                .rollers
                .iter()
                .zip(&r.figures)
                .map(|(g, f)| RollerReport {
                    roller_kg: g.roller_kg,
                    runs: g.runs,
                    target: g.figures,
                    fitted: *f,
                    rel_err_pct: f.rel_err_pct(&g.figures),
                })
                .collect()
        })
        .unwrap_or_default();
    Ok(Calibration {
        dataset: dataset.name.clone(),
        variant: crate::sim::variant_label(links),
        links,
        angles_deg: a.to_vec(),
        torques_nmm: m.iter().map(|v| v * 1e3).collect(),
        slopes_nmm_per_rad: p.ln_slopes.iter().map(|l| l.exp() * k * 1e3).collect(),
        cz_nmms_per_rad: p.cz(links) * 1e3,
        fitted: mean.figures,
        target: targets.mean,
        rel_err_pct: mean.figures.rel_err_pct(&targets.mean),
        max_abs_rel_err_pct: max_err,
        within_2pct: max_err <= 2.0,
        iterations: mean.iterations,
        simulations: mean.simulations,
        z1_restarts: mean.restarts,
        spread_simulations: spread_sims,
        threads: opts.threads,
        fit_wall_s,
        wall_s: t0.elapsed().as_secs_f64(),
        spread,
        out: None,
        notes,
        params: Some(p),
        warnings,
        rollers,
        belt: Some(setup.belt),
        gear: scroll_gear(dataset)?,
    })
}

/// The dataset's rig as a two-wheel running gear: its first `[[scroll]]`
/// entry (drive at the origin, idler at the centre distance on a force
/// tensioner: the entry's force, else the paper rig's 500 N; the paper
/// rig's contact law). `None` without scroll entries.
pub fn scroll_gear(dataset: &Dataset) -> Result<Option<RunningGear<f64>>> {
    let Some(e) = dataset.scrolls.first() else {
        return Ok(None);
    };
    let d = RigConfig::<f64>::default();
    let config = RigConfig {
        drive_diameter_m: e.drive_diameter_mm * 1e-3,
        idler_diameter_m: e.idler_diameter_mm * 1e-3,
        idler_force_n: e.idler_force_n.unwrap_or(d.idler_force_n),
        ..d
    };
    Ok(Some(RunningGear::paper_rig(
        &config,
        e.center_distance_mm * 1e-3,
    )?))
}

/// The params-file text of a calibration, with a header comment naming the
/// command that produced it.
pub fn params_toml(c: &Calibration, command: &str) -> Result<String> {
    let p = c
        .params
        .ok_or_else(|| Error::InvalidArgument("calibration has no parameters".into()))?;
    let variant = Variant::parse(&c.variant);
    let law = p.joint_law(c.links)?;
    let file = crate::params_file::to_file(variant, c.belt.as_ref(), &law, c.gear.as_ref());
    let body = toml::to_string(&file).map_err(|e| Error::Params(e.to_string()))?;
    let e = &c.rel_err_pct;
    let pct = |v: Option<f64>| v.map_or("-".into(), |x| format!("{x:+.2}"));
    Ok(format!(
        "# Method III joint law for {} ({} links), calibrated against the dataset {:?}.\n\
         # Params file version 2: with the dataset's belt (and its scroll rig as the running gear, when it has one).\n\
         # Produced by: {command}\n\
         # Fit: relative errors % Hs {} Ws {} Hd {} Wd {} T {} Λ {}\n\
         # (table breakpoints: E38 angles scaled by 38/N; slopes Z1 Z2 Z3 P1 P2 in N·mm/rad: {})\n\
         {body}",
        c.variant,
        c.links,
        c.dataset,
        pct(e.hs_mm),
        pct(e.ws_mm),
        pct(e.hd_mm),
        pct(e.wd_mm),
        pct(e.period_s),
        pct(e.log_decrement),
        c.slopes_nmm_per_rad
            .iter()
            .map(|s| format!("{s:.0}"))
            .collect::<Vec<_>>()
            .join(" "),
    ))
}

/// Write `text` to `out` atomically ([`crate::atomic::write_atomic`]: a
/// failure leaves no half-written file), refusing to write inside the
/// dataset directory.
pub fn write_params(out: &Path, dataset_dir: &Path, text: &str) -> Result<()> {
    let dir = out.parent().filter(|p| !p.as_os_str().is_empty());
    let dir_abs = std::fs::canonicalize(dir.unwrap_or(Path::new("."))).map_err(|e| {
        Error::InvalidArgument(format!("--out {}: its directory: {e}", out.display()))
    })?;
    if let Ok(ds) = std::fs::canonicalize(dataset_dir) {
        if dir_abs.starts_with(&ds) {
            return Err(Error::InvalidArgument(format!(
                "--out {}: refusing to write inside the dataset directory {}",
                out.display(),
                dataset_dir.display()
            )));
        }
    }
    if out.file_name().is_none() {
        return Err(Error::InvalidArgument(format!(
            "--out {}: not a file name",
            out.display()
        )));
    }
    crate::atomic::write_atomic(out, text.as_bytes()).map_err(|e| match e {
        Error::Io { source, .. } => Error::Io {
            action: "cannot write",
            path: out.to_path_buf(),
            source,
        },
        e => e,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parametrisation_round_trips_and_scales() {
        let p = DEFAULT_START;
        for links in [38, 56, 76] {
            let law = p.joint_law(links).unwrap();
            let q = TableParams::from_law(&law, links).unwrap();
            for i in 0..5 {
                assert!((p.ln_slopes[i] - q.ln_slopes[i]).abs() < 1e-9);
            }
            assert!((p.ln_cz - q.ln_cz).abs() < 1e-9);
            assert!((p.z1_deg - q.z1_deg).abs() < 1e-9);
        }
        let (a38, t38) = p.breakpoints(38);
        let (a76, t76) = p.breakpoints(76);
        assert_eq!(t38, t76);
        assert!((a76[0] * 2.0 - a38[0]).abs() < 1e-12);
        assert!((p.cz(76) - 2.0 * p.cz(38)).abs() < 1e-12);
    }

    #[test]
    fn series_figures_recover_a_noisy_damped_oscillation() {
        // 25 Hz camera, ±1 mm noise, two missing rows.
        let (hd, period, lam) = (225.0, 0.74, 0.73);
        let mut seed = 12345u64;
        let mut t = Vec::new();
        let mut h = Vec::new();
        for i in 0..150 {
            if i == 40 || i == 41 {
                continue;
            }
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let noise = ((seed >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 2.0;
            let ti = i as f64 * 0.04;
            let y = hd
                + 99.0 * (-lam * ti / period).exp() * (std::f64::consts::TAU * ti / period).cos();
            t.push(ti);
            h.push(y + noise);
        }
        let (h_s, t_s, l_s) = series_figures(&t, &h);
        let (h_s, t_s, l_s) = (h_s.unwrap(), t_s.unwrap(), l_s.unwrap());
        assert!((h_s - hd).abs() < 1.0, "Hd {h_s}");
        assert!((t_s - period).abs() < 0.02 * period, "T {t_s}");
        assert!((l_s - lam).abs() < 0.08 * lam, "Λ {l_s}");
        // Too short: nothing.
        assert_eq!(series_figures(&t[..50], &h[..50]), (None, None, None));
    }

    #[test]
    fn spread_statistics() {
        let s = Spread::of(&[1.0, 2.0, 3.0]).unwrap();
        assert_eq!((s.mean, s.min, s.max), (2.0, 1.0, 3.0));
        assert!((s.std - 1.0).abs() < 1e-12);
        assert!(Spread::of(&[]).is_none());
    }
}
