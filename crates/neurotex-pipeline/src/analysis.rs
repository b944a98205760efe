//! Every method's samples evaluated over many recordings: cross-validation on a set of
//! conditions, or training on some conditions and testing on others; per taxel for the
//! single-taxel method. A feature method's samples are a [`FeatureTable`] (KNN, the forest,
//! logistic regression), the `spikes` method's every recording's binned spikes
//! ([`SpikeSamples`], the spiking network's), `van-rossum`'s the [`DistanceMatrix`] between the recordings (KNN over
//! it): [`MethodSamples`] holds any of them. [`evaluator`] pairs them with a classifier
//! once, where the options are checked, and returns one [`EvaluateFn`] that `evaluate`,
//! `compare` and nested selection call alike.

use std::sync::Arc;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::classify::{
    bootstrap_mean_share, bootstrap_over_encodings, cross_validate_on, train_test_on,
    BootstrapParams, Classifier, ClassifierChoice, ConfusionMatrix, DistanceMatrix, Evaluation,
    Interval, Learner, Rows, Samples, SnnClassifier, SpikeDistanceKnn, SpikeSamples, Sweep,
    ValidCv,
};
use crate::error::{ClassifyError, ParamError, Result};
use crate::pipeline::{Encoded, Encoding, FeatureExtractor};
use crate::progress::Progress;
use crate::recording::{DatasetError, Meta, Selection};
use crate::samples::{spike_inputs, MethodChoice};
use crate::table::rows_at;
pub use crate::table::FeatureTable;
use crate::values::{Cell, Grid, Speed};

/// How to split recordings for evaluation.
#[derive(Debug, Clone, PartialEq)]
pub enum Split {
    /// Stratified k-fold cross-validation over the recordings at these speeds (all when `None`).
    CrossValidation {
        /// Speeds to include.
        speeds: Option<Vec<Speed>>,
        /// Folds, seed, repeats.
        cv: ValidCv,
        /// A manifest column (`trial`, `force_n`, or any further column) whose groups no
        /// fold may split; `None` for stratified folds.
        group_by: Option<String>,
    },
    /// Train on the recordings `train` selects, test on those `test` selects (by speed,
    /// trial, force or any further manifest column); no recording may be in both.
    Where {
        /// The training recordings.
        train: Selection,
        /// The test recordings.
        test: Selection,
    },
    /// Train on the table rows `train`, test on the rows `test` (disjoint): for splits
    /// made outside the manifest's columns, as nested model selection makes them.
    Rows {
        /// The training rows.
        train: Vec<usize>,
        /// The test rows.
        test: Vec<usize>,
    },
}

/// One taxel's accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TaxelAccuracy {
    /// Grid row.
    pub row: usize,
    /// Grid column.
    pub col: usize,
    /// Accuracy, 0..1.
    pub accuracy: f64,
}

/// The result of evaluating a feature table (the analysis level; a classifier's own result
/// is [`crate::classify::Evaluation`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// Accuracy 0..1 (for all taxels: the mean over taxels).
    pub accuracy: f64,
    /// Standard deviation over CV repeats (over taxels: mean of the per-taxel values).
    pub accuracy_std: f64,
    /// Class names in confusion-matrix order.
    pub labels: Vec<String>,
    /// Row = true label; summed over repeats, and over taxels when every taxel was evaluated.
    pub confusion: ConfusionMatrix,
    /// Test samples per evaluation.
    pub n: usize,
    /// Every taxel's accuracy, when every taxel was evaluated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub per_taxel: Option<Vec<TaxelAccuracy>>,
    /// The best taxel, chosen after the fact, when every taxel was evaluated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub best: Option<TaxelAccuracy>,
    /// Every evaluated recording's prediction in every repeat, repeat by repeat in table
    /// order; `None` when several taxels were evaluated in turn (one prediction each). Left out of
    /// the serialised form, whose readers want the summary.
    #[serde(skip)]
    pub predictions: Option<Vec<OutOfFold>>,
    /// Per evaluated recording `(table row, share of its predictions that were right)`,
    /// over repeats and, when several taxels were evaluated in turn, over taxels: what
    /// intervals and paired comparisons resample. Left out of the serialised form.
    #[serde(skip)]
    pub correct_shares: Vec<(usize, f64)>,
}

impl Outcome {
    /// The 95 % interval of the accuracy by a percentile bootstrap over the evaluated
    /// recordings (2000 resamples seeded by `seed`), each recording's predictions over
    /// repeats, and taxels, kept together.
    ///
    /// # Errors
    /// An outcome without per-recording results.
    pub fn accuracy_interval(&self, seed: u64) -> Result<Interval> {
        let shares: Vec<f64> = self.correct_shares.iter().map(|&(_, s)| s).collect();
        Ok(seeded_bootstrap(&shares, seed)?.or_wilson_at_the_bounds(shares.len()))
    }
}

/// The percentile bootstrap of the mean of `shares` (each in 0..1) with the default number
/// of resamples, seeded by `seed`.
///
/// # Errors
/// No shares, or one outside 0..1.
pub fn seeded_bootstrap(shares: &[f64], seed: u64) -> Result<Interval> {
    let params = BootstrapParams {
        seed,
        ..BootstrapParams::default()
    }
    .check()?;
    Ok(bootstrap_mean_share(shares, &params)?)
}

/// [`seeded_bootstrap`] over recordings and encodings: `shares[e]` holds every recording's
/// share under encoding `e` ([`bootstrap_over_encodings`]); one encoding gives
/// [`seeded_bootstrap`]'s interval.
///
/// # Errors
/// No encodings or shares, encodings of different lengths, or a share outside 0..1.
pub fn seeded_bootstrap_over_encodings(shares: &[Vec<f64>], seed: u64) -> Result<Interval> {
    let params = BootstrapParams {
        seed,
        ..BootstrapParams::default()
    }
    .check()?;
    Ok(bootstrap_over_encodings(shares, &params)?)
}

/// One recording's out-of-fold prediction in one evaluation repeat.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct OutOfFold {
    /// The recording, as a row of the evaluated [`FeatureTable`].
    pub row: usize,
    /// The cross-validation repeat (0 for a train/test split).
    pub repeat: usize,
    /// The fold the recording was tested in; `None` for a train/test split.
    pub fold: Option<usize>,
    /// The predicted class, an index into [`Outcome::labels`].
    pub predicted: usize,
}

impl OutOfFold {
    /// The predictions of `evaluation` whose samples are the table rows `rows`.
    fn of(evaluation: &crate::classify::Evaluation, rows: &[usize]) -> Vec<Self> {
        let mut out = Vec::new();
        for (repeat, p) in evaluation.predictions.iter().enumerate() {
            out.extend(
                p.predicted
                    .iter()
                    .enumerate()
                    .map(|(i, &predicted)| OutOfFold {
                        row: rows[i],
                        repeat,
                        fold: p.fold_of.as_ref().map(|f| f[i]),
                        predicted,
                    }),
            );
        }
        out
    }
}

/// Which feature columns to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Columns {
    /// All of them (GLCM methods).
    All,
    /// The three of one taxel (six with two populations).
    Taxel(Cell),
    /// Each taxel in turn, reporting the mean and the best.
    EachTaxel,
}

/// One column group's evaluation: the taxel it belongs to (none for all columns) and the
/// classifier's result.
struct GroupResult {
    cell: Option<usize>,
    evaluation: crate::classify::Evaluation,
}

/// The column groups `columns` names among the `dims` columns of a table on `grid`:
/// `(taxel cell, column indices)`.
pub(crate) fn column_groups(
    grid: &Grid,
    dims: usize,
    columns: Columns,
) -> Result<Vec<(Option<usize>, Vec<usize>)>> {
    let taxels: Vec<usize> = grid.taxels().collect();
    // Per-taxel methods hold 3 columns per taxel per population (SA block, then FA block
    // for sa+fa): a taxel's group is its columns in every population.
    let block = 3 * taxels.len();
    let populations = dims.checked_div(block).unwrap_or(1).max(1);
    let of_taxel = |k: usize| {
        let columns = (0..populations)
            .flat_map(|p| p * block + 3 * k..p * block + 3 * k + 3)
            .collect();
        (Some(taxels[k]), columns)
    };
    Ok(match columns {
        Columns::All => vec![(None, (0..dims).collect())],
        Columns::Taxel(cell) => {
            let index = grid.taxel_index(cell).ok_or_else(|| {
                ParamError::new(
                    "taxel",
                    "taxel must be a present cell of the grid",
                    format!("{},{} in the {} grid", cell.row, cell.col, grid),
                )
            })?;
            let k = taxels.iter().position(|&t| t == index).unwrap_or(0);
            vec![of_taxel(k)]
        }
        Columns::EachTaxel => (0..taxels.len()).map(of_taxel).collect(),
    })
}

/// The class names in order of first appearance over `rows`, and each row's class index.
fn classes(metas: &[Meta], rows: &[usize]) -> (Vec<String>, Vec<usize>) {
    let mut labels: Vec<String> = Vec::new();
    let y = rows
        .iter()
        .map(|&i| {
            let label = &metas[i].label;
            labels.iter().position(|l| l == label).unwrap_or_else(|| {
                labels.push(label.clone());
                labels.len() - 1
            })
        })
        .collect();
    (labels, y)
}

/// The number of groups of manifest column `column` among `rows` (recordings without a
/// value there one group), as grouped cross-validation counts them.
pub fn group_count(metas: &[Meta], rows: &[usize], column: &str) -> usize {
    let mut seen: Vec<String> = Vec::new();
    for &r in rows {
        let value = metas[r].field(column).unwrap_or_default();
        if !seen.contains(&value) {
            seen.push(value);
        }
    }
    seen.len()
}

/// Each row's group under the manifest column `column`, as indices from 0.
///
/// # Errors
/// A column the manifest does not have, or a single group (nothing to test on).
fn group_indices(metas: &[Meta], rows: &[usize], column: &str) -> Result<Vec<usize>> {
    let mut names: Vec<String> = Vec::new();
    let mut out = Vec::with_capacity(rows.len());
    for &i in rows {
        let meta = &metas[i];
        let value = match meta.field(column) {
            Some(value) => value,
            // A recording without a value (an empty field) groups with the others like it.
            None if metas.iter().any(|m| m.field(column).is_some()) => String::new(),
            None => {
                let rule = "--group-by must name a manifest column with values";
                let names = Meta::columns_with_values(metas).join(", ");
                let got = format!(
                    "{column} (no recording has a value there; columns with values: {names})"
                );
                return Err(ParamError::new("group-by", rule, got).into());
            }
        };
        let index = names.iter().position(|n| *n == value).unwrap_or_else(|| {
            names.push(value);
            names.len() - 1
        });
        out.push(index);
    }
    if names.len() < 2 {
        let rule = "grouped cross-validation needs at least two groups";
        return Err(
            ParamError::new("group-by", rule, format!("{column}: {} group", names.len())).into(),
        );
    }
    Ok(out)
}

/// Evaluates a feature table with `classifier`.
///
/// # Errors
/// No recordings at the asked speeds, a class smaller than the fold count, a training set
/// the classifier cannot fit, a test label unseen in training, or a taxel outside the grid.
pub fn evaluate<C: Classifier>(
    table: &FeatureTable,
    columns: Columns,
    split: &Split,
    classifier: &C,
) -> Result<Outcome> {
    let mut each = evaluate_sweep(table, columns, split, classifier)?;
    each.pop().ok_or_else(|| {
        ClassifyError::Empty {
            what: "evaluate: no classifier setting",
        }
        .into()
    })
}

/// [`evaluate`] of every setting of `sweep` (one outcome each, in its order), each fold
/// fitted once for all of them: E8's k from one neighbour search
/// ([`KnnSweep`](crate::classify::KnnSweep)).
///
/// # Errors
/// As [`evaluate`].
pub fn evaluate_sweep<C: Sweep>(
    table: &FeatureTable,
    columns: Columns,
    split: &Split,
    sweep: &C,
) -> Result<Vec<Outcome>> {
    let groups = column_groups(&table.grid, table.dims(), columns)?;
    let all: Vec<usize> = (0..table.metas.len()).collect();
    let design = Design::of(&table.metas, &all, split)?;
    // Per column group, each setting's evaluation.
    let results: Vec<Vec<Evaluation>> = groups
        .par_iter()
        .map(|(_, cols)| -> Result<Vec<Evaluation>> {
            let values = match cols.len() == table.dims() {
                true => std::borrow::Cow::Borrowed(&table.values[..]),
                false => std::borrow::Cow::Owned(table.select(&all, cols)),
            };
            design.run(&Rows::new(&values, cols.len())?, split, sweep)
        })
        .collect::<Result<_>>()?;
    let each_taxel = (columns == Columns::EachTaxel).then_some(&table.grid);
    Ok(design.outcomes(results, &groups, each_taxel))
}

/// Evaluates `learner` on the samples of the recordings `within` (sample `i` is recording
/// `metas[i]`) under `split`, whose rows are positions in `within`: one outcome per
/// setting, its recordings numbered by those positions. This is how the methods whose
/// samples are not feature rows are evaluated: the spiking network on the recordings'
/// spike inputs, KNN on their van Rossum distances.
///
/// # Errors
/// As [`evaluate`].
pub fn evaluate_samples<S: Samples + ?Sized, L: Learner<S>>(
    metas: &[Meta],
    within: &[usize],
    samples: &S,
    split: &Split,
    learner: &L,
) -> Result<Vec<Outcome>> {
    let design = Design::of(metas, within, split)?;
    let results = vec![design.run(samples, split, learner)?];
    Ok(design.outcomes(results, &[(None, Vec::new())], None))
}

/// What a split makes of the recordings it is given: the rows it trains (or
/// cross-validates) on and tests on, their classes and their groups.
struct Design {
    /// Positions among the evaluated recordings: trained on, then tested on.
    train: Vec<usize>,
    test: Vec<usize>,
    /// The same as sample indices.
    train_samples: Vec<usize>,
    test_samples: Vec<usize>,
    labels: Vec<String>,
    /// Each training, then each test row's class.
    y: Vec<usize>,
    /// Each training row's group under `--group-by`.
    groups: Option<Vec<usize>>,
}

impl Design {
    /// The design of `split` over the recordings `within` of `metas`.
    ///
    /// # Errors
    /// No recordings selected, a selection that selects nothing, a recording in both sets.
    fn of(metas: &[Meta], within: &[usize], split: &Split) -> Result<Self> {
        let whole = within.len() == metas.len() && within.iter().enumerate().all(|(i, &r)| i == r);
        let sub: std::borrow::Cow<[Meta]> = match whole {
            true => std::borrow::Cow::Borrowed(metas),
            false => within.iter().map(|&i| metas[i].clone()).collect(),
        };
        let (train, test) = split_rows(&sub, split)?;
        if train.is_empty() {
            return Err(ClassifyError::Empty {
                what: "evaluate: no recordings at the selected speeds",
            }
            .into());
        }
        let all_rows: Vec<usize> = train.iter().chain(&test).copied().collect();
        let (labels, y) = classes(&sub, &all_rows);
        let groups = match split {
            Split::CrossValidation {
                group_by: Some(column),
                ..
            } => Some(group_indices(&sub, &train, column)?),
            _ => None,
        };
        Ok(Design {
            train_samples: train.iter().map(|&r| within[r]).collect(),
            test_samples: test.iter().map(|&r| within[r]).collect(),
            train,
            test,
            labels,
            y,
            groups,
        })
    }

    /// Each setting's evaluation of `learner` on `samples`.
    fn run<S: Samples + ?Sized, L: Learner<S>>(
        &self,
        samples: &S,
        split: &Split,
        learner: &L,
    ) -> Result<Vec<Evaluation>> {
        let (y_train, y_test) = self.y.split_at(self.train.len());
        let train = (&self.train_samples[..], y_train);
        Ok(match split {
            Split::CrossValidation { cv, .. } => {
                let groups = self.groups.as_deref();
                cross_validate_on(learner, samples, train, &self.labels, *cv, groups)?
            }
            Split::Where { .. } | Split::Rows { .. } => {
                let test = (&self.test_samples[..], y_test);
                train_test_on(learner, samples, train, test, &self.labels)?
            }
        })
    }

    /// One outcome per setting from each column group's evaluations; `each_taxel` is the
    /// grid when every taxel was evaluated alone.
    fn outcomes(
        &self,
        results: Vec<Vec<Evaluation>>,
        groups: &[(Option<usize>, Vec<usize>)],
        each_taxel: Option<&Grid>,
    ) -> Vec<Outcome> {
        let (y_train, y_test) = self.y.split_at(self.train.len());
        let evaluated = match self.test.is_empty() {
            true => (&self.train[..], y_train),
            false => (&self.test[..], y_test),
        };
        by_setting(results, groups, &self.labels, evaluated, each_taxel)
    }
}

/// One [`Outcome`] per setting of a sweep from each column group's evaluations (`results`,
/// per group, one per setting), for the rows `evaluated` whose classes are `truth`.
fn by_setting(
    results: Vec<Vec<Evaluation>>,
    groups: &[(Option<usize>, Vec<usize>)],
    labels: &[String],
    (evaluated, truth): (&[usize], &[usize]),
    each_taxel: Option<&Grid>,
) -> Vec<Outcome> {
    let settings = results.first().map_or(0, Vec::len);
    let mut by_group: Vec<_> = results.into_iter().map(Vec::into_iter).collect();
    let outcomes = (0..settings).map(|_| {
        let results: Vec<GroupResult> = groups
            .iter()
            .zip(by_group.iter_mut())
            .filter_map(|((cell, _), each)| {
                let evaluation = each.next()?;
                Some(GroupResult {
                    cell: *cell,
                    evaluation,
                })
            })
            .collect();
        let predictions = match &results[..] {
            [one] => Some(OutOfFold::of(&one.evaluation, evaluated)),
            _ => None,
        };
        let correct_shares = correct_shares(&results, evaluated, truth);
        Outcome {
            predictions,
            correct_shares,
            ..combine(results, labels.to_vec(), each_taxel)
        }
    });
    outcomes.collect()
}

/// The rows `split` trains (or cross-validates) on and the rows it tests on.
///
/// # Errors
/// A selection that selects nothing, or a recording in both sets.
fn split_rows(metas: &[Meta], split: &Split) -> Result<(Vec<usize>, Vec<usize>)> {
    Ok(match split {
        Split::CrossValidation { speeds: None, .. } => ((0..metas.len()).collect(), vec![]),
        Split::CrossValidation {
            speeds: Some(s), ..
        } => (rows_at(metas, s), vec![]),
        Split::Where { train, test } => disjoint(metas, train, test)?,
        Split::Rows { train, test } => {
            let n = metas.len();
            if let Some(&i) = train.iter().chain(test).find(|&&i| i >= n) {
                let message = format!("row {i} of a table of {n} rows");
                return Err(ClassifyError::BadFeatures(message).into());
            }
            if let Some(&i) = test.iter().find(|i| train.contains(i)) {
                let message = format!("row {i} is in both the training and the test rows");
                return Err(ClassifyError::BadFeatures(message).into());
            }
            (train.clone(), test.clone())
        }
    })
}

/// The rows `train` and `test` select.
///
/// # Errors
/// A selection that selects nothing ([`Selection::rows`]), or a recording in both.
fn disjoint(
    metas: &[Meta],
    train: &Selection,
    test: &Selection,
) -> Result<(Vec<usize>, Vec<usize>)> {
    let (train_rows, test_rows) = (train.rows(metas)?, test.rows(metas)?);
    if let Some(&i) = test_rows.iter().find(|i| train_rows.contains(i)) {
        return Err(DatasetError::InBothSets {
            file: metas[i].file.clone(),
            train: train.to_string(),
            test: test.to_string(),
        }
        .into());
    }
    Ok((train_rows, test_rows))
}

/// Per evaluated recording, the share of all groups' predictions in all repeats that were
/// right (`truth[i]` is row `rows[i]`'s class).
fn correct_shares(results: &[GroupResult], rows: &[usize], truth: &[usize]) -> Vec<(usize, f64)> {
    let mut right = vec![0usize; rows.len()];
    let mut made = 0usize;
    for r in results {
        for repeat in &r.evaluation.predictions {
            made += 1;
            for (i, &p) in repeat.predicted.iter().enumerate() {
                right[i] += usize::from(p == truth[i]);
            }
        }
    }
    let made = made.max(1) as f64;
    rows.iter()
        .zip(right)
        .map(|(&row, k)| (row, k as f64 / made))
        .collect()
}

/// One outcome from the groups' results: mean accuracy and spread, summed confusion, and
/// per-taxel accuracies with the best when every taxel was evaluated.
fn combine(results: Vec<GroupResult>, labels: Vec<String>, each: Option<&Grid>) -> Outcome {
    let n_groups = results.len() as f64;
    let mut confusion = ConfusionMatrix::zeros(labels.len());
    for r in &results {
        confusion.add(&r.evaluation.confusion);
    }
    let accuracy = results.iter().map(|r| r.evaluation.accuracy).sum::<f64>() / n_groups;
    let accuracy_std = results
        .iter()
        .map(|r| r.evaluation.accuracy_std)
        .sum::<f64>()
        / n_groups;
    let per_taxel: Option<Vec<TaxelAccuracy>> = each.map(|grid| {
        results
            .iter()
            .map(|r| {
                let cell = grid.cell(r.cell.unwrap_or(0));
                TaxelAccuracy {
                    row: cell.row,
                    col: cell.col,
                    accuracy: r.evaluation.accuracy,
                }
            })
            .collect()
    });
    let best = per_taxel.as_deref().and_then(best_taxel);
    Outcome {
        accuracy,
        accuracy_std,
        labels,
        confusion,
        n: results[0].evaluation.n,
        per_taxel,
        best,
        predictions: None,
        correct_shares: Vec::new(),
    }
}

/// The first taxel of the highest accuracy, in grid order (`None` without taxels).
pub fn best_taxel(per: &[TaxelAccuracy]) -> Option<TaxelAccuracy> {
    per.iter()
        .copied()
        .fold(None, |b: Option<TaxelAccuracy>, t| match b {
            Some(b) if b.accuracy >= t.accuracy => Some(b),
            _ => Some(t),
        })
}

/// A classifier applied to its samples: evaluates the recordings `within` (indices into
/// the samples' recordings) under a split whose rows are positions in `within`. A
/// classifier whose fits are long (the spiking network) says [`Progress::Tick`] after
/// each fit to the callback; the others say nothing.
pub type EvaluateFn =
    dyn Fn(&[usize], &Split, &(dyn Fn(Progress) + Sync)) -> Result<Outcome> + Send + Sync;

/// `classifier` on `columns` of `table`'s rows.
pub fn on_table<C: Classifier + Send + 'static>(
    table: Arc<FeatureTable>,
    columns: Columns,
    classifier: C,
) -> Arc<EvaluateFn> {
    Arc::new(move |within, split, _| {
        let whole =
            within.len() == table.metas.len() && within.iter().enumerate().all(|(i, &r)| i == r);
        match whole {
            true => evaluate(&table, columns, split, &classifier),
            false => evaluate(&table.subset(within), columns, split, &classifier),
        }
    })
}

/// `learner` on `samples`, sample `i` being the recording `metas[i]`.
pub fn on_samples<S, L>(metas: Arc<Vec<Meta>>, samples: Arc<S>, learner: L) -> Arc<EvaluateFn>
where
    S: Samples + Send + ?Sized + 'static,
    L: Learner<S> + Send + 'static,
{
    Arc::new(move |within, split, on| {
        let learner = Ticking {
            learner: &learner,
            on,
        };
        let mut each = evaluate_samples(&metas, within, &*samples, split, &learner)?;
        each.pop().ok_or_else(|| {
            ClassifyError::Empty {
                what: "evaluate: no classifier setting",
            }
            .into()
        })
    })
}

/// A learner that says [`Progress::Tick`] after each fit, or as often as it says
/// ([`Learner::ticks`]: each epoch of the spiking network).
struct Ticking<'a, L> {
    learner: &'a L,
    on: &'a (dyn Fn(Progress) + Sync),
}

impl<S: ?Sized, L: Learner<S>> Learner<S> for Ticking<'_, L> {
    type Fitted = L::Fitted;

    fn learn(
        &self,
        samples: &S,
        rows: &[usize],
        y: &[usize],
    ) -> std::result::Result<Self::Fitted, ClassifyError> {
        let ticked = std::sync::atomic::AtomicUsize::new(0);
        let tick = || {
            ticked.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            (self.on)(Progress::Tick);
        };
        let fitted = self.learner.learn_ticking(samples, rows, y, &tick)?;
        // The steps a fit did not take (epochs early stopping left out), as it ends.
        (ticked.into_inner()..self.learner.ticks()).for_each(|_| (self.on)(Progress::Tick));
        Ok(fitted)
    }
}

/// What a method's classifier reads, made once and shared by every fold and candidate.
#[derive(Clone)]
pub enum MethodSamples {
    /// Feature rows, with the columns classified.
    Table(Arc<FeatureTable>, Columns),
    /// Van Rossum distances between every two recordings.
    Distances(Arc<Vec<Meta>>, Arc<DistanceMatrix>),
    /// Every recording's spikes as the spiking network's input.
    Spikes(Arc<Vec<Meta>>, Arc<SpikeSamples>),
}

impl MethodSamples {
    /// The recordings the samples stand for, in sample order.
    pub fn metas(&self) -> &[Meta] {
        match self {
            MethodSamples::Table(table, _) => &table.metas,
            MethodSamples::Distances(metas, _) | MethodSamples::Spikes(metas, _) => metas,
        }
    }

    /// What `method` makes of the recordings `view` under `encoding`: `extractor`'s feature
    /// table with the columns `columns`, the spike inputs at `step_ms` steps, or the van
    /// Rossum distances, computed by `distances` only when asked for.
    ///
    /// # Errors
    /// A feature method the recordings cannot support, or populations an encoding lacks.
    pub fn of(
        (view, encoding, extractor): (&[Encoded], Encoding, &FeatureExtractor),
        method: MethodChoice,
        columns: Columns,
        step_ms: u32,
        distances: impl FnOnce() -> Result<Arc<DistanceMatrix>>,
    ) -> Result<Self> {
        let metas = || Arc::new(view.iter().map(|e| e.meta.clone()).collect::<Vec<_>>());
        Ok(match method {
            MethodChoice::Features(m) => {
                MethodSamples::Table(Arc::new(FeatureTable::build(view, extractor, m)?), columns)
            }
            MethodChoice::VanRossum => MethodSamples::Distances(metas(), distances()?),
            MethodChoice::Spikes => {
                MethodSamples::Spikes(metas(), Arc::new(spike_inputs(view, encoding, step_ms)?))
            }
        })
    }
}

/// `classifier` on `samples`: KNN over a distance matrix, the spiking network over spike
/// inputs, any feature classifier over feature rows.
///
/// # Errors
/// A classifier that does not read these samples, or its broken parameter.
pub fn evaluator(classifier: ClassifierChoice, samples: MethodSamples) -> Result<Arc<EvaluateFn>> {
    Ok(match (samples, classifier) {
        (MethodSamples::Distances(metas, matrix), ClassifierChoice::Knn(p)) => {
            on_samples(metas, matrix, SpikeDistanceKnn::new(p.k)?)
        }
        (MethodSamples::Spikes(metas, inputs), ClassifierChoice::Snn(p)) => {
            on_samples(metas, inputs, SnnClassifier::new(p)?)
        }
        (MethodSamples::Table(table, columns), classifier) => {
            MethodChoice::Features(table.method).check_pairing(&classifier)?;
            on_table(table, columns, classifier.check()?)
        }
        (MethodSamples::Distances(..), other) => {
            return Err(MethodChoice::VanRossum
                .check_pairing(&other)
                .unwrap_err()
                .into())
        }
        (MethodSamples::Spikes(..), other) => {
            return Err(MethodChoice::Spikes
                .check_pairing(&other)
                .unwrap_err()
                .into())
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_taxels_group_holds_its_columns_in_every_population() {
        let grid = Grid::full(2, 2).unwrap();
        let each = column_groups(&grid, 12, Columns::EachTaxel).unwrap();
        assert_eq!(each[1], (Some(1), vec![3, 4, 5]));
        // sa+fa: 12 SA columns, then 12 FA columns.
        let each = column_groups(&grid, 24, Columns::EachTaxel).unwrap();
        assert_eq!(each.len(), 4);
        assert_eq!(each[1], (Some(1), vec![3, 4, 5, 15, 16, 17]));
        let one = column_groups(&grid, 24, Columns::Taxel(Cell { row: 1, col: 1 })).unwrap();
        assert_eq!(one, vec![(Some(3), vec![9, 10, 11, 21, 22, 23])]);
    }
}
