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
//! sorts logs whose events are out of order as it copies them.

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

/// One event as read: its time in the file's unit (exact for integers) and its fields.
#[derive(Debug, Clone, Copy)]
enum Stamp {
    Int(i64),
    Float(f64),
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

/// Gathers events into trains, checking each as it comes.
struct Gather<'a> {
    format: &'a EventsFormat,
    grid: &'a EventGrid,
    max_steps: u64,
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
    fn new(
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
            max_steps,
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
    fn push(&mut self, t: Stamp, cell: (i64, i64), p: Option<i64>) -> Result<(), String> {
        let step = self.step(t)?;
        let cell = self.cell(cell)?;
        let trains = match p {
            None => &mut self.on,
            Some(v) if v == self.format.values[0] => &mut self.on,
            Some(v) if v == self.format.values[1] => self
                .off
                .as_mut()
                .expect("a polarity column gives OFF trains"),
            Some(v) => {
                let [on, off] = self.format.values;
                return Err(format!(
                    "polarity {v} is neither ON ({on}) nor OFF ({off}); layout.toml's `[events] values = [on, off]` names them"
                ));
            }
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
                if ms < self.duration.unwrap_or(self.max_steps) {
                    self.last = Some(Stamp::Int(t));
                    self.last_step = Some(self.last_step.map_or(ms, |s| s.max(ms)));
                    return Ok(ms);
                }
            }
        }
        if let Some(last) = self.last {
            let back = match (last, t) {
                (Stamp::Int(a), Stamp::Int(b)) => b < a,
                (a, b) => as_f64(b) < as_f64(a),
            };
            if back {
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
        let limit = self.duration.unwrap_or(self.max_steps);
        if step >= limit {
            return Err(match self.duration {
                Some(d) => format!(
                    "time {} is at {step} ms, past the recording's duration_s ({d} ms) in the manifest",
                    show(t)
                ),
                None => format!(
                    "time {} is at {step} ms, past the longest recording accepted ({} s, layout.toml's max_duration_s): a clock's stamps need `origin = \"first\"`, or the time unit is wrong",
                    show(t),
                    self.max_steps / 1000
                ),
            });
        }
        self.last_step = Some(self.last_step.map_or(step, |s| s.max(step)));
        Ok(step)
    }

    /// The event's cell (row-major index), checked against the grid and its mask.
    fn cell(&self, (a, b): (i64, i64)) -> Result<usize, String> {
        let g = self.grid;
        let (row, col) = match self.format.taxel {
            Some(_) => {
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
            None => {
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

    fn finish(self) -> Events {
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

fn as_f64(t: Stamp) -> f64 {
    match t {
        Stamp::Int(v) => v as f64,
        Stamp::Float(v) => v,
    }
}

fn show(t: Stamp) -> String {
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
            "time {} is before the recording's start: stamps from a clock need layout.toml's `[events] origin = \"first\"`",
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
        Parsed::Columns { polarity } => {
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
enum Parsed {
    Columns {
        polarity: bool,
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
fn parse(
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
                "no column `{name}` (it has {}); layout.toml's [events] table names the columns",
                names.join(", ")
            )
        })
    };
    let cell = match &format.taxel {
        Some(taxel) => CellColumns::Taxel(need(taxel)?),
        None => CellColumns::Xy(need(&format.x)?, need(&format.y)?),
    };
    Ok(Columns {
        time: need(&format.time)?,
        cell,
        polarity: find(&format.polarity),
    })
}

fn parse_csv(
    path: &Path,
    format: &EventsFormat,
    sink: &mut impl FnMut(Parsed) -> Result<(), String>,
) -> Result<()> {
    let bad = |m: String| -> crate::Error { DataError::invalid(path, m).into() };
    let file = std::fs::File::open(path).map_err(|e| DataError::io(path, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(false)
        .from_reader(std::io::BufReader::with_capacity(1 << 16, file));
    let header = reader
        .byte_headers()
        .map_err(|e| bad(format!("not a CSV file with a header row: {e}")))?
        .clone();
    let names: Vec<&str> = header
        .iter()
        .map(|h| std::str::from_utf8(h).unwrap_or(""))
        .collect();
    let cols = columns(&names, format).map_err(bad)?;
    sink(Parsed::Columns {
        polarity: cols.polarity.is_some(),
    })
    .map_err(bad)?;
    let mut record = csv::ByteRecord::new();
    let mut line = 1usize;
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(bad(format!("line {}: {e}", line + 1))),
        }
        line += 1;
        let at = |m: String| bad(format!("line {line}: {m}"));
        let field = |i: usize| std::str::from_utf8(&record[i]).unwrap_or("").trim();
        let int = |i: usize, what: &str| -> Result<i64> {
            field(i)
                .parse::<i64>()
                .or(match field(i) {
                    "True" | "true" => Ok(1),
                    "False" | "false" => Ok(0),
                    _ => Err(()),
                })
                .map_err(|_| at(format!("{what} `{}` is not an integer", field(i))))
        };
        let t = match field(cols.time).parse::<i64>() {
            Ok(v) => Stamp::Int(v),
            Err(_) => Stamp::Float(
                field(cols.time)
                    .parse::<f64>()
                    .map_err(|_| at(format!("time `{}` is not a number", field(cols.time))))?,
            ),
        };
        let cell = match cols.cell {
            CellColumns::Xy(x, y) => (int(x, "x")?, int(y, "y")?),
            CellColumns::Taxel(i) => (int(i, "taxel")?, 0),
        };
        let p = cols.polarity.map(|i| int(i, "polarity")).transpose()?;
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
fn place(path: &Path, at: usize) -> String {
    let npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    match npy {
        true => format!("event {at} (0-based)"),
        false => format!("line {at}"),
    }
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
}

/// Options of [`import_events`].
#[derive(Debug, Clone)]
pub struct EventImportParams {
    /// Metadata from file names; without it the label is the file stem.
    pub pattern: Option<crate::import::NamePattern>,
    /// How the logs are read.
    pub format: EventsFormat,
    /// The sensor's grid (and, for a taxel column, each taxel's cell).
    pub grid: EventGrid,
}

/// The `.csv` and `.npy` files among `inputs` (folders are searched one level deep),
/// sorted.
///
/// # Errors
/// An input that does not exist or a folder that cannot be read.
pub fn event_files(inputs: &[std::path::PathBuf]) -> Result<Vec<std::path::PathBuf>> {
    let mut out = Vec::new();
    let wanted = |p: &Path| {
        p.extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("csv") || x.eq_ignore_ascii_case("npy"))
    };
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|e| DataError::io(input, e))?;
            for e in entries {
                let path = e.map_err(|e| DataError::io(input, e))?.path();
                if wanted(&path) {
                    out.push(path);
                }
            }
        } else if input.is_file() {
            out.push(input.clone());
        } else {
            return Err(DataError::invalid(input, "does not exist").into());
        }
    }
    out.sort();
    Ok(out)
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
    let read: Vec<(crate::recording::Meta, String, ImportedFile)> = files
        .par_iter()
        .map(|f| {
            let meta = crate::import::meta_from_name(f, p.pattern.as_ref())?;
            let (text, summary) = sorted_log(f, p)?;
            on_done();
            Ok((meta, text, summary))
        })
        .collect::<Result<_>>()?;
    crate::recording::create_dataset_dir(out, |dir| {
        let mut metas = Vec::new();
        let mut summaries = Vec::new();
        for (meta, text, summary) in read {
            let path = dir.join(&summary.file);
            std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
            metas.push(crate::recording::Meta {
                file: summary.file.clone(),
                ..meta
            });
            summaries.push(summary);
        }
        crate::recording::write_manifest(dir, &metas)?;
        crate::recording::write_layout(dir, &imported_layout(p))?;
        crate::recording::Dataset::open(dir)?;
        Ok(summaries)
    })
}

/// The layout an import writes: the grid, its mask, and the columns it writes.
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
        events: Some(EventsFormat {
            values: p.format.values,
            origin: p.format.origin,
            ..EventsFormat::new(p.format.time_unit)
        }),
        ..Default::default()
    }
}

/// An event as parsed: time, cell fields, polarity, and its line or record.
type RawEvent = (Stamp, (i64, i64), Option<i64>, usize);

/// One log's events in time order as the CSV text an import writes, and what was done.
fn sorted_log(path: &Path, p: &EventImportParams) -> Result<(String, ImportedFile)> {
    let mut events: Vec<RawEvent> = Vec::new();
    let mut polarity = false;
    parse(path, &p.format, &mut |event| {
        match event {
            Parsed::Columns { polarity: has } => polarity = has,
            Parsed::Event { t, cell, p, at } => events.push((t, cell, p, at)),
        }
        Ok(())
    })?;
    let key = |t: &Stamp| as_f64(*t);
    let mut reordered = 0;
    let mut latest = f64::NEG_INFINITY;
    for (t, ..) in &events {
        let v = key(t);
        if v < latest {
            reordered += 1;
        }
        latest = latest.max(v);
    }
    if reordered > 0 {
        events.sort_by(|a, b| match (a.0, b.0) {
            (Stamp::Int(x), Stamp::Int(y)) => x.cmp(&y),
            (x, y) => key(&x).total_cmp(&key(&y)),
        });
    }
    let max_steps = (crate::recording::DEFAULT_MAX_DURATION_S * 1000.0) as u64;
    let mut gather = Gather::new(&p.format, &p.grid, polarity, None, max_steps);
    let name = format!(
        "{}.csv",
        path.file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned())
    );
    let mut text = String::from(if polarity { "t,x,y,p\n" } else { "t,x,y\n" });
    for &(t, cell, pol, at) in &events {
        let named = |m: String| -> crate::Error {
            DataError::invalid(path, format!("{}: {m}", place(path, at))).into()
        };
        gather.push(t, cell, pol).map_err(named)?;
        let c = gather.cell(cell).map_err(named)?;
        use std::fmt::Write as _;
        let _ = write!(text, "{},{},{}", show(t), c % p.grid.cols, c / p.grid.cols);
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
        },
    ))
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
