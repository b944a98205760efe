//! The rate volume (paper section II-F): mean spike rate of every taxel in consecutive
//! 200 ms bins, and its quantisation to gray levels.

use std::cmp::Ordering;

use serde::{Deserialize, Serialize};

use super::exact::{f64_parts, sign_of_sum};
use crate::error::ParamError;
use crate::spikes::SpikeTrains;

/// Binning and quantisation parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VolumeParams {
    /// Bin width in ms (the paper's 200).
    pub bin_ms: usize,
    /// Gray levels L (16, the default of the `cooc3d` tool whose other defaults the paper matches).
    pub levels: usize,
    /// A fixed quantisation range `(lo, hi)` in Hz; `None` uses each volume's own min and max.
    /// The bounds are taken as the exact binary numbers the two f64 hold (`0.1` is the
    /// double nearest 1/10, a little above it), and a count's rate is compared with them
    /// exactly: a rate on a level boundary lands on that level.
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

/// Spike counts per bin, the rate volume before scaling to Hz. Its quantisation is exact:
/// rates are counts over one bin width, so levels are computed from the counts in integer
/// arithmetic (docs/decisions/0004-sixteen-gray-levels-over-the-volumes-own-range.md),
/// never from rates rounded to f64. It is also cheaper: a volume holds few distinct counts,
/// so each count's level is computed once.
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
            data: self
                .counts
                .iter()
                .map(|&c| rate_of(c, self.bin_ms))
                .collect(),
        }
    }

    /// Quantises the rates to `levels` gray levels as [`quantise`] defines them, computed
    /// exactly from the counts: with the volume's own range, a count `c` of a volume whose
    /// present counts span `min..=max` gets `min(L-1, (c - min) * L / (max - min))` in
    /// integers (all rates share one bin width, so it cancels). With a fixed range see
    /// [`VolumeParams::range`]. The levels of [`quantise`] on [`CountVolume::rates`] may be
    /// one lower where a rate sits on a boundary and f64 rounding puts it just below.
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
/// sliding window). Exact, in integer arithmetic.
pub fn count_levels(
    bin_ms: usize,
    levels: usize,
    range: Option<(f64, f64)>,
    (min, max): (u32, u32),
) -> impl Fn(u32) -> u8 {
    let rule = CountLevels::new(bin_ms, levels, range, (min, max));
    move |c: u32| rule.level(c)
}

/// Counts are u32: every count is below this.
const COUNTS_END: u64 = 1 << 32;

/// How counts become levels, exactly.
enum CountLevels {
    /// All level 0: a constant volume, or a range that is not finite with `lo < hi`.
    Constant,
    /// The volume's own range: `min(L-1, (c - min) * L / span)`.
    Own { min: u32, span: u64, levels: u64 },
    /// A fixed range: `first[k - 1]` is the smallest count of level `k` or more
    /// ([`COUNTS_END`] where no count reaches it); nondecreasing in `k`.
    Fixed { first: Vec<u64> },
}

impl CountLevels {
    fn new(
        bin_ms: usize,
        levels: usize,
        range: Option<(f64, f64)>,
        (min, max): (u32, u32),
    ) -> Self {
        let levels = levels.clamp(1, 256) as u64;
        match range {
            None if min < max => CountLevels::Own {
                min,
                span: u64::from(max - min),
                levels,
            },
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo < hi => CountLevels::Fixed {
                first: (1..levels)
                    .map(|k| first_count_of_level(k, levels, bin_ms as u64, (lo, hi)))
                    .collect(),
            },
            _ => CountLevels::Constant,
        }
    }

    fn level(&self, c: u32) -> u8 {
        match self {
            CountLevels::Constant => 0,
            CountLevels::Own { min, span, levels } => {
                // Below 2^32 * 256: no overflow. Counts below `min` (none in the volume) clamp at 0.
                let level = u64::from(c.saturating_sub(*min)) * levels / span;
                level.min(levels - 1) as u8
            }
            CountLevels::Fixed { first } => first.partition_point(|&f| f <= u64::from(c)) as u8,
        }
    }
}

/// The smallest count (below [`COUNTS_END`], or it) whose rate with bins of `bin_ms` has
/// level `k` or more over the fixed range `lo < hi` (finite): the smallest `c` with
/// `(c * 1000 / bin_ms - lo) * L >= k * (hi - lo)`, that is
/// `1000 * L * c >= bin_ms * ((L - k) * lo + k * hi)`, decided exactly.
fn first_count_of_level(k: u64, levels: u64, bin_ms: u64, (lo, hi): (f64, f64)) -> u64 {
    let ((m_lo, e_lo), (m_hi, e_hi)) = (f64_parts(lo), f64_parts(hi));
    let bin = i128::from(bin_ms);
    // Each product stays below 2^64 * 2^8 * 2^53 = 2^125.
    let reaches = |c: u64| {
        sign_of_sum(&[
            (i128::from(c) * 1000 * i128::from(levels), 0),
            (-(bin * i128::from(levels - k)) * i128::from(m_lo), e_lo),
            (-(bin * i128::from(k)) * i128::from(m_hi), e_hi),
        ]) != Ordering::Less
    };
    // The float estimate is the answer or next to it unless the range is extreme; the
    // search from it is exact either way.
    let boundary = lo + k as f64 * ((hi - lo) / levels as f64);
    let guess = (boundary * bin_ms as f64 / 1000.0).ceil();
    let guess = if guess >= 0.0 {
        guess.min(COUNTS_END as f64) as u64
    } else {
        0 // negative, or NaN from an overflowing range
    };
    first_reaching(guess, COUNTS_END, reaches)
}

/// The smallest `c` in `0..end` with `reaches(c)`, or `end` for none, for a `reaches`
/// false then true as `c` grows: a galloping search from `guess`, then bisection.
fn first_reaching(guess: u64, end: u64, reaches: impl Fn(u64) -> bool) -> u64 {
    let reaches = |c: u64| c >= end || reaches(c);
    let guess = guess.min(end);
    // `below` is a count known not to reach (None: none below), `yes` one known to.
    let (mut below, mut yes);
    let mut step = 1u64;
    if reaches(guess) {
        yes = guess;
        below = None;
        while yes > 0 {
            let probe = yes.saturating_sub(step);
            if reaches(probe) {
                yes = probe;
                step = step.saturating_mul(2);
            } else {
                below = Some(probe);
                break;
            }
        }
    } else {
        below = Some(guess);
        loop {
            let probe = guess.saturating_add(step).min(end);
            if reaches(probe) {
                yes = probe;
                break;
            }
            below = Some(probe);
            step = step.saturating_mul(2);
        }
    }
    match below {
        Some(no) => bisect(no, yes, reaches).1,
        None => yes,
    }
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
        if neurotex_core::has_feature!("avx2") {
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

/// `lo..hi` is empty (or NaN): every rate gets level 0.
fn is_constant(lo: f64, hi: f64) -> bool {
    hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater)
}

/// How close to a level boundary an f64 `v = (x - lo) / (hi - lo) * L` must lie, relative
/// to `v`, to be checked exactly: its four operations round once each from exact inputs,
/// so it is within about 4 * 2^-53 |v| of the real value; 2^-48 leaves a wide margin.
const NEAR_BOUNDARY: f64 = 1.0 / (1u64 << 48) as f64;

/// The quantisation's level of a rate for `lo < hi` in f64, and whether the real level may
/// differ (the f64 value lies within [`NEAR_BOUNDARY`] of a boundary `1..L-1`; elsewhere
/// its floor is the real one). Without branches so that loops over it vectorise.
#[inline(always)]
fn level_in(x: f64, lo: f64, hi: f64, levels: usize) -> (u8, bool) {
    // Clamped into [0, L-1] first, where truncation equals floor. `max` and `min` return
    // the number when one side is NaN, and L is at most 256 (at least 1 here, whatever
    // the caller passed), so `clamped` is a number in [0, 255].
    let top = (levels.clamp(1, 256) - 1) as f64;
    let v = (x - lo) / (hi - lo) * levels as f64;
    let clamped = v.max(0.0).min(top);
    // SAFETY: `clamped` is a number in [0, 255] (just above). The checked `as` conversion
    // would test for NaN and overflow voxel by voxel, which keeps the loop scalar.
    let level = unsafe { clamped.to_int_unchecked::<i32>() };
    let (floor, margin) = (f64::from(level), v * NEAR_BOUNDARY);
    // A NaN `v` fails every comparison: not near.
    let near = ((floor >= 1.0) & (v - floor <= margin))
        | ((floor + 1.0 <= top) & (floor + 1.0 - v <= margin));
    (level as u8, near)
}

/// Exact levels of f64 rates over `lo < hi` (both finite): the level of `x` is the number
/// of boundaries `k` in `1..L` with `(x - lo) * L >= k * (hi - lo)`, that is
/// `L * x - (L - k) * lo - k * hi >= 0`, each decided exactly.
struct ExactRateLevels {
    lo: (i64, i32),
    hi: (i64, i32),
    levels: u64,
}

impl ExactRateLevels {
    fn new(lo: f64, hi: f64, levels: usize) -> Option<Self> {
        (lo.is_finite() && hi.is_finite()).then(|| ExactRateLevels {
            lo: f64_parts(lo),
            hi: f64_parts(hi),
            levels: levels.clamp(1, 256) as u64,
        })
    }

    /// Whether `x` (finite) reaches boundary `k`: `L * x - (L - k) * lo - k * hi >= 0`.
    fn reaches(&self, x: f64, k: u64) -> bool {
        let (m_x, e_x) = f64_parts(x);
        let (l, k) = (i128::from(self.levels), i128::from(k));
        // Products below 2^8 * 2^53.
        sign_of_sum(&[
            (l * i128::from(m_x), e_x),
            (-(l - k) * i128::from(self.lo.0), self.lo.1),
            (-k * i128::from(self.hi.0), self.hi.1),
        ]) != Ordering::Less
    }

    /// The level of `x` whose f64 value `v` of the formula lies next to boundary `k`
    /// (within [`NEAR_BOUNDARY`]): the real value lies within `(k - 1, k + 1)`, so the
    /// level is `k` or `k - 1`. `None` for a rate that is not finite.
    fn level_next_to(&self, x: f64, v: f64) -> Option<u8> {
        if !x.is_finite() {
            return None;
        }
        let k = v.round().clamp(1.0, (self.levels - 1) as f64) as u64;
        Some(if self.reaches(x, k) { k } else { k - 1 } as u8)
    }

    /// The level of `x`, `None` for a rate that is not finite.
    fn level(&self, x: f64) -> Option<u8> {
        if !x.is_finite() {
            return None;
        }
        let reaches = |k: u64| self.reaches(x, k);
        // Boundaries reached are a prefix of 1..L: bisect for its length.
        Some(bisect(0, self.levels, |k| !reaches(k)).0 as u8)
    }
}

/// Quantises the volume to `levels` gray levels:
/// `min(L-1, floor((x - lo) / (hi - lo) * L))`, with `lo`, `hi` the present cells' own min
/// and max unless `range` fixes them (values outside it are clamped). A constant volume is
/// all level 0. Masked cells get level 0 and are never paired by the GLCM. Why the volume's
/// own range: docs/decisions/0004-sixteen-gray-levels-over-the-volumes-own-range.md.
///
/// The formula is evaluated exactly for the f64 values given: a rate on a boundary lands
/// on it. Rates that came from spike counts were rounded when divided by the bin width,
/// so a count on a boundary may sit just below it here: quantise a [`CountVolume`]
/// instead, which works from the counts.
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
    let exact = ExactRateLevels::new(lo, hi, levels);
    // An overflowing `hi - lo` voids the f64 error bound: every rate is decided exactly.
    let every = !(hi - lo).is_finite();
    for (q, x) in present_levels(out, &volume.data, bins, &volume.present) {
        let mut near = false;
        for (q, &x) in q.iter_mut().zip(x) {
            let (level, close) = level_in(x, lo, hi, levels);
            *q = level;
            near |= close;
        }
        // Rare: a rate within a few rounding errors of a boundary.
        if let Some(exact) = exact.as_ref().filter(|_| near || every) {
            for (q, &x) in q.iter_mut().zip(x) {
                if every {
                    *q = exact.level(x).unwrap_or(*q);
                } else if level_in(x, lo, hi, levels).1 {
                    let v = (x - lo) / (hi - lo) * levels as f64;
                    *q = exact.level_next_to(x, v).unwrap_or(*q);
                }
            }
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

/// Narrows `(low, high)`, where `high_side(high)` holds and `high_side(low)` does not (nor
/// is asked), to two neighbours with the same property, `high_side` being monotone between.
fn bisect(mut low: u64, mut high: u64, high_side: impl Fn(u64) -> bool) -> (u64, u64) {
    while high - low > 1 {
        let mid = low + (high - low) / 2;
        if high_side(mid) {
            high = mid;
        } else {
            low = mid;
        }
    }
    (low, high)
}

#[cfg(test)]
mod tests {
    use super::{count_levels, CountVolume, FastDivide};
    use crate::spikes::SpikeTrains;
    use proptest::prelude::*;

    /// A fraction `num / den`, `den > 0`, for levels straight from the quantisation's
    /// formula.
    #[derive(Debug, Clone, Copy)]
    struct Frac(i128, i128);

    impl Frac {
        fn sub(self, o: Frac) -> Frac {
            Frac(self.0 * o.1 - o.0 * self.1, self.1 * o.1)
        }
        fn div(self, o: Frac) -> Frac {
            let (num, den) = (self.0 * o.1, self.1 * o.0);
            if den < 0 {
                Frac(-num, -den)
            } else {
                Frac(num, den)
            }
        }
        fn floor(self) -> i128 {
            self.0.div_euclid(self.1)
        }
    }

    /// `min(L-1, floor((x - lo) / (hi - lo) * L))` clamped at 0, in fractions; 0 for
    /// `hi <= lo`.
    fn level_by_definition(x: Frac, lo: Frac, hi: Frac, levels: usize) -> u8 {
        let span = hi.sub(lo);
        if span.0 <= 0 {
            return 0;
        }
        let v = x.sub(lo).div(span);
        Frac(v.0 * levels as i128, v.1)
            .floor()
            .clamp(0, levels as i128 - 1) as u8
    }

    fn rate(count: u32, bin_ms: usize) -> Frac {
        Frac(i128::from(count) * 1000, bin_ms as i128)
    }

    #[test]
    fn counts_on_a_level_boundary_take_that_level() {
        // 28 lies halfway between 27 and 29: level 8 of 16. Over 201 ms the f64 rates put
        // it at 7.99999999999998 (level 7).
        let level = count_levels(201, 16, None, (27, 29));
        assert_eq!([27, 28, 29].map(&level), [0, 8, 15]);
        // The same counts as the 2D-GLCM's image: one bin spanning a 201 ms train.
        let lists: Vec<Vec<u32>> = [27, 28, 29].map(|n| (0..n).collect()).to_vec();
        let trains = SpikeTrains::from_lists(&lists, 1, 3, &[true; 3], 201);
        let image = CountVolume::collapsed(&trains).unwrap();
        let mut q = Vec::new();
        image.quantise(16, None, &mut q);
        assert_eq!(q, [0, 8, 15]);
        // And as a 3D volume of 201 ms bins.
        let volume = CountVolume::from_spikes(&trains, 201).unwrap();
        volume.quantise(16, None, &mut q);
        assert_eq!(q, [0, 8, 15]);
    }

    #[test]
    fn a_fixed_range_puts_rates_on_its_boundaries_exactly() {
        // 300 ms bins: a count of 3k is 10k Hz, boundary k of 0..160 Hz in 16 levels.
        let level = count_levels(300, 16, Some((0.0, 160.0)), (0, 60));
        for c in 0..=60 {
            assert_eq!(level(c), (c / 3).min(15) as u8, "count {c}");
        }
        // Bounds that are not whole: 1000 / 125 = 8 Hz per spike, 2.5 Hz per level.
        let level = count_levels(125, 16, Some((-2.5, 37.5)), (0, 10));
        for c in 0..=10 {
            let expected = level_by_definition(rate(c, 125), Frac(-5, 2), Frac(75, 2), 16);
            assert_eq!(level(c), expected, "count {c}");
        }
        assert_eq!(count_levels(125, 16, Some((-2.5, 37.5)), (0, 10))(2), 7);
    }

    #[test]
    fn extreme_and_broken_ranges_give_levels_without_panicking() {
        let huge = count_levels(7, 16, Some((-f64::MAX, f64::MAX)), (0, 7));
        // Level 8's boundary is 0 Hz: every count reaches it, none the next (1e307 Hz).
        assert!((0..=7).all(|c| huge(c) == 8));
        let tiny = count_levels(7, 16, Some((0.0, f64::MIN_POSITIVE / 16.0)), (0, 7));
        assert_eq!((tiny(0), tiny(1), tiny(u32::MAX)), (0, 15, 15));
        for range in [
            (1.0, 1.0),
            (2.0, 1.0),
            (f64::NAN, 1.0),
            (0.0, f64::INFINITY),
        ] {
            assert_eq!(count_levels(7, 16, Some(range), (0, 7))(5), 0, "{range:?}");
        }
        assert_eq!(count_levels(1, 16, None, (4, 4))(4), 0);
        let wide = count_levels(usize::MAX, 256, Some((-1e-300, 1e300)), (0, u32::MAX));
        assert_eq!((wide(0), wide(u32::MAX)), (0, 0));
    }

    proptest! {
        /// The levels of counts as a stream's window and every count volume take them,
        /// against the formula in fractions, over counts placed on level boundaries (the
        /// span a multiple of L) and anywhere.
        #[test]
        fn count_levels_match_the_formula_in_fractions(
            bin_ms in prop_oneof![1usize..=254, Just(201), Just(300), 255usize..40_000],
            levels in 2usize..=64,
            min in 0u32..1000,
            step in 1u32..5,
            on_boundaries in any::<bool>(),
            fixed in proptest::option::of((-400i32..400, 1i32..4000)),
            spread in 1u32..3000,
            picks in proptest::collection::vec(any::<u32>(), 1..60),
        ) {
            // Own range: the span a multiple of L puts counts min + k * step on boundary k.
            let span = if on_boundaries { step * levels as u32 } else { spread };
            let max = min + span;
            let counts: Vec<u32> = picks.iter().map(|&p| min + p % (span + 1)).collect();
            let level = count_levels(bin_ms, levels, None, (min, max));
            for &c in &counts {
                let expected = level_by_definition(rate(c, bin_ms), rate(min, bin_ms), rate(max, bin_ms), levels);
                prop_assert_eq!(level(c), expected, "count {}", c);
            }
            // A fixed range in eighths of a Hz, counts inside and outside it.
            if let Some((lo8, width8)) = fixed {
                let (lo, hi) = (f64::from(lo8) / 8.0, f64::from(lo8 + width8) / 8.0);
                let level = count_levels(bin_ms, levels, Some((lo, hi)), (min, max));
                for &p in &picks {
                    let c = p % (max + 1);
                    let expected = level_by_definition(rate(c, bin_ms), Frac(lo8.into(), 8), Frac((lo8 + width8).into(), 8), levels);
                    prop_assert_eq!(level(c), expected, "count {}", c);
                }
            }
            // A fixed range whose boundaries k are the rates of the counts
            // bin_ms * (a + k * step): lo = 1000 a Hz, a step of 1000 * step Hz per level.
            let a = i32::try_from(min % 20).unwrap() - 10;
            let (lo, hi) = (1000.0 * f64::from(a), 1000.0 * f64::from(a + (step * levels as u32) as i32));
            let level = count_levels(bin_ms, levels, Some((lo, hi)), (0, 0));
            for &p in &picks {
                let k = i64::from(p % (levels as u32 + 2));
                let on = bin_ms as i64 * (i64::from(a) + k * i64::from(step)) + i64::from(p % 3) - 1;
                let Ok(c) = u32::try_from(on) else { continue };
                let expected = level_by_definition(rate(c, bin_ms), Frac(i128::from(a) * 1000, 1), Frac(hi as i128, 1), levels);
                prop_assert_eq!(level(c), expected, "count {}", c);
            }
        }
    }

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
