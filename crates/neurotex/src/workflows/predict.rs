//! `predict`: a saved model applied to new recordings, a dataset folder or plain files,
//! with its own pipeline: whole recordings, or bin by bin as `stream` decides.

use std::path::PathBuf;

use rayon::prelude::*;

use super::stream::DecisionOptions;
use super::{say_conditions, OnProgress, OpenOptions, ReadOptions};
use crate::causal::Episode;
use crate::error::OptionsError;
use crate::model::Provenance;
use crate::pipeline::{Encoded, Pipeline};
use crate::progress::Progress;
use crate::recording::{Baseline, Dataset};
use crate::saved::{SavedModel, Trained};
use crate::Result;

/// Options of `predict`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct PredictOptions {
    /// The model file written by `neurotex train` (a spiking network's too, or a NIR
    /// graph). Its pipeline (filter, neurons, bins,
    /// GLCM offsets, baseline) is applied to the recordings, not this command's defaults.
    #[cfg_attr(feature = "cli", arg(long))]
    pub model: PathBuf,
    /// A dataset folder to predict; its manifest's labels are written beside the
    /// predictions and scored with --json.
    #[cfg_attr(feature = "cli", arg(
        long,
        required_unless_present = "files",
        conflicts_with_all = ["files", "layout", "fs", "grid", "no_header", "delimiter", "time_column", "time_unit", "channels", "duplicate_stamps", "max_gap_s"]
    ))]
    pub dataset: Option<PathBuf>,
    /// With --dataset: predict only its recordings at these speeds (mm/s, comma-separated);
    /// default all.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub speeds: Option<Vec<crate::Speed>>,
    /// Recordings to predict instead of a dataset (`.npy` or `.csv`); their labels are
    /// unknown. They must have the model's taxel grid. A file with no layout given or
    /// beside it is read as the model's training recordings were: raw logs of the logger
    /// the training dataset was imported from need no options.
    pub files: Vec<PathBuf>,
    /// With FILES: how to read them (the options of `encode`).
    /// How the files are read.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub read: ReadOptions,
    /// Decide as `neurotex stream` would, bin by bin (needs a model trained with
    /// --causal, or on address events, which need no conditioning): --out gets JSON
    /// lines, one per bin boundary of each recording's selected phase and one for its
    /// end, each with the recording's `file` and its manifest's
    /// `true_label` beside the model's `label` (the window's class; at the end, the
    /// episode's) and `decision` (null until made); the same lines `neurotex stream
    /// --episode whole` prints for that recording's frames.
    #[cfg_attr(feature = "cli", arg(long))]
    pub causal: bool,
    /// How an episode is decided.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub decision: DecisionOptions,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

impl PredictOptions {
    /// The dataset, when the options name one.
    ///
    /// # Errors
    /// The folder, its manifest or its layout cannot be read.
    pub fn dataset(&self) -> Result<Option<Dataset>> {
        self.dataset.as_ref().map(|d| self.open.open(d)).transpose()
    }

    /// The files the prediction reads besides the model: the dataset's recordings, or the
    /// files and the layout given.
    pub fn inputs(&self, dataset: Option<&Dataset>) -> Vec<PathBuf> {
        let mut inputs = vec![self.model.clone()];
        match dataset {
            Some(dataset) => inputs.extend(dataset.files()),
            None => inputs.extend(self.files.iter().chain(&self.read.layout).cloned()),
        }
        inputs
    }

    /// The dataset's recordings to predict, in manifest order: those at `--speeds`, else all.
    ///
    /// # Errors
    /// A speed at which the dataset holds no recording.
    fn selected(&self, dataset: &Dataset) -> Result<Vec<usize>> {
        match &self.speeds {
            Some(speeds) => dataset.indices_at(speeds),
            None => Ok((0..dataset.entries.len()).collect()),
        }
    }

    /// `predictions` of the recordings `encoded` of `dataset` scored against their labels,
    /// with how many of them `model` was trained on (its training dataset's recordings at
    /// its training speeds; none of another dataset's), whose predictions test nothing.
    ///
    /// # Errors
    /// A label the model does not know, or `--speeds` at which `dataset` has no recordings.
    pub fn score(
        &self,
        model: &SavedModel,
        dataset: &Dataset,
        encoded: &[Encoded],
        predictions: &[crate::model::Prediction],
    ) -> Result<crate::model::Score> {
        let truth: Vec<String> = encoded.iter().map(|e| e.meta.label.clone()).collect();
        let which = self.selected(dataset)?;
        let fitted = trained_among(model.provenance(), dataset, &which);
        Ok(crate::model::Score {
            trained_on: fitted.max(model.training_recordings_met(encoded)?),
            ..model.score(&truth, predictions)?
        })
    }

    /// Encodes the recordings (`dataset`'s, else the files given) with `model`'s pipeline,
    /// saying where layouts came from and what conditioning noticed.
    ///
    /// # Errors
    /// A recording that cannot be read, or does not fit the model (sampled, for a model
    /// trained on events).
    pub fn encode(
        &self,
        model: &SavedModel,
        dataset: Option<&Dataset>,
        on: OnProgress,
    ) -> Result<Vec<Encoded>> {
        if let Some(dataset) = dataset {
            return encode_selected(model, dataset, &self.selected(dataset)?, on);
        }
        if self.speeds.is_some() {
            let why = "--speeds selects recordings of a --dataset; files given are each predicted";
            return Err(OptionsError::Conflict(why.into()).into());
        }
        let (encoded, from) = model.encode_files(&self.files, &self.read.reading()?)?;
        for note in ReadOptions::layout_notes(&from) {
            on(Progress::Say(&note));
        }
        checked(model, encoded, 0, on)
    }

    /// Every recording's per-bin decisions and end, as `stream` decides them.
    ///
    /// # Errors
    /// A model not trained with `--causal` (for sampled recordings), or a decision rule out
    /// of range.
    pub fn episodes(&self, model: &SavedModel, encoded: &[Encoded]) -> Result<Vec<Episode>> {
        // Events skip the conditioning a stream of samples needs: only a method without a
        // running form (the spectrum) is refused for them.
        let events = !encoded.is_empty() && encoded.iter().all(|e| e.from_events);
        let refused = match model.streams() {
            Err(why) if events && why != crate::causal::NO_RUNNING_SPECTRUM => Ok(()),
            other => other.map(|_| ()),
        };
        if let Err(why) = refused {
            let message = format!(
                "{}: --causal decides as a stream: {why}",
                self.model.display()
            );
            return Err(OptionsError::Conflict(message).into());
        }
        let window_ms = self.decision.window_ms(model)?;
        let rule = self.decision.rule()?;
        encoded
            .par_iter()
            .map(|e| model.episode(e, window_ms, rule))
            .collect()
    }
}

/// Encodes every recording of `dataset` with a model's pipeline and baseline.
/// Every recording of `dataset` (sampled or address events) encoded with `model`'s own
/// pipeline, as `predict --dataset` encodes them, and checked against what the model was
/// trained on (grid, populations, stamps).
///
/// # Errors
/// A recording that cannot be read or encoded, or one the model cannot take.
pub fn encode_for(model: &SavedModel, dataset: &Dataset, on: OnProgress) -> Result<Vec<Encoded>> {
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    encode_selected(model, dataset, &all, on)
}

/// [`encode_for`] on the recordings `which` of `dataset`.
fn encode_selected(
    model: &SavedModel,
    dataset: &Dataset,
    which: &[usize],
    on: OnProgress,
) -> Result<Vec<Encoded>> {
    let said = trained_among(model.provenance(), dataset, which);
    if let Some(advice) = seen_in_training(model.provenance(), dataset, which) {
        on(Progress::Advice(&advice));
    }
    let encoded = encode_dataset(model.pipeline(), model.baseline(), dataset, which, on)?;
    checked(model, encoded, said, on)
}

/// A warning when `dataset` is the one the model was trained on (the same fingerprint): of
/// the recordings `which`, those at the training speeds were fitted, so their predictions
/// test nothing.
fn seen_in_training(provenance: &Provenance, dataset: &Dataset, which: &[usize]) -> Option<String> {
    let seen = trained_among(provenance, dataset, which);
    (seen > 0).then(|| {
        format!(
            "{seen} of these {} recordings are ones the model was trained on (this is its training dataset{}): their predictions are no test of it; `neurotex evaluate` cross-validates, or predict recordings it has not seen",
            which.len(),
            match &provenance.speeds {
                None => String::new(),
                Some(speeds) => format!(", at {} mm/s", shown_speeds(speeds)),
            }
        )
    })
}

/// How many of the recordings `which` of `dataset` the model of `provenance` was trained
/// on: those at its training speeds when `dataset` is its training dataset (the same
/// fingerprint), else none.
fn trained_among(provenance: &Provenance, dataset: &Dataset, which: &[usize]) -> usize {
    if dataset.fingerprint().ok().as_deref() != Some(provenance.fingerprint.as_str()) {
        return 0;
    }
    match &provenance.speeds {
        None => which.len(),
        Some(speeds) => (which.iter())
            .filter(|&&i| {
                dataset.entries[i]
                    .speed()
                    .is_some_and(|s| speeds.contains(&s))
            })
            .count(),
    }
}

/// Speeds as `10, 20`.
fn shown_speeds(speeds: &[crate::Speed]) -> String {
    let shown: Vec<String> = speeds.iter().map(ToString::to_string).collect();
    shown.join(", ")
}

/// `encoded` once every recording passed the model's checks, the conditions said, and a
/// warning when more of them than the `said` already warned of meet the model as its own
/// training recordings.
fn checked(
    model: &SavedModel,
    encoded: Vec<Encoded>,
    said: usize,
    on: OnProgress,
) -> Result<Vec<Encoded>> {
    // Refused before anything else is said of them, --causal's needs included.
    for e in &encoded {
        model.check_source(e)?;
    }
    say_conditions(&encoded, on);
    let met = model.training_recordings_met(&encoded)?;
    if met > said {
        on(Progress::Advice(&format!(
            "{met} of these {} have exactly the features of recordings the model was trained on (the same recordings copied or imported again, or ones its features cannot tell from them): their predictions are the model's memory of its training set, no test of it; `neurotex evaluate` cross-validates, or predict recordings it has not seen",
            crate::words::counted(encoded.len(), "recording")
        )));
    }
    Ok(encoded)
}

fn encode_dataset(
    pipeline: &Pipeline,
    baseline: Baseline,
    dataset: &Dataset,
    which: &[usize],
    on: OnProgress,
) -> Result<Vec<Encoded>> {
    let layout_baseline = dataset.layout.baseline.unwrap_or_default();
    if layout_baseline != baseline {
        on(Progress::Say(&format!(
            "note: the model removes baseline `{baseline}` as in training; {} says `{layout_baseline}`",
            dataset.root.join("layout.toml").display()
        )));
    }
    on(Progress::Stage("encoding", which.len()));
    pipeline.encode_dataset(dataset, which, &|| on(Progress::Tick))
}
