//! `import`: recordings from other layouts into the dataset format: per-trial CSV logs, a
//! stacked array with one label per sample, or address-event logs.

use std::path::{Path, PathBuf};

use super::{LogOptions, OnProgress};
use crate::error::ParamError;
use crate::events::{EventGrid, EventsFormat, Origin};
use crate::import::NamePattern;
use crate::import::{event_files, import_events, EventImportParams, Found, ImportedFile};
use crate::import::{
    find_csv, import_csv, import_stacked, Axes, CsvImportParams, ImportSummary, StackedParams,
};
use crate::progress::Progress;
use crate::recording::{Baseline, ChannelMap};
use crate::values::TimeUnit;
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
    /// A log that cannot be read (without `--skip-bad`), a folder that cannot be written, or one another run is writing.
    pub fn run(&self, out: &Path, on: OnProgress) -> Result<ImportSummary> {
        // Claimed before the inputs are read: a second run into the folder says so at once.
        let _claim = crate::io::claim_folder(out)?;
        let params = CsvImportParams {
            // `none` is what a layout without a baseline means; it is not written out
            baseline: self.baseline.filter(|b| *b != Baseline::None),
            skip_bad: self.skip_bad,
            ..self.logs.params()
        };
        let found = find_csv(&self.inputs)?;
        say_left_out(&found, on);
        let files = found.files;
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

/// Says each entry of the folders searched that is left out: not a regular file.
fn say_left_out(found: &Found, on: OnProgress) {
    for (_, why) in &found.left_out {
        on(Progress::Advice(&format!("left out {why}")));
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
    let masked = (layout.mask.iter().flatten())
        .map(|row| row.chars().filter(|&c| c == '0').count())
        .sum::<usize>();
    let masked = match masked {
        0 => String::new(),
        1 => " (1 cell masked)".to_string(),
        n => format!(" ({n} cells masked)"),
    };
    if !summary.dropped.is_empty() {
        on(Progress::Say(&format!(
            "dropped channel(s) {}: their cells are masked",
            (summary.dropped.iter())
                .map(|n| crate::values::shown_label(n))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let repeated = match merged + duplicates {
        0 => String::new(),
        _ => format!(
            "; {merged} rows merged and {duplicates} exact duplicates dropped in {}",
            crate::words::counted(summary.merged.len(), "file")
        ),
    };
    on(Progress::Say(&format!(
        "{} recordings ({} left out{repeated}) -> {}; {} channels on a {}x{} grid{masked} at {:.2} Hz nominal",
        summary.written,
        summary.skipped.len(),
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
    /// Arrays that cannot be read or do not match, a folder that cannot be written, or one another run is writing.
    pub fn run(&self, out: &Path) -> Result<usize> {
        // Claimed before the inputs are read: a second run into the folder says so at once.
        let _claim = crate::io::claim_folder(out)?;
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

/// Options of `import events`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ImportEventsOptions {
    /// Event logs (CSV with a header row, or `.npy` with a structured dtype such as
    /// tonic's), or folders whose .csv and .npy files are all imported.
    #[cfg_attr(feature = "cli", arg(required = true))]
    pub inputs: Vec<PathBuf>,
    /// The sensor's grid, `ROWSxCOLS`: x is the column (0 to COLS - 1), y the row.
    #[cfg_attr(feature = "cli", arg(long))]
    pub grid: Grid,
    /// The unit of the time stamps: `us` (tonic's), `ms` or `s`.
    #[cfg_attr(feature = "cli", arg(long = "time-unit"))]
    pub time_unit: TimeUnit,
    /// Metadata from file names, with the extension, e.g. `{label}_v{speed}_{trial}.csv`
    /// (`{speed}` in mm/s gives `speed_mm_s`, which reproduce and `compare --per
    /// speed_mm_s` need; without a pattern the label is the file stem).
    #[cfg_attr(feature = "cli", arg(long = "name-pattern"))]
    pub name_pattern: Option<NamePattern>,
    /// The time column or field.
    #[cfg_attr(feature = "cli", arg(long = "time-column", default_value = "t"))]
    pub time_column: String,
    /// The column (x) and row (y) columns or fields.
    #[cfg_attr(feature = "cli", arg(long, default_value = "x"))]
    pub x: String,
    /// See --x.
    #[cfg_attr(feature = "cli", arg(long, default_value = "y"))]
    pub y: String,
    /// Instead of --x and --y: a 0-based taxel index column, placed on the grid by
    /// --channel-map (row-major without one).
    #[cfg_attr(feature = "cli", arg(long, conflicts_with_all = ["x", "y"]))]
    pub taxel: Option<String>,
    /// With --taxel: each taxel index's cell, `row,col;row,col;...` in index order. Cells
    /// no taxel maps to are masked out (they are not silent taxels).
    #[cfg_attr(feature = "cli", arg(long = "channel-map", requires = "taxel"))]
    pub channel_map: Option<ChannelMap>,
    /// The polarity column or field [default: p, optional: a log without it holds ON
    /// events only]. Named here, or with --polarity-values, it must be in every log.
    #[cfg_attr(feature = "cli", arg(long))]
    pub polarity: Option<String>,
    /// The ON and OFF polarity values, `ON,OFF` [default: 1,0]; booleans read as 1 and 0,
    /// so `True`/`False` logs take the default.
    #[cfg_attr(
        feature = "cli",
        arg(long = "polarity-values", allow_hyphen_values = true)
    )]
    pub polarity_values: Option<String>,
    /// Time 0: `zero` (the stamps count from the recording's start) or `first` (the first
    /// event's stamp, for logs stamped with a clock).
    #[cfg_attr(feature = "cli", arg(long, default_value = "zero"))]
    pub origin: String,
}

impl ImportEventsOptions {
    /// The import's parameters.
    ///
    /// # Errors
    /// Polarity values or an origin that do not parse, or a channel map that does not fit
    /// the grid.
    pub fn params(&self) -> Result<EventImportParams> {
        let given = self.polarity_values.as_deref().unwrap_or("1,0");
        let values: Vec<i64> = given
            .split(',')
            .map(|v| v.trim().parse::<i64>())
            .collect::<Result<_, _>>()
            .ok()
            .filter(|v: &Vec<i64>| v.len() == 2 && v[0] != v[1])
            .ok_or_else(|| {
                let rule =
                    "polarity values are two different integers, ON,OFF (for example 1,0 or 1,-1)";
                ParamError::new("polarity-values", rule, given)
            })?;
        let origin = match self.origin.as_str() {
            "zero" => Origin::Zero,
            "first" => Origin::First,
            other => {
                let rule = "the origin is `zero` or `first`";
                return Err(ParamError::new("origin", rule, other).into());
            }
        };
        let (rows, cols) = (self.grid.rows(), self.grid.cols());
        let taxels: Vec<usize> = match &self.channel_map {
            Some(map) => map.cells().iter().map(|c| c.row * cols + c.col).collect(),
            None => (0..rows * cols).collect(),
        };
        let mut present = self.grid.present().to_vec();
        if let Some(map) = &self.channel_map {
            if let Some(c) = map.cells().iter().find(|c| c.row >= rows || c.col >= cols) {
                let rule = "every channel-map cell must lie on the grid";
                return Err(
                    ParamError::new("channel-map", rule, format!("{c} on {rows}x{cols}")).into(),
                );
            }
            let mut mapped = vec![false; rows * cols];
            for (i, &t) in taxels.iter().enumerate() {
                if std::mem::replace(&mut mapped[t], true) {
                    let rule = "each cell takes one taxel";
                    let got = format!(
                        "taxel {i} on {}, a cell an earlier taxel has",
                        map.cells()[i]
                    );
                    return Err(ParamError::new("channel-map", rule, got).into());
                }
            }
            present = mapped;
        }
        Ok(EventImportParams {
            pattern: self.name_pattern.clone(),
            format: EventsFormat {
                time_unit: self.time_unit,
                time: self.time_column.clone(),
                x: self.x.clone(),
                y: self.y.clone(),
                taxel: self.taxel.clone(),
                polarity: self.polarity.clone().unwrap_or_else(|| "p".into()),
                values: [values[0], values[1]],
                origin,
            },
            grid: EventGrid {
                rows,
                cols,
                present,
                taxels,
            },
            require_polarity: self.polarity.is_some() || self.polarity_values.is_some(),
        })
    }

    /// Imports the logs into the dataset folder `out`, saying what was reordered and
    /// written.
    ///
    /// # Errors
    /// A log that cannot be read or breaks a rule, a folder that cannot be written, or one another run is writing.
    pub fn run(&self, out: &Path, on: OnProgress) -> Result<Vec<ImportedFile>> {
        // Claimed before the inputs are read: a second run into the folder says so at once.
        let _claim = crate::io::claim_folder(out)?;
        let params = self.params()?;
        let found = event_files(&self.inputs)?;
        say_left_out(&found, on);
        let files = found.files;
        on(Progress::Stage("importing", files.len()));
        let imported = import_events(&files, &params, out, &|| on(Progress::Tick))?;
        for f in imported.iter().filter(|f| f.reordered > 0) {
            on(Progress::Advice(&format!(
                "{}: {} event(s) came before an earlier line's time and were sorted into time order",
                f.file, f.reordered
            )));
        }
        let events: usize = imported.iter().map(|f| f.events).sum();
        let merged: usize = imported.iter().map(|f| f.merged).sum();
        let mut spans: Vec<f64> = imported.iter().map(|f| f.span_s).collect();
        spans.sort_by(f64::total_cmp);
        let median = spans.get(spans.len() / 2).copied().unwrap_or(0.0);
        on(Progress::Say(&format!(
            "{} recordings, {events} events ({merged} in a millisecond already holding an event of their cell and polarity, so one spike) -> {}; {}x{} grid, times in {}; a recording spans {median:.3} s (median; from {:.3} to {:.3} s)",
            imported.len(),
            out.display(),
            params.grid.rows,
            params.grid.cols,
            self.time_unit,
            spans.first().copied().unwrap_or(0.0),
            spans.last().copied().unwrap_or(0.0)
        )));
        let mut firsts: Vec<f64> = imported.iter().map(|f| f.first_s).collect();
        firsts.sort_by(f64::total_cmp);
        let first = firsts.get(firsts.len() / 2).copied().unwrap_or(0.0);
        let onsets: Vec<(f64, f64)> = imported
            .iter()
            .filter(|f| f.events > 0)
            .map(|f| (f.first_s, f.span_s))
            .collect();
        let late = crate::inspect::events::LateOnsets::of(&onsets);
        if let (Some(late), Origin::Zero) = (late, params.format.origin) {
            on(Progress::Advice(&format!(
                "{}; import again with --origin first (each recording then starts at its first event), or set origin = \"first\" in {}",
                late.message(),
                out.join("layout.toml").display()
            )));
        } else if !(0.05..=600.0).contains(&median) {
            // Most of the span before the first event: the stamps count from a clock's zero.
            let why = match first > median / 2.0 && params.format.origin == Origin::Zero {
                true => format!("the first events come {first:.3} s (median) after time 0: stamps from a clock need --origin first"),
                false => format!("read with --time-unit {}: a tactile trial lasts seconds, so the unit is probably wrong", self.time_unit),
            };
            on(Progress::Advice(&format!(
                "the median recording spans {median:.3} s; {why}"
            )));
        }
        Ok(imported)
    }
}
