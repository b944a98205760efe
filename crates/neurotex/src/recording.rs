//! The data model (SPEC section 2): recordings, layouts, dataset folders and their I/O.
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

use crate::error::{DataError, ParamError, Result};
use crate::values::{Cell, Grid, Speed};

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
    /// Sliding speed in mm/s (sign = direction where the rig records it).
    pub speed_mm_s: f64,
    /// Normal force in N.
    pub force_n: f64,
    /// Trial number.
    pub trial: i64,
    /// Start of the sliding phase in s from the recording's start, if known.
    pub slide_start_s: Option<f64>,
    /// End of the sliding phase in s, if known.
    pub slide_end_s: Option<f64>,
    /// Any further manifest columns.
    pub extra: BTreeMap<String, String>,
}

impl Meta {
    /// The sliding speed as a condition.
    pub fn speed(&self) -> Speed {
        Speed::of(self.speed_mm_s)
    }
}

/// One trial's samples, time-major `T x rows x cols`, with its sampling and metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Sampling rate in Hz (nominal when `times_s` is given).
    pub fs: f64,
    /// Grid and mask.
    pub layout: Layout,
    /// Samples, `T * rows * cols`, cell index fastest. Masked cells hold 0.
    pub samples: Vec<f64>,
    /// Per-sample time stamps in s for irregularly sampled recordings (strictly increasing).
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

/// How to remove a taxel's resting value before encoding (SPEC 3.3).
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

/// The unit of a CSV recording's time column; written `ms` or `s` (in `layout.toml` too).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum TimeUnit {
    /// Milliseconds, `ms`.
    #[default]
    #[serde(rename = "ms")]
    Milliseconds,
    /// Seconds, `s`.
    #[serde(rename = "s")]
    Seconds,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::Milliseconds => 1e-3,
            TimeUnit::Seconds => 1.0,
        }
    }

    /// Milliseconds per unit.
    pub fn milliseconds(self) -> f64 {
        match self {
            TimeUnit::Milliseconds => 1.0,
            TimeUnit::Seconds => 1e3,
        }
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TimeUnit::Milliseconds => "ms",
            TimeUnit::Seconds => "s",
        })
    }
}

impl FromStr for TimeUnit {
    type Err = ParamError;

    /// Parses `ms` or `s`.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        match text.trim() {
            "ms" => Ok(TimeUnit::Milliseconds),
            "s" => Ok(TimeUnit::Seconds),
            _ => Err(ParamError::new(
                "time-unit",
                "a time unit is `ms` or `s`",
                text,
            )),
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
    pub channels: Option<Vec<String>>,
}

impl LayoutFile {
    /// Reads and checks `layout.toml`.
    ///
    /// # Errors
    /// The file is unreadable, not TOML of this form, or inconsistent.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| DataError::io(path, e))?;
        let file: LayoutFile = toml::from_str(&text)
            .map_err(|e| DataError::invalid(path, format!("not a valid layout file: {e}")))?;
        file.check(path)?;
        Ok(file)
    }

    fn check(&self, path: &Path) -> Result<()> {
        let bad = |m: String| -> Result<()> { Err(DataError::invalid(path, m).into()) };
        if let Some(fs) = self.fs {
            if !(fs.is_finite() && fs > 0.0) {
                return bad(format!(
                    "field `fs` must be a positive number of Hz, got {fs}"
                ));
            }
        }
        if self.rows.is_some() != self.cols.is_some() {
            return bad("fields `rows` and `cols` must be given together".into());
        }
        if let (Some(r), Some(c)) = (self.rows, self.cols) {
            if r == 0 || c == 0 {
                return bad(format!("grid must be at least 1x1, got {r}x{c}"));
            }
            if let Some(map) = &self.channel_map {
                let mut seen = vec![false; r * c];
                for (ch, &[mr, mc]) in map.iter().enumerate() {
                    if mr >= r || mc >= c {
                        return bad(format!(
                            "field `channel_map`: channel {ch} maps to [{mr}, {mc}], outside the {r}x{c} grid"
                        ));
                    }
                    if std::mem::replace(&mut seen[mr * c + mc], true) {
                        return bad(format!(
                            "field `channel_map`: cell [{mr}, {mc}] is given twice"
                        ));
                    }
                }
            }
            if let Some(mask) = &self.mask {
                if mask.len() != r || mask.iter().any(|row| row.chars().count() != c) {
                    return bad(format!(
                        "field `mask` must have {r} strings of {c} characters"
                    ));
                }
                if mask
                    .iter()
                    .any(|row| row.chars().any(|ch| ch != '0' && ch != '1'))
                {
                    return bad("field `mask` may hold only `0` and `1`".into());
                }
            }
        } else if self.channel_map.is_some() || self.mask.is_some() {
            return bad("fields `channel_map` and `mask` need `rows` and `cols`".into());
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

    /// The layout for a recording with `channels` channels (or a `rows x cols` array).
    fn layout_for(&self, path: &Path, shape: Shape) -> Result<Layout> {
        let (rows, cols) = match (self.rows, self.cols, shape) {
            (Some(r), Some(c), _) => (r, c),
            (_, _, Shape::Grid(r, c)) => (r, c),
            (_, _, Shape::Channels(n)) => (1, n),
        };
        let present: Vec<bool> = match &self.mask {
            Some(m) => m
                .iter()
                .flat_map(|row| row.chars().map(|ch| ch == '1'))
                .collect(),
            None => vec![true; rows * cols],
        };
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
    /// The parsed `layout.toml` (all defaults when absent).
    pub layout: LayoutFile,
}

/// The manifest's required columns.
pub const MANIFEST_COLUMNS: [&str; 5] = ["file", "label", "speed_mm_s", "force_n", "trial"];

impl Dataset {
    /// Opens a dataset folder, reading and checking `manifest.csv` and `layout.toml`.
    ///
    /// # Errors
    /// Missing or malformed manifest or layout; a manifest line naming a missing file.
    pub fn open(root: impl AsRef<Path>) -> Result<Self> {
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
        let entries = read_manifest(&manifest_path)?;
        for (i, m) in entries.iter().enumerate() {
            if !root.join(&m.file).is_file() {
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
        }
        Ok(Dataset {
            root,
            entries,
            layout,
        })
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
        let path = self.root.join(&meta.file);
        let mut rec = read_recording(&path, &self.layout)?;
        rec.meta = meta.clone();
        Ok(rec)
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

    /// The distinct speeds, ascending.
    pub fn speeds(&self) -> Vec<Speed> {
        Speed::distinct(self.entries.iter().map(Meta::speed))
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
            .filter(|&i| speeds.contains(&self.entries[i].speed()))
            .collect())
    }
}

/// A dataset that cannot serve what was asked of it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DatasetError {
    /// No recording at a speed that was asked for.
    #[error("no recordings at {speed} mm/s in {} (its speeds: {})", .root.display(), comma_separated(.available))]
    NoRecordingsAt {
        /// The speed asked for.
        speed: Speed,
        /// The dataset folder.
        root: PathBuf,
        /// The speeds the dataset has, ascending.
        available: Vec<Speed>,
    },
    /// Two recordings on different taxel grids (size or mask).
    #[error("{file}: its taxel grid differs from that of {first}; a dataset needs one layout")]
    MixedGrids {
        /// The first recording whose grid differs.
        file: String,
        /// The recording whose grid the others must share.
        first: String,
    },
    /// No recording was selected.
    #[error("no recordings selected")]
    Empty,
}

fn comma_separated(speeds: &[Speed]) -> String {
    let texts: Vec<String> = speeds.iter().map(Speed::to_string).collect();
    texts.join(", ")
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
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| csv_error(path, e))?;
    let headers = reader.headers().map_err(|e| csv_error(path, e))?.clone();
    let columns = ManifestColumns::find(path, &headers)?;
    let mut out = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| csv_error(path, e))?;
        out.push(columns.row(path, i + 2, &headers, &record)?);
    }
    if out.is_empty() {
        return Err(DataError::invalid(path, "the manifest lists no recordings").into());
    }
    Ok(out)
}

/// Where a manifest's columns are: the required ones in [`MANIFEST_COLUMNS`] order, and
/// the optional sliding interval.
struct ManifestColumns {
    required: [usize; 5],
    start: Option<usize>,
    end: Option<usize>,
}

impl ManifestColumns {
    fn find(path: &Path, headers: &csv::StringRecord) -> Result<Self> {
        let col = |name: &str| headers.iter().position(|h| h == name);
        let mut required = [0usize; 5];
        for (slot, name) in required.iter_mut().zip(MANIFEST_COLUMNS) {
            *slot = col(name).ok_or_else(|| {
                let needed = MANIFEST_COLUMNS.join(",");
                let message = format!("missing column `{name}` (a manifest needs {needed})");
                DataError::invalid(path, message)
            })?;
        }
        Ok(ManifestColumns {
            required,
            start: col("slide_start_s"),
            end: col("slide_end_s"),
        })
    }

    /// The recording that manifest line `line` describes.
    fn row(
        &self,
        path: &Path,
        line: usize,
        headers: &csv::StringRecord,
        record: &csv::StringRecord,
    ) -> Result<Meta> {
        let idx = &self.required;
        let field = |j: usize| record.get(j).unwrap_or("");
        let bad = |message: String| -> crate::Error {
            DataError::invalid(path, format!("line {line}{message}")).into()
        };
        let num = |j: usize, name: &str| -> Result<f64> {
            let s = field(j);
            let value = s.parse::<f64>().ok().filter(|v| v.is_finite());
            value.ok_or_else(|| {
                bad(format!(
                    ", field `{name}`: expected a finite number, got `{s}`"
                ))
            })
        };
        let opt = |j: Option<usize>, name: &str| -> Result<Option<f64>> {
            match j {
                Some(j) if !field(j).is_empty() => num(j, name).map(Some),
                _ => Ok(None),
            }
        };
        let non_empty = |j: usize, name: &str| -> Result<String> {
            match field(j) {
                "" => Err(bad(format!(", field `{name}` is empty"))),
                text => Ok(text.to_string()),
            }
        };
        let (file, label) = (non_empty(idx[0], "file")?, non_empty(idx[1], "label")?);
        let trial_text = field(idx[4]);
        let trial = trial_text.parse::<i64>().map_err(|_| {
            bad(format!(
                ", field `trial`: expected an integer, got `{trial_text}`"
            ))
        })?;
        let slide_start_s = opt(self.start, "slide_start_s")?;
        let slide_end_s = opt(self.end, "slide_end_s")?;
        if let (Some(a), Some(b)) = (slide_start_s, slide_end_s) {
            if !(a >= 0.0 && b > a) {
                return Err(bad(format!(": slide interval must satisfy 0 <= slide_start_s < slide_end_s, got [{a}, {b}]")));
            }
        }
        let known = |j: usize| idx.contains(&j) || Some(j) == self.start || Some(j) == self.end;
        let extra = headers
            .iter()
            .enumerate()
            .filter(|(j, _)| !known(*j))
            .map(|(j, h)| (h.to_string(), field(j).to_string()))
            .collect();
        Ok(Meta {
            file,
            label,
            speed_mm_s: num(idx[2], "speed_mm_s")?,
            force_n: num(idx[3], "force_n")?,
            trial,
            slide_start_s,
            slide_end_s,
            extra,
        })
    }
}

fn csv_error(path: &Path, e: csv::Error) -> crate::Error {
    match e.kind() {
        csv::ErrorKind::Io(_) => {
            let csv::ErrorKind::Io(io) = e.into_kind() else {
                unreachable!()
            };
            DataError::io(path, io).into()
        }
        _ => {
            let line = e
                .position()
                .map(|p| format!("line {}: ", p.line()))
                .unwrap_or_default();
            DataError::invalid(path, format!("{line}malformed CSV: {e}")).into()
        }
    }
}

/// Reads one recording file (`.npy` or `.csv`) with the dataset's layout settings.
///
/// # Errors
/// Unreadable file, unsupported dtype or shape, layout mismatch, non-finite samples,
/// non-increasing time stamps.
pub fn read_recording(path: &Path, layout: &LayoutFile) -> Result<Recording> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let (shape, raw, times_s) = match ext.as_str() {
        "npy" => {
            let (shape, raw) = read_npy(path)?;
            (shape, raw, None)
        }
        "csv" => read_csv_samples(path, layout)?,
        _ => {
            return Err(DataError::invalid(
                path,
                "unsupported recording format: expected a .npy or .csv file",
            )
            .into())
        }
    };
    let n_channels = match shape {
        Shape::Grid(r, c) => r * c,
        Shape::Channels(n) => n,
    };
    if n_channels == 0 {
        return Err(DataError::invalid(path, "recording has no channels").into());
    }
    if let Some(pos) = raw.iter().position(|v| !v.is_finite()) {
        return Err(DataError::invalid(
            path,
            format!(
                "sample {} of channel {} is {} (every sample must be a finite number)",
                pos / n_channels,
                pos % n_channels,
                raw[pos]
            ),
        )
        .into());
    }
    let lay = layout.layout_for(path, shape)?;
    let t = raw.len() / n_channels;
    let samples = if lay.channel_map.iter().copied().eq(0..lay.cells()) {
        raw
    } else {
        let cells = lay.cells();
        let mut out = vec![0.0; t * cells];
        for (frame_in, frame_out) in raw
            .chunks_exact(n_channels)
            .zip(out.chunks_exact_mut(cells))
        {
            for (&v, &cell) in frame_in.iter().zip(&lay.channel_map) {
                frame_out[cell] = v;
            }
        }
        out
    };
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

fn read_npy(path: &Path) -> Result<(Shape, Vec<f64>)> {
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    let array: ArrayD<f64> = match ArrayD::<f64>::read_npy(bytes.as_slice()) {
        Ok(a) => a,
        Err(_) => ArrayD::<f32>::read_npy(bytes.as_slice())
            .map(|a| a.mapv(f64::from))
            .map_err(|e| {
                DataError::invalid(
                    path,
                    format!("not a readable .npy of float32 or float64 samples: {e}"),
                )
            })?,
    };
    let shape = match *array.shape() {
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
    let std = array.as_standard_layout().into_owned();
    Ok((shape, std.into_raw_vec_and_offset().0))
}

fn read_csv_samples(
    path: &Path,
    layout: &LayoutFile,
) -> Result<(Shape, Vec<f64>, Option<Vec<f64>>)> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| csv_error(path, e))?;
    let headers = reader.headers().map_err(|e| csv_error(path, e))?.clone();
    let find = |name: &str| headers.iter().position(|h| h == name);
    let (time_col, unit_scale) = match &layout.time_column {
        Some(name) => {
            let j = find(name).ok_or_else(|| {
                DataError::invalid(
                    path,
                    format!("missing time column `{name}` named in layout.toml"),
                )
            })?;
            (Some(j), layout.time_unit.unwrap_or_default().seconds())
        }
        None => {
            if let Some(j) = find("t_ms").or_else(|| find("time_ms")) {
                (Some(j), 1e-3)
            } else if let Some(j) = find("t_s").or_else(|| find("time_s")) {
                (Some(j), 1.0)
            } else {
                (None, 1.0)
            }
        }
    };
    let channel_cols: Vec<usize> = match &layout.channels {
        Some(names) => names
            .iter()
            .map(|n| {
                find(n).ok_or_else(|| {
                    crate::Error::from(DataError::invalid(
                        path,
                        format!("missing channel column `{n}` named in layout.toml"),
                    ))
                })
            })
            .collect::<Result<_>>()?,
        None => (0..headers.len())
            .filter(|&j| Some(j) != time_col)
            .collect(),
    };
    let n = channel_cols.len();
    let (samples, times) = read_csv_columns(path, &mut reader, &headers, time_col, &channel_cols)?;
    let times = times.map(|t| t.into_iter().map(|x| x * unit_scale).collect());
    Ok((Shape::Channels(n), samples, times))
}

/// Reads the data rows of an opened CSV file: the `channels` columns of every row, frame
/// after frame, and the `time` column in the file's own unit, which must increase strictly.
/// Every cell must be a finite number; errors name the file, line and column. Rows are read
/// as bytes into one reused record, so no value allocates.
///
/// # Errors
/// A malformed row, a cell that is not a finite number, or a time stamp that does not increase.
pub(crate) fn read_csv_columns<R: std::io::Read>(
    path: &Path,
    reader: &mut csv::Reader<R>,
    headers: &csv::StringRecord,
    time: Option<usize>,
    channels: &[usize],
) -> Result<(Vec<f64>, Option<Vec<f64>>)> {
    let mut samples = Vec::new();
    let mut times = time.map(|_| Vec::new());
    let mut record = csv::ByteRecord::new();
    let mut line = 1usize;
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(csv_error(path, e)),
        }
        line += 1;
        let parse = |j: usize| -> Result<f64> {
            let raw = record.get(j).unwrap_or(b"");
            std::str::from_utf8(raw)
                .ok()
                .and_then(|s| s.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    DataError::invalid(
                        path,
                        format!(
                            "line {line}, column `{}`: expected a finite number, got `{}`",
                            &headers[j],
                            String::from_utf8_lossy(raw)
                        ),
                    )
                    .into()
                })
        };
        for &j in channels {
            samples.push(parse(j)?);
        }
        if let (Some(j), Some(times)) = (time, times.as_mut()) {
            let t = parse(j)?;
            if let Some(&prev) = times.last() {
                if t <= prev {
                    return Err(DataError::invalid(
                        path,
                        format!("line {line}: time stamps must increase, got {t} after {prev}"),
                    )
                    .into());
                }
            }
            times.push(t);
        }
    }
    Ok((samples, times))
}

/// Writes `manifest.csv` for `metas` into `dir`: the required columns, the sliding interval
/// when any recording has one, then every extra field any recording carries.
///
/// # Errors
/// The file cannot be written.
pub fn write_manifest(dir: &Path, metas: &[Meta]) -> Result<()> {
    let path = dir.join("manifest.csv");
    let with_slide = metas
        .iter()
        .any(|m| m.slide_start_s.is_some() || m.slide_end_s.is_some());
    let mut extra: Vec<&String> = metas.iter().flat_map(|m| m.extra.keys()).collect();
    extra.sort();
    extra.dedup();
    let mut w = csv::Writer::from_path(&path).map_err(|e| csv_error(&path, e))?;
    let mut header: Vec<&str> = MANIFEST_COLUMNS.to_vec();
    if with_slide {
        header.extend(["slide_start_s", "slide_end_s"]);
    }
    header.extend(extra.iter().map(|k| k.as_str()));
    w.write_record(&header).map_err(|e| csv_error(&path, e))?;
    let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
    for m in metas {
        let mut row = vec![
            m.file.clone(),
            m.label.clone(),
            m.speed_mm_s.to_string(),
            m.force_n.to_string(),
            m.trial.to_string(),
        ];
        if with_slide {
            row.extend([opt(m.slide_start_s), opt(m.slide_end_s)]);
        }
        row.extend(
            extra
                .iter()
                .map(|k| m.extra.get(*k).cloned().unwrap_or_default()),
        );
        w.write_record(&row).map_err(|e| csv_error(&path, e))?;
    }
    w.flush().map_err(|e| DataError::io(&path, e))?;
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
    std::fs::write(&path, text).map_err(|e| DataError::io(&path, e))?;
    Ok(())
}
