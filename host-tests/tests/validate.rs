//! The diagnosis scored on data it did not make (issue 11, item 5): a
//! reduced `trackbelt validate-diagnosis` run, one dataset of the
//! independent truth generator per outcome (none in dynamic and in scroll
//! series, the six effects, the six disturbances: 14 datasets) at a fixed
//! held-out seed, on two threads. Meant for `cargo test --release`; about
//! 14 × (generation + diagnosis) / 2 threads of wall time.
//!
//! The structure of the report is asserted, then the issue's targets: no
//! wrong name, and a share of right answers of at least [`TARGET_RIGHT`].

use trackbelt_host::validate::{all_cases, run, DatasetResult, Options, Report};

/// `count` datasets per outcome of `outcomes`, in series of `kind`, truth
/// seeds from `seed`, on two threads.
fn options(kind: &str, count: usize, seed: u64, outcomes: &[&str]) -> Options {
    Options {
        count_per_outcome: count,
        seed,
        threads: 2,
        keep_dir: None,
        kinds: vec![kind.into()],
        outcomes: outcomes.iter().map(|s| s.to_string()).collect(),
        magnitude: None,
        ceiling: false,
        rivals: false,
        repeats: 0,
    }
}

/// Runs `opts` and checks that it drew `datasets` datasets.
fn run_expecting(opts: &Options, datasets: usize) -> Report {
    let r = run(opts, &trackbelt_host::NoProgress).unwrap();
    assert_eq!(r.datasets.len(), datasets);
    r
}

/// Runs `opts`, checks that it drew `datasets` datasets and that none of
/// them got a wrong name, and returns the report.
fn run_without_wrong_name(opts: &Options, datasets: usize) -> Report {
    let r = run_expecting(opts, datasets);
    show_no_wrong_name(&r.datasets);
    r
}

/// Runs `opts` (one dataset), checks it was given no wrong name and
/// returns it.
fn only_dataset(opts: &Options) -> DatasetResult {
    let r = run_without_wrong_name(opts, 1);
    r.datasets.into_iter().next().expect("one dataset")
}

/// Runs `opts` (one dataset), checks it got no wrong name and that its
/// answer is `answer`.
fn expect_answer(opts: &Options, answer: &str) {
    let d = only_dataset(opts);
    assert_eq!(d.answer, answer, "{}", d.evidence);
}

/// Runs `opts`, checks that no dataset got a wrong name and that each
/// outcome of `expected` got its answer.
fn expect_answers(opts: &Options, expected: &[(&str, &str)]) {
    let r = run_without_wrong_name(opts, expected.len());
    for &(outcome, answer) in expected {
        let d = r
            .datasets
            .iter()
            .find(|d| d.outcome == outcome)
            .expect("every truth drawn");
        assert_eq!(d.answer, answer, "{outcome}: {}", d.evidence);
    }
}

/// The scroll runout of truth seed `seed` is found (`unexplained`) and
/// its clean twin, the same rig and belt without the eccentric wheel,
/// stays `none`; no wrong name.
fn expect_runout_found(seed: u64) {
    expect_answers(
        &options("scroll", 1, seed, &["none", "wheel_runout"]),
        &[("none", "none"), ("wheel_runout", "unexplained")],
    );
}

/// Prints every dataset and fails on the first wrong name.
fn show_no_wrong_name(datasets: &[DatasetResult]) {
    for d in datasets {
        show(d);
        assert!(
            !d.wrong_name,
            "{} seed {}: named {}",
            d.outcome, d.seed, d.answer
        );
    }
}

/// One dataset's answer on stderr (shown when a test fails).
fn show(d: &DatasetResult) {
    eprintln!(
        "{} {} seed {}: {} ({:.3} → {:.3} {}): {}",
        d.outcome, d.kind, d.seed, d.answer, d.rms_before, d.rms_after, d.unit, d.evidence
    );
}

/// The issue's target share of right answers (≥ 90 %). With one dataset
/// per outcome it allows one miss in 14 (13/14 = 0.93). This is the one
/// assertion the lead may choose to relax while the diagnosis is being
/// redesigned; the wrong-name assertion stays.
const TARGET_RIGHT: f64 = 0.9;

/// Truth seed of every dataset: held out (the diagnosis is tuned on seeds
/// below 1000).
const SEED: u64 = 9001;

// Issue 11 is open: the diagnosis gets 9 of these 14 datasets right with
// no wrong name (the rule before this round: 8/14 with 2 wrong names), so
// this test would fail on the share; it states the target and is run by
// hand until the diagnosis meets it:
//   cargo test --release -p trackbelt-host-tests --test validate -- --ignored
#[test]
#[ignore = "issue 11 open: the diagnosis does not meet the target yet (9/14, no wrong name at seed 9001)"]
fn reduced_validation_one_per_outcome() {
    let opts = Options {
        count_per_outcome: 1,
        seed: SEED,
        threads: 2,
        keep_dir: None,
        kinds: Vec::new(),
        outcomes: Vec::new(),
        magnitude: None,
        ceiling: false,
        rivals: false,
        repeats: 0,
    };
    let r = run(&opts, &trackbelt_host::NoProgress).unwrap();
    let s = &r.summary;
    let m = &r.matrix;
    for d in &r.datasets {
        eprintln!(
            "{:<24} {:<7} seed {:>5}: {:<24} expected {:<24} {:.3} → {:.3} {} (noise {:.3}), {:.1} + {:.1} s",
            d.outcome,
            d.kind,
            d.seed,
            d.answer,
            d.expected,
            d.rms_before,
            d.rms_after,
            d.unit,
            d.noise_rms,
            d.generate_s,
            d.diagnose_s
        );
    }
    eprintln!(
        "right {}/{} ({:.2}), wrong names {}, errors {}, near the noise {}/{}, wall {:.1} s",
        s.right,
        s.datasets,
        s.right_fraction,
        s.wrong_names,
        s.errors,
        s.near_noise_met,
        s.named,
        r.wall_s
    );

    // Structure: every outcome once, the matrix adds up.
    let cases = all_cases();
    assert_eq!(m.rows.len(), cases.len());
    for ((o, k), row) in cases.iter().zip(&m.rows) {
        assert_eq!(row.outcome, o.as_str());
        assert_eq!(row.kind, k.as_str());
        assert_eq!(row.expected, o.expected());
        // A draw the truth cannot simulate is replaced by the next seed.
        assert_eq!(row.total, 1);
        assert_eq!(row.counts.len(), m.columns.len());
        assert_eq!(row.counts.iter().sum::<usize>(), row.total);
        let right_col = m.columns.iter().position(|c| *c == row.expected).unwrap();
        assert_eq!(row.counts[right_col], row.right);
    }
    assert_eq!(m.columns[0], "none");
    assert!(m.columns.iter().any(|c| c == "unexplained"));
    assert_eq!(s.datasets, cases.len());
    assert_eq!(r.datasets.len(), cases.len());
    assert_eq!(s.right, m.rows.iter().map(|x| x.right).sum::<usize>());
    assert_eq!(
        s.wrong_names,
        m.rows.iter().map(|x| x.wrong_names).sum::<usize>()
    );
    for d in &r.datasets {
        assert!(d.noise_rms > 0.0, "{} seed {}: no noise", d.outcome, d.seed);
        if d.answer != "error" {
            assert!(d.rms_before.is_finite() && d.rms_after.is_finite());
        }
    }

    // The issue's targets.
    assert_eq!(s.wrong_names, 0, "wrong names (see the table above)");
    assert!(
        s.right_fraction >= TARGET_RIGHT,
        "right {}/{} = {:.2} < TARGET_RIGHT {TARGET_RIGHT}",
        s.right,
        s.datasets,
        s.right_fraction
    );
}

/// The two wrong names found at held-out truth seed 5002 (session 7): a
/// clean dynamic series and one with quadratic damping, both named
/// `amplitude_stiffness` because the truth belt's own bending curve makes
/// the period grow as the amplitude falls. The refitted table shape
/// reproduces that trend, so the signature does not count (rule 4 of the
/// README's decision). Runs in CI: two datasets, about 30 s each on a core.
/// No assertion on the share right: only that no effect is named that the
/// truth does not hold.
#[test]
fn no_wrong_name_on_a_nonlinear_truth_curve_seed_5002() {
    let opts = options("dynamic", 1, 5002, &["none", "quadratic_damping"]);
    let r = run_expecting(&opts, 2);
    for d in &r.datasets {
        show(d);
        assert!(
            d.answer == d.expected || d.answer == "none" || d.answer == "unexplained",
            "{} seed {}: named {}",
            d.outcome,
            d.seed,
            d.answer
        );
    }
    assert_eq!(r.summary.wrong_names, 0);
}

/// The four thermal-softening wrong names of held-out truth seeds 8102 and
/// 8103 (session 10): on those rigs the belt warms as the run goes on and
/// the baseline's torque–speed curve differs from the truth's, so across
/// plateaus the residual follows the temperature (−0.025 N·m/K) whatever
/// the truth. Thermal softening now needs its own signature, the torque
/// falling as the belt warms *at constant speed*, better explained by the
/// temperature than by the time (`diagnose_scroll::thermal_veto`). The
/// thermal truth of seed 8103 carries it at about 10 standard errors and
/// must still be named, and its evidence must quote that reading; the
/// other six scroll series must not be given a name they do not hold.
/// Eight scroll series, about 2 s each.
#[test]
fn thermal_softening_needs_drift_at_constant_speed_seeds_8102_8103() {
    let opts = options(
        "scroll",
        2,
        8102,
        &[
            "none",
            "bearing_friction",
            "rate_dependent_damping",
            "thermal_softening",
        ],
    );
    let r = run_without_wrong_name(&opts, 8);
    let ts = r
        .datasets
        .iter()
        .find(|d| d.outcome == "thermal_softening" && d.seed == 8103)
        .expect("thermal truth 8103");
    assert_eq!(ts.answer, "thermal_softening", "{}", ts.evidence);
    // Its evidence says what it rests on (session 61; before, the reading
    // at constant speed was only ever quoted when it vetoed softening).
    assert!(
        ts.evidence
            .contains("at constant speed the torque falls with the belt temperature by"),
        "{}",
        ts.evidence
    );
    assert_eq!(r.summary.wrong_names, 0);
}

/// Held-out seed 49806 (session 62). A clean scroll belt whose torque
/// reads softening's signature at constant speed (0.36 %/K at 3.2
/// standard errors over 7.7 K, the temperature ahead of the time) while no
/// fit of softening is supported: it is `none`, and its evidence said "no
/// drift at constant speed" beside the reading that says there is one. It
/// must say what it read. One scroll series, about 2 s.
#[test]
fn a_clean_belt_reading_softening_without_its_fit_says_so_seed_49806() {
    let opts = options("scroll", 1, 49806, &["none"]);
    let r = run_expecting(&opts, 1);
    let d = &r.datasets[0];
    assert_eq!(d.answer, "none", "{}", d.evidence);
    assert!(
        d.evidence
            .contains("at constant speed the torque falls with the belt temperature by"),
        "the reading holds on this belt: {}",
        d.evidence
    );
    assert!(
        !d.evidence.contains("no drift at constant speed"),
        "the evidence contradicts its own reading: {}",
        d.evidence
    );
    assert!(
        d.evidence
            .contains("softening's own signature holds at constant speed (read below), but no fit of softening is supported"),
        "{}",
        d.evidence
    );
}

/// Held-out seeds 9902 and 9903 (session 14), now tuning seeds. Two
/// power-law truths (exponents 0.36 and 0.49, replacing the linear
/// damping) were named bearing friction: a constant torque beside a
/// refitted cz fits such a law on the plateaus about as well as a power
/// law does, and the ramp tie-break then decided on the ramps alone, where
/// the rig model's transients are not the bench's. The tie-break now needs
/// the steady windows not to speak against its winner. The thermal truth
/// of 9903 warms on plateaus too short for the within-plateau signature;
/// it is read across the windows (`diagnose_scroll::pooled_softening`)
/// and must be named, while the torque drift of 9903, falling as its belt
/// warms but following the time, must not be called softening. Six scroll
/// series, about 1 s each.
#[test]
fn power_laws_not_named_bearing_and_pooled_softening_seeds_9902_9903() {
    let opts = options(
        "scroll",
        2,
        9902,
        &[
            "rate_dependent_damping",
            "thermal_softening",
            "torque_drift",
        ],
    );
    let r = run_without_wrong_name(&opts, 6);
    let ts = r
        .datasets
        .iter()
        .find(|d| d.outcome == "thermal_softening" && d.seed == 9903)
        .expect("thermal truth 9903");
    assert_eq!(ts.answer, "thermal_softening", "{}", ts.evidence);
    let drift = r
        .datasets
        .iter()
        .find(|d| d.outcome == "torque_drift" && d.seed == 9903)
        .expect("torque drift 9903");
    assert_eq!(drift.answer, "unexplained", "{}", drift.evidence);
}

/// Scroll series, tuning seeds 7100–7104 (session 13): the old rule called
/// every window-mean residual above the noise floor `unexplained`, so clean
/// series came back `unexplained` (3 of these 5) and a slip or a drift was
/// found only through the floor. Now a clean series is `none` unless the
/// residual carries a disturbance's own signature (a drift at constant
/// speed, a line at a wheel's turn or at a fixed frequency, a torque
/// collapse), and those signatures are read for themselves: all five clean
/// series `none`, at least four of five slip-burst series and of five
/// torque-drift series `unexplained`, no name given. Fifteen scroll
/// series, about 1 s each.
#[test]
fn scroll_clean_is_none_and_disturbances_are_found_seeds_7100_7104() {
    let opts = options("scroll", 5, 7100, &["none", "slip_bursts", "torque_drift"]);
    let r = run_expecting(&opts, 15);
    let right = |o: &str| {
        r.datasets
            .iter()
            .filter(|d| d.outcome == o && d.right)
            .count()
    };
    show_no_wrong_name(&r.datasets);
    assert_eq!(right("none"), 5, "clean scroll series not `none`");
    assert!(
        right("slip_bursts") >= 4,
        "slip bursts found {}",
        right("slip_bursts")
    );
    assert!(
        right("torque_drift") >= 4,
        "torque drift found {}",
        right("torque_drift")
    );
}

/// Dynamic series, seeds 9501 and 9508 (session 14; 9501 was held out in
/// session 12, now a tuning seed). Payne softening with a memory moves the
/// belt's mean as it swings, so the baseline's residual has a slow moving
/// mean, which the fit-alone rule took for a drifting camera and refused:
/// amplitude stiffness 9501 was `unexplained` with its law 237 BIC units
/// ahead of the runner-up and at the noise floor. The moving mean is now
/// the law's own when its residual has none left and the heights stop
/// drifting in the record's last 2 s (`diagnose_dynamic::tail_drift`);
/// a drifting camera keeps moving, including the weakest of seeds
/// 9500–9509 (9508, 0.53 mm/s, 1.9 standard errors in the tail), and
/// must stay `unexplained`. Three dynamic series, about 45 s each.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn payne_memory_moves_the_mean_a_camera_keeps_drifting_seeds_9501_9508() {
    let opts = |seed: u64, outcomes: &[&str]| options("dynamic", 1, seed, outcomes);
    let a = run(
        &opts(9501, &["amplitude_stiffness", "camera_drift"]),
        &trackbelt_host::NoProgress,
    )
    .unwrap();
    let b = run(&opts(9508, &["camera_drift"]), &trackbelt_host::NoProgress).unwrap();
    let all: Vec<&DatasetResult> = a.datasets.iter().chain(&b.datasets).collect();
    assert_eq!(all.len(), 3);
    for d in &all {
        show(d);
        assert!(
            !d.wrong_name,
            "{} seed {}: named {}",
            d.outcome, d.seed, d.answer
        );
        let expected = if d.outcome == "camera_drift" {
            "unexplained"
        } else {
            "amplitude_stiffness"
        };
        assert_eq!(
            d.answer, expected,
            "{} seed {}: {}",
            d.outcome, d.seed, d.evidence
        );
    }
}

/// Dynamic series, held-out seed 14900 (session 31's run; session 32). A
/// Payne truth (depth 0.46, its mean following in 1.9 s) led every other
/// model by 183 BIC units at the noise floor, no step or slow-mean rival
/// within reach, and was `unexplained` only because the heights still
/// drift over the record's last 2 s (−0.73 mm/s, 3.8 standard errors):
/// the belt creeps under the roller while its mean relaxes. The Payne
/// trace follows that creep (it leaves 0.26 of it, at 1.0 standard error;
/// `diagnose_dynamic::tail_followed`), as a camera's drift it does not.
/// Fails on `8255de8`. One dynamic series, about 45 s.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_payne_belt_still_creeping_at_the_end_is_named_seed_14900() {
    expect_answer(
        &options("dynamic", 1, 14900, &["amplitude_stiffness"]),
        "amplitude_stiffness",
    );
}

/// Dynamic series, seeds 9501–9502 (session 14, tuning). A candidate
/// fitted on the table's refitted shape needed its per-cycle signature
/// read; Dahl friction that stops the drop within two or three cycles
/// never shows one, and joint-friction truth 9502 was refused with its law
/// 81 BIC units ahead of every other model at the noise floor. It now
/// stands on the fit alone, as a candidate on the table as it came does,
/// when it also lowers the BIC by 20 itself: the clean series of 9501 had
/// a Dahl friction on the shape 20.1 ahead with a gain of only 13.3, and
/// must stay unnamed. Four dynamic series, about 45 s each.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn friction_on_the_refitted_shape_stands_on_the_fit_seeds_9501_9502() {
    let opts = options("dynamic", 2, 9501, &["none", "joint_friction"]);
    let r = run_without_wrong_name(&opts, 4);
    let jf = r
        .datasets
        .iter()
        .find(|d| d.outcome == "joint_friction" && d.seed == 9502)
        .expect("friction truth 9502");
    assert_eq!(jf.answer, "joint_friction", "{}", jf.evidence);
}

/// Session 15 (held-out seeds 10200 of session 14, now tuning seeds):
/// clean series whose effects tie with each other a few BIC units ahead of
/// the refitted shape, which itself leaves the noise floor, are `none`
/// (they were `unexplained`); a shaking camera whose residual line is
/// found in the refitted shape's residual is `unexplained` even when the
/// shake inflates the noise floor until the shape seems to reach it (it
/// was `none`).
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn tied_effects_over_a_shape_at_the_floor_and_a_shake_left_by_it_seeds_10200_10201() {
    let opts = options("dynamic", 2, 10200, &["none", "camera_shake"]);
    let r = run_without_wrong_name(&opts, 4);
    for d in r.datasets.iter().filter(|d| d.outcome == "none") {
        assert_eq!(d.answer, "none", "clean seed {}: {}", d.seed, d.evidence);
    }
    let shake = r
        .datasets
        .iter()
        .find(|d| d.outcome == "camera_shake" && d.seed == 10200)
        .expect("camera shake 10200");
    assert_eq!(shake.answer, "unexplained", "{}", shake.evidence);
}

/// Session 15: a torque drift while the belt warms is not thermal
/// softening when the fit needs more softening than any rubber has
/// (`softening_size_veto`; held-out seed 10405 drawn at magnitude 0.7: a
/// logger drift of −1.9 %/s was fitted as 11.8 %/K and named thermal
/// softening); real softening drawn at magnitude 2 (seeds 10400–10402,
/// fitted 0.8–1.4 %/K) keeps its name.
#[test]
fn a_drift_too_steep_for_rubber_is_not_softening_seed_10405() {
    let mut opts = options("scroll", 1, 10405, &["torque_drift"]);
    opts.magnitude = Some(0.7);
    expect_answer(&opts, "unexplained");
    let mut opts = options("scroll", 3, 10400, &["thermal_softening"]);
    opts.magnitude = Some(2.0);
    let r = run_expecting(&opts, 3);
    for d in &r.datasets {
        show(d);
        assert_eq!(
            d.answer, "thermal_softening",
            "seed {}: {}",
            d.seed, d.evidence
        );
    }
}

/// Session 19: thermal softening read across the windows
/// (`diagnose_scroll::pooled_softening`) does not overrule the speed
/// groups when they say the opposite. Tuning seed 760 (a clean scroll
/// series with a logged temperature, found on fresh tuning seeds): across
/// four plateaus at other temperatures the torque fell by 0.29 %/K beside
/// its torque–speed shape, while inside the speed groups it rose by
/// 0.15 %/K (3.9 standard errors); it was named thermal softening. The
/// softening truth of the same seed, flat inside the groups, is still
/// named. Two scroll series, about 1 s each.
#[test]
fn pooled_softening_does_not_overrule_the_speed_groups_seed_760() {
    let r = run_without_wrong_name(
        &options("scroll", 1, 760, &["none", "thermal_softening"]),
        2,
    );
    let ts = r
        .datasets
        .iter()
        .find(|d| d.outcome == "thermal_softening")
        .expect("thermal truth 760");
    assert_eq!(ts.answer, "thermal_softening", "{}", ts.evidence);
}

/// Session 19: on two plateaus bearing friction and a power law are both
/// set aside (they fit the plateaus alike), and the answer was `none`
/// however large the effect: tuning truth 763 at magnitude 3, a bearing
/// friction leaving 23 × the noise floor under the baseline, was called
/// clean. The torque growing slower with the speed than the baseline's is
/// the signature the two share, so such a residual is `unexplained`
/// (neither named); the clean series of the same belt and profile stays
/// `none`. Two scroll series, about 1 s each.
#[test]
fn a_large_torque_on_two_plateaus_is_not_none_seed_763() {
    let mut opts = options("scroll", 1, 763, &["none", "bearing_friction"]);
    opts.magnitude = Some(3.0);
    expect_answers(
        &opts,
        &[("none", "none"), ("bearing_friction", "unexplained")],
    );
}

/// Session 19's held-out run (seeds 11100–11104) gave one wrong name: the
/// clean dynamic series of seed 11102 was named joint friction. A Dahl law
/// reached the noise floor with its decrement trend read at 3.4 standard
/// errors, but a Payne law (1.02 × the floor) trailed it by only 5.5 and
/// the refitted shape (1.07 ×) by 17.7. A name now needs a lead of
/// `BIC_MARGIN` over every other model that reaches the floor too; with
/// this belt's own curve among them the answer is `none`. One dynamic
/// series, about 35 s.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_name_is_told_from_every_fit_at_the_floor_seed_11102() {
    expect_answer(&options("dynamic", 1, 11102, &["none"]), "none");
}

/// Found in session 19 by the scroll detection-limit run (`--kind scroll
/// --count 5 --seed 11200 --magnitude 0.35`) and not fixed: torque-drift
/// truth 11202 at magnitude 0.35 (the belt warming in step with the time)
/// is named thermal softening at 2.6 %/K. Inside two speed groups the
/// torque fell 3.5 ± 0.7 %/K over 2.1 K and the temperature beat the time
/// by Δχ² 4.1; across the windows by 2.2. Right softening names of the
/// same runs stand on as little (Δχ² 2.8–5.5 at best on 7 of 30, among
/// them 10402 at magnitude 2, which a test here requires), so a stricter
/// bar was not taken. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored drift_at_magnitude
#[test]
#[ignore = "issue 11 open: torque drift 11202 at magnitude 0.35 is named thermal softening"]
fn a_torque_drift_at_magnitude_0_35_is_not_softening_seed_11202() {
    let mut opts = options("scroll", 1, 11202, &["torque_drift"]);
    opts.magnitude = Some(0.35);
    only_dataset(&opts);
}

/// Session 16: a drift at constant speed is never `none` and never thermal
/// softening when the whole series follows the time. Held-out seed 10602
/// (torque drift of −1.7 %/s): inside three short speed groups the
/// temperature fitted better than the time (Δχ² 5.4), across all windows
/// the time fitted better by 44.7 (`time_over_temperature_veto`); it was
/// named thermal softening. Seed 10601 (thermal softening): the torque
/// fell at constant speed by 4.3 standard errors, refused as softening
/// because the time fitted as well, and was then reported as `none`
/// (`unnamed_thermal_drift`).
#[test]
fn a_drift_the_time_explains_is_unexplained_seeds_10601_10602() {
    expect_answer(
        &options("scroll", 1, 10602, &["torque_drift"]),
        "unexplained",
    );
    let d = only_dataset(&options("scroll", 1, 10601, &["thermal_softening"]));
    assert_ne!(d.answer, "none", "{}", d.evidence);
}

/// Session 16: a memory-less cubic stiffness is not named where its period
/// trend cannot be read (fewer than four cycles). Held-out seed 10702: a
/// clean, heavily damped belt (log decrement 1.2, three cycles) was named
/// the cubic `amplitude_stiffness` 24 BIC ahead of the refitted shape,
/// whose fit stopped at 1.436 mm against the cubic's 1.245 mm; the camera
/// shake drawn on the same belt was named the same way.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_cubic_on_three_cycles_is_the_shape_seed_10702() {
    let r = run_without_wrong_name(&options("dynamic", 1, 10702, &["none", "camera_shake"]), 2);
    let clean = r
        .datasets
        .iter()
        .find(|d| d.outcome == "none")
        .expect("clean 10702");
    assert_eq!(clean.answer, "none", "{}", clean.evidence);
}

/// Found in session 15 with `--magnitude` and not fixed yet: two
/// quadratic-damping truths named joint friction (a Dahl law fitted at
/// the noise floor, standing on the fit alone, its per-cycle trend too
/// weak to read). Seed 10400 at magnitude 0.5: Dahl on the refitted
/// shape, 33 BIC ahead of the shape, while the quadratic-damping
/// candidate stopped at 0.877 mm (16 simulations) against the Dahl law's
/// 0.748 mm; session 13's rule (no fit-alone name on the refitted shape)
/// answered `none`. Since session 16 seed 10400 is `unexplained`: a
/// +0.53 mm step in the refitted shape's residual fits within 8.5 BIC of
/// the Dahl law (`diagnose_dynamic::step_rival`). Seed 10401 at
/// magnitude 1.5: a 12 mm drop of two or three cycles, wrong on session
/// 13's build too, and still named joint friction. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored quadratic
/// Session 56 ran every ignored test on main (`c67468c`): this one
/// passes now (no wrong name; the answer is in the ignore reason). The
/// session that fixed it is not known. In the full tier (`cargo test-full`).
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn quadratic_damping_not_named_friction_seeds_10400_10401() {
    for (seed, magnitude) in [(10400, 0.5), (10401, 1.5)] {
        let mut opts = options("dynamic", 1, seed, &["quadratic_damping"]);
        opts.magnitude = Some(magnitude);
        only_dataset(&opts);
    }
}

/// Found in session 40's run at fresh seed 17900 (main at `97ebce1`) and
/// not fixed: quadratic-damping truth 17900 (magnitude 0.67: a drag law
/// of exponent 1.99 with a cap) is named joint friction (Dahl, 0.071 N·m
/// per joint, pre-sliding 0.021 rad) on the fit alone. The belt decays
/// from 17 to 10 mm in fewer than four cycles (log decrement
/// 1.21 → 1.04), so no per-cycle trend is read, and the Dahl law reaches
/// the noise floor (1.121 mm) 35.5 BIC ahead of the runner-up, amplitude
/// stiffness; the quadratic-damping candidate fits worse than both. The
/// same family as 10401. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_17900
/// Session 56 ran every ignored test on main (`c67468c`): this one
/// passes now (no wrong name; the answer is in the ignore reason). The
/// session that fixed it is not known. In the full tier (`cargo test-full`).
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_fast_decaying_quadratic_damping_is_not_named_friction_seed_17900() {
    only_dataset(&options("dynamic", 1, 17900, &["quadratic_damping"]));
}

/// Found in session 48's fresh dynamic run at seed 19500 (`--kind dynamic
/// --count 5 --seed 19500`; main's build `f065281` answers the same) and
/// not fixed: quadratic-damping truth 19501 (magnitude 0.67: a drag law
/// of exponent 1.89 with a cap) is named joint friction (Dahl, 0.0088 N·m
/// per joint, pre-sliding 0.0134 rad) on the fit alone. The belt decays
/// from 26 to 10 mm in fewer than four cycles (log decrement
/// 1.05 → 0.81), so no per-cycle trend is read, and the Dahl law reaches
/// the noise floor (1.327 mm) 61 BIC ahead of the runner-up, the refitted
/// table shape. The family of 17900 and 10401. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_19501
#[test]
#[ignore = "issue 11 open: quadratic-damping truth 19501 is named joint friction on the fit alone"]
fn a_fast_decaying_quadratic_damping_is_not_named_friction_seed_19501() {
    only_dataset(&options("dynamic", 1, 19501, &["quadratic_damping"]));
}

/// Found in session 58's fresh run at seed 21500 (main's rules: build
/// `b065015`, `--again`, whose rules `27c42ec` keeps; the session's build
/// answers the same) and not fixed:
/// quadratic-damping truth 21501 (magnitude 0.39: a drag law of exponent
/// 1.95 with a cap) is named joint friction (Dahl, 0.0157 N·m per joint,
/// pre-sliding 0.0149 rad, not at the top of its range, so
/// `dahl_never_slides` does not apply) with its signature read: the log
/// decrement rises with the amplitude (+0.0057/mm ± 0.0015 against the
/// baseline's +0.0026, 2.1 standard errors), the Dahl candidate's
/// +0.0047 reproduces it, and it leads quadratic damping, the runner-up,
/// by 36.3 BIC at the floor (0.609 mm). The family of 19703 and 19501.
/// Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_21501
#[test]
#[ignore = "issue 11 open: quadratic-damping truth 21501 is named joint friction (a Dahl law that slides)"]
fn a_drag_is_not_named_a_sliding_dahl_friction_seed_21501() {
    only_dataset(&options("dynamic", 1, 21501, &["quadratic_damping"]));
}

/// Found in session 49's full run at fresh seed 19700 (build `58e0a3f`;
/// main's build `35154b8` answers the same, `--again`) and not fixed:
/// quadratic-damping truth 19703 (magnitude 0.82: a drag law of exponent
/// 1.80 with a cap) is named joint friction (Dahl, 0.036 N·m per joint,
/// pre-sliding 0.026 rad) with its signature read. The log decrement
/// rises with the amplitude (+0.0098/mm ± 0.0035 against the baseline's
/// +0.0013, 2.4 standard errors: quadratic damping's one way, and one of
/// the two ways a Dahl law moves it); the Dahl candidate's +0.0039
/// stands within 2 standard errors of the measured trend, so it counts
/// as reproduced, and it leads the runner-up, amplitude stiffness, by
/// 28 BIC at the floor (1.198 mm). The mirror of 18901 (a Dahl truth
/// named quadratic damping), where the lead over the Dahl rival decides
/// (`dahl_takes_the_mark`); here the quadratic-damping candidate is not
/// the runner-up. Passes since session 56 (`c67468c` fails:
/// joint_friction): the Dahl fit sits at the top of its pre-sliding
/// range (`diagnose_dynamic::dahl_never_slides`). In the full tier
/// (`a_drag_is_not_named_dahl_friction_seed_21100` runs the rule in CI):
///   cargo test-full -- seed_19703
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_quadratic_damping_is_not_named_dahl_friction_seed_19703() {
    only_dataset(&options("dynamic", 1, 19703, &["quadratic_damping"]));
}

/// Found in session 51 on the kept held-out run at seed 18800 (`--kind
/// dynamic --count 10`, main's build `77ae671`): quadratic-damping truth
/// 18806 (a drag law) reaches the noise floor (1.298 mm, from 1.757) with
/// its decrement trend at 1.9 standard errors from the baseline's (too
/// weak to read), 24.8 BIC ahead of the refitted shape and 30.3 ahead of
/// joint friction, but only 11.7 ahead of amplitude stiffness, whose
/// period trend the refitted shape carries as well. It was refused under
/// the lead of 20 a name on the fit alone needs over every model; a rival
/// whose own prediction the data refute now needs only
/// `REFUTED_RIVAL_LEAD` (`diagnose_dynamic::fit_alone_lead_over`). Fails
/// on `77ae671`: `none`.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_rival_the_refitted_shape_explains_needs_no_full_lead_seed_18806() {
    expect_answer(
        &options("dynamic", 1, 18806, &["quadratic_damping"]),
        "quadratic_damping",
    );
}

/// Found in session 51 on the kept held-out run at seed 19300 (main's
/// build `77ae671`): joint-friction truth 19301 (a Dahl law) is fitted
/// by the Dahl candidate at the noise floor 152 BIC ahead of every other
/// model, its decrement trend too weak to read, and was refused because
/// the baseline's residual has no moving mean: a rule meant for the Payne
/// law's memory of the amplitude. A Dahl fit whose decrement trend moves
/// from the baseline's the Coulomb way (−0.0003/mm here: growing as the
/// amplitude falls) is a sliding friction and now stands on the fit
/// alone; fitted the other way it still needs the moving mean
/// (`quadratic_damping_11602_is_not_named_friction`). Fails on
/// `77ae671`: `none`.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_dahl_friction_on_a_weak_trend_needs_no_moving_mean_seed_19301() {
    expect_answer(
        &options("dynamic", 1, 19301, &["joint_friction"]),
        "joint_friction",
    );
}

/// Found in session 51's fresh run at seed 20100 (`validate-diagnosis
/// --count 5 --seed 20100`, build `5445d85`; main's build `77ae671`
/// answers the same) and not fixed: joint-friction truth 20104
/// (magnitude 0.89: a Dahl law, 0.067 N·m per joint) is named quadratic
/// damping on the fit alone. The measured log decrement rises with the
/// amplitude (+0.0100/mm ± 0.0049 against the baseline's +0.0044, 1.2
/// standard errors: too weak to read, quadratic damping's way and one of
/// the two ways a Dahl law moves it); the quadratic-damping candidate
/// reaches the floor (0.869 mm) 35.7 BIC ahead of amplitude stiffness
/// and 87.6 ahead of the refitted shape, while the Dahl candidate stops
/// at 1.34 × the floor, 116.7 behind, so the Dahl-rival bar
/// (`dahl_takes_the_mark`, for a rival at the floor) does not apply. The
/// mirror of 19703. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_20104
#[test]
#[ignore = "issue 11 open: Dahl truth 20104 is named quadratic damping on the fit alone"]
fn a_dahl_friction_is_not_named_quadratic_damping_on_the_fit_alone_seed_20104() {
    only_dataset(&options("dynamic", 1, 20104, &["joint_friction"]));
}

/// Found in session 71's held-out run at seed 80000 (`validate-diagnosis
/// --count 5 --seed 80000`, the session's final build `2c0254a`):
/// joint-friction truth 80001 (magnitude 0.52: a Dahl law, 0.032 N·m per
/// joint, of pre-sliding range 0.14 rad) was named quadratic damping on
/// the fit alone, 26.2 below the baseline, its decrement trend 1.3
/// standard errors from the baseline's. The friction candidate had never
/// been tried: its start from zero stayed at the baseline (no gradient
/// there), and because the baseline was at the floor too, that start
/// ended the law's starts. Session 73: a start ends them only where it
/// lowered the BIC under the baseline's; the Dahl law from the refitted
/// shape then leads quadratic damping by 37.5 and the answer is `none`
/// (its signature too weak to read). Fails on `aae0ae2`. One dynamic
/// series.
#[test]
fn a_dahl_friction_is_not_named_quadratic_damping_on_the_fit_alone_seed_80001() {
    only_dataset(&options("dynamic", 1, 80001, &["joint_friction"]));
}

/// Found in session 72's held-out run at seed 81000 (`validate-diagnosis
/// --count 5 --seed 81000`, main's `aae0ae2`): joint-friction truth
/// 81003 (magnitude 0.48, a Dahl law) was named quadratic damping on the
/// fit alone, 28 ahead of the Dahl law, its decrement trend 1.0 standard
/// error from the baseline's, on the params file's table stretched to
/// ×0.47 (beyond the usual ×0.5–2). Session 73: the fit alone names
/// nothing on a stretched baseline; the answer is `none`. Fails on
/// `aae0ae2`. One dynamic series.
#[test]
fn the_fit_alone_names_nothing_on_a_stretched_table_seed_81003() {
    only_dataset(&options("dynamic", 1, 81003, &["joint_friction"]));
}

/// Session 53 (held-out runs 20200 and 20400 of session 52, now tuning
/// seeds): a law with a memory whose per-cycle trend is too weak to read
/// must show its memory's mark (a moving mean it takes out of the
/// baseline's residual, or a Dahl fit in its sliding regime), unless it
/// leads every other model by `MEMORY_MARK_WAIVER_LEAD` (100). Payne
/// truth 20202 led the refitted shape by 181 at the noise floor, its
/// period trend 0.2 standard errors from the baseline's, and was `none`.
/// Fails on `f53c13e`. One dynamic series.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_payne_law_far_ahead_of_every_model_is_named_without_its_mark_seed_20202() {
    expect_answer(
        &options("dynamic", 1, 20202, &["amplitude_stiffness"]),
        "amplitude_stiffness",
    );
}

/// As above: Dahl truth 20404, in its pre-sliding range (its decrement
/// trend the quadratic damping's way, 1.8 standard errors from the
/// baseline's), led a Payne law by 176 at the noise floor and was `none`.
/// Fails on `f53c13e`. One dynamic series.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_dahl_law_far_ahead_of_every_model_is_named_without_its_mark_seed_20404() {
    expect_answer(
        &options("dynamic", 1, 20404, &["joint_friction"]),
        "joint_friction",
    );
}

/// Found in session 52's tuning runs (scroll seeds 49000–49339,
/// `validate-diagnosis --kind scroll --count 40`, main's build `e61d8fc`;
/// the session's `WITHIN_DRIFT_Z` answers the same) and not fixed: two
/// bearing frictions named a power law. 49032 (0.49 N·m on the idler):
/// on three plateaus the log–log slope of measured over baseline torque
/// is −0.106 ± 0.005, just past the −0.100 a sound belt's scatter
/// allows, and the plateaus lie on a line in log–log (a power law's
/// shape; the clean belt of the same rig reads +0.035); the replacing
/// power law (exponent 0.9) leads bearing friction by 12.4. 49112
/// (0.78 N·m on the idler): two plateaus tie the two families, and the
/// ramps, where the rig model's transients are not calibrated, break the
/// tie for the power law by 13.0. Since session 60 a power law needs a
/// lead of 16 there (`diagnose_scroll::RAMP_SEPARATION`), and 49112 is
/// `unexplained`; 49032, decided on its three plateaus, still fails. Run
/// by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seeds_49032_49112
#[test]
#[ignore = "issue 11 open: bearing friction 49032 is named power-law damping (49112 fixed in session 60)"]
fn a_bearing_friction_is_not_a_power_law_seeds_49032_49112() {
    for seed in [49032, 49112] {
        only_dataset(&options("scroll", 1, seed, &["bearing_friction"]));
    }
}

/// Session 60's tuning runs (`validate-diagnosis --kind scroll --count
/// 20 --seed 49500`, and `--count 40 --seed 49600` over clean belts,
/// bearing frictions and power laws; main's build `14854b9`): bearing
/// frictions 49518 (0.70 N·m) and 49605 (0.25 N·m) tie with a power law
/// on their two plateaus, and the ramps between them, where the rig
/// model's transients are not the bench's, named the power law by 14.3
/// and 13.8 BIC against a bar of 12. Both are now refused for a lead
/// under [`RAMP_SEPARATION`] (16): they must be `unexplained`, not named
/// a power law; the power laws of the same two rigs lead there by 48.0
/// and 19.4 and are still named. Four scroll series, about 1 s each, in
/// one run per seed. Fails on `14854b9`.
///
/// [`RAMP_SEPARATION`]: trackbelt_host::diagnose_scroll::RAMP_SEPARATION
#[test]
fn a_bearing_friction_is_not_named_a_power_law_on_the_ramps_seeds_49518_49605() {
    for seed in [49518, 49605] {
        expect_answers(
            &options(
                "scroll",
                1,
                seed,
                &["bearing_friction", "rate_dependent_damping"],
            ),
            &[
                ("bearing_friction", "unexplained"),
                ("rate_dependent_damping", "rate_dependent_damping"),
            ],
        );
    }
}

/// Session 71: bearing frictions 76000 (tuning run `--kind scroll
/// --count 40 --seed 76000 --outcome none,bearing_friction,rate_dependent_damping`)
/// and 77004 (the held-out full run at seed 77000), both on three
/// plateaus, were named power-law damping: the measured curve flattened
/// by −0.36 ± 0.15 and −0.12 ± 0.02, which set the bearing
/// friction aside for the power law's shape ([`speed_curve_veto`]), and
/// the flattening against the baseline then named the power law
/// (`flattening_decides`). Clean belts' curves bend by ±0.11 (one SD,
/// beyond the noise) from belt to belt, so the bend now carries that
/// scatter ([`CURVE_FLOOR`]): neither is set aside, the two families
/// tie, and both are `unexplained`. Two scroll series, about 1 s each.
/// Fails on `7ef9837`.
///
/// [`speed_curve_veto`]: trackbelt_host::diagnose_scroll::speed_curve_veto
/// [`CURVE_FLOOR`]: trackbelt_host::diagnose_scroll::CURVE_FLOOR
#[test]
fn a_bearing_friction_is_not_named_a_power_law_on_a_bend_within_a_sound_belt_s_scatter_seeds_76000_77004(
) {
    for seed in [76000, 77004] {
        expect_answer(
            &options("scroll", 1, seed, &["bearing_friction"]),
            "unexplained",
        );
    }
}

/// Found in session 63's fresh scroll run 61000 (`--kind scroll --count
/// 20 --outcome none,bearing_friction,rate_dependent_damping`, main's
/// build `66f4eb6`) and not fixed: on rig 61018 (a thick 11.6 mm belt on
/// a 208 mm drive at 320 N) the *clean* belt's own torque grows as about
/// ω^0.6 (torque/speed 0.80, 0.67, 0.55 N·m/(rad/s) at 2.35, 4.95 and
/// 7.48 rad/s: a linear damping the belt cannot follow at speed), far
/// more than the baseline's curve bends, and both the clean belt and the
/// bearing friction of that rig are named power-law damping (exponents
/// 0.8 and 0.7, 20.5 and 35.3 ahead; the curve flattens against the
/// baseline by −0.21 and −0.13). "Torque not proportional to speed" is
/// then no effect's own signature. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_61018
#[test]
#[ignore = "issue 11 open: clean belt and bearing friction 61018 are named power-law damping"]
fn a_clean_belt_that_cannot_follow_its_damping_is_not_a_power_law_seed_61018() {
    run_without_wrong_name(
        &options("scroll", 1, 61018, &["none", "bearing_friction"]),
        2,
    );
}

/// Found in session 52's tuning run at scroll seed 49300 (main's build
/// `e61d8fc`; the session's `WITHIN_DRIFT_Z` answers the same) and not
/// fixed: the clean belt 49337 is named power-law damping on the ramps.
/// On two plateaus (3.5–4.7 rad/s) bearing friction lowers BIC by 66.7
/// and the two families tie; with the ramps the power law leads by
/// 20.0, where the rig model follows the transients only roughly. Run by
/// hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_49337
#[test]
#[ignore = "issue 11 open: clean belt 49337 is named power-law damping on the ramps"]
fn a_clean_belt_is_not_named_a_power_law_on_the_ramps_seed_49337() {
    only_dataset(&options("scroll", 1, 49337, &["none"]));
}

/// Found in session 71's tuning run at scroll seed 74000 (`--kind scroll
/// --count 20 --outcome none,bearing_friction,rate_dependent_damping`,
/// main's build `7ef9837`) and not fixed: bearing friction 74007 (0.35
/// N·m on the drive) ties with a power law on its two plateaus (1.3 and
/// 2.8 rad/s), and on the ramps the power law leads by 17.3 against a bar
/// of 16 ([`RAMP_SEPARATION`]). The power-law truth of the same seed (the
/// same belt, rig, profile and noise) leads there by 21.9 and is named
/// rightly: the two series' window means differ by 0.02–0.05 N·m, and the
/// lead comes from the window where the drive accelerates at 1.9 rad/s²,
/// where the bench's rotating inertia (the idler's, which the rig model
/// lacks and `DATA.md` does not give) leaves +0.05 N·m that the power
/// law's tilt takes up better than a constant torque. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_74007
///
/// [`RAMP_SEPARATION`]: trackbelt_host::diagnose_scroll::RAMP_SEPARATION
#[test]
#[ignore = "issue 11 open: bearing friction 74007 is named power-law damping on the ramps"]
fn a_bearing_friction_is_not_named_a_power_law_on_the_ramps_seed_74007() {
    only_dataset(&options("scroll", 1, 74007, &["bearing_friction"]));
}

/// Found in session 71's fresh scroll run at seed 79000 (main's build
/// `7ef9837`): on rig 79011 (a belt of 2172 mm, 5.9 mm thick, 5.25 kg on
/// 248 and 348 mm wheels at 370 N) every series ended in an error, the rig
/// model's static solve of the belt's pretension not converging in 2000
/// iterations. The same dataset with the tensioner at 300, 340–365, 380,
/// 400, 450 or 600 N converged, at 369–375 N it did not: the solver, not
/// the physics. The proximal polish was converging, slowly; session 72
/// raised [`RIG_STATIC_ITERATIONS`] to 4000 and the clean series answers.
///
/// [`RIG_STATIC_ITERATIONS`]: trackbelt::rig::RIG_STATIC_ITERATIONS
#[test]
fn the_rig_model_settles_the_belt_of_rig_seed_79011() {
    let d = only_dataset(&options("scroll", 1, 79011, &["none"]));
    assert_ne!(d.answer, "error", "{}", d.evidence);
}

/// Found in session 71's fresh scroll run at seed 79000 (`--kind scroll
/// --count 20`, main's build `7ef9837`) and not fixed: the clean belt
/// 79015, on a slow ramp from 1.1 to 7.6 rad/s while it warms, is named
/// thermal softening: across the windows its torque falls with the belt
/// temperature beside its refitted torque–speed shape (−0.0023 ± 0.0004
/// 1/K) and follows it better than the time (Δχ² 5.2), which stands in
/// for the reading at constant speed. Letting that reading stand in only
/// where the constant-speed one cannot be read refuses it, but also three
/// right softenings of the same runs (77002, 79001, 79006). Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_79015
#[test]
#[ignore = "issue 11 open: clean belt 79015 is named thermal softening"]
fn a_clean_belt_on_a_warming_ramp_is_not_softening_seed_79015() {
    only_dataset(&options("scroll", 1, 79015, &["none"]));
}

/// Found in session 52's tuning run at scroll seed 49300 (main's build
/// `e61d8fc`; the session's `WITHIN_DRIFT_Z` answers the same) and not
/// fixed: the clean belt 49329 and torque drift 49331 (−1.4 %/s with a
/// wander of 2.5 % over 6.5 s) are named thermal softening beside the
/// belt's torque–speed shape refitted: the torque falls with the belt
/// temperature across the windows and follows it better than the time
/// (Δχ² 14.3 and 6.6). Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seeds_49329_49331
#[test]
#[ignore = "issue 11 open: clean 49329 and torque drift 49331 are named thermal softening"]
fn a_curve_or_a_drift_is_not_softening_seeds_49329_49331() {
    only_dataset(&options("scroll", 1, 49329, &["none"]));
    only_dataset(&options("scroll", 1, 49331, &["torque_drift"]));
}

/// Found in session 60's tuning run at scroll seed 49500 (`--kind scroll
/// --count 20`, main's build `14854b9`) and not fixed: torque drifts 49502
/// (magnitude 0.47, two plateaus) and 49509 (0.77) are named thermal
/// softening. On 49502 the torque falls at constant speed by 2.5 %/K at
/// 3.4 standard errors (16 windows in 2 speed groups, 3.8 K) and follows
/// the temperature better than the time there by Δχ² 2.3, while across
/// the windows the two tie (Δχ² 0.7); softening lowers BIC by 37.3 to
/// 1.15 × the floor with no rival ranked, and its evidence line does not
/// say which signature it rests on. On 49509 the constant-speed groups
/// read nothing; across the windows the torque follows the temperature
/// better than the time by Δχ² 6.0, and softening leads the runner-up by
/// 22.8. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seeds_49502_49509
#[test]
#[ignore = "issue 11 open: torque drifts 49502 and 49509 are named thermal softening"]
fn a_torque_drift_is_not_softening_seeds_49502_49509() {
    for seed in [49502, 49509] {
        only_dataset(&options("scroll", 1, seed, &["torque_drift"]));
    }
}

/// Found in session 52 on dynamic truths drawn at seeds 20300–20309
/// (`gen quadratic_damping dynamic 20306`, main's build `e61d8fc`) and
/// not fixed: quadratic-damping truth 20306 (magnitude 0.67, a drag of
/// exponent 1.80 capped at 1.5 × its reference rate, on 32 nodes) is
/// named joint friction with its signature read. The measured decrement
/// rises with the amplitude (+0.0022/mm ± 0.0009 against the baseline's
/// +0.0001, 2.5 standard errors, quadratic damping's way); the Dahl fit
/// on the refitted shape reproduces it (+0.0015) and leads quadratic
/// damping by 68.6 at the floor. A drag law with its exponent fitted
/// (tried in a scratch build) did not close the gap: on the shape it
/// went to the bound p = 3 short of the plain square's fit. The QD→JF
/// class of 17900, 10401, 19501 and 19703. Passes since session 56
/// (`c67468c` fails: joint_friction): the Dahl fit sits at the top of its
/// pre-sliding range (`diagnose_dynamic::dahl_never_slides`). In the
/// full tier:
///   cargo test-full -- seed_20306
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_capped_drag_is_not_named_friction_seed_20306() {
    only_dataset(&options("dynamic", 1, 20306, &["quadratic_damping"]));
}

/// Found in session 55's run at fresh seed 21100 (the session's scratch
/// build; main's build `72439c4` answers the same, `--again --kind
/// dynamic`) and not fixed: quadratic-damping truth 21100 (magnitude
/// 0.87, a drag of exponent 1.70 with a cap) is named joint friction
/// (Dahl, 0.042 N·m per joint, pre-sliding 0.027 rad) with its signature
/// read from the peaks (36 → 4 mm). The measured decrement rises with
/// the amplitude (+0.0047/mm ± 0.0013 against the baseline's +0.0005,
/// 3.3 standard errors, quadratic damping's way); the Dahl fit
/// reproduces it (+0.0036) and leads the quadratic-damping candidate,
/// the runner-up, by 20.7 at the floor (0.705 mm). The QD→JF class of
/// 17900, 10401, 19501, 19703 and 20306. Fixed in session 56: the Dahl
/// fit's pre-sliding angle is the top of its range on this link, a joint
/// that never slides, whose hysteresis reads the decrement trend as
/// quadratic damping does; beside quadratic damping at the floor (1.10 ×)
/// a Dahl name then needs `MEMORY_MARK_WAIVER_LEAD`
/// (`diagnose_dynamic::dahl_never_slides`), and the answer is
/// `unexplained`. Fails on `c67468c`: named joint_friction. One dynamic
/// series (the class's other two it fixes, 19703 and 20306, are in the
/// full tier).
#[test]
fn a_drag_is_not_named_dahl_friction_seed_21100() {
    only_dataset(&options("dynamic", 1, 21100, &["quadratic_damping"]));
}

/// Found in session 56's second fresh run, seed 21300 (`434a136`), and
/// not fixed: the cost of `diagnose_dynamic::dahl_never_slides`. Dahl
/// truth 21302 is fitted by the Dahl law at the top of its pre-sliding
/// range (0.0228 rad on its link), 45.7 BIC ahead of quadratic damping
/// at the floor, its decrement trend 3.1 standard errors from the
/// baseline's and reproduced. Main's build before the rule (`c67468c`)
/// names it joint friction; the rule answers `none`, because at the
/// top of the range the two families read the same. A right name that
/// stays open. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_21302
#[test]
#[ignore = "issue 11 open: Dahl truth 21302 at the top of its pre-sliding range is none (dahl_never_slides)"]
fn a_dahl_friction_at_the_top_of_its_range_is_named_seed_21302() {
    expect_answer(
        &options("dynamic", 1, 21302, &["joint_friction"]),
        "joint_friction",
    );
}

/// Found in session 44's run at fresh seed 18900 (build `68673c4`):
/// joint-friction truth 18901 (magnitude 0.42: a Dahl law, 0.034 N·m per
/// joint, on a belt of 32 nodes) was named quadratic damping with its
/// signature read. The measured log decrement rises with the amplitude
/// (+0.0053/mm ± 0.0019 against the baseline's −0.0014, 3.5 standard
/// errors: quadratic damping's one way, and one of the two ways a Dahl
/// law moves it) and the candidate reached the floor (0.607 mm) 17.9 BIC
/// ahead of the Dahl candidate, also at the floor. A quadratic-damping
/// name now leads a Dahl rival at the floor by `RIVAL_SIGNATURE_LEAD`
/// (`diagnose_dynamic::dahl_takes_the_mark`); the answer is `none`. Fails
/// on `68673c4`: named quadratic_damping.
#[test]
fn a_dahl_friction_is_not_named_quadratic_damping_seed_18901() {
    only_dataset(&options("dynamic", 1, 18901, &["joint_friction"]));
}

/// Found in session 41 by the fresh held-out run at seed 18000
/// (`trackbelt validate-diagnosis --count 5 --seed 18000`): the clean
/// dynamic series of seed 18001, a belt the truth simulates with 28 nodes
/// (the model has 38 links), is named quadratic damping on the fit alone.
/// The baseline leaves 3.330 mm over a 1.06 mm floor; quadratic damping
/// reaches the floor (1.062 mm) 29.0 BIC ahead of amplitude stiffness
/// (1.101 mm) and 106 ahead of the refitted table shape (1.191 mm, also
/// within the floor factor). Its decrement trend against the amplitude is
/// 0.3 standard errors from the baseline's (measured flat, about 0.35
/// over 15 cycles from 59 to 7 mm), so the name stands on the fit alone,
/// over the lead of 20 that this needs. The issue's own example of a
/// forced wrong name on a clean belt of another number of links. Fixed in
/// session 42: the fitted candidate's own trend sits 0.3 standard errors
/// *below* the baseline's, not up, the one way quadratic damping moves it,
/// so its gain is not its mark and a name on the fit alone is refused
/// (`SignatureCheck::WithoutMark`). Fails on `226140f`.
#[test]
fn a_clean_belt_of_another_discretisation_is_not_named_seed_18001() {
    only_dataset(&options("dynamic", 1, 18001, &["none"]));
}

/// Found in session 44's held-out run at fresh seed 18700
/// (`validate-diagnosis --count 5 --seed 18700`, main's build `0766e51`):
/// the clean belt 18704, 26 nodes against the model's 38 links, decaying
/// in three cycles under 1.2 mm of marker noise, was named quadratic
/// damping on the fit alone, 20.7 BIC ahead of the refitted shape, with
/// 7 % less residual: the baseline already stood at 1.07 × the noise
/// floor. A name on a signature that cannot be read (fewer than four
/// cycles) now needs a baseline that misses the floor by more than
/// `FLOOR_FACTOR` (`diagnose_dynamic::baseline_at_floor_on_the_fit_alone`). The
/// quadratic-damping truth of the same seed and belt (its baseline at
/// 1.25 × the floor, 20 % less residual) keeps its name. Fails on
/// `0766e51`: named quadratic_damping.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_clean_belt_at_the_floor_is_not_named_on_the_fit_alone_seed_18704() {
    expect_answers(
        &options("dynamic", 1, 18704, &["none", "quadratic_damping"]),
        &[("none", "none"), ("quadratic_damping", "quadratic_damping")],
    );
}

/// Found in session 42's held-out run at fresh seed 18100
/// (`validate-diagnosis --count 5 --seed 18100`, build `10a799b`): the
/// quadratic-damping truth 18104 (magnitude 0.95, a drag of exponent
/// 2.12 with a cap) was named joint friction (Dahl, 0.035 N·m per joint)
/// on the fit alone, 37.5 BIC ahead, fewer than two cycles above the
/// noise. The baseline's fit had stopped at its stiffness bound, ×2.00,
/// with 1.924 mm; in the box ×0.25–4 it ends inside, at ×1.97 with
/// 1.734 mm, and the Dahl law leads by only 15.6. The answer is `none`.
/// Fails on `10a799b`.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_baseline_that_stopped_at_its_old_bound_lends_no_name_seed_18104() {
    expect_answer(
        &options("dynamic", 1, 18104, &["quadratic_damping"]),
        "none",
    );
}

/// Found in session 17 by the detection-limit run (`--kind dynamic
/// --magnitude 0.35 --count 5 --seed 10900`): a camera drifting
/// (−0.35 mm/s) and a marker slipping (−1.4 mm at 2.2 s) on the belt of
/// seed 10903 (whose clean series already has a residual the baseline
/// does not follow) were named amplitude stiffness. A Payne law's memory
/// took the moving mean and the belt's own misfit at once, while the laws
/// without a memory, fitted without the slow mean, stopped far from their
/// best (the friction law on the refitted shape at 1.745 mm, 0.929 mm once
/// the truth's drift was taken out). Since session 18 each other model is
/// refitted with a slow mean beside it (`diagnose_dynamic::mean_rival`)
/// and the Payne law must lead those too. The drift is `unexplained`.
/// The slip was `unexplained` too until the refitted shape was refitted
/// from the best candidate's (later in session 18): that shape reaches
/// 0.890 mm, under the Payne law's 0.932 mm, and leaves no moving mean,
/// so a 1.4 mm step under 0.82 mm of marker noise reads `none` (a miss at
/// the detection limit, not a wrong name). Fails on the session-17
/// build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_slow_mean_at_magnitude_0_35_is_not_named_payne_seed_10903() {
    let mut opts = options("dynamic", 1, 10903, &["camera_drift", "marker_slip"]);
    opts.magnitude = Some(0.35);
    let r = run_without_wrong_name(&opts, 2);
    let drift = r.datasets.iter().find(|d| d.outcome == "camera_drift");
    let drift = drift.expect("a camera-drift dataset");
    assert_eq!(drift.answer, "unexplained", "{}", drift.evidence);
}

/// Found in session 20 by the dynamic detection-limit run (`--kind dynamic
/// --count 5 --seed 11300 --magnitude 2`): a camera shaking 14.6 mm at
/// 6.5 Hz (decaying 0.6 /s) over 0.69 mm of marker noise, sampled at
/// 25 Hz, raised the noise floor (read from sample-to-sample
/// differences) to 3.9 mm, where the baseline's residual sat (× 1.01).
/// No candidate was supported, and a disturbance found in the residual
/// counted only above the floor: the answer was `none`. The shake's line
/// (6.56 Hz, 236 × the residual's median spectral power) now makes it
/// `unexplained` whatever the floor. One dynamic series, about 40 s.
/// Fails on the session-19 build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_shake_that_raises_the_noise_floor_is_unexplained_seed_11300() {
    let mut opts = options("dynamic", 1, 11300, &["camera_shake"]);
    opts.magnitude = Some(2.0);
    expect_answer(&opts, "unexplained");
}

/// Found in session 20 by the dynamic detection-limit run (`--kind dynamic
/// --count 5 --seed 11300 --magnitude 0.35`) and not fixed: a camera
/// drifting −0.49 mm/s under 1.56 mm of marker noise (the baseline as
/// shipped, residual 6.29 mm) is named amplitude stiffness, a Payne law
/// whose mean follows in 5.4 s taking the drift to the noise floor 36
/// ahead of quadratic damping. Its period trend cannot be read (fewer
/// than four cycles), so the name stands on the fit alone, and the
/// heights' last 2 s drift by under 2 standard errors at that noise
/// (`tail_drift`; session 14 saw a 0.53 mm/s camera at 1.9). Session 21
/// asked the fitted law's own heights to stop drifting there too (this
/// one drifts 2.4 standard errors) and reverted it: the fitted law of
/// Payne truth 9501 (`payne_memory_moves_the_mean_…` above) drifts 3.2.
/// Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored weak_camera_drift
/// Session 56 ran every ignored test on main (`c67468c`): this one
/// passes now (no wrong name; the answer is in the ignore reason). The
/// session that fixed it is not known. In the full tier (`cargo test-full`).
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_weak_camera_drift_under_heavy_noise_is_not_payne_seed_11302() {
    let mut opts = options("dynamic", 1, 11302, &["camera_drift"]);
    opts.magnitude = Some(0.35);
    expect_answer(&opts, "unexplained");
}

/// Found in session 21 by the full run at seed 11400: a camera shaking
/// 3.4 mm at 7.85 Hz (decaying 0.56/s) under 1.37 mm of marker noise was
/// named the cubic amplitude stiffness, its period trend read at −2.3
/// standard errors. The shake's jumps raised the noise floor to 1.60 mm,
/// and its line, 29 times the residual's median spectral power, had
/// 0.78 mm: under half that floor, so no disturbance was read. A name
/// now needs its residual free of such a line whatever its amplitude
/// (`diagnose_dynamic::left_by_name`). Fails on session 20's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_shake_under_half_the_floor_is_not_named_seed_11400() {
    expect_answer(
        &options("dynamic", 1, 11400, &["camera_shake"]),
        "unexplained",
    );
}

/// Found in session 18 by the full run at seed 11000: a marker slip
/// (−3.4 mm at 1.9 s, magnitude 0.45) named joint friction at
/// 0.0013 N·m per joint, fitted on the refitted shape at 1.637 mm where
/// the shape alone had stopped at 2.972 mm: the name was given for the
/// shape's gain. Since then the shape is refitted from the best
/// candidate's shape when that fits much better; it reaches 1.626 mm and
/// the answer is `none`. Fails on the session-17 build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_friction_of_nothing_on_a_better_shape_is_not_named_seed_11004() {
    only_dataset(&options("dynamic", 1, 11004, &["marker_slip"]));
}

/// Found in session 16 by the full run at seed 10700: quadratic damping
/// (magnitude 0.41) named Payne softening on the fit alone, 29.6 BIC
/// ahead of the quadratic-damping candidate, its period trend at 0.2
/// standard errors. The quadratic damping refitted with a slow mean
/// beside it (`diagnose_dynamic::mean_rival`) fits better than the Payne
/// law: its lead came from a moving mean, which a memory is not the only
/// thing to make. Fails on the session-17 build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn quadratic_damping_10703_is_not_named_payne() {
    only_dataset(&options("dynamic", 1, 10703, &["quadratic_damping"]));
}

/// The other side of the two tests above: a Payne truth (tuning seed 703,
/// magnitude 0.75) whose name stands on the fit alone, 115.6 BIC ahead of
/// the baseline with its period trend too weak to read, is still named.
/// Its residual shows no moving mean, and it leads the other models
/// refitted with a slow mean by 7.2 (the refitted shape), more than the
/// 4 asked there; with 20 asked everywhere it was `unexplained`.
///
/// Lost in session 29 and kept as an open case: a Payne law named on a
/// period trend too weak to read (four cycles or more) must now take a
/// moving mean out of the baseline's residual, and this one takes none.
/// The same rule removes four wrong names of the same kind (quadratic
/// damping 12000 and 14400, joint friction 14200, clean 13602: Payne
/// laws on a weak trend, no moving mean); of the twenty Payne truths of
/// tuning seeds 700–719, 703 is the only right name it refuses.
#[test]
#[ignore = "issue 11 open: Payne truth 703 (weak period trend, no moving mean) is refused since session 29"]
fn a_payne_name_on_the_fit_alone_survives_its_slow_mean_rivals_seed_703() {
    expect_answer(
        &options("dynamic", 1, 703, &["amplitude_stiffness"]),
        "amplitude_stiffness",
    );
}

/// Found in session 15 by the full run at seeds 10500, and in session 17
/// on tuning seeds 612 and 625: the ramp tie-break named bearing friction
/// on power-law truths (every tie the ramps broke on the truth generator
/// went to bearing friction, whatever the truth). Since session 17 the
/// ramps only settle a tie where the rig model follows them to the noise
/// (`diagnose_scroll::RAMP_FLOOR_FACTOR`); these three left 1.9–2.9 × the
/// floor there. Fails on the session-16 build at every seed.
#[test]
fn ramps_do_not_settle_a_tie_the_plateaus_cannot_point_to_seeds_10501_612_625() {
    for seed in [10501, 612, 625] {
        only_dataset(&options("scroll", 1, seed, &["rate_dependent_damping"]));
    }
}

/// Session 36: power-law truths 31006 (α 0.73, magnitude 0.64) and 31008
/// tie with bearing friction on their steady windows and were
/// `unexplained`. The power law's family now holds a law replacing the
/// linear damping as well as one beside it, and with it the ramps lead to
/// the power law by 20–22 BIC; a power law that wins the ramps is named
/// (the guards against the ramps' lean towards a constant torque stay
/// bearing friction's). Fails on session 35's build (`2c30217`).
#[test]
fn a_power_law_that_wins_the_ramps_is_named_seeds_31006_31008() {
    for seed in [31006, 31008] {
        expect_answer(
            &options("scroll", 1, seed, &["rate_dependent_damping"]),
            "rate_dependent_damping",
        );
    }
}

/// Found in session 15 by the full run at seed 10500, again in session 16
/// at 10603: a marker that slips (by −4.8 mm at 2.0 s; by −1.3 mm at
/// 3.0 s) was named amplitude stiffness. A Payne law's slow mean absorbs
/// the step, and the settled-tail check (`tail_drift`, session 14) that
/// tells a drifting camera from a rubber mean does not see a step: the
/// heights stop moving after it too. Since session 16 a law with a memory
/// standing on the fit alone must also lead one step in the refitted
/// shape's residual (`diagnose_dynamic::step_rival`); both are
/// `unexplained`.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn marker_steps_not_named_payne_seeds_10500_10603() {
    for seed in [10500, 10603] {
        let d = only_dataset(&options("dynamic", 1, seed, &["marker_slip"]));
        assert_eq!(d.answer, "unexplained", "seed {seed}: {}", d.evidence);
    }
}

/// Session 33: a camera that shakes at a harmonic of the belt's frequency
/// outlives the belt's swing (`diagnose_dynamic::late_line`). Held-out
/// camera shake 15104 (6.6 mm at 3.85 Hz, decaying by 0.28/s, on the
/// second harmonic of a 1.9 Hz belt) was set aside as the belt's own
/// harmonic and answered `none`; in the record's second half, where the
/// belt has settled, its line stands alone.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_shake_that_outlives_the_belt_is_found_seed_15104() {
    expect_answer(
        &options("dynamic", 1, 15104, &["camera_shake"]),
        "unexplained",
    );
}

/// Session 33: a torque that drifts across the run as a gain falling with
/// the belt temperature is softening's form, and a logger's offset in
/// time is not (`diagnose_scroll::drift_form`). Held-out truth 15101 (run
/// of session 32) softened by −0.74 %/K across the run, the gain in
/// temperature fitting better than a logger's offset in time by Δχ² 58;
/// inside its four short speed groups the reading stayed at 2.6 standard
/// errors (3 needed), and it was `unexplained`. Truth 14600 was `none`.
/// The torque drift and the clean belt of seed 15101 keep their answers.
#[test]
fn softening_named_by_its_drift_form_seeds_15101_14600() {
    expect_answers(
        &options(
            "scroll",
            1,
            15101,
            &["none", "thermal_softening", "torque_drift"],
        ),
        &[
            ("none", "none"),
            ("thermal_softening", "thermal_softening"),
            ("torque_drift", "unexplained"),
        ],
    );
    expect_answer(
        &options("scroll", 1, 14600, &["thermal_softening"]),
        "thermal_softening",
    );
}

/// Session 35: a drift of the measured/baseline ratio on the steady
/// windows counts as a disturbance only from 0.3 %/s
/// (`diagnose_scroll::RATIO_DRIFT_MIN_PER_S`). Under a quiet logger a
/// sound belt's ripple tilts the ratio by a few tenths of a percent per
/// second and stands many standard errors out: held-out clean belt 15601
/// read −0.11 ± 0.01 %/s and power law 14201 0.25 %/s (named once the
/// drift is not read); both were `unexplained`.
#[test]
fn a_ratio_drift_under_0_3_percent_per_second_is_no_disturbance_seeds_15601_14201() {
    expect_answer(&options("scroll", 1, 15601, &["none"]), "none");
    expect_answer(
        &options("scroll", 1, 14201, &["rate_dependent_damping"]),
        "rate_dependent_damping",
    );
}

/// Issue 11, open since session 35: held-out power law 15703 (exponent
/// 0.71, magnitude 0.43) is named bearing friction by the ramp tie-break,
/// 13.2 BIC ahead on the ramps against a bar of 12. The ramps it reads
/// include the start from rest after its first window, where the rig
/// model does not follow the bench; read only from the first steady
/// window on, the two stay tied (`unexplained`) and bearing friction
/// 14020 (this tie-break's one name on 1130 kept scroll series) keeps
/// its name. That change was reverted: the synthetic bearing friction at
/// magnitude 2 of `diagnose.rs` (our own model, whose start from rest is
/// exact) is then no longer named, and that test requires it.
#[test]
#[ignore = "issue 11 open: power law 15703 is named bearing friction on the start from rest"]
fn a_power_law_is_not_named_bearing_friction_on_the_start_from_rest_seed_15703() {
    expect_answer(
        &options("scroll", 1, 15703, &["rate_dependent_damping"]),
        "unexplained",
    );
    expect_answer(
        &options("scroll", 1, 14020, &["bearing_friction"]),
        "bearing_friction",
    );
}

/// Session 35: a fixed-frequency line must make five cycles over the
/// record and stand above both of its reference bands
/// (`diagnose_scroll::FIXED_LINE_MIN_CYCLES`). The search started at
/// 0.25 Hz, where the lower band fell under the grid and went unread, so
/// the slow swing of a residual whose power falls with the frequency read
/// as a line there: the clean belt 15110 (0.25 Hz, 51×) and the softening
/// truth 16401 at magnitude 1 (0.27 Hz, 29×, the softening itself named
/// 33 BIC ahead) were `unexplained`.
#[test]
fn a_slow_swing_is_not_a_fixed_line_seeds_15110_16401() {
    expect_answer(&options("scroll", 1, 15110, &["none"]), "none");
    let mut opts = options("scroll", 1, 16401, &["thermal_softening"]);
    opts.magnitude = Some(1.0);
    expect_answer(&opts, "thermal_softening");
}

/// Session 35: a softening named on a scroll series is reported beside
/// this belt's torque–speed shape refitted
/// (`diagnose_scroll::softening_beside_shape`): a scroll dataset has no
/// figure to recalibrate the curve on, and what the baseline's shape left
/// kept the named softening's error far from the noise. Truths 15600 (the
/// session's held-out run; two speed groups) and 14101 were named with
/// 0.153 and 0.146 N·m left against 0.095 and 0.110 N·m of noise put in,
/// from 0.370 and 0.206: neither near the noise nor a third of before.
/// Beside the shape: 0.023 and 0.020 N·m.
#[test]
fn a_named_softening_falls_near_the_noise_beside_the_belts_shape_seeds_15600_14101() {
    for seed in [15600, 14101] {
        let d = only_dataset(&options("scroll", 1, seed, &["thermal_softening"]));
        assert_eq!(d.answer, "thermal_softening", "{seed}: {}", d.evidence);
        assert_eq!(
            d.near_noise,
            Some(true),
            "{seed}: {:.3} → {:.3} N·m, noise put in {:.3}: {}",
            d.rms_before,
            d.rms_after,
            d.noise_rms,
            d.evidence
        );
    }
}

/// Session 22: a logger's zero that wanders over the whole run is a drift
/// even where the steady plateaus are too short to show it. Tuning seeds
/// 761 and 769 (torque drifts of −2.9 % and −2.2 % of the mean torque per
/// second) answered `none`: on 761 no plateau reading reached its bar; on
/// 769 the drift was read on the steady windows, then dropped as thermal
/// softening's signature because the softening reading across the windows
/// (a gain) preferred the temperature, while the torque's offset followed
/// the time better by Δχ² 69 (`diagnose_scroll::offset_drift`,
/// `offset_drift_veto`). The clean series of seed 761 stays `none`.
/// Clean truths 49132 and 49138 (session 52): their rigs' torque–speed
/// curves bend where the baseline's quadratic in `ln |ω|` does not follow,
/// and with the plateaus in the order they were run that read as drifts
/// in time across them (+0.60 %/s at 6.5 standard errors, +1.09 %/s at
/// 6.3), but not inside them (−0.23 ± 0.46 and −0.65 ± 0.42 %/s):
/// `unexplained` before `WITHIN_DRIFT_Z`, `none` now. The power laws on
/// the same rigs are named, and the torque drifts on them are still
/// found.
#[test]
fn a_torque_speed_curve_the_baseline_misses_is_not_a_drift_seeds_49132_49138() {
    for seed in [49132, 49138] {
        expect_answers(
            &options(
                "scroll",
                1,
                seed,
                &["none", "rate_dependent_damping", "torque_drift"],
            ),
            &[
                ("none", "none"),
                ("rate_dependent_damping", "rate_dependent_damping"),
                ("torque_drift", "unexplained"),
            ],
        );
    }
}

#[test]
fn a_drift_across_the_series_is_unexplained_seeds_761_769() {
    expect_answers(
        &options("scroll", 1, 761, &["none", "torque_drift"]),
        &[("none", "none"), ("torque_drift", "unexplained")],
    );
    expect_answer(&options("scroll", 1, 769, &["torque_drift"]), "unexplained");
}

/// Session 22: a wheel's line is told from the belt's own harmonics by
/// the resolution the turns give, and fitted beside them. Tuning seed
/// 764: the idler's runout made a line 740× its neighbours' power over
/// 17.7 turns, but the belt's third revolution harmonic sat at order 1.084
/// of the idler, and the mask then in force (any belt line within 10 % of
/// order 1) hid it: `none`. Order 1 is now masked only within one cycle
/// over the turns tracked (0.056 here) and fitted jointly with the other
/// lines near it (`diagnose_scroll::wheel_line`). The clean series of 764
/// stays `none`; the clean series of 779, where the neighbours' lines
/// leaking into order 1 read as a line at the drive's turn (12×), is now
/// `none` too.
#[test]
fn a_runout_beside_a_belt_harmonic_is_found_seeds_764_779() {
    expect_runout_found(764);
    expect_answer(&options("scroll", 1, 779, &["none"]), "none");
}

/// An eccentric idler whose turn falls on a harmonic of the belt's
/// revolution (here within a cycle of the belt's third harmonic over the
/// turns read), where a sound belt makes a line of its own. Before
/// session 24 such a line was not read at all, and this runout (held-out
/// seed 12003) answered `none`; it is now read when it is over
/// `BELT_LINE_FRACTION` (2.5 %) of the mean torque (3.0 % here), which the clean twin's
/// own line stays under.
#[test]
fn a_runout_on_a_belt_harmonic_is_found_seed_12003() {
    expect_runout_found(12003);
}

/// Session 39: an eccentric idler on a slow rig, turning once in 2–4 s,
/// is read. Until then a wheel's line was read only on turns of at most
/// 2 s (`diagnose_scroll::LINE_TURN_S`), and these runouts answered
/// `none`: fresh seed 17609 (an idler line of 14 % of the mean torque over
/// 4.7 turns) and kept seed 30017 (7.9 % over 3.8 turns). Turns of up to
/// 4 s (`SLOW_LINE_TURN_S`) are now read where the faster turns find no
/// line, by the line's size alone. Each clean twin stays `none`. Fails on
/// `6fad0ba`.
#[test]
fn a_slow_wheels_runout_is_found_seeds_17609_30017() {
    expect_runout_found(17609);
    expect_runout_found(30017);
}

/// Session 27: a line at a wheel's turn is read by its size when the
/// rig's other lines leave too few reference orders to compare it with.
/// On scroll-only seed 11800 the drive and the idler are of nearly one
/// size (the idler's turn at order 0.99 of the drive's) and the belt's
/// harmonics sit at 0.45, 0.91 and 1.36: over 4.8 turns fewer than 4 of
/// the 14 reference orders stay clear, and an eccentric idler making a
/// line of 16.9 % of the mean torque answered `none`. Fresh seed 13405
/// likewise (7.6 % over 5.5 turns). The size path
/// (`diagnose_scroll::LINE_SIZE_FRACTION`, 6 % over 4 turns) finds
/// both; the clean twins, whose lines stay under 2 %, stay `none`.
#[test]
fn a_runout_with_too_few_reference_orders_is_found_seeds_11800_13405() {
    for seed in [11800, 13405] {
        expect_runout_found(seed);
    }
}

/// Session 34: over fewer than 4 turns a line is read by its size when
/// no neighbour can be compared and it stands 21× above what the
/// residual's noise makes at order 1
/// (`diagnose_scroll::LINE_STRONG_OVER_NOISE`). Held-out runouts 14604
/// (magnitude 0.69: 6.3 % of the mean torque over 3.8 turns of the idler,
/// 52×) and 14900 (0.86: 16.1 % over 3.7 turns, 100×) answered `none`;
/// the ramps' shape that the one-turn mean leaves over few turns stays
/// near 6× (power law 12805). Their clean twins stay `none`. Fails on
/// `8c22bbf`.
#[test]
fn a_strong_runout_over_few_turns_is_found_seeds_14604_14900() {
    for seed in [14604, 14900] {
        expect_runout_found(seed);
    }
}

/// Found in session 22's held-out run (seed 11600) and not fixed: the
/// quadratic-damping truth 11602 (magnitude 0.8) is named joint friction.
/// A Dahl law at the noise floor stands on the fit alone (its decrement
/// trend +0.0053/mm against the measured +0.0043 ± 0.0040, 1.1 standard
/// errors from the baseline: too weak to read) and leads the
/// quadratic-damping candidate by 39. Its pre-sliding angle (0.022 rad)
/// puts it where a Dahl joint's decrement grows with the amplitude, as
/// quadratic damping's does. Refusing a fit-alone friction whose own trend
/// goes that way would also refuse friction truth 11303 at magnitude 0.35
/// (named on the fit alone with a fitted trend of +0.0049/mm), and
/// friction truth 729 shows the same rising decrement at 7.1 standard
/// errors; not done.
///
/// Session 30: this passes since session 29's rule that a law with a
/// memory (Dahl's pre-sliding is one) named on a trend too weak to read
/// must take a moving mean out of the baseline's residual (`c2a02ce`);
/// the series is `none` now. Found when the ignored tests were run again,
/// so it runs in CI. Session 51 exempts a Dahl fit in its sliding regime
/// from that rule; this one's trend moves quadratic damping's way
/// (+0.0052/mm from the baseline's), so the rule still holds here. A
/// first version that exempted every Dahl law named it joint friction.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn quadratic_damping_11602_is_not_named_friction() {
    only_dataset(&options("dynamic", 1, 11602, &["quadratic_damping"]));
}

/// Found in session 23's held-out run (seed 11700): the clean series
/// 11703 was named amplitude stiffness. The recalibrated baseline left
/// 1.553 mm (3 × the floor); the refitted shape reached 0.524 mm and the
/// cubic on it 0.494 mm, 25 BIC ahead. The cubic's period trend against
/// the amplitude (−0.0006/mm) stood 2.2 standard errors from the
/// baseline's (+0.0012) towards the measured one (+0.0001 ± 0.0005), but
/// the refitted shape's own trend was −0.0006 as well: the move was the
/// shape's, not the effect's. The shape now has the signature too when it
/// makes at least half of the candidate's move from the baseline's trend,
/// even past the measured one. Fails on session 22's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_cubic_whose_trend_the_shape_makes_is_not_named_seed_11703() {
    expect_answer(&options("dynamic", 1, 11703, &["none"]), "none");
}

/// Found in session 24's held-out run (seed 12000) and not fixed: the
/// quadratic-damping truth 12000 (magnitude 0.83, a drag of exponent 2.07)
/// is named amplitude stiffness. A Payne law (depth 0.101, its mean
/// following in 0.66 s) reaches the noise floor (0.527 mm) and stands on
/// the fit alone: its period trend (+0.0006/mm against the measured
/// +0.0013 ± 0.0022) is 0.5 standard errors from the baseline's, and it
/// leads quadratic damping by 41 BIC, over the 20 of `diagnose_dynamic::WEAK_SIGNATURE_LEAD`.
/// Quadratic damping's own decrement trend is in the data at only
/// 1.4 standard errors, so a rival signature does not refuse it either.
/// The right fit-alone names of the memory laws lead by 20 to 388 (Payne
/// 11700: 37; Dahl 11403: 20), so no lead separates them from this one
/// and 11602 (39). Fixed in session 29: with four cycles or more and its
/// period trend too weak to read, a Payne law must take a moving mean out
/// of the baseline's residual (its memory's own mark) to be named; this
/// one takes none.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn quadratic_damping_12000_is_not_named_amplitude_stiffness() {
    only_dataset(&options("dynamic", 1, 12000, &["quadratic_damping"]));
}

/// Found in session 27 on fresh scroll-only seed 13400 (`--kind scroll
/// --count 10`) and not fixed, the same family as 12708 and 12903: the
/// bearing-friction truth 13402 is named power-law damping (32.4 BIC
/// below the baseline, 25 ahead of bearing friction; 0.170 → 0.073 N·m
/// against a 0.081 N·m floor). Session 26's build names it too. Fixed
/// in session 38: its measured torque grows slower with the speed than
/// the baseline's by less than a sound belt's scatter
/// (`diagnose_scroll::SUBLINEAR_FLOOR`), and the answer is `none`. Fails
/// on `cb55514`.
#[test]
fn a_bearing_friction_is_not_a_power_law_seed_13402() {
    only_dataset(&options("scroll", 1, 13402, &["bearing_friction"]));
}

/// Found in session 27's held-out run (seed 13600) and not fixed: on the
/// belt of seed 13602 (474 samples at 50 Hz, 1.12 mm of marker noise)
/// the clean series is named amplitude stiffness, a Payne law of depth
/// 0.104 (1.361 → 1.174 mm, 83 BIC ahead of the refitted shape), and the
/// quadratic-damping truth (magnitude 0.77) the cubic (k₃ =
/// −4.09 N·m/rad³, 1.637 → 1.163 mm, 46 ahead of joint friction). Both
/// stand on the fit alone: the period trend is −1.3 standard errors from
/// the baseline's in the data, and neither candidate makes any of it
/// (−0.0000/mm against the measured −0.0007 and −0.0009). A rule asking a
/// fit-alone name to move its trend towards the measured one would also
/// refuse seven right names of the held-out runs since seed 11400 whose
/// fitted trend moves away from it (quadratic damping 11402, 11503,
/// 11600, 11703, 12402; Payne 11700, 12400). The quadratic-damping
/// series' refitted table shape reaches 1.237 mm (the baseline 1.637) and
/// the cubic leads it by 52 BIC.
///
/// Session 29: the clean series is `none` now (a Payne law on a weak
/// period trend must show a moving mean; see
/// `a_clean_belt_is_not_named_payne_on_a_weak_trend_seed_13602`); the
/// quadratic damping's cubic, a law without memory, is still named.
///
/// Session 30: a cubic is no longer named on a period trend that is not
/// read (its only signature; the refitted shape is the static curve's
/// part). The quadratic damping is `none` now, a miss, not a wrong name.
/// Fails on session 29's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn the_belt_of_seed_13602_is_not_named_amplitude_stiffness() {
    only_dataset(&options("dynamic", 1, 13602, &["quadratic_damping"]));
}

/// Session 29: the clean series of seed 13602 was named amplitude
/// stiffness, a Payne law of depth 0.104 (1.361 → 1.174 mm, 83 BIC ahead
/// of the refitted shape), its period trend 1.3 standard errors from the
/// baseline's and no moving mean in the baseline's residual. A Payne law
/// on a trend too weak to read must now take out such a mean; this one is
/// `none`. Fails on session 28's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_clean_belt_is_not_named_payne_on_a_weak_trend_seed_13602() {
    expect_answer(&options("dynamic", 1, 13602, &["none"]), "none");
}

/// Found in session 29's run at seed 14500 (its final build) and not
/// fixed: the clean series 14504 (185 samples, 0.57 mm of marker noise) is
/// named amplitude stiffness, the memory-less cubic (k₃ = −5.91 N·m/rad³,
/// 0.725 → 0.619 mm at the floor), 20.0 BIC ahead of the refitted table
/// shape, exactly `diagnose_dynamic::WEAK_SIGNATURE_LEAD`, with its period
/// trend 1.0 standard error from the baseline's. The same kind as the
/// quadratic damping of seed 13602: a cubic on a weak trend, which only
/// changes the static bending curve the refitted shape also fits.
///
/// Session 30: fixed with 13602's quadratic damping (a cubic on a trend
/// that is not read is not named); the answer is `none`, which is right.
/// Fails on session 29's build.
#[test]
fn a_clean_belt_is_not_named_the_cubic_seed_14504() {
    expect_answer(&options("dynamic", 1, 14504, &["none"]), "none");
}

/// Found in session 28's held-out run (seed 14200) and not fixed: the
/// joint-friction truth 14200 (magnitude 0.53, a Dahl law: 0.038 N·m,
/// pre-sliding 0.171) is named amplitude stiffness, a Payne law of depth
/// 0.155 whose mean follows in 5.4 s (2.096 → 1.111 mm at the floor,
/// 31 BIC ahead of quadratic damping, over the 20 of
/// `diagnose_dynamic::WEAK_SIGNATURE_LEAD`). It stands on the fit alone:
/// the period trend is 0.7 standard errors from the baseline's. As the
/// amplitude falls 43 → 7 mm the measured decrement halves (0.76 → 0.38)
/// and the period shortens (0.777 → 0.678 s): a friction inside its
/// pre-sliding range is a stiffer, less damped joint at small amplitude,
/// which is also what a Payne softening at large amplitude makes. Fixed
/// in session 29: the Payne law takes no moving mean out of the
/// baseline's residual, which a name on a weak period trend now needs.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_joint_friction_is_not_named_amplitude_stiffness_seed_14200() {
    only_dataset(&options("dynamic", 1, 14200, &["joint_friction"]));
}

/// Found in session 29's run at seed 14400 (this session's build, before
/// the rule below): the quadratic-damping truth 14400 (magnitude 0.44, a
/// drag of exponent 1.94) was named amplitude stiffness, a Payne law of
/// depth 0.134 (1.922 → 1.409 mm at the floor, 24.5 BIC ahead of the
/// refitted shape), its period trend 0.6 standard errors from the
/// baseline's and no moving mean in the baseline's residual. With four
/// cycles or more and a trend too weak to read, a law with a memory must
/// now show its memory's own mark, the moving mean it takes out of the
/// baseline's residual; the right Payne names on a weak trend of held-out
/// seeds 14201 and 14403 and tuning seeds 700, 709, 714 and 718 all do.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn quadratic_damping_14400_is_not_named_amplitude_stiffness() {
    only_dataset(&options("dynamic", 1, 14400, &["quadratic_damping"]));
}

/// Session 29: a camera drift that leaves the measured height a single
/// "cycle" is not `none`. Held-out seed 14303 (1.5 mm/s): the drift made
/// the cycle reader find one cycle of 8.8 s, the disturbance test averaged
/// the residual over that "period", longer than the series after its
/// first 1.5 s, so it saw no slow mean at all, and a residual 8 × the
/// noise floor with lag-1 autocorrelation 0.98 was called model-shape
/// mismatch (`none`). The test now takes the baseline's period when fewer
/// than two measured cycles stand above the noise
/// (`diagnose_dynamic::disturbance_period`) and reads the mean moving by
/// 12.6 mm. Fails on session 28's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_drift_that_leaves_one_cycle_is_unexplained_seed_14303() {
    expect_answer(
        &options("dynamic", 1, 14303, &["camera_drift"]),
        "unexplained",
    );
}

/// Session 29: a baseline whose stiffness scale stops at its bound says
/// so. Held-out seed 14304's belt (1757 mm, 3.74 kg) is stiffer than the
/// params file's table can be scaled to (×2.00), and the recalibration on
/// its figures missed their period by 22 %; the evidence of its clean
/// series had to say how far the table was stretched and advise a refit
/// (`diagnose_dynamic::scale_note`), so that a user does not take the
/// answer at face value. Since session 42 the box is ×0.25–4 and the fit
/// ends inside it (×2.28 in session 29's trial of that box), beyond the
/// usual ×0.5–2, which the evidence names too. Fails on session 28's
/// build.
///
/// Session 50: the recalibration now restarts from other Z1 onsets
/// (`calibrate::Z1_RESTARTS_DEG`) and meets this dataset's figures
/// (1.5 %), so the diagnosis's baseline is that table at ×1.08, the
/// evidence has nothing to warn of, and the answer is `none` (the table's
/// shape refitted on the series reaches the floor). Both are checked: the
/// params file's table alone (the baseline a refused recalibration
/// leaves) still says it was stretched, and the diagnosis as shipped uses
/// the recalibrated table and does not. The second half fails on
/// session 49's build (its recalibration missed T by 22 % and was
/// refused).
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_baseline_stretched_beyond_the_usual_stiffness_says_so_seed_14304() {
    use trackbelt_host::diagnose_dynamic::diagnose_dynamic;
    use trackbelt_truth::{draw, generate, Outcome, SeriesKind};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("belt");
    generate(
        &draw(Outcome::None, SeriesKind::Dynamic, 14304).unwrap(),
        &dir,
    )
    .unwrap();
    let ds = trackbelt_host::dataset::load(&dir).unwrap();
    let mut file = trackbelt_host::catalogue::baseline(trackbelt::params::Variant::E38, None)
        .expect("the shipped E38 params file");
    file.belt = ds.belt.belt(file.belt.links);
    let d = &ds.dynamics[0];
    let s = d.series.as_ref().expect("a series");
    let alone = diagnose_dynamic(
        &[&file],
        "run-1",
        d.roller_kg,
        d.period_s,
        &s.t_s,
        &s.a_height_mm,
        &trackbelt_host::NoProgress,
    )
    .expect("diagnoses");
    assert!(
        alone
            .row
            .evidence
            .contains("the baseline's stiffness scale")
            && alone
                .row
                .evidence
                .contains("refit the table on this belt (`trackbelt calibrate`)"),
        "{}",
        alone.row.evidence
    );
    let d = only_dataset(&options("dynamic", 1, 14304, &["none"]));
    assert!(
        d.evidence
            .contains("method III recalibrated on this dataset's figures")
            && !d.evidence.contains("the baseline's stiffness scale"),
        "{}",
        d.evidence
    );
    assert_eq!(d.answer, "none", "{}", d.evidence);
}

/// Found in session 29's detection-limit run (`--kind scroll --count 10
/// --seed 16000 --magnitude 1`, fresh seeds): the torque drift 16009
/// (−1.3 %/s of the torque with a 4.7 % wander of period 6.1 s, over two
/// plateaus at 3.2 and 6.0 rad/s) was named thermal softening (0.0121 1/K,
/// 0.313 → 0.109 N·m) off the floor: across the windows the torque
/// followed the belt's temperature better than the time (Δχ² 7.1), while
/// inside the two speed groups it fell by 7.9 standard errors and followed
/// the time better by 10.8. The groups now contradict the pooled reading
/// there (`PooledSoftening::contradicted_by`), and the drift at constant
/// speed makes the answer `unexplained`. Fails on session 28's build.
#[test]
fn a_wandering_torque_drift_is_not_softening_seed_16009() {
    let mut opts = options("scroll", 1, 16009, &["torque_drift"]);
    opts.magnitude = Some(1.0);
    expect_answer(&opts, "unexplained");
}

/// Found in session 25's held-out run (seed 13000): the quadratic-damping
/// truth 13000 (magnitude 0.68, a drag of exponent 1.70) was named
/// amplitude stiffness, the cubic (k₃ = −17.4 N·m/rad³). Its period trend
/// against the amplitude stood 4.3 standard errors from the baseline's and
/// was reproduced, and it led quadratic damping by 10.6 at the noise floor,
/// over `evidence::BIC_MARGIN` (10). But quadratic damping reached the floor
/// too with its own signature, the decrement trend, at 3.2 standard errors:
/// both a stiffness and a damping reading were in the data. Such a rival
/// must now be led by `diagnose_dynamic::RIVAL_SIGNATURE_LEAD` (20); the
/// answer is `unexplained`. Fails on session 25's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn quadratic_damping_13000_is_not_named_amplitude_stiffness() {
    only_dataset(&options("dynamic", 1, 13000, &["quadratic_damping"]));
}

/// Found in session 24's fresh scroll run at seed 12200 and fixed in
/// session 34: torque-drift truth 12204 (magnitude 0.92: −2.5 %/s of the
/// RMS torque and a 6.1 s wander of 3.4 %) was named thermal softening
/// (0.0175 1/K, 28.0 BIC on 17 windows, its signature read). The belt
/// warms in step with the time on the plateaus, but across the whole run
/// a gain drifting in time fits better than one following the
/// temperature by Δχ² 36.9: softening is set aside
/// (`diagnose_scroll::drift_form_veto`). Fails on `8c22bbf`.
#[test]
fn a_torque_drift_is_not_softening_seed_12204() {
    only_dataset(&options("scroll", 1, 12204, &["torque_drift"]));
}

/// Found in session 31's final run at fresh seed 15000 (`9f71b41`) and not
/// fixed: torque-drift truth 15003 (magnitude 0.66: −1.5 %/s of the RMS
/// torque and a 3.4 s wander of 1.0 %) is named thermal softening
/// (0.0064 1/K, 25.1 BIC on 12 windows), read across the windows at
/// −0.0069 ± 0.0006 1/K with the temperature ahead of the time by Δχ²
/// 3.7 (the bar is 2). The same family as 11202 and 12204.
#[test]
#[ignore = "issue 11 open: torque-drift truth 15003 is named thermal softening"]
fn a_torque_drift_is_not_softening_seed_15003() {
    only_dataset(&options("scroll", 1, 15003, &["torque_drift"]));
}

/// Found in session 34's scroll run at fresh seed 16300 (`--kind scroll
/// --count 10`, main at `8c22bbf`) and not fixed: torque-drift truth
/// 16303 (magnitude 0.91) is named thermal softening (0.0147 1/K, 25.2
/// BIC on 15 windows), read across the windows at −0.0115 ± 0.0025 1/K
/// with the temperature ahead of the time by Δχ² 3.5 (the bar is 2).
/// Across the whole run an offset following the temperature reads best,
/// the offset in time 17.3 behind and the gain in time 7.0: the drift's
/// form does not tell it from softening either. The same family as
/// 11202 and 15003.
#[test]
#[ignore = "issue 11 open: torque-drift truth 16303 is named thermal softening"]
fn a_torque_drift_is_not_softening_seed_16303() {
    only_dataset(&options("scroll", 1, 16303, &["torque_drift"]));
}

/// Found in session 43's held-out run at fresh seed 18200 (main at
/// `995091a`) and not fixed: torque-drift truth 18200 (magnitude 0.90: a
/// logger's gain falling by 1.0 %/s with a 4.3 % wander over 7.0 s) is
/// named thermal softening (0.0118 1/K, 12.9 BIC on 10 windows, the
/// runner-up 22.9 behind). Inside two speed groups the torque fell with
/// the temperature by 5.4 standard errors over 7.3 K, and the temperature
/// beat the time by Δχ² 4.3 (the bar is 2); across the windows it fell by
/// only 1.6 standard errors; across the whole run softening's form led a
/// gain in time by 4.4. The same family as 11202, 15003 and 16303: on the
/// first plateau the belt warms in step with the time. No reading tells
/// these four from the 29 right softening names of the kept runs
/// 17000–18200, diagnosed again: the form's lead over a gain in time is
/// 3.2–7.0 on the four and 2.0–6.6 on five of the 29, and across the
/// windows the four fall by 1.6–10.9 standard errors, the right names by
/// 1.3 and more.
#[test]
#[ignore = "issue 11 open: torque-drift truth 18200 is named thermal softening"]
fn a_torque_drift_is_not_softening_seed_18200() {
    only_dataset(&options("scroll", 1, 18200, &["torque_drift"]));
}

/// Found in session 45's held-out run at fresh seed 19000 (main at
/// `1971990`) and not fixed: torque-drift truth 19002 (magnitude 0.81: a
/// logger's offset falling by 1.8 %/s of the RMS torque with a 3.7 %
/// wander of period 4.7 s over 9 s) is named thermal softening (0.0161
/// 1/K, 33.5 BIC on 13 windows, the runner-up 41.0 behind). The wander
/// happens to hold the torque flat on the one plateau where the belt's
/// temperature stays flat (2.7 rad/s, 32.4–32.7 °C), so every reading
/// sees softening: inside three speed groups the torque falls with the
/// temperature by 12 standard errors and the temperature beats the time
/// by Δχ² 20.9; across the windows by 5.5 standard errors and Δχ² 14.8.
/// Across the whole run an offset following the temperature reads best
/// and a gain in the temperature and in the time tie (2.8 and 3.0 behind
/// it). The same family as 11202, 15003, 16303 and 18200.
#[test]
#[ignore = "issue 11 open: torque-drift truth 19002 is named thermal softening"]
fn a_torque_drift_is_not_softening_seed_19002() {
    only_dataset(&options("scroll", 1, 19002, &["torque_drift"]));
}

/// Found in session 46's fresh scroll-only run at seed 47000 (`--kind
/// scroll --count 40`, the build of `ae58e5a`; main's build at `ae150c3`
/// answers the same) and not fixed: torque-drift truth 47008 (magnitude
/// 0.47: a logger's offset falling by 0.61 %/s with a 2.2 % wander of
/// period 6.0 s, on two plateaus) is named thermal softening (0.0119 1/K,
/// 32.9 BIC on 13 windows). Across the windows the torque falls with the
/// temperature by 4.6 standard errors and follows it better than the
/// time by Δχ² 2.8; inside the two speed groups it falls by 5.1 standard
/// errors and follows the time better by 3.9, within what right softening
/// names show (18902: −5.6; 44031: −3.0); across the run a gain following
/// the temperature leads a gain in time by 11.7. The same family as
/// 11202, 15003, 16303, 18200 and 19002.
#[test]
#[ignore = "issue 11 open: torque-drift truth 47008 is named thermal softening"]
fn a_torque_drift_is_not_softening_seed_47008() {
    only_dataset(&options("scroll", 1, 47008, &["torque_drift"]));
}

/// Session 45: thermal softening weighed beside this belt's torque–speed
/// shape refitted, against the shape alone
/// (`diagnose_scroll::softening_on_the_shape`, private). Softening truths
/// 43021 and 43023 (fresh scroll seed 43000, `--count 40`) were `none`:
/// against the baseline's curve the law alone lowered the BIC by 2.3 and
/// 1.2, while beside the refitted shape it lowers it by 52.4 and 64.4 and
/// leaves 0.93 and 0.50 × the noise floor. Two torque drifts stay
/// unnamed: 43014, which took 17.6 below the shape alone with no drift
/// across the run (Δχ² 4.7), and 44017 (fresh seed 44000), named by the
/// first version of the rule on a temperature ahead of the time by only
/// Δχ² 2.8. Four scroll series, about 2 s each. Fails on `4db48ce`.
#[test]
fn softening_is_weighed_beside_the_refitted_shape_seeds_43021_43023() {
    for seed in [43021, 43023] {
        expect_answer(
            &options("scroll", 1, seed, &["thermal_softening"]),
            "thermal_softening",
        );
    }
    expect_answer(&options("scroll", 1, 43014, &["torque_drift"]), "none");
    expect_answer(&options("scroll", 1, 44017, &["torque_drift"]), "none");
}

/// Found in session 45's scroll run at fresh seed 44000 (`--kind scroll
/// --count 40`) and not fixed; main's build (`1971990`) answers the same.
/// The clean belt 44028 is named thermal softening, and so was the
/// bearing friction 44028 (0.37 N·m on the idler, the same belt, rig and
/// speed profile) until session 45 raised `SOFTENING_OVER_OFFSET` (see
/// `a_form_that_barely_leads_a_logger_offset_is_not_softening_seeds_42023_44028_44035`).
/// The belt's torque–speed curve is not the baseline's (its torque per
/// rad/s is 0.45 N·m·s at 7.5 rad/s and 0.38–0.39 at 1.7–6 rad/s) and
/// the profile visits the top speed first, on a cold belt, so across the
/// windows the torque beside a quadratic in ln |ω| falls with the
/// temperature (−0.0221 ± 0.0071 1/K, the temperature ahead of the time
/// by Δχ² 10.9), while inside the four speed groups it rises by 1.1
/// standard errors. It is named on that reading (24.7 BIC, leaving 5.1 ×
/// the floor). The softening truth of the same seed reads alike (flat in
/// the groups, −0.0195 ± 0.0046 1/K across the windows) and is named
/// right.
#[test]
#[ignore = "issue 11 open: the clean belt 44028 is named thermal softening"]
fn a_curve_visited_hot_to_cold_is_not_softening_seed_44028() {
    only_dataset(&options("scroll", 1, 44028, &["none"]));
}

/// Session 45: softening's form across the run must lead a logger's
/// offset in time by `SOFTENING_OVER_OFFSET` = 16 (strong evidence, as a
/// drift in time needs to refuse softening), no longer 12. Three wrong
/// names of the fresh scroll runs 42000 and 44000 (`--kind scroll
/// --count 40`, main at `1971990`) were given by this reading with the
/// offset in time behind by 12.2–13.4, while the 28 right names it gave
/// on 945 kept scroll series led by 14.0–92.1:
/// * bearing friction 42023 (0.20 N·m on the idler): a gain falling by
///   0.12 %/K, Δχ² 20.4 over no drift, 12.5 ahead of an offset in time;
///   the law's own refit found 0.0000 1/K (the residual 0.088 → 0.088
///   N·m). A rule asking that refit to lower the BIC (`15818a0`) fixed it
///   but took five right names on the next two fresh runs and was
///   reverted (`4db48ce`). Now `unexplained` (its drift at constant
///   speed).
/// * bearing friction 44028 (0.37 N·m on the idler): 13.4 ahead, now
///   `unexplained`. The clean belt of the same seed is named by another
///   reading and stays open
///   (`a_curve_visited_hot_to_cold_is_not_softening_seed_44028`).
/// * torque drift 44035: a gain falling by 0.45 %/K, Δχ² 54.4 over no
///   drift, 12.2 ahead of an offset in time, the law alone taking the
///   residual only from 0.207 to 0.187 N·m; now `none`.
///
/// The softening truths 42023 and 44023, named by the same reading 92.1
/// and 76.1 ahead, keep their names. Five scroll series, about 1 s each.
/// Fails on `71b28ce`.
#[test]
fn a_form_that_barely_leads_a_logger_offset_is_not_softening_seeds_42023_44028_44035() {
    expect_answer(
        &options("scroll", 1, 42023, &["bearing_friction"]),
        "unexplained",
    );
    expect_answer(
        &options("scroll", 1, 44028, &["bearing_friction"]),
        "unexplained",
    );
    expect_answer(&options("scroll", 1, 44035, &["torque_drift"]), "none");
    for seed in [42023, 44023] {
        expect_answer(
            &options("scroll", 1, seed, &["thermal_softening"]),
            "thermal_softening",
        );
    }
}

/// Session 46, on the kept scroll series of session 45's runs: on two
/// steady plateaus bearing friction and a power law fit alike, and 37 of
/// 160 power-law truths of seeds 42000–45039 were `unexplained` for it
/// alone. The ramps between the plateaus now name a power law there when
/// it leads on them by [`RAMP_SEPARATION`]
/// (`diagnose_scroll::power_law_on_the_ramps`): power law 46010 (62.0,
/// 26.7 ahead) is named. Power law 42003 (40.3 BIC, 12.9 ahead) was named
/// too until session 60, when the bar on the ramps went from 12 to 16:
/// bearing frictions were named a power law there by 13.0–14.3 (see
/// `a_bearing_friction_is_not_named_a_power_law_on_the_ramps_seeds_49518_49605`),
/// so a lead of 12.9 does not tell the truths apart, and 42003 is
/// `unexplained`, a miss and not a wrong name. A constant torque that
/// wins the ramps is never named there (the rig model's misfit on the
/// ramps looks like one): bearing friction 42025 wins them by 12.4 and
/// stays `unexplained`, as does 43005, which no family leads there. Four
/// scroll series, about 1 s each. Fails on `ae150c3` (46010 `unexplained`)
/// and on `14854b9` (42003 named).
///
/// [`RAMP_SEPARATION`]: trackbelt_host::diagnose_scroll::RAMP_SEPARATION
#[test]
fn a_power_law_on_two_plateaus_is_named_on_the_ramps_seeds_42003_46010() {
    expect_answer(
        &options("scroll", 1, 46010, &["rate_dependent_damping"]),
        "rate_dependent_damping",
    );
    let d = only_dataset(&options("scroll", 1, 42003, &["rate_dependent_damping"]));
    assert_eq!(d.answer, "unexplained", "{}", d.evidence);
    assert!(
        d.evidence
            .contains("but a power law needs a lead of 16 there"),
        "42003 should be refused for its lead on the ramps: {}",
        d.evidence
    );
    for seed in [42025, 43005] {
        expect_answer(
            &options("scroll", 1, seed, &["bearing_friction"]),
            "unexplained",
        );
    }
}

/// Session 46, on the kept scroll series of session 45's runs: a power
/// law that wins the steady windows, with a bearing friction set aside
/// because the plateaus' curve flattens (the power law's shape) but
/// fitting within the separation, was refused (15 power-law truths on
/// 1540 series). It is named now when the curve flattens against the
/// baseline's own curve too (`diagnose_scroll::flattening_decides`):
/// power laws 43019 (−0.34 ± 0.03 against the baseline) and 44019
/// (−0.23 ± 0.05). Bearing friction 42036 flattens by −0.55 ± 0.14 as
/// measured, but −0.39 of it is the baseline's own curve (−0.15 ± 0.14
/// against it): it stays `unexplained`, and a first version of the rule
/// that read the measured curve alone named it a power law. Three scroll
/// series, about 1 s each. Fails on `ae150c3`.
#[test]
fn a_power_law_whose_curve_flattens_against_the_baseline_is_named_seeds_43019_44019() {
    for seed in [43019, 44019] {
        expect_answer(
            &options("scroll", 1, seed, &["rate_dependent_damping"]),
            "rate_dependent_damping",
        );
    }
    expect_answer(
        &options("scroll", 1, 42036, &["bearing_friction"]),
        "unexplained",
    );
}

/// Session 47, on the kept scroll series of seeds 42000–47039: a
/// softening whose fit beside the baseline came out negative (the
/// baseline's curve mismatch rising with the temperature, which rises
/// with the speed) was dropped, so the drift's form across the run,
/// softening's, had no candidate to name (23 softening truths of 240).
/// The fit beside this belt's refitted shape stands for it now
/// (`diagnose_scroll::softening_by_form`): softening 43003 (`none` on
/// `663c4fc`; the form leads an offset in time by Δχ² 17.1) and 44024
/// (`unexplained` there; Δχ² 87.2) are named. Two scroll series, about
/// 1 s each.
#[test]
fn a_softening_whose_plain_fit_came_out_negative_is_named_by_its_form_seeds_43003_44024() {
    for seed in [43003, 44024] {
        expect_answer(
            &options("scroll", 1, seed, &["thermal_softening"]),
            "thermal_softening",
        );
    }
}

/// Session 48, on the kept dynamic series of the full runs 18700–19400:
/// a camera shake that dies out within a few seconds is diluted in the
/// whole residual's spectrum and gone from the record's second half, and
/// was answered `none`. Its line in the residual's first 3 s
/// (`diagnose_dynamic::early_line`, at 2.5 belt frequencies or more and
/// not at a harmonic the model carries) finds it: shakes 19202 (6.7 Hz,
/// 51 × the median power, 4.0 × the belt's 1.65 Hz) and 19204 (4.0 Hz,
/// 39 ×, 2.8 × the belt's 1.41 Hz) are `unexplained`. Both were `none`
/// on `f065281`. Two dynamic series, about 20 s each.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_shake_that_dies_out_early_is_found_in_the_record_s_first_seconds_seeds_19202_19204() {
    for seed in [19202, 19204] {
        expect_answer(
            &options("dynamic", 1, seed, &["camera_shake"]),
            "unexplained",
        );
    }
}

/// Session 54, on the kept dynamic series of the full run 20500: camera
/// shake 20500 (3.4 mm at 7.3 Hz from about 1.2 s, decaying at 0.77/s,
/// under 1.1 mm of marker noise) started too late for the record's first
/// 3 s, was gone by its second half and diluted in the whole record, and
/// was answered `none`. A line in any 2 s stretch of the residual
/// (`diagnose_dynamic::brief_line`, read as `early_line` reads its
/// window) finds it between 1.0 s and 3.0 s at 42 × the median power: it
/// is `unexplained`. `none` on `1e488f3`. One dynamic series, about 20 s.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_camera_knocked_into_shaking_after_the_start_is_found_seed_20500() {
    expect_answer(
        &options("dynamic", 1, 20500, &["camera_shake"]),
        "unexplained",
    );
}

/// `validate::again` (`validate-diagnosis --again DIR`) diagnoses a kept
/// run's datasets again and compares: on the run as kept nothing
/// changes; an answer altered in its `validate.json` shows as changed
/// (and the kept figures count it); the kind and outcome filters keep
/// only their datasets, and count the figures before on those alone; a
/// directory without a report, an unknown name and a filter that keeps
/// nothing are errors. Two scroll series, about 1 s each.
#[test]
fn a_kept_run_diagnosed_again_reports_what_changed() {
    let dir = tempfile::tempdir().unwrap();
    let keep = dir.path().join("kept");
    let opts = Options {
        keep_dir: Some(keep.clone()),
        ..options("scroll", 1, 9001, &["none", "slip_bursts"])
    };
    let r = run_expecting(&opts, 2);
    let write = |doc: &serde_json::Value| {
        std::fs::write(keep.join("validate.json"), doc.to_string()).unwrap();
    };
    let mut doc = serde_json::to_value(&r).unwrap();
    write(&doc);
    let same =
        trackbelt_host::validate::again(&keep, &[], &[], 2, &trackbelt_host::NoProgress).unwrap();
    assert!(same.changed.is_empty(), "{:?}", same.changed);
    assert_eq!(same.right_before, r.summary.right);
    assert_eq!(same.report.summary.right, r.summary.right);
    let answers = |rep: &Report| {
        rep.datasets
            .iter()
            .map(|d| d.answer.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(answers(&same.report), answers(&r));
    // The kept run said the slip bursts were a bearing friction.
    let row = &mut doc["datasets"][1];
    assert_eq!(row["outcome"], "slip_bursts");
    row["answer"] = "bearing_friction".into();
    row["right"] = false.into();
    row["wrong_name"] = true.into();
    write(&doc);
    let moved =
        trackbelt_host::validate::again(&keep, &[], &[], 1, &trackbelt_host::NoProgress).unwrap();
    assert_eq!(moved.changed.len(), 1);
    let c = &moved.changed[0];
    assert_eq!(
        c.dataset,
        format!("slip_bursts-scroll-{}", r.datasets[1].seed)
    );
    assert_eq!(
        (c.before.as_str(), c.after.as_str()),
        ("bearing_friction", r.datasets[1].answer.as_str())
    );
    assert_eq!(moved.wrong_names_before, 1);
    assert_eq!(moved.report.summary.wrong_names, r.summary.wrong_names);
    // Filtered: the clean series alone, then the slip bursts alone.
    let only = |kinds: &[&str], outcomes: &[&str]| {
        let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        trackbelt_host::validate::again(
            &keep,
            &s(kinds),
            &s(outcomes),
            1,
            &trackbelt_host::NoProgress,
        )
    };
    let clean = only(&["scroll"], &["none"]).unwrap();
    assert_eq!(answers(&clean.report), vec![r.datasets[0].answer.clone()]);
    assert!(clean.changed.is_empty(), "{:?}", clean.changed);
    assert_eq!(clean.wrong_names_before, 0);
    assert_eq!(clean.right_before, usize::from(r.datasets[0].right));
    let bursts = only(&[], &["slip_bursts"]).unwrap();
    assert_eq!(bursts.report.summary.datasets, 1);
    assert_eq!(bursts.changed, moved.changed);
    assert_eq!(bursts.wrong_names_before, 1);
    // Unknown names and a filter that keeps nothing are errors.
    let e = only(&["sideways"], &[]).unwrap_err().to_string();
    assert!(e.contains("sideways"), "{e}");
    let e = only(&[], &["gremlins"]).unwrap_err().to_string();
    assert!(e.contains("gremlins"), "{e}");
    let e = only(&["dynamic"], &[]).unwrap_err().to_string();
    assert!(e.contains("no kept dataset"), "{e}");
    // No report: the error names the file.
    let e = trackbelt_host::validate::again(dir.path(), &[], &[], 1, &trackbelt_host::NoProgress)
        .unwrap_err()
        .to_string();
    assert!(e.contains("validate.json"), "{e}");
}

/// Found in session 25's fresh scroll checks (seeds 12600, 12700, 12900,
/// `--kind scroll --count 10`), on the build before and after that
/// session's changes, and not fixed: the torque–speed family's two
/// members are told apart by a BIC lead that the baseline's shape
/// mismatch can make. Power law 12600 (α 0.40) is named bearing friction
/// 12.1 ahead; bearing friction 12708 (0.16 N·m on the idler) and 12903
/// (0.50 N·m on the drive) are named power-law damping 14.0 and 22.0
/// ahead. Right names of the two families on the same sets lead by
/// 12.6–27.5.
#[test]
#[ignore = "issue 11 open: power law 12600 is named bearing friction"]
fn a_power_law_is_not_bearing_friction_seed_12600() {
    only_dataset(&options("scroll", 1, 12600, &["rate_dependent_damping"]));
}

/// See `a_power_law_is_not_bearing_friction_seed_12600`. Fixed in
/// session 38 (12600 is not): the two bearing frictions' torque grows
/// slower with the speed than the baseline's by less than a sound belt's
/// scatter (`diagnose_scroll::SUBLINEAR_FLOOR`), and both are `none`.
/// Fails on `cb55514`.
#[test]
fn a_bearing_friction_is_not_a_power_law_seeds_12708_12903() {
    only_dataset(&options("scroll", 1, 12708, &["bearing_friction"]));
    only_dataset(&options("scroll", 1, 12903, &["bearing_friction"]));
}

/// Found in session 30's run at seed 14700 (its final build): the marker
/// slip 14703 (−2.3 mm at 3.65 s) was named amplitude stiffness, a Payne
/// law 27.5 BIC ahead of the refitted shape, its period trend read at 9.2
/// standard errors and reproduced. The belt's own bending curve makes
/// that trend (its clean series 14703 has the same periods, 0.750 →
/// 0.784 s, and the refitted shape takes it to the floor there), and the
/// Payne law took the slip as the moving mean its memory makes. A law
/// with a memory that leans on it for the baseline's moving mean now
/// meets the rivals with a slow mean (a step, a line and a step) with its
/// signature read, as it did on the fit alone: a step at 3.66 s in what
/// the refitted shape leaves fits 27 BIC better. `unexplained`, right.
/// Fails on session 29's build.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_slipping_marker_is_not_a_payne_memory_seed_14703() {
    expect_answer(
        &options("dynamic", 1, 14703, &["marker_slip"]),
        "unexplained",
    );
}

/// Found in session 30's run at fresh seed 14800 (the final build,
/// `92a6134`) and not fixed: the Payne truth 14803 (depth 0.27, a mean
/// that follows in 2.0 s), on a belt the shipped table fits poorly (its
/// clean series goes 3.89 → 0.93 mm by the refitted shape alone), is
/// named quadratic damping, 43.6 BIC ahead of the Payne law at
/// the floor (3.52 → 0.96 mm). The drop lasts two or three cycles, so no
/// per-cycle trend is read and the name stands on the fit alone; on so
/// few cycles a law with a memory and an amplitude-dependent damping both
/// reshape the same short decay.
/// Session 56 ran every ignored test on main (`c67468c`): this one
/// passes now (no wrong name; the answer is in the ignore reason). The
/// session that fixed it is not known. In the full tier (`cargo test-full`).
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn an_amplitude_stiffness_is_not_named_quadratic_damping_seed_14803() {
    only_dataset(&options("dynamic", 1, 14803, &["amplitude_stiffness"]));
}

/// Found in session 30's run at fresh seed 14800 and fixed in session 31:
/// joint friction 14803 (Dahl, magnitude 0.83) on a heavily damped belt
/// (the dataset states a period of 0.430 s and a log decrement of 1.04)
/// swings past four noise floors fewer than twice, and so does the
/// baseline's trace. The belt's period was then read as 0, every spectral
/// line counted as "not a harmonic of the belt's 0.00 Hz", and the line
/// the refitted shape leaves at 2.21 Hz (0.52 mm: the belt's own swing,
/// 5 % from its stated frequency) made the friction, fitted 162 BIC ahead
/// of the shape at the floor, `unexplained`. The dataset's stated period
/// is now the belt's when the series reads none. Fails on `f44a778`.
#[test]
#[cfg_attr(
    not(feature = "full-suite"),
    ignore = "full tier (CI time): run with `cargo test-full`"
)]
fn a_heavily_damped_drop_keeps_its_own_line_seed_14803() {
    expect_answer(
        &options("dynamic", 1, 14803, &["joint_friction"]),
        "joint_friction",
    );
}

/// Found in session 37's run at fresh seed 17200 (main's build at the
/// session's start answers it the same): joint friction 17204
/// (magnitude 0.83, 0.58 mm of marker noise, 366 samples) is named
/// quadratic damping, 207.9 BIC down and 56 ahead of the runner-up, at
/// the floor (0.874 → 0.590 mm), while the decrement's trend against the
/// amplitude is not read (−1.7 standard errors from the baseline).
/// The candidate's own trend was +0.0104/mm against the baseline's
/// +0.0078 and the measured +0.0007 ± 0.0042: the other way, 2.3
/// standard errors from the candidate's. Since session 38 that
/// contradicts the name (`SignatureCheck::AgainstCandidate`); the answer
/// is `none`. Fails on `cb55514`.
#[test]
fn a_joint_friction_is_not_named_quadratic_damping_seed_17204() {
    only_dataset(&options("dynamic", 1, 17204, &["joint_friction"]));
}

/// Found in session 38's run at fresh seed 17300 (main's build,
/// `cb55514`): the clean scroll belt 17302 was named power-law damping
/// (exponent 0.9 beside the linear damping), 16.5 BIC down on 16
/// effective samples, 12.4 ahead of bearing friction. Its measured
/// torque grew slower with the speed than the baseline's by a log–log
/// slope of −0.069 ± 0.013: 5.3 standard errors by the plateaus' noise,
/// but within a sound belt's scatter from belt to belt
/// (`SUBLINEAR_FLOOR`). The power law of the same seed (slope −0.244)
/// keeps its name. Fails on `cb55514`.
#[test]
fn a_clean_belt_is_not_named_a_power_law_seed_17302() {
    expect_answers(
        &options("scroll", 1, 17302, &["none", "rate_dependent_damping"]),
        &[
            ("none", "none"),
            ("rate_dependent_damping", "rate_dependent_damping"),
        ],
    );
}

/// A dataset that holds a power-law belt's rig run *and* its drop test
/// (the truth's `generate_beside`, as the `beside --series`
/// example writes it). On the drop test a power-law damping of exponent
/// under 1 makes the log decrement grow as the amplitude falls, joint
/// friction's signature, and the dynamic diagnosis has no power-law
/// candidate; the rig run, `unexplained`, does not refuse the name. So
/// the dataset is named joint friction: 2 of the 20 power-law belts of
/// seeds 70000–70019 (70005, 70018), the only wrong names of the 80
/// mixed datasets of session 70. Single-kind datasets, which the
/// validation draws, never show it.
#[test]
#[ignore = "issue 11 open: a power-law belt's drop test beside its rig run is named joint friction (seeds 70005, 70018)"]
fn a_power_law_belt_s_drop_test_is_not_named_joint_friction_seeds_70005_70018() {
    use trackbelt_truth::{draw, generate_beside, EffectKind, Outcome, SeriesKind};
    for seed in [70005, 70018] {
        let sc = draw(
            Outcome::Effect(EffectKind::RateDependentDamping),
            SeriesKind::Scroll,
            seed,
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let ds = dir.path().join("mixed");
        generate_beside(&sc, &ds, true).unwrap();
        let d = trackbelt_host::diagnose::diagnose_dir(
            &ds,
            trackbelt::params::Variant::E38,
            None,
            &trackbelt_host::NoProgress,
        )
        .unwrap();
        let v = d.report.verdict.expect("two series: a verdict");
        eprintln!("{seed}: {} | {}", v.effect, v.evidence);
        assert!(
            v.effect == "rate_dependent_damping" || !trackbelt_host::verdict::is_name(&v.effect),
            "power-law belt {seed} named {}: {}",
            v.effect,
            v.evidence
        );
    }
}

/// Found in session 73's held-out run at seed 83000 (`validate-diagnosis
/// --count 5 --seed 83000`, the final build `ea57990`) and not fixed: the
/// clean belt 83003 and its bearing-friction twin (the same rig, belt and
/// ramp, 15 windows from 3.3 to 6.8 rad/s) are both named power-law
/// damping beside the linear damping, 56.0 and 70.0 below the baseline
/// (exponents 0.9 and 0.7), the bearing friction 23.4 ahead of its own
/// family. The class of 61018 and 74007: the baseline's torque–speed
/// curve is not this belt's, and the power law's tilt takes up the
/// difference. Run by hand:
///   cargo test --release -p trackbelt-host-tests --test validate -- --ignored seed_83003
#[test]
#[ignore = "issue 11 open: clean belt 83003 and its bearing-friction twin are named a power law"]
fn a_clean_belt_and_its_bearing_friction_are_not_a_power_law_seed_83003() {
    run_without_wrong_name(
        &options("scroll", 1, 83003, &["none", "bearing_friction"]),
        2,
    );
}
