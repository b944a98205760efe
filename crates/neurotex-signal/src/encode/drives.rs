//! Encoding whole signals: one bank or several over one recording, and banks fed by drives
//! that make their input a block of steps at a time.

use neurotex_core::spikes::SpikeTrains;

use crate::error::ParamError;

use super::{Encoder, IzhikevichParams};

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
pub(super) fn block_steps(width: usize) -> usize {
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
