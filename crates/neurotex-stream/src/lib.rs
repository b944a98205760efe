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
mod output;
mod params;
mod spike_log;
mod steps;
mod window_glcm;

// The layers below, under the names their modules had when they were one crate, so that
// `crate::causal` and the like read the same in every layer.
use neurotex_core::{csvlog, error, recording, values, Error};
use neurotex_features::features;
use neurotex_learn::snn;
use neurotex_pipeline::{causal, model, pipeline, saved, spiking_model};
use neurotex_signal::{encode, signal};

use crate::causal::{window_steps, BinDecision, Decider, EpisodeEnd, EpisodeSummary};
use crate::encode::Encoder;
use crate::error::{ParamError, Result};
use crate::recording::TimeUnit;
use crate::saved::SavedModel;
use crate::signal::{Butterworth2, CausalConditioning, Preprocessor, RestTracker, ENCODER_FS};
use network::NetworkFeed;
use spike_log::SpikeLog;
use window_glcm::WindowGlcm;

pub use output::{bin_json, end_json, write_episodes};
pub use params::{
    EpisodeRule, StreamParams, DEFAULT_MAX_GAP_S, DEFAULT_WINDOW_MS, MAX_GAP_S, MAX_STAMP_S,
};

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
    #[error("value {index} is {value:?}, not a finite number")]
    NotFinite {
        /// Which value, counted from the line's first field (the time stamp is value 0
        /// when given).
        index: usize,
        /// The value: NaN or an infinity.
        value: f64,
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
}
