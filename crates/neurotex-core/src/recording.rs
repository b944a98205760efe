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
use std::str::FromStr;

use serde::{Deserialize, Serialize};

pub use crate::error::DatasetError;
use crate::error::{ParamError, Result};
pub use crate::values::TimeUnit;
use crate::values::{Cell, Speed};

mod dataset;
mod layout_file;
mod manifest;
mod read;
mod selection;

pub use dataset::{one_grid, Dataset};
pub use layout_file::{LayoutFile, DEFAULT_MAX_DURATION_S};
pub(crate) use manifest::labels_merged_by_trimming;
pub use manifest::{
    create_dataset_dir, labels_differing_in_case, read_manifest, write_layout, write_manifest,
};
pub use read::{
    read_recording, read_recording_as, recording_from_channels, FileReading, LayoutFrom,
};
pub use selection::Selection;

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

    /// Whether every channel holds one value from the first frame to the last (and there
    /// are at least two frames): a logger that recorded no signal.
    pub fn is_constant(&self) -> bool {
        let cells = self.layout.cells().max(1);
        let Some(first) = self.samples.get(..cells) else {
            return false;
        };
        self.len() > 1 && self.samples.chunks_exact(cells).all(|frame| frame == first)
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

#[derive(Debug, Clone, Copy)]
enum Shape {
    Grid(usize, usize),
    Channels(usize),
}

/// Why a step that reads sampled signals refuses an address-event recording.
const EVENTS_NOT_SAMPLES: &str = "is an address-event recording (its layout.toml has an [events] table), not sampled signals, and this step needs samples (encode, the signal baselines of compare --encodings none, --gain auto, --causal, and predict on single files); an event dataset goes to features, evaluate, train, compare, reproduce, inspect and predict --dataset, a live sensor's events to stream --format events, and raw event logs through `neurotex import events` first";

/// The manifest's required columns.
pub const MANIFEST_COLUMNS: [&str; 2] = ["file", "label"];

/// The manifest's optional condition columns, in the order [`write_manifest`] writes them.
/// A missing column, or an empty field, means the recordings share one condition.
pub const CONDITION_COLUMNS: [&str; 3] = ["speed_mm_s", "force_n", "trial"];

pub use crate::values::VALUES_PER_LIMIT_S;
