//! Writing events as a CSV or `.npy` file an event dataset reads back.

use crate::values::TimeUnit;

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
