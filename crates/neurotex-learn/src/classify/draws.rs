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

use std::sync::{Arc, Mutex};

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

/// Most indices one [`for_each_resample`] keeps for later calls (32 MiB of them), and
/// most kept at once: a larger draw is made again each time.
const KEPT: usize = 1 << 22;

/// The draws kept: `(seed, bounds, rounds)` and the indices.
type Kept = Vec<((u64, Vec<usize>, usize), Arc<Vec<usize>>)>;

/// Calls `each` with `rounds` rounds of indices from the stream of
/// `ChaCha8Rng::seed_from_u64(seed)`: each round is `bounds[0]` indices below `bounds[0]`,
/// then `bounds[1]` below `bounds[1]`, and so on, concatenated, as
/// [`UniformIndices::fill`] draws them in turn.
///
/// A bootstrap interval draws nothing but these, and every interval of a run resamples
/// the same recordings (or units per condition) with the run's seed: the draws are the
/// same each time. So they are made once per process and kept (up to [`KEPT`] indices in
/// all; the oldest go first), and an interval then costs its sums alone. The values are
/// those drawn in turn either way (`tests::kept_draws_are_the_streams`).
///
/// The kept draws are process-wide state on purpose: a memo of a pure function of its key
/// (seed, bounds, rounds), so no result depends on what is kept or on the order of calls,
/// and it is shared by every interval and test of a run (E1 to E9, `compare`'s candidates)
/// without threading a cache through each of their signatures.
pub fn for_each_resample(
    seed: u64,
    bounds: &[usize],
    rounds: usize,
    mut each: impl FnMut(&[usize]),
) {
    let per_round: usize = bounds.iter().sum();
    let Some(total) = per_round.checked_mul(rounds).filter(|&t| t <= KEPT) else {
        // Too many to keep: drawn round by round.
        let mut draws = UniformIndices::new(seed);
        let (mut round, mut part) = (Vec::with_capacity(per_round), Vec::new());
        for _ in 0..rounds {
            round.clear();
            for &bound in bounds {
                draws.fill(bound, bound, &mut part);
                round.extend_from_slice(&part);
            }
            each(&round);
        }
        return;
    };
    static DRAWS: Mutex<Kept> = Mutex::new(Vec::new());
    let key = (seed, bounds.to_vec(), rounds);
    let found = {
        let kept = DRAWS.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter()
            .find(|(k, _)| *k == key)
            .map(|(_, d)| Arc::clone(d))
    };
    let all = found.unwrap_or_else(|| {
        let mut draws = UniformIndices::new(seed);
        let (mut all, mut part) = (Vec::with_capacity(total), Vec::new());
        for _ in 0..rounds {
            for &bound in bounds {
                draws.fill(bound, bound, &mut part);
                all.extend_from_slice(&part);
            }
        }
        let all = Arc::new(all);
        let mut kept = DRAWS.lock().unwrap_or_else(|e| e.into_inner());
        if !kept.iter().any(|(k, _)| *k == key) {
            kept.push((key, Arc::clone(&all)));
            while kept.iter().map(|(_, d)| d.len()).sum::<usize>() > KEPT {
                kept.remove(0);
            }
        }
        all
    });
    // `per_round` is 0 only with no bounds or empty ones: rounds of nothing.
    match per_round {
        0 => (0..rounds).for_each(|_| each(&[])),
        _ => all.chunks_exact(per_round).for_each(each),
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
    fn kept_draws_are_the_streams() {
        // Kept (small), kept and found again, and too many to keep (drawn round by round).
        for (seed, bounds, rounds) in [
            (3u64, vec![160, 7], 50),
            (3, vec![160, 7], 50),
            (5, vec![1000, 3000], 1500),
            (9, vec![], 4),
        ] {
            let mut one = ChaCha8Rng::seed_from_u64(seed);
            let mut calls = 0;
            for_each_resample(seed, &bounds, rounds, |round| {
                let expected: Vec<usize> = bounds
                    .iter()
                    .flat_map(|&b| {
                        (0..b)
                            .map(|_| one.gen_range(0..b as u64) as usize)
                            .collect::<Vec<_>>()
                    })
                    .collect();
                assert_eq!(round, expected, "seed {seed}, round {calls}");
                calls += 1;
            });
            assert_eq!(calls, rounds);
        }
    }

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
