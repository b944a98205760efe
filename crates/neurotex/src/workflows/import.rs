//! `import`: recordings from other layouts into the dataset format: per-trial CSV logs,
//! or a stacked array with one label per sample.

use std::path::{Path, PathBuf};

use super::{LogOptions, OnProgress};
use crate::import::{
    csv_files, import_csv, import_stacked, Axes, CsvImportParams, ImportSummary, StackedParams,
};
use crate::progress::Progress;
use crate::recording::Baseline;
use crate::{Grid, Result, SampleRate};

/// Options of `import csv`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ImportCsvOptions {
    /// CSV files, or folders whose .csv files are all imported.
    #[cfg_attr(feature = "cli", arg(required = true))]
    pub inputs: Vec<PathBuf>,
    /// How raw logs are read.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub logs: LogOptions,
    /// Baseline removal to record in layout.toml: `none` or `min` (capacitive sensors rest
    /// at a large offset).
    #[cfg_attr(feature = "cli", arg(long))]
    pub baseline: Option<Baseline>,
    /// Leave out files with errors (each is reported) instead of stopping at the first.
    #[cfg_attr(feature = "cli", arg(long = "skip-bad"))]
    pub skip_bad: bool,
}

/// Options of `import stacked`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ImportStackedOptions {
    /// The stacked samples, `.npy` of floats or integers.
    #[cfg_attr(feature = "cli", arg(long))]
    pub data: PathBuf,
    /// One label per sample, `.npy` of integers or strings.
    #[cfg_attr(feature = "cli", arg(long))]
    pub labels: PathBuf,
    /// The data's axes in order, from n (sample), t (time), row, col, channel:
    /// e.g. `n,row,col,t` for shape (N, rows, cols, T) or `n,t,channel`.
    #[cfg_attr(feature = "cli", arg(long))]
    pub axes: Axes,
    /// Sampling rate in Hz.
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub fs: SampleRate,
    /// One speed (mm/s) per sample, `.npy`.
    #[cfg_attr(feature = "cli", arg(long))]
    pub speeds: Option<PathBuf>,
    /// With a channel axis: the grid `ROWSxCOLS` to place channels on, row-major.
    #[cfg_attr(feature = "cli", arg(long))]
    pub grid: Option<Grid>,
}

impl ImportCsvOptions {
    /// Imports the logs into the dataset folder `out`, saying each file left out, each
    /// warning and what was written.
    ///
    /// # Errors
    /// A log that cannot be read (without `--skip-bad`), or a folder that cannot be written.
    pub fn run(&self, out: &Path, on: OnProgress) -> Result<ImportSummary> {
        let params = CsvImportParams {
            // `none` is what a layout without a baseline means; it is not written out
            baseline: self.baseline.filter(|b| *b != Baseline::None),
            skip_bad: self.skip_bad,
            ..self.logs.params()
        };
        let files = csv_files(&self.inputs)?;
        on(Progress::Stage("importing", files.len()));
        let summary = import_csv(&files, &params, out, &|| on(Progress::Tick))?;
        for (_, why) in &summary.skipped {
            on(Progress::Advice(&format!("left out {why}")));
        }
        for warning in &summary.warnings {
            on(Progress::Advice(&warning.to_string()));
        }
        say_summary(&summary, out, on);
        Ok(summary)
    }
}

/// Says what each file's repeated stamps became, then what was written.
fn say_summary(summary: &ImportSummary, out: &Path, on: OnProgress) {
    for m in &summary.merged {
        on(Progress::Say(&format!(
            "note: {}: {} row(s) sharing a time stamp merged, {} exact duplicate row(s) dropped",
            m.file, m.merged_rows, m.duplicate_rows
        )));
    }
    let merged: usize = summary.merged.iter().map(|m| m.merged_rows).sum();
    let duplicates: usize = summary.merged.iter().map(|m| m.duplicate_rows).sum();
    let layout = &summary.layout;
    on(Progress::Say(&format!(
        "{} recordings ({} left out; {merged} rows merged and {duplicates} exact duplicates dropped in {} files) -> {}; {} channels on a {}x{} grid at {:.2} Hz nominal",
        summary.written,
        summary.skipped.len(),
        summary.merged.len(),
        out.display(),
        layout.channels.as_ref().map_or(0, Vec::len),
        layout.rows.unwrap_or(1),
        layout.cols.unwrap_or(1),
        layout.fs.unwrap_or(0.0)
    )));
}

impl ImportStackedOptions {
    /// Imports the stacked samples into the dataset folder `out`; returns the recordings
    /// written.
    ///
    /// # Errors
    /// Arrays that cannot be read or do not match, or a folder that cannot be written.
    pub fn run(&self, out: &Path) -> Result<usize> {
        let params = StackedParams {
            axes: self.axes.clone(),
            fs: self.fs.hz(),
            grid: self.grid.clone(),
        };
        import_stacked(
            &self.data,
            &self.labels,
            self.speeds.as_deref(),
            &params,
            out,
        )
    }
}
