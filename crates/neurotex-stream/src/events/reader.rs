//! Reading a stream's events: text lines (`t,x,y,p` or `t,taxel,p`, a header optional) or
//! 16-byte binary records, with ticks and `reset` between them, each item held until the
//! next shows it is in order.

use std::collections::VecDeque;
use std::io::{BufRead, ErrorKind};

use neurotex_core::events::{EventsFormat, Stamp};

use crate::error::{DataError, Result};
use crate::recording::TimeUnit;

use super::{EventInput, RECORD_BYTES};

/// How a stream's events are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventEncoding {
    /// Text lines, `t,x,y,p` or `t,taxel,p` (the polarity optional), with or without a
    /// header naming the columns; a line holding only a time is a tick, `reset` ends the
    /// episode.
    Text,
    /// Binary records of [`RECORD_BYTES`].
    Binary,
}

/// What the input holds next.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// An event (`address` the cell's two numbers and the polarity) or a tick (`None`).
    Event {
        /// The stamp, in the stream's unit.
        stamp: Stamp,
        /// The cell and polarity, `None` for a tick.
        address: Option<(i64, i64, Option<i64>)>,
    },
    /// The sender asked for the episode to end.
    Reset,
    /// An event that could not be decoded.
    Bad {
        /// Where it was: `line 12`, `record 7`.
        place: String,
        /// Why.
        why: String,
    },
}

/// The text columns, planned from the first line.
#[derive(Debug, Clone)]
struct TextColumns {
    /// The fields of every line but a tick's (a time alone), when the first line set them.
    fields: Option<usize>,
    delimiter: Option<u8>,
    time: usize,
    a: usize,
    b: Option<usize>,
    polarity: Option<usize>,
}

/// Decodes events from `input`, named `source` in messages.
pub struct EventReader<R> {
    input: R,
    source: String,
    encoding: EventEncoding,
    format: EventsFormat,
    columns: Option<TextColumns>,
    line: Vec<u8>,
    count: u64,
    /// The first event of a stream without a header, held until the next line with a cell
    /// shows whether it was whole, with what came between (ticks, resets, bad lines).
    held: Option<Held>,
    /// Items ready to be returned, in order.
    ready: VecDeque<Item>,
}

/// A headerless stream's first event, not yet known to be whole: a stream joined mid-line
/// starts with a line cut short, which may still read as an event of fewer fields.
#[derive(Debug)]
struct Held {
    /// The event, its line's place and fields.
    item: Item,
    place: String,
    fields: usize,
    /// The lines after it, before the next event.
    after: Vec<Item>,
}

impl<R: BufRead> EventReader<R> {
    /// A reader of `encoding` events whose columns `format` names.
    pub fn new(input: R, source: &str, encoding: EventEncoding, format: &EventsFormat) -> Self {
        EventReader {
            input,
            source: source.to_string(),
            encoding,
            format: format.clone(),
            columns: None,
            line: Vec::new(),
            count: 0,
            held: None,
            ready: VecDeque::new(),
        }
    }

    /// Where the last event was (`line 12`, `record 7`).
    pub fn place(&self) -> String {
        match self.encoding {
            EventEncoding::Text => format!("line {}", self.count),
            EventEncoding::Binary => format!("record {}", self.count),
        }
    }

    /// The next item; `None` at the end of the input or once `stop()` says so.
    ///
    /// # Errors
    /// The input cannot be read, or a header names no time column.
    pub fn next(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Item>> {
        match self.encoding {
            EventEncoding::Text => self.next_line(stop),
            EventEncoding::Binary => self.next_record(stop),
        }
    }

    fn next_record(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Item>> {
        let mut record = [0u8; RECORD_BYTES];
        let mut got = 0;
        while got < RECORD_BYTES {
            let available = match self.input.fill_buf() {
                Ok(bytes) => bytes,
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) => return Err(DataError::io(&self.source, e).into()),
            };
            if available.is_empty() || (got == 0 && stop()) {
                break;
            }
            let n = available.len().min(RECORD_BYTES - got);
            record[got..got + n].copy_from_slice(&available[..n]);
            self.input.consume(n);
            got += n;
        }
        if got == 0 {
            return Ok(None);
        }
        self.count += 1;
        if got < RECORD_BYTES {
            let why = format!("the input ended after {got} of its {RECORD_BYTES} bytes");
            return Ok(Some(Item::Bad {
                place: self.place(),
                why,
            }));
        }
        let t = i64::from_le_bytes(record[..8].try_into().expect("8 bytes"));
        let x = u16::from_le_bytes([record[8], record[9]]);
        let y = u16::from_le_bytes([record[10], record[11]]);
        let p = record[12] as i8;
        let stamp = Stamp::Int(t);
        Ok(Some(match record[13] {
            0 => Item::Event {
                stamp,
                address: Some((i64::from(x), i64::from(y), Some(i64::from(p)))),
            },
            1 => Item::Event {
                stamp,
                address: None,
            },
            2 => Item::Reset,
            kind => Item::Bad {
                place: self.place(),
                why: format!("kind {kind} is none of 0 (an event), 1 (a tick), 2 (the end)"),
            },
        }))
    }

    fn next_line(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Item>> {
        loop {
            if let Some(item) = self.ready.pop_front() {
                return Ok(Some(item));
            }
            let read = crate::frames::read_line(&mut self.input, &mut self.line, 4096, stop);
            let Some(length) = read.map_err(|e| DataError::io(&self.source, e))? else {
                match self.held.take() {
                    Some(held) => self.release(held, None),
                    None => return Ok(None),
                }
                continue;
            };
            self.count += 1;
            let place = format!("line {}", self.count);
            let bad = |why: String| Item::Bad {
                place: place.clone(),
                why,
            };
            let (item, fields) = if length > 4096 {
                (bad(format!("a {length}-byte line is no event")), 0)
            } else if let Ok(text) = std::str::from_utf8(&self.line) {
                let text = text.trim().to_string();
                if text.is_empty() || text.starts_with('#') {
                    continue;
                }
                if text.eq_ignore_ascii_case("reset") {
                    (Item::Reset, 0)
                } else if self.columns.is_none() {
                    match self.plan(&text)? {
                        Planned::Header(columns) => {
                            self.columns = Some(columns);
                            continue;
                        }
                        Planned::Skip(why) => (bad(why), 0),
                        Planned::Tick(tick) => (tick, 1),
                        Planned::First(columns, item, fields) => {
                            self.columns = Some(columns);
                            self.held = Some(Held {
                                item,
                                place,
                                fields,
                                after: Vec::new(),
                            });
                            continue;
                        }
                    }
                } else {
                    self.read_line_item(&text, &place)
                }
            } else {
                (bad("the line is not UTF-8 text".into()), 0)
            };
            match self.held.take() {
                Some(mut held) if fields < 2 => {
                    held.after.push(item);
                    self.held = Some(held);
                }
                Some(held) => self.release(held, Some((item, fields))),
                None => return Ok(Some(item)),
            }
        }
    }

    /// A line's item once the columns are planned, and its fields.
    fn read_line_item(&mut self, text: &str, place: &str) -> (Item, usize) {
        let columns = self.columns.as_mut().expect("planned");
        let (_, n) = split(text, columns.delimiter);
        let item = parse_line(text, columns).unwrap_or_else(|why| Item::Bad {
            place: place.to_string(),
            why,
        });
        // A line with more fields than the held first event, that reads with them: the
        // first was cut short, and the lines have this one's fields.
        let longer = self.held.as_ref().is_some_and(|h| n > h.fields);
        if longer && matches!(item, Item::Bad { .. }) {
            let mut wider = columns.clone();
            wider.fields = Some(n);
            if let Ok(item) = parse_line(text, &wider) {
                *columns = wider;
                return (item, n);
            }
        }
        (item, n)
    }

    /// Makes the held first event and what followed it ready, then `next` (the line with a
    /// cell that decided, and its fields): the first is a bad line when `next` has more.
    fn release(&mut self, held: Held, next: Option<(Item, usize)>) {
        let cut = next
            .as_ref()
            .is_some_and(|(item, n)| *n > held.fields && !matches!(item, Item::Bad { .. }));
        self.ready.push_back(match cut {
            true => Item::Bad {
                place: held.place,
                why: format!(
                    "{} fields, and the lines after it have {}: a line cut short, as when a stream is joined mid-line",
                    held.fields,
                    next.as_ref().map_or(0, |(_, n)| *n)
                ),
            },
            false => held.item,
        });
        self.ready.extend(held.after);
        self.ready.extend(next.map(|(item, _)| item));
    }

    /// The columns from the first line: a header names them (by the format's names),
    /// otherwise they are `t`, then `x` and `y` or the taxel, then the polarity, taken from
    /// the first line that reads as an event (held until the next shows it whole). A line
    /// that is neither (names and numbers mixed, an event that does not read) is skipped.
    ///
    /// # Errors
    /// A header without the time or cell columns.
    fn plan(&self, text: &str) -> Result<Planned> {
        let delimiter = [b',', b';', b'\t']
            .into_iter()
            .find(|d| text.as_bytes().contains(d));
        let (fields, n) = split(text, delimiter);
        let names = &fields[..n.min(fields.len())];
        let taxel = self.format.taxel.as_deref();
        let is_name = |f: &&str| {
            f.parse::<f64>().is_err() && !f.is_empty() && !f.chars().any(char::is_control)
        };
        if !names.iter().all(is_name) {
            let columns = TextColumns {
                fields: Some(n),
                delimiter,
                time: 0,
                a: 1,
                b: taxel.is_none().then_some(2),
                polarity: Some(if taxel.is_some() { 2 } else { 3 }),
            };
            let numbers = !names.iter().any(is_name);
            return Ok(match parse_line(text, &columns) {
                Ok(
                    item @ Item::Event {
                        address: Some(_), ..
                    },
                ) if numbers => Planned::First(columns, item, n),
                Ok(tick) if numbers => Planned::Tick(tick),
                Err(why) if numbers => Planned::Skip(format!(
                    "{why}; a first line cut short, as when a stream is joined mid-line"
                )),
                _ => Planned::Skip("neither a header nor an event".into()),
            });
        }
        let find = |name: &str| names.iter().position(|n| n.eq_ignore_ascii_case(name));
        let missing = |name: &str| {
            let why = format!(
                "line {}: the header {names:?} has no column `{name}`",
                self.count
            );
            crate::Error::from(DataError::invalid(&self.source, why))
        };
        let f = &self.format;
        let time = find(&f.time).ok_or_else(|| missing(&f.time))?;
        let (a, b) = match taxel {
            Some(t) => (find(t).ok_or_else(|| missing(t))?, None),
            None => (
                find(&f.x).ok_or_else(|| missing(&f.x))?,
                Some(find(&f.y).ok_or_else(|| missing(&f.y))?),
            ),
        };
        Ok(Planned::Header(TextColumns {
            fields: Some(n),
            delimiter,
            time,
            a,
            b,
            polarity: find(&f.polarity),
        }))
    }
}

/// What a text stream's first lines plan.
enum Planned {
    /// A header named the columns.
    Header(TextColumns),
    /// An event read by position, its item and fields.
    First(TextColumns, Item, usize),
    /// A tick (a time alone), which plans nothing.
    Tick(Item),
    /// The line is bad (why), and the columns are still to be planned.
    Skip(String),
}

/// The fields of `text` split at `delimiter` (at runs of spaces without one), trimmed;
/// the first eight, and how many there are.
pub(super) fn split(text: &str, delimiter: Option<u8>) -> ([&str; 8], usize) {
    let mut fields = [""; 8];
    let mut n = 0;
    let mut put = |field| {
        if let Some(slot) = fields.get_mut(n) {
            *slot = field;
        }
        n += 1;
    };
    match delimiter {
        Some(d) => text.split(char::from(d)).for_each(|f| put(f.trim_ascii())),
        None => text.split_ascii_whitespace().for_each(put),
    }
    (fields, n)
}

/// One line's event or tick; `Err` says why it is neither.
fn parse_line(text: &str, columns: &TextColumns) -> std::result::Result<Item, String> {
    let (fields, n) = split(text, columns.delimiter);
    if let Some(expected) = columns.fields.filter(|&e| n != e && n != 1) {
        return Err(format!("{n} fields; the stream's lines have {expected}"));
    }
    let get = |j: usize| fields.get(j).copied().filter(|f| !f.is_empty());
    let time = get(columns.time).ok_or("the line has no time")?;
    let stamp = match time.parse::<i64>() {
        Ok(t) => Stamp::Int(t),
        Err(_) => Stamp::Float(
            time.parse::<f64>()
                .map_err(|_| format!("time `{time}` is not a number"))?,
        ),
    };
    let number = |j: usize, what: &str| -> std::result::Result<Option<i64>, String> {
        get(j)
            .map(|f| {
                f.parse::<i64>().or_else(|_| match f.parse::<f64>() {
                    Ok(v) if v.fract() == 0.0 && v.abs() < 9e15 => Ok(v as i64),
                    _ => Err(format!("{what} `{f}` is not a whole number")),
                })
            })
            .transpose()
    };
    let a = number(columns.a, "the cell")?;
    let b = match columns.b {
        Some(j) => number(j, "y")?,
        None => a.map(|_| 0),
    };
    let p = match columns.polarity {
        Some(j) => number(j, "the polarity")?,
        None => None,
    };
    let address = match (a, b) {
        (Some(a), Some(b)) => Some((a, b, p)),
        (None, None) => None,
        _ => return Err("the line has half a cell (x without y, or y without x)".into()),
    };
    Ok(Item::Event { stamp, address })
}

impl<R: BufRead> EventInput for EventReader<R> {
    fn next_item(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Item>> {
        self.next(stop)
    }

    fn place(&self) -> String {
        EventReader::place(self)
    }

    fn unit(&self) -> TimeUnit {
        self.format.time_unit
    }
}

/// The event a marker string holds (`x,y,p`, `x,y`, `taxel,p` or `taxel` for a
/// `taxel`-addressed source), stamped `stamp` s; an empty string is a tick, `reset` the
/// episode's end.
pub(crate) fn marker_item(
    stamp: f64,
    text: &str,
    taxel: bool,
) -> std::result::Result<Item, String> {
    let text = text.trim();
    if text.eq_ignore_ascii_case("reset") {
        return Ok(Item::Reset);
    }
    let delimiter = [b',', b';', b'\t']
        .into_iter()
        .find(|d| text.as_bytes().contains(d));
    let line = match delimiter {
        Some(d) => format!("{stamp}{}{text}", char::from(d)),
        None => format!("{stamp} {text}"),
    };
    let columns = TextColumns {
        fields: None,
        delimiter,
        time: 0,
        a: 1,
        b: (!taxel).then_some(2),
        polarity: Some(if taxel { 2 } else { 3 }),
    };
    // The stamp as LSL gave it, not as its text reads back (`2` would be an integer).
    Ok(match parse_line(&line, &columns)? {
        Item::Event { address, .. } => Item::Event {
            stamp: Stamp::Float(stamp),
            address,
        },
        other => other,
    })
}
