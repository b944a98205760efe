//! A live stream's frames decoded from bytes, and fed to a [`StreamClassifier`]: CSV lines
//! (a header, or none; the fields split by the `csv` crate, the delimiter detected as a
//! CSV log's is) or raw records of little-endian `f32` values (optionally after an `f64`
//! stamp). The front ends open the input (a file, standard input, a socket) and print what
//! the stream decides; everything between is here, so the binary and any other front end
//! read frames alike.
//!
//! A frame that cannot be decoded is a bad frame: counted, reported to the caller, and
//! skipped, as a frame the classifier refuses is; so is a line before the columns are
//! planned that is neither a header nor a frame (garbage, or a frame cut short: a stream
//! joined mid-line). Only what makes the rest of the input unreadable is an error: a
//! header whose columns do not fit the model, frames that fit no columns (their second
//! line), an input that ends with nothing planned, a failing read.

use std::io::{BufRead, ErrorKind, Read};
use std::path::Path;
use std::time::{Duration, Instant};

use serde_json::Value;

use super::{bin_json, end_json, Event, StreamClassifier, StreamError};
use crate::csvlog::{choose_columns, detect_delimiter_in, Columns, CsvFormat, Delimiter};
use crate::error::{DataError, Result};
use crate::recording::TimeUnit;

/// How frames are written on the input.
#[derive(Debug, Clone)]
pub enum FrameFormat {
    /// Text, one frame per line; `reset` on a line of its own ends the episode. The lines
    /// are read in the first of these formats whose columns the first line holds and fit
    /// the model (a model's training layout, its raw logs' columns, then the defaults).
    Csv(Vec<CsvFormat>),
    /// Records of one `f32` per taxel, little-endian, after an `f64` stamp in `unit` when
    /// `stamped`; a record of NaN values ends the episode.
    F32le {
        /// Whether each record starts with its stamp.
        stamped: bool,
        /// The stamps' unit.
        unit: TimeUnit,
    },
}

/// What the input holds next.
#[derive(Debug, PartialEq)]
pub enum Frame<'a> {
    /// One frame: its stamp (in `unit`) when it has one, and one value per taxel.
    Values {
        /// The stamp, as written.
        stamp: Option<f64>,
        /// The stamp's unit.
        unit: TimeUnit,
        /// One value per taxel, in the model's channel order.
        values: &'a [f64],
    },
    /// The sender asked for the episode to end.
    Reset,
    /// A frame that could not be decoded, to be counted and skipped.
    Bad {
        /// Where it was: `line 12`, `frame 7`.
        place: String,
        /// Why it could not be decoded.
        why: String,
    },
}

/// The longest CSV line taken, bytes, for `channels` taxels: 64 bytes a taxel (the longest
/// f64 text, `-2.2250738585072014e-308`, has 24 characters; the rest leaves room for
/// spaces, a time column and a few unselected ones), and at least 1 MiB for headers.
pub fn line_limit(channels: usize) -> usize {
    channels.saturating_mul(64).max(1 << 20)
}

/// Decodes frames of `channels` values from `input`, named `source` in messages.
pub struct FrameReader<R> {
    input: R,
    source: String,
    format: FrameFormat,
    channels: usize,
    /// The CSV delimiter and columns, planned from the first line.
    plan: Option<(Delimiter, Columns)>,
    line: Vec<u8>,
    /// The CSV splitter (quotes honoured), built once the delimiter is known, and the
    /// bytes of the field it is reading.
    splitter: Option<csv_core::Reader>,
    field: Vec<u8>,
    fields: Vec<f64>,
    values: Vec<f64>,
    /// Lines (CSV) or records (f32le) read so far.
    count: u64,
    /// Why the first line skipped before the columns were planned was bad, and whether a
    /// line of numbers was skipped then (one cut short: a stream joined mid-line).
    skipped: Option<String>,
    cut_skipped: bool,
}

impl<R: BufRead> FrameReader<R> {
    /// A reader of `format` frames of `channels` values (the model's taxels).
    pub fn new(input: R, source: &str, format: FrameFormat, channels: usize) -> Self {
        FrameReader {
            input,
            source: source.to_string(),
            format,
            channels,
            plan: None,
            line: Vec::new(),
            splitter: None,
            field: Vec::new(),
            fields: Vec::new(),
            values: vec![0.0; channels],
            count: 0,
            skipped: None,
            cut_skipped: false,
        }
    }

    /// The next frame; `None` at the end of the input, or once `stop()` says so (checked
    /// while waiting for bytes, so a line that never ends does not hold the stream).
    ///
    /// # Errors
    /// The input cannot be read; a CSV header's columns do not fit the model, nor do two
    /// lines of numbers before the columns are planned; the input ends with none planned.
    pub fn next(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Frame<'_>>> {
        match self.format {
            FrameFormat::Csv(_) => self.next_csv(stop),
            FrameFormat::F32le { stamped, unit } => self.next_record(stamped, unit, stop),
        }
    }

    fn read_error(&self, e: std::io::Error) -> crate::Error {
        DataError::io(&self.source, e).into()
    }

    fn next_csv(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Frame<'_>>> {
        let FrameFormat::Csv(formats) = &self.format else {
            unreachable!("next_csv reads CSV frames only")
        };
        let limit = line_limit(self.channels);
        loop {
            let read = read_line(&mut self.input, &mut self.line, limit, stop);
            let Some(length) = read.map_err(|e| self.read_error(e))? else {
                return self.ended_unplanned();
            };
            self.count += 1;
            let text = match (length > limit, std::str::from_utf8(&self.line)) {
                (true, _) => Err(format!(
                    "the line is longer than a frame of {} values may be ({length} bytes, at most {limit})",
                    self.channels
                )),
                (false, Err(e)) => Err(format!(
                    "the line is not UTF-8 text (its byte {} is not valid UTF-8)",
                    e.valid_up_to() + 1
                )),
                (false, Ok(text)) => Ok(text.trim()),
            };
            let text = match text {
                Ok(text) => text,
                Err(why) => {
                    if self.plan.is_none() {
                        self.skipped.get_or_insert_with(|| why.clone());
                    }
                    let place = self.place();
                    return Ok(Some(Frame::Bad { place, why }));
                }
            };
            if text.is_empty() || text.starts_with('#') {
                continue;
            }
            if text.eq_ignore_ascii_case("reset") {
                return Ok(Some(Frame::Reset));
            }
            if self.plan.is_none() {
                let (header, delimiter, columns) = match self.plan_columns(formats, text) {
                    Ok(plan) => plan,
                    Err(e) => {
                        let (why, numbers) = self.unplanned(formats, text, e)?;
                        self.cut_skipped |= numbers;
                        self.skipped.get_or_insert_with(|| why.clone());
                        let place = self.place();
                        return Ok(Some(Frame::Bad { place, why }));
                    }
                };
                let splitter = csv_core::ReaderBuilder::new()
                    .delimiter(delimiter.byte())
                    .build();
                (self.plan, self.splitter) = (Some((delimiter, columns)), Some(splitter));
                if header {
                    continue;
                }
            }
            let (_, columns) = self.plan.as_ref().expect("planned above");
            let splitter = self.splitter.as_mut().expect("built with the plan");
            let (field, fields) = (&mut self.field, &mut self.fields);
            let parsed = parse_fields(splitter, text, columns.names.len(), field, fields);
            if let Err(why) = parsed {
                let place = self.place();
                return Ok(Some(Frame::Bad { place, why }));
            }
            let stamp = columns.time.map(|j| self.fields[j]);
            for (v, &j) in self.values.iter_mut().zip(&columns.channels) {
                *v = self.fields[j];
            }
            let unit = columns.unit;
            return Ok(Some(Frame::Values {
                stamp,
                unit,
                values: &self.values,
            }));
        }
    }

    /// Why a line read before the columns were planned, which plans none, is a bad frame,
    /// and whether it is a line of numbers: a stream joined mid-line starts with a frame
    /// cut short, and a sender may start with a garbled line. A line of names (a header
    /// whose columns do not fit the model) is an error, as is a second line of numbers
    /// that fits no columns (the frames themselves do not fit).
    ///
    /// # Errors
    /// `planning`'s error, at the line read.
    fn unplanned(
        &self,
        formats: &[CsvFormat],
        text: &str,
        planning: crate::Error,
    ) -> Result<(String, bool)> {
        let message = match planning {
            crate::Error::Data(DataError::Invalid { message, .. }) => message,
            other => other.to_string(),
        };
        let kind = line_kind(text);
        let header = kind == LineKind::Names && formats.iter().any(|f| f.header);
        if header || (kind == LineKind::Numbers && self.cut_skipped) {
            let message = format!("{}: {message}", self.place());
            return Err(DataError::invalid(&self.source, message).into());
        }
        let why = match kind {
            LineKind::Numbers => {
                format!("a line of numbers no columns fit, taken for a frame cut short ({message})")
            }
            _ => format!("neither a header nor a frame ({message})"),
        };
        Ok((why, kind == LineKind::Numbers))
    }

    /// The end of the input: an error when lines were skipped and none planned the
    /// columns (nothing of the input was read).
    fn ended_unplanned(&self) -> Result<Option<Frame<'static>>> {
        match (&self.plan, &self.skipped) {
            (None, Some(why)) => {
                let message = format!(
                    "the input ended after {} lines, none of them a header or frame of the model's columns; the first was skipped as {why}",
                    self.count
                );
                Err(DataError::invalid(&self.source, message).into())
            }
            _ => Ok(None),
        }
    }

    /// The header flag, delimiter and columns from the first line (the header, or the
    /// first frame), of the first format whose columns it holds and fit the model's taxels.
    fn plan_columns(
        &self,
        formats: &[CsvFormat],
        text: &str,
    ) -> Result<(bool, Delimiter, Columns)> {
        let delimiter = |format: &CsvFormat| {
            format
                .delimiter
                .unwrap_or_else(|| detect_delimiter_in(&[text]))
        };
        let names = |format: &CsvFormat| {
            let mut splitter = csv_core::ReaderBuilder::new()
                .delimiter(delimiter(format).byte())
                .build();
            let mut names = Vec::new();
            for_each_field(&mut splitter, text, &mut Vec::new(), |f| {
                names.push(String::from_utf8_lossy(f).into_owned());
                true
            });
            if !format.header {
                names = (0..names.len()).map(|j| format!("column{j}")).collect();
            }
            Ok(names)
        };
        let fits = |columns: &Columns| {
            let first = columns.channels.first().map(|&c| columns.names[c].as_str());
            if let (None, Some(name)) = (columns.time, first) {
                if crate::csvlog::is_timelike_name(name) {
                    return Err(format!("column `{name}` is named like time stamps but would be read as a taxel: name it with --time-column (and --time-unit), or choose the taxels with --channels"));
                }
            }
            match columns.channels.len() == self.channels {
                true => Ok(()),
                false => Err(format!(
                    "{} channel columns selected, the model has {} taxels",
                    columns.channels.len(),
                    self.channels
                )),
            }
        };
        // A first line of numbers is a frame, not a header (a sensor at rest sends zeros),
        // unless it is the column indices 0, 1, 2, ... that pandas writes as a header.
        let numeric_frame = {
            let fields = names(&formats[0]).unwrap_or_default();
            let numbers: Vec<Option<f64>> = fields.iter().map(|f| f.trim().parse().ok()).collect();
            let indices = (0..numbers.len()).all(|j| numbers[j] == Some(j as f64));
            numbers.iter().all(Option::is_some) && !indices
        };
        let headerless: Vec<CsvFormat>;
        let formats = match numeric_frame && formats.iter().any(|f| f.header) {
            true => {
                headerless = (formats.iter())
                    .map(|f| CsvFormat {
                        header: false,
                        ..f.clone()
                    })
                    .collect();
                &headerless[..]
            }
            false => formats,
        };
        let path = Path::new(&self.source);
        let (i, columns) = choose_columns(path, formats, &names, &fits)?;
        Ok((formats[i].header, delimiter(&formats[i]), columns))
    }

    fn next_record(
        &mut self,
        stamped: bool,
        unit: TimeUnit,
        stop: &dyn Fn() -> bool,
    ) -> Result<Option<Frame<'_>>> {
        let stamp_bytes = if stamped { 8 } else { 0 };
        let size = stamp_bytes + 4 * self.channels;
        self.line.resize(size, 0);
        let got = read_full(&mut self.input, &mut self.line).map_err(|e| self.read_error(e))?;
        if got == 0 || stop() {
            return Ok(None);
        }
        self.count += 1;
        if got < size {
            let place = format!("frame {}", self.count);
            let why = format!("the input ended after {got} of its {size} bytes");
            return Ok(Some(Frame::Bad { place, why }));
        }
        let stamp =
            stamped.then(|| f64::from_le_bytes(self.line[..8].try_into().expect("8 bytes")));
        for (v, bytes) in self
            .values
            .iter_mut()
            .zip(self.line[stamp_bytes..].chunks_exact(4))
        {
            *v = f64::from(f32::from_le_bytes(bytes.try_into().expect("4 bytes")));
        }
        if self.values.iter().all(|v| v.is_nan()) {
            return Ok(Some(Frame::Reset));
        }
        Ok(Some(Frame::Values {
            stamp,
            unit,
            values: &self.values,
        }))
    }

    /// Where the last frame was (`line 12`, `frame 7`).
    pub fn place(&self) -> String {
        match self.format {
            FrameFormat::Csv(_) => format!("line {}", self.count),
            FrameFormat::F32le { .. } => format!("frame {}", self.count),
        }
    }
}

/// Calls `each` with every field of the line `text` (split as the `csv` crate splits a
/// log's rows: quotes honoured; each field trimmed of spaces) until it returns `false`.
fn for_each_field(
    splitter: &mut csv_core::Reader,
    text: &str,
    field: &mut Vec<u8>,
    mut each: impl FnMut(&[u8]) -> bool,
) {
    use csv_core::ReadFieldResult;
    splitter.reset();
    let mut input = text.as_bytes();
    field.clear();
    let mut len = 0;
    loop {
        if field.len() < len + input.len() + 1 {
            field.resize(len + input.len() + 1, 0);
        }
        let (result, read, written) = splitter.read_field(input, &mut field[len..]);
        input = &input[read..];
        len += written;
        match result {
            ReadFieldResult::InputEmpty | ReadFieldResult::OutputFull => continue,
            ReadFieldResult::End => return,
            ReadFieldResult::Field { record_end } => {
                if !each(field[..len].trim_ascii()) || record_end {
                    return;
                }
                len = 0;
            }
        }
    }
}

/// What a line that plans no columns looks like.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LineKind {
    /// Every field a name: a header.
    Names,
    /// Every field a number or empty: a frame, perhaps cut short.
    Numbers,
    /// Names and numbers mixed, or control characters: neither.
    Garbled,
}

/// The kind of line `text` is, its fields split as a frame's are.
fn line_kind(text: &str) -> LineKind {
    if text.chars().any(|c| c.is_control() && c != '\t') {
        return LineKind::Garbled;
    }
    let delimiter = detect_delimiter_in(&[text]);
    let mut splitter = csv_core::ReaderBuilder::new()
        .delimiter(delimiter.byte())
        .build();
    let (mut names, mut numbers, mut fields) = (0, 0, 0);
    for_each_field(&mut splitter, text, &mut Vec::new(), |f| {
        fields += 1;
        match std::str::from_utf8(f) {
            Ok(f) if f.is_empty() || f.parse::<f64>().is_ok() => numbers += 1,
            Ok(_) => names += 1,
            Err(_) => {}
        }
        true
    });
    match (names, numbers) {
        (n, 0) if n == fields => LineKind::Names,
        (0, n) if n == fields => LineKind::Numbers,
        _ => LineKind::Garbled,
    }
}

/// Parses a frame's line into `fields`, `expected` numbers, or says why it is a bad frame.
fn parse_fields(
    splitter: &mut csv_core::Reader,
    text: &str,
    expected: usize,
    field: &mut Vec<u8>,
    fields: &mut Vec<f64>,
) -> std::result::Result<(), String> {
    fields.clear();
    let mut not_number = None;
    for_each_field(splitter, text, field, |f| {
        let parsed = std::str::from_utf8(f)
            .ok()
            .and_then(|f| f.parse::<f64>().ok());
        match parsed {
            Some(v) => fields.push(v),
            None => not_number = Some(String::from_utf8_lossy(f).into_owned()),
        }
        not_number.is_none()
    });
    if let Some(text) = not_number {
        // Counted as the line's values are: from its first field, the stamp's when given.
        let index = fields.len();
        if text.trim().is_empty() {
            return Err(format!("value {index} is empty"));
        }
        let shown: String = text.chars().take(40).collect();
        return Err(format!("value {index} is {shown:?}, not a number"));
    }
    if fields.len() != expected {
        return Err(format!("{} fields, expected {expected}", fields.len()));
    }
    Ok(())
}

/// Reads the next line of `input` into `line` (without its newline), keeping at most
/// `limit` bytes of it: a longer line is read to its end and the rest dropped, so a peer
/// cannot make the stream buffer more. Returns the line's whole length in bytes, `None`
/// at the end of the input or once `stop()` says so.
pub(crate) fn read_line(
    input: &mut dyn BufRead,
    line: &mut Vec<u8>,
    limit: usize,
    stop: &dyn Fn() -> bool,
) -> std::io::Result<Option<usize>> {
    line.clear();
    let mut length: Option<usize> = None;
    loop {
        if stop() {
            return Ok(None);
        }
        let available = match input.fill_buf() {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if available.is_empty() {
            return Ok(length);
        }
        let newline = available.iter().position(|&b| b == b'\n');
        let part = &available[..newline.unwrap_or(available.len())];
        let room = limit.saturating_sub(line.len());
        line.extend_from_slice(&part[..part.len().min(room)]);
        let length = length.get_or_insert(0);
        *length = length.saturating_add(part.len());
        let used = newline.map_or(available.len(), |i| i + 1);
        input.consume(used);
        if newline.is_some() {
            return Ok(Some(*length));
        }
    }
}

/// Reads until `buf` is full or the input ends; the bytes read.
fn read_full(input: &mut dyn Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match input.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// Replays frames at their own pace: each frame waits until its time, counted from the
/// first frame's, has come.
#[derive(Debug)]
pub struct Replay {
    start: Instant,
    first: Option<f64>,
    /// The longest wait for one frame: a frame further ahead is bad (or starts an episode
    /// after a gap), and a stamp far ahead must not hold the replay for days.
    longest: Duration,
}

impl Replay {
    /// A replay whose longest wait is `max_gap_s` (the stream's, checked finite, in
    /// (0, 10] s).
    pub fn new(max_gap_s: f64) -> Self {
        Replay {
            start: Instant::now(),
            first: None,
            longest: Duration::from_secs_f64(max_gap_s.clamp(0.0, 3600.0)),
        }
    }

    /// Waits until `t_s` (the frame's time) has come, counted from the first frame's, or
    /// for the longest wait at most.
    pub fn wait(&mut self, t_s: f64) {
        // A stamp that is not a finite number is a bad frame later; `from_secs_f64` would
        // panic on it.
        if !t_s.is_finite() {
            return;
        }
        let first = *self.first.get_or_insert(t_s);
        let due = Duration::from_secs_f64((t_s - first).clamp(0.0, 1e6));
        if let Some(left) = due.checked_sub(self.start.elapsed()) {
            std::thread::sleep(left.min(self.longest));
        }
    }
}

/// The JSON line of one event: a bin boundary's decision, or an episode's summary with the
/// stream's bad frames so far.
pub fn event_json(stream: &StreamClassifier, event: &Event) -> Value {
    let labels = stream.model().labels();
    match event {
        Event::Bin(bin) => bin_json(labels, bin, None),
        Event::End(summary) => {
            let mut line = end_json(labels, summary, None);
            line["bad_frames"] = stream.bad_frames().into();
            line
        }
    }
}

/// Where frames come from: bytes a [`FrameReader`] decodes, or an LSL inlet's samples
/// ([`crate::lsl::LslFrames`]).
pub trait FrameSource {
    /// The next frame; `None` at the end of the input or once `stop()` says so.
    ///
    /// # Errors
    /// The input cannot be read, or no longer fits the model.
    fn next_frame(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Frame<'_>>>;
    /// Where the last frame was (`line 12`, `frame 7`, `sample 9`).
    fn place(&self) -> String;
    /// Why the input ended, when a person should hear it (a live stream that went away).
    fn ended(&self) -> Option<String> {
        None
    }
}

impl<R: BufRead> FrameSource for FrameReader<R> {
    fn next_frame(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Frame<'_>>> {
        self.next(stop)
    }

    fn place(&self) -> String {
        FrameReader::place(self)
    }
}

/// What [`feed`] reports to its caller as it goes.
pub trait Sink {
    /// Events the last frame completed (bin decisions, episode ends), in order.
    ///
    /// # Errors
    /// The caller could not pass them on (a closed pipe); the stream stops.
    fn events(&mut self, stream: &StreamClassifier, events: &[Event]) -> Result<()>;
    /// A frame skipped as bad: where it was and why.
    fn bad_frame(&mut self, place: &str, why: &str);
}

/// Feeds every frame of `frames` to `stream` until the input ends or `stop()` says so,
/// passing each frame's events to `sink`; frames wait for their time when `replay` is
/// given (a frame without stamps is `1 / fs` s after the one before). Bad frames are
/// counted, reported and skipped. The stream is not finished: the caller ends it
/// ([`StreamClassifier::finish`] or [`StreamClassifier::stop`]).
///
/// # Errors
/// As [`FrameSource::next_frame`]; the model could not classify a window; `sink` failed.
pub fn feed(
    frames: &mut dyn FrameSource,
    stream: &mut StreamClassifier,
    mut replay: Option<Replay>,
    sink: &mut dyn Sink,
    stop: &dyn Fn() -> bool,
) -> Result<()> {
    let fs = stream.params().fs;
    loop {
        let events = match frames.next_frame(stop)? {
            None => return Ok(()),
            Some(Frame::Reset) => stream.reset(),
            Some(Frame::Bad { place, why }) => {
                stream.skip_bad_frame();
                sink.bad_frame(&place, &why);
                continue;
            }
            Some(Frame::Values {
                stamp,
                unit,
                values,
            }) => {
                if let Some(r) = replay.as_mut() {
                    let time_s = stamp.map(|t| unit.to_seconds(t));
                    r.wait(time_s.unwrap_or(stream.frames() as f64 / fs));
                }
                stream.push_in(stamp, unit, values)
            }
        };
        let events = events.map(<[_]>::to_vec);
        pass_on(events, stream, sink, &|| frames.place())?;
    }
}

/// Passes what one frame or event completed to `sink`: its decisions, or the bad frame it
/// was (named by `place`).
///
/// # Errors
/// The model could not classify a window; `sink` failed.
pub(crate) fn pass_on(
    done: std::result::Result<Vec<Event>, StreamError>,
    stream: &StreamClassifier,
    sink: &mut dyn Sink,
    place: &dyn Fn() -> String,
) -> Result<()> {
    match done {
        Ok(events) if events.is_empty() => Ok(()),
        Ok(events) => sink.events(stream, &events),
        Err(StreamError::Bad(bad)) => {
            sink.bad_frame(&place(), &bad.to_string());
            Ok(())
        }
        Err(StreamError::Classify(e)) => Err(e),
    }
}
