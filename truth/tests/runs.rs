//! Several runs of one belt in one dataset (`Scenario::repeat`,
//! `generate_runs`): the first run is the single-run dataset, byte for
//! byte; the repeats keep the belt and the bench and draw their own set-up
//! and noise.

use trackbelt_truth::scenario::Test;
use trackbelt_truth::{
    draw, generate, generate_runs, DisturbanceKind, EffectKind, Outcome, SeriesKind,
};

fn entries(toml: &str, table: &str) -> usize {
    toml.lines().filter(|l| l.trim() == table).count()
}

#[test]
fn a_drop_test_dataset_of_three_runs_starts_with_the_single_run_dataset() {
    let sc = draw(
        Outcome::Effect(EffectKind::JointFriction),
        SeriesKind::Dynamic,
        65001,
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one");
    let three = dir.path().join("three");
    let single = generate(&sc, &one).unwrap();
    let runs: Vec<_> = (0..3).map(|r| sc.repeat(r)).collect();
    let multi = generate_runs(&runs, &three).unwrap();
    let read = |p: std::path::PathBuf| std::fs::read_to_string(p).unwrap();
    // The first run's series is the single-run dataset's, byte for byte;
    // the others are their own.
    let first = read(one.join("dynamic-1.csv"));
    assert_eq!(read(three.join("dynamic-1.csv")), first);
    assert_ne!(read(three.join("dynamic-2.csv")), first);
    assert_ne!(
        read(three.join("dynamic-3.csv")),
        read(three.join("dynamic-2.csv"))
    );
    // One belt, its static figures once, three drop tests.
    let toml = read(three.join("dataset.toml"));
    let single_toml = read(one.join("dataset.toml"));
    assert!(toml.starts_with(single_toml.trim_end()), "{toml}");
    assert_eq!(entries(&toml, "[[dynamic]]"), 3);
    assert_eq!(
        entries(&toml, "[[static]]"),
        entries(&single_toml, "[[static]]")
    );
    for k in 1..=3 {
        assert!(
            toml.contains(&format!("series = \"dynamic-{k}.csv\"")),
            "{toml}"
        );
    }
    assert_eq!(multi.files.len(), 4);
    assert_eq!(multi.figures, single.figures);
    assert!(
        multi.description.ends_with("; 3 runs"),
        "{}",
        multi.description
    );
    // Each repeat carries another roller on the same belt and law.
    let rollers: Vec<f64> = runs
        .iter()
        .map(|r| match &r.test {
            Test::Dynamic(d) => d.roller_kg,
            Test::Scroll(_) => f64::NAN,
        })
        .collect();
    assert!(
        rollers[1] != rollers[0] && rollers[2] != rollers[1],
        "{rollers:?}"
    );
    assert!(runs
        .iter()
        .all(|r| r.belt == sc.belt && r.material == sc.material));
    // The noise put in is the RMS over the three runs': each camera
    // draws 0.5–1.5 mm.
    assert!((0.4..1.6).contains(&multi.noise_rms), "{}", multi.noise_rms);
}

#[test]
fn rig_repeats_keep_the_rig_and_the_disturbance_and_change_the_profile() {
    let sc = draw(
        Outcome::Disturbance(DisturbanceKind::WheelRunout),
        SeriesKind::Scroll,
        65002,
    )
    .unwrap();
    let again = sc.repeat(2);
    let (Test::Scroll(a), Test::Scroll(b)) = (&sc.test, &again.test) else {
        panic!("not rig tests");
    };
    assert_eq!(
        (
            a.drive_d_m,
            a.idler_d_m,
            a.idler_force_n,
            a.duration_s,
            a.logger
        ),
        (
            b.drive_d_m,
            b.idler_d_m,
            b.idler_force_n,
            b.duration_s,
            b.logger
        )
    );
    assert_ne!(a.profile, b.profile);
    assert_eq!(again.disturbance, sc.disturbance);
    assert_eq!(sc.repeat(2), again, "a repeat is drawn from the seed alone");
}

#[test]
fn runs_of_other_belts_are_refused_and_nothing_is_written() {
    let a = draw(Outcome::None, SeriesKind::Scroll, 65003).unwrap();
    let b = draw(Outcome::None, SeriesKind::Scroll, 65004).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mixed");
    let e = generate_runs(&[a.clone(), b], &out).unwrap_err();
    assert!(e.to_string().contains("not a repeat of the first"), "{e}");
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    assert!(generate_runs(&[], &out).is_err());
    let d = draw(Outcome::None, SeriesKind::Dynamic, 65003).unwrap();
    assert!(
        generate_runs(&[a, d], &out).is_err(),
        "a drop test beside a rig run"
    );
}

#[test]
fn a_run_listed_twice_is_refused_and_nothing_is_written() {
    let a = draw(Outcome::None, SeriesKind::Scroll, 65003).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("twice");
    let e = generate_runs(&[a.clone(), a.repeat(1), a.repeat(1)], &out).unwrap_err();
    assert!(
        e.to_string()
            .contains("run 1 is listed twice (positions 2 and 3)"),
        "{e}"
    );
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    // The first run listed again is refused as well.
    assert!(generate_runs(&[a.clone(), a.clone()], &out).is_err());
    // Distinct run numbers are fine.
    generate_runs(&[a.clone(), a.repeat(1)], &out).unwrap();
}

/// A rig dataset's belt on the floor (`Scenario::drop_test_beside`,
/// `drop_figures`): the same belt and bending law, the rig's bearing left
/// out, a roller of its own; its figures are static repeats and one drop
/// test's summary without a series, and the drop test is the same one
/// whatever the rig run drew.
#[test]
fn a_rig_belt_s_drop_figures_are_static_repeats_and_one_summary_without_a_series() {
    let rig = draw(
        Outcome::Effect(EffectKind::BearingFriction),
        SeriesKind::Scroll,
        70001,
    )
    .unwrap();
    let drop = rig.drop_test_beside();
    assert_eq!(drop.kind(), SeriesKind::Dynamic);
    assert_eq!((&drop.belt, drop.material), (&rig.belt, rig.material));
    assert!(rig.bearing.is_some() && drop.bearing.is_none());
    let Test::Dynamic(d) = &drop.test else {
        panic!("not a drop test")
    };
    assert!((0.4..=3.0).contains(&d.roller_kg));
    let text = trackbelt_truth::drop_figures(&rig).unwrap();
    let doc: toml::Value = toml::from_str(&text).unwrap();
    let statics = doc["static"].as_array().unwrap();
    assert_eq!(statics.len(), d.static_runs);
    let dynamic = doc["dynamic"].as_array().unwrap();
    assert_eq!(dynamic.len(), 1);
    let entry = dynamic[0].as_table().unwrap();
    assert!(!entry.contains_key("series"), "{text}");
    for key in ["roller_kg", "hd_mm", "wd_mm", "settled_hs_mm"] {
        assert!(entry.contains_key(key), "{key} missing: {text}");
    }
    // Hd below Hs: the roller presses the belt down.
    let hs = statics[0]["hs_mm"].as_integer().unwrap();
    let hd = entry["hd_mm"].as_integer().unwrap();
    assert!(hd < hs, "{text}");
    // Another rig run of the same belt has the same drop test beside it.
    assert_eq!(trackbelt_truth::drop_figures(&rig.repeat(1)).unwrap(), text);
    // With its series: the same entries, the drop naming its file.
    let (with_series, csv) = trackbelt_truth::drop_test_with_series(&rig).unwrap();
    let named: Vec<&str> = with_series
        .lines()
        .filter(|l| !l.starts_with("series ="))
        .collect();
    assert_eq!(named, text.lines().collect::<Vec<_>>());
    assert!(with_series.contains("series = \"dynamic-1.csv\""));
    assert!(
        csv.starts_with("t_s,a_height_mm") && csv.lines().count() > 100,
        "{}",
        &csv[..80]
    );
}

/// A rig dataset with its belt's drop test beside it
/// (`generate_beside`): the rig run's series byte for byte the dataset
/// `generate` writes, its `dataset.toml` that one with the drop test's
/// entries appended (with the series, `dynamic-1.csv` beside it); a drop
/// test is not put beside a drop test, and nothing is written then.
#[test]
fn a_drop_test_beside_a_rig_run_keeps_the_rig_dataset_and_appends_the_drop_test() {
    let rig = draw(Outcome::None, SeriesKind::Scroll, 70002).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (alone, figures, both) = (
        dir.path().join("alone"),
        dir.path().join("figures"),
        dir.path().join("both"),
    );
    generate(&rig, &alone).unwrap();
    let t = trackbelt_truth::generate_beside(&rig, &figures, false).unwrap();
    assert_eq!(t.files.len(), 2);
    let read = |p: std::path::PathBuf| std::fs::read_to_string(p).unwrap();
    assert_eq!(
        read(alone.join("scroll-1.csv")),
        read(figures.join("scroll-1.csv"))
    );
    let appended = read(alone.join("dataset.toml")) + &trackbelt_truth::drop_figures(&rig).unwrap();
    assert_eq!(read(figures.join("dataset.toml")), appended);
    assert!(!figures.join("dynamic-1.csv").exists());
    let t = trackbelt_truth::generate_beside(&rig, &both, true).unwrap();
    assert_eq!(t.files.len(), 3);
    let (entries, csv) = trackbelt_truth::drop_test_with_series(&rig).unwrap();
    assert_eq!(
        read(both.join("dataset.toml")),
        read(alone.join("dataset.toml")) + &entries
    );
    assert_eq!(read(both.join("dynamic-1.csv")), csv);
    // The dataset reads as one belt with both kinds of test.
    let doc: toml::Value = toml::from_str(&read(both.join("dataset.toml"))).unwrap();
    assert_eq!(doc["scroll"].as_array().unwrap().len(), 1);
    assert_eq!(doc["dynamic"].as_array().unwrap().len(), 1);
    let drop = draw(Outcome::None, SeriesKind::Dynamic, 70002).unwrap();
    let refused = dir.path().join("refused");
    assert!(trackbelt_truth::generate_beside(&drop, &refused, true).is_err());
    assert!(!refused.exists());
}
