//! `neurotex stream`: a causal model classifies a live taxel stream frame by frame and
//! prints one JSON line per bin boundary and one per episode's end.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use neurotex::causal::DecisionRule;
use neurotex::csvlog::{ChannelSelect, Column, CsvFormat, CsvOverrides, Delimiter};
use neurotex::model::Model;
use neurotex::recording::TimeUnit;
use neurotex::stream::frames::{event_json, feed, FrameReader, Replay, Sink};
use neurotex::stream::{EpisodeRule, Event, StreamClassifier, StreamParams};

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
        Ok(StreamParams::window_ms(model, self.window_s)?)
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
    let format = frame_format(&args, &model)?;
    let mut stream = StreamClassifier::new(model, params)?;
    let input = neurotex::stream::input::open(&args.input, &|said| eprintln!("{said}"))?;
    let mut frames = FrameReader::new(input, &args.input, format, stream.channels());
    let mut out = Output {
        out: std::io::stdout().lock(),
        episodes: 0,
    };
    let replay = args
        .realtime
        .then(|| Replay::new(stream.params().max_gap_s));
    crate::interrupt::end_input_on_signal();
    let stop = crate::interrupt::stop_requested;
    feed(&mut frames, &mut stream, replay, &mut out, &stop)?;
    let events = match stop() {
        true => {
            eprintln!("interrupted: the stream stopped at its next frame");
            stream.stop()
        }
        false => stream.finish(),
    };
    let events = events.map_err(anyhow::Error::new)?.to_vec();
    out.events(&stream, &events)?;
    eprintln!(
        "{} frames, {} bad frame(s) skipped, {} episode(s)",
        stream.frames(),
        stream.bad_frames(),
        out.episodes
    );
    Ok(())
}

/// The frame format the options describe. CSV: with no option saying where the columns
/// are, the lines are read as the model's training recordings were (its dataset's columns,
/// then the raw logs' an import kept), else with a header as every column but a time column
/// named t_ms/time_ms or t_s/time_s. f32le stamps are in s unless --time-unit says.
fn frame_format(args: &StreamArgs, model: &Model) -> Result<neurotex::stream::frames::FrameFormat> {
    use neurotex::stream::frames::FrameFormat as Format;
    Ok(match args.format {
        FrameFormat::Csv => {
            let overrides = CsvOverrides {
                no_header: args.no_header,
                delimiter: args.delimiter,
                time_column: args.time_column.clone(),
                time_unit: args.time_unit,
                channels: args.channels.clone(),
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
            stamped: args.stamped,
            unit: args.time_unit.unwrap_or(TimeUnit::Seconds),
        },
    })
}

/// The JSON lines on standard output, one per bin boundary and one per episode's end,
/// each flushed at once; bad frames said on standard error.
struct Output<W: Write> {
    out: W,
    /// Episodes ended so far.
    episodes: usize,
}

impl<W: Write> Sink for Output<W> {
    fn events(&mut self, stream: &StreamClassifier, events: &[Event]) -> neurotex::Result<()> {
        let write = |e| neurotex::error::DataError::write("standard output", e);
        for event in events {
            self.episodes += usize::from(matches!(event, Event::End(_)));
            writeln!(self.out, "{}", event_json(stream, event)).map_err(write)?;
        }
        self.out.flush().map_err(write)?;
        Ok(())
    }

    fn bad_frame(&mut self, place: &str, why: &str) {
        eprintln!("warning: {place}: bad frame skipped: {why}");
    }
}
