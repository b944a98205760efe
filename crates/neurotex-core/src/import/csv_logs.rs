//! Importing per-trial CSV logs from a DAQ: the options, the files found, each log parsed and
//! written as a recording of the new dataset.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::csvlog::{read_csv_log, ChannelSelect, CsvFormat, LogColumns};
use crate::error::{DataError, ParamError, Result};
use crate::recording::{
    create_dataset_dir, labels_merged_by_trimming, recording_from_channels, write_layout,
    write_manifest, Baseline, ChannelMap, LayoutFile, Meta, Recording, TimeUnit,
};
use crate::values::Grid;

use super::event_logs::POLARITY_NAMES;
use super::name_pattern::{meta_from_name, NamePattern};
use super::stacked::read_back;
use super::warnings::{clock_like, resting_ratio, ImportWarning, OFFSET_RATIO};
use super::{files_with, invalid, Found, ParsedCsv};

/// Options of a CSV import.
#[derive(Debug, Clone)]
pub struct CsvImportParams {
    /// Metadata from file names; without it the label is the file stem.
    pub pattern: Option<NamePattern>,
    /// How the logs are laid out: header, delimiter, time and channel columns, repeated
    /// stamps. Without a time column the sampling rate `fs` is used.
    pub format: CsvFormat,
    /// The grid to place channels on; default one row of all channels.
    pub grid: Option<Grid>,
    /// Each channel's cell; default row-major.
    pub channel_map: Option<ChannelMap>,
    /// Channels left out after they are placed on the grid: their cells are masked, so a
    /// dead taxel of a full grid leaves the others where they are.
    pub drop_channels: Option<ChannelSelect>,
    /// Nominal sampling rate in Hz (required without a time column; else estimated).
    pub fs: Option<f64>,
    /// Baseline removal recorded in `layout.toml`.
    pub baseline: Option<Baseline>,
    /// Leave out files that fail (they are listed in the summary) instead of stopping.
    pub skip_bad: bool,
}

/// What an import did.
#[derive(Debug, Clone, Default)]
pub struct ImportSummary {
    /// Recordings written.
    pub written: usize,
    /// Files left out, with the reason.
    pub skipped: Vec<(PathBuf, String)>,
    /// The layout written.
    pub layout: LayoutFile,
    /// Each imported file in which rows were merged or dropped, in file order.
    pub merged: Vec<MergedRows>,
    /// What the import did that is probably not what was meant (the dataset is written all
    /// the same).
    pub warnings: Vec<ImportWarning>,
    /// The channels `drop_channels` left out (their cells masked).
    pub dropped: Vec<String>,
}

/// CSV logs read one at a time as `import csv` reads them, with the layout the import would
/// write, and no dataset written: what `neurotex inspect` checks before an import.
#[derive(Debug, Clone)]
pub struct Logs {
    /// The log files, sorted.
    pub files: Vec<PathBuf>,
    /// The layout an import of these logs would write (its rate from the options, or from
    /// the first readable log's median stamp interval).
    pub layout: LayoutFile,
    params: CsvImportParams,
}

/// The error for logs read with neither a time column nor a rate, saying first what the
/// first log's header shows: an address event's fields (`import events`), or a column
/// named like time stamps (`--time-column`).
fn no_rate(files: &[PathBuf], p: &CsvImportParams) -> crate::Error {
    let header = files
        .first()
        .and_then(|f| Some((f, crate::csvlog::header_names(f, &p.format)?)));
    if let Some((file, names)) = header {
        let time = names
            .iter()
            .position(|n| crate::csvlog::is_timelike_name(n));
        if let Err(e) = refuse_event_header(file, &names) {
            return e;
        }
        if let Some(j) = time {
            // Without --time-unit a time column's stamps are read in the unit its name
            // ends in, else in ms.
            let unit = match crate::csvlog::unit_in_name(&names[j]) {
                Some(u) => format!("in {u}, as its name says; `--time-unit` if not"),
                None => "`--time-unit` if they are not in ms".into(),
            };
            let why = format!(
                "no time column was chosen and no rate given, and column `{}` is named like time stamps: `--time-column {}` reads it as time (the rate then comes from its stamps, {unit}), or --fs gives the rate of logs without stamps",
                names[j], names[j]
            );
            return DataError::invalid(file, why).into();
        }
    }
    let rule = "without --time-column the sampling rate --fs is needed";
    ParamError::new("fs", rule, "none").into()
}

/// [`refuse_event_log`] on a header's names less the one named like time stamps.
fn refuse_event_header(file: &Path, names: &[String]) -> Result<()> {
    let time = names
        .iter()
        .position(|n| crate::csvlog::is_timelike_name(n));
    let rest: Vec<String> = (names.iter().enumerate())
        .filter(|&(j, _)| Some(j) != time)
        .map(|(_, n)| n.clone())
        .collect();
    refuse_event_log(file, &rest)
}

/// Refuses a log whose channels are an address event's fields (`x`, `y` or a taxel
/// index, and perhaps a polarity): read as samples, each event would be a frame and its
/// coordinates taxel values, at the events' rate.
fn refuse_event_log(file: &Path, channels: &[String]) -> Result<()> {
    let lower: Vec<String> = channels.iter().map(|c| c.trim().to_lowercase()).collect();
    let has = |name: &str| lower.iter().any(|c| c == name);
    let address = (has("x") && has("y")) || ["taxel", "addr", "address"].iter().any(|n| has(n));
    let event_field = |c: &String| {
        ["x", "y", "taxel", "addr", "address"].contains(&c.as_str())
            || POLARITY_NAMES.contains(&c.as_str())
    };
    if address && lower.iter().all(event_field) {
        let why = format!(
            "its columns ({}) are an address event's fields, one event per line, not one frame of taxel values per line: `neurotex import events` reads it into an event dataset, which `inspect` and every command then read as events",
            channels.join(", ")
        );
        return Err(DataError::invalid(file, why).into());
    }
    Ok(())
}

impl Logs {
    /// The logs `files` under the import's options `p`: the first log that reads gives the
    /// channels and the layout.
    ///
    /// # Errors
    /// No files, no time column and no rate, no log that reads, or a grid or channel map
    /// that does not fit the channels.
    pub fn open(files: Vec<PathBuf>, p: CsvImportParams) -> Result<Self> {
        if p.format.time_column.is_none() && p.fs.is_none() {
            return Err(no_rate(&files, &p));
        }
        let (p, _) = p.without_dropped(&files)?;
        // An event log is named as one before its stamps are judged as a sampled log's.
        let first = files.first();
        if let Some((f, names)) =
            first.and_then(|f| Some((f, crate::csvlog::header_names(f, &p.format)?)))
        {
            refuse_event_header(f, &names)?;
        }
        let mut first_error = None;
        for f in &files {
            match parse_csv(f, &p) {
                Ok(first) => {
                    let fs = match p.fs {
                        Some(fs) => fs,
                        None => nominal_fs(std::slice::from_ref(&first), f)?,
                    };
                    let unit = first.log.times.is_some().then_some(first.log.time_unit);
                    let names = &first.log.channel_names;
                    refuse_event_log(f, names)?;
                    let layout = csv_layout(&p, names, fs, unit, &first.log.columns)?;
                    return Ok(Logs {
                        files,
                        layout,
                        params: p,
                    });
                }
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        Err(first_error.unwrap_or_else(|| {
            DataError::invalid(Path::new("."), "no .csv files to inspect").into()
        }))
    }

    /// Whether a channel map places the channels (rather than row-major order).
    pub fn mapped(&self) -> bool {
        self.params.channel_map.is_some()
    }

    /// The channels' names, in log order.
    pub fn channel_names(&self) -> &[String] {
        self.layout.channels.as_deref().unwrap_or_default()
    }

    /// Reads log `i`: its recording on the layout (stamps from the first, in s; metadata
    /// from the file name) and the rows the reader merged or dropped.
    ///
    /// # Errors
    /// A log that does not read, whose name does not fit the pattern, or whose channels
    /// differ from the first log's.
    pub fn read(&self, i: usize) -> Result<(Recording, MergedRows)> {
        let path = &self.files[i];
        let ParsedCsv { meta, log } = parse_csv(path, &self.params)?;
        let names = self.channel_names();
        if log.channel_names != names {
            let message = format!("its channels {:?} differ from {names:?}", log.channel_names);
            return Err(invalid(path, message));
        }
        let unit = log.time_unit.seconds();
        let times_s = log
            .times
            .as_ref()
            .map(|t| t.iter().map(|&v| (v - t[0]) * unit).collect());
        let merged = MergedRows {
            file: meta.file.clone(),
            merged_rows: log.merged_rows,
            duplicate_rows: log.duplicate_rows,
        };
        let n = names.len();
        let rec = recording_from_channels(path, &self.layout, log.samples, n, times_s, meta)?;
        Ok((rec, merged))
    }
}

/// Rows of one file that did not become frames of their own: they shared a time stamp.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MergedRows {
    /// The file's name.
    pub file: String,
    /// Rows folded into the frame of an earlier row with the same stamp.
    pub merged_rows: usize,
    /// Exact duplicate rows dropped.
    pub duplicate_rows: usize,
}

pub(super) fn parse_csv(path: &Path, p: &CsvImportParams) -> Result<ParsedCsv> {
    let meta = meta_from_name(path, p.pattern.as_ref())?;
    let log = read_csv_log(path, &p.format)?;
    Ok(ParsedCsv { meta, log })
}

/// The `.csv` files among `inputs` (folders are searched one level deep), sorted; what a
/// folder holds that is not a regular file is left out ([`find_csv`] says which).
///
/// # Errors
/// As [`find_csv`].
pub fn csv_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    find_csv(inputs).map(|found| found.files)
}

/// The `.csv` files among `inputs` (folders are searched one level deep), sorted, and
/// those a folder holds that are not regular files, left out.
///
/// # Errors
/// An input that does not exist or is not a regular file or folder, or a folder that
/// cannot be read.
pub fn find_csv(inputs: &[PathBuf]) -> Result<Found> {
    files_with(inputs, &["csv"])
}

/// Imports CSV logs into a new dataset folder `out`: one CSV per recording with a `t_ms`
/// column (time stamps kept, relative to the first) and the selected channels, a manifest
/// from the file names, and `layout.toml`. Files are parsed in parallel; `on_done` is
/// called once per file.
///
/// # Errors
/// A bad file (unless `skip_bad`), channels that differ between files, a grid that does
/// not fit the channels, or `out` not empty.
pub fn import_csv(
    files: &[PathBuf],
    p: &CsvImportParams,
    out: &Path,
    on_done: &(dyn Fn() + Sync),
) -> Result<ImportSummary> {
    if files.is_empty() {
        return Err(DataError::invalid(out, "no .csv files to import").into());
    }
    if p.format.time_column.is_none() && p.fs.is_none() {
        return Err(no_rate(files, p));
    }
    reject_duplicate_names(files)?;
    let (p, dropped) = p.without_dropped(files)?;
    let p = &p;
    // An event log is named as one before its stamps are judged as a sampled log's.
    if let Some(names) = crate::csvlog::header_names(&files[0], &p.format) {
        refuse_event_header(&files[0], &names)?;
    }
    let mut summary = ImportSummary {
        dropped,
        ..ImportSummary::default()
    };
    let good = parse_all(files, p, on_done, &mut summary.skipped)?;
    let Some(first) = good.first() else {
        let why = match summary.skipped.first() {
            Some((_, first)) => format!(
                "every file was left out ({} with --skip-bad); the first: {first}",
                summary.skipped.len()
            ),
            None => "every file was left out".to_string(),
        };
        return Err(DataError::invalid(out, why).into());
    };
    check_parsed(&good, out)?;
    let names = first.log.channel_names.clone();
    let fs = match p.fs {
        Some(fs) => fs,
        None => nominal_fs(&good, out)?,
    };
    let unit = first.log.times.is_some().then_some(first.log.time_unit);
    let layout = csv_layout(p, &names, fs, unit, &first.log.columns)?;
    create_dataset_dir(out, |tmp| {
        write_layout(tmp, &layout)?;
        // validates the layout before anything else is written
        LayoutFile::read(&tmp.join("layout.toml"))?;
        let metas: Vec<Meta> = good
            .par_iter()
            .map(|c| write_imported(tmp, c, &names))
            .collect::<Result<_>>()?;
        write_manifest(tmp, &metas)?;
        read_back(tmp)
    })?;
    summary.written = good.len();
    summary.warnings = import_warnings(p, &layout, &good);
    summary.layout = layout;
    summary.merged = good
        .iter()
        .filter(|c| c.log.merged_rows + c.log.duplicate_rows > 0)
        .map(|c| MergedRows {
            file: c.meta.file.clone(),
            merged_rows: c.log.merged_rows,
            duplicate_rows: c.log.duplicate_rows,
        })
        .collect();
    Ok(summary)
}

/// The parsed logs' labels and channels: labels that trimming would merge, an event log
/// taken for a sampled one, and channels that differ between files are refused.
fn check_parsed(good: &[ParsedCsv], out: &Path) -> Result<()> {
    let first = &good[0];
    let labels: Vec<(String, String)> = good
        .iter()
        .map(|c| (c.meta.label.clone(), format!("file `{}`", c.meta.file)))
        .collect();
    if let Some(message) = labels_merged_by_trimming(&labels) {
        return Err(DataError::invalid(out, message).into());
    }
    let names = &first.log.channel_names;
    refuse_event_log(Path::new(&first.meta.file), names)?;
    if let Some(other) = good.iter().find(|c| &c.log.channel_names != names) {
        return Err(invalid(
            Path::new(&other.meta.file),
            format!(
                "its channels {:?} differ from {:?} of {}",
                other.log.channel_names, names, first.meta.file
            ),
        ));
    }
    Ok(())
}

/// Each input is written under its file name, so two inputs of one name (`a/x.csv` and
/// `b/x.csv`) would become one file with two manifest rows: refused, naming both.
fn reject_duplicate_names(files: &[PathBuf]) -> Result<()> {
    let mut seen: BTreeMap<&std::ffi::OsStr, &Path> = BTreeMap::new();
    for f in files {
        let Some(name) = f.file_name() else { continue };
        if let Some(first) = seen.insert(name, f) {
            let message = format!(
                "two inputs have the file name `{}` ({} and {}), which would be one file in the dataset; rename one or import them separately",
                name.to_string_lossy(),
                first.display(),
                f.display()
            );
            return Err(invalid(f, message));
        }
    }
    Ok(())
}

/// Parses every file in parallel; a bad file is an error, or with `skip_bad` is listed in
/// `skipped` with its reason.
fn parse_all(
    files: &[PathBuf],
    p: &CsvImportParams,
    on_done: &(dyn Fn() + Sync),
    skipped: &mut Vec<(PathBuf, String)>,
) -> Result<Vec<ParsedCsv>> {
    let parsed: Vec<(PathBuf, Result<ParsedCsv>)> = files
        .par_iter()
        .map(|f| {
            let r = parse_csv(f, p);
            on_done();
            (f.clone(), r)
        })
        .collect();
    let mut good = Vec::new();
    for (f, r) in parsed {
        match r {
            Ok(c) => good.push(c),
            Err(e) if p.skip_bad => skipped.push((f, e.to_string())),
            Err(e) => return Err(e),
        }
    }
    Ok(good)
}

/// The nominal sampling rate: one over the median interval of all files' time stamps.
fn nominal_fs(good: &[ParsedCsv], out: &Path) -> Result<f64> {
    let mut dts: Vec<f64> = good
        .iter()
        .filter_map(|c| Some((c.log.times.as_ref()?, c.log.time_unit.seconds())))
        .flat_map(|(t, unit)| t.windows(2).map(move |w| (w[1] - w[0]) * unit))
        .collect();
    if dts.is_empty() {
        let message = "cannot estimate the sampling rate from single-row files; give --fs";
        return Err(DataError::invalid(out, message).into());
    }
    let mid = dts.len() / 2;
    let (_, median, _) = dts.select_nth_unstable_by(mid, f64::total_cmp);
    Ok(round_nominal(1.0 / *median))
}

/// `fs`, or the number of six significant digits within a billionth of it: stamps such as
/// 0.005 s have no exact binary form, which leaves noise in the last digits of a rate such
/// as 200 Hz (200.0000000001819), and layout.toml should say 200. A rate of no such
/// number (35.714285714285715 Hz, stamps every 28 ms) is kept whole.
fn round_nominal(fs: f64) -> f64 {
    let scale = 10f64.powi(5 - fs.abs().log10().floor() as i32);
    let nice = (fs * scale).round() / scale;
    match ((nice - fs) / fs).abs() < 1e-9 {
        true => nice,
        false => fs,
    }
}

/// The layout of the imported dataset: channels fill the grid row-major unless mapped, and
/// cells no channel reaches are masked; `unit` is the logs' time unit when they have stamps,
/// `source` how they were read.
fn csv_layout(
    p: &CsvImportParams,
    names: &[String],
    fs: f64,
    unit: Option<TimeUnit>,
    source: &LogColumns,
) -> Result<LayoutFile> {
    let timed = unit.is_some();
    let n = names.len();
    let (rows, cols) = p.grid.as_ref().map_or((1, n), |g| (g.rows(), g.cols()));
    let cells = crate::values::check_grid_cells(rows, cols)?;
    if cells < n {
        let rule = "the grid must have a cell for every channel";
        let got = format!("{rows}x{cols} for {n} channels");
        return Err(ParamError::new("grid", rule, got).into());
    }
    let map: Vec<[usize; 2]> = match &p.channel_map {
        Some(map) => map.to_pairs(),
        None => (0..n).map(|k| [k / cols, k % cols]).collect(),
    };
    if map.len() != n {
        let got = format!("{} cells for {n} channels", map.len());
        let rule = "the map needs one cell per channel";
        return Err(ParamError::new("channel-map", rule, got).into());
    }
    let mut used = vec![false; cells];
    for &[r, c] in &map {
        if r < rows && c < cols {
            used[r * cols + c] = true;
        }
    }
    let full = used.iter().all(|&u| u);
    let mask_row = |r: usize| -> String {
        (0..cols)
            .map(|c| if used[r * cols + c] { '1' } else { '0' })
            .collect()
    };
    Ok(LayoutFile {
        fs: Some(fs),
        rows: Some(rows),
        cols: Some(cols),
        channel_map: (p.channel_map.is_some() || !full).then_some(map),
        mask: (!full).then(|| (0..rows).map(mask_row).collect()),
        baseline: p.baseline,
        time_column: unit.map(time_column),
        time_unit: unit,
        channels: Some(names.to_vec()),
        max_gap_s: (timed && p.format.max_gap_s != crate::csvlog::DEFAULT_MAX_GAP_S)
            .then_some(p.format.max_gap_s),
        source: Some(source.clone()),
        ..LayoutFile::default()
    })
}

/// The imported files' time column: `t_ms`, `t_s` or `t_us` after the logs' unit.
pub(super) fn time_column(unit: TimeUnit) -> String {
    format!("t_{unit}")
}

/// Writes one parsed file into the dataset folder `dir`: its time stamps less the first in
/// their own unit (when it has time stamps; [`time_column`]), then the channels. The stamps
/// are subtracted in their unit and written in the shortest form that reads back to the
/// same double, so the imported copy gives the times the raw log gives, to the bit.
fn write_imported(dir: &Path, parsed: &ParsedCsv, names: &[String]) -> Result<Meta> {
    let path = dir.join(&parsed.meta.file);
    let c = &parsed.log;
    let mut text = String::with_capacity(c.samples.len() * 8);
    if c.times.is_some() {
        text.push_str(&time_column(c.time_unit));
        text.push(',');
    }
    text.push_str(&names.join(","));
    text.push('\n');
    let t0 = c.times.as_ref().map_or(0.0, |t| t[0]);
    for (k, frame) in c.samples.chunks_exact(names.len()).enumerate() {
        if let Some(t) = &c.times {
            text.push_str(&format!("{},", t[k] - t0));
        }
        let values: Vec<String> = frame.iter().map(|v| v.to_string()).collect();
        text.push_str(&values.join(","));
        text.push('\n');
    }
    std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
    Ok(parsed.meta.clone())
}

/// The import's warnings on the logs it read ([`ImportWarning`]).
fn import_warnings(
    p: &CsvImportParams,
    layout: &LayoutFile,
    good: &[ParsedCsv],
) -> Vec<ImportWarning> {
    let mut out = Vec::new();
    let labels: Vec<&str> = good.iter().map(|c| c.meta.label.as_str()).collect();
    if let Some(labels) = crate::recording::labels_differing_in_case(&labels) {
        out.push(ImportWarning::LabelsDifferInCase { labels });
    }
    let constant = |c: &&ParsedCsv| {
        let n = c.log.channel_names.len().max(1);
        let first = c.log.samples.get(..n);
        let frames = c.log.samples.chunks_exact(n);
        c.log.samples.len() > n && frames.clone().all(|f| Some(f) == first)
    };
    let files: Vec<String> = (good.iter().filter(constant))
        .map(|c| c.meta.file.clone())
        .collect();
    if !files.is_empty() {
        out.push(ImportWarning::NoSignal { files });
    }
    let channels = layout.channels.as_ref().map_or(0, Vec::len);
    let (rows, cols) = (layout.rows.unwrap_or(1), layout.cols.unwrap_or(channels));
    if p.channel_map.is_none() && channels < rows * cols {
        out.push(ImportWarning::GridNotFilled {
            channels,
            rows,
            cols,
        });
    }
    let names = good.first().map_or(&[][..], |c| &c.log.channel_names[..]);
    for (k, channel) in names.iter().enumerate() {
        let n = names.len();
        let rising = (good.iter())
            .filter(|c| clock_like(c.log.samples.iter().skip(k).step_by(n).copied()))
            .count();
        if 2 * rising > good.len() {
            out.push(ImportWarning::RisingChannel {
                channel: channel.clone(),
                files: rising,
                total: good.len(),
            });
        }
    }
    if p.baseline.is_none() {
        let mut high: Vec<f64> = good
            .iter()
            .filter_map(|c| resting_ratio(&c.log.samples, c.log.channel_names.len()))
            .filter(|&r| r >= OFFSET_RATIO)
            .collect();
        if 2 * high.len() > good.len() {
            high.sort_by(f64::total_cmp);
            out.push(ImportWarning::RestingOffset {
                ratio: high[high.len() / 2],
                files: high.len(),
                total: good.len(),
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::round_nominal;

    #[test]
    fn a_rate_off_a_round_number_by_the_stamps_rounding_is_that_number() {
        // Stamps written in seconds every 5 ms, read back as a logger prints them.
        let times: Vec<f64> = (0..100)
            .map(|i| format!("{}", f64::from(i) * 0.005).parse().unwrap())
            .collect();
        let dts: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(
            dts.iter().any(|&dt| 1.0 / dt != 200.0),
            "the stamps are exact"
        );
        for dt in dts {
            assert_eq!(round_nominal(1.0 / dt), 200.0, "{dt}");
        }
        // Rates that no number of six digits comes within a billionth of are kept.
        assert_eq!(round_nominal(1.0 / 0.028), 1.0 / 0.028);
        assert_eq!(round_nominal(1.0 / 3.0), 1.0 / 3.0);
        assert_eq!(round_nominal(1000.0), 1000.0);
        assert_eq!(round_nominal(33.3), 33.3);
    }
}
