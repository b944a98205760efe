//! `stream`: a causal model classifies a live taxel stream frame by frame; the options
//! that say where frames come from, how they are read and how an episode is decided, and
//! `predict --causal`'s decision options.

use std::path::PathBuf;

use crate::causal::DecisionRule;
use crate::csvlog::{ChannelSelect, Column, CsvFormat, CsvOverrides, Delimiter};
use crate::error::OptionsError;
use crate::events::Origin;
use crate::recording::TimeUnit;
use crate::saved::{SavedModel, Trained};
use crate::stream::events::{EventEncoding, EventSource};
use crate::stream::frames::FrameFormat as Format;
use crate::stream::{EpisodeRule, StreamParams};
use crate::Result;

/// How the per-bin classifications of an episode become a decision, and over which window:
/// the options `stream` and `predict --causal` share.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct DecisionOptions {
    /// The window classified at each bin boundary, s (whole bins); default: the median
    /// length of the model's training recordings (10 s when the model does not say).
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
    /// a spiking network runs step by step on the spikes as they come).
    #[cfg_attr(feature = "cli", arg(long))]
    pub model: PathBuf,
    /// With --model FILE.nir from another tool (no neurotex metadata in the graph): a
    /// neurotex spiking model trained with --causal whose pipeline, grid and labels the
    /// graph's network runs with.
    #[cfg_attr(feature = "cli", arg(long))]
    pub like: Option<PathBuf>,
    /// Where frames come from: `-` (standard input), a file, `tcp://HOST:PORT` (listens
    /// there and takes one connection: the sensor's driver connects and sends frames
    /// until it closes) or `udp://HOST:PORT` (binds there; each datagram holds whole lines
    /// or frames; an empty datagram ends the input). SIGINT (Ctrl-C), SIGTERM or SIGHUP
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
                if self.origin.is_some() {
                    return Err(OptionsError::NotApplicable {
                        option: "--origin",
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
        let origin = self.origin.as_deref().map(|o| match o {
            "zero" => Origin::Zero,
            _ => Origin::First,
        });
        // Binary records' stamps are microseconds unless said: the record's definition, not
        // the training files' unit.
        let unit = match (encoding, self.time_unit) {
            (_, Some(unit)) => Some(unit),
            (EventEncoding::Binary, None) => Some(TimeUnit::Microseconds),
            (EventEncoding::Text, None) => None,
        };
        let source = EventSource::for_model(model, unit, origin).map_err(OptionsError::Conflict)?;
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
