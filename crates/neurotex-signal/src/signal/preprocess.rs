//! Conditioning a recording for the encoder: its sliding phase selected, its resting values
//! removed, resampled to 1 kHz, filtered and normalised ([`Preprocessor`]).

use crate::error::{DataError, ParamError, Result};
use crate::recording::{Baseline, Recording};

use super::butterworth::Butterworth2;
use super::normalise::{largest, normalise_by_max, normalise_fixed};
use super::resample::{
    fixed_offsets, offsets_at, relative_times, resample_less, resampled_len, slide_range, Times,
};
use super::rest::RestTracker;
use super::{LessOffsets, PreprocessParams, ENCODER_FS};

/// Whether the recording, whose times are `times`, is sampled uniformly at the encoder's
/// 1 kHz (no resampling).
fn uniform_1k(rec: &Recording, times: Times) -> bool {
    matches!(times, Times::Uniform { .. }) && (rec.fs - ENCODER_FS).abs() < 1e-9
}

/// Whether time stamps (s) fall exactly on the encoder's grid from the first: `i / 1000`
/// after the first, as a logger writing whole milliseconds gives them. Resampling such
/// stamps linearly reproduces every sample bit for bit (each grid time is a stamp), so
/// a recording at 1 kHz with them is read as sampled uniformly, and not said to be
/// resampled ([`Preprocessor::apply`]).
fn on_the_1ms_grid(t: &[f64]) -> bool {
    let first = t.first().copied().unwrap_or(0.0);
    t.iter()
        .enumerate()
        .all(|(i, &x)| x - first == i as f64 / ENCODER_FS)
}

/// The selected phase (`frames`) of a recording at 1 kHz, each sample less its cell's
/// resting value (`offsets`) and masked cells 0: a copy where the recording is already
/// uniform at 1 kHz, else resampled linearly first.
///
/// # Errors
/// A span whose resampling would not fit in memory, or a phase shorter than one step.
fn selected_phase(
    rec: &Recording,
    times: Times,
    offsets: &[f64],
    frames: std::ops::Range<usize>,
) -> Result<Vec<f64>> {
    let (cells, file) = (rec.layout.cells(), &rec.meta.file);
    let present = &rec.layout.present;
    let (lo, hi) = (frames.start, frames.end);
    let samples = if uniform_1k(rec, times) {
        less_offsets(&rec.samples[lo * cells..hi * cells], offsets, present)
    } else {
        let span = times.at(hi - 1) - times.at(lo);
        if resampled_len(span, ENCODER_FS, cells).is_none() {
            let message =
                format!("a {span} s span resampled to 1 kHz is more samples than memory can hold");
            return Err(DataError::invalid(file, message).into());
        }
        resample_less(
            &rec.samples[lo * cells..hi * cells],
            cells,
            &times.span(lo..hi),
            ENCODER_FS,
            Some((offsets, present)),
        )
    };
    if samples.is_empty() {
        return Err(phase_too_short(rec));
    }
    Ok(samples)
}

/// Each frame of `samples` (1 kHz, `cells` values each) less each cell's resting value as
/// a [`RestTracker`] over `window_ms` follows it; cells not `present` stay 0.
///
/// # Errors
/// A grid too large for the window ([`RestTracker::new`]).
fn less_tracked_rest(
    samples: &mut [f64],
    cells: usize,
    present: &[bool],
    window_ms: u32,
) -> Result<()> {
    let mut tracker = RestTracker::new(cells, window_ms)?;
    let mut rest = vec![0.0; cells];
    for frame in samples.chunks_exact_mut(cells) {
        tracker.push(frame, &mut rest);
        for ((s, &r), &p) in frame.iter_mut().zip(&rest).zip(present) {
            *s = if p { *s - r } else { 0.0 };
        }
    }
    Ok(())
}

/// The error of a selected phase without a whole 1 ms step.
fn phase_too_short(rec: &Recording) -> crate::Error {
    let message = "the selected phase is shorter than one 1 ms encoder step";
    DataError::invalid(&rec.meta.file, message).into()
}

/// A copy of frame-major `samples`, each less its cell's resting value (`offsets`) and
/// the cells not `present` 0.
pub(super) fn less_offsets(samples: &[f64], offsets: &[f64], present: &[bool]) -> Vec<f64> {
    LessOffsets::new(offsets, present).copy(samples)
}

/// A recording conditioned for the encoder: `n_steps x cells` samples at 1 kHz, in `[.., 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Conditioned {
    /// Samples, time-major, `n_steps * cells`.
    pub samples: Vec<f64>,
    /// Cells per frame (`rows * cols`).
    pub cells: usize,
    /// Whether the input was resampled to 1 kHz (the report says so).
    pub resampled: bool,
    /// Whether the recording's maximum was <= 0 so it was left at zero, not divided.
    pub flat: bool,
}

impl Conditioned {
    /// Number of 1 ms steps.
    pub fn n_steps(&self) -> usize {
        self.samples.len() / self.cells.max(1)
    }
}

/// The conditioning stages, planned once (filter designed once) and applied to many recordings.
#[derive(Debug, Clone)]
pub struct Preprocessor {
    params: PreprocessParams,
    filter: Option<Butterworth2>,
}

impl Preprocessor {
    /// Checks the parameters and designs the filter.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: &PreprocessParams) -> Result<Self, ParamError> {
        params.check()?;
        let filter = if params.cutoff_hz > 0.0 {
            Some(Butterworth2::lowpass(ENCODER_FS, params.cutoff_hz)?)
        } else {
            None
        };
        Ok(Preprocessor {
            params: params.clone(),
            filter,
        })
    }

    /// The parameters this plan applies.
    pub fn params(&self) -> &PreprocessParams {
        &self.params
    }

    /// The designed low-pass; `None` when the filter is off.
    pub fn filter(&self) -> Option<&Butterworth2> {
        self.filter.as_ref()
    }

    /// The selected phase (`frames`) of `rec` less its resting values (`offsets`), low-passed
    /// with the conditioning's filter (causal or zero-phase) where it has one, and its
    /// largest value where the filter's passes found it on their way. A recording already
    /// uniform at 1 kHz is copied by the filter's first pass, not copied and then filtered.
    /// Masked cells hold 0 and stay exactly 0, as when only taxels were filtered.
    ///
    /// # Errors
    /// As [`selected_phase`].
    fn filtered_phase(
        &self,
        rec: &Recording,
        times: Times,
        offsets: &[f64],
        frames: std::ops::Range<usize>,
    ) -> Result<(Vec<f64>, Option<f64>)> {
        let (cells, present) = (rec.layout.cells(), &rec.layout.present);
        if let (Some(_), Some(window)) = (&self.params.causal, self.params.drift_window_ms) {
            let mut samples = selected_phase(rec, times, offsets, frames)?;
            less_tracked_rest(&mut samples, cells, present, window)?;
            if let Some(filter) = &self.filter {
                filter.lfilter_frames(&mut samples, cells);
            }
            return Ok((samples, None));
        }
        let Some(filter) = &self.filter else {
            return Ok((selected_phase(rec, times, offsets, frames)?, None));
        };
        let (mut samples, top) = if uniform_1k(rec, times) {
            if cells == 0 || frames.is_empty() {
                return Err(phase_too_short(rec));
            }
            let from = &rec.samples[frames.start * cells..frames.end * cells];
            let less = LessOffsets::new(offsets, present);
            match self.params.causal {
                Some(_) => (filter.lfilter_frames_less(from, &less), None),
                None => {
                    let (samples, top) = filter.filtfilt_frames_less(from, &less);
                    (samples, Some(top))
                }
            }
        } else {
            let mut samples = selected_phase(rec, times, offsets, frames)?;
            match self.params.causal {
                Some(_) => {
                    filter.lfilter_frames(&mut samples, cells);
                    (samples, None)
                }
                None => {
                    let top = filter.filtfilt_frames_top(&mut samples, cells);
                    (samples, Some(top))
                }
            }
        };
        // A masked cell's filtered zeros are +0 or -0 (the sign of a coefficient), so the
        // largest value found before they are set to +0 is the largest after.
        if present.iter().any(|&p| !p) {
            for frame in samples.chunks_exact_mut(cells) {
                for (s, _) in frame.iter_mut().zip(present).filter(|(_, &p)| !p) {
                    *s = 0.0;
                }
            }
        }
        Ok((samples, top))
    }

    /// Conditions one recording; `dataset_baseline` is the dataset's layout choice, used
    /// when the parameters do not override it.
    ///
    /// # Errors
    /// The sliding phase is empty or outside the recording, or the baseline interval is.
    pub fn apply(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Conditioned> {
        let cells = rec.layout.cells();
        let n = rec.len();
        let file = &rec.meta.file;
        if n == 0 {
            return Err(DataError::invalid(file, "recording holds no samples").into());
        }
        // Stamps on the 1 ms grid at 1 kHz are the times a uniform recording has.
        let on_grid = (rec.fs - ENCODER_FS).abs() < 1e-9
            && rec.times_s.as_deref().is_some_and(on_the_1ms_grid);
        let stamps = rec.times_s.as_ref().filter(|_| !on_grid);
        let stamps = stamps.map(|_| relative_times(rec));
        let times = Times::of(rec, stamps.as_deref());
        let offsets = match &self.params.causal {
            // The resting values are tracked as the samples come (`less_tracked_rest`).
            Some(causal) if self.params.drift_window_ms.is_some() => {
                vec![0.0; fixed_offsets(rec, causal)?.len()]
            }
            Some(causal) => fixed_offsets(rec, causal)?,
            None => {
                let baseline = self.params.baseline.unwrap_or(dataset_baseline);
                offsets_at(rec, times, baseline)?
            }
        };
        let (lo, hi) = if self.params.slide_only {
            slide_range(rec, times)?
        } else {
            (0, n)
        };
        let (mut samples, top) = self.filtered_phase(rec, times, &offsets, lo..hi)?;
        let flat = match &self.params.causal {
            Some(causal) => normalise_fixed(&mut samples, causal.scale),
            None => {
                let max = top.unwrap_or_else(|| largest(&samples));
                normalise_by_max(&mut samples, max)
            }
        };
        Ok(Conditioned {
            samples,
            cells,
            resampled: !uniform_1k(rec, times),
            flat,
        })
    }
}
