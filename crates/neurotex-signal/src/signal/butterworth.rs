//! The second-order Butterworth low-pass: its coefficients, and its runs over every
//! channel's frames forward, backward (zero-phase) or causally, vectorised where the
//! processor allows.

use std::mem::MaybeUninit;

use crate::error::{ParamError, Result};
use crate::simd::widest_or_plain;

use super::normalise::largest;
use super::{masked_less, LessOffsets};

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
    pub(super) fn filtfilt_frames_top(&self, x: &mut [f64], cells: usize) -> f64 {
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
    pub(super) fn filtfilt_frames_less(&self, from: &[f64], less: &LessOffsets) -> (Vec<f64>, f64) {
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
    pub(super) fn lfilter_frames_less(&self, from: &[f64], less: &LessOffsets) -> Vec<f64> {
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
