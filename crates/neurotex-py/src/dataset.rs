//! Dataset folders: read into arrays, features straight from the folder (the CLI's path),
//! written from arrays, and the simulated rig written as one.

use std::path::PathBuf;

use ndarray::Array3;
use neurotex::events::Event;
use neurotex::pipeline::Pipeline;
use neurotex::recording::{
    create_dataset_dir, write_layout, write_manifest, LayoutFile, Meta, Recording,
};
use neurotex::sim::{check_design, design, write_dataset, RigParams, Texture, ALL_TEXTURES};
use neurotex::workflows::export::encoded_events;
use neurotex::workflows::simulate::texture;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use crate::calibrate::{calibrated, Report};
use crate::convert::open;
use crate::convert::{Batch, InfoTuple};
use crate::errors::{guarded, param, raise, Kind};
use crate::{params, table_of};

/// A recording's manifest fields as text, column by column (empty where it gives none).
fn manifest_row<'py>(
    py: Python<'py>,
    columns: &[String],
    m: &Meta,
) -> PyResult<Bound<'py, PyDict>> {
    let row = PyDict::new(py);
    for c in columns {
        row.set_item(c, m.field(c).unwrap_or_default())?;
    }
    Ok(row)
}

/// Reads every recording of a dataset folder (in parallel, without the GIL) as the library
/// does: a dict with `arrays` (float64 `(T, rows, cols)`), `infos` (what `features` needs
/// beside the samples), `rows` (manifest rows as text), `columns`, `fs`, `baseline`, `mask`.
/// `indices` selects manifest rows (0-based, data rows only); `None` reads all.
#[pyfunction]
#[pyo3(signature = (dir, indices=None))]
fn load_dataset<'py>(
    py: Python<'py>,
    dir: PathBuf,
    indices: Option<Vec<usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let dataset = open(&dir)?;
    if dataset.is_events() {
        let message = format!(
            "{}: an address-event dataset (its layout.toml has an [events] table), not sampled signals: its events are neurotex.events(path) or neurotex.tonic.Dataset(path), and Model.train(path) and model.predict(path) train and predict on the folder itself",
            dir.display()
        );
        return Err(raise(Kind::Data, message));
    }
    let n = dataset.entries.len();
    let indices = indices.unwrap_or_else(|| (0..n).collect());
    if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
        return Err(raise(
            Kind::Parameter,
            format!("row {bad} is beyond the manifest's {n} recordings"),
        ));
    }
    let recordings: Vec<Recording> = py.detach(|| {
        guarded(|| {
            indices
                .par_iter()
                .map(|&i| dataset.load(i))
                .collect::<neurotex::Result<Vec<_>>>()
        })
    })?;
    let out = PyDict::new(py);
    let arrays = PyList::empty(py);
    let infos = PyList::empty(py);
    let rows = PyList::empty(py);
    let mut mask: Option<Vec<bool>> = None;
    for rec in recordings {
        let l = &rec.layout;
        let t = rec.len();
        let present = l.present.clone();
        if !present.iter().all(|&p| p) {
            mask = Some(present.clone());
        }
        let m = &rec.meta;
        let info: InfoTuple = (
            m.file.clone(),
            rec.fs,
            Some(present),
            m.label.clone(),
            m.speed_mm_s,
            m.slide_start_s,
            m.slide_end_s,
            rec.times_s.clone(),
        );
        rows.append(manifest_row(py, &dataset.columns, m)?)?;
        infos.append(info)?;
        let array = Array3::from_shape_vec((t, l.rows, l.cols), rec.samples)
            .map_err(|e| raise(Kind::Data, format!("{}: {e}", m.file)))?;
        arrays.append(array.into_pyarray(py))?;
    }
    out.set_item("arrays", arrays)?;
    out.set_item("infos", infos)?;
    out.set_item("rows", rows)?;
    out.set_item("columns", dataset.columns.clone())?;
    out.set_item("fs", dataset.fs())?;
    out.set_item(
        "baseline",
        dataset.layout.baseline.unwrap_or_default().to_string(),
    )?;
    out.set_item("mask", mask)?;
    Ok(out)
}

/// A feature table, its column names, its recordings' manifest rows and what was
/// calibrated.
type TableWithRows<'py> = (
    Bound<'py, PyArray2<f64>>,
    Vec<String>,
    Bound<'py, PyList>,
    Report,
);

/// The feature table of a dataset folder, computed as `neurotex features --dataset` does
/// (the recordings read, encoded and featured in parallel without the GIL; under
/// `gain="auto"` or `causal=True` the pipeline calibrated on all of them first): `(values,
/// names, manifest rows, what was calibrated)`.
#[pyfunction]
fn features_dataset<'py>(
    py: Python<'py>,
    dir: PathBuf,
    method: &str,
    options: &Bound<'py, PyDict>,
) -> PyResult<TableWithRows<'py>> {
    let method = params::method(method)?;
    let stages = params::stages(options)?;
    let dataset = open(&dir)?;
    let (values, names, metas, c) = py.detach(|| {
        guarded(|| {
            let all: Vec<usize> = (0..dataset.entries.len()).collect();
            let baseline = dataset.layout.baseline.unwrap_or_default();
            let c = calibrated(&stages, &|i| dataset.load(i), &all, baseline)?;
            let encoded = c.pipeline.encode_dataset(&dataset, &all, &|| ())?;
            let (values, names) = table_of(&encoded, &c.pipeline, method)?;
            let metas: Vec<Meta> = encoded.into_iter().map(|e| e.meta).collect();
            Ok((values, names, metas, c))
        })
    })?;
    let rows = PyList::empty(py);
    for m in &metas {
        rows.append(manifest_row(py, &dataset.columns, m)?)?;
    }
    Ok((values.into_pyarray(py), names, rows, c.report(py)?))
}

/// One recording's events as tonic's fields: x, y, t (microseconds), p.
type EventColumns<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// The spikes of a dataset folder's recordings `indices` as address events (`export
/// events`' convention: ON `p` 1 for the SA population, OFF `p` 0 for the FA one; `t` in
/// microseconds): an event dataset's events as read, a sampled one's encoded with the stage
/// options. Returns the events of each recording asked for, every recording's manifest row,
/// and the grid `(rows, cols)` of the first recording asked for (`None` with none).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn dataset_events<'py>(
    py: Python<'py>,
    dir: PathBuf,
    options: &Bound<'py, PyDict>,
    indices: Vec<usize>,
) -> PyResult<(
    Vec<EventColumns<'py>>,
    Bound<'py, PyList>,
    Option<(usize, usize)>,
)> {
    let stages = params::stages(options)?;
    let Some(params) = stages.fixed().cloned() else {
        let why = "gain='auto' and causal=True calibrate on a whole dataset; pass the gain (neurotex.calibrate_gain chooses one) and leave causal off";
        return Err(raise(Kind::Parameter, why.to_string()));
    };
    let dataset = open(&dir)?;
    let n = dataset.entries.len();
    if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
        let why = format!("row {bad} is beyond the manifest's {n} recordings");
        return Err(raise(Kind::Parameter, why));
    }
    let encoding = params.encoding;
    let (events, grid) = py.detach(|| {
        guarded(|| {
            let pipeline = Pipeline::new(params.clone())?;
            let encoded = pipeline.encode_dataset(&dataset, &indices, &|| ())?;
            let grid = encoded.first().map(|e| (e.spikes.rows, e.spikes.cols));
            let events: Vec<Vec<Event>> = encoded
                .par_iter()
                .map(|e| encoded_events(e, encoding))
                .collect();
            Ok((events, grid))
        })
    })?;
    let columns = events
        .into_iter()
        .map(|ev| {
            let column =
                |f: fn(&Event) -> i64| ev.iter().map(f).collect::<Vec<i64>>().into_pyarray(py);
            (
                column(|e| i64::from(e.x)),
                column(|e| i64::from(e.y)),
                column(|e| i64::from(e.t_ms) * 1000),
                column(|e| i64::from(e.p)),
            )
        })
        .collect();
    let rows = PyList::empty(py);
    for m in &dataset.entries {
        rows.append(manifest_row(py, &dataset.columns, m)?)?;
    }
    Ok((columns, rows, grid))
}

/// Writes arrays as a dataset folder (whole or not at all): one `.npy` per recording named
/// as `infos` say (float32 or float64 as given, `(T, rows, cols)`), `manifest.csv` with
/// `extra` columns, and `layout.toml` with `fs` and the mask.
#[pyfunction]
#[pyo3(signature = (dir, recordings, infos, trials, forces, extra, fs))]
#[allow(clippy::too_many_arguments)]
fn save_dataset(
    py: Python<'_>,
    dir: PathBuf,
    recordings: Vec<Bound<'_, PyAny>>,
    infos: Vec<InfoTuple>,
    trials: Vec<Option<i64>>,
    forces: Vec<Option<f64>>,
    extra: Vec<std::collections::BTreeMap<String, String>>,
    fs: f64,
) -> PyResult<()> {
    let n = recordings.len();
    if [trials.len(), forces.len(), extra.len()] != [n; 3] {
        return Err(raise(
            Kind::Parameter,
            "one description per recording is needed",
        ));
    }
    let batch = Batch::new(&recordings, infos)?;
    let view = batch.view();
    let infos = view.infos();
    // Check every recording as `features` would before anything is written.
    let mut metas = Vec::with_capacity(n);
    let mut grid: Option<(usize, usize, Vec<bool>)> = None;
    for (i, info) in infos.iter().enumerate() {
        let rec = guarded(|| view.load(i))?;
        let l = &rec.layout;
        let this = (l.rows, l.cols, l.present.clone());
        match &grid {
            None => grid = Some(this),
            Some(g) if *g != this => {
                return Err(raise(
                    Kind::Data,
                    format!(
                        "{}: its grid {}x{} (or mask) differs from the first recording's {}x{}",
                        info.name, l.rows, l.cols, g.0, g.1
                    ),
                ))
            }
            Some(_) => {}
        }
        if !info.name.ends_with(".npy") || info.name.contains(['/', '\\']) {
            return Err(raise(
                Kind::Parameter,
                format!(
                    "file name `{}` must be a plain name ending in .npy",
                    info.name
                ),
            ));
        }
        let mut meta = info.meta.clone();
        meta.trial = trials[i];
        meta.force_n = forces[i];
        meta.extra = extra[i].clone();
        metas.push(meta);
    }
    let grid = grid.ok_or_else(|| raise(Kind::Data, "no recordings to save"))?;
    let layout = layout_file(fs, grid);
    py.detach(|| {
        guarded(|| {
            create_dataset_dir(&dir, |tmp| {
                for (i, info) in infos.iter().enumerate() {
                    view.write_npy(i, &tmp.join(&info.name))?;
                }
                write_manifest(tmp, &metas)?;
                write_layout(tmp, &layout)
            })
        })
    })
}

/// The `layout.toml` of recordings at `fs` Hz on a `(rows, cols, present)` grid: the mask
/// only when a cell is empty.
fn layout_file(fs: f64, (rows, cols, present): (usize, usize, Vec<bool>)) -> LayoutFile {
    let mut layout = LayoutFile {
        fs: Some(fs),
        rows: Some(rows),
        cols: Some(cols),
        ..LayoutFile::default()
    };
    if !present.iter().all(|&p| p) {
        layout.mask = Some(
            present
                .chunks(cols)
                .map(|r| r.iter().map(|&p| if p { '1' } else { '0' }).collect())
                .collect(),
        );
    }
    layout
}

/// Simulates the paper's rig into a dataset folder, as `neurotex simulate` does.
#[pyfunction]
#[pyo3(signature = (out, seed, trials, speeds, textures=None))]
fn simulate(
    py: Python<'_>,
    out: PathBuf,
    seed: u64,
    trials: u32,
    speeds: Vec<f64>,
    textures: Option<Vec<String>>,
) -> PyResult<()> {
    let textures: Vec<Texture> = match textures {
        None => ALL_TEXTURES.to_vec(),
        Some(names) => names
            .iter()
            .map(|n| texture(n).map_err(param))
            .collect::<PyResult<_>>()?,
    };
    for &s in &speeds {
        neurotex::Speed::new(s).map_err(param)?;
    }
    let rig = RigParams::default();
    py.detach(|| {
        guarded(|| {
            check_design(&rig, &textures, &speeds, trials)?;
            let design = design(&textures, &speeds, trials);
            write_dataset(&out, &rig, &design, seed, &|| ())
        })
    })
}

/// Registers the dataset functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(features_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(save_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(dataset_events, m)?)?;
    Ok(())
}
