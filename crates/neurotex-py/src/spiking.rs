//! Spiking models (`neurotex train --classifier snn`): read, applied to arrays, and moved
//! to and from NIR graphs.

use std::path::PathBuf;

use neurotex::pipeline::Encoded;
use neurotex::spiking_model::SpikingModel;
use neurotex::workflows::export::{export_nir, NirConvention};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{Batch, InfoTuple};
use crate::errors::{guarded, raise, Kind};
use crate::model::{predict_recordings, Training};
use crate::params;

/// A trained spiking network with its pipeline.
#[pyclass(module = "neurotex._native", frozen)]
pub struct NativeSpikingModel {
    pub(crate) inner: SpikingModel,
}

#[pymethods]
impl NativeSpikingModel {
    /// Reads a spiking model file, or a NIR graph written by neurotex.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let inner = py.detach(|| guarded(|| SpikingModel::load(&path)))?;
        Ok(NativeSpikingModel { inner })
    }

    /// Reads a NIR graph; `like` gives the pipeline, grid and labels of a graph that does
    /// not carry neurotex's.
    #[staticmethod]
    #[pyo3(signature = (path, like=None))]
    fn from_nir(
        py: Python<'_>,
        path: PathBuf,
        like: Option<PyRef<'_, NativeSpikingModel>>,
    ) -> PyResult<Self> {
        let like = like.map(|l| l.inner.clone());
        let inner = py.detach(|| guarded(|| SpikingModel::from_nir(&path, like.as_ref())))?;
        Ok(NativeSpikingModel { inner })
    }

    /// Writes the model file, whole or not at all.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| guarded(|| self.inner.save(&path)))
    }

    /// Writes the network as a NIR graph for the importer `convention` names (`nir`,
    /// `snntorch`, `norse`, `sinabs`, `rockpool`).
    fn write_nir(&self, py: Python<'_>, path: PathBuf, convention: &str) -> PyResult<()> {
        let convention = match convention {
            "nir" | "physical" => NirConvention::Nir,
            "snntorch" => NirConvention::Snntorch,
            "norse" => NirConvention::Norse,
            "sinabs" => NirConvention::Sinabs,
            "rockpool" => NirConvention::Rockpool,
            other => {
                return Err(raise(
                    Kind::Parameter,
                    format!(
                        "for_tool must be nir, snntorch, norse, sinabs or rockpool, got {other:?}"
                    ),
                ))
            }
        };
        py.detach(|| guarded(|| export_nir(&self.inner, &path, convention)))
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

    /// The classes, in the order of the network's outputs.
    /// Predicts every recording of a dataset folder (sampled or address events) as
    /// `neurotex predict --dataset` does: `(labels, shares (n, classes))`.
    fn predict_dataset<'py>(
        &self,
        py: Python<'py>,
        path: PathBuf,
    ) -> PyResult<crate::model::FolderPredictions<'py>> {
        let model = neurotex::saved::SavedModel::from(self.inner.clone());
        crate::model::predict_dataset(py, model, path)
    }

    #[getter]
    fn labels(&self) -> Vec<String> {
        self.inner.labels().to_vec()
    }

    /// `(inputs, hidden, classes, dt_ms)` of the network.
    #[getter]
    fn shape(&self) -> (usize, usize, usize, u32) {
        let n = self.inner.network();
        (n.inputs, n.hidden, n.classes, n.dt_ms)
    }
}

/// Trains a spiking network (`neurotex train --classifier snn`) on recordings (arrays with
/// their infos): the stage options calibrated on them, then the network on their spikes;
/// `(model, epochs run, best epoch, its validation loss)`.
#[pyfunction]
#[pyo3(signature = (recordings, infos, options, snn_options, fingerprint, baseline=None))]
fn train_spiking_model<'py>(
    py: Python<'py>,
    recordings: Vec<Bound<'py, PyAny>>,
    infos: Vec<InfoTuple>,
    options: &Bound<'py, PyDict>,
    snn_options: &Bound<'py, PyDict>,
    fingerprint: String,
    baseline: Option<&str>,
) -> PyResult<(NativeSpikingModel, usize, usize, f64)> {
    let stages = params::stages(options)?;
    let snn = params::snn(snn_options)?;
    let baseline = params::baseline(baseline)?;
    let batch = Batch::new(&recordings, infos)?;
    let view = batch.view();
    let (inner, log) = py.detach(|| {
        guarded(|| {
            let t = Training::encode(&stages, &view, baseline, fingerprint)?;
            let params = t.pipeline.params();
            SpikingModel::train(params, &t.encoded, &t.grid, (snn, &|| ()), t.provenance)
        })
    })?;
    let model = NativeSpikingModel { inner };
    Ok((model, log.epochs, log.best_epoch, log.validation_loss))
}

/// Whether the file claims to be a spiking model (its format, or a NIR graph).
#[pyfunction]
fn is_spiking_model(path: PathBuf) -> bool {
    SpikingModel::is_spiking(&path)
}

/// Adds the class and training to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeSpikingModel>()?;
    m.add_function(wrap_pyfunction!(is_spiking_model, m)?)?;
    m.add_function(wrap_pyfunction!(train_spiking_model, m)?)
}
