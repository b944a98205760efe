//! Reading one recording's samples from `.npy` or `.csv` and checking them: shape, channels
//! onto the grid's cells, finite values, duration.

use std::path::{Path, PathBuf};

use ndarray::ArrayD;
use ndarray_npy::ReadNpyExt;

use crate::csvlog::{choose_format, read_csv_log, CsvFormat, CsvOverrides};
use crate::error::{DataError, Result};
use crate::simd::widest_or_plain;
use crate::values::VALUES_PER_LIMIT_S;

use super::layout_file::{LayoutFile, DEFAULT_MAX_DURATION_S};
use super::{Layout, Meta, Recording, Shape, EVENTS_NOT_SAMPLES};

/// Reads one recording file (`.npy` or `.csv`) with the dataset's layout settings.
///
/// # Errors
/// Unreadable file, unsupported dtype or shape, layout mismatch, non-finite samples,
/// non-increasing time stamps.
pub fn read_recording(path: &Path, layout: &LayoutFile) -> Result<Recording> {
    let format = layout
        .csv_format()
        .map_err(|e| DataError::invalid(path, e.to_string()))?;
    read_recording_as(path, layout, &format)
}

/// Where the layout a recording file was read with came from.
#[derive(Debug, Clone, PartialEq)]
pub enum LayoutFrom {
    /// The caller's (`--layout FILE`).
    Given,
    /// The `layout.toml` beside the file, at this path.
    Beside(PathBuf),
    /// The one remembered with a model: its training dataset's.
    Remembered,
    /// None: the defaults.
    Default,
}

/// How a recording file given by path (not through a dataset's manifest) is read: the
/// options `encode`, `predict` and `stream` take alike. Its layout is the given one, else
/// the `layout.toml` beside the file, else one remembered (a model's training dataset's),
/// else the defaults; `fs` and `grid` then replace the layout's, and a CSV file is read in
/// the first of the layout's formats that fits it ([`LayoutFile::csv_formats`]) with the
/// CSV overrides applied.
#[derive(Debug, Clone, Default)]
pub struct FileReading {
    /// A layout given for every file.
    pub layout: Option<LayoutFile>,
    /// Sampling rate in Hz, in place of the layout's.
    pub fs: Option<f64>,
    /// Grid `(rows, cols)`, channels row-major: replaces the layout's grid, map and mask.
    pub grid: Option<(usize, usize)>,
    /// CSV reading options, in place of the layout's.
    pub csv: CsvOverrides,
}

impl FileReading {
    /// The layout for `file` and where it came from (see [`FileReading`]).
    ///
    /// # Errors
    /// A `layout.toml` beside the file that cannot be read.
    pub fn layout_for(
        &self,
        file: &Path,
        remembered: Option<&LayoutFile>,
    ) -> Result<(LayoutFile, LayoutFrom)> {
        let beside = file
            .parent()
            .map(|dir| dir.join("layout.toml"))
            .filter(|p| p.is_file());
        let (mut layout, from) = match (&self.layout, beside, remembered) {
            (Some(given), _, _) => (given.clone(), LayoutFrom::Given),
            (None, Some(path), _) => (LayoutFile::read(&path)?, LayoutFrom::Beside(path)),
            (None, None, Some(model)) => (model.clone(), LayoutFrom::Remembered),
            (None, None, None) => (LayoutFile::default(), LayoutFrom::Default),
        };
        if let Some(fs) = self.fs {
            layout.fs = Some(fs);
        }
        if let Some((rows, cols)) = self.grid {
            layout.rows = Some(rows);
            layout.cols = Some(cols);
            layout.channel_map = None;
            layout.mask = None;
        }
        Ok((layout, from))
    }

    /// The CSV format to read `file` with under `layout`: the first of its formats whose
    /// columns the file has ([`LayoutFile::csv_formats`]).
    ///
    /// # Errors
    /// A layout whose CSV fields are broken, or a file that fits none of its formats.
    pub fn csv_format(&self, file: &Path, layout: &LayoutFile) -> Result<CsvFormat> {
        let mut formats = layout
            .csv_formats(&self.csv)
            .map_err(|e| DataError::invalid(file, e.to_string()))?;
        let is_csv = file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        match is_csv {
            true => choose_format(file, &formats, &|_| Ok(())),
            false => Ok(formats.swap_remove(0)),
        }
    }

    /// Reads `file` (see [`FileReading`]), saying where its layout came from.
    ///
    /// # Errors
    /// As [`FileReading::layout_for`], [`FileReading::csv_format`] and
    /// [`read_recording_as`].
    pub fn read(
        &self,
        file: &Path,
        remembered: Option<&LayoutFile>,
    ) -> Result<(Recording, LayoutFrom)> {
        let (layout, from) = self.layout_for(file, remembered)?;
        let format = self.csv_format(file, &layout)?;
        Ok((read_recording_as(file, &layout, &format)?, from))
    }
}

/// Reads one recording file (`.npy` or `.csv`) with the layout's grid, map, mask and rate,
/// a CSV file as `format` says (which overrides the layout's CSV settings).
///
/// # Errors
/// As [`read_recording`].
pub fn read_recording_as(
    path: &Path,
    layout: &LayoutFile,
    format: &CsvFormat,
) -> Result<Recording> {
    if layout.events.is_some() {
        return Err(DataError::invalid(path, EVENTS_NOT_SAMPLES).into());
    }
    let (shape, raw, times_s, finite) = read_samples(path, format)?;
    let n_channels = checked_channels(path, shape, &raw, finite)?;
    let t = raw.len() / n_channels;
    let lay = layout.layout_for(path, shape)?;
    check_duration(path, layout, t, times_s.as_deref(), lay.cells(), raw.len())?;
    let samples = onto_cells(raw, n_channels, &lay);
    Ok(Recording {
        fs: layout.fs.unwrap_or(1000.0),
        layout: lay,
        samples,
        times_s,
        phases: None,
        meta: Meta {
            file: path
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default(),
            ..Meta::default()
        },
    })
}

/// A recording from frame-major channel samples (`n_channels` values a frame) placed on
/// the layout's grid, map and mask at its rate, as a CSV log of those channels reads;
/// `times_s` are stamps in s from the first.
///
/// # Errors
/// Channels that do not fit the layout, or more samples than its limits allow.
pub fn recording_from_channels(
    path: &Path,
    layout: &LayoutFile,
    raw: Vec<f64>,
    n_channels: usize,
    times_s: Option<Vec<f64>>,
    meta: Meta,
) -> Result<Recording> {
    let finite = all_finite(&raw);
    let n_channels = checked_channels(path, Shape::Channels(n_channels), &raw, finite)?;
    let lay = layout.layout_for(path, Shape::Channels(n_channels))?;
    let frames = raw.len() / n_channels;
    check_duration(
        path,
        layout,
        frames,
        times_s.as_deref(),
        lay.cells(),
        raw.len(),
    )?;
    let samples = onto_cells(raw, n_channels, &lay);
    Ok(Recording {
        fs: layout.fs.unwrap_or(1000.0),
        layout: lay,
        samples,
        times_s,
        phases: None,
        meta,
    })
}

/// A `.npy` or `.csv` recording's shape, samples (frame-major), time stamps in seconds
/// (CSV only) and whether every sample is finite.
///
/// # Errors
/// Another extension, or a file its reader refuses.
fn read_samples(path: &Path, format: &CsvFormat) -> Result<RawSamples> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "npy" => {
            let (shape, raw, finite) = read_npy(path)?;
            Ok((shape, raw, None, finite))
        }
        "csv" => {
            let (shape, raw, times_s) = read_csv_samples(path, format)?;
            let finite = all_finite(&raw);
            Ok((shape, raw, times_s, finite))
        }
        _ if path.is_dir() => Err(DataError::invalid(
            path,
            "a folder, not a recording: give its recordings (FOLDER/*.csv, FOLDER/*.npy), or a dataset folder with --dataset",
        )
        .into()),
        _ => Err(DataError::invalid(
            path,
            "unsupported recording format: expected a .npy or .csv file",
        )
        .into()),
    }
}

/// A file's shape, samples, time stamps in seconds and whether every sample is finite.
type RawSamples = (Shape, Vec<f64>, Option<Vec<f64>>, bool);

/// The number of channels of `shape`, checked: at least one, at most the cell limit, and
/// every sample finite (`finite`; the first bad one is named from `raw`).
///
/// # Errors
/// The rule broken.
fn checked_channels(path: &Path, shape: Shape, raw: &[f64], finite: bool) -> Result<usize> {
    let n_channels = match shape {
        Shape::Grid(r, c) => r * c,
        Shape::Channels(n) => n,
    };
    if n_channels == 0 {
        return Err(DataError::invalid(path, "recording has no channels").into());
    }
    if n_channels > crate::values::MAX_CELLS {
        let max = crate::values::MAX_CELLS;
        let message = format!("recording has {n_channels} channels, beyond the limit of {max}");
        return Err(DataError::invalid(path, message).into());
    }
    if let Some(pos) = (!finite)
        .then(|| raw.iter().position(|&v| !crate::values::sample_in_range(v)))
        .flatten()
    {
        return Err(DataError::invalid(
            path,
            format!(
                "sample {} of channel {} is {:?} ({})",
                pos / n_channels,
                pos % n_channels,
                raw[pos],
                crate::values::SAMPLE_RULE
            ),
        )
        .into());
    }
    Ok(n_channels)
}

/// The frames of `raw` (`n_channels` values each) placed on the layout's cells by its
/// channel map; unmapped cells 0. `raw` itself when the map is the identity.
fn onto_cells(raw: Vec<f64>, n_channels: usize, lay: &Layout) -> Vec<f64> {
    if lay.channel_map.iter().copied().eq(0..lay.cells()) {
        return raw;
    }
    let cells = lay.cells();
    let mut out = vec![0.0; raw.len() / n_channels * cells];
    for (frame_in, frame_out) in raw
        .chunks_exact(n_channels)
        .zip(out.chunks_exact_mut(cells))
    {
        for (&v, &cell) in frame_in.iter().zip(&lay.channel_map) {
            frame_out[cell] = v;
        }
    }
    out
}

/// A recording's time span must stay within the layout's `max_duration_s` (default
/// [`DEFAULT_MAX_DURATION_S`]), and so must what it becomes in memory: resampling allocates
/// one frame of `cells` values per millisecond of the span, and placing the channels on the
/// grid one per sample, so neither may exceed `max_duration_s` x [`VALUES_PER_LIMIT_S`]
/// values (a few channels on a huge grid, or a wide file whose stamps span an hour, would
/// otherwise ask for far more memory than the file holds). `raw_values` (already in memory)
/// is always allowed.
fn check_duration(
    path: &Path,
    layout: &LayoutFile,
    frames: usize,
    times: Option<&[f64]>,
    cells: usize,
    raw_values: usize,
) -> Result<()> {
    let fs = layout.fs.unwrap_or(1000.0);
    let span = match times {
        Some([first, .., last]) => last - first,
        Some(_) => 0.0,
        None => frames as f64 / fs,
    };
    let max = layout.max_duration_s.unwrap_or(DEFAULT_MAX_DURATION_S);
    let what = || match times {
        Some(_) => "time stamps span".to_string(),
        None => format!("{frames} samples at {fs} Hz last"),
    };
    let raise = "set `max_duration_s` in layout.toml to raise it";
    if span > max {
        let message = format!(
            "{} {span} s, beyond the limit of {max} s per recording (resampling to 1 kHz \
             allocates a frame per ms; {raise})",
            what()
        );
        return Err(DataError::invalid(path, message).into());
    }
    let max_values = max * VALUES_PER_LIMIT_S;
    let resampled = span * 1000.0 * cells as f64;
    let placed = frames as f64 * cells as f64;
    if resampled > max_values || (placed > max_values && placed > raw_values as f64) {
        let message = format!(
            "{} {span} s on {cells} grid cells: {:.3e} values once placed on the grid and \
             resampled to 1 kHz, beyond the limit of {max_values:.3e} ({max} s of a 16-taxel \
             grid; a wrong grid, rate or time unit is the usual cause, else {raise})",
            what(),
            resampled.max(placed),
        );
        return Err(DataError::invalid(path, message).into());
    }
    Ok(())
}

/// A `.npy` recording's shape, its samples as f64 and whether every one is finite.
pub(super) fn read_npy(path: &Path) -> Result<(Shape, Vec<f64>, bool)> {
    // The header is checked against the file's size first, so nothing larger than the
    // file is ever allocated for it.
    let header = crate::npy::read_header(path)?;
    let shape = match header.shape[..] {
        [_, r, c] => Shape::Grid(r, c),
        [_, n] => Shape::Channels(n),
        ref other => {
            return Err(DataError::invalid(
                path,
                format!("expected shape (T, rows, cols) or (T, channels), got {other:?}"),
            )
            .into())
        }
    };
    let (rows, cols) = match shape {
        Shape::Grid(r, c) => (r, c),
        Shape::Channels(n) => (1, n),
    };
    crate::values::check_grid_cells(rows, cols)
        .map_err(|e| DataError::invalid(path, format!("shape {:?}: {e}", header.shape)))?;
    if let Some(floats) = crate::npy::read_le_floats(path, &header)? {
        return Ok((shape, floats.samples, floats.finite));
    }
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    let unreadable = |e: ndarray_npy::ReadNpyError| {
        DataError::invalid(path, format!("not a readable .npy of float samples: {e}"))
    };
    let array: ArrayD<f64> = match (header.kind, header.item_bytes) {
        ('f', 8) => ArrayD::<f64>::read_npy(bytes.as_slice()).map_err(unreadable)?,
        ('f', 4) => ArrayD::<f32>::read_npy(bytes.as_slice())
            .map_err(unreadable)?
            .mapv(f64::from),
        _ => {
            let message = format!(
                "samples must be float32 or float64, got dtype `{}`",
                header.descr
            );
            return Err(DataError::invalid(path, message).into());
        }
    };
    drop(bytes);
    let samples = array
        .as_standard_layout()
        .into_owned()
        .into_raw_vec_and_offset()
        .0;
    let finite = all_finite(&samples);
    Ok((shape, samples, finite))
}

widest_or_plain! {
    ["avx2"]
    /// Whether every sample is in range ([`crate::values::sample_in_range`]): one pass
    /// without early exit, which vectorises (the position of a bad one is sought only for
    /// the error).
    fn all_finite(samples: &[f64]) -> bool {
        let mut bad = false;
        for &v in samples {
            bad |= !crate::values::sample_in_range(v);
        }
        !bad
    }
}

/// A CSV recording read as `format` says: its channels, samples and time stamps in seconds
/// from the first.
///
/// The first stamp is subtracted in the stamps' own unit, where integer stamps (ms or us
/// since an epoch, up to 2^53) subtract exactly, and only then converted to seconds
/// ([`TimeUnit::to_seconds`]): a raw log stamped from an epoch and its imported copy
/// stamped from 0 give the same times to the bit, and a stamp on the encoder's grid gives
/// its sample exactly.
fn read_csv_samples(
    path: &Path,
    format: &CsvFormat,
) -> Result<(Shape, Vec<f64>, Option<Vec<f64>>)> {
    let log = read_csv_log(path, format)?;
    let unit = log.time_unit;
    let times = log.times.map(|t| {
        let first = t.first().copied().unwrap_or(0.0);
        t.into_iter().map(|x| unit.to_seconds(x - first)).collect()
    });
    Ok((Shape::Channels(log.channel_names.len()), log.samples, times))
}
