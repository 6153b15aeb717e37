//! A model refitted with a slow mean beside it
//! (`diagnose_dynamic::fit_with_slow_mean`), the rival a law with a memory
//! must beat before its moving mean counts as evidence
//! (`diagnose_dynamic::mean_rival`). A drop series of the baseline's own
//! belt, with 1 mm of marker noise, is given a camera that drifts and a
//! marker that slips: the refit must take both out to the noise, and on
//! the clean series the three extra parameters must cost more BIC than
//! they gain.

use trackbelt::params::Variant;
use trackbelt_host::diagnose::baseline;
use trackbelt_host::diagnose_dynamic::{fit_dynamic, fit_with_slow_mean};
use trackbelt_host::evidence::bic_gain;
use trackbelt_host::synth::DynamicSynth;
use trackbelt_host::NoProgress;

const DRIFT_MM_PER_S: f64 = -0.4;
const STEP_AT_S: f64 = 2.5;
const STEP_MM: f64 = -1.5;

#[test]
fn a_refit_with_a_slow_mean_takes_out_a_drift_and_a_step_and_costs_on_a_clean_series() {
    let base = baseline(Variant::E38, None).unwrap();
    let synth = DynamicSynth::new(&base, 18);
    let noise = synth.noise_mm;
    let (t, clean) = synth.sample().unwrap();
    let disturbed: Vec<f64> = t
        .iter()
        .zip(&clean)
        .map(|(&s, &h)| h + DRIFT_MM_PER_S * s + if s >= STEP_AT_S { STEP_MM } else { 0.0 })
        .collect();
    let fit = |h: &[f64]| {
        let b = fit_dynamic(
            &base,
            synth.roller_kg,
            &t,
            h,
            None,
            &[0.0, 0.0],
            false,
            &NoProgress,
        )
        .unwrap();
        let g =
            fit_with_slow_mean(&base, synth.roller_kg, &t, h, &b, STEP_AT_S, &NoProgress).unwrap();
        (b, g)
    };

    let (b, g) = fit(&disturbed);
    assert!(
        b.rms > 1.3 * noise,
        "the baseline alone should not reach the noise: {:.3} mm",
        b.rms
    );
    assert!(
        g.rms <= 1.15 * noise,
        "with the slow mean it should: {:.3} mm (noise {noise} mm)",
        g.rms
    );
    assert_eq!(g.k, b.k + 3, "slope, step and its time are counted");
    assert_eq!(g.model, b.model);
    // The fitted mean carries the drift and the step: over the record the
    // model's values move by about the disturbance's whole change.
    let moved = |f: &trackbelt_host::evidence::Fitted| {
        let n = f.model_values.len();
        let head: f64 = f.model_values[..n / 10].iter().sum::<f64>() / (n / 10) as f64;
        let tail: f64 = f.model_values[n - n / 10..].iter().sum::<f64>() / (n / 10) as f64;
        tail - head
    };
    let expected = DRIFT_MM_PER_S * 0.9 * t[t.len() - 1] + STEP_MM;
    assert!(
        (moved(&g) - moved(&b) - expected).abs() < 0.8,
        "the slow mean moved the model by {:.2} mm against {expected:.2} mm",
        moved(&g) - moved(&b)
    );

    let (b, g) = fit(&clean);
    let gain = bic_gain(&b, &g, b.residual.len() as f64);
    assert!(
        gain < 0.0,
        "on a clean series the slow mean must not pay for its three parameters: BIC gain {gain:.1}"
    );
}
