//! Gray-level co-occurrence matrices over the quantised rate volume (paper section II-F,
//! eq. 4 and table I; Haralick et al. 1973).
//!
//! Coordinates are (row, col, time). For each offset `(dr, dc, dt)` a pair is
//! `(V[r, c, t] = i, V[r + dr, c + dc, t + dt] = j)`; pairs leaving the volume or touching a
//! masked cell are skipped. The counts of all offsets are summed before normalising (the
//! paper's averaging before normalising), so an offset with no pairs adds nothing.

use crate::error::ParamError;

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
#[derive(Debug, Clone, PartialEq)]
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

#[derive(Debug, Clone)]
struct PlannedOffset {
    /// Cell pairs `(from, to)` valid on the grid and the mask for this spatial offset.
    pairs: Vec<(u32, u32)>,
    /// Time offset `dt` of the second voxel.
    dt: isize,
}

/// Offset tables for one grid, mask and parameter set, built once and applied to many volumes.
#[derive(Debug, Clone)]
pub struct GlcmPlan {
    levels: usize,
    cells: usize,
    symmetric: bool,
    offsets: Vec<PlannedOffset>,
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
        let dirs: &[(i32, i32, i32)] = match kind {
            GlcmKind::ThreeD => &DIRECTIONS_13,
            GlcmKind::TwoD => &DIRECTIONS_13[..4],
        };
        let offsets: Vec<(isize, isize, isize)> = params
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
            .collect();
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
        let planned = offsets
            .iter()
            .filter_map(|&(dr, dc, dt)| {
                let mut pairs = Vec::new();
                for r in 0..rows_i {
                    for c in 0..cols_i {
                        let (r2, c2) = (r + dr, c + dc);
                        if r2 < 0 || c2 < 0 || r2 >= rows_i || c2 >= cols_i {
                            continue;
                        }
                        let (a, b) = ((r * cols_i + c) as usize, (r2 * cols_i + c2) as usize);
                        if present[a] && present[b] {
                            pairs.push((a as u32, b as u32));
                        }
                    }
                }
                (!pairs.is_empty()).then_some(PlannedOffset { pairs, dt })
            })
            .collect();
        Ok(GlcmPlan {
            levels,
            cells: rows * cols,
            symmetric,
            offsets: planned,
        })
    }

    /// Gray levels of the matrices this plan counts.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// Sums the co-occurrence counts of every planned offset over a quantised volume
    /// (`cells x bins`, cell-major, levels below `levels`) into `counts` (`levels x levels`,
    /// row = first voxel's level), overwriting it.
    ///
    /// # Panics
    /// If the volume is not `cells x bins` or `counts` is not `levels^2` (caller bugs).
    pub fn count(&self, quantised: &[u8], bins: usize, counts: &mut [u32]) {
        let l = self.levels;
        assert_eq!(
            quantised.len(),
            self.cells * bins,
            "volume must be cells x bins"
        );
        assert_eq!(counts.len(), l * l, "counts must be levels x levels");
        counts.fill(0);
        if l <= 16 {
            self.count_packed(quantised, bins, counts);
        } else {
            self.count_general(quantised, bins, counts);
        }
        if self.symmetric {
            for i in 0..l {
                for j in i..l {
                    let s = counts[i * l + j] + counts[j * l + i];
                    counts[i * l + j] = s;
                    counts[j * l + i] = s;
                }
            }
        }
    }

    /// Calls `visit(first, second)` with the two aligned level runs of every planned
    /// offset and cell pair: the first voxel's levels and the second voxel's, for every
    /// time step at which both lie inside the volume.
    fn for_each_run(&self, quantised: &[u8], bins: usize, mut visit: impl FnMut(&[u8], &[u8])) {
        for off in &self.offsets {
            let shift = off.dt.unsigned_abs();
            if shift >= bins {
                continue;
            }
            let n = bins - shift;
            let (first_start, second_start) = if off.dt < 0 { (shift, 0) } else { (0, shift) };
            for &(a, b) in &off.pairs {
                let (a, b) = (a as usize * bins, b as usize * bins);
                visit(
                    &quantised[a + first_start..a + first_start + n],
                    &quantised[b + second_start..b + second_start + n],
                );
            }
        }
    }

    /// Up to 16 levels: a pair's code `i << 4 | j` is one byte. The codes of every run are
    /// written into one buffer (a vectorised loop), then counted in a single pass into
    /// byte-indexed histograms, which need no bounds checks; four interleaved histograms
    /// break the store-to-load dependency between increments of the same bin (rate volumes
    /// have long constant runs).
    fn count_packed(&self, quantised: &[u8], bins: usize, counts: &mut [u32]) {
        let mut codes: Vec<u8> = Vec::with_capacity(self.pairs_for(bins));
        self.for_each_run(quantised, bins, |first, second| {
            codes.extend(first.iter().zip(second).map(|(&x, &y)| (x << 4) | y));
        });
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
        let l = self.levels;
        for i in 0..l {
            for j in 0..l {
                let code = (i << 4) | j;
                counts[i * l + j] = hist[0][code] + hist[1][code] + hist[2][code] + hist[3][code];
            }
        }
    }

    /// The number of voxel pairs the plan counts in a volume of `bins` time steps.
    pub fn pairs_for(&self, bins: usize) -> usize {
        self.offsets
            .iter()
            .map(|o| o.pairs.len() * bins.saturating_sub(o.dt.unsigned_abs()))
            .sum()
    }

    /// Any number of levels: index `i * L + j` into the count matrix.
    fn count_general(&self, quantised: &[u8], bins: usize, counts: &mut [u32]) {
        let l = self.levels;
        self.for_each_run(quantised, bins, |first, second| {
            for (&x, &y) in first.iter().zip(second) {
                counts[x as usize * l + y as usize] += 1;
            }
        });
    }
}
