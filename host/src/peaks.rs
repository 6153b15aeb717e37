//! The one parabola peak finder of the host: an extremum of sampled data
//! located between samples by the parabola through three of them (the
//! same construction as the core's `trackbelt::figures` tracker, for
//! irregular sample times). Used to read T and Λ from a measured series
//! (calibration) and the per-cycle extrema (diagnosis).

/// Vertex `(t, y)` of the parabola through the samples `k − 1`, `k`,
/// `k + 1` of `(t, y)`, clamped to their span; the sample itself at the
/// ends of the data or when the three points are collinear (or not
/// finite).
pub fn parabola_vertex(t: &[f64], y: &[f64], k: usize) -> (f64, f64) {
    if k == 0 || k + 1 >= t.len() || k + 1 >= y.len() {
        return (t[k], y[k]);
    }
    let (d0, d2) = (t[k - 1] - t[k], t[k + 1] - t[k]);
    let s0 = (y[k - 1] - y[k]) / d0;
    let s2 = (y[k + 1] - y[k]) / d2;
    let a = (s0 - s2) / (d0 - d2);
    let b = s0 - a * d0;
    if a == 0.0 || !a.is_finite() || !b.is_finite() {
        return (t[k], y[k]);
    }
    let tau = (-b / (2.0 * a)).clamp(d0, d2);
    (t[k] + tau, y[k] + b * tau + a * tau * tau)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_vertex_of_a_sampled_parabola() {
        let t = [0.0, 0.1, 0.25];
        let y: Vec<f64> = t
            .iter()
            .map(|x| 2.0 - 3.0 * (x - 0.12f64).powi(2))
            .collect();
        let (tv, yv) = parabola_vertex(&t, &y, 1);
        assert!((tv - 0.12).abs() < 1e-12 && (yv - 2.0).abs() < 1e-12);
        assert_eq!(parabola_vertex(&t, &y, 0), (0.0, y[0]));
        let flat = [1.0, 1.0, 1.0];
        assert_eq!(parabola_vertex(&t, &flat, 1), (0.1, 1.0));
    }
}
