//! Which encoding, feature method and classifier suit a dataset best: every
//! candidate is evaluated on the same splits of the same recordings, ranked with a 95 %
//! interval, and compared with the paper's method (3D-GLCM + KNN) by a paired test.
//!
//! The splits depend only on the recordings' labels (and groups) and the seed, never on
//! the features, so every candidate is tested on exactly the same folds and a per-recording
//! difference between two candidates is a paired one. Intervals are percentile bootstraps
//! over units (recordings, or groups of `--group-by`) stratified by condition, so that the
//! interval is of the mean over conditions the accuracy is; the comparison with the paper's
//! method is the paired sign-flip test of the per-unit differences
//! ([`sign_flip_p`]).
//!
//! Picking the best of many candidates on the same data is itself a choice fitted to that
//! data: the winner's accuracy is biased upwards (the "winner's curse"; Cawley and Talbot
//! 2010, JMLR 11). [`CompareParams::nested`] adds the honest estimate of the whole
//! procedure: for each outer split the candidates are ranked by cross-validation inside
//! its training recordings only, and the chosen one is scored on its test recordings.

pub mod candidates;
pub mod signal;

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::analysis::{Outcome, Split};
use crate::classify::draws::for_each_resample;
use crate::classify::metrics::sign_flip_p;
use crate::classify::stats::percentile;
use crate::classify::{group_folds, stratified_folds, wilson_at_the_bounds, ValidCv};
use crate::error::{ClassifyError, ParamError, Result};
use crate::progress::Progress;
use crate::recording::{Meta, Selection};

pub use crate::analysis::EvaluateFn;

/// One encoding x feature method x classifier, with its features computed.
#[derive(Clone)]
pub struct Candidate {
    /// The encoding's name (`sa`, `fa`, `sa+fa`).
    pub encoding: String,
    /// The feature method's name.
    pub method: String,
    /// The classifier's name.
    pub classifier: String,
    /// Every compared recording, in the same order for every candidate.
    pub metas: Arc<Vec<Meta>>,
    /// The classifier applied to the method's samples of some recordings under a split.
    pub evaluate: Arc<EvaluateFn>,
    /// Seconds spent making the samples (encoding shared among the methods of one
    /// encoding is split evenly among them).
    pub prepare_s: f64,
}

impl Candidate {
    /// `encoding / method / classifier`.
    pub fn name(&self) -> String {
        format!("{} / {} / {}", self.encoding, self.method, self.classifier)
    }

    /// Evaluates the candidate on all its recordings under `split`.
    ///
    /// # Errors
    /// As the candidate's classifier.
    pub fn evaluate_all(&self, split: &Split) -> Result<Outcome> {
        let all: Vec<usize> = (0..self.metas.len()).collect();
        (self.evaluate)(&all, split)
    }

    /// Whether this is the paper's method: the SA encoding, 3D-GLCM and KNN.
    pub fn is_paper(&self) -> bool {
        (
            self.encoding.as_str(),
            self.method.as_str(),
            self.classifier.as_str(),
        ) == ("sa", "glcm3d", "knn")
    }
}

/// How recordings are split.
#[derive(Debug, Clone, PartialEq)]
pub enum Protocol {
    /// Cross-validation over all recordings pooled.
    Pooled,
    /// Cross-validation within each value of a manifest column (each speed, say); the
    /// accuracy is the mean over values.
    Per(String),
    /// Each value of a manifest column held out in turn: trained on the other values,
    /// tested on it; the accuracy is the mean over held-out values.
    HoldOut(String),
    /// Trained on one selection, tested on another.
    Where {
        /// The training recordings.
        train: Selection,
        /// The test recordings.
        test: Selection,
    },
}

impl std::fmt::Display for Protocol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Protocol::Pooled => write!(f, "cross-validation over all recordings pooled"),
            Protocol::Per(c) => write!(f, "cross-validation within each `{c}`, mean over them"),
            Protocol::HoldOut(c) => write!(f, "each `{c}` held out in turn, mean over them"),
            Protocol::Where { train, test } => write!(
                f,
                "train on `{}` in [{}], test on `{}` in [{}]",
                train.column,
                train.values.join(", "),
                test.column,
                test.values.join(", ")
            ),
        }
    }
}

/// How to compare.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareParams {
    /// The splits.
    pub protocol: Protocol,
    /// Folds, seed and repeats of every cross-validation.
    pub cv: ValidCv,
    /// A manifest column whose groups no fold splits, and the unit of intervals and tests.
    pub group_by: Option<String>,
    /// Resamples of the bootstrap and the sign-flip test.
    pub resamples: usize,
    /// Also estimate the accuracy of choosing the best candidate inside each training set.
    pub nested: bool,
}

/// A candidate's accuracy at one condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConditionAccuracy {
    /// The condition's value (a speed, a session).
    pub condition: String,
    /// Accuracy, 0..1.
    pub accuracy: f64,
}

/// One candidate's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ranked {
    /// Encoding name.
    pub encoding: String,
    /// Feature method name.
    pub method: String,
    /// Classifier name.
    pub classifier: String,
    /// Accuracy, 0..1: the mean over conditions of the protocol.
    pub accuracy: f64,
    /// 95 % percentile-bootstrap interval of the accuracy over units (the Wilson score
    /// interval over the units where every one was right, or every one wrong).
    pub ci: [f64; 2],
    /// Two-sided p-value of the paired sign-flip test against the paper's method (`None`
    /// for the paper's method itself, or when it is not among the candidates).
    pub p_vs_paper: Option<f64>,
    /// Accuracy minus the paper's method's (both means over conditions).
    pub difference_vs_paper: Option<f64>,
    /// Accuracy per condition (empty for pooled cross-validation).
    pub per_condition: Vec<ConditionAccuracy>,
    /// Seconds to make the features and evaluate (wall clock, summed over the parts of the
    /// protocol; candidates and their parts are evaluated side by side, so each one's time
    /// includes its share of the others' load).
    pub seconds: f64,
    /// Whether this is the paper's method.
    pub paper: bool,
}

/// Choosing the best candidate inside each training set, scored on the test set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Nested {
    /// Accuracy of the selection procedure, 0..1 (mean over conditions).
    pub accuracy: f64,
    /// Its 95 % interval.
    pub ci: [f64; 2],
    /// How often each candidate was chosen, most often first: `(name, times)`.
    pub chosen: Vec<(String, usize)>,
    /// Outer splits.
    pub outer_splits: usize,
}

/// The comparison of every candidate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The protocol, as text.
    pub protocol: String,
    /// What intervals and tests resample: `recordings` or `groups of COLUMN`.
    pub units: String,
    /// Units compared.
    pub n_units: usize,
    /// Recordings compared.
    pub n_recordings: usize,
    /// Classes.
    pub classes: usize,
    /// Chance accuracy, 1 / classes.
    pub chance: f64,
    /// Share of the largest class among the evaluated recordings.
    pub majority: f64,
    /// Every candidate, best first.
    pub results: Vec<Ranked>,
    /// The best candidate (the first of `results`).
    pub best: Ranked,
    /// The selection procedure's own estimate, when asked for.
    pub nested: Option<Nested>,
    /// What the ranking does not say.
    pub caveat: String,
    /// Options the design could not honour as given (fewer folds than asked), each as
    /// said on standard error when the comparison ran.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// The caveat every comparison carries.
pub const CAVEAT: &str = "the best of several candidates chosen on the same recordings \
    scores higher than it will on new recordings of the same kind; the nested estimate \
    (selection inside each training set, computed when nested selection is asked for) is the \
    one to quote for the chosen procedure";

/// One candidate's scores under the protocol.
struct Scored {
    accuracy: f64,
    per_condition: Vec<ConditionAccuracy>,
    /// Per evaluated table row, its share of right predictions.
    shares: Vec<(usize, f64)>,
    seconds: f64,
}

/// Evaluates every candidate under `params` and ranks them.
///
/// # Errors
/// No candidates, tables of different recordings, or an evaluation that fails (a class
/// smaller than the folds, a protocol column the manifest lacks).
pub fn compare(candidates: &[Candidate], params: &CompareParams) -> Result<Comparison> {
    compare_with_progress(candidates, params, &crate::progress::silent)
}

/// [`compare`], saying its progress: a step per candidate and part of the protocol scored
/// (each condition's cross-validation, each held-out value, or the one split of a pooled
/// or train/test protocol), then with nested selection a step per candidate
/// cross-validated inside each outer split.
///
/// # Errors
/// As [`compare`].
pub fn compare_with_progress(
    candidates: &[Candidate],
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Comparison> {
    let first = candidates.first().ok_or(ClassifyError::Empty {
        what: "compare: no candidates",
    })?;
    let metas = &first.metas;
    if let Some(c) = candidates.iter().find(|c| c.metas != *metas) {
        let message = format!("{} has other recordings than {}", c.name(), first.name());
        return Err(ClassifyError::BadFeatures(message).into());
    }
    // Candidates are scored side by side, each part of the protocol (a condition, a
    // held-out value) on its own (each evaluation is deterministic, so the order of work
    // changes nothing but its clock): one candidate's folds are too few and too unequal
    // to keep every core busy, and a candidate's parts are its longest pieces of work.
    // Nested selection's outer splits, checked before any candidate is scored.
    let outer = match params.nested {
        true => Some(check_nested(metas, params)?),
        false => None,
    };
    let notes = fewer_folds(metas, params, outer.as_deref());
    for note in &notes {
        progress(Progress::Advice(note));
    }
    let parts = parts(metas, params)?;
    progress(Progress::Stage(
        "candidates",
        candidates.len() * parts.len(),
    ));
    let scored = score_all(candidates, &parts, params, progress)?;
    let units = Units::new(metas, &scored[0].shares, params)?;
    let paper = candidates.iter().position(Candidate::is_paper);
    // Each candidate's interval and paired test resample from their own seeded stream,
    // thousands of draws per unit: ranked side by side too.
    let mut results: Vec<Ranked> = candidates
        .par_iter()
        .zip(&scored)
        .map(|(c, s)| units.rank(c, s, paper.map(|p| &scored[p]), params))
        .collect::<Result<_>>()?;
    results.sort_by(|a, b| b.accuracy.total_cmp(&a.accuracy));
    let nested = match outer {
        Some(splits) => Some(nested(candidates, &splits, params, &units, progress)?),
        None => None,
    };
    let (classes, majority) = class_shares(metas, &scored[0].shares);
    Ok(Comparison {
        protocol: params.protocol.to_string(),
        units: match &params.group_by {
            Some(column) => format!("groups of {column}"),
            None => "recordings".into(),
        },
        n_units: units.n_units(),
        n_recordings: scored[0].shares.len(),
        classes,
        chance: 1.0 / classes.max(1) as f64,
        majority,
        best: results[0].clone(),
        results,
        nested,
        caveat: CAVEAT.into(),
        notes,
    })
}

/// What the design makes of `--folds` where it cannot honour it: fewer groups than folds
/// (each group then held out in turn) and nested selection's inner folds, which a class
/// smaller than the folds reduces; each said once, with the value given and the one used.
fn fewer_folds(
    metas: &[Meta],
    params: &CompareParams,
    outer: Option<&[OuterSplit]>,
) -> Vec<String> {
    let folds = params.cv.folds;
    let mut notes = Vec::new();
    if let Some(column) = &params.group_by {
        let all: Vec<usize> = (0..metas.len()).collect();
        let sets: Vec<(String, Vec<usize>)> = match &params.protocol {
            Protocol::Pooled => vec![(String::new(), all)],
            Protocol::Per(per) => conditions(metas, per)
                .unwrap_or_default()
                .into_iter()
                .map(|v| (format!(" at {per} = {v}"), rows_with(metas, per, &v)))
                .collect(),
            Protocol::HoldOut(_) | Protocol::Where { .. } => Vec::new(),
        };
        let fewest = sets
            .iter()
            .map(|(at, rows)| (crate::analysis::group_count(metas, rows, column), at))
            .min_by_key(|(n, _)| *n);
        if let Some((groups, at)) = fewest.filter(|(n, _)| *n < folds) {
            notes.push(format!(
                "--folds {folds} with --group-by {column}: {groups} `{column}` group(s){at}, so {groups} folds are used there (each group held out in turn)"
            ));
        }
    }
    let inner = outer
        .unwrap_or_default()
        .iter()
        .map(|split| inner_folds(folds, smallest_class(metas, &split.train)))
        .filter(|&used| used < folds);
    if let Some(used) = inner.clone().min() {
        notes.push(format!(
            "--folds {folds}: nested selection's inner cross-validation uses {used} folds in {} of {} outer training sets (their smallest class has fewer than {folds} recordings)",
            inner.count(),
            outer.map_or(0, <[_]>::len)
        ));
    }
    notes
}

/// The folds of nested selection's inner cross-validation: `folds`, fewer when a class of
/// the outer training set has fewer recordings (`smallest`), never under 2.
fn inner_folds(folds: usize, smallest: usize) -> usize {
    folds.min(smallest).max(2)
}

/// The number of classes among the evaluated rows and the largest class's share.
fn class_shares(metas: &[Meta], shares: &[(usize, f64)]) -> (usize, f64) {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for &(row, _) in shares {
        let label = &metas[row].label;
        match counts.iter_mut().find(|(l, _)| l == label) {
            Some((_, n)) => *n += 1,
            None => counts.push((label.clone(), 1)),
        }
    }
    let largest = counts.iter().map(|(_, n)| *n).max().unwrap_or(0);
    (counts.len(), largest as f64 / shares.len().max(1) as f64)
}

/// The distinct values of `column` over `metas`, numerically ordered when all are numbers.
///
/// # Errors
/// A column no recording has a value in.
fn conditions(metas: &[Meta], column: &str) -> Result<Vec<String>> {
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
fn rows_with(metas: &[Meta], column: &str, value: &str) -> Vec<usize> {
    (0..metas.len())
        .filter(|&i| metas[i].field(column).as_deref() == Some(value))
        .collect()
}

/// Cross-validation of a whole table with the comparison's folds and groups.
fn cv_split(params: &CompareParams) -> Split {
    Split::CrossValidation {
        speeds: None,
        cv: params.cv,
        group_by: params.group_by.clone(),
    }
}

/// One part of the protocol every candidate is evaluated on: one condition's
/// cross-validation, one held-out value, or the whole protocol's one split.
struct Part {
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
fn parts(metas: &[Meta], params: &CompareParams) -> Result<Vec<Part>> {
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
            let outcome = (c.evaluate)(rows, &part.split).map_err(|e| match &params.protocol {
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
fn score_all(
    candidates: &[Candidate],
    parts: &[Part],
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Scored>> {
    let n = parts.len().max(1);
    let scores: Vec<PartScore> = (0..candidates.len() * parts.len())
        .into_par_iter()
        .map(|k| {
            let scored = score_part(&candidates[k / n], &parts[k % n], params);
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
fn hold_out(column: &str, values: &[String], value: &str) -> Split {
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

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (total, n) = values.fold((0.0, 0usize), |(t, n), v| (t + v, n + 1));
    total / n.max(1) as f64
}

/// The units intervals and tests resample: per evaluated row, its unit; units grouped by
/// condition (one condition unless the protocol has several).
struct Units {
    /// Each evaluated row's unit index, in the order of the scored shares.
    unit_of: Vec<usize>,
    /// Each condition's units.
    by_condition: Vec<Vec<usize>>,
    n_units: usize,
    resamples: usize,
    seed: u64,
}

impl Units {
    fn new(metas: &[Meta], shares: &[(usize, f64)], params: &CompareParams) -> Result<Units> {
        let condition_column = match &params.protocol {
            Protocol::Per(c) | Protocol::HoldOut(c) => Some(c.as_str()),
            _ => None,
        };
        let key = |row: usize| {
            let meta = &metas[row];
            let condition = condition_column
                .and_then(|c| meta.field(c))
                .unwrap_or_default();
            let unit = match &params.group_by {
                Some(column) => meta.field(column).unwrap_or_default(),
                None => meta.file.clone(),
            };
            (condition, unit)
        };
        let mut keys: Vec<(String, String)> = Vec::new();
        let mut unit_of = Vec::with_capacity(shares.len());
        for &(row, _) in shares {
            let k = key(row);
            let index = keys.iter().position(|x| *x == k).unwrap_or_else(|| {
                keys.push(k);
                keys.len() - 1
            });
            unit_of.push(index);
        }
        let mut names: Vec<&String> = Vec::new();
        let mut by_condition: Vec<Vec<usize>> = Vec::new();
        for (u, (condition, _)) in keys.iter().enumerate() {
            match names.iter().position(|n| *n == condition) {
                Some(i) => by_condition[i].push(u),
                None => {
                    names.push(condition);
                    by_condition.push(vec![u]);
                }
            }
        }
        Ok(Units {
            unit_of,
            by_condition,
            n_units: keys.len(),
            resamples: params.resamples,
            seed: params.cv.seed,
        })
    }

    fn n_units(&self) -> usize {
        self.n_units
    }

    /// Per unit, the sum of its rows' shares and its row count.
    fn totals(&self, shares: &[(usize, f64)]) -> Vec<(f64, usize)> {
        let mut totals = vec![(0.0, 0usize); self.n_units];
        for (&(_, s), &u) in shares.iter().zip(&self.unit_of) {
            totals[u].0 += s;
            totals[u].1 += 1;
        }
        totals
    }

    /// The 95 % interval of the mean over conditions of the row-weighted mean share, by a
    /// percentile bootstrap resampling units within each condition.
    fn interval(&self, shares: &[(usize, f64)]) -> [f64; 2] {
        let totals = self.totals(shares);
        let sizes: Vec<usize> = self.by_condition.iter().map(Vec::len).collect();
        let rounds = self.resamples.max(1);
        let mut means: Vec<f64> = Vec::with_capacity(rounds);
        for_each_resample(self.seed, &sizes, rounds, |mut picked| {
            means.push(mean(self.by_condition.iter().map(|units| {
                let here;
                (here, picked) = picked.split_at(units.len());
                let (mut s, mut n) = (0.0, 0usize);
                for &i in here {
                    let u = units[i];
                    s += totals[u].0;
                    n += totals[u].1;
                }
                s / n.max(1) as f64
            })));
        });
        means.sort_by(f64::total_cmp);
        let (lower, upper) = (percentile(&means, 0.025), percentile(&means, 0.975));
        match wilson_at_the_bounds(lower, upper, sizes.iter().sum()) {
            Some(w) => [w.lower, w.upper],
            None => [lower, upper],
        }
    }

    /// Per unit, the mean share of `a` minus that of `b`.
    fn differences(&self, a: &[(usize, f64)], b: &[(usize, f64)]) -> Vec<f64> {
        let (ta, tb) = (self.totals(a), self.totals(b));
        ta.iter()
            .zip(&tb)
            .map(|(x, y)| (x.0 - y.0) / x.1.max(1) as f64)
            .collect()
    }

    fn rank(
        &self,
        c: &Candidate,
        s: &Scored,
        paper: Option<&Scored>,
        params: &CompareParams,
    ) -> Result<Ranked> {
        let against = match paper {
            Some(p) if !c.is_paper() => {
                if p.shares
                    .iter()
                    .map(|x| x.0)
                    .ne(s.shares.iter().map(|x| x.0))
                {
                    let (first, second) = (c.name(), "the paper's method".to_string());
                    return Err(ClassifyError::Unpaired { first, second }.into());
                }
                let d = self.differences(&s.shares, &p.shares);
                let p_value = sign_flip_p(&d, params.resamples, params.cv.seed)?;
                Some((p_value, s.accuracy - p.accuracy))
            }
            _ => None,
        };
        Ok(Ranked {
            encoding: c.encoding.clone(),
            method: c.method.clone(),
            classifier: c.classifier.clone(),
            accuracy: s.accuracy,
            ci: self.interval(&s.shares),
            p_vs_paper: against.map(|a| a.0),
            difference_vs_paper: against.map(|a| a.1),
            per_condition: s.per_condition.clone(),
            seconds: s.seconds,
            paper: c.is_paper(),
        })
    }
}

/// One outer split of nested selection.
struct OuterSplit {
    /// The condition it belongs to (empty for pooled cross-validation).
    condition: String,
    /// Training rows.
    train: Vec<usize>,
    /// Test rows.
    test: Vec<usize>,
}

/// What one outer split chose and how its test rows fared.
struct OuterResult {
    condition: String,
    /// The chosen candidate.
    chosen: usize,
    /// Per test row, its share of right predictions.
    shares: Vec<(usize, f64)>,
}

/// The outer splits of nested selection, from the first repeat's folds (or the held-out
/// conditions).
fn outer_splits(metas: &[Meta], params: &CompareParams) -> Result<Vec<OuterSplit>> {
    let folds_of = |rows: Vec<usize>, condition: String| -> Result<Vec<_>> {
        let fold_of = fold_assignment(metas, &rows, params)?;
        let n_folds = fold_of.iter().max().map_or(0, |&f| f + 1);
        Ok((0..n_folds)
            .map(|f| {
                let pick = |test: bool| -> Vec<usize> {
                    let rows = rows.iter().zip(&fold_of);
                    rows.filter(|(_, &g)| (g == f) == test)
                        .map(|(&r, _)| r)
                        .collect()
                };
                OuterSplit {
                    condition: condition.clone(),
                    train: pick(false),
                    test: pick(true),
                }
            })
            .collect())
    };
    match &params.protocol {
        Protocol::Pooled => folds_of((0..metas.len()).collect(), String::new()),
        Protocol::Per(column) => {
            let mut out = Vec::new();
            for value in conditions(metas, column)? {
                out.extend(folds_of(rows_with(metas, column, &value), value)?);
            }
            Ok(out)
        }
        Protocol::HoldOut(column) => Ok(conditions(metas, column)?
            .into_iter()
            .map(|value| {
                let test = rows_with(metas, column, &value);
                let train = (0..metas.len()).filter(|i| !test.contains(i)).collect();
                OuterSplit {
                    condition: value,
                    train,
                    test,
                }
            })
            .collect()),
        Protocol::Where { train, test } => Ok(vec![OuterSplit {
            condition: String::new(),
            train: train.rows(metas)?,
            test: test.rows(metas)?,
        }]),
    }
}

/// The first repeat's fold of each of `rows`: stratified by label, or by groups.
fn fold_assignment(metas: &[Meta], rows: &[usize], params: &CompareParams) -> Result<Vec<usize>> {
    let index = |values: Vec<String>| -> (Vec<usize>, Vec<String>) {
        let mut names: Vec<String> = Vec::new();
        let out = values
            .into_iter()
            .map(|v| {
                names.iter().position(|n| *n == v).unwrap_or_else(|| {
                    names.push(v);
                    names.len() - 1
                })
            })
            .collect();
        (out, names)
    };
    match &params.group_by {
        Some(column) => {
            let values = rows
                .iter()
                .map(|&r| metas[r].field(column).unwrap_or_default());
            let (groups, _) = index(values.collect());
            Ok(group_folds(&groups, params.cv.folds, params.cv.seed).0)
        }
        None => {
            let labels: Vec<String> = rows.iter().map(|&r| metas[r].label.clone()).collect();
            let (y, names) = index(labels);
            let (folds, seed) = (params.cv.folds, params.cv.seed);
            Ok(stratified_folds(&y, names.len(), folds, seed, &names)?)
        }
    }
}

/// The size of the smallest class among `rows`.
fn smallest_class(metas: &[Meta], rows: &[usize]) -> usize {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for &r in rows {
        let label = metas[r].label.as_str();
        match counts.iter_mut().find(|(l, _)| *l == label) {
            Some((_, n)) => *n += 1,
            None => counts.push((label, 1)),
        }
    }
    counts.iter().map(|c| c.1).min().unwrap_or(0)
}

/// Nested selection's outer splits, when it can run on them: its inner cross-validation
/// needs at least 2 folds, so every class at least 2 recordings in each outer training set.
fn check_nested(metas: &[Meta], params: &CompareParams) -> Result<Vec<OuterSplit>> {
    let splits = outer_splits(metas, params)?;
    for split in &splits {
        if smallest_class(metas, &split.train) < 2 {
            let rule = "nested selection cross-validates inside each outer training set: every class needs at least 2 recordings there";
            let at = match (&params.protocol, split.condition.as_str()) {
                (_, "") => "an outer training set".to_string(),
                (Protocol::Per(column) | Protocol::HoldOut(column), c) => {
                    format!("the outer training set at {column} = {c}")
                }
                (_, c) => format!("the outer training set of {c}"),
            };
            let got = format!("1 recording or none of some class in {at} (more recordings per class and condition run it)");
            return Err(ParamError::new("nested", rule, got).into());
        }
    }
    Ok(splits)
}

/// One outer split of nested selection: every candidate cross-validated on its training
/// rows (one repeat), the best trained on all of them and tested on its test rows.
fn outer(
    candidates: &[Candidate],
    split: &OuterSplit,
    params: &CompareParams,
    metas: &[Meta],
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<OuterResult> {
    // One repeat; fewer folds when a class of the training set is smaller than
    // the folds (an outer training set is a part of one condition's recordings).
    let smallest = smallest_class(metas, &split.train);
    let inner = CompareParams {
        cv: crate::classify::CvParams {
            repeats: 1,
            folds: inner_folds(params.cv.folds, smallest),
            ..*params.cv
        }
        .check()?,
        ..params.clone()
    };
    let accuracies: Vec<f64> = candidates
        .par_iter()
        .map(|c| {
            let accuracy = (c.evaluate)(&split.train, &cv_split(&inner))?.accuracy;
            progress(Progress::Tick);
            Ok(accuracy)
        })
        .collect::<Result<_>>()?;
    // The first candidate of the highest accuracy.
    let mut best = (f64::NEG_INFINITY, 0);
    for (k, &accuracy) in accuracies.iter().enumerate() {
        if accuracy > best.0 {
            best = (accuracy, k);
        }
    }
    let c = &candidates[best.1];
    let rows = Split::Rows {
        train: split.train.clone(),
        test: split.test.clone(),
    };
    let outcome = c.evaluate_all(&rows)?;
    Ok(OuterResult {
        condition: split.condition.clone(),
        chosen: best.1,
        shares: outcome.correct_shares,
    })
}

/// Nested selection: inside each outer split's training rows every candidate is
/// cross-validated (one repeat), the best is trained on all of them and tested on the
/// split's test rows.
fn nested(
    candidates: &[Candidate],
    splits: &[OuterSplit],
    params: &CompareParams,
    units: &Units,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Nested> {
    let metas = &candidates[0].metas;
    let steps = splits.len() * candidates.len();
    progress(Progress::Stage("nested selection", steps));
    let outcomes: Vec<OuterResult> = splits
        .par_iter()
        .map(|split| outer(candidates, split, params, metas, progress))
        .collect::<Result<_>>()?;
    let mut shares: Vec<(usize, f64)> = outcomes.iter().flat_map(|o| o.shares.clone()).collect();
    shares.sort_by_key(|&(row, _)| row);
    let mut chosen: Vec<(String, usize)> = Vec::new();
    for o in &outcomes {
        let name = candidates[o.chosen].name();
        match chosen.iter_mut().find(|(n, _)| *n == name) {
            Some((_, times)) => *times += 1,
            None => chosen.push((name, 1)),
        }
    }
    chosen.sort_by_key(|c| std::cmp::Reverse(c.1));
    // Mean over conditions of each condition's share of right test predictions.
    let mut per: Vec<(String, f64, usize)> = Vec::new();
    for o in &outcomes {
        let right: f64 = o.shares.iter().map(|x| x.1).sum();
        match per.iter_mut().find(|(c, _, _)| *c == o.condition) {
            Some((_, r, n)) => (*r, *n) = (*r + right, *n + o.shares.len()),
            None => per.push((o.condition.clone(), right, o.shares.len())),
        }
    }
    // The outer test sets cover the rows every candidate was scored on, once each, so the
    // units are the same.
    if shares.len() != units.unit_of.len() {
        let (first, second) = ("nested selection".to_string(), "the candidates".to_string());
        return Err(ClassifyError::Unpaired { first, second }.into());
    }
    Ok(Nested {
        accuracy: mean(per.iter().map(|(_, r, n)| r / (*n).max(1) as f64)),
        ci: units.interval(&shares),
        chosen,
        outer_splits: splits.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::{Columns, FeatureTable};
    use crate::classify::{CvParams, KnnParams};
    use crate::pipeline::Method;
    use crate::values::Grid;

    /// 3 classes x 2 speeds x 12 trials; `separable` features put each class far apart,
    /// otherwise the features are noise that knows nothing of the class.
    fn table(separable: bool) -> FeatureTable {
        let mut metas = Vec::new();
        let mut values = Vec::new();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut noise = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 1000) as f64 / 1000.0
        };
        for class in 0..3 {
            for speed in [5.0, 10.0] {
                for trial in 0..12 {
                    metas.push(Meta {
                        file: format!("c{class}_{speed}_{trial}.npy"),
                        label: format!("c{class}"),
                        speed_mm_s: Some(speed),
                        force_n: None,
                        trial: Some(trial),
                        slide_start_s: None,
                        slide_end_s: None,
                        extra: Default::default(),
                    });
                    let centre = if separable { 10.0 * class as f64 } else { 0.0 };
                    values.extend([centre + noise(), centre + noise(), centre + noise()]);
                }
            }
        }
        FeatureTable {
            method: Method::Glcm3d,
            grid: Grid::full(2, 2).unwrap(),
            names: vec!["a".into(), "b".into(), "c".into()],
            metas,
            values,
        }
    }

    fn candidate(method: &str, separable: bool) -> Candidate {
        let knn = KnnParams::default().check().unwrap();
        let table = table(separable);
        Candidate {
            encoding: "sa".into(),
            method: method.into(),
            classifier: "knn".into(),
            metas: Arc::new(table.metas.clone()),
            evaluate: crate::analysis::on_table(Arc::new(table), Columns::All, knn),
            prepare_s: 0.0,
        }
    }

    fn params(protocol: Protocol, nested: bool) -> CompareParams {
        CompareParams {
            protocol,
            cv: CvParams {
                folds: 4,
                seed: 3,
                repeats: 2,
            }
            .check()
            .unwrap(),
            group_by: None,
            resamples: 500,
            nested,
        }
    }

    #[test]
    fn a_separable_candidate_beats_the_paper_method_on_noise_significantly() {
        // The paper's method sees noise here; "good" sees the classes.
        let candidates = [candidate("glcm3d", false), candidate("good", true)];
        for protocol in [
            Protocol::Pooled,
            Protocol::Per("speed_mm_s".into()),
            Protocol::HoldOut("speed_mm_s".into()),
        ] {
            let c = compare(&candidates, &params(protocol.clone(), true)).unwrap();
            assert_eq!(c.best.method, "good", "{protocol}");
            assert_eq!(c.best.accuracy, 1.0);
            assert_eq!((c.classes, c.n_recordings, c.n_units), (3, 72, 72));
            assert!((c.chance - 1.0 / 3.0).abs() < 1e-15);
            let (best, paper) = (&c.results[0], &c.results[1]);
            assert!(paper.paper && paper.p_vs_paper.is_none());
            assert!(best.p_vs_paper.unwrap() < 0.01, "{protocol}: {best:?}");
            let gap = best.difference_vs_paper.unwrap();
            assert!((gap - (best.accuracy - paper.accuracy)).abs() < 1e-12);
            // noise classifies near chance, its interval holding chance and its estimate
            assert!(paper.ci[0] <= paper.accuracy && paper.accuracy <= paper.ci[1]);
            assert!(paper.ci[0] < 0.5 && paper.accuracy < 0.6, "{paper:?}");
            let nested = c.nested.as_ref().unwrap();
            assert_eq!(nested.chosen[0].0, "sa / good / knn");
            assert_eq!(nested.accuracy, 1.0);
            let conditions = if protocol == Protocol::Pooled { 0 } else { 2 };
            assert_eq!(best.per_condition.len(), conditions);
        }
    }

    #[test]
    fn per_condition_accuracies_average_to_the_accuracy_and_splits_are_shared() {
        let candidates = [candidate("glcm3d", true), candidate("glcm3d-again", true)];
        let c = compare(
            &candidates,
            &params(Protocol::Per("speed_mm_s".into()), false),
        )
        .unwrap();
        let r = &c.results[1];
        let mean = (r.per_condition[0].accuracy + r.per_condition[1].accuracy) / 2.0;
        assert_eq!(r.accuracy, mean);
        assert_eq!(r.per_condition[0].condition, "5");
        // the same features on the same splits: no difference at all, p = 1
        let other = c.results.iter().find(|r| !r.paper).unwrap();
        assert_eq!(other.difference_vs_paper, Some(0.0));
        assert_eq!(other.p_vs_paper, Some(1.0));
        assert!(c.nested.is_none());
    }

    #[test]
    fn a_protocol_column_without_two_values_is_an_error() {
        let candidates = [candidate("glcm3d", true)];
        let err = compare(&candidates, &params(Protocol::Per("session".into()), false));
        assert!(err.unwrap_err().to_string().contains("session"));
        assert!(compare(&[], &params(Protocol::Pooled, false)).is_err());
    }
}
