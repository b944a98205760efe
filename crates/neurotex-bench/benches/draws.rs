//! The encoder's sensitivity in `reproduce`: one recording's 8 draws (its conditioned
//! input and 7 copies perturbed at rounding level) encoded one call each
//! (`Pipeline::encode_populations`) against all in one call, each draw's populations banks
//! side by side (`Pipeline::encode_populations_side_by_side`), for the `sa` and `sa+fa`
//! encodings; and for `sa`, the draws made a block of steps at a time as the banks run
//! (`Drive::Made`, as `reproduce` makes its perturbed inputs). `perturbed_inputs` times
//! the 7 perturbed inputs themselves (their ChaCha8 stream and the products) as
//! `reproduce` makes them. The recording is the
//! simulator's 90 mm slide at 5 mm/s on the 4x4 rig (18 s), the longest of the paper's
//! design.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use neurotex::encode::{encode_drives, BankRows, Drive, MadeDrive};
use neurotex::experiments::{perturbed_input, ReproduceParams};
use neurotex::pipeline::{Encoding, Pipeline, PipelineParams};
use neurotex::recording::Baseline;
use neurotex::signal::Conditioned;
use neurotex::sim::{simulate_trial, RigParams, Texture, Trial};

/// Draws per recording, `reproduce`'s default.
const DRAWS: usize = 8;

/// `samples`, the first draw as it is, the others each times `1 + 1e-12 u` with `u` in
/// [-1, 1) from a xorshift stream (the perturbation's generator is not what is timed).
fn draws(samples: &[f64]) -> Vec<Vec<f64>> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut u = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    (0..DRAWS)
        .map(|draw| {
            let scale = if draw == 0 { 0.0 } else { 1e-12 };
            samples.iter().map(|&x| x * (1.0 + scale * u())).collect()
        })
        .collect()
}

/// A draw made as the banks ask for it: the recording's samples times a factor.
struct Scaled<'a> {
    samples: &'a [f64],
    cells: usize,
    factor: f64,
}

impl MadeDrive for Scaled<'_> {
    fn values(&self) -> usize {
        self.samples.len()
    }

    fn fill(&mut self, first: usize, mut rows: BankRows<'_>) {
        let samples = &self.samples[first * self.cells..][..rows.steps() * self.cells];
        for (row, x) in rows.rows().zip(samples.chunks_exact(self.cells)) {
            for (out, &x) in row.iter_mut().zip(x) {
                *out = x * self.factor;
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    let trial = Trial {
        texture: Texture::Sb,
        speed_mm_s: 5.0,
        trial: 0,
    };
    let rec = simulate_trial(&RigParams::default(), &trial, 0).unwrap();
    let mut group = c.benchmark_group("draws");
    group.sample_size(20);
    for encoding in [Encoding::Sa, Encoding::SaFa] {
        let params = PipelineParams {
            encoding,
            ..PipelineParams::default()
        };
        let pipeline = Pipeline::new(params).unwrap();
        let cond = pipeline.condition(&rec, Baseline::None).unwrap();
        let inputs = draws(&cond.samples);
        let conditioned: Vec<Conditioned> = inputs
            .iter()
            .map(|samples| Conditioned {
                samples: samples.clone(),
                ..cond.clone()
            })
            .collect();
        let views: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        let (cells, steps) = (cond.cells, cond.n_steps());
        let size = format!("{encoding}_{cells}x{steps}ms_{DRAWS}draws");
        group.throughput(Throughput::Elements((DRAWS * cells * steps) as u64));
        group.bench_function(BenchmarkId::new("one_by_one", &size), |b| {
            b.iter(|| {
                conditioned
                    .iter()
                    .map(|cond| pipeline.encode_populations(&rec, cond).unwrap())
                    .map(|(sa, fa)| sa.total_spikes() + fa.map_or(0, |f| f.total_spikes()))
                    .sum::<usize>()
            })
        });
        group.bench_function(BenchmarkId::new("side_by_side", &size), |b| {
            b.iter(|| {
                pipeline
                    .encode_populations_side_by_side(&rec, &views)
                    .unwrap()
                    .into_iter()
                    .map(|(sa, fa)| sa.total_spikes() + fa.map_or(0, |f| f.total_spikes()))
                    .sum::<usize>()
            })
        });
        if encoding == Encoding::Sa {
            let reproduce = ReproduceParams::default().check().unwrap();
            let inputs = format!("{cells}x{steps}ms_{}draws", DRAWS - 1);
            group.bench_function(BenchmarkId::new("perturbed_inputs", inputs), |b| {
                b.iter(|| {
                    (1..DRAWS)
                        .map(|draw| perturbed_input(&cond.samples, &reproduce, draw, 0)[0])
                        .sum::<f64>()
                })
            });
            let neuron = pipeline.params().encoder;
            let l = &rec.layout;
            group.bench_function(BenchmarkId::new("made_side_by_side", &size), |b| {
                b.iter(|| {
                    let mut made: Vec<Scaled> = (0..DRAWS)
                        .map(|draw| Scaled {
                            samples: &cond.samples,
                            cells,
                            factor: 1.0 + draw as f64 * 1e-12,
                        })
                        .collect();
                    let mut drives: Vec<Drive> = made.iter_mut().map(|m| Drive::Made(m)).collect();
                    let gains = [neuron.gain; DRAWS];
                    encode_drives(&mut drives, &gains, l.rows, l.cols, &l.present, neuron)
                        .unwrap()
                        .iter()
                        .map(|sa| sa.total_spikes())
                        .sum::<usize>()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
