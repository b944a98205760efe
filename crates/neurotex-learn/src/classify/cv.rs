//! Stratified shuffled k-fold cross-validation and train/test evaluation, over any
//! [`Classifier`].

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::samples::{Decide, Learner, Rows, Samples};
use super::{Classifier, ConfusionMatrix, Sweep};
use crate::error::{ClassifyError, ParamError};

/// Largest number of repeats (CV shuffles, E3 draws) accepted; beyond it a run would take
/// days on the paper's design, so a larger value is a typo (and `usize::MAX` repeats would
/// ask for a result vector no memory holds).
pub const MAX_REPEATS: usize = 10_000;

/// Cross-validation parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CvParams {
    /// Folds (the paper's 5).
    pub folds: usize,
    /// Seed of the first repeat's shuffle; repeat `r` uses `seed + r`.
    pub seed: u64,
    /// Repeats with different shuffles.
    pub repeats: usize,
}

impl Default for CvParams {
    fn default() -> Self {
        CvParams {
            folds: 5,
            seed: 0,
            repeats: 1,
        }
    }
}

impl CvParams {
    /// Checks the rules (at least 2 folds, 1 to [`MAX_REPEATS`] repeats) and returns the validated form
    /// that cross-validation takes.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(self) -> Result<ValidCv, ParamError> {
        if self.folds < 2 {
            return Err(ParamError::new(
                "folds",
                "cross-validation needs at least 2 folds",
                self.folds,
            ));
        }
        if self.repeats == 0 {
            return Err(ParamError::new(
                "repeats",
                "repeats must be at least 1",
                self.repeats,
            ));
        }
        if self.repeats > MAX_REPEATS {
            return Err(ParamError::new(
                "repeats",
                "repeats must be at most 10000",
                self.repeats,
            ));
        }
        Ok(ValidCv(self))
    }
}

/// Cross-validation parameters that passed [`CvParams::check`] (the default is the
/// default parameters, which pass).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ValidCv(CvParams);

impl std::ops::Deref for ValidCv {
    type Target = CvParams;
    fn deref(&self) -> &CvParams {
        &self.0
    }
}

/// Accuracy and confusion of an evaluation: one train/test split, or cross-validation over
/// repeats (mean and spread over repeats, confusion summed over them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Mean accuracy over repeats, 0..1.
    pub accuracy: f64,
    /// Population standard deviation of accuracy over repeats (0 for one).
    pub accuracy_std: f64,
    /// Each repeat's accuracy (one entry for a train/test split).
    pub per_repeat: Vec<f64>,
    /// Row = true class; summed over repeats.
    pub confusion: ConfusionMatrix,
    /// Samples evaluated per repeat.
    pub n: usize,
    /// Each repeat's prediction of every evaluated sample, so that results can be traced
    /// back to recordings.
    pub predictions: Vec<RepeatPredictions>,
}

/// One repeat's out-of-fold predictions: for every evaluated sample, in sample order, its
/// predicted class and the fold it was tested in.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RepeatPredictions {
    /// Each sample's fold; `None` for a train/test split, where every sample is tested once.
    pub fold_of: Option<Vec<usize>>,
    /// Each sample's predicted class index.
    pub predicted: Vec<usize>,
}

impl Evaluation {
    fn of_repeats(
        per_repeat: Vec<f64>,
        confusion: ConfusionMatrix,
        n: usize,
        predictions: Vec<RepeatPredictions>,
    ) -> Self {
        let mean = per_repeat.iter().sum::<f64>() / per_repeat.len().max(1) as f64;
        let var = per_repeat.iter().map(|a| (a - mean).powi(2)).sum::<f64>()
            / per_repeat.len().max(1) as f64;
        Evaluation {
            accuracy: mean,
            accuracy_std: var.sqrt(),
            per_repeat,
            confusion,
            n,
            predictions,
        }
    }
}

/// [`ClassifyError::OneClass`] when every one of `y` (not empty) is of one class.
fn two_classes(
    y: &[usize],
    class_names: &[String],
    what: &'static str,
) -> Result<(), ClassifyError> {
    match y.split_first() {
        Some((&first, rest)) if rest.iter().all(|&c| c == first) => Err(ClassifyError::OneClass {
            label: class_names
                .get(first)
                .cloned()
                .unwrap_or_else(|| first.to_string()),
            what,
        }),
        _ => Ok(()),
    }
}

/// Assigns each sample a fold so every class is spread evenly: the samples of each class are
/// shuffled with a ChaCha8 generator seeded by `seed`, then dealt to the folds in turn,
/// continuing from the fold where the previous class stopped (so fold sizes differ by at most 1).
///
/// # Errors
/// A class with fewer samples than folds (named by its index in `class_names`).
pub fn stratified_folds(
    y: &[usize],
    n_classes: usize,
    folds: usize,
    seed: u64,
    class_names: &[String],
) -> Result<Vec<usize>, ClassifyError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut fold_of = vec![0usize; y.len()];
    let mut next = 0usize;
    for class in 0..n_classes {
        let mut members: Vec<usize> = (0..y.len()).filter(|&i| y[i] == class).collect();
        if members.is_empty() {
            continue;
        }
        if members.len() < folds {
            return Err(ClassifyError::ClassTooSmall {
                label: class_names
                    .get(class)
                    .cloned()
                    .unwrap_or_else(|| class.to_string()),
                count: members.len(),
                folds,
            });
        }
        members.shuffle(&mut rng);
        for i in members {
            fold_of[i] = next;
            next = (next + 1) % folds;
        }
    }
    Ok(fold_of)
}

/// Out-of-fold predictions of `classifier` under a given fold assignment.
///
/// # Errors
/// A fold's training set the classifier cannot fit.
pub fn predict_out_of_fold<C: Classifier>(
    classifier: &C,
    x: &[f64],
    dims: usize,
    y: &[usize],
    fold_of: &[usize],
    folds: usize,
) -> Result<Vec<usize>, ClassifyError> {
    let rows = rows_of(x, dims, y.len())?;
    let all: Vec<usize> = (0..y.len()).collect();
    let mut each = out_of_fold(classifier, &rows, (&all, y), fold_of, folds)?;
    // No fold tested anything (fold numbers past `folds`): every prediction stays 0.
    Ok(each.pop().unwrap_or_else(|| vec![0; y.len()]))
}

/// `x` as feature rows of `n` samples.
///
/// # Errors
/// Values that are not `n` rows of `dims` features.
fn rows_of(x: &[f64], dims: usize, n: usize) -> Result<Rows<'_>, ClassifyError> {
    if x.len() != n * dims {
        return Err(ClassifyError::BadFeatures(format!(
            "{} feature values for {n} samples of {dims} features",
            x.len()
        )));
    }
    Ok(Rows { values: x, dims })
}

/// Out-of-fold predictions of every setting of `learner` under a given fold assignment of
/// the samples `rows` (classes `y`), one fit per fold.
fn out_of_fold<S: Samples + ?Sized, L: Learner<S>>(
    learner: &L,
    samples: &S,
    (rows, y): (&[usize], &[usize]),
    fold_of: &[usize],
    folds: usize,
) -> Result<Vec<Vec<usize>>, ClassifyError> {
    let mut predicted: Vec<Vec<usize>> = Vec::new();
    let (mut train, mut ytr, mut test, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for fold in 0..folds {
        neurotex_core::progress::stop_point();
        train.clear();
        ytr.clear();
        test.clear();
        idx.clear();
        for (i, &f) in fold_of.iter().enumerate() {
            if f == fold {
                test.push(rows[i]);
                idx.push(i);
            } else {
                train.push(rows[i]);
                ytr.push(y[i]);
            }
        }
        if idx.is_empty() {
            continue;
        }
        let model = learner.learn(samples, &train, &ytr)?;
        for (s, setting) in model.decide(samples, &test)?.into_iter().enumerate() {
            if s == predicted.len() {
                predicted.push(vec![0usize; y.len()]);
            }
            for (&i, p) in idx.iter().zip(setting) {
                predicted[s][i] = p;
            }
        }
    }
    Ok(predicted)
}

/// Stratified k-fold cross-validation of `classifier`, repeated with seeds `seed, seed + 1,
/// ...`; accuracy over the pooled out-of-fold predictions of each repeat.
///
/// # Errors
/// No samples, a class smaller than the fold count, or a training fold the classifier
/// cannot fit.
pub fn cross_validate<C: Classifier>(
    classifier: &C,
    x: &[f64],
    dims: usize,
    y: &[usize],
    class_names: &[String],
    cv: ValidCv,
) -> Result<Evaluation, ClassifyError> {
    single(cross_validate_sweep(
        classifier,
        (x, dims),
        y,
        class_names,
        cv,
        None,
    ))
}

/// Cross-validation whose folds never split a group: `groups[i]` is sample `i`'s group
/// (a session, a subject, the repeats of one run). Groups are shuffled with each repeat's
/// seed and dealt, largest first, to the fold holding fewest samples; with fewer groups
/// than folds, each group is a fold of its own (leave one group out). Folds are not
/// stratified: keeping a group whole comes first.
///
/// # Errors
/// As [`cross_validate`], and `groups` of another length than `y`.
pub fn cross_validate_grouped<C: Classifier>(
    classifier: &C,
    x: &[f64],
    dims: usize,
    y: &[usize],
    class_names: &[String],
    cv: ValidCv,
    groups: &[usize],
) -> Result<Evaluation, ClassifyError> {
    single(cross_validate_sweep(
        classifier,
        (x, dims),
        y,
        class_names,
        cv,
        Some(groups),
    ))
}

/// The one evaluation of a classifier's sweep.
fn single(each: Result<Vec<Evaluation>, ClassifyError>) -> Result<Evaluation, ClassifyError> {
    let mut each = each?;
    each.pop().ok_or(ClassifyError::Empty {
        what: "evaluate: no classifier setting",
    })
}

/// Refuses folds (`fold_of` each sample's, of `folds`) in which every sample of a class
/// (of `y`) lies in one fold: that fold's model never trains on the class.
fn every_class_trained(
    y: &[usize],
    fold_of: &[usize],
    folds: usize,
    class_names: &[String],
) -> Result<(), ClassifyError> {
    let n_classes = y.iter().max().map_or(0, |&m| m + 1);
    // Per class, the folds its samples lie in, as a count of samples per fold.
    let mut in_fold = vec![vec![0usize; folds]; n_classes];
    for (&c, &f) in y.iter().zip(fold_of) {
        in_fold[c][f] += 1;
    }
    let whole = (0..n_classes).find(|&c| in_fold[c].iter().filter(|&&n| n > 0).count() == 1);
    match whole {
        Some(c) if folds > 1 => Err(ClassifyError::GroupsHoldAClass {
            label: class_names.get(c).cloned().unwrap_or_else(|| c.to_string()),
        }),
        _ => Ok(()),
    }
}

/// Assigns each sample a fold so that no group is split (see [`cross_validate_grouped`]);
/// returns the fold of each sample and the number of folds used.
pub fn group_folds(groups: &[usize], folds: usize, seed: u64) -> (Vec<usize>, usize) {
    let n_groups = groups.iter().max().map_or(0, |&g| g + 1);
    let mut size = vec![0usize; n_groups];
    for &g in groups {
        size[g] += 1;
    }
    let mut order: Vec<usize> = (0..n_groups).filter(|&g| size[g] > 0).collect();
    let folds = folds.min(order.len()).max(1);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    order.shuffle(&mut rng);
    // A stable sort keeps the shuffled order among groups of one size.
    order.sort_by(|a, b| size[*b].cmp(&size[*a]));
    let (mut fold_of_group, mut load) = (vec![0usize; n_groups], vec![0usize; folds]);
    for g in order {
        let fold = (0..folds).min_by_key(|&f| (load[f], f)).unwrap_or(0);
        fold_of_group[g] = fold;
        load[fold] += size[g];
    }
    (groups.iter().map(|&g| fold_of_group[g]).collect(), folds)
}

/// [`cross_validate`] of every setting of `sweep` (one evaluation each, in its order),
/// grouped by `groups` as [`cross_validate_grouped`] when given; each fold is fitted once.
///
/// # Errors
/// As [`cross_validate_grouped`].
pub fn cross_validate_sweep<C: Sweep>(
    sweep: &C,
    (x, dims): (&[f64], usize),
    y: &[usize],
    class_names: &[String],
    cv: ValidCv,
    groups: Option<&[usize]>,
) -> Result<Vec<Evaluation>, ClassifyError> {
    let samples = rows_of(x, dims, y.len())?;
    let all: Vec<usize> = (0..y.len()).collect();
    cross_validate_on(sweep, &samples, (&all, y), class_names, cv, groups)
}

/// Cross-validation of every setting of `learner` over the samples `rows` of `samples`
/// (classes `y`, one per row), grouped by `groups` (one per row) as
/// [`cross_validate_grouped`] when given; each fold is fitted once. The evaluations' sample
/// order is that of `rows`.
///
/// # Errors
/// As [`cross_validate_grouped`].
pub fn cross_validate_on<S: Samples + ?Sized, L: Learner<S>>(
    learner: &L,
    samples: &S,
    (rows, y): (&[usize], &[usize]),
    class_names: &[String],
    cv: ValidCv,
    groups: Option<&[usize]>,
) -> Result<Vec<Evaluation>, ClassifyError> {
    if let Some(groups) = groups.filter(|g| g.len() != y.len()) {
        let message = format!("{} groups for {} samples", groups.len(), y.len());
        return Err(ClassifyError::BadFeatures(message));
    }
    if rows.len() != y.len() {
        let message = format!("{} samples for {} classes", rows.len(), y.len());
        return Err(ClassifyError::BadFeatures(message));
    }
    if y.is_empty() {
        return Err(ClassifyError::Empty {
            what: "cross-validate",
        });
    }
    two_classes(y, class_names, "cross-validate")?;
    let n_classes = class_names.len().max(y.iter().max().map_or(0, |&m| m + 1));
    let mut settings: Vec<Repeats> = Vec::new();
    for r in 0..cv.repeats {
        let seed = cv.seed.wrapping_add(r as u64);
        let (fold_of, folds) = match groups {
            Some(groups) => {
                let (fold_of, folds) = group_folds(groups, cv.folds, seed);
                every_class_trained(y, &fold_of, folds, class_names)?;
                (fold_of, folds)
            }
            None => (
                stratified_folds(y, n_classes, cv.folds, seed, class_names)?,
                cv.folds,
            ),
        };
        let each = out_of_fold(learner, samples, (rows, y), &fold_of, folds)
            .map_err(|e| e.with_class_names(class_names))?;
        for (s, predicted) in each.into_iter().enumerate() {
            if s == settings.len() {
                settings.push(Repeats::new(n_classes, cv.repeats));
            }
            settings[s].add(y, predicted, Some(fold_of.clone()));
        }
    }
    Ok(settings.into_iter().map(|r| r.finish(y.len())).collect())
}

/// One setting's repeats as they are made: accuracy, summed confusion, predictions.
struct Repeats {
    per_repeat: Vec<f64>,
    confusion: ConfusionMatrix,
    predictions: Vec<RepeatPredictions>,
}

impl Repeats {
    fn new(n_classes: usize, repeats: usize) -> Self {
        Repeats {
            per_repeat: Vec::with_capacity(repeats),
            confusion: ConfusionMatrix::zeros(n_classes),
            predictions: Vec::with_capacity(repeats),
        }
    }

    /// One repeat's predictions of the samples whose classes are `y`.
    fn add(&mut self, y: &[usize], predicted: Vec<usize>, fold_of: Option<Vec<usize>>) {
        let n_classes = self.confusion.n_classes();
        let matrix = ConfusionMatrix::from_predictions(y, &predicted, n_classes);
        self.per_repeat.push(matrix.accuracy());
        self.confusion.add(&matrix);
        self.predictions
            .push(RepeatPredictions { fold_of, predicted });
    }

    /// The evaluation of `n` samples per repeat.
    fn finish(self, n: usize) -> Evaluation {
        Evaluation::of_repeats(self.per_repeat, self.confusion, n, self.predictions)
    }
}

/// Trains on one set and tests on another (for example train on two speeds, test on the third).
///
/// # Errors
/// No test samples, a test class absent from training, ragged or non-finite test features,
/// or a training set the classifier cannot fit.
pub fn train_test<C: Classifier>(
    classifier: &C,
    train: (&[f64], &[usize]),
    test: (&[f64], &[usize]),
    dims: usize,
    class_names: &[String],
) -> Result<Evaluation, ClassifyError> {
    single(train_test_sweep(classifier, train, test, dims, class_names))
}

/// [`train_test`] of every setting of `sweep` (one evaluation each, in its order), fitted
/// once.
///
/// # Errors
/// As [`train_test`].
pub fn train_test_sweep<C: Sweep>(
    sweep: &C,
    train: (&[f64], &[usize]),
    test: (&[f64], &[usize]),
    dims: usize,
    class_names: &[String],
) -> Result<Vec<Evaluation>, ClassifyError> {
    let ((x_train, y_train), (x_test, y_test)) = (train, test);
    if x_test.len() != y_test.len() * dims {
        let message = "test features are ragged or not finite";
        return Err(ClassifyError::BadFeatures(message.into()));
    }
    rows_of(x_train, dims, y_train.len())?;
    let values = [x_train, x_test].concat();
    let samples = Rows {
        values: &values,
        dims,
    };
    let n = y_train.len();
    let (train_rows, test_rows): (Vec<usize>, Vec<usize>) =
        ((0..n).collect(), (n..n + y_test.len()).collect());
    let (train, test) = ((&train_rows[..], y_train), (&test_rows[..], y_test));
    train_test_on(sweep, &samples, train, test, class_names)
}

/// [`train_test`] of every setting of `learner` (one evaluation each, in its order),
/// fitted once on the samples `train.0` (classes `train.1`) of `samples` and tested on
/// the samples `test.0` (classes `test.1`).
///
/// # Errors
/// As [`train_test`].
pub fn train_test_on<S: Samples + ?Sized, L: Learner<S>>(
    learner: &L,
    samples: &S,
    (train_rows, y_train): (&[usize], &[usize]),
    (test_rows, y_test): (&[usize], &[usize]),
    class_names: &[String],
) -> Result<Vec<Evaluation>, ClassifyError> {
    if y_test.is_empty() {
        return Err(ClassifyError::Empty { what: "test" });
    }
    two_classes(y_train, class_names, "train on")?;
    if let Some(&c) = y_test.iter().find(|c| !y_train.contains(c)) {
        return Err(ClassifyError::UnknownTestLabel {
            label: class_names.get(c).cloned().unwrap_or_else(|| c.to_string()),
        });
    }
    let model = learner
        .learn(samples, train_rows, y_train)
        .map_err(|e| e.with_class_names(class_names))?;
    samples.check_test(test_rows)?;
    let n_classes = class_names
        .len()
        .max(1 + *y_train.iter().chain(y_test).max().unwrap_or(&0));
    Ok(model
        .decide(samples, test_rows)?
        .into_iter()
        .map(|predicted| {
            let mut one = Repeats::new(n_classes, 1);
            one.add(y_test, predicted, None);
            one.finish(y_test.len())
        })
        .collect())
}

#[cfg(test)]
mod group_tests {
    use super::*;

    #[test]
    fn repeats_are_bounded_so_a_huge_count_is_an_error_not_a_panic() {
        let cv = |repeats| CvParams {
            repeats,
            ..CvParams::default()
        };
        assert!(cv(MAX_REPEATS).check().is_ok());
        for repeats in [0, MAX_REPEATS + 1, usize::MAX] {
            let err = cv(repeats).check().unwrap_err();
            assert_eq!(err.name, "repeats");
        }
    }

    #[test]
    fn one_class_is_an_error_not_a_perfect_score() {
        let knn = super::super::KnnParams {
            k: 1,
            standardize: false,
        }
        .check()
        .unwrap();
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        let y = vec![0usize; 10];
        let names = vec!["only".to_string()];
        let cv = CvParams::default().check().unwrap();
        let err = cross_validate(&knn, &x, 1, &y, &names, cv).unwrap_err();
        assert!(
            matches!(&err, ClassifyError::OneClass { label, .. } if label == "only"),
            "{err}"
        );
        let err = cross_validate_grouped(&knn, &x, 1, &y, &names, cv, &[0; 10]).unwrap_err();
        assert!(matches!(err, ClassifyError::OneClass { .. }), "{err}");
        let err = train_test(&knn, (&x[..5], &y[..5]), (&x[5..], &y[5..]), 1, &names);
        assert!(matches!(err, Err(ClassifyError::OneClass { .. })));
    }

    #[test]
    fn groups_that_each_hold_one_class_are_refused() {
        let knn = super::super::KnnParams {
            k: 1,
            standardize: false,
        }
        .check()
        .unwrap();
        let x: Vec<f64> = (0..12).map(f64::from).collect();
        let y: Vec<usize> = (0..12).map(|i| i % 3).collect();
        let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
        let cv = CvParams::default().check().unwrap();
        // Grouped by the class itself: each fold's test class is never trained on.
        let err = cross_validate_grouped(&knn, &x, 1, &y, &names, cv, &y).unwrap_err();
        assert!(
            matches!(&err, ClassifyError::GroupsHoldAClass { label } if label == "a" || label == "b" || label == "c"),
            "{err}"
        );
        assert!(err
            .to_string()
            .contains("group by a column whose groups each hold recordings of several classes"));
        // Groups of every class (trials): allowed.
        let trials: Vec<usize> = (0..12).map(|i| i / 3).collect();
        assert!(cross_validate_grouped(&knn, &x, 1, &y, &names, cv, &trials).is_ok());
    }

    #[test]
    fn no_group_is_split_and_few_groups_are_held_out_one_by_one() {
        // 7 groups of uneven size over 30 samples, into 5 folds
        let groups: Vec<usize> = (0..30).map(|i| (i * 7 / 30 + i % 2) % 7).collect();
        for seed in 0..20 {
            let (fold_of, folds) = group_folds(&groups, 5, seed);
            assert_eq!(folds, 5);
            for g in 0..7 {
                let mut of_group = (0..30).filter(|&i| groups[i] == g).map(|i| fold_of[i]);
                let first = of_group.next().unwrap();
                assert!(
                    of_group.all(|f| f == first),
                    "group {g} split (seed {seed})"
                );
            }
            assert!((0..5).all(|f| fold_of.contains(&f)), "an empty fold");
        }
        // three groups, five folds asked: leave one group out
        let (fold_of, folds) = group_folds(&[0, 0, 1, 1, 2, 2], 5, 0);
        assert_eq!(folds, 3);
        let mut distinct = fold_of.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct, [0, 1, 2]);
    }
}
