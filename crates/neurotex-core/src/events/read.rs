//! Reading an event file, CSV or `.npy`: its columns found, each event checked (time order,
//! cell, polarity, duration) and gathered into spike trains.

use std::path::Path;

use crate::error::{DataError, Result};
use crate::npy::{read_data, read_header, NpyField};
use crate::values::TimeUnit;

use super::{show, to_step, EventGrid, Events, EventsFormat, Origin, Stamp, StepLimit};

/// The columns of one file, as indices into a record's values.
pub(super) struct Columns {
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
        let trains = match self.format.is_on(p).map_err(|e| e.to_string())? {
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
        let step = to_step(t, from, self.format.time_unit).map_err(|e| e.to_string())?;
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
        self.grid
            .cell(self.format.taxel.is_some(), at)
            .map_err(|e| e.to_string())
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
        /// The CSV record's first byte (its line, the header's being 1, is found from it
        /// for a message: [`place`]) or the `.npy` record (0-based).
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
pub(super) fn columns(names: &[&str], format: &EventsFormat) -> Result<Columns, String> {
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

pub(super) fn parse_csv(
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
            let why = crate::csvlog::csv_words(&e, "the header", path);
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
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) if e.is_io_error() => return Err(crate::csvlog::csv_error(path, e)),
            Err(e) => return Err(bad(crate::csvlog::csv_words(&e, "the header", path))),
        }
        // Where the record starts; its line is found from it for a message.
        let byte = record.position().map_or(0, |p| p.byte() as usize);
        let at = |m: String| bad(format!("{}: {m}", place(path, byte)));
        let (t, cell, p) = csv_event(&record, &cols).map_err(at)?;
        sink(Parsed::Event {
            t,
            cell,
            p,
            at: byte,
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

/// Where event `at` of a [`Parsed::Event`] is, as the messages say it: the `.npy` record,
/// or the CSV line (read again from the file up to the record's byte).
pub(crate) fn place(path: &Path, at: usize) -> String {
    let npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    if npy {
        return format!("event {at} (0-based)");
    }
    match crate::csvlog::record_line(path, at as u64) {
        Some(line) => format!("line {line}"),
        None => format!("the line at byte {at}"),
    }
}
