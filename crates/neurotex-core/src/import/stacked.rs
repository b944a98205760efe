//! Importing the stacked arrays machine-learning datasets ship (`data.npy` and `labels.npy`):
//! the axes' order, the labels, one recording per trial.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use ndarray::{ArrayD, Axis, IxDyn};
use ndarray_npy::ReadNpyExt;
use rayon::prelude::*;

use crate::error::{DataError, ParamError, Result};
use crate::recording::{
    create_dataset_dir, labels_merged_by_trimming, write_layout, write_manifest, LayoutFile, Meta,
};
use crate::values::{Grid, Speed};

use super::invalid;

/// The axes of a stacked array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum AxisName {
    N,
    T,
    Row,
    Col,
    Channel,
}

impl AxisName {
    fn name(self) -> &'static str {
        match self {
            AxisName::N => "n",
            AxisName::T => "t",
            AxisName::Row => "row",
            AxisName::Col => "col",
            AxisName::Channel => "channel",
        }
    }
}

/// The axes of a stacked array in order, such as `n,row,col,t` or `n,t,channel`: `n` and
/// `t` once each, and either `row` and `col` or `channel`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Axes(Vec<AxisName>);

impl FromStr for Axes {
    type Err = ParamError;

    /// Parses comma-separated axis names.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        parse_axes(text).map(Axes)
    }
}

impl fmt::Display for Axes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.0.iter().map(|a| a.name()).collect();
        f.write_str(&names.join(","))
    }
}

/// Parses axes such as `n,row,col,t` or `n,t,channel`.
fn parse_axes(text: &str) -> Result<Vec<AxisName>, ParamError> {
    let axes: Vec<AxisName> = text
        .split(',')
        .map(|a| match a.trim() {
            "n" => Ok(AxisName::N),
            "t" => Ok(AxisName::T),
            "row" => Ok(AxisName::Row),
            "col" => Ok(AxisName::Col),
            "channel" => Ok(AxisName::Channel),
            other => Err(ParamError::new(
                "axes",
                "axes are named n, t, row, col or channel",
                other,
            )),
        })
        .collect::<Result<_, _>>()?;
    let count = |a| axes.iter().filter(|&&x| x == a).count();
    let grid =
        count(AxisName::Row) == 1 && count(AxisName::Col) == 1 && count(AxisName::Channel) == 0;
    let chans =
        count(AxisName::Channel) == 1 && count(AxisName::Row) == 0 && count(AxisName::Col) == 0;
    if count(AxisName::N) != 1 || count(AxisName::T) != 1 || !(grid || chans) {
        return Err(ParamError::new(
            "axes",
            "axes must name n and t once each, and either row and col or channel",
            text,
        ));
    }
    Ok(axes)
}

/// Reads a `.npy` of numbers as f64 (f64, f32, or any integer type). The header is checked
/// against the file's size first, so nothing larger than the file is allocated.
fn read_numbers(path: &Path) -> Result<ArrayD<f64>> {
    let header = crate::npy::read_header(path)?;
    let descr = &header.descr;
    if !header.is_number() {
        let message = format!("not a .npy array of numbers (float or integer): dtype `{descr}`");
        return Err(invalid(path, message));
    }
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    macro_rules! try_as {
        ($($t:ty),*) => {$(
            if let Ok(a) = ArrayD::<$t>::read_npy(bytes.as_slice()) {
                return Ok(a.mapv(|v| v as f64));
            }
        )*};
    }
    try_as!(f64, f32, i64, i32, i16, i8, u64, u32, u16, u8);
    let message = format!("not a readable .npy array of numbers (dtype `{descr}`)");
    Err(invalid(path, message))
}

/// The largest whole number every float up to it holds exactly (2^53): float labels
/// beyond would turn distinct integers into one.
const EXACT_FLOAT_INTEGER: f64 = 9_007_199_254_740_992.0;

/// Labels stored as numbers, as text: integers of any width exactly as they are, floats
/// only when whole and within [`EXACT_FLOAT_INTEGER`], so that two labels never merge.
fn numeric_labels(path: &Path, descr: &str) -> Result<Vec<String>> {
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    macro_rules! integers {
        ($($t:ty),*) => {$(
            if let Ok(a) = ArrayD::<$t>::read_npy(bytes.as_slice()) {
                return Ok(a.iter().map(|v| v.to_string()).collect());
            }
        )*};
    }
    integers!(i64, u64, i32, u32, i16, u16, i8, u8);
    let floats = ArrayD::<f64>::read_npy(bytes.as_slice())
        .or_else(|_| ArrayD::<f32>::read_npy(bytes.as_slice()).map(|a| a.mapv(f64::from)));
    let Ok(a) = floats else {
        let message = format!("not a readable .npy array of numbers (dtype `{descr}`)");
        return Err(invalid(path, message));
    };
    let whole = |v: f64| v.fract() == 0.0 && v.abs() <= EXACT_FLOAT_INTEGER;
    if let Some((i, v)) = a.iter().enumerate().find(|(_, &v)| !whole(v)) {
        let message = format!(
            "label {i} is {v:?}: float labels must be whole numbers within ±2^53, which a float holds exactly (beyond, distinct labels become one); store labels as integers or strings"
        );
        return Err(invalid(path, message));
    }
    Ok(a.iter().map(|&v| format!("{}", v as i64)).collect())
}

/// Reads labels: integers, or fixed-width strings (`<U` or `|S`), one per sample.
fn read_labels(path: &Path) -> Result<Vec<String>> {
    let header = crate::npy::read_header(path)?;
    if header.is_number() {
        return numeric_labels(path, &header.descr);
    }
    let descr = &header.descr;
    let little = !descr.starts_with('>');
    if !(matches!(header.kind, 'U' | 'S') && little) {
        let message =
            format!("labels must be integers or strings (`<U` or `|S`), got dtype `{descr}`");
        return Err(invalid(path, message));
    }
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    // the header check proved the data section is exactly `elements * item_bytes` bytes
    let data = bytes.get(header.data_offset..).unwrap_or_default();
    let labels: Vec<String> = data
        .chunks_exact(header.item_bytes)
        .take(header.elements)
        .enumerate()
        .map(|(i, chunk)| {
            // Decoded strictly: replacing bad code points or bytes would merge labels.
            let label = match header.kind {
                'U' => chunk
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .take_while(|&c| c != 0)
                    .map(char::from_u32)
                    .collect::<Option<String>>(),
                _ => {
                    let end = chunk.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1);
                    std::str::from_utf8(&chunk[..end]).ok().map(String::from)
                }
            };
            label.ok_or_else(|| {
                invalid(
                    path,
                    format!("label {i} is not valid text (UTF-8 for `|S`, Unicode code points for `<U`)"),
                )
            })
        })
        .collect::<Result<_>>()?;
    if labels.iter().any(|l| l.is_empty()) {
        return Err(invalid(path, "a label is empty"));
    }
    Ok(labels)
}

/// Options of a stacked-array import.
#[derive(Debug, Clone)]
pub struct StackedParams {
    /// The data's axes, e.g. `n,row,col,t` or `n,t,channel`.
    pub axes: Axes,
    /// Sampling rate, Hz.
    pub fs: f64,
    /// With a channel axis: the grid to place channels on (row-major); default `1 x channels`.
    pub grid: Option<Grid>,
}

/// Imports `data` (`N` samples stacked along one axis) with `labels` (and optional speeds)
/// into a new dataset folder: one `.npy` (f32, `(T, rows, cols)`) per sample, the manifest
/// and `layout.toml`.
///
/// # Errors
/// Axes that do not fit the data, labels or speeds of the wrong length, bad values, or
/// `out` not empty.
pub fn import_stacked(
    data: &Path,
    labels: &Path,
    speeds: Option<&Path>,
    p: &StackedParams,
    out: &Path,
) -> Result<usize> {
    crate::values::SampleRate::new(p.fs)?;
    let (arr, (rows, cols)) = stacked_samples(data, p)?;
    let (n, t) = (arr.shape()[0], arr.shape()[1]);
    let metas = stacked_metas(data, labels, speeds, n)?;
    create_dataset_dir(out, |tmp| {
        metas
            .par_iter()
            .enumerate()
            .try_for_each(|(i, m)| -> Result<()> {
                let sample = arr.index_axis(Axis(0), i);
                let values: Vec<f32> = sample.iter().map(|&v| v as f32).collect();
                let a = ndarray::Array3::from_shape_vec((t, rows, cols), values)
                    .map_err(|e| DataError::invalid(data, e.to_string()))?;
                let path = tmp.join(&m.file);
                ndarray_npy::write_npy(&path, &a)
                    .map_err(|e| DataError::invalid(&path, e.to_string()))?;
                Ok(())
            })?;
        let layout = LayoutFile {
            fs: Some(p.fs),
            rows: Some(rows),
            cols: Some(cols),
            ..LayoutFile::default()
        };
        write_layout(tmp, &layout)?;
        write_manifest(tmp, &metas)?;
        read_back(tmp)
    })?;
    Ok(n)
}

/// Opens the dataset just written in `dir` and reads every recording back, so an import
/// never reports success for a dataset neurotex cannot read (a label, speed or grid the
/// readers refuse); the folder is not yet in place, and is removed on error.
///
/// # Errors
/// The first part that does not read back, with what the reader said.
pub(super) fn read_back(dir: &Path) -> Result<()> {
    let back = |e: crate::Error| -> crate::Error {
        DataError::invalid(
            dir,
            format!("the import would write a dataset neurotex cannot read back: {e}"),
        )
        .into()
    };
    let dataset = crate::recording::Dataset::open(dir).map_err(back)?;
    (0..dataset.entries.len())
        .into_par_iter()
        .try_for_each(|i| dataset.load(i).map(drop))
        .map_err(back)
}

/// The stacked array read and checked, its axes put in the order `n, t, cells...`, and the
/// grid each sample is laid out on.
fn stacked_samples(data: &Path, p: &StackedParams) -> Result<(ArrayD<f64>, (usize, usize))> {
    let axes = &p.axes.0;
    let array = read_numbers(data)?;
    if array.ndim() != axes.len() {
        let (named, has, shape) = (axes.len(), array.ndim(), array.shape());
        let message = format!("--axes names {named} axes but the data has {has} (shape {shape:?})");
        return Err(invalid(data, message));
    }
    if let Some(pos) = array
        .iter()
        .position(|&v| !crate::values::sample_in_range(v))
    {
        let value = array.iter().nth(pos).copied().unwrap_or(f64::NAN);
        let rule = crate::values::SAMPLE_RULE;
        return Err(invalid(
            data,
            format!("value {pos} (flat index) is {value:?} ({rule})"),
        ));
    }
    let find = |a: AxisName| axes.iter().position(|&x| x == a);
    let has_grid = find(AxisName::Row).is_some();
    let wanted: &[AxisName] = if has_grid {
        &[AxisName::N, AxisName::T, AxisName::Row, AxisName::Col]
    } else {
        &[AxisName::N, AxisName::T, AxisName::Channel]
    };
    let order: Vec<usize> = wanted.iter().filter_map(|&a| find(a)).collect();
    let arr = array
        .permuted_axes(IxDyn(&order))
        .as_standard_layout()
        .into_owned();
    let shape = arr.shape().to_vec();
    let grid = if has_grid {
        if let Some(g) = &p.grid {
            let rule = "--grid places a channel axis on a grid; data with row and col axes has its grid already";
            let got = format!("{g} for axes with a {}x{} grid", shape[2], shape[3]);
            return Err(ParamError::new("grid", rule, got).into());
        }
        (shape[2], shape[3])
    } else {
        let ch = shape[2];
        match &p.grid {
            Some(g) if g.cells() == ch => (g.rows(), g.cols()),
            Some(g) => {
                let rule = "the grid must have as many cells as channels";
                let got = format!("{g} for {ch} channels");
                return Err(ParamError::new("grid", rule, got).into());
            }
            None => (1, ch),
        }
    };
    if shape[0] == 0 || shape[1] == 0 {
        let message = format!("no samples or no time steps (shape {shape:?})");
        return Err(invalid(data, message));
    }
    crate::values::check_grid_cells(grid.0, grid.1)
        .map_err(|e| invalid(data, format!("shape {shape:?}: {e}")))?;
    Ok((arr, grid))
}

/// One manifest row per stacked sample: its label, its speed (none without a speeds file),
/// and a trial number counting the samples of each label and speed.
fn stacked_metas(
    data: &Path,
    labels_path: &Path,
    speeds: Option<&Path>,
    n: usize,
) -> Result<Vec<Meta>> {
    let labels = read_labels(labels_path)?.into_iter().collect::<Vec<_>>();
    if labels.len() != n {
        let message = format!("{} labels for {n} samples", labels.len());
        return Err(DataError::invalid(data, message).into());
    }
    let written: Vec<(String, String)> = labels
        .iter()
        .enumerate()
        .map(|(i, l)| (l.clone(), format!("label {i}")))
        .collect();
    if let Some(message) = labels_merged_by_trimming(&written) {
        return Err(DataError::invalid(labels_path, message).into());
    }
    let speeds: Vec<Option<f64>> = match speeds {
        Some(path) => {
            let s = read_numbers(path)?;
            if s.len() != n {
                return Err(invalid(path, format!("{} speeds for {n} samples", s.len())));
            }
            s.iter().copied().map(Some).collect()
        }
        None => vec![None; n],
    };
    let mut trial_of: BTreeMap<(String, Option<Speed>), i64> = BTreeMap::new();
    Ok((0..n)
        .map(|i| {
            let trial = trial_of
                .entry((labels[i].clone(), speeds[i].map(Speed::of)))
                .or_insert(0);
            let meta = Meta {
                file: format!("sample_{i:05}.npy"),
                label: labels[i].clone(),
                speed_mm_s: speeds[i],
                trial: Some(*trial),
                ..Meta::default()
            };
            *trial += 1;
            meta
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_back_refuses_a_dataset_the_readers_refuse() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.csv"), "t_ms,c\n0,1\n1,2\n").unwrap();
        std::fs::write(dir.path().join("manifest.csv"), "file,label\na.csv,x\n").unwrap();
        read_back(dir.path()).unwrap();
        // A recording whose samples the reader refuses (a NaN).
        std::fs::write(dir.path().join("a.csv"), "t_ms,c\n0,1\n1,NaN\n").unwrap();
        let err = read_back(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("cannot read back") && err.contains("a.csv"),
            "{err}"
        );
    }
}
