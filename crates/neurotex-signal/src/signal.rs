//! Signal conditioning before encoding: sliding-phase selection, baseline removal,
//! resampling to the encoder's 1 kHz, zero-phase Butterworth low-pass and global-max
//! normalisation.

use std::mem::MaybeUninit;

use serde::{Deserialize, Serialize};

use crate::error::{DataError, ParamError, Result};
use crate::recording::{Baseline, Phase, Recording};
use crate::simd::widest_or_plain;

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

/// Each cell's resting value as the least of its input over a trailing window: the
/// current 100 ms block so far and the `window / 100 ms` whole blocks before it (so the
/// window spans between `window` and `window + 0.1 s`). A causal counterpart of the `min`
/// baseline that follows a resting level drifting by more than the signal, at a cost of
/// one comparison per cell and step and one pass over the block minima per block. The
/// offline causal pipeline and the stream both run it, step by step, on the resampled
/// input, so they subtract the same values.
#[derive(Debug, Clone)]
pub struct RestTracker {
    cells: usize,
    blocks: usize,
    /// The last `blocks` whole blocks' minima, `blocks x cells` (infinite while unfilled).
    ring: Vec<f64>,
    /// Per cell, the least of `ring`.
    earlier: Vec<f64>,
    /// Per cell, the least of the current block so far.
    current: Vec<f64>,
    step: u64,
}

impl RestTracker {
    /// A tracker for `cells` cells over a window of `window_ms` (a checked
    /// [`PreprocessParams::drift_window_ms`]).
    ///
    /// # Errors
    /// A grid too large to keep the window's block minima for ([`MAX_DRIFT_VALUES`]).
    pub fn new(cells: usize, window_ms: u32) -> Result<Self, ParamError> {
        let blocks = (window_ms / DRIFT_BLOCK_MS).max(1) as usize;
        if cells.saturating_mul(blocks) > MAX_DRIFT_VALUES {
            let rule = "the drift window keeps one minimum per taxel and 0.1 s, at most 16777216 values over the grid";
            let got = format!(
                "{} s on {cells} cells (at most {:.1} s on this grid)",
                window_ms as f64 / 1000.0,
                (MAX_DRIFT_VALUES / cells.max(1)) as f64 / 10.0
            );
            return Err(ParamError::new("drift-window-s", rule, got));
        }
        Ok(RestTracker {
            cells,
            blocks,
            ring: vec![f64::INFINITY; cells * blocks],
            earlier: vec![f64::INFINITY; cells],
            current: vec![f64::INFINITY; cells],
            step: 0,
        })
    }

    /// Takes one step's input `raw` (one value per cell) and writes each cell's resting
    /// value into `rest`.
    ///
    /// # Panics
    /// `raw` or `rest` does not hold one value per cell.
    pub fn push(&mut self, raw: &[f64], rest: &mut [f64]) {
        let cells = self.cells;
        assert!(raw.len() == cells && rest.len() == cells);
        let block_steps = u64::from(DRIFT_BLOCK_MS);
        if self.step > 0 && self.step.is_multiple_of(block_steps) {
            let slot = ((self.step / block_steps - 1) % self.blocks as u64) as usize;
            self.ring[slot * cells..(slot + 1) * cells].copy_from_slice(&self.current);
            self.earlier.fill(f64::INFINITY);
            for block in self.ring.chunks_exact(cells) {
                for (e, &b) in self.earlier.iter_mut().zip(block) {
                    *e = e.min(b);
                }
            }
            self.current.fill(f64::INFINITY);
        }
        for (((c, &x), &e), r) in (self.current.iter_mut().zip(raw))
            .zip(&self.earlier)
            .zip(rest.iter_mut())
        {
            *c = c.min(x);
            *r = c.min(e);
        }
        self.step += 1;
    }
}

/// A second-order Butterworth low-pass as a biquad, designed by the bilinear transform
/// with prewarping (the design of `scipy.signal.butter(2, fc, fs=fs)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Butterworth2 {
    /// Numerator `b0, b1, b2`.
    pub b: [f64; 3],
    /// Denominator `1, a1, a2`.
    pub a: [f64; 3],
}

impl Butterworth2 {
    /// Designs the low-pass for sampling rate `fs` and cutoff `cutoff_hz`.
    ///
    /// # Errors
    /// The cutoff is not in `(0, fs/2)`.
    pub fn lowpass(fs: f64, cutoff_hz: f64) -> Result<Self, ParamError> {
        if !(cutoff_hz > 0.0 && cutoff_hz < fs / 2.0) {
            return Err(ParamError::new(
                "cutoff",
                "low-pass cutoff must lie strictly between 0 and half the sampling rate",
                cutoff_hz,
            ));
        }
        let k = (std::f64::consts::PI * cutoff_hz / fs).tan();
        let sqrt2 = std::f64::consts::SQRT_2;
        let norm = 1.0 / (1.0 + sqrt2 * k + k * k);
        let b0 = k * k * norm;
        Ok(Butterworth2 {
            b: [b0, 2.0 * b0, b0],
            a: [
                1.0,
                2.0 * (k * k - 1.0) * norm,
                (1.0 - sqrt2 * k + k * k) * norm,
            ],
        })
    }

    /// Steady-state initial conditions for a unit step (as `scipy.signal.lfilter_zi`).
    fn zi(&self) -> [f64; 2] {
        let [b0, b1, b2] = self.b;
        let [_, a1, a2] = self.a;
        let (p, q) = (b1 - a1 * b0, b2 - a2 * b0);
        let z0 = (p + q) / (1.0 + a1 + a2);
        [z0, q - a2 * z0]
    }

    /// Runs the filter over `x` in place (direct form II transposed) from state `z`.
    fn run(&self, x: &mut [f64], mut z: [f64; 2]) {
        for s in x.iter_mut() {
            *s = self.step(*s, &mut z);
        }
    }

    /// One sample through the filter (direct form II transposed), updating state `z`: the
    /// one place both the offline and the streaming filters compute a sample, so they agree
    /// bit for bit.
    #[inline]
    pub fn step(&self, xn: f64, z: &mut [f64; 2]) -> f64 {
        let [b0, b1, b2] = self.b;
        let [_, a1, a2] = self.a;
        let y = b0 * xn + z[0];
        z[0] = b1 * xn - a1 * y + z[1];
        z[1] = b2 * xn - a2 * y;
        y
    }

    /// The state of a filter that has seen `x0` for ever (its steady state), so that a
    /// signal starting at `x0` starts without a transient (`scipy.signal.lfilter_zi * x0`).
    pub fn steady_state(&self, x0: f64) -> [f64; 2] {
        let zi = self.zi();
        [zi[0] * x0, zi[1] * x0]
    }

    /// Causal forward filtering of `x` in place from the steady state of its first sample,
    /// as `scipy.signal.lfilter(b, a, x, zi=lfilter_zi(b, a) * x[0])`: what a stream can
    /// compute sample by sample.
    pub fn lfilter(&self, x: &mut [f64]) {
        if let Some(&x0) = x.first() {
            self.run(x, self.steady_state(x0));
        }
    }

    /// Zero-phase forward-backward filtering as `scipy.signal.filtfilt(b, a, x)` with its
    /// defaults: odd extension of 9 samples at each end (fewer for signals of 9 samples or
    /// less), steady-state initial conditions. Signals shorter than 2 samples are left as they are.
    pub fn filtfilt(&self, x: &mut [f64], scratch: &mut Vec<f64>) {
        let n = x.len();
        if n < 2 {
            return;
        }
        let pad = 9.min(n - 1);
        scratch.clear();
        scratch.reserve(n + 2 * pad);
        let (first, last) = (x[0], x[n - 1]);
        scratch.extend((1..=pad).rev().map(|i| 2.0 * first - x[i]));
        scratch.extend_from_slice(x);
        scratch.extend((1..=pad).map(|i| 2.0 * last - x[n - 1 - i]));
        let zi = self.zi();
        let x0 = scratch[0];
        self.run(scratch, [zi[0] * x0, zi[1] * x0]);
        scratch.reverse();
        let y0 = scratch[0];
        self.run(scratch, [zi[0] * y0, zi[1] * y0]);
        scratch.reverse();
        x.copy_from_slice(&scratch[pad..pad + n]);
    }

    /// [`Butterworth2::filtfilt`] of every channel of frame-major samples (`cells` values
    /// per frame), bit for bit: the channels' filters run side by side, frame after frame,
    /// so the steps are independent (they vectorise) where one channel's steps each wait on
    /// the one before, and no channel is gathered out of the frames and back.
    ///
    /// The padded signal is never built: the filter runs over the left pad, the samples in
    /// place and the right pad in turn (and back), its state carried from one to the next,
    /// the same steps in the same order as over one padded copy.
    pub fn filtfilt_frames(&self, x: &mut [f64], cells: usize) {
        self.filtfilt_frames_top(x, cells);
    }

    /// [`Butterworth2::filtfilt_frames`], returning the largest filtered value (-inf for
    /// none), found by the backward pass where a pass of its own would read every sample
    /// again.
    fn filtfilt_frames_top(&self, x: &mut [f64], cells: usize) -> f64 {
        let n = x.len() / cells.max(1);
        if n < 2 {
            return largest(x);
        }
        let pad = 9.min(n - 1);
        let frame = |i: usize| &x[i * cells..(i + 1) * cells];
        let mut left = Vec::with_capacity(pad * cells);
        for i in (1..=pad).rev() {
            left.extend(frame(0).iter().zip(frame(i)).map(|(&f, &v)| 2.0 * f - v));
        }
        let mut right = Vec::with_capacity(pad * cells);
        for i in 1..=pad {
            let (last, back) = (frame(n - 1), frame(n - 1 - i));
            right.extend(last.iter().zip(back).map(|(&l, &v)| 2.0 * l - v));
        }
        let mut state = [vec![0.0; cells], vec![0.0; cells]];
        run_frames(self, &mut left, cells, &mut state, false, true);
        run_frames(self, x, cells, &mut state, false, false);
        run_frames(self, &mut right, cells, &mut state, false, false);
        run_frames(self, &mut right, cells, &mut state, true, true);
        let top = run_frames(self, x, cells, &mut state, true, false);
        run_frames(self, &mut left, cells, &mut state, true, false);
        top
    }

    /// [`Butterworth2::filtfilt_frames`] of the frames of `from` less each cell's resting
    /// value (as [`less_offsets`] copies them), into a new buffer, and the largest filtered
    /// value: the forward pass reads `from` and makes the copy, and the backward pass finds
    /// the maximum, where a copy and a maximum would each be a pass over the samples of
    /// their own. The same bits as the three steps one after another.
    fn filtfilt_frames_less(&self, from: &[f64], less: &LessOffsets) -> (Vec<f64>, f64) {
        let cells = less.offsets.len();
        let n = from.len().checked_div(cells).unwrap_or(0);
        if n < 2 {
            let samples = less.copy(from);
            let top = largest(&samples);
            return (samples, top);
        }
        let pad = 9.min(n - 1);
        let frame = |i: usize| less.frame(&from[i * cells..(i + 1) * cells]);
        let mut left = Vec::with_capacity(pad * cells);
        for i in (1..=pad).rev() {
            left.extend(frame(0).zip(frame(i)).map(|(f, v)| 2.0 * f - v));
        }
        let mut right = Vec::with_capacity(pad * cells);
        for i in 1..=pad {
            right.extend(frame(n - 1).zip(frame(n - 1 - i)).map(|(l, v)| 2.0 * l - v));
        }
        let mut state = [vec![0.0; cells], vec![0.0; cells]];
        run_frames(self, &mut left, cells, &mut state, false, true);
        let mut x = Vec::with_capacity(n * cells);
        let out = &mut x.spare_capacity_mut()[..n * cells];
        run_frames_less(self, &from[..n * cells], less, out, &mut state, false);
        // SAFETY: the pass wrote every one of the `n` frames.
        unsafe { x.set_len(n * cells) };
        run_frames(self, &mut right, cells, &mut state, false, false);
        run_frames(self, &mut right, cells, &mut state, true, true);
        let top = run_frames(self, &mut x, cells, &mut state, true, false);
        run_frames(self, &mut left, cells, &mut state, true, false);
        (x, top)
    }

    /// [`Butterworth2::lfilter`] of every channel of frame-major samples, bit for bit, the
    /// channels side by side as in [`Butterworth2::filtfilt_frames`].
    pub fn lfilter_frames(&self, x: &mut [f64], cells: usize) {
        if x.len() >= cells && cells > 0 {
            let mut state = [vec![0.0; cells], vec![0.0; cells]];
            run_frames(self, x, cells, &mut state, false, true);
        }
    }

    /// [`Butterworth2::lfilter_frames`] of the frames of `from` less each cell's resting
    /// value, into a new buffer: the filter's one pass makes the copy.
    fn lfilter_frames_less(&self, from: &[f64], less: &LessOffsets) -> Vec<f64> {
        let cells = less.offsets.len();
        let len = from.len().checked_div(cells).unwrap_or(0) * cells;
        let mut x = Vec::with_capacity(len);
        if len > 0 {
            let mut state = [vec![0.0; cells], vec![0.0; cells]];
            let out = &mut x.spare_capacity_mut()[..len];
            run_frames_less(self, &from[..len], less, out, &mut state, true);
            // SAFETY: the pass wrote every frame.
            unsafe { x.set_len(len) };
        }
        x
    }
}

widest_or_plain! {
    ["avx512f", "avx2"]
    /// Runs every channel's filter over the frames of `x` in place, forward or (`back`)
    /// from the last frame, from the state in `z` or (`start`) each channel started in its
    /// steady state for its first value; compiled with AVX-512's 32 registers, else AVX2's
    /// four lanes, where the processor has them (no multiply and add is fused: the same
    /// bits). Returns the largest value written (-inf for none), found off the filter's
    /// chain of dependent steps, where a pass of its own would read every sample again.
    fn run_frames(
        f: &Butterworth2,
        x: &mut [f64],
        cells: usize,
        z: &mut [Vec<f64>; 2],
        back: bool,
        start: bool,
    ) -> f64 {
        let [z0, z1] = z;
        match cells {
            4 => run_width::<4>(f, x, [z0, z1], back, start),
            8 => run_width::<8>(f, x, [z0, z1], back, start),
            16 => run_width::<16>(f, x, [z0, z1], back, start),
            _ => {
                let (z0, z1) = (&mut z0[..cells], &mut z1[..cells]);
                let mut top = f64::NEG_INFINITY;
                let frames = x.chunks_exact_mut(cells);
                match back {
                    false => {
                        for (i, frame) in frames.enumerate() {
                            step_frame(f, frame, z0, z1, start && i == 0);
                            top = frame.iter().fold(top, |m, &v| if v > m { v } else { m });
                        }
                    }
                    true => {
                        for (i, frame) in frames.rev().enumerate() {
                            step_frame(f, frame, z0, z1, start && i == 0);
                            top = frame.iter().fold(top, |m, &v| if v > m { v } else { m });
                        }
                    }
                }
                top
            }
        }
    }
}

widest_or_plain! {
    ["avx512f", "avx2"]
    /// [`run_frames`] forward over the frames of `from` less each cell's resting value
    /// (masked), written to `out`: the copy of the selected phase made by the filter's
    /// first pass over it.
    fn run_frames_less(
        f: &Butterworth2,
        from: &[f64],
        less: &LessOffsets,
        out: &mut [MaybeUninit<f64>],
        z: &mut [Vec<f64>; 2],
        start: bool,
    ) {
        let [z0, z1] = z;
        match less.offsets.len() {
            4 => run_width_less::<4>(f, from, less, out, [z0, z1], start),
            8 => run_width_less::<8>(f, from, less, out, [z0, z1], start),
            16 => run_width_less::<16>(f, from, less, out, [z0, z1], start),
            cells => {
                let (z0, z1) = (&mut z0[..cells], &mut z1[..cells]);
                let mut frame = vec![0.0; cells];
                let pairs = from.chunks_exact(cells).zip(out.chunks_exact_mut(cells));
                for (i, (src, dst)) in pairs.enumerate() {
                    for (v, s) in frame.iter_mut().zip(less.frame(src)) {
                        *v = s;
                    }
                    step_frame(f, &mut frame, z0, z1, start && i == 0);
                    for (d, &v) in dst.iter_mut().zip(&frame) {
                        d.write(v);
                    }
                }
            }
        }
    }
}

/// [`run_frames`] for frames of exactly `W` cells: the state is held in arrays the
/// compiler keeps in registers from frame to frame, where with `cells` known only
/// at run time it is stored and loaded back every frame, on the chain each frame
/// waits for.
#[inline(always)]
fn run_width<const W: usize>(
    f: &Butterworth2,
    x: &mut [f64],
    [z0, z1]: [&mut Vec<f64>; 2],
    back: bool,
    start: bool,
) -> f64 {
    let mut a: [f64; W] = z0[..W].try_into().expect("W states");
    let mut b: [f64; W] = z1[..W].try_into().expect("W states");
    let mut top = [f64::NEG_INFINITY; W];
    let frames = x.as_chunks_mut::<W>().0.iter_mut();
    match back {
        false => {
            for (i, frame) in frames.enumerate() {
                step_frame(f, frame, &mut a, &mut b, start && i == 0);
                keep_largest(&mut top, frame);
            }
        }
        true => {
            for (i, frame) in frames.rev().enumerate() {
                step_frame(f, frame, &mut a, &mut b, start && i == 0);
                keep_largest(&mut top, frame);
            }
        }
    }
    z0[..W].copy_from_slice(&a);
    z1[..W].copy_from_slice(&b);
    top.into_iter().fold(f64::NEG_INFINITY, f64::max)
}

/// [`run_frames_less`] for frames of exactly `W` cells, the state in registers as in
/// [`run_width`].
#[inline(always)]
fn run_width_less<const W: usize>(
    f: &Butterworth2,
    from: &[f64],
    less: &LessOffsets,
    out: &mut [MaybeUninit<f64>],
    [z0, z1]: [&mut Vec<f64>; 2],
    start: bool,
) {
    let mut a: [f64; W] = z0[..W].try_into().expect("W states");
    let mut b: [f64; W] = z1[..W].try_into().expect("W states");
    let offsets: [f64; W] = less.offsets[..W].try_into().expect("W offsets");
    let keep: [u64; W] = less.keep[..W].try_into().expect("W masks");
    let pairs = from
        .as_chunks::<W>()
        .0
        .iter()
        .zip(out.as_chunks_mut::<W>().0);
    for (i, (src, dst)) in pairs.enumerate() {
        let mut frame: [f64; W] = std::array::from_fn(|c| masked_less(src[c], offsets[c], keep[c]));
        step_frame(f, &mut frame, &mut a, &mut b, start && i == 0);
        for (d, v) in dst.iter_mut().zip(frame) {
            d.write(v);
        }
    }
    z0[..W].copy_from_slice(&a);
    z1[..W].copy_from_slice(&b);
}

/// Each of `top`'s running maxima raised to its value of `frame` where that is larger.
#[inline(always)]
fn keep_largest(top: &mut [f64], frame: &[f64]) {
    for (m, &v) in top.iter_mut().zip(frame) {
        *m = if v > *m { v } else { *m };
    }
}

/// One frame through each channel's filter, its state in `z0` and `z1`; `first`
/// starts each channel in its steady state for its value.
#[inline(always)]
fn step_frame(f: &Butterworth2, frame: &mut [f64], z0: &mut [f64], z1: &mut [f64], first: bool) {
    if first {
        for ((&v, a), b) in frame.iter().zip(z0.iter_mut()).zip(z1.iter_mut()) {
            [*a, *b] = f.steady_state(v);
        }
    }
    for ((v, a), b) in frame.iter_mut().zip(z0.iter_mut()).zip(z1.iter_mut()) {
        let mut z = [*a, *b];
        *v = f.step(*v, &mut z);
        [*a, *b] = z;
    }
}

/// Whether the recording is sampled uniformly at the encoder's 1 kHz (no resampling).
fn uniform_1k(rec: &Recording) -> bool {
    rec.times_s.is_none() && (rec.fs - ENCODER_FS).abs() < 1e-9
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
    let uniform_1k = uniform_1k(rec);
    let samples = if uniform_1k {
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
fn less_offsets(samples: &[f64], offsets: &[f64], present: &[bool]) -> Vec<f64> {
    LessOffsets::new(offsets, present).copy(samples)
}

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
        let (mut samples, top) = if uniform_1k(rec) {
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
        let stamps = rec.times_s.as_ref().map(|_| relative_times(rec));
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
            resampled: !uniform_1k(rec),
            flat,
        })
    }
}

/// Divides every sample by the largest sample of all taxels (paper section II-E), so
/// relative activation between taxels survives. Returns `true`, and sets everything to 0,
/// when that maximum is <= 0 (a recording with no positive signal is never divided).
pub fn normalise_global_max(samples: &mut [f64]) -> bool {
    normalise_by_max(samples, largest(samples))
}

/// [`normalise_global_max`] with the samples' maximum `max` already found.
fn normalise_by_max(samples: &mut [f64], max: f64) -> bool {
    if max > 0.0 {
        // A true division, not a multiplication by `1 / max`: that rounds twice and can
        // differ in the last bit, which the encoder's threshold can turn into a spike more
        // or less; dividing gives numpy's `x / x.max()` bit for bit.
        divide_all(samples, max);
        false
    } else {
        samples.iter_mut().for_each(|s| *s = 0.0);
        true
    }
}

widest_or_plain! {
    ["avx2"]
    /// The largest of `samples` (finite numbers; -inf for none): eight running maxima,
    /// which vectorise where one fold through `f64::max` is a chain of dependent
    /// comparisons. The largest of a set does not depend on the order it is sought in (a
    /// maximum of 0 may come out as -0, which compares equal).
    fn largest(samples: &[f64]) -> f64 {
        let mut lanes = [f64::NEG_INFINITY; 8];
        let chunks = samples.chunks_exact(8);
        for &x in chunks.remainder() {
            lanes[0] = if x > lanes[0] { x } else { lanes[0] };
        }
        for chunk in chunks {
            for (m, &x) in lanes.iter_mut().zip(chunk) {
                *m = if x > *m { x } else { *m };
            }
        }
        let mut top = f64::NEG_INFINITY;
        for m in lanes {
            top = top.max(m);
        }
        top
    }
}

widest_or_plain! {
    ["avx2"]
    /// Divides every sample by `by` (correctly rounded in any vector width, so the same
    /// bits as one division at a time).
    fn divide_all(samples: &mut [f64], by: f64) {
        for s in samples {
            *s /= by;
        }
    }
}

/// Each sample's time in s from the recording's first: its time stamps less the first, or
/// `i / fs` (the stream computes its frames' times the same way, so both resample alike).
pub fn relative_times(rec: &Recording) -> Vec<f64> {
    match &rec.times_s {
        Some(t) => t.iter().map(|&x| x - t[0]).collect(),
        None => (0..rec.len()).map(|i| i as f64 / rec.fs).collect(),
    }
}

/// A recording's [`relative_times`], without a list for one sampled uniformly: its time
/// `i / fs` is computed where it is read (the same number as the list's).
#[derive(Debug, Clone, Copy)]
enum Times<'a> {
    /// Time stamps less the first.
    Stamps(&'a [f64]),
    /// `n` samples at `fs`.
    Uniform { fs: f64, n: usize },
}

impl<'a> Times<'a> {
    /// The times of `rec`, whose [`relative_times`] are `stamps` where it has time stamps.
    fn of(rec: &Recording, stamps: Option<&'a [f64]>) -> Self {
        match stamps {
            Some(t) => Times::Stamps(t),
            None => Times::Uniform {
                fs: rec.fs,
                n: rec.len(),
            },
        }
    }

    fn len(self) -> usize {
        match self {
            Times::Stamps(t) => t.len(),
            Times::Uniform { n, .. } => n,
        }
    }

    /// Sample `i`'s time.
    fn at(self, i: usize) -> f64 {
        match self {
            Times::Stamps(t) => t[i],
            Times::Uniform { fs, .. } => i as f64 / fs,
        }
    }

    /// The number of samples before the first whose time is not `before` (times ascend, so
    /// `before` holds for a prefix): `slice::partition_point` over the times.
    fn partition_point(self, before: impl Fn(f64) -> bool) -> usize {
        match self {
            Times::Stamps(t) => t.partition_point(|&x| before(x)),
            Times::Uniform { n, .. } => {
                let (mut lo, mut hi) = (0, n);
                while lo < hi {
                    let mid = lo + (hi - lo) / 2;
                    match before(self.at(mid)) {
                        true => lo = mid + 1,
                        false => hi = mid,
                    }
                }
                lo
            }
        }
    }

    /// The times of samples `range`, as a list.
    fn span(self, range: std::ops::Range<usize>) -> Vec<f64> {
        range.map(|i| self.at(i)).collect()
    }
}

/// Divides every sample by the fixed causal `scale` (a true division, as
/// [`normalise_global_max`], so the stream's per-sample division gives the same bits).
/// Returns whether no sample is positive (the recording gives the neurons no drive).
pub fn normalise_fixed(samples: &mut [f64], scale: f64) -> bool {
    let mut any_positive = false;
    for s in samples.iter_mut() {
        *s /= scale;
        any_positive |= *s > 0.0;
    }
    !any_positive
}

/// The causal resting values for `rec`'s grid, with the grid's size checked (a model
/// applied to another grid is refused before this; a hand-edited file could still differ).
fn fixed_offsets(rec: &Recording, causal: &CausalConditioning) -> Result<Vec<f64>> {
    let cells = rec.layout.cells();
    if causal.offsets.len() != cells {
        return Err(DataError::invalid(
            &rec.meta.file,
            format!(
                "the causal resting values are for {} cells, the recording has {cells}",
                causal.offsets.len()
            ),
        )
        .into());
    }
    Ok(causal.offsets.clone())
}

/// The number of samples (`frames x cells`) that [`resample_linear`] makes of a `span_s`
/// second span at `fs`, computed without overflow; `None` when it is not finite or would
/// need more than `isize::MAX` bytes of f64 (no allocation could hold it).
pub fn resampled_len(span_s: f64, fs: f64, cells: usize) -> Option<usize> {
    let steps = (span_s * fs + 1e-9).floor() + 1.0;
    let limit = (isize::MAX as usize / std::mem::size_of::<f64>()) as f64;
    if !(steps.is_finite() && steps >= 1.0 && steps <= limit) {
        return None;
    }
    (steps as usize)
        .checked_mul(cells.max(1))
        .filter(|&n| n <= isize::MAX as usize / std::mem::size_of::<f64>())
}

/// Linear interpolation of `frames` (time-major, `cells` per frame, at `times` in s from the
/// recording's start) onto a grid of `fs` starting at `times[0]`, up to the last time stamp.
///
/// # Panics
/// If `times` does not have one entry per frame, or the result would not fit in memory
/// ([`resampled_len`] is `None`): caller bugs, as readers bound a recording's span.
pub fn resample_linear(frames: &[f64], cells: usize, times: &[f64], fs: f64) -> Vec<f64> {
    resample_less(frames, cells, times, fs, None)
}

/// [`resample_linear`], each value then less its cell's resting value in the same pass when
/// `rest` gives them (`(offsets, present)`: a cell not present is 0), as a pass of its own
/// after the resampling would make it.
///
/// # Panics
/// As [`resample_linear`].
fn resample_less(
    frames: &[f64],
    cells: usize,
    times: &[f64],
    fs: f64,
    rest: Option<(&[f64], &[bool])>,
) -> Vec<f64> {
    assert_eq!(
        frames.len(),
        times.len() * cells,
        "one time stamp per frame"
    );
    if times.is_empty() || cells == 0 {
        return Vec::new();
    }
    let span = times[times.len() - 1] - times[0];
    let total = resampled_len(span, fs, cells).expect("a resampled length that fits in memory");
    let mut out = Vec::with_capacity(total);
    resample_into(
        frames,
        times,
        fs,
        rest,
        &mut out.spare_capacity_mut()[..total],
    );
    // SAFETY: the pass wrote every one of the `total` values.
    unsafe { out.set_len(total) };
    out
}

widest_or_plain! {
    ["avx512f", "avx2"]
    /// The steps of [`resample_less`] into `out` (`frames.len() / times.len()` cells a
    /// step): each value `a + (b - a) * w` of its bracketing frames, then less its resting
    /// value, lane by lane, so the width changes no bit.
    fn resample_into(
        frames: &[f64],
        times: &[f64],
        fs: f64,
        rest: Option<(&[f64], &[bool])>,
        out: &mut [MaybeUninit<f64>],
    ) {
        let cells = frames.len() / times.len();
        let t0 = times[0];
        let mut k = 0usize;
        for (s, step) in out.chunks_exact_mut(cells).enumerate() {
            if times.len() == 1 {
                for (x, &a) in step.iter_mut().zip(&frames[..cells]) {
                    x.write(a);
                }
            } else {
                let t = t0 + s as f64 / fs;
                while k + 1 < times.len() - 1 && times[k + 1] <= t {
                    k += 1;
                }
                let (ta, tb) = (times[k], times[k + 1]);
                let w = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
                let fa = &frames[k * cells..(k + 1) * cells];
                let fb = &frames[(k + 1) * cells..(k + 2) * cells];
                match rest {
                    Some((offsets, present)) => {
                        let cell = fa.iter().zip(fb).zip(offsets).zip(present);
                        for (x, (((&a, &b), &o), &p)) in step.iter_mut().zip(cell) {
                            let v = a + (b - a) * w;
                            x.write(if p { v - o } else { 0.0 });
                        }
                    }
                    None => {
                        for ((x, &a), &b) in step.iter_mut().zip(fa).zip(fb) {
                            x.write(a + (b - a) * w);
                        }
                    }
                }
                continue;
            }
            if let Some((offsets, present)) = rest {
                for ((x, &o), &p) in step.iter_mut().zip(offsets).zip(present) {
                    // SAFETY: written from the frame just above.
                    let v = unsafe { x.assume_init() };
                    x.write(if p { v - o } else { 0.0 });
                }
            }
        }
    }
}

/// The sample range `[lo, hi)` of the sliding phase: labelled phases first, then the
/// manifest's `slide_start_s`/`slide_end_s`, else the whole recording.
fn slide_range(rec: &Recording, times: Times) -> Result<(usize, usize)> {
    let n = times.len();
    if let Some(phases) = &rec.phases {
        let lo = phases.iter().position(|&p| p == Phase::Slide);
        let hi = phases.iter().rposition(|&p| p == Phase::Slide);
        return match (lo, hi) {
            (Some(lo), Some(hi)) => Ok((lo, hi + 1)),
            _ => Err(DataError::invalid(&rec.meta.file, "no sample is labelled as sliding").into()),
        };
    }
    let start = rec.meta.slide_start_s.unwrap_or(0.0);
    let end = rec.meta.slide_end_s.unwrap_or(f64::INFINITY);
    let lo = times.partition_point(|t| t < start - 1e-9);
    let hi = times.partition_point(|t| t < end - 1e-9);
    if hi <= lo || lo >= n {
        return Err(DataError::invalid(
            &rec.meta.file,
            format!(
                "slide interval [{start}, {end}) s holds no samples of this {:.3} s recording",
                rec.duration_s()
            ),
        )
        .into());
    }
    Ok((lo, hi))
}

/// Each cell's resting value under `baseline` (zeros for [`Baseline::None`]), over the whole
/// recording (`times` in s from its first sample).
///
/// # Errors
/// A mean baseline whose interval holds no samples.
pub fn baseline_offsets(rec: &Recording, times: &[f64], baseline: Baseline) -> Result<Vec<f64>> {
    offsets_at(rec, Times::Stamps(times), baseline)
}

/// [`baseline_offsets`] with the recording's [`Times`].
fn offsets_at(rec: &Recording, times: Times, baseline: Baseline) -> Result<Vec<f64>> {
    let cells = rec.layout.cells();
    match baseline {
        Baseline::None => Ok(vec![0.0; cells]),
        Baseline::Min => {
            let mut lo = vec![f64::INFINITY; cells];
            for frame in rec.samples.chunks_exact(cells) {
                for (l, &s) in lo.iter_mut().zip(frame) {
                    *l = l.min(s);
                }
            }
            Ok(lo)
        }
        Baseline::Mean { start_s, end_s } => {
            let a = times.partition_point(|t| t < start_s);
            let b = times.partition_point(|t| t < end_s);
            if b <= a {
                return Err(DataError::invalid(
                    &rec.meta.file,
                    format!("baseline interval [{start_s}, {end_s}) s holds no samples"),
                )
                .into());
            }
            let mut sum = vec![0.0; cells];
            for frame in rec.samples[a * cells..b * cells].chunks_exact(cells) {
                for (acc, &s) in sum.iter_mut().zip(frame) {
                    *acc += s;
                }
            }
            Ok(sum.into_iter().map(|s| s / (b - a) as f64).collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
