//! 3D-GLCM and the three Haralick features of one 4x4 rate volume of about 90 bins (an
//! 18 s slide at 5 mm/s in 200 ms bins), the paper's 13 directions x distances 1, 2, 4, 8.
//!
//! Three volumes: a simulated trial of the richest texture (CP, whose taxels take the most
//! gray levels), fixed synthetic trains, and uniform random levels (the worst case for the
//! level-mask counting). Each counting method is timed alone too.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::encode::SpikeTrains;
use neurotex::features::glcm::GlcmKind;
use neurotex::features::{
    haralick, quantise, CountVolume, Counting, GlcmParams, GlcmPlan, RateVolume,
};
use neurotex::pipeline::{FeatureExtractor, Method, Pipeline, PipelineParams};
use neurotex::recording::Baseline;
use neurotex::sim::texture::Texture;
use neurotex::sim::{simulate_trial, RigParams, Trial};

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

fn simulated_trains() -> SpikeTrains {
    let trial = Trial {
        texture: Texture::Cp,
        speed_mm_s: 5.0,
        trial: 0,
    };
    let recording = simulate_trial(&RigParams::default(), &trial, 0).unwrap();
    let pipeline = Pipeline::new(PipelineParams::default()).unwrap();
    pipeline.encode(&recording, Baseline::None).unwrap().spikes
}

fn bench(c: &mut Criterion) {
    let plan = GlcmPlan::new(
        4,
        4,
        &[true; 16],
        16,
        &GlcmParams::default(),
        GlcmKind::ThreeD,
    )
    .unwrap();
    let extractor =
        FeatureExtractor::new(&PipelineParams::default(), &"4x4".parse().unwrap()).unwrap();
    let mut group = c.benchmark_group("glcm3d");
    for (name, spikes) in [
        ("simulated_CP", simulated_trains()),
        ("synthetic", synthetic_trains()),
    ] {
        let volume = RateVolume::from_spikes(&spikes, 200).unwrap();
        let size = format!("{name}_4x4x{}", volume.bins);
        group.bench_function(BenchmarkId::new("quantise_count_haralick", &size), |b| {
            let mut q = Vec::new();
            let mut counts = vec![0u32; 256];
            b.iter(|| {
                quantise(&volume, 16, None, &mut q);
                plan.count(&q, volume.bins, &mut counts);
                haralick(&counts, 16)
            })
        });
        group.bench_function(BenchmarkId::new("from_spike_trains", &size), |b| {
            b.iter(|| {
                extractor
                    .population_row(&spikes, None, Method::Glcm3d)
                    .unwrap()
            })
        });
        group.bench_function(BenchmarkId::new("from_spike_trains_2d", &size), |b| {
            b.iter(|| {
                extractor
                    .population_row(&spikes, None, Method::Glcm2d)
                    .unwrap()
            })
        });
        // The levels of the counts alone, over the volume's own range and a fixed one.
        let counted = CountVolume::from_spikes(&spikes, 200).unwrap();
        for (range_name, range) in [("own_range", None), ("fixed_range", Some((5.0, 95.0)))] {
            let id = BenchmarkId::new(format!("quantise_counts_{range_name}"), &size);
            group.bench_function(id, |b| {
                let mut q = Vec::new();
                b.iter(|| counted.quantise(16, range, &mut q))
            });
        }
        let mut q = Vec::new();
        quantise(&volume, 16, None, &mut q);
        for counting in [Counting::Histogram, Counting::LevelMasks, Counting::OneHot] {
            let id = BenchmarkId::new(format!("count_{counting:?}"), &size);
            group.bench_function(id, |b| {
                let mut counts = vec![0u32; 256];
                b.iter(|| plan.count_with(&q, volume.bins, &mut counts, counting))
            });
        }
    }
    // Uniform random levels: every cell takes all 16.
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let random: Vec<u8> = (0..16 * 90)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 60) as u8
        })
        .collect();
    for counting in [Counting::Histogram, Counting::OneHot] {
        let id = BenchmarkId::new(format!("count_{counting:?}"), "random_4x4x90");
        group.bench_function(id, |b| {
            let mut counts = vec![0u32; 256];
            b.iter(|| plan.count_with(&random, 90, &mut counts, counting))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
