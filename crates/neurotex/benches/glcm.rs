//! 3D-GLCM and the three Haralick features of one 4x4x90 rate volume (an 18 s slide at
//! 5 mm/s in 200 ms bins), the paper's 13 directions x distances 1, 2, 4, 8.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::encode::SpikeTrains;
use neurotex::features::glcm::GlcmKind;
use neurotex::features::{haralick, quantise, GlcmParams, GlcmPlan, RateVolume};
use neurotex::pipeline::FeatureExtractor;
use neurotex::pipeline::{Method, PipelineParams};

fn trains() -> SpikeTrains {
    let lists: Vec<Vec<u32>> = (0..16u32)
        .map(|c| {
            (0..18_000u32)
                .filter(|t| (t * 7 + c * 13) % (40 + 3 * c + t / 900) == 0)
                .collect()
        })
        .collect();
    SpikeTrains::from_lists(&lists, 4, 4, &[true; 16], 18_000)
}

fn bench(c: &mut Criterion) {
    let spikes = trains();
    let volume = RateVolume::from_spikes(&spikes, 200).unwrap();
    assert_eq!(volume.bins, 90);
    let plan = GlcmPlan::new(
        4,
        4,
        &[true; 16],
        16,
        &GlcmParams::default(),
        GlcmKind::ThreeD,
    )
    .unwrap();
    let mut group = c.benchmark_group("glcm3d");
    group.bench_function(BenchmarkId::new("quantise_count_haralick", "4x4x90"), |b| {
        let mut q = Vec::new();
        let mut counts = vec![0u32; 256];
        b.iter(|| {
            quantise(&volume, 16, None, &mut q);
            plan.count(&q, volume.bins, &mut counts);
            haralick(&counts, 16)
        })
    });
    let extractor = FeatureExtractor::new(&PipelineParams::default(), 4, 4, &[true; 16]).unwrap();
    group.bench_function(BenchmarkId::new("from_spike_trains", "4x4x90"), |b| {
        b.iter(|| extractor.row(&spikes, Method::Glcm3d).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
