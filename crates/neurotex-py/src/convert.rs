//! numpy arrays in: views of the caller's memory (any strides, float32 or float64), read
//! without the GIL into the library's recordings and rasters.

use std::path::Path;

use ndarray::ArrayViewD;
use neurotex::error::DataError;
use neurotex::pipeline::Encoded;
use neurotex::recording::{
    Dataset, Layout, Meta, Recording, DEFAULT_MAX_DURATION_S, VALUES_PER_LIMIT_S,
};
use numpy::PyReadonlyArrayDyn;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::errors::{guarded, raise, try_vec, Kind};

/// A borrowed numpy array of samples, float32 or float64, as the caller laid it out.
pub enum Samples<'py> {
    /// float32 samples (widened exactly to f64, as the CLI reads a float32 `.npy`).
    F32(PyReadonlyArrayDyn<'py, f32>),
    /// float64 samples.
    F64(PyReadonlyArrayDyn<'py, f64>),
}

/// A view of the samples that may cross into code running without the GIL.
pub enum SamplesView<'a> {
    /// float32 samples.
    F32(ArrayViewD<'a, f32>),
    /// float64 samples.
    F64(ArrayViewD<'a, f64>),
}

impl<'py> Samples<'py> {
    /// Borrows `array`, which must be a float32 or float64 numpy array (the Python layer
    /// converts other numeric types first).
    pub fn borrow(array: &Bound<'py, PyAny>, what: &str) -> PyResult<Self> {
        if let Ok(a) = array.extract::<PyReadonlyArrayDyn<'py, f64>>() {
            return Ok(Samples::F64(a));
        }
        if let Ok(a) = array.extract::<PyReadonlyArrayDyn<'py, f32>>() {
            return Ok(Samples::F32(a));
        }
        Err(raise(
            Kind::Data,
            format!("{what}: samples must be a float32 or float64 numpy array"),
        ))
    }

    /// The view.
    pub fn view(&self) -> SamplesView<'_> {
        match self {
            Samples::F32(a) => SamplesView::F32(a.as_array()),
            Samples::F64(a) => SamplesView::F64(a.as_array()),
        }
    }
}

/// What a recording carries beside its samples.
#[derive(Debug, Clone, Default)]
pub struct RecordingInfo {
    /// Name used in error messages (`recording 3`, or the dataset file).
    pub name: String,
    /// Sampling rate in Hz.
    pub fs: f64,
    /// Grid cells holding a taxel (row-major); `None`: every cell.
    pub present: Option<Vec<bool>>,
    /// Time stamps in s of an irregularly sampled recording (strictly increasing, one per
    /// sample); `None`: regular sampling at `fs`.
    pub times_s: Option<Vec<f64>>,
    /// Manifest fields: label, speed, slide interval.
    pub meta: Meta,
}

impl SamplesView<'_> {
    /// The samples in C order as f64, with the recording's grid: `(T, rows, cols)` or
    /// `(T, channels)` (a `1 x channels` grid, as the CLI reads a `(T, channels)` file
    /// without a layout). Checks what the CLI's reader checks: shape, finite samples,
    /// duration within the per-recording limit.
    ///
    /// # Errors
    /// A `DataError` naming the recording and what is wrong.
    pub fn recording(&self, info: &RecordingInfo) -> neurotex::Result<Recording> {
        let shape = match self {
            SamplesView::F32(a) => a.shape(),
            SamplesView::F64(a) => a.shape(),
        };
        let name = &info.name;
        let bad = |message: String| -> neurotex::Error { DataError::invalid(name, message).into() };
        let (t, rows, cols) = match *shape {
            [t, r, c] => (t, r, c),
            [t, n] => (t, 1, n),
            ref other => {
                return Err(bad(format!(
                    "expected shape (T, rows, cols) or (T, channels), got {other:?}"
                )))
            }
        };
        neurotex::values::check_grid_cells(rows, cols)
            .map_err(|e| bad(format!("shape {shape:?}: {e}")))?;
        if !(info.fs.is_finite() && info.fs > 0.0) {
            return Err(bad(format!(
                "fs must be a positive sampling rate in Hz, got {}",
                info.fs
            )));
        }
        let span = span_s(info, t).map_err(bad)?;
        check_span(span, info.fs, t, rows * cols).map_err(bad)?;
        // Logical (C) order whatever the strides: a C-contiguous array is one copy. A
        // broadcast view can be far larger than the memory behind it: reserved fallibly.
        let mut samples: Vec<f64> =
            neurotex::error::try_with_capacity(t * rows * cols, &format!("{name}: the samples"))?;
        match self {
            SamplesView::F64(a) => match a.as_slice() {
                Some(s) => samples.extend_from_slice(s),
                None => samples.extend(a.iter().copied()),
            },
            SamplesView::F32(a) => samples.extend(a.iter().map(|&v| f64::from(v))),
        }
        let n_cells = rows * cols;
        if let Some(pos) = samples
            .iter()
            .position(|&v| !neurotex::values::sample_in_range(v))
        {
            return Err(bad(format!(
                "sample {} of channel {} is {:?} ({})",
                pos / n_cells,
                pos % n_cells,
                samples[pos],
                neurotex::values::SAMPLE_RULE
            )));
        }
        let mut layout = Layout::grid(rows, cols);
        if let Some(present) = &info.present {
            if present.len() != n_cells {
                return Err(bad(format!(
                    "the mask has {} cells but the recording's grid is {rows}x{cols}",
                    present.len()
                )));
            }
            layout.present = present.clone();
        }
        Ok(Recording {
            fs: info.fs,
            layout,
            samples,
            times_s: info.times_s.clone(),
            phases: None,
            meta: Meta {
                file: info.meta.file.clone(),
                ..info.meta.clone()
            },
        })
    }
}

/// The recording's span in s: from its time stamps, checked (one per sample, finite and
/// strictly increasing), or `t` samples at its rate.
fn span_s(info: &RecordingInfo, t: usize) -> Result<f64, String> {
    let Some(times) = &info.times_s else {
        return Ok(t as f64 / info.fs);
    };
    if times.len() != t {
        return Err(format!("{} time stamps for {t} samples", times.len()));
    }
    if let Some(i) = times
        .windows(2)
        .position(|w| !(w[0].is_finite() && w[1].is_finite() && w[1] > w[0]))
    {
        return Err(format!(
            "time stamps must be finite and strictly increasing; stamp {} is {} after {}",
            i + 1,
            times[i + 1],
            times[i]
        ));
    }
    Ok(match times[..] {
        [first, .., last] => last - first,
        _ => 0.0,
    })
}

/// The CLI reader's limits on a recording of `span` s (`t` samples at `fs` Hz) on `cells`
/// grid cells: its duration, and what resampling to 1 kHz allocates.
fn check_span(span: f64, fs: f64, t: usize, cells: usize) -> Result<(), String> {
    if span > DEFAULT_MAX_DURATION_S {
        return Err(format!(
            "{t} samples at {fs} Hz last {span} s, beyond the limit of \
             {DEFAULT_MAX_DURATION_S} s per recording"
        ));
    }
    let max_values = DEFAULT_MAX_DURATION_S * VALUES_PER_LIMIT_S;
    let resampled = span * 1000.0 * cells as f64;
    if resampled > max_values {
        return Err(format!(
            "{span} s on {cells} grid cells is {resampled:.3e} values once resampled to 1 kHz, \
             beyond the limit of {max_values:.3e} ({DEFAULT_MAX_DURATION_S} s of a \
             16-taxel grid); a wrong shape or rate is the usual cause"
        ));
    }
    Ok(())
}

/// One recording's description as the Python layer passes it beside the samples:
/// `(name, fs, mask or None, label, speed_mm_s, slide_start_s, slide_end_s, time stamps in s
/// or None)`.
pub type InfoTuple = (
    String,
    f64,
    Option<Vec<bool>>,
    String,
    Option<f64>,
    Option<f64>,
    Option<f64>,
    Option<Vec<f64>>,
);

/// The recording description of an [`InfoTuple`].
pub fn info_of(t: InfoTuple) -> RecordingInfo {
    let (name, fs, present, label, speed, start, end, times_s) = t;
    RecordingInfo {
        name: name.clone(),
        fs,
        present,
        times_s,
        meta: Meta {
            file: name,
            label,
            speed_mm_s: speed,
            slide_start_s: start,
            slide_end_s: end,
            ..Default::default()
        },
    }
}

/// Recordings passed from Python: the borrowed samples of each, with its description.
pub struct Batch<'py> {
    samples: Vec<Samples<'py>>,
    infos: Vec<RecordingInfo>,
}

impl<'py> Batch<'py> {
    /// Borrows every recording (float32 or float64 arrays) with its description.
    ///
    /// # Errors
    /// A `ParameterError` when the counts differ, a `DataError` for an array of another
    /// type.
    pub fn new(recordings: &[Bound<'py, PyAny>], infos: Vec<InfoTuple>) -> PyResult<Self> {
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
        Ok(Batch {
            samples,
            infos: infos.into_iter().map(info_of).collect(),
        })
    }

    /// Views of the samples for work without the GIL.
    pub fn view(&self) -> BatchView<'_> {
        BatchView {
            samples: self.samples.iter().map(Samples::view).collect(),
            infos: &self.infos,
        }
    }
}

/// A [`Batch`] as it crosses into code running without the GIL.
pub struct BatchView<'a> {
    samples: Vec<SamplesView<'a>>,
    infos: &'a [RecordingInfo],
}

impl BatchView<'_> {
    /// The number of recordings.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// The descriptions, in order.
    pub fn infos(&self) -> &[RecordingInfo] {
        self.infos
    }

    /// Recording `i` as the library reads a file (what `load` is to a dataset folder).
    ///
    /// # Errors
    /// What [`SamplesView::recording`] checks.
    pub fn load(&self, i: usize) -> neurotex::Result<Recording> {
        self.samples[i].recording(&self.infos[i])
    }

    /// Writes recording `i`'s samples as given (float32 or float64, C order) to an `.npy`
    /// file.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn write_npy(&self, i: usize, path: &std::path::Path) -> neurotex::Result<()> {
        let written = match &self.samples[i] {
            SamplesView::F32(a) => ndarray_npy::write_npy(path, &a.as_standard_layout()),
            SamplesView::F64(a) => ndarray_npy::write_npy(path, &a.as_standard_layout()),
        };
        written.map_err(|e| DataError::invalid(path, e.to_string()).into())
    }

    /// Every recording read and encoded by `encode`, in parallel on the library's pool, in
    /// order.
    ///
    /// # Errors
    /// The first failing recording's error, naming it.
    pub fn encode(
        &self,
        encode: impl Fn(&Recording) -> neurotex::Result<Encoded> + Sync,
    ) -> neurotex::Result<Vec<Encoded>> {
        (0..self.len())
            .into_par_iter()
            .map(|i| {
                let rec = self.load(i)?;
                encode(&rec).map_err(|e| e.in_recording(&self.infos[i].name))
            })
            .collect()
    }
}

/// A borrowed spike raster: uint8 `(T, rows, cols)`.
pub fn raster_of(raster: &PyReadonlyArrayDyn<'_, u8>) -> PyResult<(Vec<u8>, usize, usize)> {
    let a = raster.as_array();
    let (rows, cols) = match *a.shape() {
        [_, r, c] => (r, c),
        ref other => {
            return Err(raise(
                Kind::Data,
                format!(
                    "spikes must be a uint8 array of shape (T, rows, cols), got shape {other:?}"
                ),
            ))
        }
    };
    if rows * cols == 0 {
        return Err(raise(Kind::Data, "spikes: the grid has no cells"));
    }
    let data = try_vec(a.len(), "spikes", a.iter().copied())?;
    if let Some(pos) = data.iter().position(|&v| v > 1) {
        let cells = rows * cols;
        return Err(raise(
            Kind::Data,
            format!(
                "spikes: value {} at step {} of cell {} (a raster holds 0 or 1)",
                data[pos],
                pos / cells,
                pos % cells
            ),
        ));
    }
    Ok((data, rows, cols))
}

/// Opens a dataset folder, a missing folder raising `NotFoundError`.
pub(crate) fn open(dir: &Path) -> PyResult<Dataset> {
    if !dir.exists() {
        return Err(raise(
            Kind::NotFound,
            format!("{}: no such dataset folder", dir.display()),
        ));
    }
    guarded(|| Dataset::open(dir))
}

/// A value serialised by the library as the Python object `json.loads` gives for its
/// JSON text (dicts with the same keys in the same order, lists, `int` for integers,
/// `float` for the rest, `None` for null), built directly, without the text.
///
/// # Errors
/// A value serde cannot represent (never for the library's result types).
pub fn to_object<T: serde::Serialize>(py: Python<'_>, value: &T) -> PyResult<Py<PyAny>> {
    let value = serde_json::to_value(value).map_err(|e| raise(Kind::Internal, e.to_string()))?;
    Ok(value_object(py, &value)?.unbind())
}

/// One JSON value as a Python object (see [`to_object`]).
fn value_object<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use pyo3::types::{PyBool, PyDict, PyList, PyString};
    use serde_json::Value;
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64()) {
            (Some(u), _) => u.into_pyobject(py)?.into_any(),
            (_, Some(i)) => i.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let items = items
                .iter()
                .map(|v| value_object(py, v))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, value_object(py, v)?)?;
            }
            dict.into_any()
        }
    })
}
