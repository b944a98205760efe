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

use serde::{Deserialize, Serialize};

pub use crate::error::EventError;
use crate::error::Result;
use crate::values::TimeUnit;

mod read;
mod summary;
mod write;

pub use read::read_events;
pub(crate) use read::{parse, place, Gather, Parsed};
pub use summary::{CellEvents, EventSummary};
pub use write::{write_events, Event, EventFile};

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
    pub fn is_on(&self, p: Option<i64>) -> Result<bool, EventError> {
        let [on, off] = self.values;
        match p {
            None => Ok(true),
            Some(v) if v == on => Ok(true),
            Some(v) if v == off => Ok(false),
            Some(value) => Err(EventError::Polarity { value, on, off }),
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
    pub fn cell(&self, taxel: bool, (a, b): (i64, i64)) -> Result<usize, EventError> {
        let g = self;
        let (row, col) = match taxel {
            true => {
                let cell = usize::try_from(a)
                    .ok()
                    .and_then(|i| g.taxels.get(i))
                    .ok_or(EventError::TaxelOutside {
                        taxel: a,
                        taxels: g.taxels.len(),
                    })?;
                (cell / g.cols, cell % g.cols)
            }
            false => {
                let inside = |v: i64, n: usize| usize::try_from(v).ok().filter(|&v| v < n);
                match (inside(b, g.rows), inside(a, g.cols)) {
                    (Some(r), Some(c)) => (r, c),
                    _ => {
                        return Err(EventError::OutsideGrid {
                            x: a,
                            y: b,
                            rows: g.rows,
                            cols: g.cols,
                        })
                    }
                }
            }
        };
        let cell = row * g.cols + col;
        if !g.present[cell] {
            return Err(EventError::Masked { row, col });
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
    pub fn step_from(self, from: Stamp, unit: TimeUnit) -> Result<u64, EventError> {
        to_step(self, from, unit)
    }
}

impl std::fmt::Display for Stamp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&show(*self))
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
fn to_step(t: Stamp, from: Stamp, unit: TimeUnit) -> Result<u64, EventError> {
    let before = || EventError::BeforeStart { time: show(t) };
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
                return Err(EventError::NotFinite { time: show(t) });
            }
            let ms = d * unit.seconds() * 1000.0;
            if ms < -BOUNDARY_TOLERANCE_MS {
                return Err(before());
            }
            Ok((ms + BOUNDARY_TOLERANCE_MS).floor().max(0.0) as u64)
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
