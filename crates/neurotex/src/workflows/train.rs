//! `train`: a classifier (KNN, random forest or logistic regression) trained on a dataset's
//! features, kept as a model that `predict` and `stream` apply to new recordings.

use std::path::PathBuf;

use super::{
    calibrated_pipeline, encode_all, feature_table, indices_at, ClassifierOptions, KnnOptions,
};
use super::{OnProgress, OpenOptions};
use crate::analysis::Columns;
use crate::classify::ClassifierChoice;
use crate::error::ParamError;
use crate::model::{Model, Provenance};
use crate::options::StageOptions;
use crate::pipeline::{Method, Pipeline};
use crate::progress::Progress;
use crate::recording::Dataset;
use crate::samples::MethodChoice;
use crate::snn::{train::TrainingLog, Travel};
use crate::spiking_model::SpikingModel;
use crate::workflows::evaluate::DEFAULT_METHOD;
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
    /// slide in bands of spatial frequency; not with `--causal`), `rates` (every taxel's
    /// mean spike rate in spikes/s, the counts without their timing), or `spikes` (the spike
    /// trains themselves, read by the spiking network: `--method spikes` and
    /// `--classifier snn` each imply the other). [default: glcm3d; spikes with
    /// `--classifier snn`]
    #[cfg_attr(feature = "cli", arg(long))]
    pub method: Option<MethodChoice>,
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
        let (method, classifier) = self.method_and_classifier()?;
        let MethodChoice::Features(method) = method else {
            let message = "a spiking network is trained with TrainOptions::run_spiking";
            return Err(crate::error::OptionsError::Conflict(message.into()).into());
        };
        if stages.causal && method == Method::Spectrum {
            let why = crate::stream::NO_RUNNING_SPECTRUM;
            let message = format!("--causal trains a model for streams: {why}");
            return Err(crate::error::OptionsError::Conflict(message).into());
        }
        let indices = indices_at(dataset, self.speeds.as_deref())?;
        let calibrated = calibrated_pipeline(stages, dataset, &indices, on)?;
        let params = calibrated.params;
        let pipeline = Pipeline::new(params.clone())?;
        let columns = match (method, self.taxel) {
            (Method::Taxel, Some(cell)) => Columns::Taxel(cell),
            (_, Some(_)) => return Err(super::taxel_not_applicable()),
            (_, None) => Columns::All,
        };
        let (table, grid) = feature_table(dataset, &pipeline, &indices, method, on)?;
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

impl Trained {
    /// The model in one line: classifier, training set, features, grid.
    pub fn summary(&self) -> String {
        let model = &self.model;
        format!(
            "{} on {} recordings of {} classes, {} {} features on the {} grid",
            model.classifier(),
            model.n_training(),
            model.labels().len(),
            model.features().columns.len(),
            model.features().method.name(),
            self.grid
        )
    }
}

/// A spiking network, how its training went, and the grid of its training recordings.
#[derive(Debug)]
pub struct TrainedSpiking {
    /// The model.
    pub model: SpikingModel,
    /// Epochs run and the one kept.
    pub log: TrainingLog,
    /// The training recordings' grid.
    pub grid: Grid,
}

impl TrainedSpiking {
    /// The network in one line: its parameters, training set, inputs, how training went.
    pub fn summary(&self) -> String {
        let (model, log) = (&self.model, &self.log);
        let travel = match (model.params().travel, model.network().travel_mm_s) {
            (Travel::Median, Some(v)) => format!(" (the training speeds' median: {v} mm/s)"),
            _ => String::new(),
        };
        format!(
            "{}{travel} on {} recordings of {} classes ({} inputs: taxels x populations; best validation loss {:.3} at epoch {} of {}) on the {} grid",
            ClassifierChoice::Snn(model.params()),
            model.training().recordings,
            model.labels().len(),
            model.network().inputs,
            log.validation_loss,
            log.best_epoch,
            log.epochs,
            self.grid
        )
    }

    /// When the epoch cap, not early stopping, ended training (the validation loss lowest
    /// within the last `patience` epochs, so perhaps still falling), what to say of it.
    pub fn at_the_cap(&self) -> Option<String> {
        let (log, params) = (&self.log, self.model.params());
        let capped = log.epochs == params.epochs && log.epochs - log.best_epoch < params.patience;
        let lowest = match log.best_epoch == log.epochs {
            true => format!("still falling at the last of the {} epochs", log.epochs),
            false => format!("lowest at epoch {} of {}", log.best_epoch, log.epochs),
        };
        capped.then(|| format!("the validation loss was {lowest}: training stopped at the cap, not by early stopping; more epochs may do better (--snn-epochs; Python: the `epochs` classifier option)"))
    }
}

impl TrainOptions {
    /// Whether the options train the spiking network (`--classifier snn` or `--method
    /// spikes`).
    pub fn spiking(&self) -> bool {
        self.method() == MethodChoice::Spikes
    }

    /// The method trained on: `--method`, or what `--classifier` reads.
    pub fn method(&self) -> MethodChoice {
        self.classifier.kinds(self.method, DEFAULT_METHOD).0
    }

    /// The method and the classifier, checked: a model reads feature rows or spike
    /// inputs, so `van-rossum`, which compares recordings with each other, is evaluated,
    /// not trained.
    ///
    /// # Errors
    /// A pairing that does not run, `van-rossum`, or a broken parameter.
    pub fn method_and_classifier(&self) -> Result<(MethodChoice, ClassifierChoice)> {
        let knn = self.knn.params()?;
        let (method, classifier) = self
            .classifier
            .with_method(self.method, DEFAULT_METHOD, knn)?;
        if method == MethodChoice::VanRossum {
            let rule = "a model is trained on feature rows or on the spike trains (spikes); van-rossum is evaluated, not trained";
            return Err(ParamError::new("method", rule, method.name()).into());
        }
        Ok((method, classifier))
    }

    /// Trains the spiking network (`--classifier snn`) on the spike trains of `dataset`'s
    /// recordings, encoded with the stage options `stages`.
    ///
    /// # Errors
    /// Options out of range, recordings that cannot be read, or a training set too small
    /// for the validation split.
    pub fn run_spiking(
        &self,
        dataset: &Dataset,
        stages: &StageOptions,
        on: OnProgress,
    ) -> Result<TrainedSpiking> {
        let (_, ClassifierChoice::Snn(snn)) = self.method_and_classifier()? else {
            let message = "run_spiking trains --classifier snn";
            return Err(crate::error::OptionsError::Conflict(message.into()).into());
        };
        if self.taxel.is_some() {
            return Err(super::taxel_not_applicable());
        }
        let indices = indices_at(dataset, self.speeds.as_deref())?;
        let calibrated = calibrated_pipeline(stages, dataset, &indices, on)?;
        let params = calibrated.params;
        let pipeline = Pipeline::new(params.clone())?;
        let (encoded, grid) = encode_all(dataset, &pipeline, &indices, on)?;
        let provenance = Provenance {
            gain_calibration: calibrated.gain,
            median_duration_ms: calibrated.causal.map(|c| c.median_duration_ms),
            ..Provenance::of(dataset, self.speeds.clone())?
        };
        if let Some(note) = snn.short_window() {
            on(Progress::Say(&note));
        }
        on(Progress::Say(&format!(
            "training a {} on {} recordings; {:.0} % of each class held out for early stopping",
            ClassifierChoice::Snn(snn),
            encoded.len(),
            snn.validation * 100.0
        )));
        // Minutes on long slides: a step per epoch.
        on(Progress::Stage(
            "training the spiking network (epochs)",
            snn.epochs,
        ));
        let each_epoch = || on(Progress::Tick);
        let (model, log) =
            SpikingModel::train(&params, &encoded, &grid, (snn, &each_epoch), provenance)?;
        if log.epochs < snn.epochs {
            on(Progress::Say(&format!(
                "early stopping: training ended at epoch {} of {}, {} epochs after the lowest validation loss",
                log.epochs, snn.epochs, snn.patience
            )));
            (log.epochs..snn.epochs).for_each(|_| on(Progress::Tick));
        }
        Ok(TrainedSpiking { model, log, grid })
    }
}
