//! The bench figures as one record: [`Six`] (Hs, Ws, Hd, Wd, T, Λ; each
//! optional), used for calibration targets and fits, relative errors and
//! the paper's rows, and [`Figures`] (the six with the joint-angle ranges,
//! the paper's reference). A simulation's own JSON record is
//! [`crate::sim::SimOutput`]; [`Six::of`] reads the six from it.

use crate::sim::SimOutput;
use serde::Serialize;
use trackbelt::params::paper;

/// Names of the six figures, in [`Six::to_array`] order.
pub const FIGURE_NAMES: [&str; 6] = ["Hs", "Ws", "Hd", "Wd", "T", "Λ"];

/// One value per bench figure (Hs, Ws, Hd, Wd, T, Λ), serialised under
/// the figures' names: the figures themselves ([`Six`]) or a statistic of
/// each (e.g. the calibration's spread over repeat runs).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Default)]
pub struct PerFigure<T> {
    /// Static height of A, mm.
    pub hs_mm: T,
    /// Static width, mm.
    pub ws_mm: T,
    /// Loaded settled height of A, mm.
    pub hd_mm: T,
    /// Loaded settled width, mm.
    pub wd_mm: T,
    /// Period of A, s.
    pub period_s: T,
    /// Logarithmic decrement.
    pub log_decrement: T,
}

impl<T> PerFigure<T> {
    /// Each figure's value from its index in [`FIGURE_NAMES`] order.
    pub fn from_fn(mut f: impl FnMut(usize) -> T) -> Self {
        PerFigure {
            hs_mm: f(0),
            ws_mm: f(1),
            hd_mm: f(2),
            wd_mm: f(3),
            period_s: f(4),
            log_decrement: f(5),
        }
    }
}

/// Six bench figures; `None` where absent.
pub type Six = PerFigure<Option<f64>>;

impl Six {
    /// As an array in [`FIGURE_NAMES`] order.
    pub fn to_array(&self) -> [Option<f64>; 6] {
        [
            self.hs_mm,
            self.ws_mm,
            self.hd_mm,
            self.wd_mm,
            self.period_s,
            self.log_decrement,
        ]
    }

    /// From an array in [`FIGURE_NAMES`] order.
    pub fn from_array(a: [Option<f64>; 6]) -> Six {
        Six {
            hs_mm: a[0],
            ws_mm: a[1],
            hd_mm: a[2],
            wd_mm: a[3],
            period_s: a[4],
            log_decrement: a[5],
        }
    }

    /// The figures of a simulation.
    pub fn of(o: &SimOutput) -> Six {
        Six {
            hs_mm: Some(o.hs_mm),
            ws_mm: Some(o.ws_mm),
            hd_mm: o.hd_mm,
            wd_mm: o.wd_mm,
            period_s: o.period_s,
            log_decrement: o.log_decrement,
        }
    }

    /// Relative errors of `self` against `target`, percent.
    pub fn rel_err_pct(&self, target: &Six) -> Six {
        let mut out = [None; 6];
        for (i, (o, t)) in self.to_array().iter().zip(target.to_array()).enumerate() {
            if let (Some(o), Some(t)) = (o, t) {
                if t != 0.0 {
                    out[i] = Some(100.0 * (o - t) / t);
                }
            }
        }
        Six::from_array(out)
    }

    /// Largest |relative error| against `target` over the figures `target`
    /// has, percent; infinite if the model lacks one of them.
    pub fn max_abs_rel_err_pct(&self, target: &Six) -> f64 {
        let e = self.rel_err_pct(target).to_array();
        let mut m: f64 = 0.0;
        for (i, t) in target.to_array().iter().enumerate() {
            if t.is_some() {
                m = m.max(e[i].map_or(f64::INFINITY, f64::abs));
            }
        }
        m
    }
}

/// The six figures with the joint-angle ranges at A and C: the paper's
/// reference figures in the JSON layout of `paper --json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Figures {
    /// The six figures (serialised in place).
    #[serde(flatten)]
    pub six: Six,
    /// degrees.
    pub angle_a_deg: Option<[f64; 2]>,
    /// degrees.
    pub angle_c_deg: Option<[f64; 2]>,
}

impl Figures {
    /// The paper's figures (the core's table record); NaN angle ranges
    /// become `None`.
    pub fn from_paper(f: &paper::Figures) -> Self {
        let ang = |a: [f64; 2]| if a[0].is_nan() { None } else { Some(a) };
        Figures {
            six: Six {
                hs_mm: Some(f.hs_mm),
                ws_mm: Some(f.ws_mm),
                hd_mm: Some(f.hd_mm),
                wd_mm: Some(f.wd_mm),
                period_s: Some(f.period_s),
                log_decrement: Some(f.log_decrement),
            },
            angle_a_deg: ang(f.angle_a_deg),
            angle_c_deg: ang(f.angle_c_deg),
        }
    }
}
