//! A saved model of either kind, as `predict`, `predict --causal` and `stream` take it: a
//! feature model ([`crate::model`]) or a spiking network ([`crate::spiking_model`]). Both
//! carry the pipeline that makes their spikes and the labels of their classes; they differ
//! in what they classify (features of a window, or the spike trains themselves).

use std::path::{Path, PathBuf};

use crate::causal::{episode_decisions, spiking_episode_decisions, DecisionRule, Episode};
use crate::error::{ModelError, Result};
use crate::model::{Model, Prediction, Provenance, Score};
use crate::nir::NirFrom;
use crate::pipeline::{Encoded, Method, Pipeline, PipelineParams};
use crate::recording::{Baseline, FileReading, LayoutFrom};
use crate::signal::CausalConditioning;
use crate::spiking_model::{is_hdf5, SpikingModel};
use crate::values::Grid;

/// What every saved model says of the data it was trained on.
pub trait Trained {
    /// The training dataset: its name, baseline, layout, the median length of its
    /// recordings.
    fn provenance(&self) -> &Provenance;
}

impl Trained for Model {
    fn provenance(&self) -> &Provenance {
        Model::provenance(self)
    }
}

impl Trained for SpikingModel {
    fn provenance(&self) -> &Provenance {
        &self.training().dataset
    }
}

impl Trained for SavedModel {
    fn provenance(&self) -> &Provenance {
        match self {
            SavedModel::Features(m) => m.provenance(),
            SavedModel::Spiking(m) => Trained::provenance(&**m),
        }
    }
}

/// A feature model or a spiking network.
#[derive(Debug, Clone, PartialEq)]
pub enum SavedModel {
    /// A classifier of features (`neurotex train`).
    Features(Box<Model>),
    /// A spiking network (`neurotex train --classifier snn`, or a NIR graph).
    Spiking(Box<SpikingModel>),
}

impl From<Model> for SavedModel {
    fn from(model: Model) -> Self {
        SavedModel::Features(Box::new(model))
    }
}

impl From<SpikingModel> for SavedModel {
    fn from(model: SpikingModel) -> Self {
        SavedModel::Spiking(Box::new(model))
    }
}

impl SavedModel {
    /// What predicts, for a summary line before the model's path: nothing for a feature
    /// model, the spiking network with its training options for a spiking model file, and
    /// "the spiking network of " for a NIR graph, whose training neurotex does not know.
    pub fn described(&self, path: &Path) -> String {
        match self {
            SavedModel::Features(_) => String::new(),
            SavedModel::Spiking(_) if is_hdf5(path) => "the spiking network of ".into(),
            SavedModel::Spiking(m) => {
                let snn = crate::classify::ClassifierChoice::Snn(m.params());
                format!("the {snn} of ")
            }
        }
    }

    /// Reads the model file at `path` of either kind; a NIR graph from another tool runs
    /// with the pipeline of `like`, a spiking model file.
    ///
    /// # Errors
    /// What [`Model::load`] and [`SpikingModel::load`] refuse; `like` given for a file that
    /// is not a NIR graph.
    pub fn load(path: &Path, like: Option<&Path>) -> Result<SavedModel> {
        SavedModel::load_as(path, like, NirFrom::Nir)
    }

    /// As [`SavedModel::load`], a NIR graph read as written by `from` (see [`NirFrom`]).
    ///
    /// # Errors
    /// As [`SavedModel::load`]; `from` other than NIR for a file that is not a NIR graph.
    pub fn load_as(path: &Path, like: Option<&Path>, from: NirFrom) -> Result<SavedModel> {
        let graph_named = (path.extension()).is_some_and(|e| e.eq_ignore_ascii_case("nir"));
        if from != NirFrom::Nir && path.is_file() && !is_hdf5(path) && !graph_named {
            return Err(ModelError::Inconsistent(format!(
                "{}: --nir-from {} applies to a NIR graph, not to a model file",
                path.display(),
                from.name()
            ))
            .into());
        }
        match (like, SpikingModel::is_spiking(path)) {
            (Some(like), true) if is_hdf5(path) => {
                let like = SpikingModel::load(like)?;
                Ok(SpikingModel::from_nir_as(path, Some(&like), from)?.into())
            }
            (Some(_), _) => Err(ModelError::Inconsistent(format!(
                "{}: a pipeline to run with (--like) applies to a NIR graph, not to a model file",
                path.display()
            ))
            .into()),
            (None, true) if is_hdf5(path) => {
                Ok(SpikingModel::from_nir_as(path, None, from)?.into())
            }
            (None, true) => Ok(SpikingModel::load(path)?.into()),
            (None, false) => Ok(Model::load(path)?.into()),
        }
    }

    /// The class labels, in the order of the shares.
    pub fn labels(&self) -> &[String] {
        match self {
            SavedModel::Features(m) => m.labels(),
            SavedModel::Spiking(m) => m.labels(),
        }
    }

    /// The taxel grid recordings must have.
    pub fn grid(&self) -> &Grid {
        match self {
            SavedModel::Features(m) => m.grid(),
            SavedModel::Spiking(m) => m.grid(),
        }
    }

    /// The pipeline as trained.
    pub fn params(&self) -> &PipelineParams {
        match self {
            SavedModel::Features(m) => m.params(),
            SavedModel::Spiking(m) => m.pipeline_params(),
        }
    }

    /// The planned pipeline, the baseline resolved.
    pub fn pipeline(&self) -> &Pipeline {
        match self {
            SavedModel::Features(m) => m.pipeline(),
            SavedModel::Spiking(m) => m.pipeline(),
        }
    }

    /// The baseline applied to every recording.
    pub fn baseline(&self) -> Baseline {
        match self {
            SavedModel::Features(m) => m.baseline(),
            SavedModel::Spiking(m) => m.baseline(),
        }
    }

    /// The fixed conditioning of a model trained with `--causal`.
    pub fn causal(&self) -> Option<&CausalConditioning> {
        self.params().preprocess.causal.as_ref()
    }

    /// The conditioning a stream runs with, or why the model cannot run on a stream: it
    /// was trained without `--causal`, or its features have no running form.
    ///
    /// # Errors
    /// The reason, as a sentence.
    pub fn streams(&self) -> std::result::Result<&CausalConditioning, &'static str> {
        if let SavedModel::Features(m) = self {
            if m.features().method == Method::Spectrum {
                return Err(crate::causal::NO_RUNNING_SPECTRUM);
            }
        }
        self.causal().ok_or("a stream needs a model trained for streams (--causal); this one conditions each recording with the zero-phase filter and its own maximum, which need the whole recording")
    }

    /// Reads and encodes `files` as the training recordings were (see
    /// [`Model::encode_files`]).
    ///
    /// # Errors
    /// A file that cannot be read or encoded, named.
    pub fn encode_files(
        &self,
        files: &[PathBuf],
        reading: &FileReading,
    ) -> Result<(Vec<Encoded>, Vec<LayoutFrom>)> {
        match self {
            SavedModel::Features(m) => m.encode_files(files, reading),
            SavedModel::Spiking(m) => m.encode_files(files, reading),
        }
    }

    /// Checks that a recording is of the kind the model was trained on: events for a
    /// model trained on events (a model trained on sampled recordings takes both).
    ///
    /// # Errors
    /// A sampled recording for a model trained on events, named.
    pub fn check_source(&self, encoded: &Encoded) -> Result<()> {
        crate::model::check_source(self.provenance(), encoded)
    }

    /// How many of the encoded recordings a feature model meets as its own training
    /// recordings ([`Model::training_rows_met`]); 0 for a spiking network, which keeps no
    /// training recordings.
    ///
    /// # Errors
    /// Features that cannot be computed.
    pub fn training_recordings_met(&self, encoded: &[Encoded]) -> Result<usize> {
        match self {
            SavedModel::Features(m) => m.training_rows_met(encoded),
            SavedModel::Spiking(_) => Ok(0),
        }
    }

    /// Predicts each encoded recording's class, in parallel.
    ///
    /// # Errors
    /// A recording on another grid than the model's or of another kind than its training
    /// recordings ([`SavedModel::check_source`]), or too short for its features.
    pub fn predict(&self, encoded: &[Encoded]) -> Result<Vec<Prediction>> {
        match self {
            SavedModel::Features(m) => m.predict(encoded),
            SavedModel::Spiking(m) => m.predict(encoded),
        }
    }

    /// Scores predictions against true labels.
    ///
    /// # Errors
    /// No predictions, or a label the model does not know.
    pub fn score(&self, truth: &[String], predictions: &[Prediction]) -> Result<Score> {
        crate::model::score(self.labels(), truth, predictions)
    }

    /// The decisions at every bin boundary of one causally encoded recording and its end,
    /// as a stream of its frames gives them ([`episode_decisions`],
    /// [`spiking_episode_decisions`]).
    ///
    /// # Errors
    /// A rule out of range, a recording on another grid or of another kind than the
    /// training recordings (samples for a model trained on events), features that cannot
    /// be computed.
    pub fn episode(
        &self,
        encoded: &Encoded,
        window_ms: usize,
        rule: DecisionRule,
    ) -> Result<Episode> {
        self.check_source(encoded)?;
        match self {
            SavedModel::Features(m) => episode_decisions(m, encoded, window_ms, rule),
            SavedModel::Spiking(m) => spiking_episode_decisions(m, encoded, window_ms, rule),
        }
    }
}
