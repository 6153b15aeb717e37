//! The scroll diagnosis's test for a line locked to a wheel's turn
//! (`diagnose_scroll::disturbances` and `wheel_line`), on torque series
//! built by hand: a rig whose wheels are of one size and whose belt's
//! revolution harmonics fall among the reference orders, so that too few
//! of them are left to compare the line with. A large line there is read
//! by its size (`LINE_SIZE_FRACTION` of the mean torque over
//! `LINE_SIZE_TURNS` turns); a small one, or none, is not a disturbance.

use std::f64::consts::TAU;
use trackbelt::params::Belt;
use trackbelt::rig::RigConfig;
use trackbelt_host::diagnose_scroll::{
    disturbances, wheel_line, window_len, LINE_SIZE_FRACTION, LINE_SIZE_TURNS,
};
use trackbelt_truth::rng::Rng;

/// 12 s at 100 Hz: from rest to 3 rad/s in 1 s, held, then up to
/// 5 rad/s at 6 s, held.
fn speed() -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..1200).map(|i| i as f64 * 0.01).collect();
    let w = t
        .iter()
        .map(|&s| {
            if s < 1.0 {
                3.0 * s
            } else if s < 6.0 {
                3.0
            } else if s < 6.5 {
                3.0 + 4.0 * (s - 6.0)
            } else {
                5.0
            }
        })
        .collect();
    (t, w)
}

/// Drive angle, rad (trapezoid over the speed, as the diagnosis reads it).
fn angle(t: &[f64], w: &[f64]) -> Vec<f64> {
    let mut a = vec![0.0; t.len()];
    for i in 1..t.len() {
        a[i] = a[i - 1] + 0.5 * (w[i] + w[i - 1]) * (t[i] - t[i - 1]);
    }
    a
}

/// The rig: both wheels 260 mm, so each turns at the other's order 1.
fn rig() -> RigConfig<f64> {
    RigConfig {
        drive_diameter_m: 0.26,
        idler_diameter_m: 0.26,
        ..RigConfig::default()
    }
}

/// A 1.2 m belt, 7 mm thick: its revolution harmonics fall at orders
/// 0.70, 1.40 and 2.10 of a wheel's turn, each masking the reference
/// orders within the resolution (1/turns) about it.
fn belt() -> Belt<f64> {
    Belt {
        length_m: 1.2,
        width_m: 0.1,
        thickness_m: 0.007,
        mass_kg: 2.0,
        links: 38,
    }
}

/// The baseline's torque and a measured torque with a line of
/// `line_nm` at the wheels' turn on top of it, and a little uniform noise
/// in ±0.005 N·m from the truth generator's own pseudo-random numbers (no
/// period a line search could find).
fn series(line_nm: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (t, w) = speed();
    let a = angle(&t, &w);
    let base: Vec<f64> = w.iter().map(|&x| 0.4 + 0.2 * x).collect();
    let mut rng = Rng::new(1);
    let tq = base
        .iter()
        .zip(&a)
        .map(|(b, x)| b + line_nm * (x + 0.7).sin() + 0.01 * rng.range(-0.5, 0.5))
        .collect();
    (t, w, tq, base)
}

fn found(line_nm: f64) -> Vec<String> {
    let (t, w, tq, base) = series(line_nm);
    let k = window_len(&t);
    disturbances(&t, &w, &tq, None, &base, &rig(), &belt(), k)
}

#[test]
fn the_rig_leaves_too_few_reference_orders() {
    let (t, w, tq, base) = series(0.1);
    let r: Vec<f64> = tq.iter().zip(&base).map(|(a, b)| a - b).collect();
    // The drive's turns per drive radian; the idler turns alike.
    let l =
        wheel_line(&t, &w, &r, 1.0 / TAU, &[1.0, 2.0], &[0.70, 1.40, 2.10]).expect("turns enough");
    assert!(l.ratio.is_none(), "{l:?}");
    assert!(l.turns >= LINE_SIZE_TURNS, "{l:?}");
    assert!((l.amplitude - 0.1).abs() < 0.01, "{l:?}");
}

#[test]
fn a_large_line_is_read_by_its_size() {
    // Mean torque about 1.2 N·m: 0.1 N·m is 8 %.
    let f = found(0.1);
    assert!(
        f.iter().any(|s| s.contains("turn in the residual")
            && s.contains("too few orders free of the rig's other lines")),
        "{f:?}"
    );
    const { assert!(0.1 / 1.2 > LINE_SIZE_FRACTION) };
}

#[test]
fn a_small_line_or_none_is_not_a_wheels_line() {
    // 0.03 N·m is 2.5 % of the mean torque, a sound belt's ripple: not a
    // wheel's line (the other readings are not this test's).
    let f = found(0.03);
    assert!(
        !f.iter().any(|s| s.contains("turn in the residual")),
        "{f:?}"
    );
    assert!(found(0.0).is_empty(), "{:?}", found(0.0));
}
