//! Co-occurrence counting with level masks, for volumes whose cells each take few levels.
//!
//! A rate volume's taxel usually stays within a handful of gray levels over a whole
//! recording (the quantisation range spans all taxels, and one taxel's rate varies far less
//! than the rates of different taxels). For each cell and each level present in it, a mask
//! holds one bit per time bin. A run of pairs `(V[a, t], V[b, t + dt])` then contributes
//! `popcount(mask(a, i) & (mask(b, j) shifted by dt))` to `counts[i][j]`, which costs
//! `levels(a) x levels(b)` word operations per 128 bins instead of one increment per pair.

use super::Run;

/// Bits per mask block.
const BLOCK: usize = 128;

/// A level pair's AND and POPCNT of one 128-bin block, with the add into the count matrix
/// and its share of the shifting, costs about as much as this many histogram increments
/// (`cargo bench --bench glcm`, realistic and random volumes).
const BLOCK_PAIR_COST: usize = 3;

/// The level masks of a quantised volume's cells.
pub(super) struct LevelMasks {
    /// Time bins.
    bins: usize,
    /// 128-bin blocks per mask.
    blocks: usize,
    /// Each cell's slots are `cell_start[cell]..cell_start[cell + 1]`.
    cell_start: Vec<u32>,
    /// The level of each slot, ascending within a cell.
    level: Vec<u8>,
    /// `slots x blocks` masks; bit `t % 128` of block `t / 128` is set when the slot's
    /// level occurs at time bin `t`.
    bits: Vec<u128>,
}

impl LevelMasks {
    /// The levels present in the cells flagged in `used` (other cells get no slots) of a
    /// cell-major quantised volume with `bins` time bins per cell and levels below
    /// `levels`; the masks themselves are left for [`LevelMasks::fill`].
    pub(super) fn new(quantised: &[u8], bins: usize, levels: usize, used: &[bool]) -> Self {
        let mut masks = LevelMasks {
            bins,
            blocks: bins.div_ceil(BLOCK),
            cell_start: Vec::with_capacity(used.len() + 1),
            level: Vec::new(),
            bits: Vec::new(),
        };
        masks.cell_start.push(0);
        for (cell, &is_used) in used.iter().enumerate() {
            if is_used {
                let series = &quantised[cell * bins..(cell + 1) * bins];
                push_present_levels(series, levels, &mut masks.level);
            }
            masks.cell_start.push(masks.level.len() as u32);
        }
        masks
    }

    /// The estimated cost of counting `runs` with masks, in histogram increments.
    pub(super) fn cost(&self, runs: &[Run]) -> usize {
        runs.iter()
            .map(|run| {
                let first = self.slots(run.a as usize).len();
                let second = self.slots(run.b as usize).len();
                (first.saturating_sub(1) * second * self.blocks + second) * BLOCK_PAIR_COST
            })
            .sum()
    }

    /// Builds the masks of every slot.
    pub(super) fn fill(&mut self, quantised: &[u8]) {
        let (bins, blocks) = (self.bins, self.blocks);
        self.bits.clear();
        self.bits.reserve(self.level.len() * blocks);
        let mut chunks: Vec<[u8; 16]> = Vec::with_capacity(blocks * 8);
        for cell in 0..self.cell_start.len() - 1 {
            let slots = self.slots(cell);
            if slots.is_empty() {
                continue;
            }
            let series = &quantised[cell * bins..(cell + 1) * bins];
            // 16 bins at a time; the partial last chunk is zero-padded, and its padding
            // bits are cleared below.
            let tail = series.chunks_exact(16).remainder();
            let mut padded = [0u8; 16];
            padded[..tail.len()].copy_from_slice(tail);
            chunks.clear();
            chunks.extend(
                series
                    .chunks_exact(16)
                    .map(|c| <[u8; 16]>::try_from(c).expect("chunks_exact gives 16 bytes")),
            );
            if !tail.is_empty() {
                chunks.push(padded);
            }
            let cell_bits = self.bits.len();
            for &level in &self.level[slots] {
                for block in chunks.chunks(8) {
                    let mut words = [0u64; 2];
                    for (c, chunk) in block.iter().enumerate() {
                        let m = u64::from(equal_bytes(chunk, level));
                        words[c / 4] |= m << (16 * (c % 4));
                    }
                    self.bits
                        .push(u128::from(words[0]) | (u128::from(words[1]) << 64));
                }
            }
            if !tail.is_empty() {
                // Clear padding bits that matched level 0.
                let last = chunks.len() - 1;
                let tail_valid = u16::MAX >> (16 - tail.len());
                let clear = !(u128::from(!tail_valid) << (16 * (last % 8)));
                for mask in self.bits[cell_bits..].chunks_exact_mut(blocks) {
                    mask[last / 8] &= clear;
                }
            }
        }
    }

    /// Adds the counts of every run to `counts` (`levels x levels`); runs must come
    /// sorted by `dt`, so that each mask is shifted once per time offset, and the masks
    /// must be filled.
    pub(super) fn count_runs(&self, runs: &[Run], levels: usize, counts: &mut [u32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if neurotex_core::has_feature!("popcnt") {
                // SAFETY: the CPU supports POPCNT, checked just above.
                unsafe { self.count_runs_popcnt(runs, levels, counts) };
                return;
            }
        }
        self.count_runs_portable(runs, levels, counts);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "popcnt")]
    unsafe fn count_runs_popcnt(&self, runs: &[Run], levels: usize, counts: &mut [u32]) {
        self.count_runs_portable(runs, levels, counts);
    }

    /// Without a hardware popcount instruction `count_ones` compiles to a few shifts and
    /// adds; the same code, compiled with POPCNT enabled, is the fast path above.
    #[inline(always)]
    fn count_runs_portable(&self, runs: &[Run], levels: usize, counts: &mut [u32]) {
        if levels <= 16 && self.blocks == 1 {
            let mut packed = [0u32; 256];
            self.count_small(runs, &mut packed);
            for i in 0..levels {
                for j in 0..levels {
                    counts[i * levels + j] += packed[(i << 4) | j];
                }
            }
        } else {
            self.each_level_pair(runs, |i, j, n| {
                counts[usize::from(i) * levels + usize::from(j)] += n;
            });
        }
    }

    /// The common case, up to 16 levels and 128 bins: one `u128` per mask, and a level
    /// pair's code `i << 4 | j` indexing `packed` (no bounds checks).
    ///
    /// Each cell's slots partition its time bins, so a run's counts have known row sums
    /// (steps at which the first voxel has level `i`, whatever the second) and column
    /// sums: only the counts of all but the last level of each cell need popcounts, the
    /// last row and column follow by subtraction, and a cell with a single level needs
    /// none at all.
    #[inline(always)]
    fn count_small(&self, runs: &[Run], packed: &mut [u32; 256]) {
        let n_slots = self.level.len();
        let high: Vec<u8> = self.level.iter().map(|&i| i << 4).collect();
        let mut shifted = vec![0u128; n_slots];
        let mut column_sum = vec![0u32; n_slots];
        let mut row_sum = vec![0u32; n_slots];
        for group in runs.chunk_by(|x, y| x.dt == y.dt) {
            let dt = group[0].dt;
            // bins <= 128, so the shift is below 128. The window holds the first voxel's
            // steps at which the second voxel exists too.
            let shift = dt.unsigned_abs() as u32;
            let steps = group[0].first_steps(self.bins);
            let window = range_bits(steps.start, steps.end, 0);
            let per_slot = self
                .bits
                .iter()
                .zip(shifted.iter_mut())
                .zip(column_sum.iter_mut().zip(row_sum.iter_mut()));
            for ((&m, out), (column, row)) in per_slot {
                // One branch per direction per slot; predictable within a group.
                *out = if dt >= 0 { m >> shift } else { m << shift } & window;
                *column = out.count_ones();
                *row = (m & window).count_ones();
            }
            for run in group {
                let first = self.slots(run.a as usize);
                let second = self.slots(run.b as usize);
                let (first_last, second_last) = (first.end - 1, second.end - 1);
                let masks = &self.bits[first.start..first_last];
                let rows = &high[first.start..first_last];
                let last_row = high[first_last];
                // Counted so far in each of the first cell's rows.
                let mut in_row = [0u32; 16];
                for j in second.start..second_last {
                    let (s, column) = (shifted[j], self.level[j]);
                    let mut in_column = 0;
                    for ((&m, &r), acc) in masks.iter().zip(rows).zip(&mut in_row) {
                        let n = (m & s).count_ones();
                        packed[usize::from(r + column)] += n;
                        in_column += n;
                        *acc += n;
                    }
                    packed[usize::from(last_row + column)] += column_sum[j] - in_column;
                }
                let column = self.level[second_last];
                let mut in_column = 0;
                let row_totals = &row_sum[first.start..first_last];
                for ((&r, &total), &acc) in rows.iter().zip(row_totals).zip(&in_row) {
                    let n = total - acc;
                    packed[usize::from(r + column)] += n;
                    in_column += n;
                }
                packed[usize::from(last_row + column)] += column_sum[second_last] - in_column;
            }
        }
    }

    /// Any number of levels and bins: for every run and every pair of a level `i` present
    /// in the run's first cell and a level `j` present in its second, calls
    /// `add(i, j, n)` with `n` the number of time steps at which the first voxel has level
    /// `i` and the second level `j` (possibly 0). The first cell's slots partition its
    /// time bins, so its last slot's count is the rest of the second mask's popcount.
    #[inline(always)]
    fn each_level_pair(&self, runs: &[Run], mut add: impl FnMut(u8, u8, u32)) {
        let blocks = self.blocks;
        let n_slots = self.level.len();
        // Per time offset: each mask shifted to the first voxel's time and cut to the steps
        // at which both voxels exist, and its popcount.
        let mut shifted = vec![0u128; n_slots * blocks];
        let mut total = vec![0u32; n_slots];
        let mut window = vec![0u128; blocks];
        for group in runs.chunk_by(|x, y| x.dt == y.dt) {
            let dt = group[0].dt;
            let steps = group[0].first_steps(self.bins);
            for (k, w) in window.iter_mut().enumerate() {
                *w = range_bits(steps.start, steps.end, k * BLOCK);
            }
            for ((mask, out), t) in self
                .bits
                .chunks_exact(blocks)
                .zip(shifted.chunks_exact_mut(blocks))
                .zip(&mut total)
            {
                shift_blocks(mask, dt, out);
                for (o, w) in out.iter_mut().zip(&window) {
                    *o &= w;
                }
                *t = out.iter().map(|x| x.count_ones()).sum();
            }
            for run in group {
                let first = self.slots(run.a as usize);
                let second = self.slots(run.b as usize);
                let last = first.end - 1;
                let first_masks = &self.bits[first.start * blocks..last * blocks];
                let first_levels = &self.level[first.start..last];
                let last_level = self.level[last];
                let second_masks = shifted[second.start * blocks..second.end * blocks]
                    .chunks_exact(blocks)
                    .zip(&self.level[second.clone()])
                    .zip(&total[second]);
                for ((s, &j), &column_total) in second_masks {
                    let mut counted = 0;
                    for (m, &i) in first_masks.chunks_exact(blocks).zip(first_levels) {
                        let n = m.iter().zip(s).map(|(x, y)| (x & y).count_ones()).sum();
                        add(i, j, n);
                        counted += n;
                    }
                    add(last_level, j, column_total - counted);
                }
            }
        }
    }

    /// The slot indices of `cell`.
    fn slots(&self, cell: usize) -> std::ops::Range<usize> {
        self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize
    }
}

/// Appends the distinct levels of `series` (all below `levels`), ascending.
fn push_present_levels(series: &[u8], levels: usize, out: &mut Vec<u8>) {
    let mut seen = [0u64; 4];
    if levels <= 64 {
        // One register instead of four words in memory: no store-to-load chains.
        let mut low = 0u64;
        for &x in series {
            low |= 1u64 << x;
        }
        seen[0] = low;
    } else {
        for &x in series {
            seen[usize::from(x >> 6)] |= 1u64 << (x & 63);
        }
    }
    for (w, &word) in seen.iter().enumerate() {
        let mut rest = word;
        while rest != 0 {
            out.push((w * 64) as u8 + rest.trailing_zeros() as u8);
            rest &= rest - 1;
        }
    }
}

/// Bit `k` set where `chunk[k] == level`.
#[cfg(target_arch = "x86_64")]
fn equal_bytes(chunk: &[u8; 16], level: u8) -> u16 {
    use std::arch::x86_64::{_mm_cmpeq_epi8, _mm_loadu_si128, _mm_movemask_epi8, _mm_set1_epi8};
    // SAFETY: SSE2 is part of x86_64 itself, so these instructions always exist; the load
    // reads 16 bytes from a 16-byte array (unaligned loads are allowed).
    unsafe {
        let v = _mm_loadu_si128(chunk.as_ptr().cast());
        _mm_movemask_epi8(_mm_cmpeq_epi8(v, _mm_set1_epi8(level as i8))) as u16
    }
}

/// Bit `k` set where `chunk[k] == level`.
#[cfg(not(target_arch = "x86_64"))]
fn equal_bytes(chunk: &[u8; 16], level: u8) -> u16 {
    chunk
        .iter()
        .enumerate()
        .fold(0, |m, (k, &x)| m | (u16::from(x == level) << k))
}

/// Bits `lo..hi` of the 128-bit block starting at bit `start`.
fn range_bits(lo: usize, hi: usize, start: usize) -> u128 {
    let from = lo.clamp(start, start + BLOCK) - start;
    let to = hi.clamp(start, start + BLOCK) - start;
    if from >= to {
        return 0;
    }
    let upto = |n: usize| {
        if n == BLOCK {
            u128::MAX
        } else {
            (1u128 << n) - 1
        }
    };
    upto(to) & !upto(from)
}

/// `out` bit `t` = `mask` bit `t + dt` (0 outside the mask), over multi-block masks.
fn shift_blocks(mask: &[u128], dt: isize, out: &mut [u128]) {
    let shift = dt.unsigned_abs();
    let (skip, bits) = (shift / BLOCK, (shift % BLOCK) as u32);
    let at = |k: Option<usize>| k.and_then(|k| mask.get(k)).copied().unwrap_or(0);
    for (k, o) in out.iter_mut().enumerate() {
        *o = if dt >= 0 {
            let (lo, hi) = (at(Some(k + skip)), at(Some(k + skip + 1)));
            if bits == 0 {
                lo
            } else {
                (lo >> bits) | (hi << (BLOCK as u32 - bits))
            }
        } else {
            let (hi, lo) = (at(k.checked_sub(skip)), at(k.checked_sub(skip + 1)));
            if bits == 0 {
                hi
            } else {
                (hi << bits) | (lo >> (BLOCK as u32 - bits))
            }
        };
    }
}
