//! Python bindings of neurotex (`neurotex._native`): a thin layer over the library, as the
//! CLI is. numpy arrays come in as views of the caller's memory and are read without the
//! GIL; work across recordings runs on the library's rayon pool; results go out as numpy
//! arrays that own the library's buffers (no copy). Library errors become exceptions of
//! `neurotex.errors`; panics are caught at the boundary. The Python half of the package
//! (`python/neurotex`) gives the functions their keyword signatures and docstrings.
#![deny(missing_docs)]

mod calibrate;
mod convert;
mod dataset;
mod datasets;
mod errors;
mod estimator;
mod inspect;
mod interrupt;
mod model;
mod params;
mod reproduce;
mod spiking;
mod stream;
mod workflow;

use ndarray::{Array2, Array3};
use neurotex::encode::SpikeTrains;
use neurotex::error::DataError;
use neurotex::features::glcm::GlcmKind;
use neurotex::features::{
    haralick, haralick_full, quantise, spike_stats as stats_of, GlcmParams, GlcmPlan, RateVolume,
    VolumeParams,
};
use neurotex::pipeline::{shared_grid, Encoded, Pipeline};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use calibrate::{calibrated, Report};
use convert::{raster_of, Batch, InfoTuple};
use errors::{guarded, guarded_py, param, raise, to_py, try_vec, Kind};

/// A raster and, for `sa+fa`, the FA population's.
type Rasters<'py> = (Bound<'py, PyArray3<u8>>, Option<Bound<'py, PyArray3<u8>>>);

/// Encodes one recording: `((first population's raster, FA raster of sa+fa or None), gain
/// calibration as a dict or None)`, each raster uint8 `(T, rows, cols)` at 1 kHz. Under
/// `gain="auto"` the gain is calibrated on this recording, as `neurotex encode --gain auto`
/// does.
#[pyfunction]
#[pyo3(signature = (x, info, options, baseline=None))]
fn encode<'py>(
    py: Python<'py>,
    x: Bound<'py, PyAny>,
    info: InfoTuple,
    options: &Bound<'py, PyDict>,
    baseline: Option<&str>,
) -> PyResult<(Rasters<'py>, Option<Py<PyAny>>)> {
    let stages = params::stages(options)?;
    if stages.causal {
        return Err(raise(
            Kind::Parameter,
            "causal fixes resting values and a scale on training recordings: use it with features or Model.train (then predict or stream with the model)",
        ));
    }
    let baseline = params::baseline(baseline)?;
    let batch = Batch::new(&[x], vec![info])?;
    let view = batch.view();
    let (mut encoded, c) = py.detach(|| {
        guarded(|| {
            let c = calibrated(&stages, &|i| view.load(i), &[0], baseline)?;
            Ok((view.encode(|rec| c.pipeline.encode(rec, baseline))?, c))
        })
    })?;
    let (gain, _) = c.report(py)?;
    let e = encoded.remove(0);
    let raster = |s: &SpikeTrains| {
        Array3::from_shape_vec((s.n_steps, s.rows, s.cols), s.to_raster())
            .expect("a raster holds n_steps x rows x cols values")
            .into_pyarray(py)
    };
    let first = raster(&e.spikes);
    let fa = e.fa.as_ref().map(raster);
    Ok(((first, fa), gain))
}

/// A feature table, its column names and what was calibrated.
type TableWithCalibration<'py> = (Bound<'py, PyArray2<f64>>, Vec<String>, Report);

/// The feature table of many recordings: `(values (n, k) float64, column names, what
/// was calibrated)`. Under `gain="auto"` or `causal=True` the pipeline is calibrated on
/// all of them first, as `neurotex features` calibrates on its whole dataset.
#[pyfunction]
#[pyo3(signature = (recordings, infos, method, options, baseline=None))]
fn features<'py>(
    py: Python<'py>,
    recordings: Vec<Bound<'py, PyAny>>,
    infos: Vec<InfoTuple>,
    method: &str,
    options: &Bound<'py, PyDict>,
    baseline: Option<&str>,
) -> PyResult<TableWithCalibration<'py>> {
    if recordings.is_empty() {
        return Err(raise(Kind::Data, "no recordings to compute features of"));
    }
    let method = params::method(method)?;
    let stages = params::stages(options)?;
    let baseline = params::baseline(baseline)?;
    let batch = Batch::new(&recordings, infos)?;
    let view = batch.view();
    let all: Vec<usize> = (0..view.len()).collect();
    let (values, names, c) = py.detach(|| {
        guarded(|| {
            let c = calibrated(&stages, &|i| view.load(i), &all, baseline)?;
            let encoded = view.encode(|rec| c.pipeline.encode(rec, baseline))?;
            let (values, names) = table_of(&encoded, &c.pipeline, method)?;
            Ok((values, names, c))
        })
    })?;
    Ok((values.into_pyarray(py), names, c.report(py)?))
}

/// The feature table of encoded recordings, as the CLI's `features` command builds it.
pub(crate) fn table_of(
    encoded: &[Encoded],
    pipeline: &Pipeline,
    method: neurotex::pipeline::Method,
) -> neurotex::Result<(Array2<f64>, Vec<String>)> {
    let extractor = pipeline.extractor(&shared_grid(encoded)?)?;
    let table = neurotex::analysis::FeatureTable::build(encoded, &extractor, method)?;
    let n = table.metas.len();
    let k = table.dims();
    let values = Array2::from_shape_vec((n, k), table.values)
        .map_err(|e| DataError::invalid("features", e.to_string()))?;
    Ok((values, table.names))
}

/// MSR (Hz), CV_ISI and Fano factor of each cell of a raster: float64 `(rows, cols, 3)`.
#[pyfunction]
#[pyo3(signature = (spikes, bin_ms=200))]
fn spike_stats<'py>(
    py: Python<'py>,
    spikes: PyReadonlyArrayDyn<'py, u8>,
    bin_ms: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (data, rows, cols) = raster_of(&spikes)?;
    check_bin(bin_ms)?;
    let out = py.detach(|| {
        guarded(|| {
            let trains = SpikeTrains::from_raster(&data, rows, cols, &vec![true; rows * cols]);
            let n = trains.n_steps;
            if n < bin_ms {
                return Err(DataError::TooShort { n_ms: n, bin_ms }.into());
            }
            let values: Vec<f64> = (0..rows * cols)
                .flat_map(|cell| stats_of(trains.train(cell), n, bin_ms).to_array())
                .collect();
            Ok(Array3::from_shape_vec((rows, cols, 3), values).expect("3 statistics per cell"))
        })
    })?;
    Ok(out.into_pyarray(py))
}

/// A bin width of at least 1 ms.
fn check_bin(bin_ms: usize) -> PyResult<()> {
    VolumeParams {
        bin_ms,
        ..VolumeParams::default()
    }
    .check()
    .map_err(param)
}

/// The rate volume of a raster in Hz, float64 `(rows, cols, bins)`; `bin_ms=None`: one bin
/// spanning the whole raster (the 2D-GLCM's image).
#[pyfunction]
#[pyo3(signature = (spikes, bin_ms=Some(200)))]
fn rate_volume<'py>(
    py: Python<'py>,
    spikes: PyReadonlyArrayDyn<'py, u8>,
    bin_ms: Option<usize>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (data, rows, cols) = raster_of(&spikes)?;
    if let Some(b) = bin_ms {
        check_bin(b)?;
    }
    let out = py.detach(|| {
        guarded(|| {
            let trains = SpikeTrains::from_raster(&data, rows, cols, &vec![true; rows * cols]);
            let volume = match bin_ms {
                Some(b) => RateVolume::from_spikes(&trains, b),
                None => RateVolume::collapsed(&trains),
            }
            .ok_or(DataError::TooShort {
                n_ms: trains.n_steps,
                bin_ms: bin_ms.unwrap_or(1),
            })?;
            Ok(
                Array3::from_shape_vec((rows, cols, volume.bins), volume.data)
                    .expect("cell-major rates"),
            )
        })
    })?;
    Ok(out.into_pyarray(py))
}

/// `(rows, cols, bins)` of a volume's `shape` (`bins` 1 for a 2D image), refusing another
/// number of axes or an empty volume.
fn volume_shape(shape: &[usize], three_d: bool) -> PyResult<(usize, usize, usize)> {
    let (rows, cols, bins) = match (three_d, shape) {
        (true, &[r, c, b]) => (r, c, b),
        (false, &[r, c]) => (r, c, 1),
        (_, other) => {
            let want = if three_d {
                "(rows, cols, bins)"
            } else {
                "(rows, cols)"
            };
            return Err(raise(
                Kind::Data,
                format!("volume must have shape {want}, got {other:?}"),
            ));
        }
    };
    if rows * cols * bins == 0 {
        return Err(raise(
            Kind::Data,
            format!("volume is empty: shape {shape:?}"),
        ));
    }
    Ok((rows, cols, bins))
}

/// The summed co-occurrence counts (uint64 `(levels, levels)`) of a float volume
/// `(rows, cols, bins)` (3D) or image `(rows, cols)` (2D), quantised as the pipeline does.
#[pyfunction]
#[pyo3(signature = (volume, three_d, levels, distances, symmetric, range=None, mask=None))]
#[allow(clippy::too_many_arguments)]
fn glcm<'py>(
    py: Python<'py>,
    volume: PyReadonlyArrayDyn<'py, f64>,
    three_d: bool,
    levels: usize,
    distances: Vec<usize>,
    symmetric: bool,
    range: Option<(f64, f64)>,
    mask: Option<Vec<bool>>,
) -> PyResult<Bound<'py, PyArray2<u64>>> {
    let a = volume.as_array();
    let (rows, cols, bins) = volume_shape(a.shape(), three_d)?;
    let data = try_vec(a.len(), "volume", a.iter().copied())?;
    // the levels, one byte per value
    let mut q =
        neurotex::error::try_with_capacity::<u8>(data.len(), "volume levels").map_err(to_py)?;
    if let Some(pos) = data.iter().position(|v| !v.is_finite()) {
        return Err(raise(
            Kind::Data,
            format!(
                "volume value {pos} (C order) is {}; every value must be finite",
                data[pos]
            ),
        ));
    }
    VolumeParams {
        levels,
        range,
        ..VolumeParams::default()
    }
    .check()
    .map_err(param)?;
    let present = mask.unwrap_or_else(|| vec![true; rows * cols]);
    if present.len() != rows * cols {
        return Err(raise(
            Kind::Data,
            format!(
                "mask has {} cells, the volume's grid {rows}x{cols}",
                present.len()
            ),
        ));
    }
    let params = GlcmParams {
        distances,
        symmetric,
    };
    let kind = if three_d {
        GlcmKind::ThreeD
    } else {
        GlcmKind::TwoD
    };
    let plan = GlcmPlan::new(rows, cols, &present, levels, &params, kind).map_err(param)?;
    if !plan.counts_fit_wide(bins) {
        return Err(raise(
            Kind::Data,
            format!("{bins} time bins are too many to count"),
        ));
    }
    let counts = py.detach(|| {
        guarded(|| {
            let volume = RateVolume {
                rows,
                cols,
                bins,
                present: present.clone(),
                data,
            };
            quantise(&volume, levels, range, &mut q);
            let mut counts = vec![0u64; levels * levels];
            plan.count_wide(&q, bins, &mut counts);
            Ok(Array2::from_shape_vec((levels, levels), counts).expect("levels x levels"))
        })
    })?;
    Ok(counts.into_pyarray(py))
}

/// Haralick features of a count matrix `(L, L)` (uint64): the paper's contrast,
/// correlation, ASM, or the 13 of Haralick (1973) with `full`.
#[pyfunction]
#[pyo3(signature = (counts, full=false))]
fn haralick_features<'py>(
    py: Python<'py>,
    counts: PyReadonlyArrayDyn<'py, u64>,
    full: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = counts.as_array();
    let levels = match *a.shape() {
        [l, m] if l == m && l >= 1 => l,
        ref other => {
            return Err(raise(
                Kind::Data,
                format!("counts must be a square (levels, levels) matrix, got shape {other:?}"),
            ))
        }
    };
    let data: Vec<u64> = a.iter().copied().collect();
    // The features are ratios of sums of the counts, exact while the total stays below
    // 2^55; an empty matrix has no pairs and so no features (not a plausible [0, 1, 0]).
    let total = data.iter().try_fold(0u64, |t, &c| t.checked_add(c));
    match total {
        Some(0) => {
            return Err(raise(
                Kind::Data,
                "counts holds no pairs (every count is 0): a co-occurrence matrix without pairs has no features",
            ))
        }
        Some(t) if t < 1 << 55 => {}
        _ => {
            return Err(raise(
                Kind::Data,
                "counts total 2^55 or more, beyond the exact sums of the features: scale the matrix down",
            ))
        }
    }
    let values = guarded_py(|| {
        Ok(if full {
            let weights: Vec<f64> = data.iter().map(|&c| c as f64).collect();
            haralick_full(&weights, levels).to_vec()
        } else {
            haralick(&data, levels).to_array().to_vec()
        })
    })?;
    Ok(values.into_pyarray(py))
}

/// The names of the 13 Haralick features of `haralick(..., full=True)`.
#[pyfunction]
fn haralick_names(full: bool) -> Vec<String> {
    if full {
        neurotex::features::FULL_NAMES
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        ["contrast", "correlation", "asm"]
            .map(String::from)
            .to_vec()
    }
}

/// Checks stage options and a method without computing anything (for `fit`).
#[pyfunction]
fn check_options(method: &str, options: &Bound<'_, PyDict>) -> PyResult<()> {
    params::method(method)?;
    params::stages(options)?;
    Ok(())
}

/// The library's version.
#[pyfunction]
fn library_version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The native half of the `neurotex` package.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    interrupt::quiet_panic_hook();
    m.add_function(wrap_pyfunction!(params::stage_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(params::classifier_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(params::classifier_knobs, m)?)?;
    m.add_function(wrap_pyfunction!(encode, m)?)?;
    m.add_function(wrap_pyfunction!(features, m)?)?;
    m.add_function(wrap_pyfunction!(spike_stats, m)?)?;
    m.add_function(wrap_pyfunction!(rate_volume, m)?)?;
    m.add_function(wrap_pyfunction!(glcm, m)?)?;
    m.add_function(wrap_pyfunction!(haralick_features, m)?)?;
    m.add_function(wrap_pyfunction!(haralick_names, m)?)?;
    m.add_function(wrap_pyfunction!(library_version, m)?)?;
    m.add_function(wrap_pyfunction!(check_options, m)?)?;
    calibrate::register(m)?;
    dataset::register(m)?;
    datasets::register(m)?;
    reproduce::register(m)?;
    inspect::register(m)?;
    model::register(m)?;
    spiking::register(m)?;
    estimator::register(m)?;
    stream::register(m)?;
    workflow::register(m)?;
    Ok(())
}
