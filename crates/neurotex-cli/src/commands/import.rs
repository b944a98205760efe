//! `neurotex import`: recordings from other layouts into the dataset format.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use neurotex::import::{
    csv_files, import_csv, import_stacked, Axes, CsvImportParams, ImportSummary, StackedParams,
};
use neurotex::recording::Baseline;
use neurotex::{Grid, SampleRate};

use crate::csv_args::LogArgs;
use crate::output::{progress, tick};

/// `neurotex import`: bring recordings from other layouts into the dataset format.
#[derive(Subcommand)]
pub enum ImportCommand {
    /// Per-trial CSV logs (a header row or none, a time column, one column per channel),
    /// with metadata taken from the file names.
    Csv(ImportCsvArgs),
    /// A stacked array `(N, ...)` with one label (and optionally one speed) per sample.
    Stacked(ImportStackedArgs),
}

/// Options of `neurotex import csv`.
#[derive(Args)]
pub struct ImportCsvArgs {
    /// CSV files, or folders whose .csv files are all imported.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub logs: LogArgs,
    /// Baseline removal to record in layout.toml: `none` or `min` (capacitive sensors rest
    /// at a large offset).
    #[arg(long)]
    pub baseline: Option<Baseline>,
    /// Leave out files with errors (each is reported) instead of stopping at the first.
    #[arg(long = "skip-bad")]
    pub skip_bad: bool,
}

/// Options of `neurotex import stacked`.
#[derive(Args)]
pub struct ImportStackedArgs {
    /// The stacked samples, `.npy` of floats or integers.
    #[arg(long)]
    pub data: PathBuf,
    /// One label per sample, `.npy` of integers or strings.
    #[arg(long)]
    pub labels: PathBuf,
    /// The data's axes in order, from n (sample), t (time), row, col, channel:
    /// e.g. `n,row,col,t` for shape (N, rows, cols, T) or `n,t,channel`.
    #[arg(long)]
    pub axes: Axes,
    /// Sampling rate in Hz.
    #[arg(long, allow_negative_numbers = true)]
    pub fs: SampleRate,
    /// One speed (mm/s) per sample, `.npy`.
    #[arg(long)]
    pub speeds: Option<PathBuf>,
    /// With a channel axis: the grid `ROWSxCOLS` to place channels on, row-major.
    #[arg(long)]
    pub grid: Option<Grid>,
    /// The dataset folder to create.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `neurotex import csv` or `neurotex import stacked`.
pub fn run(command: ImportCommand) -> Result<()> {
    match command {
        ImportCommand::Csv(args) => csv(args),
        ImportCommand::Stacked(args) => stacked(args),
    }
}

fn csv(args: ImportCsvArgs) -> Result<()> {
    let params = CsvImportParams {
        // `none` is what a layout without a baseline means; it is not written out
        baseline: args.baseline.filter(|b| *b != Baseline::None),
        skip_bad: args.skip_bad,
        ..args.logs.params()
    };
    let files = csv_files(&args.inputs)?;
    let bar = progress(files.len(), "importing");
    let summary = import_csv(&files, &params, &args.out, &|| tick(&bar));
    bar.finish_and_clear();
    let summary = summary?;
    for (_, why) in &summary.skipped {
        eprintln!("warning: left out {why}");
    }
    for warning in &summary.warnings {
        eprintln!("warning: {warning}");
    }
    say_summary(&summary, &args.out);
    Ok(())
}

/// Says on standard error what each file's repeated stamps became, then what was written.
fn say_summary(summary: &ImportSummary, out: &std::path::Path) {
    for m in &summary.merged {
        eprintln!(
            "note: {}: {} row(s) sharing a time stamp merged, {} exact duplicate row(s) dropped",
            m.file, m.merged_rows, m.duplicate_rows
        );
    }
    let merged: usize = summary.merged.iter().map(|m| m.merged_rows).sum();
    let duplicates: usize = summary.merged.iter().map(|m| m.duplicate_rows).sum();
    let layout = &summary.layout;
    eprintln!(
        "{} recordings ({} left out; {merged} rows merged and {duplicates} exact duplicates dropped in {} files) -> {}; {} channels on a {}x{} grid at {:.2} Hz nominal",
        summary.written,
        summary.skipped.len(),
        summary.merged.len(),
        out.display(),
        layout.channels.as_ref().map_or(0, Vec::len),
        layout.rows.unwrap_or(1),
        layout.cols.unwrap_or(1),
        layout.fs.unwrap_or(0.0)
    );
}

fn stacked(args: ImportStackedArgs) -> Result<()> {
    let params = StackedParams {
        axes: args.axes,
        fs: args.fs.hz(),
        grid: args.grid,
    };
    let speeds = args.speeds.as_deref();
    let n = import_stacked(&args.data, &args.labels, speeds, &params, &args.out)?;
    eprintln!("{n} recordings -> {}", args.out.display());
    Ok(())
}
