//! A stream's parameters: the window, the bin, the episode rule and the limits on gaps and
//! time stamps, checked.

use serde::{Deserialize, Serialize};

use crate::causal::DecisionRule;
use crate::error::{ParamError, Result};
use crate::saved::Trained;
use crate::signal::ENCODER_FS;

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
    /// The window classified at each bin boundary, ms (rounded up to whole bins).
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

    pub(super) fn check(&self) -> Result<(), ParamError> {
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
