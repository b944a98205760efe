//! `stream`: a causal model classifies a live taxel stream frame by frame; the options
//! that say where frames come from, how they are read and how an episode is decided, and
//! `predict --causal`'s decision options.

use std::path::PathBuf;

use crate::causal::DecisionRule;
use crate::csvlog::{ChannelSelect, Column, CsvFormat, CsvOverrides, Delimiter};
use crate::error::{OptionsError, ParamError};
use crate::events::Origin;
use crate::recording::TimeUnit;
use crate::saved::{SavedModel, Trained};
use crate::stream::events::{feed_events, EventEncoding, EventInput, EventReader, EventSource};
use crate::stream::frames::FrameFormat as Format;
use crate::stream::frames::{event_json, feed, FrameReader, FrameSource, Replay, Sink};
use crate::stream::input;
use crate::stream::lsl::{Lsl, LslEvents, LslFrames, Outlet, Query};
use crate::stream::{EpisodeRule, Event, StreamClassifier, StreamParams};
use crate::Result;

/// How the per-bin classifications of an episode become a decision, and over which window:
/// the options `stream` and `predict --causal` share.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct DecisionOptions {
    /// The window classified at each bin boundary, s (rounded up to whole bins); default:
    /// the median length of the model's training recordings (10 s when the model does not
    /// say), so that a recording of that length is classified whole.
    #[cfg_attr(feature = "cli", arg(long = "window-s", allow_negative_numbers = true))]
    pub window_s: Option<f64>,
    /// The vote share a bin's label needs to count towards the decision (KNN: 0.8 is four
    /// of five neighbours).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::causal::DEFAULT_DECIDE_SHARE))]
    pub decide: f64,
    /// The consecutive bins that must agree at that share for the episode to be decided.
    #[cfg_attr(feature = "cli", arg(long = "decide-bins", default_value_t = crate::causal::DEFAULT_DECIDE_BINS))]
    pub decide_bins: usize,
}

impl DecisionOptions {
    /// The rule, checked.
    ///
    /// # Errors
    /// A share outside (0, 1] or no bins.
    pub fn rule(&self) -> Result<DecisionRule> {
        let rule = DecisionRule {
            share: self.decide,
            bins: self.decide_bins,
        };
        rule.check()?;
        Ok(rule)
    }

    /// The window in ms for `model`.
    ///
    /// # Errors
    /// A window that is not a positive whole number of the model's bins.
    pub fn window_ms(&self, model: &impl Trained) -> Result<usize> {
        Ok(StreamParams::window_ms(model, self.window_s)?)
    }
}

/// The frame format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum FrameFormat {
    /// Text lines: one frame per line, comma, semicolon or tab separated; a line `reset`
    /// ends the episode.
    Csv,
    /// Raw little-endian frames: an f64 time stamp in s when `--stamped`, then one f32 per
    /// taxel; a frame whose every value is NaN ends the episode.
    F32le,
    /// Address events as text lines: `t,x,y,p` (or `t,taxel,p` for a model trained on
    /// taxel-indexed events), with or without a header; a line holding only a time is a
    /// tick (time has reached it), `reset` ends the episode.
    Events,
    /// Address events as 16-byte little-endian records: t i64, x u16, y u16, p i8, kind u8
    /// (0 event, 1 tick, 2 end of episode), 2 unused bytes.
    EventsBin,
}

/// Options of `neurotex stream`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct StreamOptions {
    /// A model trained with `--causal` (`neurotex train --causal`, with any classifier:
    /// a spiking network runs step by step on the spikes as they come); for events, any
    /// model, such as one trained on an event dataset.
    #[cfg_attr(feature = "cli", arg(long))]
    pub model: PathBuf,
    /// With --model FILE.nir from another tool (no neurotex metadata in the graph): a
    /// neurotex spiking model trained with --causal whose pipeline, grid and labels the
    /// graph's network runs with.
    #[cfg_attr(feature = "cli", arg(long))]
    pub like: Option<PathBuf>,
    /// The tool that wrote the graph given as --model (`nir`, `snntorch` or `norse`), for
    /// what its file does not say: as for `neurotex predict --nir-from`.
    #[cfg_attr(feature = "cli", arg(long, value_name = "TOOL", default_value = "nir"))]
    pub nir_from: crate::nir::NirFrom,
    /// Where frames come from: `-` (standard input), a file, `tcp://HOST:PORT` (listens
    /// there and takes one connection: the sensor's driver connects and sends frames
    /// until it closes), `udp://HOST:PORT` (binds there; each datagram holds whole lines
    /// or frames; an empty datagram ends the input) or `lsl:NAME` / `lsl:PROPERTY=VALUE`
    /// (a Lab Streaming Layer stream: one number per taxel per sample, or for events `x, y,
    /// p` numbers or marker strings; stamps from LSL's clock; liblsl from pylsl's wheel or
    /// the system, PYLSL_LIB naming its file). SIGINT (Ctrl-C), SIGTERM or SIGHUP
    /// ends the stream at its next frame with the episode's summary.
    #[cfg_attr(feature = "cli", arg(long, default_value = "-"))]
    pub input: String,
    /// The frame format.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value = "csv"))]
    pub format: FrameFormat,
    /// The frames' rate in Hz when they carry no time stamps.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 1000.0))]
    pub fs: f64,
    /// CSV: the time-stamp column, by name (with a header) or 0-based index; without it
    /// frames are taken at --fs. A column named t_ms/time_ms or t_s/time_s is found alone.
    #[cfg_attr(feature = "cli", arg(long = "time-column"))]
    pub time_column: Option<Column>,
    /// Unit of the time stamps: `us`, `ms` or `s` (default `ms` for CSV; f32le stamps are s;
    /// events: the model's event dataset's unit, required without one; events-bin: `us`).
    #[cfg_attr(feature = "cli", arg(long = "time-unit"))]
    pub time_unit: Option<TimeUnit>,
    /// CSV: the channel columns (names, 0-based indices and ranges such as `2-17`, or a
    /// regular expression); default every column but the time column. They fill the
    /// model's taxels in row-major order.
    #[cfg_attr(feature = "cli", arg(long))]
    pub channels: Option<ChannelSelect>,
    /// CSV: the first line is data, not names; columns go by 0-based index.
    #[cfg_attr(feature = "cli", arg(long = "no-header"))]
    pub no_header: bool,
    /// CSV: the field delimiter (default: detected on the first line).
    #[cfg_attr(feature = "cli", arg(long))]
    pub delimiter: Option<Delimiter>,
    /// f32le: each frame starts with an f64 time stamp in s.
    #[cfg_attr(feature = "cli", arg(long))]
    pub stamped: bool,
    /// Events: where the first episode's time 0 is, `zero` (the stamps count from the
    /// recording's start, as an exported recording's) or `first` (its first event; later
    /// episodes always start at their first event). Default: the model's event dataset's,
    /// else `first`.
    #[cfg_attr(feature = "cli", arg(long, value_parser = ["zero", "first"]))]
    pub origin: Option<String>,
    /// Events: each names a taxel index instead of x and y (`t,taxel,p` lines; a record's
    /// x, or an LSL stream's `taxel[,p]`), mapped to cells by the channel map of the model's
    /// dataset (`import events --channel-map`), else row-major.
    #[cfg_attr(feature = "cli", arg(long))]
    pub taxel: bool,
    /// Replay the input at its own pace (its time stamps, or --fs): for demonstrations.
    #[cfg_attr(feature = "cli", arg(long))]
    pub realtime: bool,
    /// How the stream is cut into episodes: `whole` (one from the first frame, until a
    /// reset or the end), or `onset[:LEVEL[:REST_MS]]` (from the first frame whose largest
    /// taxel, less its resting value, reaches LEVEL times the model's scale, default 0.1,
    /// until it stays below half that for REST_MS, default 500).
    #[cfg_attr(feature = "cli", arg(long, default_value = "whole"))]
    pub episode: EpisodeRule,
    /// The largest gap between two frames' stamps within an episode, s, at most 10: a frame
    /// completes the 1 ms steps since the previous one, so this bounds what one frame costs.
    /// A frame further ahead is a bad frame; if the next frame follows it, the episode ends
    /// and a new one starts there.
    #[cfg_attr(feature = "cli", arg(long = "max-gap-s", default_value_t = crate::stream::DEFAULT_MAX_GAP_S))]
    pub max_gap_s: f64,
    /// The sliding speed in mm/s, for a model with all-taxels-mm features.
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub speed: Option<f64>,
    /// Publish each decision line on a Lab Streaming Layer outlet: `lsl:NAME`, a marker
    /// stream (type Markers) of one string channel, each sample a JSON line.
    #[cfg_attr(feature = "cli", arg(long))]
    pub publish: Option<String>,
    /// With `--input lsl:...`: how long to look for the stream before giving up, s.
    #[cfg_attr(feature = "cli", arg(long = "lsl-timeout-s", default_value_t = 10.0))]
    pub lsl_timeout_s: f64,
    /// How an episode is decided.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub decision: DecisionOptions,
}

impl StreamOptions {
    /// The stream's parameters for `model`, checked when the stream is made.
    ///
    /// # Errors
    /// A decision rule or window out of range.
    pub fn params(&self, model: &impl Trained) -> Result<StreamParams> {
        Ok(StreamParams {
            window_ms: self.decision.window_ms(model)?,
            rule: self.decision.rule()?,
            episodes: self.episode,
            fs: self.fs,
            max_gap_s: self.max_gap_s,
            speed_mm_s: self.speed,
        })
    }

    /// For an event stream (`--format events` or `events-bin`), how its events are
    /// written and address the model's grid; `None` for frames.
    ///
    /// # Errors
    /// An option for frames with events, or a text event stream whose unit is not known.
    pub fn event_source(&self, model: &SavedModel) -> Result<Option<(EventEncoding, EventSource)>> {
        let encoding = match self.format {
            FrameFormat::Events => EventEncoding::Text,
            FrameFormat::EventsBin => EventEncoding::Binary,
            FrameFormat::Csv | FrameFormat::F32le => {
                if self.origin.is_some() || self.taxel {
                    return Err(OptionsError::NotApplicable {
                        option: "--origin and --taxel",
                        applies_to: "--format events or events-bin",
                    }
                    .into());
                }
                return Ok(None);
            }
        };
        let frames_only = [
            ("--stamped", self.stamped),
            ("--time-column", self.time_column.is_some()),
            ("--channels", self.channels.is_some()),
            ("--no-header", self.no_header),
            ("--delimiter", self.delimiter.is_some()),
        ];
        if let Some((option, _)) = frames_only.iter().find(|o| o.1) {
            return Err(OptionsError::NotApplicable {
                option,
                applies_to: "frames (--format csv or f32le); events name their columns in a header or come as t,x,y,p",
            }
            .into());
        }
        let mut origin = self.origin.as_deref().map(|o| match o {
            "zero" => Origin::Zero,
            _ => Origin::First,
        });
        // LSL stamps are seconds on the sender's clock, whose zero means nothing.
        let lsl = self.input.starts_with("lsl:");
        if lsl {
            if origin == Some(Origin::Zero)
                || self.time_unit.is_some_and(|u| u != TimeUnit::Seconds)
            {
                return Err(OptionsError::NotApplicable {
                    option: "--origin zero or --time-unit",
                    applies_to: "events from a file or socket (LSL stamps are seconds on the sender's clock)",
                }
                .into());
            }
            origin = Some(Origin::First);
        }
        // Binary records' stamps are microseconds unless said: the record's definition, not
        // the training files' unit.
        let unit = match (encoding, self.time_unit) {
            _ if lsl => Some(TimeUnit::Seconds),
            (_, Some(unit)) => Some(unit),
            (EventEncoding::Binary, None) => Some(TimeUnit::Microseconds),
            (EventEncoding::Text, None) => None,
        };
        let source = EventSource::for_model(model, unit, origin, self.taxel)
            .map_err(OptionsError::Conflict)?;
        Ok(Some((encoding, source)))
    }

    /// The frame format the options describe. CSV: with no option saying where the columns
    /// are, the lines are read as the model's training recordings were (its dataset's columns,
    /// then the raw logs' an import kept), else with a header as every column but a time column
    /// named t_ms/time_ms or t_s/time_s. f32le stamps are in s unless --time-unit says.
    ///
    /// # Errors
    /// `--stamped` with CSV frames, or a layout the model remembers that does not read.
    pub fn frame_format(&self, model: &impl Trained) -> Result<Format> {
        if self.format == FrameFormat::Csv && self.stamped {
            return Err(OptionsError::NotApplicable {
                option: "--stamped",
                applies_to: "--format f32le (CSV frames carry their stamp in --time-column)",
            }
            .into());
        }
        Ok(match self.format {
            FrameFormat::Csv => {
                let overrides = CsvOverrides {
                    no_header: self.no_header,
                    delimiter: self.delimiter,
                    time_column: self.time_column.clone(),
                    time_unit: self.time_unit,
                    channels: self.channels.clone(),
                    ..CsvOverrides::default()
                };
                let plain = CsvFormat {
                    detect_time: true,
                    ..CsvFormat::default()
                };
                let mut formats = match (
                    model.provenance().layout.as_ref(),
                    overrides.place_columns(),
                ) {
                    (Some(layout), false) => layout.csv_formats(&overrides)?,
                    _ => Vec::new(),
                };
                formats.push(overrides.apply(plain));
                Format::Csv(formats)
            }
            FrameFormat::F32le => Format::F32le {
                stamped: self.stamped,
                unit: self.time_unit.unwrap_or(TimeUnit::Seconds),
            },
            FrameFormat::Events | FrameFormat::EventsBin => {
                let why = "events have no frame format: `StreamOptions::event_source` reads them";
                return Err(OptionsError::Conflict(why.into()).into());
            }
        })
    }
}

/// What a stream run hears as it goes.
pub struct StreamTalk<'a> {
    /// A JSON line per bin boundary and per episode's end, as it happens.
    pub out: &'a mut dyn std::io::Write,
    /// Notes for a person: the address listened on, a bad frame, why the input ended, the
    /// summary.
    pub say: &'a dyn Fn(&str),
    /// Whether a signal asked the stream to stop (checked after each frame).
    pub stop: &'a dyn Fn() -> bool,
    /// Called once the input is open (a connection accepted, a stream found): from then on
    /// a signal ends the input rather than the run.
    pub opened: &'a dyn Fn(),
}

/// Runs `neurotex stream`: opens the model and the input, classifies frames or events
/// until the input ends or `stop()` says so, and says the summary line; the decisions also
/// go to `--publish`'s LSL outlet.
///
/// # Errors
/// A model that cannot stream, options that do not fit it, an input that cannot be opened
/// or read, a live stream that came back with other channels. An error after the stream
/// began comes after the episode's end and the summary.
pub fn run_stream(args: &StreamOptions, talk: StreamTalk<'_>) -> Result<()> {
    let model = SavedModel::load_as(&args.model, args.like.as_deref(), args.nir_from)?;
    let events = args.event_source(&model)?;
    if events.is_none() {
        frames_model(args, &model)?;
    }
    let params = args.params(&model)?;
    let publish = match &args.publish {
        Some(target) => Some(publisher(target)?),
        None => None,
    };
    let StreamTalk {
        out,
        say,
        stop,
        opened,
    } = talk;
    let (mut stream, mut input) = open_input(args, model, params, events, say)?;
    // Lines pushed before a consumer connects are lost; an LSL input buffers meanwhile.
    if let (Some(outlet), Some(target)) = (&publish, &args.publish) {
        if !outlet.wait_for_consumers(PUBLISH_WAIT_S) {
            say(&format!("{target}: no consumer after {PUBLISH_WAIT_S} s; lines published before one connects are lost"));
        }
    }
    opened();
    let mut sink = Lines {
        out,
        say,
        publish,
        episodes: 0,
        events: matches!(input, Input::Events(_)),
        warned: 0,
    };
    let replay = args
        .realtime
        .then(|| Replay::new(stream.params().max_gap_s));
    let fed = match &mut input {
        Input::Frames(frames) => feed(frames.as_mut(), &mut stream, replay, &mut sink, stop),
        Input::Events(events) => feed_events(events.as_mut(), &mut stream, replay, &mut sink, stop),
    };
    let stopped = stop();
    if stopped {
        (sink.say)("interrupted: the stream stopped at its next frame");
    } else if let Some(why) = input.ended() {
        (sink.say)(&why);
    }
    let ended = match stopped {
        true => stream.stop(),
        false => stream.finish(),
    }
    .map(<[_]>::to_vec);
    let ended = ended.map_err(|e| match e {
        crate::stream::StreamError::Classify(e) => e,
        bad => OptionsError::Conflict(bad.to_string()).into(),
    })?;
    sink.events(&stream, &ended)?;
    (sink.say)(&input.summary(&stream, sink.episodes));
    fed
}

/// The stream classifier for `model`, and its input: frames or events, from bytes or LSL.
fn open_input(
    args: &StreamOptions,
    model: SavedModel,
    params: StreamParams,
    events: Option<(EventEncoding, EventSource)>,
    say: &dyn Fn(&str),
) -> Result<(StreamClassifier, Input)> {
    let lsl_query = match args.input.strip_prefix("lsl:") {
        Some(q) => Some(Query::parse(q).map_err(|e| OptionsError::Conflict(e.to_string()))?),
        None => None,
    };
    let timeout = args.lsl_timeout_s;
    if !(timeout.is_finite() && timeout > 0.0 && timeout <= 3600.0) {
        let rule = "how long to look for an LSL stream must be in (0, 3600] s";
        return Err(ParamError::new("lsl-timeout-s", rule, timeout).into());
    }
    Ok(match events {
        Some((encoding, source)) => {
            let taxel = source.format.taxel.is_some();
            let format = source.format.clone();
            let stream = StreamClassifier::for_events(model, params, source)?;
            let input = match &lsl_query {
                Some(q) => Input::Events(Box::new(LslEvents::open(q, taxel, timeout)?)),
                None => {
                    let bytes = input::open(&args.input, say)?;
                    let reader = EventReader::new(bytes, &args.input, encoding, &format);
                    Input::Events(Box::new(reader))
                }
            };
            (stream, input)
        }
        None => {
            let format = args.frame_format(&model)?;
            let stream = StreamClassifier::new(model, params)?;
            let channels = stream.channels();
            let input = match &lsl_query {
                Some(q) => Input::Frames(Box::new(LslFrames::open(q, channels, timeout)?)),
                None => {
                    let bytes = input::open(&args.input, say)?;
                    let reader = FrameReader::new(bytes, &args.input, format, channels);
                    Input::Frames(Box::new(reader))
                }
            };
            (stream, input)
        }
    })
}

/// Checks that `model` streams frames: not trained on events, trained for streams.
fn frames_model(args: &StreamOptions, model: &SavedModel) -> Result<()> {
    let from = match &args.like {
        Some(like) => format!(
            "{} (its pipeline from {})",
            args.model.display(),
            like.display()
        ),
        None => args.model.display().to_string(),
    };
    let why = match crate::stream::events::trained_on_events(model) {
        Some(why) => why,
        None => match model.streams() {
            Ok(_) => return Ok(()),
            Err(why) => why.to_string(),
        },
    };
    Err(OptionsError::Conflict(format!("{from}: {why}")).into())
}

/// How long `--publish` waits for a first consumer before the stream starts, s.
const PUBLISH_WAIT_S: f64 = 2.0;

/// The LSL outlet `--publish lsl:NAME` names.
fn publisher(target: &str) -> Result<Outlet> {
    let Some(name) = target.strip_prefix("lsl:").filter(|n| !n.trim().is_empty()) else {
        let why =
            format!("--publish takes lsl:NAME (a marker stream of the decisions), not `{target}`");
        return Err(OptionsError::Conflict(why).into());
    };
    let lsl =
        Lsl::load().map_err(|why| OptionsError::Conflict(format!("--publish {target}: {why}")))?;
    Outlet::new(&lsl, name.trim())
        .map_err(|why| OptionsError::Conflict(format!("--publish {target}: {why}")).into())
}

/// Where a stream's frames or events come from.
enum Input {
    Frames(Box<dyn FrameSource>),
    Events(Box<dyn EventInput>),
}

impl Input {
    /// The summary line: what the stream took and skipped, and its episodes.
    fn summary(&self, stream: &StreamClassifier, episodes: usize) -> String {
        let what = match self {
            Input::Frames(_) => format!(
                "{} frames, {} bad frame(s) skipped",
                stream.frames(),
                stream.bad_frames()
            ),
            Input::Events(_) => format!(
                "{} events ({} in a millisecond their cell already spiked in), {} bad event(s) skipped",
                stream.frames(),
                stream.merged_events(),
                stream.bad_frames()
            ),
        };
        format!("{what}, {episodes} episode(s)")
    }

    fn ended(&self) -> Option<String> {
        match self {
            Input::Frames(f) => f.ended(),
            Input::Events(e) => e.ended(),
        }
    }
}

/// The JSON lines, each written and flushed at once (and published on the outlet); bad
/// frames said.
struct Lines<'a> {
    out: &'a mut dyn std::io::Write,
    say: &'a dyn Fn(&str),
    publish: Option<Outlet>,
    /// Episodes ended so far.
    episodes: usize,
    /// Whether the input is events (their warnings say so).
    events: bool,
    /// Bad frames said so far.
    warned: usize,
}

/// The bad frames or events a stream says one by one; the rest are only counted, so a
/// wrong option cannot bury the decisions in warnings.
const MAX_WARNINGS: usize = 100;

impl Sink for Lines<'_> {
    fn events(&mut self, stream: &StreamClassifier, events: &[Event]) -> Result<()> {
        let write = |e| crate::error::DataError::write("standard output", e);
        for event in events {
            self.episodes += usize::from(matches!(event, Event::End(_)));
            let line = event_json(stream, event).to_string();
            writeln!(self.out, "{line}").map_err(write)?;
            if let Some(outlet) = &self.publish {
                outlet.push(&line);
            }
        }
        self.out.flush().map_err(write)?;
        Ok(())
    }

    fn bad_frame(&mut self, place: &str, why: &str) {
        let what = if self.events { "event" } else { "frame" };
        self.warned += 1;
        match self.warned.cmp(&MAX_WARNINGS) {
            std::cmp::Ordering::Less => {
                (self.say)(&format!("warning: {place}: bad {what} skipped: {why}"))
            }
            std::cmp::Ordering::Equal => (self.say)(&format!(
                "warning: {place}: bad {what} skipped: {why}; further bad {what}s are counted (the summary and each episode's end line) but not said"
            )),
            std::cmp::Ordering::Greater => {}
        }
    }
}
