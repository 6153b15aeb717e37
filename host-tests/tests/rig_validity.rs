//! No silent garbage from the rig: a run outside the model's validity is a
//! typed error naming the check and the value (or, when the figure is
//! still useful, a warning in `RigOutput::warnings`), never a plain number.

use trackbelt::params::{Method, Model, Variant};
use trackbelt::rig::{RigConfig, RigTest};
use trackbelt_host::error::Error;
use trackbelt_host::rig::{max_speed_rad_s, run_rig, Validity};

fn model(v: Variant) -> Model<f64> {
    let law = trackbelt_host::paper::law_for(v, Method::I).unwrap();
    trackbelt_host::sim::model_for(v.links(), law).unwrap()
}

fn run(
    config: RigConfig<f64>,
    speed_rad_s: f64,
) -> trackbelt_host::error::Result<trackbelt_host::rig::RigOutput> {
    let test = RigTest {
        speed_rad_s,
        ..RigTest::default()
    };
    run_rig("E56", Method::I, model(Variant::E56), config, test, false).map(|(o, _)| o)
}

fn check_of(r: trackbelt_host::error::Result<trackbelt_host::rig::RigOutput>) -> &'static str {
    match r {
        Err(Error::RigInvalid { check, .. }) => check,
        other => panic!("expected RigInvalid, got {other:?}"),
    }
}

#[test]
fn the_1e9_speed_is_an_error_naming_the_speed() {
    // Was: exit 0, 64.9 N·m mean torque, 1e-5 N·m bending.
    let e = run(RigConfig::default(), 1e9).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("drive speed") && msg.contains("1.000000e9"),
        "{msg}"
    );
    for w in [
        -1e9,
        29.0,
        -29.0,
        1e3,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ] {
        assert_eq!(check_of(run(RigConfig::default(), w)), "drive speed", "{w}");
    }
}

#[test]
fn the_speed_range_per_variant() {
    let c = RigConfig::default();
    let lim: Vec<f64> = [Variant::E38, Variant::E56, Variant::E76]
        .iter()
        .map(|&v| max_speed_rad_s(&model(v), &c))
        .collect();
    // As `trackbelt rig --help` states them.
    for (l, want) in lim.iter().zip([41.3, 28.2, 20.9]) {
        assert!((l - want).abs() < 0.05, "{lim:?}");
    }
}

#[test]
fn valid_runs_have_no_warning_and_slow_ones_are_flagged() {
    let out = run(RigConfig::default(), 5.0).unwrap();
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    let out = run(RigConfig::default(), -5.0).unwrap();
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    // 0.1 rad/s: the measured 1.5 s cover half a link passage.
    let out = run(RigConfig::default(), 0.1).unwrap();
    assert_eq!(out.warnings.len(), 1, "{:?}", out.warnings);
    assert!(
        out.warnings[0].contains("link passage"),
        "{:?}",
        out.warnings
    );
}

#[test]
fn bad_idler_forces_and_wheels_are_errors() {
    for f in [0.0, -10.0, f64::NAN, 1e-3, 1e7] {
        let c = RigConfig {
            idler_force_n: f,
            ..RigConfig::default()
        };
        assert!(run(c, 5.0).is_err(), "idler force {f}");
    }
    for d in [0.0, -0.3, 1e-6] {
        let c = RigConfig {
            drive_diameter_m: d,
            idler_diameter_m: d,
            ..RigConfig::default()
        };
        assert!(run(c, 5.0).is_err(), "wheel diameter {d}");
    }
}

#[test]
fn slip_and_energy_balance_are_errors() {
    let good = Validity {
        drive_path_speed_m_s: 0.775,
        belt_speed_m_s: 0.773,
        slip: 0.0026,
        settle_drift: 0.001,
        rejected_per_step: 0.02,
        bending_share: 0.97,
        link_passages: 26.0,
    };
    assert_eq!(good.check().unwrap(), Vec::<String>::new());
    let slipping = Validity {
        belt_speed_m_s: 27.9,
        drive_path_speed_m_s: 1.55e8,
        slip: 0.9999998,
        ..good
    };
    match slipping.check() {
        Err(Error::RigInvalid { check, value, .. }) => {
            assert_eq!(check, "belt slip");
            assert_eq!(value, 0.9999998);
        }
        other => panic!("{other:?}"),
    }
    for share in [1.022, -0.5, f64::NAN] {
        let v = Validity {
            bending_share: share,
            ..good
        };
        assert!(
            matches!(v.check(), Err(Error::RigInvalid { check, .. }) if check.starts_with("energy balance")),
            "{share}"
        );
    }
    let unsettled = Validity {
        settle_drift: 0.3,
        rejected_per_step: 2.0,
        ..good
    };
    let w = unsettled.check().unwrap();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].starts_with("not settled") && w[0].ends_with("0.3000"),
        "{w:?}"
    );
}
