//! A belt that is not the paper's on two running gears (issue 12).
//!
//! The belt: 1.40 m, 2.5 kg, 8 mm thick, N = 44 links (32 mm), with the
//! paper's method II joint law for E56 and thermal softening (−1 %/K above
//! 20 °C). Two layouts:
//!
//! * **two-wheel**: a 160 mm drive and a 200 mm idler on a tensioner;
//! * **four-wheel**: a 160 mm drive, a 140 mm idler on a tensioner, two
//!   100 mm road wheels pressing the lower run onto the ground under a
//!   12 kg load.
//!
//! Checks:
//! * the estimator (a [`GearTable`] over 20/50 °C × 300/500 N, run in f32
//!   and in 32.32 fixed point with both inputs) within **2 %** of the reference simulation's bending
//!   torque (`run_gear`: the dynamic rig test, friction drive) at 1, 2, 5
//!   and 10 rad/s, at both tensions and both temperatures, and between the
//!   knots (35 °C, 400 N at 2 and 5 rad/s);
//! * the physics: the bending loss (resistance force at one belt speed)
//!   falls as the wheels grow, rises with the joint damping cz, rises when a road wheel is added to the path; the
//!   ground carries the load.

use std::time::Instant;
use trackbelt::effects::ThermalSoftening;
use trackbelt::estimator::{BuildOptions, EstimatorState, GearTable};
use trackbelt::gear::{Ground, RunningGear, Tensioner, Wheel, WheelRole};
use trackbelt::params::{Belt, Method, Model, Variant};
use trackbelt::rig::RigTest;
use trackbelt::{Fx, Real};
use trackbelt_host::gear::{gear_table, run_gear, TableAxes};

fn model(cz_scale: f64) -> Model<f64> {
    let mut law = trackbelt_host::paper::law_for(Variant::E56, Method::II).expect("law");
    law.damping *= cz_scale;
    law.effects.thermal_softening = Some(ThermalSoftening {
        alpha_per_k: 0.01,
        reference_temp_c: 20.0,
        temp_c: 20.0,
    });
    let belt = Belt {
        length_m: 1.40,
        width_m: 0.10,
        thickness_m: 0.008,
        mass_kg: 2.5,
        links: 44,
    };
    Model::new(belt, law).expect("model")
}

fn gear(
    force_n: f64,
    wheels: &[(WheelRole, f64, f64, f64)],
    load_kg: Option<f64>,
) -> RunningGear<f64> {
    let mut g = RunningGear::new(Tensioner::Force { force_n });
    for &(role, x_m, y_m, diameter_m) in wheels {
        g.push(Wheel {
            role,
            x_m,
            y_m,
            diameter_m,
        })
        .expect("wheel");
    }
    g.ground = load_kg.map(|load_kg| Ground { load_kg });
    g.validate().expect("valid gear");
    g
}

fn two_wheel(force_n: f64, drive_d: f64, idler_d: f64) -> RunningGear<f64> {
    gear(
        force_n,
        &[
            (WheelRole::Drive, 0.0, 0.0, drive_d),
            (WheelRole::Idler, 0.50, 0.0, idler_d),
        ],
        None,
    )
}

fn four_wheel(force_n: f64) -> RunningGear<f64> {
    gear(
        force_n,
        &[
            (WheelRole::Drive, 0.0, 0.0, 0.16),
            (WheelRole::Idler, 0.45, 0.0, 0.14),
            (WheelRole::Road, 0.13, -0.07, 0.10),
            (WheelRole::Road, 0.29, -0.07, 0.10),
        ],
        Some(12.0),
    )
}

fn bending(m: &Model<f64>, g: &RunningGear<f64>, speed: f64, temp: Option<f64>) -> f64 {
    let test = RigTest {
        speed_rad_s: speed,
        ..RigTest::default()
    };
    let (out, _) = run_gear(m, g, test, temp).expect("run");
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    out.bending_torque_nm_mean
}

fn estimator_within_two_percent(name: &str, layout: fn(f64) -> RunningGear<f64>) {
    let m = model(1.0);
    let axes = TableAxes {
        temperatures_c: vec![20.0, 50.0],
        tensions_n: vec![300.0, 500.0],
    };
    let t0 = Instant::now();
    let table = gear_table(&m, &layout(400.0), &axes, &BuildOptions::default()).expect("table");
    let build_s = t0.elapsed().as_secs_f64();
    println!("{name}: table (base + 4 columns) built in {build_s:.2} s");
    assert!(build_s < 10.0, "table build {build_s:.1} s");
    let t32: GearTable<f32> = table.cast();
    let tfx: GearTable<Fx> = table.cast();
    let mut worst = 0.0f64;
    for temp in [20.0, 50.0] {
        for force in [300.0, 500.0] {
            let g = layout(force);
            for speed in [1.0, 2.0, 5.0, 10.0] {
                let r = bending(&m, &g, speed, Some(temp));
                let mut s = EstimatorState::new();
                let e = t32.update(
                    &mut s,
                    speed as f32,
                    1e-3,
                    Some(temp as f32),
                    Some(force as f32),
                );
                assert!(e.status.is_ok(), "{:?}", e.status);
                let err = e.bending_nm as f64 / r - 1.0;
                worst = worst.max(err.abs());
                // The same table in 32.32 fixed point.
                let mut sf = EstimatorState::new();
                let fx = |x: f64| Fx::from_f64(x);
                let ef = tfx.update(
                    &mut sf,
                    fx(speed),
                    fx(1e-3),
                    Some(fx(temp)),
                    Some(fx(force)),
                );
                assert!(ef.status.is_ok(), "{:?}", ef.status);
                let err_fx = ef.bending_nm.to_f64() / r - 1.0;
                assert!(err_fx.abs() <= 0.02, "{name} fixed point: {err_fx:+.4}");
                assert!((err_fx - err).abs() < 1e-4, "f32 {err} vs fixed {err_fx}");
                println!(
                    "{name} {temp} °C {force} N {speed} rad/s: estimator {:.4} N·m, reference {r:.4} ({:+.2} %)",
                    e.bending_nm,
                    100.0 * err
                );
                assert!(
                    err.abs() <= 0.02,
                    "{name} {temp} °C {force} N {speed} rad/s: {err:+.4}"
                );
            }
        }
    }
    // Between the knots: bilinear in temperature and tension.
    for speed in [2.0, 5.0] {
        let (temp, force) = (35.0, 400.0);
        let r = bending(&m, &layout(force), speed, Some(temp));
        let mut s = EstimatorState::new();
        let e = t32.update(
            &mut s,
            speed as f32,
            1e-3,
            Some(temp as f32),
            Some(force as f32),
        );
        assert!(e.status.is_ok(), "{:?}", e.status);
        let err = e.bending_nm as f64 / r - 1.0;
        println!(
            "{name} {temp} °C {force} N {speed} rad/s (between knots): estimator {:.4} N·m, reference {r:.4} ({:+.2} %)",
            e.bending_nm,
            100.0 * err
        );
        assert!(
            err.abs() <= 0.02,
            "{name} between knots {speed} rad/s: {err:+.4}"
        );
        worst = worst.max(err.abs());
    }
    println!("{name}: worst {:.2} %", 100.0 * worst);
}

#[test]
fn estimator_two_wheel_within_two_percent() {
    estimator_within_two_percent("two-wheel", |f| two_wheel(f, 0.16, 0.20));
}

#[test]
fn estimator_four_wheel_within_two_percent() {
    estimator_within_two_percent("four-wheel", four_wheel);
}

/// At the same belt speed (0.4 m/s) the bending loss — as the resistance
/// force the belt opposes, bending power over belt speed, and as torque —
/// falls as the wheels grow. (At the same drive *angular* speed the torque
/// hardly changes: the belt runs faster on a bigger wheel while each joint
/// bends less, force × radius nearly constant; the force still falls.)
#[test]
fn bending_loss_falls_as_the_wheels_grow() {
    let m = model(1.0);
    let belt_speed_m_s = 0.4;
    let forces: Vec<f64> = [0.12, 0.16, 0.22]
        .iter()
        .map(|&d| {
            let r = 0.5 * d;
            bending(&m, &two_wheel(400.0, d, d), belt_speed_m_s / r, None) / r
        })
        .collect();
    println!("bending resistance force at 0.4 m/s, wheels 120/160/220 mm: {forces:?} N");
    assert!(forces[0] > forces[1] && forces[1] > forces[2], "{forces:?}");
    // By a margin: each joint bends by about the link length over the
    // radius, at a rate set by the belt speed, so at one belt speed the
    // dissipated power falls roughly as 1/diameter².
    assert!(forces[0] > 1.4 * forces[2], "{forces:?}");
}

#[test]
fn bending_loss_rises_with_cz() {
    let g = four_wheel(400.0);
    let losses: Vec<f64> = [0.5, 1.0, 2.0]
        .iter()
        .map(|&k| bending(&model(k), &g, 5.0, None))
        .collect();
    println!("bending at cz ×0.5/×1/×2: {losses:?}");
    assert!(losses[0] < losses[1] && losses[1] < losses[2], "{losses:?}");
}

#[test]
fn bending_loss_rises_when_a_wheel_is_added() {
    let m = model(1.0);
    let two = gear(
        400.0,
        &[
            (WheelRole::Drive, 0.0, 0.0, 0.16),
            (WheelRole::Idler, 0.45, 0.0, 0.14),
        ],
        None,
    );
    let three = gear(
        400.0,
        &[
            (WheelRole::Drive, 0.0, 0.0, 0.16),
            (WheelRole::Idler, 0.45, 0.0, 0.14),
            (WheelRole::Road, 0.21, -0.07, 0.10),
        ],
        Some(12.0),
    );
    let four = four_wheel(400.0);
    let losses: Vec<f64> = [&two, &three, &four]
        .iter()
        .map(|g| bending(&m, g, 5.0, None))
        .collect();
    println!("bending with 2/3/4 wheels: {losses:?}");
    assert!(losses[0] < losses[1] && losses[1] < losses[2], "{losses:?}");
}

#[test]
fn the_ground_carries_the_load_and_the_rig_preset_is_unchanged() {
    let m = model(1.0);
    let (out, _) = run_gear(
        &m,
        &four_wheel(400.0),
        RigTest {
            speed_rad_s: 2.0,
            ..RigTest::default()
        },
        None,
    )
    .expect("run");
    let w = 12.0 * 9.81;
    let f = out.ground_force_n.expect("ground");
    println!("ground force {f:.2} N (load {w:.2} N)");
    assert!((f / w - 1.0).abs() < 0.05, "{f} vs {w}");
    // The paper's rig as a gear is the rig itself, bit for bit.
    use trackbelt::rig::{rig_test, Rig, RigConfig};
    let paper = trackbelt_host::sim::model_for(
        56,
        trackbelt_host::paper::law_for(Variant::E56, Method::II).expect("law"),
    )
    .expect("model");
    let g = RunningGear::paper_rig(&RigConfig::default(), 0.74).expect("preset");
    let test = RigTest::default();
    let mut a: Box<Rig<f64, 64>> =
        Box::new(Rig::new(paper.clone(), RigConfig::default(), Default::default()).expect("rig"));
    let mut b: Box<Rig<f64, 64>> =
        Box::new(Rig::from_gear(paper, &g, Default::default()).expect("gear"));
    let fa = rig_test(&mut a, &test, |_| {}).expect("a");
    let fb = rig_test(&mut b, &test, |_| {}).expect("b");
    assert_eq!(fa, fb);
}

#[test]
fn without_inputs_the_gear_table_is_the_one_dimensional_estimator() {
    let m = model(1.0);
    let g = four_wheel(400.0);
    let opts = BuildOptions {
        phases: 8,
        ..BuildOptions::default()
    };
    let table = gear_table(&m, &g, &TableAxes::nominal(&g, 20.0), &opts).expect("table");
    let t32: GearTable<f32> = table.cast();
    let (mut s1, mut s2) = (EstimatorState::new(), EstimatorState::new());
    for k in 0..200 {
        let w = 0.1 * k as f32;
        let a = t32.update(&mut s1, w, 1e-3, None, None);
        let b = t32.base.update(&mut s2, w, 1e-3);
        assert_eq!(a, b);
    }
    // An input off its axis is flagged and held at the edge.
    let mut s = EstimatorState::new();
    let e = t32.update(&mut s, 5.0, 1e-3, Some(f32::NAN), None);
    assert!(e
        .status
        .contains(trackbelt::estimator::Status::INPUT_OUT_OF_RANGE));
    assert!(e.torque_nm.is_finite());
}
