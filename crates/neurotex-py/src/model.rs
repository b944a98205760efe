//! Saved models: the CLI's model files read, applied to arrays, trained and written.

use std::path::PathBuf;

use neurotex::analysis::{Columns, FeatureTable};
use neurotex::model::{Model as LibModel, Prediction, Provenance};
use neurotex::pipeline::{Encoded, Method, Pipeline};
use neurotex::recording::Baseline;
use neurotex::{Cell, Grid};
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::calibrate::{calibrated, object};
use crate::convert::{Batch, BatchView, InfoTuple};
use crate::errors::{guarded, param, raise, Kind};
use crate::params;

/// A trained classifier with its pipeline, as `neurotex train` writes it.
#[pyclass(module = "neurotex._native", frozen)]
pub struct NativeModel {
    pub(crate) inner: LibModel,
}

#[pymethods]
impl NativeModel {
    /// Reads a model file written by `neurotex train` or `Model.save`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let inner = py.detach(|| guarded(|| LibModel::load(&path)))?;
        Ok(NativeModel { inner })
    }

    /// Writes the model file, whole or not at all.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| guarded(|| self.inner.save(&path)))
    }

    /// Predicts recordings: `(predicted labels, shares (n, classes))`.
    fn predict<'py>(
        &self,
        py: Python<'py>,
        recordings: Vec<Bound<'py, PyAny>>,
        infos: Vec<InfoTuple>,
    ) -> PyResult<(Vec<String>, Bound<'py, PyArray2<f64>>)> {
        let m = &self.inner;
        let predict = |encoded: &[Encoded]| m.predict(encoded);
        let model = (m.pipeline(), m.baseline(), m.labels().len());
        predict_recordings(py, &recordings, infos, model, predict)
    }

    /// Predicts every recording of a dataset folder (sampled or address events) as
    /// `neurotex predict --dataset` does: `(labels, shares (n, classes))`.
    fn predict_dataset<'py>(
        &self,
        py: Python<'py>,
        path: PathBuf,
    ) -> PyResult<FolderPredictions<'py>> {
        let model = neurotex::saved::SavedModel::from(self.inner.clone());
        predict_dataset(py, model, path)
    }

    /// The classes, in the order of the shares' columns.
    #[getter]
    fn labels(&self) -> Vec<String> {
        self.inner.labels().to_vec()
    }

    /// The feature method's name.
    #[getter]
    fn method(&self) -> &'static str {
        self.inner.features().method.name()
    }

    /// The feature columns the classifier uses.
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.inner.features().columns.clone()
    }

    /// The classifier, as the CLI prints it.
    #[getter]
    fn classifier(&self) -> String {
        self.inner.classifier().to_string()
    }

    /// The number of training recordings.
    #[getter]
    fn n_training(&self) -> usize {
        self.inner.n_training()
    }

    /// The pipeline's gain.
    #[getter]
    fn gain(&self) -> f64 {
        self.inner.params().encoder.gain
    }

    /// The dataset fingerprint the model was trained on.
    #[getter]
    fn fingerprint(&self) -> String {
        self.inner.provenance().fingerprint.clone()
    }

    /// How `gain="auto"` (`--gain auto`) chose the gain, as a dict; `None` for a gain
    /// given as a number.
    #[getter]
    fn gain_calibration(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        object(py, &self.inner.provenance().gain_calibration)
    }

    /// The causal conditioning (`offsets`, `scale`) as a dict; `None` for an offline model.
    #[getter]
    fn causal(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        object(py, &self.inner.causal())
    }

    /// A causal model's median training phase in ms (a stream's default window).
    #[getter]
    fn median_duration_ms(&self) -> Option<usize> {
        self.inner.provenance().median_duration_ms
    }
}

/// Trains a model on recordings (arrays with their labels) as `neurotex train` does on a
/// dataset folder: under `gain="auto"` or `causal=True` (the CLI's `--causal`) the pipeline
/// is calibrated on these recordings first and the calibration stored in the model.
/// `fingerprint` identifies the training data in the file; `taxel` is `"row,col"` for the
/// taxel method.
#[pyfunction]
#[pyo3(signature = (recordings, infos, method, options, classifier, classifier_options, fingerprint, baseline=None, taxel=None))]
#[allow(clippy::too_many_arguments)]
fn train_model<'py>(
    py: Python<'py>,
    recordings: Vec<Bound<'py, PyAny>>,
    infos: Vec<InfoTuple>,
    method: &str,
    options: &Bound<'py, PyDict>,
    classifier: &str,
    classifier_options: &Bound<'py, PyDict>,
    fingerprint: String,
    baseline: Option<&str>,
    taxel: Option<&str>,
) -> PyResult<NativeModel> {
    let method = params::method(method)?;
    let stages = params::stages(options)?;
    let choice = params::classifier(classifier, classifier_options)?;
    let dataset_baseline = params::baseline(baseline)?;
    let columns = match (method, taxel) {
        (Method::Taxel, Some(t)) => Columns::Taxel(t.parse::<Cell>().map_err(param)?),
        (_, Some(_)) => {
            return Err(raise(
                Kind::Parameter,
                "taxel applies only to method=\"taxel\"",
            ))
        }
        (_, None) => Columns::All,
    };
    let batch = Batch::new(&recordings, infos)?;
    let view = batch.view();
    let inner = py.detach(|| {
        guarded(|| {
            let t = Training::encode(&stages, &view, dataset_baseline, fingerprint)?;
            let extractor = t.pipeline.extractor(&t.grid)?;
            let table = FeatureTable::build(&t.encoded, &extractor, method)?;
            if let Columns::Taxel(cell) = columns {
                t.grid.locate(cell)?;
            }
            LibModel::train(t.pipeline.params(), &table, columns, choice, t.provenance)
        })
    })?;
    Ok(NativeModel { inner })
}

/// Training recordings encoded with the pipeline calibrated on them.
pub(crate) struct Training {
    /// The pipeline, gain and causal conditioning calibrated.
    pub pipeline: Pipeline,
    /// The recordings' spikes.
    pub encoded: Vec<Encoded>,
    /// Their grid.
    pub grid: Grid,
    /// What a model keeps of them.
    pub provenance: Provenance,
}

impl Training {
    /// Calibrates the stage options `stages` on every recording of `view` (as
    /// `neurotex train` does), then encodes them.
    pub(crate) fn encode(
        stages: &params::Stages,
        view: &BatchView<'_>,
        baseline: Baseline,
        fingerprint: String,
    ) -> neurotex::Result<Training> {
        let all: Vec<usize> = (0..view.len()).collect();
        let c = calibrated(stages, &|i| view.load(i), &all, baseline)?;
        let encoded = view.encode(|rec| c.pipeline.encode(rec, baseline))?;
        let grid = neurotex::pipeline::shared_grid(&encoded)?;
        let provenance = Provenance {
            fingerprint,
            baseline,
            speeds: None,
            gain_calibration: c.gain,
            median_duration_ms: c.causal.map(|c| c.median_duration_ms),
            layout: None,
        };
        Ok(Training {
            pipeline: c.pipeline,
            encoded,
            grid,
            provenance,
        })
    }
}

/// Recordings (arrays with their infos) encoded with a model's `(pipeline, baseline,
/// classes)` and predicted by `predict`, with the GIL released: `(labels, shares (n,
/// classes))`.
pub(crate) fn predict_recordings<'py>(
    py: Python<'py>,
    recordings: &[Bound<'py, PyAny>],
    infos: Vec<InfoTuple>,
    (pipeline, baseline, classes): (&Pipeline, Baseline, usize),
    predict: impl Fn(&[Encoded]) -> neurotex::Result<Vec<Prediction>> + Sync,
) -> PyResult<(Vec<String>, Bound<'py, PyArray2<f64>>)> {
    let batch = Batch::new(recordings, infos)?;
    let view = batch.view();
    let predictions = py.detach(|| {
        guarded(|| {
            let encoded = view.encode(|rec| pipeline.encode(rec, baseline))?;
            predict(&encoded)
        })
    })?;
    labels_and_shares(py, predictions, classes)
}

/// A folder's predictions: the labels and each class's share `(n, classes)`.
pub(crate) type FolderPredictions<'py> = (Vec<String>, Bound<'py, PyArray2<f64>>);

/// A model applied to every recording of the dataset folder `path` (sampled or address
/// events) as `neurotex predict --dataset PATH` applies it: `(predicted labels, shares
/// (n, classes))`; what the workflow says goes to Python's log as it is said.
pub(crate) fn predict_dataset<'py>(
    py: Python<'py>,
    model: neurotex::saved::SavedModel,
    path: PathBuf,
) -> PyResult<FolderPredictions<'py>> {
    let dataset = crate::convert::open(&path)?;
    let said = Said::default();
    let on = |p: neurotex::progress::Progress| said.hear(p);
    let predictions = crate::interrupt::watched(py, || {
        guarded(|| {
            let encoded = neurotex::workflows::predict::encode_for(&model, &dataset, &on)?;
            model.predict(&encoded)
        })
    })?;
    labels_and_shares(py, predictions, model.labels().len())
}

/// What a workflow says on its way (advice, calibrations, pieces taken) and how far its
/// stages are, put on Python's `neurotex` logger as it happens, by the package's
/// `_log_said` (advice at WARNING, the rest at INFO), so that a long run speaks while it
/// runs: each stage's start and each tenth of its steps, as the command line's bar moves.
#[derive(Default)]
pub(crate) struct Said(std::sync::Mutex<Stage>);

/// The stage under way: its name, steps and steps done.
#[derive(Default)]
pub(crate) struct Stage {
    name: String,
    steps: usize,
    done: usize,
}

impl Said {
    /// Logs a workflow's event, if it is one to log. Called from the threads of a workflow
    /// run with the GIL released (every caller runs it inside `py.detach`), so taking the
    /// GIL here waits on no thread of the run.
    pub(crate) fn hear(&self, progress: neurotex::progress::Progress) {
        use neurotex::progress::Progress;
        // A Ctrl-C during the call ends the run here ([`crate::interrupt`]).
        neurotex::progress::stop_point();
        // Advice is logged as a warning, the rest as information.
        let (line, warning) = match progress {
            Progress::Say(s) => (s.to_string(), false),
            Progress::Advice(s) => (s.to_string(), true),
            Progress::Stage(name, steps) => {
                if let Ok(mut stage) = self.0.lock() {
                    *stage = Stage {
                        name: name.to_string(),
                        steps,
                        done: 0,
                    };
                }
                (format!("{name} ({steps} steps)"), false)
            }
            Progress::Tick | Progress::Done(..) | Progress::Skipped(..) => {
                let Some(line) = self.0.lock().ok().and_then(|mut s| s.step()) else {
                    return;
                };
                (line, false)
            }
            Progress::TooSmall(_) => return,
        };
        log_now(line, warning);
    }
}

impl Stage {
    /// One step done: the line to log when it ends a tenth of the stage.
    fn step(&mut self) -> Option<String> {
        self.done += 1;
        let tenth = |d: usize| d * 10 / self.steps.max(1);
        (self.done <= self.steps && tenth(self.done) > tenth(self.done - 1))
            .then(|| format!("{} {}/{}", self.name, self.done, self.steps))
    }
}

/// Puts `line` on Python's `neurotex` logger through the package's `_log_said`, at WARNING
/// when it is a `warning`, else at INFO.
fn log_now(line: String, warning: bool) {
    Python::attach(|py| {
        let logged = py
            .import("neurotex")
            .and_then(|m| m.getattr("_log_said")?.call1((line, warning)).map(drop));
        if let Err(e) = logged {
            if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                // A Ctrl-C that reached the logging code: raised again once the workflow
                // returns, as a Ctrl-C during a run always is.
                // SAFETY: `PyErr_SetInterrupt` only sets the interpreter's flag, and the
                // GIL is held.
                unsafe { pyo3::ffi::PyErr_SetInterrupt() };
            }
        }
    });
}

/// Predictions as `(labels, shares (n, classes))`.
pub(crate) fn labels_and_shares(
    py: Python<'_>,
    predictions: Vec<Prediction>,
    classes: usize,
) -> PyResult<(Vec<String>, Bound<'_, PyArray2<f64>>)> {
    let shares: Vec<f64> = predictions.iter().flat_map(|p| p.shares.clone()).collect();
    let shares = ndarray::Array2::from_shape_vec((predictions.len(), classes), shares)
        .map_err(|e| raise(Kind::Internal, e.to_string()))?;
    let labels = predictions.into_iter().map(|p| p.predicted).collect();
    Ok((labels, shares.into_pyarray(py)))
}

/// Registers the model class and training.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeModel>()?;
    m.add_function(wrap_pyfunction!(train_model, m)?)?;
    Ok(())
}
