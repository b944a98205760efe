//! The format and columns of a set of logs, chosen from what the user gave and what the first
//! log's header line says.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{DataError, ParamError, Result};
use crate::values::TimeUnit;

use super::format::{
    ChannelSelect, Column, CsvFormat, Delimiter, DuplicateStamps, DEFAULT_MAX_GAP_S,
};
use super::header::Columns;
use super::{invalid, open_log};

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
