//! A model applied: recordings encoded as the training ones were, their feature rows
//! predicted and scored, the predictions written, and what the model holds.

use std::path::PathBuf;

use rayon::prelude::*;

use super::{FeatureSpec, Model, Prediction, Provenance, Score};
use crate::classify::{wilson_interval, ClassifierChoice, ConfusionMatrix, Predict};
use crate::error::{ClassifyError, DataError, ModelError, Result};
use crate::pipeline::{Encoded, FeatureExtractor, Pipeline, PipelineParams};
use crate::recording::{Baseline, FileReading, LayoutFile, LayoutFrom, Recording};
use crate::values::Grid;

impl Model {
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

    /// How many of the encoded recordings have exactly (bit for bit) the feature row of one
    /// of the model's training recordings: the same recordings, copied or imported again
    /// into another dataset, or recordings its features cannot tell from them. Their
    /// predictions are the model's memory of its training set, no test of it.
    ///
    /// # Errors
    /// As [`Model::predict`].
    pub fn training_rows_met(&self, encoded: &[Encoded]) -> Result<usize> {
        let bits = |row: &[f64]| -> Vec<u64> { row.iter().map(|x| x.to_bits()).collect() };
        let trained: std::collections::HashSet<Vec<u64>> =
            self.file.training.rows.iter().map(|r| bits(r)).collect();
        let rows: Vec<Vec<f64>> = encoded
            .par_iter()
            .map(|e| self.feature_row(e))
            .collect::<Result<_>>()?;
        Ok(rows.iter().filter(|r| trained.contains(&bits(r))).count())
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
    let right = y.iter().zip(&predicted).filter(|(t, p)| t == p).count();
    let classes = y.iter().collect::<std::collections::BTreeSet<_>>().len();
    Ok(Score {
        accuracy: confusion.accuracy(),
        interval: wilson_interval(right, y.len())?,
        chance: 1.0 / classes as f64,
        n: y.len(),
        labels: labels.to_vec(),
        confusion,
        trained_on: 0,
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
