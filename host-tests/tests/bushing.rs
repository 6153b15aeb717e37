//! The paper's literal bushing joint (eqs. 1–3: 1e8 N/m, 1e6 N·s/m) against
//! the exact-pin model: the bench figures agree within 1 % (SPEC §1), the
//! joints stretch by micrometres.

use trackbelt::bench::{self, BenchFigures, DynamicTest};
use trackbelt::joint::JointLaw;
use trackbelt::params::{Method, Model, Variant};
use trackbelt::stiffness::Stiffness;
use trackbelt::{Bushing, ReferenceBushingChain, ReferenceChain, Settings};

/// The bushing chain is about 1.3 MB: run on a thread with a large stack.
fn big_stack<R: Send + 'static>(f: impl FnOnce() -> R + Send + 'static) -> R {
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(f)
        .expect("spawn")
        .join()
        .expect("join")
}

struct Pair {
    pin: BenchFigures,
    bushing: BenchFigures,
    static_stretch_um: f64,
    loaded_stretch_um: f64,
    max_run_stretch_um: f64,
}

fn run_pair(v: Variant, m: Method) -> Pair {
    big_stack(move || {
        let model = Model::paper(v, m).unwrap();
        let mut pin = Box::new(ReferenceChain::new(model.clone(), Settings::default()).unwrap());
        let pin = bench::run(&mut *pin, &DynamicTest::default(), |_| {}).unwrap();
        let mut b = Box::new(
            ReferenceBushingChain::new(model, Bushing::paper(), Settings::default()).unwrap(),
        );
        let st = bench::static_test(&mut *b).unwrap();
        let static_stretch_um = b.max_stretch_m() * 1e6;
        let mut run_max = 0.0f64;
        let dy = bench::dynamic_test(&mut *b, &DynamicTest::default(), |c| {
            run_max = run_max.max(c.max_stretch_m());
        })
        .unwrap();
        Pair {
            pin,
            bushing: BenchFigures {
                static_test: st,
                dynamic_test: dy,
            },
            static_stretch_um,
            loaded_stretch_um: b.max_stretch_m() * 1e6,
            max_run_stretch_um: run_max * 1e6,
        }
    })
}

fn rel_pct(a: f64, b: f64) -> f64 {
    100.0 * (a - b) / b
}

fn check(v: Variant, m: Method) {
    let p = run_pair(v, m);
    let (a, b) = (&p.pin, &p.bushing);
    let t_pin = a.dynamic_test.period_s.expect("pin period");
    let t_b = b.dynamic_test.period_s.expect("bushing period");
    let figs = [
        ("Hs", a.static_test.hs_mm, b.static_test.hs_mm),
        ("Ws", a.static_test.ws_mm, b.static_test.ws_mm),
        ("Hd", a.dynamic_test.hd_mm, b.dynamic_test.hd_mm),
        ("Wd", a.dynamic_test.wd_mm, b.dynamic_test.wd_mm),
        ("T", t_pin, t_b),
    ];
    println!(
        "{} method {}: figure  pin  bushing  diff %",
        v.name(),
        m.name()
    );
    for (name, x, y) in figs {
        println!("  {name:<3} {x:10.4} {y:10.4} {:+8.4}", rel_pct(y, x));
    }
    println!(
        "  Λ   {:10.4} {:10.4}",
        a.dynamic_test.log_decrement.unwrap_or(f64::NAN),
        b.dynamic_test.log_decrement.unwrap_or(f64::NAN)
    );
    println!(
        "  stretch µm: static {:.3}, loaded settled {:.3}, largest during the run {:.3}",
        p.static_stretch_um, p.loaded_stretch_um, p.max_run_stretch_um
    );
    for (name, x, y) in figs {
        assert!(
            rel_pct(y, x).abs() < 1.0,
            "{} method {}: {name} pin {x} bushing {y}",
            v.name(),
            m.name()
        );
    }
    // Micrometres, not millimetres: the bushing is a stiff pin.
    assert!(p.max_run_stretch_um > 0.0 && p.max_run_stretch_um < 50.0);
}

#[test]
fn bushing_agrees_with_pins_e38_method_one() {
    check(Variant::E38, Method::I);
}

#[test]
fn bushing_agrees_with_pins_e38_method_two() {
    check(Variant::E38, Method::II);
}

#[test]
fn bushing_agrees_with_pins_e56_e76_both_methods() {
    for v in [Variant::E56, Variant::E76] {
        for m in [Method::I, Method::II] {
            check(v, m);
        }
    }
}

/// From the same settled shape, the two joint models find the same
/// equilibrium to micrometres: the sub-percent differences of the static
/// test above come from the chain's nearby equilibria (README), not from
/// the bushing.
#[test]
fn same_equilibrium_from_the_same_shape() {
    big_stack(|| {
        for m in [Method::I, Method::II] {
            let model = Model::paper(Variant::E38, m).unwrap();
            let mut pin =
                Box::new(ReferenceChain::new(model.clone(), Settings::default()).unwrap());
            let st = bench::static_test(&mut *pin).unwrap();
            let mut b = Box::new(
                ReferenceBushingChain::new(model, Bushing::paper(), Settings::default()).unwrap(),
            );
            b.set_shape_from_pins(&pin).unwrap();
            b.solve_static().unwrap();
            let (hs, ws) = (b.a_height_m() * 1e3, b.width_m() * 1e3);
            println!(
                "E38 method {}: pin Hs {:.5} Ws {:.5}; bushing Hs {hs:.5} Ws {ws:.5} mm; stretch {:.3} µm",
                m.name(),
                st.hs_mm,
                st.ws_mm,
                b.max_stretch_m() * 1e6
            );
            assert!((hs - st.hs_mm).abs() < 0.01, "Hs {hs} vs {}", st.hs_mm);
            assert!((ws - st.ws_mm).abs() < 0.01, "Ws {ws} vs {}", st.ws_mm);
        }
    });
}

#[test]
fn shape_transfer_rejects_a_different_link_count() {
    big_stack(|| {
        let pin = Box::new(
            ReferenceChain::new(
                Model::paper(Variant::E56, Method::I).unwrap(),
                Settings::default(),
            )
            .unwrap(),
        );
        let mut b = Box::new(
            ReferenceBushingChain::new(
                Model::paper(Variant::E38, Method::I).unwrap(),
                Bushing::paper(),
                Settings::default(),
            )
            .unwrap(),
        );
        assert!(b.set_shape_from_pins(&pin).is_err());
    });
}

/// The reference build holds 128 links (E76's law scaled to the shorter
/// links), agreeing with the pin model there too; one more link is a typed
/// capacity error.
#[test]
fn reference_capacity_is_128_links() {
    big_stack(|| {
        let scale = 128.0 / 76.0;
        let law = match trackbelt::params::paper::joint_law(Variant::E76, Method::I).unwrap() {
            JointLaw {
                stiffness: Stiffness::Constant { kz },
                damping,
                ..
            } => JointLaw::new(Stiffness::Constant { kz: kz * scale }, damping * scale).unwrap(),
            other => panic!("method I is a constant stiffness: {other:?}"),
        };
        let model = |n| Model::new(trackbelt::params::Belt::shredder(n), law.clone()).unwrap();
        let mut pin = Box::new(ReferenceChain::new(model(128), Settings::default()).unwrap());
        let p = bench::static_test(&mut *pin).unwrap();
        let mut b = Box::new(
            ReferenceBushingChain::new(model(128), Bushing::paper(), Settings::default()).unwrap(),
        );
        let st = bench::static_test(&mut *b).unwrap();
        println!(
            "N = 128: pin {p:?}, bushing {st:?}, stretch {:.3} µm",
            b.max_stretch_m() * 1e6
        );
        assert!(rel_pct(st.hs_mm, p.hs_mm).abs() < 1.0, "{st:?} vs {p:?}");
        assert!(rel_pct(st.ws_mm, p.ws_mm).abs() < 1.0, "{st:?} vs {p:?}");
        assert!(b.max_stretch_m() < 1e-5);
        assert!(matches!(
            ReferenceBushingChain::new(model(129), Bushing::paper(), Settings::default()),
            Err(trackbelt::Error::Capacity { .. })
        ));
    });
}
