//! Izhikevich encoding throughput: one recording on one core (SA, FA-I from the rectified
//! rate of change, and both as two banks side by side), and the paper-scale work
//! (480 trials x 16 taxels, slides of 18, 9 and 6 s: 84.5 M neuron-steps) across all cores.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use neurotex::encode::{encode, encode_fa, encode_sa_fa, Encoder, FaParams, IzhikevichParams};
use rayon::prelude::*;

fn signal(steps: usize, cells: usize) -> Vec<f64> {
    (0..steps * cells)
        .map(|i| {
            let (t, c) = ((i / cells) as f64, (i % cells) as f64);
            0.5 + 0.5 * ((t / 37.0 + c).sin() * (t / 211.0).cos())
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let params = IzhikevichParams::default();
    let mut group = c.benchmark_group("encode");
    let one = signal(18_000, 16);
    group.throughput(Throughput::Elements(one.len() as u64));
    group.bench_function(BenchmarkId::new("kernel_1core", "16x18000"), |b| {
        let mut raster = vec![0u8; one.len()];
        b.iter(|| {
            let mut enc = Encoder::new(params, 16).unwrap();
            enc.run(&one, &mut raster);
            raster[raster.len() - 1]
        })
    });
    group.bench_function(BenchmarkId::new("to_trains_1core", "16x18000"), |b| {
        b.iter(|| {
            encode(&one, 4, 4, &[true; 16], params)
                .unwrap()
                .total_spikes()
        })
    });
    group.bench_function(BenchmarkId::new("fa_to_trains_1core", "16x18000"), |b| {
        b.iter(|| {
            encode_fa(&one, 4, 4, &[true; 16], params, FaParams::default())
                .unwrap()
                .total_spikes()
        })
    });
    // SA and FA as two banks side by side (what `sa+fa` and `reproduce` encode), against
    // to_trains_1core + fa_to_trains_1core.
    group.bench_function(BenchmarkId::new("sa_fa_to_trains_1core", "16x18000"), |b| {
        b.iter(|| {
            let (sa, fa) =
                encode_sa_fa(&one, 4, 4, &[true; 16], params, FaParams::default()).unwrap();
            sa.total_spikes() + fa.total_spikes()
        })
    });
    // Paper scale: 160 recordings at each of three slide lengths (90 mm at 5, 10, 15 mm/s).
    let inputs: Vec<Vec<f64>> = [18_000, 9_000, 6_000]
        .iter()
        .map(|&s| signal(s, 16))
        .collect();
    let jobs: Vec<&Vec<f64>> = inputs
        .iter()
        .flat_map(|x| std::iter::repeat_n(x, 160))
        .collect();
    let steps: usize = jobs.iter().map(|x| x.len()).sum();
    group.throughput(Throughput::Elements(steps as u64));
    group.sample_size(10);
    group.bench_function(
        BenchmarkId::new("paper_scale_all_cores", format!("{steps}_neuron_steps")),
        |b| {
            b.iter(|| {
                jobs.par_iter()
                    .map(|x| encode(x, 4, 4, &[true; 16], params).unwrap().total_spikes())
                    .sum::<usize>()
            })
        },
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
