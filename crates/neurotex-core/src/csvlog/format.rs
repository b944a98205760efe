//! How a CSV log is written, as a user states it: its delimiter, its columns by name or
//! position, the channels to keep, what to do with repeated time stamps.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::{ParamError, Result};
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
pub struct Delimiter(pub(super) u8);

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
