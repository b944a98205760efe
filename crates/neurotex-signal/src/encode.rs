//! The Izhikevich encoder (Izhikevich 2003, "Simple model of spiking neurons"; paper
//! section II-E): each taxel drives one neuron with input current `I = G * x`.
//!
//! The scheme is that of Izhikevich's reference code, in f64, one step per millisecond:
//! at the start of a step a neuron with `v >= 30` records a spike and resets
//! (`v = c`, `u = u + d`); then `v` advances in two 0.5 ms Euler half-steps and `u` by 1 ms
//! with the new `v`. State persists between calls, so a recording fed in chunks gives
//! exactly the spikes of one call.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

/// The spike threshold (mV) of the 2003 model.
pub const V_PEAK: f64 = 30.0;

/// Neuron parameters and input gain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IzhikevichParams {
    /// Recovery time scale `a`.
    pub a: f64,
    /// Recovery sensitivity `b`.
    pub b: f64,
    /// Reset potential `c` (mV).
    pub c: f64,
    /// Recovery jump after a spike `d`.
    pub d: f64,
    /// Gain `G` from normalised signal to input current (the paper's 8).
    pub gain: f64,
}

impl Default for IzhikevichParams {
    /// Regular spiking (slowly adapting type I) with the paper's gain G = 8.
    fn default() -> Self {
        Self::preset("RS").expect("RS is a preset")
    }
}

/// The firing types of Izhikevich (2003), figure 2, as `(name, a, b, c, d)`.
pub const PRESETS: [(&str, f64, f64, f64, f64); 7] = [
    ("RS", 0.02, 0.2, -65.0, 8.0),
    ("IB", 0.02, 0.2, -55.0, 4.0),
    ("CH", 0.02, 0.2, -50.0, 2.0),
    ("FS", 0.1, 0.2, -65.0, 2.0),
    ("LTS", 0.02, 0.25, -65.0, 2.0),
    ("TC", 0.02, 0.25, -65.0, 0.05),
    ("RZ", 0.1, 0.26, -65.0, 2.0),
];

/// A firing type of Izhikevich (2003), figure 2, in the order of [`PRESETS`]; parses from
/// its name in any case (`RS`, `fs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FiringType {
    /// Regular spiking, the paper's slowly adapting type I.
    #[default]
    Rs,
    /// Intrinsically bursting.
    Ib,
    /// Chattering.
    Ch,
    /// Fast spiking.
    Fs,
    /// Low-threshold spiking.
    Lts,
    /// Thalamo-cortical.
    Tc,
    /// Resonator.
    Rz,
}

impl FiringType {
    /// Every firing type, in the order of [`PRESETS`].
    pub const ALL: [FiringType; 7] = [
        FiringType::Rs,
        FiringType::Ib,
        FiringType::Ch,
        FiringType::Fs,
        FiringType::Lts,
        FiringType::Tc,
        FiringType::Rz,
    ];

    /// The name in [`PRESETS`] (`RS`).
    pub fn name(self) -> &'static str {
        PRESETS[self as usize].0
    }

    /// The neuron parameters of this type with gain 8.
    pub fn params(self) -> IzhikevichParams {
        let (_, a, b, c, d) = PRESETS[self as usize];
        IzhikevichParams {
            a,
            b,
            c,
            d,
            gain: 8.0,
        }
    }
}

impl std::fmt::Display for FiringType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for FiringType {
    type Err = ParamError;

    /// Parses a name of [`PRESETS`], in any case.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        FiringType::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(text.trim()))
            .ok_or_else(|| {
                ParamError::new(
                    "preset",
                    "a firing type is one of RS, IB, CH, FS, LTS, TC, RZ",
                    text,
                )
            })
    }
}

impl IzhikevichParams {
    /// A named firing type from [`PRESETS`] with gain 8, or `None` for an unknown name.
    pub fn preset(name: &str) -> Option<Self> {
        name.parse().ok().map(FiringType::params)
    }

    /// Sets the gain.
    pub fn with_gain(mut self, gain: f64) -> Self {
        self.gain = gain;
        self
    }

    /// Checks the rules: `a` in (0, 1], `b` in [-1, 1], `c` in [-100, 30) mV, `d` in
    /// [-100, 100], gain in (0, 10000]. Izhikevich's firing types (2003, 2004) lie well
    /// inside (a 0.02-0.1, b -0.1-0.26, c -65 to -50, d -2 to 8); far outside, the 1 ms
    /// Euler step overflows to NaN, which never crosses the peak: the neuron would fall
    /// silent without an error.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if !(self.gain.is_finite() && self.gain > 0.0 && self.gain <= 1e4) {
            return Err(ParamError::new(
                "gain",
                "gain must be a number in (0, 10000]",
                self.gain,
            ));
        }
        if !(self.a > 0.0 && self.a <= 1.0) {
            return Err(ParamError::new(
                "a",
                "recovery scale a must be in (0, 1]",
                self.a,
            ));
        }
        if !(-1.0..=1.0).contains(&self.b) {
            return Err(ParamError::new(
                "b",
                "recovery sensitivity b must be in [-1, 1]",
                self.b,
            ));
        }
        if !(self.c >= -100.0 && self.c < V_PEAK) {
            return Err(ParamError::new(
                "c",
                "reset potential c must be in [-100, 30) mV, below the 30 mV peak",
                self.c,
            ));
        }
        if !(-100.0..=100.0).contains(&self.d) {
            return Err(ParamError::new(
                "d",
                "recovery jump d must be in [-100, 100]",
                self.d,
            ));
        }
        Ok(())
    }
}

/// A bank of Izhikevich neurons whose state carries over between calls.
#[derive(Debug, Clone)]
pub struct Encoder {
    params: IzhikevichParams,
    /// Each neuron's input gain: the parameters' gain unless built by
    /// [`Encoder::with_gains`].
    gains: Vec<f64>,
    v: Vec<f64>,
    u: Vec<f64>,
    steps: u64,
}

impl Encoder {
    /// `n` neurons at rest (`v = c`, `u = b c`).
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: IzhikevichParams, n: usize) -> Result<Self, ParamError> {
        Encoder::with_gains(params, vec![params.gain; n])
    }

    /// One neuron at rest per gain, with that input gain and `params`' other parameters.
    ///
    /// # Errors
    /// A broken parameter rule, for `params` or with one of the gains.
    fn with_gains(params: IzhikevichParams, gains: Vec<f64>) -> Result<Self, ParamError> {
        params.check()?;
        for &g in &gains {
            params.with_gain(g).check()?;
        }
        let n = gains.len();
        Ok(Encoder {
            params,
            gains,
            v: vec![params.c; n],
            u: vec![params.b * params.c; n],
            steps: 0,
        })
    }

    /// Number of neurons.
    pub fn neurons(&self) -> usize {
        self.v.len()
    }

    /// Steps run so far (the time of the next step in ms).
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Runs one step per frame of `input` (time-major, one value per neuron, normalised
    /// signal) and writes 1 into `raster` where a neuron spiked at that step, else 0.
    ///
    /// # Panics
    /// If `input` is not whole frames or `raster` is not its size (a caller bug).
    pub fn run(&mut self, input: &[f64], raster: &mut [u8]) {
        let n = self.v.len();
        assert!(
            n > 0 && input.len().is_multiple_of(n),
            "input must be whole frames"
        );
        assert_eq!(input.len(), raster.len(), "raster must match input");
        let bank = Bank {
            gains: &self.gains,
            v: &mut self.v,
            u: &mut self.u,
            input,
            raster,
        };
        run_fastest(&self.params, bank);
        self.steps += (input.len() / n) as u64;
    }

    /// Runs one step of the neurons `first..first + input.len()` only (one value each) and
    /// writes their spikes into `raster`: for callers that take a frame through all their
    /// stages a cache-sized part at a time. [`Encoder::steps`] counts [`Encoder::run`]'s
    /// frames only.
    ///
    /// # Panics
    /// If the part does not lie inside the bank or `raster` is not `input`'s size (a
    /// caller bug).
    pub fn run_part(&mut self, first: usize, input: &[f64], raster: &mut [u8]) {
        let cells = first..first + input.len();
        assert_eq!(input.len(), raster.len(), "raster must match input");
        let bank = Bank {
            gains: &self.gains[cells.clone()],
            v: &mut self.v[cells.clone()],
            u: &mut self.u[cells],
            input,
            raster,
        };
        run_fastest(&self.params, bank);
    }
}

/// The part of a bank one kernel call runs: each neuron's gain and state, and the
/// time-major input and raster (one value per neuron per frame).
struct Bank<'a> {
    gains: &'a [f64],
    v: &'a mut [f64],
    u: &'a mut [f64],
    input: &'a [f64],
    raster: &'a mut [u8],
}

/// Runs the bank with AVX-512 or AVX2 where the processor has them.
fn run_fastest(p: &IzhikevichParams, bank: Bank<'_>) {
    #[cfg(target_arch = "x86_64")]
    {
        if neurotex_core::has_feature!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, the only feature the function enables.
            unsafe { run_avx512(p, bank) };
            return;
        }
        if neurotex_core::has_feature!("avx2") {
            // SAFETY: the CPU supports AVX2, the only feature the function enables.
            unsafe { run_avx2(p, bank) };
            return;
        }
    }
    run_portable(p, bank);
}

/// Neurons per block whose state stays in registers across time steps. One step is a
/// chain of about 20 dependent operations, so a block is bound by their latency, and the
/// more independent chains (lanes) in flight the better, as long as the registers hold
/// them: 16 neurons with AVX2 (four registers of four f64 each for `v`, four for `u`,
/// out of 16), 32 with AVX-512 (four of eight each, out of 32), where a block of 32 runs in
/// little more time than one of 16. A bank of 16 taxels gains from the wider block only
/// when two populations run as one bank ([`encode_banks`]).
const BLOCK: usize = 16;

/// Blocks of [`BLOCK`], then the rest, compiled with AVX2 (4 f64 lanes). FMA is not
/// enabled, and Rust never fuses a multiply and an add on its own, so results are
/// bit-identical to the portable path.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2(p: &IzhikevichParams, mut bank: Bank<'_>) {
    let done = run_blocks::<BLOCK>(p, &mut bank, 0);
    run_rest(p, &mut bank, done);
}

/// Blocks of 32, 16 and 8 neurons (four, two and one register of eight f64 lanes per
/// state variable, see [`BLOCK`]), then the rest, with AVX-512F; bit-identical to the
/// portable path as [`run_avx2`] is.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn run_avx512(p: &IzhikevichParams, mut bank: Bank<'_>) {
    let done = avx512::run_blocks::<4>(p, &mut bank, 0);
    let done = avx512::run_blocks::<2>(p, &mut bank, done);
    let done = avx512::run_blocks::<1>(p, &mut bank, done);
    run_rest(p, &mut bank, done);
}

/// The AVX-512 blocks, written with intrinsics: the compiler's own vectorisation of
/// [`step`] kept part of a 32-neuron block's state in memory between steps, which
/// lengthened every step's chain of dependent operations.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::{Bank, IzhikevichParams, V_PEAK};

    /// f64 lanes per register.
    const LANES: usize = 8;

    /// Runs the whole blocks of `R` registers (`8 R` neurons) from neuron `first` on and
    /// returns the first neuron not run: [`super::step`]'s operations in its order, on
    /// eight neurons per instruction.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn run_blocks<const R: usize>(
        p: &IzhikevichParams,
        bank: &mut Bank<'_>,
        first: usize,
    ) -> usize {
        let n = bank.v.len();
        let width = R * LANES;
        let end = first + (n - first) / width * width;
        let [a, b, c, d] = [p.a, p.b, p.c, p.d].map(|k| _mm512_set1_pd(k));
        let [peak, half, quad, five, rest] =
            [V_PEAK, 0.5, 0.04, 5.0, 140.0].map(|k| _mm512_set1_pd(k));
        // `v += 0.5 * (0.04 * (v * v) + 5.0 * v + 140.0 - u + i)`, left to right.
        let half_step = |v: __m512d, u: __m512d, i: __m512d| {
            let square = _mm512_mul_pd(quad, _mm512_mul_pd(v, v));
            let sum = _mm512_add_pd(square, _mm512_mul_pd(five, v));
            let sum = _mm512_add_pd(_mm512_sub_pd(_mm512_add_pd(sum, rest), u), i);
            _mm512_add_pd(v, _mm512_mul_pd(half, sum))
        };
        for start in (first..end).step_by(width) {
            let load = |from: &[f64], r: usize| {
                _mm512_loadu_pd(from[start + r * LANES..][..LANES].as_ptr())
            };
            let mut v: [__m512d; R] = std::array::from_fn(|r| load(bank.v, r));
            let mut u: [__m512d; R] = std::array::from_fn(|r| load(bank.u, r));
            let g: [__m512d; R] = std::array::from_fn(|r| load(bank.gains, r));
            let frames = bank.input.chunks_exact(n);
            for (frame, out) in frames.zip(bank.raster.chunks_exact_mut(n)) {
                for r in 0..R {
                    let at = start + r * LANES;
                    let fired = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(v[r], peak);
                    let spikes = _mm512_cvtepi64_epi8(_mm512_maskz_set1_epi64(fired, 1));
                    _mm_storel_epi64(out[at..at + LANES].as_mut_ptr().cast(), spikes);
                    let vv = _mm512_mask_blend_pd(fired, v[r], c);
                    let uu = _mm512_mask_add_pd(u[r], fired, u[r], d);
                    let i = _mm512_mul_pd(g[r], _mm512_loadu_pd(frame[at..at + LANES].as_ptr()));
                    let vv = half_step(half_step(vv, uu, i), uu, i);
                    let recovery = _mm512_sub_pd(_mm512_mul_pd(b, vv), uu);
                    u[r] = _mm512_add_pd(uu, _mm512_mul_pd(a, recovery));
                    v[r] = vv;
                }
            }
            for r in 0..R {
                let at = start + r * LANES;
                _mm512_storeu_pd(bank.v[at..at + LANES].as_mut_ptr(), v[r]);
                _mm512_storeu_pd(bank.u[at..at + LANES].as_mut_ptr(), u[r]);
            }
        }
        end
    }
}

/// Blocks of [`BLOCK`], then the rest, for any processor.
fn run_portable(p: &IzhikevichParams, mut bank: Bank<'_>) {
    let done = run_blocks::<BLOCK>(p, &mut bank, 0);
    run_rest(p, &mut bank, done);
}

/// Runs the whole blocks of `B` neurons from neuron `first` on (time inner, a block's state
/// in registers) and returns the first neuron not run.
#[inline(always)]
fn run_blocks<const B: usize>(p: &IzhikevichParams, bank: &mut Bank<'_>, first: usize) -> usize {
    let n = bank.v.len();
    let end = first + (n - first) / B * B;
    for start in (first..end).step_by(B) {
        let block = start..start + B;
        let mut vb = [0.0; B];
        let mut ub = [0.0; B];
        let mut gb = [0.0; B];
        vb.copy_from_slice(&bank.v[block.clone()]);
        ub.copy_from_slice(&bank.u[block.clone()]);
        gb.copy_from_slice(&bank.gains[block.clone()]);
        let frames = bank.input.chunks_exact(n);
        for (frame, out) in frames.zip(bank.raster.chunks_exact_mut(n)) {
            let x: &[f64; B] = frame[block.clone()].try_into().expect("a block");
            let o: &mut [u8; B] = (&mut out[block.clone()]).try_into().expect("a block");
            step(p, &gb, &mut vb, &mut ub, x, o);
        }
        bank.v[block.clone()].copy_from_slice(&vb);
        bank.u[block].copy_from_slice(&ub);
    }
    end
}

/// Runs the neurons from `first` on, frame by frame.
#[inline(always)]
fn run_rest(p: &IzhikevichParams, bank: &mut Bank<'_>, first: usize) {
    let n = bank.v.len();
    if first == n {
        return;
    }
    let frames = bank.input.chunks_exact(n);
    for (frame, out) in frames.zip(bank.raster.chunks_exact_mut(n)) {
        step(
            p,
            &bank.gains[first..],
            &mut bank.v[first..],
            &mut bank.u[first..],
            &frame[first..],
            &mut out[first..],
        );
    }
}

/// One 1 ms step of the reference scheme for a group of neurons, each with its gain.
/// Branch-free per neuron so it vectorises; the order of every floating-point operation is
/// that of the reference.
#[inline(always)]
fn step(
    p: &IzhikevichParams,
    gains: &[f64],
    v: &mut [f64],
    u: &mut [f64],
    x: &[f64],
    out: &mut [u8],
) {
    let IzhikevichParams { a, b, c, d, .. } = *p;
    let lanes = v.iter_mut().zip(u.iter_mut()).zip(gains.iter().zip(x));
    for (((vi, ui), (&gain, &x)), o) in lanes.zip(out.iter_mut()) {
        let fired = *vi >= V_PEAK;
        *o = fired as u8;
        let mut vv = if fired { c } else { *vi };
        let uu = if fired { *ui + d } else { *ui };
        let i = gain * x;
        vv += 0.5 * (0.04 * (vv * vv) + 5.0 * vv + 140.0 - uu + i);
        vv += 0.5 * (0.04 * (vv * vv) + 5.0 * vv + 140.0 - uu + i);
        *ui = uu + a * (b * vv - uu);
        *vi = vv;
    }
}

pub use neurotex_core::spikes::SpikeTrains;

/// Encodes a conditioned `n_steps x cells` signal into spike trains (fresh neurons).
///
/// The signal is run in blocks of 1024 steps through a small raster that stays in cache,
/// and each block's spikes are appended to per-cell lists, so no whole-recording raster is
/// ever allocated.
///
/// # Errors
/// A broken parameter rule.
pub fn encode(
    samples: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    params: IzhikevichParams,
) -> Result<SpikeTrains, ParamError> {
    let mut trains = encode_banks(&[samples], &[params.gain], rows, cols, present, params)?;
    Ok(trains.pop().expect("one bank"))
}

/// Encodes several conditioned `n_steps x cells` signals of one grid and length, signal
/// `k` by neurons of input gain `gains[k]` and `params`' other parameters, into one set of
/// spike trains each: the same trains as [`encode`] of each signal alone
/// ([`encode_drives`] with every drive a [`Drive::Signal`]).
///
/// # Errors
/// A broken parameter rule, for `params` or with one of the gains.
///
/// # Panics
/// If the signals and gains differ in number, or the signals in length, or are not whole
/// frames (a caller bug).
pub fn encode_banks(
    signals: &[&[f64]],
    gains: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    params: IzhikevichParams,
) -> Result<Vec<SpikeTrains>, ParamError> {
    let mut drives: Vec<Drive<'_>> = signals.iter().map(|&s| Drive::Signal(s)).collect();
    encode_drives(&mut drives, gains, rows, cols, present, params)
}

/// What drives a bank of neurons: a conditioned `n_steps x cells` signal itself, its
/// rectified rate of change, or values made as the bank runs.
pub enum Drive<'a> {
    /// The signal (the SA population).
    Signal(&'a [f64]),
    /// [`rectified_rate`] of the signal (the FA-I population, see [`FaParams`]), made a
    /// block of steps at a time as the bank runs.
    RectifiedRate(&'a [f64]),
    /// Values made a block of steps at a time as the bank runs.
    Made(&'a mut dyn MadeDrive),
}

/// A drive whose values are made a block of steps at a time as its bank runs
/// ([`Drive::Made`]), rather than read from a whole signal in memory: a signal computed
/// from another (a perturbed copy) then needs no memory of its own, and its values go
/// straight into the bank's place in the frames the neurons read.
pub trait MadeDrive: Send {
    /// The number of values, `n_steps x cells`.
    fn values(&self) -> usize;

    /// Writes the values of the steps from `first` on into `rows`, one row of `cells`
    /// values per step; called for consecutive blocks of steps, from step 0 on.
    fn fill(&mut self, first: usize, rows: BankRows<'_>);
}

/// One bank's place in a block of frames of several banks side by side: a row of `cells`
/// values per step.
pub struct BankRows<'a> {
    frames: &'a mut [f64],
    width: usize,
    bank: std::ops::Range<usize>,
}

impl BankRows<'_> {
    /// The number of steps (rows).
    pub fn steps(&self) -> usize {
        self.frames.len() / self.width
    }

    /// The rows in order, each the bank's `cells` values of one step.
    pub fn rows(&mut self) -> impl Iterator<Item = &mut [f64]> {
        let bank = self.bank.clone();
        self.frames
            .chunks_exact_mut(self.width)
            .map(move |frame| &mut frame[bank.clone()])
    }
}

impl Drive<'_> {
    /// The number of values, `n_steps x cells`.
    fn values(&self) -> usize {
        match self {
            Drive::Signal(signal) | Drive::RectifiedRate(signal) => signal.len(),
            Drive::Made(made) => made.values(),
        }
    }
}

/// Steps per block of [`encode_drives`] for a bank of `width` neurons: the block's frames
/// (`8 width` bytes a step) stay within a few hundred kilobytes, so that every block of
/// neurons the kernel runs finds them in cache; never more than 1024 steps.
fn block_steps(width: usize) -> usize {
    const VALUES: usize = 32 * 1024;
    (VALUES / width.max(1)).clamp(1, 1024)
}

/// Encodes several drives of one grid and length, drive `k` by neurons of input gain
/// `gains[k]` and `params`' other parameters, into one set of spike trains each: the same
/// trains as [`encode`] of each drive's values alone (for a [`Drive::RectifiedRate`], as
/// [`encode_fa`]).
///
/// The drives run as one bank of neurons, their frames side by side, a block of steps at
/// a time through a small raster that stays in cache; each block's spikes are appended to
/// per-cell lists, so no whole-recording raster or drive is ever allocated. A neuron's
/// state depends on its own input only and every lane computes what [`step`] computes,
/// so where a neuron sits in the bank changes no bit. Where the processor has AVX-512,
/// two banks of 16 taxels run in little more time than one (see [`BLOCK`]); the callers
/// put together the encodings one recording needs (SA and FA, the gains of a sweep, the
/// perturbed draws of the encoder's sensitivity).
///
/// # Errors
/// A broken parameter rule, for `params` or with one of the gains.
///
/// # Panics
/// If the drives and gains differ in number, or the drives in length, or are not whole
/// frames (a caller bug).
pub fn encode_drives(
    drives: &mut [Drive<'_>],
    gains: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    params: IzhikevichParams,
) -> Result<Vec<SpikeTrains>, ParamError> {
    assert_eq!(drives.len(), gains.len(), "one gain per drive");
    let len = drives.first().map_or(0, Drive::values);
    assert!(
        drives.iter().all(|d| d.values() == len),
        "drives of one length"
    );
    let (cells, banks) = (rows * cols, drives.len());
    assert!(cells == 0 || len.is_multiple_of(cells), "whole frames");
    let width = cells * banks;
    let bank_gains = gains.iter().flat_map(|&g| std::iter::repeat_n(g, cells));
    let mut encoder = Encoder::with_gains(params, bank_gains.collect())?;
    let block = block_steps(width);
    let mut raster = vec![0u8; block * width];
    // The banks' frames side by side, unless one signal is its own frames.
    let direct = matches!(drives, [Drive::Signal(_)]);
    let mut frames = vec![0.0; if direct { 0 } else { block * width }];
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); width];
    let neuron_present: Vec<bool> = (0..width).map(|neuron| present[neuron % cells]).collect();
    // A grid without cells has no frames and no trains to fill.
    let n_steps = len.checked_div(cells).unwrap_or(0);
    for first in (0..n_steps).step_by(block) {
        let steps = block.min(n_steps - first);
        let input = match drives {
            [Drive::Signal(signal)] => &signal[first * cells..(first + steps) * cells],
            _ => {
                let frames = &mut frames[..steps * width];
                fill_frames(drives, cells, first, frames);
                &*frames
            }
        };
        let raster = &mut raster[..input.len()];
        encoder.run(input, raster);
        collect_spikes(raster, width, first as u32, &neuron_present, &mut lists);
    }
    Ok((0..banks)
        .map(|b| {
            let lists = &lists[b * cells..(b + 1) * cells];
            SpikeTrains::from_lists(lists, rows, cols, present, n_steps)
        })
        .collect())
}

/// Writes the steps from `first` on of every drive into `frames` (whole frames of all
/// banks side by side, `cells` values per bank).
fn fill_frames(drives: &mut [Drive<'_>], cells: usize, first: usize, frames: &mut [f64]) {
    let width = cells * drives.len();
    let steps = frames.len() / width;
    for (b, drive) in drives.iter_mut().enumerate() {
        let bank = b * cells..(b + 1) * cells;
        match drive {
            Drive::Signal(signal) => {
                let rows = signal[first * cells..(first + steps) * cells].chunks_exact(cells);
                for (row, frame) in rows.zip(frames.chunks_exact_mut(width)) {
                    copy_short(row, &mut frame[bank.clone()]);
                }
            }
            Drive::RectifiedRate(signal) => {
                for (t, frame) in (first..).zip(frames.chunks_exact_mut(width)) {
                    let out = &mut frame[bank.clone()];
                    // The first step has no previous sample, as in `rectified_rate`.
                    if t == 0 {
                        out.fill(0.0);
                        continue;
                    }
                    let before = &signal[(t - 1) * cells..(t + 1) * cells];
                    let (before, now) = before.split_at(cells);
                    for ((o, &x), &x0) in out.iter_mut().zip(now).zip(before) {
                        *o = (x - x0).abs();
                    }
                }
            }
            Drive::Made(made) => {
                let frames = &mut *frames;
                made.fill(
                    first,
                    BankRows {
                        frames,
                        width,
                        bank,
                    },
                );
            }
        }
    }
}

/// Appends the spikes of a raster of `width` neurons a step, whose first step is `first`,
/// to the present neurons' lists.
///
/// Spikes are sparse: a step's entries (each 0 or 1) are read eight at a time as one word,
/// and only its set bytes visited, in order. Step and neuron come from the loop, not from
/// dividing a spike's place in the raster.
fn collect_spikes(
    raster: &[u8],
    width: usize,
    first: u32,
    neuron_present: &[bool],
    lists: &mut [Vec<u32>],
) {
    for (t, row) in (first..).zip(raster.chunks_exact(width)) {
        let words = row.chunks_exact(8);
        let tail = words.remainder();
        for (w, word) in words.enumerate() {
            let mut bits = u64::from_le_bytes(word.try_into().expect("8 bytes"));
            while bits != 0 {
                let neuron = w * 8 + bits.trailing_zeros() as usize / 8;
                if neuron_present[neuron] {
                    lists[neuron].push(t);
                }
                bits &= bits - 1;
            }
        }
        let base = width - tail.len();
        for (neuron, _) in (base..).zip(tail).filter(|&(_, &spike)| spike != 0) {
            if neuron_present[neuron] {
                lists[neuron].push(t);
            }
        }
    }
}

/// Copies a frame's few values eight at a time: `copy_from_slice` calls `memcpy` for
/// each, whose call costs more than the copy.
#[inline(always)]
fn copy_short(from: &[f64], to: &mut [f64]) {
    let mut to_eights = to.chunks_exact_mut(8);
    let mut from_eights = from.chunks_exact(8);
    for (t, f) in to_eights.by_ref().zip(from_eights.by_ref()) {
        let f: [f64; 8] = f.try_into().expect("eight values");
        t.copy_from_slice(&f);
    }
    let rest = to_eights.into_remainder().iter_mut();
    rest.zip(from_eights.remainder()).for_each(|(t, &f)| *t = f);
}

/// Fast-adapting (FA-I) encoding parameters.
///
/// The model: an FA-I afferent responds to the rate of change of skin indentation, at
/// contact onset and offset and to vibration, not to sustained pressure (Johnson 2001,
/// Curr. Opin. Neurobiol.; Kim, Sripati and Bensmaia 2010, J. Neurophysiol., whose RA
/// model is driven by the derivative of indentation; Saal and Bensmaia 2014, Trends
/// Neurosci.). Here each taxel's FA neuron is the Izhikevich neuron of the SA channel
/// (same firing type) driven by `I_fa(t) = G_fa * |x(t) - x(t - 1 ms)|`: the full-wave
/// rectified rate of change of the conditioned, normalised signal in units per ms. The
/// signal is already low-passed by the conditioning (50 Hz by default), which is the
/// only smoothing. The first step has no previous sample and gets no drive, so a signal
/// that is constant over the selected phase gives no FA spikes at all.
///
/// The default `G_fa = 8000` follows a stated rule, not classification accuracy: FA
/// neurons should fire at a rate comparable to the SA neurons at the paper's `G = 8` on a
/// typical slide. On the simulated paper rig (`neurotex simulate`, seed 0) at 10 mm/s the
/// median SA taxel fires at 12 Hz; the median FA taxel fires at 1.1, 5.1 and 10.0 Hz with
/// `G_fa` = 3000, 5000 and 8000, so 8000. (Equal mean current, `8 * mean x / mean |dx/dt|`
/// = 1800, left most FA neurons silent: the derivative drive is sparse and peaked, and
/// the neuron's threshold is not linear.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FaParams {
    /// Gain `G_fa` from rate of change (normalised units per ms) to input current.
    pub gain: f64,
}

impl Default for FaParams {
    /// `G_fa = 8000` (see the type's rule).
    fn default() -> Self {
        FaParams { gain: 8000.0 }
    }
}

impl FaParams {
    /// Checks the rule: a gain in (0, 10000].
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if !(self.gain.is_finite() && self.gain > 0.0 && self.gain <= 1e4) {
            return Err(ParamError::new(
                "fa-gain",
                "FA gain must be a number in (0, 10000]",
                self.gain,
            ));
        }
        Ok(())
    }
}

/// The rectified rate of change `|x(t) - x(t - 1)|` per 1 ms step of a time-major signal
/// of `cells` values per frame; the first frame is 0.
///
/// # Panics
/// If `samples` is not whole frames (a caller bug).
pub fn rectified_rate(samples: &[f64], cells: usize) -> Vec<f64> {
    assert!(
        cells > 0 && samples.len().is_multiple_of(cells),
        "whole frames"
    );
    let mut out = vec![0.0; samples.len()];
    for ((now, before), o) in samples[cells..]
        .chunks_exact(cells)
        .zip(samples.chunks_exact(cells))
        .zip(out[cells..].chunks_exact_mut(cells))
    {
        for ((&x, &x0), o) in now.iter().zip(before).zip(o) {
            *o = (x - x0).abs();
        }
    }
    out
}

/// Encodes a conditioned `n_steps x cells` signal into FA-I spike trains: `neuron`'s
/// firing type driven by `G_fa |dx/dt|` (see [`FaParams`]); `neuron.gain` is not used.
///
/// # Errors
/// A broken parameter rule.
pub fn encode_fa(
    samples: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    neuron: IzhikevichParams,
    fa: FaParams,
) -> Result<SpikeTrains, ParamError> {
    fa.check()?;
    let mut drive = [Drive::RectifiedRate(samples)];
    let neuron = neuron.with_gain(fa.gain);
    let mut trains = encode_drives(&mut drive, &[fa.gain], rows, cols, present, neuron)?;
    Ok(trains.pop().expect("one bank"))
}

/// The SA trains of a conditioned signal ([`encode`] with `neuron`) and its FA-I trains
/// ([`encode_fa`]), encoded side by side as two banks ([`encode_drives`]).
///
/// # Errors
/// A broken parameter rule.
pub fn encode_sa_fa(
    samples: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    neuron: IzhikevichParams,
    fa: FaParams,
) -> Result<(SpikeTrains, SpikeTrains), ParamError> {
    neuron.check()?;
    fa.check()?;
    let mut drives = [Drive::Signal(samples), Drive::RectifiedRate(samples)];
    let gains = [neuron.gain, fa.gain];
    let [sa, fa]: [SpikeTrains; 2] =
        encode_drives(&mut drives, &gains, rows, cols, present, neuron)?
            .try_into()
            .expect("two banks");
    Ok((sa, fa))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A drive made as the banks ask for it: `signal` times `factor`.
    struct Scaled<'a> {
        signal: &'a [f64],
        cells: usize,
        factor: f64,
    }

    impl MadeDrive for Scaled<'_> {
        fn values(&self) -> usize {
            self.signal.len()
        }

        fn fill(&mut self, first: usize, mut rows: BankRows<'_>) {
            let signal = &self.signal[first * self.cells..][..rows.steps() * self.cells];
            for (row, x) in rows.rows().zip(signal.chunks_exact(self.cells)) {
                for (out, &x) in row.iter_mut().zip(x) {
                    *out = x * self.factor;
                }
            }
        }
    }

    /// Many drives of every kind side by side on a grid whose banks straddle the vector
    /// registers (9 cells), over several blocks of steps and a part block: each bank's
    /// trains are those of its values encoded alone, whole.
    #[test]
    fn drives_side_by_side_give_each_drives_own_trains() {
        let (rows, cols, steps, banks) = (3, 3, 2_500, 13);
        let cells = rows * cols;
        let present: Vec<bool> = (0..cells).map(|c| c != 4).collect();
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let signals: Vec<Vec<f64>> = (0..banks)
            .map(|_| (0..cells * steps).map(|_| next()).collect())
            .collect();
        let gains: Vec<f64> = (0..banks).map(|b| 12.0 + 2.0 * b as f64).collect();
        let factors: Vec<f64> = (0..banks).map(|b| 1.0 + b as f64 / 7.0).collect();
        let mut made: Vec<Scaled> = (0..banks)
            .map(|b| Scaled {
                signal: &signals[b],
                cells,
                factor: factors[b],
            })
            .collect();
        let mut drives: Vec<Drive> = made
            .iter_mut()
            .enumerate()
            .map(|(b, made)| match b % 3 {
                0 => Drive::Signal(&signals[b]),
                1 => Drive::RectifiedRate(&signals[b]),
                _ => Drive::Made(made),
            })
            .collect();
        assert!(block_steps(cells * banks) < steps / 4, "several blocks");
        let p = IzhikevichParams::default();
        let together = encode_drives(&mut drives, &gains, rows, cols, &present, p).unwrap();
        assert_eq!(together.len(), banks);
        for (b, trains) in together.iter().enumerate() {
            let values: Vec<f64> = match b % 3 {
                0 => signals[b].clone(),
                1 => rectified_rate(&signals[b], cells),
                _ => signals[b].iter().map(|x| x * factors[b]).collect(),
            };
            let alone = encode(&values, rows, cols, &present, p.with_gain(gains[b])).unwrap();
            assert!(alone.total_spikes() > 100, "bank {b} nearly silent");
            assert_eq!(trains, &alone, "bank {b}");
        }
    }
}
