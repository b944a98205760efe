//! The rate volume (paper section II-F): mean spike rate of every taxel in consecutive
//! 200 ms bins, and its quantisation to gray levels.

use serde::{Deserialize, Serialize};

use crate::encode::SpikeTrains;
use crate::error::ParamError;

/// Binning and quantisation parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VolumeParams {
    /// Bin width in ms (the paper's 200).
    pub bin_ms: usize,
    /// Gray levels L (16, the default of the `cooc3d` tool whose other defaults the paper matches).
    pub levels: usize,
    /// A fixed quantisation range `(lo, hi)` in Hz; `None` uses each volume's own min and max.
    pub range: Option<(f64, f64)>,
}

impl Default for VolumeParams {
    fn default() -> Self {
        VolumeParams {
            bin_ms: 200,
            levels: 16,
            range: None,
        }
    }
}

impl VolumeParams {
    /// Checks the rules: bins of at least 1 ms, 2 to 256 gray levels, `lo < hi` finite.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if self.bin_ms == 0 {
            return Err(ParamError::new(
                "bin-ms",
                "bin width must be at least 1 ms",
                self.bin_ms,
            ));
        }
        if !(2..=256).contains(&self.levels) {
            return Err(ParamError::new(
                "levels",
                "gray levels must be between 2 and 256",
                self.levels,
            ));
        }
        if let Some((lo, hi)) = self.range {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(ParamError::new(
                    "range",
                    "quantisation range must satisfy lo < hi",
                    format!("{lo}..{hi}"),
                ));
            }
        }
        Ok(())
    }
}

/// Rates in Hz, `rows x cols x bins`, stored cell-major (each cell's bins contiguous).
#[derive(Debug, Clone, PartialEq)]
pub struct RateVolume {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Time bins.
    pub bins: usize,
    /// Which cells hold a taxel.
    pub present: Vec<bool>,
    /// `rows * cols * bins` rates, index `cell * bins + bin`.
    pub data: Vec<f64>,
}

impl RateVolume {
    /// Bins the trains into `bin_ms` bins; a last bin shorter than `bin_ms` is dropped.
    /// Returns `None` when not one whole bin fits.
    pub fn from_spikes(spikes: &SpikeTrains, bin_ms: usize) -> Option<Self> {
        CountVolume::from_spikes(spikes, bin_ms).map(|c| c.rates())
    }

    /// One bin spanning the whole train (the time-collapsed image of the 2D-GLCM).
    /// Returns `None` for an empty train.
    pub fn collapsed(spikes: &SpikeTrains) -> Option<Self> {
        CountVolume::collapsed(spikes).map(|c| c.rates())
    }
}

/// Spike counts per bin, the rate volume before scaling to Hz. Its quantisation equals the
/// rate volume's exactly and is cheaper: a volume holds few distinct counts, so each
/// count's level is computed once.
#[derive(Debug, Clone, PartialEq)]
pub struct CountVolume {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Time bins.
    pub bins: usize,
    /// Bin width in ms.
    pub bin_ms: usize,
    /// Which cells hold a taxel.
    pub present: Vec<bool>,
    /// `rows * cols * bins` counts, index `cell * bins + bin`.
    pub counts: Vec<u32>,
}

impl CountVolume {
    /// Counts the trains' spikes in `bin_ms` bins; a last bin shorter than `bin_ms` is
    /// dropped. Returns `None` when not one whole bin fits.
    pub fn from_spikes(spikes: &SpikeTrains, bin_ms: usize) -> Option<Self> {
        let bins = spikes.n_steps / bin_ms.max(1);
        (bins > 0).then(|| Self::binned(spikes, bin_ms, bins))
    }

    /// One bin spanning the whole train. Returns `None` for an empty train.
    pub fn collapsed(spikes: &SpikeTrains) -> Option<Self> {
        (spikes.n_steps > 0).then(|| Self::binned(spikes, spikes.n_steps, 1))
    }

    fn binned(spikes: &SpikeTrains, bin_ms: usize, bins: usize) -> Self {
        let cells = spikes.cells();
        let mut counts = vec![0u32; cells * bins];
        // Spike times are u32; a bin wider than any time holds everything in bin 0.
        let divide = FastDivide::new(u32::try_from(bin_ms).unwrap_or(u32::MAX));
        let end = (bins as u64) * (bin_ms as u64);
        for (cell, out) in counts.chunks_exact_mut(bins).enumerate() {
            let train = spikes.train(cell);
            let train = &train[..train.partition_point(|&t| u64::from(t) < end)];
            // Trains are sorted, so the last spike of each bin writes the number of
            // spikes up to and including that bin; stores only, no chain of increments
            // on the same bin.
            let pairs = train.chunks_exact(2);
            let last = pairs.remainder();
            for (k, pair) in pairs.enumerate() {
                // Two spikes per iteration halve the loop's own instructions.
                let k = 2 * k as u32;
                out[divide.quotient(pair[0]) as usize] = k + 1;
                out[divide.quotient(pair[1]) as usize] = k + 2;
            }
            if let [t] = last {
                out[divide.quotient(*t) as usize] = train.len() as u32;
            }
            let mut before = 0;
            for c in out.iter_mut() {
                let upto = (*c).max(before);
                *c = upto - before;
                before = upto;
            }
        }
        CountVolume {
            rows: spikes.rows,
            cols: spikes.cols,
            bins,
            bin_ms,
            present: spikes.present.clone(),
            counts,
        }
    }

    /// The rates in Hz: `count * 1000 / bin_ms`.
    pub fn rates(&self) -> RateVolume {
        RateVolume {
            rows: self.rows,
            cols: self.cols,
            bins: self.bins,
            present: self.present.clone(),
            data: self.counts.iter().map(|&c| self.rate(c)).collect(),
        }
    }

    /// One count's rate in Hz, computed one way for [`CountVolume::rates`] and
    /// [`CountVolume::quantise`] so that their levels agree bit for bit.
    fn rate(&self, count: u32) -> f64 {
        rate_of(count, self.bin_ms)
    }

    /// The levels [`quantise`] gives for [`CountVolume::rates`], bit for bit.
    pub fn quantise(&self, levels: usize, range: Option<(f64, f64)>, out: &mut Vec<u8>) {
        out.clear();
        out.resize(self.counts.len(), 0);
        let (min, max) = count_range(present_rows(&self.counts, self.bins, &self.present));
        if min > max {
            return; // no present cell
        }
        let level = count_levels(self.bin_ms, levels, range, (min, max));
        let rows = present_levels(out, &self.counts, self.bins, &self.present);
        if max - min < 256 {
            // The usual case: a table indexed by a byte needs no bounds checks.
            let mut table = [0u8; 256];
            for (c, t) in (min..=max).zip(table.iter_mut()) {
                *t = level(c);
            }
            for (q, c) in rows {
                for (q, &c) in q.iter_mut().zip(c) {
                    *q = table[usize::from((c - min) as u8)];
                }
            }
        } else {
            let table: Vec<u8> = (min..=max).map(level).collect();
            for (q, c) in rows {
                for (q, &c) in q.iter_mut().zip(c) {
                    *q = table[(c - min) as usize];
                }
            }
        }
    }
}

/// The rate in Hz of `count` spikes in a bin of `bin_ms`.
fn rate_of(count: u32, bin_ms: usize) -> f64 {
    f64::from(count) * (1000.0 / bin_ms as f64)
}

/// The level of each count of a count volume with bins of `bin_ms` whose present voxels
/// span the counts `min..=max`: the levels of [`CountVolume::quantise`] (the range is
/// `range`, or the rates of `min` and `max`), for volumes kept other ways (a stream's
/// sliding window).
pub(crate) fn count_levels(
    bin_ms: usize,
    levels: usize,
    range: Option<(f64, f64)>,
    (min, max): (u32, u32),
) -> impl Fn(u32) -> u8 {
    let (lo, hi) = range.unwrap_or((rate_of(min, bin_ms), rate_of(max, bin_ms)));
    move |c: u32| level_of(rate_of(c, bin_ms), lo, hi, levels)
}

/// The smallest and largest count of `rows`, `(u32::MAX, 0)` for none.
fn count_range<'a>(rows: impl Iterator<Item = &'a [u32]>) -> (u32, u32) {
    #[inline(always)]
    fn fold<'a>(rows: impl Iterator<Item = &'a [u32]>) -> (u32, u32) {
        let (mut min, mut max) = (u32::MAX, 0);
        for row in rows {
            for &c in row {
                min = min.min(c);
                max = max.max(c);
            }
        }
        (min, max)
    }
    #[cfg(target_arch = "x86_64")]
    {
        /// The same fold where unsigned 32-bit min and max are vector instructions
        /// (SSE2, the x86_64 baseline, has none).
        #[target_feature(enable = "avx2")]
        unsafe fn fold_avx2<'a>(rows: impl Iterator<Item = &'a [u32]>) -> (u32, u32) {
            fold(rows)
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { fold_avx2(rows) };
        }
    }
    fold(rows)
}

/// Division of u32 values by a fixed divisor as a multiply and a shift (Lemire, Kaser and
/// Kurz, "Faster remainder by direct computation", 2019): exact for every u32 numerator.
#[derive(Debug, Clone, Copy)]
struct FastDivide {
    /// `ceil(2^64 / d)`, or 0 for `d = 1`.
    multiplier: u64,
}

impl FastDivide {
    fn new(divisor: u32) -> Self {
        let multiplier = if divisor <= 1 {
            0
        } else {
            u64::MAX / u64::from(divisor) + 1
        };
        FastDivide { multiplier }
    }

    fn quotient(self, n: u32) -> u32 {
        if self.multiplier == 0 {
            n
        } else {
            ((u128::from(self.multiplier) * u128::from(n)) >> 64) as u32
        }
    }
}

/// SPEC 3.9's level of one rate: `min(L-1, floor((x - lo) / (hi - lo) * L))`, clamped at
/// 0; 0 when `hi <= lo` (a constant volume).
fn level_of(x: f64, lo: f64, hi: f64, levels: usize) -> u8 {
    if is_constant(lo, hi) {
        0
    } else {
        level_in(x, lo, hi, levels)
    }
}

/// `lo..hi` is empty (or NaN): every rate gets level 0.
fn is_constant(lo: f64, hi: f64) -> bool {
    hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater)
}

/// [`level_of`] for `lo < hi`, without branches so that loops over it vectorise.
#[inline(always)]
fn level_in(x: f64, lo: f64, hi: f64, levels: usize) -> u8 {
    // Exactly the formula's order of operations, so levels at bin edges agree with it;
    // clamped into [0, L-1] first, where truncation equals floor. `max` and `min` return
    // the number when one side is NaN, and L is at most 256 (at least 1 here, whatever
    // the caller passed), so `v` is a number in [0, 255].
    let top = (levels.clamp(1, 256) - 1) as f64;
    let v = ((x - lo) / (hi - lo) * levels as f64).max(0.0).min(top);
    // SAFETY: `v` is a number in [0, 255] (just above). The checked `as` conversion would
    // test for NaN and overflow voxel by voxel, which keeps the loop scalar.
    unsafe { v.to_int_unchecked::<i32>() as u8 }
}

/// Quantises the volume to `levels` gray levels (SPEC 3.9):
/// `min(L-1, floor((x - lo) / (hi - lo) * L))`, with `lo`, `hi` the present cells' own min
/// and max unless `range` fixes them (values outside it are clamped). A constant volume is
/// all level 0. Masked cells get level 0 and are never paired by the GLCM.
pub fn quantise(volume: &RateVolume, levels: usize, range: Option<(f64, f64)>, out: &mut Vec<u8>) {
    let bins = volume.bins;
    let (lo, hi) = range.unwrap_or_else(|| {
        // Four running extremes break the dependency chain of one; comparisons rather
        // than f64::min, whose NaN rule keeps the loop scalar. Rates are finite.
        let (mut lo, mut hi) = ([f64::INFINITY; 4], [f64::NEG_INFINITY; 4]);
        for row in present_rows(&volume.data, bins, &volume.present) {
            let quads = row.chunks_exact(4);
            for &x in quads.remainder() {
                lo[0] = if x < lo[0] { x } else { lo[0] };
                hi[0] = if x > hi[0] { x } else { hi[0] };
            }
            for q in quads {
                for k in 0..4 {
                    lo[k] = if q[k] < lo[k] { q[k] } else { lo[k] };
                    hi[k] = if q[k] > hi[k] { q[k] } else { hi[k] };
                }
            }
        }
        (
            lo.into_iter().fold(f64::INFINITY, f64::min),
            hi.into_iter().fold(f64::NEG_INFINITY, f64::max),
        )
    });
    out.clear();
    out.resize(volume.data.len(), 0);
    if is_constant(lo, hi) {
        return;
    }
    for (q, x) in present_levels(out, &volume.data, bins, &volume.present) {
        for (q, &x) in q.iter_mut().zip(x) {
            *q = level_in(x, lo, hi, levels);
        }
    }
}

/// The `bins`-long rows of the present cells of a cell-major volume.
fn present_rows<'a, T>(
    data: &'a [T],
    bins: usize,
    present: &'a [bool],
) -> impl Iterator<Item = &'a [T]> {
    data.chunks_exact(bins)
        .zip(present)
        .filter(|(_, &p)| p)
        .map(|(row, _)| row)
}

/// The present cells' rows of a volume, each beside its row of `levels` to fill.
fn present_levels<'a, T>(
    levels: &'a mut [u8],
    data: &'a [T],
    bins: usize,
    present: &'a [bool],
) -> impl Iterator<Item = (&'a mut [u8], &'a [T])> {
    levels
        .chunks_exact_mut(bins)
        .zip(data.chunks_exact(bins))
        .zip(present)
        .filter(|(_, &p)| p)
        .map(|(rows, _)| rows)
}

#[cfg(test)]
mod tests {
    use super::FastDivide;

    #[test]
    fn fast_division_is_exact_for_every_u32() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u32
        };
        let divisors = [
            1,
            2,
            3,
            7,
            100,
            200,
            641,
            65_537,
            u32::MAX / 3,
            u32::MAX - 1,
            u32::MAX,
        ];
        let random: Vec<u32> = (0..200).map(|_| next() | 1).collect();
        for d in divisors.into_iter().chain(random) {
            let divide = FastDivide::new(d);
            let edges = [0, 1, d - 1, d, d.saturating_add(1), u32::MAX - 1, u32::MAX];
            let numerators: Vec<u32> = (0..2000).map(|_| next()).collect();
            for n in edges.into_iter().chain(numerators) {
                assert_eq!(divide.quotient(n), n / d, "{n} / {d}");
            }
        }
    }
}
