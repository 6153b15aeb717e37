//! Issue 12: the static solver's fallback (`trackbelt::integrator`,
//! `solve_static`). Truth seed 78's belt (1546 mm, 2.96 kg, 5.3 mm, its
//! 0.59 kg roller) at N = 44 with the method III table `calibrate` fitted
//! to it, the Z3 slope made 10 % steeper (what the period asks for): the
//! settled state of the dynamic test used to fail with "static equilibrium
//! did not converge in 400 iterations" (the relaxation let the loaded belt
//! roll off its symmetric shape, see the solver's docs). It must now
//! settle, to a static equilibrium, on the symmetric shape.

use trackbelt::bench::{self, BenchChain, DynamicTest};
use trackbelt::joint::JointLaw;
use trackbelt::params::{Belt, Model};
use trackbelt::stiffness::{Stiffness, TorqueTable};
use trackbelt::{ReferenceChain, Settings};

/// Breakpoints of the fitted table, degrees (E38's scaled by 38/44).
const ANGLES_DEG: [f64; 6] = [
    -38.86361777595138,
    -25.909072321405922,
    -5.181818181818182,
    0.0,
    2.590909090909091,
    11.227272727272727,
];
/// Its torques, N·mm (`trackbelt calibrate DATA --links 44 --no-spread`).
const TORQUES_NMM: [f64; 6] = [
    -8856.95838649376,
    -2485.0595066934843,
    -955.6216485204824,
    0.0,
    5530.233180621243,
    11899.169127683554,
];
/// Its damping, N·mm·s/rad.
const CZ_NMMS: f64 = 230.89240234614957;

/// The chain with the fitted table's Z3 slope times `z3` (Z1 and Z2
/// slopes kept: the torques below −5.18° shift by the change at −5.18°).
fn chain(z3: f64) -> Box<ReferenceChain> {
    let shift = TORQUES_NMM[2] * (z3 - 1.0);
    let torques: Vec<f64> = TORQUES_NMM
        .iter()
        .enumerate()
        .map(|(i, t)| if i < 3 { t + shift } else { *t } * 1e-3)
        .collect();
    let angles: Vec<f64> = ANGLES_DEG.iter().map(|a| a.to_radians()).collect();
    let table = TorqueTable::new(&angles, &torques).unwrap();
    let law = JointLaw::new(Stiffness::Table(table), CZ_NMMS * 1e-3).unwrap();
    let belt = Belt {
        length_m: 1.546,
        width_m: 0.196,
        thickness_m: 0.0053,
        mass_kg: 2.96,
        links: 44,
    };
    let model = Model::new(belt, law).unwrap();
    Box::new(ReferenceChain::new(model, Settings::default()).unwrap())
}

#[test]
fn the_stiffer_z3_table_settles_to_a_symmetric_static_equilibrium() {
    let test = DynamicTest {
        roller_kg: 0.59,
        duration_s: 5.0,
    };
    let mut hd = Vec::new();
    for z3 in [1.05, 1.1, 1.2] {
        let mut c = chain(z3);
        let fig = bench::run(&mut *c, &test, |_| {})
            .unwrap_or_else(|e| panic!("Z3 × {z3}: the bench run failed: {e}"));
        // The settled state is a static equilibrium: every generalised
        // force below 1e-7 of the weight (the solver's own tolerance; the
        // CLI's validity check asks 1e-4), the loop closed to a nanometre.
        let (force, closure) = BenchChain::<f64, 132>::static_imbalance(&mut *c).unwrap();
        assert!(
            force <= 1e-7,
            "Z3 × {z3}: imbalance {force:e} of the weight"
        );
        assert!(closure <= 1e-9, "Z3 × {z3}: closure {closure:e} m");
        // ... on the symmetric shape (the roller on top), not rolled off it.
        let n = 44;
        for j in 1..n {
            let (a, b) = (c.joint_angle(j), c.joint_angle(n - j));
            assert!(
                (a - b).abs().to_degrees() < 1e-3,
                "Z3 × {z3}: joint {j} {:.4}° against joint {} {:.4}°",
                a.to_degrees(),
                n - j,
                b.to_degrees()
            );
        }
        let d = fig.dynamic_test;
        assert!(d.period_s.is_some() && d.log_decrement.is_some());
        hd.push(d.hd_mm);
    }
    // A stiffer wrap range carries the roller higher.
    assert!(hd.windows(2).all(|w| w[0] < w[1]), "Hd {hd:?}");
    assert!(hd.iter().all(|h| (230.0..260.0).contains(h)), "Hd {hd:?}");
}

/// Truth seed 9009's scroll rig (a 1764 mm, 105 mm wide, 6.3 mm, 2.64 kg
/// belt on 246/220 mm wheels) with the shipped E38 law: on its 759 N
/// tensioner the rig's static solve needed 536 proximal iterations (919 at
/// 1000 N) and stopped at the core's 400 with "static equilibrium did not
/// converge", so none of its scroll series could be diagnosed (7 errors in
/// `validate-diagnosis --count 10 --seed 9000 --kind scroll`), and the
/// onboard estimator's table could not be built on it. Rigs now get
/// `trackbelt::rig::rig_settings` (`RIG_STATIC_ITERATIONS`), the table
/// builders included; the rig must settle, run, and give its table.
#[test]
fn strongly_tensioned_rig_settles() {
    use trackbelt::params::Variant;
    use trackbelt::rig::RigConfig;
    let base = trackbelt_host::diagnose::baseline(Variant::E38, None).unwrap();
    let belt = Belt {
        length_m: 1.764,
        width_m: 0.105,
        thickness_m: 0.0063,
        mass_kg: 2.64,
        links: 38,
    };
    for force in [759.0, 1000.0] {
        let config = RigConfig {
            drive_diameter_m: 0.246,
            idler_diameter_m: 0.220,
            idler_force_n: force,
            ..RigConfig::default()
        };
        let trace = trackbelt_host::forward::simulate_scroll(
            &base.law,
            &belt,
            &config,
            &|t| (10.0 * t).min(1.0),
            &|_| 20.0,
            0.2,
        )
        .unwrap_or_else(|e| panic!("{force} N: {e}"));
        assert!(trace.len() > 50, "{force} N: {} steps", trace.len());
        assert!(trace.iter().all(|s| s.2.is_finite()), "{force} N");
        // The onboard estimator's table is built on the same rig.
        let model = Model::new(belt, base.law.clone()).unwrap();
        let options = trackbelt::estimator::BuildOptions {
            phases: 2,
            ..Default::default()
        };
        trackbelt::estimator::EstimatorTable::from_model::<{ trackbelt_host::rig::RIG_CAPACITY }>(
            &model, &config, &options,
        )
        .unwrap_or_else(|e| panic!("{force} N, estimator table: {e}"));
    }
}

#[test]
fn settling_after_a_dynamic_test_can_stop_relaxing_when_the_belt_only_creeps() {
    // The shipped E38 table with a light roller, after 10 s of the
    // dynamic test: the belt is near rest, and from rest it only creeps
    // along a soft mode, its kinetic energy never peaking, so the
    // relaxation runs all its 3000 steps (a fifth of every simulation
    // the diagnosis fits). With `relax_creep_steps` (what the diagnosis's
    // forward model sets) it hands over to the Newton polish after that
    // many such steps, and the state is still a static equilibrium, at
    // the same height to the micrometre.
    let settle = |creep: usize| {
        let base =
            trackbelt_host::catalogue::baseline(trackbelt::params::Variant::E38, None).unwrap();
        let model = Model::new(base.belt, base.law).unwrap();
        let settings = Settings {
            relax_creep_steps: creep,
            ..Settings::default()
        };
        let mut c = Box::new(ReferenceChain::new(model, settings).unwrap());
        bench::static_test(&mut *c).unwrap();
        // The dynamic test's motion, without its settle.
        c.set_roller_mass(0.25).unwrap();
        c.reset_motion();
        c.set_time(0.0);
        while c.time_s() < 10.0 {
            c.step().unwrap();
        }
        let before = c.stats().steps;
        c.solve_static().unwrap();
        let relax_steps = c.stats().steps - before;
        let (force, _) = BenchChain::<f64, 132>::static_imbalance(&mut *c).unwrap();
        println!("creep {creep}: {relax_steps} relaxation steps, imbalance {force:e}");
        // The solver's own criterion (every force below 1e-7 of the weight).
        assert!(force < 1e-7, "imbalance {force:e}");
        (relax_steps, c.a_height_m())
    };
    let (full, h_full) = settle(0);
    let (cut, h_cut) = settle(trackbelt_host::forward::RELAX_CREEP_STEPS);
    assert_eq!(full, 3000);
    assert!(cut < 1000, "{cut} relaxation steps");
    assert!((h_full - h_cut).abs() < 1e-6, "{h_full} {h_cut}");
}
