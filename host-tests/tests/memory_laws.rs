//! The joint laws with a memory (`trackbelt::memory`: Dahl friction, Payne
//! softening) in the dynamic test, checked against physics rather than
//! against themselves:
//!
//! * **off is the baseline**: at zero size each gives the baseline's trace
//!   bit for bit;
//! * **dissipation**: friction takes energy out (the drop decays faster),
//!   and every run passes the validity checks (energy balance included);
//! * **statics**: the static test does not see either.

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
