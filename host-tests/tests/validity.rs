//! No silent garbage from the bench simulations (static and dynamic tests):
//! every check of `trackbelt_host::validity` passes on the paper's nine runs
//! with no warning, and each can fail: provoked, it gives a typed error
//! naming the check and the value, or a warning beside the figures, never a
//! plain figure.

use trackbelt::bench::{self, DynamicTest};
use trackbelt::params::{Method, Variant};
use trackbelt::{ReferenceChain, Settings};
use trackbelt_host::error::Error;
use trackbelt_host::sim::{model_for, simulate, SimOutput, SimTrace, Tests};
use trackbelt_host::validity::{self, BenchValidity, Monitor};

type Run = trackbelt_host::error::Result<(SimOutput, SimTrace)>;

fn run(tests: Tests, settings: Settings<f64>, dynamic: DynamicTest<f64>) -> Run {
    let (v, m) = (Variant::E38, Method::I);
    let law = trackbelt_host::paper::law_for(v, m).unwrap();
    simulate(
        model_for(v.links(), law).unwrap(),
        m,
        tests,
        settings,
        dynamic,
    )
}

/// The failed check's name, or a panic naming what came out instead.
fn failed_check(r: Run) -> &'static str {
    match r {
        Err(Error::SimInvalid { check, value, .. }) => {
            assert!(!value.is_nan() || check.contains("energy"), "{check}");
            check
        }
        Err(e) => panic!("expected SimInvalid, got the error {e}"),
        Ok((o, _)) => panic!("expected SimInvalid, got figures {o:?}"),
    }
}

fn loose_newton(position_tol_m: f64) -> Settings<f64> {
    Settings {
        position_tol_m,
        angle_tol_rad: position_tol_m * 10.0,
        ..Settings::default()
    }
}

#[test]
fn the_paper_runs_pass_every_check_without_warnings() {
    let runs =
        trackbelt_host::paper::run_methods(&Method::ALL, 2, &trackbelt_host::progress::NoProgress)
            .unwrap();
    assert_eq!(runs.len(), 9);
    let mut worst = BenchValidity::default();
    let max = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    };
    for r in &runs {
        let v = r.trace.validity;
        assert!(
            r.out.warnings.is_empty(),
            "{} {}: {:?}",
            r.variant.name(),
            r.method.name(),
            r.out.warnings
        );
        // Every check ran.
        for x in [
            v.static_imbalance,
            v.loaded_imbalance,
            v.energy_gain,
            v.damping_work_j,
            v.closure_m,
            v.closure_rate,
            v.settle_ratio,
            v.steps_per_period,
            v.rejected_per_step,
        ] {
            assert!(x.is_some_and(f64::is_finite), "{v:?}");
        }
        worst.static_imbalance = max(worst.static_imbalance, v.static_imbalance);
        worst.loaded_imbalance = max(worst.loaded_imbalance, v.loaded_imbalance);
        worst.energy_gain = max(worst.energy_gain, v.energy_gain);
        worst.closure_m = max(worst.closure_m, v.closure_m);
        worst.closure_rate = max(worst.closure_rate, v.closure_rate);
        worst.settle_ratio = max(worst.settle_ratio, v.settle_ratio);
        worst.rejected_per_step = max(worst.rejected_per_step, v.rejected_per_step);
        let fewest = worst.steps_per_period.unwrap_or(f64::INFINITY);
        worst.steps_per_period = Some(fewest.min(v.steps_per_period.unwrap()));
        // The joint damping dissipates most of what the drop releases, and
        // never more.
        let (w, e) = (v.damping_work_j.unwrap(), v.energy_released_j.unwrap());
        assert!(w > 0.9 * e && w <= e, "{v:?}");
    }
    println!("worst over the nine paper runs: {worst:?}");
    // The margins the README states.
    let w = worst;
    assert!(w.static_imbalance.unwrap() < 1e-10 && w.loaded_imbalance.unwrap() < 1e-10);
    assert!(w.energy_gain.unwrap() < 0.0);
    assert!(w.closure_m.unwrap() < 1e-9 && w.closure_rate.unwrap() < 1e-3);
    assert!(w.settle_ratio.unwrap() < 0.15 && w.rejected_per_step.unwrap() < 0.01);
    assert!(w.steps_per_period.unwrap() > 300.0);
}

#[test]
fn a_loose_newton_tolerance_breaks_the_energy_balance() {
    // 0.1 mm: the run creates energy (3× what the drop releases).
    let check = failed_check(run(Tests::Both, loose_newton(1e-4), DynamicTest::default()));
    assert_eq!(check, "energy balance (dynamic test)");
    let e = run(Tests::Both, loose_newton(1e-4), DynamicTest::default()).unwrap_err();
    assert!(e.to_string().contains("the run created energy"), "{e}");
}

#[test]
fn a_looser_newton_tolerance_lets_the_loop_open() {
    // 10 µm: the closure drifts to 2.5 µm.
    let check = failed_check(run(Tests::Both, loose_newton(1e-5), DynamicTest::default()));
    assert_eq!(check, "constraint drift (closure, positions)");
    // 1 µm still passes (closure 0.23 µm).
    let (o, t) = run(Tests::Both, loose_newton(1e-6), DynamicTest::default()).unwrap();
    assert!(t.validity.closure_m.unwrap() < validity::MAX_CLOSURE_M);
    assert!(o.hd_mm.is_some());
}

#[test]
fn a_short_dynamic_test_is_flagged_not_settled() {
    let short = DynamicTest {
        duration_s: 0.6,
        ..DynamicTest::default()
    };
    let (o, t) = run(Tests::Both, Settings::default(), short).unwrap();
    assert!(t.validity.settle_ratio.unwrap() > validity::MAX_SETTLE_RATIO);
    assert_eq!(o.warnings.len(), 1, "{:?}", o.warnings);
    assert!(o.warnings[0].starts_with("not settled"), "{:?}", o.warnings);
    // The warning is in the JSON beside the figures.
    let json = serde_json::to_value(&o).unwrap();
    assert!(json["warnings"][0]
        .as_str()
        .unwrap()
        .starts_with("not settled"));
    // Without warnings the key is absent (`paper --json` is unchanged).
    let (o, _) = run(Tests::Both, Settings::default(), DynamicTest::default()).unwrap();
    assert!(serde_json::to_value(&o).unwrap().get("warnings").is_none());
}

#[test]
fn a_huge_nominal_step_is_flagged() {
    let step = |step_s| {
        let s = Settings {
            step_s,
            ..Settings::default()
        };
        run(Tests::Both, s, DynamicTest::default()).unwrap()
    };
    // 0.5 s: the step controller hunts, and the period is resolved by a
    // handful of steps.
    let (o, t) = step(0.5);
    assert!(t.validity.rejected_per_step.unwrap() > validity::MAX_REJECTED_PER_STEP);
    assert!(
        o.warnings.iter().any(|w| w.starts_with("step rejections"))
            && o.warnings.iter().any(|w| w.starts_with("time resolution")),
        "{:?}",
        o.warnings
    );
    // 50 ms: no rejection, but 31 steps per period (T 1.4 % long).
    let (o, t) = step(0.05);
    assert!(t.validity.steps_per_period.unwrap() < validity::MIN_STEPS_PER_PERIOD);
    assert!(
        o.warnings.len() == 1 && o.warnings[0].starts_with("time resolution"),
        "{:?}",
        o.warnings
    );
    // 20 ms passes.
    assert!(step(0.02).0.warnings.is_empty());
}

#[test]
fn an_unsettled_state_fails_the_equilibrium_check() {
    // Settle, then put the roller on without settling again: the state the
    // figures would be read from is not at rest.
    let model = model_for(
        38,
        trackbelt_host::paper::law_for(Variant::E38, Method::I).unwrap(),
    )
    .unwrap();
    let mut chain = Box::new(ReferenceChain::new(model, Settings::default()).unwrap());
    bench::static_test(&mut *chain).unwrap();
    let before = chain.stats();
    let (settled, _) = chain.static_imbalance();
    assert!(settled < 1e-10);
    // Asking changes nothing.
    assert_eq!(chain.stats(), before);
    chain.set_roller_mass(1.3).unwrap();
    let mut m = Monitor::new();
    m.after_static(&mut *chain);
    let v = m.validity();
    assert!(
        v.static_imbalance.unwrap() > validity::MAX_STATIC_IMBALANCE,
        "{v:?}"
    );
    match v.check() {
        Err(Error::SimInvalid { check, value, .. }) => {
            assert_eq!(check, "static equilibrium (static test)");
            assert_eq!(value, v.static_imbalance.unwrap());
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_static_only_run_checks_its_equilibrium() {
    let (o, t) = run(Tests::Static, Settings::default(), DynamicTest::default()).unwrap();
    assert!(t.validity.static_imbalance.unwrap() < 1e-10);
    assert!(t.validity.energy_gain.is_none() && o.warnings.is_empty());
}

#[test]
fn every_check_names_itself_and_its_value() {
    // The checks no valid parameter can reach (the joint law refuses a
    // negative damping; the index-3 integrator holds the velocity closure
    // far inside its bound) still fail on the values.
    let ok = BenchValidity {
        static_imbalance: Some(1e-12),
        loaded_imbalance: Some(1e-12),
        energy_gain: Some(-1e-4),
        energy_released_j: Some(1.0),
        damping_work_j: Some(0.9),
        closure_m: Some(1e-10),
        closure_rate: Some(1e-4),
        settle_ratio: Some(0.01),
        steps_per_period: Some(500.0),
        rejected_per_step: Some(0.0),
    };
    assert_eq!(ok.check().unwrap(), Vec::<String>::new());
    let err = |v: BenchValidity| match v.check() {
        Err(e @ Error::SimInvalid { .. }) => e.to_string(),
        other => panic!("{other:?}"),
    };
    let e = err(BenchValidity {
        damping_work_j: Some(-0.2),
        ..ok
    });
    assert!(
        e.contains("joint damping work") && e.contains("-2.000000e-1"),
        "{e}"
    );
    let e = err(BenchValidity {
        loaded_imbalance: Some(0.5),
        ..ok
    });
    assert!(e.contains("loaded") && e.contains("5.000000e-1"), "{e}");
    for nan in [
        BenchValidity {
            energy_gain: Some(f64::NAN),
            ..ok
        },
        BenchValidity {
            closure_m: Some(f64::NAN),
            ..ok
        },
        BenchValidity {
            static_imbalance: Some(f64::NAN),
            ..ok
        },
    ] {
        err(nan);
    }
    let w = BenchValidity {
        closure_rate: Some(0.2),
        ..ok
    }
    .check()
    .unwrap();
    assert!(
        w.len() == 1
            && w[0].starts_with("constraint drift (closure, velocities")
            && w[0].ends_with("2.0000e-1"),
        "{w:?}"
    );
    // A negative damping never reaches a simulation: the law refuses it.
    assert!(trackbelt::joint::JointLaw::new(
        trackbelt::stiffness::Stiffness::Constant { kz: 8.6 },
        -0.1
    )
    .is_err());
}

#[test]
fn the_forward_runs_are_checked() {
    let law = trackbelt_host::paper::law_for(Variant::E38, Method::I).unwrap();
    let belt = trackbelt::params::Belt::shredder(38);
    // A short run: the trace, with the warning.
    let (trace, w) =
        trackbelt_host::forward::simulate_height_checked(&law, &belt, 1.3, 0.6).unwrap();
    assert!(!trace.is_empty() && w.len() == 1 && w[0].starts_with("not settled"));
    // The scroll runs hold the rig's speed range.
    let e = trackbelt_host::forward::simulate_scroll(
        &law,
        &belt,
        &trackbelt::rig::RigConfig::default(),
        &|_| 1e3,
        &|_| 20.0,
        0.1,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::RigInvalid {
                check: "drive speed",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn the_bushing_chain_is_checked_too() {
    let (v, m) = (Variant::E38, Method::II);
    let law = trackbelt_host::paper::law_for(v, m).unwrap();
    let (o, t) = trackbelt_host::sim::simulate_joint(
        model_for(v.links(), law).unwrap(),
        m,
        trackbelt_host::sim::Joint::Bushing,
        Tests::Both,
        Settings::default(),
        DynamicTest::default(),
    )
    .unwrap();
    let v = t.validity;
    println!("bushing E38 II: {v:?}");
    assert!(o.warnings.is_empty(), "{:?}", o.warnings);
    assert!(v.static_imbalance.unwrap() < 1e-6 && v.loaded_imbalance.unwrap() < 1e-6);
    assert!(v.energy_gain.unwrap() < 0.0 && v.energy_released_j.unwrap() > 0.0);
    // No closure constraint (the bushings stretch instead).
    assert!(v.closure_m.is_none() && o.max_stretch_um.unwrap() < 1.0);
}

#[test]
fn newton_failing_at_the_smallest_step_is_an_error() {
    // The core's own check: a step that Newton cannot take above
    // `min_step_s` ends the run with a typed error, not a figure.
    let s = Settings {
        min_step_s: 1e-3,
        step_s: 0.2,
        ..Settings::default()
    };
    match run(Tests::Both, s, DynamicTest::default()) {
        Err(Error::Model(trackbelt::Error::Diverged { reason, .. })) => {
            assert!(reason.contains("Newton"), "{reason}")
        }
        other => panic!("{other:?}"),
    }
}

/// The paper's E38 method I drop under `settings`, watched by `monitor`:
/// its verdict and what it measured.
fn drop_watched_by(
    settings: Settings<f64>,
    mut monitor: Monitor,
) -> (trackbelt_host::error::Result<Vec<String>>, BenchValidity) {
    let model = model_for(
        38,
        trackbelt_host::paper::law_for(Variant::E38, Method::I).unwrap(),
    )
    .unwrap();
    let mut chain = Box::new(ReferenceChain::new(model, settings).unwrap());
    bench::static_test(&mut *chain).unwrap();
    monitor.after_static(&mut *chain);
    let d =
        bench::dynamic_test(&mut *chain, &DynamicTest::default(), |c| monitor.observe(c)).unwrap();
    monitor.after_dynamic(&mut *chain, &d);
    let v = monitor.validity();
    (v.check(), v)
}

#[test]
fn a_monitor_sampling_every_fourth_step_fails_the_same_runs() {
    // What the diagnosis's forward model uses (`forward::MONITOR_STRIDE`):
    // the energy balance, the closure and the joint speeds after every
    // fourth step only. The runs that fail numerically fail the same check.
    assert_eq!(trackbelt_host::forward::MONITOR_STRIDE, 4);
    for (tol, expected) in [
        (1e-4, "energy balance (dynamic test)"),
        (1e-5, "constraint drift (closure, positions)"),
    ] {
        for stride in [1, 4] {
            let (verdict, v) = drop_watched_by(loose_newton(tol), Monitor::sampling_every(stride));
            match verdict {
                Err(Error::SimInvalid { check, .. }) => assert_eq!(check, expected, "{stride}"),
                other => panic!("stride {stride}, tolerance {tol}: {other:?} ({v:?})"),
            }
        }
    }
    // A sound run passes either way, with the same figures but the
    // sampled maxima, which can only be smaller and here are close.
    let (ok1, v1) = drop_watched_by(Settings::default(), Monitor::new());
    let (ok4, v4) = drop_watched_by(Settings::default(), Monitor::sampling_every(4));
    assert!(ok1.unwrap().is_empty() && ok4.unwrap().is_empty());
    assert_eq!(v1.damping_work_j, v4.damping_work_j);
    assert_eq!(v1.settle_ratio, v4.settle_ratio);
    let (c1, c4) = (v1.closure_m.unwrap(), v4.closure_m.unwrap());
    assert!(c4 <= c1 && c4 > 0.5 * c1, "{c1:e} {c4:e}");
    let (g1, g4) = (v1.energy_gain.unwrap(), v4.energy_gain.unwrap());
    assert!(g4 <= g1 && g4 > g1 - 1e-3, "{g1:e} {g4:e}");
}
