//! The stream classifier as an object fed frame by frame: a causal model's decisions at
//! every bin, as `neurotex stream` prints them.

use neurotex::causal::DecisionRule;
use neurotex::events::{Origin, Stamp};
use neurotex::recording::TimeUnit;
use neurotex::saved::SavedModel;
use neurotex::stream::events::EventSource;
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
    /// Whether it takes address events rather than frames.
    events: bool,
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

/// A bad event named by the argument of `push_event` at fault (`t`, or the cell and
/// polarity `x`, `y`, `p`), as a Python caller passed them.
fn event_error(e: StreamError, t: &Bound<'_, PyAny>) -> PyErr {
    use neurotex::stream::BadFrame as B;
    match e {
        StreamError::Bad(bad) => {
            let argument = match &bad {
                B::Address(_) => "x, y, p".to_string(),
                _ => format!("t={}", t.repr().map_or("?".into(), |r| r.to_string())),
            };
            raise(
                Kind::Data,
                format!("push_event({argument}): bad event skipped: {bad}"),
            )
        }
        StreamError::Classify(e) => to_py(e),
    }
}

#[pymethods]
impl NativeStream {
    /// A stream classifier for `model` (a feature model or a spiking network, trained with
    /// `--causal`).
    #[new]
    #[pyo3(signature = (model, window_s=None, decide=0.8, decide_bins=3, episode="whole", fs=1000.0, max_gap_s=1.0, speed=None, time_unit="s", events=false, origin=None))]
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
        events: bool,
        origin: Option<&str>,
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
        if !events {
            if origin.is_some() {
                return Err(raise(
                    Kind::Parameter,
                    "origin applies to event streams (events=True)",
                ));
            }
            let inner = guarded(|| StreamClassifier::new(model, params))?;
            return Ok(NativeStream {
                inner,
                unit,
                events,
            });
        }
        let origin = match origin {
            None => None,
            Some("zero") => Some(Origin::Zero),
            Some("first") => Some(Origin::First),
            Some(other) => {
                let why = format!("origin is \"zero\" or \"first\", not {other:?}");
                return Err(raise(Kind::Parameter, why));
            }
        };
        let source = EventSource::for_model(&model, Some(unit), origin, false)
            .map_err(|why| raise(Kind::Parameter, why))?;
        let inner = guarded(|| StreamClassifier::for_events(model, params, source))?;
        Ok(NativeStream {
            inner,
            unit,
            events,
        })
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
        if self.events {
            return Err(raise(
                Kind::Parameter,
                "this stream takes events (push_event), not frames",
            ));
        }
        let events = self
            .inner
            .push_in(t, self.unit, &values)
            .map_err(stream_error)?
            .to_vec();
        lines(py, &self.inner, &events)
    }

    /// Takes one event at `t` (in the stream's unit; an int is exact) of the cell `x`, `y`
    /// (or taxel `x`) with polarity `p`, or a tick when `x` is None; returns the lines it
    /// completed, as dicts.
    #[pyo3(signature = (t, x=None, y=None, p=None))]
    fn push_event(
        &mut self,
        py: Python<'_>,
        t: &Bound<'_, PyAny>,
        x: Option<i64>,
        y: Option<i64>,
        p: Option<i64>,
    ) -> PyResult<Vec<Py<PyAny>>> {
        if !self.events {
            return Err(raise(
                Kind::Parameter,
                "this stream takes frames (push); events need StreamClassifier(..., events=True)",
            ));
        }
        let stamp = match t.extract::<i64>() {
            Ok(t) => Stamp::Int(t),
            Err(_) => Stamp::Float(t.extract::<f64>().map_err(|_| {
                let got = t.get_type().name().map_or("?".into(), |n| n.to_string());
                raise(
                    Kind::Parameter,
                    format!("push_event: t, the time stamp, must be a number; got {got}"),
                )
            })?),
        };
        let address = x.map(|x| (x, y.unwrap_or(0), p));
        let events = self
            .inner
            .push_event(stamp, address)
            .map_err(|e| event_error(e, t))?
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
