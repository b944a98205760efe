//! A log's header line read: its delimiter detected, its names resolved to the time column
//! and the channels, a unit read from a column's name.

use std::io::Read;
use std::path::Path;

use crate::error::{DataError, Result};
use crate::values::TimeUnit;

use super::format::{ChannelSelect, Column, CsvFormat, Delimiter};
use super::{excerpt, invalid};

/// Guesses a file's delimiter from its first lines ([`detect_delimiter_in`]).
pub(super) fn detect_delimiter(path: &Path) -> Result<Delimiter> {
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
    /// Whether the unit was given (`--time-unit`, `time_unit` in layout.toml), rather than
    /// read from the time column's name or assumed.
    pub unit_given: bool,
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
            let asked = match &format.channels {
                ChannelSelect::Regex(re) => format!(" by --channels `{}`", excerpt(re.as_str())),
                _ => String::new(),
            };
            let columns = names.join(", ");
            let message = format!(
                "no channel columns selected{asked} (columns: {})",
                excerpt(&columns)
            );
            return Err(invalid(path, message));
        }
        if format.header {
            unique_names(path, &names, time.iter().chain(&channels))?;
        }
        Ok(Columns {
            names,
            time,
            unit,
            unit_known,
            unit_given: format.unit_given,
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

/// The unit a time column's name ends in: `_ms`, `_s`, `_us` (or `-`, a space, `(ms)`,
/// `[s]`), in any case.
pub fn unit_in_name(name: &str) -> Option<TimeUnit> {
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
pub(super) const EPOCH_LIKE: f64 = 1e9;

/// A column named `t_ms` or `time_ms` (in ms), else `t_s` or `time_s` (in s).
fn detect_time_column(names: &[String]) -> (Option<usize>, TimeUnit) {
    let find = |wanted: &[&str]| names.iter().position(|h| wanted.contains(&h.as_str()));
    match (find(&["t_ms", "time_ms"]), find(&["t_s", "time_s"])) {
        (Some(j), _) => (Some(j), TimeUnit::Milliseconds),
        (None, Some(j)) => (Some(j), TimeUnit::Seconds),
        (None, None) => (None, TimeUnit::Milliseconds),
    }
}
