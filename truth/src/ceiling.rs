//! How much evidence of its effect a dataset holds at best, measured with
//! the truth's own laws: the **evidence ceiling**.
//!
//! A diagnosis that misses an effect may be at fault, or the data may not
//! hold the effect above the noise once a belt's unknowns are fitted. This
//! module tells the two apart for a scenario drawn by [`crate::draw`] or
//! [`crate::draw_at`]:
//!
//! 1. the effect's scenario and its clean twin (the belt of
//!    `Outcome::None` at the same seed, on the effect's bench: the same
//!    rig, profile, camera or logger) are run without noise;
//! 2. the twin's bending stiffness (EI), the curvatures of its bending law
//!    and its linear damping are scaled — three nuisance factors, found by
//!    Nelder–Mead on their logarithms (EI and damping first, then all
//!    three from there); on a drop test the height offset is solved in
//!    closed form — so that the twin matches the effect's noise-free
//!    series as well as it can;
//! 3. what is left, in units of the noise put in, is the ceiling:
//!    `Δχ² = Σ ((effect − best twin) / σ)²` over every sample of the
//!    series' main channel (heights, and the horizontal position where
//!    written; or the torque).
//!
//! Any method that does not know the belt's exact law can gain at most
//! about this much by naming the effect: it must fit at least these
//! unknowns (the project's diagnosis refits more: the table's shape, cz
//! and the camera offset), and a fitted family of its own absorbs at least
//! as much of the effect unless it is wrong about the clean belt. With an
//! information criterion a name needs a gain of the order of ten plus the
//! effect's parameters times ln n, so a ceiling under about 20 says that
//! no method can name the effect, and one in the hundreds says the data
//! carry it. The minimiser may stop in a local minimum, so the ceiling is
//! an upper estimate.

use crate::law::{DampingLaw, FrictionLaw, Material};
use crate::scenario::Test;
use crate::{draw_at, generate, EffectKind, Error, Outcome, Scenario, SeriesKind};
use std::path::Path;

/// Most simulations of the twin one search (EI and damping, then the three
/// factors) spends.
pub const SEARCH_RUNS: usize = 40;

/// The evidence ceiling of one dataset ([`ceiling`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ceiling {
    /// Samples compared.
    pub samples: usize,
    /// The noise put into the series (its standard deviation, in the
    /// series' unit: mm or N·m).
    pub sigma: f64,
    /// Δχ² against the clean twin as it is.
    pub chi2_twin: f64,
    /// Δχ² against the best-scaled twin: the ceiling.
    pub chi2: f64,
    /// The twin's EI factor at the ceiling.
    pub ei_factor: f64,
    /// The factor on the curvatures of the twin's bending law.
    pub curvature_factor: f64,
    /// The twin's linear-damping factor.
    pub damping_factor: f64,
}

/// The evidence ceiling of the effect in `sc` (see the module's text).
/// `scratch` is a directory the runs are written into and removed from
/// (created if missing; it must not hold anything else).
///
/// Errors: the scenario holds no catalogue effect, its clean twin is
/// another belt (a scenario not made by [`crate::draw`] or
/// [`crate::draw_at`]), or a run fails.
///
/// ```no_run
/// use trackbelt_truth::{ceiling::ceiling, draw, EffectKind, Outcome, SeriesKind};
/// let sc = draw(Outcome::Effect(EffectKind::QuadraticDamping), SeriesKind::Dynamic, 14801)?;
/// let c = ceiling(&sc, &std::env::temp_dir().join("ceiling-14801"))?;
/// // Magnitude 0.38 under 0.9 mm of marker noise: about 4, beyond any method.
/// println!("Δχ² {:.1} (against the twin as it is: {:.1})", c.chi2, c.chi2_twin);
/// # Ok::<(), trackbelt_truth::Error>(())
/// ```
pub fn ceiling(sc: &Scenario, scratch: &Path) -> Result<Ceiling, Error> {
    if !matches!(sc.outcome, Outcome::Effect(_)) {
        return Err(Error::Invalid(format!(
            "the evidence ceiling is an effect's; this scenario holds {}",
            sc.outcome.as_str()
        )));
    }
    let kind = sc.kind();
    // The clean belt of the same seed, on this scenario's bench and
    // instruments (thermal softening also warms the rig more and logs the
    // temperature; neither changes a clean belt's torque).
    let clean = draw_at(Outcome::None, kind, sc.seed, sc.magnitude)?;
    if clean.belt != sc.belt || clean.nodes != sc.nodes || clean.nonuniformity != sc.nonuniformity {
        return Err(Error::Invalid(format!(
            "seed {}: the clean twin is another belt (a scenario not drawn by draw or draw_at)",
            sc.seed
        )));
    }
    let mut twin = sc.clone();
    twin.outcome = Outcome::None;
    twin.material = clean.material;
    twin.bearing = None;
    twin.disturbance = None;
    let s = start(sc, &twin, "clean twin", scratch)?;
    let chi2_twin = s.chi2;
    let mut f = |p: [f64; 3]| -> f64 {
        let mut t = s.q.clone();
        t.material = scaled(&s.q.material, p);
        s.trial(&t, scratch)
    };
    let (p2, v2) = minimise(
        &mut |p: [f64; 2]| f([p[0], 0.0, p[1]]),
        ([0.0; 2], chi2_twin),
        SEARCH_RUNS,
    );
    let (p, best) = nelder_mead(&mut f, ([p2[0], 0.0, p2[1]], v2), SEARCH_RUNS);
    let _ = std::fs::remove_dir_all(scratch);
    Ok(Ceiling {
        samples: s.y.len(),
        sigma: s.sigma,
        chi2_twin,
        chi2: best,
        ei_factor: p[0].exp(),
        curvature_factor: p[1].exp(),
        damping_factor: p[2].exp(),
    })
}

/// How well another effect of the catalogue, with its law free, stands in
/// for the effect of a dataset ([`rival_ceiling`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RivalCeiling {
    /// The rival effect.
    pub rival: EffectKind,
    /// Samples compared.
    pub samples: usize,
    /// The noise put into the series (its standard deviation, in the
    /// series' unit: mm or N·m).
    pub sigma: f64,
    /// Δχ² against the rival's twin as drawn (the rival's own law at this
    /// seed and magnitude, on the clean belt).
    pub chi2_start: f64,
    /// Δχ² against the best rival twin: the rival ceiling.
    pub chi2: f64,
    /// The twin's EI, curvature and linear-damping factors at the best.
    pub factors: [f64; 3],
    /// The rival's law at the best, in words.
    pub rival_law: String,
}

/// The rival ceiling: the effect of `sc` (drawn by [`crate::draw`] or
/// [`crate::draw_at`]) against `rival`, another effect shown by the same
/// kind of series, measured with the truth's own laws as [`ceiling`]
/// measures it against the clean belt. The twin is the clean belt of the
/// same seed with the rival's law of that seed and magnitude added, on the
/// effect's bench; its EI, curvatures and linear damping are scaled and
/// the rival's size is fitted with them (one more factor: joint friction's
/// sliding moment, the drag coefficient, the Payne depth, the bearing's
/// torque, the power law's exponent, the thermal coefficient), by
/// Nelder–Mead on the noise-free series: first the damping and the rival,
/// then all four.
///
/// A ceiling says how far the effect stands from a clean belt; this says
/// how far it stands from the rival family. Under about 20 no method can
/// tell the two apart on this dataset, whatever the effect ceiling.
///
/// Errors: as [`ceiling`], and a rival that is the effect itself or is
/// shown by the other kind of series.
///
/// ```no_run
/// use trackbelt_truth::ceiling::rival_ceiling;
/// use trackbelt_truth::{draw, EffectKind, Outcome, SeriesKind};
/// let sc = draw(Outcome::Effect(EffectKind::BearingFriction), SeriesKind::Scroll, 15003)?;
/// let scratch = std::env::temp_dir().join("rival-15003");
/// let r = rival_ceiling(&sc, EffectKind::RateDependentDamping, &scratch)?;
/// println!("Δχ² {:.1} with {}", r.chi2, r.rival_law);
/// # Ok::<(), trackbelt_truth::Error>(())
/// ```
pub fn rival_ceiling(
    sc: &Scenario,
    rival: EffectKind,
    scratch: &Path,
) -> Result<RivalCeiling, Error> {
    let Outcome::Effect(effect) = sc.outcome else {
        return Err(Error::Invalid(format!(
            "the rival ceiling is an effect's; this scenario holds {}",
            sc.outcome.as_str()
        )));
    };
    let kind = sc.kind();
    if rival == effect || rival.kind() != kind {
        return Err(Error::Invalid(format!(
            "{} is no rival of {} on a {} series",
            rival.as_str(),
            effect.as_str(),
            kind.as_str()
        )));
    }
    let r = draw_at(Outcome::Effect(rival), kind, sc.seed, sc.magnitude)?;
    if r.belt != sc.belt || r.nodes != sc.nodes || r.nonuniformity != sc.nonuniformity {
        return Err(Error::Invalid(format!(
            "seed {}: the rival's twin is another belt (a scenario not drawn by draw or draw_at)",
            sc.seed
        )));
    }
    let mut twin = sc.clone();
    twin.outcome = Outcome::Effect(rival);
    twin.material = r.material;
    twin.bearing = r.bearing;
    twin.disturbance = None;
    let s = start(sc, &twin, "rival's twin", scratch)?;
    let chi2_start = s.chi2;
    let mut f = |p: [f64; 4]| s.trial(&with_rival(&s.q, rival, p), scratch);
    let (p2, v2) = minimise(
        &mut |p: [f64; 2]| f([0.0, 0.0, p[0], p[1]]),
        ([0.0; 2], chi2_start),
        SEARCH_RUNS,
    );
    let (p, best) = nelder_mead(&mut f, ([0.0, 0.0, p2[0], p2[1]], v2), SEARCH_RUNS);
    let _ = std::fs::remove_dir_all(scratch);
    let at = with_rival(&s.q, rival, p);
    Ok(RivalCeiling {
        rival,
        samples: s.y.len(),
        sigma: s.sigma,
        chi2_start,
        chi2: best,
        factors: [p[0].exp(), p[1].exp(), p[2].exp()],
        rival_law: rival_law(&at, rival),
    })
}

/// `q` (a rival's twin) with the nuisance factors `p[0..3]` (as
/// [`scaled`]) and the rival's size `p[3]`: a log factor on joint
/// friction's sliding moment, the drag coefficient, the bearing's torque
/// or the thermal coefficient; an offset added to the Payne depth or the
/// power law's exponent (kept in 0.05…0.98).
fn with_rival(q: &Scenario, rival: EffectKind, p: [f64; 4]) -> Scenario {
    let mut t = q.clone();
    let mut m = scaled(&q.material, [p[0], p[1], p[2]]);
    let k = p[3].exp();
    match rival {
        EffectKind::JointFriction => {
            m.friction = match m.friction {
                FrictionLaw::Dahl { m_c, kappa_s } => FrictionLaw::Dahl {
                    m_c: m_c * k,
                    kappa_s,
                },
                FrictionLaw::Tanh { m_c, rate } => FrictionLaw::Tanh {
                    m_c: m_c * k,
                    rate: rate * k,
                },
                FrictionLaw::None => FrictionLaw::None,
            }
        }
        EffectKind::QuadraticDamping => {
            if let DampingLaw::Drag { c, cq, p: e, cap } = m.damping {
                m.damping = DampingLaw::Drag {
                    c,
                    cq: cq * k,
                    p: e,
                    cap,
                };
            }
        }
        EffectKind::AmplitudeStiffness => {
            if let Some(pl) = m.payne.as_mut() {
                pl.depth += p[3];
            }
        }
        EffectKind::BearingFriction => {
            if let Some(b) = t.bearing.as_mut() {
                b.torque_nm *= k;
            }
        }
        EffectKind::RateDependentDamping => {
            if let DampingLaw::Power { alpha, .. } = &mut m.damping {
                *alpha = (*alpha + p[3]).clamp(0.05, 0.98);
            }
        }
        EffectKind::ThermalSoftening => {
            if let Some(th) = m.thermal.as_mut() {
                th.beta_per_k *= k;
            }
        }
    }
    t.material = m;
    t
}

/// The rival's law in `t`, in words.
fn rival_law(t: &Scenario, rival: EffectKind) -> String {
    let m = &t.material;
    match rival {
        EffectKind::JointFriction => format!("{:?}", m.friction),
        EffectKind::QuadraticDamping | EffectKind::RateDependentDamping => {
            format!("{:?}", m.damping)
        }
        EffectKind::AmplitudeStiffness => format!("{:?}", m.payne),
        EffectKind::BearingFriction => format!("{:?}", t.bearing),
        EffectKind::ThermalSoftening => format!("{:?}", m.thermal),
    }
}

/// What a search starts from: the effect's noise-free series, the noise
/// put in, the twin without noise, whether a height offset is solved, and
/// Δχ² against the twin as it is.
struct Start {
    y: Vec<f64>,
    sigma: f64,
    q: Scenario,
    offset: bool,
    chi2: f64,
}

impl Start {
    /// Δχ² of the effect's series against the noise-free run of `t` (a
    /// trial twin of the search); infinite when `t` cannot be run, a bad
    /// point rather than an error.
    fn trial(&self, t: &Scenario, scratch: &Path) -> f64 {
        match series(t, scratch) {
            Ok((z, _)) => chi2(&self.y, &z, self.sigma, self.offset),
            Err(_) => f64::INFINITY,
        }
    }
}

/// The [`Start`] of a search for the effect of `sc` against `twin` (named
/// `what` in errors). The twin as it is must run and match the effect's
/// samples: a trial of the search that fails is only a bad point, but
/// without this start the ceiling would be an infinite figure from runs
/// that never worked.
fn start(sc: &Scenario, twin: &Scenario, what: &str, scratch: &Path) -> Result<Start, Error> {
    let (_, sigma) = series(sc, scratch)?;
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(Error::Invalid(format!(
            "noise {sigma}: no ceiling without noise"
        )));
    }
    let (y, _) = series(&quiet(sc), scratch)?;
    let q = quiet(twin);
    let offset = sc.kind() == SeriesKind::Dynamic;
    let (z0, _) = series(&q, scratch)?;
    let chi2 = chi2(&y, &z0, sigma, offset);
    if !chi2.is_finite() {
        return Err(Error::Invalid(format!(
            "seed {}: the {what}'s series ({} values) does not match the effect's ({})",
            sc.seed,
            z0.len(),
            y.len()
        )));
    }
    Ok(Start {
        y,
        sigma,
        q,
        offset,
        chi2,
    })
}

/// The main channel of `sc`'s series as written, and the noise put in.
fn series(sc: &Scenario, dir: &Path) -> Result<(Vec<f64>, f64), Error> {
    let _ = std::fs::remove_dir_all(dir);
    let truth = generate(sc, dir)?;
    let file = dir.join(match sc.kind() {
        SeriesKind::Dynamic => "dynamic-1.csv",
        SeriesKind::Scroll => "scroll-1.csv",
    });
    let text = std::fs::read_to_string(&file).map_err(|source| Error::Io {
        path: file.clone(),
        source,
    })?;
    let _ = std::fs::remove_dir_all(dir);
    let mut lines = text.lines();
    let cols: Vec<usize> = lines
        .next()
        .unwrap_or("")
        .split(',')
        .enumerate()
        .filter(|(_, h)| matches!(*h, "a_height_mm" | "a_x_mm" | "torque_nm"))
        .map(|(i, _)| i)
        .collect();
    let mut y = Vec::new();
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        for &c in &cols {
            let v = f.get(c).and_then(|s| s.parse::<f64>().ok());
            y.push(v.ok_or_else(|| Error::Invalid(format!("{}: bad row {l:?}", file.display())))?);
        }
    }
    Ok((y, truth.noise_rms))
}

/// `sc` without noise on its main channels.
fn quiet(sc: &Scenario) -> Scenario {
    let mut q = sc.clone();
    match &mut q.test {
        Test::Dynamic(d) => d.camera.noise_mm = 0.0,
        Test::Scroll(r) => {
            r.logger.torque_noise_rel = 0.0;
            r.logger.torque_noise_nm = 0.0;
            r.logger.omega_noise = 0.0;
            r.logger.temp_noise_k = 0.0;
        }
    }
    q
}

/// `m` with EI, the curvatures and the linear damping (the linear
/// coefficient of any damping law) scaled by
/// `exp(p[0])`, `exp(p[1])`, `exp(p[2])`.
fn scaled(m: &Material, p: [f64; 3]) -> Material {
    let mut m = *m;
    m.elastic = m.elastic.scaled(p[0].exp(), p[1].exp());
    let k = p[2].exp();
    m.damping = match m.damping {
        DampingLaw::Linear { c } => DampingLaw::Linear { c: c * k },
        DampingLaw::Power {
            c,
            alpha,
            rate_ref,
            eps,
        } => DampingLaw::Power {
            c: c * k,
            alpha,
            rate_ref,
            eps,
        },
        DampingLaw::Drag { c, cq, p, cap } => DampingLaw::Drag {
            c: c * k,
            cq,
            p,
            cap,
        },
    };
    m
}

/// `Σ ((a − b − offset) / σ)²`, the offset the mean difference when
/// `offset`; infinite when the lengths differ.
fn chi2(a: &[f64], b: &[f64], sigma: f64, offset: bool) -> f64 {
    if a.len() != b.len() || a.is_empty() {
        return f64::INFINITY;
    }
    let off = if offset {
        a.iter().zip(b).map(|(x, y)| x - y).sum::<f64>() / a.len() as f64
    } else {
        0.0
    };
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y - off) / sigma).powi(2))
        .sum()
}

/// Nelder–Mead in `D` dimensions from `start` (a point and its value) with
/// first steps of 0.1, at most `runs` evaluations: the best point and its
/// value.
fn nelder_mead<const D: usize>(
    f: &mut dyn FnMut([f64; D]) -> f64,
    start: ([f64; D], f64),
    runs: usize,
) -> ([f64; D], f64) {
    let mut s: Vec<([f64; D], f64)> = vec![start];
    for i in 0..D {
        let mut p = start.0;
        p[i] += 0.1;
        s.push((p, f(p)));
    }
    let mut n = D;
    let lerp = |a: &[f64; D], b: &[f64; D], t: f64| -> [f64; D] {
        let mut q = *a;
        q.iter_mut().zip(b).for_each(|(x, y)| *x += t * (y - *x));
        q
    };
    while n < runs {
        s.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (s[D].1 - s[0].1).abs() < 1e-3 * (1.0 + s[0].1) {
            break;
        }
        let mut c = [0.0; D];
        for p in &s[..D] {
            c.iter_mut().zip(&p.0).for_each(|(x, y)| *x += y / D as f64);
        }
        let worst = s[D].0;
        let r = lerp(&c, &worst, -1.0);
        let fr = f(r);
        n += 1;
        if fr < s[0].1 {
            let e = lerp(&c, &worst, -2.0);
            let fe = f(e);
            n += 1;
            s[D] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < s[D - 1].1 {
            s[D] = (r, fr);
        } else {
            let k = lerp(&c, &worst, 0.5);
            let fk = f(k);
            n += 1;
            if fk < s[D].1 {
                s[D] = (k, fk);
            } else {
                let best = s[0].0;
                for v in s.iter_mut().skip(1) {
                    let p = lerp(&best, &v.0, 0.5);
                    *v = (p, f(p));
                    n += 1;
                }
            }
        }
    }
    s.sort_by(|a, b| a.1.total_cmp(&b.1));
    s[0]
}

/// [`nelder_mead`] restarted from its best point while a restart still
/// gains half a unit (at most three runs of `runs` evaluations).
fn minimise<const D: usize>(
    f: &mut dyn FnMut([f64; D]) -> f64,
    start: ([f64; D], f64),
    runs: usize,
) -> ([f64; D], f64) {
    let mut best = start;
    for _ in 0..3 {
        let next = nelder_mead(f, best, runs);
        let gained = best.1 - next.1;
        best = next;
        if gained < 0.5 {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::{chi2, minimise, nelder_mead};

    #[test]
    fn the_search_finds_a_shifted_bowl_to_a_tenth_of_a_unit() {
        // A χ²-like bowl: 1000 units per unit of log factor squared.
        let bowl = |p: [f64; 3]| {
            1000.0 * ((p[0] - 0.3).powi(2) + 2.0 * (p[1] + 0.2).powi(2) + (p[2] - 0.1).powi(2))
        };
        let mut f = bowl;
        let (p, v) = minimise(&mut f, ([0.0; 3], bowl([0.0; 3])), 60);
        assert!(v < 0.1, "{p:?} {v}");
        // Starting at the minimum it stays there.
        let (_, w) = nelder_mead(&mut f, ([0.3, -0.2, 0.1], 0.0), 60);
        assert_eq!(w, 0.0);
    }

    #[test]
    fn chi2_takes_the_offset_out_only_when_asked() {
        let a = [1.0, 2.0, 3.0];
        let b = [0.0, 1.0, 2.0];
        assert_eq!(chi2(&a, &b, 0.5, true), 0.0);
        assert_eq!(chi2(&a, &b, 0.5, false), 12.0);
        assert!(chi2(&a, &b[..2], 1.0, false).is_infinite());
    }
}
