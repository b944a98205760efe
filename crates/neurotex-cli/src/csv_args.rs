//! How to read recording files and CSV logs: the options `import csv`, `encode` and
//! `predict` share, turned into the library's [`FileReading`] and [`CsvOverrides`] so every
//! command reads a log the same way.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::csvlog::{
    ChannelSelect, Column, CsvFormat, CsvOverrides, Delimiter, DuplicateStamps,
};
use neurotex::import::{CsvImportParams, NamePattern};
use neurotex::recording::{ChannelMap, FileReading, LayoutFile, LayoutFrom, TimeUnit};
use neurotex::{Grid, SampleRate};

/// CSV reading options.
#[derive(Args, Debug, Clone)]
pub struct CsvArgs {
    /// The file has no header row: columns go by 0-based index, and --time-column and
    /// --channels take indices.
    #[arg(long = "no-header")]
    pub no_header: bool,
    /// The field delimiter: `,`, `;` or `tab` (default: detected from the first lines).
    #[arg(long)]
    pub delimiter: Option<Delimiter>,
    /// The time-stamp column, by name or 0-based index (irregular stamps are kept and
    /// resampled onto 1 ms later).
    #[arg(long = "time-column")]
    pub time_column: Option<Column>,
    /// Unit of the time column: `ms`, `s` or `us` (default: from a suffix of the column's
    /// name such as `_ms`, `_s`, `_us` or `(s)`, else `ms`; stamps implying a rate above
    /// 20 kHz or below 0.1 Hz are then refused, asking for this option).
    #[arg(long = "time-unit")]
    pub time_unit: Option<TimeUnit>,
    /// Channel columns: a comma-separated list of names, of 0-based indices and ranges such
    /// as `2,4-7` or `0-8`, or a regular expression such as `^channel\d+$` (default: every
    /// column but the time column).
    #[arg(long)]
    pub channels: Option<ChannelSelect>,
    /// Rows sharing one time stamp: `average` (one frame, their mean), `first`, `last`, or
    /// `error`. Exact duplicate rows are dropped under each; the counts are reported.
    #[arg(long = "duplicate-stamps")]
    pub duplicate_stamps: Option<DuplicateStamps>,
    /// The longest gap between two time stamps, in s, that resampling may fill by
    /// interpolation (default 1, as `stream`'s --max-gap-s): a longer pause in a log is an
    /// error naming where, not a straight line through it.
    #[arg(long = "max-gap-s")]
    pub max_gap_s: Option<f64>,
}

impl CsvArgs {
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
#[derive(Args, Debug, Clone)]
pub struct ReadArgs {
    /// A `layout.toml` giving grid, channel map, mask, rate, baseline or CSV columns for
    /// the files (default: the `layout.toml` beside each file, else the one a model
    /// remembers from its training dataset, else the defaults). An imported dataset's
    /// layout also reads the raw logs it was imported from.
    #[arg(long)]
    pub layout: Option<PathBuf>,
    /// Sampling rate in Hz (default: the layout's, else 1000; ignored when a CSV file has
    /// a time column: its stamps give the rate).
    #[arg(long, allow_negative_numbers = true)]
    pub fs: Option<SampleRate>,
    /// Grid `ROWSxCOLS` to place the channels on, row-major (replaces the layout's grid,
    /// channel map and mask).
    #[arg(long)]
    pub grid: Option<Grid>,
    #[command(flatten)]
    pub csv: CsvArgs,
}

impl ReadArgs {
    /// The library's reading options; the layout file is read here.
    pub fn reading(&self) -> Result<FileReading> {
        Ok(FileReading {
            layout: self.layout.as_deref().map(LayoutFile::read).transpose()?,
            fs: self.fs.map(SampleRate::hz),
            grid: self.grid.as_ref().map(|g| (g.rows(), g.cols())),
            csv: self.csv.overrides(),
        })
    }

    /// Says on standard error where a layout came from when neither given nor the
    /// defaults: once per distinct source.
    pub fn say_layouts(&self, from: &[LayoutFrom]) {
        let mut said: Vec<&LayoutFrom> = Vec::new();
        for f in from {
            if said.contains(&f) {
                continue;
            }
            said.push(f);
            match f {
                LayoutFrom::Beside(path) => {
                    eprintln!("note: reading the layout beside the recording, {}", path.display())
                }
                LayoutFrom::Remembered => eprintln!(
                    "note: reading with the layout of the model's training dataset (rate, grid, CSV columns)"
                ),
                LayoutFrom::Given | LayoutFrom::Default => {}
            }
        }
    }
}

/// How raw logs are read into recordings: the options `import csv` and `inspect` share.
#[derive(Args, Debug, Clone)]
pub struct LogArgs {
    /// Fields from file names, e.g. `{label}_F{force}_V{speed}mmps_{trial}.csv`; `label`,
    /// `speed` (mm/s), `force` and `trial` fill the manifest, other fields become columns.
    /// Without it the label is the file name.
    #[arg(long = "name-pattern")]
    pub name_pattern: Option<NamePattern>,
    #[command(flatten)]
    pub csv: CsvArgs,
    /// Grid `ROWSxCOLS` to place the channels on, row-major (default one row).
    #[arg(long)]
    pub grid: Option<Grid>,
    /// Each channel's cell as `row,col;row,col;...` (needs --grid).
    #[arg(long = "channel-map", requires = "grid")]
    pub channel_map: Option<ChannelMap>,
    /// Nominal sampling rate in Hz (needed without a time column; else the median interval).
    #[arg(long, allow_negative_numbers = true)]
    pub fs: Option<SampleRate>,
}

impl LogArgs {
    /// The import's reading options (no baseline, stopping at a bad file).
    pub fn params(&self) -> CsvImportParams {
        CsvImportParams {
            pattern: self.name_pattern.clone(),
            format: self.csv.overrides().apply(CsvFormat::default()),
            grid: self.grid.clone(),
            channel_map: self.channel_map.clone(),
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
            || self.fs.is_some()
            || c.overrides().place_columns()
            || c.no_header
            || c.delimiter.is_some()
            || c.duplicate_stamps.is_some()
            || c.max_gap_s.is_some()
            || c.time_unit.is_some()
    }
}
