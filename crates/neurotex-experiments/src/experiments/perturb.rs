//! The encoder's sensitivity: each recording's conditioned input perturbed at the level of
//! rounding, once for each further encoding, and encoded.

use super::keystream::Keystream;
use super::{Draws, ValidReproduceParams};
use crate::encode::{encode_drives, BankRows, Drive, MadeDrive, SpikeTrains};
use crate::error::Result;
use crate::pipeline::{Encoding, Pipeline};
use crate::recording::Recording;
use crate::signal::Conditioned;

/// Recording `recording`'s further encodings of the encoder's sensitivity under `params`
/// ([`perturbed_encodings`]).
///
/// # Errors
/// A broken encoder rule.
pub(super) fn perturbed_draws(
    rec: &Recording,
    cond: &Conditioned,
    params: &ValidReproduceParams,
    recording: usize,
) -> Result<Vec<(SpikeTrains, Option<SpikeTrains>)>> {
    perturbed_encodings(params.pipeline(), rec, cond, params.draws(), recording)
}

/// Recording `recording`'s further encodings (`draws.encodings - 1` of them) by
/// `pipeline`: its conditioned input perturbed once for each ([`Perturbed`]), all encoded
/// in one call, each population of each draw a bank of neurons beside the others
/// ([`encode_drives`]). `recording` seeds the recording's streams: the same number gives
/// the same perturbations.
///
/// # Errors
/// A broken encoder rule.
pub fn perturbed_encodings(
    pipeline: &Pipeline,
    rec: &Recording,
    cond: &Conditioned,
    draws: Draws,
    recording: usize,
) -> Result<Vec<(SpikeTrains, Option<SpikeTrains>)>> {
    let further = 1..draws.encodings;
    let (samples, cells) = (cond.samples.as_slice(), cond.cells);
    let perturbed = |encoding| Perturbed::new(samples, cells, draws, encoding, recording);
    if further.is_empty() {
        return Ok(Vec::new());
    }
    if pipeline.params().encoding != Encoding::Sa {
        // An FA population reads its input's rate of change from one step to the next, so
        // these encodings take each perturbed input whole.
        let inputs: Vec<Vec<f64>> = further.map(|e| perturbed(e).whole()).collect();
        let inputs: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        return pipeline.encode_populations_side_by_side(rec, &inputs);
    }
    // The SA population, as `Pipeline::encode_populations` encodes it, from perturbed
    // inputs made a block of steps at a time as the banks run.
    let mut made: Vec<Perturbed> = further.map(perturbed).collect();
    let mut drives: Vec<Drive> = made.iter_mut().map(|m| Drive::Made(m)).collect();
    let (l, encoder) = (&rec.layout, pipeline.params().encoder);
    let gains = vec![encoder.gain; drives.len()];
    let trains = encode_drives(&mut drives, &gains, l.rows, l.cols, &l.present, encoder)?;
    Ok(trains.into_iter().map(|sa| (sa, None)).collect())
}

/// A recording's conditioned samples for one further encoding of the encoder's
/// sensitivity: each times `1 + u * params.perturbation` with `u` uniform in [-1, 1) from
/// a ChaCha8 stream of its own for the run's seed, the encoding and the recording. The
/// perturbations are independent across samples, encodings and recordings, and the same
/// on every run and thread count.
///
/// The stream is read a block of words at a time, and each word becomes `u` as
/// `rng.gen_range(-1.0..1.0)` makes it (rand 0.8's `UniformFloat::sample_single`): the
/// top 52 bits as a mantissa in [1, 2), less 1, times 2, less 1. Every step is exact, so
/// no draw is rejected and `u` is that of one `gen_range` call per sample, without the
/// call's cost per sample.
struct Perturbed<'a> {
    samples: &'a [f64],
    cells: usize,
    eps: f64,
    stream: Keystream,
    /// Words read from the stream, used from `next` on.
    words: Vec<u64>,
    next: usize,
}

impl<'a> Perturbed<'a> {
    /// Words per read of the stream: a few ChaCha blocks, kept in cache.
    const WORDS: usize = 512;

    /// `samples` of `cells` values a step.
    fn new(
        samples: &'a [f64],
        cells: usize,
        draws: Draws,
        encoding: usize,
        recording: usize,
    ) -> Self {
        let mut key = [0u8; 32];
        key[..8].copy_from_slice(&draws.seed.to_le_bytes());
        key[8..16].copy_from_slice(&(encoding as u64).to_le_bytes());
        key[16..24].copy_from_slice(&(recording as u64).to_le_bytes());
        key[24..].copy_from_slice(b"encoding");
        Perturbed {
            samples,
            cells,
            eps: draws.size,
            stream: Keystream::new(key),
            words: vec![0; Self::WORDS],
            next: Self::WORDS,
        }
    }

    /// Writes the next samples of the stream, perturbed, into `out`: as many at a time as
    /// the words read hold.
    fn perturb(&mut self, mut samples: &[f64], mut out: &mut [f64]) {
        while !samples.is_empty() && !out.is_empty() {
            if self.next == Self::WORDS {
                self.stream.fill(&mut self.words);
                self.next = 0;
            }
            let n = (Self::WORDS - self.next).min(samples.len()).min(out.len());
            let words = &self.words[self.next..self.next + n];
            perturb_with(words, self.eps, &samples[..n], &mut out[..n]);
            self.next += n;
            (samples, out) = (&samples[n..], &mut out[n..]);
        }
    }

    /// Every perturbed sample, in one vector.
    fn whole(mut self) -> Vec<f64> {
        let mut out = vec![0.0; self.samples.len()];
        self.perturb(self.samples, &mut out);
        out
    }
}

neurotex_core::widest_or_plain! {
    ["avx512f", "avx2"]
    /// `x * (1 + eps u)` for each sample `x` and word of the stream, `u` in [-1, 1) as
    /// `gen_range(-1.0..1.0)` makes it of the word: element by element, so any vector
    /// width gives the same bits.
    fn perturb_with(words: &[u64], eps: f64, samples: &[f64], out: &mut [f64]) {
        let n = words.len().min(samples.len()).min(out.len());
        for i in 0..n {
            let one_to_two = f64::from_bits(words[i] >> 12 | 1.0f64.to_bits());
            let u = (one_to_two - 1.0) * 2.0 + -1.0;
            out[i] = samples[i] * (1.0 + eps * u);
        }
    }
}

impl MadeDrive for Perturbed<'_> {
    fn values(&self) -> usize {
        self.samples.len()
    }

    /// The stream is read in order, so the blocks must come in order from step 0 on, as
    /// [`encode_drives`] asks for them.
    fn fill(&mut self, first: usize, mut rows: BankRows<'_>) {
        let cells = self.cells;
        let samples = &self.samples[first * cells..][..rows.steps() * cells];
        for (row, x) in rows.rows().zip(samples.chunks_exact(cells)) {
            self.perturb(x, row);
        }
    }
}

/// `samples` perturbed for further encoding `encoding` of recording `recording`, whole:
/// the input the encoder's sensitivity encodes (`reproduce` makes it a block of steps at a
/// time as the encoder runs, with the same values).
pub fn perturbed_input(
    samples: &[f64],
    params: &ValidReproduceParams,
    encoding: usize,
    recording: usize,
) -> Vec<f64> {
    Perturbed::new(samples, 1, params.draws(), encoding, recording).whole()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::ReproduceParams;
    use crate::recording::Baseline;
    use crate::sim::{design, simulate_trial, RigParams, ALL_TEXTURES};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The perturbation one `gen_range` call per sample, as the stream is meant to be read.
    fn perturbed_input_one_by_one(
        samples: &[f64],
        params: &ValidReproduceParams,
        encoding: usize,
        recording: usize,
    ) -> Vec<f64> {
        let mut key = [0u8; 32];
        key[..8].copy_from_slice(&params.seed.to_le_bytes());
        key[8..16].copy_from_slice(&(encoding as u64).to_le_bytes());
        key[16..24].copy_from_slice(&(recording as u64).to_le_bytes());
        key[24..].copy_from_slice(b"encoding");
        let mut rng = ChaCha8Rng::from_seed(key);
        let eps = params.perturbation;
        samples
            .iter()
            .map(|&x| x * (1.0 + eps * rng.gen_range(-1.0..1.0)))
            .collect()
    }

    #[test]
    fn perturbations_read_in_blocks_are_those_of_one_draw_per_sample() {
        let params = ReproduceParams::default().check().unwrap();
        // Lengths around the block of words read at a time.
        for len in [0, 1, 511, 512, 513, 1500] {
            let input: Vec<f64> = (0..len)
                .map(|i| 0.3 + (i as f64 * 0.7).cos() / 4.0)
                .collect();
            for (encoding, recording) in [(1, 0), (7, 3), (2, 479)] {
                let fast = perturbed_input(&input, &params, encoding, recording);
                let slow = perturbed_input_one_by_one(&input, &params, encoding, recording);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&slow), "{len} samples");
                // Made in pieces of 21 values, as the encoder's blocks of rows ask for them:
                // the words left from one piece serve the next.
                let whole = len / 21 * 21;
                let draws = params.draws();
                let mut made = Perturbed::new(&input[..whole], 3, draws, encoding, recording);
                let mut blocks = vec![0.0; whole];
                for (b, block) in blocks.chunks_mut(21).enumerate() {
                    let x = &input[b * 21..][..21];
                    made.perturb(x, block);
                }
                assert_eq!(
                    bits(&blocks),
                    bits(&slow[..whole]),
                    "{len} samples in blocks"
                );
            }
        }
    }

    /// A simulated recording's further encodings, one call for all of them against
    /// [`Pipeline::encode_populations`] of each perturbed input in turn, for every
    /// encoding: the same spike trains.
    #[test]
    fn draws_side_by_side_give_the_trains_of_the_draws_one_by_one() {
        let trial = &design(&ALL_TEXTURES[2..3], &[15.0], 1)[0];
        let rec = simulate_trial(&RigParams::default(), trial, 4).unwrap();
        for encoding in [Encoding::Sa, Encoding::Fa, Encoding::SaFa] {
            // Perturbations large enough that the draws' trains differ, so that a draw
            // given another's trains shows.
            let mut reproduce = ReproduceParams {
                perturbation: 1e-4,
                ..ReproduceParams::default()
            };
            reproduce.pipeline.encoding = encoding;
            let params = reproduce.check().unwrap();
            let pipeline = params.pipeline();
            let cond = pipeline.condition(&rec, Baseline::None).unwrap();
            let together = perturbed_draws(&rec, &cond, &params, 5).unwrap();
            assert_eq!(together.len(), params.encoder_draws - 1);
            for (draw, got) in (1..params.encoder_draws).zip(&together) {
                let samples = perturbed_input_one_by_one(&cond.samples, &params, draw, 5);
                let cond = Conditioned {
                    samples,
                    ..cond.clone()
                };
                let alone = pipeline.encode_populations(&rec, &cond).unwrap();
                assert_eq!(got, &alone, "{encoding:?}, draw {draw}");
                let spikes = got.0.total_spikes() + got.1.as_ref().map_or(0, |f| f.total_spikes());
                assert!(spikes > 100, "{encoding:?}: only {spikes} spikes");
            }
            let differ = together.windows(2).filter(|w| w[0] != w[1]).count();
            assert_eq!(differ, together.len() - 1, "{encoding:?}: draws alike");
        }
    }

    #[test]
    fn perturbations_are_tiny_seeded_and_independent_per_encoding_and_recording() {
        let params = ReproduceParams::default().check().unwrap();
        let input: Vec<f64> = (0..1000)
            .map(|i| 0.5 + (i as f64 * 0.01).sin() / 3.0)
            .collect();
        let a = perturbed_input(&input, &params, 1, 0);
        assert_eq!(a, perturbed_input(&input, &params, 1, 0));
        let moved = a.iter().zip(&input).filter(|(p, x)| p != x).count();
        assert!(moved > 900, "only {moved} of 1000 samples moved");
        for (p, x) in a.iter().zip(&input) {
            assert!(((p - x) / x).abs() <= params.perturbation * (1.0 + 1e-3));
        }
        assert_ne!(a, perturbed_input(&input, &params, 2, 0));
        assert_ne!(a, perturbed_input(&input, &params, 1, 1));
        let reseeded = ReproduceParams {
            seed: 1,
            ..ReproduceParams::default()
        };
        assert_ne!(a, perturbed_input(&input, &reseeded.check().unwrap(), 1, 0));
    }
}
