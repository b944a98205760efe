//! The command line's workflows on a dataset folder, called from Python: `train`,
//! `evaluate`, `compare` and `predict --dataset` run here exactly as the CLI runs them (sampled recordings or
//! address events, the spiking network or a feature classifier), so a model trained on a
//! folder from Python is the CLI's model file, byte for byte. Python keeps only the
//! conversion of its keywords into the workflow's options.

use std::path::PathBuf;

use neurotex::classify::ClassifierChoice;
use neurotex::progress::Progress;
use neurotex::recording::Selection;
use neurotex::samples::MethodChoice;
use neurotex::workflows::compare::CompareOptions;
use neurotex::workflows::evaluate::EvaluateOptions;
use neurotex::workflows::train::TrainOptions;
use neurotex::workflows::{ClassifierOptions, KnnOptions, OpenOptions, SnnOptions};
use neurotex::{Cell, Speed};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::open;
use crate::errors::{guarded, param};
use crate::interrupt::watched;
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
/// Returns the model and how a spiking network's training went (`None` for a feature
/// classifier); what the workflow says goes to Python's log as it is said.
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
) -> PyResult<(Py<PyAny>, Option<TrainingLog>)> {
    let stages = params::stage_options(options)?;
    let method = parsed::<MethodChoice>(method)?;
    let (knn, classifier) = front_end_classifier(classifier, method, classifier_options)?;
    let speeds = speeds_of(speeds)?;
    let taxel = parsed::<Cell>(taxel)?;
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
        let trained = watched(py, || guarded(|| train.run_spiking(&dataset, &stages, &on)))?;
        if let Some(note) = trained.at_the_cap() {
            on(Progress::Advice(&note));
        }
        let log = &trained.log;
        let log = (log.epochs, log.best_epoch, log.validation_loss);
        let model = NativeSpikingModel {
            inner: trained.model,
        };
        return Ok((Py::new(py, model)?.into_any(), Some(log)));
    }
    let trained = watched(py, || guarded(|| train.run(&dataset, &stages, &on)))?;
    let model = NativeModel {
        inner: trained.model,
    };
    Ok((Py::new(py, model)?.into_any(), None))
}

/// Speeds in mm/s as the library's, checked.
fn speeds_of(speeds: Option<Vec<f64>>) -> PyResult<Option<Vec<Speed>>> {
    speeds
        .map(|v| v.into_iter().map(Speed::new).collect::<Result<Vec<_>, _>>())
        .transpose()
        .map_err(param)
}

/// A value as the command line types it (`"2,3"` for a taxel, `"trial=0,1"` for a
/// selection), parsed by the library's own parser.
fn parsed<T: std::str::FromStr<Err = neurotex::error::ParamError>>(
    text: Option<&str>,
) -> PyResult<Option<T>> {
    text.map(|t| t.parse::<T>().map_err(param)).transpose()
}

/// Evaluates on the dataset folder `path` as `neurotex evaluate --dataset PATH --json`
/// does, through its workflow: the method and classifier as `train_dataset` takes them,
/// the cross-validation's `folds`, `repeats` and `seed` (`None`: the CLI's defaults), or a
/// train/test split by speeds or by manifest column (`train_where="trial=0,1"`),
/// `group_by`, and the encodings of every recording (`encoder_draws`). Returns the
/// evaluation as the CLI's JSON object; what the workflow says goes to Python's log as it
/// is said.
#[pyfunction]
#[pyo3(signature = (path, method, classifier, classifier_options, options, folds=None,
    repeats=None, seed=0, speeds=None, train_speeds=None, test_speeds=None, train_where=None,
    test_where=None, group_by=None, taxel=None, tau_ms=None, encoder_draws=1))]
#[allow(clippy::too_many_arguments)]
fn evaluate_dataset(
    py: Python<'_>,
    path: PathBuf,
    method: Option<&str>,
    classifier: Option<&str>,
    classifier_options: &Bound<'_, PyDict>,
    options: &Bound<'_, PyDict>,
    folds: Option<usize>,
    repeats: Option<usize>,
    seed: u64,
    speeds: Option<Vec<f64>>,
    train_speeds: Option<Vec<f64>>,
    test_speeds: Option<Vec<f64>>,
    train_where: Option<&str>,
    test_where: Option<&str>,
    group_by: Option<String>,
    taxel: Option<&str>,
    tau_ms: Option<f64>,
    encoder_draws: usize,
) -> PyResult<Py<PyAny>> {
    let stages = params::stage_options(options)?;
    let method = parsed::<MethodChoice>(method)?;
    let (knn, classifier) = front_end_classifier(classifier, method, classifier_options)?;
    if train_speeds.is_some() != test_speeds.is_some()
        || train_where.is_some() != test_where.is_some()
    {
        let why = "a train/test split needs both sets: train_speeds with test_speeds, train_where with test_where";
        return Err(crate::errors::raise(crate::errors::Kind::Parameter, why));
    }
    let cv = neurotex::classify::CvParams::default();
    let evaluate = EvaluateOptions {
        dataset: path.clone(),
        method,
        tau_ms: tau_ms.unwrap_or(neurotex::samples::STANDARD_TAU_MS),
        taxel: parsed::<Cell>(taxel)?,
        knn,
        folds: folds.unwrap_or(cv.folds),
        seed,
        repeats: repeats.unwrap_or(cv.repeats),
        encoder_draws,
        speeds: speeds_of(speeds)?,
        train_speeds: speeds_of(train_speeds)?,
        test_speeds: speeds_of(test_speeds)?,
        train_where: parsed::<Selection>(train_where)?,
        test_where: parsed::<Selection>(test_where)?,
        group_by,
        classifier,
        open: OpenOptions::default(),
    };
    let dataset = open(&path)?;
    let said = Said::default();
    let on = |p: Progress| said.hear(p);
    let evaluated = watched(py, || guarded(|| evaluate.run(&dataset, &stages, &on)))?;
    let json = evaluated
        .json()
        .map_err(|e| crate::errors::raise(crate::errors::Kind::Internal, e.to_string()))?;
    crate::convert::to_object(py, &json)
}

/// A comma-separated list as the command line takes it, or `standard` when `None`.
fn listed(names: Option<Vec<String>>, standard: &str) -> Vec<String> {
    names.unwrap_or_else(|| standard.split(',').map(str::to_string).collect())
}

/// Compares candidates on the dataset folder `path` as `neurotex compare --dataset PATH
/// --json` does, through its workflow: `encodings`, `methods` and `classifiers` (`None`:
/// the CLI's standard sets), the protocol (`per`, `hold_out`, or `train_where` with
/// `test_where`; pooled without), `group_by`, the cross-validation's `folds`, `repeats`
/// and `seed` (`None`: the CLI's), `nested` selection with its `inner_folds` (`None`: each
/// of the other outer folds held out in turn; refused without `nested`, as
/// `--inner-folds` is), KNN's `knn` knobs, the network's `snn` knobs and the encodings of
/// every recording (`encoder_draws`). With `out`, also writes compare.json, compare.md and the
/// figures there, as `--out`. Returns the comparison as the CLI's JSON object; what the
/// workflow says goes to Python's log as it is said.
#[pyfunction]
#[pyo3(signature = (path, options, knn, snn, encodings=None, methods=None, classifiers=None,
    speeds=None, per=None, hold_out=None, train_where=None, test_where=None, group_by=None,
    folds=None, repeats=None, seed=0, nested=false, inner_folds=None, tau_ms=None, out=None,
    encoder_draws=1))]
#[allow(clippy::too_many_arguments)]
fn compare_dataset(
    py: Python<'_>,
    path: PathBuf,
    options: &Bound<'_, PyDict>,
    knn: &Bound<'_, PyDict>,
    snn: &Bound<'_, PyDict>,
    encodings: Option<Vec<String>>,
    methods: Option<Vec<String>>,
    classifiers: Option<Vec<String>>,
    speeds: Option<Vec<f64>>,
    per: Option<String>,
    hold_out: Option<String>,
    train_where: Option<&str>,
    test_where: Option<&str>,
    group_by: Option<String>,
    folds: Option<usize>,
    repeats: Option<usize>,
    seed: u64,
    nested: bool,
    inner_folds: Option<usize>,
    tau_ms: Option<f64>,
    out: Option<PathBuf>,
    encoder_draws: usize,
) -> PyResult<Py<PyAny>> {
    use neurotex::compare::candidates as standard;
    let stages = params::stage_options(options)?;
    let (knn, _) = front_end_classifier(Some("knn"), None, knn)?;
    let snn_knobs = params::knobs_given("snn", snn)?;
    let chosen = [per.is_some(), hold_out.is_some(), train_where.is_some()];
    if chosen.iter().filter(|&&c| c).count() > 1 || train_where.is_some() != test_where.is_some() {
        let why = "one protocol at a time: per, hold_out, or train_where with test_where";
        return Err(crate::errors::raise(crate::errors::Kind::Parameter, why));
    }
    if inner_folds.is_some() && !nested {
        let why = "inner_folds sets nested selection's inner folds: give it only with nested=True";
        return Err(crate::errors::raise(crate::errors::Kind::Parameter, why));
    }
    let cv = neurotex::classify::CvParams::default();
    let compare = CompareOptions {
        dataset: path.clone(),
        speeds: speeds_of(speeds)?,
        per,
        hold_out,
        train_where: parsed::<Selection>(train_where)?,
        test_where: parsed::<Selection>(test_where)?,
        group_by,
        encodings: listed(encodings, standard::STANDARD_ENCODINGS),
        methods: listed(methods, standard::STANDARD_METHODS),
        classifiers: listed(classifiers, standard::STANDARD_CLASSIFIERS),
        tau_ms: tau_ms.unwrap_or(standard::STANDARD_TAU_MS),
        knn,
        snn: SnnOptions { knobs: snn_knobs },
        folds: folds.unwrap_or(cv.folds),
        repeats: repeats.unwrap_or(cv.repeats),
        seed,
        nested,
        inner_folds,
        encoder_draws,
        open: OpenOptions::default(),
    };
    let dataset = open(&path)?;
    let said = Said::default();
    let on = |p: Progress| said.hear(p);
    let comparison = watched(py, || {
        guarded(|| {
            // As `neurotex compare --out`: the folder claimed and checked before the run
            // (an earlier output of neurotex is replaced whole, anything else refused).
            let _claim = out
                .as_deref()
                .map(neurotex::io::claim_output_dir)
                .transpose()?;
            let comparison = compare.run(&dataset, &stages, &on)?;
            if let Some(dir) = &out {
                neurotex::report::comparison::write_comparison(dir, &comparison, &path)?;
            }
            Ok(comparison)
        })
    })?;
    crate::convert::to_object(py, &comparison)
}

/// Registers the workflows.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(train_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(compare_dataset, m)?)
}
