//! The joint laws with a memory (`trackbelt::memory`: Dahl friction, Payne
//! softening) in the dynamic test, checked against physics rather than
//! against themselves:
//!
//! * **off is the baseline**: at zero size each gives the baseline's trace
//!   bit for bit;
//! * **dissipation**: friction takes energy out (the drop decays faster),
//!   and every run passes the validity checks (energy balance included);
//! * **statics**: the static test does not see either;
//! * **the Coulomb limit**: over a prescribed steady cycle of the joint,
//!   Dahl friction dissipates its closed-form loop energy, which tends to
//!   Coulomb's `4·Mc·A` as the pre-sliding angle goes to zero, and so does
//!   the smoothed Coulomb law (`effects::JointFriction`) as its smoothing
//!   speed does (the law level: over the chaotic drop the limit is not
//!   monotone, see the README);
//! * **the Payne signature**: softening makes the period fall as the swing
//!   decays (the belt stiffens back), hardening makes it grow, each well
//!   beyond the baseline's own drift; and the arm vanishes as its
//!   relaxation time goes to zero (the mean follows the angle).

use trackbelt::joint::JointLaw;
use trackbelt::memory::{DahlFriction, PayneSoftening};
use trackbelt::params::{Belt, Method, Model, Variant};
use trackbelt::{bench, ReferenceChain, Settings};
use trackbelt_host::forward::simulate_height_checked;

fn law() -> JointLaw<f64> {
    trackbelt_host::paper::law_for(Variant::E38, Method::I).unwrap()
}

fn belt() -> Belt<f64> {
    Model::paper(Variant::E38, Method::I).unwrap().belt
}

/// The baseline law with both memory laws on.
fn with_both(dahl: DahlFriction<f64>, payne: PayneSoftening<f64>) -> JointLaw<f64> {
    let mut l = law();
    l.effects.dahl_friction = Some(dahl);
    l.effects.payne_softening = Some(payne);
    l
}

/// A's height over 8 s of the dynamic test (the paper's 1.3 kg roller), mm.
fn trace(l: &JointLaw<f64>) -> Vec<(f64, f64)> {
    let (t, warnings) = simulate_height_checked(l, &belt(), 1.3, 8.0).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    t
}

/// Height minus the settled height at the last sample.
fn swing(t: &[(f64, f64)]) -> Vec<f64> {
    let end = t.last().unwrap().1;
    t.iter().map(|p| p.1 - end).collect()
}

#[test]
fn off_is_the_baseline_bit_for_bit() {
    let base = trace(&law());
    let l = with_both(
        DahlFriction {
            torque_nm: 0.0,
            presliding_rad: 0.005,
        },
        PayneSoftening {
            depth: 0.0,
            amplitude_rad: 0.03,
            memory_s: 0.5,
            mean_s: 1.2,
        },
    );
    assert_eq!(trace(&l), base);
}

#[test]
fn dahl_friction_takes_energy_out() {
    let base = swing(&trace(&law()));
    let mut d = law();
    d.effects.dahl_friction = Some(DahlFriction {
        torque_nm: 0.02,
        presliding_rad: 0.005,
    });
    let with = swing(&trace(&d));
    // The late swing (the second half of the run) is smaller with friction.
    let late = |s: &[f64]| s[s.len() / 2..].iter().map(|x| x * x).sum::<f64>();
    assert!(
        late(&with) < 0.7 * late(&base),
        "{} {}",
        late(&with),
        late(&base)
    );
}

#[test]
fn the_static_test_does_not_see_the_memory_laws() {
    let figures = |l: JointLaw<f64>| {
        let model = Model::new(belt(), l).unwrap();
        let mut c = Box::new(ReferenceChain::new(model, Settings::default()).unwrap());
        bench::static_test(&mut *c).unwrap()
    };
    let l = with_both(
        DahlFriction {
            torque_nm: 0.05,
            presliding_rad: 0.002,
        },
        PayneSoftening {
            depth: 0.5,
            amplitude_rad: 0.01,
            memory_s: 0.3,
            mean_s: 1.5,
        },
    );
    // The relaxation before the static polish runs the dynamics (the memory
    // laws act there), so the equilibrium is the same to the solver's
    // tolerance, not bit for bit.
    let (a, b) = (figures(law()), figures(l));
    assert!((a.hs_mm - b.hs_mm).abs() < 1e-6, "{a:?} {b:?}");
    assert!((a.ws_mm - b.ws_mm).abs() < 1e-6, "{a:?} {b:?}");
}

#[test]
fn the_bushing_chain_refuses_the_memory_laws() {
    let mut l = law();
    l.effects.dahl_friction = Some(DahlFriction {
        torque_nm: 0.02,
        presliding_rad: 0.005,
    });
    let model = Model::new(belt(), l).unwrap();
    // The bushing chain is large: build it on a thread with room for it.
    let msg = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || {
            trackbelt::ReferenceBushingChain::new(
                model,
                trackbelt::Bushing::paper(),
                Settings::default(),
            )
            .err()
            .map(|e| e.to_string())
        })
        .unwrap()
        .join()
        .unwrap();
    let e = msg.expect("the bushing chain took a memory law");
    assert!(e.contains("pin chain"), "{e}");
}

/// The baseline law with a Payne law of `depth` (a_c 0.01 rad, memory
/// 0.5 s) relaxing over `mean_s`.
fn payne(depth: f64, mean_s: f64) -> JointLaw<f64> {
    let mut l = law();
    l.effects.payne_softening = Some(PayneSoftening {
        depth,
        amplitude_rad: 0.01,
        memory_s: 0.5,
        mean_s,
    });
    l
}

/// Times between successive maxima of A's height after the first 0.5 s, s.
fn peak_intervals(t: &[(f64, f64)]) -> Vec<f64> {
    let peaks: Vec<f64> = t
        .windows(3)
        .filter(|w| w[1].0 > 0.5 && w[1].1 > w[0].1 && w[1].1 >= w[2].1)
        .map(|w| w[1].0)
        .collect();
    peaks.windows(2).map(|p| p[1] - p[0]).collect()
}

/// The change of the peak interval from the first to the last, s.
fn period_drift_s(l: &JointLaw<f64>) -> f64 {
    let iv = peak_intervals(&trace(l));
    assert!(iv.len() >= 3, "{iv:?}");
    iv[iv.len() - 1] - iv[0]
}

#[test]
fn payne_softening_shortens_the_period_as_the_swing_decays() {
    let base = period_drift_s(&law());
    let soft = period_drift_s(&payne(0.5, 1.2));
    let hard = period_drift_s(&payne(-0.3, 1.2));
    // The baseline's own drift is −0.02 s; softening −0.32 s, hardening
    // +0.10 s (measured when this test was written).
    assert!(soft < base - 0.1, "softening {soft} baseline {base}");
    assert!(hard > base + 0.05, "hardening {hard} baseline {base}");
}

#[test]
fn the_payne_arm_vanishes_as_its_relaxation_time_goes_to_zero() {
    let base = trace(&law());
    let gap = |mean_s: f64| {
        trace(&payne(0.5, mean_s))
            .iter()
            .zip(&base)
            .filter(|(p, _)| p.0 <= 2.0)
            .map(|(p, b)| (p.1 - b.1).abs())
            .fold(0.0, f64::max)
    };
    // Measured 38, 14 and 2.4 mm. The limit is the time step's, not zero:
    // a mean that catches up within a step still lags by one step.
    let gaps = [gap(0.1), gap(0.01), gap(0.001)];
    assert!(
        gaps[1] < gaps[0] && gaps[2] < gaps[1] && gaps[2] < 0.1 * gaps[0],
        "largest gaps over 2 s, mm: {gaps:?}"
    );
}

/// Energy (J) one steady cycle `ζ = A·sin(2π·t)` takes out through a
/// friction moment that `step` advances over each travel: `(moment before,
/// Δζ, time) → moment after`, the moment acting against the travel.
/// 20 000 steps a cycle, the third of three cycles measured.
fn loop_energy(a: f64, mut step: impl FnMut(f64, f64, f64) -> f64) -> f64 {
    let n = 20_000;
    let (mut m, mut w) = (0.0, 0.0);
    for i in 0..3 * n {
        let (t0, t1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
        let dz = a * ((std::f64::consts::TAU * t1).sin() - (std::f64::consts::TAU * t0).sin());
        let m1 = step(m, dz, 0.5 * (t0 + t1));
        if i >= 2 * n {
            w += 0.5 * (m + m1) * dz;
        }
        m = m1;
    }
    w
}

#[test]
fn dahl_and_smoothed_coulomb_tend_to_the_coulomb_loop() {
    use trackbelt::effects::{Effects, JointFriction};
    use trackbelt::stiffness::JointMoment;
    let (mc, a) = (0.03, 0.02);
    let coulomb = 4.0 * mc * a;
    // Dahl: the steady loop in closed form. On the rising branch from −A
    // with moment −m₀, m(ζ) = Mc − (Mc + m₀)·e^(−(ζ + A)/ζs); the loop
    // closes when m₀ = Mc·(1 − e)/(1 + e), e = e^(−2A/ζs), and takes out
    // W = 4·A·Mc − 2·(Mc + m₀)·ζs·(1 − e).
    let mut last_gap = f64::INFINITY;
    for ratio in [0.3, 0.1, 0.03, 0.01, 0.003] {
        let zs = ratio * a;
        let d = DahlFriction {
            torque_nm: mc,
            presliding_rad: zs,
        };
        let w = loop_energy(a, |m, dz, _| d.advance(m, dz).0);
        let e = (-2.0 * a / zs).exp();
        let m0 = mc * (1.0 - e) / (1.0 + e);
        let exact = 4.0 * a * mc - 2.0 * (mc + m0) * zs * (1.0 - e);
        assert!(
            (w - exact).abs() < 1e-6 * coulomb,
            "ζs = {zs}: loop {w:.6e} J, closed form {exact:.6e} J"
        );
        let gap = (coulomb - w) / coulomb;
        // The gap is about ζs/A, and shrinks with it.
        assert!(gap > 0.0 && gap < last_gap, "ζs = {zs}: gap {gap:.4}");
        assert!((gap / ratio - 1.0).abs() < 0.15, "ζs = {zs}: gap {gap:.4}");
        last_gap = gap;
    }
    assert!(last_gap < 0.005, "{last_gap}");
    // The smoothed Coulomb law at rate ζ̇ = 2π·A·cos(2π·t).
    let mut last_gap = f64::INFINITY;
    for eps in [0.1, 0.03, 0.01, 0.003, 0.001] {
        let fx = Effects {
            joint_friction: Some(JointFriction {
                torque_nm: mc,
                smoothing_rad_s: eps,
            }),
            ..Effects::none()
        };
        let w = loop_energy(a, |_, _, t| {
            let rate = std::f64::consts::TAU * a * (std::f64::consts::TAU * t).cos();
            let zero = JointMoment {
                moment_nm: 0.0,
                stiffness: 0.0,
                damping: 0.0,
            };
            -fx.apply(0.0, rate, zero).moment_nm
        });
        let gap = (coulomb - w) / coulomb;
        assert!(gap > 0.0 && gap < last_gap, "ε = {eps}: gap {gap:.5}");
        last_gap = gap;
    }
    assert!(last_gap < 0.005, "{last_gap}");
}
