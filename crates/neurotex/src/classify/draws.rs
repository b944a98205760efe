//! The random draws of the resampling statistics (bootstrap intervals, sign-flip tests),
//! made in bulk.
//!
//! Every interval and paired test resamples from its own seeded ChaCha8 stream, and its
//! numbers are fixed by the values `rand`'s `gen_range(0..n)` (on `u64`) and `gen::<bool>()`
//! draw from that stream one at a time. Drawn one at a time, they cost about 8.5 ns each
//! (a quarter of it the generator, the rest a rejection branch taken at random, 37 % of
//! the time for 160 units); the paper-scale default run makes some 200 million of them.
//! Here the same values come from the stream's words read a block at a time and a
//! rejection that moves an index instead of taking a branch: about a third of the time.
//!
//! The arithmetic is rand 0.8's, which is what fixes the values (a `rand` with another
//! algorithm would move every interval, with or without this module);
//! `tests::the_draws_are_rands_one_at_a_time` holds them to `gen_range` and `gen` over
//! ranges with and without rejections, across block boundaries and repeated calls.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Words read from the generator at a time: its own block (four ChaCha blocks).
const WORDS: usize = 32;

/// Uniform indices below a bound, as `gen_range(0..bound as u64)` draws them in turn.
pub(crate) struct UniformIndices {
    rng: ChaCha8Rng,
    words: [u64; WORDS],
    /// The next unread word of `words`.
    next: usize,
}

impl UniformIndices {
    /// The stream of `ChaCha8Rng::seed_from_u64(seed)`.
    pub(crate) fn new(seed: u64) -> Self {
        UniformIndices {
            rng: ChaCha8Rng::seed_from_u64(seed),
            words: [0; WORDS],
            next: WORDS,
        }
    }

    /// Replaces `out` with the next `count` indices below `bound` (at least 1 when `count`
    /// is not 0).
    ///
    /// Each word `v` of the stream gives `hi:lo = v x bound` (128 bits); `hi` is the index
    /// when `lo` is at most `(bound << bound.leading_zeros()) - 1` and the word is
    /// rejected otherwise (rand 0.8's `sample_single_inclusive`). Every candidate is
    /// written and the write position advances only past accepted ones.
    pub(crate) fn fill(&mut self, bound: usize, count: usize, out: &mut Vec<usize>) {
        out.clear();
        if count == 0 {
            return;
        }
        assert!(bound > 0, "an index below 0");
        let range = bound as u64;
        let zone = (range << range.leading_zeros()).wrapping_sub(1);
        out.resize(count + 1, 0);
        let mut filled = 0;
        while filled < count {
            if self.next == WORDS {
                self.rng.fill(&mut self.words);
                self.next = 0;
            }
            let product = u128::from(self.words[self.next]) * u128::from(range);
            self.next += 1;
            out[filled] = (product >> 64) as usize;
            filled += usize::from(product as u64 <= zone);
        }
        out.truncate(count);
    }
}

/// Fair coin flips, as `gen::<bool>()` draws them in turn (the top bit of a 32-bit word).
pub(crate) struct Signs {
    rng: ChaCha8Rng,
    words: [u32; 2 * WORDS],
    next: usize,
}

impl Signs {
    /// The stream of `ChaCha8Rng::seed_from_u64(seed)`.
    pub(crate) fn new(seed: u64) -> Self {
        Signs {
            rng: ChaCha8Rng::seed_from_u64(seed),
            words: [0; 2 * WORDS],
            next: 2 * WORDS,
        }
    }

    /// `value` negated when the next flip is `true`: its sign bit flipped, which is what
    /// `-value` does, without a branch on the flip.
    pub(crate) fn flip(&mut self, value: f64) -> f64 {
        if self.next == self.words.len() {
            self.rng.fill(&mut self.words);
            self.next = 0;
        }
        let top = u64::from(self.words[self.next] >> 31);
        self.next += 1;
        f64::from_bits(value.to_bits() ^ (top << 63))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_draws_are_rands_one_at_a_time() {
        // 160 rejects 37.5 % of the words, 128 none, 1 half; 3 and 1000 between.
        for (seed, bounds) in [
            (0u64, [160usize, 3, 1, 1000, 128]),
            (7, [1, 128, 160, 2, 33]),
        ] {
            let mut bulk = UniformIndices::new(seed);
            let mut one = ChaCha8Rng::seed_from_u64(seed);
            let mut out = Vec::new();
            for round in 0..40 {
                let bound = bounds[round % bounds.len()];
                let count = 1 + (round * 37) % 90;
                bulk.fill(bound, count, &mut out);
                let expected: Vec<usize> = (0..count)
                    .map(|_| one.gen_range(0..bound as u64) as usize)
                    .collect();
                assert_eq!(out, expected, "seed {seed}, round {round}, bound {bound}");
            }
        }
        for seed in [0u64, 11] {
            let mut bulk = Signs::new(seed);
            let mut one = ChaCha8Rng::seed_from_u64(seed);
            for i in 0..1000 {
                let value = if i % 3 == 0 {
                    0.0
                } else {
                    0.25 * i as f64 - 60.0
                };
                let expected = if one.gen::<bool>() { -value } else { value };
                assert_eq!(bulk.flip(value).to_bits(), expected.to_bits(), "flip {i}");
            }
        }
    }
}
