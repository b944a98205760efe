//! Co-occurrence counting by sums of one-hot rows (x86_64 with AVX2, up to 16 levels).
//!
//! Each voxel's level becomes a 16-byte one-hot row (0xFF at its level, 0 elsewhere). For a
//! voxel `v` of cell `a`, subtracting the rows of its partners over all of `a`'s runs
//! gives `H(v)[j]`, the number of partners with level `j`; a run's partners of consecutive
//! time steps are consecutive rows, so one 32-byte subtraction covers two steps of a run.
//! Then `counts[level(v)] += H(v)` adds one row per voxel. The cost is about one byte-vector
//! operation per two pairs, whatever the levels, where a histogram pays one increment
//! per pair.
//!
//! Rows outside the volume are zero, so pairs leaving it add nothing; 16 steps of one cell
//! are summed in eight registers before they are added to the counts.

use super::Run;

/// Time steps summed per block: eight 32-byte registers of two rows each.
const STEPS: usize = 16;

/// Per-step partner counts are bytes: at most this many runs of one cell are summed at once.
const MAX_RUNS: usize = 255;

/// Whether [`count`] runs on this machine for `levels` gray levels.
pub(super) fn available(levels: usize) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        levels <= 16 && neurotex_core::has_feature!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = levels;
        false
    }
}

/// Adds the counts of `runs` to `counts` (`levels x levels`) over a cell-major quantised
/// volume of `cells x bins` with levels below `levels`. Runs of one first cell must be
/// adjacent; runs without pairs (`|dt| >= bins`) are skipped.
///
/// # Panics
/// If [`available`] is false for `levels`, or a run's cell is not below `cells`.
pub(super) fn count(
    quantised: &[u8],
    bins: usize,
    cells: usize,
    runs: &[Run],
    levels: usize,
    counts: &mut [u32],
) {
    assert!(
        available(levels),
        "one-hot counting needs AVX2 and <= 16 levels"
    );
    assert_eq!(quantised.len(), cells * bins);
    assert_eq!(counts.len(), levels * levels);
    assert!(runs
        .iter()
        .all(|r| (r.a as usize) < cells && (r.b as usize) < cells));
    let runs: Vec<Run> = runs.iter().filter(|r| r.len(bins) > 0).copied().collect();
    #[cfg(target_arch = "x86_64")]
    // SAFETY: AVX2 is present (`available`), and the checks above (cells in the volume,
    // every run with pairs) are what `count_avx2` relies on for its memory accesses.
    unsafe {
        count_avx2(quantised, bins, cells, &runs, levels, counts);
    }
}

/// Per-copy counts of the first 16 levels plus row 16, which takes the steps past the
/// volume's end in a last partial block.
type Rows = [[u16; 16]; 17];

/// Interleaved copies of the row counts: consecutive steps add to different copies, so
/// that a step need not wait for the previous step's store to the same row.
const COPIES: usize = 4;

/// [`count`] with AVX2, once its checks have passed. Kept in one piece although long:
/// split into `#[inline]` AVX2 helpers (one-hot rows, padded levels, offsets, groups,
/// partner sums, row adds, flush), every helper inlined and the same instructions run
/// (callgrind), `cargo bench --bench glcm` still timed `count_OneHot` 2 to 7 % slower
/// (medians of alternating runs), likely from the moved stack layout.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn count_avx2(
    quantised: &[u8],
    bins: usize,
    cells: usize,
    runs: &[Run],
    levels: usize,
    counts: &mut [u32],
) {
    use std::arch::x86_64::{
        __m128i, __m256i, _mm256_add_epi16, _mm256_castsi256_si128, _mm256_cvtepu8_epi16,
        _mm256_extracti128_si256, _mm256_loadu_si256, _mm256_setzero_si256, _mm256_storeu_si256,
        _mm256_sub_epi8,
    };
    // One-hot rows of each cell, with zero rows before (partners at negative steps) and
    // after (positive offsets, and the rest of the last block).
    let before = runs
        .iter()
        .map(|r| (-r.dt).max(0) as usize)
        .max()
        .unwrap_or(0);
    let after = runs.iter().map(|r| r.dt.max(0) as usize).max().unwrap_or(0) + STEPS;
    let stride = before + bins + after;
    let mut rows: Vec<[u8; 16]> = Vec::with_capacity(cells * stride);
    let mut one_hot = [[0u8; 16]; 16];
    for (i, row) in one_hot.iter_mut().enumerate() {
        row[i] = 0xFF;
    }
    for series in quantised.chunks_exact(bins) {
        rows.extend(std::iter::repeat_n([0u8; 16], before));
        rows.extend(series.iter().map(|&x| one_hot[usize::from(x & 15)]));
        rows.extend(std::iter::repeat_n([0u8; 16], after));
    }
    // Levels of each cell padded to whole blocks with 16, the spare row.
    let padded_bins = bins.div_ceil(STEPS) * STEPS;
    let mut padded = vec![16u8; cells * padded_bins];
    for (p, series) in padded
        .chunks_exact_mut(padded_bins)
        .zip(quantised.chunks_exact(bins))
    {
        for (p, &x) in p.iter_mut().zip(series) {
            *p = x.min(16);
        }
    }
    // Byte offset of each run's partner row for step 0, grouped by first cell.
    let offsets: Vec<isize> = runs
        .iter()
        .map(|r| ((r.b as usize * stride + before) as isize + r.dt) * 16)
        .collect();
    // Each first cell's runs, at most MAX_RUNS at a time: (cell, range of runs).
    let mut groups = Vec::new();
    let mut start = 0;
    for same_cell in runs.chunk_by(|x, y| x.a == y.a) {
        for chunk in same_cell.chunks(MAX_RUNS) {
            groups.push((same_cell[0].a as usize, start..start + chunk.len()));
            start += chunk.len();
        }
    }

    let mut copies = [[[0u16; 16]; 17]; COPIES];
    // Largest value any u16 count may have reached since the last flush.
    let mut bound = 0usize;
    let flush = |copies: &mut [Rows; COPIES], counts: &mut [u32]| {
        for copy in copies.iter_mut() {
            for (i, row) in copy.iter().take(levels).enumerate() {
                for (c, &n) in counts[i * levels..(i + 1) * levels].iter_mut().zip(row) {
                    *c += u32::from(n);
                }
            }
            *copy = [[0; 16]; 17];
        }
    };
    let base = rows.as_ptr().cast::<u8>();
    for t0 in (0..bins).step_by(STEPS) {
        for (a, group) in &groups {
            let mut acc = [_mm256_setzero_si256(); 8];
            for &offset in &offsets[group.clone()] {
                // SAFETY: the run's partner rows for steps t0 + dt .. t0 + dt + 16 lie in
                // cell b's stretch of `rows`: t0 + dt + before >= 0 as dt >= -before and
                // t0 >= 0, and t0 + 15 + dt < bins + STEPS - 1 + max(dt, 0) <= bins + after.
                let start = base.offset(offset + (t0 * 16) as isize);
                for (u, acc) in acc.iter_mut().enumerate() {
                    let row = _mm256_loadu_si256(start.add(32 * u).cast::<__m256i>());
                    *acc = _mm256_sub_epi8(*acc, row);
                }
            }
            let levels_here = &padded[a * padded_bins + t0..a * padded_bins + t0 + STEPS];
            let copies_ptr = copies.as_mut_ptr().cast::<u8>();
            let add = |step: usize, sums: __m128i| {
                let copy = step % COPIES;
                let level = usize::from(levels_here[step]);
                // SAFETY: level <= 16 (padded values are clamped), so the row lies inside
                // copy `copy` of 17 rows of 32 bytes.
                let row = copies_ptr.add((copy * 17 + level) * 32).cast::<__m256i>();
                _mm256_storeu_si256(
                    row,
                    _mm256_add_epi16(_mm256_loadu_si256(row), _mm256_cvtepu8_epi16(sums)),
                );
            };
            // Unrolled by hand: a loop here keeps the sums in memory, and reading a
            // register's upper half back from a store stalls.
            macro_rules! add_pair {
                ($($u:literal)*) => {$(
                    add(2 * $u, _mm256_castsi256_si128(acc[$u]));
                    add(2 * $u + 1, _mm256_extracti128_si256::<1>(acc[$u]));
                )*};
            }
            add_pair!(0 1 2 3 4 5 6 7);
            // Each copy took 4 rows of at most `group.len()` per count.
            bound += STEPS / COPIES * group.len();
            if bound > usize::from(u16::MAX) - STEPS / COPIES * MAX_RUNS {
                flush(&mut copies, counts);
                bound = 0;
            }
        }
    }
    flush(&mut copies, counts);
}

/// The estimated cost of [`count`], in histogram increments: half an increment per
/// 32-byte row subtraction, two per voxel for its one-hot row and the add into the counts
/// (`cargo bench --bench glcm`, and volumes of 19 to 297 bins of the simulated rig and
/// FabricSlide).
pub(super) fn cost(runs: &[Run], bins: usize, cells: usize) -> usize {
    let blocks = bins.div_ceil(STEPS);
    let subtractions = runs.len() * blocks * STEPS / 2;
    subtractions / 2 + 2 * cells * blocks * STEPS
}
