//! Address-event recordings: what an event sensor (NeuTouch, an event camera behind a skin,
//! ST-MNIST's array) writes instead of samples. Each event is a time, a cell (`x`, `y` or a
//! taxel index) and optionally a polarity. A dataset whose `layout.toml` has an `[events]`
//! table holds such files, CSV with a header row or `.npy` with a structured dtype (tonic's
//! `[('t', ...), ('x', ...), ('y', ...), ('p', ...)]` read as it is).
//!
//! Events skip the encoder: each cell's ON events are one spike train and its OFF events
//! another, in the 1 ms steps the encoder's spikes take, so every feature method and
//! classifier reads them as it reads the SA and FA populations. Two events of one cell and
//! polarity in the same millisecond are one spike (a train holds at most one per step);
//! [`Events::merged`] counts them.
//!
//! Reading is strict, as for sampled recordings: a time that goes backwards, a cell outside
//! the grid or masked, an unknown polarity, or a time past the recording's duration is an
//! error naming the file and the line (CSV) or record (`.npy`). `neurotex import events`
//! ([`crate::import::import_events`]) sorts logs whose events are out of order as it copies
//! them.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{DataError, Result};
use crate::npy::{read_data, read_header, NpyField};
use crate::values::TimeUnit;

/// The `[events]` table of `layout.toml`: how a dataset's event files are read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventsFormat {
    /// The unit of the time stamps: `us` (tonic's), `ms` or `s`. Required: event files
    /// rarely say their unit, and a wrong one moves every spike by a factor of 1000.
    pub time_unit: TimeUnit,
    /// The time column or field (default `t`).
    #[serde(default = "default_time")]
    pub time: String,
    /// The grid column's (x) and row's (y) columns or fields (default `x`, `y`).
    #[serde(default = "default_x")]
    pub x: String,
    /// See `x`.
    #[serde(default = "default_y")]
    pub y: String,
    /// Instead of `x` and `y`: a 0-based taxel index column, mapped to cells by the layout's
    /// `channel_map` (row-major order without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub taxel: Option<String>,
    /// The polarity column or field (default `p`; a file without it holds ON events only).
    #[serde(default = "default_polarity")]
    pub polarity: String,
    /// The ON and OFF polarity values (default 1 and 0, tonic's; some sensors write -1 for
    /// OFF). Booleans read as 1 and 0.
    #[serde(default = "default_values")]
    pub values: [i64; 2],
    /// Where time 0 is: `zero` (the file's stamps are from the recording's start, the
    /// default) or `first` (the first event's stamp, for sensors that write a clock).
    #[serde(default)]
    pub origin: Origin,
}

fn default_time() -> String {
    "t".into()
}
fn default_x() -> String {
    "x".into()
}
fn default_y() -> String {
    "y".into()
}
fn default_polarity() -> String {
    "p".into()
}
fn default_values() -> [i64; 2] {
    [1, 0]
}

impl EventsFormat {
    /// Whether an event of polarity `p` is ON (every event without a polarity is); `Err`
    /// for a value that is neither ON nor OFF.
    pub fn is_on(&self, p: Option<i64>) -> Result<bool, String> {
        let [on, off] = self.values;
        match p {
            None => Ok(true),
            Some(v) if v == on => Ok(true),
            Some(v) if v == off => Ok(false),
            Some(v) => Err(format!(
                "polarity {v} is neither ON ({on}) nor OFF ({off}); `import events --polarity-values ON,OFF` (or layout.toml's `[events] values = [on, off]`) names them"
            )),
        }
    }

    /// The format of files written in `unit` with the default column names.
    pub fn new(unit: TimeUnit) -> Self {
        EventsFormat {
            time_unit: unit,
            time: default_time(),
            x: default_x(),
            y: default_y(),
            taxel: None,
            polarity: default_polarity(),
            values: default_values(),
            origin: Origin::default(),
        }
    }
}

/// Where an event file's time 0 is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Origin {
    /// The stamps count from the recording's start.
    #[default]
    Zero,
    /// The first event is at time 0.
    First,
}

/// How the cells of a recording's grid are addressed.
#[derive(Debug, Clone)]
pub struct EventGrid {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Which cells hold a taxel (row-major).
    pub present: Vec<bool>,
    /// For a taxel index column: taxel `i`'s cell (row-major index).
    pub taxels: Vec<usize>,
}

impl EventGrid {
    /// The cell (row-major index) of an event at `(x, y)`, or of taxel `a` when `taxel`
    /// (`b` unused), checked against the grid and its mask; `Err` says why there is none.
    pub fn cell(&self, taxel: bool, (a, b): (i64, i64)) -> Result<usize, String> {
        let g = self;
        let (row, col) = match taxel {
            true => {
                let cell = usize::try_from(a)
                    .ok()
                    .and_then(|i| g.taxels.get(i))
                    .ok_or_else(|| {
                        format!(
                            "taxel {a} is outside the layout's {} taxels (0 to {})",
                            g.taxels.len(),
                            g.taxels.len().saturating_sub(1)
                        )
                    })?;
                (cell / g.cols, cell % g.cols)
            }
            false => {
                let inside = |v: i64, n: usize| usize::try_from(v).ok().filter(|&v| v < n);
                match (inside(b, g.rows), inside(a, g.cols)) {
                    (Some(r), Some(c)) => (r, c),
                    _ => {
                        return Err(format!(
                            "x = {a}, y = {b} is outside the {}x{} grid (x is the column, 0 to {}; y the row, 0 to {})",
                            g.rows,
                            g.cols,
                            g.cols - 1,
                            g.rows - 1
                        ))
                    }
                }
            }
        };
        let cell = row * g.cols + col;
        if !g.present[cell] {
            return Err(format!(
                "the event is at row {row}, column {col}, a cell layout.toml's mask leaves out"
            ));
        }
        Ok(cell)
    }
}

/// One recording's events as spike trains: per polarity, per cell (row-major), the sorted
/// 1 ms steps with at least one event.
#[derive(Debug, Clone, PartialEq)]
pub struct Events {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Which cells hold a taxel.
    pub present: Vec<bool>,
    /// The recording's length in 1 ms steps.
    pub n_steps: usize,
    /// ON events (every event of a file without polarities).
    pub on: Vec<Vec<u32>>,
    /// OFF events; `None` when the file has no polarity column.
    pub off: Option<Vec<Vec<u32>>>,
    /// Events read.
    pub count: usize,
    /// Events that fell in a millisecond already holding an event of their cell and
    /// polarity, and so added no spike.
    pub merged: usize,
}

/// An event's time stamp as written, in its unit: exact for integers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stamp {
    /// An integer stamp (tonic's microseconds, a clock's ticks).
    Int(i64),
    /// A decimal stamp (seconds with a fraction).
    Float(f64),
}

impl Stamp {
    /// The stamp as a number.
    pub fn as_f64(self) -> f64 {
        as_f64(self)
    }

    /// Whether the stamp is before `other`.
    pub fn before(self, other: Stamp) -> bool {
        match (self, other) {
            (Stamp::Int(a), Stamp::Int(b)) => a < b,
            (a, b) => as_f64(a) < as_f64(b),
        }
    }

    /// The 1 ms step of the stamp counted from `from`, in `unit`: integer arithmetic for
    /// integer stamps, and a decimal stamp within a millionth of a millisecond below a
    /// boundary counted on it. `Err` says why there is none (before `from`, not finite).
    pub fn step_from(self, from: Stamp, unit: TimeUnit) -> Result<u64, String> {
        to_step(self, from, unit)
    }
}

impl std::fmt::Display for Stamp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&show(*self))
    }
}

/// The columns of one file, as indices into a record's values.
struct Columns {
    time: usize,
    cell: CellColumns,
    polarity: Option<usize>,
}

enum CellColumns {
    Xy(usize, usize),
    Taxel(usize),
}

impl Columns {
    /// The names of `names` this plan does not read.
    fn unread(&self, names: &[&str]) -> Vec<String> {
        let read = |i: usize| {
            i == self.time
                || self.polarity == Some(i)
                || match self.cell {
                    CellColumns::Xy(x, y) => i == x || i == y,
                    CellColumns::Taxel(t) => i == t,
                }
        };
        (0..names.len())
            .filter(|&i| !read(i))
            .map(|i| names[i].trim().to_string())
            .collect()
    }
}

/// The longest an event recording may last, in 1 ms steps: the layout's `max_duration_s`,
/// and the bound sampled recordings keep on what a recording becomes on its grid at 1 kHz
/// (at most `max_duration_s` x [`crate::values::VALUES_PER_LIMIT_S`] values). Feature
/// methods plan a value per cell and millisecond (rasters, rate volumes), so a handful of
/// events on a huge grid would otherwise ask for gigabytes; a larger grid may last
/// proportionally less.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepLimit {
    /// The steps a recording may last.
    pub steps: u64,
    /// The span limit, in steps (`max_duration_s` in ms).
    pub span_steps: u64,
    /// The grid's cells.
    pub cells: usize,
}

impl StepLimit {
    /// The limit on a grid of `cells` cells under a span limit of `span_steps` ms.
    pub fn new(span_steps: u64, cells: usize) -> Self {
        let per_ms = crate::values::VALUES_PER_LIMIT_S / 1000.0;
        let on_grid = (span_steps as f64 * per_ms / cells.max(1) as f64).floor() as u64;
        StepLimit {
            steps: span_steps.min(on_grid),
            span_steps,
            cells,
        }
    }

    /// The limit as messages say it, with what to do about it.
    pub fn describe(&self) -> String {
        let max_s = self.span_steps as f64 / 1000.0;
        match self.steps < self.span_steps {
            false => format!("the longest recording accepted ({max_s} s, layout.toml's max_duration_s)"),
            true => format!(
                "the {} ms a recording on {} grid cells may last (its spikes on the grid at 1 kHz may hold at most max_duration_s x 16 000 values, {max_s} s of a 16-taxel grid; a wrong grid or time unit is the usual cause, else raise max_duration_s in layout.toml)",
                self.steps, self.cells
            ),
        }
    }
}

/// Gathers events into trains, checking each as it comes.
pub(crate) struct Gather<'a> {
    format: &'a EventsFormat,
    grid: &'a EventGrid,
    limit: StepLimit,
    duration: Option<u64>,
    first: Option<Stamp>,
    last_step: Option<u64>,
    last: Option<Stamp>,
    on: Vec<Vec<u32>>,
    off: Option<Vec<Vec<u32>>>,
    count: usize,
    merged: usize,
}

impl<'a> Gather<'a> {
    pub(crate) fn new(
        format: &'a EventsFormat,
        grid: &'a EventGrid,
        polarity: bool,
        duration: Option<u64>,
        max_steps: u64,
    ) -> Self {
        let cells = grid.rows * grid.cols;
        Gather {
            format,
            grid,
            limit: StepLimit::new(max_steps, cells),
            duration,
            first: None,
            last_step: None,
            last: None,
            on: vec![Vec::new(); cells],
            off: polarity.then(|| vec![Vec::new(); cells]),
            count: 0,
            merged: 0,
        }
    }

    /// Adds one event; `Err` holds the reason, the caller adds where.
    pub(crate) fn push(
        &mut self,
        t: Stamp,
        cell: (i64, i64),
        p: Option<i64>,
    ) -> Result<(), String> {
        let step = self.step(t)?;
        let cell = self.cell(cell)?;
        let trains = match self.format.is_on(p)? {
            true => &mut self.on,
            false => self
                .off
                .as_mut()
                .expect("a polarity column gives OFF trains"),
        };
        let train = &mut trains[cell];
        let step = step as u32;
        if train.last() == Some(&step) {
            self.merged += 1;
        } else {
            train.push(step);
        }
        self.count += 1;
        Ok(())
    }

    /// The event's 1 ms step, checking order, origin and duration.
    fn step(&mut self, t: Stamp) -> Result<u64, String> {
        // The common case, an integer stamp in order after the first: exact integer
        // arithmetic, no branch on the origin's kind.
        if let (Stamp::Int(t), Some(Stamp::Int(last)), Some(Stamp::Int(first))) =
            (t, self.last, self.first)
        {
            let from = match self.format.origin {
                Origin::Zero => 0,
                Origin::First => first,
            };
            let d = t.saturating_sub(from);
            if t >= last && d >= 0 {
                let ms = match self.format.time_unit {
                    TimeUnit::Microseconds => d / 1000,
                    TimeUnit::Milliseconds => d,
                    TimeUnit::Seconds => d.saturating_mul(1000),
                } as u64;
                if ms < self.duration.unwrap_or(self.limit.steps) {
                    self.last = Some(Stamp::Int(t));
                    self.last_step = Some(self.last_step.map_or(ms, |s| s.max(ms)));
                    return Ok(ms);
                }
            }
        }
        if let Some(last) = self.last {
            if t.before(last) {
                return Err(format!(
                    "time {} comes before the previous event's {}: events must be in time order (`neurotex import events` sorts them)",
                    show(t),
                    show(last)
                ));
            }
        }
        self.last = Some(t);
        let first = *self.first.get_or_insert(t);
        let from = match self.format.origin {
            Origin::Zero => Stamp::Int(0),
            Origin::First => first,
        };
        let step = to_step(t, from, self.format.time_unit)?;
        let limit = self.duration.unwrap_or(self.limit.steps);
        if step >= limit {
            let past = self.limit.describe();
            return Err(match self.duration {
                Some(d) => format!(
                    "time {} is at {step} ms, past the recording's duration_s ({d} ms) in the manifest",
                    show(t)
                ),
                None => match self.format.origin {
                    Origin::Zero => format!(
                        "time {} is at {step} ms, past {past}: a clock's stamps need `--origin first` (`origin = \"first\"` in layout.toml), or the time unit is wrong",
                        show(t),
                    ),
                    Origin::First => format!(
                        "time {} is {step} ms after the first event, past {past}: is the time unit right?",
                        show(t),
                    ),
                },
            });
        }
        self.last_step = Some(self.last_step.map_or(step, |s| s.max(step)));
        Ok(step)
    }

    /// The event's cell (row-major index), checked against the grid and its mask.
    pub(crate) fn cell(&self, at: (i64, i64)) -> Result<usize, String> {
        self.grid.cell(self.format.taxel.is_some(), at)
    }

    pub(crate) fn finish(self) -> Events {
        let n_steps = match (self.duration, self.last_step) {
            (Some(d), _) => d as usize,
            (None, Some(s)) => s as usize + 1,
            (None, None) => 0,
        };
        Events {
            rows: self.grid.rows,
            cols: self.grid.cols,
            present: self.grid.present.clone(),
            n_steps,
            on: self.on,
            off: self.off,
            count: self.count,
            merged: self.merged,
        }
    }
}

pub(crate) fn as_f64(t: Stamp) -> f64 {
    match t {
        Stamp::Int(v) => v as f64,
        Stamp::Float(v) => v,
    }
}

pub(crate) fn show(t: Stamp) -> String {
    match t {
        Stamp::Int(v) => v.to_string(),
        Stamp::Float(v) => v.to_string(),
    }
}

/// A time within this many ms below a millisecond boundary counts as on it: decimal
/// seconds such as 0.29 are not exact in binary, and `0.29 * 1000` falls a hair short of
/// 290.
const BOUNDARY_TOLERANCE_MS: f64 = 1e-6;

/// The 1 ms step of `t` counted from `from`, exact for integer stamps.
fn to_step(t: Stamp, from: Stamp, unit: TimeUnit) -> Result<u64, String> {
    let before = || {
        format!(
            "time {} is before the recording's start: stamps from a clock need `--origin first` (`origin = \"first\"` in layout.toml's [events])",
            show(t)
        )
    };
    match (t, from) {
        (Stamp::Int(t), Stamp::Int(from)) => {
            let d = t.saturating_sub(from);
            if d < 0 {
                return Err(before());
            }
            let ms = match unit {
                TimeUnit::Microseconds => d / 1000,
                TimeUnit::Milliseconds => d,
                TimeUnit::Seconds => d.saturating_mul(1000),
            };
            Ok(u64::try_from(ms).unwrap_or(u64::MAX))
        }
        (t, from) => {
            let d = as_f64(t) - as_f64(from);
            if !d.is_finite() {
                return Err(format!("time {} is not a finite number", show(t)));
            }
            let ms = d * unit.seconds() * 1000.0;
            if ms < -BOUNDARY_TOLERANCE_MS {
                return Err(before());
            }
            Ok((ms + BOUNDARY_TOLERANCE_MS).floor().max(0.0) as u64)
        }
    }
}

/// Reads one event file, CSV or `.npy` by its extension.
///
/// `duration_ms`: the recording's length when the manifest gives it (`duration_s`);
/// otherwise the recording ends at its last event. `max_steps`: the longest recording
/// accepted, in ms.
///
/// # Errors
/// An unreadable file, a missing column or field, or an event that breaks a rule of the
/// module's description; the message names the file and the line or record.
pub fn read_events(
    path: &Path,
    format: &EventsFormat,
    grid: &EventGrid,
    duration_ms: Option<u64>,
    max_steps: u64,
) -> Result<Events> {
    let mut gather: Option<Gather> = None;
    parse(path, format, &mut |event| match event {
        Parsed::Columns { polarity, .. } => {
            gather = Some(Gather::new(format, grid, polarity, duration_ms, max_steps));
            Ok(())
        }
        Parsed::Event { t, cell, p, .. } => gather
            .as_mut()
            .expect("the columns come first")
            .push(t, cell, p),
    })?;
    Ok(gather
        .unwrap_or_else(|| Gather::new(format, grid, false, duration_ms, max_steps))
        .finish())
}

/// What a parser hands on: the file's columns once, then each event in file order.
pub(crate) enum Parsed {
    Columns {
        polarity: bool,
        /// The columns or fields not read.
        unread: Vec<String>,
    },
    Event {
        t: Stamp,
        cell: (i64, i64),
        p: Option<i64>,
        /// The CSV line (1-based, the header is line 1) or the `.npy` record (0-based).
        at: usize,
    },
}

/// Parses an event file, CSV or `.npy` by its extension, handing each event to `sink`;
/// an `Err` from the sink is named with the line or record.
pub(crate) fn parse(
    path: &Path,
    format: &EventsFormat,
    sink: &mut impl FnMut(Parsed) -> Result<(), String>,
) -> Result<()> {
    let npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    match npy {
        true => parse_npy(path, format, sink),
        false => parse_csv(path, format, sink),
    }
}

/// Which of `names` (a CSV header or a dtype's fields) hold the format's columns.
fn columns(names: &[&str], format: &EventsFormat) -> Result<Columns, String> {
    let find = |name: &str| names.iter().position(|n| n.trim() == name);
    let need = |name: &str| {
        find(name).ok_or_else(|| {
            format!(
                "no column `{name}` (it has {}); `import events` options (--time-column, --x, --y, --taxel, --polarity) or layout.toml's [events] table name the columns",
                names.join(", ")
            )
        })
    };
    let named = (0..names.len()).filter(|&j| !names[j].trim().is_empty());
    let trimmed: Vec<&str> = names.iter().map(|n| n.trim()).collect();
    let why = "an event log's time, cell and polarity are found by name";
    if let Some(message) = crate::csvlog::repeated_name(&trimmed, named, why) {
        return Err(message);
    }
    let cell = match &format.taxel {
        Some(taxel) => CellColumns::Taxel(need(taxel)?),
        None => CellColumns::Xy(need(&format.x)?, need(&format.y)?),
    };
    let columns = Columns {
        time: need(&format.time)?,
        cell,
        polarity: find(&format.polarity),
    };
    let mut roles = vec![("the time", columns.time)];
    match columns.cell {
        CellColumns::Xy(x, y) => roles.extend([("x", x), ("y", y)]),
        CellColumns::Taxel(t) => roles.push(("the taxel", t)),
    }
    roles.extend(columns.polarity.map(|p| ("the polarity", p)));
    for (k, &(what, j)) in roles.iter().enumerate() {
        if let Some(&(other, _)) = roles[..k].iter().find(|&&(_, i)| i == j) {
            return Err(format!(
                "column `{}` is both {other} and {what}: each needs a column of its own (layout.toml's [events] table or `import events` options name them)",
                names[j].trim()
            ));
        }
    }
    Ok(columns)
}

fn parse_csv(
    path: &Path,
    format: &EventsFormat,
    sink: &mut impl FnMut(Parsed) -> Result<(), String>,
) -> Result<()> {
    let bad = |m: String| -> crate::Error { DataError::invalid(path, m).into() };
    let file = crate::io::open_text(path)?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(false)
        .from_reader(std::io::BufReader::with_capacity(1 << 16, file));
    let header = match reader.byte_headers() {
        Ok(header) => header.clone(),
        Err(e) if e.is_io_error() => return Err(crate::csvlog::csv_error(path, e)),
        Err(e) => {
            let why = crate::csvlog::csv_words(&e, "the header");
            return Err(bad(format!("not a CSV file with a header row: {why}")));
        }
    };
    let names: Vec<&str> = header
        .iter()
        .map(|h| std::str::from_utf8(h).unwrap_or(""))
        .collect();
    if names.iter().all(|n| n.trim().is_empty()) {
        return Err(bad(format!(
            "the file is empty or its first line is blank: an event file starts with a header row naming its columns ({}, ...)",
            format.time
        )));
    }
    let cols = columns(&names, format).map_err(bad)?;
    sink(Parsed::Columns {
        polarity: cols.polarity.is_some(),
        unread: cols.unread(&names),
    })
    .map_err(bad)?;
    let mut record = csv::ByteRecord::new();
    let mut line = 1usize;
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) if e.is_io_error() => return Err(crate::csvlog::csv_error(path, e)),
            Err(e) => return Err(bad(crate::csvlog::csv_words(&e, "the header"))),
        }
        // The line the record starts on, as the CSV reader counts lines.
        line = record.position().map_or(line + 1, |p| p.line() as usize);
        let at = |m: String| bad(format!("line {line}: {m}"));
        let (t, cell, p) = csv_event(&record, &cols).map_err(at)?;
        sink(Parsed::Event {
            t,
            cell,
            p,
            at: line,
        })
        .map_err(at)?;
    }
    Ok(())
}

/// An event's time, cell fields (`x` and `y`, or the taxel and 0) and polarity.
type EventFields = (Stamp, (i64, i64), Option<i64>);

/// One CSV record's event: its time, cell fields and polarity; `Err` says why it is none.
fn csv_event(record: &csv::ByteRecord, cols: &Columns) -> std::result::Result<EventFields, String> {
    let field = |i: usize, what: &str| -> std::result::Result<&str, String> {
        std::str::from_utf8(&record[i]).map(str::trim).map_err(|e| {
            format!(
                "{what} is not UTF-8 text (its byte {} is not)",
                e.valid_up_to() + 1
            )
        })
    };
    let int = |i: usize, what: &str| -> std::result::Result<i64, String> {
        let text = field(i, what)?;
        text.parse::<i64>()
            .or(match text {
                "True" | "true" => Ok(1),
                "False" | "false" => Ok(0),
                _ => Err(()),
            })
            .map_err(|_| format!("{what} `{text}` is not an integer"))
    };
    let time = field(cols.time, "the time")?;
    let t = match time.parse::<i64>() {
        Ok(v) => Stamp::Int(v),
        Err(_) => Stamp::Float(
            time.parse::<f64>()
                .map_err(|_| format!("time `{time}` is not a number"))?,
        ),
    };
    let cell = match cols.cell {
        CellColumns::Xy(x, y) => (int(x, "x")?, int(y, "y")?),
        CellColumns::Taxel(i) => (int(i, "taxel")?, 0),
    };
    let p = cols.polarity.map(|i| int(i, "polarity")).transpose()?;
    Ok((t, cell, p))
}

fn parse_npy(
    path: &Path,
    format: &EventsFormat,
    sink: &mut impl FnMut(Parsed) -> Result<(), String>,
) -> Result<()> {
    let bad = |m: String| -> crate::Error { DataError::invalid(path, m).into() };
    let header = read_header(path)?;
    if header.fields.is_empty() || header.shape.len() != 1 {
        return Err(bad(format!(
            "an event .npy must be a 1-D structured array (tonic's dtype, fields t, x, y, p); this one is `{}` of shape {:?}",
            header.descr, header.shape
        )));
    }
    let names: Vec<&str> = header.fields.iter().map(|f| f.name.as_str()).collect();
    let cols = columns(&names, format).map_err(bad)?;
    let fields = &header.fields;
    let cell_fields = match cols.cell {
        CellColumns::Xy(x, y) => vec![x, y],
        CellColumns::Taxel(i) => vec![i],
    };
    for f in [Some(cols.time), cols.polarity]
        .into_iter()
        .flatten()
        .chain(cell_fields)
    {
        let field: &NpyField = &fields[f];
        let ok = match field.kind {
            'i' | 'u' | 'b' => !field.big_endian || field.bytes == 1,
            'f' => f == cols.time && !field.big_endian,
            _ => false,
        };
        if !ok {
            return Err(bad(format!(
                "field `{}` is of an unsupported type (little-endian integers, booleans, or floats for the time)",
                field.name
            )));
        }
    }
    sink(Parsed::Columns {
        polarity: cols.polarity.is_some(),
        unread: cols.unread(&names),
    })
    .map_err(bad)?;
    let data = read_data(path, &header)?;
    let time = &fields[cols.time];
    for (i, record) in data.chunks_exact(header.item_bytes).enumerate() {
        let int = |f: usize| fields[f].int(record).unwrap_or_default();
        let t = match time.kind {
            'f' => Stamp::Float(time.float(record).unwrap_or(f64::NAN)),
            _ => Stamp::Int(int(cols.time)),
        };
        let cell = match cols.cell {
            CellColumns::Xy(x, y) => (int(x), int(y)),
            CellColumns::Taxel(x) => (int(x), 0),
        };
        let p = cols.polarity.map(int);
        sink(Parsed::Event { t, cell, p, at: i })
            .map_err(|m| bad(format!("{}: {m}", place(path, i))))?;
    }
    Ok(())
}

/// Where event `at` of a [`Parsed::Event`] is, as the messages say it.
pub(crate) fn place(path: &Path, at: usize) -> String {
    let npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    match npy {
        true => format!("event {at} (0-based)"),
        false => format!("line {at}"),
    }
}

/// A cell's events over every recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellEvents {
    /// Its cell, `[row, col]`.
    pub cell: [usize; 2],
    /// The median over recordings of its ON events per second (spikes: one per ms at most).
    pub on_hz: f64,
    /// The same of its OFF events; `None` without polarities.
    pub off_hz: Option<f64>,
    /// Share of recordings in which it has no event.
    pub silent_share: f64,
}

/// The events over every recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventSummary {
    /// The time unit of the stamps.
    pub time_unit: String,
    /// Events per recording, `[min, median, max]`.
    pub events: [usize; 3],
    /// Share of the events that are ON; `None` without polarities.
    pub on_share: Option<f64>,
    /// Share of the events that fell in a millisecond already holding an event of their
    /// cell and polarity (one spike for both).
    pub merged_share: f64,
    /// Recordings without any event.
    pub empty: Vec<String>,
    /// Per cell with a taxel, row-major.
    pub cells: Vec<CellEvents>,
}

impl EventSummary {
    /// The summary of `recordings` (each file's name and events) on a grid whose cells with
    /// a taxel are `present`, stamped in `time_unit`.
    pub fn of(
        recordings: &[(&str, &Events)],
        present: &[bool],
        time_unit: Option<TimeUnit>,
    ) -> Self {
        let ok = recordings;
        let count = |lists: &[Vec<u32>]| lists.iter().map(Vec::len).sum::<usize>();
        let on: usize = ok.iter().map(|(_, e)| count(&e.on)).sum();
        let off: usize = ok
            .iter()
            .filter_map(|(_, e)| e.off.as_deref().map(count))
            .sum();
        let polarities = ok.iter().any(|(_, e)| e.off.is_some());
        let read: usize = ok.iter().map(|(_, e)| e.count).sum();
        let merged: usize = ok.iter().map(|(_, e)| e.merged).sum();
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(0.0)
        };
        let per_s = |n: usize, e: &Events| match e.n_steps {
            0 => 0.0,
            steps => n as f64 * 1000.0 / steps as f64,
        };
        let cols = recordings.first().map_or(1, |(_, e)| e.cols.max(1));
        let cells = (0..present.len())
            .filter(|&c| present[c])
            .map(|c| {
                let on = ok.iter().map(|(_, e)| per_s(e.on[c].len(), e)).collect();
                let off = polarities.then(|| {
                    let off = ok
                        .iter()
                        .map(|(_, e)| per_s(e.off.as_ref().map_or(0, |o| o[c].len()), e));
                    median(off.collect())
                });
                let silent = ok
                    .iter()
                    .filter(|(_, e)| {
                        e.on[c].is_empty() && e.off.as_ref().is_none_or(|o| o[c].is_empty())
                    })
                    .count();
                CellEvents {
                    cell: [c / cols, c % cols],
                    on_hz: median(on),
                    off_hz: off,
                    silent_share: silent as f64 / ok.len().max(1) as f64,
                }
            })
            .collect();
        EventSummary {
            time_unit: time_unit.map_or(String::new(), |u| u.to_string()),
            events: {
                let mut counts: Vec<usize> = ok.iter().map(|(_, e)| e.count).collect();
                counts.sort_unstable();
                match counts.len() {
                    0 => [0; 3],
                    n => [counts[0], counts[n / 2], counts[n - 1]],
                }
            },
            on_share: polarities.then(|| on as f64 / (on + off).max(1) as f64),
            merged_share: merged as f64 / read.max(1) as f64,
            empty: ok
                .iter()
                .filter(|(_, e)| e.count == 0)
                .map(|(m, _)| m.to_string())
                .collect(),
            cells,
        }
    }
}

/// One event to write: its millisecond, grid column (x) and row (y), and polarity (1 ON,
/// 0 OFF).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Event {
    /// Time in ms from the recording's start.
    pub t_ms: u32,
    /// Row (y).
    pub y: u32,
    /// Column (x).
    pub x: u32,
    /// 1 for ON, 0 for OFF.
    pub p: u8,
}

/// How [`write_events`] writes a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EventFile {
    /// CSV `t,x,y,p` with `t` in ms.
    #[default]
    Csv,
    /// `.npy` with tonic's structured dtype `[('x', '<i8'), ('y', '<i8'), ('t', '<i8'),
    /// ('p', '<i8')]` and `t` in microseconds, tonic's unit.
    Npy,
}

impl EventFile {
    /// The unit of the times written.
    pub fn time_unit(self) -> TimeUnit {
        match self {
            EventFile::Csv => TimeUnit::Milliseconds,
            EventFile::Npy => TimeUnit::Microseconds,
        }
    }

    /// The file name extension.
    pub fn extension(self) -> &'static str {
        match self {
            EventFile::Csv => "csv",
            EventFile::Npy => "npy",
        }
    }
}

/// Writes `events` (in time order) as `kind`.
///
/// # Errors
/// The writer fails.
pub fn write_events(
    w: &mut dyn std::io::Write,
    events: &[Event],
    kind: EventFile,
) -> std::io::Result<()> {
    match kind {
        EventFile::Csv => {
            let mut out = String::with_capacity(16 * events.len() + 8);
            out.push_str("t,x,y,p\n");
            for e in events {
                use std::fmt::Write as _;
                let _ = writeln!(out, "{},{},{},{}", e.t_ms, e.x, e.y, e.p);
            }
            w.write_all(out.as_bytes())
        }
        EventFile::Npy => {
            let descr = "[('x', '<i8'), ('y', '<i8'), ('t', '<i8'), ('p', '<i8')]";
            let mut header = format!(
                "{{'descr': {descr}, 'fortran_order': False, 'shape': ({},), }}",
                events.len()
            );
            while (10 + header.len() + 1) % 64 != 0 {
                header.push(' ');
            }
            header.push('\n');
            let mut out = Vec::with_capacity(10 + header.len() + 32 * events.len());
            out.extend_from_slice(b"\x93NUMPY\x01\x00");
            out.extend_from_slice(&(header.len() as u16).to_le_bytes());
            out.extend_from_slice(header.as_bytes());
            for e in events {
                let t_us = i64::from(e.t_ms) * 1000;
                for v in [i64::from(e.x), i64::from(e.y), t_us, i64::from(e.p)] {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
            w.write_all(&out)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> EventGrid {
        let mut present = vec![true; 6];
        present[5] = false;
        EventGrid {
            rows: 2,
            cols: 3,
            present,
            taxels: (0..5).collect(),
        }
    }

    fn read(text: &str, format: &EventsFormat, duration: Option<u64>) -> Result<Events> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.csv");
        std::fs::write(&path, text).unwrap();
        read_events(&path, format, &grid(), duration, 3_600_000)
    }

    #[test]
    fn events_become_trains_by_cell_and_polarity() {
        // microseconds: 999 us is step 0, 1000 us step 1; two ON events of cell (0, 1) in
        // step 1 are one spike.
        let text = "t,x,y,p\n999,1,0,1\n1000,1,0,1\n1500,1,0,1\n2000,1,0,0\n4000,0,1,1\n";
        let e = read(text, &EventsFormat::new(TimeUnit::Microseconds), None).unwrap();
        assert_eq!((e.n_steps, e.count, e.merged), (5, 5, 1));
        assert_eq!(e.on[1], [0, 1]);
        assert_eq!(e.on[3], [4]);
        assert_eq!(e.off.as_ref().unwrap()[1], [2]);
        assert!(e
            .off
            .unwrap()
            .iter()
            .enumerate()
            .all(|(c, t)| c == 1 || t.is_empty()));
    }

    #[test]
    fn decimal_seconds_land_on_their_millisecond() {
        // 0.29 * 1000 is 289.99999999999997 in binary
        let text = "t,x,y\n0.29,0,0\n4.35,0,0\n";
        let e = read(text, &EventsFormat::new(TimeUnit::Seconds), Some(5000)).unwrap();
        assert_eq!(e.on[0], [290, 4350]);
        assert_eq!(e.n_steps, 5000);
        assert!(e.off.is_none(), "no polarity column: ON only");
    }

    #[test]
    fn a_clock_origin_and_taxel_indices() {
        let format = EventsFormat {
            taxel: Some("taxel".into()),
            origin: Origin::First,
            values: [1, -1],
            ..EventsFormat::new(TimeUnit::Milliseconds)
        };
        let text = "t,taxel,p\n1000007,4,-1\n1000009,0,1\n";
        let e = read(text, &format, None).unwrap();
        assert_eq!(e.off.unwrap()[4], [0]);
        assert_eq!(e.on[0], [2]);
    }

    #[test]
    fn written_events_read_back_as_the_same_trains() {
        let events = [
            Event {
                t_ms: 0,
                y: 0,
                x: 1,
                p: 1,
            },
            Event {
                t_ms: 3,
                y: 1,
                x: 0,
                p: 0,
            },
            Event {
                t_ms: 3,
                y: 1,
                x: 1,
                p: 1,
            },
        ];
        let dir = tempfile::tempdir().unwrap();
        for kind in [EventFile::Csv, EventFile::Npy] {
            let path = dir.path().join(format!("e.{}", kind.extension()));
            let mut bytes = Vec::new();
            write_events(&mut bytes, &events, kind).unwrap();
            std::fs::write(&path, bytes).unwrap();
            let format = EventsFormat::new(kind.time_unit());
            let e = read_events(&path, &format, &grid(), Some(10), 3_600_000).unwrap();
            assert_eq!(
                (e.on[1].as_slice(), e.on[4].as_slice()),
                (&[0][..], &[3][..]),
                "{kind:?}"
            );
            assert_eq!(e.off.as_ref().unwrap()[3], [3], "{kind:?}");
            assert_eq!((e.count, e.n_steps), (3, 10));
        }
    }

    #[test]
    fn every_broken_rule_names_its_line() {
        let us = EventsFormat::new(TimeUnit::Microseconds);
        for (text, says) in [
            ("t,x,y,p\n5,0,0,1\n4,0,0,1\n", "line 3: time 4 comes before"),
            (
                "t,x,y,p\n5,3,0,1\n",
                "line 2: x = 3, y = 0 is outside the 2x3 grid",
            ),
            ("t,x,y,p\n5,-1,0,1\n", "outside the 2x3 grid"),
            ("t,x,y,p\n5,2,1,1\n", "mask leaves out"),
            (
                "t,x,y,p\n5,0,0,2\n",
                "line 2: polarity 2 is neither ON (1) nor OFF (0)",
            ),
            ("t,x,y,p\n-5,0,0,1\n", "before the recording's start"),
            ("t,x,y,p\nNaN,0,0,1\n", "not a finite number"),
            ("t,x,y,p\nabc,0,0,1\n", "time `abc` is not a number"),
            ("t,x,y,p\n5,0.5,0,1\n", "x `0.5` is not an integer"),
            ("t,col,y,p\n5,0,0,1\n", "no column `x`"),
            ("t,x,y,p\n5,0,0\n", "line 2"),
            ("t,x,y,p\n1700000000000000,0,0,1\n", "origin = \"first\""),
        ] {
            let message = read(text, &us, None).unwrap_err().to_string();
            assert!(message.contains(says), "{text:?}: {message}");
            assert!(message.contains("e.csv"), "{message}");
        }
        let message = read("t,x,y,p\n5000,0,0,1\n", &us, Some(4))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("past the recording's duration_s"),
            "{message}"
        );
    }
}
