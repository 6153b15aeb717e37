//! The dataset's answer from its series' answers: one belt, one set of
//! laws, so several runs of it (drop tests with other rollers, rig runs
//! at other speeds) answer together.
//!
//! Each series is diagnosed on its own ([`crate::diagnose`]): its
//! decision needs its own signature and support, and a name is never
//! forced. The dataset's verdict then reads them together:
//!
//! | series' answers | verdict |
//! | --- | --- |
//! | one effect named, on one series or more, no other effect named | that effect |
//! | two different effects named | `unexplained`: one belt cannot lack both, so neither name stands |
//! | no name, a series that could not be diagnosed (`error`) | `error`: it cannot vouch for `none` |
//! | no name, some `unexplained` | `unexplained` |
//! | every series `none` | `none` |
//!
//! A series that says `none` or `unexplained` beside a name does not
//! refuse it: a run can be too short, too damped or too disturbed to show
//! what another run of the same belt shows. What the other series said is
//! in the verdict's evidence.

use crate::evidence::ResultRow;
use serde::Serialize;

/// The dataset's answer ([`dataset_verdict`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// An effect identifier, `none`, `unexplained` or `error`.
    pub effect: String,
    /// The series row that answers for it (its residuals and
    /// candidates): the first series naming the effect; for `none` and
    /// `unexplained` the first series saying so.
    pub row: usize,
    /// Series that named the verdict's effect (empty for `none` and
    /// `unexplained`).
    pub named_by: Vec<String>,
    /// Why, with every series' answer.
    pub evidence: String,
}

/// Whether `answer` names an effect (not `none`, `unexplained` or
/// `error`).
///
/// ```
/// use trackbelt_host::verdict::is_name;
/// assert!(is_name("joint_friction"));
/// assert!(!is_name("none") && !is_name("unexplained") && !is_name("error"));
/// ```
pub fn is_name(answer: &str) -> bool {
    !matches!(answer, "none" | "unexplained" | "error")
}

/// The distinct effects named among `answers`, sorted.
fn named_effects<'a>(answers: &[&'a str]) -> Vec<&'a str> {
    let mut named: Vec<&str> = answers.iter().copied().filter(|e| is_name(e)).collect();
    named.sort_unstable();
    named.dedup();
    named
}

/// The verdict's effect from the series' answers alone (`none`, an
/// effect identifier, `unexplained` or `error`, in any order): the rule of
/// [`dataset_verdict`], for scoring a dataset on some of its runs.
///
/// ```
/// use trackbelt_host::verdict::combined_answer;
/// assert_eq!(combined_answer(&["none", "bearing_friction", "unexplained"]), "bearing_friction");
/// assert_eq!(combined_answer(&["joint_friction", "amplitude_stiffness"]), "unexplained");
/// assert_eq!(combined_answer(&["none", "none"]), "none");
/// assert_eq!(combined_answer(&["none", "error"]), "error");
/// assert_eq!(combined_answer(&[]), "none");
/// ```
pub fn combined_answer<'a>(answers: &[&'a str]) -> &'a str {
    match named_effects(answers).as_slice() {
        [one] => one,
        [] if answers.contains(&"error") => "error",
        [] if answers.contains(&"unexplained") => "unexplained",
        [] => "none",
        _ => "unexplained",
    }
}

/// The verdict on a dataset whose series answered `rows` (the table
/// above); `None` without rows. With one row it is that row's answer.
///
/// ```
/// use trackbelt_host::evidence::ResultRow;
/// use trackbelt_host::verdict::dataset_verdict;
/// let row = |series: &str, effect: &str| ResultRow {
///     series: series.into(), kind: "dynamic".into(), effect: effect.into(),
///     rms_before: 1.5, rms_after: 1.0, unit: "mm".into(), evidence: String::new(),
///     candidates: Vec::new(), gain_samples: None,
/// };
/// let v = dataset_verdict(&[row("run-1", "none"), row("run-2", "joint_friction")]).unwrap();
/// assert_eq!((v.effect.as_str(), v.row), ("joint_friction", 1));
/// let v = dataset_verdict(&[row("run-1", "joint_friction"), row("run-2", "quadratic_damping")]).unwrap();
/// assert_eq!(v.effect, "unexplained");
/// let v = dataset_verdict(&[row("run-1", "none"), row("run-2", "unexplained")]).unwrap();
/// assert_eq!((v.effect.as_str(), v.row), ("unexplained", 1));
/// assert_eq!(dataset_verdict(&[row("run-1", "none")]).unwrap().effect, "none");
/// assert!(dataset_verdict(&[]).is_none());
/// ```
pub fn dataset_verdict(rows: &[ResultRow]) -> Option<Verdict> {
    let first = rows.first()?;
    if rows.len() == 1 {
        return Some(Verdict {
            effect: first.effect.clone(),
            row: 0,
            named_by: if is_name(&first.effect) {
                vec![first.series.clone()]
            } else {
                Vec::new()
            },
            evidence: first.evidence.clone(),
        });
    }
    let answers = rows
        .iter()
        .map(|r| format!("{}: {}", r.series, r.effect))
        .collect::<Vec<_>>()
        .join("; ");
    let effects: Vec<&str> = rows.iter().map(|r| r.effect.as_str()).collect();
    // The decision is [`combined_answer`]'s, so that a dataset's verdict
    // and its score on some of its runs ([`crate::validate::by_runs`])
    // cannot part; what follows finds the answering row and says why.
    let effect = combined_answer(&effects);
    let at = |pred: &dyn Fn(&ResultRow) -> bool| rows.iter().position(pred);
    if is_name(effect) {
        let row = at(&|r| r.effect == effect).unwrap_or(0);
        let named_by: Vec<String> = rows
            .iter()
            .filter(|r| r.effect == effect)
            .map(|r| r.series.clone())
            .collect();
        return Some(Verdict {
            effect: effect.to_string(),
            row,
            evidence: format!(
                "{effect} named on {} of {} series of this belt, no other effect named ({answers}); {}",
                named_by.len(),
                rows.len(),
                rows[row].evidence
            ),
            named_by,
        });
    }
    let named = named_effects(&effects);
    if named.is_empty() {
        let row = at(&|r| r.effect == effect).unwrap_or(0);
        return Some(Verdict {
            effect: effect.to_string(),
            row,
            named_by: Vec::new(),
            evidence: format!(
                "no series names an effect ({answers}); {}",
                rows[row].evidence
            ),
        });
    }
    Some(Verdict {
        effect: effect.to_string(),
        row: at(&|r| is_name(&r.effect)).unwrap_or(0),
        named_by: Vec::new(),
        evidence: format!(
            "the series name different effects ({}) of one belt, which has one set of laws: none of them is named ({answers})",
            named.join(", ")
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(i: usize, effect: &str) -> ResultRow {
        ResultRow {
            series: format!("run-{}", i + 1),
            kind: "dynamic".into(),
            effect: effect.into(),
            rms_before: 1.0,
            rms_after: 1.0,
            unit: "mm".into(),
            evidence: format!("series {i} says {effect}"),
            candidates: Vec::new(),
            gain_samples: None,
        }
    }

    /// Every dataset of one to four series answering from five answers:
    /// the verdict is [`combined_answer`]'s, its row answers as it does,
    /// and the evidence lists every series.
    #[test]
    fn the_verdict_is_the_combined_answer_on_every_mix_of_answers() {
        let pool = [
            "none",
            "unexplained",
            "joint_friction",
            "quadratic_damping",
            "error",
        ];
        for len in 1..=4usize {
            for code in 0..pool.len().pow(len as u32) {
                let answers: Vec<&str> = (0..len)
                    .map(|k| pool[(code / pool.len().pow(k as u32)) % pool.len()])
                    .collect();
                let rows: Vec<ResultRow> =
                    answers.iter().enumerate().map(|(i, a)| row(i, a)).collect();
                let v = dataset_verdict(&rows).unwrap();
                let want = if len == 1 {
                    answers[0]
                } else {
                    combined_answer(&answers)
                };
                assert_eq!(v.effect, want, "{answers:?}");
                assert!(v.row < len);
                if is_name(&v.effect) {
                    assert_eq!(rows[v.row].effect, v.effect, "{answers:?}");
                    assert!(!v.named_by.is_empty());
                } else {
                    assert!(v.named_by.is_empty(), "{answers:?}");
                }
                if len > 1 {
                    for i in 0..len {
                        assert!(
                            v.evidence.contains(&format!("run-{}", i + 1)),
                            "{}",
                            v.evidence
                        );
                    }
                }
            }
        }
    }
}
