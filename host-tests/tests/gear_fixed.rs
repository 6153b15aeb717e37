//! A fixed-centre tensioner (issue 12): the idler held where it is given,
//! the belt's tension following from its length against the path.
//!
//! The belt and the four-wheel layout of `gear.rs` (1.40 m, 2.5 kg, 8 mm,
//! N = 44, E56's method II law; a 160 mm drive, a 140 mm idler on the
//! x axis, two 100 mm road wheels 70 mm below, ground under 12 kg).
//! Checks:
//! * physics oracle: the idler fixed where the 400 N force tensioner
//!   settles gives the same state — the belt pulls on it with about 400 N
//!   at rest and running, the bending torque the force tensioner's;
//! * moving the centre outwards raises the tension (monotone), at rest and
//!   running;
//! * a centre the belt cannot reach, or one it hangs slack at, is the
//!   typed error `FixedCentreBelt` with the mm it is short or long;
//! * the estimator built for the fixed-centre gear within **2 %** of its
//!   simulation at 1, 2, 5 and 10 rad/s (f32 table); its tension axis is
//!   one point, a label.

use trackbelt::effects::ThermalSoftening;
use trackbelt::estimator::{BuildOptions, EstimatorState, GearTable};
use trackbelt::gear::{Ground, RunningGear, Tensioner, Wheel, WheelRole};
use trackbelt::params::{Belt, Method, Model, Variant};
use trackbelt::rig::{Rig, RigTest};
use trackbelt::Settings;
use trackbelt_host::gear::{gear_table, run_gear, GearOutput, TableAxes};
use trackbelt_host::rig::RIG_CAPACITY;

fn model() -> Model<f64> {
    let mut law = trackbelt_host::paper::law_for(Variant::E56, Method::II).expect("law");
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

/// The four-wheel robot with the idler's centre at `idler_x_m` on the x
/// axis.
fn four_wheel(tensioner: Tensioner<f64>, idler_x_m: f64) -> RunningGear<f64> {
    let mut g = RunningGear::new(tensioner);
    for (role, x_m, y_m, diameter_m) in [
        (WheelRole::Drive, 0.0, 0.0, 0.16),
        (WheelRole::Idler, idler_x_m, 0.0, 0.14),
        (WheelRole::Road, 0.13, -0.07, 0.10),
        (WheelRole::Road, 0.29, -0.07, 0.10),
    ] {
        g.push(Wheel {
            role,
            x_m,
            y_m,
            diameter_m,
        })
        .expect("wheel");
    }
    g.ground = Some(Ground { load_kg: 12.0 });
    g.validate().expect("valid gear");
    g
}

fn force_gear() -> RunningGear<f64> {
    four_wheel(Tensioner::Force { force_n: 400.0 }, 0.45)
}

/// Where the 400 N force tensioner's idler settles at rest, m.
fn settled_centre_m(m: &Model<f64>) -> f64 {
    let rig: Box<Rig<f64, RIG_CAPACITY>> =
        Box::new(Rig::from_gear(m.clone(), &force_gear(), Settings::default()).expect("rig"));
    rig.idler_position_m()
}

fn fixed(centre_m: f64) -> RunningGear<f64> {
    four_wheel(Tensioner::FixedCentre, centre_m)
}

fn pretension_n(m: &Model<f64>, g: &RunningGear<f64>) -> trackbelt::Result<f64> {
    let rig: Box<Rig<f64, RIG_CAPACITY>> =
        Box::new(Rig::from_gear(m.clone(), g, Settings::default())?);
    assert_eq!(rig.idler_force_n(), rig.config().idler_force_n);
    Ok(rig.idler_force_n())
}

fn run(m: &Model<f64>, g: &RunningGear<f64>, speed: f64) -> GearOutput {
    let test = RigTest {
        speed_rad_s: speed,
        ..RigTest::default()
    };
    let (out, _) = run_gear(m, g, test, None).expect("run");
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    out
}

#[test]
fn fixed_where_the_force_tensioner_settles_gives_its_state() {
    let m = model();
    let d400 = settled_centre_m(&m);
    let g = fixed(d400);
    // At rest: the belt pulls on the held idler with the 400 N that held
    // it there (measured 400.35 N).
    let p = pretension_n(&m, &g).expect("settles");
    println!("idler fixed at {:.3} mm: pretension {p:.2} N", d400 * 1e3);
    assert!((p / 400.0 - 1.0).abs() < 0.01, "pretension {p} N");
    // Running at 5 rad/s: the same tension and bending torque (measured
    // +0.6 % and +0.5 %).
    let a = run(&m, &force_gear(), 5.0);
    let b = run(&m, &g, 5.0);
    println!(
        "5 rad/s: force tensioner {:.4} N·m at {:.2} N; fixed centre {:.4} N·m at {:.2} N",
        a.bending_torque_nm_mean, a.idler_force_n, b.bending_torque_nm_mean, b.idler_force_n
    );
    assert_eq!(a.idler_force_n, 400.0);
    assert!((b.idler_force_n / 400.0 - 1.0).abs() < 0.02, "{b:?}");
    let rel = b.bending_torque_nm_mean / a.bending_torque_nm_mean - 1.0;
    assert!(rel.abs() < 0.01, "bending {rel:+.4}");
    // The idler stays where it is given (the spring gives way by the
    // force over its 1e9 N/m: 0.4 µm).
    assert!((b.axle_distance_mm - d400 * 1e3).abs() < 2e-3, "{b:?}");
}

#[test]
fn moving_the_centre_outwards_raises_the_tension() {
    let m = model();
    let d400 = settled_centre_m(&m);
    let mut rest = Vec::new();
    let mut running = Vec::new();
    for dx_mm in [-5.0, 0.0, 0.5, 1.0] {
        let g = fixed(d400 + dx_mm * 1e-3);
        rest.push(pretension_n(&m, &g).expect("settles"));
        if dx_mm >= 0.0 {
            running.push(run(&m, &g, 5.0).idler_force_n);
        }
    }
    println!("pretension at −5/0/+0.5/+1 mm: {rest:.1?} N; running at 5 rad/s (0/+0.5/+1): {running:.1?} N");
    assert!(rest.windows(2).all(|w| w[1] > w[0]), "{rest:?}");
    assert!(running.windows(2).all(|w| w[1] > w[0]), "{running:?}");
}

#[test]
fn a_centre_the_belt_cannot_fit_is_a_typed_error() {
    let m = model();
    let d400 = settled_centre_m(&m);
    // 5 mm further out: the belt would have to stretch by about 7 mm.
    match Rig::<f64, RIG_CAPACITY>::from_gear(m.clone(), &fixed(d400 + 5e-3), Settings::default()) {
        Err(
            e @ trackbelt::Error::FixedCentreBelt {
                short_by_mm,
                centre_distance_mm,
                fits_at_mm,
            },
        ) => {
            println!("{e}");
            assert!(short_by_mm > 2.0, "{short_by_mm}");
            assert!(fits_at_mm < centre_distance_mm);
            let msg = e.to_string();
            assert!(
                msg.contains("too short") && msg.contains("towards the drive"),
                "{msg}"
            );
        }
        other => panic!("expected FixedCentreBelt, got {:?}", other.map(|_| ())),
    }
    // Drive and idler alone, 300 mm apart (the belt is tight round them at
    // 448 mm): the belt hangs slack.
    let mut two = RunningGear::new(Tensioner::FixedCentre);
    for (role, x_m, diameter_m) in [
        (WheelRole::Drive, 0.0, 0.16),
        (WheelRole::Idler, 0.30, 0.14),
    ] {
        two.push(Wheel {
            role,
            x_m,
            y_m: 0.0,
            diameter_m,
        })
        .expect("wheel");
    }
    match Rig::<f64, RIG_CAPACITY>::from_gear(m.clone(), &two, Settings::default()) {
        Err(e @ trackbelt::Error::FixedCentreBelt { short_by_mm, .. }) => {
            println!("{e}");
            assert!(short_by_mm < 0.0, "{short_by_mm}");
            let msg = e.to_string();
            assert!(msg.contains("too long") && msg.contains("slack"), "{msg}");
        }
        other => panic!("expected FixedCentreBelt, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn estimator_fixed_centre_within_two_percent() {
    let m = model();
    let g = fixed(settled_centre_m(&m));
    let opts = BuildOptions::default();
    let axes = TableAxes::nominal(&g, 20.0);
    assert_eq!(axes.tensions_n, vec![0.0]);
    let table = gear_table(&m, &g, &axes, &opts).expect("table");
    // The tension axis is one point, a label: more is an error.
    let two = TableAxes {
        temperatures_c: vec![20.0],
        tensions_n: vec![300.0, 500.0],
    };
    assert!(gear_table(&m, &g, &two, &opts).is_err());
    let t32: GearTable<f32> = table.cast();
    for speed in [1.0, 2.0, 5.0, 10.0] {
        let r = run(&m, &g, speed);
        let mut s = EstimatorState::new();
        let e = t32.update(&mut s, speed as f32, 1e-3, None, None);
        assert!(e.status.is_ok(), "{:?}", e.status);
        let err = e.bending_nm as f64 / r.bending_torque_nm_mean - 1.0;
        println!(
            "{speed} rad/s: simulated {:.4} N·m (belt pull {:.1} N), estimator {:.4} N·m ({:+.2} %)",
            r.bending_torque_nm_mean,
            r.idler_force_n,
            e.bending_nm,
            100.0 * err
        );
        assert!(err.abs() < 0.02, "{speed} rad/s: {err:+.4}");
        // A tension input changes nothing on a fixed centre.
        let mut s2 = EstimatorState::new();
        let e2 = t32.update(&mut s2, speed as f32, 1e-3, None, Some(450.0));
        assert_eq!(e2.bending_nm, e.bending_nm);
        assert!(e2.status.is_ok(), "{:?}", e2.status);
    }
}
