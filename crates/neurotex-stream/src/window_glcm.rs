//! The 3D co-occurrence counts of a stream's sliding window, kept up to date one time bin
//! at a time.
//!
//! At every bin boundary a 3D-GLCM model classifies the window's rate volume. Counting its
//! pairs afresh costs `offsets x cells x bins` each time, which at large skins and long
//! windows is most of the stream's work. Here the window keeps the pairs of raw spike
//! counts (a bin of `bin_ms` holds at most `bin_ms` spikes per cell), summed over all
//! offsets: a closed bin adds the pairs whose later voxel lies in it and the bin leaving
//! the window removes the pairs whose earlier voxel lay in it, `2 x offsets x cells`
//! increments per bin whatever the window's length. Levels depend on the window's own
//! smallest and largest rate, so counts become levels only when the window is classified
//! ([`WindowGlcm::counts`]): one pass over the pairs of counts the window holds, few
//! because spike counts per bin are small.
//!
//! The counts equal [`crate::features::GlcmPlan::count_wide`] on the window's quantised
//! [`crate::features::CountVolume`] exactly (tested against it below), so a stream
//! classifies as the offline pipeline does.

use std::collections::VecDeque;

use crate::features::glcm::{planned_offsets, symmetrise, GlcmKind};
use crate::features::volume::count_levels;
use crate::features::GlcmParams;

/// The widest bin kept this way: counts up to `bin_ms` and one more value for masked
/// cells fit a byte.
pub(crate) const MAX_BIN_MS: usize = 254;

/// One population's sliding window of spike counts and their co-occurrence counts.
#[derive(Debug, Clone)]
pub(crate) struct WindowGlcm {
    rows: usize,
    cols: usize,
    present: Vec<bool>,
    bin_ms: usize,
    /// The window's length in bins.
    window_bins: usize,
    /// Each offset as `(dr, dc, lag)`: the second voxel lies `dr` rows and `dc` columns
    /// from the first and `lag` bins before it (the 3D directions look back in time).
    offsets: Vec<(isize, isize, usize)>,
    /// Side of the square tables indexed by a count: `0..=bin_ms`, then the masked value.
    side: usize,
    /// The window's closed bins, oldest first: spike counts per cell (row-major), masked
    /// cells holding `side - 1`.
    slices: VecDeque<Vec<u8>>,
    /// The bin being filled.
    current: Vec<u8>,
    /// Pairs of the window by (first count, second count), `side x side`; rows and columns
    /// of the masked value hold the pairs that touch a masked cell, never read.
    pairs: Vec<u64>,
    /// Voxels of the window by count (the masked value last).
    values: Vec<u64>,
}

/// Whether [`tally`] adds pairs or takes them away.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Tally {
    Add,
    Remove,
}

impl WindowGlcm {
    /// A window of `window_bins` bins of `bin_ms` on a `rows x cols` grid, counting the
    /// 3D offsets of `glcm`; `None` for bins wider than [`MAX_BIN_MS`] (their counts need
    /// more than a byte).
    pub(crate) fn new(
        rows: usize,
        cols: usize,
        present: &[bool],
        bin_ms: usize,
        glcm: &GlcmParams,
        window_bins: usize,
    ) -> Option<Self> {
        if bin_ms == 0 || bin_ms > MAX_BIN_MS || window_bins == 0 {
            return None;
        }
        let offsets = planned_offsets(glcm, GlcmKind::ThreeD)
            .into_iter()
            .map(|(dr, dc, dt)| {
                debug_assert!(dt <= 0, "the 3D directions look back in time");
                (dr, dc, dt.unsigned_abs())
            })
            .collect();
        let side = bin_ms + 2;
        Some(WindowGlcm {
            rows,
            cols,
            present: present.to_vec(),
            bin_ms,
            window_bins,
            offsets,
            side,
            slices: VecDeque::with_capacity(window_bins),
            current: vec![0; rows * cols],
            pairs: vec![0; side * side],
            values: vec![0; side],
        })
    }

    /// Adds one 1 ms step's spikes of the cells `first..first + raster.len()` (one byte
    /// per cell, 1 for a spike) to the bin being filled.
    pub(crate) fn add_spikes(&mut self, first: usize, raster: &[u8]) {
        for (c, &s) in self.current[first..].iter_mut().zip(raster) {
            *c += s;
        }
    }

    /// Closes the bin being filled: it enters the window, and the oldest bin leaves when
    /// the window is full.
    pub(crate) fn close_bin(&mut self) {
        let masked = (self.side - 1) as u8;
        let spare = match self.slices.len() == self.window_bins {
            true => Some(self.drop_oldest()),
            false => None,
        };
        let mut slice = std::mem::replace(
            &mut self.current,
            spare.unwrap_or_else(|| vec![0; self.rows * self.cols]),
        );
        self.current.fill(0);
        for (v, &p) in slice.iter_mut().zip(&self.present) {
            // At most one spike per step: a bin's count is at most `bin_ms`.
            *v = if p {
                (*v).min(self.bin_ms as u8)
            } else {
                masked
            };
        }
        for &v in &slice {
            self.values[usize::from(v)] += 1;
        }
        self.slices.push_back(slice);
        let newest = self.slices.len() - 1;
        for &(dr, dc, lag) in &self.offsets {
            if lag <= newest {
                let grid = (self.rows, self.cols, self.side);
                let (first, second) = (&self.slices[newest], &self.slices[newest - lag]);
                tally(&mut self.pairs, grid, first, second, (dr, dc), Tally::Add);
            }
        }
    }

    /// Takes the oldest bin out of the window and returns its buffer.
    fn drop_oldest(&mut self) -> Vec<u8> {
        let held = self.slices.len();
        for &(dr, dc, lag) in &self.offsets {
            if lag < held {
                let grid = (self.rows, self.cols, self.side);
                let (first, second) = (&self.slices[lag], &self.slices[0]);
                tally(
                    &mut self.pairs,
                    grid,
                    first,
                    second,
                    (dr, dc),
                    Tally::Remove,
                );
            }
        }
        let oldest = self.slices.pop_front().expect("a full window");
        for &v in &oldest {
            self.values[usize::from(v)] -= 1;
        }
        oldest
    }

    /// Closed bins in the window.
    #[cfg(test)]
    fn bins(&self) -> usize {
        self.slices.len()
    }

    /// The summed co-occurrence counts of the window's rate volume quantised to `levels`
    /// (over `range`, or the window's own smallest and largest rate), `levels x levels`,
    /// row = first voxel's level, as [`crate::features::GlcmPlan::count_wide`] counts
    /// them (mirrored when `symmetric`).
    pub(crate) fn counts(
        &self,
        levels: usize,
        range: Option<(f64, f64)>,
        symmetric: bool,
        out: &mut Vec<u64>,
    ) {
        out.clear();
        out.resize(levels * levels, 0);
        let held = &self.values[..=self.bin_ms];
        let (Some(min), Some(max)) = (
            held.iter().position(|&n| n > 0),
            held.iter().rposition(|&n| n > 0),
        ) else {
            return; // no present cell
        };
        let level = count_levels(self.bin_ms, levels, range, (min as u32, max as u32));
        let table: Vec<usize> = (min..=max).map(|c| usize::from(level(c as u32))).collect();
        for (i, &li) in (min..=max).zip(&table) {
            let row = &self.pairs[i * self.side + min..=i * self.side + max];
            for (&n, &lj) in row.iter().zip(&table) {
                out[li * levels + lj] += n;
            }
        }
        if symmetric {
            symmetrise(out, levels);
        }
    }
}

/// Adds (or removes) the pairs of one in-plane offset `(dr, dc)` whose first voxel lies in
/// `first` and second in `second` (two bins of a `rows x cols` grid) to `pairs`, indexed
/// by `first count * side + second count`.
fn tally(
    pairs: &mut [u64],
    (rows, cols, side): (usize, usize, usize),
    first: &[u8],
    second: &[u8],
    (dr, dc): (isize, isize),
    how: Tally,
) {
    // The first voxel's rows and columns whose partner lies inside the grid.
    let span = |n: usize, d: isize| {
        let lo = (-d).max(0) as usize;
        let hi = (n as isize - d.max(0)).max(0) as usize;
        lo..hi.max(lo)
    };
    let (rs, cs) = (span(rows, dr), span(cols, dc));
    if cs.is_empty() {
        return;
    }
    for r in rs {
        let a = r * cols;
        let b = (r as isize + dr) as usize * cols;
        let shifted = (cs.start as isize + dc) as usize;
        let firsts = &first[a + cs.start..a + cs.end];
        let seconds = &second[b + shifted..b + shifted + cs.len()];
        match how {
            Tally::Add => {
                for (&x, &y) in firsts.iter().zip(seconds) {
                    pairs[usize::from(x) * side + usize::from(y)] += 1;
                }
            }
            Tally::Remove => {
                for (&x, &y) in firsts.iter().zip(seconds) {
                    pairs[usize::from(x) * side + usize::from(y)] -= 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{CountVolume, GlcmPlan};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The window's counts against the plan's count of the same bins, quantised as the
    /// offline pipeline quantises them, after every bin of a stream longer than the window.
    fn check(rows: usize, cols: usize, window_bins: usize, seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let bin_ms = [1, 3, 20, 200, MAX_BIN_MS][rng.gen_range(0..5)];
        let present: Vec<bool> = (0..rows * cols).map(|_| rng.gen_bool(0.85)).collect();
        let glcm = GlcmParams {
            distances: match rng.gen_range(0..3) {
                0 => vec![1, 2, 4, 8],
                1 => vec![1],
                _ => vec![3, 1, 3],
            },
            symmetric: rng.gen_bool(0.5),
        };
        let levels = [2, 8, 16, 64][rng.gen_range(0..4)];
        let range = match rng.gen_bool(0.3) {
            true => Some((5.0, 90.0)),
            false => None,
        };
        let plan = GlcmPlan::new(rows, cols, &present, levels, &glcm, GlcmKind::ThreeD).unwrap();
        let mut window = WindowGlcm::new(rows, cols, &present, bin_ms, &glcm, window_bins).unwrap();
        // Spike counts per bin drawn from a few rates (as rate volumes take few levels),
        // sometimes all equal (a constant window).
        let mut history: Vec<Vec<u8>> = Vec::new();
        for bin in 0..window_bins * 2 + 3 {
            let rate = rng.gen_range(0.0..0.3);
            let constant = rng.gen_bool(0.1);
            for _ in 0..bin_ms {
                let raster: Vec<u8> = (0..rows * cols)
                    .map(|_| u8::from(!constant && rng.gen_bool(rate)))
                    .collect();
                window.add_spikes(0, &raster);
            }
            history.push(window.current.clone());
            window.close_bin();
            let held = &history[history.len().saturating_sub(window_bins)..];
            assert_eq!(window.bins(), held.len());
            let cells = rows * cols;
            let volume = CountVolume {
                rows,
                cols,
                bins: held.len(),
                bin_ms,
                present: present.clone(),
                counts: (0..cells)
                    .flat_map(|c| held.iter().map(move |s| u32::from(s[c])))
                    .collect(),
            };
            let mut q = Vec::new();
            volume.quantise(levels, range, &mut q);
            let mut expected = vec![0u64; levels * levels];
            plan.count_wide(&q, volume.bins, &mut expected);
            let mut got = Vec::new();
            window.counts(levels, range, glcm.symmetric, &mut got);
            assert_eq!(
                got, expected,
                "{rows}x{cols}, window {window_bins}, bin {bin}, seed {seed}"
            );
        }
    }

    #[test]
    fn counts_equal_the_plans_over_a_sliding_window() {
        let shapes = [(1, 1), (1, 5), (4, 4), (3, 7), (9, 2), (12, 10)];
        for (seed, &(rows, cols)) in shapes.iter().enumerate() {
            for window_bins in [1, 2, 5, 9, 17] {
                check(
                    rows,
                    cols,
                    window_bins,
                    seed as u64 * 100 + window_bins as u64,
                );
            }
        }
    }

    #[test]
    fn wide_bins_are_left_to_the_plan() {
        let glcm = GlcmParams::default();
        assert!(WindowGlcm::new(2, 2, &[true; 4], MAX_BIN_MS + 1, &glcm, 10).is_none());
        assert!(WindowGlcm::new(2, 2, &[true; 4], 200, &glcm, 0).is_none());
    }
}
