//! Reading a log's rows into samples and time stamps, and checking them: a plausible rate, no
//! gap over the limit, no time stamps among the channels.

use std::path::Path;

use crate::error::{ParamError, Result};

use super::choose::LogColumns;
use super::format::{CsvFormat, Delimiter, DuplicateStamps};
use super::header::{is_timelike_name, Columns, EPOCH_LIKE};
use super::{csv_error_after, excerpt, invalid, open_log, CsvLog};

/// Sampling rates a tactile log plausibly has, in Hz: stamps whose median step implies a
/// rate outside are most likely in another unit than assumed or named (seconds read as ms
/// give 1000 times the rate; a 1 kHz logger's microseconds read as ms give 1 Hz), so
/// unless the unit is given they are refused. The slowest taxel arrays used for texture
/// sample at tens of Hz (FabricSlide's at 35.7 Hz); 5 Hz leaves room below them and
/// still catches microsecond stamps of loggers up to 5 kHz.
pub const PLAUSIBLE_HZ: (f64, f64) = (5.0, 20_000.0);

/// Refuses stamps whose unit was assumed, or read from the time column's name, when their
/// median step implies a rate outside [`PLAUSIBLE_HZ`]: a name can say `_ms` of a logger
/// writing microseconds. A unit given (`--time-unit`) is taken as said.
fn check_plausible_rate(path: &Path, columns: &Columns, times: &[f64]) -> Result<()> {
    let (Some(t), false) = (columns.time, columns.unit_given) else {
        return Ok(());
    };
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return Ok(());
    }
    let mid = steps.len() / 2;
    let (_, &mut median, _) = steps.select_nth_unstable_by(mid, f64::total_cmp);
    let hz = 1.0 / (median * columns.unit.seconds());
    if (PLAUSIBLE_HZ.0..=PLAUSIBLE_HZ.1).contains(&hz) {
        return Ok(());
    }
    let median = format!("{median:.6}");
    let median = median.trim_end_matches('0').trim_end_matches('.');
    let (unit, fix) = match columns.unit_known {
        true => (
            format!("{}, as its name says", columns.unit),
            "say the unit with --time-unit ms, s or us (`time_unit` in layout.toml), which \
             overrides the name (and is taken as said, whatever rate it gives)",
        ),
        false => (
            columns.unit.to_string(),
            "say it with --time-unit ms, s or us (`time_unit` in layout.toml), or end the \
             column's name in `_ms`, `_s` or `_us`",
        ),
    };
    let message = format!(
        "time column `{}` steps by a median {median} {}, which is {hz:.1} Hz if its \
         stamps are in {unit}; a tactile log at that rate is unlikely, so the unit is \
         probably another: {fix}",
        excerpt(&columns.names[t]),
        columns.unit,
    );
    Err(invalid(path, message))
}

/// Refuses a gap between consecutive time stamps longer than `max_gap_s`.
fn check_gaps(path: &Path, log: &CsvLog, max_gap_s: f64) -> Result<()> {
    let Some(times) = &log.times else {
        return Ok(());
    };
    let scale = log.time_unit.seconds();
    let Some(i) = times
        .windows(2)
        .position(|w| (w[1] - w[0]) * scale > max_gap_s)
    else {
        return Ok(());
    };
    let message = format!(
        "time stamps jump by {} s between frames {} and {} (stamps {} and {} {}), beyond the \
         {max_gap_s} s that resampling may fill by interpolation: split the recording there, \
         or raise the limit (--max-gap-s, `max_gap_s` in layout.toml)",
        (times[i + 1] - times[i]) * scale,
        i + 1,
        i + 2,
        times[i],
        times[i + 1],
        log.time_unit,
    );
    Err(invalid(path, message))
}

/// Refuses a log read without a time column whose first channel is named like a time
/// column (`t`, `time...`, `...stamp...`) and rises on every row: it is its stamps, and
/// read as one more taxel it would put a ramp on a cell and leave the rate unknown.
fn check_no_stamps_among_channels(
    path: &Path,
    format: &CsvFormat,
    columns: &Columns,
    log: &CsvLog,
) -> Result<()> {
    let n = columns.channels.len();
    if columns.time.is_some() || n < 2 || log.samples.len() < 3 * n {
        return Ok(());
    }
    let column = columns.channels[0];
    let name = match format.header {
        true => columns.names[column].clone(),
        false => column.to_string(),
    };
    let timelike = format.header && is_timelike_name(&name);
    let first = log.samples.iter().step_by(n);
    let rising = first.clone().zip(first.skip(1)).all(|(a, b)| b > a);
    // A host's clock since the Unix epoch: 1.7e9 s, 1.7e12 ms, 1.7e15 us; no taxel reads
    // that much while rising on every row.
    let epoch = log.samples[0] >= EPOCH_LIKE;
    if !(rising && (timelike || epoch)) {
        return Ok(());
    }
    let why = match timelike {
        true => "is named like time stamps and rises on every row".to_string(),
        false => format!(
            "rises on every row from {}, like a clock's stamps since an epoch",
            log.samples[0]
        ),
    };
    let message = format!(
        "column `{}` {why}, but no time column was chosen, so it would be read as a taxel: \
         name it as the time column (`import csv --time-column {}`, or `time_column = \"{}\"` \
         in the layout.toml given with these files, with its unit if it is not ms), or \
         choose the taxel columns (`--channels`, or `channels` in the layout)",
        excerpt(&name),
        excerpt(&name),
        excerpt(&name),
    );
    Err(invalid(path, message))
}

/// Reads a CSV log as `format` says. Every cell must be a finite number; time stamps must
/// not decrease, and rows sharing one are handled as [`DuplicateStamps`] says. Errors name
/// the file, the line and the column.
///
/// # Errors
/// An unreadable or malformed file, a missing column, a cell that is not a finite number,
/// a time stamp that goes back, a repeated stamp under `error`, or no data rows.
pub fn read_csv_log(path: &Path, format: &CsvFormat) -> Result<CsvLog> {
    if !(format.max_gap_s.is_finite() && format.max_gap_s > 0.0) {
        let rule = "the largest gap between stamps must be a positive number of s";
        return Err(ParamError::new("max-gap-s", rule, format.max_gap_s).into());
    }
    let (mut reader, delimiter, names) = open_log(path, format)?;
    if names.is_empty() {
        return Err(invalid(path, "the file is empty"));
    }
    let columns = Columns::find(path, format, names)?;
    let mut rows = RowReader::new(path, &columns, format.duplicate_stamps);
    let mut record = csv::ByteRecord::new();
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => rows.push(&record)?,
            Err(e) => {
                let first = if format.header {
                    "the header"
                } else {
                    "line 1"
                };
                return Err(csv_error_after(path, e, first));
            }
        }
    }
    let log = rows.finish(delimiter, format);
    if log.samples.is_empty() {
        return Err(invalid(path, "no data rows"));
    }
    if let Some(times) = &log.times {
        check_plausible_rate(path, &columns, times)?;
        check_gaps(path, &log, format.max_gap_s)?;
    }
    check_no_stamps_among_channels(path, format, &columns, &log)?;
    Ok(log)
}

/// Folds rows into frames: the rows of one time stamp are kept (exact duplicates left out)
/// until the stamp changes, then become one frame.
struct RowReader<'a> {
    path: &'a Path,
    columns: &'a Columns,
    policy: DuplicateStamps,
    samples: Vec<f64>,
    times: Option<Vec<f64>>,
    /// The distinct rows of the current stamp, `channels` values each, and where the first
    /// is (its byte and its reader's line).
    group: Vec<f64>,
    group_at: (u64, u64),
    stamp: Option<f64>,
    row: Vec<f64>,
    merged_rows: usize,
    duplicate_rows: usize,
}

impl<'a> RowReader<'a> {
    fn new(path: &'a Path, columns: &'a Columns, policy: DuplicateStamps) -> Self {
        RowReader {
            path,
            columns,
            policy,
            samples: Vec::new(),
            times: columns.time.map(|_| Vec::new()),
            group: Vec::new(),
            group_at: (0, 0),
            stamp: None,
            row: Vec::with_capacity(columns.channels.len()),
            merged_rows: 0,
            duplicate_rows: 0,
        }
    }

    /// The line in the file of the record at byte `start` (its CSV reader's `line` can be
    /// one short): for error messages.
    fn line_of(&self, (start, line): (u64, u64)) -> u64 {
        super::record_line(self.path, start).unwrap_or(line)
    }

    fn parse(&self, record: &csv::ByteRecord, at: (u64, u64), j: usize) -> Result<f64> {
        let raw = record.get(j).unwrap_or(b"");
        std::str::from_utf8(raw)
            .ok()
            .and_then(|s| s.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                invalid(
                    self.path,
                    format!(
                        "line {}, column `{}`: expected a finite number, got `{}`",
                        self.line_of(at),
                        excerpt(&self.columns.names[j]),
                        excerpt(&String::from_utf8_lossy(raw))
                    ),
                )
            })
    }

    fn push(&mut self, record: &csv::ByteRecord) -> Result<()> {
        let at = record.position().map_or((0, 0), |p| (p.byte(), p.line()));
        self.row.clear();
        for k in 0..self.columns.channels.len() {
            let v = self.parse(record, at, self.columns.channels[k])?;
            if !crate::values::sample_in_range(v) {
                let name = excerpt(&self.columns.names[self.columns.channels[k]]);
                let (rule, line) = (crate::values::SAMPLE_RULE, self.line_of(at));
                let message =
                    format!("line {line}, column `{name}`: {v:?} is out of range ({rule})");
                return Err(invalid(self.path, message));
            }
            self.row.push(v);
        }
        let Some(j) = self.columns.time else {
            self.samples.extend_from_slice(&self.row);
            return Ok(());
        };
        let t = self.parse(record, at, j)?;
        match self.stamp {
            Some(prev) if t < prev => Err(invalid(
                self.path,
                format!(
                    "line {}: time stamps must not go back, got {t} after {prev}",
                    self.line_of(at)
                ),
            )),
            Some(prev) if t == prev => self.same_stamp(t, at),
            _ => {
                self.flush();
                self.stamp = Some(t);
                self.group_at = at;
                self.group.extend_from_slice(&self.row);
                Ok(())
            }
        }
    }

    /// Another row at the current stamp: dropped when it repeats one exactly, else kept
    /// for the frame (or an error under `error`).
    fn same_stamp(&mut self, t: f64, at: (u64, u64)) -> Result<()> {
        let n = self.row.len();
        if self.group.chunks_exact(n).any(|g| g == self.row.as_slice()) {
            self.duplicate_rows += 1;
            return Ok(());
        }
        if self.policy == DuplicateStamps::Error {
            let message = format!(
                "line {}: time stamp {t} repeats line {} with other values (--duplicate-stamps average, first or last merges such rows)",
                self.line_of(at),
                self.line_of(self.group_at)
            );
            return Err(invalid(self.path, message));
        }
        self.merged_rows += 1;
        self.group.extend_from_slice(&self.row);
        Ok(())
    }

    /// The current stamp's rows become one frame.
    fn flush(&mut self) {
        let n = self.columns.channels.len();
        let k = self.group.len() / n.max(1);
        if k == 0 {
            return;
        }
        match self.policy {
            DuplicateStamps::First | DuplicateStamps::Error => {
                self.samples.extend_from_slice(&self.group[..n])
            }
            DuplicateStamps::Last => self.samples.extend_from_slice(&self.group[(k - 1) * n..]),
            DuplicateStamps::Average => self.samples.extend(
                (0..n).map(|c| (0..k).map(|r| self.group[r * n + c]).sum::<f64>() / k as f64),
            ),
        }
        if let (Some(times), Some(t)) = (self.times.as_mut(), self.stamp) {
            times.push(t);
        }
        self.group.clear();
    }

    fn finish(mut self, delimiter: Delimiter, format: &CsvFormat) -> CsvLog {
        self.flush();
        let c = self.columns;
        let name = |j: usize| match format.header {
            true => c.names[j].clone(),
            false => j.to_string(),
        };
        let columns = LogColumns {
            header: Some(format.header),
            delimiter: Some(delimiter),
            time_column: c.time.map(name),
            time_unit: c.time.map(|_| c.unit),
            channels: Some(c.channels.iter().map(|&j| name(j)).collect()),
            duplicate_stamps: Some(format.duplicate_stamps),
        };
        CsvLog {
            columns,
            channel_names: self
                .columns
                .channels
                .iter()
                .map(|&j| self.columns.names[j].clone())
                .collect(),
            samples: self.samples,
            times: self.times,
            time_unit: self.columns.unit,
            merged_rows: self.merged_rows,
            duplicate_rows: self.duplicate_rows,
            delimiter,
        }
    }
}
