//! The model is written once, generic over the number type: the same code
//! runs the static test in f32. (The embedded-build bounds against f64 — Hs
//! and Hd within 1 mm, T within 1 % — and the fixed-point build are the
//! embedded-build issue's.)

use trackbelt::params::{Method, Model, Variant};
use trackbelt::{bench, Chain, Real, Settings};

fn static_hs<T: Real>() -> f64 {
    let model: Model<T> = Model::<f64>::paper(Variant::E38, Method::I).unwrap().cast();
    let mut chain = Box::new(Chain::<T, 44>::new(model, Settings::default()).unwrap());
    bench::static_test(&mut *chain).unwrap().hs_mm
}

#[test]
fn static_test_runs_in_f32_through_the_same_code() {
    let reference = static_hs::<f64>();
    let single = static_hs::<f32>();
    assert!(
        (single - reference).abs() < 1.0,
        "f32 Hs {single} vs f64 {reference}"
    );
}
