//! Stratified shuffled k-fold cross-validation and train/test evaluation.

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::knn::{Knn, KnnParams};
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
    /// Checks the rules: at least 2 folds and 1 repeat.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
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
        Ok(())
    }
}

/// Accuracy and confusion of one evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Fraction of correct predictions, 0..1.
    pub accuracy: f64,
    /// `n_classes x n_classes` counts, row = true class, column = predicted class.
    pub confusion: Vec<Vec<usize>>,
    /// Samples evaluated.
    pub n: usize,
}

/// Cross-validation over repeats: the first repeat's pooled evaluation and the spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CvResult {
    /// Mean accuracy over repeats.
    pub accuracy: f64,
    /// Population standard deviation of accuracy over repeats (0 for one repeat).
    pub accuracy_std: f64,
    /// Each repeat's accuracy.
    pub per_repeat: Vec<f64>,
    /// Confusion matrix summed over repeats (row = true class).
    pub confusion: Vec<Vec<usize>>,
    /// Samples per repeat.
    pub n: usize,
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

/// Counts `(true, predicted)` pairs into an `n_classes` square matrix.
pub fn confusion_matrix(truth: &[usize], predicted: &[usize], n_classes: usize) -> Vec<Vec<usize>> {
    let mut m = vec![vec![0usize; n_classes]; n_classes];
    for (&t, &p) in truth.iter().zip(predicted) {
        m[t][p] += 1;
    }
    m
}

fn evaluation(truth: &[usize], predicted: &[usize], n_classes: usize) -> Evaluation {
    let correct = truth.iter().zip(predicted).filter(|(a, b)| a == b).count();
    Evaluation {
        accuracy: correct as f64 / truth.len().max(1) as f64,
        confusion: confusion_matrix(truth, predicted, n_classes),
        n: truth.len(),
    }
}

/// Out-of-fold predictions of KNN under a given fold assignment.
///
/// # Errors
/// A fold's training set smaller than `k`, or bad features.
pub fn predict_out_of_fold(
    x: &[f64],
    dims: usize,
    y: &[usize],
    fold_of: &[usize],
    folds: usize,
    knn: KnnParams,
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
        let model = Knn::new(knn).fit(&xtr, dims, &ytr)?;
        for (&i, p) in idx.iter().zip(model.predict(&xte)) {
            predicted[i] = p;
        }
    }
    Ok(predicted)
}

/// Stratified k-fold cross-validation of KNN, repeated with seeds `seed, seed + 1, ...`.
///
/// # Errors
/// Bad parameters, a class smaller than the fold count, `k` larger than a training fold,
/// bad features, or no samples.
pub fn cross_validate(
    x: &[f64],
    dims: usize,
    y: &[usize],
    class_names: &[String],
    knn: KnnParams,
    cv: CvParams,
) -> Result<CvResult, ClassifyError> {
    cv.check()
        .map_err(|e| ClassifyError::BadFeatures(e.to_string()))?;
    if y.is_empty() {
        return Err(ClassifyError::Empty {
            what: "cross-validate",
        });
    }
    let n_classes = class_names.len().max(y.iter().max().map_or(0, |&m| m + 1));
    let mut per_repeat = Vec::with_capacity(cv.repeats);
    let mut confusion = vec![vec![0usize; n_classes]; n_classes];
    for r in 0..cv.repeats {
        let fold_of = stratified_folds(
            y,
            n_classes,
            cv.folds,
            cv.seed.wrapping_add(r as u64),
            class_names,
        )?;
        let predicted = predict_out_of_fold(x, dims, y, &fold_of, cv.folds, knn)?;
        let ev = evaluation(y, &predicted, n_classes);
        for (acc, row) in confusion.iter_mut().zip(&ev.confusion) {
            for (a, &v) in acc.iter_mut().zip(row) {
                *a += v;
            }
        }
        per_repeat.push(ev.accuracy);
    }
    let mean = per_repeat.iter().sum::<f64>() / per_repeat.len() as f64;
    let var = per_repeat.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / per_repeat.len() as f64;
    Ok(CvResult {
        accuracy: mean,
        accuracy_std: var.sqrt(),
        per_repeat,
        confusion,
        n: y.len(),
    })
}

/// Trains on one set and tests on another (for example train on two speeds, test on the third).
///
/// # Errors
/// A test class absent from training, `k` larger than the training set, bad features.
pub fn train_test(
    x_train: &[f64],
    y_train: &[usize],
    x_test: &[f64],
    y_test: &[usize],
    dims: usize,
    class_names: &[String],
    knn: KnnParams,
) -> Result<Evaluation, ClassifyError> {
    if y_test.is_empty() {
        return Err(ClassifyError::Empty { what: "test" });
    }
    if let Some(&c) = y_test.iter().find(|c| !y_train.contains(c)) {
        return Err(ClassifyError::UnknownTestLabel {
            label: class_names.get(c).cloned().unwrap_or_else(|| c.to_string()),
        });
    }
    let model = Knn::new(knn).fit(x_train, dims, y_train)?;
    if x_test.len() != y_test.len() * dims || x_test.iter().any(|v| !v.is_finite()) {
        return Err(ClassifyError::BadFeatures(
            "test features are ragged or not finite".into(),
        ));
    }
    let predicted = model.predict(x_test);
    let n_classes = class_names
        .len()
        .max(1 + *y_train.iter().chain(y_test).max().unwrap_or(&0));
    Ok(evaluation(y_test, &predicted, n_classes))
}
