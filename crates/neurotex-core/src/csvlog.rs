//! Reading CSV logs as lab loggers write them: with or without a header row, columns by
//! name or by 0-based index, `,` `;` or tab between fields (detected when not given), and
//! time stamps that a host may repeat. One [`CsvFormat`] describes a file; `import csv`,
//! `encode` and the dataset reader all read through [`read_csv_log`], so they cannot drift.

use std::path::Path;

use crate::error::{DataError, Result};
use crate::values::TimeUnit;

mod choose;
mod format;
mod header;
mod read;

pub use choose::{choose_columns, choose_format, CsvOverrides, LogColumns};
pub use format::{ChannelSelect, Column, CsvFormat, Delimiter, DuplicateStamps, DEFAULT_MAX_GAP_S};
use header::detect_delimiter;
pub(crate) use header::repeated_name;
pub use header::{detect_delimiter_in, header_names, is_timelike_name, unit_in_name, Columns};
pub use read::{read_csv_log, PLAUSIBLE_HZ};

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

fn invalid(path: &Path, message: impl Into<String>) -> crate::Error {
    DataError::invalid(path, message).into()
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

/// The line of `path` that a record starts on, its CSV reader's position being `start`
/// bytes in. The reader's own line count can be one short: it counts a blank line just
/// before a record into the record's position, and the `\n` of a `\r\n` ending into the
/// next record; both are stepped over here. For error messages only (it reads the file
/// again up to the record). `None` when the file cannot be read again.
pub(crate) fn record_line(path: &Path, start: u64) -> Option<u64> {
    use std::io::Read;
    // Blank lines beyond a few thousand bytes are not looked for.
    let mut bytes = Vec::new();
    let file = crate::io::open_text(path).ok()?;
    file.take(start.saturating_add(4096))
        .read_to_end(&mut bytes)
        .ok()?;
    let start = usize::try_from(start).ok()?.min(bytes.len());
    let mut line = 1 + bytes[..start].iter().filter(|&&b| b == b'\n').count() as u64;
    for &b in &bytes[start..] {
        match b {
            b'\n' => line += 1,
            b'\r' => {}
            _ => break,
        }
    }
    Some(line)
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
        _ => DataError::invalid(path, csv_words(&e, first, path)).into(),
    }
}

/// A CSV reader's error (not an I/O one) in `path` in neurotex's words: the line, what it
/// holds and what was expected, never the reader's record and byte counts.
pub(crate) fn csv_words(e: &csv::Error, first: &str, path: &Path) -> String {
    let line = (e.position()).map(|p| record_line(path, p.byte()).unwrap_or(p.line()));
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
            format!("{at}: {}", crate::words::parser_words(what))
        }
    }
}
