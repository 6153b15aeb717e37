//! Physics oracles and dataset checks for the truth generator. Kept small
//! (few nodes, short runs) so that they run quickly in a debug build.

use std::path::{Path, PathBuf};
use trackbelt_truth::chain::Chain;
use trackbelt_truth::drop::{Contact, DropConfig};
use trackbelt_truth::law::{BendingLaw, DampingLaw, FrictionLaw, Material};
use trackbelt_truth::scenario::Test;
use trackbelt_truth::*;

fn linear_material(ei_factor: f64) -> Material {
    Material {
        elastic: BendingLaw::shredder().scaled(ei_factor, 1.0),
        damping: DampingLaw::Linear {
            c: BendingLaw::SHREDDER_DAMPING * ei_factor,
        },
        friction: FrictionLaw::None,
        payne: None,
        thermal: None,
    }
}

fn shredder_drop(n: usize, ei_factor: f64) -> DropConfig {
    DropConfig {
        length_m: 2.45,
        thickness_m: 0.008,
        mass_kg: 6.4,
        nodes: n,
        ea_n: 5e4,
        material: linear_material(ei_factor),
        ei_scale: vec![1.0; n],
        floor: Contact::floor(),
    }
}

/// A fresh, empty directory under the system's temp dir.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("truth-test-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Shrink a drawn scenario so it runs fast in a debug build.
fn small(mut sc: Scenario) -> Scenario {
    sc.nodes = 20;
    match &mut sc.test {
        Test::Dynamic(d) => d.duration_s = 2.0,
        Test::Scroll(r) => {
            r.duration_s = 2.0;
            r.profile = vec![(0.0, 0.0), (0.5, 3.0), (1.2, 3.0), (1.6, 1.5), (2.0, 1.5)];
        }
    }
    sc
}

#[test]
fn law_is_smooth_asymmetric_and_consistent() {
    let l = BendingLaw::shredder();
    assert_eq!(l.moment(0.0), 0.0);
    // Monotone, with the tangent the derivative of the moment.
    let mut last = l.moment(-20.0);
    for i in -199..=200 {
        let k = i as f64 * 0.1;
        let m = l.moment(k);
        assert!(m > last, "moment not increasing at {k}");
        last = m;
        let d = (l.moment(k + 1e-5) - l.moment(k - 1e-5)) / 2e-5;
        assert!(
            (d - l.tangent(k)).abs() < 1e-4 * d.abs().max(1.0),
            "tangent at {k}"
        );
    }
    // Asymmetric: back-bending is stiffer than wrapping by the same amount.
    assert!(-l.moment(-2.0) > 1.5 * l.moment(2.0));
    // Not a scale of a linear law: the secant stiffness varies.
    assert!(l.moment(12.0) / 12.0 > 1.5 * l.moment(4.0) / 4.0);
}

#[test]
fn free_ring_energy_decays_without_drift() {
    // A circle of the belt's length in zero gravity is an equilibrium for
    // any bending law (uniform curvature); kick it and watch the energy.
    let n = 24;
    let l = 2.45;
    let rc = l / n as f64 / (2.0 * (std::f64::consts::PI / n as f64).sin());
    let x: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let p = std::f64::consts::TAU * i as f64 / n as f64;
            [rc * p.cos(), rc * p.sin()]
        })
        .collect();
    let mat = linear_material(1.0);
    let mut ch = Chain::new(x, l / n as f64, 0.004, 6.4, 5e4, vec![1.0; n]);
    // A shape-changing kick with zero net momentum (mode 2).
    for i in 0..n {
        let p = std::f64::consts::TAU * i as f64 / n as f64;
        ch.v[i] = [
            0.2 * (2.0 * p).cos() * p.cos(),
            0.2 * (2.0 * p).cos() * p.sin(),
        ];
    }
    let h = ch.stable_step(
        mat.elastic.max_tangent(),
        mat.damping.max_slope(),
        0.0,
        0.0,
        0.6,
    );
    ch.internal_forces(&mat, 1.0, 1.0);
    let e0 = ch.kinetic_energy() + ch.elastic_energy(&mat);
    let mut prev = e0;
    let steps = (1.0 / h) as usize;
    for s in 0..steps {
        ch.internal_forces(&mat, 1.0, 1.0);
        ch.advance(h);
        if s % 50 == 0 {
            let e = ch.kinetic_energy() + ch.elastic_energy(&mat);
            assert!(
                e <= prev * (1.0 + 1e-3) + 1e-9,
                "energy rose at step {s}: {prev} -> {e}"
            );
            prev = e;
        }
    }
    let e1 = ch.kinetic_energy() + ch.elastic_energy(&mat);
    let e_ring = {
        let mut c = ch.clone();
        for v in c.v.iter_mut() {
            *v = [0.0; 2];
        }
        // Elastic energy of the perfect circle.
        let k = 2.0 * (std::f64::consts::PI / n as f64) / (l / n as f64);
        l * mat.elastic.energy_density(k)
    };
    assert!(ch.is_finite());
    assert!(
        e1 - e_ring < 0.5 * (e0 - e_ring),
        "energy above the circle's did not halve: {e0} -> {e1} (circle {e_ring})"
    );
    // No drift of the centre of mass.
    let cx = ch.x.iter().map(|p| p[0]).sum::<f64>() / n as f64;
    let cy = ch.x.iter().map(|p| p[1]).sum::<f64>() / n as f64;
    assert!(
        cx.abs() < 1e-6 && cy.abs() < 1e-6,
        "centre drifted to ({cx}, {cy})"
    );
}

#[test]
fn settled_ring_stays_at_rest() {
    let cfg = shredder_drop(20, 1.0);
    let s = cfg.settle(0).unwrap();
    // A feather of a roller: the ring must stay where it settled.
    let run = cfg.drop(&s, 1e-4, 0.04, 1.0, 0.01).unwrap();
    let lo = run.a_height_m.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = run
        .a_height_m
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        hi - s.hs_m < 5e-4 && s.hs_m - lo < 5e-4,
        "A moved: {lo}..{hi} vs {}",
        s.hs_m
    );
    let dx = run
        .a_x_m
        .iter()
        .map(|x| (x - run.a_x_m[0]).abs())
        .fold(0.0, f64::max);
    assert!(dx < 5e-4, "A drifted sideways by {dx} m");
    // The flattened ring: far below the circle's 780 mm, wider than it.
    assert!(s.hs_m > 0.2 && s.hs_m < 0.6, "Hs {}", s.hs_m);
    assert!(s.ws_m > 0.8, "Ws {}", s.ws_m);
}

#[test]
fn static_figures_scale_with_bending_stiffness() {
    let soft = shredder_drop(20, 0.5).settle(0).unwrap();
    let base = shredder_drop(20, 1.0).settle(0).unwrap();
    let stiff = shredder_drop(20, 2.0).settle(0).unwrap();
    assert!(
        soft.hs_m < base.hs_m && base.hs_m < stiff.hs_m,
        "Hs {} {} {}",
        soft.hs_m,
        base.hs_m,
        stiff.hs_m
    );
    assert!(
        soft.ws_m > base.ws_m && base.ws_m > stiff.ws_m,
        "Ws {} {} {}",
        soft.ws_m,
        base.ws_m,
        stiff.ws_m
    );
}

/// Period of the ovalising mode (n = 2) of a free ring in zero gravity
/// with a constant bending stiffness `ei`, from the radius at node 0.
fn free_ring_period(ei: f64) -> f64 {
    let n = 32;
    let l = 2.45;
    let rc = l / n as f64 / (2.0 * (std::f64::consts::PI / n as f64).sin());
    let x: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let p = std::f64::consts::TAU * i as f64 / n as f64;
            [rc * p.cos(), rc * p.sin()]
        })
        .collect();
    let mat = Material {
        elastic: BendingLaw {
            ei_soft: ei,
            ei_zero: ei,
            kappa_t: 1.0,
            ei_hard: 0.0,
            kappa_h: 10.0,
            w_h: 1.0,
            ei_back: ei,
            kappa_b: 1.0,
            w_b: 1.0,
        },
        damping: DampingLaw::Linear { c: 0.0 },
        friction: FrictionLaw::None,
        payne: None,
        thermal: None,
    };
    let mut ch = Chain::new(x, l / n as f64, 0.004, 6.4, 1e6, vec![1.0; n]);
    for i in 0..n {
        let p = std::f64::consts::TAU * i as f64 / n as f64;
        let vr = 0.02 * (2.0 * p).cos();
        ch.v[i] = [vr * p.cos(), vr * p.sin()];
    }
    let h = ch.stable_step(ei, 0.0, 0.0, 0.0, 0.6);
    let mut crossings = Vec::new();
    let mut last = 0.0;
    let mut t = 0.0;
    while crossings.len() < 3 && t < 20.0 {
        ch.internal_forces(&mat, 1.0, 1.0);
        ch.advance(h);
        t += h;
        let r = (ch.x[0][0] * ch.x[0][0] + ch.x[0][1] * ch.x[0][1]).sqrt() - rc;
        if last > 0.0 && r <= 0.0 {
            crossings.push(t);
        }
        last = r;
    }
    assert_eq!(crossings.len(), 3);
    0.5 * (crossings[2] - crossings[0])
}

#[test]
fn ring_mode_period_follows_bending_stiffness() {
    // Inextensible thin ring: ω₂ = (n(n²−1)/√(n²+1))·√(EI/(ρ·R⁴)), n = 2.
    let (l, m) = (2.45, 6.4);
    let r = l / std::f64::consts::TAU;
    let analytic =
        |ei: f64| std::f64::consts::TAU / (6.0 / 5f64.sqrt() * (ei / (m / l * r.powi(4))).sqrt());
    let (t1, t4) = (free_ring_period(0.5), free_ring_period(2.0));
    assert!(
        (t1 / analytic(0.5) - 1.0).abs() < 0.03,
        "T {t1} vs analytic {}",
        analytic(0.5)
    );
    // Four times the stiffness: half the period.
    assert!((t4 / t1 - 0.5).abs() < 0.01, "T {t1} at EI, {t4} at 4·EI");
}

#[test]
fn shredder_meets_table_one_roughly() {
    // Coarse here (20 nodes, debug build); the crate docs give the 26–36-node figures.
    let cfg = shredder_drop(20, 1.0);
    let s = cfg.settle(0).unwrap();
    let run = cfg.drop(&s, 1.3, 0.05, 3.0, 0.001).unwrap();
    let (t, lam) = run.period_and_decrement().unwrap();
    let near = |x: f64, want: f64, rel: f64| (x / want - 1.0).abs() < rel;
    assert!(near(s.hs_m * 1e3, 324.0, 0.08), "Hs {}", s.hs_m);
    assert!(near(s.ws_m * 1e3, 1062.0, 0.04), "Ws {}", s.ws_m);
    assert!(near(run.hd_m * 1e3, 225.0, 0.12), "Hd {}", run.hd_m);
    assert!(near(t, 0.74, 0.15), "T {t}");
    assert!(near(lam, 0.73, 0.3), "Λ {lam}");
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

fn check_csv(path: &Path, header: &[&str]) -> usize {
    let text = read(path);
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    for h in header {
        assert!(head.contains(h), "{} lacks column {h}", path.display());
    }
    let mut rows = 0;
    let mut last_t = f64::NEG_INFINITY;
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|c| c.parse::<f64>().unwrap()).collect();
        assert_eq!(v.len(), head.len());
        assert!(v.iter().all(|x| x.is_finite()), "non-finite row {l}");
        assert!(v[0] > last_t, "time not increasing at {l}");
        last_t = v[0];
        rows += 1;
    }
    rows
}

fn check_dataset(dir: &Path) -> toml::Table {
    let text = read(&dir.join("dataset.toml"));
    // Nothing may hint at the outcome.
    for e in EffectKind::ALL {
        assert!(!text.contains(e.as_str()), "manifest names {}", e.as_str());
    }
    for d in DisturbanceKind::ALL {
        assert!(!text.contains(d.as_str()), "manifest names {}", d.as_str());
    }
    let t: toml::Table = text.parse().unwrap();
    assert_eq!(t["format"].as_integer(), Some(1));
    assert!(t["name"].is_str());
    let belt = t["belt"].as_table().unwrap();
    for k in ["length_mm", "width_mm", "thickness_mm", "mass_kg"] {
        let v = belt[k]
            .as_float()
            .or(belt[k].as_integer().map(|i| i as f64))
            .unwrap();
        assert!(v > 0.0, "{k}");
    }
    t
}

fn num(v: &toml::Value) -> f64 {
    v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap()
}

#[test]
fn dynamic_dataset_is_well_formed_and_deterministic() {
    let sc = small(
        draw(
            Outcome::Effect(EffectKind::JointFriction),
            SeriesKind::Dynamic,
            5,
        )
        .unwrap(),
    );
    let (a, b) = (scratch("dyn-a"), scratch("dyn-b"));
    let ta = generate(&sc, &a).unwrap();
    let tb = generate(&sc, &b).unwrap();
    assert_eq!(
        ta,
        Truth {
            files: ta.files.clone(),
            ..tb.clone()
        }
    );
    for f in ["dataset.toml", "dynamic-1.csv"] {
        assert_eq!(
            read(&a.join(f)),
            read(&b.join(f)),
            "{f} differs between two runs"
        );
    }
    let t = check_dataset(&a);
    assert!(!t["static"].as_array().unwrap().is_empty());
    for s in t["static"].as_array().unwrap() {
        assert!(num(&s["hs_mm"]) > 0.0 && num(&s["ws_mm"]) > 0.0);
    }
    let d = &t["dynamic"].as_array().unwrap()[0];
    assert!(num(&d["roller_kg"]) > 0.0);
    let series = a.join(d["series"].as_str().unwrap());
    let rows = check_csv(&series, &["t_s", "a_height_mm"]);
    assert!(rows > 40, "{rows} rows");
    assert!(
        ta.noise_rms > 0.3 && ta.noise_rms < 2.0,
        "noise {}",
        ta.noise_rms
    );
    // A different seed gives another dataset.
    let sc2 = small(
        draw(
            Outcome::Effect(EffectKind::JointFriction),
            SeriesKind::Dynamic,
            6,
        )
        .unwrap(),
    );
    assert_ne!(sc, sc2);
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

#[test]
fn scroll_dataset_is_well_formed() {
    let sc = small(
        draw(
            Outcome::Effect(EffectKind::ThermalSoftening),
            SeriesKind::Scroll,
            9,
        )
        .unwrap(),
    );
    let d = scratch("scroll");
    let truth = generate(&sc, &d).unwrap();
    let t = check_dataset(&d);
    let s = &t["scroll"].as_array().unwrap()[0];
    for k in [
        "drive_diameter_mm",
        "idler_diameter_mm",
        "center_distance_mm",
        "idler_force_n",
    ] {
        assert!(num(&s[k]) > 0.0, "{k}");
    }
    let rows = check_csv(
        &d.join(s["series"].as_str().unwrap()),
        &["t_s", "omega_rad_s", "torque_nm", "belt_temp_c"],
    );
    assert!(rows > 30, "{rows} rows");
    assert!(truth.figures.mean_torque_nm.unwrap() > 0.0);
    assert_eq!(truth.expected, "thermal_softening");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn every_outcome_draws_in_its_kinds_only() {
    let mut outcomes = vec![Outcome::None];
    outcomes.extend(EffectKind::ALL.iter().map(|&e| Outcome::Effect(e)));
    outcomes.extend(
        DisturbanceKind::ALL
            .iter()
            .map(|&d| Outcome::Disturbance(d)),
    );
    for o in outcomes {
        for k in [SeriesKind::Dynamic, SeriesKind::Scroll] {
            let r = draw(o, k, 3);
            assert_eq!(r.is_ok(), o.kinds().contains(&k), "{o:?} in {k:?}");
            if let Ok(sc) = r {
                assert_eq!(sc.kind(), k);
                assert_eq!(sc, draw(o, k, 3).unwrap(), "draw is not deterministic");
            }
        }
    }
}

#[test]
fn refuses_a_non_empty_directory() {
    let d = scratch("busy");
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("x"), "x").unwrap();
    let sc = small(draw(Outcome::None, SeriesKind::Dynamic, 1).unwrap());
    assert!(matches!(generate(&sc, &d), Err(Error::NotEmpty(_))));
    let _ = std::fs::remove_dir_all(&d);
}
