//! A live taxel stream classified frame by frame with a causal model (docs/live-rigs.md):
//! online resampling to 1 kHz, the causal filter, the fixed resting values and scale,
//! Izhikevich state across frames, and at every bin boundary the model's classification of
//! the current window with the decision rule of [`crate::causal`].
//!
//! Every stage keeps its state between frames and computes each 1 ms step with the same
//! arithmetic as the offline causal pipeline ([`crate::signal::Preprocessor`] with
//! [`crate::signal::CausalConditioning`], [`crate::encode::Encoder`],
//! [`crate::causal::episode_decisions`]), so a recording streamed as one episode gives
//! exactly the decisions of the offline twin.
//!
//! Memory is bounded by the window, not the stream: per taxel the filter, neuron and
//! resampler state (a few f64) and the spike times of the current window (as u32).
#![deny(missing_docs)]

pub mod events;
pub mod frames;
pub mod input;
pub mod lsl;
mod network;
mod spike_log;
mod window_glcm;

// The layers below, under the names their modules had when they were one crate, so that
// `crate::causal` and the like read the same in every layer.
use neurotex_core::{csvlog, error, recording, values, Error};
use neurotex_features::features;
use neurotex_learn::snn;
use neurotex_pipeline::{causal, model, pipeline, saved, spiking_model};
use neurotex_signal::{encode, signal};

use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};

use crate::causal::{
    network_window, window_steps, BinDecision, Decider, DecisionRule, EpisodeEnd, EpisodeSummary,
};
use crate::encode::{Encoder, SpikeTrains};
use crate::error::{ParamError, Result};
use crate::model::{Model, Prediction};
use crate::pipeline::{Encoded, Encoding};
use crate::recording::{Meta, TimeUnit};
use crate::saved::{SavedModel, Trained};
use crate::signal::{Butterworth2, CausalConditioning, Preprocessor, RestTracker, ENCODER_FS};
use crate::spiking_model::decide;
use network::NetworkFeed;
use spike_log::SpikeLog;
use window_glcm::WindowGlcm;

/// The default largest gap between two frames' time stamps within one episode, s: a
/// longer silence ends the episode (resampling across it would invent samples).
pub const DEFAULT_MAX_GAP_S: f64 = 1.0;

/// The largest `max_gap_s` allowed, s. A frame completes the 1 kHz steps (and their bins)
/// since the previous frame, so the largest gap bounds what one frame can cost: 10 000
/// steps and 50 classifications.
pub const MAX_GAP_S: f64 = 10.0;

/// The largest time stamp either side of zero, s (2^33 s, about 272 years): up to there an
/// f64 stamp resolves 1 µs or better; beyond, stamps 1 ms apart can round to one number
/// (at 2^53 ms to the same one), and the 1 kHz resampling would place steps wrongly.
pub const MAX_STAMP_S: f64 = 8_589_934_592.0;

/// The default window when the model does not record its training recordings' length,
/// ms.
pub const DEFAULT_WINDOW_MS: usize = 10_000;

/// How a stream is cut into episodes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum EpisodeRule {
    /// One episode from the first frame until a reset or the end of the input.
    Whole,
    /// An episode starts at the first frame whose largest conditioned taxel value
    /// (resting value removed, divided by the scale; unfiltered) reaches `level`, and ends
    /// once that value has stayed below `level / 2` for `rest_ms`.
    Onset {
        /// The contact level, in units of the model's scale.
        level: f64,
        /// How long the signal stays at rest before the episode ends, ms.
        rest_ms: usize,
    },
}

impl std::str::FromStr for EpisodeRule {
    type Err = ParamError;

    /// `whole`, `onset` (level 0.1, rest 500 ms), `onset:LEVEL` or `onset:LEVEL:REST_MS`.
    fn from_str(s: &str) -> Result<Self, ParamError> {
        let bad = || {
            ParamError::new(
                "episode",
                "episodes are `whole`, `onset`, `onset:LEVEL` or `onset:LEVEL:REST_MS` (LEVEL > 0, REST_MS >= 1)",
                s,
            )
        };
        let mut parts = s.trim().split(':');
        match parts.next() {
            Some("whole") if parts.next().is_none() => Ok(EpisodeRule::Whole),
            Some("onset") => {
                let level = match parts.next() {
                    Some(l) => l.parse::<f64>().map_err(|_| bad())?,
                    None => 0.1,
                };
                let rest_ms = match parts.next() {
                    Some(r) => r.parse::<usize>().map_err(|_| bad())?,
                    None => 500,
                };
                let ok = level.is_finite() && level > 0.0 && (1..=3_600_000).contains(&rest_ms);
                if !ok || parts.next().is_some() {
                    return Err(bad());
                }
                Ok(EpisodeRule::Onset { level, rest_ms })
            }
            _ => Err(bad()),
        }
    }
}

/// How a stream is classified.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamParams {
    /// The window classified at each bin boundary, ms (whole bins).
    pub window_ms: usize,
    /// When the per-bin classifications become a decision.
    pub rule: DecisionRule,
    /// How the stream is cut into episodes.
    pub episodes: EpisodeRule,
    /// The frames' rate when they carry no time stamps, Hz.
    pub fs: f64,
    /// The largest gap between time stamps within an episode, s.
    pub max_gap_s: f64,
    /// The sliding speed, for models whose features need it (`all-taxels-mm`).
    pub speed_mm_s: Option<f64>,
}

impl StreamParams {
    /// The defaults for `model`: its training recordings' median length as the window
    /// ([`DEFAULT_WINDOW_MS`] when unknown), the default rule, whole episodes, 1 kHz.
    pub fn for_model(model: &impl Trained) -> Self {
        StreamParams {
            window_ms: model
                .provenance()
                .median_duration_ms
                .unwrap_or(DEFAULT_WINDOW_MS),
            rule: DecisionRule::default(),
            episodes: EpisodeRule::Whole,
            fs: ENCODER_FS,
            max_gap_s: DEFAULT_MAX_GAP_S,
            speed_mm_s: None,
        }
    }

    /// The window classified at each bin boundary for `model`, in ms: `window_s` seconds
    /// when given, else the model's default ([`StreamParams::for_model`]).
    ///
    /// # Errors
    /// A window outside (0, 3600] s.
    pub fn window_ms(model: &impl Trained, window_s: Option<f64>) -> Result<usize, ParamError> {
        match window_s {
            None => Ok(Self::for_model(model).window_ms),
            Some(s) if s.is_finite() && s > 0.0 && s <= 3600.0 => Ok((s * 1000.0).round() as usize),
            Some(s) => Err(ParamError::new(
                "window-s",
                "the window must be in (0, 3600] s",
                s,
            )),
        }
    }

    fn check(&self) -> Result<(), ParamError> {
        self.rule.check()?;
        if !(1..=3_600_000).contains(&self.window_ms) {
            let rule = "the window must be between 1 ms and one hour";
            return Err(ParamError::new("window", rule, self.window_ms));
        }
        if !(self.fs.is_finite() && self.fs >= 1.0 && self.fs <= 1e6) {
            let rule = "the frame rate must be between 1 Hz and 1 MHz";
            return Err(ParamError::new("fs", rule, self.fs));
        }
        if !(self.max_gap_s.is_finite() && self.max_gap_s > 0.0 && self.max_gap_s <= MAX_GAP_S) {
            let rule =
                "the largest gap must be in (0, 10] s (it bounds the steps one frame completes)";
            return Err(ParamError::new("max-gap", rule, self.max_gap_s));
        }
        Ok(())
    }
}

/// What a stream reports.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A bin boundary's classification.
    Bin(BinDecision),
    /// The end of an episode.
    End(EpisodeSummary),
}

/// A frame that was skipped, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadFrame {
    /// Not one value per channel.
    #[error("expected {expected} values, got {got}")]
    FieldCount {
        /// The model's channels.
        expected: usize,
        /// The frame's values.
        got: usize,
    },
    /// A value that is not a finite number.
    #[error("value {index} is not a finite number")]
    NotFinite {
        /// Which value, counted from the line's first field (the time stamp is value 0
        /// when given).
        index: usize,
    },
    /// A value beyond [`crate::values::MAX_SAMPLE_MAGNITUDE`]: no sensor's reading.
    #[error("value {index} is {value:?}, beyond ±1e15, which is no sensor's reading")]
    OutOfRange {
        /// Which value, counted from the line's first field (the time stamp is value 0
        /// when given).
        index: usize,
        /// The value.
        value: f64,
    },
    /// A time stamp that is not a finite number.
    #[error("the time stamp {t} is not a finite number")]
    StampNotFinite {
        /// The stamp, as given (in its own unit).
        t: f64,
    },
    /// A time stamp not after the previous frame's.
    #[error("time stamp {t} s is not after the previous frame's {previous} s")]
    Stamp {
        /// The frame's stamp.
        t: f64,
        /// The previous frame's.
        previous: f64,
    },
    /// A time stamp further after the previous frame's than the largest gap.
    #[error(
        "time stamp {t} s is {:.6} s after the previous stamp, {previous} s: more than the largest gap ({max_gap_s} s)",
        .t - .previous
    )]
    Jump {
        /// The frame's stamp.
        t: f64,
        /// The previous frame's.
        previous: f64,
        /// The largest gap.
        max_gap_s: f64,
    },
    /// An event stamped before the previous event.
    #[error("time stamp {t} s is before the previous event's {previous} s: events must come in time order")]
    Order {
        /// The event's stamp.
        t: f64,
        /// The previous event's.
        previous: f64,
    },
    /// An event that names no cell of the model's grid, or a polarity that is neither ON
    /// nor OFF.
    #[error("{0}")]
    Address(crate::error::EventError),
    /// A time stamp beyond [`MAX_STAMP_S`].
    #[error("time stamp {t} s exceeds the exact range of stamps (within 2^33 s, about 272 years, of zero; beyond, stamps 1 ms apart can be one number)")]
    StampRange {
        /// The frame's stamp.
        t: f64,
    },
}

/// Why a frame was not taken.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// A bad frame, counted and skipped: the stream goes on.
    #[error("bad frame: {0}")]
    Bad(#[from] BadFrame),
    /// The model could not classify a window (only a model that cannot run on this
    /// stream, such as one whose features need a speed that was not given).
    #[error(transparent)]
    Classify(#[from] crate::Error),
}

/// The longest episode, in 1 ms steps: spike times are kept as u32 (49 days); an episode
/// this long ends and the next starts, one hour short of the limit (far more than the
/// steps one frame completes, [`MAX_GAP_S`]).
const MAX_EPISODE_STEPS: usize = u32::MAX as usize - 3_600_000;

/// One episode's state.
#[derive(Debug, Clone)]
struct EpisodeState {
    /// The first frame's time stamp (in its unit), or its frame number without stamps.
    origin: f64,
    /// Frames of the episode seen by the resampler.
    frames: usize,
    /// The resampler's last two frames' times, s from the origin (the values are
    /// [`StreamClassifier::before`] and [`StreamClassifier::last`]).
    before_t: f64,
    last_t: f64,
    /// The next 1 kHz step the resampler emits.
    next: usize,
    /// Steps conditioned so far.
    steps: usize,
    /// The causal filter's two state values per cell.
    filter_state: [Vec<f64>; 2],
    /// Whether [`StreamClassifier::previous`] holds the previous step (for the FA drive).
    has_previous: bool,
    /// The populations' neurons, in the order of [`Encoded::populations`], each marked
    /// whether it is FA (driven by the rectified rate of change).
    neurons: Vec<(Encoder, bool)>,
    /// What the window keeps of the spikes.
    kept: Kept,
    decider: Decider,
    bins: usize,
    /// Since when (s from the origin) the signal has been at rest, for onset episodes.
    rest_since: Option<f64>,
    /// The resting values tracked through the episode under a drift window.
    tracker: Option<RestTracker>,
}

/// What an episode keeps of its spikes for the classifications at bin boundaries.
#[derive(Debug, Clone)]
struct Kept {
    /// The spikes of the current window, per population (none for a spiking network,
    /// which takes them as they come).
    spikes: Vec<SpikeLog>,
    /// A spiking network's state.
    network: Option<NetworkFeed>,
    /// Per population, the window's co-occurrence counts kept bin by bin, for 3D-GLCM
    /// models (empty for others, which count the window's spike times afresh).
    glcm: Vec<WindowGlcm>,
}

impl Kept {
    /// Opens the next 1 ms step.
    fn begin_step(&mut self) {
        for log in &mut self.spikes {
            log.begin_step();
        }
    }

    /// Takes the open step's spikes of `population` in the cells from `start` on
    /// (`raster[i]` for cell `start + i`, whose taxel flag is `present[i]`).
    fn add(&mut self, population: usize, start: usize, raster: &[u8], present: &[bool]) {
        if let Some(window) = self.glcm.get_mut(population) {
            window.add_spikes(start, raster);
        }
        if let Some(log) = self.spikes.get_mut(population) {
            log.add_part(start, raster, present);
        }
        if let Some(feed) = &mut self.network {
            feed.add(population, start, raster);
        }
    }
}

/// A causal model classifying a live stream frame by frame.
#[derive(Debug)]
pub struct StreamClassifier {
    model: SavedModel,
    params: StreamParams,
    conditioning: CausalConditioning,
    filter: Option<Butterworth2>,
    rows: usize,
    cols: usize,
    present: Vec<bool>,
    /// The cell of each value of a frame.
    channel_cells: Vec<usize>,
    bin: usize,
    window: usize,
    /// Frames at 1 kHz without stamps go straight to the encoder (as offline).
    uniform_1k: bool,
    /// An empty window of a 3D-GLCM model's co-occurrence counts, each episode's start.
    empty_glcm: Option<WindowGlcm>,
    episode: Option<EpisodeState>,
    /// The previous frame's time stamp.
    previous_stamp: Option<f64>,
    /// The stamp of the last frame refused for not following the previous one, until the
    /// next frame that reaches the stamp check: when that frame follows it instead, the
    /// clock has jumped (see [`StreamClassifier::push`]).
    stray_stamp: Option<f64>,
    frames: u64,
    bad_frames: u64,
    events: Vec<Event>,
    // Per-frame buffers, `rows * cols` each, reused so that a frame between bin boundaries
    // allocates nothing.
    cell_frame: Vec<f64>,
    before: Vec<f64>,
    last: Vec<f64>,
    step_in: Vec<f64>,
    /// The resting values of the current step under a drift window.
    rest: Vec<f64>,
    conditioned: Vec<f64>,
    previous: Vec<f64>,
    drive: Vec<f64>,
    raster: Vec<u8>,
    /// An event stream's state (`None` for frames).
    event_input: Option<events::EventState>,
}

pub use crate::causal::NO_RUNNING_SPECTRUM;

impl StreamClassifier {
    /// A stream classifier for a causal `model` (a feature model or a spiking network);
    /// frames hold one value per taxel of the model's grid, in row-major order of the
    /// cells holding a taxel.
    ///
    /// # Errors
    /// A model trained without `--causal` (its filter needs the future), a model whose
    /// features need a speed when none is given, or broken parameters.
    pub fn new(model: impl Into<SavedModel>, params: StreamParams) -> Result<Self> {
        let model = model.into();
        if let Some(why) = events::trained_on_events(&model) {
            return Err(crate::error::OptionsError::Conflict(why).into());
        }
        let conditioning = match model.streams() {
            Ok(conditioning) => conditioning.clone(),
            Err(why) => return Err(crate::error::OptionsError::Conflict(why.into()).into()),
        };
        Self::with_conditioning(model, params, conditioning)
    }

    /// [`StreamClassifier::new`] with the conditioning of frames given (unused by events).
    fn with_conditioning(
        model: SavedModel,
        params: StreamParams,
        conditioning: CausalConditioning,
    ) -> Result<Self> {
        params.check()?;
        if let SavedModel::Features(m) = &model {
            if m.features().method == crate::pipeline::Method::AllTaxelsMm
                && !params.speed_mm_s.is_some_and(|v| v.is_finite() && v != 0.0)
            {
                let rule = "the model's all-taxels-mm features need the sliding speed (--speed)";
                return Err(ParamError::new("speed", rule, "none").into());
            }
        }
        let grid = model.grid().clone();
        let (rows, cols) = (grid.rows(), grid.cols());
        let cells = rows * cols;
        let present = grid.present().to_vec();
        if conditioning.offsets.len() != cells {
            let rule = "the model's causal resting values must match its grid";
            return Err(ParamError::new("model", rule, conditioning.offsets.len()).into());
        }
        if let Some(window) = model.params().preprocess.drift_window_ms {
            RestTracker::new(cells, window)?;
        }
        let channel_cells = (0..cells).filter(|&c| present[c]).collect();
        let filter = Preprocessor::new(&model.params().preprocess)?
            .filter()
            .copied();
        let bin = model.params().volume.bin_ms;
        let window = window_steps(params.window_ms, bin);
        let empty_glcm = match &model {
            SavedModel::Features(m) if m.features().method == crate::pipeline::Method::Glcm3d => {
                WindowGlcm::new(
                    rows,
                    cols,
                    &present,
                    bin,
                    m.extractor().glcm_params(),
                    window / bin,
                )
            }
            _ => None,
        };
        let buffer = vec![0.0; cells];
        Ok(StreamClassifier {
            conditioning,
            filter,
            rows,
            cols,
            present,
            channel_cells,
            bin,
            window,
            uniform_1k: (params.fs - ENCODER_FS).abs() < 1e-9,
            empty_glcm,
            episode: None,
            previous_stamp: None,
            stray_stamp: None,
            frames: 0,
            bad_frames: 0,
            events: Vec::new(),
            cell_frame: buffer.clone(),
            before: buffer.clone(),
            last: buffer.clone(),
            step_in: buffer.clone(),
            rest: buffer.clone(),
            conditioned: buffer.clone(),
            previous: buffer.clone(),
            drive: buffer,
            raster: vec![0; cells],
            event_input: None,
            model,
            params,
        })
    }

    /// The model.
    pub fn model(&self) -> &SavedModel {
        &self.model
    }

    /// The parameters.
    pub fn params(&self) -> &StreamParams {
        &self.params
    }

    /// Values a frame holds: one per taxel.
    pub fn channels(&self) -> usize {
        self.channel_cells.len()
    }

    /// Frames taken (bad ones not counted).
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Frames skipped as bad.
    pub fn bad_frames(&self) -> u64 {
        self.bad_frames
    }

    /// Counts a frame the caller could not even parse (a text line that is not numbers, a
    /// truncated binary frame) among the bad frames.
    pub fn skip_bad_frame(&mut self) {
        self.bad_frames += 1;
    }

    /// Spike times held for the current window, over all populations and cells (what
    /// grows with the window, not with the stream).
    pub fn retained_spikes(&self) -> usize {
        self.episode
            .as_ref()
            .map_or(0, |e| e.kept.spikes.iter().map(SpikeLog::len).sum())
    }

    /// Whether an episode is under way.
    pub fn in_episode(&self) -> bool {
        self.episode.is_some()
    }

    /// Takes one frame: its time stamp in s (`None` for frames at the stream's fixed rate;
    /// a stream stamps every frame or none) and one value per taxel; [`Self::push_in`]
    /// with stamps in seconds. Returns what the
    /// frame completed: a classification at each bin boundary it reached, and the end of
    /// an episode it closed.
    ///
    /// A stamped frame follows the previous one when its stamp is after the previous
    /// frame's by at most `max_gap_s`. A frame that does not is a bad frame
    /// ([`BadFrame::Stamp`] or [`BadFrame::Jump`]); if the next frame (with a valid stamp and
    /// values) follows that bad frame instead of the previous one, the clock has jumped (a
    /// pause, a restarted sensor): the episode ends (`ended_by: gap`) and a new one starts
    /// at that next frame. So one wrong stamp (a bit flip far ahead, a repeated or early
    /// stamp) costs its own frame only, and a clock that jumps and stays costs one frame.
    ///
    /// # Errors
    /// [`StreamError::Bad`] for a bad frame (wrong value count, a value that is not finite,
    /// a time stamp beyond [`MAX_STAMP_S`] or not following the previous one): it is
    /// counted and skipped, and the stream goes on. [`StreamError::Classify`] when the
    /// model cannot classify a window.
    pub fn push(&mut self, time_s: Option<f64>, values: &[f64]) -> Result<&[Event], StreamError> {
        self.push_in(time_s, TimeUnit::Seconds, values)
    }

    /// [`Self::push`] with the time stamp in `unit`, the unit it was logged in (a stream
    /// gives every stamp in one unit). An episode's first stamp is subtracted in that unit
    /// (exact for integer stamps up to 2^53, such as ms since an epoch) before the
    /// difference becomes seconds ([`TimeUnit::to_seconds`]), as offline reading does: so
    /// frames stamped on the encoder's 1 ms grid give their values to the encoder exactly,
    /// and the same spikes as the same frames unstamped at 1 kHz.
    ///
    /// # Errors
    /// As [`Self::push`].
    pub fn push_in(
        &mut self,
        stamp: Option<f64>,
        unit: TimeUnit,
        values: &[f64],
    ) -> Result<&[Event], StreamError> {
        self.events.clear();
        let time_s = stamp.map(|t| unit.to_seconds(t));
        let (jumped, index) = self.accept(time_s, values)?;
        if jumped && self.episode.is_some() {
            self.end_episode(EpisodeEnd::Gap)?;
        }
        if self
            .episode
            .as_ref()
            .is_some_and(|e| e.steps >= MAX_EPISODE_STEPS)
        {
            self.end_episode(EpisodeEnd::Gap)?;
        }
        // Only onset episodes look at the contact level: a whole-stream episode skips the
        // pass over the cells.
        let level = match self.params.episodes {
            EpisodeRule::Onset { .. } => self.contact_level(),
            EpisodeRule::Whole => 0.0,
        };
        if self.episode.is_none() {
            if let EpisodeRule::Onset { level: onset, .. } = self.params.episodes {
                if level < onset {
                    return Ok(&self.events);
                }
            }
            self.episode = Some(self.new_episode(stamp.unwrap_or(index)));
        }
        let origin = self
            .episode
            .as_ref()
            .expect("an episode is under way")
            .origin;
        // As offline: stamps less the first (in their own unit), or frame numbers over the
        // rate.
        let relative = match stamp {
            Some(t) => unit.to_seconds(t - origin),
            None => (index - origin) / self.params.fs,
        };
        if time_s.is_none() && self.uniform_1k {
            // The frame is the step's input; the buffers trade places, not values (both
            // hold 0 in masked cells, and the next frame overwrites every taxel).
            std::mem::swap(&mut self.step_in, &mut self.cell_frame);
            self.step()?;
        } else {
            self.resample(relative)?;
        }
        self.end_at_rest(level, relative)?;
        Ok(&self.events)
    }

    /// Checks a frame, follows its stamp (`time_s`, seconds) and places its values on the
    /// cells: whether the stamps jumped, and the frame's index in the stream.
    fn accept(&mut self, time_s: Option<f64>, values: &[f64]) -> Result<(bool, f64), StreamError> {
        let checked = self.check_frame(time_s, values);
        let jumped = match (checked, time_s) {
            (Err(bad), _) => Err(bad),
            (Ok(()), Some(t)) => self.follow(t),
            (Ok(()), None) => Ok(false),
        };
        let jumped = match jumped {
            Ok(jumped) => jumped,
            Err(bad) => {
                self.bad_frames += 1;
                return Err(bad.into());
            }
        };
        let index = self.frames as f64;
        self.frames += 1;
        if values.len() == self.cell_frame.len() {
            self.cell_frame.copy_from_slice(values); // every cell holds a taxel
        } else {
            for (&v, &cell) in values.iter().zip(&self.channel_cells) {
                self.cell_frame[cell] = v;
            }
        }
        Ok((jumped, index))
    }

    /// Ends an onset episode once the contact `level` has stayed below half the onset
    /// level for the rule's rest time (`relative`: the frame's time in the episode, s).
    fn end_at_rest(&mut self, level: f64, relative: f64) -> Result<(), StreamError> {
        if let EpisodeRule::Onset {
            level: onset,
            rest_ms,
        } = self.params.episodes
        {
            let episode = self.episode.as_mut().expect("an episode is under way");
            if level < onset / 2.0 {
                let since = *episode.rest_since.get_or_insert(relative);
                if relative - since >= rest_ms as f64 / 1000.0 {
                    self.end_episode(EpisodeEnd::Rest)?;
                }
            } else {
                episode.rest_since = None;
            }
        }
        Ok(())
    }

    /// Ends the current episode (a reset frame or control line); the next frame starts a
    /// new one (at once, or at contact for onset episodes).
    ///
    /// # Errors
    /// The model cannot classify the episode's last window.
    pub fn reset(&mut self) -> Result<&[Event], StreamError> {
        // The next episode's clock may start again: its stamps follow none before.
        self.previous_stamp = None;
        self.stray_stamp = None;
        self.end_with(EpisodeEnd::Reset)
    }

    /// Ends the stream: the last steps of the current episode and its summary.
    ///
    /// # Errors
    /// The model cannot classify the episode's last window.
    pub fn finish(&mut self) -> Result<&[Event], StreamError> {
        self.end_with(EpisodeEnd::EndOfInput)
    }

    /// Stops the stream before its input ended (an interrupt): as [`StreamClassifier::finish`],
    /// the episode's summary saying it was stopped.
    ///
    /// # Errors
    /// The model cannot classify the episode's last window.
    pub fn stop(&mut self) -> Result<&[Event], StreamError> {
        self.end_with(EpisodeEnd::Stopped)
    }

    /// Ends the current episode, if any, for `why`; its summary is the one event.
    fn end_with(&mut self, why: EpisodeEnd) -> Result<&[Event], StreamError> {
        self.events.clear();
        if self.episode.is_some() {
            self.end_episode(why)?;
        }
        Ok(&self.events)
    }

    fn check_frame(&self, time_s: Option<f64>, values: &[f64]) -> Result<(), BadFrame> {
        let expected = self.channel_cells.len();
        if values.len() != expected {
            return Err(BadFrame::FieldCount {
                expected,
                got: values.len(),
            });
        }
        let first_value = usize::from(time_s.is_some());
        if let Some(t) = time_s {
            if !t.is_finite() {
                return Err(BadFrame::StampNotFinite { t });
            }
            if t.abs() > MAX_STAMP_S {
                return Err(BadFrame::StampRange { t });
            }
        }
        // One pass without early exit (it vectorises); the position only for a bad frame.
        let in_range = crate::values::sample_in_range;
        if values.iter().fold(false, |bad, &v| bad | !in_range(v)) {
            let i = values.iter().position(|&v| !in_range(v)).unwrap_or(0);
            let index = i + first_value;
            return Err(match values[i].is_finite() {
                false => BadFrame::NotFinite { index },
                true => BadFrame::OutOfRange {
                    index,
                    value: values[i],
                },
            });
        }
        Ok(())
    }

    /// Whether a frame stamped `t` (otherwise good) moves the stream's clock: `Ok(false)`
    /// when it follows the previous frame, `Ok(true)` when it follows the last frame refused
    /// instead (the clock jumped there), the bad frame otherwise. Only frames that reach
    /// this check touch the clock, so a frame refused for its values cannot confirm a jump.
    fn follow(&mut self, t: f64) -> Result<bool, BadFrame> {
        let max_gap_s = self.params.max_gap_s;
        // Events may share a stamp; frames may not.
        let equal = self.event_input.is_some();
        let follows = |p: f64| (t > p || (equal && t == p)) && t - p <= max_gap_s;
        let stray = self.stray_stamp.take();
        let Some(previous) = self.previous_stamp else {
            self.previous_stamp = Some(t);
            return Ok(false);
        };
        // When it follows both (a repeated stamp was refused), the clock has not moved.
        if follows(previous) || stray.is_some_and(follows) {
            self.previous_stamp = Some(t);
            return Ok(!follows(previous));
        }
        self.stray_stamp = Some(t);
        Err(match t <= previous {
            true if equal => BadFrame::Order { t, previous },
            true => BadFrame::Stamp { t, previous },
            false => BadFrame::Jump {
                t,
                previous,
                max_gap_s,
            },
        })
    }

    /// The largest taxel value of the current frame, resting value removed, in units of
    /// the scale (unfiltered): what onset episodes compare to their level.
    fn contact_level(&self) -> f64 {
        let c = &self.conditioning;
        self.channel_cells
            .iter()
            .map(|&cell| (self.cell_frame[cell] - c.offsets[cell]) / c.scale)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    fn new_episode(&self, origin: f64) -> EpisodeState {
        let cells = self.rows * self.cols;
        let p = self.model.params();
        let neuron = |gain: f64| {
            Encoder::new(p.encoder.with_gain(gain), cells).expect("the model's checked parameters")
        };
        let neurons = match p.encoding {
            Encoding::Sa => vec![(neuron(p.encoder.gain), false)],
            Encoding::Fa => vec![(neuron(p.fa.gain), true)],
            Encoding::SaFa => vec![(neuron(p.encoder.gain), false), (neuron(p.fa.gain), true)],
        };
        let (spikes, network) = match &self.model {
            SavedModel::Features(_) => (vec![SpikeLog::default(); neurons.len()], None),
            SavedModel::Spiking(m) => {
                let net = m.network();
                let window = network_window(self.window, self.bin, net.dt_ms as usize);
                (
                    Vec::new(),
                    Some(NetworkFeed::new(net, &self.present, window)),
                )
            }
        };
        EpisodeState {
            origin,
            frames: 0,
            before_t: 0.0,
            last_t: 0.0,
            next: 0,
            steps: 0,
            filter_state: [vec![0.0; cells], vec![0.0; cells]],
            has_previous: false,
            kept: Kept {
                spikes,
                network,
                glcm: match &self.empty_glcm {
                    Some(empty) => vec![empty.clone(); neurons.len()],
                    None => Vec::new(),
                },
            },
            neurons,
            decider: Decider::new(self.params.rule),
            bins: 0,
            rest_since: None,
            tracker: (p.preprocess.drift_window_ms)
                .map(|w| RestTracker::new(cells, w).expect("a window checked with the model")),
        }
    }

    /// Takes the current frame, at `t` s from the episode's start, into the resampler
    /// and conditions each 1 kHz step before `t`: those steps lie between the last frame
    /// and this one, as [`crate::signal::resample_linear`] brackets them.
    fn resample(&mut self, t: f64) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        if episode.frames > 0 {
            let ta = episode.last_t;
            loop {
                let episode = self.episode.as_mut().expect("an episode is under way");
                let ts = 0.0 + episode.next as f64 / ENCODER_FS;
                if ts >= t {
                    break;
                }
                episode.next += 1;
                let w = ((ts - ta) / (t - ta)).clamp(0.0, 1.0);
                interpolate(&self.last, &self.cell_frame, w, &mut self.step_in);
                self.step()?;
            }
        }
        let episode = self.episode.as_mut().expect("an episode is under way");
        std::mem::swap(&mut self.before, &mut self.last);
        self.last.copy_from_slice(&self.cell_frame);
        episode.before_t = episode.last_t;
        episode.last_t = t;
        episode.frames += 1;
        Ok(())
    }

    /// The episode's last steps, up to its last frame's time, as offline: bracketed by
    /// the last two frames (clamped beyond the last), or the only frame.
    fn flush(&mut self) -> Result<(), StreamError> {
        if self.event_input.is_some() {
            return self.flush_events();
        }
        let episode = self.episode.as_mut().expect("an episode is under way");
        let (ta, tb) = (episode.before_t, episode.last_t);
        let total = match episode.frames {
            0 => return Ok(()),
            1 => 1,
            _ => crate::signal::resampled_len(tb, ENCODER_FS, 1)
                .expect("a span bounded by the longest episode"),
        };
        loop {
            let episode = self.episode.as_mut().expect("an episode is under way");
            if episode.next >= total {
                return Ok(());
            }
            let ts = 0.0 + episode.next as f64 / ENCODER_FS;
            episode.next += 1;
            match episode.frames {
                1 => self.step_in.copy_from_slice(&self.last),
                _ => {
                    let w = ((ts - ta) / (tb - ta)).clamp(0.0, 1.0);
                    interpolate(&self.before, &self.last, w, &mut self.step_in);
                }
            }
            self.step()?;
        }
    }

    /// Conditions one 1 kHz step (`step_in`, raw values per cell), runs the neurons,
    /// keeps their spikes, and classifies at a bin boundary.
    ///
    /// The cells go through every stage [`PART`] at a time, so that a large skin's step
    /// reads and writes each cell's state once while the part's values stay in the
    /// cache. Conditioning removes the resting value, filters and scales, with the
    /// operations of the offline pipeline in its order. Masked cells are filtered too:
    /// their input is 0 and a filter started at 0 stays at exactly 0, as offline, where
    /// they are left out; including them keeps the loop free of gathers.
    fn step(&mut self) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        let first = episode.steps == 0;
        let cells = self.rows * self.cols;
        let has_fa = episode.neurons.iter().any(|n| n.1);
        let [z0, z1] = &mut episode.filter_state;
        let offsets = match &mut episode.tracker {
            Some(tracker) => {
                tracker.push(&self.step_in, &mut self.rest);
                &self.rest
            }
            None => &self.conditioning.offsets,
        };
        episode.kept.begin_step();
        for start in (0..cells).step_by(PART) {
            let part = start..(start + PART).min(cells);
            let conditioning = Conditioning {
                raw: &self.step_in[part.clone()],
                offsets: &offsets[part.clone()],
                present: &self.present[part.clone()],
                state: [&mut z0[part.clone()], &mut z1[part.clone()]],
                out: &mut self.conditioned[part.clone()],
            };
            conditioning.run(self.filter.as_ref(), self.conditioning.scale, first);
            let raster = &mut self.raster[part.clone()];
            for (population, (neurons, is_fa)) in episode.neurons.iter_mut().enumerate() {
                let input = match is_fa {
                    false => &self.conditioned[part.clone()],
                    true => {
                        let drive = &mut self.drive[part.clone()];
                        let x = &self.conditioned[part.clone()];
                        let p = &self.previous[part.clone()];
                        for ((d, &x), &p) in drive.iter_mut().zip(x).zip(p) {
                            *d = if episode.has_previous {
                                (x - p).abs()
                            } else {
                                0.0
                            };
                        }
                        &*drive
                    }
                };
                neurons.run_part(part.start, input, raster);
                let present = &self.present[part.clone()];
                episode.kept.add(population, part.start, raster, present);
            }
        }
        if has_fa {
            std::mem::swap(&mut self.previous, &mut self.conditioned);
            episode.has_previous = true;
        }
        self.end_step()
    }

    /// Ends the episode's current 1 ms step, whose spikes were added: the network's step
    /// when its time step is complete, and the window's classification at a bin boundary.
    fn end_step(&mut self) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        episode.steps += 1;
        if let (Some(feed), SavedModel::Spiking(m)) = (&mut episode.kept.network, &self.model) {
            feed.end_ms(m.network());
        }
        if episode.steps.is_multiple_of(self.bin) {
            for window in &mut episode.kept.glcm {
                window.close_bin();
            }
            self.boundary()?;
        }
        Ok(())
    }

    /// Classifies the window ending at the current step, a bin boundary.
    fn boundary(&mut self) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        let end = episode.steps;
        let start = end.saturating_sub(self.window);
        // Later windows start later, and the episode's summary no earlier than this one.
        for log in &mut episode.kept.spikes {
            log.drop_before(start);
        }
        let (class, shares) = match (&self.model, &episode.kept.network) {
            (SavedModel::Spiking(m), Some(feed)) => decide(&feed.scores(m.network())),
            (SavedModel::Features(m), _) => {
                let prediction = match episode.kept.glcm.is_empty() {
                    true => self.classify(m, start, end)?,
                    false => self.classify_window(m)?,
                };
                (m.class_index(&prediction.predicted), prediction.shares)
            }
            (SavedModel::Spiking(_), None) => unreachable!("a spiking model's episode runs it"),
        };
        let t_s = end as f64 / 1000.0;
        let episode = self.episode.as_mut().expect("an episode is under way");
        let decided = episode.decider.observe(t_s, class, shares[class]);
        episode.bins += 1;
        let decision = episode.decider.decision().map(|d| d.0);
        self.events.push(Event::Bin(BinDecision {
            t_s,
            class,
            shares,
            decided,
            decision,
        }));
        Ok(())
    }

    /// The model's prediction for the steps `[start, end)` of the episode.
    fn classify(&self, model: &Model, start: usize, end: usize) -> Result<Prediction, StreamError> {
        let episode = self.episode.as_ref().expect("an episode is under way");
        let trains: Vec<SpikeTrains> = episode
            .kept
            .spikes
            .iter()
            .map(|log| log.trains(start, end, (self.rows, self.cols), &self.present))
            .collect();
        let mut populations = trains.into_iter();
        let encoded = Encoded {
            meta: Meta {
                file: "stream".into(),
                speed_mm_s: self.params.speed_mm_s,
                ..Meta::default()
            },
            spikes: populations.next().expect("one population at least"),
            fa: populations.next(),
            resampled: false,
            flat: false,
            from_events: false,
        };
        Ok(model.predict_one(&encoded)?)
    }

    /// The model's prediction for the current window from its co-occurrence counts kept
    /// bin by bin (3D-GLCM models): the same features as [`StreamClassifier::classify`]
    /// gives at a bin boundary, without counting the window afresh.
    fn classify_window(&self, model: &Model) -> Result<Prediction, StreamError> {
        let episode = self.episode.as_ref().expect("an episode is under way");
        let extractor = model.extractor();
        let volume = extractor.volume_params();
        let symmetric = extractor.glcm_params().symmetric;
        let mut row = Vec::new();
        let mut counts = Vec::new();
        for window in &episode.kept.glcm {
            window.counts(volume.levels, volume.range, symmetric, &mut counts);
            row.extend(extractor.haralick_row(&counts));
        }
        Ok(model.predict_extracted(&row)?)
    }

    /// Conditions the episode's last steps, then summarises it: the classification of its
    /// last window (all of it when shorter) and the decision.
    fn end_episode(&mut self, ended_by: EpisodeEnd) -> Result<(), StreamError> {
        self.flush()?;
        let episode = self.episode.as_mut().expect("an episode is under way");
        let n = episode.steps;
        let whole = n.min(self.window);
        let last = match (&self.model, &mut episode.kept.network) {
            _ if whole < self.bin => None,
            (SavedModel::Spiking(m), Some(feed)) => {
                feed.flush(m.network());
                Some(decide(&feed.scores(m.network())))
            }
            (SavedModel::Features(m), _) => {
                let p = self.classify(m, n - whole, n)?;
                Some((m.class_index(&p.predicted), p.shares))
            }
            (SavedModel::Spiking(_), None) => unreachable!("a spiking model's episode runs it"),
        };
        let episode = self.episode.take().expect("an episode is under way");
        let decision = episode.decider.decision();
        self.events.push(Event::End(EpisodeSummary {
            duration_s: n as f64 / 1000.0,
            class: last.as_ref().map(|l| l.0),
            shares: last.map(|l| l.1),
            decision: decision.map(|d| d.0),
            decided_at_s: decision.map(|d| d.1),
            bins: episode.bins,
            ended_by,
        }));
        Ok(())
    }
}

/// Cells taken through all the stages of a step at a time: their values and state (some
/// 60 bytes per cell) stay in the first-level cache.
const PART: usize = 512;

/// One step of some cells to condition: their raw values, resting values, whether they
/// hold a taxel, the filter's state, and where the conditioned values go.
struct Conditioning<'a> {
    raw: &'a [f64],
    offsets: &'a [f64],
    present: &'a [bool],
    state: [&'a mut [f64]; 2],
    out: &'a mut [f64],
}

impl Conditioning<'_> {
    /// Removes the resting value (0 for masked cells), filters (the filter started in its
    /// steady state at the episode's first step) when there is a filter, and divides by
    /// the scale: the offline causal pipeline's operations in its order.
    fn run(self, filter: Option<&Butterworth2>, scale: f64, first: bool) {
        #[cfg(target_arch = "x86_64")]
        {
            /// The same loops with AVX2's four-lane division; no FMA, so the results are
            /// the portable path's bit for bit.
            #[target_feature(enable = "avx2")]
            unsafe fn run_avx2(
                cells: Conditioning<'_>,
                filter: Option<&Butterworth2>,
                scale: f64,
                first: bool,
            ) {
                cells.run_portable(filter, scale, first);
            }
            if neurotex_core::has_feature!("avx2") {
                // SAFETY: the CPU supports AVX2, checked just above.
                return unsafe { run_avx2(self, filter, scale, first) };
            }
        }
        self.run_portable(filter, scale, first);
    }

    #[inline(always)]
    fn run_portable(self, filter: Option<&Butterworth2>, scale: f64, first: bool) {
        let n = self.out.len();
        let (raw, offsets, present) = (&self.raw[..n], &self.offsets[..n], &self.present[..n]);
        let [z0, z1] = self.state;
        let (z0, z1, out) = (&mut z0[..n], &mut z1[..n], self.out);
        let input = |i: usize| if present[i] { raw[i] - offsets[i] } else { 0.0 };
        match filter {
            Some(f) => {
                if first {
                    for i in 0..n {
                        [z0[i], z1[i]] = f.steady_state(input(i));
                    }
                }
                for i in 0..n {
                    let mut z = [z0[i], z1[i]];
                    out[i] = f.step(input(i), &mut z) / scale;
                    [z0[i], z1[i]] = z;
                }
            }
            None => {
                for (i, x) in out.iter_mut().enumerate() {
                    *x = input(i) / scale;
                }
            }
        }
    }
}

/// `out = a + (b - a) * w`, cell by cell: the arithmetic of
/// [`crate::signal::resample_linear`].
fn interpolate(a: &[f64], b: &[f64], w: f64, out: &mut [f64]) {
    for ((o, &x), &y) in out.iter_mut().zip(a).zip(b) {
        *o = x + (y - x) * w;
    }
}

/// Writes each recording's episode as `neurotex stream --episode whole` prints it for that
/// recording's frames: a line per bin boundary, then its end, each with the recording's
/// `file` (`predict --causal`).
///
/// # Errors
/// `w` fails.
pub fn write_episodes(
    w: &mut dyn std::io::Write,
    labels: &[String],
    encoded: &[Encoded],
    episodes: &[crate::causal::Episode],
) -> std::io::Result<()> {
    for (e, episode) in encoded.iter().zip(episodes) {
        let file = Some(e.meta.file.as_str());
        for bin in &episode.bins {
            writeln!(w, "{}", bin_json(labels, bin, file))?;
        }
        // A whole recording was read or refused as a whole: it had no bad frame.
        let mut end = end_json(labels, &episode.summary, file);
        end["bad_frames"] = 0.into();
        writeln!(w, "{end}")?;
    }
    Ok(())
}

/// A bin boundary's line: `{"t_s", "label", "scores", "decided", "decision"}`, with the
/// recording's `file` first when given (`predict --causal`).
pub fn bin_json(labels: &[String], bin: &BinDecision, file: Option<&str>) -> Value {
    let mut line = Map::new();
    if let Some(file) = file {
        line.insert("file".into(), file.into());
    }
    line.insert("t_s".into(), bin.t_s.into());
    line.insert("label".into(), labels[bin.class].clone().into());
    let scores: Map<String, Value> = labels
        .iter()
        .zip(&bin.shares)
        .map(|(l, &s)| (l.clone(), s.into()))
        .collect();
    line.insert("scores".into(), scores.into());
    line.insert("decided".into(), bin.decided.into());
    line.insert(
        "decision".into(),
        bin.decision.map(|c| labels[c].clone()).into(),
    );
    line.into()
}

/// An episode's end: `{"end": true, "label", "decided_at_s", "decision", "duration_s",
/// "bins", "ended_by"}`; `label` is the whole episode's classification (its last window
/// when longer), null when it is shorter than one bin.
pub fn end_json(labels: &[String], summary: &EpisodeSummary, file: Option<&str>) -> Value {
    let mut line = json!({
        "end": true,
        "label": summary.class.map(|c| labels[c].clone()),
        "decided_at_s": summary.decided_at_s,
        "decision": summary.decision.map(|c| labels[c].clone()),
        "duration_s": summary.duration_s,
        "bins": summary.bins,
        "ended_by": summary.ended_by,
    });
    if let Some(file) = file {
        line["file"] = file.into();
    }
    line
}
