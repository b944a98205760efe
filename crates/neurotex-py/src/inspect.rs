//! `neurotex inspect` from Python: the same check of a dataset folder or of raw logs, its
//! findings and numbers handed back as dicts, and its files written as the CLI writes them.

use std::path::PathBuf;
use std::str::FromStr;

use neurotex::csvlog::CsvOverrides;
use neurotex::import::CsvImportParams;
use neurotex::inspect::{inspect as run_inspection, InspectParams, Opened};
use neurotex::report::inspection::{text_lines, write_inspection};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::to_object;
use crate::errors::{guarded, raise, Kind};
use crate::params;

/// `text` parsed as option `key`'s value, or a `ParameterError` naming it.
fn parse<T: FromStr>(key: &str, text: Option<String>) -> PyResult<Option<T>>
where
    T::Err: std::fmt::Display,
{
    text.map(|t| {
        t.parse::<T>()
            .map_err(|e| raise(Kind::Parameter, format!("invalid parameter `{key}`: {e}")))
    })
    .transpose()
}

/// How raw logs are read: the options of `import csv`, by their Python names.
fn log_params(reading: &Bound<'_, PyDict>) -> PyResult<CsvImportParams> {
    let text = |key: &str| -> PyResult<Option<String>> {
        match reading.get_item(key)? {
            Some(v) if !v.is_none() => Ok(Some(v.str()?.to_string())),
            _ => Ok(None),
        }
    };
    let header = match reading.get_item("header")? {
        Some(v) if !v.is_none() => v.extract::<bool>()?,
        _ => true,
    };
    let overrides = CsvOverrides {
        no_header: !header,
        delimiter: parse("delimiter", text("delimiter")?)?,
        time_column: parse("time_column", text("time_column")?)?,
        time_unit: parse("time_unit", text("time_unit")?)?,
        channels: parse("channels", text("channels")?)?,
        duplicate_stamps: parse("duplicate_stamps", text("duplicate_stamps")?)?,
        max_gap_s: parse("max_gap_s", text("max_gap_s")?)?,
    };
    Ok(CsvImportParams {
        pattern: parse("name_pattern", text("name_pattern")?)?,
        format: overrides.apply(Default::default()),
        grid: parse("grid", text("grid")?)?,
        channel_map: parse("channel_map", text("channel_map")?)?,
        drop_channels: parse("drop_channels", text("drop_channels")?)?,
        fs: parse::<f64>("fs", text("fs")?)?,
        baseline: None,
        skip_bad: false,
    })
}

/// Inspects `paths` (one dataset folder, or raw logs read with `reading`) as `neurotex
/// inspect` does; writes `out` when given. Returns the inspection as a dict and the lines
/// the CLI prints. The GIL is released while the recordings are read.
#[pyfunction]
#[pyo3(signature = (paths, options, reading, out=None, encoder=true, folds=5, k=5))]
#[allow(clippy::too_many_arguments)]
fn inspect(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    options: &Bound<'_, PyDict>,
    reading: &Bound<'_, PyDict>,
    out: Option<PathBuf>,
    encoder: bool,
    folds: usize,
    k: usize,
) -> PyResult<(Py<PyAny>, Vec<String>)> {
    let stages = params::stages(options)?;
    let gain_target = match stages.gain {
        neurotex::calibrate::GainChoice::Auto { target_hz } => Some(target_hz),
        neurotex::calibrate::GainChoice::Fixed(_) => None,
    };
    let params = InspectParams {
        pipeline: stages.to_calibrate().clone(),
        encoder,
        folds,
        k,
        gain_target,
        traces: out.is_some(),
    };
    let Some(first) = paths.first().cloned() else {
        return Err(raise(
            Kind::Parameter,
            "inspect needs a dataset folder or raw logs",
        ));
    };
    let reading_given = reading.values().iter().any(|v| !v.is_none());
    let logs = log_params(reading)?;
    let inspection = py.detach(|| {
        guarded(|| {
            let opened = Opened::open(&paths, logs, reading_given, false)?;
            let inspection = run_inspection(opened.source(), &params, &|| {})?;
            if let Some(dir) = &out {
                write_inspection(dir, &inspection, &first)?;
            }
            Ok(inspection)
        })
    })?;
    Ok((to_object(py, &inspection)?, text_lines(&inspection)))
}

/// Registers `inspect`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(inspect, m)?)
}
