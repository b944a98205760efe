//! Spiking models (`neurotex train --classifier snn`): read, applied to arrays, and moved
//! to and from NIR graphs.

use std::path::PathBuf;

use neurotex::spiking_model::SpikingModel;
use neurotex::workflows::export::{export_nir, NirConvention};
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;

use crate::convert::{Batch, InfoTuple};
use crate::errors::{guarded, raise, Kind};

/// A trained spiking network with its pipeline.
#[pyclass(module = "neurotex._native", frozen)]
pub struct NativeSpikingModel {
    inner: SpikingModel,
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

    /// Writes the network as a NIR graph (`convention`: `physical` or `snntorch`).
    fn write_nir(&self, py: Python<'_>, path: PathBuf, convention: &str) -> PyResult<()> {
        let convention = match convention {
            "physical" => NirConvention::Physical,
            "snntorch" => NirConvention::Snntorch,
            other => {
                return Err(raise(
                    Kind::Parameter,
                    format!("convention must be physical or snntorch, got {other:?}"),
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
        let batch = Batch::new(&recordings, infos)?;
        let view = batch.view();
        let predictions = py.detach(|| {
            guarded(|| {
                let encoded =
                    view.encode(|rec| self.inner.pipeline().encode(rec, self.inner.baseline()))?;
                self.inner.predict(&encoded)
            })
        })?;
        let classes = self.inner.labels().len();
        let shares: Vec<f64> = predictions.iter().flat_map(|p| p.shares.clone()).collect();
        let shares = ndarray::Array2::from_shape_vec((predictions.len(), classes), shares)
            .map_err(|e| raise(Kind::Internal, e.to_string()))?;
        let labels = predictions.into_iter().map(|p| p.predicted).collect();
        Ok((labels, shares.into_pyarray(py)))
    }

    /// The classes, in the order of the network's outputs.
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

/// Adds the class to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeSpikingModel>()
}
