//! Classification (SPEC 3.12-3.13): a [`Classifier`] trait (fit, then predict), k-nearest
//! neighbours with training-fold z-scoring, stratified shuffled k-fold cross-validation and
//! train/test evaluation over any classifier, and the [`ConfusionMatrix`] they fill; then
//! what the results mean (SPEC 9): [`Metrics`] with chance levels, 95 % intervals for an
//! accuracy, and McNemar's paired test of two methods ([`metrics`], on [`stats`]).

pub mod confusion;
pub mod cv;
pub mod knn;
pub mod metrics;
pub mod spike_distance;
pub mod stats;

pub use confusion::ConfusionMatrix;
pub use cv::{
    cross_validate, cross_validate_grouped, group_folds, stratified_folds, train_test, CvParams,
    Evaluation, RepeatPredictions, ValidCv,
};
pub use knn::{Knn, KnnModel, KnnParams};
pub use metrics::{
    bootstrap_accuracy, bootstrap_mean_share, mcnemar_exact, mcnemar_exact_p,
    t_interval_over_repeats, wilson_interval, BootstrapParams, ClassMetrics, Interval,
    IntervalMethod, Metrics, PairedTest, PairedVerdict, Side, ValidBootstrap,
};
pub use spike_distance::{
    van_rossum, van_rossum_squared, DistanceMatrix, SpikeDistanceKnn, SpikeDistanceKnnModel,
    VanRossum, VanRossumParams,
};
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

/// A fitted classifier (linfa's `Predict`).
pub trait Predict {
    /// The features per sample the model was fitted on.
    fn dims(&self) -> usize;

    /// The predicted class index of each row of `x` (row-major, [`Predict::dims`] per row).
    ///
    /// # Panics
    /// If `x` is not whole rows of the training dimension (a caller bug).
    fn predict(&self, x: &[f64]) -> Vec<usize>;
}
