//! Saved models (docs/models-and-streaming.md): a classifier trained on one dataset, with
//! everything needed to apply it to new recordings, in one self-describing, versioned JSON
//! file: the validated pipeline, the feature method and columns, the taxel grid, the
//! classifier's parameters and training set, the class labels, and the training data's
//! fingerprint.
//!
//! The fitted classifier (KNN, random forest or logistic regression, a [`ClassifierChoice`]
//! tagged by `kind`) is kept in the file as its parameters and its training feature rows
//! and labels, and re-fitted on load, rather than as the fitted model's internal state
//! (KNN's z-scored columns and visiting stride, the forest's trees, the regression's
//! weights). Fitting is deterministic (the forest's seed is among its parameters, and its
//! result does not depend on the number of threads), so the re-fitted model predicts
//! exactly what the saved one did; the raw rows mean the same to any reader (Python fits
//! scikit-learn's classifiers on them), stay valid when the fast layout changes, and pass
//! through every check of [`Classifier::fit`] when a file is loaded, where stored internals
//! could hold a stride or a scale that no fit would produce. Files written before the
//! forest and the regression existed (`"kind": "knn"`) read unchanged.

use serde::{Deserialize, Serialize};

use crate::classify::{ChosenModel, ClassifierChoice, ConfusionMatrix, Interval};
use crate::error::Result;
pub use crate::error::{ModelError, MODEL_FORMAT as FORMAT, MODEL_VERSION as VERSION};
use crate::pipeline::{FeatureExtractor, Method, Pipeline, PipelineParams};
use crate::recording::{Baseline, Dataset, LayoutFile};
use crate::values::{Cell, Grid, Speed};

mod file;
mod predict;
#[cfg(test)]
mod tests;

pub use file::check_header;
pub(crate) use file::{check_trained, invalid, unreadable};
pub use predict::write_predictions;
pub(crate) use predict::{check_source, encode_files, score};

/// The gain `--gain auto` chose and what it rests on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GainCalibration {
    /// The target median rate, Hz.
    pub target_hz: f64,
    /// The chosen gain.
    pub gain: f64,
    /// The median rate at the chosen gain, Hz.
    pub median_hz: f64,
    /// Training recordings used.
    pub recordings: usize,
    /// (taxel, recording) pairs with any signal, over which the median runs.
    pub pairs: usize,
    /// Whether the target was out of reach within the searched gains (the gain is then
    /// the range's end).
    pub clamped: bool,
}

/// Which features a model classifies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureSpec {
    /// The feature set.
    pub method: Method,
    /// For [`Method::Taxel`], the one taxel whose statistics are used; `None` for all of
    /// the method's columns (every taxel's three statistics together).
    pub taxel: Option<Cell>,
    /// The column names, in order.
    pub columns: Vec<String>,
}

/// Where a model's training data came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// [`Dataset::fingerprint`] of the training dataset.
    pub fingerprint: String,
    /// The dataset's baseline from `layout.toml` (`none` when it gives none): the baseline
    /// the recordings were conditioned with unless the pipeline set its own.
    pub baseline: Baseline,
    /// The speeds trained on; `None` for all of the dataset's.
    pub speeds: Option<Vec<Speed>>,
    /// How `--gain auto` chose the pipeline's gain on the training recordings; `None` for a
    /// gain given as a number.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gain_calibration: Option<GainCalibration>,
    /// For a causal model: the median length of the training recordings' selected phases,
    /// ms (a stream's default window).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub median_duration_ms: Option<usize>,
    /// How the training dataset's recordings were read (its `layout.toml`: rate, grid,
    /// channel map, CSV columns, and the raw logs' columns an import keeps): recording
    /// files given later without a layout of their own are read the same way. `None` for
    /// a model trained on arrays, or written before models kept it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layout: Option<LayoutFile>,
}

impl Provenance {
    /// The provenance of training on `dataset` at `speeds` (all when `None`).
    ///
    /// # Errors
    /// The manifest or a listed file can no longer be read.
    pub fn of(dataset: &Dataset, speeds: Option<Vec<Speed>>) -> Result<Self> {
        Ok(Provenance {
            fingerprint: dataset.fingerprint()?,
            baseline: dataset.layout.baseline.unwrap_or_default(),
            speeds,
            gain_calibration: None,
            median_duration_ms: None,
            layout: Some(dataset.layout.clone()),
        })
    }
}

/// The training set as stored: one feature row and one label per training recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct TrainingSet {
    dataset: Provenance,
    labels: Vec<String>,
    rows: Vec<Vec<f64>>,
}

/// The file's form. Fields are written in this order, so the file reads from what it is
/// to how it was made, with the long training rows last.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct ModelFile {
    format: String,
    version: u64,
    neurotex_version: String,
    pipeline: PipelineParams,
    features: FeatureSpec,
    grid: Grid,
    classifier: ClassifierChoice,
    labels: Vec<String>,
    training: TrainingSet,
}

/// The two fields read before the rest, so that a file of another format or version is
/// named as such rather than as damaged.
#[derive(Deserialize)]
struct Header {
    format: Option<serde_json::Value>,
    version: Option<serde_json::Value>,
}

/// One recording's prediction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// The predicted class.
    pub predicted: String,
    /// Each class's share, in the order of [`Model::labels`], summing to 1: its votes
    /// among KNN's `k` neighbours, its mean leaf share over the forest's trees, or the
    /// logistic regression's probability (see [`Predict::predict_with_shares`]).
    pub shares: Vec<f64>,
}

/// Predictions scored against known labels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// Share of recordings predicted right, 0..1.
    pub accuracy: f64,
    /// The accuracy's 95 % interval: Wilson's score interval over the recordings, each
    /// one prediction of a fixed model.
    pub interval: Interval,
    /// Chance: one over the classes among the recordings scored.
    pub chance: f64,
    /// Recordings scored.
    pub n: usize,
    /// The model's classes, in confusion-matrix order.
    pub labels: Vec<String>,
    /// Row = true label, column = predicted label.
    pub confusion: ConfusionMatrix,
    /// Of the recordings scored, those the model was trained on (its training dataset's,
    /// at its training speeds): their predictions test nothing, and the accuracy is no
    /// test of the model unless this is 0. Set by the caller that knows the dataset; 0
    /// from [`Model::score`].
    #[serde(default)]
    pub trained_on: usize,
}

impl Score {
    /// One line for a terminal: `accuracy 75.0% [57.9, 86.7] over 32 recordings (95 %
    /// Wilson interval); chance 12.5%`, and how many of them the model was trained on.
    pub fn summary(&self) -> String {
        let mut line = format!(
            "accuracy {:.1}% [{:.1}, {:.1}] over {} (95 % Wilson interval); chance {:.1}%",
            100.0 * self.accuracy,
            100.0 * self.interval.lower,
            100.0 * self.interval.upper,
            neurotex_core::words::counted(self.n, "recording"),
            100.0 * self.chance
        );
        if self.trained_on > 0 {
            line += &format!(
                "; {} of them the model was trained on, so this is no test of it",
                self.trained_on
            );
        }
        line
    }
}

/// A trained model: what its file holds, with the pipeline, the feature extractor and the
/// classifier made ready from it.
#[derive(Debug, Clone)]
pub struct Model {
    file: ModelFile,
    pipeline: Pipeline,
    extractor: FeatureExtractor,
    columns: Vec<usize>,
    classifier: ChosenModel,
}

impl PartialEq for Model {
    /// Models are equal when their files are: everything else is made from the file.
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file
    }
}
