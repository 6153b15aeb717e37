//! The measured-data loop (SPEC §5, issue 6): synthetic datasets with one
//! effect switched on and not declared, with none, or with a disturbance
//! outside the catalogue; the diagnosis must name the effect (and bring the
//! residual to the noise floor), say `none`, or say `unexplained`.
//!
//! Every case writes a dataset into a temporary directory and runs the
//! diagnosis through the `trackbelt_cli` library, exactly as
//! `trackbelt diagnose DIR` does. Cases run on two threads.

use std::path::{Path, PathBuf};
use trackbelt::params::Variant;
use trackbelt_host::diagnose::{baseline, diagnose_dir, EffectKind, ResultRow};
use trackbelt_host::synth::{Disturbance, DynamicSynth, ScrollDisturbance, ScrollSynth};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("trackbelt-diag-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(dir: &Path) -> ResultRow {
    let d = diagnose_dir(dir, Variant::E38, None, &trackbelt_host::NoProgress).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    assert_eq!(d.report.results.len(), 1);
    d.report.results[0].clone()
}

#[derive(Clone, Copy, Debug)]
enum Case {
    Dyn(Option<EffectKind>, f64, f64, u64),
    DynDist(&'static str, u64),
    Scroll(Option<EffectKind>, f64, u64),
    ScrollDist(&'static str, u64),
}

fn dataset(case: Case, name: &str) -> PathBuf {
    let base = baseline(Variant::E38, None).unwrap();
    let dir = tmp(name);
    match case {
        Case::Dyn(e, m, noise, seed) => {
            let mut s = DynamicSynth::new(&base, seed);
            s.noise_mm = noise;
            if let Some(e) = e {
                s = s.with_effect(e, m);
            }
            s.write(&dir, name).unwrap();
        }
        Case::DynDist(d, seed) => {
            let mut s = DynamicSynth::new(&base, seed);
            s.disturbance = Disturbance::parse(d, 1.0);
            s.write(&dir, name).unwrap();
        }
        Case::Scroll(e, m, seed) => {
            let mut s = ScrollSynth::new(&base, seed);
            if let Some(e) = e {
                s = s.with_effect(e, m);
            }
            s.write(&dir, name).unwrap();
        }
        Case::ScrollDist(d, seed) => {
            let mut s = ScrollSynth::new(&base, seed);
            s.disturbance = ScrollDisturbance::parse(d, 1.0);
            s.write(&dir, name).unwrap();
        }
    }
    dir
}

/// Run `cases` on two threads; returns the rows in order.
fn run_all(cases: &[(&'static str, Case)]) -> Vec<ResultRow> {
    let mut out: Vec<Option<ResultRow>> = vec![None; cases.len()];
    std::thread::scope(|s| {
        let chunks: Vec<Vec<usize>> = (0..2)
            .map(|k| (k..cases.len()).step_by(2).collect())
            .collect();
        let handles: Vec<_> = chunks
            .into_iter()
            .map(|idx| {
                s.spawn(move || {
                    idx.into_iter()
                        .map(|i| {
                            let (name, case) = cases[i];
                            (i, run(&dataset(case, name)))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in handles {
            for (i, r) in h.join().unwrap() {
                out[i] = Some(r);
            }
        }
    });
    out.into_iter().map(|r| r.unwrap()).collect()
}

/// Noise floor implied by the row's evidence is not exposed; the test
/// checks "near the floor" against the synthetic noise it put in.
fn near_floor(r: &ResultRow, noise: f64) {
    assert!(
        r.rms_after <= 1.25 * noise,
        "{}: rms_after {:.3} not near the noise floor {noise}: {}",
        r.effect,
        r.rms_after,
        r.evidence
    );
}

/// The other bar for a named effect: the error cut to at most a
/// third of the baseline's.
fn cut_to_a_third(r: &ResultRow, name: &str) {
    assert!(
        r.rms_after <= r.rms_before / 3.0,
        "{name}: {} {:.3} → {:.3} {}, not cut to a third: {}",
        r.effect,
        r.rms_before,
        r.rms_after,
        r.unit,
        r.evidence
    );
}

/// The dynamic cases: clean, each effect strong (0.4 mm noise, so the
/// effect dominates: `rms_after ≤ rms_before / 3`) and the three
/// disturbances outside the catalogue. The fast tier (CI).
#[test]
fn dynamic_effects_are_named_and_explained() {
    use EffectKind::*;
    check_dynamic_cases(&[
        ("clean", Case::Dyn(None, 0.0, 1.0, 1)),
        ("jf-strong", Case::Dyn(Some(JointFriction), 4.0, 0.4, 2)),
        ("qd-strong", Case::Dyn(Some(QuadraticDamping), 6.0, 0.4, 3)),
        (
            "as-strong",
            Case::Dyn(Some(AmplitudeStiffness), 4.0, 0.4, 4),
        ),
        ("drift", Case::DynDist("camera_drift", 12)),
        ("mode", Case::DynDist("second_mode", 13)),
        ("slip", Case::DynDist("marker_slip", 14)),
    ]);
}

/// The same loop at nominal size and near the detection limit (1 mm
/// noise). The full tier (`cargo test-full`; see the README's test
/// tiers): seven more dynamic diagnoses, about 3 minutes on two threads.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn dynamic_effects_at_nominal_size_and_the_limit_are_named_or_none() {
    use EffectKind::*;
    check_dynamic_cases(&[
        // Nominal, 1 mm noise.
        ("jf-1", Case::Dyn(Some(JointFriction), 1.0, 1.0, 5)),
        ("qd-1", Case::Dyn(Some(QuadraticDamping), 1.0, 1.0, 6)),
        ("as-1", Case::Dyn(Some(AmplitudeStiffness), 1.0, 1.0, 7)),
        ("as-soft", Case::Dyn(Some(AmplitudeStiffness), -1.0, 1.0, 8)),
        // Near the detection limit (see README), 1 mm noise: named or
        // `none`, never a wrong name.
        ("jf-limit", Case::Dyn(Some(JointFriction), 0.35, 1.0, 9)),
        ("qd-limit", Case::Dyn(Some(QuadraticDamping), 0.5, 1.0, 10)),
        (
            "as-limit",
            Case::Dyn(Some(AmplitudeStiffness), 0.75, 1.0, 11),
        ),
    ]);
}

/// Diagnoses `cases` (two threads) and checks each answer: the effect
/// named and brought near the noise put in (and, at ×4 or more, cut to a
/// third), `none` for the clean belt, `unexplained` for a disturbance;
/// the `-limit`, `as-1` and `as-soft` cases may also be `none` (only for
/// an unread signature, for the cubic), never another name.
fn check_dynamic_cases(cases: &[(&'static str, Case)]) {
    let rows = run_all(cases);
    let mut failures = Vec::new();
    for ((name, case), r) in cases.iter().zip(&rows) {
        eprintln!(
            "{name}: {} {:.3} → {:.3} mm | {}",
            r.effect, r.rms_before, r.rms_after, r.evidence
        );
        // The cubic at ×1 and ×−1 with 1 mm of noise leaves its period
        // trend, the cubic's one signature, under the bar (0.3 and 0.4
        // standard errors from the baseline's): the data do not carry
        // it, and issue 11 names an effect only with its signature in
        // the data. Since session 30 a cubic on a trend that is not read
        // is not named (`diagnose_dynamic`: every such name on the
        // independent generator's data was wrong, clean 14504 and
        // quadratic damping 13602 among them), so these two may be
        // `none`, for that reason only; another name still fails. The
        // cubic whose trend is read (`as-strong`, 0.4 mm noise) must
        // still be named.
        if name.ends_with("-limit") || *name == "as-soft" || *name == "as-1" {
            let Case::Dyn(Some(e), ..) = case else {
                unreachable!()
            };
            if r.effect != e.id() && r.effect != "none" {
                failures.push(format!("{name}: wrong name {} ({})", r.effect, r.evidence));
            }
            if name.starts_with("as-")
                && r.effect == "none"
                && !r.evidence.contains("signature is not in the data")
            {
                failures.push(format!(
                    "{name}: `none` for another reason than an unread signature ({})",
                    r.evidence
                ));
            }
            continue;
        }
        let expected = match case {
            Case::Dyn(None, ..) => "none",
            Case::Dyn(Some(e), ..) => e.id(),
            _ => "unexplained",
        };
        if r.effect != expected {
            failures.push(format!(
                "{name}: expected {expected}, got {} ({})",
                r.effect, r.evidence
            ));
            continue;
        }
        assert_eq!(r.unit, "mm");
        assert_eq!(r.kind, "dynamic");
        if let Case::Dyn(Some(_), m, noise, _) = case {
            near_floor(r, *noise);
            if *m >= 4.0 {
                cut_to_a_third(r, name);
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn weak_effects_are_never_given_a_wrong_name() {
    use EffectKind::*;
    let cases: Vec<(&'static str, Case)> = vec![
        ("jf-weak", Case::Dyn(Some(JointFriction), 0.1, 1.0, 21)),
        ("qd-weak", Case::Dyn(Some(QuadraticDamping), 0.15, 1.0, 22)),
        (
            "as-weak",
            Case::Dyn(Some(AmplitudeStiffness), 0.25, 1.0, 23),
        ),
    ];
    for ((name, case), r) in cases.iter().zip(run_all(&cases)) {
        let Case::Dyn(Some(e), ..) = case else {
            unreachable!()
        };
        eprintln!("{name}: {} | {}", r.effect, r.evidence);
        assert!(
            r.effect == e.id() || r.effect == "none" || r.effect == "unexplained",
            "{name}: named {}",
            r.effect
        );
    }
}

#[test]
fn scroll_effects_are_named_or_left_unexplained() {
    use EffectKind::*;
    let cases: Vec<(&'static str, Case)> = vec![
        ("s-clean", Case::Scroll(None, 0.0, 1)),
        ("s-bearing", Case::Scroll(Some(BearingFriction), 2.0, 2)),
        (
            "s-bearing-strong",
            Case::Scroll(Some(BearingFriction), 3.0, 3),
        ),
        ("s-thermal", Case::Scroll(Some(ThermalSoftening), 1.0, 4)),
        (
            "s-thermal-strong",
            Case::Scroll(Some(ThermalSoftening), 2.0, 5),
        ),
        ("s-rate", Case::Scroll(Some(RateDependentDamping), 1.0, 6)),
        // Weak or confusable: never a wrong name.
        (
            "s-bearing-weak",
            Case::Scroll(Some(BearingFriction), 0.5, 9),
        ),
        ("s-bearing-1", Case::Scroll(Some(BearingFriction), 1.0, 10)),
        (
            "s-rate-weak",
            Case::Scroll(Some(RateDependentDamping), 0.5, 11),
        ),
        (
            "s-thermal-weak",
            Case::Scroll(Some(ThermalSoftening), 0.2, 12),
        ),
        ("s-drift", Case::ScrollDist("sensor_drift", 7)),
        ("s-periodic", Case::ScrollDist("periodic_load", 8)),
    ];
    let rows = run_all(&cases);
    let mut failures = Vec::new();
    for ((name, case), r) in cases.iter().zip(&rows) {
        eprintln!(
            "{name}: {} {:.3} → {:.3} N·m | {}",
            r.effect, r.rms_before, r.rms_after, r.evidence
        );
        assert_eq!(r.kind, "scroll");
        let ok = match case {
            Case::Scroll(None, ..) => r.effect == "none",
            // Power-law damping over 1.5–5 rad/s is nearly a constant plus a
            // linear torque (bearing friction + cz): the diagnosis may say
            // so (`unexplained`), never a wrong name. The same for weak
            // effects (`none` allowed too).
            Case::Scroll(Some(e), m, _) if *m <= 1.0 && *e != ThermalSoftening || *m < 0.5 => {
                r.effect == e.id() || r.effect == "unexplained" || r.effect == "none"
            }
            Case::Scroll(Some(RateDependentDamping), ..) => {
                r.effect == "rate_dependent_damping" || r.effect == "unexplained"
            }
            Case::Scroll(Some(e), ..) => r.effect == e.id(),
            _ => r.effect == "unexplained",
        };
        if !ok {
            failures.push(format!("{name}: got {} ({})", r.effect, r.evidence));
        }
        if let Case::Scroll(Some(e), m, _) = case {
            if r.effect == e.id() && *m >= 3.0 {
                cut_to_a_third(r, name);
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The README's two worked examples ("Worked example"): the shipped
/// datasets `data/synthetic-joint-friction` (`trackbelt synth` with joint
/// friction at magnitude 2, 1 mm of marker noise, seed 1) and
/// `data/synthetic-scroll-bearing` (bearing friction at magnitude 2, seed
/// 2) get the names the README shows, with the error brought down as it
/// says: to within 1.25 × the noise put in, and to under a third.
/// Session 58 found a rule change (per-cycle trends read on three
/// cycles) that answered `none` on the first, the name refused because
/// the candidate's trend overshot the measured one; no test had pinned
/// the README's answer.
#[test]
fn the_readmes_worked_examples_get_their_names() {
    let shipped = |name: &str| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../data")
            .join(name);
        let d = diagnose_dir(&dir, Variant::E38, None, &trackbelt_host::NoProgress).unwrap();
        assert_eq!(d.report.results.len(), 1);
        d.report.results[0].clone()
    };
    // `trackbelt synth`'s marker noise, mm.
    let noise_put_in_mm = 1.0;
    let r = shipped("synthetic-joint-friction");
    assert_eq!(r.effect, "joint_friction", "{}", r.evidence);
    near_floor(&r, noise_put_in_mm);
    candidates_back_the_name(&r);
    let r = shipped("synthetic-scroll-bearing");
    assert_eq!(r.effect, "bearing_friction", "{}", r.evidence);
    cut_to_a_third(&r, "synthetic-scroll-bearing");
    candidates_back_the_name(&r);
}

/// The row's candidate table agrees with its answer: the named effect
/// leads, supported, with the residual the row reports after; the list is
/// ranked by gain, every effect of the series' kind appears once (and the
/// refitted shape on a dynamic series), and the JSON carries it.
fn candidates_back_the_name(r: &ResultRow) {
    let c = &r.candidates;
    assert!(!c.is_empty(), "{}: no candidates", r.series);
    assert_eq!(c[0].model, r.effect, "{c:?}");
    assert_eq!(c[0].rms, r.rms_after, "{c:?}");
    assert!(
        c[0].bic_gain >= trackbelt_host::diagnose::BIC_MARGIN,
        "{c:?}"
    );
    assert!(
        c.windows(2).all(|w| w[0].bic_gain >= w[1].bic_gain),
        "{c:?}"
    );
    let n = r
        .gain_samples
        .expect("the samples the gains are counted on");
    assert!(n >= 3.0 && n.is_finite(), "{n}");
    let mut models: Vec<&str> = c.iter().map(|x| x.model.as_str()).collect();
    models.sort_unstable();
    let expected: &[&str] = if r.kind == "dynamic" {
        &[
            "amplitude_stiffness",
            "joint_friction",
            "quadratic_damping",
            "table_shape",
        ]
    } else {
        &[
            "bearing_friction",
            "rate_dependent_damping",
            "thermal_softening",
        ]
    };
    assert_eq!(models, expected, "{}", r.series);
    let j = serde_json::to_value(r).unwrap();
    assert_eq!(j["candidates"][0]["model"], r.effect.as_str());
    assert!(j["gain_samples"].is_number());
}

#[test]
fn summary_only_dataset_gets_an_answer() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/shredder-table1");
    let d = diagnose_dir(&dir, Variant::E38, None, &trackbelt_host::NoProgress).unwrap();
    assert_eq!(d.report.dataset, "shredder-table1");
    assert_eq!(d.report.results.len(), 1);
    let r = &d.report.results[0];
    eprintln!(
        "{} {} {:.1} % | {}",
        r.series, r.effect, r.rms_before, r.evidence
    );
    assert!(r.effect == "none" || r.effect == "unexplained");
    assert!(r.rms_before.is_finite() && r.unit == "%");
    // The JSON document serialises.
    let j = serde_json::to_value(&d.report).unwrap();
    assert!(j["results"][0]["evidence"].is_string());
    // No model was fitted to summary figures: no candidate table.
    assert!(r.candidates.is_empty() && r.gain_samples.is_none());
    assert!(j["results"][0]["candidates"].is_null());
}

#[test]
fn bad_dataset_is_an_error_not_a_panic() {
    let dir = tmp("missing");
    let e = diagnose_dir(&dir, Variant::E38, None, &trackbelt_host::NoProgress);
    assert!(e.is_err());
}

/// A scroll dataset that also holds the belt's static runs: the scroll
/// baseline is tried from the table calibrated on those figures (this
/// belt's own, issue 11's "the baseline is this belt, calibrated on this
/// dataset") as well as from the file's, and the one that fits the
/// series better is kept and named. The belt here is the shipped E38
/// belt made 2.5 times stiffer: its static figures calibrate a stiffer
/// table, whose rig torque follows the series more closely than the
/// file's table with its cz refitted can. Without the static runs the
/// same series is diagnosed from the file's table alone, as before.
#[test]
fn a_scroll_series_is_diagnosed_from_the_belt_its_static_runs_calibrate() {
    let base = baseline(Variant::E38, None).unwrap();
    let stiff = trackbelt_host::catalogue::scale_stiffness(&base.law, 2.5);
    let mut s = ScrollSynth::new(&base, 31);
    s.law = stiff.clone();
    s.law.damping = base.law.damping * 1.1;
    let plain = tmp("scroll-plain");
    s.write(&plain, "stiff-belt").unwrap();
    // The belt's own static figures, from the same law.
    let model = trackbelt::params::Model::new(base.belt, stiff).unwrap();
    let mut chain =
        Box::new(trackbelt::ReferenceChain::new(model, trackbelt::Settings::default()).unwrap());
    let st = trackbelt::bench::static_test(&mut *chain).unwrap();
    let mut ds = trackbelt_host::dataset::load(&plain).unwrap();
    ds.statics = [(-1.5, 2.0), (1.0, -1.0)]
        .iter()
        .enumerate()
        .map(|(i, (dh, dw))| trackbelt_host::dataset::StaticEntry {
            label: Some(format!("run-{}", i + 1)),
            hs_mm: st.hs_mm + dh,
            ws_mm: st.ws_mm + dw,
        })
        .collect();
    let with_statics = tmp("scroll-statics");
    trackbelt_host::dataset::write(&ds, &with_statics).unwrap();

    let from_file = run(&plain);
    let own = run(&with_statics);
    eprintln!(
        "file's table: {} {:.4} | {}",
        from_file.effect, from_file.rms_before, from_file.evidence
    );
    eprintln!(
        "this belt's: {} {:.4} | {}",
        own.effect, own.rms_before, own.evidence
    );
    assert!(
        !from_file.evidence.contains("baseline: "),
        "no static runs, no second table: {}",
        from_file.evidence
    );
    assert!(
        own.evidence.contains("baseline: this belt's table")
            && own
                .evidence
                .contains("recalibrated on this dataset's figures"),
        "{}",
        own.evidence
    );
    assert!(
        own.rms_before < 0.8 * from_file.rms_before,
        "this belt's table should fit its series clearly better: {:.4} against {:.4} N·m",
        own.rms_before,
        from_file.rms_before
    );
    assert!(own.effect == "none", "a clean series: {}", own.evidence);
}

/// A second table whose rig run fails is set aside, not the series'
/// end: the scroll series is diagnosed from the table that runs, as it
/// is without the second one, and the evidence says which table was set
/// aside and why. (Held-out power law 70005 with the belt's drop figures
/// beside its rig run: the table recalibrated on them did not settle on
/// the rig's wheels, and the whole dataset was an error.) With no table
/// that runs, it is an error naming the series and the table.
///
/// Until session 72 the failing table here was the baseline at a
/// thousandth of its stiffness, said to be too soft to hold the
/// pretension. It was not: it failed because the static solve stopped at
/// 2000 iterations, and at [`RIG_STATIC_ITERATIONS`] = 4000 it settles
/// (as do 10⁻⁵–10⁻¹¹ of the stiffness, checked by hand). The table that
/// fails is now one whose damping is negative, which the rig refuses.
///
/// [`RIG_STATIC_ITERATIONS`]: trackbelt::rig::RIG_STATIC_ITERATIONS
#[test]
fn a_table_that_fails_on_the_rig_is_set_aside_for_one_that_runs() {
    use trackbelt_host::diagnose::diagnose_scroll_from;
    let base = baseline(Variant::E38, None).unwrap();
    let dir = tmp("scroll-failing-table");
    ScrollSynth::new(&base, 31).write(&dir, "clean").unwrap();
    let ds = trackbelt_host::dataset::load(&dir).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let mut broken = base.clone();
    // A negative damping: the rig refuses the law (a typed error).
    broken.law.damping = -base.law.damping;
    broken.source = "a table the rig refuses".into();
    let np = &trackbelt_host::NoProgress;
    let alone = diagnose_scroll_from(&[&base], "run-1", &ds.scrolls[0], np).unwrap();
    let e = match diagnose_scroll_from(&[&broken], "run-1", &ds.scrolls[0], np) {
        Err(e) => e.to_string(),
        Ok(d) => panic!(
            "the refused table alone must fail on the rig: {}",
            d.row.evidence
        ),
    };
    assert!(
        e.contains("run-1") && e.contains("a table the rig refuses"),
        "{e}"
    );
    let both = diagnose_scroll_from(&[&base, &broken], "run-1", &ds.scrolls[0], np).unwrap();
    assert_eq!(both.row.effect, alone.row.effect);
    assert_eq!(both.row.rms_before, alone.row.rms_before);
    assert!(
        both.row
            .evidence
            .contains("this belt's table set aside: its rig run failed")
            && both.row.evidence.contains("a table the rig refuses"),
        "{}",
        both.row.evidence
    );
}
