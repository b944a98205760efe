//! The command line's workflows on a dataset folder, called from Python: `train` and
//! `predict --dataset` run here exactly as the CLI runs them (sampled recordings or
//! address events, the spiking network or a feature classifier), so a model trained on a
//! folder from Python is the CLI's model file, byte for byte. Python keeps only the
//! conversion of its keywords into the workflow's options.

use std::path::PathBuf;

use neurotex::classify::ClassifierChoice;
use neurotex::progress::Progress;
use neurotex::samples::MethodChoice;
use neurotex::workflows::train::TrainOptions;
use neurotex::workflows::{ClassifierOptions, KnnOptions, OpenOptions};
use neurotex::{Cell, Speed};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::open;
use crate::errors::{guarded, param};
use crate::model::{NativeModel, Said};
use crate::params;
use crate::spiking::NativeSpikingModel;

/// How a spiking network's training went: epochs run, the best epoch, its validation loss.
type TrainingLog = (usize, usize, f64);

/// The classifier `kind` (`None`: what `method` implies) with Python's knobs
/// `options`, as `train`'s options take it.
fn front_end_classifier(
    kind: Option<&str>,
    method: Option<MethodChoice>,
    options: &Bound<'_, PyDict>,
) -> PyResult<(KnnOptions, ClassifierOptions)> {
    let kind = kind.unwrap_or(match method {
        Some(MethodChoice::Spikes) => "snn",
        _ => "knn",
    });
    let choice = match kind {
        "snn" => ClassifierChoice::Snn(params::snn(options)?),
        other => params::classifier(other, options)?,
    };
    let knn = match choice {
        ClassifierChoice::Knn(p) => KnnOptions {
            k: p.k,
            no_standardize: !p.standardize,
        },
        _ => KnnOptions {
            k: neurotex::classify::KnnParams::default().k,
            no_standardize: false,
        },
    };
    let classifier = ClassifierOptions {
        classifier: Some(choice),
        ..ClassifierOptions::default()
    };
    Ok((knn, classifier))
}

/// Trains on the dataset folder `path` as `neurotex train --dataset PATH` does, through
/// its workflow: `method` and `classifier` (`None`: the CLI's defaults, each implying the
/// other for the spiking network), the classifier's `classifier_options`, the stage
/// `options`, the recordings at `speeds` only (all when `None`), `taxel` as `"row,col"`.
/// Returns the model, how a spiking network's training went (`None` for a feature
/// classifier), and what the workflow said.
#[pyfunction]
#[pyo3(signature = (path, method, classifier, classifier_options, options, speeds=None, taxel=None))]
#[allow(clippy::too_many_arguments)]
fn train_dataset(
    py: Python<'_>,
    path: PathBuf,
    method: Option<&str>,
    classifier: Option<&str>,
    classifier_options: &Bound<'_, PyDict>,
    options: &Bound<'_, PyDict>,
    speeds: Option<Vec<f64>>,
    taxel: Option<&str>,
) -> PyResult<(Py<PyAny>, Option<TrainingLog>, Vec<String>)> {
    let stages = params::stage_options(options)?;
    let method = method
        .map(|m| m.parse::<MethodChoice>().map_err(param))
        .transpose()?;
    let (knn, classifier) = front_end_classifier(classifier, method, classifier_options)?;
    let speeds = speeds
        .map(|v| v.into_iter().map(Speed::new).collect::<Result<Vec<_>, _>>())
        .transpose()
        .map_err(param)?;
    let taxel = taxel
        .map(|t| t.parse::<Cell>().map_err(param))
        .transpose()?;
    let train = TrainOptions {
        dataset: path.clone(),
        speeds,
        method,
        taxel,
        knn,
        classifier,
        open: OpenOptions::default(),
    };
    let dataset = open(&path)?;
    let said = Said::default();
    let on = |p: Progress| said.hear(p);
    if train.spiking() {
        let trained = py.detach(|| guarded(|| train.run_spiking(&dataset, &stages, &on)))?;
        let log = &trained.log;
        let log = (log.epochs, log.best_epoch, log.validation_loss);
        let model = NativeSpikingModel {
            inner: trained.model,
        };
        return Ok((Py::new(py, model)?.into_any(), Some(log), said.lines()));
    }
    let trained = py.detach(|| guarded(|| train.run(&dataset, &stages, &on)))?;
    let model = NativeModel {
        inner: trained.model,
    };
    Ok((Py::new(py, model)?.into_any(), None, said.lines()))
}

/// Registers the workflows.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(train_dataset, m)?)
}
