//! How recordings are found and read: the options on opening a dataset folder, on reading
//! recording files given by path, and on reading raw CSV logs, turned into the library's
//! [`FileReading`] and [`CsvImportParams`] so that every command reads a log the same way.

use std::path::{Path, PathBuf};

use crate::csvlog::{ChannelSelect, Column, CsvFormat, CsvOverrides, Delimiter, DuplicateStamps};
use crate::import::{CsvImportParams, NamePattern};
use crate::recording::{ChannelMap, Dataset, FileReading, LayoutFile, LayoutFrom, TimeUnit};
use crate::{Grid, Result, SampleRate};

/// Options on opening a dataset, shared by every command that reads one.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct OpenOptions {
    /// Let manifest `file` entries point outside the dataset folder (`../x.npy`, absolute
    /// paths, symbolic links to elsewhere). Refused by default: a manifest should not make
    /// neurotex read any file on the machine.
    #[cfg_attr(feature = "cli", arg(long = "allow-outside-paths"))]
    pub allow_outside_paths: bool,
}

impl OpenOptions {
    /// Opens the dataset folder `dir` under these options.
    ///
    /// # Errors
    /// The folder, its manifest or its layout cannot be read.
    pub fn open(&self, dir: &Path) -> Result<Dataset> {
        Dataset::open_with(dir, self.allow_outside_paths)
    }
}

/// CSV reading options.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct CsvOptions {
    /// The file has no header row: columns go by 0-based index, and --time-column and
    /// --channels take indices.
    #[cfg_attr(feature = "cli", arg(long = "no-header"))]
    pub no_header: bool,
    /// The field delimiter: `,`, `;` or `tab` (default: detected from the first lines).
    #[cfg_attr(feature = "cli", arg(long))]
    pub delimiter: Option<Delimiter>,
    /// The time-stamp column, by name or 0-based index (irregular stamps are kept and
    /// resampled onto 1 ms later).
    #[cfg_attr(feature = "cli", arg(long = "time-column"))]
    pub time_column: Option<Column>,
    /// Unit of the time column: `ms`, `s` or `us` (default: from a suffix of the column's
    /// name such as `_ms`, `_s`, `_us` or `(s)`, else `ms`; stamps implying a rate above
    /// 20 kHz or below 5 Hz are then refused, asking for this option, which is taken as
    /// said).
    #[cfg_attr(feature = "cli", arg(long = "time-unit"))]
    pub time_unit: Option<TimeUnit>,
    /// Channel columns: a comma-separated list of names, of 0-based indices and ranges such
    /// as `2,4-7` or `0-8`, or a regular expression such as `^channel\d+$` (default: every
    /// column but the time column).
    #[cfg_attr(feature = "cli", arg(long))]
    pub channels: Option<ChannelSelect>,
    /// Rows sharing one time stamp: `average` (one frame, their mean), `first`, `last`, or
    /// `error`. Exact duplicate rows are dropped under each; the counts are reported.
    #[cfg_attr(feature = "cli", arg(long = "duplicate-stamps"))]
    pub duplicate_stamps: Option<DuplicateStamps>,
    /// The longest gap between two time stamps, in s, that resampling may fill by
    /// interpolation (default 1, as `stream`'s --max-gap-s): a longer pause in a log is an
    /// error naming where, not a straight line through it.
    #[cfg_attr(feature = "cli", arg(long = "max-gap-s"))]
    pub max_gap_s: Option<f64>,
}

impl CsvOptions {
    /// The options given, for the library to put in place of a layout's settings.
    pub fn overrides(&self) -> CsvOverrides {
        CsvOverrides {
            no_header: self.no_header,
            delimiter: self.delimiter,
            time_column: self.time_column.clone(),
            time_unit: self.time_unit,
            channels: self.channels.clone(),
            duplicate_stamps: self.duplicate_stamps,
            max_gap_s: self.max_gap_s,
        }
    }
}

/// How a command reads recording files given by path: their layout, rate, grid and CSV
/// columns. The same options on `encode` and `predict`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ReadOptions {
    /// A `layout.toml` giving grid, channel map, mask, rate, baseline or CSV columns for
    /// the files (default: the `layout.toml` beside each file, else the one a model
    /// remembers from its training dataset, else the defaults). An imported dataset's
    /// layout also reads the raw logs it was imported from.
    #[cfg_attr(feature = "cli", arg(long))]
    pub layout: Option<PathBuf>,
    /// Sampling rate in Hz (default: the layout's, else 1000; ignored when a CSV file has
    /// a time column: its stamps give the rate).
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub fs: Option<SampleRate>,
    /// Grid `ROWSxCOLS` to place the channels on, row-major (replaces the layout's grid,
    /// channel map and mask).
    #[cfg_attr(feature = "cli", arg(long))]
    pub grid: Option<Grid>,
    /// How CSV logs are read.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub csv: CsvOptions,
}

impl ReadOptions {
    /// The library's reading options; the layout file is read here.
    ///
    /// # Errors
    /// The layout file cannot be read.
    pub fn reading(&self) -> Result<FileReading> {
        Ok(FileReading {
            layout: self.layout.as_deref().map(LayoutFile::read).transpose()?,
            fs: self.fs.map(SampleRate::hz),
            grid: self.grid.as_ref().map(|g| (g.rows(), g.cols())),
            csv: self.csv.overrides(),
        })
    }

    /// Where each layout came from when neither given nor the defaults, as notes for the
    /// user: once per distinct source.
    pub fn layout_notes(from: &[LayoutFrom]) -> Vec<String> {
        let mut said: Vec<&LayoutFrom> = Vec::new();
        let mut notes = Vec::new();
        for f in from {
            if said.contains(&f) {
                continue;
            }
            said.push(f);
            match f {
                LayoutFrom::Beside(path) => notes.push(format!(
                    "note: reading the layout beside the recording, {}",
                    path.display()
                )),
                LayoutFrom::Remembered => notes.push(
                    "note: reading with the layout of the model's training dataset (rate, grid, CSV columns)"
                        .to_string(),
                ),
                LayoutFrom::Given | LayoutFrom::Default => {}
            }
        }
        notes
    }
}

/// How raw logs are read into recordings: the options `import csv` and `inspect` share.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct LogOptions {
    /// Fields from file names, e.g. `{label}_F{force}_V{speed}mmps_{trial}.csv`; `label`,
    /// `speed` (mm/s), `force` and `trial` fill the manifest, other fields become columns.
    /// Without it the label is the file name.
    #[cfg_attr(feature = "cli", arg(long = "name-pattern"))]
    pub name_pattern: Option<NamePattern>,
    /// How CSV logs are read.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub csv: CsvOptions,
    /// Grid `ROWSxCOLS` to place the channels on, row-major (default one row).
    #[cfg_attr(feature = "cli", arg(long))]
    pub grid: Option<Grid>,
    /// Each channel's cell as `row,col;row,col;...` (needs --grid).
    #[cfg_attr(feature = "cli", arg(long = "channel-map", requires = "grid"))]
    pub channel_map: Option<ChannelMap>,
    /// Channels to leave out after placing every channel on the grid (row-major or by
    /// --channel-map): names, 0-based column indices such as `5,17`, or a regular
    /// expression. Their cells are masked, so a dead taxel of a full grid leaves the others
    /// where they are.
    #[cfg_attr(feature = "cli", arg(long = "drop-channels"))]
    pub drop_channels: Option<ChannelSelect>,
    /// Nominal sampling rate in Hz (needed without a time column; else the median interval).
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub fs: Option<SampleRate>,
}

impl LogOptions {
    /// The import's reading options (no baseline, stopping at a bad file).
    pub fn params(&self) -> CsvImportParams {
        CsvImportParams {
            pattern: self.name_pattern.clone(),
            format: self.csv.overrides().apply(CsvFormat::default()),
            grid: self.grid.clone(),
            channel_map: self.channel_map.clone(),
            drop_channels: self.drop_channels.clone(),
            fs: self.fs.map(SampleRate::hz),
            baseline: None,
            skip_bad: false,
        }
    }

    /// Whether any option was given (they apply to raw logs, not to a dataset folder).
    pub fn any(&self) -> bool {
        let c = &self.csv;
        self.name_pattern.is_some()
            || self.grid.is_some()
            || self.channel_map.is_some()
            || self.drop_channels.is_some()
            || self.fs.is_some()
            || c.overrides().place_columns()
            || c.no_header
            || c.delimiter.is_some()
            || c.duplicate_stamps.is_some()
            || c.max_gap_s.is_some()
            || c.time_unit.is_some()
    }
}
