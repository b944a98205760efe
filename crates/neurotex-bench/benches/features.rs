//! The feature methods beyond the paper on one 4x4 recording of 18 s (a 90 mm slide at
//! 5 mm/s): the 13 Haralick features of one 16-level matrix, the multi-scale 3D-GLCM
//! (50, 100, 200, 400 ms bins, paper and full Haralick sets), all taxels' statistics
//! per second and per mm of travel, and one taxel's signal statistics (the baselines
//! without spikes) over the slide's 18 000 samples.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::encode::SpikeTrains;
use neurotex::features::{haralick_full, signal_stats};
use neurotex::pipeline::{FeatureExtractor, FeatureParams, HaralickSet, Method, PipelineParams};

fn synthetic_trains() -> SpikeTrains {
    let lists: Vec<Vec<u32>> = (0..16u32)
        .map(|c| {
            (0..18_000u32)
                .filter(|t| (t * 7 + c * 13) % (40 + 3 * c + t / 900) == 0)
                .collect()
        })
        .collect();
    SpikeTrains::from_lists(&lists, 4, 4, &[true; 16], 18_000)
}

fn extractor(haralick: HaralickSet) -> FeatureExtractor {
    let params = PipelineParams {
        features: FeatureParams {
            haralick,
            ..FeatureParams::default()
        },
        ..PipelineParams::default()
    };
    FeatureExtractor::new(&params, &"4x4".parse().unwrap()).unwrap()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("features");
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let counts: Vec<f64> = (0..256)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 54) as f64
        })
        .collect();
    group.bench_function(BenchmarkId::new("haralick_full", "16_levels"), |b| {
        b.iter(|| haralick_full(&counts, 16))
    });
    let spikes = synthetic_trains();
    for (set, name) in [(HaralickSet::Paper, "paper"), (HaralickSet::Full, "full")] {
        let e = extractor(set);
        let id = BenchmarkId::new(format!("glcm3d_multi_{name}"), "4x4x18000ms");
        group.bench_function(id, |b| {
            b.iter(|| {
                e.population_row(&spikes, None, Method::Glcm3dMulti)
                    .unwrap()
            })
        });
    }
    let e = extractor(HaralickSet::Paper);
    for method in [Method::AllTaxels, Method::AllTaxelsMm, Method::Spectrum] {
        let id = BenchmarkId::new(method.name(), "4x4x18000ms");
        group.bench_function(id, |b| {
            b.iter(|| e.population_row(&spikes, Some(5.0), method).unwrap())
        });
    }
    let signal: Vec<f64> = (0..18_000)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect();
    group.bench_function(BenchmarkId::new("signal_stats", "18000"), |b| {
        b.iter(|| signal_stats(std::hint::black_box(&signal)))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
