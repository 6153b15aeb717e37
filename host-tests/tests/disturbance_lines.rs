//! The dynamic diagnosis's test for an oscillation that is not the belt's
//! (`diagnose_dynamic::disturbance`), on residuals built by hand: the flank
//! of the belt's own decaying line is not a disturbance, a shaking camera
//! is.

use trackbelt_host::diagnose_dynamic::disturbance;

/// 8 s at 30 Hz.
fn times() -> Vec<f64> {
    (0..240).map(|i| i as f64 / 30.0).collect()
}

/// What shape mismatch leaves: the belt's own swing, decaying (log
/// decrement 0.6 a cycle) while its frequency rises 1.20 → 1.35 Hz as the
/// amplitude falls, as the held-out truths' drops do.
fn own_swing(t: f64) -> f64 {
    let phase = std::f64::consts::TAU * (1.20 * t + 0.5 * 0.15 * t * t / 8.0);
    3.0 * (-0.6 * 1.27 * t).exp() * phase.sin()
}

#[test]
fn the_flank_of_the_belts_own_line_is_not_a_disturbance() {
    let t = times();
    let r: Vec<f64> = t.iter().map(|&t| own_swing(t)).collect();
    let model = vec![0.0; t.len()];
    let found = disturbance(&t, &r, &model, 0.3, 1.0 / 1.27);
    assert!(found.is_none(), "{found:?}");
}

#[test]
fn a_shaking_camera_is_a_disturbance() {
    let t = times();
    let r: Vec<f64> = t
        .iter()
        .map(|&t| own_swing(t) + 0.6 * (std::f64::consts::TAU * 4.3 * t).sin())
        .collect();
    // The model's swing carries no line at 4.3 Hz (near the belt's 3rd
    // harmonic, where only a line the model has counts as the belt's).
    let model: Vec<f64> = t.iter().map(|&t| 20.0 * own_swing(t)).collect();
    let found = disturbance(&t, &r, &model, 0.3, 1.0 / 1.27).expect("the 4.3 Hz line");
    assert!(found.contains("4.3"), "{found}");
}
