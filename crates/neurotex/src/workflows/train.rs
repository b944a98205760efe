//! `train`: a classifier (KNN, random forest or logistic regression) trained on a dataset's
//! features, kept as a model that `predict` and `stream` apply to new recordings.

use std::path::PathBuf;

use super::{calibrated_pipeline, feature_table, indices_at, ClassifierOptions, KnnOptions};
use super::{OnProgress, OpenOptions};
use crate::analysis::Columns;
use crate::model::{Model, Provenance};
use crate::options::StageOptions;
use crate::pipeline::{Method, Pipeline};
use crate::recording::Dataset;
use crate::{Cell, Grid, Result, Speed};

/// Options of `train`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct TrainOptions {
    /// The training dataset folder (with `manifest.csv`, optional `layout.toml`).
    #[cfg_attr(feature = "cli", arg(long))]
    pub dataset: PathBuf,
    /// Train only on recordings at these speeds (mm/s, comma-separated); default all.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub speeds: Option<Vec<Speed>>,
    /// Feature set: `taxel`, `glcm2d`, `glcm3d` (the paper's spatio-temporal approach),
    /// `all-taxels`, `all-taxels-mm`, `glcm3d-multi` or `spectrum` (spike counts along the
    /// slide in bands of spatial frequency; not with `--causal`).
    #[cfg_attr(feature = "cli", arg(long, default_value = "glcm3d"))]
    pub method: Method,
    /// With `--method taxel`: classify with this one taxel's statistics, as `ROW,COL`.
    /// Without it, every taxel's three statistics together form one feature row.
    #[cfg_attr(feature = "cli", arg(long))]
    pub taxel: Option<Cell>,
    /// KNN's neighbours and z-scoring.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub knn: KnnOptions,
    /// The classifier and its knobs.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub classifier: ClassifierOptions,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

/// A model and the grid of the recordings it was trained on.
#[derive(Debug)]
pub struct Trained {
    /// The model.
    pub model: Model,
    /// The training recordings' grid.
    pub grid: Grid,
}

impl TrainOptions {
    /// Trains the model on `dataset` with the stage options `stages`.
    ///
    /// # Errors
    /// Options out of range or that do not go together, recordings that cannot be read,
    /// or too few recordings for the classifier.
    pub fn run(&self, dataset: &Dataset, stages: &StageOptions, on: OnProgress) -> Result<Trained> {
        if stages.causal && self.method == Method::Spectrum {
            let why = crate::stream::NO_RUNNING_SPECTRUM;
            let message = format!("--causal trains a model for streams: {why}");
            return Err(crate::error::OptionsError::Conflict(message).into());
        }
        let indices = indices_at(dataset, self.speeds.as_deref())?;
        let calibrated = calibrated_pipeline(stages, dataset, &indices, on)?;
        let params = calibrated.params;
        let pipeline = Pipeline::new(params.clone())?;
        let classifier = self.classifier.choice(self.knn.params()?)?;
        if matches!(classifier, crate::classify::ClassifierChoice::Snn(_)) {
            let message = "model files do not hold a spiking network yet: `evaluate --method spikes --classifier snn` and `compare --methods spikes` run it";
            return Err(crate::error::OptionsError::Conflict(message.into()).into());
        }
        let columns = match (self.method, self.taxel) {
            (Method::Taxel, Some(cell)) => Columns::Taxel(cell),
            (_, Some(_)) => return Err(super::taxel_not_applicable()),
            (_, None) => Columns::All,
        };
        let (table, grid) = feature_table(dataset, &pipeline, &indices, self.method, on)?;
        if let Some(cell) = self.taxel {
            grid.locate(cell)?;
        }
        let provenance = Provenance {
            gain_calibration: calibrated.gain,
            median_duration_ms: calibrated.causal.map(|c| c.median_duration_ms),
            ..Provenance::of(dataset, self.speeds.clone())?
        };
        let model = Model::train(&params, &table, columns, classifier, provenance)?;
        Ok(Trained { model, grid })
    }
}
