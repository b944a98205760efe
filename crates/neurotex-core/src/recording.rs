//! The data model: recordings, layouts, dataset folders and their I/O (docs/your-data.md).
//!
//! A dataset is a folder with `manifest.csv` naming recordings (`.npy` or `.csv`) and an
//! optional `layout.toml`. Recordings are loaded one at a time ([`Dataset::load`]) so a
//! dataset's raw samples are never all in memory at once.
//!
//! The layout's settings a user also types on a command line ([`Baseline`], [`TimeUnit`],
//! [`ChannelMap`]) parse from text with `FromStr`.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use ndarray::ArrayD;
use ndarray_npy::ReadNpyExt;
use serde::{Deserialize, Serialize};

use crate::csvlog::{
    choose_format, csv_error, read_csv_log, CsvFormat, CsvOverrides, Delimiter, DuplicateStamps,
    LogColumns,
};
pub use crate::error::DatasetError;
use crate::error::{DataError, ParamError, Result};
use crate::simd::widest_or_plain;
pub use crate::values::TimeUnit;
use crate::values::{Cell, Grid, SampleRate, Speed, FS_RULE};

/// The phase of the protocol a sample belongs to (paper section II-D).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(u8)]
pub enum Phase {
    /// The sensor is off the surface.
    Free,
    /// Pressing onto the surface up to the target force.
    Contact,
    /// Held still at the target force.
    Hold,
    /// Sliding across the texture.
    Slide,
    /// Lifting off.
    Retract,
}

/// Where the taxels sit: a `rows x cols` grid, the map from file channel to grid cell and
/// the cells that hold no taxel.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// For each file channel, its cell index `row * cols + col`.
    pub channel_map: Vec<usize>,
    /// For each cell, whether a taxel is there (`false` = masked).
    pub present: Vec<bool>,
}

impl Layout {
    /// A full grid whose channels fill the cells in row-major order.
    pub fn grid(rows: usize, cols: usize) -> Self {
        Layout {
            rows,
            cols,
            channel_map: (0..rows * cols).collect(),
            present: vec![true; rows * cols],
        }
    }

    /// Number of grid cells (`rows * cols`).
    pub fn cells(&self) -> usize {
        self.rows * self.cols
    }
}

/// A recording's descriptive fields, as in the manifest.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Meta {
    /// The recording's file name relative to the dataset folder.
    pub file: String,
    /// Texture class.
    pub label: String,
    /// Sliding speed in mm/s (sign = direction where the rig records it); `None` when the
    /// manifest has no `speed_mm_s` column or leaves the field empty (one condition).
    pub speed_mm_s: Option<f64>,
    /// Normal force in N; `None` when the manifest does not give it.
    pub force_n: Option<f64>,
    /// Trial number; `None` when the manifest does not give it.
    pub trial: Option<i64>,
    /// Start of the sliding phase in s from the recording's start, if known.
    pub slide_start_s: Option<f64>,
    /// End of the sliding phase in s, if known.
    pub slide_end_s: Option<f64>,
    /// Any further manifest columns.
    pub extra: BTreeMap<String, String>,
}

impl Meta {
    /// The sliding speed as a condition; `None` when the manifest gives none.
    pub fn speed(&self) -> Option<Speed> {
        self.speed_mm_s.map(Speed::of)
    }

    /// The value of manifest column `column` as text (numbers written as the shortest
    /// decimal that reads back to them, as [`write_manifest`] does); `None` when this
    /// recording has no value there (an absent column or an empty field).
    pub fn field(&self, column: &str) -> Option<String> {
        let number = |v: Option<f64>| v.map(|x| x.to_string());
        match column {
            "file" => Some(self.file.clone()),
            "label" => Some(self.label.clone()),
            "speed_mm_s" => number(self.speed_mm_s),
            "force_n" => number(self.force_n),
            "trial" => self.trial.map(|t| t.to_string()),
            "slide_start_s" => number(self.slide_start_s),
            "slide_end_s" => number(self.slide_end_s),
            other => self.extra.get(other).filter(|v| !v.is_empty()).cloned(),
        }
    }

    /// The manifest columns some of `metas` have a value in, in manifest order (the
    /// standard columns first): what a column-naming option may name.
    pub fn columns_with_values(metas: &[Meta]) -> Vec<String> {
        let standard = ["file", "label"].into_iter().chain(NUMERIC_COLUMNS);
        let extra = metas
            .iter()
            .flat_map(|m| m.extra.keys().map(String::as_str));
        let mut names: Vec<String> = Vec::new();
        for name in standard.chain(extra) {
            let valued = metas.iter().any(|m| m.field(name).is_some());
            if valued && !names.iter().any(|n| n == name) {
                names.push(name.to_string());
            }
        }
        names
    }
}

/// The manifest columns whose values are numbers, compared as numbers.
pub const NUMERIC_COLUMNS: [&str; 5] = [
    "speed_mm_s",
    "force_n",
    "trial",
    "slide_start_s",
    "slide_end_s",
];

/// One trial's samples, time-major `T x rows x cols`, with its sampling and metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Sampling rate in Hz (nominal when `times_s` is given).
    pub fs: f64,
    /// Grid and mask.
    pub layout: Layout,
    /// Samples, `T * rows * cols`, cell index fastest. Masked cells hold 0.
    pub samples: Vec<f64>,
    /// Per-sample time stamps in s from the first (so the first is 0; strictly increasing),
    /// for recordings read with time stamps.
    pub times_s: Option<Vec<f64>>,
    /// Per-sample protocol phase, where the source labels phases.
    pub phases: Option<Vec<Phase>>,
    /// Descriptive fields.
    pub meta: Meta,
}

impl Recording {
    /// Number of time samples.
    pub fn len(&self) -> usize {
        self.samples.len() / self.layout.cells().max(1)
    }

    /// Whether the recording holds no samples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Duration in seconds.
    pub fn duration_s(&self) -> f64 {
        match &self.times_s {
            Some(t) if t.len() >= 2 => t[t.len() - 1] - t[0],
            _ => self.len() as f64 / self.fs,
        }
    }
}

/// How to remove a taxel's resting value before encoding.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Baseline {
    /// Leave the signal as it is (the paper's piezoresistive signal rests at zero).
    #[default]
    None,
    /// Subtract each taxel's minimum over the recording.
    Min,
    /// Subtract each taxel's mean over `[start_s, end_s)` of the recording.
    Mean {
        /// Interval start in s.
        start_s: f64,
        /// Interval end in s.
        end_s: f64,
    },
}

impl FromStr for Baseline {
    type Err = ParamError;

    /// Parses `none` or `min`; a mean over an interval is set in `layout.toml`.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        match text.trim() {
            "none" => Ok(Baseline::None),
            "min" => Ok(Baseline::Min),
            _ => Err(ParamError::new(
                "baseline",
                "a baseline is `none` or `min` (a mean over an interval is set in layout.toml)",
                text,
            )),
        }
    }
}

impl fmt::Display for Baseline {
    /// `none`, `min` (as typed on a command line), or `mean over [START, END) s`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Baseline::None => f.write_str("none"),
            Baseline::Min => f.write_str("min"),
            Baseline::Mean { start_s, end_s } => write!(f, "mean over [{start_s}, {end_s}) s"),
        }
    }
}

/// Each file channel's grid cell, in channel order: written `row,col;row,col;...`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelMap(Vec<Cell>);

impl ChannelMap {
    /// The map of `cells`, channel `k` to `cells[k]`.
    pub fn new(cells: Vec<Cell>) -> Self {
        ChannelMap(cells)
    }

    /// The cells in channel order.
    pub fn cells(&self) -> &[Cell] {
        &self.0
    }

    /// The map as `layout.toml` writes it, one `[row, col]` per channel.
    pub fn to_pairs(&self) -> Vec<[usize; 2]> {
        self.0.iter().map(|c| [c.row, c.col]).collect()
    }
}

impl fmt::Display for ChannelMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, c) in self.0.iter().enumerate() {
            let sep = if k == 0 { "" } else { ";" };
            write!(f, "{sep}{},{}", c.row, c.col)?;
        }
        Ok(())
    }
}

impl FromStr for ChannelMap {
    type Err = ParamError;

    /// Parses `row,col;row,col;...` (for example `0,0;0,1;1,0`).
    fn from_str(text: &str) -> Result<Self, ParamError> {
        text.split(';')
            .map(|entry| {
                entry.parse::<Cell>().map_err(|_| {
                    ParamError::new(
                        "channel-map",
                        "a channel map is row,col entries separated by `;`, for example 0,0;0,1",
                        format!("`{entry}` in {text}"),
                    )
                })
            })
            .collect::<Result<_, _>>()
            .map(ChannelMap)
    }
}

/// `layout.toml`: how to read a dataset's recordings.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayoutFile {
    /// Sampling rate in Hz (default 1000).
    pub fs: Option<f64>,
    /// Grid rows.
    pub rows: Option<usize>,
    /// Grid columns.
    pub cols: Option<usize>,
    /// For each file channel, `[row, col]`.
    pub channel_map: Option<Vec<[usize; 2]>>,
    /// One string per row, `1` for a taxel and `0` for a masked cell, e.g. `["1111", "1001"]`.
    pub mask: Option<Vec<String>>,
    /// Baseline removal.
    pub baseline: Option<Baseline>,
    /// CSV recordings: the time column's name.
    pub time_column: Option<String>,
    /// CSV recordings: the time column's unit, `ms` or `s`.
    pub time_unit: Option<TimeUnit>,
    /// CSV recordings: the channel columns, in channel order (default: every other column).
    /// Without a header row, the time column and the channels are 0-based indices (`"0"`).
    pub channels: Option<Vec<String>>,
    /// CSV recordings: the longest gap between time stamps resampling may fill, in s
    /// (default [`crate::csvlog::DEFAULT_MAX_GAP_S`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_gap_s: Option<f64>,
    /// Longest recording accepted, in s (default [`DEFAULT_MAX_DURATION_S`]); resampling
    /// allocates one frame per millisecond of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_duration_s: Option<f64>,
    /// CSV recordings: whether the first row names the columns (default `true`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub header: Option<bool>,
    /// CSV recordings: the field delimiter, `,` `;` or `tab` (default: detected).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delimiter: Option<Delimiter>,
    /// CSV recordings: rows sharing a time stamp (default `average`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duplicate_stamps: Option<DuplicateStamps>,
    /// How the raw logs an imported dataset came from were read (`import csv` writes it):
    /// a CSV file outside the dataset whose columns are not the dataset's is read this
    /// way, so a raw log of the same logger needs no options.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<LogColumns>,
    /// The recordings are address events, not samples: how to read them
    /// ([`crate::events`]). Needs `rows` and `cols`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub events: Option<crate::events::EventsFormat>,
}

/// The longest recording accepted unless `layout.toml` sets `max_duration_s`: one hour.
/// Resampling to the encoder's 1 kHz allocates one frame per millisecond of a recording's
/// time span, so the span, not the file's size, sets the memory: an hour of a 4x4 grid is
/// 3.6 million frames, 460 MB of f64 samples, about what a laptop can spare per worker.
/// The paper's slides last seconds; a span of days is a wrong time unit or sampling rate.
pub const DEFAULT_MAX_DURATION_S: f64 = 3600.0;

impl LayoutFile {
    /// Which of the grid's `cells` hold a taxel, row-major: the mask's `1`s, or all.
    fn present(&self, cells: usize) -> Vec<bool> {
        match &self.mask {
            Some(m) => m
                .iter()
                .flat_map(|row| row.chars().map(|ch| ch == '1'))
                .collect(),
            None => vec![true; cells],
        }
    }

    /// How events address the cells of a `rows x cols` grid: the mask's cells, and each
    /// taxel index's cell (the channel map's, or row-major order without one).
    pub fn event_grid(&self, rows: usize, cols: usize) -> crate::events::EventGrid {
        let present = self.present(rows * cols);
        let taxels = match &self.channel_map {
            Some(map) => map.iter().map(|&[r, c]| r * cols + c).collect(),
            None => (0..rows * cols).collect(),
        };
        crate::events::EventGrid {
            rows,
            cols,
            present,
            taxels,
        }
    }

    /// Reads and checks `layout.toml`.
    ///
    /// # Errors
    /// The file is unreadable, not TOML of this form, or inconsistent.
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::io::read_text(path)?;
        let file: LayoutFile = toml::from_str(&text).map_err(|e| {
            let why = crate::error::toml_error(&text, &e);
            DataError::invalid(path, format!("not a valid layout file: {why}"))
        })?;
        file.check(path)?;
        Ok(file)
    }

    /// How this layout's CSV recordings are laid out: `time_column` and `channels` are
    /// names with a header row and 0-based indices without one; with a header and no
    /// `time_column`, a column named `t_ms` or `time_ms` (ms), or `t_s` or `time_s` (s), is
    /// the time column.
    ///
    /// # Errors
    /// Without a header row, a time column or channel that is not an index.
    pub fn csv_format(&self) -> Result<CsvFormat, ParamError> {
        self.own_columns().csv_format(self.max_gap_s)
    }

    /// The formats a CSV file read with this layout may be in, by preference: the layout's
    /// own (its dataset's files), then its `[source]` (the raw logs they were imported
    /// from), each with `overrides` applied; only the overridden own format when the
    /// overrides say where the columns are.
    ///
    /// # Errors
    /// As [`LayoutFile::csv_format`].
    pub fn csv_formats(&self, overrides: &CsvOverrides) -> Result<Vec<CsvFormat>, ParamError> {
        let mut formats = vec![overrides.apply(self.csv_format()?)];
        if let Some(source) = self.source.as_ref().filter(|_| !overrides.place_columns()) {
            formats.push(overrides.apply(source.csv_format(self.max_gap_s)?));
        }
        Ok(formats)
    }

    /// The layout's own CSV fields.
    fn own_columns(&self) -> LogColumns {
        LogColumns {
            header: self.header,
            delimiter: self.delimiter,
            time_column: self.time_column.clone(),
            time_unit: self.time_unit,
            channels: self.channels.clone(),
            duplicate_stamps: self.duplicate_stamps,
        }
    }

    /// Checks every field against the rules the importers apply to the same values, so a
    /// layout written by hand is refused where an import's options would have been (a
    /// layout kept in a model file is checked when the model is read), naming `path` in the
    /// error.
    ///
    /// # Errors
    /// The first rule broken.
    pub fn check(&self, path: &Path) -> Result<()> {
        let bad = |m: String| -> Result<()> { Err(DataError::invalid(path, m).into()) };
        if let Err(e) = self.csv_formats(&CsvOverrides::default()) {
            return bad(e.to_string());
        }
        if let Some(fs) = self.fs.filter(|&fs| SampleRate::new(fs).is_err()) {
            return bad(format!("field `fs`: {FS_RULE}, got {fs}"));
        }
        let positive = [
            ("max_gap_s", self.max_gap_s, "s"),
            ("max_duration_s", self.max_duration_s, "s"),
        ];
        for (field, value, unit) in positive {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return bad(format!(
                    "field `{field}` must be a positive number of {unit}, got {v}"
                ));
            }
        }
        if self.rows.is_some() != self.cols.is_some() {
            return bad("fields `rows` and `cols` must be given together".into());
        }
        if let (Some(r), Some(c)) = (self.rows, self.cols) {
            self.check_grid(r, c).or_else(bad)?;
        } else if self.channel_map.is_some() || self.mask.is_some() {
            return bad("fields `channel_map` and `mask` need `rows` and `cols`".into());
        }
        if let Some(channels) = &self.channels {
            // A column named twice would be read twice, as two taxels of one signal.
            let mut seen = std::collections::HashMap::new();
            for (j, name) in channels.iter().enumerate() {
                if let Some(i) = seen.insert(name.as_str(), j) {
                    return bad(format!(
                        "field `channels` names `{}` twice (entries {} and {}): each channel is a column of its own",
                        crate::csvlog::excerpt(name),
                        i + 1,
                        j + 1
                    ));
                }
            }
        }
        if let Some(events) = &self.events {
            if self.rows.is_none() {
                return bad("an [events] table needs the grid: give `rows` and `cols`".into());
            }
            let [on, off] = events.values;
            if on == off {
                return bad(format!("[events] `values`: the ON and OFF polarity values must be two different integers, got [{on}, {off}]"));
            }
        }
        if let Some(Baseline::Mean { start_s, end_s }) = self.baseline {
            if !(start_s.is_finite() && end_s.is_finite() && start_s >= 0.0 && end_s > start_s) {
                return bad(format!(
                    "field `baseline`: mean interval must satisfy 0 <= start_s < end_s, got [{start_s}, {end_s}]"
                ));
            }
        }
        Ok(())
    }

    /// The grid's fields on a `r x c` grid: its size, the mask (its shape, at least one
    /// taxel), and the channel map (one cell per channel, each on the grid, none twice,
    /// none masked, as many as `channels`); `Err` says which rule is broken.
    fn check_grid(&self, r: usize, c: usize) -> std::result::Result<(), String> {
        if r == 0 || c == 0 {
            return Err(format!("grid must be at least 1x1, got {r}x{c}"));
        }
        crate::values::check_grid_cells(r, c)
            .map_err(|e| format!("fields `rows` and `cols`: {e}"))?;
        if let Some(mask) = &self.mask {
            if mask.len() != r || mask.iter().any(|row| row.chars().count() != c) {
                return Err(format!(
                    "field `mask` must have {r} strings of {c} characters"
                ));
            }
            if mask
                .iter()
                .any(|row| row.chars().any(|ch| ch != '0' && ch != '1'))
            {
                return Err("field `mask` may hold only `0` and `1`".into());
            }
            if mask.iter().all(|row| !row.contains('1')) {
                return Err("field `mask` must leave at least one taxel (a `1`)".into());
            }
        }
        let present = self.present(r * c);
        let channels = self.channels.as_ref().map(Vec::len);
        let Some(map) = &self.channel_map else {
            let taxels = present.iter().filter(|&&p| p).count();
            return match channels.filter(|&n| n != taxels) {
                Some(n) => Err(format!("field `channels` names {n} channels, but the {r}x{c} grid has {taxels} taxel cells and no `channel_map` places them")),
                None => Ok(()),
            };
        };
        if let Some(n) = channels.filter(|&n| n != map.len()) {
            return Err(format!("field `channel_map` has {} cells for the {n} channels of `channels`: the map needs one cell per channel", map.len()));
        }
        let mut seen = vec![false; r * c];
        for (ch, &[mr, mc]) in map.iter().enumerate() {
            if mr >= r || mc >= c {
                return Err(format!(
                    "field `channel_map`: channel {ch} maps to [{mr}, {mc}], outside the {r}x{c} grid"
                ));
            }
            if std::mem::replace(&mut seen[mr * c + mc], true) {
                return Err(format!(
                    "field `channel_map`: cell [{mr}, {mc}] is given twice"
                ));
            }
            if !present[mr * c + mc] {
                return Err(format!("field `channel_map`: channel {ch} maps to [{mr}, {mc}], a cell the mask marks empty"));
            }
        }
        Ok(())
    }

    /// The layout for a recording with `channels` channels (or a `rows x cols` array).
    fn layout_for(&self, path: &Path, shape: Shape) -> Result<Layout> {
        let (rows, cols) = match (self.rows, self.cols, shape) {
            (Some(r), Some(c), _) => (r, c),
            (_, _, Shape::Grid(r, c)) => (r, c),
            (_, _, Shape::Channels(n)) => (1, n),
        };
        let present = self.present(rows * cols);
        let n_channels = match shape {
            Shape::Grid(r, c) => {
                if (r, c) != (rows, cols) {
                    return Err(DataError::invalid(
                        path,
                        format!("recording is a {r}x{c} grid but layout.toml says {rows}x{cols}"),
                    )
                    .into());
                }
                r * c
            }
            Shape::Channels(n) => n,
        };
        let channel_map: Vec<usize> = match (&self.channel_map, shape) {
            (Some(map), _) => map.iter().map(|&[r, c]| r * cols + c).collect(),
            (None, Shape::Grid(..)) => (0..rows * cols).collect(),
            (None, Shape::Channels(n)) => {
                let taxels: Vec<usize> = (0..rows * cols).filter(|&i| present[i]).collect();
                if taxels.len() != n {
                    return Err(DataError::invalid(
                        path,
                        format!(
                            "recording has {n} channels but the {rows}x{cols} layout has {} taxel cells",
                            taxels.len()
                        ),
                    )
                    .into());
                }
                taxels
            }
        };
        if channel_map.len() != n_channels {
            return Err(DataError::invalid(
                path,
                format!(
                    "recording has {n_channels} channels but layout.toml maps {}",
                    channel_map.len()
                ),
            )
            .into());
        }
        if let Some(&cell) = channel_map.iter().find(|&&cell| !present[cell]) {
            return Err(DataError::invalid(
                path,
                format!(
                    "layout maps a channel to cell [{}, {}], which the mask marks empty",
                    cell / cols,
                    cell % cols
                ),
            )
            .into());
        }
        // A cell no channel reaches carries no signal: masked, never scored as a taxel.
        let mut present = present;
        if self.channel_map.is_some() {
            let mut mapped = vec![false; rows * cols];
            channel_map.iter().for_each(|&cell| mapped[cell] = true);
            present.iter_mut().zip(mapped).for_each(|(p, m)| *p &= m);
        }
        Ok(Layout {
            rows,
            cols,
            channel_map,
            present,
        })
    }
}

#[derive(Debug, Clone, Copy)]
enum Shape {
    Grid(usize, usize),
    Channels(usize),
}

/// A dataset folder: its manifest, layout and where the recordings are.
#[derive(Debug, Clone)]
pub struct Dataset {
    /// The folder.
    pub root: PathBuf,
    /// One entry per recording, in manifest order.
    pub entries: Vec<Meta>,
    /// The manifest's column names, in its order.
    pub columns: Vec<String>,
    /// The parsed `layout.toml` (all defaults when absent).
    pub layout: LayoutFile,
}

/// Why a step that reads sampled signals refuses an address-event recording.
const EVENTS_NOT_SAMPLES: &str = "is an address-event recording (its layout.toml has an [events] table), not sampled signals, and this step needs samples (encode, the signal baselines of compare --encodings none, --gain auto, --causal, and predict on single files); an event dataset goes to features, evaluate, train, compare, reproduce, inspect and predict --dataset, a live sensor's events to stream --format events, and raw event logs through `neurotex import events` first";

/// The manifest's required columns.
pub const MANIFEST_COLUMNS: [&str; 2] = ["file", "label"];

/// The manifest's optional condition columns, in the order [`write_manifest`] writes them.
/// A missing column, or an empty field, means the recordings share one condition.
pub const CONDITION_COLUMNS: [&str; 3] = ["speed_mm_s", "force_n", "trial"];

impl Dataset {
    /// Opens a dataset folder, reading and checking `manifest.csv` and `layout.toml`; every
    /// recording must lie inside the folder (see [`Dataset::open_with`]).
    ///
    /// # Errors
    /// Missing or malformed manifest or layout; a manifest line naming a missing file or
    /// one outside the folder.
    pub fn open(root: impl AsRef<Path>) -> Result<Self> {
        Self::open_with(root, false)
    }

    /// [`Dataset::open`], with `allow_outside_paths` choosing whether manifest `file`
    /// entries may leave the dataset folder (`../x.npy`, absolute paths, symbolic links to
    /// elsewhere). Refused by default: a dataset folder copied or shared should hold its
    /// recordings, and a manifest from elsewhere should not make neurotex read any file.
    ///
    /// # Errors
    /// As [`Dataset::open`].
    pub fn open_with(root: impl AsRef<Path>, allow_outside_paths: bool) -> Result<Self> {
        let root = root.as_ref().to_path_buf();
        if !root.is_dir() {
            return Err(DataError::invalid(
                &root,
                "is not a dataset folder (expected a folder with manifest.csv)",
            )
            .into());
        }
        let layout_path = root.join("layout.toml");
        let layout = if layout_path.exists() {
            LayoutFile::read(&layout_path)?
        } else {
            LayoutFile::default()
        };
        let manifest_path = root.join("manifest.csv");
        if !manifest_path.exists() {
            return Err(no_manifest(&root).into());
        }
        let (columns, entries) = read_manifest_columns(&manifest_path)?;
        for (i, m) in entries.iter().enumerate() {
            let file = root.join(&m.file);
            if let Some(meta) = std::fs::metadata(&file).ok().filter(|m| !m.is_file()) {
                let kind = crate::io::kind_name(meta.file_type());
                let why = format!(
                    "line {}: file `{}` is {kind}, not a regular file: a dataset's recordings are regular files",
                    i + 2,
                    m.file
                );
                return Err(DataError::invalid(&manifest_path, why).into());
            }
            if !file.is_file() {
                return Err(DataError::invalid(
                    &manifest_path,
                    format!(
                        "line {}: file `{}` does not exist in {}",
                        i + 2,
                        m.file,
                        root.display()
                    ),
                )
                .into());
            }
            if !allow_outside_paths {
                check_inside(&root, &m.file).map_err(|why| {
                    DataError::invalid(
                        &manifest_path,
                        format!("line {}: file `{}` {why}", i + 2, m.file),
                    )
                })?;
            }
        }
        Ok(Dataset {
            root,
            entries,
            columns,
            layout,
        })
    }

    /// Every file the dataset reads: `manifest.csv`, `layout.toml` when there is one, and
    /// each recording the manifest lists (so a command can refuse to write over its input).
    pub fn files(&self) -> Vec<PathBuf> {
        let mut files = vec![
            self.root.join("manifest.csv"),
            self.root.join("layout.toml"),
        ];
        files.extend(self.entries.iter().map(|m| self.root.join(&m.file)));
        files
    }

    /// The sampling rate of the dataset's recordings (default 1000 Hz, the paper's).
    pub fn fs(&self) -> f64 {
        self.layout.fs.unwrap_or(1000.0)
    }

    /// Loads recording `index` from disk.
    ///
    /// # Errors
    /// Unreadable file, wrong shape, non-finite samples, non-increasing time stamps.
    ///
    /// # Panics
    /// If `index` is out of range (a caller bug).
    pub fn load(&self, index: usize) -> Result<Recording> {
        let meta = &self.entries[index];
        if self.is_events() {
            return Err(DataError::invalid(self.root.join(&meta.file), EVENTS_NOT_SAMPLES).into());
        }
        let path = self.root.join(&meta.file);
        let mut rec = read_recording(&path, &self.layout)?;
        rec.meta = meta.clone();
        Ok(rec)
    }

    /// Whether the recordings are address events (`layout.toml` has an `[events]` table).
    pub fn is_events(&self) -> bool {
        self.layout.events.is_some()
    }

    /// Loads event recording `index` as spike trains ([`crate::events`]); the manifest's
    /// optional `duration_s` column gives its length.
    ///
    /// # Errors
    /// Not an event dataset, an unreadable file, a bad `duration_s`, or an event that breaks
    /// a rule.
    ///
    /// # Panics
    /// If `index` is out of range (a caller bug).
    pub fn load_events(&self, index: usize) -> Result<crate::events::Events> {
        let meta = &self.entries[index];
        let path = self.root.join(&meta.file);
        let (Some(format), Some(rows), Some(cols)) =
            (&self.layout.events, self.layout.rows, self.layout.cols)
        else {
            let why = "is a sampled recording: its dataset's layout.toml has no [events] table";
            return Err(DataError::invalid(&path, why).into());
        };
        let manifest = || self.root.join("manifest.csv");
        let duration = match meta.field("duration_s").filter(|d| !d.is_empty()) {
            None => None,
            Some(text) => match text.parse::<f64>() {
                Ok(s) if s.is_finite() && s >= 0.0 => Some((s * 1000.0).round() as u64),
                _ => {
                    let why = format!(
                        "line {}: duration_s `{text}` is not a non-negative number of seconds",
                        index + 2
                    );
                    return Err(DataError::invalid(manifest(), why).into());
                }
            },
        };
        let grid = self.layout.event_grid(rows, cols);
        let max_s = self.layout.max_duration_s.unwrap_or(DEFAULT_MAX_DURATION_S);
        // Spike times are u32 milliseconds: at most 49 days, far past any limit one sets.
        let max_steps = ((max_s * 1000.0) as u64).min(u64::from(u32::MAX));
        let limit = crate::events::StepLimit::new(max_steps, rows * cols);
        if let Some(d) = duration.filter(|&d| d > limit.steps) {
            let why = format!(
                "line {}: duration_s {} s is longer than {}",
                index + 2,
                d as f64 / 1000.0,
                limit.describe()
            );
            return Err(DataError::invalid(manifest(), why).into());
        }
        crate::events::read_events(&path, format, &grid, duration, max_steps)
    }

    /// A fingerprint of the dataset as its manifest lists it, `sha256:` and 64 hex digits:
    /// SHA-256 over the manifest's length in bytes (8 bytes, little-endian), the bytes of
    /// `manifest.csv`, then each listed file's size in bytes (8 bytes, little-endian) in
    /// manifest order. File sizes, not contents, keep it cheap on large datasets; so a
    /// recording rewritten with different samples of the same size keeps the fingerprint.
    /// In Python: `h = hashlib.sha256(); h.update(len(m).to_bytes(8, "little")); h.update(m)`,
    /// then `h.update(os.path.getsize(f).to_bytes(8, "little"))` for each file.
    ///
    /// # Errors
    /// The manifest or a listed file can no longer be read.
    pub fn fingerprint(&self) -> Result<String> {
        use sha2::{Digest, Sha256};
        let manifest_path = self.root.join("manifest.csv");
        let manifest =
            std::fs::read(&manifest_path).map_err(|e| DataError::io(&manifest_path, e))?;
        let mut hasher = Sha256::new();
        hasher.update((manifest.len() as u64).to_le_bytes());
        hasher.update(&manifest);
        for meta in &self.entries {
            let path = self.root.join(&meta.file);
            let size = std::fs::metadata(&path)
                .map_err(|e| DataError::io(&path, e))?
                .len();
            hasher.update(size.to_le_bytes());
        }
        let hex: String = hasher
            .finalize()
            .iter()
            .map(|byte| format!("{byte:02x}"))
            .collect();
        Ok(format!("sha256:{hex}"))
    }

    /// The distinct labels in order of first appearance.
    pub fn labels(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for m in &self.entries {
            if !out.contains(&m.label) {
                out.push(m.label.clone());
            }
        }
        out
    }

    /// The distinct speeds, ascending; empty when the manifest gives none.
    pub fn speeds(&self) -> Vec<Speed> {
        Speed::distinct(self.entries.iter().filter_map(Meta::speed))
    }

    /// The indices of the recordings at any of `speeds`, in manifest order.
    ///
    /// # Errors
    /// [`DatasetError::NoRecordingsAt`] for the first of `speeds` at which the dataset
    /// holds no recording, naming the speeds it has.
    pub fn indices_at(&self, speeds: &[Speed]) -> Result<Vec<usize>> {
        let available = self.speeds();
        if let Some(&speed) = speeds.iter().find(|s| !available.contains(s)) {
            return Err(DatasetError::NoRecordingsAt {
                speed,
                root: self.root.clone(),
                available,
            }
            .into());
        }
        Ok((0..self.entries.len())
            .filter(|&i| self.entries[i].speed().is_some_and(|s| speeds.contains(&s)))
            .collect())
    }
}

/// Whether manifest entry `file` stays inside dataset folder `root`: a relative path
/// without `..` that, once symbolic links are resolved, still lies under the folder.
/// Returns why not.
fn check_inside(root: &Path, file: &str) -> std::result::Result<(), String> {
    use std::path::Component;
    let outside = "lies outside the dataset folder; manifest paths must stay inside it (--allow-outside-paths lets them out)";
    let relative = Path::new(file)
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if !relative {
        return Err(format!("{outside} (no absolute paths or `..`)"));
    }
    let canonical = |p: &Path| {
        p.canonicalize()
            .map_err(|e| format!("cannot be resolved: {e}"))
    };
    if !canonical(&root.join(file))?.starts_with(canonical(root)?) {
        return Err(format!("{outside} (a symbolic link leads out)"));
    }
    Ok(())
}

/// Recordings whose manifest column holds one of some values, written `COLUMN=V1,V2`:
/// numeric columns ([`NUMERIC_COLUMNS`]) compare as numbers (`5` is `5.0`), every other
/// column as text. Any column but `label` (selecting classes leaves the test set with
/// classes never trained on).
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// The manifest column.
    pub column: String,
    /// The values, as written.
    pub values: Vec<String>,
}

impl Selection {
    /// The recordings at `speeds`.
    pub fn speeds(speeds: &[Speed]) -> Self {
        Selection {
            column: "speed_mm_s".into(),
            values: speeds.iter().map(Speed::to_string).collect(),
        }
    }

    fn numeric(&self) -> bool {
        NUMERIC_COLUMNS.contains(&self.column.as_str())
    }

    /// Whether `field` (a recording's value in the column) is `value`.
    fn same(&self, field: &str, value: &str) -> bool {
        if self.numeric() {
            matches!((field.parse::<f64>(), value.parse::<f64>()), (Ok(a), Ok(b)) if a == b)
        } else {
            field == value
        }
    }

    /// The indices of `metas` selected, in order.
    ///
    /// # Errors
    /// [`DatasetError::NoColumn`] when no recording has a value in the column,
    /// [`DatasetError::NoRecordingsWhere`] for the first value no recording has, naming
    /// the values present.
    pub fn rows(&self, metas: &[Meta]) -> Result<Vec<usize>> {
        let fields: Vec<Option<String>> = metas.iter().map(|m| m.field(&self.column)).collect();
        let mut present: Vec<&str> = fields.iter().flatten().map(String::as_str).collect();
        if present.is_empty() {
            let mut columns: Vec<String> = MANIFEST_COLUMNS.map(String::from).to_vec();
            let others = NUMERIC_COLUMNS.iter().map(|c| c.to_string());
            let others = others.chain(metas.iter().flat_map(|m| m.extra.keys().cloned()));
            for c in others {
                if !columns.contains(&c) && metas.iter().any(|m| m.field(&c).is_some()) {
                    columns.push(c);
                }
            }
            let column = self.column.clone();
            return Err(DatasetError::NoColumn { column, columns }.into());
        }
        if let Some(value) = self
            .values
            .iter()
            .find(|v| !present.iter().any(|f| self.same(f, v)))
        {
            if self.numeric() {
                present.sort_by(|a, b| {
                    a.parse::<f64>()
                        .unwrap_or(0.0)
                        .total_cmp(&b.parse().unwrap_or(0.0))
                });
            } else {
                present.sort();
            }
            present.dedup();
            return Err(DatasetError::NoRecordingsWhere {
                column: self.column.clone(),
                value: value.clone(),
                present: present.into_iter().map(String::from).collect(),
            }
            .into());
        }
        let chosen = |f: &Option<String>| {
            f.as_deref()
                .is_some_and(|f| self.values.iter().any(|v| self.same(f, v)))
        };
        Ok((0..metas.len()).filter(|&i| chosen(&fields[i])).collect())
    }
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.column, self.values.join(","))
    }
}

impl FromStr for Selection {
    type Err = ParamError;

    /// Parses `COLUMN=V1,V2,...`; values of numeric columns must be numbers.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let rule = "a selection is COLUMN=VALUE[,VALUE...] over a manifest column other than label, numbers in numeric columns";
        let bad = || ParamError::new("where", rule, text);
        let (column, values) = text.split_once('=').ok_or_else(bad)?;
        let column = column.trim().to_string();
        let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
        if column.is_empty() || column == "label" || values.iter().any(String::is_empty) {
            return Err(bad());
        }
        let selection = Selection { column, values };
        let number = |v: &String| v.parse::<f64>().is_ok_and(f64::is_finite);
        if selection.numeric() && !selection.values.iter().all(number) {
            return Err(bad());
        }
        Ok(selection)
    }
}

/// The one grid that recordings share, from `(file, grid)` pairs in dataset order.
///
/// # Errors
/// [`DatasetError::MixedGrids`] naming the first recording whose grid (size or mask)
/// differs from the first one's; [`DatasetError::Empty`] when there is no pair.
pub fn one_grid<'a>(grids: impl IntoIterator<Item = (&'a str, Grid)>) -> Result<Grid> {
    let mut grids = grids.into_iter();
    let (first, first_grid) = grids.next().ok_or(DatasetError::Empty)?;
    match grids.find(|(_, grid)| *grid != first_grid) {
        Some((file, _)) => Err(DatasetError::MixedGrids {
            file: file.to_string(),
            first: first.to_string(),
        }
        .into()),
        None => Ok(first_grid),
    }
}

/// Reads and checks a manifest.
///
/// # Errors
/// Missing file, missing column, unparsable or non-finite field; each names the line.
pub fn read_manifest(path: &Path) -> Result<Vec<Meta>> {
    read_manifest_columns(path).map(|(_, metas)| metas)
}

/// Reads and checks a manifest: its column names in order, and its recordings.
/// The error for a folder without `manifest.csv`: when it holds recordings (raw logs,
/// say), it says how to make a dataset folder of them.
fn no_manifest(root: &Path) -> DataError {
    let recordings = std::fs::read_dir(root)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .filter(|e| {
                    let name = e.file_name().to_string_lossy().to_lowercase();
                    name.ends_with(".csv") || name.ends_with(".npy")
                })
                .count()
        })
        .unwrap_or(0);
    let why = match recordings {
        0 => "is not a dataset folder (expected a folder with manifest.csv)".to_string(),
        n => format!(
            "is not a dataset folder (no manifest.csv) but holds {n} .csv/.npy file(s): \
             import them into a dataset folder first (`neurotex import csv` for per-trial \
             logs, `neurotex import stacked` for arrays; in Python, `neurotex.save_dataset`)"
        ),
    };
    DataError::invalid(root, why)
}

fn read_manifest_columns(path: &Path) -> Result<(Vec<String>, Vec<Meta>)> {
    // Fields are trimmed (`a.npy, smooth` is common); the labels as written are kept to
    // refuse two that differ only by surrounding spaces, which trimming would make one class.
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::Headers)
        .from_reader(crate::io::open_text(path)?);
    let headers = reader.headers().map_err(|e| csv_error(path, e))?.clone();
    let columns = ManifestColumns::find(path, &headers)?;
    let mut out = Vec::new();
    let mut raw_labels = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let mut record = record.map_err(|e| csv_error(path, e))?;
        let raw_label = record.get(columns.required[1]).unwrap_or("").to_string();
        record.trim();
        out.push(columns.row(path, i + 2, &headers, &record)?);
        raw_labels.push((raw_label, format!("line {}", i + 2)));
    }
    if let Some(message) = labels_merged_by_trimming(&raw_labels) {
        return Err(DataError::invalid(path, message).into());
    }
    if out.is_empty() {
        return Err(DataError::invalid(path, "the manifest lists no recordings").into());
    }
    // A recording listed twice would count twice, and could sit in a training and a test
    // fold at once. Names are compared by their path components (`./a.npy` is `a.npy`).
    let mut seen: std::collections::HashMap<PathBuf, usize> = std::collections::HashMap::new();
    for (i, meta) in out.iter().enumerate() {
        let key: PathBuf = Path::new(&meta.file)
            .components()
            .filter(|c| c != &std::path::Component::CurDir)
            .collect();
        if let Some(first) = seen.insert(key, i) {
            let message = format!(
                "line {}: file `{}` is listed again (first on line {}); each recording may be \
                 listed once",
                i + 2,
                meta.file,
                first + 2
            );
            return Err(DataError::invalid(path, message).into());
        }
    }
    Ok((headers.iter().map(String::from).collect(), out))
}

/// Two labels that differ only by surrounding whitespace, which reading a manifest trims,
/// so that they would silently become one class: a message naming both, or `None`.
/// `labels` are the labels as written, each with where it was written.
pub(crate) fn labels_merged_by_trimming(labels: &[(String, String)]) -> Option<String> {
    let mut first: std::collections::HashMap<&str, &(String, String)> = Default::default();
    labels.iter().find_map(|entry| {
        let (raw, at) = entry;
        let (first_raw, first_at) = *first.entry(raw.trim()).or_insert(entry);
        (first_raw != raw).then(|| {
            format!(
                "{at}: label `{raw}` and `{first_raw}` ({first_at}) differ only by surrounding \
                 spaces, which neurotex trims, so they would be one class; write them \
                 identically, or as distinct names"
            )
        })
    })
}

/// Where a manifest's columns are: the required ones in [`MANIFEST_COLUMNS`] order, the
/// optional conditions in [`CONDITION_COLUMNS`] order, and the optional sliding interval.
struct ManifestColumns {
    required: [usize; 2],
    conditions: [Option<usize>; 3],
    start: Option<usize>,
    end: Option<usize>,
}

impl ManifestColumns {
    fn find(path: &Path, headers: &csv::StringRecord) -> Result<Self> {
        let names: Vec<&str> = headers.iter().collect();
        let why = "a manifest's fields are found by column name";
        if let Some(message) = crate::csvlog::repeated_name(&names, 0..names.len(), why) {
            return Err(DataError::invalid(path, message).into());
        }
        let col = |name: &str| headers.iter().position(|h| h == name);
        let mut required = [0usize; 2];
        for (slot, name) in required.iter_mut().zip(MANIFEST_COLUMNS) {
            *slot = col(name).ok_or_else(|| {
                let needed = MANIFEST_COLUMNS.join(",");
                let message = format!("missing column `{name}` (a manifest needs {needed})");
                DataError::invalid(path, message)
            })?;
        }
        Ok(ManifestColumns {
            required,
            conditions: CONDITION_COLUMNS.map(col),
            start: col("slide_start_s"),
            end: col("slide_end_s"),
        })
    }

    /// Whether column `j` is one neurotex reads into a field of its own.
    fn known(&self, j: usize) -> bool {
        self.required.contains(&j)
            || self.conditions.contains(&Some(j))
            || Some(j) == self.start
            || Some(j) == self.end
    }

    /// The recording that manifest line `line` describes.
    fn row(
        &self,
        path: &Path,
        line: usize,
        headers: &csv::StringRecord,
        record: &csv::StringRecord,
    ) -> Result<Meta> {
        let field = |j: usize| record.get(j).unwrap_or("");
        let bad = |message: String| -> crate::Error {
            DataError::invalid(path, format!("line {line}{message}")).into()
        };
        // An absent column and an empty field both mean "not given".
        let given = |j: Option<usize>| j.map(field).filter(|s| !s.is_empty());
        let number = |j: Option<usize>, name: &str| -> Result<Option<f64>> {
            let Some(s) = given(j) else { return Ok(None) };
            let value = s.parse::<f64>().ok().filter(|v| v.is_finite());
            value.map(Some).ok_or_else(|| {
                bad(format!(
                    ", field `{name}`: expected a finite number, got `{s}`"
                ))
            })
        };
        let non_empty = |j: usize, name: &str| -> Result<String> {
            match field(j) {
                "" => Err(bad(format!(", field `{name}` is empty"))),
                text => Ok(text.to_string()),
            }
        };
        let idx = &self.required;
        let (file, label) = (non_empty(idx[0], "file")?, non_empty(idx[1], "label")?);
        let [speed, force, trial] = self.conditions;
        let trial = match given(trial) {
            None => None,
            Some(text) => Some(text.parse::<i64>().map_err(|_| {
                bad(format!(
                    ", field `trial`: expected an integer, got `{text}`"
                ))
            })?),
        };
        let slide_start_s = number(self.start, "slide_start_s")?;
        let slide_end_s = number(self.end, "slide_end_s")?;
        if let (Some(a), Some(b)) = (slide_start_s, slide_end_s) {
            if !(a >= 0.0 && b > a) {
                return Err(bad(format!(": slide interval must satisfy 0 <= slide_start_s < slide_end_s, got [{a}, {b}]")));
            }
        }
        let extra = headers
            .iter()
            .enumerate()
            .filter(|(j, _)| !self.known(*j))
            .map(|(j, h)| (h.to_string(), field(j).to_string()))
            .collect();
        Ok(Meta {
            file,
            label,
            speed_mm_s: number(speed, "speed_mm_s")?,
            force_n: number(force, "force_n")?,
            trial,
            slide_start_s,
            slide_end_s,
            extra,
        })
    }
}

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

pub use crate::values::VALUES_PER_LIMIT_S;

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
fn read_npy(path: &Path) -> Result<(Shape, Vec<f64>, bool)> {
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

/// Writes `manifest.csv` for `metas` into `dir`: `file,label`, each condition column
/// ([`CONDITION_COLUMNS`]) that some recording gives (empty where another does not), the
/// sliding interval when any recording has one, then every extra field any recording
/// carries. [`read_manifest`] reads the same recordings back.
///
/// # Errors
/// The file cannot be written.
pub fn write_manifest(dir: &Path, metas: &[Meta]) -> Result<()> {
    let path = dir.join("manifest.csv");
    let given = |column: &str| metas.iter().any(|m| m.field(column).is_some());
    let mut header: Vec<&str> = MANIFEST_COLUMNS.to_vec();
    header.extend(CONDITION_COLUMNS.into_iter().filter(|c| given(c)));
    if given("slide_start_s") || given("slide_end_s") {
        header.extend(["slide_start_s", "slide_end_s"]);
    }
    let mut extra: Vec<&str> = metas
        .iter()
        .flat_map(|m| m.extra.keys().map(String::as_str))
        .collect();
    extra.sort();
    extra.dedup();
    header.extend(extra);
    let mut w = csv::Writer::from_path(&path).map_err(|e| csv_error(&path, e))?;
    w.write_record(&header).map_err(|e| csv_error(&path, e))?;
    for m in metas {
        let row = header.iter().map(|c| m.field(c).unwrap_or_default());
        w.write_record(row).map_err(|e| csv_error(&path, e))?;
    }
    w.flush().map_err(|e| DataError::write(&path, e))?;
    Ok(())
}

/// Creates dataset folder `dir` whole or not at all, with [`crate::io::create_dir_atomic`]:
/// `fill` writes into a temporary folder beside it, which is renamed to `dir` only when
/// `fill` succeeds (and removed otherwise, or on SIGINT/SIGTERM in the binary).
///
/// # Errors
/// `dir` exists and is not empty, or `fill` or the rename fails.
pub fn create_dataset_dir<T>(dir: &Path, fill: impl FnOnce(&Path) -> Result<T>) -> Result<T> {
    crate::io::create_dir_atomic(dir, fill)
}

/// Writes `layout.toml` into `dir`.
///
/// # Errors
/// The file cannot be written.
pub fn write_layout(dir: &Path, layout: &LayoutFile) -> Result<()> {
    let path = dir.join("layout.toml");
    let text = toml::to_string(layout).map_err(|e| DataError::invalid(&path, e.to_string()))?;
    std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
    Ok(())
}
