//! The floor's stiffness and friction are not in the paper; the figures
//! must barely depend on them: over a decade of each, Hs and Hd move by
//! under 2 mm.

use trackbelt::bench::DynamicTest;
use trackbelt::params::{Method, Model, Variant};
use trackbelt::Settings;
use trackbelt_host::sim::{simulate, SimOutput, Tests};

fn run(stiffness: f64, friction: f64) -> SimOutput {
    let mut model = Model::paper(Variant::E38, Method::I).unwrap();
    model.floor.stiffness_n_per_m = stiffness;
    model.floor.friction = friction;
    simulate(
        model,
        Method::I,
        Tests::Both,
        Settings::default(),
        DynamicTest::default(),
    )
    .unwrap()
    .0
}

#[test]
fn floor_stiffness_and_friction_over_a_decade_move_heights_by_under_2_mm() {
    let base = run(1.0e5, 0.6);
    for (k, mu) in [(1.0e4, 0.6), (1.0e6, 0.6), (1.0e5, 0.1), (1.0e5, 1.0)] {
        let o = run(k, mu);
        let dhs = (o.hs_mm - base.hs_mm).abs();
        let dhd = (o.hd_mm.unwrap() - base.hd_mm.unwrap()).abs();
        assert!(dhs < 2.0, "k {k} μ {mu}: Hs moved {dhs:.2} mm");
        assert!(dhd < 2.0, "k {k} μ {mu}: Hd moved {dhd:.2} mm");
    }
}
