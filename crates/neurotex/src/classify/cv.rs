//! Stratified shuffled k-fold cross-validation and train/test evaluation, over any
//! [`Classifier`].

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::{Classifier, ConfusionMatrix, Predict};
use crate::error::{ClassifyError, ParamError};

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
    /// Checks the rules (at least 2 folds and 1 repeat) and returns the validated form
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
    /// back to recordings (SPEC 9).
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
    let mut predicted = vec![0usize; y.len()];
    let (mut xtr, mut ytr, mut xte, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for fold in 0..folds {
        xtr.clear();
        ytr.clear();
        xte.clear();
        idx.clear();
        for (i, &f) in fold_of.iter().enumerate() {
            let row = &x[i * dims..(i + 1) * dims];
            if f == fold {
                xte.extend_from_slice(row);
                idx.push(i);
            } else {
                xtr.extend_from_slice(row);
                ytr.push(y[i]);
            }
        }
        if idx.is_empty() {
            continue;
        }
        let model = classifier.fit(&xtr, dims, &ytr)?;
        for (&i, p) in idx.iter().zip(model.predict(&xte)) {
            predicted[i] = p;
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
    if y.is_empty() {
        return Err(ClassifyError::Empty {
            what: "cross-validate",
        });
    }
    let n_classes = class_names.len().max(y.iter().max().map_or(0, |&m| m + 1));
    let mut per_repeat = Vec::with_capacity(cv.repeats);
    let mut predictions = Vec::with_capacity(cv.repeats);
    let mut confusion = ConfusionMatrix::zeros(n_classes);
    for r in 0..cv.repeats {
        let seed = cv.seed.wrapping_add(r as u64);
        let fold_of = stratified_folds(y, n_classes, cv.folds, seed, class_names)?;
        let predicted = predict_out_of_fold(classifier, x, dims, y, &fold_of, cv.folds)?;
        let matrix = ConfusionMatrix::from_predictions(y, &predicted, n_classes);
        per_repeat.push(matrix.accuracy());
        confusion.add(&matrix);
        predictions.push(RepeatPredictions {
            fold_of: Some(fold_of),
            predicted,
        });
    }
    Ok(Evaluation::of_repeats(
        per_repeat,
        confusion,
        y.len(),
        predictions,
    ))
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
    let ((x_train, y_train), (x_test, y_test)) = (train, test);
    if y_test.is_empty() {
        return Err(ClassifyError::Empty { what: "test" });
    }
    if let Some(&c) = y_test.iter().find(|c| !y_train.contains(c)) {
        return Err(ClassifyError::UnknownTestLabel {
            label: class_names.get(c).cloned().unwrap_or_else(|| c.to_string()),
        });
    }
    let model = classifier.fit(x_train, dims, y_train)?;
    if x_test.len() != y_test.len() * dims || x_test.iter().any(|v| !v.is_finite()) {
        return Err(ClassifyError::BadFeatures(
            "test features are ragged or not finite".into(),
        ));
    }
    let predicted = model.predict(x_test);
    let n_classes = class_names
        .len()
        .max(1 + *y_train.iter().chain(y_test).max().unwrap_or(&0));
    let confusion = ConfusionMatrix::from_predictions(y_test, &predicted, n_classes);
    Ok(Evaluation::of_repeats(
        vec![confusion.accuracy()],
        confusion,
        y_test.len(),
        vec![RepeatPredictions {
            fold_of: None,
            predicted,
        }],
    ))
}
