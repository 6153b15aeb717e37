//! The evidence ceiling ([`trackbelt_truth::ceiling`]) against the
//! physics: the effect's own evidence grows as its size squared (a small
//! effect shifts the series linearly in its size), fitting the twin never
//! loses evidence it did not have, and a clean scenario has no ceiling.

use trackbelt_truth::ceiling::ceiling;
use trackbelt_truth::{draw_at, EffectKind, Outcome, SeriesKind};

#[test]
fn the_ceiling_grows_as_the_effects_size_squared() {
    let scratch = tempfile_dir("ceiling-scaling");
    let at = |m: f64| {
        let sc = draw_at(
            Outcome::Effect(EffectKind::QuadraticDamping),
            SeriesKind::Dynamic,
            14804,
            m,
        )
        .unwrap();
        ceiling(&sc, &scratch).unwrap()
    };
    let (small, large) = (at(0.25), at(0.5));
    for c in [small, large] {
        assert!(c.chi2 >= 0.0 && c.chi2 <= c.chi2_twin, "{c:?}");
        assert!(c.samples > 100 && c.sigma > 0.0, "{c:?}");
    }
    // Twice the size, four times the evidence (within the law's own
    // nonlinearity and the search's tolerance).
    let ratio = large.chi2 / small.chi2;
    assert!(
        (2.5..6.5).contains(&ratio),
        "{small:?} {large:?} ratio {ratio}"
    );
}

#[test]
fn thermal_softening_is_compared_on_its_own_warmer_rig() {
    // Softening also warms the rig more and logs the temperature; the
    // clean twin runs on that rig, and the effect's evidence is large at
    // magnitude 1.
    let sc = draw_at(
        Outcome::Effect(EffectKind::ThermalSoftening),
        SeriesKind::Scroll,
        15000,
        1.0,
    )
    .unwrap();
    let c = ceiling(&sc, &tempfile_dir("ceiling-thermal")).unwrap();
    assert!(c.chi2 > 100.0 && c.chi2 <= c.chi2_twin, "{c:?}");
}

#[test]
fn a_clean_scenario_has_no_ceiling() {
    let sc = draw_at(Outcome::None, SeriesKind::Dynamic, 14804, 0.5).unwrap();
    let err = ceiling(&sc, &tempfile_dir("ceiling-none")).unwrap_err();
    assert!(err.to_string().contains("effect"), "{err}");
}

/// A fresh scratch path under the system's temporary directory.
fn tempfile_dir(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("{name}-{}", std::process::id()))
}
