//! Period and logarithmic decrement of A's oscillation.
//!
//! Following the paper (eq. 4, `Λ = ln(A_n / A_{n+1})`) and what an
//! independent simulation found robust: take the **first two maxima** of A's
//! height after the roller is released (the minima are disturbed when the
//! top run touches the bottom run), measure their amplitudes about the
//! **settled** height, and their time difference as the period. Each maximum
//! is located between samples by a parabola through three samples.
//!
//! ```
//! use trackbelt::figures::{PeakTracker, period_and_decrement};
//! let (t_true, lam) = (0.75_f64, 0.7_f64);
//! let mut p = PeakTracker::new();
//! for i in 0..4000 {
//!     let t = i as f64 * 1e-3;
//!     let y = 0.225 + 0.1 * (-lam / t_true * t).exp() * (core::f64::consts::TAU * t / t_true).cos();
//!     p.push(t, y);
//! }
//! let (t, l) = period_and_decrement(p.maxima(), 0.225).unwrap();
//! assert!((t - t_true).abs() < 1e-4 && (l - lam).abs() < 1e-3);
//! ```

use heapless::Vec;

/// Most extrema a tracker keeps.
pub const MAX_EXTREMA: usize = 16;

/// A located extremum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extremum {
    /// Time, s.
    pub time_s: f64,
    /// Value (unit of the signal).
    pub value: f64,
}

/// Streaming detector of local maxima and minima (fixed memory).
///
/// Maxima are recorded only after the first minimum, so the resting value
/// at the start (the roller is put on at rest) is not counted.
#[derive(Debug, Clone, Default)]
pub struct PeakTracker {
    window: [(f64, f64); 3],
    count: usize,
    maxima: Vec<Extremum, MAX_EXTREMA>,
    minima: Vec<Extremum, MAX_EXTREMA>,
}

impl PeakTracker {
    /// Empty tracker.
    pub fn new() -> Self {
        Self::default()
    }

    /// Feed one sample (times strictly increasing; others are ignored, as
    /// are non-finite samples).
    pub fn push(&mut self, t: f64, y: f64) {
        if !t.is_finite() || !y.is_finite() {
            return;
        }
        if self.count > 0 && t <= self.window[2].0 {
            return;
        }
        self.window = [self.window[1], self.window[2], (t, y)];
        self.count += 1;
        if self.count < 3 {
            return;
        }
        let [(_, y0), (_, y1), (_, y2)] = self.window;
        if y1 > y0 && y1 >= y2 && !self.minima.is_empty() {
            let e = vertex(self.window);
            let _ = self.maxima.push(e);
        } else if y1 < y0 && y1 <= y2 {
            let e = vertex(self.window);
            let _ = self.minima.push(e);
        }
    }

    /// Maxima found so far (after the first minimum).
    pub fn maxima(&self) -> &[Extremum] {
        &self.maxima
    }

    /// Minima found so far.
    pub fn minima(&self) -> &[Extremum] {
        &self.minima
    }
}

/// Vertex of the parabola through three samples `(time, value)` (clamped
/// to their span; the middle sample when the three are collinear): the one
/// peak finder of the project, used by the bench figures here and by the
/// host's measured-series figures and per-cycle extrema.
///
/// ```
/// use trackbelt::figures::vertex;
/// let f = |t: f64| 2.0 - 3.0 * (t - 0.12) * (t - 0.12);
/// let e = vertex([(0.0, f(0.0)), (0.1, f(0.1)), (0.25, f(0.25))]);
/// assert!((e.time_s - 0.12).abs() < 1e-12 && (e.value - 2.0).abs() < 1e-12);
/// ```
pub fn vertex(w: [(f64, f64); 3]) -> Extremum {
    let [(t0, y0), (t1, y1), (t2, y2)] = w;
    let d0 = t0 - t1;
    let d2 = t2 - t1;
    let s0 = (y0 - y1) / d0;
    let s2 = (y2 - y1) / d2;
    let a = (s0 - s2) / (d0 - d2);
    let b = s0 - a * d0;
    // Times out of order (or NaN), where `clamp` would
    // panic; the middle sample then, as for a flat window.
    if a == 0.0 || !a.is_finite() || !b.is_finite() || d0.is_nan() || d2.is_nan() || d0 > d2 {
        return Extremum {
            time_s: t1,
            value: y1,
        };
    }
    let tau = (-b / (2.0 * a)).clamp(d0, d2);
    Extremum {
        time_s: t1 + tau,
        value: y1 + b * tau + a * tau * tau,
    }
}

/// `(T, Λ)` from the first two maxima about the settled value; `None` when
/// there are fewer than two maxima, they do not decay, or a figure would
/// not be finite (e.g. an infinite settled value or excursion).
pub fn period_and_decrement(maxima: &[Extremum], settled: f64) -> Option<(f64, f64)> {
    if maxima.len() < 2 {
        return None;
    }
    let (a, b) = (maxima[0], maxima[1]);
    let (ha, hb) = (a.value - settled, b.value - settled);
    if !(ha > 0.0 && hb > 0.0) {
        return None;
    }
    let (period, decrement) = (b.time_s - a.time_s, libm::log(ha / hb));
    (period.is_finite() && decrement.is_finite()).then_some((period, decrement))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(t: f64, period: f64, lam: f64) -> f64 {
        0.2 - 0.1 * libm::exp(-lam / period * t) * libm::cos(core::f64::consts::TAU * t / period)
    }

    #[test]
    fn recovers_known_period_and_decrement_on_a_coarse_grid() {
        // 25 Hz, like the camera.
        for &(period, lam) in &[(0.74, 0.73), (1.5, 0.69), (0.8, 0.3)] {
            let mut p = PeakTracker::new();
            for i in 0..200 {
                let t = i as f64 / 25.0 + 0.013;
                p.push(t, signal(t, period, lam));
            }
            let (tt, ll) = period_and_decrement(p.maxima(), 0.2).unwrap();
            assert!((tt - period).abs() < 0.01 * period, "T {tt} vs {period}");
            assert!((ll - lam).abs() < 0.03, "Λ {ll} vs {lam}");
        }
    }

    #[test]
    fn start_at_rest_is_not_a_maximum() {
        let mut p = PeakTracker::new();
        for i in 0..3000 {
            let t = i as f64 * 1e-3;
            // Starts at a maximum, at rest: falls first, like A.
            p.push(t, 0.4 - signal(t, 0.75, 0.7));
        }
        assert!(p.maxima()[0].time_s > 0.7);
        assert!(p.minima()[0].time_s < 0.4);
    }

    #[test]
    fn overdamped_signal_has_no_figures() {
        let mut p = PeakTracker::new();
        for i in 0..1000 {
            let t = i as f64 * 1e-3;
            p.push(t, 0.2 + 0.1 * libm::exp(-5.0 * t));
        }
        assert!(period_and_decrement(p.maxima(), 0.2).is_none());
    }

    #[test]
    fn ignores_non_finite_and_repeated_times() {
        let mut p = PeakTracker::new();
        p.push(0.0, 1.0);
        p.push(0.0, 5.0);
        p.push(f64::NAN, 1.0);
        p.push(0.1, f64::INFINITY);
        assert!(p.maxima().is_empty());
    }
}
