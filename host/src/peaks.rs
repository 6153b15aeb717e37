//! The one parabola peak finder of the host: an extremum of sampled data
//! located between samples by the parabola through three of them (the
//! core's [`trackbelt::figures::vertex`], addressed by sample index). Used to read T and Λ from a measured series
//! (calibration) and the per-cycle extrema (diagnosis).

/// Vertex `(t, y)` of the parabola through the samples `k − 1`, `k`,
/// `k + 1` of `(t, y)`, clamped to their span; the sample itself at the
/// ends of the data or when the three points are collinear (or not
/// finite).
pub fn parabola_vertex(t: &[f64], y: &[f64], k: usize) -> (f64, f64) {
    if k == 0 || k + 1 >= t.len() || k + 1 >= y.len() {
        return (t[k], y[k]);
    }
    let e = trackbelt::figures::vertex([(t[k - 1], y[k - 1]), (t[k], y[k]), (t[k + 1], y[k + 1])]);
    (e.time_s, e.value)
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
