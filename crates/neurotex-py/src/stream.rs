//! The stream classifier as an object fed frame by frame: a causal model's decisions at
//! every bin, as `neurotex stream` prints them.

use neurotex::causal::DecisionRule;
use neurotex::recording::TimeUnit;
use neurotex::saved::SavedModel;
use neurotex::stream::{bin_json, end_json, Event, StreamClassifier, StreamError, StreamParams};
use pyo3::prelude::*;

use crate::convert::to_object;
use crate::errors::{guarded, param, raise, to_py, Kind};
use crate::model::NativeModel;
use crate::spiking::NativeSpikingModel;

/// A causal model classifying a live stream.
#[pyclass(module = "neurotex._native")]
pub struct NativeStream {
    inner: StreamClassifier,
    /// The unit of every stamp pushed.
    unit: TimeUnit,
}

/// The events as dicts, the lines `neurotex stream` prints (without `bad_frames`).
fn lines(py: Python<'_>, stream: &StreamClassifier, events: &[Event]) -> PyResult<Vec<Py<PyAny>>> {
    let labels = stream.model().labels();
    events
        .iter()
        .map(|e| match e {
            Event::Bin(b) => to_object(py, &bin_json(labels, b, None)),
            Event::End(s) => to_object(py, &end_json(labels, s, None)),
        })
        .collect()
}

fn stream_error(e: StreamError) -> PyErr {
    match e {
        StreamError::Bad(bad) => raise(Kind::Data, format!("bad frame skipped: {bad}")),
        StreamError::Classify(e) => to_py(e),
    }
}

#[pymethods]
impl NativeStream {
    /// A stream classifier for `model` (a feature model or a spiking network, trained with
    /// `--causal`).
    #[new]
    #[pyo3(signature = (model, window_s=None, decide=0.8, decide_bins=3, episode="whole", fs=1000.0, max_gap_s=1.0, speed=None, time_unit="s"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        model: &Bound<'_, PyAny>,
        window_s: Option<f64>,
        decide: f64,
        decide_bins: usize,
        episode: &str,
        fs: f64,
        max_gap_s: f64,
        speed: Option<f64>,
        time_unit: &str,
    ) -> PyResult<Self> {
        let unit: TimeUnit = time_unit.parse().map_err(param)?;
        let model: SavedModel = match (
            model.cast::<NativeModel>(),
            model.cast::<NativeSpikingModel>(),
        ) {
            (Ok(m), _) => m.get().inner.clone().into(),
            (_, Ok(m)) => m.get().inner.clone().into(),
            _ => {
                return Err(raise(
                    Kind::Parameter,
                    "a stream runs a Model or a SpikingModel",
                ))
            }
        };
        let mut params = StreamParams::for_model(&model);
        params.window_ms = StreamParams::window_ms(&model, window_s).map_err(param)?;
        params.rule = DecisionRule {
            share: decide,
            bins: decide_bins,
        };
        params.episodes = episode.parse().map_err(param)?;
        params.fs = fs;
        params.max_gap_s = max_gap_s;
        params.speed_mm_s = speed;
        let inner = guarded(|| StreamClassifier::new(model, params))?;
        Ok(NativeStream { inner, unit })
    }

    /// Takes one frame (one value per taxel) with its time stamp in the stream's unit, or
    /// none at the stream's rate; returns the lines it completed, as dicts.
    #[pyo3(signature = (values, t=None))]
    fn push(
        &mut self,
        py: Python<'_>,
        values: Vec<f64>,
        t: Option<f64>,
    ) -> PyResult<Vec<Py<PyAny>>> {
        let events = self
            .inner
            .push_in(t, self.unit, &values)
            .map_err(stream_error)?
            .to_vec();
        lines(py, &self.inner, &events)
    }

    /// Ends the current episode; its summary line.
    fn reset(&mut self, py: Python<'_>) -> PyResult<Vec<Py<PyAny>>> {
        let events = self.inner.reset().map_err(stream_error)?.to_vec();
        lines(py, &self.inner, &events)
    }

    /// Ends the stream; the last lines.
    fn finish(&mut self, py: Python<'_>) -> PyResult<Vec<Py<PyAny>>> {
        let events = self.inner.finish().map_err(stream_error)?.to_vec();
        lines(py, &self.inner, &events)
    }

    /// Values a frame holds.
    #[getter]
    fn channels(&self) -> usize {
        self.inner.channels()
    }

    /// Frames taken.
    #[getter]
    fn frames(&self) -> u64 {
        self.inner.frames()
    }

    /// Frames skipped as bad.
    #[getter]
    fn bad_frames(&self) -> u64 {
        self.inner.bad_frames()
    }
}

/// Registers the stream class.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeStream>()
}
