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

    /// Checks the rules: finite values, `a > 0`, reset below the 30 mV peak, gain > 0.
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
        if !(self.a.is_finite() && self.a > 0.0) {
            return Err(ParamError::new(
                "a",
                "recovery scale a must be positive",
                self.a,
            ));
        }
        if !self.b.is_finite() || !self.d.is_finite() {
            return Err(ParamError::new(
                "b, d",
                "b and d must be finite",
                format!("{}, {}", self.b, self.d),
            ));
        }
        if !(self.c.is_finite() && self.c < V_PEAK) {
            return Err(ParamError::new(
                "c",
                "reset potential c must be below the 30 mV peak",
                self.c,
            ));
        }
        Ok(())
    }
}

/// A bank of Izhikevich neurons whose state carries over between calls.
#[derive(Debug, Clone)]
pub struct Encoder {
    params: IzhikevichParams,
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
        params.check()?;
        Ok(Encoder {
            params,
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
        assert!(n > 0 && input.len() % n == 0, "input must be whole frames");
        assert_eq!(input.len(), raster.len(), "raster must match input");
        run_fastest(self.params, &mut self.v, &mut self.u, input, raster);
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
        let (v, u) = (&mut self.v[cells.clone()], &mut self.u[cells]);
        run_fastest(self.params, v, u, input, raster);
    }
}

/// [`run_blocks`] with AVX2 where the processor has it.
fn run_fastest(
    p: IzhikevichParams,
    v: &mut [f64],
    u: &mut [f64],
    input: &[f64],
    raster: &mut [u8],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, the only feature the function enables.
            unsafe { run_avx2(p, v, u, input, raster) };
            return;
        }
    }
    run_blocks(p, v, u, input, raster);
}

/// Neurons per block whose state stays in registers across time steps: enough independent
/// dependency chains to hide the latency of the update (about 20 dependent operations).
const BLOCK: usize = 16;

/// [`run_blocks`] compiled with AVX2 (4 f64 lanes). FMA is not enabled, and Rust never
/// fuses a multiply and an add on its own, so results are bit-identical to the portable path.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2(
    p: IzhikevichParams,
    v: &mut [f64],
    u: &mut [f64],
    input: &[f64],
    raster: &mut [u8],
) {
    run_blocks(p, v, u, input, raster);
}

/// Runs the neurons a block of [`BLOCK`] at a time (time inner), then any remainder.
#[inline(always)]
fn run_blocks(p: IzhikevichParams, v: &mut [f64], u: &mut [f64], input: &[f64], raster: &mut [u8]) {
    let n = v.len();
    let full = n / BLOCK * BLOCK;
    for start in (0..full).step_by(BLOCK) {
        let mut vb = [0.0; BLOCK];
        let mut ub = [0.0; BLOCK];
        vb.copy_from_slice(&v[start..start + BLOCK]);
        ub.copy_from_slice(&u[start..start + BLOCK]);
        for (frame, out) in input.chunks_exact(n).zip(raster.chunks_exact_mut(n)) {
            let x: &[f64; BLOCK] = frame[start..start + BLOCK].try_into().expect("block");
            let o: &mut [u8; BLOCK] = (&mut out[start..start + BLOCK]).try_into().expect("block");
            step(&p, &mut vb, &mut ub, x, o);
        }
        v[start..start + BLOCK].copy_from_slice(&vb);
        u[start..start + BLOCK].copy_from_slice(&ub);
    }
    if full < n {
        for (frame, out) in input.chunks_exact(n).zip(raster.chunks_exact_mut(n)) {
            step(
                &p,
                &mut v[full..],
                &mut u[full..],
                &frame[full..],
                &mut out[full..],
            );
        }
    }
}

/// One 1 ms step of the reference scheme for a group of neurons. Branch-free per neuron so
/// it vectorises; the order of every floating-point operation is that of the reference.
#[inline(always)]
fn step(p: &IzhikevichParams, v: &mut [f64], u: &mut [f64], x: &[f64], out: &mut [u8]) {
    let IzhikevichParams { a, b, c, d, gain } = *p;
    for (((vi, ui), &x), o) in v.iter_mut().zip(u.iter_mut()).zip(x).zip(out.iter_mut()) {
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

/// Spike trains of a grid of neurons: per cell, the sorted step indices (ms) of its spikes,
/// stored compactly as one index array with offsets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpikeTrains {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Which cells hold a taxel.
    pub present: Vec<bool>,
    /// Number of 1 ms steps encoded.
    pub n_steps: usize,
    offsets: Vec<u32>,
    times: Vec<u32>,
}

impl SpikeTrains {
    /// Collects trains from a `n_steps x cells` raster (1 = spike).
    ///
    /// # Panics
    /// If the raster is not whole frames of `present.len()` cells (a caller bug).
    pub fn from_raster(raster: &[u8], rows: usize, cols: usize, present: &[bool]) -> Self {
        let cells = rows * cols;
        assert_eq!(present.len(), cells);
        assert!(cells > 0 && raster.len() % cells == 0);
        let n_steps = raster.len() / cells;
        let mut counts = vec![0u32; cells + 1];
        for frame in raster.chunks_exact(cells) {
            for (c, &s) in counts[1..].iter_mut().zip(frame) {
                *c += u32::from(s);
            }
        }
        for (cell, &p) in present.iter().enumerate() {
            if !p {
                counts[cell + 1] = 0;
            }
        }
        let mut offsets = counts;
        for i in 1..offsets.len() {
            offsets[i] += offsets[i - 1];
        }
        let mut fill = offsets.clone();
        let mut times = vec![0u32; offsets[cells] as usize];
        for (t, frame) in raster.chunks_exact(cells).enumerate() {
            for (cell, &s) in frame.iter().enumerate() {
                if s != 0 && present[cell] {
                    times[fill[cell] as usize] = t as u32;
                    fill[cell] += 1;
                }
            }
        }
        SpikeTrains {
            rows,
            cols,
            present: present.to_vec(),
            n_steps,
            offsets,
            times,
        }
    }

    /// Builds trains from per-cell spike time lists.
    ///
    /// # Panics
    /// If there is not one list per cell, or a list is unsorted or reaches `n_steps`.
    pub fn from_lists(
        lists: &[Vec<u32>],
        rows: usize,
        cols: usize,
        present: &[bool],
        n_steps: usize,
    ) -> Self {
        assert_eq!(lists.len(), rows * cols);
        let mut offsets = vec![0u32];
        let mut times = Vec::new();
        for l in lists {
            assert!(l.windows(2).all(|w| w[0] < w[1]) && l.iter().all(|&t| (t as usize) < n_steps));
            times.extend_from_slice(l);
            offsets.push(times.len() as u32);
        }
        SpikeTrains {
            rows,
            cols,
            present: present.to_vec(),
            n_steps,
            offsets,
            times,
        }
    }

    /// Builds trains from their compact form: `offsets[c]..offsets[c + 1]` indexes cell
    /// `c`'s spike times in `times` (what a stream assembles for its window without a list
    /// per cell).
    ///
    /// # Panics
    /// If there is not one offset per cell plus one, offsets decrease or pass the end of
    /// `times`, or a train is unsorted or reaches `n_steps` (caller bugs).
    pub fn from_parts(
        rows: usize,
        cols: usize,
        present: &[bool],
        n_steps: usize,
        offsets: Vec<u32>,
        times: Vec<u32>,
    ) -> Self {
        assert_eq!(offsets.len(), rows * cols + 1);
        assert!(offsets.windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(offsets[rows * cols] as usize, times.len());
        let trains = SpikeTrains {
            rows,
            cols,
            present: present.to_vec(),
            n_steps,
            offsets,
            times,
        };
        for c in 0..trains.cells() {
            let t = trains.train(c);
            assert!(t.windows(2).all(|w| w[0] < w[1]) && t.iter().all(|&x| (x as usize) < n_steps));
        }
        trains
    }

    /// The grid the trains were encoded on.
    pub fn grid(&self) -> crate::values::Grid {
        crate::values::Grid::from_parts(self.rows, self.cols, &self.present)
    }

    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.rows * self.cols
    }

    /// The spike times (ms) of cell `cell` (row-major index).
    pub fn train(&self, cell: usize) -> &[u32] {
        &self.times[self.offsets[cell] as usize..self.offsets[cell + 1] as usize]
    }

    /// Total spikes over all cells.
    pub fn total_spikes(&self) -> usize {
        self.times.len()
    }

    /// The first `n_steps` steps only (for time-to-recognition).
    pub fn truncated(&self, n_steps: usize) -> SpikeTrains {
        let lists: Vec<Vec<u32>> = (0..self.cells())
            .map(|c| {
                self.train(c)
                    .iter()
                    .copied()
                    .filter(|&t| (t as usize) < n_steps)
                    .collect()
            })
            .collect();
        SpikeTrains::from_lists(
            &lists,
            self.rows,
            self.cols,
            &self.present,
            n_steps.min(self.n_steps),
        )
    }

    /// The steps `[start, end)` only, as trains of their own (step `start` becomes step 0):
    /// the window a causal classifier looks at.
    ///
    /// # Panics
    /// If `start > end` or `end > n_steps` (a caller bug).
    pub fn window(&self, start: usize, end: usize) -> SpikeTrains {
        assert!(
            start <= end && end <= self.n_steps,
            "a window inside the trains"
        );
        let lists: Vec<Vec<u32>> = (0..self.cells())
            .map(|c| {
                let train = self.train(c);
                let lo = train.partition_point(|&t| (t as usize) < start);
                let hi = train.partition_point(|&t| (t as usize) < end);
                train[lo..hi].iter().map(|&t| t - start as u32).collect()
            })
            .collect();
        SpikeTrains::from_lists(&lists, self.rows, self.cols, &self.present, end - start)
    }

    /// The trains with cells moved: cell `i`'s train goes to cell `perm[i]`.
    ///
    /// # Panics
    /// If `perm` is not a permutation of the cells.
    pub fn permuted(&self, perm: &[usize]) -> SpikeTrains {
        assert_eq!(perm.len(), self.cells());
        let mut lists = vec![Vec::new(); self.cells()];
        let mut present = vec![false; self.cells()];
        for (from, &to) in perm.iter().enumerate() {
            lists[to] = self.train(from).to_vec();
            present[to] = self.present[from];
        }
        SpikeTrains::from_lists(&lists, self.rows, self.cols, &present, self.n_steps)
    }

    /// The raster `n_steps x cells` (1 = spike), for writing `.npy` output.
    pub fn to_raster(&self) -> Vec<u8> {
        let cells = self.cells();
        let mut out = vec![0u8; self.n_steps * cells];
        for cell in 0..cells {
            for &t in self.train(cell) {
                out[t as usize * cells + cell] = 1;
            }
        }
        out
    }

    /// Address events `(t_ms, row, col)` sorted by time, then row, then column.
    pub fn events(&self) -> Vec<(u32, usize, usize)> {
        let mut ev: Vec<(u32, usize, usize)> = (0..self.cells())
            .flat_map(|cell| {
                self.train(cell)
                    .iter()
                    .map(move |&t| (t, cell / self.cols, cell % self.cols))
            })
            .collect();
        ev.sort_unstable();
        ev
    }
}

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
    const BLOCK_STEPS: usize = 1024;
    let cells = rows * cols;
    let mut encoder = Encoder::new(params, cells)?;
    let mut raster = vec![0u8; BLOCK_STEPS * cells];
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); cells];
    for (k, block) in samples.chunks(BLOCK_STEPS * cells).enumerate() {
        let raster = &mut raster[..block.len()];
        encoder.run(block, raster);
        let t0 = k * BLOCK_STEPS;
        // Spikes are sparse: test eight entries at a time as one word.
        let mut collect = |i: usize| {
            let cell = i % cells;
            if present[cell] {
                lists[cell].push((t0 + i / cells) as u32);
            }
        };
        let words = raster.chunks_exact(8);
        let tail = words.remainder();
        for (w, word) in words.enumerate() {
            if u64::from_ne_bytes(word.try_into().expect("8 bytes")) != 0 {
                (0..8)
                    .filter(|&j| word[j] != 0)
                    .for_each(|j| collect(w * 8 + j));
            }
        }
        let base = raster.len() - tail.len();
        (0..tail.len())
            .filter(|&j| tail[j] != 0)
            .for_each(|j| collect(base + j));
    }
    Ok(SpikeTrains::from_lists(
        &lists,
        rows,
        cols,
        present,
        samples.len() / cells.max(1),
    ))
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
    assert!(cells > 0 && samples.len() % cells == 0, "whole frames");
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
    let drive = rectified_rate(samples, (rows * cols).max(1));
    encode(&drive, rows, cols, present, neuron.with_gain(fa.gain))
}
