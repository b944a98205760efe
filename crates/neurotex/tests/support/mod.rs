//! What several test files share (`mod support;`): a seeded generator for varied inputs,
//! proptest strategies for the stages' inputs, and the small simulated design of the
//! whole-run tests.

// Each test file is its own crate and uses only part of this module.
#![allow(dead_code)]

use std::ops::Range;

use neurotex::experiments::Source;
use neurotex::sim::{design, RigParams, Texture};
use proptest::prelude::*;

/// The small design the whole-run tests (golden results, report intervals) simulate: 4
/// textures x 10, 20 mm/s x 6 trials of 20 mm slides after a 0.5 s hold, with `seed`.
pub fn small_design(seed: u64) -> Source<'static> {
    let rig = RigParams {
        hold_s: 0.5,
        slide_mm: 20.0,
        ..RigParams::default()
    };
    let textures = [Texture::Ft1, Texture::Sb, Texture::Stf, Texture::Cp];
    Source::Simulated {
        rig: Box::new(rig),
        trials: design(&textures, &[10.0, 20.0], 6),
        seed,
    }
}

/// Marsaglia's xorshift64 (shifts 13, 7, 17), seeded: the same seed gives the same numbers
/// on every machine and thread count. For varied test inputs, not for statistics.
#[derive(Debug, Clone)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from `seed`, made odd so that the state is never zero.
    pub fn new(seed: u64) -> Self {
        XorShift(seed | 1)
    }

    /// The next number.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// The next number modulo `n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// A fraction in `[0, 1)` in steps of `1 / steps`.
    pub fn fraction(&mut self, steps: u64) -> f64 {
        self.below(steps) as f64 / steps as f64
    }
}

/// A quantised rate volume on a masked grid, as GLCM counting takes it: `q[(row * cols +
/// col) * bins + bin]` is a level below `levels`; masked cells carry levels too, which must
/// never be counted.
#[derive(Debug, Clone)]
pub struct Volume {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Time bins.
    pub bins: usize,
    /// Gray levels.
    pub levels: usize,
    /// Per cell, whether it holds a taxel.
    pub present: Vec<bool>,
    /// The levels, cell-major.
    pub q: Vec<u8>,
}

/// Volumes of a grid with `rows x cols` cells, each holding a taxel with probability
/// `p_present`, `bins` bins and `levels` levels; `fill(cells, bins, levels)` draws the levels.
fn masked_volume<S: Strategy<Value = Vec<u8>>>(
    shape: (Range<usize>, Range<usize>, Range<usize>, Range<usize>),
    p_present: f64,
    fill: impl Fn(usize, usize, usize) -> S,
) -> impl Strategy<Value = Volume> {
    shape.prop_flat_map(move |(rows, cols, bins, levels)| {
        let cells = rows * cols;
        (
            proptest::collection::vec(proptest::bool::weighted(p_present), cells),
            fill(cells, bins, levels),
        )
            .prop_map(move |(present, q)| Volume {
                rows,
                cols,
                bins,
                levels,
                present,
                q,
            })
    })
}

/// Small volumes whose every voxel takes any level.
pub fn uniform_volume() -> impl Strategy<Value = Volume> {
    masked_volume((1..6, 1..6, 1..25, 2..17), 0.85, |cells, bins, levels| {
        proptest::collection::vec(0u8..levels as u8, cells * bins)
    })
}

/// Volumes like real rate volumes: each cell keeps to a few levels of its own, over up to
/// 300 bins (more than one 128-bin mask block), so every counting method is exercised.
pub fn few_levels_volume() -> impl Strategy<Value = Volume> {
    masked_volume((1..5, 1..5, 1..300, 2..40), 0.9, |cells, bins, levels| {
        (
            proptest::collection::vec(proptest::collection::vec(0u8..levels as u8, 1..5), cells),
            proptest::collection::vec(any::<u8>(), cells * bins),
        )
            .prop_map(move |(own, picks)| {
                picks
                    .iter()
                    .enumerate()
                    .map(|(k, &pick)| {
                        let mine = &own[k / bins];
                        mine[pick as usize % mine.len()]
                    })
                    .collect()
            })
    })
}

/// One taxel's spike times: distinct 1 ms steps below `end`, ascending, `spikes` of them.
pub fn spike_train(end: u32, spikes: Range<usize>) -> impl Strategy<Value = Vec<u32>> {
    proptest::collection::btree_set(0..end, spikes).prop_map(|set| set.into_iter().collect())
}
