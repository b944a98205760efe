//! Nested selection: the candidates ranked inside each outer training set, the chosen one
//! scored on its test set.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::parts::{conditions, cv_split, hold_out, rows_with};
use super::units::Units;
use super::{kept_or, mean, Candidate, CompareParams, Keep, Nested, Protocol};
use crate::analysis::Split;
use crate::classify::{group_folds, stratified_folds};
use crate::error::{ClassifyError, ParamError, Result};
use crate::progress::{silent, Progress};
use crate::recording::Meta;

/// What the design makes of `--folds` where it cannot honour it: fewer groups than folds
/// (each group then held out in turn) and nested selection's inner folds, which a class
/// smaller than the folds reduces; each said once, with the value given and the one used.
pub(super) fn fewer_folds(
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
    let asked = fresh_folds(params);
    let mut fewer = inner_folds_of(metas, params, outer.unwrap_or_default());
    fewer.retain(|&used| used < asked);
    if let Some(low) = fewer.iter().min() {
        notes.push(format!(
            "nested selection's inner cross-validation uses as few as {low} folds instead of {asked} in {} of {} outer training sets (their smallest class has fewer than {asked} recordings)",
            fewer.len(),
            outer.map_or(0, <[_]>::len)
        ));
    }
    notes.extend(outer.and_then(|outer| inner_within_one_condition(metas, params, outer)));
    notes
}

/// The inner cross-validation's folds in each of `splits` whose inner ranking
/// cross-validates on folds of its own (rather than holding conditions or the other outer
/// folds out).
fn inner_folds_of(metas: &[Meta], params: &CompareParams, splits: &[OuterSplit]) -> Vec<usize> {
    (splits.iter())
        .filter(|split| inner_held_out(metas, params, split).is_none())
        .filter(|split| !on_outer_folds(metas, params, split))
        .map(|split| inner_folds(fresh_folds(params), smallest_class(metas, &split.train)))
        .collect()
}

/// The folds of an inner cross-validation on folds of its own: `--inner-folds`, or where it
/// is not given and the outer folds cannot serve, `--folds`.
fn fresh_folds(params: &CompareParams) -> usize {
    params.inner_folds.unwrap_or(params.cv.folds)
}

/// The fewest outer folds the inner ranking holds out in turn (with three, each inner fit
/// would train on a third of its condition's recordings).
pub(super) const OUTER_FOLDS_TO_RANK_ON: usize = 4;

/// Whether `split`'s inner ranking holds out each other outer fold of its condition in
/// turn: where no inner folds are asked for, the condition has four outer folds or more
/// (with three, each inner fit would train on a third of its recordings), and every such
/// inner training set holds every class of the outer training set.
pub(super) fn on_outer_folds(metas: &[Meta], params: &CompareParams, split: &OuterSplit) -> bool {
    if params.inner_folds.is_some() || split.others.len() + 1 < OUTER_FOLDS_TO_RANK_ON {
        return false;
    }
    let classes = |rows: &mut dyn Iterator<Item = usize>| -> Vec<&str> {
        let mut labels: Vec<&str> = rows.map(|r| metas[r].label.as_str()).collect();
        labels.sort_unstable();
        labels.dedup();
        labels
    };
    let all = classes(&mut split.train.iter().copied());
    split.others.iter().all(|held| {
        let mut fit = without(&split.train, held).into_iter();
        classes(&mut fit) == all
    })
}

/// The folds of nested selection's inner cross-validation: `folds` (the inner folds asked
/// for), fewer when a class of the outer training set has fewer recordings (`smallest`),
/// never under 2.
fn inner_folds(folds: usize, smallest: usize) -> usize {
    folds.min(smallest).max(2)
}

/// What nested selection reports its steps to and keeps its finished pieces in.
pub(super) type Around<'a> = (&'a (dyn Fn(Progress) + Sync), Option<&'a dyn Keep>);

/// Under a hold-out protocol, the column and its values in `split`'s training set when
/// there are two or more: the inner ranking then holds out each of them in turn.
fn inner_held_out<'p>(
    metas: &[Meta],
    params: &'p CompareParams,
    split: &OuterSplit,
) -> Option<(&'p str, Vec<String>)> {
    let Protocol::HoldOut(column) = &params.protocol else {
        return None;
    };
    let values = conditions(metas, column).unwrap_or_default();
    let present: Vec<String> = (values.into_iter())
        .filter(|v| (split.train.iter()).any(|&r| metas[r].field(column).as_ref() == Some(v)))
        .collect();
    (present.len() > 1).then_some((column.as_str(), present))
}

/// How the outer training sets ranked the candidates, in words.
fn inner_ranking(metas: &[Meta], params: &CompareParams, splits: &[OuterSplit]) -> String {
    let folds = inner_folds_of(metas, params, splits);
    let aligned = (splits.iter())
        .filter(|split| on_outer_folds(metas, params, split))
        .count();
    let held = splits.len() - folds.len() - aligned;
    let cv = match (folds.iter().min(), folds.iter().max()) {
        (Some(&a), Some(&b)) if a == b => format!("{a}-fold cross-validation"),
        (Some(&a), Some(&b)) => format!("{a}- to {b}-fold cross-validation"),
        _ => String::new(),
    };
    match (&params.protocol, held) {
        (Protocol::HoldOut(column), h) if h == splits.len() => {
            format!("each other value of {column} held out in turn, inside each outer training set")
        }
        (Protocol::HoldOut(column), 0) => {
            format!("{cv} inside each outer training set (each holds one value of {column})")
        }
        (Protocol::HoldOut(column), h) => format!(
            "each other value of {column} held out in turn inside {h} outer training sets, {cv} inside the {} that hold one",
            splits.len() - h
        ),
        _ if aligned == splits.len() => {
            "each of the other outer folds of its condition held out in turn, inside each outer training set".to_string()
        }
        _ if aligned > 0 => format!(
            "each of the other outer folds of its condition held out in turn inside {aligned} outer training sets, {cv} inside the {} where a class would be missing from a fit",
            splits.len() - aligned
        ),
        _ => format!("{cv} inside each outer training set"),
    }
}

/// Under a hold-out protocol, the note that some outer training sets hold one condition, so
/// that their inner ranking can only cross-validate within it.
fn inner_within_one_condition(
    metas: &[Meta],
    params: &CompareParams,
    outer: &[OuterSplit],
) -> Option<String> {
    let Protocol::HoldOut(column) = &params.protocol else {
        return None;
    };
    let within = outer
        .iter()
        .filter(|split| inner_held_out(metas, params, split).is_none())
        .count();
    (within > 0).then(|| format!(
        "nested selection with --hold-out {column}: {within} of {} outer training sets hold one value of `{column}`, so their inner ranking cross-validates within it and favours what does best on a condition seen in training, which need not carry to the one held out (more values of `{column}` let it hold one out)",
        outer.len()
    ))
}

/// One outer split of nested selection.
pub(super) struct OuterSplit {
    /// The condition it belongs to (empty for pooled cross-validation).
    pub(super) condition: String,
    /// Training rows.
    pub(super) train: Vec<usize>,
    /// Test rows.
    pub(super) test: Vec<usize>,
    /// The test rows of the other outer folds of its condition, under cross-validation (the
    /// inner ranking can hold out each in turn).
    pub(super) others: Vec<Vec<usize>>,
}

/// The rows of `rows` not in `out`, both ascending (as every split's rows are).
fn without(rows: &[usize], out: &[usize]) -> Vec<usize> {
    (rows.iter().copied())
        .filter(|r| out.binary_search(r).is_err())
        .collect()
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
pub(super) fn outer_splits(metas: &[Meta], params: &CompareParams) -> Result<Vec<OuterSplit>> {
    let folds_of = |rows: Vec<usize>, condition: String| -> Result<Vec<_>> {
        let fold_of = fold_assignment(metas, &rows, params)?;
        let n_folds = fold_of.iter().max().map_or(0, |&f| f + 1);
        let pick = |f: usize, test: bool| -> Vec<usize> {
            let rows = rows.iter().zip(&fold_of);
            rows.filter(|(_, &g)| (g == f) == test)
                .map(|(&r, _)| r)
                .collect()
        };
        Ok((0..n_folds)
            .map(|f| OuterSplit {
                condition: condition.clone(),
                train: pick(f, false),
                test: pick(f, true),
                others: (0..n_folds)
                    .filter(|&g| g != f)
                    .map(|g| pick(g, true))
                    .collect(),
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
                    others: Vec::new(),
                }
            })
            .collect()),
        Protocol::Where { train, test } => Ok(vec![OuterSplit {
            condition: String::new(),
            train: train.rows(metas)?,
            test: test.rows(metas)?,
            others: Vec::new(),
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
    let mut labels: Vec<&str> = rows.iter().map(|&r| metas[r].label.as_str()).collect();
    labels.sort_unstable();
    let sizes = labels.chunk_by(|a, b| a == b).map(<[_]>::len);
    sizes.min().unwrap_or(0)
}

/// Nested selection's outer splits, when it can run on them: its inner cross-validation
/// needs at least 2 folds, so every class at least 2 recordings in each outer training set.
pub(super) fn check_nested(metas: &[Meta], params: &CompareParams) -> Result<Vec<OuterSplit>> {
    if let Some(folds @ 0..2) = params.inner_folds {
        let rule = "nested selection's inner cross-validation needs 2 folds or more";
        return Err(ParamError::new("inner-folds", rule, folds).into());
    }
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
            let got = format!("1 recording or none of some class in {at} (more recordings per class and condition run it; without nested selection the comparison runs as it is)");
            return Err(ParamError::new("nested", rule, got).into());
        }
    }
    Ok(splits)
}

/// One outer split of nested selection: every candidate ranked on its training rows (each
/// other outer fold held out in turn, or cross-validated on folds of its own, one repeat,
/// or with each of their conditions held out under a hold-out protocol), the best trained
/// on all of them and tested on its test rows.
fn outer(
    candidates: &[Candidate],
    (s, split): (usize, &OuterSplit),
    (params, shared): (&CompareParams, &SharedFits),
    metas: &[Meta],
    (progress, keep): Around<'_>,
) -> Result<OuterResult> {
    // One repeat; fewer folds when a class of the training set is smaller than
    // the folds (an outer training set is a part of one condition's recordings).
    let smallest = smallest_class(metas, &split.train);
    let inner = CompareParams {
        cv: crate::classify::CvParams {
            repeats: 1,
            folds: inner_folds(fresh_folds(params), smallest),
            ..*params.cv
        }
        .check()?,
        ..params.clone()
    };
    // The inner ranking asks the outer protocol's question: under a hold-out protocol each
    // condition of the training set is held out in turn (the mean of their accuracies, as
    // the outer accuracy is), so that the candidate chosen is the one that carries best to
    // a condition it was not trained on; with one condition there, cross-validation within
    // it is all there is ([`inner_within_one_condition`] says so). Under cross-validation
    // it holds out each other outer fold in turn, where the folds allow.
    let held = inner_splits(metas, params, split);
    let inner_accuracy = |k: usize, c: &Candidate| -> Result<f64> {
        if held.is_empty() {
            return Ok((c.evaluate)(&split.train, &cv_split(&inner), &silent)?.accuracy);
        }
        let mut sum = 0.0;
        for (split_of_value, rows) in &held {
            sum += match rows.as_ref().and_then(|r| shared.accuracy(k, c, r)) {
                Some(accuracy) => accuracy,
                None => (c.evaluate)(&split.train, split_of_value, &silent)?.accuracy,
            };
        }
        Ok(sum / held.len() as f64)
    };
    let accuracies: Vec<f64> = candidates
        .par_iter()
        .enumerate()
        .map(|(k, c)| {
            crate::progress::stop_point();
            let key = format!("inner accuracy of {} in outer split {s}", c.name());
            let accuracy = kept_or(keep, &key, || inner_accuracy(k, c))?;
            progress(Progress::Tick);
            Ok(accuracy)
        })
        .collect::<Result<_>>()?;
    // The first candidate of the highest accuracy.
    let best = (0..accuracies.len()).fold(0, |b, k| match accuracies[k] > accuracies[b] {
        true => k,
        false => b,
    });
    let (train, test) = (split.train.clone(), split.test.clone());
    let outcome = candidates[best].evaluate_all(&Split::Rows { train, test })?;
    Ok(OuterResult {
        condition: split.condition.clone(),
        chosen: best,
        shares: outcome.correct_shares,
    })
}

/// The inner splits `split`'s ranking holds out in turn, each with its rows among all
/// recordings (those a fit another outer split makes can stand in for): each other value
/// of the hold-out column, or each other outer fold of its condition; none where it
/// cross-validates on folds of its own.
fn inner_splits(
    metas: &[Meta],
    params: &CompareParams,
    split: &OuterSplit,
) -> Vec<(Split, Option<HeldRows>)> {
    if let Some((column, values)) = inner_held_out(metas, params, split) {
        return (values.iter())
            .map(|value| {
                let held = hold_out(column, &values, value);
                let rows = held_rows(metas, &split.train, &held);
                (held, rows)
            })
            .collect();
    }
    if !on_outer_folds(metas, params, split) {
        return Vec::new();
    }
    // Positions among the outer training rows, for the split's own evaluation.
    let at = |rows: &[usize]| -> Vec<usize> {
        let position = |r: &usize| split.train.binary_search(r).ok();
        rows.iter().filter_map(position).collect()
    };
    (split.others.iter())
        .map(|test| {
            let fit = without(&split.train, test);
            let mut tested: Vec<usize> = test.iter().chain(&split.test).copied().collect();
            tested.sort_unstable();
            let own = Split::Rows {
                train: at(&fit),
                test: at(test),
            };
            let test = test.clone();
            (own, Some(HeldRows { fit, test, tested }))
        })
        .collect()
}

/// An inner split in one outer split, as rows among all recordings: the rows trained on,
/// the rows tested, and the rows a fit on `fit` shared between outer splits is tested on
/// (the same whichever split makes it).
struct HeldRows {
    fit: Vec<usize>,
    test: Vec<usize>,
    tested: Vec<usize>,
}

/// The rows `held` trains and tests on inside the outer training rows `within`, numbered
/// among all recordings (ascending); `None` where the split selects nothing (its own
/// evaluation then says why).
fn held_rows(metas: &[Meta], within: &[usize], held: &Split) -> Option<HeldRows> {
    let Split::Where { train, test } = held else {
        return None;
    };
    let sub: Vec<Meta> = within.iter().map(|&r| metas[r].clone()).collect();
    let among_all = |rows: Vec<usize>| -> Vec<usize> { rows.iter().map(|&i| within[i]).collect() };
    let fit = among_all(train.rows(&sub).ok()?);
    let tested = (0..metas.len())
        .filter(|r| fit.binary_search(r).is_err())
        .collect();
    Some(HeldRows {
        fit,
        test: among_all(test.rows(&sub).ok()?),
        tested,
    })
}

/// The inner rankings' fits that outer splits share under a hold-out protocol. Outer split
/// `a`, holding out value `b` of its training set, trains on the recordings of neither, as
/// outer split `b` does holding out `a`: with 12 values, 132 inner fits per candidate are 66
/// different ones. Each is made once and tested on every recording outside it; an inner
/// split reads its accuracy off its own test rows. The fit is the one the inner split would
/// make (the same training rows, in the same order, with the same classes) and each
/// recording's prediction depends on the fit alone, so every accuracy is the same, bit for
/// bit, as the inner split's own evaluation. Where a shared fit cannot stand in (a class
/// outside it that it would have to be tested on, a method scoring each taxel alone), the
/// inner split is evaluated on its own.
#[derive(Default)]
struct SharedFits {
    slots: Mutex<SharedSlots>,
    /// The candidates found to score groups of columns alone (evaluated split by split).
    alone: Mutex<Vec<usize>>,
}

/// Per candidate and training rows, the shared fit's right predictions (1 or 0 per
/// recording tested, by row), or `None` where it cannot stand in.
type SharedSlots = HashMap<(usize, Vec<usize>), Option<Arc<Vec<(usize, f64)>>>>;

impl SharedFits {
    /// Candidate `k`'s (`c`) accuracy on `rows.test` trained on `rows.fit`, from the shared
    /// fit; `None` where it cannot stand in.
    fn accuracy(&self, k: usize, c: &Candidate, rows: &HeldRows) -> Option<f64> {
        if lock(&self.alone).contains(&k) {
            return None;
        }
        let key = (k, rows.fit.clone());
        let known = lock(&self.slots).get(&key).cloned();
        // The lock is not held while fitting: two outer splits that meet the same fit at
        // once each make it (the same bits), rather than one waiting inside rayon's pool.
        let right = match known {
            Some(right) => right,
            None => {
                let right = shared_fit(c, rows, || lock(&self.alone).push(k));
                lock(&self.slots).entry(key).or_insert(right).clone()
            }
        }?;
        let mut sum = 0.0;
        for row in &rows.test {
            let at = right.binary_search_by_key(row, |r| r.0).ok()?;
            sum += right[at].1;
        }
        // A sum of ones and zeros is the count of right predictions exactly, so this is
        // the inner split's own accuracy (right / tested).
        Some(sum / rows.test.len().max(1) as f64)
    }
}

/// `m` locked (a lock poisoned by a panic elsewhere still holds whole entries).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Candidate `c` trained on the rows `rows.fit` and tested on `rows.tested`: each
/// recording's right prediction (1 or 0), by row; `None` where that cannot stand in for an
/// inner split's own evaluation (a test class it has not trained on, several groups of
/// columns each scored alone: `in_groups` is then called).
fn shared_fit(
    c: &Candidate,
    rows: &HeldRows,
    in_groups: impl FnOnce(),
) -> Option<Arc<Vec<(usize, f64)>>> {
    let (train, test) = (rows.fit.clone(), rows.tested.clone());
    let outcome = c.evaluate_all(&Split::Rows { train, test }).ok()?;
    // Predictions are kept for one group of columns only: then each share is 1 or 0.
    if outcome.predictions.is_none() {
        in_groups();
        return None;
    }
    let mut right = outcome.correct_shares;
    right.sort_unstable_by_key(|r| r.0);
    Some(Arc::new(right))
}

/// Nested selection: inside each outer split's training rows every candidate is
/// cross-validated (one repeat), the best is trained on all of them and tested on the
/// split's test rows.
pub(super) fn nested(
    candidates: &[Candidate],
    splits: &[OuterSplit],
    params: &CompareParams,
    units: &Units,
    (progress, keep): Around<'_>,
) -> Result<Nested> {
    let metas = &candidates[0].metas;
    let steps = splits.len() * candidates.len();
    progress(Progress::Stage("nested selection", steps));
    let shared = SharedFits::default();
    let outcomes: Vec<OuterResult> = splits
        .par_iter()
        .enumerate()
        .map(|split| {
            let around = (progress, keep);
            outer(candidates, split, (params, &shared), metas, around)
        })
        .collect::<Result<_>>()?;
    let mut shares: Vec<(usize, f64)> = outcomes.iter().flat_map(|o| o.shares.clone()).collect();
    shares.sort_by_key(|&(row, _)| row);
    let mut chosen: Vec<(String, usize)> = Vec::new();
    for name in outcomes.iter().map(|o| candidates[o.chosen].name()) {
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
        inner: inner_ranking(metas, params, splits),
    })
}
