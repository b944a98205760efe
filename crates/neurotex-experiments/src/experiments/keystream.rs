//! The ChaCha8 stream of the encoder's perturbed draws, sixteen blocks at a time with
//! AVX-512: the words `ChaCha8Rng::from_seed(seed)` fills a `[u64]` with (stream 0, the
//! 64-bit block counter from 0, each word two 32-bit words of a block, low first), so the
//! draws, and every number made from them, are those of `rand_chacha`. Without AVX-512 the
//! stream is `rand_chacha`'s own. Written here because `rand_chacha`'s vector backend
//! makes at most four blocks per call (AVX2 width), and the sensitivity's draws spent
//! about a tenth of `reproduce`'s CPU in it; with sixteen blocks per AVX-512 call (and the
//! words turned into numbers in one pass) the draws' share fell from about 17 % to 7 %
//! (docs/performance.md). A test holds the words equal to `rand_chacha`'s.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Words of sixteen blocks.
pub(super) const WORDS_PER_CALL: usize = 128;

/// A ChaCha8 stream read in whole calls of [`WORDS_PER_CALL`] words.
pub(super) struct Keystream {
    /// The seed as eight little-endian words.
    key: [u32; 8],
    /// The next block.
    block: u64,
    /// `rand_chacha`'s generator where AVX-512 is not allowed or not present.
    rng: Option<ChaCha8Rng>,
}

impl Keystream {
    /// The stream of `ChaCha8Rng::from_seed(seed)`.
    pub(super) fn new(seed: [u8; 32]) -> Self {
        let mut key = [0u32; 8];
        for (k, bytes) in key.iter_mut().zip(seed.chunks_exact(4)) {
            *k = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        }
        let rng = (!wide()).then(|| ChaCha8Rng::from_seed(seed));
        Keystream { key, block: 0, rng }
    }

    /// The next `out.len()` words, a multiple of [`WORDS_PER_CALL`].
    pub(super) fn fill(&mut self, out: &mut [u64]) {
        assert!(out.len().is_multiple_of(WORDS_PER_CALL));
        if let Some(rng) = &mut self.rng {
            rng.fill(out);
            return;
        }
        #[cfg(target_arch = "x86_64")]
        for chunk in out.chunks_exact_mut(WORDS_PER_CALL) {
            // SAFETY: `wide()` said the CPU has AVX-512F (else `rng` is set).
            unsafe { sixteen_blocks(&self.key, self.block, chunk) };
            self.block = self.block.wrapping_add(16);
        }
    }
}

/// Whether the run makes the stream with AVX-512.
fn wide() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        neurotex_core::has_feature!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// "expand 32-byte k".
const CONSTANTS: [u32; 4] = [0x6170_7865, 0x3320_646e, 0x7962_2d32, 0x6b20_6574];

/// Blocks `block..block + 16` of the stream into `out` (128 words): each of the sixteen
/// state words a register, one block per lane; the 32-bit words paired into 64-bit ones in
/// registers, then put in block order.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn sixteen_blocks(key: &[u32; 8], block: u64, out: &mut [u64]) {
    use std::arch::x86_64::*;
    let mut init = [_mm512_setzero_si512(); 16];
    for (w, &c) in CONSTANTS.iter().enumerate() {
        init[w] = _mm512_set1_epi32(c as i32);
    }
    for (w, &k) in key.iter().enumerate() {
        init[4 + w] = _mm512_set1_epi32(k as i32);
    }
    let (mut low, mut high) = ([0u32; 16], [0u32; 16]);
    for b in 0..16 {
        let n = block.wrapping_add(b as u64);
        (low[b], high[b]) = (n as u32, (n >> 32) as u32);
    }
    init[12] = _mm512_loadu_si512(low.as_ptr().cast());
    init[13] = _mm512_loadu_si512(high.as_ptr().cast());
    let mut x = init;
    // A quarter round, written out where it is used (a closure need not inherit the
    // function's target feature).
    macro_rules! quarter {
        ($a:literal, $b:literal, $c:literal, $d:literal) => {
            x[$a] = _mm512_add_epi32(x[$a], x[$b]);
            x[$d] = _mm512_rol_epi32::<16>(_mm512_xor_si512(x[$d], x[$a]));
            x[$c] = _mm512_add_epi32(x[$c], x[$d]);
            x[$b] = _mm512_rol_epi32::<12>(_mm512_xor_si512(x[$b], x[$c]));
            x[$a] = _mm512_add_epi32(x[$a], x[$b]);
            x[$d] = _mm512_rol_epi32::<8>(_mm512_xor_si512(x[$d], x[$a]));
            x[$c] = _mm512_add_epi32(x[$c], x[$d]);
            x[$b] = _mm512_rol_epi32::<7>(_mm512_xor_si512(x[$b], x[$c]));
        };
    }
    for _ in 0..4 {
        quarter!(0, 4, 8, 12);
        quarter!(1, 5, 9, 13);
        quarter!(2, 6, 10, 14);
        quarter!(3, 7, 11, 15);
        quarter!(0, 5, 10, 15);
        quarter!(1, 6, 11, 12);
        quarter!(2, 7, 8, 13);
        quarter!(3, 4, 9, 14);
    }
    // Word pair `i` of every block: the low unpack holds blocks 0, 1, 4, 5, ..., the high
    // one blocks 2, 3, 6, 7, ... (two per 128-bit lane).
    let mut pairs = [0u64; 128];
    for i in 0..8 {
        let (a, b) = (
            _mm512_add_epi32(x[2 * i], init[2 * i]),
            _mm512_add_epi32(x[2 * i + 1], init[2 * i + 1]),
        );
        let at = pairs[16 * i..].as_mut_ptr();
        _mm512_storeu_si512(at.cast(), _mm512_unpacklo_epi32(a, b));
        _mm512_storeu_si512(at.add(8).cast(), _mm512_unpackhi_epi32(a, b));
    }
    const LOW: [usize; 8] = [0, 1, 4, 5, 8, 9, 12, 13];
    const HIGH: [usize; 8] = [2, 3, 6, 7, 10, 11, 14, 15];
    for i in 0..8 {
        for j in 0..8 {
            out[LOW[j] * 8 + i] = pairs[16 * i + j];
            out[HIGH[j] * 8 + i] = pairs[16 * i + 8 + j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stream_is_rand_chachas() {
        let mut seed = [0u8; 32];
        for (i, s) in seed.iter_mut().enumerate() {
            *s = (i as u8).wrapping_mul(37).wrapping_add(11);
        }
        let mut reference = ChaCha8Rng::from_seed(seed);
        let mut stream = Keystream::new(seed);
        // Across a carry of the counter's low word too.
        stream.block = u64::from(u32::MAX) - 20;
        reference.set_word_pos(u128::from(stream.block) * 16);
        if let Some(rng) = &mut stream.rng {
            rng.set_word_pos(u128::from(stream.block) * 16);
        }
        for _ in 0..5 {
            let (mut expected, mut got) = (vec![0u64; 512], vec![0u64; 512]);
            reference.fill(&mut expected[..]);
            stream.fill(&mut got);
            assert_eq!(got, expected);
        }
    }
}
