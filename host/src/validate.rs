//! The diagnosis scored on data it did not make (issue 11, `trackbelt
//! validate-diagnosis`): datasets drawn at random by the independent truth
//! generator ([`trackbelt_truth`]) for every outcome — `none` in dynamic
//! and in scroll series, each of the six catalogue effects, each
//! disturbance outside the catalogue — are written, diagnosed with
//! [`diagnose_dir`] (variant E38, its default
//! params, no hint) and the answers put against the truth's.
//!
//! The [`Report`] holds the confusion matrix (rows: the truth's outcome;
//! columns: the diagnosed answer), the share of right answers, the number
//! of wrong names (an effect named that is not the truth's; `unexplained`
//! or `none` for an effect is a miss, not a wrong name), whether each named
//! effect brought the residual near the noise put in ([`near_noise`]), and
//! the residuals before/after and the times per dataset.
//!
//! Dataset `i` (0-based) of an outcome is drawn with the truth seed
//! `seed + i` (`trackbelt_truth::draw(outcome, kind, seed + i)`), the same
//! seeds for every outcome, so `--seed 5000` checks on seeds 5000, 5001, …
//! that a diagnosis tuned on seeds below 1000 never saw. A draw the truth
//! simulator cannot run (unstable, invalid) is skipped, listed in
//! [`Report::skipped`], and replaced by the next seed after the last one of
//! that outcome. Datasets are diagnosed in parallel; every answer and
//! residual is the same for any number of threads (only the times differ).
//! The times are wall times of one dataset while the others run on the
//! same pool of [`Options::threads`] workers (the diagnosis's own
//! simulations share it); `threads: 1` gives the one-core figures.

use crate::diagnose::diagnose_dir;
use crate::error::{Error, Result};
use crate::evidence::{CandidateRow, ResultRow};
use crate::parallel::map_isolated;
use crate::progress::Progress;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;
use trackbelt::params::Variant;
use trackbelt_truth::{DisturbanceKind, EffectKind, Outcome, SeriesKind};

/// The issue's target share of right answers.
pub const TARGET_RIGHT_FRACTION: f64 = 0.9;
/// The issue's target: datasets per outcome at least.
pub const TARGET_MIN_PER_OUTCOME: usize = 5;
/// A named effect is near the noise when its residual is at most this
/// many times the noise put in …
pub const NEAR_NOISE_FACTOR: f64 = 1.25;
/// … or at most the baseline's residual divided by this.
pub const NEAR_NOISE_REDUCTION: f64 = 3.0;
/// Rounds of redraws after failed draws before the run gives up.
pub const MAX_REDRAW_ROUNDS: usize = 4;
/// The variant every dataset is diagnosed with.
pub const VARIANT: Variant = Variant::E38;

/// What to run.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Datasets per outcome (and per series kind for `none`), at least 1.
    pub count_per_outcome: usize,
    /// First truth seed of every outcome.
    pub seed: u64,
    /// Worker threads (at least 1); the answers do not depend on it.
    pub threads: usize,
    /// Keep the datasets in this directory (`<outcome>-<kind>-<seed>/`);
    /// none of them may exist yet (nothing is overwritten). Without it every dataset lives
    /// in a temporary directory removed after its diagnosis.
    pub keep_dir: Option<PathBuf>,
    /// Only these series kinds (`dynamic`, `scroll`); empty: both.
    pub kinds: Vec<String>,
    /// Only these outcomes (`none`, an effect identifier or a disturbance
    /// name, see [`outcome_names`]); empty: all.
    pub outcomes: Vec<String>,
    /// Draw every effect and disturbance at this magnitude
    /// (`trackbelt_truth::draw_at`: 1 clearly visible, 0.35 moderate, at
    /// most [`MAX_MAGNITUDE`]) instead of uniform in 0.35–1: the
    /// detection limit of an effect is read from runs at a few
    /// magnitudes. Every other variation is drawn from the seed as
    /// before, so a run at another magnitude changes only the effect's
    /// size. `None`: drawn at random.
    pub magnitude: Option<f64>,
    /// Also measure each effect dataset's evidence ceiling
    /// ([`trackbelt_truth::ceiling`]: the most evidence of its effect the
    /// data hold once the clean belt's stiffness, curvatures and damping
    /// are fitted with the truth's own law), so that a miss the data could
    /// not support is told from one the diagnosis should have made
    /// ([`by_ceiling`]). Costs up to about 160 more truth runs per effect
    /// dataset.
    pub ceiling: bool,
    /// Also measure each effect dataset's rival ceilings
    /// ([`trackbelt_truth::ceiling::rival_ceiling`]: how far the effect
    /// stands from each other effect of its kind, that effect's law fitted
    /// with the clean belt's factors) and count the right answers by the
    /// separation, the smallest of the evidence ceiling and the rival
    /// ceilings ([`by_separation`]). Implies [`Options::ceiling`]; costs
    /// about twice its runs again per rival.
    pub rivals: bool,
    /// Runs of the same belt per dataset beyond the first (0: one run, as
    /// the truth draws it). Each repeat is
    /// [`trackbelt_truth::Scenario::repeat`]: another roller and camera on
    /// a drop test, another speed profile and warming on the same rig,
    /// noise of its own; every series is diagnosed and the dataset answers
    /// by [`crate::verdict::dataset_verdict`]. The first run is the
    /// dataset a run without repeats draws, so the same seeds answer how
    /// much a second or third run of the belt adds. The ceilings are the
    /// first run's. At most [`MAX_REPEATS`].
    pub repeats: usize,
}

/// Largest [`Options::repeats`].
pub const MAX_REPEATS: usize = 5;

/// Largest magnitude [`Options::magnitude`] takes (the truth generator's
/// own bound).
pub const MAX_MAGNITUDE: f64 = 5.0;

/// Median and maximum of a set of values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// Median (mean of the middle two for an even count).
    pub median: f64,
    /// Maximum.
    pub max: f64,
}

impl Stats {
    /// Of the finite values of `v`; `None` when there is none.
    pub fn of(v: impl IntoIterator<Item = f64>) -> Option<Stats> {
        let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
        Some(Stats {
            median: crate::evidence::median(v.iter().copied())?,
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// One dataset: what the truth put in, what the diagnosis said.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DatasetResult {
    /// The truth's outcome (`none`, an effect identifier or a disturbance name).
    pub outcome: String,
    /// `dynamic` or `scroll`.
    pub kind: String,
    /// Truth seed (`trackbelt_truth::draw(outcome, kind, seed)`).
    pub seed: u64,
    /// The right answer (`none`, the effect's identifier or `unexplained`).
    pub expected: String,
    /// The diagnosis's answer (`none`, an effect identifier,
    /// `unexplained`, or `error` when the diagnosis failed).
    pub answer: String,
    /// `answer == expected`.
    pub right: bool,
    /// An effect named that is not the truth's.
    pub wrong_name: bool,
    /// Magnitude knob of the effect or disturbance (0.35–1).
    pub magnitude: f64,
    /// The truth's description of what it switched on.
    pub description: String,
    /// RMS residual of the refitted baseline (NaN when the diagnosis failed).
    pub rms_before: f64,
    /// RMS residual after (NaN when the diagnosis failed).
    pub rms_after: f64,
    /// RMS of the white noise put into the main channel.
    pub noise_rms: f64,
    /// Unit of the three (`mm` or `N·m`).
    pub unit: String,
    /// For a named effect: whether [`near_noise`] holds; `None` otherwise.
    pub near_noise: Option<bool>,
    /// Time to generate the dataset, s.
    pub generate_s: f64,
    /// Time to diagnose it, s.
    pub diagnose_s: f64,
    /// The dataset's directory when kept.
    pub dir: Option<PathBuf>,
    /// The diagnosis's reason, or its error message.
    pub evidence: String,
    /// For an effect dataset when [`Options::ceiling`] is set: its
    /// evidence ceiling, Δχ² in units of the noise put in
    /// ([`trackbelt_truth::ceiling::Ceiling::chi2`]).
    pub evidence_ceiling: Option<f64>,
    /// Why the evidence ceiling of an effect dataset could not be measured
    /// (the dataset's answer still counts).
    pub ceiling_error: Option<String>,
    /// For an effect dataset when [`Options::rivals`] is set: its rival
    /// ceiling against each other effect of its kind.
    pub rival_ceilings: Vec<RivalChi2>,
    /// The answering row's candidates, largest BIC gain first
    /// ([`crate::evidence::ResultRow::candidates`]): what the decision
    /// weighed, for reading a run's evidence by number. Empty when the
    /// diagnosis failed, and in a kept run's record read back for
    /// [`again`] (which diagnoses anew).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub candidates: Vec<CandidateRow>,
    /// With several runs per dataset ([`Options::repeats`]): each
    /// series' own answer, in the dataset's order (the first is the
    /// answer the first run alone gets); empty (and left out of the JSON)
    /// with one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub series_answers: Vec<String>,
}

/// One rival ceiling of an effect dataset ([`Options::rivals`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RivalChi2 {
    /// The rival effect's identifier.
    pub rival: String,
    /// Δχ² against the best twin with the rival's law
    /// ([`trackbelt_truth::ceiling::RivalCeiling::chi2`]), in units of the
    /// noise put in; `None` when it could not be measured.
    pub chi2: Option<f64>,
    /// Why it could not be measured.
    pub error: Option<String>,
}

impl DatasetResult {
    /// How far the effect stands from the nearest explanation that is not
    /// the effect: the smallest of the evidence ceiling and the rival
    /// ceilings, with what it was measured against (`"clean"` or the
    /// rival's identifier). `None` unless the evidence ceiling and every
    /// rival ceiling were measured.
    ///
    /// ```
    /// use trackbelt_host::validate::{DatasetResult, RivalChi2};
    /// let mut d = DatasetResult {
    ///     outcome: "bearing_friction".into(), kind: "scroll".into(), seed: 1,
    ///     expected: "bearing_friction".into(), answer: "unexplained".into(),
    ///     right: false, wrong_name: false, magnitude: 0.5, description: String::new(),
    ///     rms_before: 1.0, rms_after: 1.0, noise_rms: 1.0, unit: "N·m".into(), near_noise: None,
    ///     generate_s: 0.1, diagnose_s: 1.0, dir: None, evidence: String::new(),
    ///     evidence_ceiling: Some(92.0), ceiling_error: None,
    ///     rival_ceilings: vec![RivalChi2 { rival: "rate_dependent_damping".into(), chi2: Some(13.7), error: None }],
    ///     candidates: Vec::new(), series_answers: Vec::new(),
    /// };
    /// assert_eq!(d.separation(), Some((13.7, "rate_dependent_damping")));
    /// d.rival_ceilings[0].chi2 = None;
    /// assert_eq!(d.separation(), None);
    /// ```
    pub fn separation(&self) -> Option<(f64, &str)> {
        let mut best = (self.evidence_ceiling.filter(|c| !c.is_nan())?, "clean");
        if self.rival_ceilings.is_empty() {
            return None;
        }
        for r in &self.rival_ceilings {
            let c = r.chi2.filter(|c| !c.is_nan())?;
            if c < best.0 {
                best = (c, r.rival.as_str());
            }
        }
        Some(best)
    }
}

/// Evidence ceilings (Δχ²) that split the effect datasets in
/// [`by_ceiling`]: under the first, no method can name the effect (a name
/// needs an information-criterion gain of about ten plus the effect's
/// parameters times ln n); from the second up, the data carry it clearly.
pub const CEILING_BINS: [f64; 2] = [20.0, 100.0];

/// Right answers among one effect's datasets with their ceiling in each
/// of the three ranges [`CEILING_BINS`] makes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CeilingRow {
    /// The effect's identifier.
    pub effect: String,
    /// `(right, datasets)` under [`CEILING_BINS`]`[0]`, between the two,
    /// and from [`CEILING_BINS`]`[1]` up.
    pub bins: [(usize, usize); 3],
}

/// The effect datasets of `datasets` that carry an evidence ceiling,
/// counted by effect and ceiling range (effects in order of first
/// appearance); empty without ceilings.
///
/// ```
/// use trackbelt_host::validate::{by_ceiling, DatasetResult};
/// let d = |right: bool, c: f64| DatasetResult {
///     outcome: "quadratic_damping".into(), kind: "dynamic".into(), seed: 1,
///     expected: "quadratic_damping".into(), answer: if right { "quadratic_damping" } else { "none" }.into(),
///     right, wrong_name: false, magnitude: 0.5, description: String::new(),
///     rms_before: 1.0, rms_after: 1.0, noise_rms: 1.0, unit: "mm".into(), near_noise: None,
///     generate_s: 0.1, diagnose_s: 1.0, dir: None, evidence: String::new(),
///     evidence_ceiling: Some(c), ceiling_error: None, rival_ceilings: Vec::new(),
///     candidates: Vec::new(), series_answers: Vec::new(),
/// };
/// let rows = by_ceiling(&[d(false, 4.0), d(true, 45.0), d(false, 900.0), d(true, 120.0)]);
/// assert_eq!(rows[0].bins, [(0, 1), (1, 1), (1, 2)]);
/// ```
pub fn by_ceiling(datasets: &[DatasetResult]) -> Vec<CeilingRow> {
    binned(datasets, |d| d.evidence_ceiling.filter(|c| !c.is_nan()))
}

/// As [`by_ceiling`], by the separation ([`DatasetResult::separation`]:
/// the smaller of the evidence ceiling and the rival ceilings) instead;
/// empty without rival ceilings.
///
/// ```
/// use trackbelt_host::validate::{by_separation, DatasetResult, RivalChi2};
/// let d = |right: bool, c: f64, r: f64| DatasetResult {
///     outcome: "bearing_friction".into(), kind: "scroll".into(), seed: 1,
///     expected: "bearing_friction".into(), answer: if right { "bearing_friction" } else { "none" }.into(),
///     right, wrong_name: false, magnitude: 0.5, description: String::new(),
///     rms_before: 1.0, rms_after: 1.0, noise_rms: 1.0, unit: "N·m".into(), near_noise: None,
///     generate_s: 0.1, diagnose_s: 1.0, dir: None, evidence: String::new(),
///     evidence_ceiling: Some(c), ceiling_error: None,
///     rival_ceilings: vec![RivalChi2 { rival: "rate_dependent_damping".into(), chi2: Some(r), error: None }],
///     candidates: Vec::new(), series_answers: Vec::new(),
/// };
/// // A large ceiling against the clean belt, a small one against the rival.
/// let rows = by_separation(&[d(false, 900.0, 12.0), d(true, 400.0, 150.0)]);
/// assert_eq!(rows[0].bins, [(0, 1), (0, 0), (1, 1)]);
/// ```
pub fn by_separation(datasets: &[DatasetResult]) -> Vec<CeilingRow> {
    binned(datasets, |d| d.separation().map(|s| s.0))
}

/// Right answers by effect and [`CEILING_BINS`] range of `key`, over the
/// datasets where it is measured.
fn binned(
    datasets: &[DatasetResult],
    key: impl Fn(&DatasetResult) -> Option<f64>,
) -> Vec<CeilingRow> {
    let mut rows: Vec<CeilingRow> = Vec::new();
    for d in datasets {
        let Some(c) = key(d) else {
            continue;
        };
        let bin = CEILING_BINS.iter().filter(|&&b| c >= b).count();
        let i = match rows.iter().position(|r| r.effect == d.outcome) {
            Some(i) => i,
            None => {
                rows.push(CeilingRow {
                    effect: d.outcome.clone(),
                    bins: [(0, 0); 3],
                });
                rows.len() - 1
            }
        };
        rows[i].bins[bin].0 += usize::from(d.right);
        rows[i].bins[bin].1 += 1;
    }
    rows
}

/// How the datasets score on their first `runs` runs alone
/// ([`by_runs`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunsRow {
    /// Runs of each dataset counted (the first ones).
    pub runs: usize,
    /// Datasets scored.
    pub datasets: usize,
    /// Right answers.
    pub right: usize,
    /// Effects named that are not the truth's.
    pub wrong_names: usize,
}

/// With several runs per dataset: the score on the first 1, 2, … runs
/// of each, from the series' own answers
/// ([`DatasetResult::series_answers`]) combined as the dataset's verdict
/// combines them ([`crate::verdict::combined_answer`]); the last row is
/// the run's own score. Empty when a dataset has no series answers (one
/// run each, or a failed diagnosis). Each series was diagnosed against
/// the whole dataset's baseline: a drop-test dataset is recalibrated on
/// the figures of all its runs, so on dynamic series the first run's
/// answer here can differ from the answer of the one-run dataset of the
/// same seed (on scroll series without static figures it cannot).
///
/// ```
/// # use trackbelt_host::validate::{by_runs, DatasetResult};
/// let d = |expected: &str, answers: &[&str]| DatasetResult {
///     outcome: expected.into(), kind: "dynamic".into(), seed: 1, expected: expected.into(),
///     answer: String::new(), right: false, wrong_name: false, magnitude: 0.5,
///     description: String::new(), rms_before: 1.0, rms_after: 1.0, noise_rms: 1.0,
///     unit: "mm".into(), near_noise: None, generate_s: 0.1, diagnose_s: 1.0, dir: None,
///     evidence: String::new(), evidence_ceiling: None, ceiling_error: None,
///     rival_ceilings: Vec::new(), candidates: Vec::new(),
///     series_answers: answers.iter().map(|s| s.to_string()).collect(),
/// };
/// let rows = by_runs(&[d("joint_friction", &["none", "joint_friction"]), d("none", &["none", "none"])]);
/// assert_eq!((rows[0].runs, rows[0].right), (1, 1));
/// assert_eq!((rows[1].runs, rows[1].right, rows[1].wrong_names), (2, 2, 0));
/// ```
pub fn by_runs(datasets: &[DatasetResult]) -> Vec<RunsRow> {
    let Some(most) = datasets.iter().map(|d| d.series_answers.len()).min() else {
        return Vec::new();
    };
    if most < 2 {
        return Vec::new();
    }
    (1..=most)
        .map(|k| {
            let (mut right, mut wrong_names) = (0, 0);
            for d in datasets {
                let first: Vec<&str> = d.series_answers[..k].iter().map(String::as_str).collect();
                let a = crate::verdict::combined_answer(&first);
                right += usize::from(a == d.expected);
                wrong_names += usize::from(is_name(a) && a != d.expected);
            }
            RunsRow {
                runs: k,
                datasets: datasets.len(),
                right,
                wrong_names,
            }
        })
        .collect()
}

/// A draw the truth simulator could not run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Skipped {
    /// The outcome.
    pub outcome: String,
    /// The series kind.
    pub kind: String,
    /// The seed.
    pub seed: u64,
    /// Why.
    pub reason: String,
}

/// Residuals of one row of the matrix.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RowErrors {
    /// Unit of the residuals.
    pub unit: String,
    /// Baseline residual.
    pub rms_before: Option<Stats>,
    /// Residual after the diagnosis.
    pub rms_after: Option<Stats>,
    /// Noise put in.
    pub noise: Option<Stats>,
    /// Diagnosis time per dataset, s.
    pub diagnose_s: Option<Stats>,
}

/// One row of the confusion matrix: one truth outcome (and series kind).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MatrixRow {
    /// The truth's outcome.
    pub outcome: String,
    /// `dynamic` or `scroll`.
    pub kind: String,
    /// The right answer.
    pub expected: String,
    /// Datasets per answer, in the order of [`Matrix::columns`].
    pub counts: Vec<usize>,
    /// Datasets in the row.
    pub total: usize,
    /// Right answers.
    pub right: usize,
    /// Wrong names.
    pub wrong_names: usize,
    /// Residuals.
    pub errors: RowErrors,
}

/// The confusion matrix.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Matrix {
    /// Answers: `none`, the six effects, `unexplained`, then any other
    /// answer that occurred (`error`, unknown names), sorted.
    pub columns: Vec<String>,
    /// Truth outcomes: `none` (dynamic), `none` (scroll), the effects, the
    /// disturbances (those that occurred).
    pub rows: Vec<MatrixRow>,
}

/// The headline figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Datasets diagnosed.
    pub datasets: usize,
    /// Right answers.
    pub right: usize,
    /// `right / datasets` (0 when there is none).
    pub right_fraction: f64,
    /// Effects named that are not the truth's.
    pub wrong_names: usize,
    /// Datasets where the diagnosis failed (column `error`).
    pub errors: usize,
    /// Datasets where an effect was named (right or wrong).
    pub named: usize,
    /// Of those, how many meet [`near_noise`].
    pub near_noise_met: usize,
    /// Fewest datasets of any row.
    pub min_per_outcome: usize,
    /// All of the issue's targets hold: right fraction ≥
    /// [`TARGET_RIGHT_FRACTION`], no wrong name, every named effect near
    /// the noise, at least [`TARGET_MIN_PER_OUTCOME`] datasets per outcome.
    pub target_met: bool,
    /// Generation time per dataset, s.
    pub generate_s: Option<Stats>,
    /// Diagnosis time per dataset, s.
    pub diagnose_s: Option<Stats>,
    /// Diagnosis time per dynamic dataset, s.
    pub diagnose_dynamic_s: Option<Stats>,
    /// Diagnosis time per scroll dataset, s.
    pub diagnose_scroll_s: Option<Stats>,
}

/// The `validate-diagnosis --json` document.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// First truth seed.
    pub seed: u64,
    /// Datasets asked per outcome.
    pub count_per_outcome: usize,
    /// The magnitude every effect and disturbance was drawn at
    /// ([`Options::magnitude`]); `None`: uniform in 0.35–1.
    pub magnitude: Option<f64>,
    /// Worker threads.
    pub threads: usize,
    /// Runs of one belt in each dataset (1 unless [`Options::repeats`]).
    pub runs_per_dataset: usize,
    /// Variant diagnosed with.
    pub variant: String,
    /// Headline figures.
    pub summary: Summary,
    /// The confusion matrix.
    pub matrix: Matrix,
    /// Every dataset, by row then seed.
    pub datasets: Vec<DatasetResult>,
    /// Draws the truth simulator could not run.
    pub skipped: Vec<Skipped>,
    /// The effects' right answers by evidence ceiling ([`by_ceiling`];
    /// empty without [`Options::ceiling`]).
    pub by_ceiling: Vec<CeilingRow>,
    /// The effects' right answers by separation ([`by_separation`]; empty
    /// without [`Options::rivals`]).
    pub by_separation: Vec<CeilingRow>,
    /// With several runs per dataset: the score on each dataset's first
    /// 1, 2, … runs ([`by_runs`]; empty, and left out of the JSON, with
    /// one run).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub by_runs: Vec<RunsRow>,
    /// Wall time of the run, s.
    pub wall_s: f64,
}

/// The "near the noise" criterion of a named effect: `rms_after ≤ 1.25 ×
/// noise` or `rms_after ≤ rms_before / 3`.
pub fn near_noise(rms_before: f64, rms_after: f64, noise: f64) -> bool {
    rms_after <= NEAR_NOISE_FACTOR * noise || rms_after <= rms_before / NEAR_NOISE_REDUCTION
}

/// Whether `answer` names an effect (anything but `none`, `unexplained`
/// and `error`).
pub fn is_name(answer: &str) -> bool {
    crate::verdict::is_name(answer)
}

/// Every outcome with the series kinds it is drawn in, in the matrix's
/// row order.
pub fn all_cases() -> Vec<(Outcome, SeriesKind)> {
    let mut v = vec![
        (Outcome::None, SeriesKind::Dynamic),
        (Outcome::None, SeriesKind::Scroll),
    ];
    v.extend(
        EffectKind::ALL
            .iter()
            .map(|&e| (Outcome::Effect(e), e.kind())),
    );
    v.extend(
        DisturbanceKind::ALL
            .iter()
            .map(|&d| (Outcome::Disturbance(d), d.kind())),
    );
    v
}

/// The outcome names [`Options::outcomes`] takes.
pub fn outcome_names() -> Vec<&'static str> {
    let mut v = vec!["none"];
    for (o, _) in all_cases() {
        if !v.contains(&o.as_str()) {
            v.push(o.as_str());
        }
    }
    v
}

/// Checks the kind and outcome filters ([`Options::kinds`],
/// [`Options::outcomes`]): every name must be one they take.
fn check_filters(kinds: &[String], outcomes: &[String]) -> Result<()> {
    for k in kinds {
        if k != "dynamic" && k != "scroll" {
            return Err(Error::InvalidArgument(format!(
                "series kind {k:?}: expected dynamic or scroll"
            )));
        }
    }
    let names = outcome_names();
    for o in outcomes {
        if !names.contains(&o.as_str()) {
            return Err(Error::InvalidArgument(format!(
                "outcome {o:?}: expected one of {}",
                names.join(", ")
            )));
        }
    }
    Ok(())
}

/// Whether an `outcome` of series `kind` passes the filters (an empty
/// filter passes everything).
fn passes(kinds: &[String], outcomes: &[String], outcome: &str, kind: &str) -> bool {
    (kinds.is_empty() || kinds.iter().any(|x| x == kind))
        && (outcomes.is_empty() || outcomes.iter().any(|x| x == outcome))
}

/// The cases `opts` selects.
fn selected(opts: &Options) -> Result<Vec<(Outcome, SeriesKind)>> {
    check_filters(&opts.kinds, &opts.outcomes)?;
    let cases: Vec<_> = all_cases()
        .into_iter()
        .filter(|(o, k)| passes(&opts.kinds, &opts.outcomes, o.as_str(), k.as_str()))
        .collect();
    if cases.is_empty() {
        return Err(Error::InvalidArgument(
            "no outcome left: the kind and outcome filters exclude each other".into(),
        ));
    }
    Ok(cases)
}

/// One dataset to make and diagnose.
#[derive(Debug, Clone, Copy)]
struct Job {
    outcome: Outcome,
    kind: SeriesKind,
    seed: u64,
    magnitude: Option<f64>,
    ceiling: bool,
    rivals: bool,
    runs: u32,
}

impl Job {
    fn name(&self) -> String {
        dataset_name(self.outcome.as_str(), self.kind.as_str(), self.seed)
    }
}

/// The directory name of a kept dataset: `<outcome>-<kind>-<seed>`.
fn dataset_name(outcome: &str, kind: &str, seed: u64) -> String {
    format!("{outcome}-{kind}-{seed}")
}

/// What became of one job.
enum JobResult {
    Done(Box<DatasetResult>),
    /// The truth could not simulate the draw.
    Skipped(String),
}

/// Progress steps of one dataset's generation …
const GENERATE_STEPS: u64 = 20;
/// … and of its diagnosis (its simulations scaled to it).
const DIAGNOSE_STEPS: u64 = 80;

/// Forwards the diagnosis's steps to the run's progress, scaled from the
/// bound the diagnosis announces to [`DIAGNOSE_STEPS`].
struct Forward<'a> {
    outer: &'a dyn Progress,
    bound: AtomicU64,
    done: AtomicU64,
    sent: AtomicU64,
}

impl<'a> Forward<'a> {
    /// Forwarding to `outer`, nothing sent yet.
    fn new(outer: &'a dyn Progress) -> Self {
        Self {
            outer,
            bound: AtomicU64::new(0),
            done: AtomicU64::new(0),
            sent: AtomicU64::new(0),
        }
    }

    /// Bring the outer steps sent up to `target`.
    fn send(&self, target: u64) {
        let prev = self.sent.fetch_max(target, Ordering::Relaxed);
        for _ in prev..target {
            self.outer.step();
        }
    }

    /// Step the rest of [`DIAGNOSE_STEPS`].
    fn finish(&self) {
        self.send(DIAGNOSE_STEPS);
    }
}

impl Progress for Forward<'_> {
    fn set_total(&self, total: u64) {
        self.bound.store(total, Ordering::Relaxed);
    }
    fn step(&self) {
        let k = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let bound = self.bound.load(Ordering::Relaxed);
        if let Some(q) = (DIAGNOSE_STEPS * k).checked_div(bound) {
            self.send(q.min(DIAGNOSE_STEPS));
        }
    }
}

/// A temporary directory named from `prefix`, removed when dropped.
fn temp_dir(prefix: &str) -> Result<tempfile::TempDir> {
    tempfile::Builder::new()
        .prefix(prefix)
        .tempdir()
        .map_err(|source| Error::Io {
            action: "cannot make a temporary directory",
            path: std::env::temp_dir(),
            source,
        })
}

fn run_job(job: &Job, keep: Option<&Path>, progress: &dyn Progress) -> Result<JobResult> {
    let t0 = Instant::now();
    let tmp;
    let dir = match keep {
        Some(k) => k.join(job.name()),
        None => {
            tmp = temp_dir("trackbelt-validate-")?;
            tmp.path().join(job.name())
        }
    };
    let drawn = match job.magnitude {
        Some(m) => trackbelt_truth::draw_at(job.outcome, job.kind, job.seed, m),
        None => trackbelt_truth::draw(job.outcome, job.kind, job.seed),
    };
    let generated = drawn.and_then(|sc| {
        let runs: Vec<_> = (0..job.runs.max(1)).map(|r| sc.repeat(r)).collect();
        trackbelt_truth::generate_runs(&runs, &dir).map(|t| (sc, t))
    });
    let (scenario, truth) = match generated {
        Ok(t) => t,
        Err(e @ (trackbelt_truth::Error::Unstable { .. } | trackbelt_truth::Error::Invalid(_))) => {
            for _ in 0..GENERATE_STEPS {
                progress.step();
            }
            // The truth made the directory; leave no empty one behind.
            let _ = std::fs::remove_dir(&dir);
            return Ok(JobResult::Skipped(e.to_string()));
        }
        Err(e) => return Err(Error::Truth(e).context(format!("dataset {}", job.name()))),
    };
    let generate_s = t0.elapsed().as_secs_f64();
    for _ in 0..GENERATE_STEPS {
        progress.step();
    }
    let expected = truth.expected.to_string();
    let d = diagnose_scored(&dir, &expected, truth.noise_unit, truth.noise_rms, progress);
    // The evidence ceiling, in a scratch directory of its own.
    let (mut evidence_ceiling, mut ceiling_error) = (None, None);
    if job.ceiling && matches!(job.outcome, Outcome::Effect(_)) {
        let scratch = temp_dir("trackbelt-ceiling-")?;
        match trackbelt_truth::ceiling::ceiling(&scenario, &scratch.path().join("run")) {
            Ok(c) => evidence_ceiling = Some(c.chi2),
            Err(e) => ceiling_error = Some(e.to_string()),
        }
    }
    // Its rival ceilings, each in a scratch directory of its own.
    let mut rival_ceilings = Vec::new();
    if let (true, Outcome::Effect(effect)) = (job.rivals, job.outcome) {
        for rival in trackbelt_truth::EffectKind::ALL
            .into_iter()
            .filter(|r| *r != effect && r.kind() == job.kind)
        {
            let scratch = temp_dir("trackbelt-rival-")?;
            let c = trackbelt_truth::ceiling::rival_ceiling(
                &scenario,
                rival,
                &scratch.path().join("run"),
            );
            rival_ceilings.push(RivalChi2 {
                rival: rival.as_str().to_string(),
                chi2: c.as_ref().ok().map(|c| c.chi2),
                error: c.err().map(|e| e.to_string()),
            });
        }
    }
    Ok(JobResult::Done(Box::new(DatasetResult {
        outcome: job.outcome.as_str().to_string(),
        kind: job.kind.as_str().to_string(),
        seed: job.seed,
        right: d.right,
        wrong_name: d.wrong_name,
        expected,
        answer: d.answer,
        magnitude: truth.magnitude,
        description: truth.description,
        rms_before: d.rms_before,
        rms_after: d.rms_after,
        noise_rms: truth.noise_rms,
        unit: d.unit,
        near_noise: d.near_noise,
        generate_s,
        diagnose_s: d.diagnose_s,
        dir: keep.map(|_| dir.clone()),
        evidence: d.evidence,
        evidence_ceiling,
        ceiling_error,
        rival_ceilings,
        candidates: d.candidates,
        series_answers: d.series_answers,
    })))
}

/// A dataset's diagnosis, answered ([`answer_of`]) and scored
/// ([`scored`]): what a fresh run and [`again`] both record of it.
struct Diagnosed {
    answer: String,
    right: bool,
    wrong_name: bool,
    rms_before: f64,
    rms_after: f64,
    unit: String,
    near_noise: Option<bool>,
    diagnose_s: f64,
    evidence: String,
    candidates: Vec<CandidateRow>,
    series_answers: Vec<String>,
}

/// Diagnose the dataset in `dir` (its steps forwarded to `progress`),
/// answer for it and score the answer against `expected`, for noise of
/// `noise_rms` put in, in `noise_unit`.
fn diagnose_scored(
    dir: &Path,
    expected: &str,
    noise_unit: &str,
    noise_rms: f64,
    progress: &dyn Progress,
) -> Diagnosed {
    let t1 = Instant::now();
    let fwd = Forward::new(progress);
    let diagnosis = diagnose_dir(dir, VARIANT, None, &fwd);
    let diagnose_s = t1.elapsed().as_secs_f64();
    fwd.finish();
    let (row, series_answers) = answer_of(diagnosis, noise_unit);
    let (right, wrong_name, near_noise) = scored(
        &row.effect,
        expected,
        &row.unit,
        noise_unit,
        (row.rms_before, row.rms_after),
        noise_rms,
    );
    Diagnosed {
        answer: row.effect,
        right,
        wrong_name,
        rms_before: row.rms_before,
        rms_after: row.rms_after,
        unit: row.unit,
        near_noise,
        diagnose_s,
        evidence: row.evidence,
        candidates: row.candidates,
        series_answers,
    }
}

/// The row that answers for a dataset's diagnosis, with the series'
/// own answers when there are several: one series answers for itself;
/// several answer together ([`crate::verdict::dataset_verdict`]: the
/// verdict's effect and evidence on the row of the series that answers
/// for it). A failed diagnosis answers `error` (its message as the
/// evidence, the residuals NaN, in `noise_unit`, no candidates).
fn answer_of(
    diagnosis: Result<crate::diagnose::Diagnosis>,
    noise_unit: &str,
) -> (ResultRow, Vec<String>) {
    let failed = |why: String| ResultRow {
        series: String::new(),
        kind: String::new(),
        effect: "error".to_string(),
        rms_before: f64::NAN,
        rms_after: f64::NAN,
        unit: noise_unit.to_string(),
        evidence: why,
        candidates: Vec::new(),
        gain_samples: None,
    };
    match diagnosis {
        Ok(d) => {
            let mut rows = d.report.results;
            let series = if rows.len() > 1 {
                rows.iter().map(|r| r.effect.clone()).collect()
            } else {
                Vec::new()
            };
            match crate::verdict::dataset_verdict(&rows) {
                Some(v) if v.row < rows.len() => {
                    let mut row = rows.swap_remove(v.row);
                    row.effect = v.effect;
                    row.evidence = v.evidence;
                    (row, series)
                }
                _ => (
                    failed("the diagnosis returned no result".to_string()),
                    series,
                ),
            }
        }
        Err(e) => (failed(e.to_string()), Vec::new()),
    }
}

/// How `answer` scores against `expected`: right, a wrong name (an
/// effect named that is not the truth's), and for a name in the noise's
/// unit (`unit` against `noise_unit`) whether its residuals `(before,
/// after)` meet [`near_noise`] for the noise put in, `noise_rms`.
fn scored(
    answer: &str,
    expected: &str,
    unit: &str,
    noise_unit: &str,
    (rms_before, rms_after): (f64, f64),
    noise_rms: f64,
) -> (bool, bool, Option<bool>) {
    let named = is_name(answer);
    let near = (named && unit == noise_unit).then(|| near_noise(rms_before, rms_after, noise_rms));
    (answer == expected, named && answer != expected, near)
}

/// One dataset whose answer changed when a kept run was diagnosed again
/// ([`again`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Changed {
    /// The dataset's directory name (`<outcome>-<kind>-<seed>`).
    pub dataset: String,
    /// The right answer.
    pub expected: String,
    /// The kept run's answer.
    pub before: String,
    /// This build's answer.
    pub after: String,
}

/// A kept run diagnosed again by this build ([`again`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Again {
    /// The new report, on the same datasets (nothing is generated: every
    /// `generate_s` is 0; the ceilings are the kept run's).
    pub report: Report,
    /// Right answers of the kept run on those datasets.
    pub right_before: usize,
    /// Wrong names of the kept run on those datasets.
    pub wrong_names_before: usize,
    /// Every answer that differs, in the report's order.
    pub changed: Vec<Changed>,
}

/// The datasets of a kept run's `validate.json` (`path`, parsed as
/// `doc`), each with its directory under `dir`.
fn kept_datasets(doc: &serde_json::Value, dir: &Path, path: &Path) -> Result<Vec<DatasetResult>> {
    let bad = |what: String| {
        Error::InvalidArgument(format!(
            "{}: {what}: not a report of `validate-diagnosis --keep`",
            path.display()
        ))
    };
    let rows = doc
        .get("datasets")
        .and_then(|d| d.as_array())
        .ok_or_else(|| bad("no `datasets` list".into()))?;
    rows.iter()
        .enumerate()
        .map(|(i, row)| {
            let text = |key: &str| {
                row.get(key)
                    .and_then(|v| v.as_str())
                    .map(str::to_string)
                    .ok_or_else(|| bad(format!("dataset {i}: no text `{key}`")))
            };
            let number = |key: &str| row.get(key).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
            let seed = row
                .get("seed")
                .and_then(|v| v.as_u64())
                .ok_or_else(|| bad(format!("dataset {i}: no `seed`")))?;
            let (outcome, kind) = (text("outcome")?, text("kind")?);
            let rival_ceilings = row
                .get("rival_ceilings")
                .and_then(|v| v.as_array())
                .map(|a| {
                    a.iter()
                        .map(|r| RivalChi2 {
                            rival: r.get("rival").and_then(|v| v.as_str()).unwrap_or("").into(),
                            chi2: r.get("chi2").and_then(|v| v.as_f64()),
                            error: r.get("error").and_then(|v| v.as_str()).map(str::to_string),
                        })
                        .collect()
                })
                .unwrap_or_default();
            Ok(DatasetResult {
                expected: text("expected")?,
                answer: text("answer")?,
                right: row.get("right").and_then(|v| v.as_bool()).unwrap_or(false),
                wrong_name: row
                    .get("wrong_name")
                    .and_then(|v| v.as_bool())
                    .unwrap_or(false),
                magnitude: number("magnitude"),
                description: text("description").unwrap_or_default(),
                rms_before: number("rms_before"),
                rms_after: number("rms_after"),
                noise_rms: number("noise_rms"),
                unit: text("unit")?,
                near_noise: row.get("near_noise").and_then(|v| v.as_bool()),
                generate_s: 0.0,
                diagnose_s: number("diagnose_s"),
                dir: Some(dir.join(dataset_name(&outcome, &kind, seed))),
                evidence: text("evidence").unwrap_or_default(),
                evidence_ceiling: row.get("evidence_ceiling").and_then(|v| v.as_f64()),
                ceiling_error: text("ceiling_error").ok(),
                rival_ceilings,
                candidates: Vec::new(),
                series_answers: row
                    .get("series_answers")
                    .and_then(|v| v.as_array())
                    .map(|a| {
                        a.iter()
                            .filter_map(|v| v.as_str().map(str::to_string))
                            .collect()
                    })
                    .unwrap_or_default(),
                outcome,
                kind,
                seed,
            })
        })
        .collect()
}

/// Diagnose again, with this build, the datasets a `validate-diagnosis
/// --keep DIR` run left in `dir`, and compare the answers with the ones
/// its `validate.json` holds: a rule is checked on every kept run this
/// way before it meets a fresh one, and the record's "re-diagnosed from
/// the kept datasets" figures are made so. Nothing in `dir` is written;
/// each dataset is read from `dir/<outcome>-<kind>-<seed>/`, so a kept
/// run may be moved. Only the kept datasets of the series `kinds` and the
/// `outcomes` asked are diagnosed (empty: all; the names of
/// [`Options::kinds`] and [`Options::outcomes`]), and the figures before
/// are counted on those alone: the scroll part of a kept full run is
/// checked in minutes, where its dynamic series take about 20 s each.
/// `threads` workers, one dataset each (the answers do not depend on it).
///
/// Errors: a kind or outcome that is no such name; `validate.json`
/// missing or unreadable, or not such a report (the message says which
/// file and, for JSON, which line); no kept dataset passing the filters.
/// A dataset that cannot be diagnosed answers `error`, as in [`run`].
pub fn again(
    dir: &Path,
    kinds: &[String],
    outcomes: &[String],
    threads: usize,
    progress: &dyn Progress,
) -> Result<Again> {
    check_filters(kinds, outcomes)?;
    let t0 = Instant::now();
    let path = dir.join("validate.json");
    let text = std::fs::read_to_string(&path).map_err(|source| Error::Io {
        action: "cannot read",
        path: path.clone(),
        source,
    })?;
    let doc: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        Error::InvalidArgument(format!(
            "{}: {e}: not a report of `validate-diagnosis --keep`",
            path.display()
        ))
    })?;
    let kept: Vec<DatasetResult> = kept_datasets(&doc, dir, &path)?
        .into_iter()
        .filter(|d| passes(kinds, outcomes, &d.outcome, &d.kind))
        .collect();
    if kept.is_empty() {
        return Err(Error::InvalidArgument(format!(
            "{}: no kept dataset of the kinds and outcomes asked",
            path.display()
        )));
    }
    progress.set_total(DIAGNOSE_STEPS * kept.len() as u64);
    let threads = threads.max(1);
    let results: Vec<DatasetResult> = map_isolated(&kept, threads, |old| {
        // (`kept_datasets` set every directory.)
        let target = old.dir.clone().unwrap_or_default();
        let d = diagnose_scored(&target, &old.expected, &old.unit, old.noise_rms, progress);
        DatasetResult {
            right: d.right,
            wrong_name: d.wrong_name,
            answer: d.answer,
            rms_before: d.rms_before,
            rms_after: d.rms_after,
            unit: d.unit,
            near_noise: d.near_noise,
            diagnose_s: d.diagnose_s,
            evidence: d.evidence,
            candidates: d.candidates,
            series_answers: d.series_answers,
            ..old.clone()
        }
    });
    let changed = kept
        .iter()
        .zip(&results)
        .filter(|(k, d)| k.answer != d.answer)
        .map(|(k, d)| Changed {
            dataset: dataset_name(&d.outcome, &d.kind, d.seed),
            expected: d.expected.clone(),
            before: k.answer.clone(),
            after: d.answer.clone(),
        })
        .collect();
    let right_before = kept.iter().filter(|k| k.right).count();
    let wrong_names_before = kept.iter().filter(|k| k.wrong_name).count();
    let field = |key: &str| doc.get(key).and_then(|v| v.as_u64()).unwrap_or(0);
    Ok(Again {
        report: report(
            Settings {
                seed: field("seed"),
                count_per_outcome: field("count_per_outcome") as usize,
                magnitude: doc.get("magnitude").and_then(|v| v.as_f64()),
                threads,
                runs_per_dataset: (field("runs_per_dataset") as usize).max(1),
            },
            results,
            Vec::new(),
            t0,
        ),
        right_before,
        wrong_names_before,
        changed,
    })
}

/// The confusion matrix and summary of `datasets` (rows in the order of
/// first appearance, which [`run`] makes the order of [`all_cases`]).
pub fn tabulate(datasets: &[DatasetResult]) -> (Matrix, Summary) {
    let mut columns: Vec<String> = std::iter::once("none")
        .chain(EffectKind::ALL.iter().map(|e| e.as_str()))
        .chain(std::iter::once("unexplained"))
        .map(String::from)
        .collect();
    let mut extra: Vec<String> = datasets
        .iter()
        .map(|d| d.answer.clone())
        .filter(|a| !columns.contains(a))
        .collect();
    extra.sort();
    extra.dedup();
    columns.extend(extra);
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for d in datasets {
        let k = (d.outcome.as_str(), d.kind.as_str());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    let rows: Vec<MatrixRow> = keys
        .iter()
        .map(|&(outcome, kind)| {
            let ds: Vec<&DatasetResult> = datasets
                .iter()
                .filter(|d| d.outcome == outcome && d.kind == kind)
                .collect();
            let counts = columns
                .iter()
                .map(|c| ds.iter().filter(|d| &d.answer == c).count())
                .collect();
            MatrixRow {
                outcome: outcome.to_string(),
                kind: kind.to_string(),
                expected: ds[0].expected.clone(),
                counts,
                total: ds.len(),
                right: ds.iter().filter(|d| d.right).count(),
                wrong_names: ds.iter().filter(|d| d.wrong_name).count(),
                errors: RowErrors {
                    unit: ds[0].unit.clone(),
                    rms_before: Stats::of(ds.iter().map(|d| d.rms_before)),
                    rms_after: Stats::of(ds.iter().map(|d| d.rms_after)),
                    noise: Stats::of(ds.iter().map(|d| d.noise_rms)),
                    diagnose_s: Stats::of(ds.iter().map(|d| d.diagnose_s)),
                },
            }
        })
        .collect();
    let n = datasets.len();
    let right = datasets.iter().filter(|d| d.right).count();
    let right_fraction = if n == 0 { 0.0 } else { right as f64 / n as f64 };
    let wrong_names = datasets.iter().filter(|d| d.wrong_name).count();
    let named = datasets.iter().filter(|d| is_name(&d.answer)).count();
    let near_noise_met = datasets
        .iter()
        .filter(|d| d.near_noise == Some(true))
        .count();
    let min_per_outcome = rows.iter().map(|r| r.total).min().unwrap_or(0);
    let summary = Summary {
        datasets: n,
        right,
        right_fraction,
        wrong_names,
        errors: datasets.iter().filter(|d| d.answer == "error").count(),
        named,
        near_noise_met,
        min_per_outcome,
        target_met: n > 0
            && right_fraction >= TARGET_RIGHT_FRACTION
            && wrong_names == 0
            && near_noise_met == named
            && min_per_outcome >= TARGET_MIN_PER_OUTCOME,
        generate_s: Stats::of(datasets.iter().map(|d| d.generate_s)),
        diagnose_s: Stats::of(datasets.iter().map(|d| d.diagnose_s)),
        diagnose_dynamic_s: Stats::of(
            datasets
                .iter()
                .filter(|d| d.kind == "dynamic")
                .map(|d| d.diagnose_s),
        ),
        diagnose_scroll_s: Stats::of(
            datasets
                .iter()
                .filter(|d| d.kind == "scroll")
                .map(|d| d.diagnose_s),
        ),
    };
    (Matrix { columns, rows }, summary)
}

/// Generate and diagnose the datasets `opts` asks for; `progress` is told
/// the most steps first (100 per dataset: 20 for its generation, 80 for
/// its diagnosis), then one step at a time.
pub fn run(opts: &Options, progress: &dyn Progress) -> Result<Report> {
    let t0 = Instant::now();
    if opts.count_per_outcome == 0 {
        return Err(Error::InvalidArgument(
            "count per outcome must be at least 1".into(),
        ));
    }
    if let Some(m) = opts.magnitude {
        if !(m.is_finite() && m > 0.0 && m <= MAX_MAGNITUDE) {
            return Err(Error::InvalidArgument(format!(
                "magnitude {m}: expected a number above 0 and at most {MAX_MAGNITUDE} (1: clearly visible, 0.35: moderate)"
            )));
        }
    }
    if opts.repeats > MAX_REPEATS {
        return Err(Error::InvalidArgument(format!(
            "{} runs per dataset: at most {} (the first and {MAX_REPEATS} repeats)",
            opts.repeats + 1,
            MAX_REPEATS + 1
        )));
    }
    let cases = selected(opts)?;
    let count = opts.count_per_outcome as u64;
    let mut pending: Vec<Job> = cases
        .iter()
        .flat_map(|&(outcome, kind)| {
            (0..count).map(move |i| Job {
                outcome,
                kind,
                seed: opts.seed.wrapping_add(i),
                magnitude: opts.magnitude,
                ceiling: opts.ceiling || opts.rivals,
                rivals: opts.rivals,
                runs: opts.repeats as u32 + 1,
            })
        })
        .collect();
    let keep = opts.keep_dir.as_deref();
    if let Some(k) = keep {
        for p in pending.iter().map(|j| k.join(j.name())) {
            if p.exists() {
                return Err(Error::InvalidArgument(format!(
                    "{} exists already (--keep never overwrites)",
                    p.display()
                )));
            }
        }
        std::fs::create_dir_all(k).map_err(|source| Error::Io {
            action: "cannot make directory",
            path: k.to_path_buf(),
            source,
        })?;
    }
    // Next seed per case for redraws.
    let mut next: Vec<u64> = vec![opts.seed.wrapping_add(count); cases.len()];
    const STEPS: u64 = GENERATE_STEPS + DIAGNOSE_STEPS;
    let mut total: u64 = STEPS * pending.len() as u64;
    progress.set_total(total);
    let mut results: Vec<DatasetResult> = Vec::new();
    let mut skipped = Vec::new();
    let threads = opts.threads.max(1);
    for _round in 0..=MAX_REDRAW_ROUNDS {
        if pending.is_empty() {
            break;
        }
        // Each dataset alone on its worker (`map_isolated`), so that its
        // time is its own: in one shared pool a worker waiting for the
        // fitter's inner loops took up other datasets, and a run of 819 s
        // for 70 datasets reported 597 s for one series.
        let out = map_isolated(&pending, threads, |job| run_job(job, keep, progress));
        let mut redraw = Vec::new();
        for (job, r) in pending.iter().zip(out) {
            match r? {
                JobResult::Done(d) => results.push(*d),
                JobResult::Skipped(reason) => {
                    skipped.push(Skipped {
                        outcome: job.outcome.as_str().into(),
                        kind: job.kind.as_str().into(),
                        seed: job.seed,
                        reason,
                    });
                    let c = cases
                        .iter()
                        .position(|&(o, k)| o == job.outcome && k == job.kind)
                        .unwrap_or(0);
                    let j = Job {
                        seed: next[c],
                        ..*job
                    };
                    next[c] = next[c].wrapping_add(1);
                    total += GENERATE_STEPS;
                    redraw.push(j);
                }
            }
        }
        pending = redraw;
        progress.set_total(total);
    }
    if let Some(j) = pending.first() {
        return Err(Error::InvalidArgument(format!(
            "the truth simulator failed on {} draws in a row for {} ({}); see the skipped seeds",
            MAX_REDRAW_ROUNDS + 1,
            j.outcome.as_str(),
            j.kind.as_str()
        )));
    }
    // Rows in case order, seeds ascending (redraws come last otherwise).
    let row = |d: &DatasetResult| {
        cases
            .iter()
            .position(|(o, k)| o.as_str() == d.outcome && k.as_str() == d.kind)
            .unwrap_or(usize::MAX)
    };
    results.sort_by(|a, b| row(a).cmp(&row(b)).then(a.seed.cmp(&b.seed)));
    Ok(report(
        Settings {
            seed: opts.seed,
            count_per_outcome: opts.count_per_outcome,
            magnitude: opts.magnitude,
            threads,
            runs_per_dataset: opts.repeats + 1,
        },
        results,
        skipped,
        t0,
    ))
}

/// The settings a report states ([`Report`]'s fields of the same names).
struct Settings {
    seed: u64,
    count_per_outcome: usize,
    magnitude: Option<f64>,
    threads: usize,
    runs_per_dataset: usize,
}

/// The report of `datasets` diagnosed (in their order) with the run's
/// settings, timed from `t0`.
fn report(
    settings: Settings,
    datasets: Vec<DatasetResult>,
    skipped: Vec<Skipped>,
    t0: Instant,
) -> Report {
    let (matrix, summary) = tabulate(&datasets);
    let Settings {
        seed,
        count_per_outcome,
        magnitude,
        threads,
        runs_per_dataset,
    } = settings;
    Report {
        seed,
        count_per_outcome,
        magnitude,
        threads,
        runs_per_dataset,
        variant: VARIANT.name().to_string(),
        summary,
        matrix,
        by_ceiling: by_ceiling(&datasets),
        by_separation: by_separation(&datasets),
        by_runs: by_runs(&datasets),
        datasets,
        skipped,
        wall_s: t0.elapsed().as_secs_f64(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(outcome: &str, kind: &str, expected: &str, answer: &str, seed: u64) -> DatasetResult {
        let named = is_name(answer);
        DatasetResult {
            outcome: outcome.into(),
            kind: kind.into(),
            seed,
            expected: expected.into(),
            answer: answer.into(),
            right: answer == expected,
            wrong_name: named && answer != expected,
            magnitude: 0.5,
            description: String::new(),
            rms_before: 3.0,
            rms_after: if named { 1.0 } else { 3.0 },
            noise_rms: 1.0,
            unit: "mm".into(),
            near_noise: named.then(|| near_noise(3.0, 1.0, 1.0)),
            generate_s: seed as f64,
            diagnose_s: 1.0,
            dir: None,
            evidence: String::new(),
            evidence_ceiling: None,
            ceiling_error: None,
            rival_ceilings: Vec::new(),
            candidates: Vec::new(),
            series_answers: Vec::new(),
        }
    }

    #[test]
    fn matrix_bookkeeping() {
        let d = vec![
            row("none", "dynamic", "none", "none", 1),
            row("none", "dynamic", "none", "joint_friction", 2),
            row(
                "joint_friction",
                "dynamic",
                "joint_friction",
                "joint_friction",
                1,
            ),
            row(
                "joint_friction",
                "dynamic",
                "joint_friction",
                "unexplained",
                2,
            ),
            row(
                "joint_friction",
                "dynamic",
                "joint_friction",
                "quadratic_damping",
                3,
            ),
            row("camera_drift", "dynamic", "unexplained", "unexplained", 1),
            row("torque_drift", "scroll", "unexplained", "error", 1),
        ];
        let (m, s) = tabulate(&d);
        assert_eq!(m.columns.len(), 9);
        assert_eq!(m.columns[0], "none");
        assert_eq!(m.columns[7], "unexplained");
        assert_eq!(m.columns[8], "error");
        assert_eq!(m.rows.len(), 4);
        let col = |c: &str| m.columns.iter().position(|x| x == c).unwrap();
        let jf = &m.rows[1];
        assert_eq!(
            (jf.outcome.as_str(), jf.total, jf.right),
            ("joint_friction", 3, 1)
        );
        assert_eq!(jf.counts[col("joint_friction")], 1);
        assert_eq!(jf.counts[col("unexplained")], 1);
        assert_eq!(jf.counts[col("quadratic_damping")], 1);
        assert_eq!(jf.wrong_names, 1);
        for r in &m.rows {
            assert_eq!(r.counts.iter().sum::<usize>(), r.total);
        }
        assert_eq!(m.rows.iter().map(|r| r.total).sum::<usize>(), d.len());
        assert_eq!(s.datasets, 7);
        assert_eq!(s.right, 3);
        // `unexplained` for an effect is a miss, not a wrong name; naming
        // an effect on clean data is.
        assert_eq!(s.wrong_names, 2);
        assert_eq!(s.errors, 1);
        assert_eq!(s.named, 3);
        assert_eq!(s.near_noise_met, 3);
        assert_eq!(s.min_per_outcome, 1);
        assert!(!s.target_met);
        assert!((s.right_fraction - 3.0 / 7.0).abs() < 1e-12);
        let g = s.generate_s.unwrap();
        assert_eq!((g.median, g.max), (1.0, 3.0));
        assert_eq!(
            Stats::of([4.0, 1.0, f64::NAN, 2.0, 3.0]).unwrap().median,
            2.5
        );
        assert_eq!(Stats::of([f64::NAN]), None);
        assert!(near_noise(3.0, 1.25, 1.0));
        assert!(near_noise(9.0, 3.0, 1.0));
        assert!(!near_noise(3.0, 1.3, 1.0));
    }

    #[test]
    fn magnitude_outside_the_truths_range_is_an_error() {
        for m in [0.0, -0.5, f64::NAN, f64::INFINITY, MAX_MAGNITUDE + 0.1] {
            let o = Options {
                count_per_outcome: 1,
                seed: 1,
                threads: 1,
                magnitude: Some(m),
                ..Options::default()
            };
            match run(&o, &crate::NoProgress) {
                Err(Error::InvalidArgument(msg)) => assert!(msg.contains("magnitude"), "{msg}"),
                other => panic!("magnitude {m}: {:?}", other.map(|r| r.summary)),
            }
        }
    }
}
