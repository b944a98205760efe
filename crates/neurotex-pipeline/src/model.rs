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

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::analysis::{column_groups, Columns, FeatureTable};
use crate::classify::{ChosenModel, Classifier, ClassifierChoice, ConfusionMatrix, Predict};
use crate::error::{ClassifyError, DataError, ParamError, Result};
pub use crate::error::{ModelError, MODEL_FORMAT as FORMAT, MODEL_VERSION as VERSION};
use crate::pipeline::{Encoded, FeatureExtractor, Method, Pipeline, PipelineParams};
use crate::recording::{Baseline, Dataset, FileReading, LayoutFile, LayoutFrom, Recording};
use crate::values::{Cell, Grid, Speed};

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
    /// Recordings scored.
    pub n: usize,
    /// The model's classes, in confusion-matrix order.
    pub labels: Vec<String>,
    /// Row = true label, column = predicted label.
    pub confusion: ConfusionMatrix,
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

impl Model {
    /// Trains `classifier` on `columns` of `table` (the features of the training recordings,
    /// conditioned and encoded with `params`).
    ///
    /// # Errors
    /// [`Columns::EachTaxel`] (a model classifies with one set of columns), a taxel outside
    /// the grid, broken parameters, or a training set the classifier cannot fit (`k`
    /// larger than the training set, non-finite features).
    pub fn train(
        params: &PipelineParams,
        table: &FeatureTable,
        columns: Columns,
        classifier: ClassifierChoice,
        provenance: Provenance,
    ) -> Result<Model> {
        let taxel = match columns {
            Columns::All => None,
            Columns::Taxel(cell) => Some(cell),
            Columns::EachTaxel => {
                return Err(ParamError::new(
                    "taxel",
                    "a model classifies with one set of columns: all of them, or one taxel's",
                    "every taxel in turn",
                )
                .into())
            }
        };
        let groups = column_groups(&table.grid, table.dims(), columns)?;
        let selected = &groups[0].1;
        let row_labels: Vec<String> = table.metas.iter().map(|m| m.label.clone()).collect();
        let mut labels: Vec<String> = Vec::new();
        for label in &row_labels {
            if !labels.contains(label) {
                labels.push(label.clone());
            }
        }
        let file = ModelFile {
            format: FORMAT.to_string(),
            version: VERSION,
            neurotex_version: env!("CARGO_PKG_VERSION").to_string(),
            pipeline: params.clone(),
            features: FeatureSpec {
                method: table.method,
                taxel,
                columns: selected.iter().map(|&j| table.names[j].clone()).collect(),
            },
            grid: table.grid.clone(),
            classifier,
            labels,
            training: TrainingSet {
                dataset: provenance,
                labels: row_labels,
                rows: (0..table.metas.len())
                    .map(|i| table.select(&[i], selected))
                    .collect(),
            },
        };
        Model::assemble(file)
    }

    /// Checks a model file's content and makes its pipeline, extractor and classifier.
    ///
    /// # Errors
    /// A broken parameter rule, parts that disagree, or a training set that cannot be fit.
    fn assemble(file: ModelFile) -> Result<Model> {
        let inconsistent = |what: String| -> crate::Error { ModelError::Inconsistent(what).into() };
        let grid = &file.grid;
        let grid = Grid::masked(grid.rows(), grid.cols(), grid.present().to_vec())?;
        // The model conditions new recordings as it did its training set, whatever the
        // baseline of their dataset's layout.
        let mut resolved = file.pipeline.clone();
        let baseline = resolved.preprocess.baseline;
        resolved.preprocess.baseline = Some(baseline.unwrap_or(file.training.dataset.baseline));
        let pipeline = Pipeline::new(resolved)?;
        let extractor = pipeline.extractor(&grid)?;
        let spec = &file.features;
        let columns = match (spec.method, spec.taxel) {
            (Method::Taxel, Some(cell)) => Columns::Taxel(cell),
            (_, None) => Columns::All,
            (method, Some(_)) => {
                return Err(inconsistent(format!(
                    "a taxel is given for method {}, which has no per-taxel columns",
                    method.name()
                )))
            }
        };
        let names = extractor.names(spec.method);
        let columns = column_groups(&grid, names.len(), columns)?.remove(0).1;
        let expected: Vec<&String> = columns.iter().map(|&j| &names[j]).collect();
        if spec.columns.iter().collect::<Vec<_>>() != expected {
            return Err(inconsistent(format!(
                "feature columns {:?} are not those of method {} on the {grid} grid",
                spec.columns,
                spec.method.name()
            )));
        }
        check_trained(&file.labels, &file.pipeline, &grid, &file.training.dataset)
            .map_err(inconsistent)?;
        let classifier = fit(&file, columns.len())?;
        Ok(Model {
            file,
            pipeline,
            extractor,
            columns,
            classifier,
        })
    }

    /// Writes the model to `path` as pretty-printed JSON, whole or not at all.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        crate::io::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.file).map_err(std::io::Error::other)?;
            writeln!(w)
        })
    }

    /// Reads a model file written by [`Model::save`].
    ///
    /// # Errors
    /// [`DataError::Io`] for an unreadable file; [`ModelError::NotAModel`] for JSON of
    /// another format, [`ModelError::UnsupportedVersion`] for another format version, and
    /// [`ModelError::Damaged`] for a truncated file, one that is not JSON, or content that
    /// breaks a rule.
    pub fn load(path: &Path) -> Result<Model> {
        let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
        if bytes.starts_with(b"\x89HDF\r\n\x1a\n") {
            // HDF5: a NIR graph, which holds a spiking network.
            let path = path.to_path_buf();
            return Err(ModelError::SpikingModel { path }.into());
        }
        let damaged = |reason: String| -> crate::Error {
            ModelError::Damaged {
                path: path.to_path_buf(),
                reason,
            }
            .into()
        };
        let header: Header = serde_json::from_slice(&bytes).map_err(|e| match e.classify() {
            serde_json::error::Category::Data => ModelError::NotAModel {
                path: path.to_path_buf(),
                found: "missing (the file is not a JSON object)".into(),
            }
            .into(),
            _ => damaged(crate::error::json_error(&e)),
        })?;
        let (format, version) = (header.format.as_ref(), header.version.as_ref());
        check_header(path, format, version, (FORMAT, VERSION))?;
        let file: ModelFile =
            serde_json::from_slice(&bytes).map_err(|e| damaged(crate::error::json_error(&e)))?;
        Model::assemble(file).map_err(|e| damaged(e.to_string()))
    }

    /// Conditions and encodes one recording as the training recordings were (the model's
    /// pipeline and baseline).
    ///
    /// # Errors
    /// A recording the pipeline cannot take (empty sliding phase, shorter than one bin).
    pub fn encode(&self, recording: &Recording) -> Result<Encoded> {
        self.pipeline.encode(recording, self.baseline())
    }

    /// Reads and encodes the recordings `files` as `reading` says (a file without a layout
    /// given or beside it is read with the training dataset's, its raw logs' columns
    /// included: [`FileReading`]) and as the training recordings were encoded, in
    /// parallel; each is named by its path as given, with where its layout came from.
    ///
    /// # Errors
    /// A file that cannot be read, or that the pipeline cannot take, named.
    pub fn encode_files(
        &self,
        files: &[PathBuf],
        reading: &FileReading,
    ) -> Result<(Vec<Encoded>, Vec<LayoutFrom>)> {
        let remembered = self.provenance().layout.as_ref();
        encode_files(&self.pipeline, self.baseline(), remembered, files, reading)
    }

    /// Writes one CSV row per recording: `file,label,predicted`, then `share_<class>` for
    /// each class of the model; `label` is empty unless `known`.
    ///
    /// # Errors
    /// `w` fails.
    pub fn write_predictions(
        &self,
        w: &mut dyn std::io::Write,
        encoded: &[Encoded],
        predictions: &[Prediction],
        known: bool,
    ) -> std::io::Result<()> {
        write_predictions(w, self.labels(), encoded, predictions, known)
    }

    /// Predicts the class of each encoded recording, in parallel.
    ///
    /// # Errors
    /// [`ModelError::OtherGrid`] naming the first recording on another grid than the
    /// model's; a sampled recording for a model trained on events; a recording shorter
    /// than one bin.
    pub fn predict(&self, encoded: &[Encoded]) -> Result<Vec<Prediction>> {
        for e in encoded {
            self.check_grid(e)?;
            check_source(self.provenance(), e)?;
        }
        let rows: Vec<Vec<f64>> = encoded
            .par_iter()
            .map(|e| self.feature_row(e))
            .collect::<Result<_>>()?;
        self.predict_rows(&rows.concat())
    }

    /// Predicts the class of one encoded recording on the calling thread (a causal
    /// classifier's window at a bin boundary, where a thread pool would only add latency).
    ///
    /// # Errors
    /// As [`Model::predict`].
    pub fn predict_one(&self, encoded: &Encoded) -> Result<Prediction> {
        self.check_grid(encoded)?;
        let row = self.feature_row(encoded)?;
        Ok(self.predict_rows(&row)?.remove(0))
    }

    /// Predicts the class of one row of the extractor's features (all of them, as
    /// [`FeatureExtractor::row`] gives them; the model takes its columns).
    ///
    /// # Errors
    /// As [`Model::predict_rows`].
    pub fn predict_extracted(&self, row: &[f64]) -> Result<Prediction> {
        let row: Vec<f64> = self.columns.iter().map(|&j| row[j]).collect();
        Ok(self.predict_rows(&row)?.remove(0))
    }

    /// The feature extractor.
    pub fn extractor(&self) -> &FeatureExtractor {
        &self.extractor
    }

    /// [`ModelError::OtherGrid`] unless `e` has the model's grid.
    fn check_grid(&self, e: &Encoded) -> Result<()> {
        let s = &e.spikes;
        if (s.rows, s.cols) == (self.file.grid.rows(), self.file.grid.cols())
            && s.present == self.file.grid.present()
        {
            return Ok(());
        }
        let found = Grid::masked(s.rows, s.cols, s.present.clone())
            .map_err(|err| crate::Error::from(err).in_recording(&e.meta.file))?;
        Err(ModelError::OtherGrid {
            file: e.meta.file.clone(),
            expected: self.file.grid.clone(),
            found,
        }
        .into())
    }

    /// The model's feature columns of one encoded recording.
    fn feature_row(&self, e: &Encoded) -> Result<Vec<f64>> {
        let row = self
            .extractor
            .row(e, self.file.features.method)
            .map_err(|err| err.in_recording(&e.meta.file))?;
        Ok(self.columns.iter().map(|&j| row[j]).collect())
    }

    /// Predicts the class of each feature row of `x` (row-major, the model's columns,
    /// `columns` of [`Model::features`], per row).
    ///
    /// # Errors
    /// Rows of another length, or a feature that is not finite.
    pub fn predict_rows(&self, x: &[f64]) -> Result<Vec<Prediction>> {
        let dims = self.columns.len();
        if !x.len().is_multiple_of(dims) {
            return Err(ClassifyError::BadFeatures(format!(
                "{} feature values are not whole rows of the model's {dims} features",
                x.len()
            ))
            .into());
        }
        if let Some(pos) = x.iter().position(|v| !v.is_finite()) {
            return Err(ClassifyError::BadFeatures(format!(
                "feature {} of row {} is not finite",
                pos % dims,
                pos / dims
            ))
            .into());
        }
        let n_classes = self.file.labels.len();
        Ok(self
            .classifier
            .predict_with_shares(x)
            .into_iter()
            .map(|(class, shares)| Prediction {
                predicted: self.file.labels[class].clone(),
                shares: (0..n_classes)
                    .map(|c| shares.get(c).copied().unwrap_or(0.0))
                    .collect(),
            })
            .collect())
    }

    /// Scores `predictions` against the true labels `truth`, one per prediction.
    ///
    /// # Errors
    /// No predictions, or a true label that is not one of the model's classes (named).
    ///
    /// # Panics
    /// If `truth` and `predictions` differ in length (a caller bug).
    pub fn score(&self, truth: &[String], predictions: &[Prediction]) -> Result<Score> {
        score(&self.file.labels, truth, predictions)
    }

    /// The class labels, in the order of [`Prediction::shares`].
    pub fn labels(&self) -> &[String] {
        &self.file.labels
    }

    /// The index in [`Model::labels`] of a label the model predicted.
    ///
    /// # Panics
    /// If `label` is not one of the model's classes (a caller bug: predictions only name
    /// the model's classes).
    pub fn class_index(&self, label: &str) -> usize {
        self.file
            .labels
            .iter()
            .position(|l| l == label)
            .expect("a predicted label is one of the model's classes")
    }

    /// The causal conditioning the model was trained with; `None` for the paper's
    /// offline pipeline (zero-phase filter, each recording's own baseline and maximum).
    pub fn causal(&self) -> Option<&crate::signal::CausalConditioning> {
        self.file.pipeline.preprocess.causal.as_ref()
    }

    /// The feature method, the taxel and the column names.
    pub fn features(&self) -> &FeatureSpec {
        &self.file.features
    }

    /// The taxel grid recordings must have.
    pub fn grid(&self) -> &Grid {
        &self.file.grid
    }

    /// The pipeline parameters as trained (the baseline `None` when the training dataset's
    /// layout chose it; see [`Model::baseline`]).
    pub fn params(&self) -> &PipelineParams {
        &self.file.pipeline
    }

    /// The planned pipeline, with the baseline resolved to [`Model::baseline`].
    pub fn pipeline(&self) -> &Pipeline {
        &self.pipeline
    }

    /// The baseline applied to every recording: the pipeline's own, else the training
    /// dataset's.
    pub fn baseline(&self) -> Baseline {
        self.file
            .pipeline
            .preprocess
            .baseline
            .unwrap_or(self.file.training.dataset.baseline)
    }

    /// The classifier and its parameters.
    pub fn classifier(&self) -> ClassifierChoice {
        self.file.classifier
    }

    /// Where the training data came from.
    pub fn provenance(&self) -> &Provenance {
        &self.file.training.dataset
    }

    /// Training recordings.
    pub fn n_training(&self) -> usize {
        self.file.training.rows.len()
    }

    /// The neurotex version that wrote the model.
    pub fn neurotex_version(&self) -> &str {
        &self.file.neurotex_version
    }
}

/// Fits the file's classifier on its training rows of `dims` features.
///
/// # Errors
/// Rows of another length, labels that are not classes of the model, or a training set
/// the classifier cannot fit.
fn fit(file: &ModelFile, dims: usize) -> Result<ChosenModel> {
    let training = &file.training;
    let inconsistent = |what: String| -> crate::Error { ModelError::Inconsistent(what).into() };
    if training.labels.len() != training.rows.len() {
        return Err(inconsistent(format!(
            "{} training labels for {} training rows",
            training.labels.len(),
            training.rows.len()
        )));
    }
    if let Some(i) = training.rows.iter().position(|r| r.len() != dims) {
        return Err(inconsistent(format!(
            "training row {i} has {} features, expected {dims}",
            training.rows[i].len()
        )));
    }
    // The features neurotex computes are rates, statistics and Haralick values, all far
    // below this; a larger value in a model file is damage, and would overflow the
    // z-scoring's squares to infinity and the distances to NaN.
    const MAX_FEATURE: f64 = 1e15;
    for (i, row) in training.rows.iter().enumerate() {
        if let Some(j) = row.iter().position(|v| v.is_nan() || v.abs() > MAX_FEATURE) {
            return Err(inconsistent(format!(
                "training row {i}, feature {j} is {}, beyond the ±1e15 any feature can reach",
                row[j]
            )));
        }
    }
    let y = training
        .labels
        .iter()
        .map(|l| {
            file.labels.iter().position(|c| c == l).ok_or_else(|| {
                inconsistent(format!("training label `{l}` is not one of the classes"))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    // Training lists exactly the labels of its rows: a class without a row would leave the
    // classifier with fewer outputs than the file has labels.
    if let Some(label) = (0..file.labels.len()).find(|c| !y.contains(c)) {
        return Err(inconsistent(format!(
            "field `labels`: class `{}` has no training row",
            file.labels[label]
        )));
    }
    let classifier = file.classifier.check()?;
    Ok(classifier.fit(&training.rows.concat(), dims, &y)?)
}

/// Checks that a recording is of the kind the model was trained on: a model trained on
/// address events (its training layout has an `[events]` table) takes events only, as a
/// stream of frames refuses it, since samples would go through an encoder whose spikes it
/// never learned. (A model trained on sampled recordings takes events: the spikes of the
/// encoder, exported as events, give its predictions bit for bit.)
///
/// # Errors
/// [`DataError::Invalid`] naming the recording.
pub(crate) fn check_source(provenance: &Provenance, e: &Encoded) -> Result<()> {
    let on_events = provenance
        .layout
        .as_ref()
        .is_some_and(|l| l.events.is_some());
    if on_events && !e.from_events {
        let why = "is a sampled recording, but the model was trained on address events, which skip the encoder: give it its sensor's events (an event dataset made by `neurotex import events`, or `neurotex stream --format events`)";
        return Err(DataError::invalid(&e.meta.file, why).into());
    }
    Ok(())
}

/// Checks what training guarantees of any model's file beyond its pipeline's own rules:
/// at least two distinct labels, a causal conditioning with one resting value per cell of
/// `grid`, and a provenance training could have written (a stream's default window of at
/// least 1 ms, a finite gain calibration, a layout that passes its own checks).
///
/// # Errors
/// The rule broken, as a sentence naming the field.
pub(crate) fn check_trained(
    labels: &[String],
    pipeline: &PipelineParams,
    grid: &Grid,
    provenance: &Provenance,
) -> std::result::Result<(), String> {
    if labels.len() < 2 {
        return Err(format!(
            "field `labels` holds {} class(es); a model is trained on at least two",
            labels.len()
        ));
    }
    if let Some(i) = (1..labels.len()).find(|&i| labels[..i].contains(&labels[i])) {
        return Err(format!(
            "field `labels`: class `{}` is listed twice",
            labels[i]
        ));
    }
    if let Some(causal) = &pipeline.preprocess.causal {
        let cells = grid.rows() * grid.cols();
        if causal.offsets.len() != cells {
            return Err(format!(
                "field `pipeline.preprocess.causal.offsets` holds {} resting values for the {cells} cells of the {grid} grid",
                causal.offsets.len()
            ));
        }
    }
    if provenance.median_duration_ms == Some(0) {
        return Err("field `training.dataset.median_duration_ms` is 0; training recordings last at least one bin".into());
    }
    if let Some(g) = &provenance.gain_calibration {
        let numbers = [g.target_hz, g.gain, g.median_hz];
        if numbers.iter().any(|v| !(v.is_finite() && *v >= 0.0)) || g.gain == 0.0 {
            return Err(format!(
                "field `training.dataset.gain_calibration`: target {} Hz, gain {}, median {} Hz; each must be finite and not negative, the gain positive",
                g.target_hz, g.gain, g.median_hz
            ));
        }
    }
    if let Some(layout) = &provenance.layout {
        let at = Path::new("field `training.dataset.layout`");
        layout.check(at).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Scores `predictions` against the true labels `truth` for a model of classes `labels`
/// (see [`Model::score`]).
///
/// # Errors
/// As [`Model::score`].
pub(crate) fn score(
    labels: &[String],
    truth: &[String],
    predictions: &[Prediction],
) -> Result<Score> {
    assert_eq!(
        truth.len(),
        predictions.len(),
        "one true label per prediction"
    );
    if truth.is_empty() {
        return Err(ClassifyError::Empty { what: "score" }.into());
    }
    let index = |label: &str| labels.iter().position(|l| l == label);
    let y = truth
        .iter()
        .map(|t| index(t).ok_or_else(|| ClassifyError::UnknownTestLabel { label: t.clone() }))
        .collect::<Result<Vec<_>, _>>()?;
    let predicted: Vec<usize> = predictions
        .iter()
        .map(|p| index(&p.predicted).unwrap_or(0))
        .collect();
    let confusion = ConfusionMatrix::from_predictions(&y, &predicted, labels.len());
    Ok(Score {
        accuracy: confusion.accuracy(),
        n: y.len(),
        labels: labels.to_vec(),
        confusion,
    })
}

/// Reads and encodes `files` with `pipeline` and `baseline` (see [`Model::encode_files`];
/// `remembered` is the training dataset's layout).
///
/// # Errors
/// As [`Model::encode_files`].
pub(crate) fn encode_files(
    pipeline: &Pipeline,
    baseline: Baseline,
    remembered: Option<&LayoutFile>,
    files: &[PathBuf],
    reading: &FileReading,
) -> Result<(Vec<Encoded>, Vec<LayoutFrom>)> {
    files
        .par_iter()
        .map(|path| {
            let file = path.display().to_string();
            let (mut recording, from) = reading.read(path, remembered)?;
            recording.meta.file = file.clone();
            let encoded = pipeline
                .encode(&recording, baseline)
                .map_err(|e| e.in_recording(&file))?;
            Ok((encoded, from))
        })
        .collect::<Result<Vec<_>>>()
        .map(|pairs| pairs.into_iter().unzip())
}

/// Checks a model file's `format` and `version` fields (`None` when missing) against the
/// `expected` format and version: the other kind of model file is named as such.
///
/// # Errors
/// [`ModelError::NotSpiking`] or [`ModelError::SpikingModel`] for the other kind,
/// [`ModelError::NotAModel`] for another format, [`ModelError::UnsupportedVersion`].
pub fn check_header(
    path: &Path,
    format: Option<&serde_json::Value>,
    version: Option<&serde_json::Value>,
    expected: (&str, u64),
) -> Result<()> {
    let path = path.to_path_buf();
    let text =
        |field: Option<&serde_json::Value>| field.map_or("missing".into(), |v| v.to_string());
    match format.and_then(|f| f.as_str()) {
        Some(f) if f == expected.0 => {}
        Some(FORMAT) => return Err(ModelError::NotSpiking { path }.into()),
        Some(crate::error::SNN_MODEL_FORMAT) => {
            return Err(ModelError::SpikingModel { path }.into())
        }
        _ => {
            let found = text(format);
            return Err(ModelError::NotAModel { path, found }.into());
        }
    }
    if version.and_then(|v| v.as_u64()) != Some(expected.1) {
        let found = text(version);
        return Err(ModelError::UnsupportedVersion { path, found }.into());
    }
    Ok(())
}

/// Writes one CSV row per recording for a model of classes `labels` (see
/// [`Model::write_predictions`]).
///
/// # Errors
/// `w` fails.
pub fn write_predictions(
    w: &mut dyn std::io::Write,
    labels: &[String],
    encoded: &[Encoded],
    predictions: &[Prediction],
    known: bool,
) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    let shares = labels.iter().map(|l| format!("share_{l}"));
    let header: Vec<String> = ["file", "label", "predicted"]
        .map(String::from)
        .into_iter()
        .chain(shares)
        .collect();
    out.write_record(&header)?;
    for (e, p) in encoded.iter().zip(predictions) {
        let label = if known { e.meta.label.as_str() } else { "" };
        let ids = [e.meta.file.as_str(), label, p.predicted.as_str()].map(String::from);
        out.write_record(ids.into_iter().chain(p.shares.iter().map(f64::to_string)))?;
    }
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classify::{ForestParams, KnnParams, LinearParams};
    use crate::encode::SpikeTrains;
    use crate::recording::Meta;

    /// `n` feature values in [0, 10), seeded.
    fn values(seed: u64, n: usize) -> Vec<f64> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n).map(|_| 10.0 * rng.gen::<f64>()).collect()
    }

    /// A `method` table of three classes x 6 recordings on a 2x2 grid whose class shifts
    /// every feature, so that the classes are told apart.
    fn table(method: Method) -> FeatureTable {
        let grid = Grid::full(2, 2).unwrap();
        let extractor = FeatureExtractor::new(&PipelineParams::default(), &grid).unwrap();
        let names = extractor.names(method);
        let labels = ["rough", "smooth", "ribbed"];
        let metas: Vec<Meta> = (0..18)
            .map(|i| Meta {
                file: format!("r{i}.npy"),
                label: labels[i % 3].to_string(),
                ..Meta::default()
            })
            .collect();
        let noise = values(7, metas.len() * names.len());
        let values = noise
            .chunks(names.len())
            .enumerate()
            .flat_map(|(i, row)| row.iter().map(move |v| v + 20.0 * (i % 3) as f64))
            .collect();
        FeatureTable {
            method,
            grid,
            names,
            metas,
            values,
        }
    }

    fn provenance() -> Provenance {
        Provenance {
            fingerprint: "sha256:00".into(),
            baseline: Baseline::Min,
            speeds: Some(vec![Speed::of(5.0)]),
            gain_calibration: None,
            median_duration_ms: None,
            layout: None,
        }
    }

    fn trained(method: Method, columns: Columns) -> Model {
        let knn = ClassifierChoice::Knn(KnnParams {
            k: 3,
            standardize: true,
        });
        trained_with(method, columns, knn)
    }

    fn trained_with(method: Method, columns: Columns, classifier: ClassifierChoice) -> Model {
        let params = PipelineParams::default();
        Model::train(&params, &table(method), columns, classifier, provenance()).unwrap()
    }

    #[test]
    fn a_saved_model_loads_equal_and_predicts_the_same() {
        let dir = tempfile::tempdir().unwrap();
        for (method, columns) in [
            (Method::Glcm3d, Columns::All),
            (Method::Taxel, Columns::All),
            (Method::Taxel, Columns::Taxel(Cell { row: 1, col: 0 })),
        ] {
            let model = trained(method, columns);
            let dims = model.features().columns.len();
            let queries = values(99, 40 * dims);
            let before = model.predict_rows(&queries).unwrap();
            let path = dir.path().join("model.json");
            model.save(&path).unwrap();
            let loaded = Model::load(&path).unwrap();
            assert_eq!(loaded, model);
            assert_eq!(loaded.predict_rows(&queries).unwrap(), before);
            assert_eq!(loaded.baseline(), Baseline::Min, "the training layout's");
            for p in &before {
                assert!((p.shares.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                let top = model
                    .labels()
                    .iter()
                    .position(|l| *l == p.predicted)
                    .unwrap();
                assert!(p.shares.iter().all(|&s| s <= p.shares[top]));
            }
        }
    }

    #[test]
    fn forest_and_linear_models_save_load_and_predict_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let forest = ForestParams {
            trees: 25,
            seed: 3,
            ..ForestParams::default()
        };
        for choice in [
            ClassifierChoice::Forest(forest),
            ClassifierChoice::Linear(LinearParams::default()),
        ] {
            let model = trained_with(Method::Glcm3d, Columns::All, choice);
            let dims = model.features().columns.len();
            let queries = values(5, 30 * dims);
            let before = model.predict_rows(&queries).unwrap();
            let path = dir.path().join("model.json");
            model.save(&path).unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.contains(&format!("\"kind\": \"{}\"", choice.name())));
            let loaded = Model::load(&path).unwrap();
            assert_eq!(loaded.classifier(), choice);
            assert_eq!(loaded.predict_rows(&queries).unwrap(), before);
            let rows: Vec<f64> = (0..18)
                .flat_map(|i| model.file.training.rows[i].clone())
                .collect();
            let right = model
                .predict_rows(&rows)
                .unwrap()
                .iter()
                .zip(&model.file.training.labels)
                .filter(|(p, l)| p.predicted == **l)
                .count();
            assert_eq!(right, 18, "{choice}: separable training rows");
            for p in &before {
                assert!((p.shares.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                let top = model
                    .labels()
                    .iter()
                    .position(|l| *l == p.predicted)
                    .unwrap();
                assert!(p.shares.iter().all(|&s| s <= p.shares[top]));
            }
        }
    }

    #[test]
    fn the_file_describes_itself() {
        let model = trained(Method::Taxel, Columns::Taxel(Cell { row: 0, col: 1 }));
        let value = serde_json::to_value(&model.file).unwrap();
        assert_eq!(value["format"], "neurotex-model");
        assert_eq!(value["version"], 1);
        assert_eq!(value["neurotex_version"], env!("CARGO_PKG_VERSION"));
        assert_eq!(value["pipeline"]["preprocess"]["cutoff_hz"], 50.0);
        assert_eq!(value["pipeline"]["encoder"]["gain"], 8.0);
        assert_eq!(
            value["pipeline"]["glcm"]["distances"],
            serde_json::json!([1, 2, 4, 8])
        );
        assert_eq!(
            value["features"]["columns"],
            serde_json::json!(["r0c1_msr", "r0c1_cv_isi", "r0c1_fano"])
        );
        assert_eq!(
            value["classifier"],
            serde_json::json!({"kind": "knn", "k": 3, "standardize": true})
        );
        assert_eq!(
            value["labels"],
            serde_json::json!(["rough", "smooth", "ribbed"])
        );
        assert_eq!(value["training"]["dataset"]["baseline"]["kind"], "min");
        assert_eq!(value["training"]["rows"].as_array().unwrap().len(), 18);
    }

    #[test]
    fn the_training_rows_are_one_set_of_columns() {
        let params = PipelineParams::default();
        let err = Model::train(
            &params,
            &table(Method::Taxel),
            Columns::EachTaxel,
            ClassifierChoice::default(),
            provenance(),
        )
        .unwrap_err();
        assert!(matches!(
            err,
            crate::Error::Param(ParamError { name: "taxel", .. })
        ));
        let err = Model::train(
            &params,
            &table(Method::Glcm3d),
            Columns::All,
            ClassifierChoice::Knn(KnnParams {
                k: 19,
                standardize: true,
            }),
            provenance(),
        )
        .unwrap_err();
        assert!(matches!(
            err,
            crate::Error::Classify(ClassifyError::KTooLarge { k: 19, n_train: 18 })
        ));
    }

    /// Writes `text` to a file and loads it as a model.
    fn load_text(text: &str) -> crate::Error {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        std::fs::write(&path, text).unwrap();
        Model::load(&path).unwrap_err()
    }

    #[test]
    fn files_of_another_format_or_version_or_damaged_are_named_errors() {
        let model = trained(Method::Glcm3d, Columns::All);
        let text = serde_json::to_string_pretty(&model.file).unwrap();
        let err = load_text(&text.replacen("\"version\": 1", "\"version\": 99", 1));
        assert!(
            matches!(&err, crate::Error::Model(ModelError::UnsupportedVersion { found, .. }) if found == "99"),
            "{err}"
        );
        assert!(
            err.to_string().contains("version 99 is not supported"),
            "{err}"
        );
        let err = load_text(&text.replacen("neurotex-model", "other-model", 1));
        assert!(
            matches!(err, crate::Error::Model(ModelError::NotAModel { .. })),
            "{err}"
        );
        let err = load_text("[1, 2]");
        assert!(
            matches!(err, crate::Error::Model(ModelError::NotAModel { .. })),
            "{err}"
        );
        for damaged in [
            &text[..text.len() / 2],
            "",
            "not json",
            &text.replacen("\"kind\": \"knn\"", "\"kind\": \"forest\"", 1),
            &text.replacen("\"levels\": 16", "\"levels\": 1", 1),
            &text.replacen("\"rows\": 2,", "\"rows\": 3,", 1),
            &text.replacen("\"asm\"", "\"energy\"", 1),
            &text.replacen("\"k\": 3", "\"k\": 0", 1),
            // absurd neuron constants: the Euler step would overflow to NaN, silently
            // silencing every neuron
            &text.replacen("\"a\": 0.02", "\"a\": 1e300", 1),
            &text.replacen("\"b\": 0.2", "\"b\": -1e300", 1),
            &text.replacen("\"d\": 8.0", "\"d\": 1e300", 1),
        ] {
            let err = load_text(damaged);
            assert!(
                matches!(err, crate::Error::Model(ModelError::Damaged { .. })),
                "{err}"
            );
        }
        let missing = Model::load(Path::new("/nonexistent/model.json")).unwrap_err();
        assert!(matches!(missing, crate::Error::Data(DataError::Io { .. })));
    }

    #[test]
    fn model_files_asking_for_absurd_work_or_values_are_damaged_not_aborts() {
        let model = trained(Method::Glcm3d, Columns::All);
        let value = serde_json::to_value(&model.file).unwrap();
        // a billion trees: refused by the forest's limit before anything is allocated
        let mut forest = value.clone();
        let trees = ForestParams {
            trees: 1_000_000_000,
            ..ForestParams::default()
        };
        forest["classifier"] = serde_json::to_value(ClassifierChoice::Forest(trees)).unwrap();
        let err = load_text(&forest.to_string());
        assert!(
            matches!(err, crate::Error::Model(ModelError::Damaged { .. })),
            "{err}"
        );
        assert!(err.to_string().contains("at most 10000"), "{err}");
        // a training value that would overflow the z-scoring
        let mut rows = value;
        rows["training"]["rows"][0][1] = serde_json::json!(1e300);
        let err = load_text(&rows.to_string());
        assert!(
            err.to_string().contains("training row 0, feature 1"),
            "{err}"
        );
    }

    #[test]
    fn recordings_of_another_grid_are_named() {
        let model = trained(Method::Glcm3d, Columns::All);
        let encoded = |file: &str, rows: usize, cols: usize| Encoded {
            meta: Meta {
                file: file.into(),
                ..Meta::default()
            },
            spikes: SpikeTrains::from_raster(
                &vec![0; 400 * rows * cols],
                rows,
                cols,
                &vec![true; rows * cols],
            ),
            fa: None,
            resampled: false,
            flat: false,
            from_events: false,
        };
        assert_eq!(model.predict(&[encoded("a.npy", 2, 2)]).unwrap().len(), 1);
        let err = model
            .predict(&[encoded("a.npy", 2, 2), encoded("b.npy", 3, 3)])
            .unwrap_err();
        assert!(
            matches!(&err, crate::Error::Model(ModelError::OtherGrid { file, .. }) if file == "b.npy"),
            "{err}"
        );
        assert!(err.to_string().contains("3x3, 9 taxels"), "{err}");
    }

    #[test]
    fn scores_count_true_labels_against_predictions() {
        let model = trained(Method::Glcm3d, Columns::All);
        let p = |label: &str| Prediction {
            predicted: label.into(),
            shares: vec![],
        };
        let truth: Vec<String> = ["rough", "smooth", "ribbed"].map(String::from).to_vec();
        let score = model
            .score(&truth, &[p("rough"), p("rough"), p("ribbed")])
            .unwrap();
        assert_eq!(score.n, 3);
        assert!((score.accuracy - 2.0 / 3.0).abs() < 1e-15);
        assert_eq!(score.confusion.rows()[1], vec![1, 0, 0]);
        let err = model
            .score(&["felt".to_string()], &[p("rough")])
            .unwrap_err();
        assert!(matches!(
            err,
            crate::Error::Classify(ClassifyError::UnknownTestLabel { .. })
        ));
    }
}
