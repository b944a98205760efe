//! Reading CSV logs as lab loggers write them: with or without a header row, columns by
//! name or by 0-based index, `,` `;` or tab between fields (detected when not given), and
//! time stamps that a host may repeat. One [`CsvFormat`] describes a file; `import csv`,
//! `encode` and the dataset reader all read through [`read_csv_log`], so they cannot drift.

use std::fmt;
use std::io::Read;
use std::path::Path;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::{DataError, ParamError, Result};
use crate::values::TimeUnit;

/// One column of a CSV log: by its header name, or by its 0-based position.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Column {
    /// The column whose header is this name.
    Name(String),
    /// The column at this 0-based position.
    Index(usize),
}

impl FromStr for Column {
    type Err = ParamError;

    /// Digits are a 0-based index, anything else a header name.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let text = text.trim();
        if text.is_empty() {
            return Err(ParamError::new("time-column", "a name or index", "nothing"));
        }
        Ok(match text.parse::<usize>() {
            Ok(i) if text.bytes().all(|b| b.is_ascii_digit()) => Column::Index(i),
            _ => Column::Name(text.to_string()),
        })
    }
}

impl fmt::Display for Column {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Column::Name(name) => f.write_str(name),
            Column::Index(i) => write!(f, "{i}"),
        }
    }
}

/// How to pick the channel columns of a CSV log.
#[derive(Debug, Clone)]
pub enum ChannelSelect {
    /// Every column but the time column.
    All,
    /// These columns by header name, in this order.
    Names(Vec<String>),
    /// These columns by 0-based position, in this order.
    Indices(Vec<usize>),
    /// Columns whose header names match, in file order.
    Regex(regex::Regex),
}

impl ChannelSelect {
    /// A regular expression when the text holds one of `^$*+?[]()|\`; else a comma-separated
    /// list: of 0-based indices and ranges (`0-8`, `2,4-7`, both ends included) when every
    /// entry is one, of header names otherwise.
    ///
    /// # Errors
    /// An invalid regular expression, or a range whose end is before its start.
    pub fn parse(text: &str) -> Result<Self, ParamError> {
        if text.chars().any(|c| "^$*+?[]()|\\".contains(c)) {
            return regex::Regex::new(text)
                .map(ChannelSelect::Regex)
                .map_err(|e| {
                    ParamError::new(
                        "channels",
                        "not a valid regular expression",
                        format!("{text} ({e})"),
                    )
                });
        }
        let entries: Vec<&str> = text
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect();
        if entries.is_empty() {
            return Err(ParamError::new(
                "channels",
                "name at least one column",
                text,
            ));
        }
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        let is_index = |e: &&str| match e.split_once('-') {
            Some((a, b)) => digits(a.trim()) && digits(b.trim()),
            None => digits(e),
        };
        if !entries.iter().all(is_index) {
            return Ok(ChannelSelect::Names(
                entries.iter().map(|s| s.to_string()).collect(),
            ));
        }
        let mut indices = Vec::new();
        for entry in entries {
            let number = |s: &str| {
                s.trim().parse::<usize>().map_err(|_| {
                    ParamError::new("channels", "indices must be small integers", entry)
                })
            };
            let (a, b) = match entry.split_once('-') {
                Some((a, b)) => (number(a)?, number(b)?),
                None => (number(entry)?, number(entry)?),
            };
            if b < a {
                let rule = "a range is FIRST-LAST with FIRST <= LAST";
                return Err(ParamError::new("channels", rule, entry));
            }
            if b - a >= MAX_COLUMNS || indices.len() + (b - a) >= MAX_COLUMNS {
                let rule = "at most 65536 channel columns";
                return Err(ParamError::new("channels", rule, entry));
            }
            indices.extend(a..=b);
        }
        Ok(ChannelSelect::Indices(indices))
    }
}

/// The most channel columns a selection may name (a bound on what a typo such as `0-99999999`
/// may allocate).
const MAX_COLUMNS: usize = 65_536;

impl FromStr for ChannelSelect {
    type Err = ParamError;

    /// As [`ChannelSelect::parse`].
    fn from_str(text: &str) -> Result<Self, ParamError> {
        ChannelSelect::parse(text)
    }
}

/// The byte between fields: written `,`, `;` or `tab` (also `\t` or a tab itself).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Delimiter(u8);

impl Delimiter {
    /// The byte.
    pub fn byte(self) -> u8 {
        self.0
    }
}

impl FromStr for Delimiter {
    type Err = ParamError;

    /// `,`, `;`, `tab`, `\t` or a tab character.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        match text {
            "," | "comma" => Ok(Delimiter(b',')),
            ";" | "semicolon" => Ok(Delimiter(b';')),
            "tab" | "\\t" | "\t" => Ok(Delimiter(b'\t')),
            other => Err(ParamError::new(
                "delimiter",
                "the delimiter is `,`, `;` or `tab`",
                other,
            )),
        }
    }
}

impl fmt::Display for Delimiter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            b'\t' => f.write_str("tab"),
            b => write!(f, "{}", b as char),
        }
    }
}

impl Serialize for Delimiter {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl<'de> Deserialize<'de> for Delimiter {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// What to do with rows that share one time stamp (a host stamping a buffer it read).
/// Rows equal in the time stamp and every selected channel are exact duplicates: they are
/// dropped under every choice, `error` included.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DuplicateStamps {
    /// One frame, the mean of the rows.
    #[default]
    Average,
    /// One frame, the first row.
    First,
    /// One frame, the last row.
    Last,
    /// An error naming the line.
    Error,
}

impl FromStr for DuplicateStamps {
    type Err = ParamError;

    /// `average`, `first`, `last` or `error`.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        match text {
            "average" => Ok(DuplicateStamps::Average),
            "first" => Ok(DuplicateStamps::First),
            "last" => Ok(DuplicateStamps::Last),
            "error" => Ok(DuplicateStamps::Error),
            other => Err(ParamError::new(
                "duplicate-stamps",
                "one of `average`, `first`, `last` or `error`",
                other,
            )),
        }
    }
}

impl fmt::Display for DuplicateStamps {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DuplicateStamps::Average => "average",
            DuplicateStamps::First => "first",
            DuplicateStamps::Last => "last",
            DuplicateStamps::Error => "error",
        })
    }
}

/// How a CSV log is laid out.
#[derive(Debug, Clone)]
pub struct CsvFormat {
    /// Whether the first row names the columns; without it, columns go by 0-based index.
    pub header: bool,
    /// The byte between fields; detected from the first lines when `None`.
    pub delimiter: Option<Delimiter>,
    /// The time-stamp column; none means the rows are evenly spaced at a known rate.
    pub time_column: Option<Column>,
    /// The unit of the time column.
    pub time_unit: TimeUnit,
    /// Whether `time_unit` was given (an option, `layout.toml`): when not, a unit named in
    /// the time column's name (`t_s`, `stamp_us`, `time (ms)`) is taken instead, and with
    /// none there, stamps implying an implausible rate are refused ([`PLAUSIBLE_HZ`]).
    pub unit_given: bool,
    /// With a header row and no `time_column`: take a column named `t_ms` or `time_ms` (in
    /// ms), or `t_s` or `time_s` (in s), as the time column when there is one.
    pub detect_time: bool,
    /// The channel columns.
    pub channels: ChannelSelect,
    /// Rows that share a time stamp.
    pub duplicate_stamps: DuplicateStamps,
    /// The longest gap between two time stamps, in s, that resampling may fill by
    /// interpolation (default [`DEFAULT_MAX_GAP_S`]); a longer one is an error.
    pub max_gap_s: f64,
}

/// The longest gap between time stamps read by default, in s: the live stream's default
/// too. A logger that stopped for minutes would otherwise have the pause filled with a
/// straight line, and recordings with different data could give identical features.
pub const DEFAULT_MAX_GAP_S: f64 = 1.0;

impl Default for CsvFormat {
    /// A header row, detected delimiter, no time column (none detected), every column,
    /// `average`.
    fn default() -> Self {
        CsvFormat {
            header: true,
            delimiter: None,
            time_column: None,
            time_unit: TimeUnit::Milliseconds,
            unit_given: false,
            detect_time: false,
            channels: ChannelSelect::All,
            duplicate_stamps: DuplicateStamps::Average,
            max_gap_s: DEFAULT_MAX_GAP_S,
        }
    }
}

/// How a CSV log's columns are written down in `layout.toml` and in model files: the
/// reading options as text, `time_column` and `channels` by header name, or by 0-based
/// index (`"0"`) without a header row. A dataset's files are read with its layout's; an
/// imported dataset also keeps its raw logs' as `[source]`, so that a raw log of the same
/// logger reads as the import read it ([`choose_format`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogColumns {
    /// Whether the first row names the columns (default `true`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub header: Option<bool>,
    /// The field delimiter, `,` `;` or `tab` (default: detected).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delimiter: Option<Delimiter>,
    /// The time column's name (index without a header).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_column: Option<String>,
    /// The time column's unit, `ms`, `s` or `us`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_unit: Option<TimeUnit>,
    /// The channel columns, in channel order (default: every other column).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channels: Option<Vec<String>>,
    /// Rows sharing a time stamp (default `average`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duplicate_stamps: Option<DuplicateStamps>,
}

impl LogColumns {
    /// The format these columns describe; with a header and no `time_column`, a column
    /// named `t_ms` or `time_ms` (ms), or `t_s` or `time_s` (s), is the time column.
    /// `max_gap_s` is the largest gap resampling may fill (default [`DEFAULT_MAX_GAP_S`]).
    ///
    /// # Errors
    /// Without a header row, a time column or channel that is not an index.
    pub fn csv_format(&self, max_gap_s: Option<f64>) -> Result<CsvFormat, ParamError> {
        let header = self.header.unwrap_or(true);
        let column = |text: &str| -> Result<Column, ParamError> {
            let col: Column = text.parse()?;
            match col {
                Column::Name(_) if !header => Err(ParamError::new(
                    "layout.toml",
                    "without a header row (header = false) columns are 0-based indices",
                    text,
                )),
                col => Ok(col),
            }
        };
        let channels = match &self.channels {
            None => ChannelSelect::All,
            Some(names) if header => ChannelSelect::Names(names.clone()),
            Some(names) => ChannelSelect::Indices(
                names
                    .iter()
                    .map(|n| match column(n)? {
                        Column::Index(i) => Ok(i),
                        Column::Name(_) => unreachable!("names are refused above"),
                    })
                    .collect::<Result<_, _>>()?,
            ),
        };
        Ok(CsvFormat {
            header,
            delimiter: self.delimiter,
            time_column: self.time_column.as_deref().map(column).transpose()?,
            time_unit: self.time_unit.unwrap_or_default(),
            unit_given: self.time_unit.is_some(),
            detect_time: header && self.time_column.is_none(),
            channels,
            duplicate_stamps: self.duplicate_stamps.unwrap_or_default(),
            max_gap_s: max_gap_s.unwrap_or(DEFAULT_MAX_GAP_S),
        })
    }
}

/// The CSV reading options a command line or a caller gives, each in place of the layout's
/// setting when given: how `encode`, `predict`, `stream` and `import csv` take them alike.
#[derive(Debug, Clone, Default)]
pub struct CsvOverrides {
    /// The file has no header row.
    pub no_header: bool,
    /// The field delimiter.
    pub delimiter: Option<Delimiter>,
    /// The time-stamp column.
    pub time_column: Option<Column>,
    /// The time column's unit.
    pub time_unit: Option<TimeUnit>,
    /// The channel columns.
    pub channels: Option<ChannelSelect>,
    /// Rows sharing one time stamp.
    pub duplicate_stamps: Option<DuplicateStamps>,
    /// The longest gap resampling may fill, s.
    pub max_gap_s: Option<f64>,
}

impl CsvOverrides {
    /// Whether any option that says where the columns are was given: then it is the
    /// caller's format that is read, not one remembered from a layout or a model.
    pub fn place_columns(&self) -> bool {
        self.no_header || self.time_column.is_some() || self.channels.is_some()
    }

    /// `base` with every given option in place of its setting.
    pub fn apply(&self, mut base: CsvFormat) -> CsvFormat {
        if self.no_header {
            base.header = false;
            base.detect_time = false;
        }
        if let Some(d) = self.delimiter {
            base.delimiter = Some(d);
        }
        if let Some(col) = &self.time_column {
            // Another time column than the layout's: its unit is its own (a `_s` in its
            // name, else the rate check), not the one the layout gave for its column.
            if base.time_column.as_ref() != Some(col) {
                base.time_unit = TimeUnit::default();
                base.unit_given = false;
            }
            base.time_column = Some(col.clone());
            base.detect_time = false;
        }
        if let Some(unit) = self.time_unit {
            base.time_unit = unit;
            base.unit_given = true;
        }
        if let Some(channels) = &self.channels {
            base.channels = channels.clone();
        }
        if let Some(policy) = self.duplicate_stamps {
            base.duplicate_stamps = policy;
        }
        if let Some(gap) = self.max_gap_s {
            base.max_gap_s = gap;
        }
        base
    }
}

/// Of `formats` (candidates in order of preference), the one to read the CSV log at `path`
/// with: the first under which its first line has every column and `fits` the columns
/// found; with one candidate, that one.
///
/// # Errors
/// The file's first line cannot be read, or no candidate fits: the first candidate's
/// reason, and each other's.
pub fn choose_format(
    path: &Path,
    formats: &[CsvFormat],
    fits: &dyn Fn(&Columns) -> std::result::Result<(), String>,
) -> Result<CsvFormat> {
    if let [only] = formats {
        return Ok(only.clone());
    }
    choose_columns(path, formats, &|f| first_line_names(path, f), fits)
        .map(|(i, _)| formats[i].clone())
}

/// Of `formats`, the index of the first under which the first line's fields (`names`
/// gives them as that format splits them) hold every column and `fits` the columns, with
/// those columns.
///
/// # Errors
/// `names` fails, or no candidate fits: the reasons of each.
pub fn choose_columns(
    path: &Path,
    formats: &[CsvFormat],
    names: &dyn Fn(&CsvFormat) -> Result<Vec<String>>,
    fits: &dyn Fn(&Columns) -> std::result::Result<(), String>,
) -> Result<(usize, Columns)> {
    let mut reasons = Vec::new();
    for (i, format) in formats.iter().enumerate() {
        let found = Columns::find(path, format, names(format)?);
        match found
            .map_err(|e| reason_of(path, e))
            .and_then(|c| fits(&c).map(|()| c))
        {
            Ok(columns) => return Ok((i, columns)),
            Err(why) if !reasons.contains(&why) => reasons.push(why),
            Err(_) => {}
        }
    }
    let message = match reasons.as_slice() {
        [one] => one.clone(),
        [own, others @ ..] => format!(
            "{own}; nor read another way it may be written ({}); name its columns with --time-column and --channels (or --no-header), or give a --layout",
            others.join("; ")
        ),
        [] => "no format to read it with".to_string(),
    };
    Err(invalid(path, message))
}

/// An error's message without the file's name, which the caller adds once.
fn reason_of(path: &Path, e: crate::Error) -> String {
    match e {
        crate::Error::Data(DataError::Invalid { path: p, message }) if p == path => message,
        other => other.to_string(),
    }
}

/// The first line's fields as `format` splits them: header names, or `column{index}`
/// without a header.
fn first_line_names(path: &Path, format: &CsvFormat) -> Result<Vec<String>> {
    open_log(path, format).map(|(_, _, names)| names)
}

/// A log file as its reader reads it: a regular file, a line at a time up to the limit.
type LogFile = crate::io::LineBounded<std::fs::File>;

/// A reader of the log at `path` as `format` says, past its first line: the reader, the
/// delimiter (given or detected) and the first line's fields as column names (header
/// names, or `column{index}` without a header, the first line then still to be read).
fn open_log(
    path: &Path,
    format: &CsvFormat,
) -> Result<(csv::Reader<LogFile>, Delimiter, Vec<String>)> {
    let delimiter = match format.delimiter {
        Some(d) => d,
        None => detect_delimiter(path)?,
    };
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(delimiter.byte())
        .has_headers(format.header)
        .trim(csv::Trim::All)
        .from_reader(crate::io::open_text(path)?);
    let first = reader.headers().map_err(|e| csv_error(path, e))?;
    let names = match format.header {
        true => first.iter().map(str::to_string).collect(),
        false => (0..first.len()).map(|j| format!("column{j}")).collect(),
    };
    Ok((reader, delimiter, names))
}

/// A CSV log read: its frames and what was done to its rows.
#[derive(Debug, Clone)]
pub struct CsvLog {
    /// The selected channels' names: header names, or `column{index}` without a header.
    pub channel_names: Vec<String>,
    /// Frames, time-major: `frames x channels`.
    pub samples: Vec<f64>,
    /// One time stamp per frame in the file's own unit, strictly increasing.
    pub times: Option<Vec<f64>>,
    /// The unit of `times`.
    pub time_unit: TimeUnit,
    /// Rows folded into another row's frame because they share its time stamp (exact
    /// duplicates not counted).
    pub merged_rows: usize,
    /// Exact duplicate rows dropped.
    pub duplicate_rows: usize,
    /// The delimiter used (given or detected).
    pub delimiter: Delimiter,
    /// How the log was read, resolved: the delimiter found, the time column and channels
    /// by name (by index without a header), the time unit: what reads the same logger's
    /// logs again.
    pub columns: LogColumns,
}

fn invalid(path: &Path, message: impl Into<String>) -> crate::Error {
    DataError::invalid(path, message).into()
}

/// Guesses a file's delimiter from its first lines ([`detect_delimiter_in`]).
fn detect_delimiter(path: &Path) -> Result<Delimiter> {
    let mut head = Vec::with_capacity(16 * 1024);
    crate::io::open_input(path)?
        .take(16 * 1024)
        .read_to_end(&mut head)
        .map_err(|e| DataError::io(path, e))?;
    let text = String::from_utf8_lossy(&head);
    let mut lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    if head.len() == 16 * 1024 && lines.len() > 1 {
        lines.pop(); // probably cut short
    }
    lines.truncate(10);
    Ok(detect_delimiter_in(&lines))
}

/// The column names of a log's header row, from its first 16 KiB; `None` when the file
/// cannot be read, has no header row by `format`, or its first line is longer.
pub fn header_names(path: &Path, format: &CsvFormat) -> Option<Vec<String>> {
    // Never opened unless a regular file: a FIFO would block the open.
    if !format.header || !std::fs::metadata(path).ok()?.is_file() {
        return None;
    }
    let mut head = Vec::with_capacity(16 * 1024);
    std::fs::File::open(path)
        .and_then(|f| f.take(16 * 1024).read_to_end(&mut head))
        .ok()?;
    let text = String::from_utf8_lossy(&head);
    let first = text.lines().find(|l| !l.trim().is_empty())?;
    if head.len() == 16 * 1024 && !text.contains('\n') {
        return None;
    }
    let delimiter = format
        .delimiter
        .unwrap_or_else(|| detect_delimiter_in(&[first]))
        .byte() as char;
    let unquote = |f: &str| f.trim().trim_matches('"').trim().to_string();
    Some(first.split(delimiter).map(unquote).collect())
}

/// Guesses the delimiter from the first lines of a log (a file's first ten, or a stream's
/// first): among `,` `;` and tab, the one found the same non-zero number of times on each
/// line, the most frequent such one (tab, then `;`, then `,` on a tie: `;` files often
/// carry decimal commas); `,` when none is.
pub fn detect_delimiter_in(lines: &[&str]) -> Delimiter {
    let mut best: Option<(usize, u8)> = None;
    for candidate in [b'\t', b';', b','] {
        let counts: Vec<usize> = lines
            .iter()
            .map(|l| l.bytes().filter(|&b| b == candidate).count())
            .collect();
        let Some(&n) = counts.first() else { continue };
        if n > 0 && counts.iter().all(|&c| c == n) && best.is_none_or(|(m, _)| n > m) {
            best = Some((n, candidate));
        }
    }
    Delimiter(best.map_or(b',', |(_, b)| b))
}

/// Where the time and channel columns of a log are, and the columns' names.
#[derive(Debug, Clone)]
pub struct Columns {
    /// Every column's name: header names, or `column{index}` without a header.
    pub names: Vec<String>,
    /// The time column's index, if any.
    pub time: Option<usize>,
    /// The time column's unit.
    pub unit: TimeUnit,
    /// Whether the unit was given or named in the time column's name, rather than assumed.
    pub unit_known: bool,
    /// The channel columns' indices, in channel order.
    pub channels: Vec<usize>,
}

/// Where column `col` is among `names`; `what` says which role it plays in errors.
fn resolve_column(
    path: &Path,
    what: &str,
    col: &Column,
    names: &[String],
    header: bool,
) -> Result<usize> {
    match col {
        Column::Index(i) if *i < names.len() => Ok(*i),
        Column::Index(i) => Err(invalid(
            path,
            format!(
                "{what} {i} (0-based) does not exist: line 1 has {} columns",
                names.len()
            ),
        )),
        Column::Name(name) if !header => Err(invalid(
            path,
            format!("without a header row the {what} goes by 0-based index, got `{name}`"),
        )),
        Column::Name(name) => names.iter().position(|h| h == name).ok_or_else(|| {
            invalid(
                path,
                format!(
                    "missing {what} `{}` (columns: {})",
                    excerpt(name),
                    excerpt(&names.join(", "))
                ),
            )
        }),
    }
}

impl Columns {
    /// Finds `format`'s time and channel columns among `names` (the header's, or
    /// `column{index}` without one); `path` names the source in errors.
    ///
    /// # Errors
    /// A missing column, a name without a header row, the time column among the channels,
    /// or no channel selected.
    pub fn find(path: &Path, format: &CsvFormat, names: Vec<String>) -> Result<Self> {
        let (time, unit) = match &format.time_column {
            Some(col) => (
                Some(resolve_column(
                    path,
                    "time column",
                    col,
                    &names,
                    format.header,
                )?),
                format.time_unit,
            ),
            None if format.detect_time && format.header => detect_time_column(&names),
            None => (None, format.time_unit),
        };
        let named = time
            .filter(|_| format.header)
            .and_then(|t| unit_in_name(&names[t]));
        let (unit, unit_known) = match named {
            Some(named) if !format.unit_given => (named, true),
            _ => (unit, format.unit_given || named.is_some()),
        };
        // A header ending in a delimiter (`a,b,`), as some loggers write every line, has
        // an empty last name: not a channel.
        let trailing = format.header && names.last().is_some_and(String::is_empty);
        let last = names.len() - 1;
        let channels: Vec<usize> = match &format.channels {
            ChannelSelect::All => (0..names.len())
                .filter(|&j| Some(j) != time && !(trailing && j == last))
                .collect(),
            ChannelSelect::Names(list) => list
                .iter()
                .map(|n| {
                    let col = Column::Name(n.clone());
                    resolve_column(path, "channel column", &col, &names, format.header)
                })
                .collect::<Result<_>>()?,
            ChannelSelect::Indices(list) => list
                .iter()
                .map(|&i| {
                    let col = Column::Index(i);
                    resolve_column(path, "channel column", &col, &names, format.header)
                })
                .collect::<Result<_>>()?,
            ChannelSelect::Regex(_) if !format.header => {
                let message = "without a header row --channels takes indices such as 2-17, not a regular expression";
                return Err(invalid(path, message));
            }
            ChannelSelect::Regex(re) => (0..names.len())
                .filter(|&j| Some(j) != time && re.is_match(&names[j]))
                .collect(),
        };
        if let Some(t) = time.filter(|t| channels.contains(t)) {
            let message = format!("column `{}` is both the time and a channel", names[t]);
            return Err(invalid(path, message));
        }
        if channels.is_empty() {
            return Err(invalid(path, "no channel columns selected"));
        }
        if format.header {
            unique_names(path, &names, time.iter().chain(&channels))?;
        }
        Ok(Columns {
            names,
            time,
            unit,
            unit_known,
            channels,
        })
    }
}

/// The columns used must have distinct names: a layout, a model and the import's map
/// find channels by name, and a repeated name would send them all to its first column.
fn unique_names<'a>(
    path: &Path,
    names: &[String],
    used: impl Iterator<Item = &'a usize>,
) -> Result<()> {
    let why = "layouts, models and imported datasets find channels by name";
    match repeated_name(names, used.copied(), why) {
        Some(message) => Err(invalid(path, message)),
        None => Ok(()),
    }
}

/// The message refusing two of the columns `used` (indices into a header's `names`) that
/// share one name, `why` saying what finds columns by name; `None` when they are distinct.
/// Every table neurotex reads by column name refuses a repeated name with it: a reader
/// finds the first column of a name, and the other's values would be silently unread.
pub(crate) fn repeated_name<S: AsRef<str>>(
    names: &[S],
    used: impl Iterator<Item = usize>,
    why: &str,
) -> Option<String> {
    let mut first: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for j in used {
        let name = names[j].as_ref();
        if let Some(&i) = first.get(name) {
            let (i, j) = (i.min(j), i.max(j));
            return Some(format!(
                "columns {} and {} of line 1 are both named `{}`: each column read needs a \
                 name of its own ({why}), so rename them in the header row",
                i + 1,
                j + 1,
                excerpt(name)
            ));
        }
        first.insert(name, j);
    }
    None
}

/// `text`, cut to its first 60 characters (with `...`) so that an error never echoes a
/// huge field whole.
pub(crate) fn excerpt(text: &str) -> std::borrow::Cow<'_, str> {
    const MAX: usize = 60;
    match text.char_indices().nth(MAX) {
        None => text.into(),
        Some((end, _)) => format!("{}...", &text[..end]).into(),
    }
}

/// The unit a time column's name ends in: `_ms`, `_s`, `_us` (or `-`, a space, `(ms)`,
/// `[s]`), in any case.
fn unit_in_name(name: &str) -> Option<TimeUnit> {
    let name = name.trim().to_lowercase();
    let name = name.trim_end_matches([')', ']']);
    [
        ("ms", TimeUnit::Milliseconds),
        ("us", TimeUnit::Microseconds),
        ("µs", TimeUnit::Microseconds),
        ("s", TimeUnit::Seconds),
    ]
    .into_iter()
    .find(|(suffix, _)| {
        name.strip_suffix(suffix)
            .is_some_and(|rest| rest.ends_with(['_', '-', ' ', '(', '[']))
    })
    .map(|(_, unit)| unit)
}

/// Sampling rates a tactile log plausibly has, in Hz: stamps whose median step implies a
/// rate outside are most likely in another unit than assumed (seconds read as ms give
/// 1000 times the rate), so without a unit given or named they are refused.
pub const PLAUSIBLE_HZ: (f64, f64) = (0.1, 20_000.0);

/// Refuses stamps whose unit was only assumed when their median step implies a rate
/// outside [`PLAUSIBLE_HZ`].
fn check_plausible_rate(path: &Path, columns: &Columns, times: &[f64]) -> Result<()> {
    let (Some(t), false) = (columns.time, columns.unit_known) else {
        return Ok(());
    };
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return Ok(());
    }
    let mid = steps.len() / 2;
    let (_, &mut median, _) = steps.select_nth_unstable_by(mid, f64::total_cmp);
    let hz = 1.0 / (median * columns.unit.seconds());
    if (PLAUSIBLE_HZ.0..=PLAUSIBLE_HZ.1).contains(&hz) {
        return Ok(());
    }
    let median = format!("{median:.6}");
    let median = median.trim_end_matches('0').trim_end_matches('.');
    let message = format!(
        "time column `{}` steps by a median {median} {unit}, which is {hz:.1} Hz if its \
         stamps are in {unit}; a tactile log at that rate is unlikely, so the unit is \
         probably another: say it with --time-unit ms, s or us (`time_unit` in layout.toml), \
         or end the column's name in `_ms`, `_s` or `_us`",
        excerpt(&columns.names[t]),
        unit = columns.unit,
    );
    Err(invalid(path, message))
}

/// Refuses a gap between consecutive time stamps longer than `max_gap_s`.
fn check_gaps(path: &Path, log: &CsvLog, max_gap_s: f64) -> Result<()> {
    let Some(times) = &log.times else {
        return Ok(());
    };
    let scale = log.time_unit.seconds();
    let Some(i) = times
        .windows(2)
        .position(|w| (w[1] - w[0]) * scale > max_gap_s)
    else {
        return Ok(());
    };
    let message = format!(
        "time stamps jump by {} s between frames {} and {} (stamps {} and {} {}), beyond the \
         {max_gap_s} s that resampling may fill by interpolation: split the recording there, \
         or raise the limit (--max-gap-s, `max_gap_s` in layout.toml)",
        (times[i + 1] - times[i]) * scale,
        i + 1,
        i + 2,
        times[i],
        times[i + 1],
        log.time_unit,
    );
    Err(invalid(path, message))
}

/// Refuses a log read without a time column whose first channel is named like a time
/// column (`t`, `time...`, `...stamp...`) and rises on every row: it is its stamps, and
/// read as one more taxel it would put a ramp on a cell and leave the rate unknown.
fn check_no_stamps_among_channels(
    path: &Path,
    format: &CsvFormat,
    columns: &Columns,
    log: &CsvLog,
) -> Result<()> {
    let n = columns.channels.len();
    if columns.time.is_some() || n < 2 || log.samples.len() < 3 * n {
        return Ok(());
    }
    let column = columns.channels[0];
    let name = match format.header {
        true => columns.names[column].clone(),
        false => column.to_string(),
    };
    let timelike = format.header && is_timelike_name(&name);
    let first = log.samples.iter().step_by(n);
    let rising = first.clone().zip(first.skip(1)).all(|(a, b)| b > a);
    // A host's clock since the Unix epoch: 1.7e9 s, 1.7e12 ms, 1.7e15 us; no taxel reads
    // that much while rising on every row.
    let epoch = log.samples[0] >= EPOCH_LIKE;
    if !(rising && (timelike || epoch)) {
        return Ok(());
    }
    let why = match timelike {
        true => "is named like time stamps and rises on every row".to_string(),
        false => format!(
            "rises on every row from {}, like a clock's stamps since an epoch",
            log.samples[0]
        ),
    };
    let message = format!(
        "column `{}` {why}, but no time column was chosen, so it would be read as a taxel: \
         name it as the time column (`import csv --time-column {}`, or `time_column = \"{}\"` \
         in the layout.toml given with these files, with its unit if it is not ms), or \
         choose the taxel columns (`--channels`, or `channels` in the layout)",
        excerpt(&name),
        excerpt(&name),
        excerpt(&name),
    );
    Err(invalid(path, message))
}

/// Whether a column's name says it holds time stamps: `t`, `time...`, `...stamp...`, or
/// `t...` with a unit (`t_ms`), in any case.
pub fn is_timelike_name(name: &str) -> bool {
    let lower = name.trim().to_lowercase();
    lower == "t"
        || lower.starts_with("time")
        || lower.contains("stamp")
        || unit_in_name(&lower).is_some_and(|_| lower.starts_with("t"))
}

/// The least first value of a rising first column taken for a clock's stamps since an
/// epoch rather than a taxel (a billion: 2001 in seconds since 1970).
const EPOCH_LIKE: f64 = 1e9;

/// A column named `t_ms` or `time_ms` (in ms), else `t_s` or `time_s` (in s).
fn detect_time_column(names: &[String]) -> (Option<usize>, TimeUnit) {
    let find = |wanted: &[&str]| names.iter().position(|h| wanted.contains(&h.as_str()));
    match (find(&["t_ms", "time_ms"]), find(&["t_s", "time_s"])) {
        (Some(j), _) => (Some(j), TimeUnit::Milliseconds),
        (None, Some(j)) => (Some(j), TimeUnit::Seconds),
        (None, None) => (None, TimeUnit::Milliseconds),
    }
}

/// Reads a CSV log as `format` says. Every cell must be a finite number; time stamps must
/// not decrease, and rows sharing one are handled as [`DuplicateStamps`] says. Errors name
/// the file, the line and the column.
///
/// # Errors
/// An unreadable or malformed file, a missing column, a cell that is not a finite number,
/// a time stamp that goes back, a repeated stamp under `error`, or no data rows.
pub fn read_csv_log(path: &Path, format: &CsvFormat) -> Result<CsvLog> {
    if !(format.max_gap_s.is_finite() && format.max_gap_s > 0.0) {
        let rule = "the largest gap between stamps must be a positive number of s";
        return Err(ParamError::new("max-gap-s", rule, format.max_gap_s).into());
    }
    let (mut reader, delimiter, names) = open_log(path, format)?;
    if names.is_empty() {
        return Err(invalid(path, "the file is empty"));
    }
    let columns = Columns::find(path, format, names)?;
    let mut rows = RowReader::new(path, &columns, format.duplicate_stamps);
    let mut record = csv::ByteRecord::new();
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => rows.push(&record)?,
            Err(e) => {
                let first = if format.header {
                    "the header"
                } else {
                    "line 1"
                };
                return Err(csv_error_after(path, e, first));
            }
        }
    }
    let log = rows.finish(delimiter, format);
    if log.samples.is_empty() {
        return Err(invalid(path, "no data rows"));
    }
    if let Some(times) = &log.times {
        check_plausible_rate(path, &columns, times)?;
        check_gaps(path, &log, format.max_gap_s)?;
    }
    check_no_stamps_among_channels(path, format, &columns, &log)?;
    Ok(log)
}

/// Folds rows into frames: the rows of one time stamp are kept (exact duplicates left out)
/// until the stamp changes, then become one frame.
struct RowReader<'a> {
    path: &'a Path,
    columns: &'a Columns,
    policy: DuplicateStamps,
    samples: Vec<f64>,
    times: Option<Vec<f64>>,
    /// The distinct rows of the current stamp, `channels` values each, and the line of the
    /// first.
    group: Vec<f64>,
    group_line: u64,
    stamp: Option<f64>,
    row: Vec<f64>,
    merged_rows: usize,
    duplicate_rows: usize,
}

impl<'a> RowReader<'a> {
    fn new(path: &'a Path, columns: &'a Columns, policy: DuplicateStamps) -> Self {
        RowReader {
            path,
            columns,
            policy,
            samples: Vec::new(),
            times: columns.time.map(|_| Vec::new()),
            group: Vec::new(),
            group_line: 0,
            stamp: None,
            row: Vec::with_capacity(columns.channels.len()),
            merged_rows: 0,
            duplicate_rows: 0,
        }
    }

    fn parse(&self, record: &csv::ByteRecord, line: u64, j: usize) -> Result<f64> {
        let raw = record.get(j).unwrap_or(b"");
        std::str::from_utf8(raw)
            .ok()
            .and_then(|s| s.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                invalid(
                    self.path,
                    format!(
                        "line {line}, column `{}`: expected a finite number, got `{}`",
                        excerpt(&self.columns.names[j]),
                        excerpt(&String::from_utf8_lossy(raw))
                    ),
                )
            })
    }

    fn push(&mut self, record: &csv::ByteRecord) -> Result<()> {
        let line = record.position().map_or(0, |p| p.line());
        self.row.clear();
        for k in 0..self.columns.channels.len() {
            let v = self.parse(record, line, self.columns.channels[k])?;
            if !crate::values::sample_in_range(v) {
                let name = excerpt(&self.columns.names[self.columns.channels[k]]);
                let rule = crate::values::SAMPLE_RULE;
                let message =
                    format!("line {line}, column `{name}`: {v:?} is out of range ({rule})");
                return Err(invalid(self.path, message));
            }
            self.row.push(v);
        }
        let Some(j) = self.columns.time else {
            self.samples.extend_from_slice(&self.row);
            return Ok(());
        };
        let t = self.parse(record, line, j)?;
        match self.stamp {
            Some(prev) if t < prev => Err(invalid(
                self.path,
                format!("line {line}: time stamps must not go back, got {t} after {prev}"),
            )),
            Some(prev) if t == prev => self.same_stamp(t, line),
            _ => {
                self.flush();
                self.stamp = Some(t);
                self.group_line = line;
                self.group.extend_from_slice(&self.row);
                Ok(())
            }
        }
    }

    /// Another row at the current stamp: dropped when it repeats one exactly, else kept
    /// for the frame (or an error under `error`).
    fn same_stamp(&mut self, t: f64, line: u64) -> Result<()> {
        let n = self.row.len();
        if self.group.chunks_exact(n).any(|g| g == self.row.as_slice()) {
            self.duplicate_rows += 1;
            return Ok(());
        }
        if self.policy == DuplicateStamps::Error {
            let message = format!(
                "line {line}: time stamp {t} repeats line {} with other values (--duplicate-stamps average, first or last merges such rows)",
                self.group_line
            );
            return Err(invalid(self.path, message));
        }
        self.merged_rows += 1;
        self.group.extend_from_slice(&self.row);
        Ok(())
    }

    /// The current stamp's rows become one frame.
    fn flush(&mut self) {
        let n = self.columns.channels.len();
        let k = self.group.len() / n.max(1);
        if k == 0 {
            return;
        }
        match self.policy {
            DuplicateStamps::First | DuplicateStamps::Error => {
                self.samples.extend_from_slice(&self.group[..n])
            }
            DuplicateStamps::Last => self.samples.extend_from_slice(&self.group[(k - 1) * n..]),
            DuplicateStamps::Average => self.samples.extend(
                (0..n).map(|c| (0..k).map(|r| self.group[r * n + c]).sum::<f64>() / k as f64),
            ),
        }
        if let (Some(times), Some(t)) = (self.times.as_mut(), self.stamp) {
            times.push(t);
        }
        self.group.clear();
    }

    fn finish(mut self, delimiter: Delimiter, format: &CsvFormat) -> CsvLog {
        self.flush();
        let c = self.columns;
        let name = |j: usize| match format.header {
            true => c.names[j].clone(),
            false => j.to_string(),
        };
        let columns = LogColumns {
            header: Some(format.header),
            delimiter: Some(delimiter),
            time_column: c.time.map(name),
            time_unit: c.time.map(|_| c.unit),
            channels: Some(c.channels.iter().map(|&j| name(j)).collect()),
            duplicate_stamps: Some(format.duplicate_stamps),
        };
        CsvLog {
            columns,
            channel_names: self
                .columns
                .channels
                .iter()
                .map(|&j| self.columns.names[j].clone())
                .collect(),
            samples: self.samples,
            times: self.times,
            time_unit: self.columns.unit,
            merged_rows: self.merged_rows,
            duplicate_rows: self.duplicate_rows,
            delimiter,
        }
    }
}

/// A CSV reading error under the file's name, with its line when the reader knows it,
/// the first line counted as the header.
pub(crate) fn csv_error(path: &Path, e: csv::Error) -> crate::Error {
    csv_error_after(path, e, "the header")
}

/// As [`csv_error`], `first` naming the file's first line (`the header`, `line 1`).
fn csv_error_after(path: &Path, e: csv::Error, first: &str) -> crate::Error {
    match e.kind() {
        csv::ErrorKind::Io(_) => {
            let csv::ErrorKind::Io(io) = e.into_kind() else {
                unreachable!()
            };
            crate::io::read_error(path, io)
        }
        _ => DataError::invalid(path, csv_words(&e, first)).into(),
    }
}

/// A CSV reader's error (not an I/O one) in neurotex's words: the line, what it holds
/// and what was expected, never the reader's record and byte counts.
pub(crate) fn csv_words(e: &csv::Error, first: &str) -> String {
    let line = e.position().map(|p| p.line());
    let at = line.map(|l| format!("line {l}")).unwrap_or("a line".into());
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!(
            "{at} has {len} field(s) where {first} has {expected_len}: every line needs one \
             field per column (a field holding the delimiter goes in double quotes)"
        ),
        csv::ErrorKind::Utf8 { err, .. } => format!(
            "{at}: field {} is not UTF-8 text (save the file as UTF-8)",
            err.field() + 1
        ),
        _ => {
            let text = e.to_string();
            // The reader's own wording after its position, if any.
            let what = text.rsplit("): ").next().unwrap_or(&text);
            format!("{at}: {}", crate::error::parser_words(what))
        }
    }
}
