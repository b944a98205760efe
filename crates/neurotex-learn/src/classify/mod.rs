//! Classification: a [`Classifier`] trait (fit, then predict), k-nearest neighbours with
//! training-fold z-scoring, a random forest ([`forest`]) and multinomial logistic
//! regression ([`linear`]) beside it, one [`ClassifierChoice`] over the three, stratified
//! shuffled k-fold cross-validation and train/test evaluation over any classifier, and the
//! [`ConfusionMatrix`] they fill; then what the results mean: [`Metrics`] with chance
//! levels, 95 % intervals for an accuracy, and McNemar's paired test of two methods
//! ([`metrics`], on [`stats`]).

pub mod choice;
pub mod confusion;
pub mod cv;
pub mod draws;
pub mod forest;
pub mod knn;
pub mod linear;
pub mod metrics;
pub mod samples;
pub mod spike_distance;
pub mod spiking;
pub mod stats;

pub use choice::{ChosenClassifier, ChosenModel, ClassifierChoice};
pub use confusion::ConfusionMatrix;
pub use cv::{
    cross_validate, cross_validate_grouped, cross_validate_on, cross_validate_sweep, group_folds,
    stratified_folds, train_test, train_test_on, train_test_sweep, CvParams, Evaluation,
    RepeatPredictions, ValidCv,
};
pub use forest::{Forest, ForestModel, ForestParams};
pub use knn::{Knn, KnnModel, KnnParams, KnnSweep, KnnSweepModel};
pub use linear::{Linear, LinearModel, LinearParams};
pub use metrics::{
    bootstrap_accuracy, bootstrap_mean_share, bootstrap_over_encodings, mcnemar_exact,
    mcnemar_exact_p, t_interval_over_repeats, wilson_at_the_bounds, wilson_interval,
    BootstrapParams, ClassMetrics, Interval, IntervalMethod, Metrics, PairedTest, PairedVerdict,
    Side, ValidBootstrap,
};
pub use samples::{Decide, Learner, Rows, Samples};
pub use spike_distance::{
    van_rossum, van_rossum_squared, DistanceMatrix, SpikeDistanceKnn, SpikeDistanceKnnModel,
    VanRossum, VanRossumParams,
};
pub use spiking::{SnnClassifier, SnnModel, SpikeSamples};
pub use stats::StatsError;

use crate::error::ClassifyError;

/// An unfitted classifier with validated parameters (linfa's `Fit`): fitting stores what
/// prediction needs and checks the training data.
pub trait Classifier: Sync {
    /// The fitted model.
    type Model: Predict;

    /// Fits on `x` (row-major, `dims` features per sample) with class indices `y`.
    ///
    /// # Errors
    /// Training data this classifier cannot use (empty, ragged, non-finite, too small).
    fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<Self::Model, ClassifyError>;
}

/// A classifier that, fitted once, predicts under several settings at once, the way one
/// neighbour search gives KNN's vote for every k ([`knn::KnnSweep`]). Each setting's
/// predictions are those of the classifier fitted with that setting alone, so
/// cross-validating a sweep is cross-validating each setting, with one fit per fold.
/// Every [`Classifier`] is a sweep of one setting.
pub trait Sweep: Sync {
    /// The fitted model.
    type Model: SweepModel;

    /// Fits on `x` (row-major, `dims` features per sample) with class indices `y`.
    ///
    /// # Errors
    /// Training data one of the settings cannot use.
    fn fit_sweep(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<Self::Model, ClassifyError>;
}

/// A fitted [`Sweep`].
pub trait SweepModel {
    /// Each setting's predicted class of each row of `x` (row-major), setting by setting.
    ///
    /// # Panics
    /// If `x` is not whole rows of the training dimension (a caller bug).
    fn predict_sweep(&self, x: &[f64]) -> Vec<Vec<usize>>;
}

impl<C: Classifier> Sweep for C {
    type Model = C::Model;

    fn fit_sweep(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<C::Model, ClassifyError> {
        self.fit(x, dims, y)
    }
}

impl<M: Predict> SweepModel for M {
    fn predict_sweep(&self, x: &[f64]) -> Vec<Vec<usize>> {
        vec![self.predict(x)]
    }
}

/// A fitted classifier (linfa's `Predict`).
pub trait Predict {
    /// The features per sample the model was fitted on.
    fn dims(&self) -> usize;

    /// The predicted class index of each row of `x` (row-major, [`Predict::dims`] per row).
    ///
    /// # Panics
    /// If `x` is not whole rows of the training dimension (a caller bug).
    fn predict(&self, x: &[f64]) -> Vec<usize> {
        let shares = self.predict_with_shares(x);
        shares.into_iter().map(|(c, _)| c).collect()
    }

    /// The classes the shares of [`Predict::predict_with_shares`] cover: the largest class
    /// index seen in training, plus one.
    fn n_classes(&self) -> usize;

    /// The predicted class of each row of `x` with every class's share, indexed by class
    /// ([`Predict::n_classes`] of them, summing to 1): KNN's votes among the `k`
    /// neighbours, the forest's mean of its trees' leaf class distributions, the linear
    /// model's softmax probabilities. The predicted class is the one [`Predict::predict`]
    /// gives; it has the largest share.
    ///
    /// # Panics
    /// If `x` is not whole rows of the training dimension (a caller bug).
    fn predict_with_shares(&self, x: &[f64]) -> Vec<(usize, Vec<f64>)>;
}

/// Checks a training set: not empty, whole rows of `dims` features, all finite, fewer
/// than 2^32 samples (the forest packs sample indices into 32 bits).
///
/// # Errors
/// The first rule broken.
fn check_training(x: &[f64], dims: usize, y: &[usize]) -> Result<(), ClassifyError> {
    let n = y.len();
    if n == 0 || dims == 0 {
        return Err(ClassifyError::Empty { what: "train on" });
    }
    if x.len() != n * dims {
        return Err(ClassifyError::BadFeatures(format!(
            "{} feature values for {n} samples of {dims} features",
            x.len()
        )));
    }
    if u32::try_from(n).is_err() {
        return Err(ClassifyError::BadFeatures(format!(
            "{n} training samples, more than the 2^32 - 1 supported"
        )));
    }
    if let Some(pos) = x.iter().position(|v| !v.is_finite()) {
        return Err(ClassifyError::BadFeatures(format!(
            "feature {} of training sample {} is not finite",
            pos % dims,
            pos / dims
        )));
    }
    Ok(())
}

/// The first class with the largest share (ties go to the lower class index).
pub(crate) fn first_max(shares: &[f64]) -> usize {
    let mut best = 0;
    for (c, &s) in shares.iter().enumerate() {
        if s > shares[best] {
            best = c;
        }
    }
    best
}
