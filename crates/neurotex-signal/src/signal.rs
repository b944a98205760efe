//! Signal conditioning before encoding: sliding-phase selection, baseline removal,
//! resampling to the encoder's 1 kHz, zero-phase Butterworth low-pass and global-max
//! normalisation.

use std::mem::MaybeUninit;

use serde::{Deserialize, Serialize};

use crate::error::{ParamError, Result};
use crate::recording::Baseline;
use crate::simd::widest_or_plain;

mod butterworth;
mod normalise;
mod preprocess;
mod resample;
mod rest;

pub use butterworth::Butterworth2;
pub use normalise::{normalise_fixed, normalise_global_max};
pub use preprocess::{Conditioned, Preprocessor};
pub use resample::{baseline_offsets, relative_times, resample_linear, resampled_len};
pub use rest::RestTracker;

/// The encoder's sampling rate: one Izhikevich step per millisecond (paper section II-E).
pub const ENCODER_FS: f64 = 1000.0;

/// Parameters of the conditioning stages.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PreprocessParams {
    /// Low-pass cutoff in Hz; 0 turns the filter off. The paper gives none: 50 Hz.
    pub cutoff_hz: f64,
    /// Use only the sliding phase (the paper's choice); `false` keeps the whole recording.
    pub slide_only: bool,
    /// Baseline removal; `None` takes the dataset's `layout.toml` choice.
    pub baseline: Option<Baseline>,
    /// Causal conditioning (for streaming): a causal filter and a resting value and scale
    /// fixed at training, instead of the zero-phase filter and each recording's own
    /// baseline and maximum. `None` (the paper's offline pipeline) when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub causal: Option<CausalConditioning>,
    /// Under causal conditioning, each cell's resting value is the least of its input over
    /// a trailing window of this many ms ([`RestTracker`]) instead of the value fixed at
    /// training: for sensors whose resting level drifts between or within recordings.
    /// `None` keeps the fixed values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drift_window_ms: Option<u32>,
}

impl Default for PreprocessParams {
    fn default() -> Self {
        PreprocessParams {
            cutoff_hz: 50.0,
            slide_only: true,
            baseline: None,
            causal: None,
            drift_window_ms: None,
        }
    }
}

/// What causal conditioning fixes at training so that a sample can be conditioned the
/// moment it arrives, as a live stream needs
/// (docs/decisions/0013-causal-conditioning-with-a-scale-fixed-at-training.md): the offline
/// pipeline's zero-phase filter needs the future, its `min` baseline and its division by
/// the recording's maximum need the whole recording. Here the low-pass runs forward only
/// (the same Butterworth biquad, started in its steady state for the first sample, as
/// `scipy.signal.lfilter` with `lfilter_zi * x[0]`), each cell's resting value is
/// subtracted as fixed `offsets`, and every sample is divided by one fixed `scale`
/// ([`crate::causal::calibrate_conditioning`] sets both from the training recordings).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CausalConditioning {
    /// Each cell's resting value, row-major over the grid (0 for a masked cell).
    pub offsets: Vec<f64>,
    /// The divisor taking the filtered, offset-free signal to about `[0, 1]`.
    pub scale: f64,
}

impl CausalConditioning {
    /// Checks the rules: finite offsets, a finite positive scale.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(ParamError::new(
                "causal.scale",
                "the causal normalisation scale must be a finite positive number",
                self.scale,
            ));
        }
        if let Some(bad) = self.offsets.iter().find(|o| !o.is_finite()) {
            return Err(ParamError::new(
                "causal.offsets",
                "every causal resting value must be a finite number",
                bad,
            ));
        }
        Ok(())
    }
}

impl PreprocessParams {
    /// Checks the rules: the cutoff is 0 or strictly between 0 and the Nyquist rate of 500 Hz.
    ///
    /// # Errors
    /// The rule broken, as a [`ParamError`].
    pub fn check(&self) -> Result<(), ParamError> {
        let c = self.cutoff_hz;
        if !(0.0..ENCODER_FS / 2.0).contains(&c) {
            return Err(ParamError::new(
                "cutoff",
                "low-pass cutoff must be 0 (off) or between 0 and 500 Hz (half the 1 kHz encoder rate)",
                c,
            ));
        }
        if let Some(window) = self.drift_window_ms {
            if !(DRIFT_BLOCK_MS..=MAX_DRIFT_WINDOW_MS).contains(&window)
                || window % DRIFT_BLOCK_MS != 0
            {
                return Err(ParamError::new(
                    "drift-window-s",
                    "the drift window must be a multiple of 0.1 s from 0.1 to 600 s",
                    window as f64 / 1000.0,
                ));
            }
        }
        match &self.causal {
            Some(causal) => causal.check(),
            None => Ok(()),
        }
    }
}

/// The drift window's blocks, in 1 ms steps: [`RestTracker`] keeps one minimum per block.
pub const DRIFT_BLOCK_MS: u32 = 100;
/// The longest drift window, ms: ten minutes.
pub const MAX_DRIFT_WINDOW_MS: u32 = 600_000;
/// The most block minima a [`RestTracker`] keeps (cells x blocks): 128 MiB.
pub const MAX_DRIFT_VALUES: usize = 1 << 24;

/// How the selected phase is taken out of a recording: each cell's resting value
/// subtracted, and the cells not present cleared to +0.
struct LessOffsets<'a> {
    offsets: &'a [f64],
    /// Per cell, a mask that keeps a present cell's bits and clears an absent one's: a
    /// choice without a branch, so the passes vectorise.
    keep: Vec<u64>,
}

impl<'a> LessOffsets<'a> {
    fn new(offsets: &'a [f64], present: &[bool]) -> Self {
        let keep = present
            .iter()
            .map(|&p| if p { u64::MAX } else { 0 })
            .collect();
        LessOffsets { offsets, keep }
    }

    /// One frame's values.
    fn frame<'s>(&'s self, frame: &'s [f64]) -> impl Iterator<Item = f64> + 's {
        let cells = frame.iter().zip(self.offsets).zip(&self.keep);
        cells.map(|((&s, &r), &k)| masked_less(s, r, k))
    }

    /// A copy of the whole frames of `samples`.
    fn copy(&self, samples: &[f64]) -> Vec<f64> {
        let n = match self.offsets.len() {
            0 => return Vec::new(),
            cells => samples.len() / cells * cells,
        };
        let mut out = Vec::with_capacity(n);
        let into = &mut out.spare_capacity_mut()[..n];
        copy_less_offsets(samples, self.offsets, &self.keep, into);
        // SAFETY: the pass wrote every one of the `n` values (whole frames of `samples`).
        unsafe { out.set_len(n) };
        out
    }
}

/// A sample less its cell's resting value `r`, its bits kept or cleared by `keep`.
#[inline(always)]
fn masked_less(s: f64, r: f64, keep: u64) -> f64 {
    f64::from_bits((s - r).to_bits() & keep)
}

widest_or_plain! {
    ["avx2"]
    /// [`less_offsets`]' pass: each frame of `samples` less `offsets`, masked by `keep`,
    /// into `out`.
    ///
    /// # Panics
    /// `out` is not whole frames of `samples`, or `keep` not one mask per cell.
    fn copy_less_offsets(
        samples: &[f64],
        offsets: &[f64],
        keep: &[u64],
        out: &mut [MaybeUninit<f64>],
    ) {
        let cells = offsets.len();
        assert!(keep.len() == cells && out.len().is_multiple_of(cells) && out.len() <= samples.len());
        for (frame, into) in samples.chunks_exact(cells).zip(out.chunks_exact_mut(cells)) {
            for (((o, &s), &r), &k) in into.iter_mut().zip(frame).zip(offsets).zip(keep) {
                o.write(masked_less(s, r, k));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::normalise::{divide_all, largest};
    use super::preprocess::less_offsets;
    use super::resample::{resample_less, Times};
    use super::*;
    use crate::recording::Recording;

    #[test]
    fn resampled_length_is_bounded_not_wrapped() {
        assert_eq!(resampled_len(0.01, 1000.0, 16), Some(11 * 16));
        assert_eq!(
            resampled_len(1e8, 1000.0, 16),
            Some((1e11 as usize + 1) * 16)
        );
        assert_eq!(resampled_len(1e18, 1000.0, 16), None);
        assert_eq!(resampled_len(1e15, 1000.0, usize::MAX / 2), None);
        assert_eq!(resampled_len(f64::INFINITY, 1000.0, 1), None);
        assert_eq!(resampled_len(f64::NAN, 1000.0, 1), None);
    }

    /// Numbers spread over `[lo, hi)` from a xorshift generator seeded with `state`.
    fn uniform(mut state: u64, lo: f64, hi: f64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * (hi - lo) + lo
        }
    }

    /// The resampling with the resting values taken off in the same pass gives the bits of
    /// the resampling followed by a pass of its own, at every width the processor has, on
    /// irregular stamps (a repeated stamp and a long gap among them) and a masked cell.
    #[test]
    fn resampling_less_rest_is_the_two_passes_bit_for_bit() {
        let mut next = uniform(11, -50.0, 4000.0);
        let mut step = uniform(12, 0.002, 0.04);
        for cells in [1, 3, 16, 17] {
            let mut times = vec![0.0];
            for k in 1..300 {
                let dt = match k {
                    40 => 0.0,
                    90 => 0.3,
                    _ => step(),
                };
                times.push(times[k - 1] + dt);
            }
            let frames: Vec<f64> = (0..times.len() * cells).map(|_| next()).collect();
            let offsets: Vec<f64> = (0..cells).map(|_| next()).collect();
            let present: Vec<bool> = (0..cells).map(|c| c % 5 != 2).collect();
            let mut expected = resample_linear(&frames, cells, &times, ENCODER_FS);
            for frame in expected.chunks_exact_mut(cells) {
                for ((x, &o), &p) in frame.iter_mut().zip(&offsets).zip(&present) {
                    *x = if p { *x - o } else { 0.0 };
                }
            }
            let rest = Some((&offsets[..], &present[..]));
            let got = resample_less(&frames, cells, &times, ENCODER_FS, rest);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&expected), "{cells} cells");
            let one = resample_less(&frames[..cells], cells, &times[..1], ENCODER_FS, rest);
            assert_eq!(
                bits(&one),
                bits(&expected[..cells]),
                "{cells} cells, one stamp"
            );
        }
    }

    /// The tracker's resting value is, at every step, the least input from the start of
    /// the block `window / 100 ms` blocks back through the current step: checked against
    /// that minimum taken directly, for windows of one and of several blocks, across many
    /// replacements of the ring, on a drifting input.
    #[test]
    fn the_rest_tracker_is_the_trailing_minimum_by_its_definition() {
        let mut next = uniform(7, -1.0, 1.0);
        let cells = 3;
        let steps = 2_345;
        let input: Vec<f64> = (0..steps * cells)
            .map(|i| next() + (i / cells) as f64 * 0.01)
            .collect();
        for window_ms in [100, 300, 1_000] {
            let mut tracker = RestTracker::new(cells, window_ms).unwrap();
            let mut rest = vec![0.0; cells];
            let blocks = (window_ms / DRIFT_BLOCK_MS) as usize;
            for t in 0..steps {
                tracker.push(&input[t * cells..(t + 1) * cells], &mut rest);
                let from = (t / 100).saturating_sub(blocks) * 100;
                for (c, &r) in rest.iter().enumerate() {
                    let least = (from..=t)
                        .map(|u| input[u * cells + c])
                        .fold(f64::INFINITY, f64::min);
                    assert_eq!(
                        r.to_bits(),
                        least.to_bits(),
                        "window {window_ms} step {t} cell {c}"
                    );
                }
            }
        }
        assert!(RestTracker::new(1 << 20, 100_000).is_err());
    }

    /// The masked copy less offsets, the maximum and the division equal their one-value-
    /// at-a-time definitions bit for bit (whichever instruction set runs them), a frame
    /// remainder of the maximum's eight lanes included.
    #[test]
    fn whole_array_passes_are_their_scalar_definitions() {
        let mut next = uniform(0x9E37_79B9_7F4A_7C15, -3.0, 3.0);
        for (n, cells) in [(1, 1), (3, 5), (13, 16), (7, 3)] {
            let x: Vec<f64> = (0..n * cells).map(|_| next()).collect();
            let mut offsets: Vec<f64> = (0..cells).map(|_| next()).collect();
            // A sample equal to its offset (difference +0) and a negative difference.
            offsets[0] = x[0];
            let present: Vec<bool> = (0..cells).map(|c| c % 3 != 1).collect();
            let got = less_offsets(&x, &offsets, &present);
            let want: Vec<f64> = x
                .iter()
                .enumerate()
                .map(|(i, &s)| match present[i % cells] {
                    true => s - offsets[i % cells],
                    false => 0.0,
                })
                .collect();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "copy, {n} frames of {cells}");
            let top = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(largest(&x), top, "maximum, {n} frames of {cells}");
            let mut divided = x.clone();
            divide_all(&mut divided, 0.37);
            let want: Vec<f64> = x.iter().map(|v| v / 0.37).collect();
            assert_eq!(
                bits(&divided),
                bits(&want),
                "division, {n} frames of {cells}"
            );
        }
        assert!(less_offsets(&[1.0], &[], &[]).is_empty());
    }

    /// The filters that copy the selected phase out of a recording on their first pass
    /// (and find the maximum on their last) give the bits of the copy, the filter and the
    /// maximum one after another: every width the passes specialise (4, 8, 16) and others,
    /// masked cells, and signals too short to filter.
    #[test]
    fn fused_passes_are_the_passes_one_after_another() {
        let f = Butterworth2::lowpass(ENCODER_FS, 50.0).unwrap();
        let mut next = uniform(0x5851_F42D_4C95_7F2D, -1.0, 3.0);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (n, cells) in [
            (1, 16),
            (2, 4),
            (5, 16),
            (12, 8),
            (300, 16),
            (300, 7),
            (40, 1),
        ] {
            // A partial frame at the end, which no pass reads.
            let x: Vec<f64> = (0..n * cells + cells / 2).map(|_| next()).collect();
            let offsets: Vec<f64> = (0..cells).map(|_| next()).collect();
            let present: Vec<bool> = (0..cells).map(|c| c % 5 != 2).collect();
            let less = LessOffsets::new(&offsets, &present);
            let mut want = less_offsets(&x, &offsets, &present);
            f.filtfilt_frames(&mut want, cells);
            let (got, top) = f.filtfilt_frames_less(&x, &less);
            assert_eq!(bits(&got), bits(&want), "filtfilt, {n} frames of {cells}");
            assert_eq!(top, largest(&want), "maximum, {n} frames of {cells}");
            let mut want = less_offsets(&x, &offsets, &present);
            f.lfilter_frames(&mut want, cells);
            let got = f.lfilter_frames_less(&x, &less);
            assert_eq!(bits(&got), bits(&want), "lfilter, {n} frames of {cells}");
        }
    }

    /// The times of a uniformly sampled recording, computed where they are read, are the
    /// list's: each time, and the sample a search for any time finds.
    #[test]
    fn uniform_times_are_the_listed_times() {
        let layout = crate::recording::Layout::grid(1, 1);
        for (n, fs) in [
            (0, 1000.0),
            (1, 1000.0),
            (7, 3.0),
            (1000, 1000.0),
            (999, 333.3),
        ] {
            let rec = Recording {
                fs,
                layout: layout.clone(),
                samples: vec![0.0; n],
                times_s: None,
                phases: None,
                meta: Default::default(),
            };
            let listed = relative_times(&rec);
            let times = Times::of(&rec, None);
            assert_eq!(times.len(), n);
            assert_eq!(bits_of(&times.span(0..n)), bits_of(&listed));
            for t in [-1.0, 0.0, 1e-9, 0.5, 0.999, 1.0, 2.0 / 3.0, 2.5, 1e9] {
                let want = listed.partition_point(|&x| x < t - 1e-9);
                assert_eq!(
                    times.partition_point(|x| x < t - 1e-9),
                    want,
                    "{n} at {fs} Hz, {t}"
                );
            }
        }
    }

    fn bits_of(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The channels filtered side by side equal each channel filtered alone, bit for bit
    /// (the single-channel filters are checked against scipy in tests/reference_values.rs).
    #[test]
    fn frames_filter_as_each_channel_alone() {
        let f = Butterworth2::lowpass(ENCODER_FS, 50.0).unwrap();
        let mut next = uniform(0x2545_F491_4F6C_DD1D, -1.0, 3.0);
        for (n, cells) in [
            (1, 3),
            (2, 1),
            (5, 16),
            (10, 7),
            (11, 16),
            (300, 9),
            (40, 4),
            (40, 8),
            (300, 16),
        ] {
            let x: Vec<f64> = (0..n * cells).map(|_| next()).collect();
            let channel =
                |c: usize| -> Vec<f64> { x.iter().skip(c).step_by(cells).copied().collect() };
            let mut both = x.clone();
            f.filtfilt_frames(&mut both, cells);
            let mut forward = x.clone();
            f.lfilter_frames(&mut forward, cells);
            for c in 0..cells {
                let mut alone = channel(c);
                f.filtfilt(&mut alone, &mut Vec::new());
                let got: Vec<f64> = both.iter().skip(c).step_by(cells).copied().collect();
                assert_eq!(
                    got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    alone.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "filtfilt, {n} frames of {cells}, channel {c}"
                );
                let mut alone = channel(c);
                f.lfilter(&mut alone);
                let got: Vec<f64> = forward.iter().skip(c).step_by(cells).copied().collect();
                assert_eq!(
                    got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    alone.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "lfilter, {n} frames of {cells}, channel {c}"
                );
            }
        }
    }
}
