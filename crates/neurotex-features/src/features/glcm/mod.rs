//! Gray-level co-occurrence matrices over the quantised rate volume (paper section II-F,
//! eq. 4 and table I; Haralick et al. 1973).
//!
//! Coordinates are (row, col, time). For each offset `(dr, dc, dt)` a pair is
//! `(V[r, c, t] = i, V[r + dr, c + dc, t + dt] = j)`; pairs leaving the volume or touching a
//! masked cell are skipped. The counts of all offsets are summed before normalising (the
//! paper's averaging before normalising), so an offset with no pairs adds nothing.

mod masks;
mod onehot;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use masks::LevelMasks;

/// The paper's 13 direction vectors (table I), as `(row, col, time)` for D = 1.
pub const DIRECTIONS_13: [(i32, i32, i32); 13] = [
    (0, 1, 0),
    (-1, 1, 0),
    (-1, 0, 0),
    (-1, -1, 0),
    (0, 1, -1),
    (0, 0, -1),
    (0, -1, -1),
    (-1, 0, -1),
    (1, 0, -1),
    (-1, 1, -1),
    (1, -1, -1),
    (-1, -1, -1),
    (1, 1, -1),
];

/// Co-occurrence parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GlcmParams {
    /// Offset distances D (the paper's 1, 2, 4, 8).
    pub distances: Vec<usize>,
    /// Count each pair in both orders (off by default, as in the paper).
    pub symmetric: bool,
}

impl Default for GlcmParams {
    fn default() -> Self {
        GlcmParams {
            distances: vec![1, 2, 4, 8],
            symmetric: false,
        }
    }
}

impl GlcmParams {
    /// Checks the rules: at least one distance, each between 1 and 1000.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if self.distances.is_empty() {
            return Err(ParamError::new(
                "distances",
                "at least one offset distance is needed",
                "none",
            ));
        }
        if let Some(&d) = self.distances.iter().find(|&&d| d == 0 || d > 1000) {
            return Err(ParamError::new(
                "distances",
                "offset distances must be between 1 and 1000",
                d,
            ));
        }
        Ok(())
    }
}

/// Which offsets a plan counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GlcmKind {
    /// The 13 directions of the 3D volume.
    ThreeD,
    /// The first four (in-plane) directions, for the time-collapsed image.
    TwoD,
}

/// How [`GlcmPlan::count_with`] counts the pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Counting {
    /// [`Counting::OneHot`] where it runs and the volume has at most 128 time bins
    /// (measured on 116 such simulated and FabricSlide volumes: faster than the histogram
    /// on all, than level masks on 103, median 0.65x their time); otherwise, per volume,
    /// whichever method needs the fewest operations, estimated from the number of levels
    /// each cell takes.
    Auto,
    /// One histogram increment per voxel pair.
    Histogram,
    /// Popcounts of per-level time masks: fast when each cell takes few levels, as the
    /// cells of rate volumes do.
    LevelMasks,
    /// Sums of one-hot level rows, two time steps per vector operation, whatever the
    /// levels (x86_64 with AVX2 and at most 16 levels; elsewhere this counts as
    /// [`Counting::Histogram`]).
    OneHot,
}

/// Largest total of co-occurrence counts [`GlcmPlan::count`] takes: its counts are u32.
pub const MAX_COUNTED_PAIRS: u64 = u32::MAX as u64;

/// Most pairs [`GlcmPlan::count_wide`] counts in one slice of u32 counters (half of
/// [`MAX_COUNTED_PAIRS`], so a slice may also hold one-sided counts of a symmetric plan).
pub const MAX_SLICE_PAIRS: u64 = 1 << 31;

/// All pairs of one cell pair at one time offset: `(V[a, t], V[b, t + dt])` for every `t`
/// at which both voxels lie inside the volume.
#[derive(Debug, Clone, Copy)]
struct Run {
    /// First cell.
    a: u32,
    /// Second cell.
    b: u32,
    /// The second voxel's time offset.
    dt: isize,
}

impl Run {
    /// Pairs in the run over `bins` time bins.
    fn len(&self, bins: usize) -> usize {
        bins.saturating_sub(self.dt.unsigned_abs())
    }

    /// The first voxel's time steps at which the second voxel lies inside a volume of
    /// `bins` bins too.
    fn first_steps(&self, bins: usize) -> std::ops::Range<usize> {
        let start = if self.dt < 0 {
            self.dt.unsigned_abs()
        } else {
            0
        };
        start..start + self.len(bins)
    }
}

/// Counts each pair in both orders: `counts + counts^T` (`l x l`), the diagonal doubled
/// as both orders of a pair of equal levels.
pub fn symmetrise<T: Copy + std::ops::Add<Output = T>>(counts: &mut [T], l: usize) {
    for i in 0..l {
        for j in i..l {
            let s = counts[i * l + j] + counts[j * l + i];
            counts[i * l + j] = s;
            counts[j * l + i] = s;
        }
    }
}

/// The `(dr, dc, dt)` offsets of `kind`: the paper's directions times each distance, in
/// the order of `params.distances`.
pub fn planned_offsets(params: &GlcmParams, kind: GlcmKind) -> Vec<(isize, isize, isize)> {
    let dirs: &[(i32, i32, i32)] = match kind {
        GlcmKind::ThreeD => &DIRECTIONS_13,
        GlcmKind::TwoD => &DIRECTIONS_13[..4],
    };
    params
        .distances
        .iter()
        .flat_map(|&d| {
            dirs.iter().map(move |&(dr, dc, dt)| {
                (
                    dr as isize * d as isize,
                    dc as isize * d as isize,
                    dt as isize * d as isize,
                )
            })
        })
        .collect()
}

/// Offset tables for one grid, mask and parameter set, built once and applied to many volumes.
#[derive(Debug, Clone)]
pub struct GlcmPlan {
    levels: usize,
    cells: usize,
    symmetric: bool,
    /// Every cell pair and time offset of the planned offsets, sorted by time offset.
    runs: Vec<Run>,
    /// The same runs sorted by first cell.
    by_cell: Vec<Run>,
    /// Cells in at least one pair.
    paired: Vec<bool>,
}

impl GlcmPlan {
    /// Plans the offsets of `kind` (the paper's directions times each distance) for a
    /// `rows x cols` grid with `present` cells.
    ///
    /// # Errors
    /// Broken parameter rules, or fewer than 2 or more than 256 levels.
    ///
    /// # Panics
    /// If `present` is not one flag per cell (a caller bug).
    pub fn new(
        rows: usize,
        cols: usize,
        present: &[bool],
        levels: usize,
        params: &GlcmParams,
        kind: GlcmKind,
    ) -> Result<Self, ParamError> {
        params.check()?;
        let offsets = planned_offsets(params, kind);
        Self::from_offsets(rows, cols, present, levels, &offsets, params.symmetric)
    }

    /// Plans arbitrary `(dr, dc, dt)` offsets (for custom direction sets and for tests
    /// against tools that report one matrix per offset).
    ///
    /// # Errors
    /// Fewer than 2 or more than 256 levels.
    ///
    /// # Panics
    /// If `present` is not one flag per cell (a caller bug).
    pub fn from_offsets(
        rows: usize,
        cols: usize,
        present: &[bool],
        levels: usize,
        offsets: &[(isize, isize, isize)],
        symmetric: bool,
    ) -> Result<Self, ParamError> {
        if !(2..=256).contains(&levels) {
            return Err(ParamError::new(
                "levels",
                "gray levels must be between 2 and 256",
                levels,
            ));
        }
        assert_eq!(present.len(), rows * cols);
        let (rows_i, cols_i) = (rows as isize, cols as isize);
        let mut runs = Vec::new();
        for &(dr, dc, dt) in offsets {
            for r in 0..rows_i {
                for c in 0..cols_i {
                    let (r2, c2) = (r + dr, c + dc);
                    if r2 < 0 || c2 < 0 || r2 >= rows_i || c2 >= cols_i {
                        continue;
                    }
                    let (a, b) = ((r * cols_i + c) as usize, (r2 * cols_i + c2) as usize);
                    if present[a] && present[b] {
                        runs.push(Run {
                            a: a as u32,
                            b: b as u32,
                            dt,
                        });
                    }
                }
            }
        }
        let mut by_cell = runs.clone();
        by_cell.sort_by_key(|r| (r.a, r.dt));
        // Grouped by time offset, each level mask is shifted once per offset.
        runs.sort_by_key(|r| r.dt);
        let mut paired = vec![false; rows * cols];
        for r in &runs {
            paired[r.a as usize] = true;
            paired[r.b as usize] = true;
        }
        Ok(GlcmPlan {
            levels,
            cells: rows * cols,
            symmetric,
            runs,
            by_cell,
            paired,
        })
    }

    /// Gray levels of the matrices this plan counts.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// Sums the co-occurrence counts of every planned offset over a quantised volume
    /// (`cells x bins`, cell-major, levels below `levels`) into `counts` (`levels x levels`,
    /// row = first voxel's level), overwriting it. Same as [`GlcmPlan::count_with`] with
    /// [`Counting::Auto`].
    ///
    /// # Panics
    /// If the volume is not `cells x bins`, `counts` is not `levels^2`, a voxel's level
    /// is not below `levels`, or the volume has more pairs than u32 counts hold
    /// ([`GlcmPlan::counts_fit`] is false): caller bugs.
    pub fn count(&self, quantised: &[u8], bins: usize, counts: &mut [u32]) {
        self.count_with(quantised, bins, counts, Counting::Auto);
    }

    /// [`GlcmPlan::count`] with a chosen counting method; every method gives the same counts.
    ///
    /// # Panics
    /// As [`GlcmPlan::count`].
    pub fn count_with(
        &self,
        quantised: &[u8],
        bins: usize,
        counts: &mut [u32],
        counting: Counting,
    ) {
        let l = self.levels;
        assert_eq!(
            quantised.len(),
            self.cells * bins,
            "volume must be cells x bins"
        );
        assert_eq!(counts.len(), l * l, "counts must be levels x levels");
        counts.fill(0);
        if bins == 0 {
            return;
        }
        // Runs whose time offset leaves the volume have no pairs.
        let first = self.runs.partition_point(|r| r.dt <= -(bins as isize));
        let last = self.runs.partition_point(|r| r.dt < bins as isize);
        let runs = &self.runs[first..last];
        let pairs: usize = runs.iter().map(|r| r.len(bins)).sum();
        // Every counter of every method (histograms, popcount sums, the one-hot kernel's
        // flushed u16 rows) holds a partial sum of these pairs, so a total that fits u32
        // is proof that none of them wraps.
        assert!(
            (pairs as u64) << u64::from(self.symmetric) <= MAX_COUNTED_PAIRS,
            "a volume of {pairs} pairs overflows u32 counts; check GlcmPlan::counts_fit first"
        );
        let one_hot = onehot::available(l);
        let count_one_hot = |counts: &mut [u32]| {
            onehot::count(quantised, bins, self.cells, &self.by_cell, l, counts);
        };
        match counting {
            Counting::OneHot if one_hot => count_one_hot(counts),
            Counting::Auto if one_hot && bins <= 128 => count_one_hot(counts),
            Counting::Histogram | Counting::OneHot => {
                self.count_histogram(quantised, bins, runs, counts);
            }
            Counting::LevelMasks | Counting::Auto => {
                let mut masks = LevelMasks::new(quantised, bins, l, &self.paired);
                let masks_cost = masks.cost(runs);
                let one_hot_cost = if one_hot {
                    onehot::cost(runs, bins, self.cells)
                } else {
                    usize::MAX
                };
                if counting == Counting::Auto && one_hot_cost < masks_cost.min(pairs) {
                    count_one_hot(counts);
                } else if counting == Counting::LevelMasks || masks_cost <= pairs {
                    masks.fill(quantised);
                    masks.count_runs(runs, l, counts);
                } else {
                    self.count_histogram(quantised, bins, runs, counts);
                }
            }
        }
        if self.symmetric {
            symmetrise(counts, l);
        }
    }

    /// Adds the counts of `runs` to `counts`, one increment per pair.
    fn count_histogram(&self, quantised: &[u8], bins: usize, runs: &[Run], counts: &mut [u32]) {
        let l = self.levels;
        let aligned = |run: &Run| {
            let steps = run.first_steps(bins);
            let (a, b) = (run.a as usize * bins, run.b as usize * bins);
            let second = (steps.start as isize + run.dt) as usize;
            (
                &quantised[a + steps.start..a + steps.end],
                &quantised[b + second..b + second + steps.len()],
            )
        };
        if l > 16 {
            for run in runs {
                let (first, second) = aligned(run);
                for (&x, &y) in first.iter().zip(second) {
                    counts[x as usize * l + y as usize] += 1;
                }
            }
            return;
        }
        // Up to 16 levels a pair's code `i << 4 | j` is one byte. The codes of every run
        // are written into one buffer (a vectorised loop), then counted in a single pass
        // into byte-indexed histograms, which need no bounds checks; four interleaved
        // histograms break the store-to-load dependency between increments of the same
        // bin (rate volumes have long constant runs).
        let mut codes = vec![0u8; runs.iter().map(|r| r.len(bins)).sum()];
        let mut rest = &mut codes[..];
        for run in runs {
            let (first, second) = aligned(run);
            let (now, later) = rest.split_at_mut(first.len());
            for ((c, &x), &y) in now.iter_mut().zip(first).zip(second) {
                *c = (x << 4) | y;
            }
            rest = later;
        }
        let mut hist = [[0u32; 256]; 4];
        let mut quads = codes.chunks_exact(4);
        for q in &mut quads {
            hist[0][q[0] as usize] += 1;
            hist[1][q[1] as usize] += 1;
            hist[2][q[2] as usize] += 1;
            hist[3][q[3] as usize] += 1;
        }
        for &c in quads.remainder() {
            hist[0][c as usize] += 1;
        }
        for i in 0..l {
            for j in 0..l {
                let code = (i << 4) | j;
                counts[i * l + j] += hist[0][code] + hist[1][code] + hist[2][code] + hist[3][code];
            }
        }
    }

    /// The number of voxel pairs the plan counts in a volume of `bins` time steps.
    pub fn pairs_for(&self, bins: usize) -> usize {
        self.runs.iter().map(|r| r.len(bins)).sum()
    }

    /// The total of the counts over a volume of `bins` time steps (each pair counted
    /// twice when symmetric), in u64 so it cannot wrap.
    pub fn counted_pairs(&self, bins: usize) -> u64 {
        let pairs: u64 = self.runs.iter().map(|r| r.len(bins) as u64).sum();
        pairs << u64::from(self.symmetric)
    }

    /// Whether u32 counts hold a volume of `bins` time steps: its
    /// [`GlcmPlan::counted_pairs`] is at most [`MAX_COUNTED_PAIRS`]. The counting kernels
    /// add u32 lanes (twice as many per vector as u64); a volume beyond it (4.3 billion
    /// pairs: an hour-long recording on a grid of thousands of taxels, or many distances)
    /// is counted by [`GlcmPlan::count_wide`].
    pub fn counts_fit(&self, bins: usize) -> bool {
        self.counted_pairs(bins) <= MAX_COUNTED_PAIRS
    }

    /// Whether [`GlcmPlan::count_wide`] can count a volume of `bins` time steps: one run
    /// (a cell pair at one time offset, at most `bins` pairs) must fit the u32 counters of a
    /// slice, so `bins` may be at most [`MAX_SLICE_PAIRS`], 2^31 time bins, far beyond any
    /// recording the readers accept.
    pub fn counts_fit_wide(&self, bins: usize) -> bool {
        bins as u64 <= MAX_SLICE_PAIRS
    }

    /// [`GlcmPlan::count`] into u64 counts, for volumes of any size: a volume whose counts
    /// fit u32 ([`GlcmPlan::counts_fit`]) is counted as usual and widened; a larger one is
    /// counted in slices of runs of at most [`MAX_SLICE_PAIRS`] pairs each, whose u32 counts
    /// cannot wrap, added up in u64.
    ///
    /// # Panics
    /// As [`GlcmPlan::count`], except for the size, and if
    /// [`GlcmPlan::counts_fit_wide`] is false (a caller bug).
    pub fn count_wide(&self, quantised: &[u8], bins: usize, counts: &mut [u64]) {
        let l = self.levels;
        assert_eq!(counts.len(), l * l, "counts must be levels x levels");
        self.count_sliced(quantised, bins, counts, MAX_SLICE_PAIRS);
    }

    /// [`GlcmPlan::count_wide`] with slices of at most `slice_pairs` pairs (small in tests).
    fn count_sliced(&self, quantised: &[u8], bins: usize, counts: &mut [u64], slice_pairs: u64) {
        let l = self.levels;
        let mut narrow = vec![0u32; l * l];
        if self.counted_pairs(bins) <= slice_pairs.min(MAX_COUNTED_PAIRS) {
            self.count(quantised, bins, &mut narrow);
            for (wide, &n) in counts.iter_mut().zip(&narrow) {
                *wide = u64::from(n);
            }
            return;
        }
        assert!(
            bins as u64 <= slice_pairs,
            "a run of {bins} pairs is longer than a slice; check GlcmPlan::counts_fit_wide first"
        );
        counts.fill(0);
        let mut start = 0;
        while start < self.runs.len() {
            let mut end = start;
            let mut pairs = 0u64;
            while end < self.runs.len() && pairs + self.runs[end].len(bins) as u64 <= slice_pairs {
                pairs += self.runs[end].len(bins) as u64;
                end += 1;
            }
            // Counted one-sided; the sum is mirrored once, in u64, below.
            self.sliced(&self.runs[start..end])
                .count(quantised, bins, &mut narrow);
            for (wide, &n) in counts.iter_mut().zip(&narrow) {
                *wide += u64::from(n);
            }
            start = end;
        }
        if self.symmetric {
            symmetrise(counts, l);
        }
    }

    /// A one-sided plan of some of this plan's runs (sorted by time offset, as `runs` is).
    fn sliced(&self, runs: &[Run]) -> GlcmPlan {
        let mut by_cell = runs.to_vec();
        by_cell.sort_by_key(|r| (r.a, r.dt));
        let mut paired = vec![false; self.cells];
        for r in runs {
            paired[r.a as usize] = true;
            paired[r.b as usize] = true;
        }
        GlcmPlan {
            levels: self.levels,
            cells: self.cells,
            symmetric: false,
            runs: runs.to_vec(),
            by_cell,
            paired,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_volume_whose_pairs_overflow_u32_counts_is_detected_before_counting() {
        let plan = GlcmPlan::new(
            4,
            4,
            &[true; 16],
            16,
            &GlcmParams::default(),
            GlcmKind::ThreeD,
        )
        .unwrap();
        let per_bin = plan.counted_pairs(1_000_001) - plan.counted_pairs(1_000_000);
        assert!(per_bin > 0);
        assert!(plan.counts_fit(1000));
        let limit_bins = (MAX_COUNTED_PAIRS / per_bin) as usize;
        assert!(!plan.counts_fit(limit_bins + 1000));
        // computed in u64: no wrap even where usize pair counts would pass u32::MAX
        assert!(plan.counted_pairs(limit_bins + 1000) > MAX_COUNTED_PAIRS);
    }

    /// A small xorshift volume of `cells x bins` levels below `levels`.
    fn volume(cells: usize, bins: usize, levels: u8, mut seed: u64) -> Vec<u8> {
        (0..cells * bins)
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed % u64::from(levels)) as u8
            })
            .collect()
    }

    #[test]
    fn counting_in_slices_of_runs_adds_up_to_the_whole_count() {
        for symmetric in [false, true] {
            let params = GlcmParams {
                distances: vec![1, 2, 3],
                symmetric,
            };
            let present = [true, true, false, true, true, true];
            let plan = GlcmPlan::new(2, 3, &present, 8, &params, GlcmKind::ThreeD).unwrap();
            let bins = 40;
            let q = volume(6, bins, 8, 0x9e37_79b9_7f4a_7c15);
            let mut whole = vec![0u32; 64];
            plan.count(&q, bins, &mut whole);
            let whole: Vec<u64> = whole.into_iter().map(u64::from).collect();
            // Slices of at most 41..97 pairs: many slices, with runs of 37..40 pairs each.
            for slice_pairs in [41, 60, 97] {
                let mut wide = vec![7u64; 64];
                plan.count_sliced(&q, bins, &mut wide, slice_pairs);
                assert_eq!(
                    wide, whole,
                    "symmetric {symmetric}, slices of {slice_pairs}"
                );
            }
            let mut wide = vec![0u64; 64];
            plan.count_wide(&q, bins, &mut wide);
            assert_eq!(wide, whole);
        }
    }

    #[test]
    fn a_run_longer_than_a_slice_is_refused() {
        let plan =
            GlcmPlan::new(1, 2, &[true; 2], 4, &GlcmParams::default(), GlcmKind::TwoD).unwrap();
        assert!(plan.counts_fit_wide(1 << 31));
        assert!(!plan.counts_fit_wide((1 << 31) + 1));
        let q = volume(2, 50, 4, 3);
        let mut wide = vec![0u64; 16];
        let refused = std::panic::catch_unwind(move || plan.count_sliced(&q, 50, &mut wide, 20));
        assert!(refused.is_err());
    }
}
