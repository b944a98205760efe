//! Spike trains, the encoder's output and the input of every spike method: per cell of a
//! taxel grid, the sorted 1 ms steps of its spikes. They live at the bottom so that the
//! features and the classifiers name them without depending on the encoder.

use serde::{Deserialize, Serialize};

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
        assert!(cells > 0 && raster.len().is_multiple_of(cells));
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
