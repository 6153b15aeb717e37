//! Bad parameters and inputs are typed errors naming the field, never a
//! panic or a hang (the CLI side is tested in `cli/tests/cli.rs`).

use trackbelt::bench::{dynamic_test, DynamicTest};
use trackbelt::joint::JointLaw;
use trackbelt::params::{Belt, Method, Model, Variant};
use trackbelt::stiffness::{Stiffness, TorqueTable};
use trackbelt::{Chain, Error, ReferenceChain, Settings};

fn law() -> JointLaw<f64> {
    trackbelt::params::paper::joint_law(Variant::E38, Method::I).unwrap()
}

fn field_of(e: Error) -> &'static str {
    match e {
        Error::InvalidParameter { field, .. } => field,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn non_positive_or_nan_belt_parameters_name_the_field() {
    let mut b = Belt::<f64>::shredder(38);
    b.mass_kg = 0.0;
    assert_eq!(field_of(Model::new(b, law()).unwrap_err()), "belt.mass_kg");
    b = Belt::shredder(38);
    b.length_m = -2.45;
    assert_eq!(field_of(Model::new(b, law()).unwrap_err()), "belt.length_m");
    b = Belt::shredder(38);
    b.thickness_m = f64::NAN;
    assert_eq!(
        field_of(Model::new(b, law()).unwrap_err()),
        "belt.thickness_m"
    );
    b = Belt::shredder(2);
    assert_eq!(field_of(Model::new(b, law()).unwrap_err()), "belt.links");
    let mut m = Model::paper(Variant::E38, Method::I).unwrap();
    m.floor.friction = f64::NAN;
    assert_eq!(field_of(m.validate().unwrap_err()), "floor.friction");
    assert!(JointLaw::new(Stiffness::Constant { kz: f64::NAN }, 0.1).is_err());
    assert!(JointLaw::new(Stiffness::Constant { kz: 1.0 }, f64::INFINITY).is_err());
}

#[test]
fn bad_tables_are_rejected() {
    assert!(TorqueTable::<f64>::new(&[], &[]).is_err());
    assert!(
        TorqueTable::new(&[-0.2, -0.3], &[-1.0, -2.0]).is_err(),
        "non-monotone angles"
    );
    assert!(
        TorqueTable::new(&[-0.3, -0.2], &[-1.0, -2.0]).is_err(),
        "falling torque"
    );
    assert!(TorqueTable::new(&[-0.3, f64::NAN], &[-1.0, -2.0]).is_err());
}

#[test]
fn links_over_capacity_is_a_capacity_error() {
    let model = Model::new(Belt::shredder(200), law()).unwrap();
    match ReferenceChain::new(model, Settings::default()) {
        Err(Error::Capacity {
            requested,
            capacity,
            ..
        }) => {
            assert_eq!(requested, 204);
            assert_eq!(capacity, 132);
        }
        Err(e) => panic!("expected a capacity error, got {e:?}"),
        Ok(_) => panic!("expected a capacity error"),
    }
    let small = Model::new(Belt::shredder(38), law()).unwrap();
    assert!(Chain::<f64, 40>::new(small, Settings::default()).is_err());
}

#[test]
fn non_finite_run_time_inputs_are_errors_not_hangs() {
    let model = Model::paper(Variant::E38, Method::I).unwrap();
    let mut chain = Box::new(ReferenceChain::new(model, Settings::default()).unwrap());
    assert!(chain.step_max(f64::NAN).is_err());
    assert!(chain.step_max(-1.0).is_err());
    assert!(chain.set_roller_mass(f64::NAN).is_err());
    let t = DynamicTest {
        roller_kg: 1.3,
        duration_s: f64::INFINITY,
    };
    assert!(dynamic_test(&mut *chain, &t, |_| {}).is_err());
    let t = DynamicTest {
        roller_kg: f64::NAN,
        duration_s: 1.0,
    };
    assert!(dynamic_test(&mut *chain, &t, |_| {}).is_err());
    let bad = Settings {
        step_s: f64::NAN,
        ..Settings::default()
    };
    let model = Model::paper(Variant::E38, Method::I).unwrap();
    assert!(ReferenceChain::new(model, bad).is_err());
}

#[test]
fn joint_angles_sum_to_minus_two_pi() {
    let model = Model::paper(Variant::E56, Method::I).unwrap();
    let mut chain = Box::new(ReferenceChain::new(model, Settings::default()).unwrap());
    trackbelt::bench::static_test(&mut *chain).unwrap();
    let sum: f64 = (0..chain.links()).map(|j| chain.joint_angle(j)).sum();
    assert!((sum + std::f64::consts::TAU).abs() < 1e-9, "sum {sum}");
    // The closing joint (A, at the top) is straight-ish; C is bent the way the belt wraps.
    assert!(chain.joint_angle(0).abs() < 0.2);
}
