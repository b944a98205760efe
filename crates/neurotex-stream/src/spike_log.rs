//! The spikes of a stream's sliding window in time order: per 1 ms step, the cells that
//! spiked.
//!
//! A list per cell would make every bin boundary visit every cell's list to drop the
//! spikes that left the window, one cache miss per cell on a large skin. Here the window
//! is two queues (the spiking cells, and how many spiked at each step), dropped from the
//! front in order, and trains per cell are assembled (a counting sort) only when a
//! window's spike times are needed.

use std::collections::VecDeque;

use crate::encode::SpikeTrains;

/// One population's spikes from step `first_step` on.
#[derive(Debug, Clone, Default)]
pub(crate) struct SpikeLog {
    /// The episode step of the first step held.
    first_step: usize,
    /// Spikes at each step held, oldest first.
    per_step: VecDeque<u32>,
    /// The cells that spiked, step by step (ascending within a step).
    cells: VecDeque<u32>,
}

impl SpikeLog {
    /// Opens the next step: its spikes come with [`SpikeLog::add_part`].
    pub(crate) fn begin_step(&mut self) {
        self.per_step.push_back(0);
    }

    /// Adds the open step's spikes of the cells `first..first + raster.len()`: those whose
    /// byte is not 0 and that hold a taxel (`present`, of the same cells). Parts come in
    /// order of their first cell.
    ///
    /// # Panics
    /// If no step is open (a caller bug).
    pub(crate) fn add_part(&mut self, first: usize, raster: &[u8], present: &[bool]) {
        let before = self.cells.len();
        // Spikes are sparse: test eight cells at a time as one word.
        for (w, word) in raster.chunks(8).enumerate() {
            let quiet = match <[u8; 8]>::try_from(word) {
                Ok(bytes) => u64::from_ne_bytes(bytes) == 0,
                Err(_) => word.iter().all(|&b| b == 0),
            };
            if quiet {
                continue;
            }
            for (k, &b) in word.iter().enumerate() {
                let cell = w * 8 + k;
                if b != 0 && present[cell] {
                    self.cells.push_back((first + cell) as u32);
                }
            }
        }
        *self.per_step.back_mut().expect("an open step") += (self.cells.len() - before) as u32;
    }

    /// Forgets the steps before `step`.
    pub(crate) fn drop_before(&mut self, step: usize) {
        while self.first_step < step {
            let Some(n) = self.per_step.pop_front() else {
                self.first_step = step;
                return;
            };
            self.cells.drain(..n as usize);
            self.first_step += 1;
        }
    }

    /// Spikes held.
    pub(crate) fn len(&self) -> usize {
        self.cells.len()
    }

    /// The trains of the steps `start..end` (held, or the window starts at the first step
    /// held), times from `start`, on a `rows x cols` grid of `present` cells.
    pub(crate) fn trains(
        &self,
        start: usize,
        end: usize,
        (rows, cols): (usize, usize),
        present: &[bool],
    ) -> SpikeTrains {
        debug_assert!(start >= self.first_step && end <= self.first_step + self.per_step.len());
        // The window's run of the queue: the steps before `start` are skipped.
        let skip = start - self.first_step;
        let steps = end - start;
        let mut from = 0usize;
        for &n in self.per_step.iter().take(skip) {
            from += n as usize;
        }
        let spikes = |f: &mut dyn FnMut(u32, u32)| {
            let mut cells = self.cells.range(from..);
            for (t, &n) in self.per_step.iter().skip(skip).take(steps).enumerate() {
                for &cell in cells.by_ref().take(n as usize) {
                    f(cell, t as u32);
                }
            }
        };
        // A counting sort by cell: the steps come in time order, so each train is sorted.
        let mut offsets = vec![0u32; rows * cols + 1];
        spikes(&mut |cell, _| offsets[cell as usize + 1] += 1);
        for c in 0..rows * cols {
            offsets[c + 1] += offsets[c];
        }
        let mut next = offsets.clone();
        let mut times = vec![0u32; offsets[rows * cols] as usize];
        spikes(&mut |cell, t| {
            let slot = &mut next[cell as usize];
            times[*slot as usize] = t;
            *slot += 1;
        });
        SpikeTrains::from_parts(rows, cols, present, steps, offsets, times)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Windows of a logged raster against the trains of the same raster's rows.
    #[test]
    fn windows_equal_the_rasters_trains() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (rows, cols) = (5, 7);
        let cells = rows * cols;
        let present: Vec<bool> = (0..cells).map(|_| rng.gen_bool(0.8)).collect();
        let raster: Vec<u8> = (0..300 * cells)
            .map(|_| u8::from(rng.gen_bool(0.1)))
            .collect();
        let mut log = SpikeLog::default();
        for (step, frame) in raster.chunks_exact(cells).enumerate() {
            log.begin_step();
            // Parts of uneven size, as a stream's last part is.
            for (k, part) in frame.chunks(8).enumerate() {
                log.add_part(k * 8, part, &present[k * 8..k * 8 + part.len()]);
            }
            let end = step + 1;
            let start = end.saturating_sub(40);
            if end % 10 == 0 || step % 7 == 3 {
                log.drop_before(start);
                let got = log.trains(start, end, (rows, cols), &present);
                let want = SpikeTrains::from_raster(
                    &raster[start * cells..end * cells],
                    rows,
                    cols,
                    &present,
                );
                assert_eq!(got, want, "steps {start}..{end}");
                let held = raster[start * cells..end * cells]
                    .iter()
                    .zip(present.iter().cycle())
                    .filter(|(&b, &p)| b != 0 && p)
                    .count();
                assert_eq!(log.len(), held, "the log keeps the window only");
                // A later start within the held steps.
                let later = (start + 13).min(end - 1);
                let want = SpikeTrains::from_raster(
                    &raster[later * cells..end * cells],
                    rows,
                    cols,
                    &present,
                );
                assert_eq!(log.trains(later, end, (rows, cols), &present), want);
            }
        }
    }
}
