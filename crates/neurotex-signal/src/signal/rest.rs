//! Tracking each cell's resting value as a stream goes: the median of recent blocks, for the
//! baseline of causal conditioning.

use crate::error::{ParamError, Result};

use super::{DRIFT_BLOCK_MS, MAX_DRIFT_VALUES};

/// Each cell's resting value as the least of its input over a trailing window: the
/// current 100 ms block so far and the `window / 100 ms` whole blocks before it (so the
/// window spans between `window` and `window + 0.1 s`). A causal counterpart of the `min`
/// baseline that follows a resting level drifting by more than the signal, at a cost of
/// one comparison per cell and step and one pass over the block minima per block. The
/// offline causal pipeline and the stream both run it, step by step, on the resampled
/// input, so they subtract the same values.
#[derive(Debug, Clone)]
pub struct RestTracker {
    cells: usize,
    blocks: usize,
    /// The last `blocks` whole blocks' minima, `blocks x cells` (infinite while unfilled).
    ring: Vec<f64>,
    /// Per cell, the least of `ring`.
    earlier: Vec<f64>,
    /// Per cell, the least of the current block so far.
    current: Vec<f64>,
    step: u64,
}

impl RestTracker {
    /// A tracker for `cells` cells over a window of `window_ms` (a checked
    /// [`PreprocessParams::drift_window_ms`]).
    ///
    /// # Errors
    /// A grid too large to keep the window's block minima for ([`MAX_DRIFT_VALUES`]).
    pub fn new(cells: usize, window_ms: u32) -> Result<Self, ParamError> {
        let blocks = (window_ms / DRIFT_BLOCK_MS).max(1) as usize;
        if cells.saturating_mul(blocks) > MAX_DRIFT_VALUES {
            let rule = "the drift window keeps one minimum per taxel and 0.1 s, at most 16777216 values over the grid";
            let got = format!(
                "{} s on {cells} cells (at most {:.1} s on this grid)",
                window_ms as f64 / 1000.0,
                (MAX_DRIFT_VALUES / cells.max(1)) as f64 / 10.0
            );
            return Err(ParamError::new("drift-window-s", rule, got));
        }
        Ok(RestTracker {
            cells,
            blocks,
            ring: vec![f64::INFINITY; cells * blocks],
            earlier: vec![f64::INFINITY; cells],
            current: vec![f64::INFINITY; cells],
            step: 0,
        })
    }

    /// Takes one step's input `raw` (one value per cell) and writes each cell's resting
    /// value into `rest`.
    ///
    /// # Panics
    /// `raw` or `rest` does not hold one value per cell.
    pub fn push(&mut self, raw: &[f64], rest: &mut [f64]) {
        let cells = self.cells;
        assert!(raw.len() == cells && rest.len() == cells);
        let block_steps = u64::from(DRIFT_BLOCK_MS);
        if self.step > 0 && self.step.is_multiple_of(block_steps) {
            let slot = ((self.step / block_steps - 1) % self.blocks as u64) as usize;
            self.ring[slot * cells..(slot + 1) * cells].copy_from_slice(&self.current);
            self.earlier.fill(f64::INFINITY);
            for block in self.ring.chunks_exact(cells) {
                for (e, &b) in self.earlier.iter_mut().zip(block) {
                    *e = e.min(b);
                }
            }
            self.current.fill(f64::INFINITY);
        }
        for (((c, &x), &e), r) in (self.current.iter_mut().zip(raw))
            .zip(&self.earlier)
            .zip(rest.iter_mut())
        {
            *c = c.min(x);
            *r = c.min(e);
        }
        self.step += 1;
    }
}
