//! `gain="auto"` and `causal=True`: the pipeline calibrated on the training recordings
//! (labels never read) before anything is encoded, in the order the CLI calibrates it.

use std::path::PathBuf;

use neurotex::calibrate::GainCalibration;
use neurotex::causal::ConditioningCalibration;
use neurotex::pipeline::Pipeline;
use neurotex::recording::{Baseline, Recording};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;

use crate::convert::{open, to_object, Batch, InfoTuple};
use crate::errors::guarded;
use crate::params::{self, Stages};

/// Reads the training recordings by index.
pub type Load<'a> = dyn Fn(usize) -> neurotex::Result<Recording> + Sync + 'a;

/// The pipeline of the stage options, calibrated.
pub struct Calibrated {
    /// The planned pipeline, with the calibrated gain and causal conditioning in place.
    pub pipeline: Pipeline,
    /// What `gain="auto"` chose.
    pub gain: Option<GainCalibration>,
    /// What `causal=True` fixed.
    pub causal: Option<ConditioningCalibration>,
}

/// What was calibrated, for Python: the gain calibration and the causal conditioning as
/// dicts (the library's serialised forms, as a model file holds them), each `None` when
/// not asked for.
pub type Report = (Option<Py<PyAny>>, Option<Py<PyAny>>);

impl Calibrated {
    /// What was calibrated, as objects for the Python layer.
    pub fn report(&self, py: Python<'_>) -> PyResult<Report> {
        Ok((object(py, &self.gain)?, object(py, &self.causal)?))
    }
}

/// `value` as a Python object ([`to_object`]), `None` for `None`.
pub fn object<T: Serialize>(py: Python<'_>, value: &Option<T>) -> PyResult<Option<Py<PyAny>>> {
    value.as_ref().map(|v| to_object(py, v)).transpose()
}

/// The pipeline the stage options name, calibrated on the recordings `indices` (read by
/// `load`) as the library's [`calibrate_pipeline`] does: what the CLI's commands calibrate
/// too, so the same recordings give the same pipeline.
///
/// # Errors
/// No recording, one that cannot be read or conditioned, no signal to calibrate on.
pub fn calibrated(
    stages: &Stages,
    load: &Load<'_>,
    indices: &[usize],
    baseline: Baseline,
) -> neurotex::Result<Calibrated> {
    let c = stages.calibrate(load, indices, baseline)?;
    Ok(Calibrated {
        pipeline: Pipeline::new(c.params)?,
        gain: c.gain,
        causal: c.causal,
    })
}

/// Calibrates the stage options on recordings (arrays): what `features` would choose.
#[pyfunction]
#[pyo3(signature = (recordings, infos, options, baseline=None))]
fn calibrate<'py>(
    py: Python<'py>,
    recordings: Vec<Bound<'py, PyAny>>,
    infos: Vec<InfoTuple>,
    options: &Bound<'py, PyDict>,
    baseline: Option<&str>,
) -> PyResult<Report> {
    let stages = params::stages(options)?;
    let baseline = params::baseline(baseline)?;
    let batch = Batch::new(&recordings, infos)?;
    let view = batch.view();
    let all: Vec<usize> = (0..view.len()).collect();
    let c = py.detach(|| guarded(|| calibrated(&stages, &|i| view.load(i), &all, baseline)))?;
    c.report(py)
}

/// Calibrates the stage options on every recording of a dataset folder, as `neurotex
/// features --dataset` does.
#[pyfunction]
fn calibrate_dataset(
    py: Python<'_>,
    dir: PathBuf,
    options: &Bound<'_, PyDict>,
) -> PyResult<Report> {
    let stages = params::stages(options)?;
    let dataset = open(&dir)?;
    let baseline = dataset.layout.baseline.unwrap_or_default();
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    let c = py.detach(|| guarded(|| calibrated(&stages, &|i| dataset.load(i), &all, baseline)))?;
    c.report(py)
}

/// Registers the calibration functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_dataset, m)?)
}
