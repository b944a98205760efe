//! Saved models: the CLI's model files read, applied to arrays, trained and written.

use std::path::PathBuf;

use neurotex::analysis::{Columns, FeatureTable};
use neurotex::model::{Model as LibModel, Provenance};
use neurotex::pipeline::{Encoded, Pipeline};
use neurotex::Cell;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::convert::{Samples, SamplesView};
use crate::errors::{guarded, param, raise, Kind};
use crate::{info_of, params, Failure, InfoTuple};

/// A trained classifier with its pipeline, as `neurotex train` writes it.
#[pyclass(module = "neurotex._native", frozen)]
pub struct NativeModel {
    pub(crate) inner: LibModel,
}

/// Encodes recordings with the model's own pipeline, in parallel without the GIL.
fn encode_with(
    py: Python<'_>,
    model: &LibModel,
    recordings: &[Bound<'_, PyAny>],
    infos: Vec<InfoTuple>,
) -> PyResult<Vec<Encoded>> {
    if recordings.len() != infos.len() {
        return Err(raise(
            Kind::Parameter,
            "one description per recording is needed",
        ));
    }
    let samples = recordings
        .iter()
        .enumerate()
        .map(|(i, r)| Samples::borrow(r, &format!("recording {i}")))
        .collect::<PyResult<Vec<_>>>()?;
    let views: Vec<SamplesView<'_>> = samples.iter().map(Samples::view).collect();
    let infos: Vec<_> = infos.into_iter().map(info_of).collect();
    let result: Result<Vec<Encoded>, Failure> = py.detach(|| {
        crate::guarded_failure(|| {
            views
                .par_iter()
                .zip(infos.par_iter())
                .map(|(view, info)| {
                    let rec = view.recording(info).map_err(Failure::Input)?;
                    model
                        .encode(&rec)
                        .map_err(|e| Failure::Library(e.in_recording(&info.name)))
                })
                .collect()
        })
    });
    Ok(result?)
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
        let encoded = encode_with(py, &self.inner, &recordings, infos)?;
        let predictions = py.detach(|| guarded(|| self.inner.predict(&encoded)))?;
        let classes = self.inner.labels().len();
        let shares: Vec<f64> = predictions.iter().flat_map(|p| p.shares.clone()).collect();
        let shares = ndarray::Array2::from_shape_vec((predictions.len(), classes), shares)
            .map_err(|e| raise(Kind::Internal, e.to_string()))?;
        let labels = predictions.into_iter().map(|p| p.predicted).collect();
        Ok((labels, shares.into_pyarray(py)))
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
}

/// Trains a model on recordings (arrays with their labels) as `neurotex train` does on a
/// dataset folder. `fingerprint` identifies the training data in the file; `taxel` is
/// `"row,col"` for the taxel method.
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
    let params = params::pipeline(options)?;
    let choice = params::classifier(classifier, classifier_options)?;
    let pipeline = Pipeline::new(params.clone()).map_err(param)?;
    let dataset_baseline = crate::dataset_baseline(baseline)?;
    let columns = match (method, taxel) {
        (neurotex::pipeline::Method::Taxel, Some(t)) => {
            Columns::Taxel(t.parse::<Cell>().map_err(param)?)
        }
        (_, Some(_)) => {
            return Err(raise(
                Kind::Parameter,
                "taxel applies only to method=\"taxel\"",
            ))
        }
        (_, None) => Columns::All,
    };
    let samples = recordings
        .iter()
        .enumerate()
        .map(|(i, r)| Samples::borrow(r, &format!("recording {i}")))
        .collect::<PyResult<Vec<_>>>()?;
    let infos: Vec<_> = infos.into_iter().map(info_of).collect();
    let encoded = crate::encode_all(py, &samples, infos, &pipeline, dataset_baseline)?;
    let inner = py.detach(|| {
        guarded(|| {
            let grid = neurotex::recording::one_grid(encoded.iter().map(|e| {
                let s = &e.spikes;
                (
                    e.meta.file.as_str(),
                    neurotex::Grid::masked(s.rows, s.cols, s.present.clone())
                        .expect("the encoder's grid is valid"),
                )
            }))?;
            let extractor = pipeline.extractor(&grid)?;
            let table = FeatureTable::build(&encoded, &extractor, method)?;
            if let Columns::Taxel(cell) = columns {
                grid.locate(cell)?;
            }
            let provenance = Provenance {
                fingerprint,
                baseline: dataset_baseline,
                speeds: None,
                gain_calibration: None,
                // Python trains offline models; a causal model (the CLI's `--causal`) is
                // not offered here yet.
                median_duration_ms: None,
            };
            LibModel::train(&params, &table, columns, choice, provenance)
        })
    })?;
    Ok(NativeModel { inner })
}

/// Registers the model class and training.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeModel>()?;
    m.add_function(wrap_pyfunction!(train_model, m)?)?;
    Ok(())
}
