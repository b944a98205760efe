//! `neurotex stream`: a causal model classifies a live taxel stream frame by frame and
//! prints one JSON line per bin boundary and one per episode's end.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, UdpSocket};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use neurotex::causal::DecisionRule;
use neurotex::csvlog::{ChannelSelect, Column, Columns, CsvFormat, Delimiter};
use neurotex::model::Model;
use neurotex::recording::TimeUnit;
use neurotex::stream::{
    bin_json, end_json, EpisodeRule, Event, StreamClassifier, StreamError, StreamParams,
};

/// How the per-bin classifications of an episode become a decision, and over which window:
/// the options `stream` and `predict --causal` share.
#[derive(Args, Debug, Clone)]
pub struct DecisionArgs {
    /// The window classified at each bin boundary, s (whole bins); default: the median
    /// length of the model's training recordings (10 s when the model does not say).
    #[arg(long = "window-s", allow_negative_numbers = true)]
    pub window_s: Option<f64>,
    /// The vote share a bin's label needs to count towards the decision (KNN: 0.8 is four
    /// of five neighbours).
    #[arg(long, default_value_t = neurotex::causal::DEFAULT_DECIDE_SHARE)]
    pub decide: f64,
    /// The consecutive bins that must agree at that share for the episode to be decided.
    #[arg(long = "decide-bins", default_value_t = neurotex::causal::DEFAULT_DECIDE_BINS)]
    pub decide_bins: usize,
}

impl DecisionArgs {
    /// The rule, checked.
    pub fn rule(&self) -> Result<DecisionRule> {
        let rule = DecisionRule {
            share: self.decide,
            bins: self.decide_bins,
        };
        rule.check()?;
        Ok(rule)
    }

    /// The window in ms for `model`.
    pub fn window_ms(&self, model: &Model) -> Result<usize> {
        match self.window_s {
            None => Ok(StreamParams::for_model(model).window_ms),
            Some(s) if s.is_finite() && s > 0.0 && s <= 3600.0 => Ok((s * 1000.0).round() as usize),
            Some(s) => bail!("--window-s must be in (0, 3600] s, got {s}"),
        }
    }
}

/// The frame format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FrameFormat {
    /// Text lines: one frame per line, comma, semicolon or tab separated; a line `reset`
    /// ends the episode.
    Csv,
    /// Raw little-endian frames: an f64 time stamp in s when `--stamped`, then one f32 per
    /// taxel; a frame whose every value is NaN ends the episode.
    F32le,
}

/// Options of `neurotex stream`.
#[derive(Args)]
pub struct StreamArgs {
    /// A model trained with `--causal` (`neurotex train --causal`).
    #[arg(long)]
    pub model: PathBuf,
    /// Where frames come from: `-` (standard input), a file, `tcp://HOST:PORT` (listens
    /// there and takes one connection: the sensor's driver connects and sends frames
    /// until it closes) or `udp://HOST:PORT` (binds there; each datagram holds whole lines
    /// or frames; an empty datagram ends the input). SIGINT (Ctrl-C), SIGTERM or SIGHUP
    /// ends the stream at its next frame with the episode's summary.
    #[arg(long, default_value = "-")]
    pub input: String,
    /// The frame format.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: FrameFormat,
    /// The frames' rate in Hz when they carry no time stamps.
    #[arg(long, default_value_t = 1000.0)]
    pub fs: f64,
    /// CSV: the time-stamp column, by name (with a header) or 0-based index; without it
    /// frames are taken at --fs. A column named t_ms/time_ms or t_s/time_s is found alone.
    #[arg(long = "time-column")]
    pub time_column: Option<Column>,
    /// Unit of the time stamps: `ms` or `s` (default `ms` for CSV; f32le stamps are s).
    #[arg(long = "time-unit")]
    pub time_unit: Option<TimeUnit>,
    /// CSV: the channel columns (names, 0-based indices and ranges such as `2-17`, or a
    /// regular expression); default every column but the time column. They fill the
    /// model's taxels in row-major order.
    #[arg(long)]
    pub channels: Option<ChannelSelect>,
    /// CSV: the first line is data, not names; columns go by 0-based index.
    #[arg(long = "no-header")]
    pub no_header: bool,
    /// CSV: the field delimiter (default: detected on the first line).
    #[arg(long)]
    pub delimiter: Option<Delimiter>,
    /// f32le: each frame starts with an f64 time stamp in s.
    #[arg(long)]
    pub stamped: bool,
    /// Replay the input at its own pace (its time stamps, or --fs): for demonstrations.
    #[arg(long)]
    pub realtime: bool,
    /// How the stream is cut into episodes: `whole` (one from the first frame, until a
    /// reset or the end), or `onset[:LEVEL[:REST_MS]]` (from the first frame whose largest
    /// taxel, less its resting value, reaches LEVEL times the model's scale, default 0.1,
    /// until it stays below half that for REST_MS, default 500).
    #[arg(long, default_value = "whole")]
    pub episode: EpisodeRule,
    /// The largest gap between two frames' stamps within an episode, s, at most 10: a frame
    /// completes the 1 ms steps since the previous one, so this bounds what one frame costs.
    /// A frame further ahead is a bad frame; if the next frame follows it, the episode ends
    /// and a new one starts there.
    #[arg(long = "max-gap-s", default_value_t = neurotex::stream::DEFAULT_MAX_GAP_S)]
    pub max_gap_s: f64,
    /// The sliding speed in mm/s, for a model with all-taxels-mm features.
    #[arg(long, allow_negative_numbers = true)]
    pub speed: Option<f64>,
    #[command(flatten)]
    pub decision: DecisionArgs,
}

/// Runs `neurotex stream`.
pub fn run(args: StreamArgs) -> Result<()> {
    let model = Model::load(&args.model)?;
    let params = StreamParams {
        window_ms: args.decision.window_ms(&model)?,
        rule: args.decision.rule()?,
        episodes: args.episode,
        fs: args.fs,
        max_gap_s: args.max_gap_s,
        speed_mm_s: args.speed,
    };
    if args.format == FrameFormat::Csv && args.stamped {
        bail!("--stamped is for --format f32le; CSV frames carry their stamp in --time-column");
    }
    let mut stream = StreamClassifier::new(model, params)?;
    let input = open_input(&args.input)?;
    let mut out = Output::new(std::io::stdout().lock());
    let pace = args.realtime.then(|| Pace::new(stream.params().max_gap_s));
    crate::interrupt::end_input_on_signal();
    match args.format {
        FrameFormat::Csv => read_csv(&args, input, &mut stream, &mut out, pace)?,
        FrameFormat::F32le => read_f32le(&args, input, &mut stream, &mut out, pace)?,
    }
    let events = match crate::interrupt::stop_requested() {
        true => {
            eprintln!("interrupted: the stream stopped at its next frame");
            stream.stop()
        }
        false => stream.finish(),
    };
    let events = events.map_err(fatal)?.to_vec();
    out.events(&stream, &events)?;
    eprintln!(
        "{} frames, {} bad frame(s) skipped, {} episode(s)",
        stream.frames(),
        stream.bad_frames(),
        out.episodes
    );
    Ok(())
}

/// The input as a byte reader.
fn open_input(input: &str) -> Result<Box<dyn BufRead>> {
    if input == "-" {
        return Ok(Box::new(BufReader::new(std::io::stdin())));
    }
    if let Some(address) = input.strip_prefix("tcp://") {
        let listener =
            TcpListener::bind(address).with_context(|| format!("listening on tcp://{address}"))?;
        eprintln!("listening on tcp://{}", listener.local_addr()?);
        let (socket, peer) = listener.accept().context("accepting a connection")?;
        eprintln!("connection from {peer}");
        return Ok(Box::new(BufReader::new(socket)));
    }
    if let Some(address) = input.strip_prefix("udp://") {
        let socket =
            UdpSocket::bind(address).with_context(|| format!("binding udp://{address}"))?;
        eprintln!("receiving on udp://{}", socket.local_addr()?);
        return Ok(Box::new(BufReader::new(Datagrams {
            socket,
            buffer: vec![0; 65_536],
            start: 0,
            end: 0,
        })));
    }
    let path = Path::new(input);
    let file = std::fs::File::open(path).with_context(|| format!("opening {}", path.display()))?;
    Ok(Box::new(BufReader::new(file)))
}

/// UDP datagrams read as one byte stream; an empty datagram is its end.
struct Datagrams {
    socket: UdpSocket,
    buffer: Vec<u8>,
    start: usize,
    end: usize,
}

impl Read for Datagrams {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.start == self.end {
            self.end = self.socket.recv(&mut self.buffer)?;
            self.start = 0;
            if self.end == 0 {
                return Ok(0);
            }
        }
        let n = out.len().min(self.end - self.start);
        out[..n].copy_from_slice(&self.buffer[self.start..self.start + n]);
        self.start += n;
        Ok(n)
    }
}

/// Replays frames at their own pace.
struct Pace {
    start: Instant,
    first: Option<f64>,
    /// The longest wait for one frame: a frame further ahead is bad (or starts an episode
    /// after a gap), and a stamp far ahead must not hold the replay for days.
    longest: Duration,
}

impl Pace {
    /// A replay whose longest wait is `max_gap_s`, checked by the stream (finite, in
    /// (0, 10] s).
    fn new(max_gap_s: f64) -> Self {
        Pace {
            start: Instant::now(),
            first: None,
            longest: Duration::from_secs_f64(max_gap_s.clamp(0.0, 3600.0)),
        }
    }

    /// Waits until `t_s` (the frame's time) has come, counted from the first frame's, or
    /// for the largest gap at most.
    fn wait(&mut self, t_s: f64) {
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

/// A classification failure ends the stream (a bad frame does not).
fn fatal(e: StreamError) -> anyhow::Error {
    anyhow::Error::new(e)
}

/// Pushes one frame (its stamp in `unit`) and prints what it completed; a bad frame is said on standard error,
/// with where it was, and skipped.
fn push(
    stream: &mut StreamClassifier,
    out: &mut Output<impl Write>,
    stamp: Option<f64>,
    unit: TimeUnit,
    values: &[f64],
    place: &dyn Fn() -> String,
) -> Result<()> {
    match stream.push_in(stamp, unit, values) {
        Ok(events) => {
            let events = events.to_vec();
            out.events(stream, &events)
        }
        Err(StreamError::Bad(bad)) => {
            eprintln!("warning: {}: bad frame skipped: {bad}", place());
            Ok(())
        }
        Err(e) => Err(fatal(e)),
    }
}

/// The longest CSV line taken, bytes, for `channels` taxels: 64 bytes a taxel (the longest
/// f64 text, `-2.2250738585072014e-308`, has 24 characters; the rest leaves room for
/// spaces, a time column and a few unselected ones), and at least 1 MiB for headers.
fn line_limit(channels: usize) -> usize {
    channels.saturating_mul(64).max(1 << 20)
}

/// Reads the next line of `input` into `line` (without its newline), keeping at most
/// `limit` bytes of it: a longer line is read to its end and the rest dropped, so a peer
/// cannot make the stream buffer more. Returns the line's whole length in bytes, `None`
/// at the end of the input or once a signal asked the stream to stop (a line that never
/// ends does not hold the stream past the signal).
fn read_line(
    input: &mut dyn BufRead,
    line: &mut Vec<u8>,
    limit: usize,
) -> std::io::Result<Option<usize>> {
    line.clear();
    let mut length: Option<usize> = None;
    loop {
        if crate::interrupt::stop_requested() {
            return Ok(None);
        }
        let available = match input.fill_buf() {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
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

/// Counts a frame that could not be parsed and says so on standard error.
fn skip(stream: &mut StreamClassifier, place: &str, why: impl std::fmt::Display) {
    stream.skip_bad_frame();
    eprintln!("warning: {place}: bad frame skipped: {why}");
}

/// The CSV frames of `input`: a header line (unless --no-header), then one frame per line.
/// A line longer than [`line_limit`] or not UTF-8 is a bad frame (the header or first line
/// is needed, so there it is an error).
fn read_csv(
    args: &StreamArgs,
    mut input: Box<dyn BufRead>,
    stream: &mut StreamClassifier,
    out: &mut Output<impl Write>,
    mut pace: Option<Pace>,
) -> Result<()> {
    let format = csv_format(args);
    let mut plan: Option<(u8, Columns)> = None;
    let mut fields: Vec<f64> = Vec::new();
    let mut values: Vec<f64> = Vec::new();
    let limit = line_limit(stream.channels());
    let mut line: Vec<u8> = Vec::new();
    let mut line_no = 0usize;
    loop {
        let read = read_line(&mut *input, &mut line, limit);
        let read =
            read.with_context(|| format!("reading line {} of {}", line_no + 1, args.input))?;
        let Some(length) = read else { break };
        line_no += 1;
        let place = || format!("line {line_no}");
        let text = match (length > limit, std::str::from_utf8(&line)) {
            (true, _) => Err(format!(
                "the line is longer than a frame of {} values may be ({length} bytes, at most {limit})",
                stream.channels()
            )),
            (false, Err(e)) => Err(format!(
                "the line is not UTF-8 text (its byte {} is not valid UTF-8)",
                e.valid_up_to() + 1
            )),
            (false, Ok(text)) => Ok(text.trim()),
        };
        let text = match (text, &plan) {
            (Ok(text), _) => text,
            (Err(why), None) => bail!("{}: {}: {why}", args.input, place()),
            (Err(why), Some(_)) => {
                skip(stream, &place(), why);
                continue;
            }
        };
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        if text.eq_ignore_ascii_case("reset") {
            let events = stream.reset().map_err(fatal)?.to_vec();
            out.events(stream, &events)?;
            continue;
        }
        let (delimiter, columns) = match &plan {
            Some(p) => p,
            None => {
                plan = Some(plan_columns(args, &format, text, stream)?);
                if format.header {
                    continue;
                }
                plan.as_ref().expect("just set")
            }
        };
        if let Err(why) = parse_fields(text, *delimiter, columns.names.len(), &mut fields) {
            skip(stream, &place(), why);
            continue;
        }
        let stamp = columns.time.map(|j| fields[j]);
        values.clear();
        values.extend(columns.channels.iter().map(|&j| fields[j]));
        if let Some(p) = pace.as_mut() {
            let time_s = stamp.map(|t| columns.unit.to_seconds(t));
            p.wait(time_s.unwrap_or(stream.frames() as f64 / args.fs));
        }
        push(stream, out, stamp, columns.unit, &values, &place)?;
    }
    Ok(())
}

/// The CSV format the options describe (time column found by name when there is a header
/// and no --time-column).
fn csv_format(args: &StreamArgs) -> CsvFormat {
    CsvFormat {
        header: !args.no_header,
        delimiter: args.delimiter,
        time_column: args.time_column.clone(),
        time_unit: args.time_unit.unwrap_or_default(),
        detect_time: !args.no_header && args.time_column.is_none(),
        channels: args.channels.clone().unwrap_or(ChannelSelect::All),
        ..CsvFormat::default()
    }
}

/// The delimiter and the columns from the first line (the header, or the first frame),
/// checked against the model's taxels.
fn plan_columns(
    args: &StreamArgs,
    format: &CsvFormat,
    text: &str,
    stream: &StreamClassifier,
) -> Result<(u8, Columns)> {
    let source = PathBuf::from(&args.input);
    let delimiter = format.delimiter.map_or_else(|| detect(text), |d| d.byte());
    let split: Vec<&str> = text.split(delimiter as char).map(str::trim).collect();
    let names: Vec<String> = match format.header {
        true => split.iter().map(|s| s.to_string()).collect(),
        false => (0..split.len()).map(|j| format!("column{j}")).collect(),
    };
    let columns = Columns::find(&source, format, names)?;
    if columns.channels.len() != stream.channels() {
        bail!(
            "{}: {} channel columns selected, the model has {} taxels",
            args.input,
            columns.channels.len(),
            stream.channels()
        );
    }
    Ok((delimiter, columns))
}

/// Parses a frame's line into `fields`, `expected` numbers split at `delimiter`, or says
/// why it is a bad frame.
fn parse_fields(
    text: &str,
    delimiter: u8,
    expected: usize,
    fields: &mut Vec<f64>,
) -> std::result::Result<(), String> {
    fields.clear();
    for field in text.split(delimiter as char) {
        match field.trim().parse::<f64>() {
            Ok(v) => fields.push(v),
            Err(_) => return Err("a field is not a number".to_string()),
        }
    }
    if fields.len() != expected {
        return Err(format!("{} fields, expected {expected}", fields.len()));
    }
    Ok(())
}

/// The delimiter of a first line: tab, `;` or `,`, whichever it holds most of.
fn detect(line: &str) -> u8 {
    [b'\t', b';', b',']
        .into_iter()
        .max_by_key(|&d| line.bytes().filter(|&b| b == d).count())
        .filter(|&d| line.bytes().any(|b| b == d))
        .unwrap_or(b',')
}

/// The raw frames of `input`.
fn read_f32le(
    args: &StreamArgs,
    mut input: Box<dyn BufRead>,
    stream: &mut StreamClassifier,
    out: &mut Output<impl Write>,
    mut pace: Option<Pace>,
) -> Result<()> {
    let stamp = if args.stamped { 8 } else { 0 };
    let size = stamp + 4 * stream.channels();
    let mut frame = vec![0u8; size];
    let mut values = vec![0.0; stream.channels()];
    let mut number = 0u64;
    loop {
        let got = read_full(&mut input, &mut frame)?;
        if got == 0 || crate::interrupt::stop_requested() {
            return Ok(());
        }
        number += 1;
        let place = || format!("frame {number}");
        if got < size {
            eprintln!(
                "warning: {}: bad frame skipped: the input ended after {got} of its {size} bytes",
                place()
            );
            stream.skip_bad_frame();
            return Ok(());
        }
        let unit = args.time_unit.unwrap_or(TimeUnit::Seconds);
        let stamped = args
            .stamped
            .then(|| f64::from_le_bytes(frame[..8].try_into().expect("8 bytes")));
        for (v, bytes) in values.iter_mut().zip(frame[stamp..].chunks_exact(4)) {
            *v = f64::from(f32::from_le_bytes(bytes.try_into().expect("4 bytes")));
        }
        if values.iter().all(|v| v.is_nan()) {
            let events = stream.reset().map_err(fatal)?.to_vec();
            out.events(stream, &events)?;
            continue;
        }
        if let Some(p) = pace.as_mut() {
            let time_s = stamped.map(|t| unit.to_seconds(t));
            p.wait(time_s.unwrap_or(stream.frames() as f64 / args.fs));
        }
        push(stream, out, stamped, unit, &values, &place)?;
    }
}

/// Reads until `buf` is full or the input ends; the bytes read.
fn read_full(input: &mut dyn Read, buf: &mut [u8]) -> Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match input.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e).context("reading frames"),
        }
    }
    Ok(filled)
}

/// The JSON lines: one per bin boundary, one per episode's end, each flushed at once.
struct Output<W: Write> {
    out: W,
    /// Episodes ended so far.
    episodes: usize,
}

impl<W: Write> Output<W> {
    fn new(out: W) -> Self {
        Output { out, episodes: 0 }
    }

    fn events(&mut self, stream: &StreamClassifier, events: &[Event]) -> Result<()> {
        let labels = stream.model().labels();
        for event in events {
            let line = match event {
                Event::Bin(bin) => bin_json(labels, bin, None),
                Event::End(summary) => {
                    let mut line = end_json(labels, summary, None);
                    line["bad_frames"] = stream.bad_frames().into();
                    self.episodes += 1;
                    line
                }
            };
            writeln!(self.out, "{line}")?;
        }
        self.out.flush()?;
        Ok(())
    }
}
