//! The protocol's parts (conditions, held-out values) and every candidate scored on them.

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{kept_or, mean, Candidate, CompareParams, ConditionAccuracy, Keep, Protocol, Scored};
use crate::analysis::Split;
use crate::error::{ParamError, Result};
use crate::progress::{silent, Progress};
use crate::recording::{Meta, Selection};

/// The distinct values of `column` over `metas`, numerically ordered when all are numbers.
///
/// # Errors
/// A column no recording has a value in.
pub(super) fn conditions(metas: &[Meta], column: &str) -> Result<Vec<String>> {
    let mut values: Vec<String> = Vec::new();
    for m in metas {
        if let Some(v) = m.field(column) {
            if !values.contains(&v) {
                values.push(v);
            }
        }
    }
    if values.is_empty() {
        let rule = "the protocol's column must be a manifest column with values";
        let names = Meta::columns_with_values(metas).join(", ");
        let got =
            format!("{column}, which no recording has a value in (columns with values: {names})");
        return Err(ParamError::new("per / hold-out", rule, got).into());
    }
    if values.len() < 2 {
        let rule = "the protocol's column must have at least two values";
        let got = format!("{column}: {} value(s)", values.len());
        return Err(ParamError::new("per / hold-out", rule, got).into());
    }
    if values.iter().all(|v| v.parse::<f64>().is_ok()) {
        values.sort_by(|a, b| {
            let (a, b): (f64, f64) = (a.parse().unwrap_or(0.0), b.parse().unwrap_or(0.0));
            a.total_cmp(&b)
        });
    }
    Ok(values)
}

/// The rows of `metas` whose `column` is `value`.
pub(super) fn rows_with(metas: &[Meta], column: &str, value: &str) -> Vec<usize> {
    (0..metas.len())
        .filter(|&i| metas[i].field(column).as_deref() == Some(value))
        .collect()
}

/// Cross-validation of a whole table with the comparison's folds and groups.
pub(super) fn cv_split(params: &CompareParams) -> Split {
    Split::CrossValidation {
        speeds: None,
        cv: params.cv,
        group_by: params.group_by.clone(),
    }
}

/// One part of the protocol every candidate is evaluated on: one condition's
/// cross-validation, one held-out value, or the whole protocol's one split.
pub(super) struct Part {
    /// The condition it is of (a value of the protocol's column); `None` for a protocol of
    /// one split.
    condition: Option<String>,
    /// The table rows evaluated (within one condition); `None` for every recording.
    rows: Option<Vec<usize>>,
    split: Split,
}

/// The parts of the protocol, in the order a candidate's results are put together.
///
/// # Errors
/// A protocol column without two values.
pub(super) fn parts(metas: &[Meta], params: &CompareParams) -> Result<Vec<Part>> {
    let whole = |split| {
        vec![Part {
            condition: None,
            rows: None,
            split,
        }]
    };
    Ok(match &params.protocol {
        Protocol::Pooled => whole(cv_split(params)),
        Protocol::Per(column) => (conditions(metas, column)?.into_iter())
            .map(|value| Part {
                rows: Some(rows_with(metas, column, &value)),
                condition: Some(value),
                split: cv_split(params),
            })
            .collect(),
        Protocol::HoldOut(column) => {
            let values = conditions(metas, column)?;
            (values.iter())
                .map(|value| Part {
                    condition: Some(value.clone()),
                    rows: None,
                    split: hold_out(column, &values, value),
                })
                .collect()
        }
        Protocol::Where { train, test } => whole(Split::Where {
            train: train.clone(),
            test: test.clone(),
        }),
    })
}

/// One candidate's result on one part: its accuracy, each evaluated table row's share of
/// right predictions, and the seconds it took.
#[derive(Serialize, Deserialize)]
struct PartScore {
    accuracy: f64,
    shares: Vec<(usize, f64)>,
    seconds: f64,
}

/// Evaluates one candidate on one part of the protocol, timing it.
fn score_part(c: &Candidate, part: &Part, params: &CompareParams) -> Result<PartScore> {
    let start = Instant::now();
    let (accuracy, shares) = match &part.rows {
        Some(rows) => {
            let outcome =
                (c.evaluate)(rows, &part.split, &silent).map_err(|e| match &params.protocol {
                    Protocol::Per(column) => {
                        in_condition(e, column, part.condition.as_deref().unwrap_or_default())
                    }
                    _ => e,
                })?;
            let shares = outcome.correct_shares.iter();
            (
                outcome.accuracy,
                shares.map(|&(r, s)| (rows[r], s)).collect(),
            )
        }
        None => {
            let outcome = c.evaluate_all(&part.split)?;
            (outcome.accuracy, outcome.correct_shares)
        }
    };
    Ok(PartScore {
        accuracy,
        shares,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Every candidate evaluated on every part of the protocol, each pair a piece of work of
/// its own run side by side (a step of `progress` each), put together per candidate in
/// the order of the parts: the same scores as one candidate and part after another.
///
/// # Errors
/// An evaluation that fails.
pub(super) fn score_all(
    candidates: &[Candidate],
    parts: &[Part],
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
    keep: Option<&dyn Keep>,
) -> Result<Vec<Scored>> {
    let n = parts.len().max(1);
    let scores: Vec<PartScore> = (0..candidates.len() * parts.len())
        .into_par_iter()
        .map(|k| {
            crate::progress::stop_point();
            let (c, part) = (&candidates[k / n], &parts[k % n]);
            let key = format!("score of {} on part {}", c.name(), k % n);
            let scored = kept_or(keep, &key, || score_part(c, part, params));
            progress(Progress::Tick);
            scored
        })
        .collect::<Result<_>>()?;
    Ok(candidates
        .iter()
        .zip(scores.chunks(n))
        .map(|(c, scores)| scored(c, parts, scores, params))
        .collect())
}

/// One candidate's scores under the protocol from its parts' (in the order of `parts`).
fn scored(c: &Candidate, parts: &[Part], scores: &[PartScore], params: &CompareParams) -> Scored {
    let mut per_condition = Vec::new();
    let mut shares = Vec::new();
    for (part, s) in parts.iter().zip(scores) {
        shares.extend_from_slice(&s.shares);
        if let Some(condition) = &part.condition {
            per_condition.push(ConditionAccuracy {
                condition: condition.clone(),
                accuracy: s.accuracy,
            });
        }
    }
    let accuracy = match &params.protocol {
        Protocol::Per(_) | Protocol::HoldOut(_) => mean(per_condition.iter().map(|p| p.accuracy)),
        Protocol::Pooled | Protocol::Where { .. } => scores[0].accuracy,
    };
    shares.sort_by_key(|&(row, _)| row);
    Scored {
        accuracy,
        per_condition,
        shares,
        seconds: c.prepare_s + scores.iter().map(|s| s.seconds).sum::<f64>(),
    }
}

/// Trains on every value of `column` but `value`, tests on `value`.
pub(super) fn hold_out(column: &str, values: &[String], value: &str) -> Split {
    let others = values.iter().filter(|v| *v != value).cloned().collect();
    let select = |values| Selection {
        column: column.to_string(),
        values,
    };
    Split::Where {
        train: select(others),
        test: select(vec![value.to_string()]),
    }
}

/// An error of one condition's evaluation, saying which condition; a condition too small
/// for the folds or neighbours keeps its classification error, so that the hint and a
/// larger run's skip can tell it apart.
fn in_condition(e: crate::Error, column: &str, value: &str) -> crate::Error {
    if e.is_design() {
        return e.in_analysis(format!("{column} = {value}"));
    }
    let rule = "every condition must be evaluable on its own";
    ParamError::new("per", rule, format!("{column} = {value}: {e}")).into()
}
