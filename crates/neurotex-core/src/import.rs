//! Importing recordings from other layouts into the dataset format: per-trial CSV logs from
//! a DAQ (metadata from file names) and the stacked arrays machine-learning datasets ship.
//!
//! The options a user types ([`NamePattern`], [`ChannelSelect`], [`Axes`]) parse from text
//! with `FromStr`.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use ndarray::{ArrayD, Axis, IxDyn};
use ndarray_npy::ReadNpyExt;
use rayon::prelude::*;

pub use crate::csvlog::ChannelSelect;
use crate::csvlog::{read_csv_log, CsvFormat, CsvLog, LogColumns};
use crate::error::{DataError, ParamError, Result};
use crate::recording::{
    create_dataset_dir, labels_merged_by_trimming, recording_from_channels, write_layout,
    write_manifest, Baseline, ChannelMap, LayoutFile, Meta, Recording, TimeUnit,
};
use crate::values::{Grid, Speed};

mod dropped;

/// A file-name pattern such as `{label}_F{force}_V{speed}mmps_{trial}.csv`: literal text and
/// `{field}`s. `label`, `speed` (mm/s), `force` (N) and `trial` fill the manifest's columns;
/// any other field becomes an extra manifest column. Text outside the fields is matched
/// literally (brackets, parentheses and dots included), in time linear in the name's
/// length: the pattern becomes a regular expression of the `regex` crate, which never
/// backtracks.
#[derive(Debug, Clone)]
pub struct NamePattern {
    parts: Vec<Part>,
    /// The fields in order: capture group `k + 1` holds field `k`.
    fields: Vec<String>,
    regex: regex::Regex,
}

impl PartialEq for NamePattern {
    fn eq(&self, other: &Self) -> bool {
        self.parts == other.parts
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Part {
    Literal(String),
    Field(String),
}

/// What a field's value looks like: `speed` and `force` are numbers, `trial` an integer,
/// anything else at least one character, as few as possible.
fn field_regex(field: &str) -> &'static str {
    match field {
        "speed" | "force" => r"([+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)",
        "trial" => r"([+-]?[0-9]+)",
        _ => r"(.+?)",
    }
}

impl NamePattern {
    /// Parses a pattern.
    ///
    /// # Errors
    /// Unbalanced braces, an empty field name, a field named twice, two fields with nothing
    /// between them, or a pattern too long to compile.
    pub fn parse(pattern: &str) -> Result<Self, ParamError> {
        let bad = |rule| ParamError::new("name-pattern", rule, pattern);
        let parts = split_pattern(pattern)?;
        let mut fields: Vec<String> = Vec::new();
        let mut source = String::from(r"(?s)\A");
        for part in &parts {
            match part {
                Part::Literal(text) => source.push_str(&regex::escape(text)),
                Part::Field(name) => {
                    if fields.contains(name) {
                        return Err(bad("each field may appear once"));
                    }
                    fields.push(name.clone());
                    source.push_str(field_regex(name));
                }
            }
        }
        if fields.is_empty() {
            return Err(bad("the pattern names no {field}"));
        }
        source.push_str(r"\z");
        let regex = regex::Regex::new(&source).map_err(|_| bad("the pattern is too long"))?;
        Ok(NamePattern {
            parts,
            fields,
            regex,
        })
    }

    /// The pattern as written: literal text and `{field}`s.
    pub fn text(&self) -> String {
        self.parts
            .iter()
            .map(|part| match part {
                Part::Literal(text) => text.clone(),
                Part::Field(name) => format!("{{{name}}}"),
            })
            .collect()
    }

    /// The fields of `name`, or `None` when it does not match. Fields match as few
    /// characters as possible (at least one) such that the rest still matches; `speed` and
    /// `force` only match numbers and `trial` only integers, so a label may contain the
    /// pattern's separators (`Denim_Flex_F150_...`).
    pub fn matches(&self, name: &str) -> Option<BTreeMap<String, String>> {
        let caps = self.regex.captures(name)?;
        let fields = self.fields.iter().enumerate();
        Some(
            fields
                .map(|(k, field)| (field.clone(), caps[k + 1].to_string()))
                .collect(),
        )
    }
}

/// A pattern's literal text and `{field}`s, in order.
fn split_pattern(pattern: &str) -> Result<Vec<Part>, ParamError> {
    let bad = |rule| ParamError::new("name-pattern", rule, pattern);
    let mut parts = Vec::new();
    let mut rest = pattern;
    while !rest.is_empty() {
        let literal_end = rest.find('{').unwrap_or(rest.len());
        if literal_end > 0 {
            if rest[..literal_end].contains('}') {
                return Err(bad("a `}` without its `{`"));
            }
            parts.push(Part::Literal(rest[..literal_end].to_string()));
            rest = &rest[literal_end..];
            continue;
        }
        let end = rest
            .find('}')
            .ok_or_else(|| bad("every `{` needs a closing `}`"))?;
        let name = &rest[1..end];
        if name.is_empty() || name.contains('{') {
            return Err(bad("fields are written {name}, with a non-empty name"));
        }
        if matches!(parts.last(), Some(Part::Field(_))) {
            return Err(bad("two fields need literal text between them"));
        }
        parts.push(Part::Field(name.to_string()));
        rest = &rest[end + 1..];
    }
    Ok(parts)
}

impl FromStr for NamePattern {
    type Err = ParamError;

    /// As [`NamePattern::parse`].
    fn from_str(pattern: &str) -> Result<Self, ParamError> {
        NamePattern::parse(pattern)
    }
}

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

/// A choice of the import that is probably a mistake, found on the logs it read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImportWarning {
    /// Fewer channels than grid cells and no channel map: the channels fill the grid row by
    /// row, so cells that are neighbours on the grid need not be on the sensor.
    #[error("{channels} channels on a {rows}x{cols} grid fill it row by row and leave {} empty, so taxels that are neighbours on the grid (what the GLCM compares) need not be neighbours on the sensor; {}", cells(rows * cols - channels), grid_advice(*channels))]
    GridNotFilled {
        /// Channels imported.
        channels: usize,
        /// Grid rows.
        rows: usize,
        /// Grid columns.
        cols: usize,
    },
    /// A channel rises at every row of most logs, as a clock or a sample counter does: a
    /// time column read as a taxel.
    #[error("channel `{channel}` rises at every row in {files} of {total} logs, as a clock or a sample counter does: a time column read as a taxel; --time-column {channel} reads it as time (and --channels can leave it out)")]
    RisingChannel {
        /// The channel.
        channel: String,
        /// Logs in which it rises at every row.
        files: usize,
        /// Logs imported.
        total: usize,
    },
    /// Most recordings rest far above their range and no baseline is removed: the
    /// encoder, normalising by each recording's maximum, sees mostly the offset.
    #[error("in {files} of {total} recordings the channels rest at about {ratio:.0} times their range above zero (median channel) and no baseline is removed, so the encoder sees mostly the resting offset; --baseline min removes each channel's minimum")]
    RestingOffset {
        /// The median over those recordings of the median channel's minimum over its range.
        ratio: f64,
        /// Recordings resting that high.
        files: usize,
        /// Recordings imported.
        total: usize,
    },
}

/// "1 cell" or "n cells".
fn cells(n: usize) -> String {
    if n == 1 {
        "1 cell".to_owned()
    } else {
        format!("{n} cells")
    }
}

/// What places `channels` channels on the grid the sensor has.
pub fn grid_advice(channels: usize) -> String {
    let side = (channels as f64).sqrt().round() as usize;
    if side * side == channels {
        format!("--grid {side}x{side} (or a channel map) places them as a square sensor has them")
    } else {
        "a grid of the sensor's shape (--grid) or a channel map places them".to_string()
    }
}

/// A resting value this many times the signal's range, or more, is an offset the encoder
/// should not see: normalised by the recording's maximum, the input then spans half its
/// scale or less (FabricSlide's capacitive channels rest at 2 to 12 times their range).
pub const OFFSET_RATIO: f64 = 1.0;

/// The import's warnings on the logs it read ([`ImportWarning`]).
fn import_warnings(
    p: &CsvImportParams,
    layout: &LayoutFile,
    good: &[ParsedCsv],
) -> Vec<ImportWarning> {
    let mut out = Vec::new();
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

/// Whether `values` never fall and rise at (nearly) every step, as a clock or a sample
/// counter does: at least two steps, none falling, and at least 99 % rising (a rare equal
/// pair is a repeated reading).
pub fn clock_like(values: impl Iterator<Item = f64>) -> bool {
    let (mut rises, mut falls, mut steps, mut prev) = (0usize, 0usize, 0usize, None);
    for v in values {
        if let Some(p) = prev {
            steps += 1;
            rises += usize::from(v > p);
            falls += usize::from(v < p);
        }
        prev = Some(v);
    }
    steps >= 2 && falls == 0 && rises as f64 >= 0.99 * steps as f64
}

/// The median over a log's channels (`frames x channels`, time-major) of each channel's
/// minimum over its range; channels that never move are left out, `None` without any.
fn resting_ratio(samples: &[f64], channels: usize) -> Option<f64> {
    let mut ratios: Vec<f64> = (0..channels)
        .filter_map(|c| {
            let column = samples.iter().skip(c).step_by(channels.max(1));
            let (lo, hi) = column.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
            (hi > lo && lo > 0.0).then(|| lo / (hi - lo))
        })
        .collect();
    if ratios.is_empty() {
        return None;
    }
    ratios.sort_by(f64::total_cmp);
    Some(ratios[ratios.len() / 2])
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
            let why = format!(
                "no time column was chosen and no rate given, and column `{}` is named like time stamps: `--time-column {}` reads it as time (the rate then comes from its stamps; `--time-unit` if they are not in ms), or --fs gives the rate of logs without stamps",
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

struct ParsedCsv {
    meta: Meta,
    log: CsvLog,
}

fn invalid(path: &Path, message: impl Into<String>) -> crate::Error {
    DataError::invalid(path, message).into()
}

pub(crate) fn meta_from_name(path: &Path, pattern: Option<&NamePattern>) -> Result<Meta> {
    // A lossy name would turn distinct non-UTF-8 names (and the labels in them) into one.
    let name = match path.file_name().map(|n| n.to_str()) {
        Some(Some(name)) => name.to_string(),
        Some(None) => {
            let message = "the file name is not valid UTF-8, so neither it nor a label taken from it can be written into the manifest; rename the file";
            return Err(invalid(path, message));
        }
        None => String::new(),
    };
    let mut meta = Meta {
        file: name.clone(),
        ..Meta::default()
    };
    let Some(pattern) = pattern else {
        meta.label = Path::new(&name)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        return Ok(meta);
    };
    let fields = pattern
        .matches(&name)
        .ok_or_else(|| {
            let message = format!(
                "the file name does not match --name-pattern `{}` (text outside {{fields}} must match exactly, case included)",
                pattern.text()
            );
            invalid(path, message)
        })?;
    for (key, value) in fields {
        let number = |what: &str| -> Result<f64> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    invalid(
                        path,
                        format!("field {{{key}}} of the file name must be {what}, got `{value}`"),
                    )
                })
        };
        match key.as_str() {
            "label" => meta.label = value.clone(),
            "speed" => meta.speed_mm_s = Some(number("a number of mm/s")?),
            "force" => meta.force_n = Some(number("a number")?),
            "trial" => {
                meta.trial = Some(value.parse().map_err(|_| {
                    invalid(
                        path,
                        format!(
                            "field {{trial}} of the file name must be an integer, got `{value}`"
                        ),
                    )
                })?)
            }
            _ => {
                meta.extra.insert(key, value);
            }
        }
    }
    if meta.label.is_empty() {
        return Err(invalid(path, "the pattern gives no {label}"));
    }
    Ok(meta)
}

fn parse_csv(path: &Path, p: &CsvImportParams) -> Result<ParsedCsv> {
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

/// The files a scan of a command's inputs found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Found {
    /// The files to read, sorted.
    pub files: Vec<PathBuf>,
    /// Entries of the folders searched, named like the files wanted, that are not regular
    /// files (a pipe, a device, a link to one or to nothing), with the reason: reading a
    /// pipe blocks until something writes it, and a device may never end.
    pub left_out: Vec<(PathBuf, String)>,
}

/// The files among `inputs` with one of `extensions` (any case; folders are searched one
/// level deep, files given by name are taken whatever their extension), sorted.
///
/// # Errors
/// An input that does not exist or is not a regular file or folder, or a folder that
/// cannot be read.
fn files_with(inputs: &[PathBuf], extensions: &[&str]) -> Result<Found> {
    let wanted = |p: &Path| {
        p.extension()
            .is_some_and(|x| extensions.iter().any(|e| x.eq_ignore_ascii_case(e)))
    };
    let mut found = Found::default();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|e| DataError::io(input, e))?;
            for e in entries {
                let path = e.map_err(|e| DataError::io(input, e))?.path();
                if !wanted(&path) {
                    continue;
                }
                match crate::io::check_input(&path) {
                    Ok(()) => found.files.push(path),
                    Err(why) => found.left_out.push((path, why.to_string())),
                }
            }
        } else if std::fs::symlink_metadata(input).is_ok() {
            crate::io::check_input(input)?;
            found.files.push(input.clone());
        } else {
            return Err(invalid(input, "does not exist"));
        }
    }
    found.files.sort();
    found.left_out.sort();
    Ok(found)
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
    let mut summary = ImportSummary {
        dropped,
        ..ImportSummary::default()
    };
    let good = parse_all(files, p, on_done, &mut summary.skipped)?;
    let Some(first) = good.first() else {
        return Err(DataError::invalid(out, "every file was left out").into());
    };
    let labels: Vec<(String, String)> = good
        .iter()
        .map(|c| (c.meta.label.clone(), format!("file `{}`", c.meta.file)))
        .collect();
    if let Some(message) = labels_merged_by_trimming(&labels) {
        return Err(DataError::invalid(out, message).into());
    }
    let names = first.log.channel_names.clone();
    refuse_event_log(Path::new(&first.meta.file), &names)?;
    if let Some(other) = good.iter().find(|c| c.log.channel_names != names) {
        return Err(invalid(
            Path::new(&other.meta.file),
            format!(
                "its channels {:?} differ from {:?} of {}",
                other.log.channel_names, names, first.meta.file
            ),
        ));
    }
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
    Ok(1.0 / *median)
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
fn time_column(unit: TimeUnit) -> String {
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

/// The axes of a stacked array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum AxisName {
    N,
    T,
    Row,
    Col,
    Channel,
}

impl AxisName {
    fn name(self) -> &'static str {
        match self {
            AxisName::N => "n",
            AxisName::T => "t",
            AxisName::Row => "row",
            AxisName::Col => "col",
            AxisName::Channel => "channel",
        }
    }
}

/// The axes of a stacked array in order, such as `n,row,col,t` or `n,t,channel`: `n` and
/// `t` once each, and either `row` and `col` or `channel`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Axes(Vec<AxisName>);

impl FromStr for Axes {
    type Err = ParamError;

    /// Parses comma-separated axis names.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        parse_axes(text).map(Axes)
    }
}

impl fmt::Display for Axes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.0.iter().map(|a| a.name()).collect();
        f.write_str(&names.join(","))
    }
}

/// Parses axes such as `n,row,col,t` or `n,t,channel`.
fn parse_axes(text: &str) -> Result<Vec<AxisName>, ParamError> {
    let axes: Vec<AxisName> = text
        .split(',')
        .map(|a| match a.trim() {
            "n" => Ok(AxisName::N),
            "t" => Ok(AxisName::T),
            "row" => Ok(AxisName::Row),
            "col" => Ok(AxisName::Col),
            "channel" => Ok(AxisName::Channel),
            other => Err(ParamError::new(
                "axes",
                "axes are named n, t, row, col or channel",
                other,
            )),
        })
        .collect::<Result<_, _>>()?;
    let count = |a| axes.iter().filter(|&&x| x == a).count();
    let grid =
        count(AxisName::Row) == 1 && count(AxisName::Col) == 1 && count(AxisName::Channel) == 0;
    let chans =
        count(AxisName::Channel) == 1 && count(AxisName::Row) == 0 && count(AxisName::Col) == 0;
    if count(AxisName::N) != 1 || count(AxisName::T) != 1 || !(grid || chans) {
        return Err(ParamError::new(
            "axes",
            "axes must name n and t once each, and either row and col or channel",
            text,
        ));
    }
    Ok(axes)
}

/// Reads a `.npy` of numbers as f64 (f64, f32, or any integer type). The header is checked
/// against the file's size first, so nothing larger than the file is allocated.
fn read_numbers(path: &Path) -> Result<ArrayD<f64>> {
    let header = crate::npy::read_header(path)?;
    let descr = &header.descr;
    if !header.is_number() {
        let message = format!("not a .npy array of numbers (float or integer): dtype `{descr}`");
        return Err(invalid(path, message));
    }
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    macro_rules! try_as {
        ($($t:ty),*) => {$(
            if let Ok(a) = ArrayD::<$t>::read_npy(bytes.as_slice()) {
                return Ok(a.mapv(|v| v as f64));
            }
        )*};
    }
    try_as!(f64, f32, i64, i32, i16, i8, u64, u32, u16, u8);
    let message = format!("not a readable .npy array of numbers (dtype `{descr}`)");
    Err(invalid(path, message))
}

/// The largest whole number every float up to it holds exactly (2^53): float labels
/// beyond would turn distinct integers into one.
const EXACT_FLOAT_INTEGER: f64 = 9_007_199_254_740_992.0;

/// Labels stored as numbers, as text: integers of any width exactly as they are, floats
/// only when whole and within [`EXACT_FLOAT_INTEGER`], so that two labels never merge.
fn numeric_labels(path: &Path, descr: &str) -> Result<Vec<String>> {
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    macro_rules! integers {
        ($($t:ty),*) => {$(
            if let Ok(a) = ArrayD::<$t>::read_npy(bytes.as_slice()) {
                return Ok(a.iter().map(|v| v.to_string()).collect());
            }
        )*};
    }
    integers!(i64, u64, i32, u32, i16, u16, i8, u8);
    let floats = ArrayD::<f64>::read_npy(bytes.as_slice())
        .or_else(|_| ArrayD::<f32>::read_npy(bytes.as_slice()).map(|a| a.mapv(f64::from)));
    let Ok(a) = floats else {
        let message = format!("not a readable .npy array of numbers (dtype `{descr}`)");
        return Err(invalid(path, message));
    };
    let whole = |v: f64| v.fract() == 0.0 && v.abs() <= EXACT_FLOAT_INTEGER;
    if let Some((i, v)) = a.iter().enumerate().find(|(_, &v)| !whole(v)) {
        let message = format!(
            "label {i} is {v:?}: float labels must be whole numbers within ±2^53, which a float holds exactly (beyond, distinct labels become one); store labels as integers or strings"
        );
        return Err(invalid(path, message));
    }
    Ok(a.iter().map(|&v| format!("{}", v as i64)).collect())
}

/// Reads labels: integers, or fixed-width strings (`<U` or `|S`), one per sample.
fn read_labels(path: &Path) -> Result<Vec<String>> {
    let header = crate::npy::read_header(path)?;
    if header.is_number() {
        return numeric_labels(path, &header.descr);
    }
    let descr = &header.descr;
    let little = !descr.starts_with('>');
    if !(matches!(header.kind, 'U' | 'S') && little) {
        let message =
            format!("labels must be integers or strings (`<U` or `|S`), got dtype `{descr}`");
        return Err(invalid(path, message));
    }
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    // the header check proved the data section is exactly `elements * item_bytes` bytes
    let data = bytes.get(header.data_offset..).unwrap_or_default();
    let labels: Vec<String> = data
        .chunks_exact(header.item_bytes)
        .take(header.elements)
        .enumerate()
        .map(|(i, chunk)| {
            // Decoded strictly: replacing bad code points or bytes would merge labels.
            let label = match header.kind {
                'U' => chunk
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .take_while(|&c| c != 0)
                    .map(char::from_u32)
                    .collect::<Option<String>>(),
                _ => {
                    let end = chunk.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1);
                    std::str::from_utf8(&chunk[..end]).ok().map(String::from)
                }
            };
            label.ok_or_else(|| {
                invalid(
                    path,
                    format!("label {i} is not valid text (UTF-8 for `|S`, Unicode code points for `<U`)"),
                )
            })
        })
        .collect::<Result<_>>()?;
    if labels.iter().any(|l| l.is_empty()) {
        return Err(invalid(path, "a label is empty"));
    }
    Ok(labels)
}

/// Options of a stacked-array import.
#[derive(Debug, Clone)]
pub struct StackedParams {
    /// The data's axes, e.g. `n,row,col,t` or `n,t,channel`.
    pub axes: Axes,
    /// Sampling rate, Hz.
    pub fs: f64,
    /// With a channel axis: the grid to place channels on (row-major); default `1 x channels`.
    pub grid: Option<Grid>,
}

/// Imports `data` (`N` samples stacked along one axis) with `labels` (and optional speeds)
/// into a new dataset folder: one `.npy` (f32, `(T, rows, cols)`) per sample, the manifest
/// and `layout.toml`.
///
/// # Errors
/// Axes that do not fit the data, labels or speeds of the wrong length, bad values, or
/// `out` not empty.
pub fn import_stacked(
    data: &Path,
    labels: &Path,
    speeds: Option<&Path>,
    p: &StackedParams,
    out: &Path,
) -> Result<usize> {
    crate::values::SampleRate::new(p.fs)?;
    let (arr, (rows, cols)) = stacked_samples(data, p)?;
    let (n, t) = (arr.shape()[0], arr.shape()[1]);
    let metas = stacked_metas(data, labels, speeds, n)?;
    create_dataset_dir(out, |tmp| {
        metas
            .par_iter()
            .enumerate()
            .try_for_each(|(i, m)| -> Result<()> {
                let sample = arr.index_axis(Axis(0), i);
                let values: Vec<f32> = sample.iter().map(|&v| v as f32).collect();
                let a = ndarray::Array3::from_shape_vec((t, rows, cols), values)
                    .map_err(|e| DataError::invalid(data, e.to_string()))?;
                let path = tmp.join(&m.file);
                ndarray_npy::write_npy(&path, &a)
                    .map_err(|e| DataError::invalid(&path, e.to_string()))?;
                Ok(())
            })?;
        let layout = LayoutFile {
            fs: Some(p.fs),
            rows: Some(rows),
            cols: Some(cols),
            ..LayoutFile::default()
        };
        write_layout(tmp, &layout)?;
        write_manifest(tmp, &metas)?;
        read_back(tmp)
    })?;
    Ok(n)
}

/// Opens the dataset just written in `dir` and reads every recording back, so an import
/// never reports success for a dataset neurotex cannot read (a label, speed or grid the
/// readers refuse); the folder is not yet in place, and is removed on error.
///
/// # Errors
/// The first part that does not read back, with what the reader said.
fn read_back(dir: &Path) -> Result<()> {
    let back = |e: crate::Error| -> crate::Error {
        DataError::invalid(
            dir,
            format!("the import would write a dataset neurotex cannot read back: {e}"),
        )
        .into()
    };
    let dataset = crate::recording::Dataset::open(dir).map_err(back)?;
    (0..dataset.entries.len())
        .into_par_iter()
        .try_for_each(|i| dataset.load(i).map(drop))
        .map_err(back)
}

/// The stacked array read and checked, its axes put in the order `n, t, cells...`, and the
/// grid each sample is laid out on.
fn stacked_samples(data: &Path, p: &StackedParams) -> Result<(ArrayD<f64>, (usize, usize))> {
    let axes = &p.axes.0;
    let array = read_numbers(data)?;
    if array.ndim() != axes.len() {
        let (named, has, shape) = (axes.len(), array.ndim(), array.shape());
        let message = format!("--axes names {named} axes but the data has {has} (shape {shape:?})");
        return Err(invalid(data, message));
    }
    if let Some(pos) = array
        .iter()
        .position(|&v| !crate::values::sample_in_range(v))
    {
        let value = array.iter().nth(pos).copied().unwrap_or(f64::NAN);
        let rule = crate::values::SAMPLE_RULE;
        return Err(invalid(
            data,
            format!("value {pos} (flat index) is {value:?} ({rule})"),
        ));
    }
    let find = |a: AxisName| axes.iter().position(|&x| x == a);
    let has_grid = find(AxisName::Row).is_some();
    let wanted: &[AxisName] = if has_grid {
        &[AxisName::N, AxisName::T, AxisName::Row, AxisName::Col]
    } else {
        &[AxisName::N, AxisName::T, AxisName::Channel]
    };
    let order: Vec<usize> = wanted.iter().filter_map(|&a| find(a)).collect();
    let arr = array
        .permuted_axes(IxDyn(&order))
        .as_standard_layout()
        .into_owned();
    let shape = arr.shape().to_vec();
    let grid = if has_grid {
        if let Some(g) = &p.grid {
            let rule = "--grid places a channel axis on a grid; data with row and col axes has its grid already";
            let got = format!("{g} for axes with a {}x{} grid", shape[2], shape[3]);
            return Err(ParamError::new("grid", rule, got).into());
        }
        (shape[2], shape[3])
    } else {
        let ch = shape[2];
        match &p.grid {
            Some(g) if g.cells() == ch => (g.rows(), g.cols()),
            Some(g) => {
                let rule = "the grid must have as many cells as channels";
                let got = format!("{g} for {ch} channels");
                return Err(ParamError::new("grid", rule, got).into());
            }
            None => (1, ch),
        }
    };
    if shape[0] == 0 || shape[1] == 0 {
        let message = format!("no samples or no time steps (shape {shape:?})");
        return Err(invalid(data, message));
    }
    crate::values::check_grid_cells(grid.0, grid.1)
        .map_err(|e| invalid(data, format!("shape {shape:?}: {e}")))?;
    Ok((arr, grid))
}

/// One manifest row per stacked sample: its label, its speed (none without a speeds file),
/// and a trial number counting the samples of each label and speed.
fn stacked_metas(
    data: &Path,
    labels_path: &Path,
    speeds: Option<&Path>,
    n: usize,
) -> Result<Vec<Meta>> {
    let labels = read_labels(labels_path)?.into_iter().collect::<Vec<_>>();
    if labels.len() != n {
        let message = format!("{} labels for {n} samples", labels.len());
        return Err(DataError::invalid(data, message).into());
    }
    let written: Vec<(String, String)> = labels
        .iter()
        .enumerate()
        .map(|(i, l)| (l.clone(), format!("label {i}")))
        .collect();
    if let Some(message) = labels_merged_by_trimming(&written) {
        return Err(DataError::invalid(labels_path, message).into());
    }
    let speeds: Vec<Option<f64>> = match speeds {
        Some(path) => {
            let s = read_numbers(path)?;
            if s.len() != n {
                return Err(invalid(path, format!("{} speeds for {n} samples", s.len())));
            }
            s.iter().copied().map(Some).collect()
        }
        None => vec![None; n],
    };
    let mut trial_of: BTreeMap<(String, Option<Speed>), i64> = BTreeMap::new();
    Ok((0..n)
        .map(|i| {
            let trial = trial_of
                .entry((labels[i].clone(), speeds[i].map(Speed::of)))
                .or_insert(0);
            let meta = Meta {
                file: format!("sample_{i:05}.npy"),
                label: labels[i].clone(),
                speed_mm_s: speeds[i],
                trial: Some(*trial),
                ..Meta::default()
            };
            *trial += 1;
            meta
        })
        .collect())
}

/// What `import events` did with one file.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedFile {
    /// The file written into the dataset.
    pub file: String,
    /// Events imported.
    pub events: usize,
    /// Events that came before an earlier line's time and were moved into time order.
    pub reordered: usize,
    /// Events that share a millisecond with another of their cell and polarity.
    pub merged: usize,
    /// The recording's span from its start (by the origin) to its last event, s.
    pub span_s: f64,
    /// Its first event's time from its start, s (0 with `--origin first`).
    pub first_s: f64,
    /// Whether the log has a polarity column.
    pub polarity: bool,
}

/// Options of [`import_events`].
#[derive(Debug, Clone)]
pub struct EventImportParams {
    /// Metadata from file names; without it the label is the file stem.
    pub pattern: Option<NamePattern>,
    /// How the logs are read.
    pub format: crate::events::EventsFormat,
    /// The sensor's grid (and, for a taxel column, each taxel's cell).
    pub grid: crate::events::EventGrid,
    /// The polarity column was named (or its values given): a log without it is an error,
    /// not ON events only.
    pub require_polarity: bool,
}

/// The `.csv` and `.npy` files among `inputs` (folders are searched one level deep),
/// sorted, and those a folder holds that are not regular files, left out.
///
/// # Errors
/// As [`find_csv`].
pub fn event_files(inputs: &[PathBuf]) -> Result<Found> {
    files_with(inputs, &["csv", "npy"])
}

/// Imports event logs into a new dataset folder `out`: each file's events sorted into time
/// order (a stable sort: events of one time keep their order) and checked as a dataset's
/// reader checks them, written as `<stem>.csv` with columns `t,x,y,p` (times and
/// polarities as the log wrote them, taxel indices turned into x and y); a manifest from
/// the file names; `layout.toml` with the grid and the `[events]` table. Files are read in
/// parallel; `on_done` is called once per file.
///
/// Sorting rather than refusing: a logger that writes events from several buffers
/// interleaves them a little, and the order carries no information a stable sort loses. A
/// dataset's reader, in contrast, refuses events out of order, so a dataset is always in
/// the order every command reads.
///
/// # Errors
/// A file that cannot be read or breaks a rule (named with its line), two files of one
/// stem, or `out` not empty.
pub fn import_events(
    files: &[std::path::PathBuf],
    p: &EventImportParams,
    out: &Path,
    on_done: &(dyn Fn() + Sync),
) -> Result<Vec<ImportedFile>> {
    use rayon::prelude::*;
    if files.is_empty() {
        return Err(DataError::invalid(out, "no .csv or .npy event files to import").into());
    }
    let mut stems = std::collections::BTreeMap::new();
    for f in files {
        let stem = f.file_stem().map(|s| s.to_string_lossy().into_owned());
        if let Some(first) = stems.insert(stem.clone(), f) {
            let why = format!(
                "`{}` and `{}` would both be {}.csv in the dataset; rename one",
                first.display(),
                f.display(),
                stem.unwrap_or_default()
            );
            return Err(DataError::invalid(f, why).into());
        }
    }
    crate::recording::create_dataset_dir(out, |dir| {
        // Each log is written as soon as it is read: an import holds one log per thread.
        let read: Vec<(crate::recording::Meta, ImportedFile)> = files
            .par_iter()
            .map(|f| {
                let meta = meta_from_name(f, p.pattern.as_ref())?;
                let (text, summary) = sorted_log(f, p)?;
                let path = dir.join(&summary.file);
                std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
                on_done();
                let meta = crate::recording::Meta {
                    file: summary.file.clone(),
                    ..meta
                };
                Ok((meta, summary))
            })
            .collect::<Result<_>>()?;
        // `read` is in the order of `files`.
        let with = read.iter().zip(files).find(|(r, _)| r.1.polarity);
        let without = read.iter().zip(files).find(|(r, _)| !r.1.polarity);
        if let (Some((_, with)), Some((_, without))) = (with, without) {
            let why = format!(
                "has no polarity column `{}`, which {} has: its OFF events would be read as ON",
                p.format.polarity,
                with.display()
            );
            return Err(DataError::invalid(without, why).into());
        }
        let (metas, summaries): (Vec<_>, Vec<_>) = read.into_iter().unzip();
        crate::recording::write_manifest(dir, &metas)?;
        crate::recording::write_layout(dir, &imported_layout(p))?;
        crate::recording::Dataset::open(dir)?;
        Ok(summaries)
    })
}

/// The layout an import writes: the grid, its mask, the columns it writes, and for logs
/// addressed by taxel index the channel map (a stream of the same sensor's taxel indices
/// reads it, `neurotex stream --taxel`).
fn imported_layout(p: &EventImportParams) -> crate::recording::LayoutFile {
    let g = &p.grid;
    let masked = g.present.iter().any(|&x| !x);
    crate::recording::LayoutFile {
        rows: Some(g.rows),
        cols: Some(g.cols),
        mask: masked.then(|| {
            g.present
                .chunks(g.cols)
                .map(|row| row.iter().map(|&x| if x { '1' } else { '0' }).collect())
                .collect()
        }),
        channel_map: p.format.taxel.as_ref().map(|_| {
            g.taxels
                .iter()
                .map(|&cell| [cell / g.cols, cell % g.cols])
                .collect()
        }),
        events: Some(crate::events::EventsFormat {
            values: p.format.values,
            origin: p.format.origin,
            ..crate::events::EventsFormat::new(p.format.time_unit)
        }),
        ..Default::default()
    }
}

/// Column names that say an event's polarity, refused when left unread.
const POLARITY_NAMES: [&str; 9] = [
    "p",
    "pol",
    "polarity",
    "sign",
    "on",
    "onoff",
    "on_off",
    "parity",
    "ev_polarity",
];

/// An event as parsed: time, cell fields, polarity, and its line or record.
type RawEvent = (crate::events::Stamp, (i64, i64), Option<i64>, usize);

/// Checks that a log's polarity is read when it has one: the column named (or its values
/// given) is there, and no unread column is named like a polarity, which would leave
/// every OFF event ON, silently.
fn polarity_read(
    p: &EventImportParams,
    polarity: bool,
    unread: &[String],
) -> std::result::Result<(), String> {
    if p.require_polarity && !polarity {
        return Err(format!(
            "no polarity column `{}`, which --polarity or --polarity-values asks for",
            p.format.polarity
        ));
    }
    let polarity_like = |name: &str| POLARITY_NAMES.contains(&name.to_ascii_lowercase().as_str());
    match unread.iter().find(|n| !polarity && polarity_like(n)) {
        Some(name) => Err(format!(
            "column `{name}` is not read, and its name says polarity: name it with --polarity {name} (and --polarity-values ON,OFF unless they are 1,0), or the log's OFF events would be read as ON"
        )),
        None => Ok(()),
    }
}

/// Sorts `events` into time order, stably (events of one time keep the log's order); the
/// events that came before an earlier line's time.
fn sort_stably(events: &mut [RawEvent]) -> usize {
    let key = |t: &crate::events::Stamp| crate::events::as_f64(*t);
    let mut reordered = 0;
    let mut latest = f64::NEG_INFINITY;
    for (t, ..) in events.iter() {
        let v = key(t);
        if v < latest {
            reordered += 1;
        }
        latest = latest.max(v);
    }
    if reordered > 0 {
        events.sort_by(|a, b| match (a.0, b.0) {
            (crate::events::Stamp::Int(x), crate::events::Stamp::Int(y)) => x.cmp(&y),
            (x, y) => key(&x).total_cmp(&key(&y)),
        });
    }
    reordered
}

/// One log's events in time order as the CSV text an import writes, and what was done.
fn sorted_log(path: &Path, p: &EventImportParams) -> Result<(String, ImportedFile)> {
    let mut events: Vec<RawEvent> = Vec::new();
    let mut polarity = false;
    let mut unread = Vec::new();
    crate::events::parse(path, &p.format, &mut |event| {
        match event {
            crate::events::Parsed::Columns {
                polarity: has,
                unread: other,
            } => (polarity, unread) = (has, other),
            crate::events::Parsed::Event { t, cell, p, at } => events.push((t, cell, p, at)),
        }
        Ok(())
    })?;
    let bad = |why: String| -> crate::Error { DataError::invalid(path, why).into() };
    polarity_read(p, polarity, &unread).map_err(bad)?;
    if events.is_empty() {
        return Err(bad(
            "holds no events (a header only, or an empty array)".into()
        ));
    }
    let reordered = sort_stably(&mut events);
    let max_steps = (crate::recording::DEFAULT_MAX_DURATION_S * 1000.0) as u64;
    let mut gather = crate::events::Gather::new(&p.format, &p.grid, polarity, None, max_steps);
    let name = format!(
        "{}.csv",
        path.file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned())
    );
    let mut text = String::from(if polarity { "t,x,y,p\n" } else { "t,x,y\n" });
    for &(t, cell, pol, at) in &events {
        let named = |m: String| -> crate::Error {
            DataError::invalid(path, format!("{}: {m}", crate::events::place(path, at))).into()
        };
        gather.push(t, cell, pol).map_err(named)?;
        let c = gather.cell(cell).map_err(named)?;
        use std::fmt::Write as _;
        let _ = write!(
            text,
            "{},{},{}",
            crate::events::show(t),
            c % p.grid.cols,
            c / p.grid.cols
        );
        let _ = match pol {
            Some(v) => writeln!(text, ",{v}"),
            None => writeln!(text),
        };
    }
    let done = gather.finish();
    Ok((
        text,
        ImportedFile {
            file: name,
            events: done.count,
            reordered,
            merged: done.merged,
            span_s: done.n_steps as f64 / 1000.0,
            first_s: done
                .on
                .iter()
                .chain(done.off.iter().flatten())
                .filter_map(|train| train.first())
                .min()
                .map_or(0.0, |&step| f64::from(step) / 1000.0),
            polarity,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_back_refuses_a_dataset_the_readers_refuse() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.csv"), "t_ms,c\n0,1\n1,2\n").unwrap();
        std::fs::write(dir.path().join("manifest.csv"), "file,label\na.csv,x\n").unwrap();
        read_back(dir.path()).unwrap();
        // A recording whose samples the reader refuses (a NaN).
        std::fs::write(dir.path().join("a.csv"), "t_ms,c\n0,1\n1,NaN\n").unwrap();
        let err = read_back(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("cannot read back") && err.contains("a.csv"),
            "{err}"
        );
    }
}
