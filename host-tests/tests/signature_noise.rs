//! The per-cycle trends of a model trace are read under the series' noise
//! (`diagnose_dynamic::model_signature`): against them, marker noise alone
//! does not make a quadratic-damping signature, as it did against the
//! noise-free trend.

use trackbelt_host::diagnose_dynamic::{model_signature, signature, Cycle};
use trackbelt_host::synth::Rng;

/// A swing whose log decrement (0.5 a cycle) does not depend on the
/// amplitude: 37 mm falling to 2 mm over 8 s, period 0.8 s.
fn swing(t: &[f64]) -> Vec<f64> {
    t.iter()
        .map(|&t| 37.0 * (-0.5 * t / 0.8).exp() * (std::f64::consts::TAU * t / 0.8).cos())
        .collect()
}

fn decrement(c: &Cycle) -> f64 {
    c.log_decrement
}

#[test]
fn noise_alone_makes_no_decrement_trend_against_the_model_read_under_noise() {
    for (rate, sd) in [(25.0, 0.8), (50.0, 1.2)] {
        let t: Vec<f64> = (0..(8.0 * rate) as usize)
            .map(|i| i as f64 / rate)
            .collect();
        let model = swing(&t);
        let min_amp = (4.0f64 * sd).max(1.0);
        let plain = signature(&t, &model, 0.0, min_amp)
            .trend(decrement)
            .unwrap()
            .0;
        let noisy = model_signature(&t, &model, 0.0, min_amp, sd)
            .trend(decrement)
            .unwrap()
            .0;
        let (mut z_plain, mut z_noisy, mut n) = (0.0, 0.0, 0.0);
        // Measurements: the same swing under other noise than the model's
        // realisations.
        for seed in 0..60u64 {
            let mut rng = Rng::new(1000 + seed);
            let h: Vec<f64> = model.iter().map(|x| x + sd * rng.normal()).collect();
            let Some((b, se)) = signature(&t, &h, 0.0, min_amp).trend(decrement) else {
                continue;
            };
            z_plain += (b - plain) / se;
            z_noisy += (b - noisy) / se;
            n += 1.0;
        }
        assert!(n >= 50.0, "{rate} Hz, {sd} mm: only {n} readable");
        let (z_plain, z_noisy) = (z_plain / n, z_noisy / n);
        eprintln!("{rate} Hz, {sd} mm: mean z {z_plain:+.2} against the noise-free trend, {z_noisy:+.2} against the one under noise ({n} series)");
        // Against the noise-free trend the noise reads as a signature …
        assert!(z_plain > 0.6, "{rate} Hz, {sd} mm: {z_plain:+.2}");
        // … against the trend read under noise it does not.
        assert!(z_noisy.abs() < 0.35, "{rate} Hz, {sd} mm: {z_noisy:+.2}");
    }
}
